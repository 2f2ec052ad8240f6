//! Fagor 8055 leadscrew error compensation table `AL<axis>`: writer and reader.
//!
//! Spec and sources: `formats/fagor8055/README.md` (\[seen\] real files from
//! one machine in `../shared/data/api-xd/`, the 8055 installation manual
//! §7.5.7). One line per point, no header:
//!
//! ```text
//!       P0001         X    0.00000       EX   -0.00127        EX    0.00000
//! ```
//!
//! point number, axis letter and position, then `E<axis>` and the error in
//! the positive direction, `E<axis>` and the error in the negative direction.
//! Positions and errors are in the machine's unit (the files here are inch,
//! 5 decimals), positions strictly increasing, at most 1000 points. The
//! error is the axis error actual − target, written as it is; a negative
//! column of zeros means the positive one serves both directions.

use crate::compensate::CompensationTable;
use crate::emit::fagor::{self, LIMIT_MM};
use crate::emit::{BacklashAdvice, BacklashParameter, EmitError, EmitOptions};
use crate::error::ParseError;
use crate::read::text::{self, Line};
use crate::units::LengthUnit;

/// \[seen\] 8055 manual §7.5.7: "up to 1000 points per axis" (NPOINTS, P16).
pub const MAX_POINTS: usize = 1000;

/// Decimals of positions and errors: \[seen\] 5 in the inch files; the
/// manual's ranges (±99999.9999 mm, ±3937.00787 inches) give 4 in mm.
pub fn decimals(unit: LengthUnit) -> usize {
    match unit {
        LengthUnit::Millimetre => 4,
        LengthUnit::Inch => 5,
    }
}

/// Writes the `AL<axis>` table of `options.axes[0]` in `options.machine_unit`, CRLF.
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let unit = options.machine_unit;
    let places = decimals(unit);
    let axis = axis_letter(options)?;
    let resolution_mm = unit.to_mm(10f64.powi(-(places as i32)));
    if fagor::down_column_vanishes(table, resolution_mm) {
        return Err(EmitError::Profile(
            "the ↓ column of this bidirectional table is zero at every point, and a Fagor 8055 then applies the ↑ column in both directions: write it with --mode mean".to_string(),
        ));
    }
    let (positive, negative) = fagor::columns_mm(table);
    let number = |mm: f64| fagor::fixed(unit.from_mm(mm), places);
    let mut out = String::new();
    for (index, position_mm) in table.positions.iter().enumerate() {
        out.push_str(&format!(
            "      {:<14}{axis}{:>11}{:>9}{:>11}{:>10}{:>11}\r\n",
            format!("P{:04}", index + 1),
            number(*position_mm),
            format!("E{axis}"),
            number(positive[index]),
            format!("E{axis}"),
            number(negative[index]),
        ));
    }
    Ok(out)
}

/// The axis letter the table is written for: one capital letter, as the
/// 8055 names its axes.
fn axis_letter(options: &EmitOptions) -> Result<char, EmitError> {
    let name = options.axes.first().map_or("", |a| a.axis.as_str());
    let mut chars = name.chars();
    match (chars.next(), chars.next()) {
        (Some(letter), None) if letter.is_ascii_uppercase() => Ok(letter),
        _ => Err(EmitError::Profile(format!(
            "a Fagor 8055 table names its axis with one capital letter (X, Y, Z, U, V, W, A, B, C), not {name:?}: give --axis"
        ))),
    }
}

/// \[reconstructed\] The 8055 axis parameter BACKLASH (P14, the one before
/// LSCRWCOM P15 and NPOINTS P16 in the manual's list), in the machine unit.
pub fn backlash_parameter(backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
    let axes: Vec<&str> = options.axes.iter().map(|a| a.axis.as_str()).collect();
    BacklashAdvice::Parameter(BacklashParameter::new(
        format!("axis parameter BACKLASH (P14) of axis {}", axes.join(", ")),
        backlash_mm,
        options.machine_unit,
        decimals(options.machine_unit),
        BACKLASH_SIGN,
        Some(
            "or write the table with --mode bidirectional: the negative-direction errors then carry the reversal and BACKLASH stays 0".to_string(),
        ),
    ))
}

/// \[reconstructed\] What a positive Fagor backlash value means.
pub(crate) const BACKLASH_SIGN: &str =
    "positive when the axis falls short after a reversal (lost motion, the usual case)";

/// How to load the table.
pub fn activation(file_name: &str, options: &EmitOptions) -> String {
    let axis = options.axes.first().map_or("X", |a| a.axis.as_str());
    format!(
        "load {file_name} as the leadscrew table of axis {axis} (AL{axis}); set the axis parameters LSCRWCOM (P15) = ON and NPOINTS (P16) to the number of points, then home the axis"
    )
}

/// Reads an `AL<axis>` table for `axis` in `unit`; whether the table is
/// bidirectional is told by its negative column (all zero: mean).
pub fn read(input: &str, axis: &str, unit: LengthUnit) -> Result<CompensationTable, ParseError> {
    let mut positions_mm: Vec<f64> = Vec::new();
    let (mut positive, mut negative) = (Vec::new(), Vec::new());
    for line in text::lines(input).filter(|l| !l.is_blank()) {
        let (position_mm, up_mm, down_mm) = row(&line, positions_mm.len() + 1, axis, unit)?;
        if let Some(previous) = positions_mm.last()
            && position_mm <= *previous
        {
            let token = line.fields().nth(2).unwrap_or(line.text);
            return Err(line.error_at(
                token,
                format!(
                    "position {} does not increase (previous {}): the 8055 needs the points in ascending order",
                    unit.from_mm(position_mm),
                    unit.from_mm(*previous)
                ),
            ));
        }
        if positions_mm.len() == MAX_POINTS {
            return Err(line.error_at(
                line.text.trim_start(),
                format!(
                    "more than {MAX_POINTS} points: the 8055 takes at most {MAX_POINTS} per axis"
                ),
            ));
        }
        positions_mm.push(position_mm);
        positive.push(up_mm);
        negative.push(down_mm);
    }
    if positions_mm.len() < 2 {
        return Err(ParseError::new(
            text::end_of_file_line(input),
            1,
            "expected at least two points (P0001 X position EX error EX error)",
        ));
    }
    let bidirectional = negative.iter().any(|v| *v != 0.0);
    Ok(fagor::table_of(
        axis,
        positions_mm,
        positive,
        negative,
        bidirectional,
    ))
}

/// One line: `P<n> <axis> <position> E<axis> <error+> E<axis> <error->`.
fn row(
    line: &Line<'_>,
    expected_point: usize,
    axis: &str,
    unit: LengthUnit,
) -> Result<(f64, f64, f64), ParseError> {
    let fields: Vec<&str> = line.fields().collect();
    if fields.len() != 7 {
        let at = fields.get(7).copied().unwrap_or(line.text.trim_start());
        return Err(line.error_at(
            at,
            format!(
                "expected 7 fields (P0001 X position EX error EX error), found {}",
                fields.len()
            ),
        ));
    }
    let point = fields[0];
    let digits = point.strip_prefix('P').unwrap_or("");
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(line.expected_at(point, "a point number P0001, P0002, …"));
    }
    if digits.parse::<usize>().ok() != Some(expected_point) {
        return Err(line.error_at(
            point,
            format!("expected point P{expected_point:04}, found {point}: the points are numbered 1, 2, 3, … in order"),
        ));
    }
    if fields[1] != axis {
        return Err(line.error_at(
            fields[1],
            format!(
                "this is a table of axis {}, not of the measured axis {axis}: give --axis {} if the test measured it",
                fields[1], fields[1]
            ),
        ));
    }
    let error_label = format!("E{axis}");
    for label in [fields[3], fields[5]] {
        if label != error_label {
            return Err(line.expected_at(label, &error_label));
        }
    }
    let column = |token: &str| line.column_of(token);
    let position = text::number(line, fields[2], "position")?;
    let position_mm = text::check_target_mm(unit.to_mm(position), line.number, column(fields[2]))?;
    let error_mm = |token: &str, what: &str| -> Result<f64, ParseError> {
        let value = text::number(line, token, what)?;
        text::check_deviation_mm(unit.to_mm(value), line.number, column(token))
    };
    let up = error_mm(fields[4], "positive-direction error")?;
    let down = error_mm(fields[6], "negative-direction error")?;
    if position_mm.abs() > LIMIT_MM {
        return Err(line.error_at(
            fields[2],
            "position beyond ±99999.9999 mm (±3937.00787 in), the 8055's range",
        ));
    }
    Ok((position_mm, up, down))
}

/// Whether the text looks like an 8055 table: its first non-blank line
/// starts `P<digits> <letter> <number> E<letter>`.
pub fn looks_like(text: &str) -> bool {
    let Some(first) = text.lines().find(|l| !l.trim().is_empty()) else {
        return false;
    };
    let fields: Vec<&str> = first.split_whitespace().collect();
    fields.len() >= 4
        && fields[0].len() > 1
        && fields[0].starts_with('P')
        && fields[0][1..].bytes().all(|b| b.is_ascii_digit())
        && fields[3].starts_with('E')
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::TableValues;
    use crate::emit::MachineProfile;

    fn options(axis: &str, unit: LengthUnit) -> EmitOptions {
        let mut options = EmitOptions::for_axis(&MachineProfile::default(), axis, "").unwrap();
        options.machine_unit = unit;
        options
    }

    #[test]
    fn the_real_first_rows_by_hand() {
        // ../shared/data/api-xd/test__data__ALX (LF), inch: 5 in = 127 mm,
        // −0.00127 in = −0.032258 mm.
        let text = "      P001          X    0.00000       EX    0.00000        EX    0.00000\n      P002          X    5.00000       EX   -0.00127        EX    0.00000\n      P003          X   10.00000       EX   -0.00276        EX    0.00000\n";
        let table = read(text, "X", LengthUnit::Inch).unwrap();
        assert_eq!(table.positions, vec![0.0, 127.0, 254.0]);
        let TableValues::Mean(values) = &table.values else {
            panic!("a zero negative column is a mean table")
        };
        assert!((values[1] - -0.032_258).abs() < 1e-12, "{values:?}");
        assert!((values[2] - -0.070_104).abs() < 1e-12, "{values:?}");
        // Written back: the same columns (4-digit point numbers, CRLF).
        let written = write(&table, &options("X", LengthUnit::Inch)).unwrap();
        assert_eq!(
            written.lines().nth(1).unwrap(),
            "      P0002         X    5.00000       EX   -0.00127        EX    0.00000"
        );
        assert!(written.ends_with("0.00000\r\n"));
    }

    #[test]
    fn bidirectional_tables_use_both_columns() {
        let table = CompensationTable {
            axis: "Y".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![-100.0, 0.0],
            values: TableValues::Bidirectional {
                up: vec![0.0123, 0.0],
                down: vec![0.0223, 0.001],
            },
            reference: 0.0,
            suggested_backlash: None,
        };
        let text = write(&table, &options("Y", LengthUnit::Millimetre)).unwrap();
        assert_eq!(
            text.lines().next().unwrap(),
            "      P0001         Y  -100.0000       EY     0.0123        EY     0.0223"
        );
        let back = read(&text, "Y", LengthUnit::Millimetre).unwrap();
        assert_eq!(back.values, table.values);
        // A ↓ column of zeros would be read by the control as "same as ↑".
        let mut vanishing = table.clone();
        vanishing.values = TableValues::Bidirectional {
            up: vec![0.0123, 0.0],
            down: vec![0.0, 0.00001],
        };
        assert!(write(&vanishing, &options("Y", LengthUnit::Millimetre)).is_err());
    }

    #[test]
    fn bad_lines_are_refused_at_their_column() {
        let good = "      P001          X    0.00000       EX    0.00000        EX    0.00000\n";
        let cases = [
            (
                "      P002          X    5.00000       EX   -0.00127        EX\n",
                (2, 7),
                "expected 7 fields",
            ),
            (
                "      P003          X    5.00000       EX   -0.00127        EX    0.00000\n",
                (2, 7),
                "expected point P0002",
            ),
            (
                "      P002          Y    5.00000       EY   -0.00127        EY    0.00000\n",
                (2, 21),
                "not of the measured axis X",
            ),
            (
                "      P002          X    5.00000       EX   -0,00127        EX    0.00000\n",
                (2, 45),
                "decimal comma",
            ),
            (
                "      P002          X    0.00000       EX   -0.00127        EX    0.00000\n",
                (2, 26),
                "does not increase",
            ),
        ];
        for (second, (line, column), needle) in cases {
            let error = read(&format!("{good}{second}"), "X", LengthUnit::Inch).unwrap_err();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "{error}"
            );
            assert!(error.to_string().contains(needle), "{error}");
        }
        assert!(read(good, "X", LengthUnit::Inch).is_err());
        assert!(looks_like(good));
        assert!(!looks_like("0 0.001 0.002\n"));
    }
}
