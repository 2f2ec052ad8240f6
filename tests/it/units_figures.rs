//! The report's figures and notes in the units of their axis: a rotary
//! axis' outlier run is said in ″ (µrad) at a target in °, as `evaluate
//! --json` writes it, never in µm at a target in mm.

use crate::util::axcomp;

/// The rotary fixture with 25″ added to run 1↓ at 90° (`tests/data/rotary`).
const OUTLIER_RUN: &str = "tests/data/rotary/c-outlier-run.csv";

fn report(args: &[&str]) -> String {
    let directory = tempfile::tempdir().unwrap();
    let html = directory.path().join("r.html");
    let out = html.to_str().unwrap();
    let run = axcomp([&["report", OUTLIER_RUN, "-o", out, "-q"][..], args].concat());
    assert_eq!(run.code, 0, "{}", run.stderr);
    std::fs::read_to_string(&html).unwrap()
}

/// Run 1↓ at 90° reads 28.523″, the other ↓ runs 3.133, 3.209, 2.803 and
/// 3.316″ (the fixture): 28.523 − 3.11525 = 25.40775″ = 123.18 µrad
/// (1″ = π/648000 rad).
#[test]
fn a_rotary_outlier_run_is_said_in_its_angle_unit_at_a_target_in_degrees() {
    let arcsec = report(&[]);
    assert!(
        arcsec.contains("run 1↓ is a suspected outlier (score ")
            && arcsec.contains("; +25.41 ″ off the other runs at 90°)"),
        "{arcsec}"
    );
    let urad = report(&["--angle-unit", "urad"]);
    assert!(
        urad.contains("; +123.18 µrad off the other runs at 90°)"),
        "{urad}"
    );
}
