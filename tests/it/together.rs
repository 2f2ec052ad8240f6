//! Inputs that are joined or compared must belong together
//! (`together`): every command that takes two of them refuses a
//! clear mismatch with exit code 2 and the reason (another axis, ranges
//! without a common stretch, the same file or the same readings twice) and
//! shows a doubtful one as a warning, on stderr and in the report (other
//! machine names, other units, a range that only partly overlaps).
//!
//! Inputs are `fixtures/sample-x.rtl` edited as text (axis, machine, one
//! reading, the targets shifted) and the real ESS and API files.

use std::path::{Path, PathBuf};

use crate::util::{Run, axcomp, root, shared_data};

const SAMPLE: &str = "fixtures/sample-x.rtl";

fn sample() -> PathBuf {
    root().join(SAMPLE)
}

/// The sample's text with `edits` (from, to) applied, each exactly once.
fn edited(edits: &[(&str, &str)]) -> String {
    let mut text = std::fs::read_to_string(sample()).unwrap();
    for (from, to) in edits {
        assert_eq!(text.matches(from).count(), 1, "{from:?} once in the sample");
        text = text.replacen(from, to, 1);
    }
    text
}

/// The sample's text with every target moved by `shift_mm` (the lines
/// between `Targets :` and `Flags:`), and one reading changed so that the
/// readings are not the sample's.
fn shifted(shift_mm: f64) -> String {
    let text = edited(&[("1   1        -1.019", "1   1        -1.119")]);
    let mut out = Vec::new();
    let mut in_targets = false;
    for line in text.lines() {
        if line.starts_with("Flags:") {
            in_targets = false;
        }
        if in_targets {
            let moved: Vec<String> = line
                .split_whitespace()
                .map(|t| format!("{:.4}", t.parse::<f64>().unwrap() + shift_mm))
                .collect();
            out.push(moved.join("  "));
        } else {
            out.push(line.to_string());
        }
        if line.starts_with("Targets :") {
            in_targets = true;
        }
    }
    out.join("\n") + "\n"
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn run(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Run {
    axcomp(args.iter().map(|a| a.as_ref()))
}

fn refused(result: &Run, reason: &str) {
    assert_eq!(result.code, 2, "must be refused: {}", result.stdout);
    assert!(result.stderr.contains(reason), "{}", result.stderr);
}

/// A re-test of the sample: one reading changed (a re-test never repeats a test to the digit).
const RETEST: (&str, &str) = ("1   1        -1.019", "1   1        -1.119");

#[test]
fn evaluate_refuses_one_file_twice_and_a_copy_of_it() {
    let dir = tempfile::tempdir().unwrap();
    // Today's bug: 10↑ 10↓ runs from one 5↑ 5↓ file.
    let result = run(&[&"evaluate", &sample(), &sample()]);
    refused(&result, "fixtures/sample-x.rtl is given twice");
    // Another spelling of the same path is the same file.
    let result = run(&[
        &"evaluate",
        &sample(),
        &root().join("fixtures/./sample-x.rtl"),
    ]);
    refused(&result, "fixtures/sample-x.rtl is given twice");
    let copy = write(dir.path(), "copy.rtl", &edited(&[]));
    let result = run(&[&"evaluate", &sample(), &copy]);
    refused(
        &result,
        "hold the same readings (the same file, or a copy of it)",
    );
    let result = run(&[
        &"convert",
        &sample(),
        &copy,
        &"--controller",
        &"tnc640",
        &"-o",
        &dir.path().join("X.COM"),
    ]);
    refused(&result, "hold the same readings");
    assert!(!dir.path().join("X.COM").exists(), "nothing written");
}

#[test]
fn evaluate_refuses_files_of_two_axes() {
    let dir = tempfile::tempdir().unwrap();
    let y = write(
        dir.path(),
        "y.rtl",
        &edited(&[("Axis: X", "Axis: Y"), RETEST]),
    );
    let result = run(&[&"evaluate", &sample(), &y]);
    refused(&result, "is of axis X, ");
    assert!(
        result.stderr.contains("y.rtl of axis Y"),
        "{}",
        result.stderr
    );
}

#[test]
fn api_files_of_two_stretches_do_not_join() {
    // Real files: the X file covers 0 … 3302 mm, the "Y" file −2159 … 0 mm.
    let result = run(&[
        &"evaluate",
        &shared_data("api-xd/example__8055__X Axis Forward.pos"),
        &shared_data("api-xd/example__8055__Y Axis Forward.pos"),
    ]);
    refused(
        &result,
        "the ranges do not overlap, so they are not one test",
    );
}

#[test]
fn report_refuses_a_retest_of_another_axis_range_or_the_same_file() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("report.html");
    let y = write(
        dir.path(),
        "y.rtl",
        &edited(&[("Axis: X", "Axis: Y"), RETEST]),
    );
    let far = write(dir.path(), "far.rtl", &shifted(1000.0));
    for (after, reason) in [
        (y.as_path(), "is of axis X, "),
        (
            far.as_path(),
            "far.rtl 1000 … 1750 mm: the ranges do not overlap",
        ),
        (sample().as_path(), "is given twice"),
    ] {
        let result = run(&[&"report", &sample(), &"--after", &after, &"-o", &html]);
        refused(&result, reason);
        assert!(
            !html.exists(),
            "no report for inputs that do not belong together"
        );
    }
    // Real ESS files of different stages: −4 … 4 mm against 15 … 55.8 mm.
    let result = run(&[
        &"report",
        &shared_data(
            "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__back__target_x_report.md_ISO230.dat",
        ),
        &"--after",
        &shared_data("ecmc/ecmccfg/examples__mcu1025_fat_sat__report.md_ISO230.dat"),
        &"-o",
        &html,
    ]);
    refused(&result, "the ranges do not overlap");
    assert!(!html.exists());
}

#[test]
fn report_shows_doubts_as_warnings_in_the_terminal_and_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("report.html");
    // Another machine name and a range moved by 400 mm: 0 … 750 against 400 … 1150.
    let other = shifted(400.0).replace("Machine: MCV 754 Quick", "Machine: Other mill");
    let after = write(dir.path(), "other.rtl", &other);
    let result = run(&[&"report", &sample(), &"--after", &after, &"-o", &html]);
    assert_eq!(result.code, 0, "{}", result.stderr);
    let page = std::fs::read_to_string(&html).unwrap();
    for warning in [
        "names machine \"MCV 754 Quick\", ",
        "other.rtl \"Other mill\": check that both are of the same machine",
        "covers 0 … 750 mm, ",
        "other.rtl 400 … 1150 mm: they overlap only in part",
    ] {
        assert!(
            result.stderr.contains(warning),
            "stderr lacks {warning:?}: {}",
            result.stderr
        );
        let escaped = warning.replace('"', "&quot;");
        assert!(
            page.contains(warning) || page.contains(&escaped),
            "the report lacks {warning:?}"
        );
    }
    // Real ESS files of two X axes (both state TARGET_DU:X…): −20 … 20 mm against −4 … 4 mm.
    let html2 = dir.path().join("ess.html");
    let result = run(&[
        &"report",
        &shared_data("ecmc/ecmc_target_muts_logger/b02__x__target_x.md_ISO230.dat"),
        &"--after",
        &shared_data(
            "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__target_x_report_ILD50.md_ISO230.dat",
        ),
        &"-o",
        &html2,
    ]);
    assert_eq!(result.code, 0, "{}", result.stderr);
    assert!(
        result.stderr.contains("covers -20 … 20 mm"),
        "{}",
        result.stderr
    );
    assert!(
        std::fs::read_to_string(&html2)
            .unwrap()
            .contains("they overlap only in part"),
        "the report shows the doubt"
    );
}

#[test]
fn report_warns_when_the_files_were_written_in_different_units() {
    // Real API file in inch (0 … 3302 mm, machine "Saint Gobain WA") after the mm sample.
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("report.html");
    let inch = shared_data("api-xd/example__8055__X Axis Forward.pos");
    // The API file is dated 2016-07-19: the sample, its first test here, dated before it.
    let first = write(
        dir.path(),
        "sample-x.rtl",
        &edited(&[("Date: 2026-11-20 09:14:00", "Date: 2015-11-20 09:14:00")]),
    );
    let result = run(&[&"report", &first, &"--after", &inch, &"-o", &html]);
    assert_eq!(result.code, 0, "{}", result.stderr);
    assert!(
        result.stderr.contains("was written in mm, "),
        "{}",
        result.stderr
    );
    assert!(
        result.stderr.contains("Forward.pos in inch"),
        "{}",
        result.stderr
    );
    assert!(
        std::fs::read_to_string(&html)
            .unwrap()
            .contains("in inch: both are converted to mm")
    );
}

#[test]
fn diagnose_refuses_and_warns_as_report_does() {
    let dir = tempfile::tempdir().unwrap();
    let y = write(
        dir.path(),
        "y.rtl",
        &edited(&[("Axis: X", "Axis: Y"), RETEST]),
    );
    let result = run(&[&"diagnose", &"--after", &y, &"--before", &sample()]);
    refused(&result, "is of axis X, ");
    let result = run(&[&"diagnose", &"--after", &sample(), &"--before", &sample()]);
    refused(&result, "is given twice");
    let copy = write(dir.path(), "copy.rtl", &edited(&[]));
    let result = run(&[&"diagnose", &"--after", &copy, &"--before", &sample()]);
    refused(&result, "hold the same readings");
    let other = write(
        dir.path(),
        "other.rtl",
        &edited(&[("Machine: MCV 754 Quick", "Machine: Other mill"), RETEST]),
    );
    let result = run(&[&"diagnose", &"--after", &other, &"--before", &sample()]);
    assert_eq!(result.code, 0, "{}", result.stderr);
    assert!(
        result.stderr.contains("other.rtl \"Other mill\""),
        "{}",
        result.stderr
    );
}

/// Writes a TNC 640 table of `input` (optionally on a grid) and returns its path.
fn table(dir: &Path, input: &Path, name: &str, grid: &[&str]) -> PathBuf {
    let path = dir.join(name);
    let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![
        &"convert",
        &input,
        &"--controller",
        &"tnc640",
        &"-o",
        &path,
        &"-q",
    ];
    for flag in grid {
        args.push(flag);
    }
    let result = run(&args);
    assert_eq!(result.code, 0, "{}", result.stderr);
    path
}

#[test]
fn convert_existing_checks_the_table_against_the_test() {
    let dir = tempfile::tempdir().unwrap();
    // A table over 0 … 300 mm only, and one over 1000 … 1750 mm.
    let short = table(
        dir.path(),
        &sample(),
        "short.COM",
        &["--step", "50", "--count", "7"],
    );
    let far_test = write(dir.path(), "far.rtl", &shifted(1000.0));
    let far = table(dir.path(), &far_test, "far.COM", &[]);
    let out = dir.path().join("next.COM");
    let result = run(&[
        &"convert",
        &sample(),
        &"--controller",
        &"tnc640",
        &"--existing",
        &far,
        &"-o",
        &out,
    ]);
    refused(
        &result,
        "far.COM 1000 … 1750 mm: the ranges do not overlap, so they are not a table and a test it applies to",
    );
    assert!(!out.exists());
    let result = run(&[
        &"convert",
        &sample(),
        &"--controller",
        &"tnc640",
        &"--existing",
        &short,
        &"-o",
        &out,
        &"--json",
    ]);
    assert_eq!(result.code, 0, "{}", result.stderr);
    let warning = "short.COM 0 … 300 mm: they overlap only in part; beyond the table's points the controller holds its end values";
    assert!(result.stderr.contains(warning), "{}", result.stderr);
    let json: serde_json::Value = serde_json::from_str(&result.stdout).unwrap();
    assert!(
        json["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains(warning)),
        "the JSON has the warning too"
    );
}

#[test]
fn predict_checks_each_table_against_the_test_of_its_axis() {
    let dir = tempfile::tempdir().unwrap();
    let far_test = write(dir.path(), "far.rtl", &shifted(1000.0));
    let far = table(dir.path(), &far_test, "far.COM", &[]);
    let result = run(&[&"predict", &"--measured", &sample(), &"--table", &far]);
    refused(&result, "the ranges do not overlap");
    let short = table(
        dir.path(),
        &sample(),
        "short.COM",
        &["--step", "50", "--count", "7"],
    );
    let result = run(&[
        &"predict",
        &"--measured",
        &sample(),
        &"--table",
        &short,
        &"--json",
    ]);
    assert_eq!(result.code, 0, "{}", result.stderr);
    assert!(
        result.stderr.contains("holds its end values"),
        "{}",
        result.stderr
    );
    let json: serde_json::Value = serde_json::from_str(&result.stdout).unwrap();
    assert!(
        json["notes"]
            .as_array()
            .unwrap()
            .iter()
            .any(|n| n.as_str().unwrap().contains("holds its end values")),
        "{}",
        result.stdout
    );
}
