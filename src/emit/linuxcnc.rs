//! LinuxCNC screw compensation `COMP_FILE` (`[JOINT_n] COMP_FILE_TYPE = 0|1`): writer and reader.
//!
//! Spec and sources: `formats/linuxcnc/README.md` (\[seen\]: LinuxCNC 2.9
//! `ini-config.adoc`, `usrmotintf.cc`, `control.c`, and a run on LinuxCNC 2.9
//! in this project's tests). One triplet per line, `nominal forward reverse`,
//! nothing else (the loader stops at the first line that is not three
//! numbers, so no header or comment is written and a reader must refuse one),
//! nominal strictly increasing, at most 256 lines, machine units.
//!
//! - Type 0: forward/reverse are the actual positions reached moving +/−:
//!   nominal + error. LinuxCNC computes the trim nominal − actual = −error.
//! - Type 1: forward/reverse are the trims themselves, added to the motor
//!   command: −error.
//!
//! Between lines LinuxCNC interpolates linearly, outside it holds the end
//! values, and at standstill it keeps the last direction's value
//! (`control.c`, `compute_screw_comp`).

use crate::compensate::{CompensationTable, TableValues};
use crate::emit::{BacklashAdvice, EmitError, EmitOptions, minimal};
use crate::error::ParseError;
use crate::measurement::Direction;
use crate::read::text::{self, Line};
use crate::units::LengthUnit;

/// Decimals written: 1 nm in mm machines, 0.1 µin in inch machines (also
/// the resolution of the thermal model's external offset, `linuxcnc_thermal`).
pub(crate) fn decimals(unit: LengthUnit) -> usize {
    match unit {
        LengthUnit::Millimetre => 6,
        LengthUnit::Inch => 7,
    }
}

/// Writes the `COMP_FILE` for the table (type from `options.linuxcnc_type`).
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let unit = options.file_unit();
    let places = decimals(unit);
    if options.linuxcnc_type > 1 {
        return Err(EmitError::Profile(format!(
            "COMP_FILE_TYPE must be 0 or 1, found {}",
            options.linuxcnc_type
        )));
    }
    // Round nominal and errors to the written decimals first, so that a
    // type-0 value (nominal + error) minus its nominal gives the error back exactly.
    let scale = 10f64.powi(places as i32);
    let rounded = |mm: f64| (unit.from_mm(mm) * scale).round() / scale;
    let text = |value: f64| minimal(value, places);
    let mut out = String::new();
    for (index, &position_mm) in table.positions.iter().enumerate() {
        let nominal = rounded(position_mm);
        let error = |d: Direction| rounded(table.values.for_direction(d)[index]);
        let (forward, reverse) = match options.linuxcnc_type {
            0 => (
                nominal + error(Direction::Up),
                nominal + error(Direction::Down),
            ),
            _ => (-error(Direction::Up), -error(Direction::Down)),
        };
        out.push_str(&format!(
            "{} {} {}\n",
            text(nominal),
            text(forward),
            text(reverse)
        ));
    }
    Ok(out)
}

/// No backlash parameter: \[seen\] LinuxCNC 2.9 `ini-config.adoc`, "If
/// `COMP_FILE` is specified for a joint, `BACKLASH` is not used"
/// (`../shared/notes/controller-and-laser-formats.md` §6). The reversal goes
/// into the file's forward and reverse columns instead.
pub fn backlash_parameter(backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
    let joints: Vec<String> = options
        .axes
        .iter()
        .map(|axis| format!("[JOINT_{}] BACKLASH", axis.linuxcnc_joint))
        .collect();
    BacklashAdvice::NoParameter(format!(
        "no backlash parameter: {} is ignored once COMP_FILE is set, so this mean table leaves the reversal of {:.2} µm (−B̄) in place; write the table with --mode bidirectional to take it out (forward and reverse columns, COMP_FILE_TYPE 0 or 1)",
        joints.join(", "),
        crate::units::mm_to_um(backlash_mm)
    ))
}

/// The INI lines that activate the file on a joint; for a rotary joint,
/// what LinuxCNC does beyond the table (\[seen\] `ini-config.adoc`: no
/// modulo wrap, the end values held; `WRAPPED_ROTARY = 1` keeps the joint
/// within 0…359.999°).
pub fn activation(file_name: &str, options: &EmitOptions) -> String {
    let lines = options
        .axes
        .iter()
        .map(|axis| {
            format!(
                "[JOINT_{}]\nCOMP_FILE = {file_name}\nCOMP_FILE_TYPE = {}",
                axis.linuxcnc_joint, options.linuxcnc_type
            )
        })
        .collect::<Vec<_>>()
        .join("\n\n");
    if options.kind == crate::measurement::AxisKind::Rotary {
        return format!(
            "{lines}\n\nA rotary joint: the table is in degrees ([TRAJ]ANGULAR_UNITS = degree) and LinuxCNC does not wrap it: \
             beyond its first and last points it holds the end values. With [JOINT_n]WRAPPED_ROTARY = 1 the joint runs 0…359.999°, \
             which a 0…360° table covers; otherwise make the table cover every angle the joint turns to"
        );
    }
    lines
}

/// Reads a `COMP_FILE`. `file_type` may be `None` when the numbers tell it
/// (type 0 forward values sit near the nominal, type 1 values near zero).
pub fn read(
    input: &str,
    axis: &str,
    file_type: Option<u8>,
    unit: LengthUnit,
) -> Result<CompensationTable, ParseError> {
    let mut rows: Vec<(f64, f64, f64)> = Vec::new();
    let mut lines = text::lines(input).collect::<Vec<Line<'_>>>();
    while lines.last().is_some_and(|l| l.is_blank()) {
        lines.pop();
    }
    for line in &lines {
        let fields: Vec<&str> = line.fields().collect();
        if fields.len() != 3 {
            let at = if line.is_blank() {
                line.text
            } else {
                line.text.trim_start()
            };
            return Err(line.error_at(
                at,
                format!(
                    "expected three numbers (nominal forward reverse), found {} field(s): LinuxCNC stops reading the table here",
                    fields.len()
                ),
            ));
        }
        let nominal = text::number(line, fields[0], "nominal position")?;
        let forward = text::number(line, fields[1], "forward value")?;
        let reverse = text::number(line, fields[2], "reverse value")?;
        if let Some(previous) = rows.last()
            && nominal <= previous.0
        {
            return Err(line.error_at(
                fields[0],
                format!(
                    "nominal {nominal} does not increase (previous {}): LinuxCNC refuses the table",
                    previous.0
                ),
            ));
        }
        rows.push((nominal, forward, reverse));
    }
    if rows.len() < 2 {
        return Err(ParseError::new(
            1,
            1,
            "expected at least two lines of nominal forward reverse",
        ));
    }
    if rows.len() > 256 {
        return Err(ParseError::new(
            257,
            1,
            "more than 256 lines: LinuxCNC takes at most 256 (EMCMOT_COMP_SIZE)",
        ));
    }
    let file_type = match file_type {
        Some(t) => t,
        None => infer_type(&rows, unit)?,
    };
    // A type-0 difference of two numbers written with `places` decimals has
    // `places` decimals: round away the float noise of the subtraction.
    let scale = 10f64.powi(decimals(unit) as i32);
    let to_error = |nominal: f64, value: f64| match file_type {
        0 => unit.to_mm(((value - nominal) * scale).round() / scale),
        _ => -unit.to_mm(value),
    };
    let positions_mm: Vec<f64> = rows.iter().map(|r| unit.to_mm(r.0)).collect();
    let up: Vec<f64> = rows.iter().map(|r| to_error(r.0, r.1)).collect();
    let down: Vec<f64> = rows.iter().map(|r| to_error(r.0, r.2)).collect();
    let values = if up.iter().zip(&down).all(|(a, b)| (a - b).abs() < 1e-12) {
        TableValues::Mean(up)
    } else {
        TableValues::Bidirectional { up, down }
    };
    Ok(super::table_as_read(axis, positions_mm, values))
}

/// Type 0 if every value sits within 1 mm of its nominal and some nominal is
/// far from zero; type 1 if every value is within 1 mm of zero and some
/// nominal is far from zero; otherwise the numbers do not tell.
fn infer_type(rows: &[(f64, f64, f64)], unit: LengthUnit) -> Result<u8, ParseError> {
    let one_mm = unit.from_mm(1.0);
    let far = rows.iter().any(|r| r.0.abs() > 2.0 * one_mm);
    let near_nominal = rows
        .iter()
        .all(|r| (r.1 - r.0).abs() < one_mm && (r.2 - r.0).abs() < one_mm);
    let near_zero = rows
        .iter()
        .all(|r| r.1.abs() < one_mm && r.2.abs() < one_mm);
    match (far, near_nominal, near_zero) {
        (true, true, false) => Ok(0),
        (true, false, true) => Ok(1),
        _ => Err(ParseError::new(
            1,
            1,
            "cannot tell COMP_FILE_TYPE from the numbers; give it (--linuxcnc-type 0 or 1)",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::profile::MachineProfile;

    fn options(file_type: u8) -> EmitOptions {
        EmitOptions {
            axes: vec![MachineProfile::default().axis("X").unwrap()],
            table_name: String::new(),
            machine_unit: LengthUnit::Millimetre,
            linuxcnc_type: file_type,
            max_points: None,
            max_value_mm: None,
            provenance: None,
            cec_values_are_corrections: true,
            tnc640_columns: Vec::new(),
            kind: Default::default(),
        }
    }

    fn table() -> CompensationTable {
        CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![0.0, 100.0],
            values: TableValues::Bidirectional {
                up: vec![0.0, 0.010],
                down: vec![0.0, -0.010],
            },
            reference: 0.0,
            suggested_backlash: None,
        }
    }

    #[test]
    fn the_spec_example_by_hand() {
        // controllers.md: `100 100.010 99.990` moving + to X50 gives motor 49.995,
        // i.e. the axis ran 10 µm long at 100 mm moving +: error +0.010 there.
        assert_eq!(
            write(&table(), &options(0)).unwrap(),
            "0 0 0\n100 100.01 99.99\n"
        );
        assert_eq!(
            write(&table(), &options(1)).unwrap(),
            "0 0 0\n100 -0.01 0.01\n"
        );
    }

    #[test]
    fn both_types_read_back_and_are_told_apart() {
        for file_type in [0, 1] {
            let text = write(&table(), &options(file_type)).unwrap();
            let back = read(&text, "X", None, LengthUnit::Millimetre).unwrap();
            assert_eq!(back, table(), "type {file_type}");
        }
        let ambiguous = "0 0 0\n1 1.001 0.999\n";
        assert!(
            read(ambiguous, "X", None, LengthUnit::Millimetre)
                .unwrap_err()
                .message
                .contains("--linuxcnc-type")
        );
        let told = read(ambiguous, "X", Some(0), LengthUnit::Millimetre).unwrap();
        assert!((told.value_at(1.0, Direction::Up) - 0.001).abs() < 1e-12);
    }

    #[test]
    fn lines_linuxcnc_would_stop_at_are_refused() {
        let cases = [
            ("# header\n0 0 0\n100 100 100\n", (1, 1), "three numbers"),
            ("0 0 0\n\n100 100 100\n", (2, 1), "stops reading"),
            ("0 0 0\n0 0 0\n", (2, 1), "does not increase"),
            ("0 0 0\n100 1,5 0\n", (2, 5), "decimal comma"),
        ];
        for (text, (line, column), needle) in cases {
            let error = read(text, "X", Some(0), LengthUnit::Millimetre).unwrap_err();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "{text:?}: {error}"
            );
            assert!(error.message.contains(needle), "{error}");
        }
    }

    #[test]
    fn inch_machines_write_inches() {
        let mut inch = options(0);
        inch.machine_unit = LengthUnit::Inch;
        let t = CompensationTable {
            positions: vec![0.0, 25.4],
            values: TableValues::Mean(vec![0.0, 0.00254]),
            ..table()
        };
        assert_eq!(write(&t, &inch).unwrap(), "0 0 0\n1 1.0001 1.0001\n");
    }
}
