//! The pitch error compensation data (`PITCH.TXT`) read: its data lines,
//! and the absolute compensation of one axis they imply.

use std::collections::BTreeMap;

use super::{AxisParameters, DATA_NUMBER_OFFSET, READ_LIMIT};
use crate::compensate::{CompensationTable, TableValues};
use crate::error::ParseError;
use crate::measurement::{AxisKind, Direction};
use crate::read::text::{self, Line};

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

/// One data line of a pitch file: its point, value and line.
#[derive(Clone, Copy, Debug)]
pub(super) struct DataLine<'a> {
    pub(super) value: i64,
    pub(super) line: Line<'a>,
}

/// The pitch file's data by point, and the line of its closing `%` (or last line).
pub(super) fn parse_pitch(
    input: &str,
) -> Result<(BTreeMap<i64, DataLine<'_>>, Line<'_>), ParseError> {
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
            .filter(|v: &i64| v.unsigned_abs() <= READ_LIMIT as u64)
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

/// The increments of the sections ending at points 3621 … 3622 for travel
/// in `direction` (keyed by those points; the ↓ ones read at 3626 …), or an
/// error at `end` naming the missing data number.
pub(super) fn increments(
    data: &BTreeMap<i64, DataLine<'_>>,
    end: &Line<'_>,
    p: &AxisParameters,
    direction: Direction,
) -> Result<BTreeMap<i64, i64>, ParseError> {
    (p.most_negative..=p.most_positive)
        .map(|point| {
            let at = p.data_point(direction, point);
            match data.get(&at) {
                Some(d) => Ok((point, d.value)),
                None => Err(end.error_at(
                    end.text,
                    format!(
                        "the pitch file has no data number N{} (point {at} of axis {}{}: {}): the parameter backup does not belong to this pitch file",
                        at + DATA_NUMBER_OFFSET,
                        p.axis,
                        match direction {
                            Direction::Up => "",
                            Direction::Down => " for travel in the negative direction, 3626",
                        },
                        p.source
                    ),
                )),
            }
        })
        .collect()
}

/// The absolute compensation, in units, at every point 3621 − 1 … 3622
/// from the increments: `at_reference` at the reference point (0, or 3627
/// for travel in the negative direction).
pub(super) fn absolute_units(
    p: &AxisParameters,
    increments: &BTreeMap<i64, i64>,
    at_reference: i64,
) -> Vec<(i64, i64)> {
    let mut absolute = BTreeMap::new();
    absolute.insert(p.reference_point, at_reference);
    let mut sum = at_reference;
    for point in p.reference_point + 1..=p.most_positive {
        sum += increments[&point];
        absolute.insert(point, sum);
    }
    let mut sum = at_reference;
    for point in (p.first_point()..p.reference_point).rev() {
        sum -= increments[&(point + 1)];
        absolute.insert(point, sum);
    }
    absolute.into_iter().collect()
}

/// Reads the pitch error compensation of the axis of `p` from a pitch file:
/// the error it compensates (−absolute compensation) at every point
/// 3621 − 1 … 3622, zero at the reference point; with 3605#0 one column
/// per direction, the ↓ one 3627 from zero there.
pub fn read(input: &str, p: &AxisParameters) -> Result<CompensationTable, ParseError> {
    let (data, end) = parse_pitch(input)?;
    let unit = p.unit();
    let mut columns = Vec::with_capacity(2);
    let mut positions_mm = Vec::new();
    for direction in p.directions() {
        let increments = increments(&data, &end, p, *direction)?;
        let (positions, values): (Vec<f64>, Vec<f64>) =
            absolute_units(p, &increments, p.at_reference(*direction))
                .into_iter()
                .map(|(point, units)| (p.position(point), -(units as f64) * unit + 0.0))
                .unzip();
        positions_mm = positions;
        columns.push(values);
    }
    let values = match <[Vec<f64>; 2]>::try_from(columns) {
        Ok([up, down]) => TableValues::Bidirectional { up, down },
        Err(mut one) => TableValues::Mean(one.remove(0)),
    };
    Ok(CompensationTable {
        axis: p.axis.clone(),
        kind: if p.rotary {
            AxisKind::Rotary
        } else {
            AxisKind::Linear
        },
        positions: positions_mm,
        values,
        reference: p.position(p.reference_point),
        suggested_backlash: None,
    })
}

/// One data line as the control writes it: `N1nnnnQ0P<value>`, a space
/// after it when its length is odd (\[file\] every line of the real backups).
pub(super) fn data_line(point: i64, value: i64) -> String {
    let mut line = format!("N{}Q0P{value}", point + DATA_NUMBER_OFFSET);
    if line.len() % 2 == 1 {
        line.push(' ');
    }
    line
}
