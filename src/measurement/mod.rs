//! The measurement of one axis: the plain, validated data every stage meets on.
//!
//! An axis is linear or rotary ([`AxisKind`]). Its targets and deviations
//! are bare `f64`s in the axis' unit: mm on a linear axis, degrees on a
//! rotary one (`../shared/spec/standards.md` §6: targets in degrees,
//! deviations reported in ″), as the statistics are the same arithmetic in
//! either; their names ([`Measurement::targets`], [`Run::deviations`]) name
//! no unit, since the unit is the axis'. A value leaves them typed:
//! [`Measurement::positions`], [`Measurement::deviations_of`] and
//! [`AxisKind::position`] give a [`Position`] (`Mm` or `Deg`,
//! `crate::units`), so a stage that prints or serialises a value cannot take
//! a degree for a millimetre.
//!
//! A [`Measurement`] holds the targets (strictly increasing), the runs
//! (each with its direction and one deviation per target, `None` where a
//! reading is missing), the environment record and the metadata. It can only
//! be built through [`Measurement::new`], which checks the invariants that
//! `evaluate` relies on (`../shared/spec/style.md` §1, "Put preconditions in
//! types"): readers check the same things first, with line and column, so
//! this check is the last guard, not the user's error message.
//!
//! Deviations are positional deviations x_ij = P_ij − P_i (actual minus
//! target, `../shared/spec/iso230-2.md` "Data"), stored in the axis' unit (mm, or ° on a rotary axis).

use std::fmt;

use crate::units::{AngleUnit, Deg, DeviationUnit, Mm};

mod metadata;

pub use metadata::{
    AXIS_PLACEHOLDER, AxisSource, Environment, Metadata, SourceFormat, StartEnd, TestDate,
    TestSetup,
};

/// Approach direction of a run: ↑ moves in the positive direction, ↓ in the negative.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Direction {
    /// Targets approached moving in the positive direction (↑).
    Up,
    /// Targets approached moving in the negative direction (↓).
    Down,
}

impl Direction {
    /// Both directions, ↑ first.
    pub const BOTH: [Direction; 2] = [Direction::Up, Direction::Down];

    /// `up` or `down`, as in JSON and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::Up => "up",
            Direction::Down => "down",
        }
    }

    /// The other direction.
    pub fn reversed(self) -> Direction {
        match self {
            Direction::Up => Direction::Down,
            Direction::Down => Direction::Up,
        }
    }

    /// A reversal's share of a reading in this direction, in the reversal's
    /// unit: ↑ readings sit B/2 above the bidirectional mean and ↓ readings
    /// B/2 below, since B = x̄↑ − x̄↓ (ISO 230-2, `iso230-2.md` §reversal).
    pub fn reversal_share(self, reversal: f64) -> f64 {
        match self {
            Direction::Up => reversal / 2.0,
            Direction::Down => -reversal / 2.0,
        }
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Direction::Up => "↑",
            Direction::Down => "↓",
        })
    }
}

/// Whether an axis moves along a line or turns: the unit of its values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AxisKind {
    /// A linear axis: targets and deviations in mm.
    #[default]
    Linear,
    /// A rotary axis: targets and deviations in degrees (reported in ″).
    Rotary,
}

impl AxisKind {
    /// `linear` or `rotary`, as in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            AxisKind::Linear => "linear",
            AxisKind::Rotary => "rotary",
        }
    }

    /// The unit its deviations are reported in: µm on a linear axis,
    /// `angle` on a rotary one.
    pub fn deviation_unit(self, angle: AngleUnit) -> DeviationUnit {
        match self {
            AxisKind::Linear => DeviationUnit::Micrometre,
            AxisKind::Rotary => DeviationUnit::Angle(angle),
        }
    }

    /// The unit of a target position in sentences: `mm` or `°`.
    pub fn position_unit(self) -> &'static str {
        match self {
            AxisKind::Linear => "mm",
            AxisKind::Rotary => "°",
        }
    }

    /// What follows a position in a sentence: ` mm`, or `°` set close.
    pub fn unit_after_number(self) -> &'static str {
        match self {
            AxisKind::Linear => " mm",
            AxisKind::Rotary => "°",
        }
    }

    /// A bare number in this axis' unit (a target, a deviation, a figure),
    /// typed: [`Mm`] on a linear axis, [`Deg`] on a rotary one. With
    /// [`crate::evaluate::TargetStats::typed`], the one place where such a
    /// number gets its unit.
    pub fn position(self, value: f64) -> Position {
        match self {
            AxisKind::Linear => ByKind::Linear(Mm(value)),
            AxisKind::Rotary => ByKind::Rotary(Deg(value)),
        }
    }
}

/// Something of a linear axis (`L`, in mm) or of a rotary one (`R`, in
/// degrees): what a bare number in an axis' unit becomes once the axis'
/// kind is asked ([`AxisKind::position`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ByKind<L, R> {
    /// Of a linear axis.
    Linear(L),
    /// Of a rotary axis.
    Rotary(R),
}

impl<L, R> ByKind<L, R> {
    /// The axis' kind.
    pub fn kind(&self) -> AxisKind {
        match self {
            ByKind::Linear(_) => AxisKind::Linear,
            ByKind::Rotary(_) => AxisKind::Rotary,
        }
    }

    /// The linear axis' value; `None` on a rotary axis.
    pub fn linear(self) -> Option<L> {
        match self {
            ByKind::Linear(value) => Some(value),
            ByKind::Rotary(_) => None,
        }
    }

    /// The rotary axis' value; `None` on a linear axis.
    pub fn rotary(self) -> Option<R> {
        match self {
            ByKind::Linear(_) => None,
            ByKind::Rotary(value) => Some(value),
        }
    }
}

/// A position, or a length along the axis (a range, a deviation), in its
/// axis' unit: mm on a linear axis, ° on a rotary one.
pub type Position = ByKind<Mm, Deg>;

impl Position {
    /// The bare number in its axis' unit (mm, or ° on a rotary axis): for
    /// arithmetic that is the same in both, once the kinds are known to agree.
    pub fn in_axis_unit(self) -> f64 {
        match self {
            ByKind::Linear(Mm(value)) => value,
            ByKind::Rotary(Deg(value)) => value,
        }
    }

    /// What follows the number in a sentence: ` mm`, or `°` set close.
    pub fn unit_after_number(self) -> &'static str {
        self.kind().unit_after_number()
    }
}

/// One pass over the targets in one direction.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// ↑ or ↓.
    pub direction: Direction,
    /// Run number within its direction, starting at 1, in the order measured
    /// (ISO 230-2's j). Runs of a bidirectional test share numbers: run 2↑ and
    /// run 2↓ are the two halves of the second cycle.
    pub number: u32,
    /// When the run started, in seconds after the test started, if known.
    pub start_time_s: Option<f64>,
    /// One deviation per target (same order as the targets), in the axis'
    /// unit: mm, or ° on a rotary axis ([`Measurement::deviations_of`] gives
    /// them typed); `None` is a missing reading.
    pub deviations: Vec<Option<f64>>,
}

impl Run {
    /// `2↑`: how runs are named to users.
    pub fn label(&self) -> String {
        format!("{}{}", self.number, self.direction)
    }
}

/// What differs where two files have as many targets and the same ends:
/// the first target that is elsewhere.
fn differing_target_text(difference: Option<(usize, f64, f64)>, kind: AxisKind) -> String {
    let unit = kind.unit_after_number();
    difference.map_or_else(String::new, |(number, first, other)| {
        format!(
            ": target {number} is at {first:?}{unit} in the first and {other:?}{unit} in the second"
        )
    })
}

/// Why a set of targets and runs is not a valid measurement.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeasurementError {
    /// Two files to join have other targets.
    #[error(
        "cannot join the files: targets differ ({count} targets {first:?}…{last:?}{unit} against {other_count} targets {other_first:?}…{other_last:?}{unit}){}",
        differing_target_text(*first_difference, *kind),
        unit = kind.unit_after_number()
    )]
    TargetsDiffer {
        /// Linear or rotary (both files): the unit of the positions.
        kind: AxisKind,
        /// The first target that differs, when both have as many: its
        /// number (from 1) and its position in each, in the axis' unit.
        first_difference: Option<(usize, f64, f64)>,
        /// Targets of the first.
        count: usize,
        /// Its first target, in the axis' unit (mm or °).
        first: f64,
        /// Its last target.
        last: f64,
        /// Targets of the second.
        other_count: usize,
        /// Its first target.
        other_first: f64,
        /// Its last target.
        other_last: f64,
    },
    /// A linear and a rotary measurement cannot be joined.
    #[error("cannot join the files: one is a {} axis, the other {}", first.as_str(), second.as_str())]
    KindsDiffer {
        /// The first file's kind.
        first: AxisKind,
        /// The second's.
        second: AxisKind,
    },
    /// No targets.
    #[error("no targets")]
    NoTargets,
    /// A target is NaN or infinite.
    #[error("target {index} is not a finite number")]
    NonFiniteTarget {
        /// 1-based target number.
        index: usize,
    },
    /// Targets not strictly increasing.
    #[error("targets must be strictly increasing: target {index} ({value}) follows {previous}")]
    TargetsNotIncreasing {
        /// 1-based target number.
        index: usize,
        /// Its value, in the axis' unit (mm, or °).
        value: f64,
        /// The value before it.
        previous: f64,
    },
    /// No runs.
    #[error("no runs")]
    NoRuns,
    /// A run's deviation count differs from the target count.
    #[error("run {run} has {found} deviations for {expected} targets")]
    RunLength {
        /// The run, as `2↑`.
        run: String,
        /// Target count.
        expected: usize,
        /// Deviation count.
        found: usize,
    },
    /// A deviation is NaN or infinite.
    #[error("run {run} has a non-finite deviation at target {index}")]
    NonFiniteDeviation {
        /// The run.
        run: String,
        /// 1-based target number.
        index: usize,
    },
    /// A run has no reading at all.
    #[error("run {run} has no readings")]
    EmptyRun {
        /// The run.
        run: String,
    },
    /// Two runs share a direction and number.
    #[error("run {run} appears twice")]
    DuplicateRun {
        /// The run.
        run: String,
    },
    /// Run numbers must start at 1 and be consecutive per direction.
    #[error(
        "runs {direction} must be numbered 1, 2, 3, … in the order measured; found {numbers:?}"
    )]
    RunNumbering {
        /// The direction.
        direction: Direction,
        /// The numbers found.
        numbers: Vec<u32>,
    },
}

/// Selects runs to leave out of an evaluation: a run number in one or both directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunSelector {
    /// Run number within its direction.
    pub number: u32,
    /// `None` selects that number in both directions.
    pub direction: Option<Direction>,
}

impl RunSelector {
    /// Whether this selector picks `run`.
    pub fn selects(&self, run: &Run) -> bool {
        run.number == self.number && self.direction.is_none_or(|d| d == run.direction)
    }
}

impl fmt::Display for RunSelector {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.direction {
            Some(direction) => write!(f, "{}:{}", self.number, direction.as_str()),
            None => write!(f, "{}", self.number),
        }
    }
}

/// A validated measurement of one axis (see the module doc for the invariants).
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    axis: String,
    kind: AxisKind,
    /// In the axis' unit: mm, or ° on a rotary axis.
    targets: Vec<f64>,
    runs: Vec<Run>,
    /// The test conditions.
    pub environment: Environment,
    /// Who, what, where, when, and from which file.
    pub metadata: Metadata,
}

impl Measurement {
    /// Builds a measurement, checking its invariants:
    /// - at least one target, all finite and strictly increasing;
    /// - at least one run, each with one finite-or-missing deviation per target
    ///   and at least one reading;
    /// - runs numbered 1, 2, 3, … per direction, without repeats.
    ///
    /// # Example
    /// ```
    /// use axcomp::measurement::{Direction, Measurement, Run};
    /// let run = Run { direction: Direction::Up, number: 1, start_time_s: None,
    ///                 deviations: vec![Some(0.0), Some(0.002)] };
    /// let m = Measurement::new("X", vec![0.0, 100.0], vec![run],
    ///                          Default::default(), Default::default()).unwrap();
    /// assert_eq!(m.targets(), &[0.0, 100.0]);
    /// assert!(Measurement::new("X", vec![100.0, 0.0], vec![], Default::default(),
    ///                          Default::default()).is_err());
    /// ```
    pub fn new(
        axis: impl Into<String>,
        targets: Vec<f64>,
        runs: Vec<Run>,
        environment: Environment,
        metadata: Metadata,
    ) -> Result<Measurement, MeasurementError> {
        check_targets(&targets)?;
        check_runs(&runs, targets.len())?;
        Ok(Measurement {
            axis: axis.into(),
            kind: AxisKind::Linear,
            targets,
            runs,
            environment,
            metadata,
        })
    }

    /// The axis name (`X`, `Y`, `Z`, `U`, …); [`AXIS_PLACEHOLDER`] when the
    /// file does not record it (see [`Measurement::axis_source`]).
    pub fn axis(&self) -> &str {
        &self.axis
    }

    /// Where the axis name came from.
    pub fn axis_source(&self) -> &AxisSource {
        &self.metadata.axis_source
    }

    /// Whether the axis name was stated by the file or given by the user,
    /// rather than the placeholder.
    pub fn axis_recorded(&self) -> bool {
        self.metadata.axis_source.is_recorded()
    }

    /// Linear or rotary: whether the values are mm or degrees.
    pub fn kind(&self) -> AxisKind {
        self.kind
    }

    /// The same measurement of an axis of `kind` ([`Measurement::new`]
    /// builds a linear one): the values are then read in its unit.
    ///
    /// # Example
    /// ```
    /// use axcomp::measurement::{AxisKind, Direction, Measurement, Run};
    /// let run = Run { direction: Direction::Up, number: 1, start_time_s: None,
    ///                 deviations: vec![Some(0.0), Some(0.001)] };
    /// let c = Measurement::new("C", vec![0.0, 90.0], vec![run],
    ///                          Default::default(), Default::default()).unwrap()
    ///     .with_kind(AxisKind::Rotary);
    /// assert_eq!(c.kind(), AxisKind::Rotary);
    /// ```
    pub fn with_kind(mut self, kind: AxisKind) -> Measurement {
        self.kind = kind;
        self
    }

    /// The targets P_i in the axis' unit (mm, or ° on a rotary axis),
    /// strictly increasing: for arithmetic that is the same in either unit.
    pub fn targets(&self) -> &[f64] {
        &self.targets
    }

    /// The targets P_i, typed by the axis' kind ([`Position`]: `Mm` or `Deg`).
    pub fn positions(&self) -> impl Iterator<Item = Position> + '_ {
        self.targets
            .iter()
            .map(|&target| self.kind.position(target))
    }

    /// One run's deviations, typed by the axis' kind ([`Position`]: `Mm` or
    /// `Deg`); `None` where a reading is missing. A deviation of a rotary
    /// axis is a [`Deg`], which no `Mm` slot takes:
    /// ```compile_fail
    /// # use axcomp::measurement::{AxisKind, Direction, Measurement, Run};
    /// # use axcomp::units::Mm;
    /// # let run = Run { direction: Direction::Up, number: 1, start_time_s: None,
    /// #                 deviations: vec![Some(0.001)] };
    /// # let c = Measurement::new("C", vec![90.0], vec![run], Default::default(),
    /// #                          Default::default()).unwrap().with_kind(AxisKind::Rotary);
    /// let first: Mm = c.deviations_of(&c.runs()[0]).next().unwrap().unwrap();
    /// ```
    pub fn deviations_of<'a>(&self, run: &'a Run) -> impl Iterator<Item = Option<Position>> + 'a {
        let kind = self.kind;
        run.deviations
            .iter()
            .map(move |deviation| deviation.map(|value| kind.position(value)))
    }

    /// The runs, in the order measured.
    pub fn runs(&self) -> &[Run] {
        &self.runs
    }

    /// The runs in one direction, in the order measured.
    pub fn runs_in(&self, direction: Direction) -> impl Iterator<Item = &Run> {
        self.runs
            .iter()
            .filter(move |run| run.direction == direction)
    }

    /// How many runs go in `direction`.
    pub fn run_count(&self, direction: Direction) -> usize {
        self.runs_in(direction).count()
    }

    /// Names the axis (for a file that names none, or the wrong one); the
    /// name is then [`AxisSource::Given`].
    pub fn set_axis(&mut self, axis: impl Into<String>) {
        self.axis = axis.into();
        self.metadata.axis_source = AxisSource::Given;
    }

    /// Names the axis as stated by the file, in `source` (for the reader,
    /// which finds some names only after parsing, e.g. in a file name).
    pub fn set_axis_from(&mut self, axis: impl Into<String>, source: AxisSource) {
        self.axis = axis.into();
        self.metadata.axis_source = source;
    }

    /// The same measurement without the selected runs. Remaining runs keep
    /// their numbers, so reports still name them as the file does.
    pub fn without_runs(
        mut self,
        excluded: &[RunSelector],
    ) -> Result<Measurement, MeasurementError> {
        // By value: the kept runs stay where they are, nothing is copied.
        self.runs
            .retain(|run| !excluded.iter().any(|selector| selector.selects(run)));
        if self.runs.is_empty() {
            return Err(MeasurementError::NoRuns);
        }
        Ok(self)
    }

    /// The same measurement with every reading replaced by
    /// `reading(run, target index, value in the axis' unit)`; missing readings stay missing,
    /// targets, runs and conditions are kept. (A table taken off, an effect
    /// taken out, a predicted change put in.)
    pub fn map_readings(
        &self,
        reading: impl Fn(&Run, usize, f64) -> f64,
    ) -> Result<Measurement, MeasurementError> {
        let runs: Vec<Run> = self
            .runs
            .iter()
            .map(|run| Run {
                deviations: run
                    .deviations
                    .iter()
                    .enumerate()
                    .map(|(i, value)| value.map(|v| reading(run, i, v)))
                    .collect(),
                ..run.clone()
            })
            .collect();
        check_runs(&runs, self.targets.len())?;
        // Field by field: `..self.clone()` would copy every run once more.
        Ok(Measurement {
            axis: self.axis.clone(),
            kind: self.kind,
            targets: self.targets.clone(),
            runs,
            environment: self.environment.clone(),
            metadata: self.metadata.clone(),
        })
    }

    /// Joins two measurements of the same axis and targets (e.g. the forward
    /// and reverse `.pos` files of one test). Runs of `other` follow those of
    /// `self` and are renumbered after them, per direction.
    pub fn merge(&self, other: &Measurement) -> Result<Measurement, MeasurementError> {
        // In the axis' unit: 1 nm, or 1e-6° (0.0036″).
        const SAME_TARGET: f64 = 1e-6;
        if self.kind != other.kind {
            return Err(MeasurementError::KindsDiffer {
                first: self.kind,
                second: other.kind,
            });
        }
        if self.targets.len() != other.targets.len()
            || self
                .targets
                .iter()
                .zip(&other.targets)
                .any(|(a, b)| (a - b).abs() > SAME_TARGET)
        {
            let first_difference = (self.targets.len() == other.targets.len())
                .then(|| {
                    self.targets
                        .iter()
                        .zip(&other.targets)
                        .position(|(a, b)| (a - b).abs() > SAME_TARGET)
                        .map(|i| (i + 1, self.targets[i], other.targets[i]))
                })
                .flatten();
            return Err(MeasurementError::TargetsDiffer {
                kind: self.kind,
                first_difference,
                count: self.targets.len(),
                first: self.targets.first().copied().unwrap_or_default(),
                last: self.targets.last().copied().unwrap_or_default(),
                other_count: other.targets.len(),
                other_first: other.targets.first().copied().unwrap_or_default(),
                other_last: other.targets.last().copied().unwrap_or_default(),
            });
        }
        let mut runs = self.runs.clone();
        for run in &other.runs {
            let already = runs.iter().filter(|r| r.direction == run.direction).count() as u32;
            runs.push(Run {
                number: already + 1,
                ..run.clone()
            });
        }
        Ok(Measurement::new(
            self.axis.clone(),
            self.targets.clone(),
            runs,
            self.environment.clone(),
            self.metadata.clone(),
        )?
        .with_kind(self.kind))
    }
}

fn check_targets(targets: &[f64]) -> Result<(), MeasurementError> {
    if targets.is_empty() {
        return Err(MeasurementError::NoTargets);
    }
    for (index, target) in targets.iter().enumerate() {
        if !target.is_finite() {
            return Err(MeasurementError::NonFiniteTarget { index: index + 1 });
        }
        if index > 0 && targets[index - 1] >= *target {
            return Err(MeasurementError::TargetsNotIncreasing {
                index: index + 1,
                value: *target,
                previous: targets[index - 1],
            });
        }
    }
    Ok(())
}

fn check_runs(runs: &[Run], target_count: usize) -> Result<(), MeasurementError> {
    if runs.is_empty() {
        return Err(MeasurementError::NoRuns);
    }
    for run in runs {
        if run.deviations.len() != target_count {
            return Err(MeasurementError::RunLength {
                run: run.label(),
                expected: target_count,
                found: run.deviations.len(),
            });
        }
        if let Some(index) = run
            .deviations
            .iter()
            .position(|value| value.is_some_and(|v| !v.is_finite()))
        {
            return Err(MeasurementError::NonFiniteDeviation {
                run: run.label(),
                index: index + 1,
            });
        }
        if run.deviations.iter().all(Option::is_none) {
            return Err(MeasurementError::EmptyRun { run: run.label() });
        }
    }
    for direction in Direction::BOTH {
        let numbers: Vec<u32> = runs
            .iter()
            .filter(|run| run.direction == direction)
            .map(|run| run.number)
            .collect();
        let mut sorted = numbers.clone();
        sorted.sort_unstable();
        if let Some(pair) = sorted.windows(2).find(|pair| pair[0] == pair[1]) {
            return Err(MeasurementError::DuplicateRun {
                run: format!("{}{direction}", pair[0]),
            });
        }
        if sorted.iter().enumerate().any(|(i, n)| *n != i as u32 + 1) {
            return Err(MeasurementError::RunNumbering { direction, numbers });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(direction: Direction, number: u32, values: &[Option<f64>]) -> Run {
        Run {
            direction,
            number,
            start_time_s: None,
            deviations: values.to_vec(),
        }
    }

    fn measurement(targets: Vec<f64>, runs: Vec<Run>) -> Result<Measurement, MeasurementError> {
        Measurement::new(
            "X",
            targets,
            runs,
            Environment::default(),
            Metadata::default(),
        )
    }

    #[test]
    fn invariants_are_checked() {
        let ok = run(Direction::Up, 1, &[Some(0.0), None]);
        assert!(measurement(vec![0.0, 1.0], vec![ok.clone()]).is_ok());
        assert_eq!(
            measurement(vec![], vec![ok.clone()]),
            Err(MeasurementError::NoTargets)
        );
        assert!(matches!(
            measurement(vec![0.0, 0.0], vec![ok.clone()]),
            Err(MeasurementError::TargetsNotIncreasing { index: 2, .. })
        ));
        assert!(matches!(
            measurement(vec![0.0, f64::NAN], vec![ok.clone()]),
            Err(MeasurementError::NonFiniteTarget { index: 2 })
        ));
        assert_eq!(
            measurement(vec![0.0, 1.0], vec![]),
            Err(MeasurementError::NoRuns)
        );
        assert!(matches!(
            measurement(vec![0.0], vec![ok.clone()]),
            Err(MeasurementError::RunLength { .. })
        ));
        let nan = run(Direction::Up, 1, &[Some(f64::INFINITY), None]);
        assert!(matches!(
            measurement(vec![0.0, 1.0], vec![nan]),
            Err(MeasurementError::NonFiniteDeviation { index: 1, .. })
        ));
        let empty = run(Direction::Down, 1, &[None, None]);
        assert!(matches!(
            measurement(vec![0.0, 1.0], vec![ok.clone(), empty]),
            Err(MeasurementError::EmptyRun { .. })
        ));
        let twice = vec![ok.clone(), ok.clone()];
        assert!(matches!(
            measurement(vec![0.0, 1.0], twice),
            Err(MeasurementError::DuplicateRun { .. })
        ));
        let gap = run(Direction::Up, 3, &[Some(0.0), None]);
        assert!(matches!(
            measurement(vec![0.0, 1.0], vec![ok, gap]),
            Err(MeasurementError::RunNumbering { .. })
        ));
    }

    #[test]
    fn excluding_runs_keeps_their_numbers() {
        let runs = vec![
            run(Direction::Up, 1, &[Some(0.0)]),
            run(Direction::Down, 1, &[Some(0.0)]),
            run(Direction::Up, 2, &[Some(0.0)]),
            run(Direction::Down, 2, &[Some(0.0)]),
        ];
        let m = measurement(vec![0.0], runs).unwrap();
        let both = RunSelector {
            number: 1,
            direction: None,
        };
        let kept = m.clone().without_runs(&[both]).unwrap();
        assert_eq!(kept.runs().len(), 2);
        assert!(kept.runs().iter().all(|r| r.number == 2));
        let down_only = RunSelector {
            number: 2,
            direction: Some(Direction::Down),
        };
        assert_eq!(m.without_runs(&[down_only]).unwrap().runs().len(), 3);
    }

    #[test]
    fn merging_forward_and_reverse_files() {
        let forward = measurement(
            vec![0.0, 5.0],
            vec![run(Direction::Up, 1, &[Some(0.0), Some(1.0)])],
        )
        .unwrap();
        let reverse = measurement(
            vec![0.0, 5.0],
            vec![run(Direction::Down, 1, &[Some(0.5), Some(1.5)])],
        )
        .unwrap();
        let both = forward.merge(&reverse).unwrap();
        assert_eq!(both.run_count(Direction::Up), 1);
        assert_eq!(both.run_count(Direction::Down), 1);
        let other = measurement(
            vec![0.0, 6.0],
            vec![run(Direction::Down, 1, &[Some(0.5), None])],
        )
        .unwrap();
        assert!(
            forward
                .merge(&other)
                .unwrap_err()
                .to_string()
                .contains("targets differ")
        );
        assert_eq!(
            forward.merge(&other).unwrap_err().to_string(),
            "cannot join the files: targets differ (2 targets 0.0…5.0 mm against 2 targets 0.0…6.0 mm): \
             target 2 is at 5.0 mm in the first and 6.0 mm in the second"
        );
    }

    #[test]
    fn a_rotary_axis_positions_are_degrees() {
        let up = |targets: Vec<f64>| {
            measurement(
                targets,
                vec![run(Direction::Up, 1, &[Some(0.0), Some(0.001)])],
            )
            .unwrap()
            .with_kind(AxisKind::Rotary)
        };
        let (quarter, half) = (up(vec![0.0, 90.0]), up(vec![0.0, 180.0]));
        assert_eq!(
            quarter.positions().collect::<Vec<_>>(),
            [ByKind::Rotary(Deg(0.0)), ByKind::Rotary(Deg(90.0))]
        );
        // 0.001° at 90°: a degree, not a millimetre.
        assert_eq!(
            quarter
                .deviations_of(&quarter.runs()[0])
                .collect::<Vec<_>>(),
            [
                Some(ByKind::Rotary(Deg(0.0))),
                Some(ByKind::Rotary(Deg(0.001)))
            ]
        );
        assert_eq!(AxisKind::Linear.position(90.0), ByKind::Linear(Mm(90.0)));
        assert_eq!(
            quarter.merge(&half).unwrap_err().to_string(),
            "cannot join the files: targets differ (2 targets 0.0…90.0° against 2 targets 0.0…180.0°): \
             target 2 is at 90.0° in the first and 180.0° in the second"
        );
    }
}
