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
//! pieces they share (a µm cell, a plot). This file builds the plain data
//! they show (formatted numbers, text from the files, the SVGs); the
//! templates escape text as [`esc`] does (`askama.toml`).
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

use askama::Template;
use serde::Serialize;

use crate::compensate::TableMode;
use crate::diagnose::{Diagnosis, ResidualStats};
use crate::effects::{Parameter, ParameterValue};
use crate::evaluate::TestConformance;
use crate::evaluate::conformance::{Check, Requirement};
use crate::evaluate::environment::{AGREEMENT_PPM, IndexComparison, RefractiveIndexCheck};
use crate::evaluate::standard::{Vdi3441, vdi_figure_name};
use crate::evaluate::verdict::Figure;
use crate::evaluate::{Standard, StandardUsed};
use crate::measurement::{AxisKind, Direction, Measurement, StartEnd};
use crate::report::acceptance::{ReportInput, TableRecord, TestRecord, charts, prediction};
use crate::report::chart::chart;
use crate::report::format::{SourcedUm, inch_beside, inch_text, um};
use crate::report::json::source_notes;
use crate::report::json::{EvaluationJson, FiguresJson, PerTargetJson, iso_keys};
use crate::report::plot::{FONT, PlotError, PlotFormat};
use crate::report::uncertainty::{NOT_EVALUATED_NOTE, UncertaintyJson};
use crate::report::verdict::{Judged, verdict_box};
use crate::units::{AngleUnit, DeviationUnit, LengthUnit, mm_to_um, um_to_mm};

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
/// let input = ReportInput { before, after: None, table: None, diagnosis: None, limits: &[],
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
            (Some(diagnosis), Some(_)) => Some(diagnosis_view(diagnosis, &plot)),
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
/// one in ° and ″ or µrad (its `Measurement` holds ° in the `_mm` fields).
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

/// The unit the report shows a test's deviations in (held in the `_mm`
/// fields as mm, or ° on a rotary axis): µm, or ″ or µrad.
fn deviation_shown(measurement: &Measurement, angle: AngleUnit) -> DeviationUnit {
    measurement.kind().deviation_unit(angle)
}

/// `uncertainty.html`: the budget of the test being accepted, largest
/// contributor first, and U of the figures.
struct UncertaintyView {
    /// "test FILE" or "re-test FILE".
    test_name: String,
    /// U(E) = U(M) = U(A).
    expanded: SourcedUm,
    /// u_c, µm, three decimals.
    combined_um: String,
    /// k.
    k: String,
    /// The equipment profile.
    equipment: String,
    /// (name, u, source), largest first.
    rows: Vec<(&'static str, SourcedUm, String)>,
    /// U(R), U(B) not evaluated.
    note: &'static str,
}

/// The budget of the test being accepted (the re-test when there is one, as
/// the verdict box); `None` when no budget was made.
fn uncertainty_view(input: &ReportInput<'_>) -> Option<UncertaintyView> {
    let (prefix, what, test) = match &input.after {
        Some(after) => ("after", "re-test", after),
        None => ("before", "test", &input.before),
    };
    let json = UncertaintyJson::from_budget(test.budget?);
    let test_name = match &test.measurement.metadata.source_file {
        Some(file) => format!("{what} {}", file.display()),
        None => what.to_string(),
    };
    Some(UncertaintyView {
        test_name,
        expanded: SourcedUm::new(format!("{prefix}.uncertainty_um.E"), Some(json.E)),
        combined_um: format!("{:.3}", json.u_c),
        k: json.k.to_string(),
        equipment: json.equipment.clone(),
        rows: json
            .budget
            .iter()
            .enumerate()
            .map(|(index, c)| {
                let key = format!("{prefix}.uncertainty_um.budget.{index}.u_um");
                (c.name, SourcedUm::new(key, Some(c.u_um)), c.source.clone())
            })
            .collect(),
        note: NOT_EVALUATED_NOTE,
    })
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

/// `header.html`. Text from the file is `None` when it does not record it.
struct Header {
    axis: String,
    kind: String,
    machine: Option<String>,
    serial_number: Option<String>,
    operator: Option<String>,
    date: Option<String>,
    location: Option<String>,
    /// Present when the file has a title (which may still be blank).
    title: Option<Option<String>>,
    /// ("Measurement" or "Re-test", its file).
    sources: Vec<(&'static str, SourceLine)>,
    table: Option<TableFile>,
    /// The standard, as the header names it.
    standard: String,
    /// Whether its definitions are reconstructed from public sources.
    reconstructed: bool,
}

/// A test's file, its format and size.
struct SourceLine {
    file: Option<String>,
    format: &'static str,
    unit: &'static str,
    targets: usize,
    runs_up: usize,
    runs_down: usize,
}

struct TableFile {
    file: String,
    controller: &'static str,
}

/// `conditions.html`: one column pair (start, end) per test.
struct Conditions {
    test_names: Vec<&'static str>,
    rows: Vec<Row>,
    refractive_index: Vec<IndexView>,
}

/// A row of the conditions table.
struct Row {
    label: &'static str,
    unit: &'static str,
    cells: Vec<Cell>,
}

/// A cell of the conditions table.
enum Cell {
    /// Text over `colspan` columns, `None`: not recorded.
    Text {
        colspan: usize,
        text: Option<String>,
    },
    /// What the test has for an ISO 230-2 requirement, and whether it meets it.
    Conformance { finding: String, met: Compliance },
    /// A number, over start and end when `wide`; `None`: not recorded.
    Number { wide: bool, value: Option<String> },
}

/// A requirement of ISO 230-2: met, a recommendation not followed, or not met.
enum Compliance {
    Met,
    NotFollowed,
    NotMet,
}

/// The refractive index check of one test.
struct IndexView {
    /// The test's name when the report has two.
    heading: Option<&'static str>,
    agreement_ppm: f64,
    made: Vec<IndexRow>,
    all_agree: bool,
    wavelength_assumed: bool,
    vacuum_wavelength_um: f64,
    /// (start or end, what the file does not record).
    missing: Vec<(&'static str, String)>,
}

struct IndexRow {
    when: &'static str,
    factor_um: String,
    material_correction_ppm: Option<String>,
    implied_n: String,
    edlen_n: String,
    difference_ppm_full: f64,
    difference_ppm: String,
    agrees: bool,
}

/// `figures.html`.
struct Figures {
    /// With a re-test: both tests side by side, and the change.
    compared: bool,
    test_names: Vec<&'static str>,
    rows: Vec<FigureRow>,
    /// (test name, its figures in inches) for an inch file.
    inch: Vec<(&'static str, String)>,
    source_notes: Vec<&'static str>,
    /// The ISO 230-2 figures' k (2; 3 for the ±3s editions) and 2k, for the note.
    k: f64,
    two_k: f64,
    /// A standard other than ISO 230-2 (VDI 3441): its name and its figures,
    /// one row each (symbol and name, a cell per test); empty for ISO 230-2.
    standard_name: &'static str,
    standard_rows: Vec<(String, Vec<Option<SourcedUm>>)>,
    /// Whether E, M and A show their U (a test has a budget).
    with_u: bool,
}

/// A figure's row: per test bidirectional, ↑ and ↓ (`None`: the figure has
/// no directions).
struct FigureRow {
    symbol: &'static str,
    name: &'static str,
    cells: Vec<Option<SourcedUm>>,
    change: Option<String>,
}

/// `deviation.html`: the test's plot, or the first test's and the re-test's.
enum Deviation {
    One(Option<Plot>),
    Pair(Option<Plot>, Option<Plot>),
}

/// `per_target.html`: one table per test.
struct PerTargetTable {
    heading: Option<&'static str>,
    rows: Vec<PerTargetRow>,
}

struct PerTargetRow {
    target: String,
    n_up: usize,
    n_down: usize,
    cells: Vec<SourcedUm>,
}

/// `table.html`.
struct TableView {
    file: String,
    controller: &'static str,
    points: usize,
    first_mm: f64,
    last_mm: f64,
    step_mm: Option<f64>,
    mode: TableMode,
    reference_mm: f64,
    max_abs_um: String,
    suggested_backlash_um: Option<String>,
    plot: Option<Plot>,
    prediction: Option<PredictionView>,
}

struct PredictionView {
    range_um: String,
    uncompensated_range_um: String,
    /// (key, cell) of the figures the paragraph names: A, E, B, or every
    /// figure of another standard.
    figures: Vec<(&'static str, SourcedUm)>,
    plot: Option<Plot>,
}

/// `diagnosis.html`.
struct DiagnosisView {
    predicted_from_first_test: bool,
    residual_before: ResidualCells,
    residual_after: ResidualCells,
    noise: SourcedUm,
    time_assumed: bool,
    figures: Vec<FigureRow>,
    accepted: Vec<EffectRow>,
    /// (effect kind, why it was not accepted).
    rejected: Vec<(&'static str, String)>,
    unexplained: UnexplainedView,
    residual_plot: Option<Plot>,
    along_axis_plot: Option<Plot>,
    effects_plot: Option<Plot>,
}

struct ResidualCells {
    rms: SourcedUm,
    max_abs: SourcedUm,
}

struct EffectRow {
    kind: &'static str,
    parameters: Vec<ParameterText>,
    delta_bic: String,
    trials: Option<usize>,
    /// `None`: below 0.0001 (`macros.html`, `p_value`).
    p_value: Option<String>,
    cv_rmse_without_um: String,
    cv_rmse_with_um: String,
    explanation: String,
    warnings: Vec<String>,
}

/// One parameter with its standard uncertainty; µm values carry their data key.
enum ParameterText {
    Run(u32),
    Um {
        name: &'static str,
        value: SourcedUm,
        plus_minus: Option<String>,
    },
    Number {
        name: &'static str,
        value: String,
        plus_minus: Option<String>,
        unit: &'static str,
    },
}

struct UnexplainedView {
    significant: bool,
    p_value: Option<String>,
    rms_um: String,
    /// Where it is largest, mm, `, `-separated; empty: spread along the axis.
    where_mm: String,
}

/// `notes.html`: a line of the warnings, naming its test.
struct Note {
    test: &'static str,
    what: NoteText,
}

enum NoteText {
    Warning(String),
    Outlier {
        run: u32,
        direction: Direction,
        score: String,
        offset_um: String,
        worst_target_mm: f64,
    },
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

fn header(input: &ReportInput<'_>) -> Header {
    let measurement = input.before.measurement;
    let metadata = &measurement.metadata;
    let mut sources = vec![("Measurement", source_line(measurement))];
    if let Some(after) = &input.after {
        sources.push(("Re-test", source_line(after.measurement)));
    }
    Header {
        axis: axis_shown(measurement),
        // What the test is, and whether it meets ISO 230-2 (`evaluate::conformance`).
        kind: input.before.evaluation.conformance.title(),
        machine: recorded(metadata.machine.as_deref()),
        serial_number: recorded(metadata.serial_number.as_deref()),
        operator: recorded(metadata.operator.as_deref()),
        date: recorded(metadata.date.as_ref().map(|d| d.raw.as_str())),
        location: recorded(metadata.location.as_deref()),
        title: metadata
            .description
            .as_deref()
            .map(|description| recorded(Some(description))),
        sources,
        table: input.table.as_ref().map(|table| TableFile {
            file: table.file.to_string(),
            controller: table.controller.name(),
        }),
        standard: standard_line(&input.before.evaluation.standard),
        reconstructed: input.before.evaluation.standard.reconstructed,
    }
}

/// The header's line on the standard: its name, and what A and R mean in it.
fn standard_line(standard: &StandardUsed) -> String {
    let iso = format!(
        "test of accuracy and repeatability of positioning of numerically controlled axes; A and R with the coverage of that edition (x̄ ± {k}s, R = {r}s)",
        k = standard.k,
        r = 2.0 * standard.k
    );
    if standard.key == Vdi3441.key() {
        return format!(
            "{}: P, Pa, Ps and U of each direction's statistics; the ISO 230-2:2014 figures beside them ({iso})",
            standard.name
        );
    }
    format!("{}, {iso}", standard.name)
}

fn source_line(measurement: &Measurement) -> SourceLine {
    let metadata = &measurement.metadata;
    SourceLine {
        file: metadata
            .source_file
            .as_ref()
            .map(|p| p.display().to_string()),
        format: metadata.source_format.map_or("", |f| f.name()),
        unit: match measurement.kind() {
            AxisKind::Linear => metadata.length_unit.as_str(),
            AxisKind::Rotary => "°",
        },
        targets: measurement.targets_mm().len(),
        runs_up: measurement.run_count(Direction::Up),
        runs_down: measurement.run_count(Direction::Down),
    }
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

fn conditions(input: &ReportInput<'_>) -> Conditions {
    let tests = tests_of(input);
    let mut rows = test_rows(&tests);
    rows.extend(conformance_rows(&tests));
    rows.extend(setup_rows(&tests));
    rows.extend(environment_rows(&tests));
    Conditions {
        test_names: tests.iter().map(|(name, _)| *name).collect(),
        rows,
        refractive_index: tests
            .iter()
            .map(|(name, test)| {
                let heading = if tests.len() > 1 { Some(*name) } else { None };
                refractive_index(heading, &test.evaluation.refractive_index)
            })
            .collect(),
    }
}

/// A row with one cell over start and end per test.
fn wide_row(
    tests: &[(&str, &TestRecord<'_>)],
    label: &'static str,
    unit: &'static str,
    cell: &dyn Fn(&TestRecord<'_>) -> Cell,
) -> Row {
    Row {
        label,
        unit,
        cells: tests.iter().map(|(_, test)| cell(test)).collect(),
    }
}

/// Text over start and end.
fn text(text: Option<String>) -> Cell {
    Cell::Text { colspan: 2, text }
}

/// The unit of the tests' positions: `mm`, or `°` on a rotary axis.
fn position_unit(tests: &[(&str, &TestRecord<'_>)]) -> &'static str {
    match tests.first().map(|(_, t)| t.measurement.kind()) {
        Some(AxisKind::Rotary) => "°",
        _ => "mm",
    }
}

fn test_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    vec![
        wide_row(tests, "Runs", "", &|t| {
            let m = t.measurement;
            text(Some(format!(
                "{}↑ {}↓",
                m.run_count(Direction::Up),
                m.run_count(Direction::Down)
            )))
        }),
        wide_row(tests, "Targets", position_unit(tests), &|t| {
            let targets = t.measurement.targets_mm();
            text(Some(format!(
                "{} from {} to {}",
                targets.len(),
                targets.first().copied().unwrap_or_default(),
                targets.last().copied().unwrap_or_default()
            )))
        }),
        wide_row(tests, "Duration", "min", &|t| {
            text(
                t.measurement
                    .metadata
                    .duration_s()
                    .map(|s| format!("{:.0}", s / 60.0)),
            )
        }),
    ]
}

/// The instrument and set-up (`Metadata::setup`), in mm and, for an inch
/// file, in inches beside; "not recorded" where the file does not say.
fn setup_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    let mut rows = instrument_rows(tests);
    if position_unit(tests) == "°" {
        // The angle reference a rotary laser test turns against (an indexer
        // such as Renishaw's XR20): no format axcomp reads records it yet.
        rows.insert(0, wide_row(tests, "Rotary reference", "", &|_| text(None)));
    }
    rows
}

fn instrument_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    let nothing = tests.iter().all(|(_, t)| {
        t.measurement.metadata.setup.is_empty()
            && t.measurement.environment.vacuum_wavelength_um.is_none()
    });
    if nothing {
        return vec![Row {
            label: "Instrument, set-up",
            unit: "",
            cells: vec![Cell::Text {
                colspan: 2 * tests.len(),
                text: None,
            }],
        }];
    }
    let inch = |m: &Measurement, value_mm: f64| {
        if m.metadata.length_unit == LengthUnit::Inch {
            format!(" ({} in)", inch_text(LengthUnit::Inch.from_mm(value_mm)))
        } else {
            String::new()
        }
    };
    type Pick<'a> = &'a dyn Fn(&Measurement) -> Option<String>;
    let rows: [(&str, &str, Pick<'_>); 6] = [
        ("Instrument", "", &|m| {
            recorded(m.metadata.setup.instrument.as_deref())
        }),
        ("Instrument serial number", "", &|m| {
            recorded(m.metadata.setup.instrument_serial.as_deref())
        }),
        ("Laser wavelength (vacuum)", "µm", &|m| {
            m.environment
                .vacuum_wavelength_um
                .map(|w| format!("{w:.6}"))
        }),
        ("Feed", "mm/min", &|m| {
            m.metadata
                .setup
                .feed_mm_per_min
                .map(|f| format!("{f}{}", inch(m, f).replace(" in)", " in/min)")))
        }),
        ("Dwell", "s", &|m| {
            m.metadata.setup.dwell_s.map(|d| format!("{d}"))
        }),
        ("Measuring line: other axes at", "mm", &|m| {
            let axes = &m.metadata.setup.other_axes_mm;
            if axes.is_empty() {
                return None;
            }
            let list: Vec<String> = axes
                .iter()
                .map(|(axis, at)| format!("{axis} {at}{}", inch(m, *at)))
                .collect();
            Some(list.join(", "))
        }),
    ];
    rows.into_iter()
        .map(|(label, unit, pick)| wide_row(tests, label, unit, &|t| text(pick(t.measurement))))
        .collect()
}

/// The test against ISO 230-2 (`evaluate::conformance`): what the test has
/// and whether it meets each requirement, three rows of the conditions table.
fn conformance_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    let met = |checks: &[Option<&Check>]| {
        if checks.iter().all(|c| c.is_some_and(|c| c.met)) {
            Compliance::Met
        } else if checks
            .iter()
            .all(|c| c.is_some_and(|c| c.requirement.is_recommendation()))
        {
            Compliance::NotFollowed
        } else {
            Compliance::NotMet
        }
    };
    type Judge<'a> = &'a dyn Fn(&TestConformance) -> Cell;
    let rows: [(&str, Judge<'_>); 3] = [
        ("Runs for ISO 230-2", &|c| {
            let runs = c.check(Requirement::Runs);
            let both = c.check(Requirement::BothDirections);
            let directions = if both.is_some_and(|b| b.met) {
                "both directions"
            } else {
                "one direction"
            };
            Cell::Conformance {
                finding: format!(
                    "{} per direction, {directions} (5 each way, 1 over {})",
                    runs.and_then(|r| r.found).unwrap_or_default(),
                    if c.kind() == AxisKind::Rotary {
                        "360°"
                    } else {
                        "2000 mm"
                    },
                ),
                met: met(&[runs, both]),
            }
        }),
        ("Targets for ISO 230-2", &|c| {
            let count = c.check(Requirement::Targets);
            let density = c.check(Requirement::TargetsPerMetre);
            let per_metre = density
                .and_then(|d| d.found)
                .map_or_else(String::new, |d| format!(", {d:.1} per metre"));
            // A rotary axis has no per-metre rule (evaluate::conformance).
            if c.kind() == AxisKind::Rotary {
                return Cell::Conformance {
                    finding: format!("{} (at least 5)", c.targets),
                    met: met(&[count]),
                };
            }
            Cell::Conformance {
                finding: format!("{}{per_metre} (at least 5, and 5 per metre)", c.targets),
                met: met(&[count, density]),
            }
        }),
        ("Spacing for ISO 230-2", &|c| {
            let spacing = c.check(Requirement::IrregularSpacing);
            Cell::Conformance {
                finding: spacing.and_then(|s| s.found).map_or_else(
                    || "irregular".to_string(),
                    |step| {
                        let unit = if c.kind() == AxisKind::Rotary {
                            "°"
                        } else {
                            " mm"
                        };
                        format!("constant step {}{unit}", signed(step, 3))
                    },
                ),
                met: met(&[spacing]),
            }
        }),
    ];
    // Nor a spacing rule: a rotary test's even steps are its principal angles.
    let rotary = tests
        .iter()
        .any(|(_, t)| t.evaluation.conformance.kind() == AxisKind::Rotary);
    rows.into_iter()
        .filter(|(label, _)| !(rotary && label.starts_with("Spacing")))
        .map(|(label, judge)| wide_row(tests, label, "", &|t| judge(&t.evaluation.conformance)))
        .collect()
}

fn environment_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    type Pick = fn(&Measurement) -> StartEnd;
    let rows: [(&str, &str, usize, Pick); 7] = [
        ("Air temperature", "°C", 3, |m| {
            m.environment.air_temperature_c
        }),
        ("Air pressure", "kPa", 3, |m| m.environment.air_pressure_kpa),
        ("Relative humidity", "%", 1, |m| {
            m.environment.air_humidity_pct
        }),
        ("Material temperature 1", "°C", 3, |m| {
            m.environment.material_temperature_c[0]
        }),
        ("Material temperature 2", "°C", 3, |m| {
            m.environment.material_temperature_c[1]
        }),
        ("Material temperature 3", "°C", 3, |m| {
            m.environment.material_temperature_c[2]
        }),
        ("Environmental factor", "µm", 8, |m| {
            m.environment.environmental_factor_um
        }),
    ];
    let number = |wide: bool, value: Option<f64>, decimals: usize| Cell::Number {
        wide,
        value: value.map(|v| signed(v, decimals)),
    };
    let mut shown = Vec::new();
    for (label, unit, decimals, pick) in rows {
        let recorded = tests.iter().any(|(_, t)| !pick(t.measurement).is_empty());
        if !recorded && label.starts_with("Material temperature ") && !label.ends_with('1') {
            continue;
        }
        let cells = tests
            .iter()
            .flat_map(|(_, test)| {
                let value = pick(test.measurement);
                [value.start, value.end].map(|v| number(false, v, decimals))
            })
            .collect();
        shown.push(Row { label, unit, cells });
    }
    shown.push(Row {
        label: "Expansion coefficient",
        unit: "µm/(m·K)",
        cells: tests
            .iter()
            .map(|(_, test)| {
                let value = test.measurement.environment.expansion_coefficient_ppm_per_k;
                number(true, value, 2)
            })
            .collect(),
    });
    shown
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

fn refractive_index(heading: Option<&'static str>, check: &RefractiveIndexCheck) -> IndexView {
    let at = [("start", &check.start), ("end", &check.end)];
    let made: Vec<IndexRow> = at
        .iter()
        .filter_map(|(when, comparison)| match comparison {
            IndexComparison::Made(at) => Some(IndexRow {
                when,
                factor_um: format!("{:.8}", at.factor_um),
                material_correction_ppm: at.material_correction_ppm.map(|c| signed(c, 3)),
                implied_n: format!("{:.9}", at.implied_n),
                edlen_n: format!("{:.9}", at.edlen_n),
                difference_ppm_full: at.difference_ppm,
                difference_ppm: signed_plus(at.difference_ppm, 2),
                agrees: at.agrees(),
            }),
            IndexComparison::Missing(_) => None,
        })
        .collect();
    IndexView {
        heading,
        agreement_ppm: AGREEMENT_PPM,
        all_agree: made.iter().all(|row| row.agrees),
        made,
        wavelength_assumed: check.wavelength_assumed,
        vacuum_wavelength_um: check.vacuum_wavelength_um,
        missing: at
            .iter()
            .filter_map(|(when, comparison)| match comparison {
                IndexComparison::Missing(missing) => Some((*when, missing.join(", "))),
                IndexComparison::Made(_) => None,
            })
            .collect(),
    }
}

/// (symbol, name, figure); a figure with directions gets a column for each.
const FIGURE_ROWS: [(&str, &str, Figure); 6] = [
    ("A", "accuracy of positioning", Figure::A),
    ("E", "systematic positional deviation", Figure::E),
    ("R", "repeatability of positioning", Figure::R),
    ("M", "mean bidirectional positional deviation", Figure::M),
    ("B", "reversal value", Figure::B),
    ("B̄", "mean reversal value", Figure::BMean),
];

/// A figure's value as `figures_um` gives it, µm.
fn figure_value(figures: &FiguresJson, figure: Figure) -> Option<f64> {
    figures.get(figure.name())
}

fn figures(input: &ReportInput<'_>) -> Figures {
    let tests = tests_of(input);
    let figures: Vec<FiguresJson> = tests
        .iter()
        .map(|(_, test)| match test.measurement.kind() {
            AxisKind::Linear => FiguresJson::from_figures(&test.evaluation.figures),
            AxisKind::Rotary => {
                FiguresJson::from_standard_deg(&test.evaluation.standard_figures, input.angle)
            }
        })
        .collect();
    let rows = FIGURE_ROWS
        .into_iter()
        .map(|(symbol, name, figure)| {
            let cells = figures
                .iter()
                .zip(&tests)
                .zip(["before", "after"])
                .flat_map(|((f, (_, test)), prefix)| {
                    // Where these figures are in the test's JSON: its
                    // `figures_um`, or beside another standard's.
                    let object = if test.measurement.kind() == AxisKind::Rotary {
                        format!("figures_{}", input.angle.name())
                    } else if iso_keys(&test.evaluation.standard_figures) {
                        "figures_um".to_string()
                    } else {
                        "figures_iso230_2_um".to_string()
                    };
                    // U beside the figures it is evaluated for (E, M, A).
                    let cell = |shown: Figure| {
                        SourcedUm::new(
                            format!("{prefix}.{object}.{}", shown.name()),
                            figure_value(f, shown),
                        )
                        .with_u(
                            test.budget
                                .and_then(|b| shown.expanded_uncertainty_mm(b))
                                .map(mm_to_um),
                        )
                    };
                    let directed = [Direction::Up, Direction::Down]
                        .map(|direction| figure.directed(direction).map(cell));
                    [Some(cell(figure)), directed[0].clone(), directed[1].clone()]
                })
                .collect();
            let change = match figures.as_slice() {
                [before, after] => Some(um(figure_value(before, figure)
                    .zip(figure_value(after, figure))
                    .map(|(b, a)| a - b))),
                _ => None,
            };
            FigureRow {
                symbol,
                name,
                cells,
                change,
            }
        })
        .collect();
    let standard = input.before.evaluation.standard;
    let standard_rows = if standard.key == Vdi3441.key() {
        input
            .before
            .evaluation
            .standard_figures
            .iter()
            .map(|figure| {
                let cells = tests
                    .iter()
                    .zip(["before", "after"])
                    .map(|((_, test), prefix)| {
                        let value = test
                            .evaluation
                            .standard_figures
                            .iter()
                            .find(|f| f.key == figure.key)
                            .and_then(|f| f.value_mm);
                        Some(SourcedUm::new(
                            format!("{prefix}.figures_um.{}", figure.key),
                            value.map(mm_to_um),
                        ))
                    })
                    .collect();
                (
                    format!("{}  {}", figure.key, vdi_figure_name(figure.key)),
                    cells,
                )
            })
            .collect()
    } else {
        Vec::new()
    };
    Figures {
        k: standard.k,
        two_k: 2.0 * standard.k,
        standard_name: standard.name,
        standard_rows,
        with_u: tests.iter().any(|(_, test)| test.budget.is_some()),
        compared: figures.len() > 1,
        test_names: tests.iter().map(|(name, _)| *name).collect(),
        rows,
        inch: inch_figures(&tests),
        source_notes: source_notes(input.before.measurement.metadata.source_format).to_vec(),
    }
}

/// For an inch file, the bidirectional figures in inches too (the file's unit).
fn inch_figures(tests: &[(&'static str, &TestRecord<'_>)]) -> Vec<(&'static str, String)> {
    let mut notes = Vec::new();
    for (name, test) in tests {
        if test.measurement.metadata.length_unit != LengthUnit::Inch {
            continue;
        }
        let f = &FiguresJson::from_figures(&test.evaluation.figures);
        let parts: Vec<String> = FIGURE_ROWS
            .iter()
            .flat_map(|&(symbol, _, figure)| {
                let directed = [(Direction::Up, "↑"), (Direction::Down, "↓")]
                    .into_iter()
                    .filter_map(move |(d, arrow)| Some((figure.directed(d)?, arrow)));
                let figures = std::iter::once((figure, "")).chain(directed);
                figures.filter_map(move |(shown, arrow)| {
                    let um = figure_value(f, shown)?;
                    Some(format!(
                        "{symbol}{arrow} {} in",
                        inch_text(LengthUnit::Inch.from_mm(um_to_mm(um)))
                    ))
                })
            })
            .collect();
        if !parts.is_empty() {
            notes.push((*name, parts.join(", ")));
        }
    }
    notes
}

fn per_target(input: &ReportInput<'_>) -> Vec<PerTargetTable> {
    tests_of(input)
        .into_iter()
        .zip(["before", "after"])
        .map(|((name, test), prefix)| PerTargetTable {
            heading: input.after.as_ref().map(|_| name),
            rows: per_target_rows(test, prefix, input.angle),
        })
        .collect()
}

fn per_target_rows(test: &TestRecord<'_>, prefix: &str, angle: AngleUnit) -> Vec<PerTargetRow> {
    let length_unit = test.measurement.metadata.length_unit.as_str();
    let kind = test.measurement.kind();
    let rotary = kind == AxisKind::Rotary;
    let mut rows = Vec::new();
    for (index, stats) in test.evaluation.per_target.iter().enumerate() {
        let t = PerTargetJson::from_stats_of(stats, kind, angle);
        // The JSON key: `mean_up_um`, or `mean_up_arcsec` (`_urad`) on a rotary axis.
        let cells = t.cells().map(|(key, value)| {
            SourcedUm::new(format!("{prefix}.per_target.{index}.{key}"), value)
        });
        let (n_up, n_down) = t.readings();
        rows.push(PerTargetRow {
            target: if rotary {
                format!("{}°", t.target())
            } else {
                format!("{}{}", t.target(), inch_beside(length_unit, &[t.target()]))
            },
            n_up,
            n_down,
            cells: cells.to_vec(),
        });
    }
    rows
}

fn table_view(
    input: &ReportInput<'_>,
    record: &TableRecord<'_>,
    plot: &dyn Fn(&str) -> Option<Plot>,
) -> TableView {
    let table = record.table;
    let prediction = prediction(&input.before, table, input.standard).map(|predicted| {
        let iso_family = iso_keys(&predicted.figures);
        PredictionView {
            range_um: um(Some(predicted.range_um())),
            uncompensated_range_um: um(Some(predicted.uncompensated_range_um())),
            figures: predicted
                .figures
                .iter()
                .filter(|f| !iso_family || ["A", "E", "B"].contains(&f.key))
                .map(|f| {
                    let key = format!("prediction.figures_um.{}", f.key);
                    (f.key, SourcedUm::new(key, f.value_mm.map(mm_to_um)))
                })
                .collect(),
            plot: plot("predicted"),
        }
    });
    TableView {
        file: record.file.to_string(),
        controller: record.controller.name(),
        points: table.positions_mm.len(),
        first_mm: table.positions_mm.first().copied().unwrap_or_default(),
        last_mm: table.positions_mm.last().copied().unwrap_or_default(),
        step_mm: table.regular_step_mm(),
        mode: table.values.mode(),
        reference_mm: table.reference_mm,
        max_abs_um: signed(mm_to_um(table.max_abs_mm()), 2),
        suggested_backlash_um: table.suggested_backlash_mm.map(|b| signed(mm_to_um(b), 2)),
        plot: plot("table"),
        prediction,
    }
}

fn diagnosis_view(diagnosis: &Diagnosis, plot: &dyn Fn(&str) -> Option<Plot>) -> DiagnosisView {
    let u = &diagnosis.unexplained;
    DiagnosisView {
        predicted_from_first_test: diagnosis.predicted_from_first_test,
        residual_before: residual_cells("residual_before", &diagnosis.residual_before),
        residual_after: residual_cells("residual_after", &diagnosis.residual_after),
        noise: SourcedUm::new("diagnosis.noise_um".to_string(), Some(diagnosis.noise_um)),
        time_assumed: diagnosis.time_assumed,
        figures: diagnosis_figures(diagnosis),
        accepted: accepted_effects(diagnosis),
        rejected: diagnosis
            .rejected
            .iter()
            .map(|rejected| (rejected.kind.name(), rejected.why.clone()))
            .collect(),
        unexplained: UnexplainedView {
            significant: u.significant,
            p_value: p_value(u.p_value),
            rms_um: um(Some(u.rms_um)),
            where_mm: u
                .where_mm
                .iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(", "),
        },
        residual_plot: plot("residual"),
        along_axis_plot: plot("residual-along-axis"),
        effects_plot: plot("effects"),
    }
}

/// The RMS and largest |value| cells of a residual.
fn residual_cells(name: &str, stats: &ResidualStats) -> ResidualCells {
    let key = |what: &str| format!("diagnosis.{name}.{what}");
    ResidualCells {
        rms: SourcedUm::new(key("rms_um"), Some(stats.rms_um)),
        max_abs: SourcedUm::new(key("max_abs_um"), Some(stats.max_abs_um)),
    }
}

fn diagnosis_figures(diagnosis: &Diagnosis) -> Vec<FigureRow> {
    let figures = &diagnosis.standard_figures;
    let sets = [
        ("measured", &figures.measured),
        ("predicted", &figures.predicted),
        ("predicted_with_effects", &figures.predicted_with_effects),
    ]
    .map(|(set, figures)| (set, FiguresJson::from_standard(figures)));
    // The ISO 230-2 family's bidirectional figures, or every figure of another standard.
    let rows: Vec<(&'static str, &'static str, &'static str)> = if sets[0].1.is_iso230_2() {
        FIGURE_ROWS
            .iter()
            .map(|&(symbol, name, figure)| (symbol, name, figure.name()))
            .collect()
    } else {
        sets[0]
            .1
            .values
            .iter()
            .map(|&(key, _)| (key, vdi_figure_name(key), key))
            .collect()
    };
    rows.into_iter()
        .map(|(symbol, name, key)| FigureRow {
            symbol,
            name,
            cells: sets
                .iter()
                .map(|(set, json)| {
                    Some(SourcedUm::new(
                        format!("diagnosis.figures.{set}.{key}"),
                        json.get(key),
                    ))
                })
                .collect(),
            change: None,
        })
        .collect()
}

fn accepted_effects(diagnosis: &Diagnosis) -> Vec<EffectRow> {
    diagnosis
        .accepted
        .iter()
        .enumerate()
        .map(|(index, accepted)| {
            let evidence = &accepted.evidence;
            EffectRow {
                kind: accepted.effect.kind().name(),
                parameters: accepted
                    .effect
                    .parameters()
                    .into_iter()
                    .map(|parameter| parameter_text(index, &parameter, &accepted.uncertainty))
                    .collect(),
                delta_bic: signed(evidence.delta_bic, 1),
                trials: (evidence.trials > 1).then_some(evidence.trials),
                p_value: p_value(evidence.p_value),
                cv_rmse_without_um: um(Some(evidence.cv_rmse_without_um)),
                cv_rmse_with_um: um(Some(evidence.cv_rmse_with_um)),
                explanation: accepted.explanation.clone(),
                warnings: accepted.warnings.clone(),
            }
        })
        .collect()
}

/// One parameter with its standard uncertainty; µm values carry their data key.
fn parameter_text(
    index: usize,
    parameter: &Parameter,
    uncertainty: &[(&str, f64)],
) -> ParameterText {
    let (key, name, unit) = (parameter.key, parameter.name, parameter.unit);
    let plus_minus = uncertainty
        .iter()
        .find(|(k, _)| *k == key)
        .map(|(_, u)| format!("{u:.2}"));
    match parameter.value {
        ParameterValue::Run(run) => ParameterText::Run(run),
        ParameterValue::Number(value) if unit == "µm" => ParameterText::Um {
            name,
            value: SourcedUm::new(format!("diagnosis.accepted.{index}.{key}"), Some(value)),
            plus_minus,
        },
        ParameterValue::Number(value) => ParameterText::Number {
            name,
            value: format!("{value:.2}"),
            plus_minus,
            unit,
        },
    }
}

/// `= 0.1262` as `Some("0.1262")`; `None` below 0.0001.
fn p_value(p: f64) -> Option<String> {
    (p >= 1e-4).then(|| format!("{p:.4}"))
}

fn notes(input: &ReportInput<'_>) -> Vec<Note> {
    let mut notes = Vec::new();
    for (test, record) in tests_of(input) {
        for warning in record.warnings {
            notes.push(Note {
                test,
                what: NoteText::Warning(warning.text_in(input.angle)),
            });
        }
        for outlier in &record.evaluation.outliers {
            notes.push(Note {
                test,
                what: NoteText::Outlier {
                    run: outlier.run,
                    direction: outlier.direction,
                    score: format!("{:.1}", outlier.score),
                    offset_um: signed_plus(
                        deviation_shown(record.measurement, input.angle)
                            .from_internal(outlier.offset_mm),
                        2,
                    ),
                    worst_target_mm: outlier.worst_target_mm,
                },
            });
        }
    }
    notes
}

/// The embedded font as base64, for `@font-face` (the SVG plots' text).
fn font_base64() -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(FONT.len().div_ceil(3) * 4);
    for chunk in FONT.chunks(3) {
        let bytes = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let group = u32::from(bytes[0]) << 16 | u32::from(bytes[1]) << 8 | u32::from(bytes[2]);
        for (position, shift) in [18, 12, 6, 0].into_iter().enumerate() {
            if position <= chunk.len() {
                out.push(ALPHABET[(group >> shift & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
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
