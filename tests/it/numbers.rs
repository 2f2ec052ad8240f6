//! The numbers the engineer reads come from what was given, never from a
//! silent default: `predict` refuses a model that does not cover the test
//! and its headline and plot keep each direction; `diagnose` says only
//! numbers its own output measures (or why one differs), gives a drift per
//! run when the file records no times, and prints the tests' warnings; tests
//! that do not belong together (another stretch, swapped dates) are refused.
//!
//! Inputs: the real API and MUTS files in `../shared/data`, the demo's
//! `fixtures/demo` (first test 08:30, re-test 10:00, X 0 … 750 mm, a mean
//! table `X.COM`).

use std::path::{Path, PathBuf};

use axcomp::measurement::{Direction, Measurement};
use axcomp::read::read_path;
use serde_json::Value;

use crate::util::{axcomp, root, shared_data};

const API_X: &str = "api-xd/example__8055__X Axis Forward.pos";
const MUTS: &str = "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__";
const B02_X: &str = "ecmc/ecmc_target_muts_logger/b02__x__target_x.md_ISO230.dat";

fn muts(name: &str) -> PathBuf {
    shared_data(&format!("{MUTS}{name}.md_ISO230.dat"))
}

fn demo(name: &str) -> PathBuf {
    root().join("fixtures/demo").join(name)
}

fn text(path: &Path) -> String {
    path.display().to_string()
}

/// B̄ = mean over targets of (x̄_i↑ − x̄_i↓), µm, from the readings (ISO
/// 230-2 §3.2.8's mean reversal value, by hand).
pub(crate) fn mean_reversal_um(m: &Measurement) -> f64 {
    let mean = |i: usize, direction: Direction| {
        let values: Vec<f64> = m
            .runs()
            .iter()
            .filter(|r| r.direction == direction)
            .filter_map(|r| r.deviations[i])
            .collect();
        values.iter().sum::<f64>() / values.len() as f64
    };
    let n = m.targets().len();
    let sum: f64 = (0..n)
        .map(|i| mean(i, Direction::Up) - mean(i, Direction::Down))
        .sum();
    1000.0 * sum / n as f64
}

/// The numbers written in a sentence, as written (`-8.63`, `0.0086`, `1`).
fn numbers_in(sentence: &str) -> Vec<String> {
    let chars: Vec<char> = sentence.chars().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts_number = chars[i].is_ascii_digit()
            || (chars[i] == '-' && chars.get(i + 1).is_some_and(char::is_ascii_digit));
        // A digit inside a word (B̄ has none; "ISO230") is not a number.
        let inside_word = i > 0 && chars[i - 1].is_alphabetic();
        if starts_number && !inside_word {
            let mut j = i + 1;
            while j < chars.len()
                && (chars[j].is_ascii_digit()
                    || (chars[j] == '.' && chars.get(j + 1).is_some_and(char::is_ascii_digit)))
            {
                j += 1;
            }
            found.push(chars[i..j].iter().collect());
            i = j;
        } else {
            i += 1;
        }
    }
    found
}

fn two(v: f64) -> String {
    format!("{v:.2}")
}

/// Finding 9: on the MUTS pair every number of the explanations is one the
/// same output measures (a figure, an effect's parameter, their difference,
/// the backlash change −B̄ in mm) and the reversal's sentence says the
/// figures' B̄; the drift is per run, the file recording no times; the
/// tests' own warnings are printed.
#[test]
fn diagnose_on_the_muts_pair_says_only_numbers_it_measures() {
    let before = muts("back__target_x_report");
    let after = muts("back__target_x_report_2");
    let args = [
        "diagnose".to_string(),
        "--before".into(),
        text(&before),
        "--after".into(),
        text(&after),
    ];
    let run = axcomp(args.iter().chain(&["--json".to_string()]));
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).unwrap();
    let figures = &json["figures_um"];
    let figure = |set: &str, key: &str| figures[set][key].as_f64().unwrap();

    // The measured B̄ is the file's, by hand: −8.63 µm now, −39.54 µm in the first test.
    let after_b = mean_reversal_um(&read_path(&after, None).unwrap().measurement);
    let before_b = mean_reversal_um(&read_path(&before, None).unwrap().measurement);
    assert!((figure("measured", "B_mean") - after_b).abs() < 1e-9);
    assert!((figure("predicted", "B_mean") - before_b).abs() < 1e-9);
    assert_eq!(two(after_b), "-8.63");
    assert_eq!(two(before_b), "-39.54");

    let effects = json["effects"].as_array().unwrap();
    let effect = |kind: &str| {
        effects
            .iter()
            .find(|e| e["kind"] == kind)
            .unwrap_or_else(|| panic!("no {kind} in {effects:?}"))
    };
    // The reversal: the figures' B̄ then and now, their difference, and the
    // backlash change −B̄ now in mm; the fitted B said with why it differs.
    let reversal = effect("reversal");
    let explanation = reversal["explanation"].as_str().unwrap();
    let b_fit = reversal["params"]["B_um"].as_f64().unwrap();
    for part in [
        format!(
            "B̄ {} µm predicted, {} µm measured now",
            two(before_b),
            two(after_b)
        ),
        format!("a change of {} µm", two(after_b - before_b)),
        format!(
            "change the backlash parameter by {:.4} mm (−B̄ now",
            -after_b / 1000.0
        ),
        format!("The fit's B = {} µm differs from that change", two(b_fit)),
        "taken out, which the measured B̄ includes".to_string(),
    ] {
        assert!(explanation.contains(&part), "{part:?} not in {explanation}");
    }
    assert!(!explanation.contains("16.87"), "{explanation}");
    // The drift: per run, not per hour (the ecmc file records no times).
    let drift = effect("drift");
    assert!(drift["params"]["rate_um_per_run"].is_f64(), "{drift}");
    assert!(drift["params"].get("rate_um_per_h").is_none(), "{drift}");
    assert!(
        drift["explanation"].as_str().unwrap().contains(
            "µm per run during the test (per run, not per hour: the file records no times)"
        ),
        "{drift}"
    );

    // Every number of every explanation is one of the output's own.
    let mut allowed: Vec<String> = Vec::new();
    for set in ["measured", "predicted", "predicted_with_effects"] {
        for value in figures[set].as_object().unwrap().values() {
            allowed.extend(value.as_f64().map(two));
        }
    }
    allowed.push(two(after_b - before_b));
    allowed.push(format!("{:.4}", -after_b / 1000.0));
    for e in effects {
        for (_, value) in e["params"].as_object().unwrap() {
            if let Some(v) = value.as_u64() {
                allowed.push(v.to_string());
            } else if let Some(v) = value.as_f64() {
                allowed.push(two(v));
            }
        }
    }
    for e in effects {
        let sentence = e["explanation"].as_str().unwrap();
        for number in numbers_in(sentence) {
            assert!(
                allowed.contains(&number),
                "{number} in {sentence:?} is no number of the output ({allowed:?})"
            );
        }
    }

    // The terminal says the same, with no rate per hour anywhere.
    let terminal = axcomp(&args);
    assert_eq!(terminal.code, 0, "{}", terminal.stderr);
    assert!(!terminal.stdout.contains("µm/h"), "{}", terminal.stdout);
    assert!(terminal.stdout.contains("rate_um_per_run"));
    // Each test's warnings as evaluate gives them, naming its file.
    for file in [&before, &after] {
        assert!(
            terminal
                .stderr
                .contains(&format!("{}: targets evenly spaced every 2 mm", text(file))),
            "{}",
            terminal.stderr
        );
    }
}

/// Finding 12: a ±20 mm ecmc test as the first test of the demo's
/// 0 … 750 mm re-test shares 0 … 20 mm, 20/750 = 2.7 % of the re-test: refused
/// by diagnose and report, exit 2, nothing written.
#[test]
fn a_retest_of_another_stretch_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("report.html");
    let first = shared_data(B02_X);
    let retest = demo("after.rtl");
    let reason = "after.rtl 0 … 750 mm: only 3 % of the re-test lies where the first test measured";
    let diagnose = axcomp([
        "diagnose",
        "--before",
        &text(&first),
        "--after",
        &text(&retest),
    ]);
    assert_eq!(diagnose.code, 2, "{}", diagnose.stdout);
    assert!(diagnose.stderr.contains(reason), "{}", diagnose.stderr);
    let report = axcomp([
        "report",
        &text(&first),
        "--after",
        &text(&retest),
        "-o",
        &text(&html),
    ]);
    assert_eq!(report.code, 2, "{}", report.stdout);
    assert!(report.stderr.contains(reason), "{}", report.stderr);
    assert!(!html.exists());
}

/// Finding 12: the demo's first test is dated 2026-11-20 08:30, its re-test
/// 10:00 (their `Date:` lines); given the other way round they are refused.
#[test]
fn tests_given_against_their_recorded_dates_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("report.html");
    let (before, after) = (demo("before.rtl"), demo("after.rtl"));
    let reason = "after.rtl was measured on 2026-11-20 10:00:00, ";
    let swapped = axcomp([
        "diagnose",
        "--before",
        &text(&after),
        "--after",
        &text(&before),
    ]);
    assert_eq!(swapped.code, 2, "{}", swapped.stdout);
    assert!(swapped.stderr.contains(reason), "{}", swapped.stderr);
    assert!(
        swapped
            .stderr
            .contains("before.rtl on 2026-11-20 08:30:00: the first test is the later one"),
        "{}",
        swapped.stderr
    );
    let report = axcomp([
        "report",
        &text(&after),
        "--after",
        &text(&before),
        "-o",
        &text(&html),
    ]);
    assert_eq!(report.code, 2, "{}", report.stdout);
    assert!(report.stderr.contains(reason), "{}", report.stderr);
    // In their order they pass.
    let ordered = axcomp([
        "diagnose",
        "--before",
        &text(&before),
        "--after",
        &text(&after),
    ]);
    assert_eq!(ordered.code, 0, "{}", ordered.stderr);
}

/// Finding 7: the API X test covers 0 … 3302 mm (130 in, 26 targets every
/// 5 in); the bundled MCV 754 Quick strokes X over 0 … 750 mm. predict
/// refuses and asks for --machine; with a model whose X stroke covers the
/// test it predicts.
#[test]
fn predict_refuses_a_model_that_does_not_cover_the_test() {
    let dir = tempfile::tempdir().unwrap();
    let api = shared_data(API_X);
    let table = dir.path().join("X.COM");
    let convert = axcomp([
        "convert",
        &text(&api),
        "--controller",
        "tnc640",
        "-o",
        &text(&table),
    ]);
    assert_eq!(convert.code, 0, "{}", convert.stderr);
    let args = |machine: Option<&Path>| {
        let mut args = vec![
            "predict".to_string(),
            "--measured".into(),
            text(&api),
            "--table".into(),
            text(&table),
        ];
        if let Some(machine) = machine {
            args.extend(["--machine".to_string(), text(machine)]);
        }
        args
    };
    let refused = axcomp(args(None));
    assert_eq!(refused.code, 2, "{}", refused.stdout);
    assert!(
        refused.stderr.contains(
            "the test of X covers 0 … 3302 mm, beyond the X stroke 0 … 750 mm of the machine model (MCV 754 Quick)"
        ),
        "{}",
        refused.stderr
    );
    assert!(refused.stderr.contains("--machine"), "{}", refused.stderr);
    // The same machine with a 0 … 3400 mm X stroke covers it.
    let bundled =
        std::fs::read_to_string(root().join("fixtures/machines/mcv754-quick.toml")).unwrap();
    let long = bundled.replacen("stroke_mm = [0.0, 750.0]", "stroke_mm = [0.0, 3400.0]", 1);
    assert_ne!(long, bundled, "the X stroke is the first stroke_mm line");
    let machine = dir.path().join("long.toml");
    std::fs::write(&machine, long).unwrap();
    let covered = axcomp(args(Some(&machine)));
    assert_eq!(covered.code, 0, "{}", covered.stderr);
}

/// Finding 8: with the demo's mean table each direction keeps half the
/// reversal the first test measured (B̄ by hand from the file, −3.23 µm):
/// the volumetric headline is at least |B̄|/2 and says so; the backlash
/// parameter takes it out. Before, the headline was 0.15 µm.
#[test]
fn the_volumetric_headline_keeps_what_each_direction_keeps() {
    let before = demo("before.rtl");
    let b_um = mean_reversal_um(&read_path(&before, None).unwrap().measurement);
    assert_eq!(two(b_um), "-3.23");
    let predict = |extra: &[&str]| {
        let mut args = vec![
            "predict".to_string(),
            "--measured".into(),
            text(&before),
            "--table".into(),
            text(&demo("X.COM")),
        ];
        args.extend(extra.iter().map(ToString::to_string));
        let run = axcomp(args);
        assert_eq!(run.code, 0, "{}", run.stderr);
        run.stdout
    };
    let json: Value = serde_json::from_str(&predict(&["--json"])).unwrap();
    assert_eq!(json["table_mode"], "mean");
    let after = json["volumetric_max_um"].as_f64().unwrap();
    assert!(after >= b_um.abs() / 2.0, "{after} µm < |B̄|/2");
    let terminal = predict(&[]);
    assert!(
        terminal.contains("(the worse of ↑ and ↓: each direction keeps what the tables leave of the reversal the first test measured, X B̄ = -3.23 µm)"),
        "{terminal}"
    );
    // The backlash parameter takes the mean reversal out of both directions.
    let set: Value = serde_json::from_str(&predict(&["--json", "--backlash-set"])).unwrap();
    let with_backlash = set["volumetric_max_um"].as_f64().unwrap();
    assert!(with_backlash < after / 5.0, "{with_backlash} vs {after}");
}

/// Finding 8: the report's predicted re-test with a mean table draws both
/// directions (they differ by the reversal the table leaves).
#[test]
fn the_report_plots_both_predicted_directions() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("report.html");
    let run = axcomp([
        "report",
        &text(&demo("before.rtl")),
        "--table",
        &text(&demo("X.COM")),
        "-o",
        &text(&html),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let page = std::fs::read_to_string(&html).unwrap();
    for legend in ["predicted re-test ↑", "predicted re-test ↓"] {
        assert!(page.contains(legend), "the report lacks {legend:?}");
    }
}
