//! The `evaluate` command end to end: the report (golden file), flags, errors.

use crate::util::{assert_golden, axcomp, root, test_data};

const SAMPLE: &str = "fixtures/sample-x.rtl";

#[test]
fn terminal_report_of_the_bundled_sample() {
    let run = axcomp(["evaluate", SAMPLE]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert_golden(&run.stdout, &test_data("golden/evaluate-sample-x.txt"));
}

#[test]
fn json_report_of_the_bundled_sample() {
    let run = axcomp(["evaluate", "--json", SAMPLE]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    for key in [
        "format",
        "axis",
        "targets_mm",
        "runs",
        "figures_um",
        "per_target",
        "outliers",
    ] {
        assert!(json.get(key).is_some(), "missing key {key}");
    }
    assert_eq!(json["format"], "rtl");
    assert_eq!(json["runs"]["up"], 5);
    let target = &json["per_target"][0];
    for key in [
        "target_mm",
        "mean_up_um",
        "mean_down_um",
        "mean_um",
        "s_up_um",
        "s_down_um",
        "B_um",
        "R_up_um",
        "R_down_um",
        "R_um",
    ] {
        assert!(target.get(key).is_some(), "missing per-target key {key}");
    }
    assert_golden(&run.stdout, &test_data("golden/evaluate-sample-x.json"));
}

#[test]
fn excluding_a_run_changes_the_counts_and_is_recorded() {
    let run = axcomp([
        "evaluate",
        "--json",
        SAMPLE,
        "--exclude-run",
        "1:down",
        "--exclude-run",
        "5",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(
        (json["runs"]["up"].as_u64(), json["runs"]["down"].as_u64()),
        (Some(4), Some(3))
    );
    assert_eq!(json["excluded_runs"], serde_json::json!(["1:down", "5"]));
}

#[test]
fn excluding_a_run_that_does_not_exist_is_an_error() {
    let run = axcomp(["evaluate", SAMPLE, "--exclude-run", "6:up"]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr
            .contains("--exclude-run 6:up: no such run (the file has runs 1–5 ↑ and 1–5 ↓)"),
        "{}",
        run.stderr
    );
}

#[test]
fn format_override_and_axis_rename() {
    let forced = axcomp(["evaluate", "--format", "csv", SAMPLE]);
    assert_eq!(forced.code, 2);
    assert!(
        forced
            .stderr
            .contains("sample-x.rtl:1:1: expected the header target_mm,run,direction,deviation_um"),
        "{}",
        forced.stderr
    );
    let unknown = axcomp(["evaluate", "--format", "xls", SAMPLE]);
    assert_eq!(unknown.code, 2);
    assert!(
        unknown
            .stderr
            .contains("supported: rtl, ecmc, api-pos, csv"),
        "{}",
        unknown.stderr
    );
    let renamed = axcomp(["evaluate", "--json", "--axis", "U", SAMPLE]);
    assert!(renamed.stdout.contains("\"axis\": \"U\""));
}

#[test]
fn warnings_go_to_stderr_unless_quiet() {
    let pos = crate::util::shared_data("api-xd/example__8055__X Axis Forward.pos");
    let loud = axcomp(["evaluate".as_ref(), pos.as_os_str()]);
    assert!(
        loud.stderr.contains("warning: unidirectional test"),
        "{}",
        loud.stderr
    );
    let quiet = axcomp(["evaluate".as_ref(), "--quiet".as_ref(), pos.as_os_str()]);
    assert_eq!((quiet.code, quiet.stderr.as_str()), (0, ""));
}

#[test]
fn usage_errors_exit_2_and_help_exits_0() {
    assert_eq!(axcomp(["evaluate"]).code, 2);
    assert_eq!(axcomp(["frobnicate"]).code, 2);
    let help = axcomp(["evaluate", "--help"]);
    assert_eq!(help.code, 0);
    assert!(help.stdout.contains("--exclude-run"));
    let missing = axcomp(["evaluate", "no-such-file.rtl"]);
    assert_eq!(missing.code, 2);
    assert!(
        missing.stderr.contains("no-such-file.rtl: No such file"),
        "{}",
        missing.stderr
    );
}

/// A missing input and an output into a missing folder: one line each, the
/// OS message once, no temporary file's name (issue 11, point 6).
#[test]
fn file_errors_are_one_clean_line() {
    let missing = axcomp(["evaluate", "no-such-file.rtl"]);
    assert_eq!(missing.code, 2);
    assert_eq!(
        missing.stderr,
        "axcomp: error: cannot read no-such-file.rtl: No such file or directory (os error 2)\n"
    );
    let report = axcomp(["report", "no-such-file.rtl", "-o", "no-such-folder/r.html"]);
    assert_eq!(
        report.stderr,
        "axcomp: error: cannot read no-such-file.rtl: No such file or directory (os error 2)\n"
    );

    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("out/dir/X.COM");
    let sample = root().join("fixtures/sample-x.rtl");
    let run = axcomp([
        "convert".as_ref(),
        sample.as_os_str(),
        "--controller".as_ref(),
        "tnc640".as_ref(),
        "-o".as_ref(),
        output.as_os_str(),
    ]);
    assert_eq!(run.code, 2);
    assert_eq!(
        run.stderr,
        format!(
            "axcomp: error: cannot write {}: the folder {} does not exist\n",
            output.display(),
            directory.path().join("out/dir").display()
        )
    );
    assert!(
        !directory.path().join("out").exists(),
        "no folder is created"
    );
}

/// The CSV layout as Excel saves it in a European locale (`;` and a decimal
/// comma) and as tab-separated text reads to the same figures as the comma
/// layout (issue 11, point 6).
#[test]
fn excel_csv_layouts_give_the_same_figures() {
    let directory = tempfile::tempdir().unwrap();
    let rows = [
        (0.0, 1, "up", "0.5"),
        (100.0, 1, "up", "-1.25"),
        (0.0, 1, "down", "1.5"),
        (100.0, 1, "down", "-0.75"),
        (0.0, 2, "up", "0.25"),
        (100.0, 2, "up", "-1.5"),
        (0.0, 2, "down", "1.75"),
        (100.0, 2, "down", "-0.5"),
    ];
    let write = |name: &str, separator: &str, comma: bool| {
        let mut text = format!(
            "# axis: Y{separator}{separator}{separator}\r\ntarget_mm{separator}run{separator}direction{separator}deviation_um\r\n"
        );
        for (target, run, direction, value) in rows {
            let value = if comma {
                value.replace('.', ",")
            } else {
                value.to_string()
            };
            text.push_str(&format!(
                "{target}{separator}{run}{separator}{direction}{separator}{value}\r\n"
            ));
        }
        let path = directory.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let comma = write("comma.csv", ",", false);
    let semicolon = write("excel.csv", ";", true);
    let tab = write("text.txt", "\t", false);
    let figures = |path: &std::path::Path| {
        let report = crate::util::evaluate_json(&[path]);
        assert_eq!(report["format"], "csv");
        assert_eq!(report["axis"], "Y");
        (report["figures_um"].clone(), report["per_target"].clone())
    };
    let expected = figures(&comma);
    // x̄↑ at 0 mm: (0.5 + 0.25) / 2, by hand.
    assert_eq!(expected.1[0]["mean_up_um"], 0.375);
    assert_eq!(figures(&semicolon), expected);
    assert_eq!(figures(&tab), expected);
}
