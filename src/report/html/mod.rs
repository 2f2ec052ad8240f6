//! The acceptance report as one self-contained HTML page: inline CSS, inline
//! SVG plots, the embedded plot font as a data URL, no script, no network.
//!
//! [`render`] turns a [`ReportInput`] into the page. The markup is in
//! compile-time-checked askama templates at the crate root: `templates/report.html`
//! is the page (head, the inline CSS of `templates/report/report.css` and
//! `verdict.css`, the sections, signatures and footer) and includes one template per section
//! from `templates/report/`, in order: `header.html` (machine, axis,
//! operator, date, files, standard); `verdict.html`, the acceptance verdict box
//! (`report::verdict`: PASS or FAIL with its checks, or "no acceptance limits
//! given: no verdict"); `conditions.html`, test conditions and environment
//! with the refractive index check (`evaluate::environment`); `figures.html`,
//! the ISO 230-2 figures (side by side with the re-test's when there is one);
//! `deviation.html`, the deviation plot(s); `per_target.html`, the per-target
//! table(s); with a table `table.html`, its plot and the predicted re-test;
//! with a diagnosis `diagnosis.html`, its figures, effects and plots;
//! `notes.html`, the warnings. `templates/report/macros.html` holds the
//! pieces they share (a µm cell, a plot). This module builds the plain data
//! they show (formatted numbers, text from the files, the SVGs); the
//! templates escape text as [`esc`] does (`askama.toml`). Each section's
//! view and the code that builds it are in the submodule of the template's
//! name (`header`, `conditions`, `figures`, …).
//!
//! # Numbers a script can check
//!
//! Every figure and per-target value is shown exactly as the terminal report
//! shows it (`terminal::um`: µm, two decimals, `—` when not evaluated) in a
//! cell that carries its source:
//!
//! ```text
//! <td class="num" data-key="before.figures_um.A" data-um="13.191…">13.19</td>
//! ```
//!
//! `data-key` is the path of the value in the `evaluate --json` object of
//! the first test (`before.…`) or the re-test (`after.…`), or in the
//! diagnosis (`diagnosis.residual_before.rms_um`,
//! `diagnosis.figures.predicted.A`, `diagnosis.accepted.0.B_um`, …), or
//! the verdict's (`after.verdict.checks.0.value_um`, whose row also names
//! the figure cell it checks in `data-figure-key`);
//! `data-um` is the value at full precision (`null` when not evaluated). The
//! page also embeds
//!
//! ```text
//! <script type="application/json" id="axcomp-data">
//! { "generator": "axcomp 0.1.0 …", "before": {evaluate --json}, "after": {…} | null }
//! </script>
//! ```
//!
//! Print: A4 pages (`@page`), no dark backgrounds, plots and small tables
//! never split across pages, long tables repeat their header.

mod conditions;
mod diagnosis;
mod figures;
mod header;
mod notes;
mod per_target;
mod table;
mod uncertainty;

use askama::Template;
use serde::Serialize;

use crate::compensate::TableMode;
use crate::measurement::{AxisKind, Measurement};
use crate::report::acceptance::{ReportInput, TestRecord, charts};
use crate::report::chart::chart;
use crate::report::json::EvaluationJson;
use crate::report::plot::{FONT, PlotError, PlotFormat};
use crate::report::uncertainty::UncertaintyJson;
use crate::report::verdict::{Judged, verdict_box};
use crate::units::AngleUnit;
use conditions::{Cell, Compliance, Conditions, conditions};
use diagnosis::{DiagnosisView, ParameterText, diagnosis_view};
use figures::{Figures, figures};
use header::{Header, header};
use notes::{Note, NoteText, notes};
use per_target::{PerTargetTable, per_target};
use table::{TableView, table_view};
use uncertainty::{UncertaintyView, uncertainty_view};

/// Renders the whole report.
///
/// # Example
/// ```
/// use axcomp::{evaluate::{ISO_230_2, evaluate}, measurement::SourceFormat, read};
/// use axcomp::report::acceptance::{ReportInput, TestRecord};
/// let csv = "target_mm,run,direction,deviation_um\n\
///            0,1,up,0\n100,1,up,4\n0,1,down,-2\n100,1,down,2\n\
///            0,2,up,2\n100,2,up,6\n0,2,down,0\n100,2,down,4\n";
/// let (measurement, warnings) = read::parse_str(csv, SourceFormat::Csv).unwrap();
/// let evaluation = evaluate(&measurement);
/// let before = TestRecord { measurement: &measurement, evaluation: &evaluation, warnings: &warnings, budget: None };
/// let input = ReportInput { before, after: None, table: None, prediction: None, diagnosis: None, limits: &[],
///     decision: Default::default(), standard: &ISO_230_2, angle: Default::default(),
///     generator: "axcomp" };
/// let html = axcomp::report::html::render(&input).unwrap();
/// // E = max(x̄↑; x̄↓) − min(x̄↑; x̄↓) = 5 − (−1) = 6 µm, shown as the terminal shows it.
/// assert!(html.contains(r#"data-key="before.figures_um.E" data-um="6">6.00</td>"#));
/// ```
pub fn render(input: &ReportInput<'_>) -> Result<String, PlotError> {
    let mut plots = Vec::new();
    for named in charts(input) {
        let bytes = chart(&named.chart, PlotFormat::Svg)?;
        let svg = String::from_utf8_lossy(&bytes);
        // The templates label the SVG (role and title) in its opening tag.
        let (head, tail) = match svg.split_once("<svg ") {
            Some((head, tail)) => (head.to_string(), Some(tail.to_string())),
            None => (svg.into_owned(), None),
        };
        plots.push(Plot {
            name: named.name,
            title: named.chart.title,
            head,
            tail,
        });
    }
    let plot = |name: &str| plots.iter().find(|plot| plot.name == name).cloned();
    let data = ReportDataJson {
        generator: input.generator,
        before: evaluation_json(&input.before, input),
        after: input.after.as_ref().map(|a| evaluation_json(a, input)),
    };
    let json = serde_json::to_string(&data).unwrap_or_else(|_| "null".into());
    let page = Page {
        generator: input.generator,
        title: format!(
            "ISO 230-2 report, {} axis {}",
            input
                .before
                .measurement
                .metadata
                .machine
                .as_deref()
                .unwrap_or("machine"),
            axis_shown(input.before.measurement)
        ),
        font_base64: font_base64(),
        units: Units::of(input.before.measurement.kind(), input.angle),
        header: header(input),
        verdict: verdict_box(input),
        conditions: conditions(input),
        figures: figures(input),
        uncertainty: uncertainty_view(input),
        deviation: if input.after.is_none() {
            Deviation::One(plot("deviation"))
        } else {
            Deviation::Pair(plot("deviation-before"), plot("deviation-after"))
        },
        polar: ["polar", "polar-before", "polar-after"]
            .into_iter()
            .filter_map(plot)
            .collect(),
        per_target: per_target(input),
        table: input
            .table
            .as_ref()
            .map(|table| table_view(input, table, &plot)),
        diagnosis: match (input.diagnosis, &input.after) {
            (Some(diagnosis), Some(_)) => diagnosis_view(diagnosis, &plot),
            _ => None,
        },
        notes: notes(input),
        json: json_in_script(&json),
    };
    // Rendering writes into a String and the templates call no filter that
    // can fail, so it cannot fail.
    Ok(page.to_string())
}

/// The page (`templates/report.html`): one field per section.
#[derive(Template)]
#[template(path = "report.html")]
struct Page<'a> {
    generator: &'a str,
    title: String,
    font_base64: String,
    units: Units,
    header: Header,
    verdict: Option<Judged>,
    conditions: Conditions,
    figures: Figures,
    uncertainty: Option<UncertaintyView>,
    deviation: Deviation,
    /// A rotary axis' polar plots (one per test); empty for a linear axis.
    polar: Vec<Plot>,
    per_target: Vec<PerTargetTable>,
    table: Option<TableView>,
    diagnosis: Option<DiagnosisView>,
    notes: Vec<Note>,
    /// The `axcomp-data` JSON, safe inside `<script>` ([`json_in_script`]).
    json: String,
}

/// The units a report is written in: a linear axis in mm and µm, a rotary
/// one in ° and ″ or µrad (its `Measurement` holds ° where a linear one holds mm).
struct Units {
    /// `linear` or `rotary`, as the subtitle names the axis.
    kind: &'static str,
    rotary: bool,
    /// A deviation's unit: `µm`, `″` or `µrad`.
    deviation: &'static str,
    /// The same in words, for the rotary note: `arc-seconds (1° = 3600″)`.
    deviation_named: &'static str,
    /// A position's unit: `mm` or `°`.
    position: &'static str,
}

impl Units {
    fn of(kind: AxisKind, angle: AngleUnit) -> Units {
        let rotary = kind == AxisKind::Rotary;
        Units {
            kind: kind.as_str(),
            rotary,
            deviation: kind.deviation_unit(angle).symbol(),
            deviation_named: match angle {
                AngleUnit::Arcsec => "arc-seconds (1° = 3600″)",
                AngleUnit::Urad => "microradians, µrad (1° = π/180 rad = 10⁶·π/180 µrad)",
            },
            position: if rotary { "°" } else { "mm" },
        }
    }
}

/// A plot as report::chart draws it, split at its opening `<svg ` tag
/// (`head` is what comes before it, nothing for plotters' SVG), with its title.
#[derive(Clone)]
struct Plot {
    name: &'static str,
    title: String,
    head: String,
    tail: Option<String>,
}

/// `deviation.html`: the test's plot, or the first test's and the re-test's.
enum Deviation {
    One(Option<Plot>),
    Pair(Option<Plot>, Option<Plot>),
}

/// The embedded `axcomp-data` block.
#[derive(Debug, Serialize)]
struct ReportDataJson<'a> {
    generator: &'a str,
    before: EvaluationJson,
    after: Option<EvaluationJson>,
}

/// JSON inside `<script>`: `<` as `\u003c`, so no text from a file can close
/// the element (`</script>`) or open a comment.
fn json_in_script(json: &str) -> String {
    json.replace('<', "\\u003c")
}

/// As `evaluate --json` prints it, with the same limits, rule and budget.
fn evaluation_json(test: &TestRecord<'_>, input: &ReportInput<'_>) -> EvaluationJson {
    let mut json = EvaluationJson::new(
        test.measurement,
        test.evaluation,
        &[],
        test.warnings,
        input.angle,
    );
    json.uncertainty_um = test.budget.map(UncertaintyJson::from_budget);
    json.verdict =
        crate::report::verdict::judge(test.evaluation, input.limits, input.decision, test.budget);
    json
}

/// The axis name, or "not recorded" when the file does not state it (the
/// name is then only a placeholder, `measurement::AXIS_PLACEHOLDER`).
fn axis_shown(measurement: &Measurement) -> String {
    if measurement.axis_recorded() {
        measurement.axis().to_string()
    } else {
        "(not recorded)".to_string()
    }
}

/// Text from a file, `None` when it is missing or blank.
fn recorded(value: Option<&str>) -> Option<String> {
    value
        .map(str::trim)
        .filter(|v| !v.is_empty())
        .map(str::to_string)
}

fn tests_of<'a>(input: &'a ReportInput<'a>) -> Vec<(&'static str, &'a TestRecord<'a>)> {
    let mut tests = vec![(
        if input.after.is_some() {
            "First test"
        } else {
            "Test"
        },
        &input.before,
    )];
    if let Some(after) = &input.after {
        tests.push(("Re-test", after));
    }
    tests
}

/// A number with a fixed number of decimals and the minus sign for negatives.
fn signed(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    text.replacen('-', "−", 1)
}

fn signed_plus(value: f64, decimals: usize) -> String {
    let text = signed(value, decimals);
    if value >= 0.0 {
        format!("+{text}")
    } else {
        text
    }
}

/// The embedded font as base64, for `@font-face` (the SVG plots' text).
fn font_base64() -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(FONT)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::format::{esc, um_cell};

    #[test]
    fn text_from_files_is_escaped() {
        assert_eq!(
            esc("<script>\"a\" & 'b'</script>"),
            "&lt;script&gt;&quot;a&quot; &amp; &#39;b&#39;&lt;/script&gt;"
        );
        assert_eq!(
            json_in_script(r#"{"m":"</script><!--"}"#),
            r#"{"m":"\u003c/script>\u003c!--"}"#
        );
    }

    #[test]
    fn cells_show_the_terminal_rounding_and_keep_the_full_value() {
        assert_eq!(
            um_cell("before.figures_um.A", Some(13.191_234)),
            "<td class=\"num\" data-key=\"before.figures_um.A\" data-um=\"13.191234\">13.19</td>"
        );
        assert_eq!(
            um_cell("x", None),
            "<td class=\"num\" data-key=\"x\" data-um=\"null\">—</td>"
        );
        assert_eq!(signed(-1.5, 2), "−1.50");
        assert_eq!(signed_plus(0.585, 2), "+0.58");
    }

    #[test]
    fn the_font_is_base64_that_decodes_back() {
        let encoded = font_base64();
        assert_eq!(encoded.len(), FONT.len().div_ceil(3) * 4);
        // By hand: the first four bytes of a TrueType file are 00 01 00 00,
        // whose first three encode as "AAEA".
        assert!(encoded.starts_with("AAEA"), "{}", &encoded[..8]);
        let padding = encoded.chars().rev().take_while(|c| *c == '=').count();
        assert_eq!(padding, (3 - FONT.len() % 3) % 3);
    }
}
