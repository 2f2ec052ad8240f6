//! Fanuc pitch error compensation data (`PITCH.TXT`, punch format): read,
//! written, and updated in place, with the parameters of the axis read from
//! the machine's parameter backup (`CNC-PARA.TXT`).
//!
//! Spec and sources: `formats/fanuc/README.md` (\[manual\] the 0i-PB and 30i
//! parameter manuals, Fanuc technical report A-77810E; \[file\] a real backup
//! of one machine in `../shared/data/fanuc/`). The pitch file is
//!
//! ```text
//! %
//! N10000Q0P0
//! N10001Q0P-1␠
//! …
//! %
//! ```
//!
//! one data number (10000 + compensation point) a line, its value an integer
//! in detection units × magnification (3623). The values are incremental: the
//! value of point n is the compensation output while the axis travels from
//! point n − 1 to point n, point n lying at 1240 + (n − 3620) × 3624, and the
//! absolute compensation is zero at the reference point 3620. The file holds
//! the points of every axis; an axis uses 3621 … 3622.
//!
//! The absolute compensation is the correction the control adds, so the
//! error it compensates (axcomp's table value) is its negative.

use std::collections::BTreeMap;

use crate::compensate::{CompensationTable, TableMode, TableValues};
use crate::emit::{BacklashAdvice, EmitError, EmitOptions};
use crate::error::ParseError;
use crate::measurement::AxisKind;
use crate::read::text::{self, Line};

/// \[file\] Data number of compensation point 0 (`N10000` … in the real `PITCH.TXT`).
pub const DATA_NUMBER_OFFSET: i64 = 10_000;

/// \[reconstructed\] Largest |value| of one point, in units of detection unit ×
/// magnification: no public manual page giving it was found; a signed byte
/// (−128 … 127) is assumed, the range of the other controllers' incremental
/// tables of this kind (Mitsubishi E68 manual p. II-292: "Range: –128 to 127").
pub const POINT_LIMIT: i64 = 127;

/// \[manual, secondary\] The number of points between the extremes an axis
/// may use (cnc.wiki "Setup Guide for Fanuc Pitch Error Compensation
/// Parameters": "maximum of 128 compensation points between extremes").
pub const MAX_POINTS: usize = 128;

/// The largest point a data number can name (N99999).
const MAX_POINT: i64 = 99_999 - DATA_NUMBER_OFFSET;

/// \[reconstructed\] The largest |value| a data line is read with: 8 digits,
/// as the parameters' (no file holds more; the sums then never overflow).
const READ_LIMIT: i64 = 99_999_999;

/// The parameter backup of a Fanuc control (`CNC-PARA.TXT`): every
/// parameter's values, with where they stand in the file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParameterBackup {
    /// The file name, for messages.
    pub source: String,
    entries: BTreeMap<u32, Vec<Entry>>,
}

/// One value of a parameter: for an axis `A<n>`, a path `L<n>`, a spindle
/// `S<n>`, or the whole control.
#[derive(Clone, Debug, PartialEq)]
struct Entry {
    index: Option<(char, usize)>,
    value: String,
    line: usize,
    column: usize,
}

/// What the parameter backup says of one axis' pitch error compensation.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisParameters {
    /// The axis name (1020).
    pub axis: String,
    /// The controlled axis number (`A<n>`).
    pub number: usize,
    /// 3620: the point of the reference position.
    pub reference_point: i64,
    /// 3621: the most negative point.
    pub most_negative: i64,
    /// 3622: the most positive point.
    pub most_positive: i64,
    /// 3623: the magnification.
    pub magnification: i64,
    /// 3624: the interval, mm (° on a rotary axis).
    pub interval: f64,
    /// 3625: travel per turn of a rotary axis, ° (0: 360°).
    pub travel_per_turn: f64,
    /// 3605#0: bidirectional pitch error compensation.
    pub bidirectional: bool,
    /// 1240: the machine position of the reference position, mm or °.
    pub reference_position: f64,
    /// Least command increment / CMR (1013, 1820), mm or °.
    pub detection_unit: f64,
    /// 1006#0: a rotary axis.
    pub rotary: bool,
    /// 1851 and 1852, detection units.
    pub backlash: (i64, i64),
    /// Where 3620, 3621 and 3622 of the axis stand in the backup.
    pub source: String,
    /// Whether the numbers come from a backup (false: axcomp's defaults).
    pub from_backup: bool,
}

impl AxisParameters {
    /// The numbers a new file uses without a backup, for a table of
    /// `count` points `step` apart whose reference is point `reference`:
    /// points 0 … count − 1, \[reconstructed\] detection unit 0.001 mm
    /// (IS-B, 1820 = 2, CMR 1) and magnification 1.
    pub fn default_for(axis: &str, count: usize, step: f64, reference: usize, at: f64) -> Self {
        let reference_point = reference as i64;
        AxisParameters {
            axis: axis.to_string(),
            number: 1,
            reference_point,
            most_negative: 1,
            most_positive: count as i64 - 1,
            magnification: 1,
            interval: step,
            travel_per_turn: 0.0,
            bidirectional: false,
            reference_position: at,
            detection_unit: 0.001,
            rotary: false,
            backlash: (0, 0),
            source: "axcomp's defaults".to_string(),
            from_backup: false,
        }
    }

    /// One unit of a point's value: detection unit × magnification, mm or °.
    pub fn unit(&self) -> f64 {
        self.detection_unit * self.magnification as f64
    }

    /// The machine position of point `point`, mm or °.
    pub fn position(&self, point: i64) -> f64 {
        self.reference_position + (point - self.reference_point) as f64 * self.interval
    }

    /// The first point of the axis' curve: the start of the section of 3621.
    pub fn first_point(&self) -> i64 {
        self.most_negative - 1
    }

    /// The point at `position`, when it is one.
    fn point_at(&self, position: f64) -> Option<i64> {
        let exact = (position - self.reference_position) / self.interval;
        let point = exact.round();
        ((exact - point).abs() < 1e-6).then_some(self.reference_point + point as i64)
    }

    /// The parameters to set, as the user types them.
    pub fn settings(&self) -> String {
        let mut text = format!(
            "3620 = {}, 3621 = {}, 3622 = {}, 3623 = {}, 3624 = {}",
            self.reference_point,
            self.most_negative,
            self.most_positive,
            self.magnification,
            crate::emit::minimal(self.interval, 4)
        );
        if self.rotary {
            text.push_str(&format!(
                ", 3625 = {}",
                crate::emit::minimal(self.travel_per_turn, 4)
            ));
        }
        text
    }
}

impl ParameterBackup {
    /// Parses a parameter backup: `%` lines and `N<number>Q1` lines whose
    /// values follow `P` (`M`/`I` for metric/inch data), alone or after
    /// `A<axis>`, `L<path>` or `S<spindle>`.
    pub fn parse(input: &str, source: &str) -> Result<ParameterBackup, ParseError> {
        let mut entries: BTreeMap<u32, Vec<Entry>> = BTreeMap::new();
        for line in text::lines(input) {
            let content = line.text.trim_end();
            if content.is_empty() || content == "%" {
                continue;
            }
            let (number, rest) = parameter_number(&line, content)?;
            let values = parameter_values(&line, rest)?;
            entries.entry(number).or_default().extend(values);
        }
        if entries.is_empty() {
            return Err(ParseError::new(
                1,
                1,
                "expected a Fanuc parameter backup (N00000Q1P… lines between %), found no parameter",
            ));
        }
        Ok(ParameterBackup {
            source: source.to_string(),
            entries,
        })
    }

    /// The value of parameter `number` for index `(kind, n)` (or the whole control).
    fn value(&self, number: u32, index: Option<(char, usize)>) -> Result<&Entry, String> {
        let index_text = index.map_or(String::new(), |(k, n)| format!(" {k}{n}"));
        self.entries
            .get(&number)
            .and_then(|list| list.iter().find(|e| e.index == index))
            .ok_or_else(|| {
                format!(
                    "{}: parameter {number:04}{index_text} is missing",
                    self.source
                )
            })
    }

    fn integer(&self, number: u32, index: Option<(char, usize)>) -> Result<i64, String> {
        let entry = self.value(number, index)?;
        entry.value.parse().map_err(|_| {
            format!(
                "{}:{}:{}: parameter {number:04}: expected an integer, found {:?}",
                self.source, entry.line, entry.column, entry.value
            )
        })
    }

    fn real(&self, number: u32, index: Option<(char, usize)>) -> Result<f64, String> {
        let entry = self.value(number, index)?;
        entry.value.parse().map_err(|_| {
            format!(
                "{}:{}:{}: parameter {number:04}: expected a number, found {:?}",
                self.source, entry.line, entry.column, entry.value
            )
        })
    }

    /// Bit `bit` of a bit parameter: \[manual\] B-63950EN/02 p.8 and p.12,
    /// whose examples read `P00000001` as bit 0 set and `P00001000` as bit 3
    /// set: the last digit is bit 0 (as #7 … #0 on the screen).
    fn bit(&self, number: u32, index: Option<(char, usize)>, bit: usize) -> Result<bool, String> {
        let entry = self.value(number, index)?;
        let bits = entry.value.as_bytes();
        match bits.get(7usize.saturating_sub(bit)) {
            Some(b'0') if bits.len() == 8 => Ok(false),
            Some(b'1') if bits.len() == 8 => Ok(true),
            _ => Err(format!(
                "{}:{}:{}: parameter {number:04}: expected 8 bits, found {:?}",
                self.source, entry.line, entry.column, entry.value
            )),
        }
    }

    /// The axis names of 1020, by controlled axis number.
    pub fn axis_names(&self) -> Vec<(usize, String)> {
        let Some(list) = self.entries.get(&1020) else {
            return Vec::new();
        };
        list.iter()
            .filter_map(|e| match (e.index, e.value.parse::<u32>()) {
                (Some(('A', n)), Ok(code)) if code > 0 => {
                    char::from_u32(code).map(|c| (n, c.to_string()))
                }
                _ => None,
            })
            .collect()
    }

    /// The pitch error compensation parameters of `axis`.
    pub fn axis(&self, axis: &str) -> Result<AxisParameters, String> {
        let names = self.axis_names();
        let Some(number) = names.iter().find(|(_, n)| n == axis).map(|(i, _)| *i) else {
            let list: Vec<&str> = names.iter().map(|(_, n)| n.as_str()).collect();
            return Err(format!(
                "{}: parameter 1020 names no axis {axis} (its axes: {})",
                self.source,
                list.join(", ")
            ));
        };
        let a = Some(('A', number));
        // [manual] B-63950EN/02 p.106: least command increment / CMR = detection unit;
        // 1820 = 2 × CMR for CMR 0.5 … 48, 1 / CMR + 100 for 1/2 … 1/27.
        let cmr_setting = self.integer(1820, a)?;
        let cmr = match cmr_setting {
            1..=96 => cmr_setting as f64 / 2.0,
            101..=127 => 1.0 / (cmr_setting - 100) as f64,
            _ => {
                return Err(format!(
                    "{}: 1820 of axis {axis} is {cmr_setting}: expected 1 … 96 or 101 … 127",
                    self.source
                ));
            }
        };
        // [reconstructed] 1013 all bits 0 is IS-B (least command increment
        // 0.001 mm or °, B-63943EN-1/02 p.109); what each bit selects was not found.
        let increment_bits = self.value(1013, a)?;
        if increment_bits.value != "00000000" {
            return Err(format!(
                "{}:{}:{}: 1013 of axis {axis} is {}: axcomp reads IS-B (1013 = 00000000) only; which bit selects which increment system is not established",
                self.source, increment_bits.line, increment_bits.column, increment_bits.value
            ));
        }
        // [reconstructed] 1001#0 INM: an inch machine.
        let paths = self.entries.get(&1001).map_or(0, Vec::len);
        for path in 1..=paths.max(1) {
            if self
                .bit(1001, Some(('L', path)), 0)
                .or_else(|_| self.bit(1001, None, 0))?
            {
                return Err(format!(
                    "{}: 1001#0 (INM) is 1: an inch machine, which axcomp does not read",
                    self.source
                ));
            }
        }
        let least_command_increment = 0.001;
        let position_of = |n: u32| {
            self.value(n, a)
                .map(|e| format!("{n} at {}:{}:{}", self.source, e.line, e.column))
        };
        let parameters = AxisParameters {
            axis: axis.to_string(),
            number,
            reference_point: self.integer(3620, a)?,
            most_negative: self.integer(3621, a)?,
            most_positive: self.integer(3622, a)?,
            magnification: self.integer(3623, a)?,
            interval: self.real(3624, a)?,
            travel_per_turn: self.real(3625, a).unwrap_or(0.0),
            bidirectional: self.bit(3605, a, 0)?,
            reference_position: self.real(1240, a)?,
            detection_unit: least_command_increment / cmr,
            rotary: self.bit(1006, a, 0)?,
            backlash: (self.integer(1851, a)?, self.integer(1852, a)?),
            source: [position_of(3620)?, position_of(3621)?, position_of(3622)?].join(", "),
            from_backup: true,
        };
        check_parameters(&parameters)?;
        Ok(parameters)
    }
}

/// The parameters a pitch table can be built on, or why not.
fn check_parameters(p: &AxisParameters) -> Result<(), String> {
    let axis = &p.axis;
    if p.magnification < 1 {
        return Err(format!(
            "3623 of axis {axis} is {}: pitch error compensation is off (magnification 0)",
            p.magnification
        ));
    }
    if !(p.interval > 0.0 && p.interval.is_finite() && p.reference_position.is_finite()) {
        return Err(format!(
            "3624 of axis {axis} is {}: the interval must be > 0",
            p.interval
        ));
    }
    if !(p.first_point() <= p.reference_point && p.reference_point <= p.most_positive) {
        return Err(format!(
            "the reference point 3620 = {} of axis {axis} lies outside its points 3621 − 1 = {} … 3622 = {} ({})",
            p.reference_point,
            p.first_point(),
            p.most_positive,
            p.source
        ));
    }
    if p.first_point() < 0 || p.most_positive > MAX_POINT {
        return Err(format!(
            "3621 … 3622 of axis {axis} are {} … {}: the points are 0 … {MAX_POINT} (data numbers N10000 … N99999)",
            p.most_negative, p.most_positive
        ));
    }
    Ok(())
}

/// `N<5 digits>Q1` and the rest of the line.
fn parameter_number<'a>(line: &Line<'a>, content: &'a str) -> Result<(u32, &'a str), ParseError> {
    let digits = content.strip_prefix('N').unwrap_or("");
    let end = digits
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(digits.len());
    let number = &digits[..end];
    if number.is_empty() || !content.starts_with('N') {
        return Err(line.expected_at(content, "a parameter N00000Q1…"));
    }
    let rest = &digits[end..];
    let Some(values) = rest.strip_prefix("Q1") else {
        return Err(line.expected_at(rest, "Q1 (parameter data) after the number"));
    };
    let value = number
        .parse()
        .map_err(|_| line.expected_at(number, "a parameter number"))?;
    Ok((value, values))
}

/// The values of one parameter line: `P<value>` or `(A|L|S|T)<n>(P|M|I)<value>…`.
fn parameter_values(line: &Line<'_>, mut rest: &str) -> Result<Vec<Entry>, ParseError> {
    let mut values = Vec::new();
    while let Some(first) = rest.chars().next() {
        // [file] A<axis>, L<path>, S<spindle>, and T<n> on a few parameters.
        let index = if first.is_ascii_uppercase() && !matches!(first, 'P' | 'M' | 'I') {
            let digits = &rest[1..];
            let end = digits
                .find(|c: char| !c.is_ascii_digit())
                .unwrap_or(digits.len());
            let n: usize = digits[..end]
                .parse()
                .map_err(|_| line.expected_at(digits, "an axis, path or spindle number"))?;
            rest = &digits[end..];
            Some((first, n))
        } else {
            None
        };
        let Some(rest_value) = rest
            .strip_prefix('P')
            .or_else(|| rest.strip_prefix('M'))
            .or_else(|| rest.strip_prefix('I'))
        else {
            return Err(line.expected_at(rest, "P, M or I and the value"));
        };
        let end = rest_value
            .find(|c: char| !(c.is_ascii_digit() || matches!(c, '-' | '+' | '.')))
            .unwrap_or(rest_value.len());
        let value = &rest_value[..end];
        if value.is_empty() {
            return Err(line.expected_at(rest_value, "a value"));
        }
        values.push(Entry {
            index,
            value: value.to_string(),
            line: line.number,
            column: line.column_of(value),
        });
        rest = &rest_value[end..];
        if index.is_none() {
            break;
        }
    }
    if !rest.is_empty() {
        return Err(line.expected_at(rest, "the end of the line"));
    }
    Ok(values)
}

/// Whether the text is a pitch file: a `%` line, then `N1nnnnQ0P…`.
pub fn looks_like(text: &str) -> bool {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    lines.next() == Some("%")
        && lines.next().is_some_and(|l| {
            l.starts_with('N')
                && l.get(6..9) == Some("Q0P")
                && l[1..6].bytes().all(|b| b.is_ascii_digit())
        })
}

/// Whether the text is a parameter backup: a `%` line, then `N<5 digits>Q1`.
pub fn looks_like_parameters(text: &str) -> bool {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    lines.next() == Some("%")
        && lines
            .next()
            .is_some_and(|l| l.starts_with('N') && l.get(6..8) == Some("Q1"))
}

/// One data line of a pitch file: its point, value and line.
#[derive(Clone, Copy, Debug)]
struct DataLine<'a> {
    value: i64,
    line: Line<'a>,
}

/// The pitch file's data by point, and the line of its closing `%` (or last line).
fn parse_pitch(input: &str) -> Result<(BTreeMap<i64, DataLine<'_>>, Line<'_>), ParseError> {
    let mut data: BTreeMap<i64, DataLine<'_>> = BTreeMap::new();
    let mut last = None;
    for line in text::lines(input) {
        let content = line.text.trim_end();
        if content.is_empty() {
            continue;
        }
        last = Some(line);
        if content == "%" {
            continue;
        }
        let digits = content.strip_prefix('N').unwrap_or("");
        let number_text = digits.get(..5).unwrap_or("");
        let number: i64 = match number_text.parse() {
            Ok(n) if number_text.bytes().all(|b| b.is_ascii_digit()) => n,
            _ => return Err(line.expected_at(content, "a data number N10000 … or %")),
        };
        let rest = &digits[5..];
        let Some(value_text) = rest.strip_prefix("Q0P") else {
            return Err(line.expected_at(rest, "Q0P (pitch error compensation data)"));
        };
        let value: i64 = value_text
            .parse()
            .ok()
            .filter(|v: &i64| v.abs() <= READ_LIMIT)
            .ok_or_else(|| line.expected_at(value_text, "an integer value of at most 8 digits"))?;
        if number < DATA_NUMBER_OFFSET {
            return Err(line.error_at(
                content,
                format!("data number {number} is below {DATA_NUMBER_OFFSET}, the first pitch error compensation point"),
            ));
        }
        let point = number - DATA_NUMBER_OFFSET;
        if data.insert(point, DataLine { value, line }).is_some() {
            return Err(line.error_at(content, format!("data number N{number} is given twice")));
        }
    }
    match last {
        Some(last) if !data.is_empty() => Ok((data, last)),
        _ => Err(ParseError::new(
            1,
            1,
            "expected Fanuc pitch error compensation data (%, N10000Q0P…, %), found none",
        )),
    }
}

/// The increments of points `from ..= to`, or an error at `end` naming the missing one.
fn increments(
    data: &BTreeMap<i64, DataLine<'_>>,
    end: &Line<'_>,
    p: &AxisParameters,
) -> Result<BTreeMap<i64, i64>, ParseError> {
    (p.most_negative..=p.most_positive)
        .map(|point| match data.get(&point) {
            Some(d) => Ok((point, d.value)),
            None => Err(end.error_at(
                end.text,
                format!(
                    "the pitch file has no data number N{} (point {point} of axis {}: {}): the parameter backup does not belong to this pitch file",
                    point + DATA_NUMBER_OFFSET,
                    p.axis,
                    p.source
                ),
            )),
        })
        .collect()
}

/// The absolute compensation, in units, at every point `first ..= last`
/// from the increments: zero at the reference point.
fn absolute_units(p: &AxisParameters, increments: &BTreeMap<i64, i64>) -> Vec<(i64, i64)> {
    let mut absolute = BTreeMap::new();
    absolute.insert(p.reference_point, 0i64);
    let mut sum = 0;
    for point in p.reference_point + 1..=p.most_positive {
        sum += increments[&point];
        absolute.insert(point, sum);
    }
    let mut sum = 0;
    for point in (p.first_point()..p.reference_point).rev() {
        sum -= increments[&(point + 1)];
        absolute.insert(point, sum);
    }
    absolute.into_iter().collect()
}

/// Reads the pitch error compensation of the axis of `p` from a pitch file:
/// the error it compensates (−absolute compensation) at every point
/// 3621 − 1 … 3622, zero at the reference point.
pub fn read(input: &str, p: &AxisParameters) -> Result<CompensationTable, ParseError> {
    let (data, end) = parse_pitch(input)?;
    if p.bidirectional {
        return Err(ParseError::new(
            1,
            1,
            format!(
                "3605#0 of axis {} is 1 (bidirectional pitch error compensation): axcomp reads the one-direction table only",
                p.axis
            ),
        ));
    }
    let increments = increments(&data, &end, p)?;
    let unit = p.unit();
    let (positions_mm, values): (Vec<f64>, Vec<f64>) = absolute_units(p, &increments)
        .into_iter()
        .map(|(point, units)| (p.position(point), -(units as f64) * unit + 0.0))
        .unzip();
    Ok(CompensationTable {
        axis: p.axis.clone(),
        positions_mm,
        values: TableValues::Mean(values),
        reference_mm: p.position(p.reference_point),
        suggested_backlash_mm: None,
    })
}

/// The control's points inside the measured range `first_mm ..= last_mm`:
/// the first one's position and their count; refused when the reference
/// point is not among them (the new compensation is zero there, which only
/// a measurement across it can tell).
pub fn points_in(p: &AxisParameters, first_mm: f64, last_mm: f64) -> Result<(f64, usize), String> {
    let inside: Vec<i64> = (p.first_point()..=p.most_positive)
        .filter(|n| {
            let x = p.position(*n);
            x >= first_mm - 1e-6 && x <= last_mm + 1e-6
        })
        .collect();
    let reference = p.position(p.reference_point);
    match (inside.first(), inside.last()) {
        (Some(a), Some(b)) if (*a..=*b).contains(&p.reference_point) => {
            Ok((p.position(*a), inside.len()))
        }
        _ => Err(format!(
            "the reference point 3620 = {} of axis {} is at {reference} ({}), outside the measured range {first_mm} … {last_mm}: the Fanuc compensation is zero there, so the test must reach it",
            p.reference_point, p.axis, p.source
        )),
    }
}

/// What to tell the user of a table written with `p`: a magnification too
/// coarse for the error, with the one that would do (every point rescaled).
pub fn notes(table: &CompensationTable, options: &EmitOptions) -> Vec<String> {
    let Ok(p) = parameters_for(table, options) else {
        return Vec::new();
    };
    let values = table
        .values
        .for_direction(crate::measurement::Direction::Up);
    let (low, high) = values
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let range = high - low;
    let largest_step = values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    // The finest magnification whose points still hold every section's change.
    let finest = ((largest_step / p.detection_unit / POINT_LIMIT as f64).ceil() as i64).max(1);
    let mut notes = Vec::new();
    if let Some(k) = closing_point(table, &p) {
        let closure = values[k] - values[0];
        if closure.abs() > p.unit() / 2.0 {
            notes.push(format!(
                "Fanuc: the points of one turn sum to zero (0i-PB parameter manual): the measured {}° between the start and the end of the turn is left out",
                crate::emit::minimal(closure, 6)
            ));
        }
    }
    if p.unit() > range / 10.0 && finest < p.magnification {
        notes.push(format!(
            "Fanuc: 3623 = {} gives steps of {} mm, coarse for an error of {} mm peak to valley; 3623 = {finest} would give {} mm steps (every point of the axis rescaled by {}/{finest}, the parameter changed with the data)",
            p.magnification,
            crate::emit::minimal(p.unit(), 7),
            crate::emit::minimal(range, 4),
            crate::emit::minimal(p.detection_unit * finest as f64, 7),
            p.magnification
        ));
    }
    notes
}

/// The parameters a table is written with: the backup's, or axcomp's
/// defaults for the table's own grid.
pub fn parameters_for(
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<AxisParameters, EmitError> {
    let axis = options.axes.first().map_or("X", |a| a.axis.as_str());
    if let Some(p) = options.axes.first().and_then(|a| a.fanuc.clone()) {
        return Ok(p);
    }
    let step = table.regular_step_mm().ok_or(EmitError::UnevenSpacing {
        controller: "fanuc",
    })?;
    let reference = table
        .positions_mm
        .iter()
        .position(|x| (x - table.reference_mm).abs() < 1e-9)
        .ok_or_else(|| {
            EmitError::Profile(format!(
                "a Fanuc table is zero at a compensation point (3620); {} mm is none: give --reference at a point",
                table.reference_mm
            ))
        })?;
    let mut p = AxisParameters::default_for(
        axis,
        table.positions_mm.len(),
        step,
        reference,
        table.reference_mm,
    );
    p.rotary = options.kind == AxisKind::Rotary;
    if p.rotary {
        p.travel_per_turn = 360.0;
    }
    Ok(p)
}

/// The new increments of the points the table covers, in units: the
/// absolute compensation −value rounded at each point (the rounding
/// carried, never accumulated), differenced. Only points whose section lies
/// inside the table get one.
fn new_increments(
    table: &CompensationTable,
    p: &AxisParameters,
) -> Result<BTreeMap<i64, i64>, EmitError> {
    if table.values.mode() == TableMode::Bidirectional {
        return Err(EmitError::NoBidirectional {
            controller: "fanuc",
        });
    }
    let mut points = Vec::with_capacity(table.positions_mm.len());
    for position in &table.positions_mm {
        let point = p
            .point_at(*position)
            .filter(|n| (p.first_point()..=p.most_positive).contains(n))
            .ok_or_else(|| {
                EmitError::Profile(format!(
                    "{position} is no compensation point of axis {} (1240 + (n − 3620) × 3624 for n = {} … {}; {}): build the table on the control's points",
                    p.axis,
                    p.first_point(),
                    p.most_positive,
                    p.source
                ))
            })?;
        points.push(point);
    }
    if (table.reference_mm - p.position(p.reference_point)).abs() > 1e-9 {
        return Err(EmitError::Profile(format!(
            "the Fanuc compensation is zero at the reference point 3620 = {} ({} = {} mm); the table is zero at {} mm: give --reference {} (inside the measured range)",
            p.reference_point,
            p.axis,
            p.position(p.reference_point),
            table.reference_mm,
            p.position(p.reference_point)
        )));
    }
    let unit = p.unit();
    let absolute: Vec<i64> = wanted(table, p)
        .iter()
        .map(|v| (-v / unit).round() as i64)
        .collect();
    let mut increments = BTreeMap::new();
    for k in 1..points.len() {
        if points[k] != points[k - 1] + 1 {
            return Err(EmitError::Profile(format!(
                "the table's points must be consecutive compensation points of axis {} ({} mm apart, 3624)",
                p.axis, p.interval
            )));
        }
        increments.insert(points[k], absolute[k].saturating_sub(absolute[k - 1]));
    }
    check_limits(&increments, p)?;
    Ok(increments)
}

/// The table's values as the control can hold them: \[manual\] 0i-PB
/// p.100, on a rotary axis the points of one turn sum to zero, else the
/// error accumulates turn after turn: the end of a full turn takes the
/// start's value (`notes` says what is dropped).
fn wanted(table: &CompensationTable, p: &AxisParameters) -> Vec<f64> {
    let mut values = table
        .values
        .for_direction(crate::measurement::Direction::Up)
        .to_vec();
    if let Some(k) = closing_point(table, p) {
        values[k] = values[0];
    }
    values
}

/// On a rotary axis, the index of the table point one turn after its first
/// point (3625, 0 for 360°), when the table reaches it.
fn closing_point(table: &CompensationTable, p: &AxisParameters) -> Option<usize> {
    if !p.rotary {
        return None;
    }
    let turn = if p.travel_per_turn > 0.0 {
        p.travel_per_turn
    } else {
        360.0
    };
    let first = table.positions_mm.first()?;
    table
        .positions_mm
        .iter()
        .position(|x| (x - first - turn).abs() < 1e-6)
}

/// Refuses increments beyond a point's limit, naming the magnification that would hold them.
fn check_limits(increments: &BTreeMap<i64, i64>, p: &AxisParameters) -> Result<(), EmitError> {
    let Some((&point, &value)) = increments.iter().max_by_key(|(_, v)| v.unsigned_abs()) else {
        return Ok(());
    };
    if value.unsigned_abs() <= POINT_LIMIT as u64 {
        return Ok(());
    }
    let needed =
        (value.unsigned_abs() as f64 * p.magnification as f64 / POINT_LIMIT as f64).ceil() as i64;
    Err(EmitError::Profile(format!(
        "point {point} of axis {} needs {value} × {} = {} mm, beyond ±{POINT_LIMIT} units a point holds (3623 = {}): set 3623 = {needed} (every point rescaled; units of {} mm) and convert again",
        p.axis,
        crate::emit::minimal(p.unit(), 7),
        crate::emit::minimal(value as f64 * p.unit(), 7),
        p.magnification,
        crate::emit::minimal(p.detection_unit * needed as f64, 7)
    )))
}

/// One data line as the control writes it: `N1nnnnQ0P<value>`, a space
/// after it when its length is odd (\[file\] every line of the real backups).
fn data_line(point: i64, value: i64) -> String {
    let mut line = format!("N{}Q0P{value}", point + DATA_NUMBER_OFFSET);
    if line.len() % 2 == 1 {
        line.push(' ');
    }
    line
}

/// A new pitch file with the points of the table's axis: `%`, the data
/// lines of points 3621 − 1 … 3622 (the sections outside the table hold
/// the compensation: 0), `%`, LF, as the real backup.
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let p = parameters_for(table, options)?;
    let increments = new_increments(table, &p)?;
    let mut out = String::from("%\n");
    for point in p.first_point()..=p.most_positive {
        let value = increments.get(&point).copied().unwrap_or(0);
        out.push_str(&data_line(
            point,
            rotary_reference_value(&p, point, value, &increments),
        ));
        out.push('\n');
    }
    out.push('%');
    Ok(out)
}

/// \[manual\] 0i-PB B-63980EN/01 p.100: on a rotary axis whose most negative
/// point is the reference point, the reference point holds the value of the
/// most positive one.
fn rotary_reference_value(
    p: &AxisParameters,
    point: i64,
    value: i64,
    increments: &BTreeMap<i64, i64>,
) -> i64 {
    if p.rotary && point == p.reference_point && p.most_negative == p.reference_point {
        return increments.get(&p.most_positive).copied().unwrap_or(value);
    }
    value
}

/// The pitch file `existing` with the points the table covers replaced:
/// every other line, and every line end, as it was.
pub fn update(
    existing: &str,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<String, EmitError> {
    let p = parameters_for(table, options)?;
    let (data, end) = parse_pitch(existing).map_err(|e| EmitError::Profile(e.to_string()))?;
    increments(&data, &end, &p).map_err(|e| EmitError::Profile(e.to_string()))?;
    let increments = new_increments(table, &p)?;
    let changed: BTreeMap<usize, String> = increments
        .iter()
        .filter(|(point, value)| data[point].value != **value)
        .map(|(point, value)| (data[point].line.number, data_line(*point, *value)))
        .collect();
    let mut out = String::with_capacity(existing.len() + 16);
    for (index, segment) in existing.split_inclusive('\n').enumerate() {
        match changed.get(&(index + 1)) {
            Some(line) => {
                let content_end = segment.trim_end_matches(['\n', '\r']).len();
                out.push_str(line);
                out.push_str(&segment[content_end..]);
            }
            None => out.push_str(segment),
        }
    }
    Ok(out)
}

/// Whether the written text reads back to the table at its points, within
/// half a unit.
pub fn check_read_back(
    text: &str,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<(), EmitError> {
    let p = parameters_for(table, options)?;
    let back = read(text, &p).map_err(|e| {
        EmitError::Internal(format!("the written fanuc table does not read back: {e}"))
    })?;
    for (position, value) in table.positions_mm.iter().zip(wanted(table, &p)) {
        let read = back.value_at(*position, crate::measurement::Direction::Up);
        if (read - value).abs() > p.unit() / 2.0 + 1e-12 {
            return Err(EmitError::Internal(format!(
                "the written fanuc table reads {read} at {position}, not {value}"
            )));
        }
    }
    Ok(())
}

/// \[manual\] 0i-C B-64120EN/01 p.116: 1851 (cutting feed) and 1852 (rapid
/// traverse, with 1800#4 RBK = 1) in detection units, −9999 … 9999; "the
/// positive or negative direction for compensating values is the direction
/// of movement".
pub fn backlash_parameter(backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
    let axis = options.axes.first().map_or("X", |a| a.axis.as_str());
    let (unit, known) = match options.axes.first().and_then(|a| a.fanuc.as_ref()) {
        Some(p) => (p.detection_unit, true),
        None => (0.001, false),
    };
    let value = (backlash_mm / unit).round() as i64;
    let unit_text = crate::emit::minimal(unit, 7);
    let assumed = if known {
        String::new()
    } else {
        " (assumed: IS-B with 1820 = 2; give --fanuc-parameters for the machine's)".to_string()
    };
    BacklashAdvice::NoParameter(format!(
        "set 1851 of axis {axis} (backlash, cutting feed) to {value} detection units of {unit_text} mm{assumed}, = {} mm; positive compensates lost motion (the value is output in the direction of movement after a reversal); for rapid traverse set 1852 to the reversal measured at rapid traverse and 1800#4 (RBK) = 1",
        crate::emit::minimal(value as f64 * unit, 7)
    ))
}

/// What to do after loading the file.
pub fn activation(file_name: &str, table: &CompensationTable, options: &EmitOptions) -> String {
    let settings = parameters_for(table, options).map_or_else(
        |e| e.to_string(),
        |p| {
            let what = if p.from_backup {
                "as in the parameter backup"
            } else {
                "axcomp's numbering; detection unit assumed 0.001 mm (0.001° on a rotary axis): check 1013 and 1820"
            };
            format!("{} ({what})", p.settings())
        },
    );
    format!(
        "load {file_name} as pitch error compensation data (punch format); parameters {settings}; then turn the power off and on and return the axis to the reference position"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 0i-PB manual's linear example (B-63980EN/01 p.100): points 33 … 49
    /// around reference 40 (at 0 mm), 50 mm apart.
    fn manual_parameters() -> AxisParameters {
        AxisParameters {
            most_negative: 33,
            most_positive: 49,
            reference_point: 40,
            interval: 50.0,
            ..AxisParameters::default_for("X", 1, 50.0, 40, 0.0)
        }
    }

    #[test]
    fn the_manual_example_reads_to_its_absolute_curve() {
        let values = [2, 1, 1, -2, 0, -1, 0, -1, 2, 1, 0, -1, -1, -2, 0, 1, 2];
        let mut text = String::from("%\n");
        for (k, v) in values.iter().enumerate() {
            text.push_str(&data_line(33 + k as i64, *v));
            text.push('\n');
        }
        text.push('%');
        let table = read(&text, &manual_parameters()).unwrap();
        // Point 32 at −400 mm … point 49 at 450 mm.
        assert_eq!(table.positions_mm[0], -400.0);
        assert_eq!(table.positions_mm.len(), 18);
        // By hand: absolute at 0 = 0; at −50: −v40 = +1; at −100: 1 − v39 = 1;
        // at 50: v41 = 2; at 100: 3. The table holds −absolute × 1 µm.
        let at = |x: f64| table.value_at(x, crate::measurement::Direction::Up) * 1000.0;
        assert!((at(0.0)).abs() < 1e-9);
        assert!((at(-50.0) + 1.0).abs() < 1e-9);
        assert!((at(-100.0) + 1.0).abs() < 1e-9);
        assert!((at(50.0) + 2.0).abs() < 1e-9);
        assert!((at(100.0) + 3.0).abs() < 1e-9);
        // Written back from the table: the same increments at 33 … 49.
        let mut options = crate::emit::EmitOptions::for_axis(&Default::default(), "X", "").unwrap();
        options.axes[0].fanuc = Some(manual_parameters());
        let written = write(&table, &options).unwrap();
        assert_eq!(written, text.replacen("%\n", "%\nN10032Q0P0\n", 1));
    }

    fn table(positions_mm: Vec<f64>, values: Vec<f64>) -> CompensationTable {
        CompensationTable {
            axis: "X".into(),
            reference_mm: positions_mm[0],
            positions_mm,
            values: TableValues::Mean(values),
            suggested_backlash_mm: None,
        }
    }

    fn options_with(p: AxisParameters) -> EmitOptions {
        let mut options = EmitOptions::for_axis(&Default::default(), "X", "").unwrap();
        options.axes[0].fanuc = Some(p);
        options
    }

    #[test]
    fn the_worked_example() {
        // formats/fanuc/README.md: 2.3 µm long at 100 mm, 1 µm units: the
        // correction −2.3 µm rounds to −2 units at the point at 100 mm.
        let t = table(vec![0.0, 100.0], vec![0.0, 0.0023]);
        let p = AxisParameters::default_for("X", 2, 100.0, 0, 0.0);
        assert_eq!(
            write(&t, &options_with(p)).unwrap(),
            "%\nN10000Q0P0\nN10001Q0P-2 \n%"
        );
    }

    #[test]
    fn a_point_beyond_its_limit_names_the_magnification_that_holds_it() {
        // −0.2 mm over one section in 1 µm units: 200 > 127, 3623 = 2 holds it.
        let t = table(vec![0.0, 100.0], vec![0.0, -0.2]);
        let p = AxisParameters::default_for("X", 2, 100.0, 0, 0.0);
        let error = write(&t, &options_with(p)).unwrap_err().to_string();
        assert!(error.contains("needs 200"), "{error}");
        assert!(error.contains("set 3623 = 2"), "{error}");
    }

    #[test]
    fn a_coarse_magnification_is_said_with_the_finer_one() {
        // Units of 0.001 mm × 10 = 0.01 mm for an error of 0.02 mm peak to
        // valley; 3623 = 1 holds its 0.01 mm sections (10 units).
        let t = table(vec![0.0, 100.0, 200.0], vec![0.0, 0.01, 0.02]);
        let p = AxisParameters {
            magnification: 10,
            ..AxisParameters::default_for("X", 3, 100.0, 0, 0.0)
        };
        let notes = notes(&t, &options_with(p.clone()));
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("3623 = 1 would give 0.001 mm steps"),
            "{notes:?}"
        );
        let fine = AxisParameters {
            magnification: 1,
            ..p
        };
        assert!(super::notes(&t, &options_with(fine)).is_empty());
    }

    #[test]
    fn a_rotary_reference_point_holds_the_last_points_value() {
        // 0i-PB p.100: reference 1 = most negative 1, 90° apart, 3622 = 1 + 360/90.
        let p = AxisParameters {
            most_negative: 1,
            most_positive: 5,
            rotary: true,
            ..AxisParameters::default_for("B", 5, 90.0, 1, 0.0)
        };
        // Errors in whole units of 0.001° (detection unit assumed, 3623 = 1).
        let t = table(
            vec![0.0, 90.0, 180.0, 270.0, 360.0],
            vec![0.0, 0.002, 0.001, -0.003, 0.0],
        );
        let text = write(&t, &options_with(p.clone())).unwrap();
        let values = increments_of(&text);
        // Absolute corrections 0, −2, −1, 3, 0: increments −2, 1, 4, −3; the
        // reference point 1 takes point 5's −3; they sum to 0 over the turn.
        assert_eq!(
            values,
            vec![(0, 0), (1, -3), (2, -2), (3, 1), (4, 4), (5, -3)]
        );
        let back = read(&text, &p).unwrap();
        assert_eq!(back.positions_mm.len(), 6);
        // A turn that does not close (0.002° at 360°) is closed, and said.
        let open = table(
            vec![0.0, 90.0, 180.0, 270.0, 360.0],
            vec![0.0, 0.002, 0.001, -0.003, 0.002],
        );
        let mut options = options_with(p);
        options.kind = AxisKind::Rotary;
        let text = write(&open, &options).unwrap();
        // Points 2 … 5, one turn, sum to zero.
        let turn: i64 = increments_of(&text)[2..].iter().map(|(_, v)| v).sum();
        assert_eq!(turn, 0);
        check_read_back(&text, &open, &options).unwrap();
        let notes = notes(&open, &options);
        assert!(
            notes[0].contains("0.002° between the start and the end"),
            "{notes:?}"
        );
    }

    fn increments_of(text: &str) -> Vec<(i64, i64)> {
        let (data, _) = parse_pitch(text).unwrap();
        data.iter().map(|(n, d)| (*n, d.value)).collect()
    }

    #[test]
    fn odd_lines_get_a_space_as_in_the_real_file() {
        assert_eq!(data_line(0, 0), "N10000Q0P0");
        assert_eq!(data_line(1, -1), "N10001Q0P-1 ");
        assert_eq!(data_line(310, 10), "N10310Q0P10 ");
        assert_eq!(data_line(311, -10), "N10311Q0P-10");
    }

    #[test]
    fn bad_lines_are_refused_at_their_column() {
        let error = parse_pitch("%\nN10000Q0P0\nN10001Q0Px\n%").unwrap_err();
        assert_eq!((error.position.line, error.position.column), (3, 10));
        let error = ParameterBackup::parse("%\nN01020Q1A1P88A2\n%", "P").unwrap_err();
        assert_eq!((error.position.line, error.position.column), (2, 16));
        assert!(looks_like("%\nN10000Q0P0\n%"));
        assert!(!looks_like("%_N_X_MPF\n"));
    }
}
