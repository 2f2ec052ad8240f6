//! The published `diagnose --json` keys, byte for byte, for linear and
//! rotary axes: the unit of each value is in its key (`residual_before_um`,
//! `figures_arcsec`, `unexplained.where_deg`, a periodic effect's
//! `period_deg` and `amplitude_urad`, `evidence.cv_rmse_with_arcsec`), a
//! promise to scripts. The linear golden files were written by the binary
//! before the wire structs carried their units in their types, so they show
//! that the typed structs write exactly what the run-time renaming wrote.

use std::path::Path;

use crate::util::{Run, assert_golden, axcomp, shared_data, test_data};

/// `axcomp args` run in `dir`; it must succeed.
fn run_in(dir: &Path, args: &[&str]) -> Run {
    let run = crate::parity::cli(dir, args);
    assert_eq!(run.code, 0, "axcomp {args:?}: {}", run.stderr);
    run
}

/// `output` compared with `golden/diagnose/<name>`.
fn assert_diagnose_golden(name: &str, output: &str) {
    assert_golden(output, &test_data(&format!("golden/diagnose/{name}")));
}

/// `diagnose` with `args` from the crate root, compared with `golden/diagnose/<name>`.
fn assert_diagnose(name: &str, args: &[&str]) {
    let run = axcomp(std::iter::once("diagnose").chain(args.iter().copied()));
    assert_eq!(run.code, 0, "{name}: {}", run.stderr);
    assert_diagnose_golden(name, &run.stdout);
}

/// The demo's re-test (a drift found): JSON and terminal.
#[test]
fn linear_demo_retest_keeps_its_keys() {
    let files = [
        "--after",
        "fixtures/demo/after.rtl",
        "--before",
        "fixtures/demo/before.rtl",
        "--table",
        "fixtures/demo/X.COM",
        "-q",
    ];
    let mut json = files.to_vec();
    json.push("--json");
    assert_diagnose("linear-demo.json", &json);
    assert_diagnose("linear-demo.txt", &files);
}

/// A real ecmc test (ESS, `../shared/data`) alone: an outlier run's
/// `run`, `direction` and `offset_um`.
#[test]
fn linear_outlier_run_keeps_its_keys() {
    let file = "../shared/data/ecmc/ecmccfg/examples__mcu1025_fat_sat__report.md_ISO230.dat";
    assert!(shared_data("ecmc/ecmccfg/examples__mcu1025_fat_sat__report.md_ISO230.dat").exists());
    assert_diagnose(
        "linear-ecmc-outlier-run.json",
        &["--after", file, "--json", "-q"],
    );
    assert_diagnose("linear-ecmc-outlier-run.txt", &["--after", file, "-q"]);
}

/// A 15 mm screw lead error found at the profile's lead (`parity.rs`'s
/// re-test): a periodic effect's `period_mm`, `amplitude_um`, `phase_rad`.
#[test]
fn linear_periodic_keeps_its_keys() {
    let work = tempfile::tempdir().unwrap();
    crate::parity::screw_lead_retest(work.path());
    let args = [
        "diagnose",
        "--after",
        "after.rtl",
        "--before",
        "before.rtl",
        "--table",
        "X.COM",
        "--machine",
        "vc1810.toml",
        "-q",
    ];
    let mut json = args.to_vec();
    json.push("--json");
    assert_diagnose_golden("linear-periodic.json", &run_in(work.path(), &json).stdout);
    assert_diagnose_golden("linear-periodic.txt", &run_in(work.path(), &args).stdout);
}

/// A rotary re-test with a second-order term the first test did not have
/// (`rotary.rs`'s seed 21): in ″, in µrad, and the terminal.
#[test]
fn rotary_retest_keeps_its_keys() {
    let work = tempfile::tempdir().unwrap();
    crate::retest_case::rotary_retest_files(work.path(), (2, 3.0, 0.3), 21);
    let args = [
        "diagnose",
        "--after",
        "after-21.csv",
        "--before",
        "before-21.csv",
        "--table",
        "C-21.comp",
        "-q",
    ];
    let with = |extra: &[&'static str]| {
        let mut all = args.to_vec();
        all.extend(extra);
        run_in(work.path(), &all).stdout
    };
    assert_diagnose_golden("rotary-retest.json", &with(&["--json"]));
    assert_diagnose_golden(
        "rotary-retest-urad.json",
        &with(&["--json", "--angle-unit", "urad"]),
    );
    assert_diagnose_golden("rotary-retest.txt", &with(&[]));
}

/// A rotary test alone with a reversal: `B_arcsec`.
#[test]
fn rotary_reversal_keeps_its_keys() {
    let file = "tests/data/rotary/c-outlier-run.csv";
    assert_diagnose("rotary-reversal.json", &["--after", file, "--json", "-q"]);
    assert_diagnose("rotary-reversal.txt", &["--after", file, "-q"]);
}

/// The keys of the objects at `indent` spaces in pretty-printed JSON, in
/// the order written (serde_json's `Value` keeps them sorted, so they are
/// read from the text).
fn keys_at(text: &str, indent: usize) -> Vec<&str> {
    let prefix = format!("{}\"", " ".repeat(indent));
    text.lines()
        .filter_map(|line| line.strip_prefix(prefix.as_str()))
        .filter_map(|rest| rest.split_once("\":").map(|(key, _)| key))
        .collect()
}

/// The text from the first `from` to the next `to` after it.
fn block<'a>(text: &'a str, from: &str, to: &str) -> &'a str {
    let start = text.find(from).unwrap();
    &text[start..start + text[start..].find(to).unwrap()]
}

/// A rotary axis' `diagnose --json` writes its keys in the order a linear
/// axis' does, with `axis_kind` after the files (they were sorted by name,
/// a side effect of renaming them at run time): the same object, the
/// evidence and the figures in the standard's order (`A`, `A_up`, …).
#[test]
fn rotary_keys_are_in_the_linear_order() {
    let linear =
        std::fs::read_to_string(test_data("golden/diagnose/linear-periodic.json")).unwrap();
    for (name, unit) in [
        ("rotary-retest.json", "arcsec"),
        ("rotary-retest-urad.json", "urad"),
    ] {
        let rotary =
            std::fs::read_to_string(test_data(&format!("golden/diagnose/{name}"))).unwrap();
        let in_rotary_units = |keys: Vec<&str>| -> Vec<String> {
            keys.into_iter()
                .map(|key| {
                    key.replace("_um", &format!("_{unit}"))
                        .replace("_mm", "_deg")
                })
                .collect()
        };
        let mut expected = in_rotary_units(keys_at(&linear, 2));
        expected.insert(3, "axis_kind".to_string());
        assert_eq!(keys_at(&rotary, 2), expected, "{name}");
        // The effect's keys and its evidence's (the one periodic effect of each).
        assert_eq!(
            keys_at(block(&rotary, "\"effects\"", "\"rejected\""), 6),
            keys_at(block(&linear, "\"effects\"", "\"rejected\""), 6),
            "{name}"
        );
        assert_eq!(
            keys_at(block(&rotary, "\"evidence\"", "}"), 8),
            in_rotary_units(keys_at(block(&linear, "\"evidence\"", "}"), 8)),
            "{name}"
        );
        assert!(
            rotary.contains("\"measured\": {\n      \"A\": "),
            "{name}: {rotary}"
        );
    }
}
