//! The parameter backup (`CNC-PARA.TXT`) read, and what it says of one
//! axis' pitch error compensation ([`AxisParameters`]).

use std::collections::BTreeMap;

use super::{MAX_POINT, READ_LIMIT};
use crate::error::ParseError;
use crate::measurement::Direction;
use crate::read::text::{self, Line};

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
    /// 3605 as the backup has it (8 bits, `#7 … #0`; empty without a
    /// backup): its other bits are not known to axcomp (`notes` says so).
    pub bits_3605: String,
    /// Where 3605 of the axis stands in the backup (`FILE:LINE:COL`; empty
    /// without a backup).
    pub at_3605: String,
    /// 3626: with 3605#0, the most negative point of the table for travel
    /// in the negative direction (its points 3626 … 3626 + 3622 − 3621).
    pub negative_first: i64,
    /// 3627: with 3605#0, the absolute compensation at the reference
    /// position for travel in the negative direction, in units.
    pub reference_negative: i64,
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
            bits_3605: String::new(),
            at_3605: String::new(),
            negative_first: 0,
            reference_negative: 0,
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

    /// `value` (mm or °) as the user reads it: `0.001 mm`, `0.0001°`.
    pub fn unit_text(&self, value: f64) -> String {
        let number = crate::emit::minimal(value, 7);
        match self.rotary {
            true => format!("{number}°"),
            false => format!("{number} mm"),
        }
    }

    /// The unit of the axis' positions: `°` on a rotary axis, else `mm`.
    pub fn length_unit(&self) -> &'static str {
        if self.rotary { "°" } else { "mm" }
    }

    /// The machine position of point `point`, mm or °.
    pub fn position(&self, point: i64) -> f64 {
        self.reference_position + (point - self.reference_point) as f64 * self.interval
    }

    /// The first point of the axis' curve: the start of the section of 3621.
    pub fn first_point(&self) -> i64 {
        self.most_negative - 1
    }

    /// The bits of 3605 set besides #0, whose meaning axcomp does not know.
    pub fn unknown_3605_bits(&self) -> Vec<usize> {
        self.bits_3605
            .bytes()
            .rev()
            .enumerate()
            .filter(|(bit, b)| *bit > 0 && *b == b'1')
            .map(|(bit, _)| bit)
            .collect()
    }

    /// The directions the axis has a table for: ↑, and ↓ with 3605#0.
    pub fn directions(&self) -> &'static [Direction] {
        if self.bidirectional {
            &Direction::BOTH
        } else {
            &[Direction::Up]
        }
    }

    /// The data point holding the section that ends at `point` for travel
    /// in `direction`: \[reconstructed\] the ↓ table (3626 …) in the order
    /// of the ↑ one (3621 …), point 3626 + k for the section of 3621 + k.
    pub fn data_point(&self, direction: Direction, point: i64) -> i64 {
        match direction {
            Direction::Up => point,
            Direction::Down => point - self.most_negative + self.negative_first,
        }
    }

    /// The absolute compensation at the reference position, in units:
    /// zero for travel in the positive direction, 3627 in the negative one.
    pub fn at_reference(&self, direction: Direction) -> i64 {
        match direction {
            Direction::Up => 0,
            Direction::Down => self.reference_negative,
        }
    }

    /// The point at `position`, when it is one.
    pub(super) fn point_at(&self, position: f64) -> Option<i64> {
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
        if self.bidirectional {
            text.push_str(&format!(
                ", 3605#0 = 1, 3626 = {}, 3627 = {}",
                self.negative_first, self.reference_negative
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

    /// An integer parameter: \[reconstructed\] at most 8 digits, as every
    /// one of the real backup (beyond, the point arithmetic would overflow).
    pub(super) fn integer(&self, number: u32, index: Option<(char, usize)>) -> Result<i64, String> {
        let entry = self.value(number, index)?;
        entry
            .value
            .parse()
            .ok()
            .filter(|v: &i64| v.unsigned_abs() <= READ_LIMIT as u64)
            .ok_or_else(|| {
                format!(
                    "{}:{}:{}: parameter {number:04}: expected an integer of at most 8 digits, found {:?}",
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
            bits_3605: self.value(3605, a)?.value.clone(),
            at_3605: self
                .value(3605, a)
                .map(|e| format!("{}:{}:{}", self.source, e.line, e.column))?,
            // [manual] A-77810E table (a); absent on a control without the function.
            negative_first: self.integer(3626, a).unwrap_or(0),
            reference_negative: self.integer(3627, a).unwrap_or(0),
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
    let last_negative = p.data_point(Direction::Down, p.most_positive);
    if p.bidirectional
        && (p.negative_first < 0
            || last_negative > MAX_POINT
            || (p.negative_first <= p.most_positive && last_negative >= p.first_point()))
    {
        return Err(format!(
            "3626 of axis {axis} is {}: its table for travel in the negative direction, points {} … {last_negative}, must lie in 0 … {MAX_POINT} apart from the positive one ({} … {})",
            p.negative_first,
            p.negative_first,
            p.first_point(),
            p.most_positive
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

/// Whether the text is a parameter backup: a `%` line, then `N<5 digits>Q1`.
pub fn looks_like_parameters(text: &str) -> bool {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    lines.next() == Some("%")
        && lines
            .next()
            .is_some_and(|l| l.starts_with('N') && l.get(6..8) == Some("Q1"))
}
