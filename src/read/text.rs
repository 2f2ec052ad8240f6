//! Building blocks for the line-oriented formats: numbered lines, fields with
//! their columns, and strict numbers.
//!
//! Every format axcomp reads is line-oriented, so the parsers first number
//! the lines and then parse each line; the line number in an error is then
//! exact (`../shared/spec/style.md` §4). Columns count characters from 1.
//!
//! Numbers are strict: a plain decimal (`-12.5`, `+0.0012`, `.5`, `1e-3`).
//! nom's `double` would accept `nan`, `inf` and `infinity`, and `1e400` parses
//! to infinity; here a token is first *recognised* as a decimal with nom, then
//! parsed, and anything non-finite is refused. A decimal comma is refused with
//! a message that says so.

use nom::branch::alt;
use nom::character::complete::{char, digit0, digit1, one_of};
use nom::combinator::opt;
use nom::sequence::pair;
use nom::{IResult, Parser};

use crate::error::{ParseError, describe_found};
use crate::units::{deg_to_arcsec, mm_to_um};

/// One line of a file: its 1-based number and its text without the line end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Line<'a> {
    /// Line number, from 1.
    pub number: usize,
    /// The text, without `\n` or `\r\n`.
    pub text: &'a str,
}

impl<'a> Line<'a> {
    /// The 1-based character column of `part`, which must be a sub-slice of this line.
    pub fn column_of(&self, part: &str) -> usize {
        let offset = (part.as_ptr() as usize).saturating_sub(self.text.as_ptr() as usize);
        let offset = offset.min(self.text.len());
        self.text[..offset].chars().count() + 1
    }

    /// The column just after the last character (for "found end of line").
    pub fn end_column(&self) -> usize {
        self.text.chars().count() + 1
    }

    /// An error at the start of `part`.
    pub fn error_at(&self, part: &str, message: impl Into<String>) -> ParseError {
        ParseError::new(self.number, self.column_of(part), message)
    }

    /// An `expected …, found …` error at the start of `part`.
    pub fn expected_at(&self, part: &str, expected: &str) -> ParseError {
        ParseError::expected(
            self.number,
            self.column_of(part),
            expected,
            &describe_found(part),
        )
    }

    /// The whitespace-separated fields of the line.
    pub fn fields(&self) -> impl Iterator<Item = &'a str> {
        self.text.split_whitespace()
    }

    /// Whether the line holds nothing but whitespace.
    pub fn is_blank(&self) -> bool {
        self.text.trim().is_empty()
    }
}

/// Splits text into numbered lines, accepting LF and CRLF line ends.
pub fn lines(text: &str) -> Lines<'_> {
    Lines {
        rest: Some(text),
        number: 1,
    }
}

/// The numbered lines of a text ([`lines`]): the pieces of `split('\n')`,
/// each without its `\r`.
#[derive(Clone, Debug)]
pub struct Lines<'a> {
    /// The text from the next line on; `None` after the last line.
    rest: Option<&'a str>,
    /// The next line's number.
    number: usize,
}

impl<'a> Lines<'a> {
    /// Goes on at `rest`, which is the text from the start of line `number`
    /// on, and ends with the text (a reader that read some lines another way).
    pub fn resume_at(&mut self, rest: &'a str, number: usize) {
        self.rest = Some(rest);
        self.number = number;
    }

    /// The text of the lines not taken yet and the next line's number
    /// (for [`Lines::resume_at`]); `None` after the last line.
    pub fn remaining(&self) -> Option<(&'a str, usize)> {
        Some((self.rest?, self.number))
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = Line<'a>;

    fn next(&mut self) -> Option<Line<'a>> {
        let current = self.rest?;
        // A plain byte search: lines are short, and the string searcher's
        // set-up costs more than the search.
        let raw = match current.bytes().position(|b| b == b'\n') {
            Some(end) => {
                self.rest = Some(&current[end + 1..]);
                &current[..end]
            }
            None => {
                self.rest = None;
                current
            }
        };
        let line = Line {
            number: self.number,
            text: raw.strip_suffix('\r').unwrap_or(raw),
        };
        self.number += 1;
        Some(line)
    }
}

/// The line just past the end of the text, for "expected …, found end of file".
pub fn end_of_file_line(text: &str) -> usize {
    let count = text.split('\n').count();
    if text.ends_with('\n') {
        count
    } else {
        count + 1
    }
}

/// Recognises a plain decimal number: sign, digits, optional fraction, optional exponent.
///
/// The matched text is taken from the length of what remains, not with
/// `nom::combinator::recognize`: in nom 8.0.0 `recognize` returns a short slice
/// when a `digit0`-style parser consumes to the end of a `&str`
/// (rust-bakery/nom#1808, #1887; fixed on nom's main branch, not released).
fn decimal(input: &str) -> IResult<&str, &str> {
    let (rest, _) = (
        opt(one_of("+-")),
        alt((
            pair(digit1, opt(pair(char('.'), digit0))).map(|_| ()),
            pair(char('.'), digit1).map(|_| ()),
        )),
        opt((one_of("eE"), opt(one_of("+-")), digit1)),
    )
        .parse(input)?;
    Ok((rest, consumed(input, rest)))
}

/// The part of `input` a parser consumed, given what it left.
pub fn consumed<'a>(input: &'a str, rest: &str) -> &'a str {
    &input[..input.len() - rest.len()]
}

/// Parses a whole token as a finite decimal number, or says what is wrong with it.
///
/// `what` names the quantity for the message ("target", "deviation").
pub fn number(line: &Line<'_>, token: &str, what: &str) -> Result<f64, ParseError> {
    // Only an error needs the text: it is not formatted for a reading that parses.
    // The common case first: a token of digits, sign, point and exponent
    // letters that the standard parser takes is a decimal of the grammar
    // below (which would parse the same token with the same parser); every
    // other token goes through the grammar for its message.
    if let Some(value) = short_decimal(token) {
        return Ok(value);
    }
    let plain = token
        .bytes()
        .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E'));
    if plain
        && let Ok(value) = token.parse::<f64>()
        && value.is_finite()
    {
        return Ok(value);
    }
    let expected = || format!("a number ({what})");
    let Ok((rest, digits)) = decimal(token) else {
        return Err(line.expected_at(token, &expected()));
    };
    if !rest.is_empty() {
        if rest.starts_with(',') && rest[1..].starts_with(|c: char| c.is_ascii_digit()) {
            return Err(line.error_at(
                token,
                format!(
                    "expected a number ({what}) with '.' as decimal point, found decimal comma in {}",
                    describe_found(token)
                ),
            ));
        }
        return Err(line.expected_at(token, &expected()));
    }
    let value: f64 = digits
        .parse()
        .map_err(|_| line.expected_at(token, &expected()))?;
    if !value.is_finite() {
        return Err(line.error_at(
            token,
            format!("expected a finite number ({what}), found {token:?}, which overflows"),
        ));
    }
    Ok(value)
}

/// The value of `[+-]digits[.digits]` with at most 15 digits, or `None`
/// for any other token (which the standard parser then reads).
///
/// The same value as `token.parse::<f64>()`, found faster: the digits as an
/// integer (below 10^15, so exact as an f64) divided by 10^(digits after the
/// point) (exact up to 10^22) is one correctly rounded division of two exact
/// values, which is the correctly rounded decimal, as the standard parser
/// gives (Clinger's fast path). A large file has a hundred thousand readings.
pub(crate) fn short_decimal(token: &str) -> Option<f64> {
    match short_decimal_at(token.as_bytes(), 0)? {
        (value, end) if end == token.len() => Some(value),
        _ => None,
    }
}

/// [`short_decimal`] of the token at `bytes[at..]`, the longest run of
/// digits, points and signs there, and the offset just after it; `None`
/// when that token is not a short decimal. One pass over the token, for
/// the rows of a large file (`read::rtl`'s `SimpleRow`).
#[inline]
pub(crate) fn short_decimal_at(bytes: &[u8], mut at: usize) -> Option<(f64, usize)> {
    const MAX_DIGITS: usize = 15;
    const POWERS_OF_TEN: [f64; MAX_DIGITS + 1] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    ];
    let negative = bytes.get(at) == Some(&b'-');
    if matches!(bytes.get(at), Some(b'-' | b'+')) {
        at += 1;
    }
    let mut digits: u64 = 0;
    let mut digit_count = 0;
    // The number of digits before the point, once there is one.
    let mut point: Option<usize> = None;
    loop {
        match bytes.get(at) {
            Some(&byte @ b'0'..=b'9') => {
                if digit_count == MAX_DIGITS {
                    return None;
                }
                digits = digits * 10 + u64::from(byte - b'0');
                digit_count += 1;
            }
            Some(b'.') if point.is_none() => point = Some(digit_count),
            // A second point or a sign inside the token.
            Some(b'.' | b'+' | b'-') => return None,
            _ => break,
        }
        at += 1;
    }
    if digit_count == 0 {
        return None;
    }
    let decimals = point.map_or(0, |before| digit_count - before);
    let magnitude = digits as f64 / POWERS_OF_TEN[decimals];
    Some((if negative { -magnitude } else { magnitude }, at))
}

/// Largest deviation accepted, mm, either sign: 1 m.
///
/// A positioning error is micrometres, at most millimetres; a reading beyond
/// ±1 m is a wrong unit, a wrong column or a corrupt file, and values near
/// ±1e308 overflow the statistics and the chart scales (`report` spun for
/// minutes, `evaluate` printed `inf`). Every reader checks its deviations
/// against this one bound ([`check_deviation_mm`]).
pub const MAX_DEVIATION_MM: f64 = 1000.0;

/// Largest target position accepted, mm, either sign: 100 m, longer than any
/// machine axis a laser interferometer measures (the longest linear ranges
/// are 80 m). Checked by every reader with [`check_target_mm`].
pub const MAX_TARGET_MM: f64 = 100_000.0;

/// Refuses a deviation (already in mm) that is not finite or beyond
/// [`MAX_DEVIATION_MM`], at the given line and column.
#[inline]
pub fn check_deviation_mm(value_mm: f64, line: usize, column: usize) -> Result<f64, ParseError> {
    if value_mm.abs() <= MAX_DEVIATION_MM {
        return Ok(value_mm);
    }
    deviation_beyond_bound(value_mm, line, column)
}

#[cold]
fn deviation_beyond_bound(value_mm: f64, line: usize, column: usize) -> Result<f64, ParseError> {
    // In µm, as deviations are read, unless that overflows (a value near f64::MAX in mm).
    let found = if mm_to_um(value_mm).is_finite() {
        format!("{} µm", shown(mm_to_um(value_mm)))
    } else {
        format!("{} mm", shown(value_mm))
    };
    Err(ParseError::new(
        line,
        column,
        format!(
            "expected a deviation within ±{} µm (±1 m), found {found}: check the unit and the column of the file",
            mm_to_um(MAX_DEVIATION_MM),
        ),
    ))
}

/// Largest deviation of a rotary axis accepted, degrees, either sign: 1°,
/// 3600″, where positioning errors are arc-seconds: beyond it is a wrong unit
/// or column ([`check_deviation_deg`]).
pub const MAX_DEVIATION_DEG: f64 = 1.0;

/// Refuses a rotary deviation (already in degrees) that is not finite or
/// beyond [`MAX_DEVIATION_DEG`], at the given line and column.
pub fn check_deviation_deg(value_deg: f64, line: usize, column: usize) -> Result<f64, ParseError> {
    if value_deg.abs() <= MAX_DEVIATION_DEG {
        return Ok(value_deg);
    }
    Err(ParseError::new(
        line,
        column,
        format!(
            "expected a rotary deviation within ±{}″ (±1°), found {}″: check the unit and the column of the file",
            deg_to_arcsec(MAX_DEVIATION_DEG),
            shown(deg_to_arcsec(value_deg)),
        ),
    ))
}

/// Refuses a target (already in mm) that is not finite or beyond
/// [`MAX_TARGET_MM`], at the given line and column.
pub fn check_target_mm(value_mm: f64, line: usize, column: usize) -> Result<f64, ParseError> {
    if value_mm.abs() <= MAX_TARGET_MM {
        return Ok(value_mm);
    }
    Err(ParseError::new(
        line,
        column,
        format!(
            "expected a target within ±{MAX_TARGET_MM} mm (±100 m), found {} mm: check the unit and the column of the file",
            shown(value_mm)
        ),
    ))
}

/// A value for a message: short, whatever its size (`1.0e308`, not 309 digits).
fn shown(value: f64) -> String {
    if value.is_finite() && value.abs() < 1e9 {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

/// Parses a whole token as a non-negative integer.
pub fn integer(line: &Line<'_>, token: &str, what: &str) -> Result<u64, ParseError> {
    let all_digits = !token.is_empty() && token.bytes().all(|b| b.is_ascii_digit());
    if !all_digits {
        return Err(line.expected_at(token, &format!("a whole number ({what})")));
    }
    token
        .parse()
        .map_err(|_| line.error_at(token, format!("{what} {token} is too large")))
}

/// The run number (from 1) and direction (`up`/`down`, `↑`/`↓`) fields of
/// a CSV row, as the positioning and geometry layouts write them.
pub fn run_and_direction(
    line: &Line<'_>,
    run_field: &str,
    direction_field: &str,
) -> Result<(u64, crate::measurement::Direction), ParseError> {
    use crate::measurement::Direction;
    let run = integer(line, run_field, "run number")?;
    if run == 0 {
        return Err(line.error_at(run_field, "expected a run number from 1, found 0"));
    }
    let direction = match direction_field.to_ascii_lowercase().as_str() {
        "up" | "↑" => Direction::Up,
        "down" | "↓" => Direction::Down,
        _ => return Err(line.expected_at(direction_field, "direction up or down")),
    };
    Ok((run, direction))
}

/// Splits `key<sep>value` at the first `sep`; the key is trimmed, the value is
/// trimmed and still a slice of the line (so columns stay right).
pub fn split_key(text: &str, sep: char) -> Option<(&str, &str)> {
    let at = text.find(sep)?;
    Some((text[..at].trim(), text[at + sep.len_utf8()..].trim()))
}

/// Test helper for the readers' tables of bad inputs: parses each case's
/// text and asserts that it fails at (line, column) with a message that
/// contains the needle.
#[cfg(test)]
pub(crate) fn assert_errors_at<T: std::fmt::Debug>(
    parse: impl Fn(&str) -> Result<T, ParseError>,
    cases: &[(&str, (usize, usize), &str)],
) {
    for &(text, (line, column), needle) in cases {
        let error = parse(text).unwrap_err();
        assert_eq!(
            (error.position.line, error.position.column),
            (line, column),
            "{text:?}: {error}"
        );
        assert!(error.message.contains(needle), "{text:?}: {error}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(text: &str) -> Line<'_> {
        Line { number: 7, text }
    }

    #[test]
    fn numbered_lines_strip_crlf() {
        let all: Vec<_> = lines("a\r\nb\n\nc").collect();
        assert_eq!(all.len(), 4);
        assert_eq!(all[0].text, "a");
        assert_eq!(all[1].number, 2);
        assert_eq!(all[3].text, "c");
        assert_eq!(end_of_file_line("a\nb\n"), 3);
        assert_eq!(end_of_file_line("a\nb"), 3);
        for text in ["", "\n", "a", "a\n", "\n\nb\r\n", "µ\r\nx\n\n"] {
            let pieces: Vec<&str> = text.split('\n').collect();
            let texts: Vec<&str> = lines(text).map(|line| line.text).collect();
            let expected: Vec<&str> = pieces
                .iter()
                .map(|raw| raw.strip_suffix('\r').unwrap_or(raw))
                .collect();
            assert_eq!(texts, expected, "{text:?}");
        }
    }

    #[test]
    fn columns_count_characters() {
        let l = line("µm  12.5");
        let token = l.fields().nth(1).unwrap();
        assert_eq!(l.column_of(token), 5);
        assert_eq!(l.end_column(), 9);
    }

    #[test]
    fn strict_numbers() {
        let l = line("x");
        for (text, value) in [
            ("12.5", 12.5),
            ("-0.0012", -0.0012),
            ("+3", 3.0),
            (".5", 0.5),
            ("5.", 5.0),
            ("1e-3", 0.001),
            ("-2.5E+2", -250.0),
        ] {
            assert_eq!(number(&l, text, "value").unwrap(), value, "{text}");
        }
        for bad in [
            "nan",
            "NaN",
            "inf",
            "-infinity",
            "",
            "1.2.3",
            "12a",
            "--1",
            "e5",
            "0x10",
        ] {
            let error = number(&l, bad, "value").unwrap_err();
            assert!(
                error.message.starts_with("expected a number (value)"),
                "{bad}: {error}"
            );
        }
        let comma = number(&l, "1,5", "deviation").unwrap_err();
        assert!(comma.message.contains("decimal comma"), "{comma}");
        let huge = number(&l, "1e400", "target").unwrap_err();
        assert!(huge.message.contains("overflows"), "{huge}");
    }

    #[test]
    fn short_decimals_are_the_standard_parse() {
        for token in [
            "0",
            "-0",
            "-0.0",
            "+0.5",
            ".5",
            "5.",
            "-.25",
            "0.1",
            "-1.019",
            "999.9",
            "0.3",
            "123456789012345",
            "1234567.89012345",
            "-0.000000000000001",
            "9007199254740993",
        ] {
            let expected: f64 = token.parse().unwrap();
            let value = short_decimal(token).unwrap_or(expected);
            assert_eq!(value.to_bits(), expected.to_bits(), "{token}");
        }
        for other in [
            "",
            ".",
            "-",
            "1e5",
            "1.2.3",
            "12a",
            "--1",
            "1,5",
            "1234567890123456",
        ] {
            assert_eq!(short_decimal(other), None, "{other}");
        }
    }

    proptest::proptest! {
        #[test]
        fn short_decimals_match_the_standard_parser(token in "[+-]?[0-9]{0,9}([.][0-9]{0,9})?") {
            if let Some(value) = short_decimal(&token) {
                let expected: f64 = token.parse().unwrap();
                proptest::prop_assert_eq!(value.to_bits(), expected.to_bits());
            }
        }
    }

    #[test]
    fn absurd_values_are_refused_with_their_position() {
        assert_eq!(check_deviation_mm(-999.5, 3, 4), Ok(-999.5));
        let error = check_deviation_mm(1e305, 3, 4).unwrap_err();
        assert_eq!((error.position.line, error.position.column), (3, 4));
        assert!(error.message.contains("found 1e308 µm"), "{error}");
        assert!(error.message.contains("±1000000 µm"), "{error}");
        let error = check_deviation_mm(-1e308, 3, 4).unwrap_err();
        assert!(error.message.contains("found -1e308 mm"), "{error}");
        assert!(check_deviation_mm(f64::NAN, 1, 1).is_err());
        assert!(check_deviation_mm(1000.001, 1, 1).is_err());
        assert_eq!(check_target_mm(-100_000.0, 1, 1), Ok(-100_000.0));
        let error = check_target_mm(2e5, 9, 2).unwrap_err();
        assert!(error.message.contains("found 200000 mm"), "{error}");
        assert!(check_target_mm(f64::INFINITY, 1, 1).is_err());
    }

    #[test]
    fn decimal_recognises_up_to_the_end_of_input() {
        // Regression guard for rust-bakery/nom#1808 (see `decimal`).
        assert_eq!(decimal("1.270"), Ok(("", "1.270")));
        assert_eq!(decimal("12 x"), Ok((" x", "12")));
    }

    #[test]
    fn strict_integers() {
        let l = line("x");
        assert_eq!(integer(&l, "42", "run").unwrap(), 42);
        assert!(integer(&l, "-1", "run").is_err());
        assert!(integer(&l, "1.0", "run").is_err());
        assert!(integer(&l, "99999999999999999999999", "run").is_err());
    }

    #[test]
    fn keys_split_and_trim() {
        assert_eq!(
            split_key("Air temp   : 20.3 20.4", ':'),
            Some(("Air temp", "20.3 20.4"))
        );
        assert_eq!(split_key("UNIT=mm", '='), Some(("UNIT", "mm")));
        assert_eq!(split_key("no separator", ':'), None);
    }
}
