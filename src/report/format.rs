//! How the reports write a value: µm with two decimals (`—` when not
//! evaluated), inches beside the mm of an inch file, HTML escaping, and a µm
//! cell that carries its source (the JSON key and the full value, so a test can
//! check the page against `--json`). Every report file uses these; this file
//! uses none of them.

use std::fmt;

use askama::Template;

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
    // Writing into a String cannot fail.
    let _ = escape_into(&mut out, text);
    out
}

/// The report templates' escaper (`askama.toml`): the same five characters
/// as [`esc`], so text from a file is escaped alike wherever the page shows it.
#[derive(Clone, Copy, Debug)]
pub struct Html;

impl askama::filters::Escaper for Html {
    fn write_escaped_str<W: fmt::Write>(&self, dest: W, string: &str) -> fmt::Result {
        escape_into(dest, string)
    }
}

/// A µm value with its source (see the module doc), as a template shows it:
/// `data-key`, `data-um` and the text.
#[derive(Clone, Debug, PartialEq)]
pub struct SourcedUm {
    /// The value's path in the JSON (`before.figures_um.A`).
    pub key: String,
    /// The full value, `null` when not evaluated.
    pub full: String,
    /// As the terminal report shows it ([`um`]).
    pub shown: String,
}

impl SourcedUm {
    /// The value at `key`, `None` when not evaluated.
    pub fn new(key: String, value: Option<f64>) -> SourcedUm {
        SourcedUm {
            key,
            full: value.map_or_else(|| "null".to_string(), |v| v.to_string()),
            shown: um(value),
        }
    }
}

/// A µm cell with its source (see the module doc); the markup is the
/// templates' `um_cell` macro.
pub fn um_cell(key: &str, value: Option<f64>) -> String {
    UmCell {
        um: &SourcedUm::new(key.to_string(), value),
    }
    .to_string()
}

#[derive(Template)]
#[template(
    source = r#"{% import "report/macros.html" as m %}{% call m::um_cell(um) %}"#,
    ext = "html"
)]
struct UmCell<'a> {
    um: &'a SourcedUm,
}

fn escape_into<W: fmt::Write>(mut dest: W, text: &str) -> fmt::Result {
    for c in text.chars() {
        match c {
            '&' => dest.write_str("&amp;")?,
            '<' => dest.write_str("&lt;")?,
            '>' => dest.write_str("&gt;")?,
            '"' => dest.write_str("&quot;")?,
            '\'' => dest.write_str("&#39;")?,
            _ => dest.write_char(c)?,
        }
    }
    Ok(())
}
