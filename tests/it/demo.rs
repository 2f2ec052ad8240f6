//! `axcomp demo` (issue 7): every file it promises, numbers equal to those of
//! `evaluate --json` and `diagnose --json` on the same files (the `system`
//! target opens its report in Chromium), and bundled data that is exactly what its truth gives.

use std::path::Path;

use serde_json::Value;

use crate::pixels::Pixels;
use crate::util::{axcomp, root};

const PROMISED: [&str; 20] = [
    "truth.toml",
    "before.rtl",
    "after.rtl",
    "evaluate.json",
    "tables/itnc530/X.COM",
    "tables/tnc640/X.COM",
    "tables/sinumerik840d/X.MPF",
    "tables/linuxcnc/x.comp",
    "tables/next/X.COM",
    "predict.json",
    "diagnose.json",
    "effects.toml",
    "report.html",
    "png/deviation-before.png",
    "png/deviation-after.png",
    "png/table.png",
    "png/predicted.png",
    "png/residual.png",
    "png/residual-along-axis.png",
    "png/effects.png",
];

fn json_file(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn json_run(args: &[&str]) -> Value {
    let run = axcomp(args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    serde_json::from_str(&run.stdout).unwrap()
}

#[test]
fn the_demo_writes_what_it_promises_with_the_numbers_of_evaluate_and_diagnose() {
    let directory = tempfile::tempdir().unwrap();
    let out = directory.path().join("demo");
    let run = axcomp(["demo", "--out", out.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert_eq!(
        run.stdout.lines().count(),
        10,
        "a ten-line summary:\n{}",
        run.stdout
    );
    assert!(run.stdout.contains("report.html"), "{}", run.stdout);
    for name in PROMISED {
        assert!(out.join(name).is_file(), "{name} missing");
    }
    let file = |name: &str| out.join(name).to_str().unwrap().to_string();

    // The first test: the same numbers as `evaluate --json` on the written file.
    let evaluate = json_run(&["evaluate", &file("before.rtl"), "--json"]);
    let demo = json_file(&out.join("evaluate.json"));
    for key in [
        "figures_um",
        "per_target",
        "runs",
        "environment",
        "outliers",
    ] {
        assert_eq!(demo[key], evaluate[key], "{key}");
    }

    // The diagnosis: the same as `diagnose --json` with the TNC 640 table.
    let diagnose = json_run(&[
        "diagnose",
        "--after",
        &file("after.rtl"),
        "--before",
        &file("before.rtl"),
        "--table",
        &file("tables/tnc640/X.COM"),
        "--json",
    ]);
    let demo = json_file(&out.join("diagnose.json"));
    for key in [
        "residual_before_um",
        "effects",
        "rejected",
        "residual_after_um",
        "figures_um",
        "unexplained",
    ] {
        assert_eq!(demo[key], diagnose[key], "{key}");
    }
    // It finds what the truth put in after the first test (the drift, 4 µm/h) and
    // not the reversal both tests measured, which the prediction carries.
    let kinds: Vec<&str> = demo["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["drift"]);
    let rate = demo["effects"][0]["params"]["rate_um_per_h"]
        .as_f64()
        .unwrap();
    assert!((rate - 4.0).abs() < 0.4, "{rate}");
    let reversal = demo["rejected"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["kind"] == "reversal")
        .expect("reversal looked for");
    assert!(
        reversal["why"]
            .as_str()
            .unwrap()
            .starts_with("no change since the first test, whose B̄ = -3.23 µm"),
        "{reversal}"
    );
    let predicted_a = demo["figures_um"]["predicted"]["A"].clone();
    // The prediction: the same as `predict --json` with that table.
    let predict = json_run(&[
        "predict",
        "--measured",
        &file("before.rtl"),
        "--table",
        &file("tables/tnc640/X.COM"),
        "--json",
    ]);
    let demo = json_file(&out.join("predict.json"));
    for key in ["predicted_figures_um", "per_target", "volumetric_max_um"] {
        assert_eq!(demo[key], predict[key], "{key}");
    }
    // One predicted A for the one re-test: predict's, diagnose's and the report's.
    assert_eq!(demo["predicted_figures_um"]["A"], predicted_a);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    // The report carries each test's U with the bundled equipment, as
    // `evaluate` (no --equipment) computes it for the same file: beside E in
    // the figures table, and the re-test's (the one accepted) in its budget.
    for (test, name) in [("before", "before.rtl"), ("after", "after.rtl")] {
        let evaluated = json_run(&["evaluate", &file(name), "--json"]);
        let u = evaluated["uncertainty_um"]["E"].as_f64().unwrap();
        let cell = format!("data-key=\"{test}.figures_um.E\"");
        let at = html.find(&cell).unwrap();
        let cell_text = &html[at..at + html[at..].find("</td>").unwrap()];
        assert!(
            cell_text.ends_with(&format!(" ± {u:.2}</span>")),
            "{test}: {cell_text}"
        );
    }
    let after = json_run(&["evaluate", &file("after.rtl"), "--json"]);
    let u = &after["uncertainty_um"]["E"];
    assert!(
        html.contains(&format!(
            "data-key=\"after.uncertainty_um.E\" data-um=\"{u}\""
        )),
        "the report's U of the re-test is not {u}"
    );
    assert!(
        html.contains(&format!(
            "data-key=\"prediction.figures_um.A\" data-um=\"{predicted_a}\""
        )),
        "the report's predicted A is not {predicted_a}"
    );
    assert!(
        run.stdout.contains(&format!(
            "re-test A {:.2} µm",
            predicted_a.as_f64().unwrap()
        )),
        "{}",
        run.stdout
    );

    // The PNGs are plots, not empty canvases.
    for name in PROMISED.iter().filter(|n| n.ends_with(".png")) {
        let pixels = Pixels::read(&out.join(name));
        assert!(pixels.inked() > 0.02, "{name}: {}", pixels.inked());
    }

    // A second run into the same folder replaces nothing without --force.
    let again = axcomp(["demo", "--out", out.to_str().unwrap()]);
    assert_eq!(again.code, 2);
    assert!(again.stderr.contains("--force"), "{}", again.stderr);
    assert_eq!(
        axcomp(["demo", "--out", out.to_str().unwrap(), "--force"]).code,
        0
    );
}

#[test]
fn the_bundled_demo_files_are_what_the_truth_gives() {
    // As fixtures/demo/truth.toml says how they were made.
    let directory = tempfile::tempdir().unwrap();
    let demo = root().join("fixtures/demo");
    let path = |name: &str| directory.path().join(name).to_str().unwrap().to_string();
    let fixture = |name: &str| demo.join(name).to_str().unwrap().to_string();
    crate::util::synth_loop_files(directory.path(), &demo.join("truth.toml"), Some("2026"));
    for name in ["before.rtl", "X.COM", "after.rtl"] {
        let made = std::fs::read(path(name)).unwrap();
        let bundled = std::fs::read(fixture(name)).unwrap();
        assert_eq!(
            made, bundled,
            "{name} differs from what fixtures/demo/truth.toml gives"
        );
    }
}
