//! `axcomp report` end to end (issue 7): the report's numbers are those of
//! `evaluate --json` and of the library's `Diagnosis`; the page opens in a
//! real browser (Debian's chromium, headless) without console messages and
//! is not blank; it prints on A4; its PNG plots decode and every character
//! they draw is in the embedded font; bad input fails with exit code 2.
//!
//! Screenshots and PDFs are kept under `target/tmp/report/` (not in git).

use std::path::{Path, PathBuf};

use axcomp::compensate::{Extrapolate, GridSpec, TableMode, TableOptions, build_table};
use axcomp::cycle::CycleTiming;
use axcomp::diagnose::{DiagnoseInput, Diagnosis, diagnose};
use axcomp::effects::ParameterValue;
use axcomp::emit::{self, Controller, EmitOptions, MachineProfile};
use axcomp::evaluate::{ISO_230_2, evaluate};
use axcomp::read::{read_path, rtl};
use axcomp::report::acceptance::{ReportInput, TableRecord, TestRecord, charts};
use axcomp::synth::{self, Truth};

use crate::browser::{BrowserOutput, Pixels, artefacts, open_in_browser};
use crate::util::{axcomp, evaluate_json, test_data};

const SAMPLE: &str = "fixtures/sample-x.rtl";

/// Every `data-key` value of a report: (key, full value, text shown).
fn keyed_values(html: &str) -> Vec<(String, Option<f64>, String)> {
    let mut found = Vec::new();
    for piece in html.split("data-key=\"").skip(1) {
        let (key, rest) = piece.split_once('"').unwrap();
        let Some(rest) = rest.strip_prefix(" data-um=\"") else {
            continue;
        };
        let (value, rest) = rest.split_once('"').unwrap();
        let text = rest[1..].split('<').next().unwrap().to_string();
        let value = (value != "null").then(|| value.parse::<f64>().unwrap());
        found.push((key.to_string(), value, text));
    }
    found
}

/// The terminal report's rounding, written out again here: two decimals, `—`.
fn shown(value: Option<f64>) -> String {
    value.map_or_else(|| "—".to_string(), |v| format!("{v:.2}"))
}

/// Checks every cell whose key starts with `prefix.` against `source` (a
/// JSON object such as `evaluate --json`'s); returns how many were checked.
pub(crate) fn check_against_json(html: &str, prefix: &str, source: &serde_json::Value) -> usize {
    let mut checked = 0;
    for (key, value, text) in keyed_values(html) {
        let Some(path) = key.strip_prefix(&format!("{prefix}.")) else {
            continue;
        };
        let pointer = format!("/{}", path.replace('.', "/"));
        let expected = source
            .pointer(&pointer)
            .unwrap_or_else(|| panic!("{key}: no {pointer} in the source JSON"));
        assert_eq!(value, expected.as_f64(), "{key}: the report's value");
        assert_eq!(text, shown(value), "{key}: the report's text");
        checked += 1;
    }
    checked
}

/// The embedded `axcomp-data` JSON of a page (or of chromium's DOM dump).
pub(crate) fn embedded_data(html: &str) -> serde_json::Value {
    let start = html
        .find("id=\"axcomp-data\">")
        .expect("the page embeds #axcomp-data");
    let json = &html[start + "id=\"axcomp-data\">".len()..];
    let json = &json[..json.find("</script>").unwrap()];
    serde_json::from_str(json).expect("#axcomp-data is JSON")
}

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

/// A first test, a mean table written for a TNC 640, and a re-test with the
/// table applied, a reversal and a warm-up drift the model does not declare,
/// all written as files and read back as the report reads them.
struct RetestCase {
    directory: tempfile::TempDir,
    before: PathBuf,
    after: PathBuf,
    table: PathBuf,
}

const TRUTH: &str = r#"
[axis]
name = "X"
machine = "MCV 754 Quick <test & \"escape\">"

[cycle]
start_mm = 0.0
end_mm = 750.0
count = 16
jitter_mm = 9.0
runs = 5
start = "2026-11-20 09:14:00"

[error]
scale_um_per_m = 9.5
periodic = [{ period_mm = 200.0, amplitude_um = 1.8, phase_rad = 0.4 }]

[noise]
sigma_um = 0.35

[[effect]]
kind = "reversal"
B_um = -3.2

# The reversal grows by 1.5 µm after the first test: the change is what diagnose finds.
[[effect]]
kind = "reversal"
B_um = -1.5
tests = ["after"]

[[effect]]
kind = "drift"
rate_um_per_h = 4.0
tests = ["after"]
"#;

fn table_options() -> EmitOptions {
    EmitOptions::for_axis(&MachineProfile::default(), "X", "X.COM").unwrap()
}

impl RetestCase {
    fn new() -> RetestCase {
        let truth = Truth::from_toml_str(TRUTH).unwrap();
        let first = synth::before(&truth, 3).unwrap();
        let options = TableOptions {
            mode: TableMode::Mean,
            grid: GridSpec::Targets,
            reference_mm: None,
            extrapolate: Extrapolate::Hold,
        };
        let table = build_table(&first, &evaluate(&first), &options).unwrap();
        let retest = synth::after(&truth, &table, 3).unwrap();
        let directory = tempfile::tempdir().unwrap();
        let case = RetestCase {
            before: directory.path().join("before.rtl"),
            after: directory.path().join("after.rtl"),
            table: directory.path().join("X.COM"),
            directory,
        };
        std::fs::write(&case.before, rtl::write(&first)).unwrap();
        std::fs::write(&case.after, rtl::write(&retest)).unwrap();
        let text = emit::write(Controller::Tnc640, &table, &table_options()).unwrap();
        std::fs::write(&case.table, text).unwrap();
        case
    }

    fn report(&self, extra: &[&str]) -> (PathBuf, crate::util::Run) {
        let output = self.directory.path().join("report.html");
        let mut args = vec![
            "report".to_string(),
            self.before.display().to_string(),
            "--after".into(),
            self.after.display().to_string(),
            "--table".into(),
            self.table.display().to_string(),
            "--diagnose".into(),
            "-o".into(),
            output.display().to_string(),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        (output, axcomp(args))
    }

    /// The diagnosis as the library gives it for the files as read back.
    fn diagnosis(&self) -> Diagnosis {
        let before = read_path(&self.before, None).unwrap().measurement;
        let after = read_path(&self.after, None).unwrap().measurement;
        let text = std::fs::read_to_string(&self.table).unwrap();
        let (_, table) = emit::read_any(&text, &table_options(), None).unwrap();
        diagnose(&DiagnoseInput {
            angle: Default::default(),
            after: &after,
            before: Some(&before),
            table: Some(&table),
            backlash_set: false,
            angular: None,
            known_periods: &[],
            timing: CycleTiming::ASSUMED,
            standard: &ISO_230_2,
        })
        .unwrap()
    }
}

/// The diagnosis values the report keys, from the library.
fn diagnosis_json(d: &Diagnosis) -> serde_json::Value {
    let figures = |f: &axcomp::evaluate::AxisFigures| {
        let json = axcomp::report::json::FiguresJson::from_figures(f);
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
        "residual_before": {"rms_um": d.residual_before.rms_um, "max_abs_um": d.residual_before.max_abs_um},
        "residual_after": {"rms_um": d.residual_after.rms_um, "max_abs_um": d.residual_after.max_abs_um},
        "noise_um": d.noise_um,
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
        .map(|r| r.deviations_mm.iter().flatten().count())
        .sum();
    assert_eq!(diagnosis.readings.len(), readings);
    let rms = (diagnosis
        .readings
        .iter()
        .map(|r| (r.residual_um - r.fitted_um).powi(2))
        .sum::<f64>()
        / readings as f64)
        .sqrt();
    assert!(
        (rms - diagnosis.residual_after.rms_um).abs() < 1e-9,
        "{rms}"
    );
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
    let input = ReportInput {
        before: TestRecord {
            measurement: &before,
            evaluation: &evaluation_before,
            warnings: &[],
            budget: None,
        },
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

// --- In a real browser -------------------------------------------------------

#[test]
fn the_sample_report_opens_in_chromium_without_errors_and_is_not_blank() {
    let directory = tempfile::tempdir().unwrap();
    let page = directory.path().join("report.html");
    // With limits A fails (13.19 > 12 µm): the verdict box is drawn too.
    let limits = ["--limit", "A=12", "--limit", "R=7"];
    let mut args = vec!["report", SAMPLE, "-o", page.to_str().unwrap()];
    args.extend(limits);
    let run = axcomp(args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let screenshot = artefacts().join("sample-x.png");
    // 2800 px: the page down to the plot's caption, verdict box and the
    // uncertainty budget included.
    let browser = open_in_browser(&page, (1280, 2800), BrowserOutput::Screenshot(&screenshot));
    assert!(browser.console.is_empty(), "console: {:?}", browser.console);
    let shot = Pixels::read(&screenshot);
    let (inked, blue) = (shot.inked(), shot.blue());
    assert!(
        inked > 0.05,
        "screenshot {} is {inked} inked",
        screenshot.display()
    );
    assert!(blue > 0.005, "no plot in {}: {blue}", screenshot.display());
    // The FAIL box's red (#c81414 border and heading; the plot's orange has
    // more green), above the test conditions. Measured: 0.003 of the pixels
    // with the box, 0.0 for the same page without limits.
    let red = shot.fraction(|r, g, b| r > 150 && g < 60 && b < 60);
    assert!(
        red > 0.0005,
        "no red FAIL box in {}: {red}",
        screenshot.display()
    );
    let at = |needle: &str| browser.dom.find(needle).unwrap();
    assert!(at("data-verdict=\"fail\"") < at("id=\"conditions\""));
    // The browser parsed what was meant: one plot, 16 target rows, the data block intact.
    assert_eq!(browser.dom.matches("<svg").count(), 1);
    assert_eq!(
        browser.dom.matches("data-key=\"before.per_target.").count(),
        16 * 9
    );
    let mut evaluate_args = vec![SAMPLE];
    evaluate_args.extend(limits);
    let evaluation = crate::verdict::evaluate_json_with(&evaluate_args);
    assert_eq!(embedded_data(&browser.dom)["before"], evaluation);
}

/// Issue 13: the budget table (largest contributor first) and the decision
/// rule are on the page; E = 11.21 ± 1.82 µm against 12 µm under ISO 14253-1
/// is "not proven", an amber box (#b06a00) in the screenshot.
#[test]
fn the_report_shows_the_uncertainty_budget_and_the_decision_rule() {
    let directory = tempfile::tempdir().unwrap();
    let page = directory.path().join("report.html");
    let run = axcomp([
        "report",
        SAMPLE,
        "-o",
        page.to_str().unwrap(),
        "--limit",
        "E=12",
        "--decision",
        "iso14253-1",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let screenshot = artefacts().join("sample-x-uncertainty.png");
    let browser = open_in_browser(&page, (1280, 2400), BrowserOutput::Screenshot(&screenshot));
    assert!(browser.console.is_empty(), "console: {:?}", browser.console);
    let dom = &browser.dom;
    assert!(dom.contains("data-verdict=\"not-proven\""));
    assert!(dom.contains("Acceptance verdict: NOT PROVEN"));
    assert!(dom.contains("data-rule=\"iso14253-1\""), "no rule");
    assert!(dom.contains(
        "Decision rule (iso14253-1): ISO 14253-1: conformance proven when value + U ≤ limit"
    ));
    let at = |needle: &str| dom.find(needle).unwrap_or_else(|| panic!("{needle}"));
    // The budget table, largest first: u_M,MACHINE (0.8775 µm) leads.
    assert!(at("id=\"figures\"") < at("id=\"uncertainty\""));
    assert!(at("id=\"uncertainty\"") < at("id=\"deviation\""));
    let rows: Vec<&str> = dom
        .split("data-contributor=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap())
        .collect();
    assert_eq!(rows.len(), 5, "{rows:?}");
    assert_eq!(rows[0], "u_M,MACHINE");
    // Every number on the page is the embedded JSON's (U included).
    let data = embedded_data(dom);
    assert!(check_against_json(dom, "before", &data["before"]) > 0);
    assert!(dom.contains("data-key=\"before.uncertainty_um.E\""));
    assert!(dom.contains("data-key=\"before.verdict.checks.0.U_um\""));
    let shot = Pixels::read(&screenshot);
    let amber = shot.fraction(|r, g, b| r > 150 && (80..140).contains(&g) && b < 40);
    assert!(
        amber > 0.0003,
        "no amber NOT PROVEN box in {}: {amber}",
        screenshot.display()
    );
}

#[test]
fn the_retest_report_opens_in_chromium_and_prints_on_a4() {
    let case = RetestCase::new();
    let (page, run) = case.report(&[]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let screenshot = artefacts().join("retest.png");
    // 3400 px: down to the plots, below the uncertainty budget.
    let browser = open_in_browser(&page, (1280, 3400), BrowserOutput::Screenshot(&screenshot));
    assert!(browser.console.is_empty(), "console: {:?}", browser.console);
    let shot = Pixels::read(&screenshot);
    let (inked, blue) = (shot.inked(), shot.blue());
    assert!(
        inked > 0.05 && blue > 0.005,
        "{}: {inked}, {blue}",
        screenshot.display()
    );
    assert_eq!(browser.dom.matches("<svg").count(), 7);

    // Printed: A4 pages (595 × 842 pt), several of them.
    let pdf = artefacts().join("retest.pdf");
    open_in_browser(&page, (1280, 1000), BrowserOutput::Pdf(&pdf));
    let bytes = std::fs::read(&pdf).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    let boxes: Vec<&str> = text
        .split("/MediaBox [")
        .skip(1)
        .map(|s| s.split(']').next().unwrap())
        .collect();
    assert!(boxes.len() >= 4, "{} pages", boxes.len());
    for media_box in boxes {
        let numbers: Vec<f64> = media_box
            .split_whitespace()
            .map(|n| n.parse().unwrap())
            .collect();
        // A4 is 210 × 297 mm = 595.3 × 841.9 pt; Chromium rounds to its pixel grid.
        assert!(
            (numbers[2] - 595.3).abs() < 2.0 && (numbers[3] - 841.9).abs() < 2.0,
            "{media_box}"
        );
    }
}

#[test]
fn the_browser_checks_can_fail() {
    // A page with a script error and nothing drawn: the console check and the
    // ink check must both catch it, or they prove nothing about the report.
    let directory = tempfile::tempdir().unwrap();
    let page = directory.path().join("broken.html");
    std::fs::write(
        &page,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"></head><body>\
         <script>undefinedFunction();</script></body></html>",
    )
    .unwrap();
    let screenshot = directory.path().join("broken.png");
    let browser = open_in_browser(&page, (800, 600), BrowserOutput::Screenshot(&screenshot));
    assert!(
        browser
            .console
            .iter()
            .any(|l| l.contains("Uncaught ReferenceError")),
        "{:?}",
        browser.console
    );
    let shot = Pixels::read(&screenshot);
    let (inked, blue) = (shot.inked(), shot.blue());
    assert!(inked < 0.001 && blue == 0.0, "{inked} {blue}");
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
/// reference named; it opens in the browser and is not blank.
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

    let screenshot = artefacts().join("rotary-c.png");
    let browser = open_in_browser(&page, (1280, 2800), BrowserOutput::Screenshot(&screenshot));
    assert!(browser.console.is_empty(), "console: {:?}", browser.console);
    let shot = Pixels::read(&screenshot);
    assert!(shot.inked() > 0.05, "{} is blank", screenshot.display());
    // The plots' blues (the ↑ band, runs and means): measured 0.004 of this
    // tall page, none without plots.
    let blue = shot.blue();
    assert!(blue > 0.001, "no plot in {}: {blue}", screenshot.display());
    assert_eq!(browser.dom.matches("<svg").count(), 2);
    assert_eq!(
        browser.dom.matches("data-key=\"before.per_target.").count(),
        9 * targets
    );
    assert_eq!(embedded_data(&browser.dom)["before"], evaluation);

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
