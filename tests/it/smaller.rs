//! Smaller findings of one review, each through the binary: what the
//! engineer reads must name the right axis, point and precision.

use crate::util::{axcomp, root};

const SAMPLE: &str = "fixtures/sample-x.rtl";

/// A 100 mm step on the 0 … 750 mm test reaches 0 + 7·100 = 700 mm; the
/// 50 mm beyond it are left out of the table, and convert says so.
#[test]
fn convert_says_where_a_step_that_does_not_divide_the_range_ends() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("X.COM");
    let run = axcomp([
        "convert",
        root().join(SAMPLE).to_str().unwrap(),
        "--controller",
        "itnc530",
        "--axis",
        "X",
        "--step",
        "100",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let said = format!("{}{}", run.stdout, run.stderr);
    assert!(
        said.contains("the table ends at 700 mm, its last compensation point, short of the measured end 750 mm"),
        "{said}"
    );
    assert!(said.contains("give a step that divides 750 mm"), "{said}");
    // A step that divides the range ends at the measured end: no note.
    let run = axcomp([
        "convert",
        root().join(SAMPLE).to_str().unwrap(),
        "--controller",
        "itnc530",
        "--axis",
        "X",
        "--step",
        "150",
        "-o",
        dir.path().join("X2.COM").to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(!format!("{}{}", run.stdout, run.stderr).contains("the table ends at"));
}

/// A TNC 640 table of axis Y given for the X test: the error names both axes.
#[test]
fn a_y_table_for_an_x_test_says_which_axis_each_is_for() {
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("Y.COM");
    let sample = root().join(SAMPLE);
    let run = axcomp([
        "convert",
        sample.to_str().unwrap(),
        "--controller",
        "tnc640",
        "--axis",
        "Y",
        "-o",
        table.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let run = axcomp([
        "predict",
        "--measured",
        &format!("X={}", sample.display()),
        "--table",
        &format!("X={}", table.display()),
    ]);
    assert_eq!(run.code, 2, "{}{}", run.stdout, run.stderr);
    assert!(
        run.stderr
            .contains("Y.COM:2:1: the table is for axis Y (its value column), the test for axis X"),
        "{}",
        run.stderr
    );
}

/// The Fagor 8055 inch table on the terminal shows what the file holds
/// (5 decimals), row for row: 0.000008 in is written 0.00001 in the file.
#[test]
fn the_fagor_8055_inch_table_prints_as_the_file_has() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ALX");
    let run = axcomp([
        "convert",
        crate::util::shared_data("api-xd/example__8055__X Axis Forward.pos")
            .to_str()
            .unwrap(),
        "--controller",
        "fagor8055",
        "--axis",
        "X",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let file = std::fs::read_to_string(&out).unwrap();
    let file_values: Vec<f64> = file
        .lines()
        .filter(|l| l.trim_start().starts_with('P'))
        .map(|l| l.split_whitespace().nth(4).unwrap().parse().unwrap())
        .collect();
    let printed: Vec<f64> = run
        .stdout
        .lines()
        .skip_while(|l| !l.contains("value in"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().nth(2).unwrap().parse().unwrap())
        .collect();
    assert_eq!(printed.len(), 27, "{}", run.stdout);
    assert_eq!(printed, file_values, "{}", run.stdout);
    assert!(run.stdout.contains("  0.00001  "), "{}", run.stdout);
}

/// diagnose's terminal shows a periodic effect's phase with 4 decimals (as
/// the effects file writes it), the JSON's full value rounded.
#[test]
fn diagnose_prints_the_phase_with_four_decimals() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let case = crate::diagnose_periodic::case(15.0, 3, true);
    std::fs::write(path("truth.toml"), &case.truth).unwrap();
    crate::util::synth_loop_files(
        dir.path(),
        dir.path().join("truth.toml").as_path(),
        Some("3"),
    );
    let profile = root().join("fixtures/machines/vc1810.toml");
    let args = |json: bool| {
        let mut args = vec![
            "diagnose".to_string(),
            "--after".into(),
            path("after.rtl"),
            "--before".into(),
            path("before.rtl"),
            "--table".into(),
            path("X.COM"),
            "--machine".into(),
            profile.to_str().unwrap().to_string(),
        ];
        if json {
            args.push("--json".into());
        }
        args
    };
    let run = axcomp(args(true));
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let phase = json["effects"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["kind"] == "periodic")
        .unwrap()["params"]["phase_rad"]
        .as_f64()
        .unwrap();
    let run = axcomp(args(false));
    assert_eq!(run.code, 0, "{}", run.stderr);
    let shown = format!("phase_rad = {phase:.4}");
    assert!(
        run.stdout.contains(&format!("{shown},")) || run.stdout.contains(&format!("{shown} ")),
        "{}",
        run.stdout
    );
}

/// A one-run ↑ test has E↑ but neither M (bidirectional) nor A (needs s):
/// the uncertainty line names U(E) only; a full test names all three.
#[test]
fn the_uncertainty_line_names_only_the_figures_evaluated() {
    let one_run = axcomp([
        "evaluate",
        crate::util::shared_data("api-xd/example__8055__X Axis Forward.pos")
            .to_str()
            .unwrap(),
    ]);
    assert_eq!(one_run.code, 0, "{}", one_run.stderr);
    let line = one_run
        .stdout
        .lines()
        .find(|l| l.starts_with("U("))
        .unwrap_or_else(|| panic!("{}", one_run.stdout));
    assert!(line.starts_with("U(E) = 8.13 µm (k = 2"), "{line}");
    let full = axcomp(["evaluate", root().join(SAMPLE).to_str().unwrap()]);
    assert_eq!(full.code, 0, "{}", full.stderr);
    assert!(
        full.stdout.contains("\nU(E) = U(M) = U(A) = "),
        "{}",
        full.stdout
    );
}

/// `report` of an evenly spaced test and re-test says the even-spacing
/// warning once for each file, naming it (it printed the same line twice).
#[test]
fn report_says_each_files_even_spacing_once_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    // 17 targets 0 … 800 mm without jitter: every 50 mm.
    std::fs::write(
        path("truth.toml"),
        "[cycle]\nstart_mm = 0.0\nend_mm = 800.0\ncount = 17\njitter_mm = 0.0\nruns = 5\nstart = \"2026-11-20 09:00:00\"\n\n\
         [error]\nscale_um_per_m = 9.5\n\n[noise]\nsigma_um = 0.4\n",
    )
    .unwrap();
    crate::util::synth_loop_files(
        dir.path(),
        dir.path().join("truth.toml").as_path(),
        Some("3"),
    );
    let run = axcomp([
        "report",
        &path("before.rtl"),
        "--after",
        &path("after.rtl"),
        "--table",
        &path("X.COM"),
        "-o",
        &path("r.html"),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let even: Vec<&str> = run
        .stderr
        .lines()
        .filter(|l| l.contains("targets evenly spaced every 50 mm"))
        .collect();
    assert_eq!(even.len(), 2, "{}", run.stderr);
    assert!(
        even[0].starts_with(&format!("axcomp: warning: {}: ", path("before.rtl"))),
        "{}",
        run.stderr
    );
    assert!(
        even[1].starts_with(&format!("axcomp: warning: {}: ", path("after.rtl"))),
        "{}",
        run.stderr
    );
}
