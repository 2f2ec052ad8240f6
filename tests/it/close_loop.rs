//! Issue 6 end to end through the binary: a reversal that appears after the
//! first test (so no model fed by it can declare it), a table, the re-test,
//! the diagnosis with its JSON and effects file, and the next table and
//! prediction accounting for it.

use serde_json::Value;

use crate::util::axcomp;

const TRUTH: &str = "\
[axis]\nname = \"X\"\n\n\
[cycle]\nstart_mm = 0.0\nend_mm = 750.0\ncount = 21\njitter_mm = 6.0\nruns = 5\nstart = \"2026-11-20 09:00:00\"\n\n\
[error]\nscale_um_per_m = 9.5\nperiodic = [{ period_mm = 300.0, amplitude_um = 2.0, phase_rad = 0.4 }]\n\n\
[noise]\nsigma_um = 0.25\n\n\
[[effect]]\nkind = \"reversal\"\nB_um = -3.0\ntests = [\"after\"]\n";

fn run_ok(args: &[&str]) -> String {
    let run = axcomp(args);
    assert_eq!(run.code, 0, "axcomp {}: {}", args.join(" "), run.stderr);
    run.stdout
}

#[test]
fn diagnose_finds_the_reversal_and_the_next_table_and_prediction_use_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    std::fs::write(path("truth.toml"), TRUTH).unwrap();
    crate::util::synth_loop_files(dir.path(), &dir.path().join("truth.toml"), None);
    // The same seed writes the same first test.
    assert_eq!(
        std::fs::read(path("before.rtl")).unwrap(),
        std::fs::read(path("before2.rtl")).unwrap()
    );

    let stdout = run_ok(&[
        "diagnose",
        "--after",
        &path("after.rtl"),
        "--before",
        &path("before.rtl"),
        "--table",
        &path("X.COM"),
        "--json",
        "--write-effects",
        &path("effects.toml"),
    ]);
    let json: Value = serde_json::from_str(&stdout).unwrap();
    // The keys of the issue, with units.
    for key in [
        "residual_before_um",
        "effects",
        "rejected",
        "residual_after_um",
        "figures_um",
        "unexplained",
    ] {
        assert!(json.get(key).is_some(), "{key} missing: {stdout}");
    }
    let effects = json["effects"].as_array().unwrap();
    assert_eq!(effects.len(), 1, "{stdout}");
    assert_eq!(effects[0]["kind"], "reversal");
    let b = effects[0]["params"]["B_um"].as_f64().unwrap();
    assert!((b + 3.0).abs() < 0.3, "{b}");
    assert!(effects[0]["uncertainty"]["B_um"].as_f64().unwrap() < 0.1);
    assert!(
        effects[0]["explanation"]
            .as_str()
            .unwrap()
            .contains("bidirectional")
    );
    let before_rms = json["residual_before_um"]["rms"].as_f64().unwrap();
    let after_rms = json["residual_after_um"]["rms"].as_f64().unwrap();
    assert!(after_rms < before_rms / 3.0, "{after_rms} vs {before_rms}");
    assert_eq!(json["unexplained"]["significant"], false);
    // Measured B ≈ 3 µm, the prediction none, the prediction with the effect the measured.
    let figures = &json["figures_um"];
    let measured_b = figures["measured"]["B"].as_f64().unwrap();
    assert!(figures["predicted"]["B"].as_f64().unwrap() < 1.0);
    assert!((figures["predicted_with_effects"]["B"].as_f64().unwrap() - measured_b).abs() < 0.5);

    // The readable report says the same.
    let text = run_ok(&[
        "diagnose",
        "--after",
        &path("after.rtl"),
        "--before",
        &path("before.rtl"),
        "--table",
        &path("X.COM"),
    ]);
    assert!(
        text.contains("reversal") && text.contains("The reversal changed since the first test"),
        "{text}"
    );

    // The effects file: the next table is bidirectional …
    let effects_file = std::fs::read_to_string(path("effects.toml")).unwrap();
    assert!(
        effects_file.contains("kind = \"reversal\""),
        "{effects_file}"
    );
    let convert: Value = serde_json::from_str(&run_ok(&[
        "convert",
        &path("after.rtl"),
        "--existing",
        &path("X.COM"),
        "--controller",
        "tnc640",
        "--effects",
        &path("effects.toml"),
        "-o",
        &path("X2.COM"),
        "--json",
    ]))
    .unwrap();
    assert_eq!(convert["mode"], "bidirectional");
    assert!(
        convert["effects"][0]
            .as_str()
            .unwrap()
            .starts_with("reversal")
    );
    // … and the prediction with it has the reversal the re-test showed.
    let predict: Value = serde_json::from_str(&run_ok(&[
        "predict",
        "--measured",
        &path("before.rtl"),
        "--table",
        &path("X.COM"),
        "--effects",
        &path("effects.toml"),
        "--json",
    ]))
    .unwrap();
    // It is the first test's reversal (carried; ≈ 0 here) plus the change found,
    // to the 4 decimals the effects file keeps and the table's second-order shift.
    let predicted_b = predict["predicted_figures_um"]["B_mean"].as_f64().unwrap();
    let carried_b = predict["measured_B_mean_um"].as_f64().unwrap();
    assert!(carried_b.abs() < 0.3, "{carried_b}");
    assert!(
        (predicted_b - (carried_b + b)).abs() < 1e-3,
        "{predicted_b} vs {carried_b} + {b}"
    );
    // An effects file written elsewhere must not overwrite without --force.
    let again = axcomp([
        "diagnose",
        "--after",
        &path("after.rtl"),
        "--before",
        &path("before.rtl"),
        "--table",
        &path("X.COM"),
        "--write-effects",
        &path("effects.toml"),
    ]);
    assert_eq!(again.code, 2);
    assert!(again.stderr.contains("--force"), "{}", again.stderr);
}
