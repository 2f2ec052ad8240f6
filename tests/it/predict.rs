//! `axcomp predict` end to end: the bundled sample, a TNC 640 table written
//! by `convert`, and an error description with a pitch.

use axcomp::compensate::retest::{Applied, KnownError, predicted_deviation};
use axcomp::emit::{self, Controller};
use axcomp::evaluate::evaluate;
use axcomp::measurement::Direction;
use axcomp::read::read_path;
use serde_json::Value;

use crate::util::{axcomp, root};

fn sample() -> std::path::PathBuf {
    root().join("fixtures/sample-x.rtl")
}

/// A TNC 640 table of the sample at its targets, written by the binary.
fn table(dir: &std::path::Path) -> std::path::PathBuf {
    table_in_mode(dir, "mean")
}

/// The same in `mode` (mean or bidirectional).
fn table_in_mode(dir: &std::path::Path, mode: &str) -> std::path::PathBuf {
    let path = dir.join(format!("X-{mode}.COM"));
    let run = axcomp([
        "convert".as_ref(),
        sample().as_os_str(),
        "--controller".as_ref(),
        "tnc640".as_ref(),
        "--mode".as_ref(),
        mode.as_ref(),
        "-o".as_ref(),
        path.as_os_str(),
        "-q".as_ref(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    path
}

/// `predict --measured sample --table TABLE [extra…] --json`.
fn predict_json(table: &std::path::Path, extra: &[&str]) -> Value {
    let mut args: Vec<std::ffi::OsString> = vec![
        "predict".into(),
        "--measured".into(),
        sample().into(),
        "--table".into(),
        table.into(),
        "--json".into(),
    ];
    args.extend(extra.iter().map(Into::into));
    let run = axcomp(args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    serde_json::from_str(&run.stdout).unwrap()
}

#[test]
fn the_predicted_retest_is_the_table_applied_to_the_measurement() {
    let dir = tempfile::tempdir().unwrap();
    let table_path = table(dir.path());
    let run = axcomp([
        "predict".as_ref(),
        "--measured".as_ref(),
        sample().as_os_str(),
        "--table".as_ref(),
        table_path.as_os_str(),
        "--json".as_ref(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["axis"], "X");
    assert_eq!(json["with_measured_scatter"], true);

    // The same by hand from the library: the table as the TNC 640 file reads
    // back (its 4 decimals), applied to the first test's spline.
    let measurement = read_path(&sample(), None).unwrap().measurement;
    let evaluation = evaluate(&measurement);
    let known = KnownError::from_evaluation(&evaluation).unwrap();
    let text = std::fs::read_to_string(&table_path).unwrap();
    let options = emit::EmitOptions::for_axis(&emit::MachineProfile::default(), "X", "").unwrap();
    let (controller, active) = emit::read_any(&text, &options, None).unwrap();
    assert_eq!(controller, Controller::Tnc640);
    let per_target = json["per_target"].as_array().unwrap();
    assert_eq!(per_target.len(), measurement.targets().len());
    for (row, &x) in per_target.iter().zip(measurement.targets()) {
        assert_eq!(row["target_mm"].as_f64().unwrap(), x);
        for (key, direction) in [
            ("predicted_up_um", Direction::Up),
            ("predicted_down_um", Direction::Down),
        ] {
            let expected =
                predicted_deviation(&known, Applied::table(&active), x, direction) * 1000.0;
            let value = row[key].as_f64().unwrap();
            assert!(
                (value - expected).abs() < 1e-6,
                "{x} {key}: {value} vs {expected}"
            );
        }
    }
    // The re-test keeps the sample's repeatability per direction; the mean table takes M
    // from 8.06 µm to what the 4-decimal table and the spline leave (< 0.2 µm).
    let figures = &json["predicted_figures_um"];
    let r_up = evaluation.figures.r_up.unwrap() * 1000.0;
    assert!((figures["R_up"].as_f64().unwrap() - r_up).abs() < 1e-9);
    assert!(figures["M"].as_f64().unwrap() < 0.2, "{}", figures["M"]);
    // Without the table the line reads the measurement itself (evaluate's figures:
    // E 11.21, B 3.44, B̄ −3.18 µm in README), reversal included.
    let before = &json["figures_before_um"];
    for (key, measured) in [
        ("A", evaluation.figures.a),
        ("E", evaluation.figures.e),
        ("M", evaluation.figures.m),
        ("B", evaluation.figures.b),
        ("B_mean", evaluation.figures.b_mean),
    ] {
        let measured = measured.unwrap() * 1000.0;
        assert!(
            (before[key].as_f64().unwrap() - measured).abs() < 1e-6,
            "{key}: {} vs {measured}",
            before[key]
        );
    }
    assert!((before["E"].as_f64().unwrap() - 11.21).abs() < 0.005);
    // A mean table leaves the measured reversal: B within 0.3 µm of the measured 3.44 µm.
    let b = figures["B"].as_f64().unwrap();
    assert!((b - 3.44).abs() < 0.3, "{b}");
    assert_eq!(json["table_mode"], "mean");
    assert!((json["measured_B_mean_um"].as_f64().unwrap() + 3.18).abs() < 0.005);
    assert_eq!(json["backlash_set"], false);
    // Volumetric: only EXX is known, so the maximum is on X; the table brings it down,
    // but each direction keeps half the reversal a mean table leaves (|B̄|/2 = 1.59 µm).
    let before = json["volumetric_max_before_um"].as_f64().unwrap();
    let after = json["volumetric_max_um"].as_f64().unwrap();
    assert!(after < before / 4.0, "{after} vs {before}");
    assert!(after >= 3.18 / 2.0, "{after}");
    assert_eq!(json["grid_points"], 16 * 11 * 12);
    // The sample's reversal is carried, and the note says a mean table leaves it.
    let notes = json["notes"].as_array().unwrap();
    assert!(
        notes.iter().any(|n| {
            let n = n.as_str().unwrap();
            n.contains("B̄ = -3.18 µm") && n.contains("a mean table leaves it")
        }),
        "{notes:?}"
    );
}

#[test]
fn a_bidirectional_table_or_the_backlash_parameter_takes_the_measured_reversal_out() {
    let dir = tempfile::tempdir().unwrap();
    // The sample's B is 3.44 µm, B̄ −3.18 µm (README).
    let mean = table_in_mode(dir.path(), "mean");
    let bidirectional = table_in_mode(dir.path(), "bidirectional");
    let b_of = |json: &Value| json["predicted_figures_um"]["B"].as_f64().unwrap();
    let b_mean_of = |json: &Value| json["predicted_figures_um"]["B_mean"].as_f64().unwrap();

    let with_bidirectional = predict_json(&bidirectional, &[]);
    assert!(
        b_of(&with_bidirectional) <= 0.3,
        "{}",
        b_of(&with_bidirectional)
    );
    assert_eq!(with_bidirectional["table_mode"], "bidirectional");
    // So a bidirectional table is predicted better than a mean one, never worse.
    let with_mean = predict_json(&mean, &[]);
    assert!(
        with_bidirectional["predicted_figures_um"]["A"]
            .as_f64()
            .unwrap()
            < with_mean["predicted_figures_um"]["A"].as_f64().unwrap()
    );

    // The backlash parameter (set as convert suggests, −B̄) takes B̄ out; B_i − B̄ stays
    // (the sample's B_i range from −3.35 to −2.89 µm about −3.18: |B| well under 1 µm).
    let with_backlash = predict_json(&mean, &["--backlash-set"]);
    assert_eq!(with_backlash["backlash_set"], true);
    assert!(
        b_mean_of(&with_backlash).abs() < 0.05,
        "{}",
        b_mean_of(&with_backlash)
    );
    assert!(b_of(&with_backlash) < 1.0, "{}", b_of(&with_backlash));

    // Both at once would take the reversal out twice: refused.
    let run = axcomp([
        "predict".as_ref(),
        "--measured".as_ref(),
        sample().as_os_str(),
        "--table".as_ref(),
        bidirectional.as_os_str(),
        "--backlash-set".as_ref(),
    ]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr.contains("must be 0 with a bidirectional table"),
        "{}",
        run.stderr
    );
}

#[test]
fn a_pitch_moves_the_reading_on_a_lower_line() {
    // EBX rising to 20 µrad at 750 mm: 500 mm lower the reading changes by
    // −500 mm × EBX(x), −10 µm at the end of the stroke (see src/predict/tests.rs).
    let dir = tempfile::tempdir().unwrap();
    let table_path = table(dir.path());
    let errors = dir.path().join("errors.toml");
    std::fs::write(
        &errors,
        "[EBX]\npositions_mm = [0.0, 750.0]\nvalues_urad = [0.0, 20.0]\n",
    )
    .unwrap();
    let measured = format!("{}@y=0,z=0", sample().display());
    let predict_on = |line: &str| -> Value {
        let run = axcomp([
            "predict",
            "--errors",
            errors.to_str().unwrap(),
            "--measured",
            &measured,
            "--table",
            &format!("X={}", table_path.display()),
            "--line",
            line,
            "--json",
        ]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        serde_json::from_str(&run.stdout).unwrap()
    };
    let same = predict_on("y=0,z=0");
    let lower = predict_on("y=0,z=-500");
    let last = |v: &Value| {
        v["per_target"].as_array().unwrap().last().unwrap()["before_up_um"]
            .as_f64()
            .unwrap()
    };
    assert!(
        (last(&lower) - last(&same) + 10.0).abs() < 1e-6,
        "{} {}",
        last(&lower),
        last(&same)
    );
    assert_eq!(lower["line_mm"]["z"], -500.0);
}

#[test]
fn bad_inputs_exit_2_with_the_place() {
    let dir = tempfile::tempdir().unwrap();
    let table_path = table(dir.path());
    let errors = dir.path().join("errors.toml");
    std::fs::write(&errors, "[EBX]\nvalue_urad = \"steep\"\n").unwrap();
    let run = axcomp([
        "predict".as_ref(),
        "--errors".as_ref(),
        errors.as_os_str(),
        "--measured".as_ref(),
        sample().as_os_str(),
        "--table".as_ref(),
        table_path.as_os_str(),
    ]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.contains("errors.toml:2:14"), "{}", run.stderr);

    // Two measured axes: the table must say which it is for.
    let run = axcomp([
        "predict".as_ref(),
        "--measured".as_ref(),
        sample().as_os_str(),
        "--measured".as_ref(),
        sample().as_os_str(),
        "--table".as_ref(),
        table_path.as_os_str(),
    ]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.contains("say which axis"), "{}", run.stderr);

    // The same axis measured twice.
    let run = axcomp([
        "predict".as_ref(),
        "--measured".as_ref(),
        sample().as_os_str(),
        "--measured".as_ref(),
        sample().as_os_str(),
        "--table".as_ref(),
        format!("X={}", table_path.display()).as_ref(),
    ]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.contains("EXX is given twice"), "{}", run.stderr);

    let run = axcomp(["predict", "--table", "X=nope.COM", "--line", "q=3"]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.contains("x, y or z"), "{}", run.stderr);
}
