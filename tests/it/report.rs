//! `axcomp report` end to end (issue 7): the report's numbers are those of
//! `evaluate --json` and of the library's `Diagnosis`; the page opens in a
//! real browser (Debian's chromium, headless) without console messages and
//! is not blank; it prints on A4; its PNG plots decode and every character
//! they draw is in the embedded font; bad input fails with exit code 2.
//!
//! Screenshots and PDFs are kept under `target/tmp/report/` (not in git).

use std::path::Path;

use axcomp::diagnose::Diagnosis;
use axcomp::effects::ParameterValue;
use axcomp::emit;
use axcomp::evaluate::{ISO_230_2, evaluate};
use axcomp::read::read_path;
use axcomp::report::acceptance::{ReportInput, TableRecord, TestRecord, charts};

pub(crate) use crate::page::{check_against_json, embedded_data, keyed_values};
use crate::pixels::{Pixels, artefacts};
use crate::retest_case::{RetestCase, table_options};
use crate::util::{axcomp, evaluate_json, test_data};

const SAMPLE: &str = "fixtures/sample-x.rtl";

#[test]
fn the_sample_report_shows_the_figures_of_evaluate_json() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("report.html");
    let run = axcomp(["report", SAMPLE, "-o", output.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&output).unwrap();
    let evaluation = evaluate_json(&[Path::new(SAMPLE)]);
    // 12 axis figures, 9 values at each of the 16 targets, U and the 5
    // contributors of the budget, each equal to evaluate's.
    assert_eq!(
        check_against_json(&html, "before", &evaluation),
        12 + 16 * 9 + 1 + 5
    );
    assert_eq!(embedded_data(&html)["before"], evaluation);
    // The figures of the README (computed by evaluate, checked there by hand).
    for (key, text) in [
        ("A", "13.19"),
        ("E", "11.21"),
        ("R", "6.26"),
        ("M", "8.06"),
        ("B", "3.44"),
    ] {
        let cell = format!("data-key=\"before.figures_um.{key}\"");
        let at = html.find(&cell).unwrap();
        assert!(
            html[at..]
                .split('<')
                .next()
                .unwrap()
                .ends_with(&format!(">{text}")),
            "{key}"
        );
        // U beside E, M and A as the terminal writes it (`13.19 ± 1.82`),
        // evaluate's uncertainty_um; nothing beside R and B.
        let cell_text = &html[at..at + html[at..].find("</td>").unwrap()];
        match evaluation["uncertainty_um"][key].as_f64() {
            Some(u) if ["A", "E", "M"].contains(&key) => assert!(
                cell_text.ends_with(&format!(" ± {u:.2}</span>")),
                "{key}: {cell_text}"
            ),
            _ => assert!(!cell_text.contains('±'), "{key}: {cell_text}"),
        }
    }
    assert!(html.contains(
        ">13.19<span class=\"u\" title=\"expanded uncertainty U (k = 2)\"> ± 1.82</span>"
    ));
    // The refractive index check, recomputed in Python from seed 001 eq. 36:
    // at the start 20.412 °C, 987.12 mbar, 41.3 %RH give n − 1 = 264.0751 ppm;
    // the factor 0.31641106 µm with λ 0.632991 µm and the material correction
    // 11.7 ppm/K · (20.2395 − 20) K gives 264.0652 ppm: −0.0100 ppm, the
    // rounding of the factor's 8 decimals. The report says the two agree.
    let ppm: f64 = html
        .split("data-ppm=\"")
        .nth(1)
        .and_then(|rest| rest.split('"').next())
        .unwrap()
        .parse()
        .unwrap();
    assert!((ppm + 0.009_99).abs() < 1e-4, "{ppm}");
    assert!(!html.contains("differs by more than 1 ppm"));
    assert!(html.contains("agrees (within ±1 ppm)"));
    assert!(html.contains("X axis as found, before compensation"));
    // Self-contained: nothing is fetched.
    for external in ["src=\"http", "href=\"http", "@import", "url(http"] {
        assert!(!html.contains(external), "{external}");
    }
}

/// The diagnosis values the report keys, from the library.
fn diagnosis_json(d: &Diagnosis) -> serde_json::Value {
    let figures = |f: &axcomp::evaluate::AxisFigures| {
        let json = axcomp::report::json::FiguresJson::of_linear(&f.typed(d.kind));
        serde_json::to_value(json).unwrap()
    };
    let accepted: Vec<serde_json::Value> = d
        .accepted
        .iter()
        .map(|a| {
            let map: serde_json::Map<String, serde_json::Value> = a
                .effect
                .parameters()
                .into_iter()
                .map(|p| {
                    let v = match p.value {
                        ParameterValue::Number(v) => v,
                        ParameterValue::Run(run) => f64::from(run),
                    };
                    (p.key.to_string(), serde_json::json!(v))
                })
                .collect();
            serde_json::Value::Object(map)
        })
        .collect();
    serde_json::json!({
        "residual_before": {"rms_um": d.residual_before.rms, "max_abs_um": d.residual_before.max_abs},
        "residual_after": {"rms_um": d.residual_after.rms, "max_abs_um": d.residual_after.max_abs},
        "noise_um": d.noise,
        "figures": {
            "measured": figures(&d.figures.measured),
            "predicted": figures(&d.figures.predicted),
            "predicted_with_effects": figures(&d.figures.predicted_with_effects),
        },
        "accepted": accepted,
    })
}

#[test]
fn the_retest_report_shows_evaluate_and_diagnose_numbers_and_writes_pngs() {
    let case = RetestCase::new();
    let png = case.directory.path().join("png");
    let (output, run) = case.report(&["--png", png.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&output).unwrap();
    let before = evaluate_json(&[&case.before]);
    let after = evaluate_json(&[&case.after]);
    assert_eq!(check_against_json(&html, "before", &before), 12 + 16 * 9);
    // The re-test, being accepted, also has its U and 5 budget rows.
    assert_eq!(
        check_against_json(&html, "after", &after),
        12 + 16 * 9 + 1 + 5
    );
    let data = embedded_data(&html);
    assert_eq!((&data["before"], &data["after"]), (&before, &after));

    let diagnosis = case.diagnosis();
    let kinds: Vec<&str> = diagnosis
        .accepted
        .iter()
        .map(|a| a.effect.kind().name())
        .collect();
    assert_eq!(
        kinds,
        ["reversal", "drift"],
        "the truth has both after the first test"
    );
    // 5 residual values, 3 × 6 figures, and the reversal's B (drift has no µm parameter).
    assert_eq!(
        check_against_json(&html, "diagnosis", &diagnosis_json(&diagnosis)),
        5 + 18 + 1
    );
    // Every reading is kept, and the fitted model is what residual_after measures.
    let after_measurement = read_path(&case.after, None).unwrap().measurement;
    let readings: usize = after_measurement
        .runs()
        .iter()
        .map(|r| r.deviations.iter().flatten().count())
        .sum();
    assert_eq!(diagnosis.readings.len(), readings);
    let rms = (diagnosis
        .readings
        .iter()
        .map(|r| (r.residual - r.fitted).powi(2))
        .sum::<f64>()
        / readings as f64)
        .sqrt();
    assert!((rms - diagnosis.residual_after.rms).abs() < 1e-9, "{rms}");
    // Text from the file is escaped: the machine name has <, & and ".
    assert!(html.contains("MCV 754 Quick &lt;test &amp; &quot;escape&quot;&gt;"));
    assert!(!html.contains("<test &"));

    let names = [
        "deviation-before",
        "deviation-after",
        "table",
        "predicted",
        "residual",
        "residual-along-axis",
        "effects",
    ];
    for name in names {
        let path = png.join(format!("{name}.png"));
        let pixels = Pixels::read(&path);
        let coloured = pixels.inked();
        assert_eq!(pixels.size, (960, 600), "{name}");
        assert!(
            coloured > 0.01,
            "{name}: {coloured} of the pixels are not white"
        );
        assert!(
            html.contains(&format!("id=\"plot-{name}\"")),
            "{name} in the HTML"
        );
    }
}

#[test]
fn every_character_the_plots_draw_is_in_the_embedded_font() {
    use ab_glyph::{Font, FontRef};
    let font = FontRef::try_from_slice(include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf"))
        .unwrap();
    let case = RetestCase::new();
    let read = |path: &Path| read_path(path, None).unwrap().measurement;
    let (before, after) = (read(&case.before), read(&case.after));
    let (evaluation_before, evaluation_after) = (evaluate(&before), evaluate(&after));
    let text = std::fs::read_to_string(&case.table).unwrap();
    let (controller, table) = emit::read_any(&text, &table_options(), None).unwrap();
    let diagnosis = case.diagnosis();
    let before_record = TestRecord {
        measurement: &before,
        evaluation: &evaluation_before,
        warnings: &[],
        budget: None,
    };
    // The predicted re-test the workflow gives the report.
    let prediction = axcomp::workflow::report::predicted_retest(&before_record, &table, &ISO_230_2);
    let input = ReportInput {
        before: before_record,
        after: Some(TestRecord {
            measurement: &after,
            evaluation: &evaluation_after,
            warnings: &[],
            budget: None,
        }),
        table: Some(TableRecord {
            table: &table,
            file: "X.COM",
            controller,
        }),
        prediction: prediction.as_ref(),
        diagnosis: Some(&diagnosis),
        limits: &[],
        decision: Default::default(),
        standard: &ISO_230_2,
        angle: Default::default(),
        generator: "test",
    };
    let charts = charts(&input);
    assert_eq!(charts.len(), 7);
    // The tick labels: digits, point and the minus sign.
    let mut texts = vec!["0123456789.\u{2212}".to_string()];
    for named in &charts {
        texts.extend(named.chart.texts().into_iter().map(str::to_string));
    }
    for text in &texts {
        for c in text.chars() {
            assert_ne!(
                font.glyph_id(c).0,
                0,
                "{c:?} (U+{:04X}) in {text:?} is not in the font",
                c as u32
            );
        }
    }
    // A rotary axis' charts write the arc-second sign (the polar plot's
    // rings, the deviation axis in ″): the PNG draws it as ″, not as `"`.
    assert_ne!(font.glyph_id('\u{2033}').0, 0);
    assert_ne!(font.glyph_id('\u{2033}'), font.glyph_id('"'));
    // And the check can fail: a character the subset lacks.
    assert_eq!(font.glyph_id('č').0, 0);
}

#[test]
fn bad_input_names_the_file_and_line_and_writes_nothing() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("r.html");
    let bad = test_data("bad/rtl-two-fields.rtl");
    let run = axcomp([
        "report",
        bad.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(run.stderr.contains("rtl-two-fields.rtl:"), "{}", run.stderr);
    assert!(!run.stderr.contains("panicked"));
    assert!(!output.exists());

    let not_a_table = test_data("bad/unknown.txt");
    let run = axcomp([
        "report",
        SAMPLE,
        "--table",
        not_a_table.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr
            .contains("unknown.txt:1:1: unknown compensation table format"),
        "{}",
        run.stderr
    );
    assert!(!output.exists());

    let run = axcomp(["report", SAMPLE, "--diagnose"]);
    assert_eq!(run.code, 2, "--diagnose needs --after: {}", run.stderr);
}

#[test]
fn an_existing_report_is_kept_unless_forced() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("r.html");
    std::fs::write(&output, "keep me").unwrap();
    let run = axcomp(["report", SAMPLE, "-o", output.to_str().unwrap()]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr.contains("already exists; use --force"),
        "{}",
        run.stderr
    );
    assert_eq!(std::fs::read_to_string(&output).unwrap(), "keep me");
    let run = axcomp(["report", SAMPLE, "-o", output.to_str().unwrap(), "--force"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        std::fs::read_to_string(&output)
            .unwrap()
            .starts_with("<!DOCTYPE html>")
    );
}

/// Issue 11: the unexplained-structure sentence read "lack of fit p = = 0.0290".
/// The p-value is the library's, printed once, with one "=" (or "<").
#[test]
fn the_lack_of_fit_p_value_is_printed_once_with_one_sign() {
    let case = RetestCase::new();
    let (output, run) = case.report(&[]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&output).unwrap();
    let p = case.diagnosis().unexplained.p_value;
    let expected = if p < 1e-4 {
        "lack of fit p < 0.0001".to_string()
    } else {
        format!("lack of fit p = {p:.4}")
    };
    assert_eq!(html.matches("lack of fit p").count(), 1, "{html}");
    assert_eq!(html.matches(&expected).count(), 1, "{expected} in the page");
    for doubled in ["= =", "= < 0"] {
        let at = html.find(doubled);
        assert!(
            at.is_none(),
            "a doubled sign: {}",
            &html[at.unwrap_or(0).saturating_sub(200)..][..300]
        );
    }
}

/// Issue 14: a rotary axis' report is in ° and ″, its keyed cells those of
/// the rotary `evaluate --json` (`figures_arcsec`, `mean_up_arcsec`, …), with
/// a polar plot of the mean deviation beside the linear one and the rotary
/// reference named (the `system` target opens it in the browser).
#[test]
fn a_rotary_report_is_in_arcseconds_with_a_polar_plot() {
    const ROTARY: &str = "fixtures/rotary/c.csv";
    let page = artefacts().join("rotary-c.html");
    let run = axcomp(["report", ROTARY, "-o", page.to_str().unwrap(), "--force"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&page).unwrap();
    let evaluation = evaluate_json(&[Path::new(ROTARY)]);
    assert_eq!(embedded_data(&html)["before"], evaluation);
    let targets = evaluation["targets_deg"].as_array().unwrap().len();
    // 12 axis figures and 9 values at each target, none in µm.
    assert_eq!(
        check_against_json(&html, "before", &evaluation),
        12 + 9 * targets
    );
    assert!(html.contains("data-key=\"before.figures_arcsec.A\""));
    assert!(html.contains("data-key=\"before.per_target.3.mean_up_arcsec\""));
    let keys = keyed_values(&html);
    assert!(
        keys.iter()
            .all(|(key, ..)| !key.ends_with("_um") && !key.contains("_um."))
    );
    for text in [
        "Acceptance report: rotary axis C",
        "ISO 230-2 figures [″]",
        "Per target [″]",
        "<th>target [°]</th>",
        "<td class=\"num\">45°</td>",
        "target position [°]",
        "positional deviation [″]",
        "Acceptance limits are not evaluated for a rotary axis yet",
        "id=\"rotary-note\"",
    ] {
        assert!(html.contains(text), "{text} missing");
    }
    // The rotary reference: no file format records it.
    let reference = html.find("<th>Rotary reference</th>").unwrap();
    assert!(
        html[reference..]
            .split("</tr>")
            .next()
            .unwrap()
            .contains("not recorded")
    );
    // The polar plot: an SVG with its caption, after the linear one.
    let polar = html.find("id=\"plot-polar\"").expect("the polar plot");
    assert!(html.find("id=\"plot-deviation\"").unwrap() < polar);
    let figure = &html[polar..polar + html[polar..].find("</figure>").unwrap()];
    assert!(figure.contains("<svg role=\"img\""));
    assert!(figure.contains("<figcaption>The mean deviation around the circle"));
    assert!(figure.contains("90°") && figure.contains("0″"));

    // What does not apply to a rotary axis yet is refused, naming it.
    for (flag, value) in [
        ("--limit", "A=5"),
        ("--table", "X.COM"),
        ("--equipment", "fixtures/equipment/hene-default.toml"),
    ] {
        let run = axcomp(["report", ROTARY, flag, value, "-o", "never.html"]);
        assert_eq!(run.code, 2, "{flag}: {}", run.stderr);
        assert!(run.stderr.contains("rotary axis"), "{flag}: {}", run.stderr);
    }
}
