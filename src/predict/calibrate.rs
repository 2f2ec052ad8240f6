//! The 21 errors calibrated to the measured files: each measured axis's
//! positioning error set so that the model reproduces the measured means on
//! the measured line (the module doc's "The errors" and "The laser's reading").

use super::{MeasuredAxis, PredictError, PredictInput, axis_named};
use crate::compensate::retest::KnownError;
use crate::evaluate::evaluate;
use crate::model::{
    Axis, ErrorFunction, ErrorName, ErrorTable, GeometricErrors, Interpolation, Machine, Method,
};

/// The positioning error of an axis: EXX, EYY or EZZ.
pub fn positioning_error(axis: Axis) -> ErrorName {
    match axis {
        Axis::X => ErrorName::EXX,
        Axis::Y => ErrorName::EYY,
        Axis::Z => ErrorName::EZZ,
    }
}

/// The sign with which an axis's positioning error enters the volumetric
/// error along that axis: +1 in every chain the model builds (the error is
/// defined as actual − nominal along the axis); anything else is a bug.
pub fn positioning_sign(machine: &Machine, axis: Axis) -> Result<f64, PredictError> {
    let [low, high] = machine.axis(axis).stroke_mm;
    let mut errors = GeometricErrors::default();
    let slope = ErrorTable::new(vec![low, high], vec![0.0, 1e-3], Interpolation::Linear)?;
    errors.set(positioning_error(axis), ErrorFunction::Table(slope))?;
    let at = |x: f64| {
        let mut p = machine.reference_mm();
        p[axis.index()] = x;
        machine
            .volumetric_error(&errors, p, Method::Full)
            .translation_mm[axis.index()]
    };
    let gain = (at(high) - at(low)) / 1e-3;
    if (gain.abs() - 1.0).abs() > 1e-6 {
        return Err(PredictError::Internal(format!(
            "{} enters E_{axis} with a gain of {gain}, not ±1",
            positioning_error(axis)
        )));
    }
    Ok(gain.signum())
}

/// D(x): the laser's reading on `line_mm` with `axis` at `x_mm`, mm.
pub(super) fn line_deviation(
    machine: &Machine,
    errors: &GeometricErrors,
    axis: Axis,
    sign: f64,
    line_mm: [f64; 3],
    x_mm: f64,
) -> f64 {
    let mut p = line_mm;
    p[axis.index()] = x_mm;
    let reference = machine.reference_mm()[axis.index()];
    let own_at_reference = errors
        .function(positioning_error(axis))
        .map_or(0.0, |f| f.value_at(reference));
    sign * machine
        .volumetric_error(errors, p, Method::Full)
        .translation_mm[axis.index()]
        + own_at_reference
}

/// The errors with each measured axis's positioning error set so that the
/// model reproduces the measured means on the measured line.
pub(super) fn calibrated_errors(input: &PredictInput<'_>) -> Result<GeometricErrors, PredictError> {
    calibrate_positioning(input.machine, input.errors, input.measured)
}

/// The 21 errors with each measured axis's positioning error set so that the
/// model reproduces the measured means on the measured line (module doc):
/// what `predict` predicts with, and what `predict --survey` assembles.
pub fn calibrate_positioning(
    machine: &Machine,
    errors: &GeometricErrors,
    measured: &[MeasuredAxis<'_>],
) -> Result<GeometricErrors, PredictError> {
    let mut errors = errors.clone();
    let mut given: Vec<ErrorName> = ErrorName::ALL
        .into_iter()
        .filter(|name| {
            errors
                .function(*name)
                .is_some_and(|f| *f != ErrorFunction::Constant(0.0))
        })
        .collect();
    for measured in measured {
        let axis = axis_named("a measurement", measured.measurement.axis())?;
        let name = positioning_error(axis);
        if given.contains(&name) {
            return Err(PredictError::GivenTwice(name));
        }
        given.push(name);
        let known = KnownError::from_evaluation(&evaluate(measured.measurement))
            .ok_or(PredictError::NoMeans(axis))?;
        let machine = machine.with_optics(&measured.optics)?;
        let sign = positioning_sign(&machine, axis)?;
        // The others' contribution on the measured line, with EAA still zero.
        let values: Vec<f64> = known
            .positions()
            .iter()
            .zip(known.mean_values())
            .map(|(&x, mean)| {
                mean - line_deviation(&machine, &errors, axis, sign, measured.line_mm, x)
            })
            .collect();
        let table = ErrorTable::new(known.positions().to_vec(), values, Interpolation::Spline)?;
        errors.set(name, ErrorFunction::Table(table))?;
    }
    Ok(errors)
}
