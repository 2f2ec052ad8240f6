//! Cross-axis (straightness) tables: applied to the errors they compensate,
//! and made from the errors for a controller.

use super::{PredictError, axis_named, merged_positions};
use crate::compensate::cross_axis::CrossAxisTable;
use crate::model::{
    ErrorComponent, ErrorFunction, ErrorName, ErrorTable, GeometricErrors, Grid, Interpolation,
    Machine,
};

/// The errors with each cross-axis table applied to the straightness it
/// compensates: E<column><table axis>_c(x) = E(x) − v(x), linear through
/// the grid's positions and the table's points (the column axis's own
/// errors move by v, a few µm: below a nanometre, as for positioning).
pub(crate) fn cross_compensated(
    errors: &GeometricErrors,
    tables: &[CrossAxisTable],
    grid: &Grid,
) -> Result<GeometricErrors, PredictError> {
    let mut compensated = errors.clone();
    for cross in tables {
        let axis = axis_named("a cross-axis table", &cross.table_axis)?;
        let direction = axis_named("a cross-axis table's column", &cross.table.axis)?;
        if axis == direction {
            return Err(PredictError::Survey {
                what: format!("the cross-axis table {direction} = F({axis})"),
                why: "moves its own axis: that is a positioning table (--table)".to_string(),
            });
        }
        let name = ErrorName::of(ErrorComponent::Translation { axis, direction });
        let own = compensated.function(name).cloned().unwrap_or_default();
        let positions = merged_positions(grid.axis_mm(axis), &cross.table.positions);
        let values = positions
            .iter()
            .map(|&x| own.value_at(x) - cross.value_at(x))
            .collect();
        compensated.set(
            name,
            ErrorFunction::Table(ErrorTable::new(positions, values, Interpolation::Linear)?),
        )?;
    }
    Ok(compensated)
}

/// A cross-axis table of the straightness `name` (EYX: X's in Y) as the
/// errors hold it, at `points` evenly spaced positions over its axis's
/// stroke, zero at the machine's reference position.
pub fn cross_axis_table(
    machine: &Machine,
    errors: &GeometricErrors,
    name: ErrorName,
    points: usize,
) -> Result<CrossAxisTable, PredictError> {
    let ErrorComponent::Translation { axis, .. } = name.component() else {
        return Err(PredictError::Internal(format!("{name} is no straightness")));
    };
    if points < 2 {
        return Err(PredictError::Internal(format!(
            "{name} with {points} points is no straightness table"
        )));
    }
    let [low, high] = machine.axis(axis).stroke_mm;
    let positions: Vec<f64> = (0..points)
        .map(|i| low + (high - low) * i as f64 / (points - 1) as f64)
        .collect();
    cross_axis_table_at(
        errors,
        name,
        positions,
        machine.reference_mm()[axis.index()],
    )
}

/// A cross-axis table of the straightness `name` as the errors hold it, at
/// `positions_mm` of its axis, zero at `reference_mm` (`convert` writes it
/// on the grid the engineer chose).
pub fn cross_axis_table_at(
    errors: &GeometricErrors,
    name: ErrorName,
    positions_mm: Vec<f64>,
    reference_mm: f64,
) -> Result<CrossAxisTable, PredictError> {
    let ErrorComponent::Translation { axis, direction } = name.component() else {
        return Err(PredictError::Internal(format!("{name} is no straightness")));
    };
    if axis == direction || positions_mm.len() < 2 {
        return Err(PredictError::Internal(format!(
            "{name} with {} points is no straightness table",
            positions_mm.len()
        )));
    }
    let function = errors.function(name).cloned().unwrap_or_default();
    let values = positions_mm.iter().map(|&x| function.value_at(x)).collect();
    Ok(CrossAxisTable::new(
        &axis.to_string(),
        &direction.to_string(),
        positions_mm,
        values,
        reference_mm,
    ))
}
