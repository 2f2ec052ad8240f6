//! `axcomp convert`: the reversal a mean table leaves, as each controller's
//! own backlash parameter (name, unit, value to type, sign), and none for
//! LinuxCNC, whose BACKLASH is ignored once COMP_FILE is set.
//!
//! Expected values by hand: `fixtures/sample-x.rtl` has B̄ = −3.18 µm
//! (`evaluate`: −3.179725 µm), so the suggested backlash −B̄ is 3.18 µm =
//! 0.0032 mm to the controllers' 4 decimals, and 3.179725 / 25 400 =
//! 0.000125 inch to 6 decimals on an inch machine.

use crate::util::{axcomp, evaluate_json, root};

const SAMPLE: &str = "fixtures/sample-x.rtl";
const INCH_PROFILE: &str = "fixtures/machines/gantry-inch.toml";

/// Runs convert with a regular 50 mm grid (every controller takes it);
/// returns the terminal summary and the --json object.
fn convert(controller: &str, extra: &[&str]) -> (String, serde_json::Value) {
    let directory = tempfile::tempdir().unwrap();
    let run_with = |json: bool, name: &str| {
        let output = directory.path().join(name);
        let mut args: Vec<String> = vec![
            "convert".into(),
            root().join(SAMPLE).display().to_string(),
            "--controller".into(),
            controller.into(),
            "--step".into(),
            "50".into(),
            "-o".into(),
            output.display().to_string(),
            "--quiet".into(),
        ];
        args.extend(extra.iter().map(|a| a.to_string()));
        if json {
            args.push("--json".into());
        }
        let run = axcomp(&args);
        assert_eq!(run.code, 0, "convert {args:?}: {}", run.stderr);
        run.stdout
    };
    let text = run_with(false, "text");
    let json = serde_json::from_str(&run_with(true, "json")).unwrap();
    (text, json)
}

fn backlash_lines(summary: &str) -> Vec<&str> {
    summary
        .lines()
        .filter(|line| line.starts_with("Backlash"))
        .collect()
}

#[test]
fn the_sample_reversal_is_minus_3_18_um() {
    // The hand numbers above rest on this figure of the evaluation.
    let json = evaluate_json(&[&root().join(SAMPLE)]);
    let b_mean_um = json["figures_um"]["B_mean"].as_f64().unwrap();
    assert!((b_mean_um + 3.18).abs() < 0.005, "B̄ = {b_mean_um}");
}

#[test]
fn each_controller_gets_its_own_backlash_line_in_mm() {
    let expected = [
        (
            "itnc530",
            "MP710.0",
            "positive when the rotary encoder reading is ahead of the table",
        ),
        (
            "tnc640",
            "CfgAxisComp/backLash (MP 401802) of axis X",
            "positive when the rotary encoder reading is ahead of the table",
        ),
        (
            "sinumerik840d",
            "MD32450 $MA_BACKLASH[0,X1]",
            "positive when the encoder is leading the machine part",
        ),
    ];
    for (controller, name, sign) in expected {
        let (summary, json) = convert(controller, &[]);
        let lines = backlash_lines(&summary);
        assert_eq!(
            lines,
            vec![format!("Backlash parameter: {name} = 0.0032 mm (−B̄ = 3.18 µm)").as_str()],
            "{controller}: {summary}"
        );
        assert!(summary.contains(&format!("  sign: {sign}")), "{summary}");
        assert!(
            !summary.contains("µm (−B̄; Heidenhain"),
            "the old µm line is gone"
        );
        let parameter = &json["backlash_parameter"];
        assert_eq!(parameter["name"], name, "{controller}");
        assert_eq!(parameter["value"].as_f64(), Some(0.0032), "{controller}");
        assert_eq!(parameter["unit"], "mm", "{controller}");
        assert!(parameter["sign"].as_str().unwrap().starts_with(sign));
        assert!(json["backlash_note"].is_null());
        // The µm key stays, as promised.
        let um = json["suggested_backlash_um"].as_f64().unwrap();
        assert!((um - 3.18).abs() < 0.005, "{um}");
    }
}

#[test]
fn linuxcnc_gets_no_backlash_value_but_the_way_to_take_the_reversal_out() {
    for extra in [&[][..], &["--machine", INCH_PROFILE][..]] {
        let (summary, json) = convert("linuxcnc", extra);
        let lines = backlash_lines(&summary);
        assert_eq!(lines.len(), 1, "{summary}");
        let line = lines[0];
        assert!(!line.starts_with("Backlash parameter"), "{line}");
        assert!(
            line.contains("[JOINT_0] BACKLASH is ignored once COMP_FILE is set"),
            "{line}"
        );
        assert!(line.contains("--mode bidirectional"), "{line}");
        assert!(line.contains("3.18 µm"), "{line}");
        assert!(!line.contains("0.0032"), "no value to type: {line}");
        assert!(json["backlash_parameter"].is_null());
        assert_eq!(
            json["backlash_note"].as_str(),
            Some(line.trim_start_matches("Backlash: "))
        );
    }
}

#[test]
fn an_inch_machine_gets_inch_where_the_controller_reads_inch() {
    // Sinumerik scales length machine data in inch on an inch control
    // (MD10240 = 0): 3.179725 µm / 25 400 = 0.000125 inch.
    let (summary, json) = convert("sinumerik840d", &["--machine", INCH_PROFILE]);
    assert_eq!(
        backlash_lines(&summary),
        vec!["Backlash parameter: MD32450 $MA_BACKLASH[0,AX1] = 0.000125 inch (−B̄ = 3.18 µm)"],
        "{summary}"
    );
    assert_eq!(json["backlash_parameter"]["unit"], "inch");
    assert_eq!(json["backlash_parameter"]["value"].as_f64(), Some(0.000125));
    // Heidenhain machine parameters are entered in mm on any machine.
    for (controller, name) in [
        ("itnc530", "MP710.0"),
        ("tnc640", "CfgAxisComp/backLash (MP 401802) of axis X"),
    ] {
        let (summary, json) = convert(controller, &["--machine", INCH_PROFILE]);
        assert_eq!(
            backlash_lines(&summary),
            vec![format!("Backlash parameter: {name} = 0.0032 mm (−B̄ = 3.18 µm)").as_str()],
            "{controller}: {summary}"
        );
        assert_eq!(json["backlash_parameter"]["unit"], "mm");
    }
}

#[test]
fn a_bidirectional_table_needs_no_backlash_parameter() {
    let (summary, json) = convert("tnc640", &["--mode", "bidirectional"]);
    assert!(backlash_lines(&summary).is_empty(), "{summary}");
    assert!(json["suggested_backlash_um"].is_null());
    assert!(json["backlash_parameter"].is_null());
    assert!(json["backlash_note"].is_null());
}
