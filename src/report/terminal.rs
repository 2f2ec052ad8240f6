//! The terminal report of `axcomp evaluate`: header, per-target table, axis figures.
//!
//! Renders from the JSON wire object, so the terminal and `--json` can never
//! disagree. Values are µm (″ on a rotary axis) with two decimals; `—`
//! means "not evaluated".

use std::fmt::Write;

use tabled::builder::Builder;
use tabled::settings::object::Columns;
use tabled::settings::{Alignment, Style};
use unicode_width::UnicodeWidthStr;

use crate::evaluate::standard::vdi_figure_name;
use crate::report::format::{
    NOT_EVALUATED, inch_beside, push_integer, push_shortest, push_um, text_of, um,
};
use crate::report::json::{EvaluationJson, OutlierJson, PerTargetJson, StartEndJson};

/// Renders the whole evaluation report.
pub fn evaluation_report(report: &EvaluationJson) -> String {
    let mut out = String::new();
    header(&mut out, report);
    out.push('\n');
    let unit = report.deviation_unit();
    let _ = writeln!(out, "Per target [{unit}]");
    per_target_table(&mut out, report);
    let _ = writeln!(out, "\n\nAxis figures [{unit}] ({})", report.standard_name);
    // The ISO 230-2 family's figures in their table (↑, ↓ beside each);
    // another standard's one per row.
    let iso_family = report.figures().is_iso230_2();
    if iso_family {
        out.push_str(&figures_table(report));
    } else {
        out.push_str(&keyed_figures_table(report));
    }
    if report.definitions_reconstructed {
        let _ = write!(
            out,
            "\nDefinitions reconstructed from public sources, not read in the standard (docs/src/evaluate.md, Standards)."
        );
    }
    out.push('\n');
    if let Some(uncertainty) = &report.uncertainty_um {
        // A figure is evaluated when any of its directions has a value (E↑ of a one-direction test).
        let evaluated: Vec<&str> = ["E", "M", "A"]
            .into_iter()
            .filter(|figure| {
                report.figures().values.iter().any(|(key, value)| {
                    value.is_some()
                        && (key == figure
                            || key.strip_prefix(figure).is_some_and(|d| d.starts_with('_')))
                })
            })
            .collect();
        out.push_str(&crate::report::uncertainty::terminal(
            uncertainty,
            &evaluated,
        ));
    }
    if !report.outliers.is_empty() {
        out.push_str("\nSuspected outlier runs (included; exclude with --exclude-run RUN:DIRECTION only if you know why)\n");
        for o in report.outliers.iter().map(OutlierJson::shown) {
            let _ = writeln!(
                out,
                "  run {}:{}  score {:.1}  largest offset {:+.2} {unit} at {}{}",
                o.run,
                o.direction,
                o.score,
                o.offset,
                o.worst_target,
                report.position_unit()
            );
        }
    }
    if let Some(verdict) = &report.verdict {
        out.push_str(&crate::report::verdict::terminal(verdict));
    }
    for note in &report.notes {
        let _ = writeln!(out, "\nNote: {note}.");
    }
    out
}

fn header(out: &mut String, r: &EvaluationJson) {
    let text = |value: &Option<String>| value.clone().unwrap_or_else(|| NOT_EVALUATED.to_string());
    let mut rows: Vec<(&str, String)> = Vec::new();
    let source = match (&r.source_file, r.format) {
        (Some(file), Some(format)) => format!("{file} ({format}, {})", r.length_unit),
        (None, Some(format)) => format.to_string(),
        _ => NOT_EVALUATED.to_string(),
    };
    rows.push(("File", source));
    let serial = r
        .metadata
        .serial_number
        .as_ref()
        .map(|s| format!(", serial {s}"))
        .unwrap_or_default();
    rows.push(("Machine", format!("{}{serial}", text(&r.metadata.machine))));
    rows.push((
        "Axis",
        r.axis_source
            .describe(r.axis.as_deref().unwrap_or_default()),
    ));
    rows.push(("Date", text(&r.metadata.date)));
    if r.metadata.operator.is_some() {
        rows.push(("Operator", text(&r.metadata.operator)));
    }
    if r.metadata.location.is_some() {
        rows.push(("Location", text(&r.metadata.location)));
    }
    if r.metadata.description.is_some() {
        rows.push(("Title", text(&r.metadata.description)));
    }
    let first = r.targets().first().copied().unwrap_or_default();
    let last = r.targets().last().copied().unwrap_or_default();
    let excluded = if r.excluded_runs.is_empty() {
        String::new()
    } else {
        format!(" (excluded: {})", r.excluded_runs.join(", "))
    };
    rows.push(("Runs", format!("{}↑ {}↓{excluded}", r.runs.up, r.runs.down)));
    rows.push((
        "Targets",
        format!(
            "{} from {first} to {last}{}{}",
            r.targets().len(),
            r.position_unit(),
            inch_beside(r.length_unit, &[first, last])
        ),
    ));
    rows.push(("Test", r.test_conformance.title.clone()));
    rows.push(("Environment", environment_line(r)));
    for (key, value) in rows {
        let _ = writeln!(out, "{key:<12} {value}");
    }
}

fn environment_line(r: &EvaluationJson) -> String {
    let e = &r.environment;
    let pair = |value: &StartEndJson, unit: &str, decimals: usize| match (value.start, value.end) {
        (Some(s), Some(t)) => Some(format!("{s:.decimals$} → {t:.decimals$} {unit}")),
        (Some(v), None) | (None, Some(v)) => Some(format!("{v:.decimals$} {unit}")),
        (None, None) => None,
    };
    let mut parts = Vec::new();
    if let Some(air) = pair(&e.air_temperature_c, "°C", 2) {
        parts.push(format!("air {air}"));
    }
    if let Some(p) = pair(&e.air_pressure_kpa, "kPa", 2) {
        parts.push(p);
    }
    if let Some(h) = pair(&e.air_humidity_pct, "%RH", 1) {
        parts.push(h);
    }
    for (index, sensor) in e.material_temperature_c.iter().enumerate() {
        if let Some(t) = pair(sensor, "°C", 2) {
            parts.push(format!("material {} {t}", index + 1));
        }
    }
    if let Some(c) = e.expansion_coefficient_ppm_per_k {
        parts.push(format!("expansion {c:.2} ppm/K"));
    }
    if parts.is_empty() {
        "not recorded".to_string()
    } else {
        parts.join("; ")
    }
}

/// The per-target table's columns.
const PER_TARGET_COLUMNS: usize = 12;

/// The per-target table as `tabled`'s `Style::psql()` with every column
/// right-aligned draws it, byte for byte, each row written straight into
/// the report.
///
/// Drawn here rather than by `tabled::Table`, which keeps every cell as a
/// `String` with its own layout state (a large test has 120 000 cells);
/// the small tables keep `tabled`.
/// Fast path: with it and the others of the evaluate report, a 10 000-target × 10-run `evaluate` takes 0.009 s cpu whole process (quiet 2-core machine, 2026-11-27); with `tabled` and `{:.2}` it took 2× that.
fn per_target_table(out: &mut String, r: &EvaluationJson) {
    let target_header = format!("target [{}]", r.position_unit().trim_start());
    let header: [&str; PER_TARGET_COLUMNS] = [
        &target_header,
        "n↑",
        "n↓",
        "x̄↑",
        "x̄↓",
        "x̄",
        "s↑",
        "s↓",
        "B_i",
        "R_i↑",
        "R_i↓",
        "R_i",
    ];
    let widths = column_widths(header.map(cell_width), &r.per_target);
    let line_width: usize = widths.iter().map(|w| w + 3).sum();
    // Written as bytes into the report's own buffer (a byte is pushed
    // without the encoding a `String` push goes through), which is text again after.
    let mut table = std::mem::take(out).into_bytes();
    table.reserve((r.per_target.len() + 2) * (line_width + 8));
    for (column, cell) in header.iter().enumerate() {
        push_cell(
            &mut table,
            column,
            widths[column],
            cell.as_bytes(),
            cell_width(cell),
        );
    }
    table.push(b'\n');
    for (column, width) in widths.iter().enumerate() {
        if column > 0 {
            table.push(b'+');
        }
        table.extend(std::iter::repeat_n(b'-', width + 2));
    }
    let mut row = Vec::new();
    for t in &r.per_target {
        table.push(b'\n');
        let ends = row_cells(&mut row, t);
        let mut start = 0;
        for (column, end) in ends.into_iter().enumerate() {
            let cell = &row[start..end];
            push_cell(
                &mut table,
                column,
                widths[column],
                cell,
                data_cell_width(cell),
            );
            start = end;
        }
    }
    *out = text_of(table);
}

/// The cells of one row, written one after another into `row` (emptied
/// first), and where each ends.
fn row_cells(row: &mut Vec<u8>, t: &PerTargetJson) -> [usize; PER_TARGET_COLUMNS] {
    row.clear();
    let mut ends = [0; PER_TARGET_COLUMNS];
    push_shortest(row, t.target());
    ends[0] = row.len();
    let (n_up, n_down) = t.readings();
    push_integer(row, n_up as u64);
    ends[1] = row.len();
    push_integer(row, n_down as u64);
    ends[2] = row.len();
    for (column, (_, value)) in t.cells().into_iter().enumerate() {
        push_um(row, value);
        ends[column + 3] = row.len();
    }
    ends
}

/// The columns each column of the table takes: its header's or its widest
/// cell's. A target's text is made to be measured (the shortest text of a
/// number is not the longest at the largest number); a count's or a
/// two-decimal value's text is longest at the column's largest or its
/// smallest value (and `—`, one column, where a value is missing).
fn column_widths(
    header: [usize; PER_TARGET_COLUMNS],
    rows: &[PerTargetJson],
) -> [usize; PER_TARGET_COLUMNS] {
    let mut widths = header;
    let mut text = Vec::new();
    let mut widen = |column: usize, text: &mut Vec<u8>| {
        widths[column] = widths[column].max(data_cell_width(text));
        text.clear();
    };
    let mut most_readings = (0, 0);
    let mut lowest = [f64::INFINITY; 9];
    let mut highest = [f64::NEG_INFINITY; 9];
    let mut missing = [false; 9];
    for t in rows {
        push_shortest(&mut text, t.target());
        widen(0, &mut text);
        let (n_up, n_down) = t.readings();
        most_readings = (most_readings.0.max(n_up), most_readings.1.max(n_down));
        for (column, (_, value)) in t.cells().into_iter().enumerate() {
            match value {
                Some(v) => {
                    lowest[column] = lowest[column].min(v);
                    highest[column] = highest[column].max(v);
                }
                None => missing[column] = true,
            }
        }
    }
    if !rows.is_empty() {
        push_integer(&mut text, most_readings.0 as u64);
        widen(1, &mut text);
        push_integer(&mut text, most_readings.1 as u64);
        widen(2, &mut text);
    }
    for column in 0..9 {
        let extremes = [lowest[column], highest[column]];
        for value in extremes.into_iter().filter(|v| v.is_finite()) {
            push_um(&mut text, Some(value));
            widen(column + 3, &mut text);
        }
        if missing[column] {
            push_um(&mut text, None);
            widen(column + 3, &mut text);
        }
    }
    widths
}

/// The columns a data cell takes: every one is ASCII (a number) but
/// [`NOT_EVALUATED`], which takes one.
fn data_cell_width(cell: &[u8]) -> usize {
    if cell == NOT_EVALUATED.as_bytes() {
        1
    } else {
        cell.len()
    }
}

/// The columns a cell takes in a terminal.
fn cell_width(cell: &str) -> usize {
    if cell.is_ascii() {
        cell.len()
    } else {
        UnicodeWidthStr::width(cell)
    }
}

/// One cell as `Style::psql()` draws it, right-aligned in its column of
/// `width`: the column's separator, a space, the padding, the cell (which
/// takes `cell_width` columns) and a space.
fn push_cell(out: &mut Vec<u8>, column: usize, width: usize, cell: &[u8], cell_width: usize) {
    if column > 0 {
        out.push(b'|');
    }
    out.push(b' ');
    out.extend(std::iter::repeat_n(b' ', width - cell_width));
    out.extend_from_slice(cell);
    out.push(b' ');
}

/// A standard's figures one per row, as its keys name them (VDI 3441).
fn keyed_figures_table(r: &EvaluationJson) -> String {
    let mut builder = Builder::default();
    builder.push_record(["figure", "value"]);
    for (key, value) in &r.figures().values {
        builder.push_record([format!("{key}  {}", vdi_figure_name(key)), um(*value)]);
    }
    let mut table = builder.build();
    table
        .with(Style::psql())
        .modify(Columns::new(1..), Alignment::right());
    table.to_string()
}

fn figures_table(r: &EvaluationJson) -> String {
    let f = r.figures();
    // `11.96 ± 3.49` where U of the figure is evaluated (E, M, A).
    let u = r.uncertainty_um.as_ref();
    let with_u = |value: Option<f64>, expanded: Option<f64>| match (value, expanded) {
        (Some(_), Some(expanded)) => format!("{} ± {}", um(value), um(Some(expanded))),
        _ => um(value),
    };
    let mut builder = Builder::default();
    builder.push_record(["figure", "bidirectional", "↑", "↓"]);
    builder.push_record([
        "A  accuracy".to_string(),
        with_u(f.get("A"), u.map(|u| u.A)),
        um(f.get("A_up")),
        um(f.get("A_down")),
    ]);
    builder.push_record([
        "E  systematic deviation".to_string(),
        with_u(f.get("E"), u.map(|u| u.E)),
        um(f.get("E_up")),
        um(f.get("E_down")),
    ]);
    builder.push_record([
        "R  repeatability".to_string(),
        um(f.get("R")),
        um(f.get("R_up")),
        um(f.get("R_down")),
    ]);
    builder.push_record([
        "M  mean bidirectional deviation".to_string(),
        with_u(f.get("M"), u.map(|u| u.M)),
        String::new(),
        String::new(),
    ]);
    builder.push_record([
        "B  reversal value".to_string(),
        um(f.get("B")),
        String::new(),
        String::new(),
    ]);
    builder.push_record([
        "B̄  mean reversal value".to_string(),
        um(f.get("B_mean")),
        String::new(),
        String::new(),
    ]);
    let mut table = builder.build();
    table
        .with(Style::psql())
        .modify(Columns::new(1..), Alignment::right());
    table.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::{Direction, Environment, Measurement, Metadata, Run};
    use crate::units::AngleUnit;

    fn run(direction: Direction, number: u32, deviations_mm: [Option<f64>; 3]) -> Run {
        Run {
            direction,
            number,
            start_time_s: None,
            deviations: deviations_mm.to_vec(),
        }
    }

    /// The table drawn cell by cell is the one `tabled` draws from the
    /// same cells: widths from the widest cell wherever it is (a negative
    /// smallest value, a long target, `—`), every column right-aligned.
    #[test]
    fn per_target_table_is_tableds_psql_table() {
        let (up, down) = (Direction::Up, Direction::Down);
        let runs = vec![
            run(up, 1, [Some(0.0123), Some(-0.1), None]),
            run(down, 1, [Some(0.000001), Some(-0.10004), Some(0.2)]),
            run(up, 2, [Some(0.0124), Some(-0.09), Some(0.21)]),
            run(down, 2, [Some(-0.000001), Some(-0.1), Some(0.19999)]),
        ];
        let measurement = Measurement::new(
            "X",
            vec![0.0, 12.5, 1000.125],
            runs,
            Environment::default(),
            Metadata::default(),
        )
        .unwrap();
        let report = EvaluationJson::from_evaluation(
            &measurement,
            crate::evaluate::evaluate(&measurement),
            &[],
            &[],
            AngleUnit::default(),
        );
        let mut drawn = String::new();
        per_target_table(&mut drawn, &report);

        let mut builder = Builder::default();
        builder.push_record([
            format!("target [{}]", report.position_unit().trim_start()),
            "n↑".into(),
            "n↓".into(),
            "x̄↑".into(),
            "x̄↓".into(),
            "x̄".into(),
            "s↑".into(),
            "s↓".into(),
            "B_i".into(),
            "R_i↑".into(),
            "R_i↓".into(),
            "R_i".into(),
        ]);
        for t in &report.per_target {
            let (n_up, n_down) = t.readings();
            let mut row = vec![t.target().to_string(), n_up.to_string(), n_down.to_string()];
            row.extend(t.cells().map(|(_, value)| um(value)));
            builder.push_record(row);
        }
        let mut table = builder.build();
        table
            .with(Style::psql())
            .modify(Columns::new(..), Alignment::right());
        assert_eq!(drawn, table.to_string());
        // The cases the widths come from are there.
        for cell in [" 1000.125 ", " -100.02 ", " — ", " 0.00 "] {
            assert!(drawn.contains(cell), "{cell} in\n{drawn}");
        }
    }

    #[test]
    fn missing_values_show_a_dash_not_zero() {
        assert_eq!(um(None), "—");
        assert_eq!(um(Some(1.234)), "1.23");
        assert_eq!(um(Some(-0.005)), "-0.01");
    }
}
