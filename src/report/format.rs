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
    let mut text = Vec::new();
    push_um(&mut text, value);
    text_of(text)
}

/// The text of bytes the `push_` functions wrote (always UTF-8: digits,
/// signs, points and [`NOT_EVALUATED`]).
pub fn text_of(bytes: Vec<u8>) -> String {
    String::from_utf8(bytes)
        .unwrap_or_else(|error| String::from_utf8_lossy(error.as_bytes()).into_owned())
}

/// `name` padded with spaces to `width` columns as a terminal shows it
/// (B̄'s bar is a combining character and takes no column).
pub fn pad_name(name: &str, width: usize) -> String {
    let shown = name
        .chars()
        .filter(|c| !('\u{300}'..='\u{36f}').contains(c))
        .count();
    format!("{name}{}", " ".repeat(width.saturating_sub(shown)))
}

/// Appends [`um`]'s text to `out`, without a `String` of its own (a large
/// test's per-target table has a hundred thousand of these). The `push_`
/// functions write bytes: a byte is pushed without the character encoding
/// a `String` push goes through ([`text_of`] makes the text).
pub fn push_um(out: &mut Vec<u8>, value: Option<f64>) {
    match value {
        None => out.extend_from_slice(NOT_EVALUATED.as_bytes()),
        // −0.004 µm is 0.00, not "-0.00".
        Some(v) if v.abs() < 0.005 => out.extend_from_slice(b"0.00"),
        Some(v) => push_two_decimals(out, v),
    }
}

/// Appends `format!("{:.2}", value)` to `out`, the same text, faster.
/// Fast path: with it and the others of the evaluate report, a 10 000-target × 10-run `evaluate` takes 0.014 s cpu whole process, 0.028 s without.
///
/// The standard formatter rounds the exact binary value to two decimals,
/// which takes arbitrary-precision arithmetic. `value × 100` rounded to an
/// integer gives the same digits whenever the product is not within its own
/// rounding error (under 1e-7 for |value| < 1e7) of a half: there the
/// standard formatter decides.
fn push_two_decimals(out: &mut Vec<u8>, value: f64) {
    use std::io::Write;
    let scaled = value * 100.0;
    if scaled.abs() < 1e9 {
        // Rounded half away from zero by truncation, not by `f64::round`,
        // a library call: whenever the check below passes, the result is
        // the integer nearest `scaled`, which is what `round` gives.
        let hundredths = (scaled + 0.5f64.copysign(scaled)) as i64;
        let clear_of_a_tie = 0.5 - (scaled - hundredths as f64).abs() > 1e-6;
        if clear_of_a_tie && hundredths != 0 {
            // Made in a buffer and appended at once. Below 10⁹ hundredths: at
            // most seven digits of units, the sign, the point and two decimals.
            let magnitude = hundredths.unsigned_abs();
            let (units, cents) = (magnitude / 100, magnitude % 100);
            let mut digits = 1;
            while units >= 10u64.pow(digits) {
                digits += 1;
            }
            let sign = usize::from(hundredths < 0);
            let point = sign + digits as usize;
            let mut text = [b'-'; 16];
            write_digits(&mut text[sign..point], units);
            text[point] = b'.';
            write_digits(&mut text[point + 1..point + 3], cents);
            out.extend_from_slice(&text[..point + 3]);
            return;
        }
    }
    let _ = write!(out, "{value:.2}");
}

/// Appends `format!("{value}")` to `out` (the shortest text that reads back
/// to `value`), the same text, faster for a value with at most six decimals
/// below 10⁹ in size, as targets are.
///
/// The shortest text of such a value is `units / 10^k` with the least k
/// whose text reads back to it: below 10⁹ a float's neighbours are closer
/// than 10⁻⁶, so at most one k-decimal text reads back to it, and one with
/// fewer digits would have fewer decimals. `units / 10^k` in floating point
/// is what reading that text gives (both exact below 2⁵³, one rounding).
/// Anything else, and ±0, goes to the standard formatter.
pub fn push_shortest(out: &mut Vec<u8>, value: f64) {
    use std::io::Write;
    const POWERS_OF_TEN: [f64; 7] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6];
    if value != 0.0 && value.abs() < 1e9 {
        for (decimals, scale) in POWERS_OF_TEN.iter().enumerate() {
            let scaled = value * scale;
            let units = (scaled + 0.5f64.copysign(scaled)) as i64;
            if units as f64 / scale == value {
                if units < 0 {
                    out.push(b'-');
                }
                let units = units.unsigned_abs();
                let scale = 10u64.pow(decimals as u32);
                push_integer(out, units / scale);
                if decimals > 0 {
                    out.push(b'.');
                    push_digits(out, units % scale, decimals);
                }
                return;
            }
        }
    }
    let _ = write!(out, "{value}");
}

/// Appends the last `count` decimal digits of `value`, with leading zeros.
fn push_digits(out: &mut Vec<u8>, value: u64, count: usize) {
    let mut digits = [b'0'; 20];
    write_digits(&mut digits[..count], value);
    out.extend_from_slice(&digits[..count]);
}

/// Fills `slot` with the last `slot.len()` digits of `value`, zero-padded.
#[inline]
fn write_digits(slot: &mut [u8], value: u64) {
    let mut rest = value;
    for digit in slot.iter_mut().rev() {
        *digit = b'0' + (rest % 10) as u8;
        rest /= 10;
    }
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
    inch_text_places(value_in, 6)
}

/// An inch value with at most `places` decimals, as a file of that many shows it.
pub fn inch_text_places(value_in: f64, places: usize) -> String {
    let text = format!("{value_in:.places$}");
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
    /// The expanded uncertainty U shown after it (`± 1.82`), as the
    /// terminal shows it; `None` where U is not evaluated.
    pub u: Option<String>,
}

impl SourcedUm {
    /// The value at `key`, `None` when not evaluated.
    pub fn new(key: String, value: Option<f64>) -> SourcedUm {
        SourcedUm {
            key,
            full: value.map_or_else(|| "null".to_string(), |v| v.to_string()),
            shown: um(value),
            u: None,
        }
    }

    /// With U shown after the value (`13.19 ± 1.82`), where both are evaluated.
    pub fn with_u(self, expanded_um: Option<f64>) -> SourcedUm {
        let u = expanded_um
            .filter(|_| self.full != "null")
            .map(|u| um(Some(u)));
        SourcedUm { u, ..self }
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

/// Appends the decimal digits of `value` (what `{}` writes, without the
/// formatting machinery: the large per-target table writes 120 000 numbers).
#[inline]
pub fn push_integer(out: &mut Vec<u8>, value: u64) {
    let mut digits = [0u8; 20];
    let mut start = digits.len();
    let mut rest = value;
    loop {
        start -= 1;
        digits[start] = b'0' + (rest % 10) as u8;
        rest /= 10;
        if rest == 0 {
            break;
        }
    }
    out.extend_from_slice(&digits[start..]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The standard formatter is the definition `push_two_decimals` must match.
    fn standard(value: f64) -> String {
        format!("{value:.2}")
    }

    fn fast(value: f64) -> String {
        let mut text = Vec::new();
        push_two_decimals(&mut text, value);
        text_of(text)
    }

    #[test]
    fn two_decimals_match_the_standard_formatter_at_ties_and_edges() {
        // Decimal ties whose binary value lies just below or above the half,
        // values that round to zero, and values past the fast path's range.
        for value in [
            0.125,
            -0.125,
            0.375,
            1.005,
            -1.005,
            2.675,
            0.015,
            0.045,
            1.115,
            10.005,
            0.005,
            -0.005,
            0.0049,
            -0.0049,
            0.0,
            -0.0,
            99.995,
            1e7,
            -1e7,
            123456789.125,
            1e300,
            f64::MIN_POSITIVE,
            0.994999,
            0.995,
            9.999,
        ] {
            assert_eq!(fast(value), standard(value), "{value:e}");
        }
        assert_eq!(um(Some(-0.004)), "0.00");
        assert_eq!(um(Some(-1.236)), "-1.24");
        assert_eq!(um(None), NOT_EVALUATED);
        for value in [
            0.0,
            -0.0,
            0.1,
            -0.1,
            999.9,
            0.3,
            1e-7,
            123456.789012,
            999999999.9,
            1e9,
            5e-324,
            1.0,
            -2.5,
            0.000001,
            0.0000015,
        ] {
            let mut text = Vec::new();
            push_shortest(&mut text, value);
            assert_eq!(text_of(text), format!("{value}"), "{value:e}");
        }
        for value in [0, 7, 10, 99, 100, 12345, u64::MAX] {
            let mut text = Vec::new();
            push_integer(&mut text, value);
            assert_eq!(text_of(text), value.to_string());
        }
    }

    proptest! {
        #[test]
        fn two_decimals_match_the_standard_formatter(value in -1e8f64..1e8) {
            prop_assert_eq!(fast(value), standard(value));
        }

        #[test]
        fn shortest_matches_the_standard_formatter(units in -1_000_000_000_000_000i64..1_000_000_000_000_000, decimals in 0..9u32, any in proptest::num::f64::ANY) {
            // Decimals as targets are written, and any float at all.
            for value in [units as f64 / 10f64.powi(decimals as i32), any] {
                let mut text = Vec::new();
                push_shortest(&mut text, value);
                prop_assert_eq!(text_of(text), format!("{value}"));
            }
        }

        #[test]
        fn two_decimals_match_on_the_hundredths_grid(hundredths in -10_000_000i64..10_000_000, half in 0..3i64) {
            // k/100 and (k + ½)/100: exactly the values where rounding is delicate.
            let value = (hundredths as f64 + half as f64 * 0.5) / 100.0;
            prop_assert_eq!(fast(value), standard(value));
        }
    }
}
