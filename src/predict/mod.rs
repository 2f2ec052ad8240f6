//! Prediction after compensation (`axcomp predict`): what a re-test of a
//! compensated axis will show along its laser line, and what the table leaves
//! in the work volume, from the volumetric model.
//!
//! **The errors.** The 21 errors come from an error description
//! ([`crate::model::read_error_description`]) and from measured files: a
//! linear test of axis A on line L reads A's positioning error EAA *plus*
//! what the other errors add along L (the Abbe terms of pitch and yaw, a
//! squareness, …). So EAA is set to the measured per-target means minus the
//! model's contribution of the other errors on L, as a not-a-knot spline
//! through the targets: the model then reproduces the measurement on L
//! exactly at the targets (first order in the errors; to 1e-9 mm with full
//! transforms), and predicts what changes on another line or with another
//! tool.
//!
//! **The laser's reading** on line L at axis position x is
//!
//! ```text
//! D(x) = E_A(x on L) + EAA(reference)
//! ```
//!
//! E_A the model's volumetric error along A (zero at the machine's reference
//! position, eq. 68), EAA(reference) added back so that D is the positioning
//! error as the laser reads it, not shifted to zero at the machine reference
//! (a constant: no ISO figure depends on it). EAA enters E_A with +1 in every
//! chain the model builds; [`positioning_sign`] checks it.
//!
//! **The table** holds v(x, d) in the same convention (actual − target). The
//! controller drives to m = x − v(x, d), linear between the table's points and
//! holding its end values, per direction for a bidirectional table; the axis
//! reaches m + its error there, so the re-test reads
//!
//! ```text
//! predicted(x, d) = D(x − v(x, d)) − v(x, d)
//! ```
//!
//! as in [`crate::compensate::retest`], with D from the model instead of the
//! first test's spline. On the measured line and without other errors the
//! two agree exactly.
//!
//! **The measured reversal.** The geometric model has no direction; the
//! first test of the axis has: D(x, d) adds the reversal's share the test
//! measured at x, e(x, d) − x̄(x) (a spline through x̄_i↑ − x̄_i and
//! x̄_i↓ − x̄_i). A mean table leaves it in the re-test, a bidirectional table
//! takes it out, and so does the controller's backlash parameter when it is
//! set as `convert` suggests ([`PredictInput::backlash_set`]; then only the
//! reversal's variation along the axis, B_i − B̄, is left).
//!
//! **Scatter.** A prediction is of the systematic part. When the axis was
//! measured, the predicted re-test keeps that test's readings' scatter about
//! their per-target means (each reading moved by the predicted change), so
//! its R is the first test's and A and E are comparable with a real re-test.
//! Without a measurement there is one run per direction and no R.
//!
//! **The work volume.** The residual volumetric error map applies each table
//! to its axis's positioning error, EAA_c(x) = EAA(x − v) − v, sampled at the
//! grid's positions and the table's points; the other errors of the axis are
//! taken at x rather than at x − v (they move by the table's few µm of
//! position: a change of slope × v, below a nanometre). A bidirectional table
//! gives a map per direction; the larger maximum is reported.
//!
//! Pure: values in, values out.

use crate::compensate::CompensationTable;
use crate::compensate::cross_axis::CrossAxisTable;
use crate::compensate::retest::{Applied, BacklashRefusal, KnownError};
use crate::effects::Effect;
use crate::evaluate::{Standard, StandardUsed, evaluate};
use crate::measurement::{Direction, Measurement};
use crate::model::{
    Axis, ErrorComponent, ErrorFunction, ErrorName, ErrorTable, GeometricErrors, Grid,
    Interpolation, Machine, Method, ModelError, Optics,
};

mod calibrate;
mod cross_axis;
mod retest;
pub mod survey;

use calibrate::calibrated_errors;
pub use calibrate::{calibrate_positioning, positioning_error, positioning_sign};
pub(crate) use cross_axis::cross_compensated;
pub use cross_axis::{cross_axis_table, cross_axis_table_at};
use retest::{Line, predicted_retest};
pub use retest::{PredictedRetest, PredictedTarget};

/// A measured file and the line it was measured on.
#[derive(Clone, Copy, Debug)]
pub struct MeasuredAxis<'a> {
    /// The test: its axis name must be X, Y or Z.
    pub measurement: &'a Measurement,
    /// Machine position of the line (the measured axis's own coordinate is ignored), mm.
    pub line_mm: [f64; 3],
    /// Where the laser's moving optic sits ([`Optics::AT_TOOL_TIP`]: at the
    /// tool tip): the Abbe arms of the axes under its body are their arms to
    /// the tool plus its offset (`Machine::with_optics`).
    pub optics: Optics,
}

/// What `predict` is given.
#[derive(Clone, Copy, Debug)]
pub struct PredictInput<'a> {
    /// The machine as it was measured.
    pub machine: &'a Machine,
    /// Errors from a description (all zero if none); a measured axis's
    /// positioning error must not be given here too.
    pub errors: &'a GeometricErrors,
    /// Measured files.
    pub measured: &'a [MeasuredAxis<'a>],
    /// Tables, each for its axis (at most one per axis).
    pub tables: &'a [CompensationTable],
    /// Cross-axis (straightness) tables, applied as the controller does:
    /// the column axis moved by −value at the table axis's position.
    pub cross_tables: &'a [CrossAxisTable],
    /// The re-test line: machine position, mm (each table's own axis coordinate is ignored).
    pub line_mm: [f64; 3],
    /// The tool of the re-test, if not the machine description's: last
    /// tool-side error frame → functional point, mm.
    pub retest_tool_offset_mm: Option<[f64; 3]>,
    /// Step of the volumetric error map, mm.
    pub grid_step_mm: f64,
    /// Effects found by `diagnose` that the geometric model lacks: their
    /// systematic part (reversal, scale, periodic) is added to every
    /// re-test's line, about its first target. A reversal here is the change
    /// since the first test, which the prediction already carries.
    pub effects: &'a [Effect],
    /// The controller's backlash parameter is set as `convert` suggests: it
    /// takes out the mean reversal B̄ of each measured axis with a mean table.
    pub backlash_set: bool,
    /// The standard whose figures the re-tests report
    /// ([`PredictedRetest::standard_figures`]); the prediction itself does
    /// not depend on it.
    pub standard: &'a dyn Standard,
}

/// The largest volumetric error over the grid and where, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumetricMaximum {
    /// max ‖E‖, mm.
    pub max_mm: f64,
    /// Machine position, mm.
    pub at_mm: [f64; 3],
}

/// The prediction.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The standard of the re-tests' `standard_figures`.
    pub standard: StandardUsed,
    /// The 21 errors the model used (with the measured positioning errors).
    pub errors: GeometricErrors,
    /// One predicted re-test per table.
    pub retests: Vec<PredictedRetest>,
    /// Volumetric error without the tables.
    pub volumetric_before: VolumetricMaximum,
    /// With the tables (the worse direction).
    pub volumetric_after: VolumetricMaximum,
    /// With the positioning tables only (no cross-axis tables; the same as
    /// `volumetric_after` when there are none).
    pub volumetric_positioning_only: VolumetricMaximum,
    /// At `volumetric_after`'s point, each error's share of the error there
    /// (its first-order contribution along ‖E‖'s direction over ‖E‖; they
    /// add up to 1), largest first: which error to compensate next.
    pub shares: Vec<ErrorShare>,
    /// Grid points of the map.
    pub grid_points: usize,
}

/// One error's part of the largest residual volumetric error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorShare {
    /// The error.
    pub name: ErrorName,
    /// Its contribution along the error's direction over ‖E‖ (negative: it
    /// takes some of the error away).
    pub share: f64,
    /// Its contribution's size there, mm.
    pub contribution_mm: f64,
}

/// Why a prediction cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PredictError {
    /// An axis name the model does not have.
    #[error("{what} is for axis {name:?}; the model has the linear axes X, Y and Z")]
    UnknownAxis {
        /// A measurement or a table.
        what: &'static str,
        /// Its axis name.
        name: String,
    },
    /// Two sources for one error.
    #[error("{0} is given twice (by the error description or another measured file): give it once")]
    GivenTwice(ErrorName),
    /// Two tables for one axis.
    #[error("two tables for axis {0}: give one table per axis")]
    TwoTables(Axis),
    /// A measured file without a single mean deviation.
    #[error("the measurement of axis {0} has no target with a mean deviation")]
    NoMeans(Axis),
    /// No table.
    #[error("no compensation table to predict with")]
    NoTable,
    /// The backlash parameter is said to be set, but its value is not known or it cannot apply.
    #[error("the backlash parameter of axis {axis} {why}")]
    Backlash {
        /// The axis.
        axis: Axis,
        /// Why it cannot be applied.
        why: BacklashRefusal,
    },
    /// The model refused a value.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A survey that cannot be assembled (a test it names, a pair it asks for).
    #[error("{what}: {why}")]
    Survey {
        /// The survey's test file or table.
        what: String,
        /// What is wrong.
        why: String,
    },
    /// A measured test reaching beyond the model's stroke of its axis: the
    /// model's errors (and its map) are not defined there.
    #[error(
        "the test of {axis} covers {from_mm} … {to_mm} mm, beyond the {axis} stroke {low_mm} … {high_mm} mm of the machine model ({machine}): a model that does not cover the test predicts nothing of it; give the machine's own description with --machine"
    )]
    BeyondStroke {
        /// The axis.
        axis: Axis,
        /// The test's first target, mm.
        from_mm: f64,
        /// Its last target, mm.
        to_mm: f64,
        /// The model's stroke, mm.
        low_mm: f64,
        /// mm.
        high_mm: f64,
        /// The model's name.
        machine: String,
    },
    /// A bug.
    #[error("internal error, please report: {0}")]
    Internal(String),
    /// A predicted re-test could not be built (a bug).
    #[error("internal error, please report: {0}")]
    Measurement(#[from] crate::measurement::MeasurementError),
}

/// Predicts the re-tests and the residual volumetric error.
pub fn predict(input: &PredictInput<'_>) -> Result<Prediction, PredictError> {
    if input.tables.is_empty() && input.cross_tables.is_empty() {
        return Err(PredictError::NoTable);
    }
    for measured in input.measured {
        within_stroke(input.machine, measured.measurement)?;
    }
    let errors = calibrated_errors(input)?;
    let retest_machine = match input.retest_tool_offset_mm {
        Some(offset) => input.machine.with_tool_offset(offset)?,
        None => input.machine.clone(),
    };
    let mut retests = Vec::new();
    let mut seen: Vec<Axis> = Vec::new();
    for table in input.tables {
        let axis = axis_named("a table", &table.axis)?;
        if seen.contains(&axis) {
            return Err(PredictError::TwoTables(axis));
        }
        seen.push(axis);
        let measured = input
            .measured
            .iter()
            .find(|m| axis_named("a measurement", m.measurement.axis()).ok() == Some(axis));
        retests.push(predicted_retest(
            &retest_machine,
            &errors,
            Line {
                axis,
                line_mm: input.line_mm,
            },
            table,
            measured.map(|m| m.measurement),
            input,
        )?);
    }
    let grid = Grid::over_strokes(&retest_machine, input.grid_step_mm)?;
    let zero = VolumetricMaximum {
        max_mm: 0.0,
        at_mm: [0.0; 3],
    };
    let (mut after, mut positioning_only) = (zero, zero);
    let mut after_errors = errors.clone();
    // Each table as the controller applies it, with the reversal the first
    // test of its axis measured: the map of each direction keeps what the
    // re-test of that direction keeps.
    let mut applying = Vec::new();
    for table in input.tables {
        let axis = axis_named("a table", &table.axis)?;
        let known = input
            .measured
            .iter()
            .find(|m| axis_named("a measurement", m.measurement.axis()).ok() == Some(axis))
            .and_then(|m| KnownError::from_evaluation(&evaluate(m.measurement)));
        applying.push((table, known));
    }
    let mut before_map = zero;
    let own: Vec<GeometricErrors> = Direction::BOTH
        .into_iter()
        .map(|direction| with_reversal(&errors, &applying, &grid, direction))
        .collect::<Result<_, _>>()?;
    let positioned: Vec<GeometricErrors> = Direction::BOTH
        .into_iter()
        .map(|direction| {
            compensated_errors(&errors, &applying, input.backlash_set, &grid, direction)
        })
        .collect::<Result<_, _>>()?;
    // The map is zero at the reference position; each direction's is taken
    // from the reference reached as the two directions do on average, so
    // what one direction keeps of the reversal stays in its map.
    let reference = retest_machine.reference_mm();
    let own_offsets = direction_offsets(&own, &applying, reference)?;
    let offsets = direction_offsets(&positioned, &applying, reference)?;
    for k in 0..2 {
        let largest = |errors: &GeometricErrors, offset: [f64; 3]| {
            let map = retest_machine.error_map(errors, &grid, Method::Full);
            largest_with_offset(&map, offset)
        };
        let found = largest(&own[k], own_offsets[k]);
        if found.max_mm >= before_map.max_mm {
            before_map = found;
        }
        let found = largest(&positioned[k], offsets[k]);
        if found.max_mm >= positioning_only.max_mm {
            positioning_only = found;
        }
        let compensated = cross_compensated(&positioned[k], input.cross_tables, &grid)?;
        let found = largest(&compensated, offsets[k]);
        if found.max_mm >= after.max_mm {
            after = found;
            after_errors = compensated;
        }
    }
    let shares = shares_at(&retest_machine, &after_errors, after.at_mm);
    Ok(Prediction {
        standard: StandardUsed::of(input.standard),
        errors,
        retests,
        volumetric_before: before_map,
        volumetric_after: after,
        volumetric_positioning_only: positioning_only,
        shares,
        grid_points: grid.len(),
    })
}

/// Per direction (↑, ↓), each table's axis' positioning error at the
/// reference position less the two directions' mean there, mm, as a
/// translation: what a map zeroed at the reference drops of a direction.
fn direction_offsets(
    directed: &[GeometricErrors],
    applying: &[Applying<'_>],
    reference_mm: [f64; 3],
) -> Result<[[f64; 3]; 2], PredictError> {
    let mut offsets = [[0.0; 3]; 2];
    for (table, _) in applying {
        let axis = axis_named("a table", &table.axis)?;
        let name = positioning_error(axis);
        let at = |errors: &GeometricErrors| {
            errors
                .function(name)
                .map_or(0.0, |f| f.value_at(reference_mm[axis.index()]))
        };
        let (up, down) = (at(&directed[0]), at(&directed[1]));
        let mean = 0.5 * (up + down);
        offsets[0][axis.index()] = up - mean;
        offsets[1][axis.index()] = down - mean;
    }
    Ok(offsets)
}

/// The largest ‖E + offset‖ over the map and where.
fn largest_with_offset(map: &crate::model::ErrorMap, offset_mm: [f64; 3]) -> VolumetricMaximum {
    let offset = nalgebra::Vector3::from(offset_mm);
    let mut best = VolumetricMaximum {
        max_mm: 0.0,
        at_mm: map.grid.position_mm(0),
    };
    for (index, error) in map.errors.iter().enumerate() {
        let norm = (error.translation_mm + offset).norm();
        if norm > best.max_mm {
            best = VolumetricMaximum {
                max_mm: norm,
                at_mm: map.grid.position_mm(index),
            };
        }
    }
    best
}

/// Refuses a test whose targets leave the model's stroke of its axis (by
/// more than a micrometre: a stroke written to the mm holds its targets).
fn within_stroke(machine: &Machine, measurement: &Measurement) -> Result<(), PredictError> {
    let axis = axis_named("a measurement", measurement.axis())?;
    let [low_mm, high_mm] = machine.axis(axis).stroke_mm;
    let targets = measurement.targets();
    let (from_mm, to_mm) = (targets[0], targets[targets.len() - 1]);
    let slack_mm = 1e-3;
    if from_mm < low_mm - slack_mm || to_mm > high_mm + slack_mm {
        return Err(PredictError::BeyondStroke {
            axis,
            from_mm,
            to_mm,
            low_mm,
            high_mm,
            machine: machine.name().to_string(),
        });
    }
    Ok(())
}

/// The machine axis a measurement or table is for.
pub fn axis_named(what: &'static str, name: &str) -> Result<Axis, PredictError> {
    let mut letters = name.trim().chars();
    match (letters.next(), letters.next()) {
        (Some(letter), None) => Axis::from_letter(letter.to_ascii_uppercase()),
        _ => None,
    }
    .ok_or_else(|| PredictError::UnknownAxis {
        what,
        name: name.to_string(),
    })
}

/// Each error's share of the volumetric error at `at_mm` (first order, so
/// the shares add up to 1), largest |share| first.
fn shares_at(machine: &Machine, errors: &GeometricErrors, at_mm: [f64; 3]) -> Vec<ErrorShare> {
    let total = machine
        .volumetric_error(errors, at_mm, Method::FirstOrder)
        .translation_mm;
    let norm = total.norm();
    if norm == 0.0 {
        return Vec::new();
    }
    let mut shares: Vec<ErrorShare> = ErrorName::ALL
        .iter()
        .map(|&name| {
            let mut single = GeometricErrors::default();
            match (name.component(), errors.function(name)) {
                (ErrorComponent::Squareness(pair), _) => {
                    single.squareness.set(pair, errors.squareness.get(pair));
                }
                (_, Some(function)) => {
                    // A motion error's function is always settable.
                    let _ = single.set(name, function.clone());
                }
                _ => {}
            }
            let part = machine
                .volumetric_error(&single, at_mm, Method::FirstOrder)
                .translation_mm;
            ErrorShare {
                name,
                share: part.dot(&total) / (norm * norm),
                contribution_mm: part.norm(),
            }
        })
        .filter(|s| s.contribution_mm > 0.0)
        .collect();
    shares.sort_by(|a, b| b.share.abs().total_cmp(&a.share.abs()));
    shares
}

/// The grid's and a table's positions in order, once each (within 1 nm): the
/// points where a compensated error is exact.
fn merged_positions(grid_mm: &[f64], table_mm: &[f64]) -> Vec<f64> {
    let mut positions: Vec<f64> = grid_mm.iter().chain(table_mm).copied().collect();
    positions.sort_by(f64::total_cmp);
    positions.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    positions
}

/// A table and the first test of its axis, as its reversal is known.
type Applying<'a> = (&'a CompensationTable, Option<KnownError>);

/// The errors with each table's axis's positioning error in one direction:
/// EAA(x) + r(x, d), r the reversal's share the first test of the axis
/// measured (the geometric model has no direction; the test has), linear
/// through the grid's positions and the test's targets.
fn with_reversal(
    errors: &GeometricErrors,
    applying: &[Applying<'_>],
    grid: &Grid,
    direction: Direction,
) -> Result<GeometricErrors, PredictError> {
    let mut directed = errors.clone();
    for (table, known) in applying {
        let Some(known) = known else { continue };
        let axis = axis_named("a table", &table.axis)?;
        let name = positioning_error(axis);
        let own = errors.function(name).cloned().unwrap_or_default();
        let positions = merged_positions(grid.axis_mm(axis), known.positions());
        let values = positions
            .iter()
            .map(|&x| own.value_at(x) + known.reversal_share_at(x, direction))
            .collect();
        let function = ErrorTable::new(positions, values, Interpolation::Linear)?;
        directed.set(name, ErrorFunction::Table(function))?;
    }
    Ok(directed)
}

/// The errors with each table applied to its axis's positioning error, for
/// one direction: EAA_c(x) = EAA(x − v) + r(x − v, d) − v, v the table's
/// value (and the backlash parameter's share, when set) and r the reversal's
/// share the first test of the axis measured; linear through the grid's
/// positions and the table's points (exact at both).
fn compensated_errors(
    errors: &GeometricErrors,
    applying: &[Applying<'_>],
    backlash_set: bool,
    grid: &Grid,
    direction: Direction,
) -> Result<GeometricErrors, PredictError> {
    let mut compensated = errors.clone();
    for (table, known) in applying {
        let axis = axis_named("a table", &table.axis)?;
        let applied = Applied::with_backlash(Some(table), known.as_ref(), backlash_set)
            .map_err(|why| PredictError::Backlash { axis, why })?;
        let name = positioning_error(axis);
        let own = errors.function(name).cloned().unwrap_or_default();
        let positions = merged_positions(grid.axis_mm(axis), &table.positions);
        let values = positions
            .iter()
            .map(|&x| {
                let v = applied.value_at(x, direction);
                let reversal = known
                    .as_ref()
                    .map_or(0.0, |k| k.reversal_share_at(x - v, direction));
                own.value_at(x - v) + reversal - v
            })
            .collect();
        let function = ErrorTable::new(positions, values, Interpolation::Linear)?;
        compensated.set(name, ErrorFunction::Table(function))?;
    }
    Ok(compensated)
}

#[cfg(test)]
mod tests;
