//! What a controller would refuse, refused before anything is written: the
//! reasons ([`EmitError`]) and the checks ([`check_table`]).

use super::{Controller, EmitOptions, fagor, resolution_mm};
use crate::compensate::{CompensationTable, TableMode};
use crate::measurement::{AxisKind, Direction, Position};
use crate::units::LengthUnit;

/// Why a table is refused for a controller.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EmitError {
    /// An axis whose letter gives no default for a name the controller needs.
    #[error(
        "axis {axis:?} has no default {what}; give it in the machine profile under [controller.axes.{axis}]"
    )]
    NoDefault {
        /// The axis.
        axis: String,
        /// The profile key it needs.
        what: &'static str,
    },
    /// More points than the controller takes.
    #[error(
        "{controller} takes at most {max} compensation points, the table has {count}; use a larger --step"
    )]
    TooManyPoints {
        /// The controller.
        controller: &'static str,
        /// The limit.
        max: usize,
        /// The table's points.
        count: usize,
    },
    /// Points not strictly increasing.
    #[error(
        "compensation positions must be strictly increasing: {}{} follows {}{}",
        position.in_axis_unit(), position.unit_after_number(),
        previous.in_axis_unit(), previous.unit_after_number()
    )]
    NotIncreasing {
        /// The offending point.
        position: Position,
        /// The one before.
        previous: Position,
    },
    /// Uneven spacing where the format has one step.
    #[error(
        "{controller} needs evenly spaced points (one step for the whole table); give --step (and --start, --count)"
    )]
    UnevenSpacing {
        /// The controller.
        controller: &'static str,
    },
    /// A step the format cannot write exactly.
    #[error(
        "{controller} writes the step to {}{unit}; a step of {}{unit} would shift the points along the table: give --step as a multiple of {}{unit}",
        resolution.in_axis_unit(), step.in_axis_unit(), resolution.in_axis_unit(),
        unit = step.unit_after_number()
    )]
    StepNotRepresentable {
        /// The controller.
        controller: &'static str,
        /// The step.
        step: Position,
        /// The format's resolution.
        resolution: Position,
    },
    /// A compensation point beyond the positions the format can hold.
    #[error(
        "compensation point {}{unit} is beyond the {controller} position range of ±{}{unit}",
        position.in_axis_unit(), limit.in_axis_unit(),
        unit = position.unit_after_number()
    )]
    PositionOutOfRange {
        /// The controller.
        controller: &'static str,
        /// The point.
        position: Position,
        /// The limit.
        limit: Position,
    },
    /// A value beyond the format's or the machine's range.
    #[error(
        "value {}{unit} at {}{unit} is beyond the {what} range of ±{}{unit}",
        value.in_axis_unit(), position.in_axis_unit(), limit.in_axis_unit(),
        unit = position.unit_after_number()
    )]
    ValueOutOfRange {
        /// The value.
        value: Position,
        /// Where.
        position: Position,
        /// Whose range.
        what: &'static str,
        /// The limit.
        limit: Position,
    },
    /// The format has one column only.
    #[error(
        "{controller} tables hold one value per point; use --mode mean (and set the backlash parameter to the suggested value)"
    )]
    NoBidirectional {
        /// The controller.
        controller: &'static str,
    },
    /// The format needs zero at its first point.
    #[error(
        "{controller} needs the value 0 at the first point (the datum); the table is {}{} there: use --reference at the first point",
        value.in_axis_unit(), value.unit_after_number()
    )]
    NotZeroAtDatum {
        /// The controller.
        controller: &'static str,
        /// The value at the first point.
        value: Position,
    },
    /// A rotary axis for a format that shows no rotary form.
    #[error(
        "{controller} tables are written for linear axes only: the format's documents show no rotary table (formats/{controller}/README.md)"
    )]
    RotaryNotSupported {
        /// The controller.
        controller: &'static str,
    },
    /// A full-turn modulo table must go from 0° to 360°.
    #[error(
        "a Sinumerik modulo table of a rotary axis goes from 0° to 360° ($AA_ENC_COMP_MIN 0, MAX 360); this one goes from {first_deg}° to {last_deg}°: build it on a 0…360° grid (--start 0 --step …)"
    )]
    ModuloRange {
        /// The first point, °.
        first_deg: f64,
        /// The last point, °.
        last_deg: f64,
    },
    /// A modulo table whose ends, one physical position, differ.
    #[error(
        "a Sinumerik modulo table repeats every turn, so its values at 0° and 360° must be equal; this one has {first_deg}° at 0° and {last_deg}° at 360°"
    )]
    ModuloEndsDiffer {
        /// The value at 0°, °.
        first_deg: f64,
        /// The value at 360°, °.
        last_deg: f64,
    },
    /// A table of one kind of axis with the options of the other: its
    /// numbers would be written in the other unit (degrees as mm).
    #[error(
        "the table is of a {} axis (in {}) and the file is for a {} axis (in {}): they do not belong together",
        table.as_str(), table.position_unit(), options.as_str(), options.position_unit()
    )]
    KindMismatch {
        /// The table's axis kind.
        table: AxisKind,
        /// The kind the options write.
        options: AxisKind,
    },
    /// A profile value the format cannot use.
    #[error("{0}")]
    Profile(String),
    /// A bug: the written text does not read back to the table.
    #[error("internal error, please report: {0}")]
    Internal(String),
}

/// The largest |compensation point| and |value| a format holds, mm; the value
/// limit comes with the name of its range, for the message.
fn format_limits_mm(
    controller: Controller,
    machine_unit: LengthUnit,
) -> (f64, (&'static str, f64)) {
    match controller {
        // [reconstructed] Points: ±99 999.9999 mm, the input range of the
        // iTNC 530's traverse limits (MP910–MP921); beyond it a point is no
        // axis position and would overflow the 14-character AXISPOS column of
        // a TNC 640 table. Values: ±9.9999 mm, the range of the backlash
        // parameter MP750 and of a signed 4-decimal field; no COM-specific
        // limit is public.
        Controller::Itnc530 | Controller::Tnc640 => (99_999.999_9, ("Heidenhain", 9.9999)),
        // No published limit, but both controllers parse numbers as doubles,
        // which hold every multiple of the resolution up to 9·10¹⁵ of them:
        // 10¹⁵ resolutions keeps every written digit, also where a LinuxCNC
        // type-0 row writes point + value.
        Controller::Sinumerik840d | Controller::LinuxCnc => {
            let digits_mm = resolution_mm(controller, machine_unit) * 1e15;
            (digits_mm, ("15-digit", digits_mm))
        }
        Controller::Fagor8055 | Controller::Fagor8065 => {
            (fagor::LIMIT_MM, ("Fagor", fagor::LIMIT_MM))
        }
        // [reconstructed] 3624 and 1240 hold ±99 999.999 mm (IS-B); each
        // point's own limit is checked by `fanuc` in its units.
        Controller::Fanuc => (99_999.999, ("Fanuc", 99_999.999)),
    }
}

/// Checks what the controller would reject, before anything is written.
pub fn check_table(
    controller: Controller,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<(), EmitError> {
    let name = controller.name();
    let typed = |value: f64| table.kind.position(value);
    if table.kind != options.kind {
        return Err(EmitError::KindMismatch {
            table: table.kind,
            options: options.kind,
        });
    }
    check_rotary(controller, table, options)?;
    let count = table.positions.len();
    let limit = match (controller.max_points(), options.max_points) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };
    if let Some(max) = limit
        && count > max
    {
        return Err(EmitError::TooManyPoints {
            controller: name,
            max,
            count,
        });
    }
    for pair in table.positions.windows(2) {
        if pair[1] <= pair[0] {
            return Err(EmitError::NotIncreasing {
                position: typed(pair[1]),
                previous: typed(pair[0]),
            });
        }
    }
    if !controller.accepts_free_positions() {
        let Some(step) = table.regular_step() else {
            return Err(EmitError::UnevenSpacing { controller: name });
        };
        // One step for the whole table, written to the format's resolution:
        // a rounded step would shift point k by k times the rounding.
        let resolution = resolution_mm(controller, options.file_unit());
        if ((step / resolution).round() * resolution - step).abs() > 1e-9 {
            return Err(EmitError::StepNotRepresentable {
                controller: name,
                step: typed(step),
                resolution: typed(resolution),
            });
        }
    }
    // A Fanuc control has a table per direction with 3605#0, which the
    // axis' parameters tell (`fanuc::write` refuses with what to set).
    if table.values.mode() == TableMode::Bidirectional
        && !controller.supports_bidirectional()
        && controller != Controller::Fanuc
    {
        return Err(EmitError::NoBidirectional { controller: name });
    }
    // TNC 335/407 manuals: "The error curve must always start with correction value = 0 at the datum point."
    let first_value = table.values.for_direction(Direction::Up)[0];
    if controller == Controller::Itnc530 && first_value.abs() >= 0.5e-4 {
        return Err(EmitError::NotZeroAtDatum {
            controller: name,
            value: typed(first_value),
        });
    }
    let (position_limit_mm, value_limit) = format_limits_mm(controller, options.file_unit());
    if let Some(position_mm) = table
        .positions
        .iter()
        .find(|position| position.abs() > position_limit_mm)
    {
        return Err(EmitError::PositionOutOfRange {
            controller: name,
            position: typed(*position_mm),
            limit: typed(position_limit_mm),
        });
    }
    let machine_limit = options.max_value_mm.map(|limit| ("machine profile", limit));
    for (what, limit_mm) in std::iter::once(value_limit).chain(machine_limit) {
        for direction in crate::measurement::Direction::BOTH {
            let column = table.values.for_direction(direction);
            if let Some((value, position)) = column
                .iter()
                .zip(&table.positions)
                .find(|(value, _)| value.abs() > limit_mm)
            {
                return Err(EmitError::ValueOutOfRange {
                    value: typed(*value),
                    position: typed(*position),
                    what,
                    limit: typed(limit_mm),
                });
            }
        }
    }
    Ok(())
}

/// What a rotary table must be for `controller` (module doc).
fn check_rotary(
    controller: Controller,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<(), EmitError> {
    if options.kind != AxisKind::Rotary {
        return Ok(());
    }
    match controller {
        Controller::Fagor8055 | Controller::Fagor8065 => {
            return Err(EmitError::RotaryNotSupported {
                controller: controller.name(),
            });
        }
        Controller::Sinumerik840d => {}
        Controller::Itnc530 | Controller::Tnc640 | Controller::LinuxCnc | Controller::Fanuc => {
            return Ok(());
        }
    }
    let (first, last) = (
        table.positions[0],
        table.positions[table.positions.len() - 1],
    );
    if !options.is_full_turn(table) {
        return Ok(());
    }
    if first.abs() > 1e-9 {
        return Err(EmitError::ModuloRange {
            first_deg: first,
            last_deg: last,
        });
    }
    let resolution = resolution_mm(controller, options.file_unit());
    for direction in crate::measurement::Direction::BOTH {
        let column = table.values.for_direction(direction);
        let (first_deg, last_deg) = (column[0], column[column.len() - 1]);
        if (first_deg - last_deg).abs() > resolution / 2.0 {
            return Err(EmitError::ModuloEndsDiffer {
                first_deg,
                last_deg,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::TableValues;

    /// A table of the two points 0 and 90 with the values 0 and 0.001, of
    /// an axis of `kind`.
    fn table(kind: AxisKind) -> CompensationTable {
        CompensationTable {
            axis: "C".into(),
            kind,
            positions: vec![0.0, 90.0],
            values: TableValues::Mean(vec![0.0, 0.001]),
            reference: 0.0,
            suggested_backlash: None,
        }
    }

    #[test]
    fn a_table_is_written_only_for_its_own_kind_of_axis() {
        let linear =
            EmitOptions::for_axis(&super::super::MachineProfile::default(), "C", "C").unwrap();
        let rotary = EmitOptions {
            kind: AxisKind::Rotary,
            ..linear.clone()
        };
        // 0 and 90° would be written as 0 and 90 mm, and 90 mm as 90°.
        for controller in [Controller::LinuxCnc, Controller::Tnc640] {
            let error =
                super::super::write(controller, &table(AxisKind::Rotary), &linear).unwrap_err();
            assert_eq!(
                error,
                EmitError::KindMismatch {
                    table: AxisKind::Rotary,
                    options: AxisKind::Linear
                }
            );
            assert_eq!(
                error.to_string(),
                "the table is of a rotary axis (in °) and the file is for a linear axis (in mm): they do not belong together"
            );
            assert!(matches!(
                super::super::write(controller, &table(AxisKind::Linear), &rotary),
                Err(EmitError::KindMismatch {
                    table: AxisKind::Linear,
                    options: AxisKind::Rotary
                })
            ));
            // Of one kind, both are written.
            assert!(super::super::write(controller, &table(AxisKind::Rotary), &rotary).is_ok());
            assert!(super::super::write(controller, &table(AxisKind::Linear), &linear).is_ok());
        }
    }

    #[test]
    fn a_rotary_table_is_refused_in_degrees() {
        let linear =
            EmitOptions::for_axis(&super::super::MachineProfile::default(), "C", "C").unwrap();
        let rotary = EmitOptions {
            kind: AxisKind::Rotary,
            ..linear
        };
        // The iTNC 530 (named itnc530) writes the step to 0.0001 (its resolution, ° on a
        // rotary axis): 0.00015° is no multiple of it.
        let mut fine = table(AxisKind::Rotary);
        fine.positions = vec![0.0, 0.00015, 0.0003];
        fine.values = TableValues::Mean(vec![0.0; 3]);
        assert_eq!(
            check_table(Controller::Itnc530, &fine, &rotary)
                .unwrap_err()
                .to_string(),
            "itnc530 writes the step to 0.0001°; a step of 0.00015° would shift the points along the table: give --step as a multiple of 0.0001°"
        );
        // 0.001° at its first point, 0°: the iTNC 530 needs 0 there.
        let mut shifted = table(AxisKind::Rotary);
        shifted.values = TableValues::Mean(vec![0.001, 0.0]);
        assert_eq!(
            check_table(Controller::Itnc530, &shifted, &rotary)
                .unwrap_err()
                .to_string(),
            "itnc530 needs the value 0 at the first point (the datum); the table is 0.001° there: use --reference at the first point"
        );
    }
}
