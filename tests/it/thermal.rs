//! `axcomp thermal` through the binary: the real spindle log's held-out
//! figures, a synthetic truth recovered, bad logs refused.

use std::path::Path;

use serde_json::Value;

use crate::util::{axcomp, shared_data};

const REAL: &str = "thermal/data__thermal expansion error original.csv";

/// The real log's columns, read here with the standard library alone.
fn real_columns() -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(shared_data(REAL)).unwrap();
    let mut lines = text.trim_start_matches('\u{feff}').lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let mut columns = vec![Vec::new(); header.len()];
    for line in lines.filter(|l| !l.trim().is_empty()) {
        for (column, cell) in columns.iter_mut().zip(line.split(',')) {
            column.push(cell.parse::<f64>().unwrap());
        }
    }
    (header, columns)
}

/// The first-order lag written out again for the test: x₀ at the first row,
/// then y += (1 − e^(−Δt/τ))(x − y).
fn lag(values: &[f64], dt: f64, tau: f64) -> Vec<f64> {
    let mut y = values[0];
    values
        .iter()
        .map(|&x| {
            if tau > 0.0 {
                y += (1.0 - (-dt / tau).exp()) * (x - y);
            } else {
                y = x;
            }
            y
        })
        .collect()
}

fn rms_max(values: &[f64]) -> (f64, f64) {
    let rms = (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt();
    (rms, values.iter().fold(0.0, |m: f64, v| m.max(v.abs())))
}

/// The model of a model file run over the real log here, from its terms
/// (the lags starting at the first row), checked against `thermal apply
/// --json`'s `predicted_um` row by row; the held-out rms and max (rows
/// 1501–4683) of the residual from the log's own drift column.
fn held_out_recomputed(model: &toml::Table, json: &Value) -> (f64, f64) {
    let (header, columns) = real_columns();
    let column = |name: &str| &columns[header.iter().position(|h| h == name).unwrap()];
    let mut predicted = vec![0.0; columns[0].len()];
    for term in model["term"].as_array().unwrap() {
        let t = term.as_table().unwrap();
        let values = column(t["sensor"].as_str().unwrap());
        let lagged = lag(values, 60.0, t["tau_s"].as_float().unwrap());
        let c = t["coefficient_um_per_k"].as_float().unwrap();
        let reference = t["reference_c"].as_float().unwrap();
        assert_eq!(
            reference, values[0],
            "reference temperature: the first row's"
        );
        for (p, l) in predicted.iter_mut().zip(lagged) {
            *p += c * (l - reference);
        }
    }
    let from_binary: Vec<f64> = json["predicted_um"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(from_binary.len(), 4683);
    for (a, b) in predicted.iter().zip(&from_binary) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    let drift = column("delta L");
    let residual: Vec<f64> = drift
        .iter()
        .zip(&predicted)
        .map(|(d, p)| d - drift[0] - p)
        .collect();
    let (rms, max) = rms_max(&residual[1500..]);
    let after = &json["outside_fit_rows"]["after"];
    assert!((after["rms_um"].as_f64().unwrap() - rms).abs() < 1e-9);
    assert!((after["max_um"].as_f64().unwrap() - max).abs() < 1e-9);
    (rms, max)
}

fn fit_real(dir: &Path, name: &str, extra: &[&str]) -> (toml::Table, Value) {
    let model = dir.join(name);
    let log = shared_data(REAL);
    let mut args = vec!["thermal", "fit"];
    args.push(log.to_str().unwrap());
    args.extend([
        "--drift",
        "delta L",
        "--sample-interval",
        "60",
        "--rows",
        "1-1500",
        "-o",
    ]);
    args.push(model.to_str().unwrap());
    args.extend(extra);
    let fit = axcomp(&args);
    assert_eq!(fit.code, 0, "{}", fit.stderr);
    let apply = axcomp([
        "thermal",
        "apply",
        model.to_str().unwrap(),
        log.to_str().unwrap(),
        "--sample-interval",
        "60",
        "--json",
    ]);
    assert_eq!(apply.code, 0, "{}", apply.stderr);
    let toml: toml::Table = std::fs::read_to_string(&model).unwrap().parse().unwrap();
    (toml, serde_json::from_str(&apply.stdout).unwrap())
}

/// Fitted on the warm-up only (rows 1–1500, minutes 0–1499), the rest
/// (minutes 1500–4682) predicted: better than every baseline of the
/// issue (static 2.5/4.1, lagged 1.6/3.7, ridge 3.3/5.3 µm) and within the
/// goal (rms ≤ 1.5, max ≤ 3.0 µm), with the front bearing and housing
/// sensors (T0–T4: the fixed bearing, whose growth reaches the nose) as
/// rises over the table (T14: the measuring loop's other end). The model's
/// prediction is recomputed here from its file, and the residual from the
/// log's own column.
#[test]
fn real_log_held_out_beats_every_baseline() {
    let dir = tempfile::tempdir().unwrap();
    let (model, json) = fit_real(
        dir.path(),
        "front.toml",
        &["--sensors", "T0,T1,T2,T3,T4", "--reference", "T14"],
    );
    let (header, columns) = real_columns();
    let column = |name: &str| &columns[header.iter().position(|h| h == name).unwrap()];
    let (rms, max) = held_out_recomputed(&model, &json);
    let drift = column("delta L");
    // The issue and SOURCES.md state 17.37 µm (rounded): the log holds 17.371999.
    let (before_rms, before_max) = rms_max(&drift[1500..]);
    assert!(
        (before_max - 17.37).abs() < 0.005,
        "uncompensated max {before_max}"
    );
    assert!(
        rms <= 1.5 && max <= 3.0,
        "held-out rms {rms:.3} max {max:.3} µm"
    );
    for (baseline_rms, baseline_max) in [(2.5, 4.1), (1.6, 3.7), (3.3, 5.3)] {
        assert!(rms < baseline_rms && max < baseline_max);
    }
    let outside = &json["outside_fit_rows"];
    assert_eq!(outside["after"]["rows"], 3183);
    assert!((outside["after"]["rms_um"].as_f64().unwrap() - rms).abs() < 1e-9);
    assert!((outside["after"]["max_um"].as_f64().unwrap() - max).abs() < 1e-9);
    assert!((outside["before"]["rms_um"].as_f64().unwrap() - before_rms).abs() < 1e-9);
    // The model file says what it was fitted on.
    assert_eq!(model["fit"]["first_row"].as_integer(), Some(1));
    assert_eq!(model["fit"]["last_row"].as_integer(), Some(1500));
    assert_eq!(model["fit"]["reference"].as_str(), Some("T14"));
}

/// Left to choose from all 16 sensors with no reference, the same
/// cross-validation picks the rear bearing (T12), which keeps warming after
/// the warm-up while the drift falls: the held-out figures are then worse
/// than the lagged baseline. This is the limit the physical choice above
/// lifts, kept as a test so the README's statement stays true.
#[test]
fn real_log_all_sensors_extrapolate_worse() {
    let dir = tempfile::tempdir().unwrap();
    let (model, json) = fit_real(dir.path(), "all.toml", &[]);
    let sensors: Vec<&str> = model["term"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["sensor"].as_str().unwrap())
        .collect();
    assert!(sensors.contains(&"T12"), "{sensors:?}");
    let rms = json["outside_fit_rows"]["after"]["rms_um"]
        .as_f64()
        .unwrap();
    assert!(rms > 1.6, "held-out rms {rms}");
}

/// The ISO 230-3 view of the real log: the largest drift and when, and a
/// sensor's rise, against the column read here.
#[test]
fn real_log_evaluate() {
    let log = shared_data(REAL);
    let run = axcomp([
        "thermal",
        "evaluate",
        log.to_str().unwrap(),
        "--drift",
        "delta L",
        "--sample-interval",
        "60",
        "--test",
        "spindle",
        "--json",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).unwrap();
    let (header, columns) = real_columns();
    let drift = &columns[0];
    let (at, max) =
        drift.iter().enumerate().fold(
            (0, 0.0f64),
            |best, (i, &v)| if v > best.1 { (i, v) } else { best },
        );
    assert_eq!(json["max_drift_um"].as_f64(), Some(max));
    assert_eq!(json["max_drift_at_min"].as_f64(), Some(at as f64));
    assert_eq!(json["duration_min"].as_f64(), Some(4682.0));
    let t12 = &columns[header.iter().position(|h| h == "T12").unwrap()];
    let rise = t12.iter().fold(f64::MIN, |m, &v| m.max(v)) - t12[0];
    let sensor = &json["sensors"][12];
    assert_eq!(sensor["name"], "T12");
    assert!((sensor["max_rise_k"].as_f64().unwrap() - rise).abs() < 1e-12);
}

/// A synthetic log from a known truth (the drift 1.2 µm/K of "bearing"
/// lagged 40 min and −3 µm/K of "air" lagged 320 min, noise 0.3 µm): fitted
/// on the first 60 % of the rows, the truth's sensors are the ones chosen,
/// each time constant within a factor of two of the truth's, and the
/// held-out rms within twice the noise, for several seeds.
#[test]
fn synthetic_truth_recovered() {
    recover_synthetic_truth(&[]);
}

/// The same truth recovered by the automatic choice (`--reference auto
/// --validation late`): the truth is no rise over one sensor (its two
/// coefficients do not cancel), and the late validation prefers no
/// reference to the coldest sensor (the air), as it should.
#[test]
fn synthetic_truth_recovered_automatically() {
    recover_synthetic_truth(&["--reference", "auto", "--validation", "late"]);
}

fn recover_synthetic_truth(extra: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    for seed in ["1", "2", "3"] {
        let log = dir.path().join(format!("log{seed}.csv"));
        let model = dir.path().join(format!("model{seed}.toml"));
        let synth = axcomp(["synth", "--thermal", log.to_str().unwrap(), "--seed", seed]);
        assert_eq!(synth.code, 0, "{}", synth.stderr);
        let mut args = vec![
            "thermal",
            "fit",
            log.to_str().unwrap(),
            "--drift",
            "drift",
            "--rows",
            "1-2592",
            "-o",
            model.to_str().unwrap(),
        ];
        args.extend(extra);
        let fit = axcomp(&args);
        assert_eq!(fit.code, 0, "{}", fit.stderr);
        let toml: toml::Table = std::fs::read_to_string(&model).unwrap().parse().unwrap();
        let mut found: Vec<(String, f64)> = toml["term"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| {
                (
                    t["sensor"].as_str().unwrap().to_string(),
                    t["tau_s"].as_float().unwrap(),
                )
            })
            .collect();
        found.sort_by(|a, b| a.0.cmp(&b.0));
        let names: Vec<&str> = found.iter().map(|f| f.0.as_str()).collect();
        assert_eq!(names, ["air", "bearing"], "seed {seed}: {found:?}");
        assert_eq!(toml["fit"].get("reference"), None, "seed {seed}");
        for ((_, tau), truth) in found.iter().zip([19_200.0, 2_400.0]) {
            assert!(
                *tau >= truth / 2.0 && *tau <= truth * 2.0,
                "seed {seed}: {found:?}"
            );
        }
        let apply = axcomp([
            "thermal",
            "apply",
            model.to_str().unwrap(),
            log.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(apply.code, 0, "{}", apply.stderr);
        let json: Value = serde_json::from_str(&apply.stdout).unwrap();
        let rms = json["outside_fit_rows"]["after"]["rms_um"]
            .as_f64()
            .unwrap();
        assert!(rms <= 2.0 * 0.3, "seed {seed}: held-out rms {rms}");
    }
}

/// Bad logs are refused with exit 2 and the file, line and column.
#[test]
fn bad_logs_refused_at_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "backwards.csv",
            "time [s],d,T1\n0,0,20\n60,0.1,20.1\n30,0.2,20.2\n",
            "4:1",
        ),
        (
            "gap.csv",
            "time [min],d,T1\n0,0,20\n1,0.1,20.1\n2,0.1,20.1\n9,0.2,20.2\n",
            "5:1",
        ),
        ("word.csv", "time [s],d,T1\n0,0,20\n60,0.1,warm\n", "3:8"),
        ("short.csv", "time [s],d,T1\n0,0,20\n60,0.1\n", "3:7"),
        ("hot.csv", "time [s],d,T1 [K]\n0,0,20\n60,0.1,20\n", "2:5"),
        ("blank.csv", "time [s],d,T1\n0,0,20\n\n60,0.1,20\n", "3:1"),
        ("nodrift.csv", "time [s],x,T1\n0,0,20\n60,0.1,20\n", "1:1"),
        ("notime.csv", "d,T1\n0,20\n0.1,20\n", "1:1"),
        ("unit.csv", "time,d,T1\n0,0,20\n60,0.1,20\n", "1:1"),
    ];
    for (name, text, at) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let run = axcomp([
            "thermal",
            "evaluate",
            path.to_str().unwrap(),
            "--drift",
            "d",
        ]);
        assert_eq!(run.code, 2, "{name}: {}", run.stderr);
        let expected = format!("{}:{at}: ", path.display());
        assert!(run.stderr.contains(&expected), "{name}: {}", run.stderr);
    }
}

/// A model file with a key the reader does not know is refused at its line.
#[test]
fn model_file_unknown_key_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (_, _) = fit_real(
        dir.path(),
        "m.toml",
        &["--sensors", "T0", "--max-sensors", "1"],
    );
    let path = dir.path().join("m.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("[[term]]\n", "[[term]]\ngain = 2\n");
    std::fs::write(&path, text.as_bytes()).unwrap();
    let line = text.lines().position(|l| l == "gain = 2").unwrap() + 1;
    let log = shared_data(REAL);
    let run = axcomp([
        "thermal",
        "apply",
        path.to_str().unwrap(),
        log.to_str().unwrap(),
        "--sample-interval",
        "60",
    ]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr
            .contains(&format!("m.toml:{line}:1: unknown field `gain`")),
        "{}",
        run.stderr
    );
}

/// A thermal log of a re-test: `time [min]`, one sensor `T` rising
/// `k_per_h` K/h from 20 °C, a row a minute for `hours`.
fn rising_log(k_per_h: f64, hours: usize) -> String {
    let mut text = String::from("time [min],T1 [°C]\n");
    for minute in 0..=hours * 60 {
        text.push_str(&format!(
            "{minute},{}\n",
            20.0 + k_per_h * minute as f64 / 60.0
        ));
    }
    text
}

/// A model of one unlagged term: `c` µm/K of `T1` from 20 °C.
fn one_term_model(c: f64) -> String {
    format!(
        "[fit]\ndrift = \"d\"\nfirst_row = 1\nlast_row = 10\nfrom_s = 0.0\nto_s = 540.0\ncandidates = [\"T1\"]\nblocks = 5\ncv_rms_um = 0.1\nfit_rms_um = 0.1\n\n[[term]]\nsensor = \"T1\"\ntau_s = 0.0\ncoefficient_um_per_k = {c}\nreference_c = 20.0\n"
    )
}

/// The demo's re-test warms up (its truth: a drift of 4 µm/h). With a log
/// of the re-test whose sensor rises 0.2 K/h and a model of 15 µm/K, the
/// temperatures explain 15 × 0.2 = 3 µm/h of it (by hand); the share is
/// that over the drift found, in the JSON and on the terminal.
#[test]
fn diagnose_says_how_much_of_the_drift_the_log_explains() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("retest-thermal.csv");
    let model = dir.path().join("model.toml");
    std::fs::write(&log, rising_log(0.2, 6)).unwrap();
    std::fs::write(&model, one_term_model(15.0)).unwrap();
    let demo = crate::util::root().join("fixtures/demo");
    let base = |json: bool| {
        let mut args: Vec<String> = [
            "diagnose",
            "--before",
            demo.join("before.rtl").to_str().unwrap(),
            "--after",
            demo.join("after.rtl").to_str().unwrap(),
            "--table",
            demo.join("X.COM").to_str().unwrap(),
            "--thermal",
            log.to_str().unwrap(),
            "--thermal-model",
            model.to_str().unwrap(),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        if json {
            args.push("--json".to_string());
        }
        axcomp(&args)
    };
    let run = base(true);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).unwrap();
    let thermal = &json["thermal"];
    let found = thermal["found_um_per_h"].as_f64().unwrap();
    let explained = thermal["explained_um_per_h"].as_f64().unwrap();
    assert!((found - 4.0).abs() < 0.4, "found {found}");
    assert!((explained - 3.0).abs() < 1e-9, "explained {explained}");
    let share = thermal["share"].as_f64().unwrap();
    assert!((share - explained / found).abs() < 1e-12);
    let text = base(false);
    assert_eq!(text.code, 0, "{}", text.stderr);
    let percent = format!("is {:.0} % explained", 100.0 * share);
    assert!(text.stdout.contains(&percent), "{}", text.stdout);
    // A log shorter than the re-test is said, not stretched.
    std::fs::write(&log, rising_log(0.2, 0) + "1,20.0\n").unwrap();
    let short = base(true);
    assert_eq!(short.code, 0, "{}", short.stderr);
    let json: Value = serde_json::from_str(&short.stdout).unwrap();
    let why = json["thermal"]["text"].as_str().unwrap();
    assert!(why.contains("the thermal log covers 1.0 min"), "{why}");
    assert!(json["thermal"].get("share").is_none());
}

/// `report --thermal` with a model: the thermal section, before the
/// signatures, with the held-out figures `thermal apply --json` gives
/// (the same values, full precision in data-um) and the two plots.
#[test]
fn report_has_the_thermal_section() {
    let dir = tempfile::tempdir().unwrap();
    let (_, json) = fit_real(
        dir.path(),
        "front.toml",
        &["--sensors", "T0,T1,T2,T3,T4", "--reference", "T14"],
    );
    let out = dir.path().join("report.html");
    let sample = crate::util::root().join("fixtures/sample-x.rtl");
    let run = axcomp([
        "report",
        sample.to_str().unwrap(),
        "--thermal",
        shared_data(REAL).to_str().unwrap(),
        "--thermal-sample-interval",
        "60",
        "--thermal-model",
        dir.path().join("front.toml").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&out).unwrap();
    let section = html
        .find("<section id=\"thermal\">")
        .expect("thermal section");
    let signatures = html.find("<section id=\"signatures\"").unwrap();
    assert!(section < signatures);
    let thermal = &html[section..signatures];
    assert_eq!(thermal.matches("<svg ").count(), 2);
    for key in ["after.rms_um", "after.max_um", "before.max_um"] {
        let (part, name) = key.split_once('.').unwrap();
        let expected = json["outside_fit_rows"][part][name].as_f64().unwrap();
        let cell = format!("data-key=\"thermal.outside_fit_rows.{key}\" data-um=\"{expected}\"");
        assert!(thermal.contains(&cell), "{cell}");
    }
    // A bad log is refused at its line and column, and no report is written.
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "time [s],d,T1\n0,0,20\n60,0.1,warm\n").unwrap();
    let out2 = dir.path().join("report2.html");
    let run = axcomp([
        "report",
        sample.to_str().unwrap(),
        "--thermal",
        bad.to_str().unwrap(),
        "--thermal-drift",
        "d",
        "-o",
        out2.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(&format!("{}:3:8: ", bad.display())),
        "{}",
        run.stderr
    );
    assert!(!out2.exists());
}

/// The web app's thermal page (in process): the real log uploaded with the physical
/// sensor set fitted on the warm-up shows the same model and held-out
/// figures as `thermal fit` and `thermal apply --json` (one piece of work
/// behind both); a bad log is a 400 naming its line and column.
#[test]
fn web_thermal_page_fits_as_the_cli_does() {
    use crate::http::Form;
    let dir = tempfile::tempdir().unwrap();
    let (model, json) = fit_real(
        dir.path(),
        "front.toml",
        &["--sensors", "T0,T1,T2,T3,T4", "--reference", "T14"],
    );
    let app = crate::server::App::new();
    let get = app.get("/thermal", &[]);
    assert_eq!(get.status, 200);
    assert!(get.text().contains("name=\"log\""));
    let index = app.get("/", &[]);
    assert!(index.text().contains("<a href=\"/thermal\">"));
    let log = std::fs::read(shared_data(REAL)).unwrap();
    let form = Form::new()
        .file("log", "spindle.csv", &log)
        .text("drift", "delta L")
        .text("sample_interval", "60")
        .text("rows", "1-1500")
        .text("sensors", "T0,T1,T2,T3,T4")
        .text("reference", "T14");
    let answer = app.post("/thermal", form, &[]);
    assert_eq!(answer.status, 200, "{}", answer.text());
    let page = answer.text();
    let expected = json["outside_fit_rows"]["after"]["rms_um"]
        .as_f64()
        .unwrap();
    assert!(
        page.contains(&format!(
            "data-key=\"thermal.outside_fit_rows.after.rms_um\" data-um=\"{expected}\""
        )),
        "held-out rms {expected} not on the page"
    );
    for term in model["term"].as_array().unwrap() {
        let row = format!(
            "<tr><th>{}</th><td class=\"num\">{:.0}</td><td class=\"num\">{:+.3}</td>",
            term["sensor"].as_str().unwrap(),
            term["tau_s"].as_float().unwrap() / 60.0,
            term["coefficient_um_per_k"].as_float().unwrap()
        );
        assert!(page.contains(&row), "{row}");
    }
    assert_eq!(page.matches("<svg ").count(), 2);
    let bad = Form::new()
        .file("log", "bad.csv", b"time [s],d,T1\n0,0,20\n60,0.1,warm\n")
        .text("drift", "d");
    let refused = app.post("/thermal", bad, &[]);
    assert_eq!(refused.status, 400);
    assert!(
        refused.text().contains("bad.csv:3:8: "),
        "{}",
        refused.text()
    );
}

/// The automatic choice, with no sensor named (`--reference auto
/// --validation late`), fitted on the warm-up only: the reference is the
/// coldest sensor on average over rows 1–1500 (the table T14, found here
/// from the raw columns), the coefficients of the rises over it share the
/// drift's sign, and the last third of the warm-up is predicted from the rows
/// before it. It takes the front housing's end face T1 (lag 160 min) over
/// the table (lag 640 min): held out (minutes 1500–4682), recomputed here
/// from the model file, rms 0.66 µm and max 1.83 µm, within the goal
/// (1.5/3.0) and better than every baseline. The model file records the
/// validation.
#[test]
fn real_log_automatic_reference() {
    let dir = tempfile::tempdir().unwrap();
    let (model, json) = fit_real(
        dir.path(),
        "auto.toml",
        &["--reference", "auto", "--validation", "late"],
    );
    let (header, columns) = real_columns();
    let mean = |k: usize| columns[k][..1500].iter().sum::<f64>() / 1500.0;
    let coldest = (1..header.len())
        .min_by(|&a, &b| mean(a).total_cmp(&mean(b)))
        .unwrap();
    assert_eq!(header[coldest], "T14");
    assert_eq!(model["fit"]["reference"].as_str(), Some("T14"));
    assert_eq!(model["fit"]["validation"].as_str(), Some("late"));
    let terms: Vec<(&str, f64, f64)> = model["term"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            (
                t["sensor"].as_str().unwrap(),
                t["tau_s"].as_float().unwrap() / 60.0,
                t["coefficient_um_per_k"].as_float().unwrap(),
            )
        })
        .collect();
    assert_eq!(terms.len(), 2, "{terms:?}");
    assert_eq!((terms[0].0, terms[0].1), ("T1", 160.0), "{terms:?}");
    assert_eq!((terms[1].0, terms[1].1), ("T14", 640.0), "{terms:?}");
    assert!(terms[0].2 > 0.0 && (terms[0].2 + terms[1].2).abs() < 1e-12);
    let (rms, max) = held_out_recomputed(&model, &json);
    assert_eq!(
        (format!("{rms:.2}"), format!("{max:.2}")),
        ("0.66".to_string(), "1.83".to_string())
    );
    assert!(rms <= 1.5 && max <= 3.0);
    for (baseline_rms, baseline_max) in [(2.5, 4.1), (1.6, 3.7), (3.3, 5.3)] {
        assert!(rms < baseline_rms && max < baseline_max);
    }
}
