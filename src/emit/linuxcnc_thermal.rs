//! A thermal model as a LinuxCNC HAL file: the model computed online with
//! components that ship with LinuxCNC and fed to an axis' external offset.
//!
//! Per term: `lowpass` (`out += gain·(in − out)`, `gain = 1 − e^(−T/τ)` for
//! the servo period T: the exact step of the first-order lag, as
//! `thermal::lag`; τ = 0 is gain 1), then `scale` (`out = in·gain + offset`,
//! `gain = −c/1000` mm/K and `offset = c·T_ref/1000` mm: the term's drift,
//! negated, so the offset takes the drift out), `sum2` chained to add the
//! terms, `conv_float_s32` to the axis' `eoffset-counts` at
//! `eoffset-scale` 1 nm. Facts (manual: LinuxCNC 2.9 man pages lowpass(9),
//! scale(9), sum2(9), conv_float_s32(9); the External Offsets chapter of the
//! LinuxCNC 2.9 documentation): `lowpass.N.gain` is a parameter and
//! `lowpass.N.load` a pin that copies `in` to `out`; external offsets need
//! `[AXIS_L]OFFSET_AV_RATIO` in the INI and `axis.L.eoffset-enable`.
//! `conv_float_s32` truncates toward zero: the offset is within 1 nm.

use crate::thermal::ThermalModel;
use crate::units::um_to_mm;

/// The offset's resolution, mm per count (`axis.L.eoffset-scale`).
pub const EOFFSET_SCALE_MM: f64 = 1e-6;

/// The lowpass gain of a lag `tau_s` updated every `period_s`.
pub fn lowpass_gain(tau_s: f64, period_s: f64) -> f64 {
    if tau_s <= 0.0 {
        1.0
    } else {
        1.0 - (-period_s / tau_s).exp()
    }
}

/// The HAL file for `model` on axis `axis` (x, y, z, …) in a thread of
/// `period_s` (the servo thread's period, s).
pub fn write_hal(model: &ThermalModel, axis: &str, period_s: f64, thread: &str) -> String {
    let n = model.terms.len();
    let axis = axis.to_ascii_lowercase();
    let names = |prefix: &str, count: usize, from: usize| -> String {
        (from..from + count)
            .map(|k| format!("{prefix}{k}"))
            .collect::<Vec<_>>()
            .join(",")
    };
    let mut hal = format!(
        "# axcomp thermal model as HAL: offset_mm = -sum over terms of\n\
         #   c/1000 * (lowpass(T, tau) - T_ref), c in um/K, T in degC.\n\
         # Fitted on rows {}-{} of the drift {:?}; prediction uncertainty {:.2} um (1 sigma).\n\
         # Connect each temperature (degC) to its signal, e.g. net thermal-T0 <= <sensor pin>.\n\
         # Hold thermal-load TRUE for the first period: the lags start at the first reading.\n\
         # Needs [AXIS_{}]OFFSET_AV_RATIO in the INI (external offsets, LinuxCNC 2.8+).\n",
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
    hal.push_str("loadrt conv_float_s32 names=thermal-counts\n");
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
        "addf thermal-to-counts {thread}\naddf thermal-counts {thread}\n"
    ));
    for (k, term) in model.terms.iter().enumerate() {
        let c_mm = um_to_mm(term.coefficient_um_per_k);
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
            -c_mm,
            c_mm * term.reference_c,
        ));
    }
    // The running sum: thermal-sum-k adds term k to the sum of the terms before it.
    let mut total = "thermal-term-0.out".to_string();
    for k in 1..n {
        hal.push_str(&format!(
            "net thermal-partial-{k} {total} => thermal-sum-{k}.in0\n\
             net thermal-mm-{k} thermal-term-{k}.out => thermal-sum-{k}.in1\n"
        ));
        total = format!("thermal-sum-{k}.out");
    }
    hal.push_str(&format!(
        "net thermal-offset-mm {total} => thermal-to-counts.in\n\
         setp thermal-to-counts.gain {:e}\n\
         net thermal-offset-counts-float thermal-to-counts.out => thermal-counts.in\n\
         setp axis.{axis}.eoffset-scale {:e}\n\
         net thermal-offset-counts thermal-counts.out => axis.{axis}.eoffset-counts\n\
         setp axis.{axis}.eoffset-enable 1\n",
        1.0 / EOFFSET_SCALE_MM,
        EOFFSET_SCALE_MM
    ));
    hal
}
