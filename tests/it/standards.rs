//! `--standard` (issue 13): VDI/DGQ 3441 and the ±3s forms of ISO 230-2:1988
//! and JIS B 6192 against an independent computation, written here from the
//! formulas of `../shared/spec/standards.md` §2–3, on the ecmc test-report
//! data (5 targets × 5 cycles each way). The readings come from the reader;
//! everything after that is computed in this file.

use approx::abs_diff_eq;
use serde_json::Value;

use axcomp::measurement::Direction;
use axcomp::read;

use crate::util::{axcomp, root};

const ECMC: &str =
    "../shared/data/ecmc/ecmccfg/examples__ESS__mcu1025_fat_sat__report.md_ISO230.dat";
const TOLERANCE_UM: f64 = 0.005;

/// Per target: (x̄↑, x̄↓, s↑, s↓) in µm, with the n − 1 divisor.
fn cells() -> Vec<(f64, f64, f64, f64)> {
    cells_of(std::path::Path::new(ECMC))
}

/// The same of any file.
fn cells_of(path: &std::path::Path) -> Vec<(f64, f64, f64, f64)> {
    let measurement = read::read_path(path, None).unwrap().measurement;
    let stats = |direction: Direction, index: usize| {
        let values: Vec<f64> = measurement
            .runs_in(direction)
            .filter_map(|run| run.deviations[index])
            .map(|mm| mm * 1000.0)
            .collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let s = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        (mean, s)
    };
    (0..measurement.targets().len())
        .map(|i| {
            let (up, s_up) = stats(Direction::Up, i);
            let (down, s_down) = stats(Direction::Down, i);
            (up, down, s_up, s_down)
        })
        .collect()
}

fn figures(standard: &str) -> Value {
    let run = axcomp(["evaluate", ECMC, "--json", "--standard", standard]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["standard"], standard);
    json
}

fn close(json: &Value, key: &str, expected: f64) {
    let found = json["figures_um"][key].as_f64().unwrap_or(f64::NAN);
    assert!(
        abs_diff_eq!(found, expected, epsilon = TOLERANCE_UM),
        "{key}: axcomp {found} µm, independent {expected} µm"
    );
}

fn max(values: impl Iterator<Item = f64>) -> f64 {
    values.fold(f64::NEG_INFINITY, f64::max)
}

fn min(values: impl Iterator<Item = f64>) -> f64 {
    values.fold(f64::INFINITY, f64::min)
}

#[test]
fn vdi_3441_matches_the_spec_formulas() {
    let cells = cells();
    let json = figures("vdi3441");
    assert_eq!(json["definitions_reconstructed"], true);
    let keys: Vec<&str> = json["figures_um"]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(keys, ["P", "Pa", "Ps_max", "Ps_mean", "U_max", "U_mean"]);
    // U_i = |x̄↑ − x̄↓|, Ps_i = 6·(s↑ + s↓)/2, x̄_i = (x̄↑ + x̄↓)/2.
    let u = |c: &(f64, f64, f64, f64)| (c.0 - c.1).abs();
    let ps = |c: &(f64, f64, f64, f64)| 6.0 * (c.2 + c.3) / 2.0;
    let mean = |c: &(f64, f64, f64, f64)| (c.0 + c.1) / 2.0;
    let m = cells.len() as f64;
    close(&json, "U_max", max(cells.iter().map(u)));
    close(&json, "U_mean", cells.iter().map(u).sum::<f64>() / m);
    close(&json, "Ps_max", max(cells.iter().map(ps)));
    close(&json, "Ps_mean", cells.iter().map(ps).sum::<f64>() / m);
    close(
        &json,
        "Pa",
        max(cells.iter().map(mean)) - min(cells.iter().map(mean)),
    );
    let p = max(cells.iter().map(|c| mean(c) + (u(c) + ps(c)) / 2.0))
        - min(cells.iter().map(|c| mean(c) - (u(c) + ps(c)) / 2.0));
    close(&json, "P", p);
}

#[test]
fn the_plus_minus_3s_forms_match_the_spec_formulas() {
    let cells = cells();
    for standard in ["iso230-2:1988", "jis-b6192"] {
        let json = figures(standard);
        assert_eq!(json["definitions_reconstructed"], true, "{standard}");
        // R_i↑ = 6s↑; R_i = max(3s↑ + 3s↓ + |B_i|, 6s↑, 6s↓); A from x̄ ± 3s.
        let r_i = |c: &(f64, f64, f64, f64)| {
            (3.0 * c.2 + 3.0 * c.3 + (c.0 - c.1).abs())
                .max(6.0 * c.2)
                .max(6.0 * c.3)
        };
        close(&json, "R", max(cells.iter().map(r_i)));
        close(&json, "R_up", max(cells.iter().map(|c| 6.0 * c.2)));
        close(&json, "R_down", max(cells.iter().map(|c| 6.0 * c.3)));
        let high = max(cells
            .iter()
            .flat_map(|c| [c.0 + 3.0 * c.2, c.1 + 3.0 * c.3]));
        let low = min(cells
            .iter()
            .flat_map(|c| [c.0 - 3.0 * c.2, c.1 - 3.0 * c.3]));
        close(&json, "A", high - low);
        // E, M and B do not change with k.
        let e =
            max(cells.iter().flat_map(|c| [c.0, c.1])) - min(cells.iter().flat_map(|c| [c.0, c.1]));
        close(&json, "E", e);
        close(&json, "B", max(cells.iter().map(|c| (c.0 - c.1).abs())));
    }
}

#[test]
fn the_iso_editions_give_the_same_figures_and_name_themselves() {
    let reference = figures("iso230-2:2014");
    assert_eq!(reference["definitions_reconstructed"], false);
    for standard in ["iso230-2:2006", "iso230-2:1997", "gb/t17421.2"] {
        let json = figures(standard);
        assert_eq!(json["figures_um"], reference["figures_um"], "{standard}");
        assert_eq!(json["definitions_reconstructed"], false);
    }
    assert!(
        figures("gb/t17421.2")["standard_name"]
            .as_str()
            .unwrap()
            .contains("identical adoption of ISO 230-2:1997")
    );
}

#[test]
fn a_standard_without_established_definitions_is_refused() {
    for name in ["asme-b5.54", "nmtba"] {
        let run = axcomp(["evaluate", ECMC, "--standard", name]);
        assert_eq!(run.code, 2, "{name}");
        assert!(run.stderr.contains("is not supported"), "{}", run.stderr);
        assert!(run.stderr.contains("vdi3441, ") || run.stderr.contains("vdi3441"));
        assert!(run.stderr.contains("iso230-2:1988"));
    }
}

/// `axcomp ARGS… --json`, exit 0, parsed.
fn json_of(args: &[&str]) -> Value {
    let run = axcomp(args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    serde_json::from_str(&run.stdout).unwrap()
}

/// The value of `data-key="KEY"`'s `data-um` in a report, µm.
fn data_um(html: &str, key: &str) -> Option<f64> {
    let (_, rest) = html.split_once(&format!("data-key=\"{key}\" data-um=\""))?;
    rest.split('"').next()?.parse().ok()
}

/// `predict`, `diagnose` and `report` with `--standard`: the predicted
/// re-test's figures under the standard's keys, computed here from
/// predict's per-target predicted means and the first test's s (the
/// predicted re-test keeps the first test's scatter), and the same numbers
/// in the three outputs.
#[test]
fn predict_diagnose_and_report_give_the_standards_figures_of_one_prediction() {
    let sample = root().join("fixtures/demo/before.rtl");
    let sample = sample.to_str().unwrap();
    let retest = root().join("fixtures/demo/after.rtl");
    let retest = retest.to_str().unwrap();
    let directory = tempfile::tempdir().unwrap();
    let table = directory.path().join("X.COM");
    let table = table.to_str().unwrap();
    let run = axcomp([
        "convert",
        sample,
        "--controller",
        "tnc640",
        "-o",
        table,
        "-q",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let cells = cells_of(std::path::Path::new(sample));
    for standard in ["vdi3441", "iso230-2:1988", "iso230-2:2014"] {
        let with = ["--table", table, "--standard", standard];
        let predict = json_of(&[&["predict", "--measured", sample, "--json"], &with[..]].concat());
        assert_eq!(predict["standard"], standard);
        // (x̄↑, x̄↓, s↑, s↓) of the predicted re-test, µm.
        let predicted: Vec<(f64, f64, f64, f64)> = predict["per_target"]
            .as_array()
            .unwrap()
            .iter()
            .zip(&cells)
            .map(|(t, c)| {
                let up = t["predicted_up_um"].as_f64().unwrap();
                let down = t["predicted_down_um"].as_f64().unwrap();
                (up, down, c.2, c.3)
            })
            .collect();
        let figures = &predict["predicted_figures_um"];
        let check = |key: &str, expected: f64| {
            let found = figures[key].as_f64().unwrap_or(f64::NAN);
            assert!(
                abs_diff_eq!(found, expected, epsilon = TOLERANCE_UM),
                "{standard} {key}: axcomp {found} µm, independent {expected} µm"
            );
        };
        let mean = |c: &(f64, f64, f64, f64)| (c.0 + c.1) / 2.0;
        if standard == "vdi3441" {
            let keys: Vec<&String> = figures.as_object().unwrap().keys().collect();
            assert_eq!(keys, ["P", "Pa", "Ps_max", "Ps_mean", "U_max", "U_mean"]);
            let u = |c: &(f64, f64, f64, f64)| (c.0 - c.1).abs();
            let ps = |c: &(f64, f64, f64, f64)| 6.0 * (c.2 + c.3) / 2.0;
            check("U_max", max(predicted.iter().map(u)));
            check("Ps_max", max(predicted.iter().map(ps)));
            check(
                "Pa",
                max(predicted.iter().map(mean)) - min(predicted.iter().map(mean)),
            );
            check(
                "P",
                max(predicted.iter().map(|c| mean(c) + (u(c) + ps(c)) / 2.0))
                    - min(predicted.iter().map(|c| mean(c) - (u(c) + ps(c)) / 2.0)),
            );
        } else {
            let k = if standard == "iso230-2:1988" {
                3.0
            } else {
                2.0
            };
            let high = max(predicted
                .iter()
                .flat_map(|c| [c.0 + k * c.2, c.1 + k * c.3]));
            let low = min(predicted
                .iter()
                .flat_map(|c| [c.0 - k * c.2, c.1 - k * c.3]));
            check("A", high - low);
            check("R_up", max(predicted.iter().map(|c| 2.0 * k * c.2)));
        }
        // Without the table the prediction on the measured line is the
        // measurement: evaluate's figures under the same standard.
        let evaluated = json_of(&["evaluate", sample, "--standard", standard, "--json"]);
        for (key, value) in evaluated["figures_um"].as_object().unwrap() {
            let before = predict["figures_before_um"][key].as_f64().unwrap();
            assert!(
                abs_diff_eq!(before, value.as_f64().unwrap(), epsilon = 1e-6),
                "{standard} {key}"
            );
        }
        // diagnose's predicted figures and the report's are predict's.
        let diagnose = json_of(
            &[
                &[
                    "diagnose", "--after", retest, "--before", sample, "--json", "-q",
                ],
                &with[..],
            ]
            .concat(),
        );
        assert_eq!(diagnose["standard"], standard);
        let output = directory
            .path()
            .join(format!("{}.html", standard.replace(':', "-")));
        let run = axcomp(
            [
                &["report", sample, "-o", output.to_str().unwrap(), "-q"],
                &with[..],
            ]
            .concat(),
        );
        assert_eq!(run.code, 0, "{}", run.stderr);
        let html = std::fs::read_to_string(&output).unwrap();
        for (key, value) in figures.as_object().unwrap() {
            let value = value.as_f64().unwrap();
            let diagnosed = diagnose["figures_um"]["predicted"][key].as_f64().unwrap();
            assert!(
                abs_diff_eq!(diagnosed, value, epsilon = 1e-6),
                "{standard} {key}: diagnose {diagnosed}, predict {value}"
            );
            // The report names A, E and B of ISO 230-2, every figure of another standard.
            if standard == "vdi3441" || ["A", "E", "B"].contains(&key.as_str()) {
                let shown =
                    data_um(&html, &format!("prediction.figures_um.{key}")).unwrap_or_else(|| {
                        panic!("{standard}: no prediction.figures_um.{key} in the report")
                    });
                assert!(
                    abs_diff_eq!(shown, value, epsilon = 1e-6),
                    "{standard} {key}: report {shown}, predict {value}"
                );
            }
        }
    }
}

/// The report names the chosen standard with its coverage, shows VDI's own
/// table and says the definitions are reconstructed; every number it shows
/// is the one in its embedded JSON (the ISO table of a VDI report under
/// `figures_iso230_2_um`); the `system` target renders it in Chromium.
#[test]
fn the_report_names_the_chosen_standard() {
    use crate::report::{check_against_json, embedded_data};

    let directory = tempfile::tempdir().unwrap();
    for (standard, names, vdi_table) in [
        (
            "iso230-2:1988",
            "ISO 230-2:1988 (±3s), test of accuracy and repeatability of positioning of numerically controlled axes; A and R with the coverage of that edition (x̄ ± 3s, R = 6s)",
            false,
        ),
        (
            "vdi3441",
            "VDI/DGQ 3441 (1977): P, Pa, Ps and U of each direction",
            true,
        ),
    ] {
        let page = directory
            .path()
            .join(format!("{}.html", standard.replace([':', '/'], "-")));
        let run = axcomp([
            "report",
            "fixtures/demo/before.rtl",
            "--after",
            "fixtures/demo/after.rtl",
            "--standard",
            standard,
            "-o",
            page.to_str().unwrap(),
        ]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        let html = std::fs::read_to_string(&page).unwrap();
        assert!(
            html.contains(names),
            "{standard}: the header does not say {names:?}"
        );
        assert!(
            html.contains("Definitions reconstructed from public sources"),
            "{standard}: no reconstructed note"
        );
        assert_eq!(
            html.contains("VDI/DGQ 3441 (1977) figures [µm]"),
            vdi_table,
            "{standard}"
        );
        let data = embedded_data(&html);
        assert_eq!(data["before"]["standard"], standard);
        let checked = check_against_json(&html, "before", &data["before"])
            + check_against_json(&html, "after", &data["after"]);
        assert!(checked > 20, "{standard}: only {checked} values checked");
        if vdi_table {
            // P of both tests, under VDI's key, and the ISO table beside it.
            assert!(html.contains("data-key=\"before.figures_um.P\""));
            assert!(html.contains("data-key=\"after.figures_iso230_2_um.A\""));
        }
    }
}
