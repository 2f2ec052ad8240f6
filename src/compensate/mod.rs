//! Compensation tables from an evaluated measurement.
//!
//! A [`CompensationTable`] is what every controller format is written from
//! and read into: compensation points (mm, strictly increasing) and, per
//! point, the axis error to compensate, in mm, in axcomp's one sign
//! convention: **the positional deviation actual − target** (ISO 230-2's
//! x̄), shifted so the value at the reference point is zero. Each emitter in
//! `emit/` converts that to its controller's own convention (an error for
//! Heidenhain and Siemens LEC, a correction for Siemens CEC, actual positions
//! or trims for LinuxCNC) and back.
//!
//! Building a table ([`build_table`]):
//! 1. the source curve per direction is the per-target mean deviation
//!    (`mean` mode: the bidirectional mean x̄_i; `bidirectional` mode: x̄_i↑
//!    and x̄_i↓), a unidirectional test giving its one direction;
//! 2. it is linearly interpolated onto the compensation points (the measured
//!    targets, or a regular grid `start + k·step`); a point outside the
//!    measured range is refused unless extrapolation is asked for (hold the
//!    end value, or write zero);
//! 3. the table is shifted so its value at the reference point is zero
//!    (controllers reference there; default the first point, as Kadlečík's (2019)
//!    tool does);
//! 4. in `mean` mode the suggested backlash parameter is −B̄ = mean(x̄↓ − x̄↑).
//!
//! A rotary axis' table is built the same way in degrees. On a full turn
//! (targets from θ to θ + 360°) the two ends are one physical position
//! (`../shared/spec/standards.md` §6): the source curve takes the mean of
//! their two x̄ at both ends, so the table's end values are equal, as a
//! modulo table needs (`evaluate` warns when the two disagree beyond the
//! repeatability).
//!
//! A measurement taken with a table already active measures the residual;
//! [`add_existing_table`] turns it back into the uncompensated deviations
//! (residual + the active table, applied as the controller applies it) before
//! a new table is built.
//!
//! Pure: no I/O. Lengths in mm.

pub mod cross_axis;
pub mod effects;
pub mod plan;
pub mod retest;
pub mod update;

use crate::evaluate::Evaluation;
use crate::evaluate::conformance::FULL_TURN_DEG;
use crate::measurement::{AxisKind, Direction, Measurement, MeasurementError, Position};

/// How many standard errors B̄ must be from zero to count as a measured
/// reversal: at 3σ a reversal-free axis passes for one in 0.3 % of tests.
const REVERSAL_STANDARD_ERRORS: f64 = 3.0;

/// The mean reversal value B̄ of a test (mm, or °) when it shows one beyond
/// its noise, so that a bidirectional table (or the backlash parameter) is
/// worth having: |B̄| > 3 standard errors. The standard error is that of the
/// mean of the per-target x̄_i↑ − x̄_i↓, σ·√(Σ (1/n↑ + 1/n↓)) / m with σ pooled
/// over every target and direction. `None` for a unidirectional test, one
/// without repeated runs (no σ) or a reversal within the noise.
pub fn measured_reversal(evaluation: &Evaluation) -> Option<f64> {
    let b_mean = evaluation.figures.b_mean?;
    let variance = evaluation.pooled_variance()?;
    let (mut sum_of_inverses, mut targets) = (0.0, 0usize);
    for t in evaluation
        .per_target
        .iter()
        .filter(|t| t.up.n > 0 && t.down.n > 0)
    {
        sum_of_inverses += 1.0 / t.up.n as f64 + 1.0 / t.down.n as f64;
        targets += 1;
    }
    let standard_error = (variance * sum_of_inverses).sqrt() / targets as f64;
    (b_mean.abs() > REVERSAL_STANDARD_ERRORS * standard_error).then_some(b_mean)
}

/// Whether the table has one column or one per direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableMode {
    /// One table from the bidirectional mean x̄_i (plus a suggested backlash).
    Mean,
    /// Separate ↑ and ↓ tables from x̄_i↑ and x̄_i↓.
    Bidirectional,
}

impl TableMode {
    /// The mode named `mean` or `bidirectional` (`--mode`), or why not.
    pub fn from_name(name: &str) -> Result<TableMode, String> {
        match name {
            "mean" => Ok(TableMode::Mean),
            "bidirectional" => Ok(TableMode::Bidirectional),
            _ => Err(format!("expected mean or bidirectional, found {name:?}")),
        }
    }

    /// `mean` or `bidirectional`.
    pub fn as_str(self) -> &'static str {
        match self {
            TableMode::Mean => "mean",
            TableMode::Bidirectional => "bidirectional",
        }
    }
}

/// What to do with a compensation point outside the measured range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extrapolate {
    /// Refuse the table.
    Refuse,
    /// Hold the value of the nearest measured end.
    Hold,
    /// Write zero (no compensation there).
    Zero,
}

impl Extrapolate {
    /// The rule named `hold` or `zero` (`--extrapolate`; refusing is the
    /// default, not named), or why not.
    pub fn from_name(name: &str) -> Result<Extrapolate, String> {
        match name {
            "hold" => Ok(Extrapolate::Hold),
            "zero" => Ok(Extrapolate::Zero),
            _ => Err(format!("expected hold or zero, found {name:?}")),
        }
    }
}

/// Where the compensation points go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridSpec {
    /// At the measured targets.
    Targets,
    /// At `start + k·step`, k = 0 … count − 1, in the axis' unit (mm, or °
    /// on a rotary axis: [`build_table`] refuses a grid of the other kind).
    Regular {
        /// First point.
        start: Position,
        /// Spacing (> 0).
        step: Position,
        /// Number of points (≥ 2).
        count: usize,
    },
}

/// How to build a table. No `Default`: the caller states every choice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableOptions {
    /// One table or one per direction.
    pub mode: TableMode,
    /// Where the points go.
    pub grid: GridSpec,
    /// Position where the table is zero; `None` for the first point.
    pub reference: Option<Position>,
    /// Points outside the measured range.
    pub extrapolate: Extrapolate,
}

impl TableOptions {
    /// Refuses options whose positions (the grid's start and step, the
    /// reference) are of an axis of another kind than `kind`.
    fn check_kind(&self, kind: AxisKind) -> Result<(), CompensateError> {
        if let GridSpec::Regular { start, step, .. } = self.grid {
            check_kind("grid's start", start, kind)?;
            check_kind("grid's step", step, kind)?;
        }
        if let Some(reference) = self.reference {
            check_kind("reference", reference, kind)?;
        }
        Ok(())
    }
}

/// `position`'s bare number when it is of an axis of `kind`, else the
/// refusal naming `what` it is.
pub(crate) fn check_kind(
    what: &'static str,
    position: Position,
    kind: AxisKind,
) -> Result<f64, CompensateError> {
    if position.kind() != kind {
        return Err(CompensateError::KindMismatch {
            what,
            given: position.kind(),
            measured: kind,
        });
    }
    Ok(position.in_axis_unit())
}

/// The values of a table: one column, or one per direction. Axis error
/// (actual − target) in the axis' unit (mm, or °), zero at the reference.
#[derive(Clone, Debug, PartialEq)]
pub enum TableValues {
    /// One value per point, for both directions.
    Mean(Vec<f64>),
    /// ↑ and ↓ values per point.
    Bidirectional {
        /// Moving in the positive direction.
        up: Vec<f64>,
        /// Moving in the negative direction.
        down: Vec<f64>,
    },
}

impl TableValues {
    /// The values for one direction.
    pub fn for_direction(&self, direction: Direction) -> &[f64] {
        match (self, direction) {
            (TableValues::Mean(values), _) => values,
            (TableValues::Bidirectional { up, .. }, Direction::Up) => up,
            (TableValues::Bidirectional { down, .. }, Direction::Down) => down,
        }
    }

    /// `mean` or `bidirectional`.
    pub fn mode(&self) -> TableMode {
        match self {
            TableValues::Mean(_) => TableMode::Mean,
            TableValues::Bidirectional { .. } => TableMode::Bidirectional,
        }
    }

    fn map(&self, f: impl Fn(&[f64]) -> Vec<f64>) -> TableValues {
        match self {
            TableValues::Mean(values) => TableValues::Mean(f(values)),
            TableValues::Bidirectional { up, down } => TableValues::Bidirectional {
                up: f(up),
                down: f(down),
            },
        }
    }
}

/// A compensation table in axcomp's convention (see the module doc).
///
/// Its numbers are bare `f64`s in the unit of its axis' [`AxisKind`]: mm on a
/// linear axis, degrees on a rotary one. They leave the table typed through
/// [`CompensationTable::positions_typed`] and its siblings ([`Position`]:
/// `Mm` or `Deg`), so a degree cannot be taken for a millimetre:
/// ```compile_fail
/// # use axcomp::compensate::{CompensationTable, TableValues};
/// # use axcomp::measurement::AxisKind;
/// use axcomp::units::Mm;
/// let table = CompensationTable {
///     axis: "C".into(),
///     kind: AxisKind::Rotary,
///     positions: vec![0.0, 90.0],
///     values: TableValues::Mean(vec![0.0, 0.001]),
///     reference: 0.0,
///     suggested_backlash: None,
/// };
/// let start: Mm = table.reference_typed();
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct CompensationTable {
    /// The compensated axis.
    pub axis: String,
    /// Linear or rotary: the unit of every number below (mm or °).
    pub kind: AxisKind,
    /// Compensation points, in the axis' unit, strictly increasing.
    pub positions: Vec<f64>,
    /// Axis error at each point, in the axis' unit, zero at the reference.
    pub values: TableValues,
    /// Where the table is zero, in the axis' unit.
    pub reference: f64,
    /// Suggested backlash parameter, in the axis' unit (mean mode): −B̄,
    /// positive for the usual lost motion (the axis falls short in the
    /// direction it moves).
    pub suggested_backlash: Option<f64>,
}

impl CompensationTable {
    /// The axis error the table holds at `position` (in the axis' unit) when
    /// moving in `direction`, as controllers apply tables: linear between
    /// points, the end values held outside (Siemens K3 §4.4, LinuxCNC
    /// `control.c`, Heidenhain).
    pub fn value_at(&self, position: f64, direction: Direction) -> f64 {
        interpolate_hold(
            &self.positions,
            self.values.for_direction(direction),
            position,
        )
    }

    /// The spacing in the axis' unit if the points are evenly spaced (within
    /// 1 nm), else `None`.
    pub fn regular_step(&self) -> Option<f64> {
        regular_step(&self.positions)
    }

    /// The largest |value| of the table, in the axis' unit.
    pub fn max_abs(&self) -> f64 {
        let all = match &self.values {
            TableValues::Mean(values) => values.clone(),
            TableValues::Bidirectional { up, down } => up.iter().chain(down).copied().collect(),
        };
        all.iter().fold(0.0, |max: f64, v| max.max(v.abs()))
    }

    /// The compensation points, typed by the axis' kind (`Mm` or `Deg`).
    pub fn positions_typed(&self) -> impl Iterator<Item = Position> + '_ {
        self.positions.iter().map(|&p| self.kind.position(p))
    }

    /// Where the table is zero, typed by the axis' kind.
    pub fn reference_typed(&self) -> Position {
        self.kind.position(self.reference)
    }

    /// The spacing of evenly spaced points, typed by the axis' kind.
    pub fn regular_step_typed(&self) -> Option<Position> {
        self.regular_step().map(|step| self.kind.position(step))
    }

    /// The suggested backlash parameter, typed by the axis' kind.
    pub fn suggested_backlash_typed(&self) -> Option<Position> {
        self.suggested_backlash.map(|b| self.kind.position(b))
    }
}

/// Why a table cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CompensateError {
    /// Bidirectional mode needs both directions.
    #[error(
        "bidirectional tables need runs in both directions; this test has only {0} runs (use --mode mean)"
    )]
    OneDirectionOnly(Direction),
    /// No target has a mean deviation.
    #[error("no target has a mean deviation to compensate")]
    NoData,
    /// The backlash parameter cannot be applied as said.
    #[error("the backlash parameter {0}")]
    Backlash(retest::BacklashRefusal),
    /// The controller needs one step and the targets have none.
    #[error(
        "the targets are unevenly spaced ({count} targets from {} to {}{}) and {controller} needs one step: give --step (and optionally --start, --count)",
        first.in_axis_unit(), last.in_axis_unit(), last.unit_after_number()
    )]
    UnevenTargets {
        /// How many targets.
        count: usize,
        /// The first.
        first: Position,
        /// The last.
        last: Position,
        /// The controller's name.
        controller: &'static str,
    },
    /// A compensation point lies outside the measured range.
    #[error(
        "compensation point {}{} is outside the measured range {} … {}{}; use --extrapolate hold or --extrapolate zero, or a grid inside the range",
        position.in_axis_unit(), position.unit_after_number(),
        first.in_axis_unit(), last.in_axis_unit(), last.unit_after_number()
    )]
    OutsideMeasuredRange {
        /// The point.
        position: Position,
        /// First measured target.
        first: Position,
        /// Last measured target.
        last: Position,
    },
    /// The reference position lies outside the table.
    #[error(
        "reference position {}{} is outside the table {} … {}{}",
        reference.in_axis_unit(), reference.unit_after_number(),
        first.in_axis_unit(), last.in_axis_unit(), last.unit_after_number()
    )]
    ReferenceOutside {
        /// The reference.
        reference: Position,
        /// First point.
        first: Position,
        /// Last point.
        last: Position,
    },
    /// An update cannot be referred where the test did not measure.
    #[error(
        "{} {}{} is outside the measured range {} … {}{}: the test did not measure the residual there, so the update cannot be referred to it; give --reference with the position inside the measured range where the update should add nothing (the machine's reference point)",
        if *given { "the reference" } else { "the existing table is zero (its reference) at" },
        reference.in_axis_unit(), reference.unit_after_number(),
        first.in_axis_unit(), last.in_axis_unit(), last.unit_after_number()
    )]
    UpdateReference {
        /// The reference.
        reference: Position,
        /// Whether `--reference` gave it (else it is the existing table's zero).
        given: bool,
        /// First measured target.
        first: Position,
        /// Last measured target.
        last: Position,
    },
    /// A position given for an axis of one kind (a reference, a grid, an
    /// existing table) with a measurement of the other.
    #[error(
        "the {what} is in {} (a {} axis' unit), but the test measured a {} axis, in {}: they do not belong together",
        given.position_unit(), given.as_str(), measured.as_str(), measured.position_unit()
    )]
    KindMismatch {
        /// What was given: `reference`, `grid's step`, `existing table`.
        what: &'static str,
        /// The kind it is of.
        given: AxisKind,
        /// The kind of the measured axis.
        measured: AxisKind,
    },
    /// A one-direction test cannot update a table with a column per direction.
    #[error(
        "the existing table has a column per direction, and this test ran {0} only: the other direction's column would be lost (replaced by the {0} curve); measure both directions, or write a new table without --existing"
    )]
    OneDirectionUpdate(Direction),
    /// `--extrapolate` has no meaning in an update.
    #[error(
        "--extrapolate does not apply with --existing: outside the measured range the existing table's values are kept as they are"
    )]
    ExtrapolateUpdate,
    /// The grid is not usable.
    #[error("invalid grid: {0}")]
    Grid(String),
    /// A measurement could not be rebuilt with the effects taken out (a bug).
    #[error("internal error, please report: {0}")]
    Measurement(#[from] crate::measurement::MeasurementError),
}

/// The spacing of evenly spaced positions (within 1 nm), or `None`.
pub fn regular_step(positions: &[f64]) -> Option<f64> {
    const SAME_STEP_MM: f64 = 1e-6;
    if positions.len() < 2 {
        return None;
    }
    let step = (positions[positions.len() - 1] - positions[0]) / (positions.len() - 1) as f64;
    let even = positions
        .windows(2)
        .all(|pair| ((pair[1] - pair[0]) - step).abs() <= SAME_STEP_MM);
    (even && step > 0.0).then_some(step)
}

/// Linear interpolation with the end values held outside `[x0, xn]`.
/// `xs` strictly increasing, same length as `ys`, not empty.
pub fn interpolate_hold(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    debug_assert_eq!(xs.len(), ys.len());
    let last = xs.len() - 1;
    if x <= xs[0] {
        return ys[0];
    }
    if x >= xs[last] {
        return ys[last];
    }
    // First index with xs[i] > x; x lies in [xs[i-1], xs[i]).
    let i = xs.partition_point(|&p| p <= x);
    let (x0, x1, y0, y1) = (xs[i - 1], xs[i], ys[i - 1], ys[i]);
    y0 + (y1 - y0) * (x - x0) / (x1 - x0)
}

/// The source curve of one direction (or of the mean): positions and mean
/// deviations of the targets where it is defined.
fn source_curve(
    evaluation: &Evaluation,
    pick: impl Fn(&crate::evaluate::TargetStats) -> Option<f64>,
) -> (Vec<f64>, Vec<f64>) {
    evaluation
        .per_target
        .iter()
        .filter_map(|t| pick(t).map(|value| (t.target, value)))
        .unzip()
}

/// A rotary curve over a full turn with one value at both ends, the mean of
/// the two: they are one physical position (module doc). Any other curve as it is.
fn join_full_turn(curve: (Vec<f64>, Vec<f64>), kind: AxisKind) -> (Vec<f64>, Vec<f64>) {
    let (positions, mut values) = curve;
    let (Some(first), Some(last)) = (positions.first(), positions.last()) else {
        return (positions, values);
    };
    if kind == AxisKind::Rotary && (last - first - FULL_TURN_DEG).abs() < 1e-6 {
        let last_index = values.len() - 1;
        let joined = (values[0] + values[last_index]) / 2.0;
        values[0] = joined;
        values[last_index] = joined;
    }
    (positions, values)
}

/// Builds a compensation table from a measurement and its evaluation.
///
/// # Example
/// ```
/// use axcomp::compensate::{build_table, Extrapolate, GridSpec, TableMode, TableOptions, TableValues};
/// use axcomp::evaluate::evaluate;
/// use axcomp::read::parse_str;
/// use axcomp::measurement::{ByKind, SourceFormat};
/// use axcomp::units::Mm;
/// let csv = "target_mm,run,direction,deviation_um\n0,1,up,1\n100,1,up,-2\n0,1,down,3\n100,1,down,0\n";
/// let (m, _) = parse_str(csv, SourceFormat::Csv).unwrap();
/// let options = TableOptions { mode: TableMode::Mean, grid: GridSpec::Targets,
///                              reference: None, extrapolate: Extrapolate::Refuse };
/// let table = build_table(&m, &evaluate(&m), &options).unwrap();
/// // x̄ = 2, −1 µm; shifted to zero at 0 mm: 0, −3 µm.
/// assert_eq!(table.values, TableValues::Mean(vec![0.0, -0.003]));
/// // −B̄ = mean(x̄↓ − x̄↑) = mean(2, 2) µm.
/// // A linear axis' table: its numbers leave it as millimetres.
/// let Some(ByKind::Linear(Mm(backlash_mm))) = table.suggested_backlash_typed() else {
///     panic!("a linear axis' backlash is in mm")
/// };
/// assert!((backlash_mm - 0.002).abs() < 1e-15);
/// ```
pub fn build_table(
    measurement: &Measurement,
    evaluation: &Evaluation,
    options: &TableOptions,
) -> Result<CompensationTable, CompensateError> {
    let kind = measurement.kind();
    options.check_kind(kind)?;
    let positions = grid_positions(measurement.targets(), options.grid)?;
    let has = |d: Direction| measurement.run_count(d) > 0;
    let source_curve = |pick: fn(&crate::evaluate::TargetStats) -> Option<f64>| {
        join_full_turn(source_curve(evaluation, pick), kind)
    };
    let (raw, suggested_backlash) = match options.mode {
        TableMode::Mean => {
            let curve = match (has(Direction::Up), has(Direction::Down)) {
                (true, true) => source_curve(|t| t.mean),
                (true, false) => source_curve(|t| t.up.mean),
                _ => source_curve(|t| t.down.mean),
            };
            let column = resample(&curve, &positions, kind, options.extrapolate)?;
            let backlash = evaluation.figures.b_mean.map(|b| -b);
            (TableValues::Mean(column), backlash)
        }
        TableMode::Bidirectional => {
            for direction in Direction::BOTH {
                if !has(direction) {
                    return Err(CompensateError::OneDirectionOnly(direction.reversed()));
                }
            }
            let up = resample(
                &source_curve(|t| t.up.mean),
                &positions,
                kind,
                options.extrapolate,
            )?;
            let down = resample(
                &source_curve(|t| t.down.mean),
                &positions,
                kind,
                options.extrapolate,
            )?;
            (TableValues::Bidirectional { up, down }, None)
        }
    };
    let reference_at = options
        .reference
        .map_or(positions[0], Position::in_axis_unit);
    let (first, last) = (positions[0], positions[positions.len() - 1]);
    if reference_at < first - 1e-9 || reference_at > last + 1e-9 {
        return Err(CompensateError::ReferenceOutside {
            reference: kind.position(reference_at),
            first: kind.position(first),
            last: kind.position(last),
        });
    }
    let values = shift_to_reference(
        &raw,
        &positions,
        reference_at,
        options.extrapolate == Extrapolate::Zero,
        measurement,
    );
    Ok(CompensationTable {
        axis: measurement.axis().to_string(),
        kind,
        positions,
        values,
        reference: reference_at,
        suggested_backlash,
    })
}

/// Subtracts the value at the reference. Zero-extrapolated points (marked by
/// lying outside the measured range) stay zero: "no compensation there".
/// In bidirectional mode both columns are shifted by the same amount, their
/// mean at the reference, so the reversal between them is kept and the table
/// does not depend on the direction the controller references in.
fn shift_to_reference(
    raw: &TableValues,
    positions: &[f64],
    reference_at: f64,
    zero_outside: bool,
    measurement: &Measurement,
) -> TableValues {
    let targets = measurement.targets();
    let (first, last) = (targets[0], targets[targets.len() - 1]);
    let at_reference =
        |d: Direction| interpolate_hold(positions, raw.for_direction(d), reference_at);
    let offset = (at_reference(Direction::Up) + at_reference(Direction::Down)) / 2.0;
    raw.map(|column| {
        column
            .iter()
            .zip(positions)
            .map(|(value, &p)| {
                let outside = p < first - 1e-9 || p > last + 1e-9;
                if zero_outside && outside {
                    0.0
                } else {
                    value - offset
                }
            })
            .collect()
    })
}

/// The compensation points of a grid spec, in the unit of the grid (and of
/// the targets: [`build_table`] checks that they agree).
pub fn grid_positions(targets: &[f64], grid: GridSpec) -> Result<Vec<f64>, CompensateError> {
    match grid {
        GridSpec::Targets => {
            if targets.len() < 2 {
                return Err(CompensateError::Grid(
                    "a table needs at least 2 points; the test has 1 target".into(),
                ));
            }
            Ok(targets.to_vec())
        }
        GridSpec::Regular { start, step, count } => {
            let (start_mm, step_mm) = (start.in_axis_unit(), step.in_axis_unit());
            if !(step_mm.is_finite() && step_mm > 0.0) {
                return Err(CompensateError::Grid(format!(
                    "step must be positive, found {step_mm}{}",
                    step.unit_after_number()
                )));
            }
            if count < 2 {
                return Err(CompensateError::Grid(format!(
                    "a table needs at least 2 points, found {count}"
                )));
            }
            if !start_mm.is_finite() {
                return Err(CompensateError::Grid(format!(
                    "start must be a number, found {start_mm}"
                )));
            }
            Ok((0..count)
                .map(|k| round_nm(start_mm + k as f64 * step_mm))
                .collect())
        }
    }
}

/// A grid position rounded to 1e-9 mm, so that e.g. 0.1·3 prints as 0.3.
fn round_nm(mm: f64) -> f64 {
    (mm * 1e9).round() / 1e9
}

/// Interpolates a source curve onto the points, applying the extrapolation rule.
fn resample(
    curve: &(Vec<f64>, Vec<f64>),
    positions: &[f64],
    kind: AxisKind,
    extrapolate: Extrapolate,
) -> Result<Vec<f64>, CompensateError> {
    let (xs, ys) = curve;
    if xs.is_empty() {
        return Err(CompensateError::NoData);
    }
    let (first, last) = (xs[0], xs[xs.len() - 1]);
    positions
        .iter()
        .map(|&p| {
            let outside = p < first - 1e-9 || p > last + 1e-9;
            match (outside, extrapolate) {
                (true, Extrapolate::Refuse) => Err(CompensateError::OutsideMeasuredRange {
                    position: kind.position(p),
                    first: kind.position(first),
                    last: kind.position(last),
                }),
                _ => Ok(interpolate_hold(xs, ys, p)),
            }
        })
        .collect()
}

/// Turns a measurement taken with `active` compensation on into the deviations
/// the axis would show without it: each reading plus the active table's value
/// there, in its direction (the controller subtracted that value).
pub fn add_existing_table(
    measurement: &Measurement,
    active: &CompensationTable,
) -> Result<Measurement, MeasurementError> {
    let targets = measurement.targets();
    measurement.map_readings(|run, i, v| v + active.value_at(targets[i], run.direction))
}

#[cfg(test)]
mod tests;
