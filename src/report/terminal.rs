//! The terminal report of `axcomp evaluate`: header, per-target table, axis figures.
//!
//! Renders from the JSON wire object, so the terminal and `--json` can never
//! disagree. Values are µm with two decimals; `—` means "not evaluated".

use std::fmt::Write;

use tabled::builder::Builder;
use tabled::settings::object::Columns;
use tabled::settings::{Alignment, Style};

use crate::report::format::{NOT_EVALUATED, inch_beside, um};
use crate::report::json::{EvaluationJson, StartEndJson};

/// Renders the whole evaluation report.
pub fn evaluation_report(report: &EvaluationJson) -> String {
    let mut out = String::new();
    header(&mut out, report);
    out.push('\n');
    out.push_str("Per target [µm]\n");
    out.push_str(&per_target_table(report));
    out.push_str("\n\nAxis figures [µm] (ISO 230-2)\n");
    out.push_str(&figures_table(report));
    out.push('\n');
    if !report.outliers.is_empty() {
        out.push_str("\nSuspected outlier runs (included; exclude with --exclude-run RUN:DIRECTION only if you know why)\n");
        for o in &report.outliers {
            let _ = writeln!(
                out,
                "  run {}:{}  score {:.1}  largest offset {:+.2} µm at {} mm",
                o.run, o.direction, o.score, o.offset_um, o.worst_target_mm
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
    rows.push(("Axis", r.axis_source.describe(&r.axis)));
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
    let first = r.targets_mm.first().copied().unwrap_or_default();
    let last = r.targets_mm.last().copied().unwrap_or_default();
    let excluded = if r.excluded_runs.is_empty() {
        String::new()
    } else {
        format!(" (excluded: {})", r.excluded_runs.join(", "))
    };
    rows.push(("Runs", format!("{}↑ {}↓{excluded}", r.runs.up, r.runs.down)));
    rows.push((
        "Targets",
        format!(
            "{} from {first} to {last} mm{}",
            r.targets_mm.len(),
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

fn per_target_table(r: &EvaluationJson) -> String {
    let mut builder = Builder::default();
    builder.push_record([
        "target [mm]",
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
    ]);
    for t in &r.per_target {
        builder.push_record([
            format!("{}", t.target_mm),
            t.n_up.to_string(),
            t.n_down.to_string(),
            um(t.mean_up_um),
            um(t.mean_down_um),
            um(t.mean_um),
            um(t.s_up_um),
            um(t.s_down_um),
            um(t.B_um),
            um(t.R_up_um),
            um(t.R_down_um),
            um(t.R_um),
        ]);
    }
    let mut table = builder.build();
    table
        .with(Style::psql())
        .modify(Columns::new(0..), Alignment::right());
    table.to_string()
}

fn figures_table(r: &EvaluationJson) -> String {
    let f = &r.figures_um;
    let mut builder = Builder::default();
    builder.push_record(["figure", "bidirectional", "↑", "↓"]);
    builder.push_record(["A  accuracy".to_string(), um(f.A), um(f.A_up), um(f.A_down)]);
    builder.push_record([
        "E  systematic deviation".to_string(),
        um(f.E),
        um(f.E_up),
        um(f.E_down),
    ]);
    builder.push_record([
        "R  repeatability".to_string(),
        um(f.R),
        um(f.R_up),
        um(f.R_down),
    ]);
    builder.push_record([
        "M  mean bidirectional deviation".to_string(),
        um(f.M),
        String::new(),
        String::new(),
    ]);
    builder.push_record([
        "B  reversal value".to_string(),
        um(f.B),
        String::new(),
        String::new(),
    ]);
    builder.push_record([
        "B̄  mean reversal value".to_string(),
        um(f.B_mean),
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

    #[test]
    fn missing_values_show_a_dash_not_zero() {
        assert_eq!(um(None), "—");
        assert_eq!(um(Some(1.234)), "1.23");
        assert_eq!(um(Some(-0.005)), "-0.01");
    }
}
