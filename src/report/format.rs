//! How the reports write a value: µm with two decimals (`—` when not
//! evaluated), inches beside the mm of an inch file, HTML escaping, and a µm
//! cell that carries its source (the JSON key and the full value, so a test can
//! check the page against `--json`). Every report file uses these; this file
//! uses none of them.

use crate::units::LengthUnit;

/// How a not-evaluated value is shown.
pub const NOT_EVALUATED: &str = "—";

/// Formats an optional µm value with two decimals, or `—`.
pub fn um(value: Option<f64>) -> String {
    value.map_or_else(
        || NOT_EVALUATED.to_string(),
        // −0.004 µm is 0.00, not "-0.00".
        |v| format!("{:.2}", if v.abs() < 0.005 { 0.0 } else { v }),
    )
}

/// A length in an inch file's own unit, ` (… in)`, beside the mm; empty for mm files.
pub fn inch_beside(length_unit: &str, values_mm: &[f64]) -> String {
    if LengthUnit::from_name(length_unit) != Some(LengthUnit::Inch) {
        return String::new();
    }
    let inches: Vec<String> = values_mm
        .iter()
        .map(|v| inch_text(LengthUnit::Inch.from_mm(*v)))
        .collect();
    format!(" ({} in)", inches.join(" to "))
}

/// Inches with at most six decimals (0.025 µm), no trailing zeros.
pub fn inch_text(value_in: f64) -> String {
    let text = format!("{value_in:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".to_string()
    } else {
        text.to_string()
    }
}

/// Escapes text for HTML content and attribute values.
pub fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// A µm cell with its source (see the module doc).
pub fn um_cell(key: &str, value: Option<f64>) -> String {
    format!(
        "<td class=\"num\" {}>{}</td>",
        source(key, value),
        um(value)
    )
}

/// The `data-key` and `data-um` attributes of a µm value.
pub fn source(key: &str, value: Option<f64>) -> String {
    let full = value.map_or_else(|| "null".to_string(), |v| v.to_string());
    format!("data-key=\"{}\" data-um=\"{full}\"", esc(key))
}
