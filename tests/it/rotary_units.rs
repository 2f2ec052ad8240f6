//! A rotary axis' table refusals say positions in degrees, the unit the
//! engineer typed `--start`, `--step` and `--reference` in (the fixture
//! `fixtures/rotary/c.csv` measures 0 … 360° every 15°).

use crate::util::axcomp;

const ROTARY: &str = "fixtures/rotary/c.csv";

/// `convert` of the rotary fixture to `controller` with `extra` flags: it
/// must be refused (exit 2); its message.
fn refused(controller: &str, extra: &[&str]) -> String {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("c.comp");
    let mut args = vec![
        "convert",
        ROTARY,
        "--controller",
        controller,
        "-o",
        output.to_str().unwrap(),
    ];
    args.extend(extra);
    let run = axcomp(args);
    assert_eq!(run.code, 2, "{}\n{}", run.stdout, run.stderr);
    assert!(!output.exists(), "nothing is written when refused");
    run.stderr
}

/// The refusal of `convert` to LinuxCNC with `extra` says `expected`, and
/// no "mm".
fn said_in_degrees(extra: &[&str], expected: &str) {
    said_in_degrees_for("linuxcnc", extra, expected);
}

/// [`said_in_degrees`] for `controller`.
fn said_in_degrees_for(controller: &str, extra: &[&str], expected: &str) {
    let stderr = refused(controller, extra);
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

/// `convert --existing --json` of a rotary axis writes the update's
/// positions under `_deg` keys: the fixture's 0 … 360° updated on a 30°
/// grid, the old 15°, 45°, … 345° points dropped, referred to the old
/// table's zero, 0°.
#[test]
fn a_rotary_update_says_its_positions_in_degrees_in_json() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("c.comp");
    let run = axcomp([
        "convert",
        ROTARY,
        "--controller",
        "linuxcnc",
        "--existing",
        "formats/linuxcnc/golden/rotary-c-mean-type0.txt",
        "--start",
        "0",
        "--step",
        "30",
        "-o",
        output.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let update = &json["update"];
    assert_eq!(update["measured_deg"], serde_json::json!([0.0, 360.0]));
    assert_eq!(update["reference_deg"], 0.0);
    assert_eq!(update["kept_deg"], serde_json::json!([]));
    let dropped: Vec<f64> = (0..12).map(|k| 15.0 + 30.0 * f64::from(k)).collect();
    assert_eq!(update["dropped_deg"], serde_json::json!(dropped));
    assert_eq!(update["added_deg"], serde_json::json!([]));
    let keys: Vec<&String> = update.as_object().unwrap().keys().collect();
    assert!(keys.iter().all(|k| !k.ends_with("_mm")), "{keys:?}");
}

#[test]
fn a_step_the_itnc_cannot_write_is_said_in_degrees() {
    // The iTNC 530 writes the step to 0.0001°: 7.50005° is no multiple.
    said_in_degrees_for(
        "itnc530",
        &["--start", "0", "--step", "7.50005", "--count", "3"],
        "writes the step to 0.0001°; a step of 7.50005° would shift the points along the table: \
         give --step as a multiple of 0.0001°",
    );
}
