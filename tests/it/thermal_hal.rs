//! `axcomp thermal hal`: the HAL file of a hand-written two-term model
//! (golden file `formats/linuxcnc/golden/thermal-z.hal`), its numbers
//! against values computed by hand, and the gate that keeps the counts at 0
//! until the machine is on and homed (what LinuxCNC's motion controller
//! needs to apply the whole offset: `formats/linuxcnc/thermal.md`).

use approx::abs_diff_eq;

use crate::util::{assert_golden, axcomp, root, test_data};

const MODEL: &str = "thermal/two-terms.toml";

/// The golden files `thermal hal` writes, by controller folder
/// (`convert::every_golden_file_has_a_case`).
pub const GOLDENS: [(&str, &str); 1] = [("linuxcnc", "thermal-z.hal")];

fn hal_for(model: &str, axis: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("thermal.hal");
    let run = axcomp([
        "thermal",
        "hal",
        test_data(model).to_str().unwrap(),
        "--axis",
        axis,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    std::fs::read_to_string(out).unwrap()
}

/// The value `setp NAME VALUE` gives in `hal`.
fn setp(hal: &str, name: &str) -> f64 {
    let prefix = format!("setp {name} ");
    hal.lines()
        .find_map(|l| l.strip_prefix(prefix.as_str()))
        .unwrap_or_else(|| panic!("no setp {name} in:\n{hal}"))
        .parse()
        .unwrap()
}

#[test]
fn the_hal_file_of_a_two_term_model_is_the_golden_file() {
    let hal = hal_for(MODEL, "z");
    let (controller, name) = GOLDENS[0];
    assert_golden(
        &hal,
        &root().join(format!("formats/{controller}/golden/{name}")),
    );
}

#[test]
fn the_hal_file_computes_the_model_in_mm() {
    let hal = hal_for(MODEL, "z");
    // T0: τ = 600 s in a 1 ms thread: gain 1 − e^(−x), x = 1/600 000,
    // = x − x²/2 + x³/6 − … = 1.666 665 277 778 549 4e-6 (the series to
    // x⁴, 40 digits); to 1e-12 relative: 1 − exp(−x) in f64 is off by 6e-12.
    // 1.5 µm/K → −0.0015 mm/K and +0.0015 × 25 = 0.0375 mm.
    let gain = setp(&hal, "thermal-lag-0.gain");
    assert!(
        (gain / 1.666_665_277_778_549_4e-6 - 1.0).abs() < 1e-12,
        "{gain:e}"
    );
    assert_eq!(setp(&hal, "thermal-term-0.gain"), -0.0015);
    assert!((setp(&hal, "thermal-term-0.offset") - 0.0375).abs() < 1e-15);
    // T14: no lag (gain 1); −2 µm/K → +0.002 mm/K and −0.04 mm.
    assert_eq!(setp(&hal, "thermal-lag-1.gain"), 1.0);
    assert_eq!(setp(&hal, "thermal-term-1.gain"), 0.002);
    assert!((setp(&hal, "thermal-term-1.offset") + 0.04).abs() < 1e-15);
    // Settled at T0 = 27 °C, T14 = 21 °C the drift is 1.5·2 − 2·1 = 1 µm:
    // the offset takes it out, −0.001 mm, in 1 nm counts.
    let offset_mm = 27.0 * setp(&hal, "thermal-term-0.gain")
        + setp(&hal, "thermal-term-0.offset")
        + 21.0 * setp(&hal, "thermal-term-1.gain")
        + setp(&hal, "thermal-term-1.offset");
    assert!((offset_mm + 0.001).abs() < 1e-15, "{offset_mm}");
    assert_eq!(setp(&hal, "thermal-to-counts.gain"), 1e6);
    assert_eq!(setp(&hal, "axis.z.eoffset-scale"), 1e-6);
    assert_eq!(setp(&hal, "axis.z.eoffset-enable"), 1.0);
}

#[test]
fn the_counts_stay_zero_until_the_machine_is_on_and_homed() {
    let hal = hal_for(MODEL, "x");
    for line in [
        "net thermal-offset-counts-float thermal-to-counts.out => thermal-gate.in1",
        "net thermal-machine-on motion.motion-enabled => thermal-ready.in0",
        "net thermal-homed motion.is-all-homed => thermal-ready.in1",
        "net thermal-ready thermal-ready.out => thermal-gate.sel",
        "net thermal-offset-counts-gated thermal-gate.out => thermal-counts.in",
        "net thermal-offset-counts thermal-counts.out => axis.x.eoffset-counts",
    ] {
        assert!(hal.lines().any(|l| l == line), "no {line:?} in:\n{hal}");
    }
    // mux2's in0 (the counts when not ready) is never set: 0.
    assert!(!hal.contains("thermal-gate.in0"), "{hal}");
    // The gate runs after the counts are computed and before they are converted.
    let at = |f: &str| {
        hal.lines()
            .position(|l| l == format!("addf {f} servo-thread"))
            .unwrap_or_else(|| panic!("no addf {f}"))
    };
    assert!(at("thermal-to-counts") < at("thermal-gate"));
    assert!(at("thermal-gate") < at("thermal-counts"));
}

/// On an inch machine (`[controller] units = "inch"`, LinuxCNC's
/// `[TRAJ]LINEAR_UNITS = inch`) the external offset is in inches: the same
/// model's gains divided by 25.4, counts of 0.1 µin.
#[test]
fn on_an_inch_machine_the_offset_is_in_inches() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("thermal.hal");
    let run = axcomp([
        "thermal",
        "hal",
        test_data(MODEL).to_str().unwrap(),
        "--axis",
        "z",
        "--machine",
        root()
            .join("fixtures/machines/gantry-inch.toml")
            .to_str()
            .unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let hal = std::fs::read_to_string(out).unwrap();
    assert!(hal.contains("offset (inch)"), "{hal}");
    // 1.5 µm/K = 0.0015 mm/K = 0.0015/25.4 in/K = 5.905 511 811e-5 in/K;
    // from 25 °C: 1.476 377 952 8e-3 in. −2 µm/K: 7.874 015 748e-5 in/K.
    let close = |name: &str, expected: f64| {
        let value = setp(&hal, name);
        assert!(
            abs_diff_eq!(value / expected, 1.0, epsilon = 1e-12),
            "{name}: {value:e}, expected {expected:e}"
        );
    };
    close("thermal-term-0.gain", -5.905_511_811_023_622e-5);
    close("thermal-term-0.offset", 1.476_377_952_755_905_5e-3);
    close("thermal-term-1.gain", 7.874_015_748_031_496e-5);
    close("thermal-term-1.offset", -1.574_803_149_606_299_3e-3);
    // The lag does not depend on the unit.
    assert_eq!(
        setp(&hal, "thermal-lag-0.gain"),
        setp(&hal_for(MODEL, "z"), "thermal-lag-0.gain")
    );
    assert_eq!(setp(&hal, "thermal-to-counts.gain"), 1e7);
    assert_eq!(setp(&hal, "axis.z.eoffset-scale"), 1e-7);
}
