//! The terminal report of `axcomp diagnose`, from its JSON object.

use std::fmt::Write;

use super::{Cell, DiagnoseJson};
use crate::report::format::{pad_name, um};

/// The terminal report.
pub fn render(report: &DiagnoseJson) -> String {
    let report = report.shown();
    let (dev, pos) = (report.deviation.suffix(), report.position_suffix);
    let mut out = String::new();
    let source = match (report.before, report.table) {
        (Some(before), Some(table)) => format!("predicted from {before} with {table}"),
        (Some(before), None) => format!("predicted from {before} (no table)"),
        _ => "no first test: structure between runs only".to_string(),
    };
    let _ = writeln!(out, "Re-test      {} ({source})", report.after);
    let (b, a) = (report.residual_before, report.residual_after);
    let _ = writeln!(
        out,
        "Residual     rms {}{dev}, max {}{dev}; with the effects rms {}{dev}, max {}{dev}; noise {}{dev}",
        um(Some(b.0)),
        um(Some(b.1)),
        um(Some(a.0)),
        um(Some(a.1)),
        um(Some(report.noise)),
    );
    let _ = writeln!(out, "\nFound");
    if report.effects.is_empty() {
        let _ = writeln!(out, "  nothing beyond noise");
    }
    for effect in &report.effects {
        let params: Vec<String> = effect
            .params
            .iter()
            .map(|(key, cell, sigma)| match (cell, sigma) {
                // A run has no uncertainty: it is shown as it is.
                (Cell::Number(v), Some(u)) => format!("{key} = {v:.2} ± {u:.2}"),
                // A number without an uncertainty (a phase): 4 decimals, as the effects file.
                (Cell::Number(v), None) => format!("{key} = {v:.4}"),
                (Cell::Text(text), _) => format!("{key} = {text}"),
            })
            .collect();
        let _ = writeln!(
            out,
            "  {:<12} {}   (ΔBIC {:.1}; runs left out predicted {:.2} → {:.2}{dev})",
            effect.kind,
            params.join(", "),
            effect.delta_bic,
            effect.cv_rmse_without,
            effect.cv_rmse_with,
        );
        let _ = writeln!(out, "  {:<12} {}", "", effect.explanation);
        if effect.kind == "reversal"
            && let Some(friction) = report.friction
        {
            for line in friction.lines() {
                let _ = writeln!(out, "  {:<12} {line}", "");
            }
        }
        for warning in effect.warnings {
            let _ = writeln!(out, "  {:<12} warning: {warning}", "");
        }
    }
    let _ = writeln!(out, "\nNot found");
    for rejected in report.rejected {
        let _ = writeln!(out, "  {:<12} {}", rejected.kind, rejected.why);
    }
    let u = &report.unexplained;
    let _ = writeln!(out);
    if u.significant {
        let places: Vec<String> = u.places.iter().map(|x| format!("{x}")).collect();
        let _ = writeln!(
            out,
            "Unexplained  significant structure (p = {:.1e}), rms {}{dev}, largest at {}{pos}: no known effect describes it",
            u.p_value,
            um(Some(u.rms)),
            places.join(", ")
        );
    } else {
        let _ = writeln!(
            out,
            "Unexplained  nothing significant (p = {:.2}), rms {}{dev}",
            u.p_value,
            um(Some(u.rms))
        );
    }
    // The first column fits its heading: `Figures [µrad]` is wider than `Figures [µm]`.
    let heading = format!("Figures [{}]", dev.trim());
    let width = heading.chars().count().max(12);
    let _ = writeln!(
        out,
        "\n{heading:<width$} |  measured | predicted | predicted with effects   ({}{})",
        report.standard_name,
        if report.definitions_reconstructed {
            "; definitions reconstructed from public sources (docs/src/evaluate.md, Standards)"
        } else {
            ""
        }
    );
    let _ = writeln!(
        out,
        "{}+-----------+-----------+-----------------------",
        "-".repeat(width + 1)
    );
    let f = report.figures;
    for (name, key) in f.measured.terminal_rows() {
        let _ = writeln!(
            out,
            " {} | {:>9} | {:>9} | {:>22}",
            pad_name(name, width - 1),
            um(f.measured.get(key)),
            um(f.predicted.get(key)),
            um(f.predicted_with_effects.get(key))
        );
    }
    out
}
