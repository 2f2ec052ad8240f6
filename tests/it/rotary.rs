//! Rotary axes end to end (issue 14): the readers, `evaluate` in arc-seconds
//! with the rotary rules of ISO 230-2 (`../shared/spec/standards.md` §6),
//! and the commands that refuse a rotary axis so far.
//! See: issue 14.

use std::path::{Path, PathBuf};

use crate::retest_case::rotary_retest_files;
use crate::util::{axcomp, test_data};

/// Writes `rows` (target°, run, direction, deviation″) as a rotary CSV.
fn rotary_csv(directory: &Path, name: &str, rows: &[(f64, u32, &str, f64)]) -> PathBuf {
    let mut text = String::from("# axis: C\ntarget_deg,run,direction,deviation_arcsec\n");
    for (target, run, direction, deviation) in rows {
        text.push_str(&format!("{target},{run},{direction},{deviation}\n"));
    }
    let path = directory.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Two runs each way at `targets`, the deviations per run in the order
/// up 1, up 2, down 1, down 2 (one value per target each).
fn two_runs(targets: &[f64], runs: [&[f64]; 4]) -> Vec<(f64, u32, &'static str, f64)> {
    let labels = [(1, "up"), (2, "up"), (1, "down"), (2, "down")];
    let mut rows = Vec::new();
    for ((run, direction), values) in labels.into_iter().zip(runs) {
        for (target, value) in targets.iter().zip(values) {
            rows.push((*target, run, direction, *value));
        }
    }
    rows
}

fn json_of(path: &Path) -> (serde_json::Value, String) {
    let run = axcomp(["evaluate".as_ref(), "--json".as_ref(), path.as_os_str()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    (serde_json::from_str(&run.stdout).unwrap(), run.stderr)
}

const FULL_TURN: [f64; 5] = [0.0, 90.0, 180.0, 270.0, 360.0];

#[test]
fn a_rotary_csv_is_evaluated_in_arc_seconds() {
    let directory = tempfile::tempdir().unwrap();
    let path = rotary_csv(
        directory.path(),
        "c.csv",
        &two_runs(
            &FULL_TURN,
            [
                &[1.0, 2.0, 3.0, 2.0, 1.0],
                &[3.0, 2.0, 1.0, 2.0, 3.0],
                &[-1.0, 0.0, 1.0, 0.0, -1.0],
                &[-1.0, 0.0, -1.0, 0.0, -1.0],
            ],
        ),
    );
    let (json, stderr) = json_of(&path);
    // By hand: x̄↑ = 2 everywhere, x̄↓ = −1, 0, 0, 0, −1; x̄ = 0.5, 1, 1, 1, 0.5;
    // B_i = 3, 2, 2, 2, 3. s↑ = √2 at 0°, 180°, 360°, else 0; s↓ = √2 at 180° only.
    // E = 2 − (−1) = 3, E↑ = 0, E↓ = 1, M = 1 − 0.5 = 0.5, B = 3, B̄ = 12/5.
    // A = (2 + 2√2) − (0 − 2√2) = 2 + 4√2; R = R_180° = 2√2 + 2√2 + 2.
    let root2 = 2f64.sqrt();
    let figures = &json["figures_arcsec"];
    for (key, expected) in [
        ("E", 3.0),
        ("E_up", 0.0),
        ("E_down", 1.0),
        ("M", 0.5),
        ("B", 3.0),
        ("B_mean", 2.4),
        ("A", 2.0 + 4.0 * root2),
        ("R", 2.0 + 4.0 * root2),
        ("R_up", 4.0 * root2),
    ] {
        let value = figures[key].as_f64().unwrap_or_else(|| panic!("{key}"));
        assert!(
            (value - expected).abs() < 1e-9,
            "{key}: {value} ≠ {expected}"
        );
    }
    assert_eq!(json["axis_kind"], "rotary");
    assert_eq!(json["length_unit"], "deg");
    assert_eq!(json["targets_deg"][4], 360.0);
    assert_eq!(json["test_conformance"]["length_deg"], 360.0);
    for absent in ["targets_mm", "figures_um", "uncertainty_um"] {
        assert!(json.get(absent).is_none(), "{absent} on a rotary axis");
    }
    let target = &json["per_target"][0];
    assert_eq!(target["target_deg"], 0.0);
    assert!((target["mean_arcsec"].as_f64().unwrap() - 0.5).abs() < 1e-12);
    assert!((target["s_up_arcsec"].as_f64().unwrap() - root2).abs() < 1e-12);
    for key in [
        "mean_up_arcsec",
        "mean_down_arcsec",
        "B_arcsec",
        "R_up_arcsec",
        "R_down_arcsec",
        "R_arcsec",
    ] {
        assert!(target.get(key).is_some(), "missing {key}");
    }
    assert!(target.get("target_mm").is_none() && target.get("mean_um").is_none());
    // All four principal angles are there, and 0° and 360° agree: the one
    // warning is the runs'.
    assert_eq!(json["warnings"].as_array().unwrap().len(), 1, "{stderr}");
    assert!(
        stderr.contains("(fewer only on rotary axes over 360°)"),
        "{stderr}"
    );
    let run = axcomp(["evaluate".as_ref(), path.as_os_str()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    for text in [
        "Per target [″]",
        "Axis figures [″]",
        "target [°]",
        "5 from 0 to 360°",
        "rotary axis, bidirectional test, 2 runs, 5 targets over 360°",
    ] {
        assert!(run.stdout.contains(text), "{text} in\n{}", run.stdout);
    }
    assert!(!run.stdout.contains("µm"), "{}", run.stdout);
}

#[test]
fn over_a_full_turn_repeatability_and_a_are_not_evaluated() {
    let directory = tempfile::tempdir().unwrap();
    let targets: Vec<f64> = (0..=8).map(|k| 90.0 * k as f64).collect();
    let values: Vec<f64> = (0..=8).map(|k| k as f64 * 0.5).collect();
    let shifted: Vec<f64> = values.iter().map(|v| v + 1.0).collect();
    let path = rotary_csv(
        directory.path(),
        "two-turns.csv",
        &two_runs(&targets, [&values, &shifted, &values, &shifted]),
    );
    let (json, _) = json_of(&path);
    let figures = &json["figures_arcsec"];
    for key in ["A", "A_up", "A_down", "R", "R_up", "R_down"] {
        assert!(figures[key].is_null(), "{key} = {}", figures[key]);
    }
    // x̄ = 0.5 + 0.5 k at both directions: E = 4, B = 0.
    assert!((figures["E"].as_f64().unwrap() - 4.0).abs() < 1e-12);
    assert_eq!(figures["B"], 0.0);
    let warnings = json["warnings"].to_string();
    assert!(
        warnings.contains("rotary axis over 360° (720°): ISO 230-2 takes one approach per direction and target there (n = 1), so the repeatabilities and A are not evaluated"),
        "{warnings}"
    );
    // One run each way is what the standard asks there.
    let runs = &json["test_conformance"]["checks"][0];
    assert_eq!(
        (runs["check"].as_str(), runs["required"].as_f64()),
        (Some("runs"), Some(1.0))
    );
}

#[test]
fn missing_principal_angles_and_disagreeing_ends_are_said() {
    let directory = tempfile::tempdir().unwrap();
    let targets = [10.0, 100.0, 190.0, 280.0, 350.0];
    let flat = [0.0; 5];
    let path = rotary_csv(
        directory.path(),
        "off.csv",
        &two_runs(&targets, [&flat, &flat, &flat, &flat]),
    );
    let (json, _) = json_of(&path);
    let warnings = json["warnings"].to_string();
    assert!(
        warnings.contains(
            "principal angle(s) 90°, 180°, 270° within the range are not among the targets"
        ),
        "{warnings}"
    );

    // 0° and 360° one turn apart: x̄ = 0.5″ at 0° and 11″ at 360°, 10.5″
    // apart, more than R_i = max(2√2 + 3, 2) = 5.83″ (by hand).
    let path = rotary_csv(
        directory.path(),
        "ends.csv",
        &two_runs(
            &FULL_TURN,
            [
                &[1.0, 2.0, 3.0, 2.0, 12.0],
                &[3.0, 2.0, 1.0, 2.0, 12.0],
                &[-1.0, 0.0, 1.0, 0.0, 10.0],
                &[-1.0, 0.0, -1.0, 0.0, 10.0],
            ],
        ),
    );
    let (json, _) = json_of(&path);
    let warnings = json["warnings"].to_string();
    assert!(
        warnings.contains("0° and 360° are one physical position, but their mean deviations differ by 10.50″ (+0.50″ and +11.00″), more than the repeatability there (5.83″)"),
        "{warnings}"
    );
    // The same with --angle-unit urad, × π/648000·10⁶ by hand: 10.5″ =
    // 50.905 µrad, 0.5″ = 2.424, 11″ = 53.330, (2√2 + 3)″ = 28.257 µrad;
    // on stderr and in the JSON alike.
    let run = axcomp([
        "evaluate".as_ref(),
        "--json".as_ref(),
        "--angle-unit".as_ref(),
        "urad".as_ref(),
        path.as_os_str(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let said = "differ by 50.91 µrad (+2.42 µrad and +53.33 µrad), more than the repeatability there (28.26 µrad)";
    assert!(run.stderr.contains(said), "{}", run.stderr);
    assert!(run.stdout.contains(said), "{}", run.stdout);
    // And in the report's notes.
    let html = directory.path().join("ends.html");
    let run = axcomp([
        "report".as_ref(),
        path.as_os_str(),
        "--angle-unit".as_ref(),
        "urad".as_ref(),
        "-o".as_ref(),
        html.as_os_str(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stderr.contains(said), "{}", run.stderr);
    assert!(std::fs::read_to_string(&html).unwrap().contains(said));
}

#[test]
fn an_ecmc_file_in_degrees_is_a_rotary_axis() {
    // tests/data/rotary/ecmc-deg.dat is hand-made: REF − TGT at 0° is 1.8″
    // and 5.4″ forward (x̄↑ = 3.6″), −1.8″ and 0″ backward (x̄↓ = −0.9″).
    let (json, _) = json_of(&test_data("rotary/ecmc-deg.dat"));
    assert_eq!(json["axis_kind"], "rotary");
    assert_eq!(json["axis"], "C");
    assert_eq!(json["targets_deg"][4], 360.0);
    let first = &json["per_target"][0];
    for (key, expected) in [
        ("mean_up_arcsec", 3.6),
        ("mean_down_arcsec", -0.9),
        ("B_arcsec", 4.5),
    ] {
        let value = first[key].as_f64().unwrap();
        assert!((value - expected).abs() < 1e-6, "{key}: {value}");
    }
}

#[test]
fn commands_for_linear_axes_only_refuse_a_rotary_one() {
    let path = test_data("rotary/ecmc-deg.dat");
    let equipment = crate::util::root().join("fixtures/equipment/hene-default.toml");
    for args in [
        vec![
            "report".as_ref(),
            path.as_os_str(),
            "--axis".as_ref(),
            "C".as_ref(),
            "--limit".as_ref(),
            "E=5".as_ref(),
            "-o".as_ref(),
            "/nonexistent/r.html".as_ref(),
        ],
        vec![
            "evaluate".as_ref(),
            path.as_os_str(),
            "--limit".as_ref(),
            "E=5".as_ref(),
        ],
        // The budget is a length laser's: asked for on a rotary axis, it is
        // refused, not left out without a word.
        vec![
            "evaluate".as_ref(),
            path.as_os_str(),
            "--equipment".as_ref(),
            equipment.as_os_str(),
        ],
        vec![
            "evaluate".as_ref(),
            path.as_os_str(),
            "--decision".as_ref(),
            "iso14253-1".as_ref(),
        ],
    ] {
        let run = axcomp(&args);
        assert_eq!(run.code, 2, "{args:?}: {}", run.stdout);
        assert!(run.stderr.contains("is a rotary axis"), "{}", run.stderr);
    }
}

/// A rotary C axis' options for `controller` tables (the default profile).
fn rotary_options() -> axcomp::emit::EmitOptions {
    let profile = axcomp::emit::MachineProfile::default();
    let mut options = axcomp::emit::EmitOptions::for_axis(&profile, "C", "C.COM").unwrap();
    options.kind = axcomp::measurement::AxisKind::Rotary;
    options
}

fn rotary_table(
    positions_deg: &[f64],
    values_deg: &[f64],
) -> axcomp::compensate::CompensationTable {
    axcomp::compensate::CompensationTable {
        axis: "C".to_string(),
        kind: axcomp::measurement::AxisKind::Rotary,
        positions: positions_deg.to_vec(),
        values: axcomp::compensate::TableValues::Mean(values_deg.to_vec()),
        reference: positions_deg[0],
        suggested_backlash: None,
    }
}

#[test]
fn rotary_tables_are_written_in_degrees_and_read_back() {
    use axcomp::emit::{self, Controller, EmitError};
    let options = rotary_options();
    // 0.0001° = 0.36″ steps, what a 4-decimal Heidenhain value holds exactly.
    let full = rotary_table(&FULL_TURN, &[0.0, 0.0012, -0.0007, 0.0003, 0.0]);
    for controller in [
        Controller::Itnc530,
        Controller::Tnc640,
        Controller::Sinumerik840d,
        Controller::LinuxCnc,
    ] {
        // `write` reads every text back and compares it with the table.
        let text = emit::write(controller, &full, &options)
            .unwrap_or_else(|e| panic!("{}: {e}", controller.name()));
        let (_, back) = emit::read_any(&text, &options, Some(0)).unwrap();
        assert_eq!(back.positions, FULL_TURN, "{}", controller.name());
        // The file holds bare numbers; the axis read them as degrees.
        assert_eq!(
            back.reference_typed(),
            axcomp::measurement::ByKind::Rotary(axcomp::units::Deg(FULL_TURN[0])),
            "{}",
            controller.name()
        );
    }
    let sinumerik = emit::write(Controller::Sinumerik840d, &full, &options).unwrap();
    for line in [
        "$AA_ENC_COMP[0,1,C1]=0.0012",
        "$AA_ENC_COMP_MIN[0,C1]=0.0",
        "$AA_ENC_COMP_MAX[0,C1]=360.0",
        "$AA_ENC_COMP_IS_MODULO[0,C1]=1",
    ] {
        assert!(sinumerik.contains(line), "{line} in\n{sinumerik}");
    }
    // AXISPOS and values in degrees, as they are.
    let tnc640 = emit::write(Controller::Tnc640, &full, &options).unwrap();
    assert!(
        tnc640.contains("1    +90   ") && tnc640.contains("+0.0012"),
        "{tnc640}"
    );
    // LinuxCNC type 0: nominal + error, degrees.
    let linuxcnc = emit::write(Controller::LinuxCnc, &full, &options).unwrap();
    assert!(
        linuxcnc.starts_with("0 0 0\n90 90.0012 90.0012\n"),
        "{linuxcnc}"
    );
    let activation = emit::activation(Controller::LinuxCnc, &full, "C.comp", &options);
    assert!(activation.contains("WRAPPED_ROTARY = 1"), "{activation}");

    // A part of a turn is no modulo table.
    let part = rotary_table(&[0.0, 90.0, 180.0], &[0.0, 0.001, 0.002]);
    let text = emit::write(Controller::Sinumerik840d, &part, &options).unwrap();
    assert!(text.contains("$AA_ENC_COMP_IS_MODULO[0,C1]=0"), "{text}");

    // Refusals, naming what is wrong.
    let ends = rotary_table(&FULL_TURN, &[0.0, 0.001, 0.0, 0.0, 0.0005]);
    let error = emit::write(Controller::Sinumerik840d, &ends, &options).unwrap_err();
    assert_eq!(
        error,
        EmitError::ModuloEndsDiffer {
            first_deg: 0.0,
            last_deg: 0.0005
        }
    );
    assert!(
        error.to_string().contains("0° at 0° and 0.0005° at 360°"),
        "{error}"
    );
    let shifted = rotary_table(&[-180.0, -90.0, 0.0, 90.0, 180.0], &[0.0; 5]);
    let error = emit::write(Controller::Sinumerik840d, &shifted, &options).unwrap_err();
    assert!(error.to_string().contains("from -180° to 180°"), "{error}");
    for controller in [Controller::Fagor8055, Controller::Fagor8065] {
        let error = emit::write(controller, &full, &options).unwrap_err();
        assert_eq!(
            error,
            EmitError::RotaryNotSupported {
                controller: controller.name()
            }
        );
    }
}

#[test]
fn a_full_turn_table_joins_its_ends() {
    use axcomp::compensate::{
        Extrapolate, GridSpec, TableMode, TableOptions, TableValues, build_table,
    };
    use axcomp::measurement::SourceFormat;
    // x̄ = 1″ at 0° and 3″ at 360° (one position): both ends get their mean,
    // 2″, and the table is zero there (reference 0°); 90° stays 5″ − 2″.
    let csv = "target_deg,run,direction,deviation_arcsec\n0,1,up,1\n90,1,up,5\n360,1,up,3\n";
    let (c, _) = axcomp::read::parse_str(csv, SourceFormat::Csv).unwrap();
    let options = TableOptions {
        mode: TableMode::Mean,
        grid: GridSpec::Targets,
        reference: None,
        extrapolate: Extrapolate::Refuse,
    };
    let table = build_table(&c, &axcomp::evaluate::evaluate(&c), &options).unwrap();
    let TableValues::Mean(values) = table.values else {
        panic!("a mean table")
    };
    let arcsec: Vec<f64> = values.iter().map(|v| v * 3600.0).collect();
    for (value, expected) in arcsec.iter().zip([0.0, 3.0, 0.0]) {
        assert!((value - expected).abs() < 1e-9, "{arcsec:?}");
    }
}

/// ISO 230-2's figures computed here from the CSV text, independently of
/// `read` and `evaluate` (`../shared/spec/iso230-2.md`): per target and
/// direction x̄ and s (n − 1), then A, E, M, R, B and B̄, in ″.
fn independent_figures(csv: &str) -> Vec<(&'static str, f64)> {
    use std::collections::BTreeMap;
    // (target in thousandths of a degree, up?) → readings ″
    let mut readings: BTreeMap<(i64, bool), Vec<f64>> = BTreeMap::new();
    for line in csv.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        let target = (fields[0].parse::<f64>().unwrap() * 1000.0).round() as i64;
        readings
            .entry((target, fields[2] == "up"))
            .or_default()
            .push(fields[3].parse().unwrap());
    }
    let stats = |values: &Vec<f64>| {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let s = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        (mean, s)
    };
    let targets: Vec<i64> = readings
        .keys()
        .map(|(t, _)| *t)
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let (mut up, mut down) = (Vec::new(), Vec::new());
    for t in &targets {
        up.push(stats(&readings[&(*t, true)]));
        down.push(stats(&readings[&(*t, false)]));
    }
    let max = |v: Vec<f64>| v.into_iter().fold(f64::MIN, f64::max);
    let min = |v: Vec<f64>| v.into_iter().fold(f64::MAX, f64::min);
    let span = |v: Vec<f64>| max(v.clone()) - min(v);
    let means = |d: &Vec<(f64, f64)>| d.iter().map(|(m, _)| *m).collect::<Vec<f64>>();
    let both: Vec<f64> = means(&up).into_iter().chain(means(&down)).collect();
    let reversal: Vec<f64> = up.iter().zip(&down).map(|(u, d)| u.0 - d.0).collect();
    let r_i: Vec<f64> = up
        .iter()
        .zip(&down)
        .map(|(u, d)| {
            (2.0 * u.1 + 2.0 * d.1 + (u.0 - d.0).abs())
                .max(4.0 * u.1)
                .max(4.0 * d.1)
        })
        .collect();
    let high = |d: &Vec<(f64, f64)>| d.iter().map(|(m, s)| m + 2.0 * s).collect::<Vec<f64>>();
    let low = |d: &Vec<(f64, f64)>| d.iter().map(|(m, s)| m - 2.0 * s).collect::<Vec<f64>>();
    vec![
        (
            "A",
            max(high(&up).into_iter().chain(high(&down)).collect())
                - min(low(&up).into_iter().chain(low(&down)).collect()),
        ),
        ("A_up", max(high(&up)) - min(low(&up))),
        ("A_down", max(high(&down)) - min(low(&down))),
        ("E", span(both)),
        ("E_up", span(means(&up))),
        ("E_down", span(means(&down))),
        (
            "M",
            span(
                up.iter()
                    .zip(&down)
                    .map(|(u, d)| (u.0 + d.0) / 2.0)
                    .collect(),
            ),
        ),
        ("R", max(r_i)),
        ("R_up", max(up.iter().map(|(_, s)| 4.0 * s).collect())),
        ("R_down", max(down.iter().map(|(_, s)| 4.0 * s).collect())),
        ("B", max(reversal.iter().map(|b| b.abs()).collect())),
        (
            "B_mean",
            reversal.iter().sum::<f64>() / reversal.len() as f64,
        ),
    ]
}

/// Issue 14's synthetic rotary test: 0–360° every 15°, 5 runs each way, a
/// known truth (fixtures/rotary/truth.toml). The bundled file is exactly what
/// the truth gives; its figures equal an independent computation to 0.01″;
/// its tables for the iTNC 530, TNC 640, Sinumerik and LinuxCNC are golden
/// files (`convert::golden_files_per_controller`, cases `rotary-c-*`).
#[test]
fn the_synthetic_rotary_test_evaluates_to_an_independent_computation() {
    let truth_text =
        std::fs::read_to_string(crate::util::root().join("fixtures/rotary/truth.toml")).unwrap();
    let truth = axcomp::synth::RotaryTruth::from_toml_str(&truth_text).unwrap();
    let measurement = axcomp::synth::rotary_test(&truth, 14).unwrap();
    let csv_path = crate::util::root().join("fixtures/rotary/c.csv");
    let bundled = std::fs::read_to_string(&csv_path).unwrap();
    assert_eq!(
        axcomp::read::csv::write(&measurement),
        bundled,
        "regenerate as truth.toml says"
    );
    assert_eq!(measurement.targets().len(), 25);
    assert_eq!(measurement.runs().len(), 10);

    let (json, _) = json_of(&csv_path);
    let figures = &json["figures_arcsec"];
    for (key, expected) in independent_figures(&bundled) {
        let value = figures[key].as_f64().unwrap_or_else(|| panic!("{key}"));
        assert!(
            (value - expected).abs() < 0.01,
            "{key}: {value}″ against {expected}″"
        );
    }
    // The truth shows through the noise (σ = 0.3″, 5 runs): B̄ near the
    // planted 2.4″, and M (the span of x̄_i, where the reversal cancels) near
    // the span of 4 sin(θ + 0.5) + 1.5 sin(2θ − 1.1) at the targets.
    let b_mean = figures["B_mean"].as_f64().unwrap();
    assert!((b_mean - 2.4).abs() < 0.2, "{b_mean}");
    let curve: Vec<f64> = (0..25)
        .map(|k| {
            let theta = (15.0 * k as f64).to_radians();
            4.0 * (theta + 0.5).sin() + 1.5 * (2.0 * theta - 1.1).sin()
        })
        .collect();
    let span = curve.iter().cloned().fold(f64::MIN, f64::max)
        - curve.iter().cloned().fold(f64::MAX, f64::min);
    let m = figures["M"].as_f64().unwrap();
    assert!((m - span).abs() < 0.5, "M {m}″ against the truth's {span}″");
    // A full turn with every principal angle and agreeing ends, 5 runs:
    // no warning (the linear even-spacing note does not apply).
    let warnings = json["warnings"].as_array().unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
}

#[test]
fn a_bad_rotary_truth_is_refused_with_its_position() {
    let directory = tempfile::tempdir().unwrap();
    let truth = directory.path().join("t.toml");
    std::fs::write(
        &truth,
        "[rotary]\nstart_deg = 0.0\nend_deg = 360.0\ncount = 5\nruns = 1\nsigma_arcsec = 0.1\nwobble = 2\n",
    )
    .unwrap();
    let output = directory.path().join("c.csv");
    let run = axcomp([
        "synth".as_ref(),
        "--truth".as_ref(),
        truth.as_os_str(),
        "-o".as_ref(),
        output.as_os_str(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stdout);
    assert!(run.stderr.contains("t.toml:7:1"), "{}", run.stderr);
    assert!(!output.exists(), "nothing half-written");
    let rtl = directory.path().join("c.rtl");
    let good = crate::util::root().join("fixtures/rotary/truth.toml");
    let run = axcomp([
        "synth".as_ref(),
        "--truth".as_ref(),
        good.as_os_str(),
        "-o".as_ref(),
        rtl.as_os_str(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stdout);
    assert!(
        run.stderr.contains("write a rotary test as .csv"),
        "{}",
        run.stderr
    );
    assert!(!rtl.exists());
}

/// The rotary report, whole: the terminal in ° and ″, the JSON with the
/// unit in its keys (golden files; the linear ones are unchanged).
#[test]
fn evaluate_reports_of_the_rotary_fixture() {
    let file = "fixtures/rotary/c.csv";
    let run = axcomp(["evaluate", file]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    crate::util::assert_golden(&run.stdout, &test_data("golden/evaluate-rotary-c.txt"));
    let run = axcomp(["evaluate", "--json", file]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    crate::util::assert_golden(&run.stdout, &test_data("golden/evaluate-rotary-c.json"));
}

/// A LinuxCNC table that was active on a rotary joint reads back in degrees
/// on an inch machine too: the machine's length unit does not apply.
#[test]
fn an_active_rotary_table_is_read_in_degrees_on_an_inch_machine() {
    let directory = tempfile::tempdir().unwrap();
    let profile = directory.path().join("m.toml");
    std::fs::write(&profile, "[controller]\nunits = \"inch\"\n").unwrap();
    let output = directory.path().join("c.comp");
    let run = axcomp([
        "convert".as_ref(),
        "fixtures/rotary/c.csv".as_ref(),
        "--controller".as_ref(),
        "linuxcnc".as_ref(),
        "--machine".as_ref(),
        profile.as_os_str(),
        "--existing".as_ref(),
        "formats/linuxcnc/golden/rotary-c-mean-type0.txt".as_ref(),
        "-o".as_ref(),
        output.as_os_str(),
        "--json".as_ref(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["file_unit"], "deg");
    // The measurement plus the active table it was taken with: the new
    // table is about twice the first (the test saw the uncompensated axis,
    // so the residual adds to the table), in degrees, not 25.4 times it.
    let written = std::fs::read_to_string(&output).unwrap();
    let golden =
        std::fs::read_to_string("formats/linuxcnc/golden/rotary-c-mean-type0.txt").unwrap();
    let at_90 = |text: &str| -> f64 {
        let row = text.lines().find(|l| l.starts_with("90 ")).unwrap();
        row.split(' ').nth(1).unwrap().parse::<f64>().unwrap() - 90.0
    };
    let ratio = at_90(&written) / at_90(&golden);
    assert!((ratio - 2.0).abs() < 0.01, "{ratio}");
}

/// `diagnose --quiet` of the re-test `files` (before, table, after) with
/// `extra` flags; it must succeed.
fn diagnose_retest(files: &(PathBuf, PathBuf, PathBuf), extra: &[&str]) -> crate::util::Run {
    let (before, table, after) = files;
    let mut args = vec![
        "diagnose".as_ref(),
        "--after".as_ref(),
        after.as_os_str(),
        "--before".as_ref(),
        before.as_os_str(),
        "--table".as_ref(),
        table.as_os_str(),
        "--quiet".as_ref(),
    ];
    args.extend(extra.iter().map(std::ffi::OsStr::new));
    let run = axcomp(args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    run
}

/// Every key of a JSON value, at every depth.
fn keys_of(value: &serde_json::Value, keys: &mut Vec<String>) {
    match value {
        serde_json::Value::Object(map) => {
            for (key, item) in map {
                keys.push(key.clone());
                keys_of(item, keys);
            }
        }
        serde_json::Value::Array(items) => items.iter().for_each(|v| keys_of(v, keys)),
        _ => {}
    }
}

/// Issue 14: a rotary re-test with a once- or twice-per-revolution term the
/// first test did not have (the encoder remounted, the table's eccentricity
/// changed) is diagnosed as a periodic effect of that order, period
/// 360°/order, amplitude within 10 % of the truth's, in ″ in the terminal
/// and the JSON (keys `_arcsec`, `_deg`, no `_um` or `_mm`). The expected
/// order and amplitude are the planted truth's.
#[test]
fn diagnose_finds_a_per_revolution_harmonic_with_its_order() {
    let directory = tempfile::tempdir().unwrap();
    for (seed, extra) in [
        (21, (2, 3.0, 0.3)),
        (22, (2, 3.0, -2.0)),
        (23, (1, 2.5, 1.2)),
        (24, (3, 2.0, 0.0)),
    ] {
        let (order, amplitude_arcsec, _) = extra;
        let files = rotary_retest_files(directory.path(), extra, seed);
        let run = diagnose_retest(&files, &["--json"]);
        let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
        assert_eq!(json["axis_kind"], "rotary");
        let periodic: Vec<&serde_json::Value> = json["effects"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["kind"] == "periodic")
            .collect();
        assert_eq!(periodic.len(), 1, "seed {seed}: {}", run.stdout);
        let params = &periodic[0]["params"];
        assert_eq!(params["per_revolution"], order, "seed {seed}: {params}");
        let period = params["period_deg"].as_f64().unwrap();
        assert!((period - 360.0 / f64::from(order)).abs() < 1e-9, "{period}");
        let found = params["amplitude_arcsec"].as_f64().unwrap();
        assert!(
            (found - amplitude_arcsec).abs() <= 0.1 * amplitude_arcsec,
            "seed {seed}: order {order}: found {found}″, planted {amplitude_arcsec}″"
        );
        assert!(
            periodic[0]["uncertainty"]["amplitude_arcsec"]
                .as_f64()
                .unwrap()
                < 0.1 * amplitude_arcsec
        );
        // Nothing else was planted: the reversal is the first test's, which
        // the prediction carries.
        assert_eq!(
            json["effects"].as_array().unwrap().len(),
            1,
            "{}",
            run.stdout
        );
        let mut keys = Vec::new();
        keys_of(&json, &mut keys);
        assert!(
            keys.iter()
                .all(|k| !k.ends_with("_um") && !k.ends_with("_mm")),
            "{keys:?}"
        );
        for key in ["residual_before_arcsec", "figures_arcsec", "noise_arcsec"] {
            assert!(json.get(key).is_some(), "{key}");
        }
        // The residual before the effects holds the planted harmonic: its
        // rms over a full turn is about amplitude/√2 (with 0.3″ noise).
        let rms = json["residual_before_arcsec"]["rms"].as_f64().unwrap();
        let expected = amplitude_arcsec / 2f64.sqrt();
        assert!(
            (rms - expected).abs() < 0.2 * expected,
            "{rms} vs {expected}"
        );

        let run = diagnose_retest(&files, &[]);
        assert!(
            run.stdout.contains(&format!("{order} per revolution")),
            "{}",
            run.stdout
        );
        assert!(run.stdout.contains("Figures [″]"), "{}", run.stdout);
        assert!(!run.stdout.contains("µm"), "{}", run.stdout);
        assert!(!run.stdout.contains(" mm"), "{}", run.stdout);
    }
}

/// A rotary diagnosis refuses what is still lengths only: the effects file
/// and an angular (Abbe) profile.
#[test]
fn diagnose_of_a_rotary_axis_refuses_length_only_flags() {
    let directory = tempfile::tempdir().unwrap();
    for flag in ["--write-effects", "--angular"] {
        let other = directory.path().join("x");
        let run = axcomp([
            "diagnose".as_ref(),
            "--after".as_ref(),
            "fixtures/rotary/c.csv".as_ref(),
            flag.as_ref(),
            other.as_os_str(),
        ]);
        assert_eq!(run.code, 2, "{}", run.stdout);
        assert!(
            run.stderr.contains("is a rotary axis") && run.stderr.contains(flag),
            "{}",
            run.stderr
        );
        assert!(!other.exists());
    }
}

/// µrad in one arc-second, from the definition (1″ = π/648000 rad), not
/// from `axcomp::units`.
const URAD_PER_ARCSEC: f64 = std::f64::consts::PI / 648_000.0 * 1e6;

/// Walks the ″ object `arcsec` beside the µrad object `urad`: every key
/// ending in `_arcsec` is there as `_urad` with every number in it (at any
/// depth) the ″ number × [`URAD_PER_ARCSEC`] (within rounding), every
/// other value the same. Returns how many numbers were compared scaled.
fn assert_urad_beside_arcsec(
    arcsec: &serde_json::Value,
    urad: &serde_json::Value,
    scaled: bool,
    at: &str,
) -> usize {
    use serde_json::Value;
    match (arcsec, urad) {
        (Value::Object(a), Value::Object(u)) => {
            assert_eq!(a.len(), u.len(), "{at}: {:?} vs {:?}", a.keys(), u.keys());
            let mut count = 0;
            for (key, value) in a {
                let (key_urad, scaled) = match key.strip_suffix("_arcsec") {
                    Some(stem) => (format!("{stem}_urad"), true),
                    None => (key.clone(), scaled),
                };
                let other = u
                    .get(&key_urad)
                    .unwrap_or_else(|| panic!("{at}.{key_urad} missing"));
                count += assert_urad_beside_arcsec(value, other, scaled, &format!("{at}.{key}"));
            }
            count
        }
        (Value::Array(a), Value::Array(u)) => {
            assert_eq!(a.len(), u.len(), "{at}");
            a.iter()
                .zip(u)
                .enumerate()
                .map(|(i, (a, u))| assert_urad_beside_arcsec(a, u, scaled, &format!("{at}.{i}")))
                .sum()
        }
        (Value::Number(a), Value::Number(u)) if scaled => {
            let (a, u) = (a.as_f64().unwrap(), u.as_f64().unwrap());
            let expected = a * URAD_PER_ARCSEC;
            assert!(
                (u - expected).abs() <= 1e-12 * expected.abs().max(1.0),
                "{at}: {u} µrad ≠ {a}″ × {URAD_PER_ARCSEC} = {expected}"
            );
            1
        }
        // A sentence that says a deviation says it in the unit asked for.
        (Value::String(a), Value::String(u)) if a != u => {
            assert!(
                a.contains('″') && !u.contains('″') && u.contains("µrad"),
                "{at}: {a:?} vs {u:?}"
            );
            0
        }
        (a, u) => {
            assert_eq!(a, u, "{at}");
            0
        }
    }
}

/// `--angle-unit urad`: the rotary fixture's every deviation figure is the
/// arc-second figure × π/648000·10⁶ (computed here, not by axcomp), every
/// key that ends in `_arcsec` ends in `_urad` (and none in `_arcsec`), and
/// the terminal says µrad. The default is still ″.
#[test]
fn evaluate_in_microradians_is_the_arcsec_report_times_the_factor() {
    let file = "fixtures/rotary/c.csv";
    let run = axcomp(["evaluate", "--json", file]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let arcsec: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let run = axcomp(["evaluate", "--json", "--angle-unit", "arcsec", file]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert_eq!(
        serde_json::from_str::<serde_json::Value>(&run.stdout).unwrap(),
        arcsec
    );
    let run = axcomp(["evaluate", "--json", "--angle-unit", "urad", file]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let urad: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let compared = assert_urad_beside_arcsec(&arcsec, &urad, false, "");
    // 25 targets × 9 statistics, and the 12 ISO 230-2 figures at least.
    assert!(compared >= 25 * 9 + 12, "{compared}");
    let mut keys = Vec::new();
    keys_of(&urad, &mut keys);
    assert!(keys.iter().all(|k| !k.ends_with("_arcsec")), "{keys:?}");
    assert!(keys.iter().any(|k| k == "figures_urad"), "{keys:?}");
    assert!(keys.iter().any(|k| k == "mean_up_urad"), "{keys:?}");
    // One figure by hand: E = 17.33″ in the golden file → µrad.
    let e_arcsec = arcsec["figures_arcsec"]["E"].as_f64().unwrap();
    let e_urad = urad["figures_urad"]["E"].as_f64().unwrap();
    assert!((e_urad / e_arcsec - 4.848_136_811).abs() < 1e-8);

    let run = axcomp(["evaluate", "--angle-unit", "urad", file]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stdout.contains("Per target [µrad]"), "{}", run.stdout);
    assert!(run.stdout.contains("Axis figures [µrad]"), "{}", run.stdout);
    assert!(!run.stdout.contains('″'), "{}", run.stdout);
}

/// `report --angle-unit urad`: the tables, the rotary note and the plots'
/// labels say µrad, the figures are the µrad JSON's, and no ″ is left in
/// the deviation units.
#[test]
fn report_in_microradians() {
    let directory = tempfile::tempdir().unwrap();
    let html_path = directory.path().join("r.html");
    let png = directory.path().join("png");
    let run = axcomp([
        "report".as_ref(),
        "fixtures/rotary/c.csv".as_ref(),
        "--angle-unit".as_ref(),
        "urad".as_ref(),
        "-o".as_ref(),
        html_path.as_os_str(),
        "--png".as_ref(),
        png.as_os_str(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&html_path).unwrap();
    for text in [
        "ISO 230-2 figures [µrad]",
        "Per target [µrad]",
        "data-key=\"before.figures_urad.A\"",
        "data-key=\"before.per_target.0.mean_up_urad\"",
        "positional deviation [µrad]",
        "in microradians",
    ] {
        assert!(html.contains(text), "{text}");
    }
    for text in ["figures_arcsec", "_arcsec\"", "[″]", "labelled with in ″"] {
        assert!(!html.contains(text), "{text}");
    }
    // The figure A shown is the µrad figure of evaluate, to two decimals.
    let run = axcomp([
        "evaluate",
        "--json",
        "--angle-unit",
        "urad",
        "fixtures/rotary/c.csv",
    ]);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let a_urad = json["figures_urad"]["A"].as_f64().unwrap();
    assert!(
        html.contains(&format!(
            "data-key=\"before.figures_urad.A\" data-um=\"{a_urad}\">{a_urad:.2}<"
        )),
        "A = {a_urad}"
    );
    assert!(png.join("polar.png").exists());
}

/// `--angle-unit` cannot apply to a linear axis (its deviations are µm):
/// `evaluate`, `report` and `diagnose` refuse it, exit 2, saying why.
#[test]
fn angle_unit_on_a_linear_axis_is_refused() {
    let directory = tempfile::tempdir().unwrap();
    let html = directory.path().join("r.html");
    let linear = "fixtures/sample-x.rtl";
    for args in [
        vec!["evaluate", "--angle-unit", "urad", linear],
        vec!["evaluate", "--json", "--angle-unit", "arcsec", linear],
        vec![
            "report",
            linear,
            "--angle-unit",
            "urad",
            "-o",
            html.to_str().unwrap(),
        ],
        vec!["diagnose", "--after", linear, "--angle-unit", "urad"],
    ] {
        let run = axcomp(&args);
        assert_eq!(run.code, 2, "{args:?}: {}", run.stdout);
        assert!(
            run.stderr.contains("--angle-unit") && run.stderr.contains("linear axis"),
            "{args:?}: {}",
            run.stderr
        );
        assert!(run.stdout.is_empty(), "{args:?}");
    }
    assert!(!html.exists());
    let run = axcomp(["evaluate", "--angle-unit", "mrad", "fixtures/rotary/c.csv"]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.contains("arcsec, urad"), "{}", run.stderr);
}

/// `diagnose --angle-unit urad` on a rotary re-test: the same diagnosis,
/// every `_arcsec` key `_urad` with its value × π/648000·10⁶, µrad in the terminal.
#[test]
fn diagnose_in_microradians() {
    let directory = tempfile::tempdir().unwrap();
    let files = rotary_retest_files(directory.path(), (2, 3.0, 0.3), 31);
    let json_in = |unit: &str| -> serde_json::Value {
        let run = diagnose_retest(&files, &["--json", "--angle-unit", unit]);
        serde_json::from_str(&run.stdout).unwrap()
    };
    let (arcsec, urad) = (json_in("arcsec"), json_in("urad"));
    let compared = assert_urad_beside_arcsec(&arcsec, &urad, false, "");
    assert!(compared > 10, "{compared}");
    let mut keys = Vec::new();
    keys_of(&urad, &mut keys);
    assert!(keys.iter().all(|k| !k.contains("arcsec")), "{keys:?}");
    let text = diagnose_retest(&files, &["--angle-unit", "urad"]).stdout;
    assert!(text.contains("Figures [µrad]"), "{text}");
    assert!(!text.contains('″'), "{text}");
}
