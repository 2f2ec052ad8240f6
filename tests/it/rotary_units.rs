//! A rotary axis' table refusals say positions in degrees, the unit the
//! engineer typed `--start`, `--step` and `--reference` in (the fixture
//! `fixtures/rotary/c.csv` measures 0 … 360° every 15°).

use crate::util::axcomp;

const ROTARY: &str = "fixtures/rotary/c.csv";

/// `convert` of the rotary fixture to LinuxCNC with `extra` flags: it must
/// be refused (exit 2); its message.
fn refused(extra: &[&str]) -> String {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("c.comp");
    let mut args = vec![
        "convert",
        ROTARY,
        "--controller",
        "linuxcnc",
        "-o",
        output.to_str().unwrap(),
    ];
    args.extend(extra);
    let run = axcomp(args);
    assert_eq!(run.code, 2, "{}\n{}", run.stdout, run.stderr);
    assert!(!output.exists(), "nothing is written when refused");
    run.stderr
}

/// The refusal of `convert` with `extra` says `expected`, and no "mm".
fn said_in_degrees(extra: &[&str], expected: &str) {
    let stderr = refused(extra);
    assert!(stderr.contains(expected), "{stderr}");
    assert!(!stderr.contains("mm"), "{stderr}");
}

#[test]
fn a_reference_outside_the_rotary_table_is_said_in_degrees() {
    said_in_degrees(
        &["--reference", "400"],
        "reference position 400° is outside the table 0 … 360°",
    );
}

#[test]
fn a_grid_point_outside_the_rotary_range_is_said_in_degrees() {
    // 0, 50, … 400°: the ninth point, 400°, lies past the last target, 360°.
    said_in_degrees(
        &["--start", "0", "--step", "50", "--count", "9"],
        "compensation point 400° is outside the measured range 0 … 360°",
    );
}

#[test]
fn an_update_reference_outside_the_rotary_test_is_said_in_degrees() {
    // The table written from this very test (0 … 360°) as the active one.
    said_in_degrees(
        &[
            "--existing",
            "formats/linuxcnc/golden/rotary-c-mean-type0.txt",
            "--reference",
            "-30",
        ],
        "the reference -30° is outside the measured range 0 … 360°",
    );
}
