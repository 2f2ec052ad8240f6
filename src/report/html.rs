//! The acceptance report as one self-contained HTML page: inline CSS, inline
//! SVG plots, the embedded plot font as a data URL, no script, no network.
//!
//! [`render`] turns a [`ReportInput`] into the page. Sections, in order:
//! header (machine, axis, operator, date, files, standard); the acceptance
//! verdict box (`report::verdict`: PASS or FAIL with its checks, or "no
//! acceptance limits given: no verdict"); test conditions
//! and environment with the refractive index check
//! (`evaluate::environment`); the ISO 230-2 figures (side by side with the
//! re-test's when there is one); the deviation plot(s); the per-target
//! table(s); with a table its plot and the predicted re-test; with a
//! diagnosis its figures, effects and plots; warnings; signatures.
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

use std::fmt::Write;

use serde::Serialize;

use crate::diagnose::{Diagnosis, ResidualStats};
use crate::effects::{Parameter, ParameterValue};
use crate::evaluate::AxisFigures;
use crate::evaluate::TestConformance;
use crate::evaluate::conformance::{Check, Requirement};
use crate::evaluate::environment::{AGREEMENT_PPM, IndexAt, IndexComparison, RefractiveIndexCheck};
use crate::evaluate::verdict::{Figure, Limit};
use crate::measurement::{Direction, Measurement, StartEnd};
use crate::report::acceptance::{
    NamedChart, ReportInput, TableRecord, TestRecord, charts, prediction,
};
use crate::report::chart::chart;
use crate::report::format::{esc, inch_beside, inch_text, source, um, um_cell};
use crate::report::json::source_notes;
use crate::report::json::{EvaluationJson, FiguresJson, PerTargetJson};
use crate::report::plot::{FONT, PlotError, PlotFormat};
use crate::units::{LengthUnit, mm_to_um, um_to_mm};

/// The embedded `axcomp-data` block.
#[derive(Debug, Serialize)]
struct ReportDataJson<'a> {
    generator: &'a str,
    before: EvaluationJson,
    after: Option<EvaluationJson>,
}

/// Renders the whole report.
///
/// # Example
/// ```
/// use axcomp::{evaluate::evaluate, measurement::SourceFormat, read};
/// use axcomp::report::acceptance::{ReportInput, TestRecord};
/// let csv = "target_mm,run,direction,deviation_um\n\
///            0,1,up,0\n100,1,up,4\n0,1,down,-2\n100,1,down,2\n\
///            0,2,up,2\n100,2,up,6\n0,2,down,0\n100,2,down,4\n";
/// let (measurement, warnings) = read::parse_str(csv, SourceFormat::Csv).unwrap();
/// let evaluation = evaluate(&measurement);
/// let before = TestRecord { measurement: &measurement, evaluation: &evaluation, warnings: &warnings };
/// let input = ReportInput { before, after: None, table: None, diagnosis: None, limits: &[], generator: "axcomp" };
/// let html = axcomp::report::html::render(&input).unwrap();
/// // E = max(x̄↑; x̄↓) − min(x̄↑; x̄↓) = 5 − (−1) = 6 µm, shown as the terminal shows it.
/// assert!(html.contains(r#"data-key="before.figures_um.E" data-um="6">6.00</td>"#));
/// ```
pub fn render(input: &ReportInput<'_>) -> Result<String, PlotError> {
    let charts = charts(input);
    let mut svgs = Vec::with_capacity(charts.len());
    for named in &charts {
        let bytes = chart(&named.chart, PlotFormat::Svg)?;
        svgs.push((named, String::from_utf8_lossy(&bytes).into_owned()));
    }
    let svg_of = |name: &str| {
        svgs.iter()
            .find(|(named, _)| named.name == name)
            .map(|(named, svg)| (*named, svg.as_str()))
    };
    let mut body = String::new();
    header(&mut body, input);
    crate::report::verdict::html_section(&mut body, input);
    conditions(&mut body, input);
    figures_section(&mut body, input);
    deviation_section(&mut body, input, &svg_of);
    per_target_section(&mut body, input);
    if let Some(table) = &input.table {
        table_section(&mut body, input, table, &svg_of);
    }
    if let (Some(diagnosis), Some(_)) = (input.diagnosis, &input.after) {
        diagnosis_section(&mut body, diagnosis, &svg_of);
    }
    notes_section(&mut body, input);
    signatures(&mut body);
    let _ = writeln!(
        body,
        "<footer><p>Made by {} from the files named above. The numbers are those of \
         <code>axcomp evaluate --json</code>, which is embedded in this page \
         (<code>#axcomp-data</code>).</p></footer>",
        esc(input.generator)
    );
    let data = ReportDataJson {
        generator: input.generator,
        before: evaluation_json(&input.before, input.limits),
        after: input
            .after
            .as_ref()
            .map(|a| evaluation_json(a, input.limits)),
    };
    let json = serde_json::to_string(&data).unwrap_or_else(|_| "null".into());
    let title = format!(
        "ISO 230-2 report, {} axis {}",
        input
            .before
            .measurement
            .metadata
            .machine
            .as_deref()
            .unwrap_or("machine"),
        axis_shown(input.before.measurement)
    );
    Ok(format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <meta name=\"generator\" content=\"{generator}\">\n<title>{title}</title>\n\
         <style>\n{css}</style>\n</head>\n<body>\n{body}\
         <script type=\"application/json\" id=\"axcomp-data\">{json}</script>\n</body>\n</html>\n",
        generator = esc(input.generator),
        title = esc(&title),
        css = css(),
        json = json_in_script(&json),
    ))
}

/// JSON inside `<script>`: `<` as `\u003c`, so no text from a file can close
/// the element (`</script>`) or open a comment.
fn json_in_script(json: &str) -> String {
    json.replace('<', "\\u003c")
}

/// As `evaluate --json` prints it, with the same limits.
fn evaluation_json(test: &TestRecord<'_>, limits: &[Limit]) -> EvaluationJson {
    let mut json = EvaluationJson::new(test.measurement, test.evaluation, &[], test.warnings);
    json.verdict = crate::report::verdict::judge(test.evaluation, limits);
    json
}

/// A µm value in running text, with its source.
fn um_strong(key: &str, value: Option<f64>) -> String {
    format!("<strong {}>{}</strong>", source(key, value), um(value))
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

fn text_or_missing(value: Option<&str>) -> String {
    match value.map(str::trim).filter(|v| !v.is_empty()) {
        Some(text) => esc(text),
        None => "<span class=\"missing\">not recorded</span>".to_string(),
    }
}

fn header(out: &mut String, input: &ReportInput<'_>) {
    let measurement = input.before.measurement;
    let metadata = &measurement.metadata;
    // What the test is, and whether it meets ISO 230-2 (`evaluate::conformance`).
    let _ = write!(
        out,
        "<header>\n<h1>Accuracy and repeatability of positioning</h1>\n\
         <p class=\"subtitle\">Acceptance report: linear axis {axis}, {kind}</p>\n</header>\n",
        axis = esc(&axis_shown(measurement)),
        kind = esc(&input.before.evaluation.conformance.title()),
    );
    out.push_str("<table class=\"meta\">\n");
    let row = |out: &mut String, a: &str, b: String, c: &str, d: String| {
        let _ = writeln!(
            out,
            "<tr><th>{a}</th><td>{b}</td><th>{c}</th><td>{d}</td></tr>"
        );
    };
    row(
        out,
        "Machine",
        text_or_missing(metadata.machine.as_deref()),
        "Serial number",
        text_or_missing(metadata.serial_number.as_deref()),
    );
    row(
        out,
        "Axis",
        esc(&axis_shown(measurement)),
        "Operator",
        text_or_missing(metadata.operator.as_deref()),
    );
    row(
        out,
        "Date",
        text_or_missing(metadata.date.as_ref().map(|d| d.raw.as_str())),
        "Location",
        text_or_missing(metadata.location.as_deref()),
    );
    let wide = |out: &mut String, a: &str, b: String| {
        let _ = writeln!(out, "<tr><th>{a}</th><td colspan=\"3\">{b}</td></tr>");
    };
    if metadata.description.is_some() {
        wide(
            out,
            "Title",
            text_or_missing(metadata.description.as_deref()),
        );
    }
    wide(out, "Measurement", source_line(measurement));
    if let Some(after) = &input.after {
        wide(out, "Re-test", source_line(after.measurement));
    }
    if let Some(table) = &input.table {
        wide(
            out,
            "Compensation table",
            format!("{} ({})", esc(table.file), table.controller.name()),
        );
    }
    wide(
        out,
        "Standard",
        "ISO 230-2:2014, test of accuracy and repeatability of positioning of numerically \
         controlled axes; A and R with the coverage of that edition (x̄ ± 2s, R = 4s)"
            .to_string(),
    );
    out.push_str("</table>\n");
}

fn source_line(measurement: &Measurement) -> String {
    let metadata = &measurement.metadata;
    let file = metadata
        .source_file
        .as_ref()
        .map(|p| esc(&p.display().to_string()))
        .unwrap_or_else(|| "<span class=\"missing\">no file</span>".to_string());
    let format = metadata.source_format.map_or("", |f| f.name());
    format!(
        "{file} ({format}, {}; {} targets, {}↑ {}↓ runs)",
        metadata.length_unit.as_str(),
        measurement.targets_mm().len(),
        measurement.run_count(Direction::Up),
        measurement.run_count(Direction::Down)
    )
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

fn conditions(out: &mut String, input: &ReportInput<'_>) {
    out.push_str("<section id=\"conditions\">\n<h2>Test conditions and environment</h2>\n");
    let tests = tests_of(input);
    out.push_str("<table class=\"keep\">\n<thead><tr><th></th><th>unit</th>");
    for (name, _) in &tests {
        let _ = write!(out, "<th colspan=\"2\">{name}</th>");
    }
    out.push_str("</tr>\n<tr><th></th><th></th>");
    for _ in &tests {
        out.push_str("<th>start</th><th>end</th>");
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    test_rows(out, &tests);
    conformance_rows(out, &tests);
    setup_rows(out, &tests);
    environment_rows(out, &tests);
    out.push_str("</tbody></table>\n");
    refractive_index_explained(out);
    for (name, test) in &tests {
        let heading = if tests.len() > 1 { Some(*name) } else { None };
        refractive_index(out, heading, &test.evaluation.refractive_index);
    }
    out.push_str("</section>\n");
}

fn test_rows(out: &mut String, tests: &[(&str, &TestRecord<'_>)]) {
    let mut row = |label: &str, unit: &str, cell: &dyn Fn(&Measurement) -> String| {
        let _ = write!(out, "<tr><th>{label}</th><td>{unit}</td>");
        for (_, test) in tests {
            let _ = write!(out, "<td colspan=\"2\">{}</td>", cell(test.measurement));
        }
        out.push_str("</tr>\n");
    };
    row("Runs", "", &|m| {
        format!(
            "{}↑ {}↓",
            m.run_count(Direction::Up),
            m.run_count(Direction::Down)
        )
    });
    row("Targets", "mm", &|m| {
        let targets = m.targets_mm();
        format!(
            "{} from {} to {}",
            targets.len(),
            targets.first().copied().unwrap_or_default(),
            targets.last().copied().unwrap_or_default()
        )
    });
    row("Duration", "min", &|m| {
        m.metadata.duration_s().map_or_else(
            || "<span class=\"missing\">not recorded</span>".to_string(),
            |s| format!("{:.0}", s / 60.0),
        )
    });
}

/// The instrument and set-up (`Metadata::setup`), in mm and, for an inch
/// file, in inches beside; "not recorded" where the file does not say.
fn setup_rows(out: &mut String, tests: &[(&str, &TestRecord<'_>)]) {
    let missing = || "<span class=\"missing\">not recorded</span>".to_string();
    let inch = |m: &Measurement, value_mm: f64| {
        if m.metadata.length_unit == LengthUnit::Inch {
            format!(" ({} in)", inch_text(LengthUnit::Inch.from_mm(value_mm)))
        } else {
            String::new()
        }
    };
    type Cell<'a> = &'a dyn Fn(&Measurement) -> String;
    let rows: [(&str, &str, Cell<'_>); 6] = [
        ("Instrument", "", &|m| {
            text_or_missing(m.metadata.setup.instrument.as_deref())
        }),
        ("Instrument serial number", "", &|m| {
            text_or_missing(m.metadata.setup.instrument_serial.as_deref())
        }),
        ("Laser wavelength (vacuum)", "µm", &|m| {
            m.environment
                .vacuum_wavelength_um
                .map_or_else(missing, |w| format!("{w:.6}"))
        }),
        ("Feed", "mm/min", &|m| {
            m.metadata.setup.feed_mm_per_min.map_or_else(missing, |f| {
                format!("{f}{}", inch(m, f).replace(" in)", " in/min)"))
            })
        }),
        ("Dwell", "s", &|m| {
            m.metadata
                .setup
                .dwell_s
                .map_or_else(missing, |d| format!("{d}"))
        }),
        ("Measuring line: other axes at", "mm", &|m| {
            let axes = &m.metadata.setup.other_axes_mm;
            if axes.is_empty() {
                return missing();
            }
            let list: Vec<String> = axes
                .iter()
                .map(|(axis, at)| format!("{} {at}{}", esc(axis), inch(m, *at)))
                .collect();
            list.join(", ")
        }),
    ];
    let nothing = tests.iter().all(|(_, t)| {
        t.measurement.metadata.setup.is_empty()
            && t.measurement.environment.vacuum_wavelength_um.is_none()
    });
    if nothing {
        let _ = writeln!(
            out,
            "<tr><th>Instrument, set-up</th><td></td><td colspan=\"{}\">{}</td></tr>",
            2 * tests.len(),
            missing()
        );
        return;
    }
    for (label, unit, cell) in rows {
        let _ = write!(out, "<tr><th>{label}</th><td>{unit}</td>");
        for (_, test) in tests {
            let _ = write!(out, "<td colspan=\"2\">{}</td>", cell(test.measurement));
        }
        out.push_str("</tr>\n");
    }
}

/// The test against ISO 230-2 (`evaluate::conformance`): what the test has
/// and whether it meets each requirement, three rows of the conditions table.
fn conformance_rows(out: &mut String, tests: &[(&str, &TestRecord<'_>)]) {
    let verdict = |checks: &[Option<&Check>]| {
        if checks.iter().all(|c| c.is_some_and(|c| c.met)) {
            "<span class=\"met\">met</span>"
        } else if checks
            .iter()
            .all(|c| c.is_some_and(|c| c.requirement.is_recommendation()))
        {
            "<span class=\"missing\">not followed</span>"
        } else {
            "<span class=\"missing\">not met</span>"
        }
    };
    type Cell<'a> = &'a dyn Fn(&TestConformance) -> String;
    let rows: [(&str, Cell<'_>); 3] = [
        ("Runs for ISO 230-2", &|c| {
            let runs = c.check(Requirement::Runs);
            let both = c.check(Requirement::BothDirections);
            let directions = if both.is_some_and(|b| b.met) {
                "both directions"
            } else {
                "one direction"
            };
            format!(
                "{} per direction, {directions} (5 each way, 1 over 2000 mm): {}",
                runs.and_then(|r| r.found).unwrap_or_default(),
                verdict(&[runs, both])
            )
        }),
        ("Targets for ISO 230-2", &|c| {
            let count = c.check(Requirement::Targets);
            let density = c.check(Requirement::TargetsPerMetre);
            let per_metre = density
                .and_then(|d| d.found)
                .map_or_else(String::new, |d| format!(", {d:.1} per metre"));
            format!(
                "{}{per_metre} (at least 5, and 5 per metre): {}",
                c.targets,
                verdict(&[count, density])
            )
        }),
        ("Spacing for ISO 230-2", &|c| {
            let spacing = c.check(Requirement::IrregularSpacing);
            let found = spacing.and_then(|s| s.found).map_or_else(
                || "irregular".to_string(),
                |step| format!("constant step {} mm", signed(step, 3)),
            );
            format!("{found}: {}", verdict(&[spacing]))
        }),
    ];
    for (label, cell) in rows {
        let _ = write!(out, "<tr><th>{label}</th><td></td>");
        for (_, test) in tests {
            let _ = write!(
                out,
                "<td colspan=\"2\">{}</td>",
                cell(&test.evaluation.conformance)
            );
        }
        out.push_str("</tr>\n");
    }
}

fn environment_rows(out: &mut String, tests: &[(&str, &TestRecord<'_>)]) {
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
    for (label, unit, decimals, pick) in rows {
        let recorded = tests.iter().any(|(_, t)| !pick(t.measurement).is_empty());
        if !recorded && label.starts_with("Material temperature ") && !label.ends_with('1') {
            continue;
        }
        let _ = write!(out, "<tr><th>{label}</th><td>{unit}</td>");
        for (_, test) in tests {
            let value = pick(test.measurement);
            for v in [value.start, value.end] {
                let _ = write!(out, "{}", number_cell(v, decimals));
            }
        }
        out.push_str("</tr>\n");
    }
    let _ = write!(out, "<tr><th>Expansion coefficient</th><td>µm/(m·K)</td>");
    for (_, test) in tests {
        let value = test.measurement.environment.expansion_coefficient_ppm_per_k;
        let _ = write!(
            out,
            "{}",
            number_cell(value, 2).replace("<td", "<td colspan=\"2\"")
        );
    }
    out.push_str("</tr>\n");
}

fn number_cell(value: Option<f64>, decimals: usize) -> String {
    match value {
        Some(v) => format!("<td class=\"num\">{}</td>", signed(v, decimals)),
        None => "<td class=\"missing\">not recorded</td>".to_string(),
    }
}

/// A number with a fixed number of decimals and the minus sign for negatives.
fn signed(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    text.replacen('-', "−", 1)
}

fn refractive_index_explained(out: &mut String) {
    out.push_str(
        "<h3>Refractive index of air</h3>\n<p>The index the laser used is implied by the \
         environmental factor it recorded, λ<sub>vac</sub> / (2·n<sub>air</sub>·(1 + \
         α·(T<sub>material</sub> − 20 °C))); it is compared with Edlén's equation as the laser \
         software applies it (seed 001, eq. 36: n<sub>air</sub> = 1 + \
         7.86·10<sup>−5</sup>·P/(273 + T) − 1.5·10<sup>−11</sup>·H·(T<sup>2</sup> + 160), \
         T in °C, P in mbar, H in %) from the recorded air temperature, pressure and humidity. \
         A difference of 1 ppm is a length error of 1 µm per metre of travel.</p>\n",
    );
}

fn refractive_index(out: &mut String, test_name: Option<&str>, check: &RefractiveIndexCheck) {
    out.push_str("<div class=\"keep\">\n");
    if let Some(name) = test_name {
        let _ = writeln!(out, "<h4>{name}</h4>");
    }
    let wavelength = if check.wavelength_assumed {
        format!(
            "The file does not record the laser's vacuum wavelength; {} µm (HeNe) is assumed.",
            check.vacuum_wavelength_um
        )
    } else {
        format!(
            "Vacuum wavelength {} µm, as recorded.",
            check.vacuum_wavelength_um
        )
    };
    let made: Vec<(&str, &IndexAt)> = [("start", &check.start), ("end", &check.end)]
        .into_iter()
        .filter_map(|(when, c)| match c {
            IndexComparison::Made(at) => Some((when, at)),
            IndexComparison::Missing(_) => None,
        })
        .collect();
    if !made.is_empty() {
        out.push_str(
            "<table><thead><tr><th></th><th>factor [µm]</th><th>material correction [ppm]</th>\
             <th>n<sub>air</sub> implied</th><th>n<sub>air</sub> by eq. 36</th>\
             <th>difference [ppm]</th><th></th></tr></thead><tbody>\n",
        );
        for (when, at) in &made {
            let correction = at.material_correction_ppm.map_or_else(
                || "<span class=\"missing\">none (no material sensor or coefficient)</span>".into(),
                |c| signed(c, 3),
            );
            let verdict = if at.agrees() {
                format!("agrees (within ±{AGREEMENT_PPM} ppm)")
            } else {
                format!("<strong>differs by more than {AGREEMENT_PPM} ppm</strong>")
            };
            let _ = writeln!(
                out,
                "<tr><th>{when}</th><td class=\"num\">{:.8}</td><td class=\"num\">{correction}</td>\
                 <td class=\"num\">{:.9}</td><td class=\"num\">{:.9}</td>\
                 <td class=\"num\" data-ppm=\"{}\">{}</td><td>{verdict}</td></tr>",
                at.factor_um,
                at.implied_n,
                at.edlen_n,
                at.difference_ppm,
                signed_plus(at.difference_ppm, 2)
            );
        }
        out.push_str("</tbody></table>\n");
        let _ = writeln!(out, "<p class=\"note\">{wavelength}</p>");
        if made.iter().any(|(_, at)| !at.agrees()) {
            out.push_str(
                "<p class=\"attention\">The factor the laser applied does not match the recorded \
                 air: either the sensors and the laser disagreed during the test, the factor was \
                 entered by hand, or the laser's wavelength differs from the one assumed. Lengths \
                 in this test may be off by the difference shown, in µm per metre.</p>\n",
            );
        }
    }
    for (when, comparison) in [("start", &check.start), ("end", &check.end)] {
        if let IndexComparison::Missing(missing) = comparison {
            let _ = writeln!(
                out,
                "<p class=\"missing-note\">Refractive index not checked at the {when} of the test: the file does not \
                 record the {}.</p>",
                missing.join(", ")
            );
        }
    }
    out.push_str("</div>\n");
}

fn signed_plus(value: f64, decimals: usize) -> String {
    let text = signed(value, decimals);
    if value >= 0.0 {
        format!("+{text}")
    } else {
        text
    }
}

/// (row label, figure); a figure with directions gets a column for each.
const FIGURE_ROWS: [(&str, Figure); 6] = [
    ("A &nbsp;accuracy of positioning", Figure::A),
    ("E &nbsp;systematic positional deviation", Figure::E),
    ("R &nbsp;repeatability of positioning", Figure::R),
    ("M &nbsp;mean bidirectional positional deviation", Figure::M),
    ("B &nbsp;reversal value", Figure::B),
    ("B̄ &nbsp;mean reversal value", Figure::BMean),
];

/// A figure's value as `figures_um` gives it, µm.
fn figure_value(figures: &FiguresJson, figure: Figure) -> Option<f64> {
    match figure {
        Figure::A => figures.A,
        Figure::AUp => figures.A_up,
        Figure::ADown => figures.A_down,
        Figure::E => figures.E,
        Figure::EUp => figures.E_up,
        Figure::EDown => figures.E_down,
        Figure::M => figures.M,
        Figure::R => figures.R,
        Figure::RUp => figures.R_up,
        Figure::RDown => figures.R_down,
        Figure::B => figures.B,
        Figure::BMean => figures.B_mean,
    }
}

fn figures_section(out: &mut String, input: &ReportInput<'_>) {
    out.push_str(
        "<section id=\"figures\" class=\"keep\">\n<h2>ISO 230-2 figures [µm]</h2>\n<table class=\"figures\">\n",
    );
    let tests = tests_of(input);
    let figures: Vec<(&str, FiguresJson)> = tests
        .iter()
        .map(|(name, test)| (*name, FiguresJson::from_figures(&test.evaluation.figures)))
        .collect();
    let prefixes = ["before", "after"];
    out.push_str("<thead>");
    if figures.len() > 1 {
        out.push_str("<tr><th></th>");
        for (name, _) in &figures {
            let _ = write!(out, "<th colspan=\"3\">{name}</th>");
        }
        out.push_str("<th>change</th></tr>");
    }
    out.push_str("<tr><th>figure</th>");
    for _ in &figures {
        out.push_str("<th>bidirectional</th><th>↑</th><th>↓</th>");
    }
    if figures.len() > 1 {
        out.push_str("<th>bidirectional</th>");
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for (label, figure) in FIGURE_ROWS {
        let _ = write!(out, "<tr><th>{label}</th>");
        for ((_, f), prefix) in figures.iter().zip(prefixes) {
            out.push_str(&um_cell(
                &format!("{prefix}.figures_um.{}", figure.name()),
                figure_value(f, figure),
            ));
            for direction in [Direction::Up, Direction::Down] {
                match figure.directed(direction) {
                    Some(directed) => out.push_str(&um_cell(
                        &format!("{prefix}.figures_um.{}", directed.name()),
                        figure_value(f, directed),
                    )),
                    None => out.push_str("<td></td>"),
                }
            }
        }
        if let [(_, before), (_, after)] = figures.as_slice() {
            let change = figure_value(before, figure)
                .zip(figure_value(after, figure))
                .map(|(b, a)| a - b);
            let _ = write!(out, "<td class=\"num\">{}</td>", um(change));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table>\n");
    out.push_str(
        "<p class=\"note\">A: the spread of x̄ ± 2s over all targets and directions; E: of the \
         mean deviations x̄↑, x̄↓; R: the largest repeatability at a target, \
         max(2s↑ + 2s↓ + |B<sub>i</sub>|; 4s↑; 4s↓); M: of the bidirectional means x̄; B: the \
         largest |x̄↑ − x̄↓|; B̄: its signed mean (negative: the axis falls short in the \
         direction it moves). — means not evaluated.</p>\n",
    );
    inch_figures(out, &tests);
    for note in source_notes(input.before.measurement.metadata.source_format) {
        let _ = writeln!(
            out,
            "<p class=\"note\" id=\"source-note\">Note: {}.</p>",
            esc(note)
        );
    }
    out.push_str("</section>\n");
}

/// For an inch file, the bidirectional figures in inches too (the file's unit).
fn inch_figures(out: &mut String, tests: &[(&str, &TestRecord<'_>)]) {
    for (name, test) in tests {
        if test.measurement.metadata.length_unit != LengthUnit::Inch {
            continue;
        }
        let f = FiguresJson::from_figures(&test.evaluation.figures);
        let parts: Vec<String> = FIGURE_ROWS
            .iter()
            .flat_map(|&(_, figure)| {
                let directed = [(Direction::Up, "↑"), (Direction::Down, "↓")]
                    .into_iter()
                    .filter_map(move |(d, arrow)| Some((figure.directed(d)?, arrow)));
                let figures = std::iter::once((figure, "")).chain(directed);
                figures.filter_map(move |(shown, arrow)| {
                    let um = figure_value(&f, shown)?;
                    let name = if figure == Figure::BMean {
                        "B̄"
                    } else {
                        figure.name()
                    };
                    Some(format!(
                        "{name}{arrow} {} in",
                        inch_text(LengthUnit::Inch.from_mm(um_to_mm(um)))
                    ))
                })
            })
            .collect();
        if parts.is_empty() {
            continue;
        }
        let _ = writeln!(
            out,
            "<p class=\"note inch\">{name}, in inches (the unit of its file): {}.</p>",
            parts.join(", ")
        );
    }
}

type SvgOf<'a> = dyn Fn(&str) -> Option<(&'a NamedChart, &'a str)> + 'a;

fn figure(out: &mut String, svg_of: &SvgOf<'_>, name: &str, caption: &str) {
    let Some((named, svg)) = svg_of(name) else {
        return;
    };
    let labelled = svg.replacen(
        "<svg ",
        &format!(
            "<svg role=\"img\" aria-label=\"{}\" ",
            esc(&named.chart.title)
        ),
        1,
    );
    let _ = write!(
        out,
        "<figure id=\"plot-{name}\">\n{labelled}\n<figcaption>{caption}</figcaption>\n</figure>\n"
    );
}

const DEVIATION_CAPTION: &str = "Every reading: ▲ approached moving ↑ (positive direction), ▼ \
    moving ↓, thin lines join the readings of one run. Thick lines: the mean deviation per \
    direction, x̄↑ and x̄↓; dashed: the bidirectional mean x̄; shaded: x̄ ± 2s per direction, \
    whose extremes give A.";

fn deviation_section(out: &mut String, input: &ReportInput<'_>, svg_of: &SvgOf<'_>) {
    out.push_str("<section id=\"deviation\">\n<h2>Positional deviation</h2>\n");
    if input.after.is_none() {
        figure(out, svg_of, "deviation", DEVIATION_CAPTION);
    } else {
        out.push_str("<div class=\"pair\">\n");
        figure(
            out,
            svg_of,
            "deviation-before",
            &format!("First test. {DEVIATION_CAPTION}"),
        );
        figure(
            out,
            svg_of,
            "deviation-after",
            "Re-test, on the same scale as the first test.",
        );
        out.push_str("</div>\n");
    }
    out.push_str("</section>\n");
}

fn per_target_section(out: &mut String, input: &ReportInput<'_>) {
    out.push_str("<section id=\"per-target\">\n<h2>Per target [µm]</h2>\n");
    for ((name, test), prefix) in tests_of(input).into_iter().zip(["before", "after"]) {
        if input.after.is_some() {
            let _ = writeln!(out, "<h3>{name}</h3>");
        }
        per_target_table(out, test, prefix);
    }
    out.push_str(
        "<p class=\"note\">x̄: mean positional deviation (actual − target) per direction and \
         bidirectional; s: estimator of the standard uncertainty (n − 1); B<sub>i</sub> = \
         x̄↑ − x̄↓; R<sub>i</sub>↑ = 4s↑, R<sub>i</sub>↓ = 4s↓, R<sub>i</sub> = \
         max(2s↑ + 2s↓ + |B<sub>i</sub>|; R<sub>i</sub>↑; R<sub>i</sub>↓).</p>\n</section>\n",
    );
}

fn per_target_table(out: &mut String, test: &TestRecord<'_>, prefix: &str) {
    out.push_str(
        "<table class=\"per-target\"><thead><tr><th>target [mm]</th><th>n↑</th><th>n↓</th>\
         <th>x̄↑</th><th>x̄↓</th><th>x̄</th><th>s↑</th><th>s↓</th><th>B<sub>i</sub></th>\
         <th>R<sub>i</sub>↑</th><th>R<sub>i</sub>↓</th><th>R<sub>i</sub></th></tr></thead>\n<tbody>\n",
    );
    for (index, stats) in test.evaluation.per_target.iter().enumerate() {
        let t = PerTargetJson::from_stats(stats);
        let key = |name: &str| format!("{prefix}.per_target.{index}.{name}");
        let _ = write!(
            out,
            "<tr><td class=\"num\">{}{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>",
            t.target_mm,
            inch_beside(
                test.measurement.metadata.length_unit.as_str(),
                &[t.target_mm]
            ),
            t.n_up,
            t.n_down
        );
        for (name, value) in [
            ("mean_up_um", t.mean_up_um),
            ("mean_down_um", t.mean_down_um),
            ("mean_um", t.mean_um),
            ("s_up_um", t.s_up_um),
            ("s_down_um", t.s_down_um),
            ("B_um", t.B_um),
            ("R_up_um", t.R_up_um),
            ("R_down_um", t.R_down_um),
            ("R_um", t.R_um),
        ] {
            out.push_str(&um_cell(&key(name), value));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table>\n");
}

fn table_section(
    out: &mut String,
    input: &ReportInput<'_>,
    record: &TableRecord<'_>,
    svg_of: &SvgOf<'_>,
) {
    let table = record.table;
    out.push_str("<section id=\"table\">\n<h2>Compensation table and predicted re-test</h2>\n");
    let first = table.positions_mm.first().copied().unwrap_or_default();
    let last = table.positions_mm.last().copied().unwrap_or_default();
    let spacing = table
        .regular_step_mm()
        .map_or_else(|| "uneven spacing".to_string(), |s| format!("every {s} mm"));
    // A table read from its file carries no suggestion (only one built from
    // the test does); the value to type is in the controller's unit, which
    // `convert` prints (`Controller::backlash_parameter`), so the µm here is
    // labelled as the reversal, not as a parameter value.
    let backlash = table.suggested_backlash_mm.map_or_else(String::new, |b| {
        format!(
            "<tr><th>Reversal the table leaves</th><td>−B̄ = {} µm: set the controller's backlash parameter (<code>axcomp convert</code> prints it in the controller's unit)</td></tr>",
            signed(mm_to_um(b), 2)
        )
    });
    let _ = writeln!(
        out,
        "<table class=\"keep\"><tbody>\
         <tr><th>File</th><td>{file} ({controller})</td></tr>\
         <tr><th>Points</th><td>{count} from {first} to {last} mm, {spacing}</td></tr>\
         <tr><th>Values</th><td>{mode}; zero at the reference {reference} mm; largest |value| {max} µm</td></tr>\
         {backlash}</tbody></table>",
        file = esc(record.file),
        controller = record.controller.name(),
        count = table.positions_mm.len(),
        mode = match table.values.mode() {
            crate::compensate::TableMode::Mean => "one value per point for both directions",
            crate::compensate::TableMode::Bidirectional => "separate values moving ↑ and ↓",
        },
        reference = table.reference_mm,
        max = signed(mm_to_um(table.max_abs_mm()), 2),
    );
    figure(
        out,
        svg_of,
        "table",
        "The table in axcomp's convention: the axis error (actual − target) the controller \
         compensates, zero at the reference, whatever sign the file's format uses. Lines: as the \
         controller applies it, linear between the points and the end values held; dashed: the \
         first test's bidirectional mean, shifted to zero at the reference.",
    );
    if let Some(predicted) = prediction(&input.before, table) {
        let figures = &predicted.figures;
        let _ = writeln!(
            out,
            "<p>Predicted re-test along the laser line with the table active: the first test's \
             mean deviation in each direction with the table applied as the controller applies it \
             (linear between points, ends held), so the reversal the first test measured is in it \
             (a mean table leaves it, a bidirectional table takes it out). Its range (largest − \
             smallest) is <strong data-key=\"prediction.range_um\">{} µm</strong>, against {} µm \
             without the table. With the first test's scatter, the predicted re-test has \
             A {} µm, E {} µm and B {} µm (as <code>axcomp predict</code> gives them). Drift \
             and anything else that changes between the tests are not in the prediction: a \
             re-test adds them.</p>",
            um(Some(predicted.range_um())),
            um(Some(predicted.uncompensated_range_um())),
            um_strong("prediction.figures_um.A", figures.a_mm.map(mm_to_um)),
            um_strong("prediction.figures_um.E", figures.e_mm.map(mm_to_um)),
            um_strong("prediction.figures_um.B", figures.b_mm.map(mm_to_um)),
        );
        figure(
            out,
            svg_of,
            "predicted",
            "Predicted re-test with the table (solid) and the axis without it (dashed); with a \
             re-test, its measured means per direction (▲ ↑, ▼ ↓).",
        );
    }
    out.push_str("</section>\n");
}

fn diagnosis_section(out: &mut String, diagnosis: &Diagnosis, svg_of: &SvgOf<'_>) {
    out.push_str("<section id=\"diagnosis\">\n<h2>Diagnosis of the re-test</h2>\n");
    let basis = if diagnosis.predicted_from_first_test {
        "the prediction from the first test and the table"
    } else {
        "the re-test's own systematic error"
    };
    let _ = write!(
        out,
        "<p>The residual is each re-test reading minus {basis}. Effects the model does not \
         declare are fitted to it and accepted only with strong evidence (BIC) that also \
         predicts runs left out of the fit.</p>\n\
         <table class=\"keep\"><thead><tr><th>residual [µm]</th><th>RMS</th><th>largest |value|</th></tr></thead><tbody>\n\
         <tr><th>against the prediction</th>{}</tr>\n\
         <tr><th>after the accepted effects</th>{}</tr>\n\
         <tr><th>scatter of one reading left</th>{}<td></td></tr>\n</tbody></table>\n",
        residual_cells("residual_before", &diagnosis.residual_before),
        residual_cells("residual_after", &diagnosis.residual_after),
        um_cell("diagnosis.noise_um", Some(diagnosis.noise_um)),
    );
    if diagnosis.time_assumed {
        out.push_str(
            "<p class=\"note\">The file records no test duration: the times of the readings \
             are assumed from a typical ISO 230-2 cycle (this matters for drift).</p>\n",
        );
    }
    diagnosis_figures(out, diagnosis);
    accepted_effects(out, diagnosis);
    rejected_effects(out, diagnosis);
    unexplained(out, diagnosis);
    figure(
        out,
        svg_of,
        "residual",
        "Each reading's residual in the order measured (▲ moving ↑, ▼ moving ↓) and the fitted \
         model: the level along the axis plus the accepted effects.",
    );
    figure(
        out,
        svg_of,
        "residual-along-axis",
        if diagnosis.unexplained.significant {
            "The residual along the axis, the fitted model per direction (mean over the runs at \
             each target) and, in red, the targets where structure is left unexplained."
        } else {
            "The residual along the axis and the fitted model per direction (mean over the runs \
             at each target)."
        },
    );
    figure(
        out,
        svg_of,
        "effects",
        "What each accepted effect contributes to every reading, in the order measured.",
    );
    out.push_str("</section>\n");
}

/// The RMS and largest |value| cells of a residual.
fn residual_cells(name: &str, stats: &ResidualStats) -> String {
    let key = |what: &str| format!("diagnosis.{name}.{what}");
    um_cell(&key("rms_um"), Some(stats.rms_um))
        + &um_cell(&key("max_abs_um"), Some(stats.max_abs_um))
}

fn diagnosis_figures(out: &mut String, diagnosis: &Diagnosis) {
    let sets: [(&str, &str, &AxisFigures); 3] = [
        ("measured", "re-test, measured", &diagnosis.figures.measured),
        (
            "predicted",
            "predicted by the model",
            &diagnosis.figures.predicted,
        ),
        (
            "predicted_with_effects",
            "predicted with the effects",
            &diagnosis.figures.predicted_with_effects,
        ),
    ];
    out.push_str(
        "<h3>Figures of the re-test, measured and predicted [µm]</h3>\n<table class=\"keep figures\"><thead><tr><th>figure</th>",
    );
    for (_, label, _) in &sets {
        let _ = write!(out, "<th>{label}</th>");
    }
    out.push_str("</tr></thead><tbody>\n");
    for (label, figure) in FIGURE_ROWS {
        let _ = write!(out, "<tr><th>{label}</th>");
        for (set, _, figures) in &sets {
            let json = FiguresJson::from_figures(figures);
            out.push_str(&um_cell(
                &format!("diagnosis.figures.{set}.{}", figure.name()),
                figure_value(&json, figure),
            ));
        }
        out.push_str("</tr>\n");
    }
    out.push_str(
        "</tbody></table>\n<p class=\"note\">Predicted: the model's re-test with the \
         re-test's own scatter; with the effects: the same plus the accepted effects. Where \
         the last column matches the measured one, the effects explain the re-test.</p>\n",
    );
}

fn accepted_effects(out: &mut String, diagnosis: &Diagnosis) {
    out.push_str("<h3>Effects found</h3>\n");
    if diagnosis.accepted.is_empty() {
        out.push_str("<p>None: no effect lowers the information criterion enough.</p>\n");
        return;
    }
    out.push_str(
        "<table class=\"effects\"><thead><tr><th>effect</th><th>parameters</th>\
         <th>evidence</th><th>what it is and what to do</th></tr></thead><tbody>\n",
    );
    for (index, accepted) in diagnosis.accepted.iter().enumerate() {
        let parameters = accepted
            .effect
            .parameters()
            .into_iter()
            .map(|parameter| parameter_text(index, &parameter, &accepted.uncertainty))
            .collect::<Vec<_>>()
            .join("<br>");
        let evidence = &accepted.evidence;
        let trials = if evidence.trials > 1 {
            format!(" among {} shapes", evidence.trials)
        } else {
            String::new()
        };
        let warnings: String = accepted
            .warnings
            .iter()
            .map(|w| format!("<br><em>{}</em>", esc(w)))
            .collect();
        let _ = writeln!(
            out,
            "<tr><th>{}</th><td>{parameters}</td><td>ΔBIC {}{trials}; p {}; \
             prediction error of left-out runs {} → {} µm</td><td>{}{warnings}</td></tr>",
            accepted.effect.kind().name(),
            signed(evidence.delta_bic, 1),
            p_value(evidence.p_value),
            um(Some(evidence.cv_rmse_without_um)),
            um(Some(evidence.cv_rmse_with_um)),
            esc(&accepted.explanation),
        );
    }
    out.push_str("</tbody></table>\n");
}

/// One parameter with its standard uncertainty; µm values carry their data key.
fn parameter_text(index: usize, parameter: &Parameter, uncertainty: &[(&str, f64)]) -> String {
    let (key, name, unit) = (parameter.key, parameter.name, parameter.unit);
    let plus_minus = uncertainty
        .iter()
        .find(|(k, _)| *k == key)
        .map(|(_, u)| format!(" ± {u:.2}"))
        .unwrap_or_default();
    match parameter.value {
        ParameterValue::Run(run) => format!("run {run}"),
        ParameterValue::Number(value) if unit == "µm" => format!(
            "{name} = <span data-key=\"diagnosis.accepted.{index}.{key}\" data-um=\"{value}\">{}</span>{plus_minus} µm",
            um(Some(value))
        ),
        ParameterValue::Number(value) => format!("{name} = {value:.2}{plus_minus} {unit}"),
    }
}

/// `< 0.0001` or `= 0.1262`, to follow a "p".
fn p_value(p: f64) -> String {
    if p < 1e-4 {
        "< 0.0001".to_string()
    } else {
        format!("= {p:.4}")
    }
}

fn rejected_effects(out: &mut String, diagnosis: &Diagnosis) {
    if diagnosis.rejected.is_empty() {
        return;
    }
    out.push_str("<h3>Effects looked for and not found</h3>\n<ul class=\"rejected\">\n");
    for rejected in &diagnosis.rejected {
        let _ = writeln!(
            out,
            "<li><strong>{}</strong>: {}</li>",
            rejected.kind.name(),
            esc(&rejected.why)
        );
    }
    out.push_str("</ul>\n");
}

fn unexplained(out: &mut String, diagnosis: &Diagnosis) {
    let u = &diagnosis.unexplained;
    out.push_str("<h3>Unexplained structure</h3>\n");
    if u.significant {
        let places = if u.where_mm.is_empty() {
            "spread along the axis".to_string()
        } else {
            let list: Vec<String> = u.where_mm.iter().map(|x| format!("{x}")).collect();
            format!("largest at {} mm", list.join(", "))
        };
        let _ = writeln!(
            out,
            "<p class=\"attention\">The re-test has structure none of the effects explains \
             (lack of fit p {}; RMS of the per-target mean residual {} µm), {places}. \
             Look at the machine there: a step in the scale, a damaged screw, a collision, \
             or a sag the model does not have.</p>",
            p_value(u.p_value),
            um(Some(u.rms_um))
        );
    } else {
        let _ = writeln!(
            out,
            "<p>None: what the effects leave is the scatter of the readings (lack of fit p {}; \
             RMS of the per-target mean residual {} µm).</p>",
            p_value(u.p_value),
            um(Some(u.rms_um))
        );
    }
}

fn notes_section(out: &mut String, input: &ReportInput<'_>) {
    let tests = tests_of(input);
    let any = tests
        .iter()
        .any(|(_, t)| !t.warnings.is_empty() || !t.evaluation.outliers.is_empty());
    if !any {
        return;
    }
    out.push_str("<section id=\"notes\" class=\"keep\">\n<h2>Warnings</h2>\n<ul>\n");
    for (name, test) in tests {
        for warning in test.warnings {
            let _ = writeln!(out, "<li>{name}: {}</li>", esc(&warning.to_string()));
        }
        for outlier in &test.evaluation.outliers {
            let _ = writeln!(
                out,
                "<li>{name}: run {}{} is a suspected outlier (score {:.1}; {} µm off the other \
                 runs at {} mm); it is included in the figures.</li>",
                outlier.run,
                outlier.direction,
                outlier.score,
                signed_plus(mm_to_um(outlier.offset_mm), 2),
                outlier.worst_target_mm
            );
        }
    }
    out.push_str("</ul>\n</section>\n");
}

fn signatures(out: &mut String) {
    out.push_str(
        "<section id=\"signatures\" class=\"keep\">\n<h2>Acceptance</h2>\n\
         <table class=\"signatures\"><tbody>\
         <tr><th>Measured by</th><td></td><th>Date</th><td></td></tr>\
         <tr><th>Accepted by</th><td></td><th>Date</th><td></td></tr>\
         </tbody></table>\n</section>\n",
    );
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

fn css() -> String {
    format!(
        "@font-face {{ font-family: \"axcomp-plot\"; src: url(data:font/ttf;base64,{font}) format(\"truetype\"); }}\n{CSS}{verdict}",
        font = font_base64(),
        verdict = crate::report::verdict::CSS
    )
}

const CSS: &str = r#"@page { size: A4; margin: 15mm 14mm 16mm 14mm; }
html { background: #fff; }
body { font-family: "DejaVu Sans", "Liberation Sans", Arial, sans-serif; font-size: 14px;
  line-height: 1.4; color: #111; background: #fff; max-width: 1000px; margin: 0 auto; padding: 16px 20px; }
h1 { font-size: 23px; margin: 0; }
h2 { font-size: 18px; margin: 26px 0 8px; padding-bottom: 2px; border-bottom: 2px solid #1f5faa;
  break-after: avoid; page-break-after: avoid; }
h3 { font-size: 15px; margin: 16px 0 6px; break-after: avoid; page-break-after: avoid; }
h4 { font-size: 14px; margin: 10px 0 4px; break-after: avoid; page-break-after: avoid; }
.subtitle { margin: 2px 0 12px; color: #333; }
table { border-collapse: collapse; margin: 6px 0; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #b8bec6; padding: 2px 7px; vertical-align: top; }
th { text-align: left; font-weight: 600; }
thead th { background: #eef2f7; text-align: center; }
td.num { text-align: right; white-space: nowrap; }
table.meta { width: 100%; }
table.meta th { width: 16%; background: #f6f8fa; }
table.figures td.num { min-width: 4.5em; }
table.figures tbody th { white-space: nowrap; }
table.per-target { font-size: 12.5px; }
table.effects td, table.effects th { font-size: 13px; }
table.signatures { width: 100%; }
table.signatures td { height: 2.6em; width: 34%; }
.missing, td.missing { color: #777; font-style: italic; }
.note, .missing-note, figcaption { font-size: 12.5px; color: #333; }
.attention { border-left: 4px solid #c81414; padding: 4px 10px; background: #fdf3f3; }
figure { margin: 12px 0; break-inside: avoid; page-break-inside: avoid; }
figure svg { display: block; width: 100%; height: auto; }
svg text { font-family: "axcomp-plot", "DejaVu Sans", sans-serif; }
.keep, tr { break-inside: avoid; page-break-inside: avoid; }
thead { display: table-header-group; }
footer { margin-top: 24px; font-size: 12px; color: #444; border-top: 1px solid #ccc; }
code { font-size: 0.95em; }
@media (min-width: 1500px) {
  body { max-width: 1560px; }
  .pair { display: grid; grid-template-columns: 1fr 1fr; gap: 16px; }
}
@media print {
  body { max-width: none; margin: 0; padding: 0; font-size: 9.5pt; }
  h1 { font-size: 16pt; } h2 { font-size: 12.5pt; } h3 { font-size: 10.5pt; }
  table.per-target { font-size: 8.5pt; }
  .note, .missing-note, figcaption { font-size: 8.5pt; }
  .pair { display: block; }
  thead th, table.meta th, .attention { background: none; }
  section { break-before: auto; }
}
"#;

#[cfg(test)]
mod tests {
    use super::*;

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
