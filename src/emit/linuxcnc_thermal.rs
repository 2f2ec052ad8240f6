//! A thermal model as a LinuxCNC HAL file: the model computed online with
//! components that ship with LinuxCNC and fed to an axis' external offset.
//!
//! Per term: `lowpass` (`out += gain·(in − out)`, `gain = 1 − e^(−T/τ)` for
//! the servo period T: the exact step of the first-order lag, as
//! `thermal::lag`; τ = 0 is gain 1), then `scale` (`out = in·gain + offset`,
//! `gain = −c/1000` mm/K and `offset = c·T_ref/1000` mm: the term's drift,
//! negated, so the offset takes the drift out; in inch on an inch machine:
//! LinuxCNC's external offset is in `[TRAJ]LINEAR_UNITS`), `sum2` chained to
//! add the terms, `conv_float_s32` to the axis' `eoffset-counts` at
//! `eoffset-scale` 1 nm (0.1 µin). Facts (manual: LinuxCNC 2.9 man pages lowpass(9),
//! scale(9), sum2(9), conv_float_s32(9); the External Offsets chapter of the
//! LinuxCNC 2.9 documentation): `lowpass.N.gain` is a parameter and
//! `lowpass.N.load` a pin that copies `in` to `out`; external offsets need
//! `[AXIS_L]OFFSET_AV_RATIO` in the INI and `axis.L.eoffset-enable`. A
//! component module is loaded once: beside a configuration that loads the
//! same components, the file needs `[HAL]TWOPASS`, which combines the
//! `loadrt` lines of all HAL files when they all use `names=` (LinuxCNC 2.9
//! `twopass.tcl`; the HAL manual's "Twopass" chapter).
//! `conv_float_s32` truncates toward zero: the offset is within 1 nm.
//!
//! The motion controller takes `eoffset-counts` as increments: each period
//! it adds the change of the counts since the last period, but only while
//! the machine is on and every joint homed, and it zeroes the offset when
//! the machine is switched on (LinuxCNC 2.9 `src/emc/motion/control.c`,
//! `plan_external_offsets`; motion(9): "the register is reset to zero at
//! each machine startup"). The model runs from the file's loading, so its
//! offset is already there at switch-on: fed straight in, it would be lost
//! and only its later changes applied. The counts therefore pass a gate
//! (`and2` of `motion.motion-enabled` and `motion.is-all-homed` selecting a
//! `mux2`) and are 0 until the machine is on and homed: their first change
//! is then the whole offset, and switching off and on again repeats it.

use crate::thermal::ThermalModel;
use crate::units::{LengthUnit, um_to_mm};

/// The offset's resolution in the machine's unit per count
/// (`axis.L.eoffset-scale`): 1 nm on a mm machine, 0.1 µin on an inch one,
/// the resolution of the LinuxCNC table's values.
pub fn eoffset_scale(unit: LengthUnit) -> f64 {
    10f64.powi(-counts_exponent(unit))
}

/// Counts per machine unit are 10 to this power (exact in f64).
fn counts_exponent(unit: LengthUnit) -> i32 {
    i32::try_from(super::linuxcnc::decimals(unit)).unwrap_or(6)
}

/// The lowpass gain of a lag `tau_s` updated every `period_s`:
/// `1 − e^(−T/τ)`, as `−expm1(−T/τ)`, which keeps its digits where T/τ is
/// tiny (1 ms against hours: `1 − e^(−x)` would lose ten of them).
pub fn lowpass_gain(tau_s: f64, period_s: f64) -> f64 {
    if tau_s <= 0.0 {
        1.0
    } else {
        -(-period_s / tau_s).exp_m1()
    }
}

/// The HAL file for `model` on axis `axis` (x, y, z, …) of a machine in
/// `unit` (its `[TRAJ]LINEAR_UNITS`) in a thread of `period_s` (the servo
/// thread's period, s).
pub fn write_hal(
    model: &ThermalModel,
    axis: &str,
    unit: LengthUnit,
    period_s: f64,
    thread: &str,
) -> String {
    let n = model.terms.len();
    let scale = eoffset_scale(unit);
    let axis = axis.to_ascii_lowercase();
    let names = |prefix: &str, count: usize, from: usize| -> String {
        (from..from + count)
            .map(|k| format!("{prefix}{k}"))
            .collect::<Vec<_>>()
            .join(",")
    };
    let mut hal = format!(
        "# axcomp thermal model as HAL: offset ({}) = -sum over terms of\n\
         #   c * (lowpass(T, tau) - T_ref), c in um/K written in {}/K, T in degC.\n\
         # For a machine in {} ([TRAJ]LINEAR_UNITS): the external offset is in machine units.\n\
         # Fitted on rows {}-{} of the drift {:?}; prediction uncertainty {:.2} um (1 sigma, in the fit rows' conditions).\n\
         # Connect each temperature (degC) to its signal, e.g. net thermal-T0 <= <sensor pin>.\n\
         # Hold thermal-load TRUE for the first period: the lags start at the first reading.\n\
         # Needs [AXIS_{}]OFFSET_AV_RATIO in the INI (external offsets, LinuxCNC 2.8+).\n\
         # Links motion.motion-enabled and motion.is-all-homed: where the configuration\n\
         # has them on signals already, use those signals in the two nets below.\n\
         # A component is loaded once: where the configuration loads lowpass, scale, sum2,\n\
         # and2, mux2 or conv_float_s32 too, set [HAL]TWOPASS = on (LinuxCNC then combines\n\
         # the loadrt lines of all HAL files; they must all use names=, not count=).\n",
        unit.as_str(),
        unit.as_str(),
        unit.as_str(),
        model.fit.first_row,
        model.fit.last_row,
        model.fit.drift,
        model.fit.cv_rms_um,
        axis.to_ascii_uppercase()
    );
    if n == 0 {
        hal.push_str("# the model has no term: no offset\n");
        return hal;
    }
    hal.push_str(&format!(
        "loadrt lowpass names={}\n",
        names("thermal-lag-", n, 0)
    ));
    // One loadrt per component: LinuxCNC refuses to load a component twice.
    hal.push_str(&format!(
        "loadrt scale names={},thermal-to-counts\n",
        names("thermal-term-", n, 0)
    ));
    if n > 1 {
        hal.push_str(&format!(
            "loadrt sum2 names={}\n",
            names("thermal-sum-", n - 1, 1)
        ));
    }
    hal.push_str(
        "loadrt and2 names=thermal-ready\n\
         loadrt mux2 names=thermal-gate\n\
         loadrt conv_float_s32 names=thermal-counts\n",
    );
    for k in 0..n {
        hal.push_str(&format!("addf thermal-lag-{k} {thread}\n"));
    }
    for k in 0..n {
        hal.push_str(&format!("addf thermal-term-{k} {thread}\n"));
    }
    for k in 1..n {
        hal.push_str(&format!("addf thermal-sum-{k} {thread}\n"));
    }
    hal.push_str(&format!(
        "addf thermal-to-counts {thread}\n\
         addf thermal-ready {thread}\n\
         addf thermal-gate {thread}\n\
         addf thermal-counts {thread}\n"
    ));
    for (k, term) in model.terms.iter().enumerate() {
        // The term's drift per K in the machine's unit.
        let c = unit.from_mm(um_to_mm(term.coefficient_um_per_k));
        hal.push_str(&format!(
            "# term {k}: {} through tau = {} s, {} um/K from {} degC\n\
             setp thermal-lag-{k}.gain {:e}\n\
             net thermal-{} => thermal-lag-{k}.in\n\
             net thermal-load => thermal-lag-{k}.load\n\
             net thermal-lagged-{k} thermal-lag-{k}.out => thermal-term-{k}.in\n\
             setp thermal-term-{k}.gain {:e}\n\
             setp thermal-term-{k}.offset {:e}\n",
            term.sensor,
            term.tau_s,
            term.coefficient_um_per_k,
            term.reference_c,
            lowpass_gain(term.tau_s, period_s),
            term.sensor,
            -c,
            c * term.reference_c,
        ));
    }
    // The running sum: thermal-sum-k adds term k to the sum of the terms before it.
    let mut total = "thermal-term-0.out".to_string();
    for k in 1..n {
        hal.push_str(&format!(
            "net thermal-partial-{k} {total} => thermal-sum-{k}.in0\n\
             net thermal-offset-{k} thermal-term-{k}.out => thermal-sum-{k}.in1\n"
        ));
        total = format!("thermal-sum-{k}.out");
    }
    hal.push_str(&format!(
        "net thermal-offset {total} => thermal-to-counts.in\n\
         setp thermal-to-counts.gain {:e}\n\
         net thermal-offset-counts-float thermal-to-counts.out => thermal-gate.in1\n\
         # The counts stay 0 until the machine is on and homed: LinuxCNC adds only\n\
         # their changes, from then on, to an offset it zeroes at machine on.\n\
         net thermal-machine-on motion.motion-enabled => thermal-ready.in0\n\
         net thermal-homed motion.is-all-homed => thermal-ready.in1\n\
         net thermal-ready thermal-ready.out => thermal-gate.sel\n\
         net thermal-offset-counts-gated thermal-gate.out => thermal-counts.in\n\
         setp axis.{axis}.eoffset-scale {:e}\n\
         net thermal-offset-counts thermal-counts.out => axis.{axis}.eoffset-counts\n\
         setp axis.{axis}.eoffset-enable 1\n",
        10f64.powi(counts_exponent(unit)),
        scale
    ));
    hal
}
