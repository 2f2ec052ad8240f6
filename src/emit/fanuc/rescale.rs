//! The alternative to a magnification (3623) too coarse for the error: the
//! axis' whole table in a finer unit, with the parameter change to make.

use std::collections::BTreeMap;

use super::{
    AxisParameters, POINT_RANGE, absolute_units, data_line, finest_for_sections, increments,
    magnification_for, parameters_for, parse_pitch, replace_lines, update, write,
};
use crate::compensate::CompensationTable;
use crate::emit::{EmitError, EmitOptions};
use crate::measurement::Direction;

/// The pitch file with the axis in a finer magnification, and what to do.
#[derive(Clone, Debug, PartialEq)]
pub struct Rescaled {
    /// The file to load instead of the one at the old magnification.
    pub text: String,
    /// The new magnification (3623).
    pub magnification: i64,
    /// What to set with it, in the control's words.
    pub instruction: String,
}

/// The finest magnification whose points hold both the table's sections
/// and the old increments of `existing`, rescaled ([`POINT_RANGE`]).
fn finest(table: &CompensationTable, p: &AxisParameters, old: &[i64]) -> i64 {
    let columns = [Direction::Up, Direction::Down].map(|d| table.values.for_direction(d));
    let new = finest_for_sections(&columns, p.detection_unit);
    let kept = old
        .iter()
        .map(|v| magnification_for(*v as f64 * p.magnification as f64))
        .fold(1, i64::max);
    new.max(kept)
}

/// `existing` (or a new file) with every point of the axis at magnification
/// `magnification` (the finest that holds the table when `None`): the old
/// points' absolute compensation rescaled (exact when the old magnification
/// is a multiple of the new one, else rounded at each point), the table's
/// points new, every other line as it was.
pub fn rescaled(
    existing: Option<&str>,
    table: &CompensationTable,
    options: &EmitOptions,
    magnification: Option<i64>,
) -> Result<Rescaled, EmitError> {
    let p = parameters_for(table, options)?;
    let old = match existing {
        Some(text) => old_increments(text, &p)?,
        None => BTreeMap::new(),
    };
    let flat: Vec<i64> = old.values().flat_map(|m| m.values().copied()).collect();
    let m = magnification.unwrap_or_else(|| finest(table, &p, &flat));
    if m < 1 || m == p.magnification {
        return Err(EmitError::Profile(format!(
            "3623 of axis {} is {}: no finer magnification holds the table ({} … {} units a point)",
            p.axis,
            p.magnification,
            POINT_RANGE.start(),
            POINT_RANGE.end()
        )));
    }
    let fine = AxisParameters {
        magnification: m,
        ..p.clone()
    };
    let mut fine_options = options.clone();
    fine_options.axes[0].fanuc = Some(fine.clone());
    let text = match existing {
        Some(text) => {
            let moved = rescale_lines(text, &p, &fine, &old)?;
            update(&moved, table, &fine_options)?
        }
        None => write(table, &fine_options)?,
    };
    let instruction = format!(
        "set 3623 of axis {} to {m} (it is {}: units of {} instead of {}) together with loading this file, in place of the one at 3623 = {}; then turn the power off and on and return the axis to the reference position",
        p.axis,
        p.magnification,
        p.unit_text(fine.unit()),
        p.unit_text(p.unit()),
        p.magnification
    );
    Ok(Rescaled {
        text,
        magnification: m,
        instruction,
    })
}

/// The increments of the axis in `text`, by direction and point.
fn old_increments(
    text: &str,
    p: &AxisParameters,
) -> Result<BTreeMap<Direction, BTreeMap<i64, i64>>, EmitError> {
    let (data, end) = parse_pitch(text).map_err(|e| EmitError::Profile(e.to_string()))?;
    p.directions()
        .iter()
        .map(|d| {
            increments(&data, &end, p, *d)
                .map(|i| (*d, i))
                .map_err(|e| EmitError::Profile(e.to_string()))
        })
        .collect()
}

/// `text` with the axis' points at the magnification of `fine`: each
/// point's absolute compensation × old / new, rounded, differenced.
fn rescale_lines(
    text: &str,
    p: &AxisParameters,
    fine: &AxisParameters,
    old: &BTreeMap<Direction, BTreeMap<i64, i64>>,
) -> Result<String, EmitError> {
    let (data, _) = parse_pitch(text).map_err(|e| EmitError::Profile(e.to_string()))?;
    let ratio = p.magnification as f64 / fine.magnification as f64;
    let mut changed = BTreeMap::new();
    for (direction, increments) in old {
        let absolute: BTreeMap<i64, i64> =
            absolute_units(p, increments, p.at_reference(*direction))
                .into_iter()
                .map(|(n, units)| (n, (units as f64 * ratio).round() as i64))
                .collect();
        for point in p.most_negative..=p.most_positive {
            let value = absolute[&point] - absolute[&(point - 1)];
            let at = p.data_point(*direction, point);
            if !POINT_RANGE.contains(&value) {
                return Err(EmitError::Profile(format!(
                    "point {at} of axis {} holds {} units at 3623 = {}: beyond {} … {}",
                    p.axis,
                    value,
                    fine.magnification,
                    POINT_RANGE.start(),
                    POINT_RANGE.end()
                )));
            }
            changed.insert(data[&at].line.number, data_line(at, value));
        }
    }
    Ok(replace_lines(text, &changed))
}
