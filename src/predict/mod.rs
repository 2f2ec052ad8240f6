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

use crate::compensate::cross_axis::CrossAxisTable;
use crate::compensate::retest::{Applied, BacklashRefusal, KnownError};
use crate::compensate::{CompensationTable, TableMode};
use crate::effects::Effect;
use crate::evaluate::{
    AxisFigures, Standard, StandardFigure, StandardUsed, evaluate, evaluate_with,
};
use crate::measurement::{Direction, Measurement, Run};
use crate::model::{
    Axis, ErrorComponent, ErrorFunction, ErrorName, ErrorTable, GeometricErrors, Grid,
    Interpolation, Machine, Method, ModelError, Optics,
};
use crate::units::um_to_mm;

pub mod survey;

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

/// The predicted re-test of one compensated axis.
#[derive(Clone, Debug, PartialEq)]
pub struct PredictedRetest {
    /// The axis.
    pub axis: Axis,
    /// The line, mm.
    pub line_mm: [f64; 3],
    /// Per target: the deviation without and with the table.
    pub per_target: Vec<PredictedTarget>,
    /// The predicted re-test as readings (with the measured scatter when the
    /// axis was measured).
    pub retest: Measurement,
    /// Its ISO 230-2:2014 figures.
    pub figures: AxisFigures,
    /// The ISO 230-2:2014 figures of the same line without the table.
    pub figures_before: AxisFigures,
    /// Its figures as [`PredictInput::standard`] reports them (its keys):
    /// `evaluate_with` of [`PredictedRetest::retest`].
    pub standard_figures: Vec<StandardFigure>,
    /// The same line without the table, as that standard reports it.
    pub standard_figures_before: Vec<StandardFigure>,
    /// Whether the readings carry a measured test's scatter (else one run per
    /// direction, no repeatability).
    pub with_measured_scatter: bool,
    /// The mean reversal B̄ the first test of the axis measured, which the
    /// prediction carries, mm; `None` without a bidirectional first test.
    pub measured_mean_reversal_mm: Option<f64>,
    /// The mean reversal the controller's backlash parameter takes out, mm (0 if not set).
    pub backlash_reversal_mm: f64,
    /// Whether the table is mean or bidirectional.
    pub table_mode: TableMode,
}

/// One target of a predicted re-test, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PredictedTarget {
    /// Target, mm.
    pub target_mm: f64,
    /// Deviation on the line without the table moving ↑, mm.
    pub before_up_mm: f64,
    /// The same moving ↓ (differs from ↑ only by effects), mm.
    pub before_down_mm: f64,
    /// Predicted deviation with the table moving ↑, mm.
    pub up_mm: f64,
    /// Predicted deviation with the table moving ↓, mm.
    pub down_mm: f64,
}

impl PredictedTarget {
    /// With the table, in a direction, mm.
    pub fn after(&self, direction: Direction) -> f64 {
        match direction {
            Direction::Up => self.up_mm,
            Direction::Down => self.down_mm,
        }
    }

    /// Without the table, in a direction, mm.
    pub fn before(&self, direction: Direction) -> f64 {
        match direction {
            Direction::Up => self.before_up_mm,
            Direction::Down => self.before_down_mm,
        }
    }
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
    let targets = measurement.targets_mm();
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
fn line_deviation(
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
fn calibrated_errors(input: &PredictInput<'_>) -> Result<GeometricErrors, PredictError> {
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
            .positions_mm()
            .iter()
            .zip(known.mean_values_mm())
            .map(|(&x, mean)| {
                mean - line_deviation(&machine, &errors, axis, sign, measured.line_mm, x)
            })
            .collect();
        let table = ErrorTable::new(known.positions_mm().to_vec(), values, Interpolation::Spline)?;
        errors.set(name, ErrorFunction::Table(table))?;
    }
    Ok(errors)
}

/// An axis and the line its re-test runs on.
#[derive(Clone, Copy, Debug)]
struct Line {
    axis: Axis,
    line_mm: [f64; 3],
}

/// The re-test of one compensated axis on the line.
fn predicted_retest(
    machine: &Machine,
    errors: &GeometricErrors,
    line: Line,
    table: &CompensationTable,
    measured: Option<&Measurement>,
    input: &PredictInput<'_>,
) -> Result<PredictedRetest, PredictError> {
    let Line { axis, line_mm } = line;
    let (effects, backlash_set, standard) = (input.effects, input.backlash_set, input.standard);
    let sign = positioning_sign(machine, axis)?;
    let targets: Vec<f64> = match measured {
        Some(m) => m.targets_mm().to_vec(),
        None => table.positions_mm.clone(),
    };
    // The first test's own error, per direction: the reversal it measured.
    let known = measured.and_then(|m| KnownError::from_evaluation(&evaluate(m)));
    let measured_mean_reversal_mm = known
        .as_ref()
        .filter(|k| k.is_bidirectional())
        .map(KnownError::mean_reversal_mm);
    let applied = Applied::with_backlash(Some(table), known.as_ref(), backlash_set)
        .map_err(|why| PredictError::Backlash { axis, why })?;
    let first_target = targets.first().copied().unwrap_or(0.0);
    // D(x, d): the model's reading, the measured reversal and the effects it lacks, mm.
    let deviation = |x: f64, direction: Direction| {
        let effects_um: f64 = effects
            .iter()
            .filter_map(|e| e.systematic_um(x, direction, first_target))
            .sum();
        let reversal = known
            .as_ref()
            .map_or(0.0, |k| k.reversal_share_at(x, direction));
        line_deviation(machine, errors, axis, sign, line_mm, x) + reversal + um_to_mm(effects_um)
    };
    let compensated = |x: f64, direction: Direction| {
        let v = applied.value_at(x, direction);
        deviation(x - v, direction) - v
    };
    let per_target: Vec<PredictedTarget> = targets
        .iter()
        .map(|&x| PredictedTarget {
            target_mm: x,
            before_up_mm: deviation(x, Direction::Up),
            before_down_mm: deviation(x, Direction::Down),
            up_mm: compensated(x, Direction::Up),
            down_mm: compensated(x, Direction::Down),
        })
        .collect();
    let (retest, before) = match measured {
        Some(m) => (
            with_scatter(m, |i, d| per_target[i].after(d))?,
            with_scatter(m, |i, d| per_target[i].before(d))?,
        ),
        None => (
            one_run_each_way(axis, &per_target, PredictedTarget::after)?,
            one_run_each_way(axis, &per_target, PredictedTarget::before)?,
        ),
    };
    Ok(PredictedRetest {
        axis,
        line_mm,
        figures: evaluate(&retest).figures,
        figures_before: evaluate(&before).figures,
        standard_figures: evaluate_with(&retest, standard).standard_figures,
        standard_figures_before: evaluate_with(&before, standard).standard_figures,
        per_target,
        retest,
        with_measured_scatter: measured.is_some(),
        measured_mean_reversal_mm,
        backlash_reversal_mm: applied.backlash_reversal_mm,
        table_mode: table.values.mode(),
    })
}

/// The measured readings with their per-target, per-direction mean replaced
/// by `systematic(target index, direction)`: the scatter is kept.
fn with_scatter(
    measured: &Measurement,
    systematic: impl Fn(usize, Direction) -> f64,
) -> Result<Measurement, PredictError> {
    Ok(crate::compensate::retest::with_scatter(
        measured,
        &evaluate(measured),
        systematic,
    )?)
}

/// A re-test of one run each way holding the predicted values.
fn one_run_each_way(
    axis: Axis,
    per_target: &[PredictedTarget],
    value: fn(&PredictedTarget, Direction) -> f64,
) -> Result<Measurement, PredictError> {
    let runs = Direction::BOTH
        .into_iter()
        .map(|direction| Run {
            direction,
            number: 1,
            start_time_s: None,
            deviations_mm: per_target
                .iter()
                .map(|t| Some(value(t, direction)))
                .collect(),
        })
        .collect();
    let metadata = crate::measurement::Metadata {
        axis_source: crate::measurement::AxisSource::Given,
        ..Default::default()
    };
    Measurement::new(
        axis.letter().to_string(),
        per_target.iter().map(|t| t.target_mm).collect(),
        runs,
        Default::default(),
        metadata,
    )
    .map_err(PredictError::from)
}

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
        let positions = merged_positions(grid.axis_mm(axis), &cross.table.positions_mm);
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
        let positions = merged_positions(grid.axis_mm(axis), known.positions_mm());
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
        let positions = merged_positions(grid.axis_mm(axis), &table.positions_mm);
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
