//! `axcomp predict --survey` end to end: a synthetic machine's geometry tests
//! (`synth::geometry`) written to files, a survey naming them, and the
//! measured state in the report.

use axcomp::model::Machine;
use axcomp::synth::geometry::{GeometryPlan, measure, random_truth};
use serde_json::Value;

use crate::util::axcomp;

/// A table that changes nothing (X, 0 … 750 mm), so the prediction is the survey's.
const NULL_TABLE: &str = "BEGIN X.COM MM\r\nNR   AXISPOS       BACKLASH      X\r\n0    +0                          +0.0000\r\n1    +750                        +0.0000\r\n[END]\r\n";

/// The example plan, lighter: 50 mm targets, one run each way, optics at the tool.
fn plan() -> GeometryPlan {
    GeometryPlan {
        step_mm: 50.0,
        runs: 1,
        optics_offset_mm: [[0.0; 3]; 3],
        ..GeometryPlan::example()
    }
}

/// The synthetic survey's files in `dir`; returns the survey's path.
fn write_survey(dir: &std::path::Path, edit: impl Fn(String) -> String) -> std::path::PathBuf {
    let machine = Machine::bundled();
    let truth = random_truth(&machine, &plan(), 15).unwrap();
    let synthetic = measure(&machine, &truth, &plan(), 16).unwrap();
    for (name, text) in &synthetic.tests {
        std::fs::write(dir.join(name), text).unwrap();
    }
    std::fs::write(dir.join("X.COM"), NULL_TABLE).unwrap();
    let path = dir.join("survey.toml");
    std::fs::write(&path, edit(synthetic.survey)).unwrap();
    path
}

fn predict(survey: &std::path::Path, extra: &[&str]) -> crate::util::Run {
    let table = survey.with_file_name("X.COM");
    let mut args: Vec<std::ffi::OsString> = vec![
        "predict".into(),
        "--survey".into(),
        survey.into(),
        "--table".into(),
        format!("X={}", table.display()).into(),
    ];
    args.extend(extra.iter().map(Into::into));
    axcomp(args)
}

#[test]
fn the_report_lists_what_was_measured_and_what_assumed() {
    let dir = tempfile::tempdir().unwrap();
    // Only X's test, and no squareness: 6 measured, 15 assumed.
    let survey = write_survey(dir.path(), |text| {
        let cut = text.find("\n[[test]]\nfile = \"Y.csv\"").unwrap();
        text[..cut].replace("from_straightness = [\"XY\", \"XZ\", \"YZ\"]", "")
    });
    let run = predict(&survey, &["--json"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).unwrap();
    let names = |key: &str| -> Vec<String> {
        json["survey"][key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| {
                v.as_str()
                    .map_or_else(|| v["error"].as_str().unwrap().to_string(), str::to_string)
            })
            .collect()
    };
    assert_eq!(
        names("measured"),
        ["EXX", "EYX", "EZX", "EAX", "EBX", "ECX"]
    );
    assert_eq!(names("assumed").len(), 15);
    assert_eq!(json["survey"]["assumed"][0]["as"], "zero");
    let straightness = json["survey"]["straightness"].as_array().unwrap();
    assert_eq!(straightness.len(), 2);
    assert_eq!(straightness[0]["reference_line"], "least-squares");
    // The laser's reference turned by 25 µrad about Z, and EXOY adds EXOY·X
    // to E_y (notes §2.5): EYX's slope carries both, and only them.
    let truth = random_truth(&Machine::bundled(), &plan(), 15).unwrap();
    let expected = 25.0 + truth.squareness.xy_rad * 1e6;
    let slope = straightness[0]["slope_urad"].as_f64().unwrap();
    assert!((slope - expected).abs() < 0.2, "{slope} against {expected}");

    let run = predict(&survey, &[]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stdout
            .contains("Survey: 6 of the 21 errors measured, 15 assumed"),
        "{}",
        run.stdout
    );
    assert!(
        run.stdout.contains("  measured  EXX EYX EZX EAX EBX ECX"),
        "{}",
        run.stdout
    );
}

#[test]
fn squareness_is_reported_in_the_surveys_convention() {
    let dir = tempfile::tempdir().unwrap();
    let mut values = Vec::new();
    for convention in ["right-handed", "larger-than-90"] {
        let survey = write_survey(dir.path(), |text| {
            text.replace("\"right-handed\"", &format!("\"{convention}\""))
        });
        let run = predict(&survey, &["--json"]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        let json: Value = serde_json::from_str(&run.stdout).unwrap();
        assert_eq!(json["survey"]["measured"].as_array().unwrap().len(), 21);
        let xy = &json["survey"]["squareness"][0];
        assert_eq!(xy["pair"], "XY");
        assert_eq!(xy["convention"], convention);
        values.push((
            xy["value_urad"].as_f64().unwrap(),
            xy["model_urad"].as_f64().unwrap(),
        ));
    }
    // The same machine: the value changes sign, the model's EXOY does not.
    assert!((values[0].0 + values[1].0).abs() < 1e-9, "{values:?}");
    assert!((values[0].1 - values[1].1).abs() < 1e-9, "{values:?}");
}

#[test]
fn bad_surveys_exit_2_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str); 3] = [
        ("file = \"X.csv\"", "file = \"missing.csv\""),
        (
            "reference_line = \"least-squares\"",
            "reference_line = \"best\"",
        ),
        ("[squareness]", "errors = \"nope.toml\"\n[squareness]"),
    ];
    for (from, to) in cases {
        let survey = write_survey(dir.path(), |text| text.replacen(from, to, 1));
        let run = predict(&survey, &[]);
        assert_eq!(run.code, 2, "{to}: {}", run.stderr);
        assert!(
            run.stderr.contains(dir.path().to_str().unwrap()),
            "{}",
            run.stderr
        );
    }
    // A geometry test given as a positioning test says what it is.
    let survey = write_survey(dir.path(), |text| text);
    let run = axcomp([
        "evaluate".as_ref(),
        survey.with_file_name("X.csv").as_os_str(),
    ]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr.contains("X.csv:3:1: this is a geometry test"),
        "{}",
        run.stderr
    );
}

#[test]
fn cross_axis_tables_change_the_map_and_the_shares_add_up() {
    let dir = tempfile::tempdir().unwrap();
    let survey = write_survey(dir.path(), |text| text);
    let mut maxima = Vec::new();
    for golden in [
        "formats/tnc640/golden/cross-Y-of-X.COM",
        "formats/sinumerik840d/golden/cross-Y-of-X-cec.MPF",
    ] {
        let mut file = crate::util::root().join(golden);
        if golden.ends_with(".COM") {
            // The TNC 640 has one table per axis: X's (null) positioning
            // column and Y = F(X) are one file, given as both.
            let own = survey.with_file_name("X.COM");
            std::fs::copy(&file, &own).unwrap();
            file = own;
        }
        let spec = format!("Y=F(X):{}", file.display());
        let run = predict(&survey, &["--cross-table", &spec, "--json"]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        let json: Value = serde_json::from_str(&run.stdout).unwrap();
        let after = json["volumetric_max_um"].as_f64().unwrap();
        let positioning = json["volumetric_max_positioning_only_um"].as_f64().unwrap();
        assert_ne!(after, positioning);
        let shares = json["shares"].as_array().unwrap();
        let total: f64 = shares.iter().map(|s| s["share"].as_f64().unwrap()).sum();
        // First order: the shares add up to the whole (the map is full transforms).
        assert!((total - 1.0).abs() < 1e-3, "{total}");
        maxima.push(after);
    }
    // The two controllers' files hold the same table: the same prediction.
    assert!((maxima[0] - maxima[1]).abs() < 1e-9, "{maxima:?}");
    let run = predict(&survey, &["--cross-table", "Y=G(X):x.COM"]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr.contains("expected COLUMN=F(AXIS):FILE"),
        "{}",
        run.stderr
    );
    let run = predict(&survey, &[]);
    assert!(
        run.stdout
            .contains("where it is largest, by error (compensate the first next): EXOY"),
        "{}",
        run.stdout
    );
}
