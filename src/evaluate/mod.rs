//! ISO 230-2 evaluation of a linear positioning test.
//!
//! Implements `../shared/spec/iso230-2.md`: per target the mean positional
//! deviations x̄_i↑, x̄_i↓, x̄_i, the estimators of standard uncertainty s_i↑,
//! s_i↓ (n − 1 in the denominator, inside the square root: seed 001 eq. (8)/(9)
//! has a typo there), the reversal value B_i = x̄_i↑ − x̄_i↓ and the
//! repeatabilities R_i↑ = 4 s_i↑, R_i↓ = 4 s_i↓,
//! R_i = max(2 s_i↑ + 2 s_i↓ + |B_i|; R_i↑; R_i↓); per axis A, A↑, A↓, E, E↑,
//! E↓, M, R, R↑, R↓, B = max |B_i| and the signed mean reversal B̄ (seed 001
//! eq. (22) swaps two signs in A; the spec's form is used).
//!
//! Undefined is `None`, never 0: a unidirectional test has no bidirectional
//! figures; with n = 1 run in a direction s, R and A are undefined there. An
//! axis figure is evaluated only when what it needs is defined at every
//! target; otherwise it is `None` and a warning names the target. Suspected
//! outlier runs are flagged ([`outliers`]) but stay in the figures.
//! [`environment`] checks the test conditions: the refractive index the laser
//! used against Edlén's equation. [`conformance`] checks the test itself
//! against ISO 230-2 (targets, runs, directions, spacing); its warnings come
//! first in [`Evaluation::warnings`].
//!
//! Pure: no I/O, no printing. All lengths in mm.

pub mod conformance;
pub mod environment;
pub mod outliers;
pub mod verdict;

use crate::error::Warning;
use crate::measurement::{Direction, Measurement};
pub use conformance::TestConformance;
pub use outliers::SuspectedOutlier;

/// Statistics of one target in one direction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DirectionStats {
    /// Number of readings n.
    pub n: usize,
    /// Mean positional deviation x̄, mm (`None` when n = 0).
    pub mean_mm: Option<f64>,
    /// Estimator of the standard uncertainty s, mm (`None` when n < 2).
    pub s_mm: Option<f64>,
}

impl DirectionStats {
    /// Mean and s of the readings (two-pass, for accuracy with offsets much larger than the scatter).
    pub fn of(values: &[f64]) -> DirectionStats {
        let n = values.len();
        if n == 0 {
            return DirectionStats::default();
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let s = (n >= 2).then(|| {
            let sum_sq: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
            (sum_sq / (n - 1) as f64).sqrt()
        });
        DirectionStats {
            n,
            mean_mm: Some(mean),
            s_mm: s,
        }
    }

    /// The band x̄ ± 2s used by A, as (low, high), mm.
    pub fn band(&self) -> Option<(f64, f64)> {
        let (mean, s) = (self.mean_mm?, self.s_mm?);
        Some((mean - 2.0 * s, mean + 2.0 * s))
    }

    /// The unidirectional repeatability R_i = 4 s_i.
    fn repeatability(&self) -> Option<f64> {
        self.s_mm.map(|s| 4.0 * s)
    }
}

/// Everything ISO 230-2 defines at one target.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetStats {
    /// Target P_i, mm.
    pub target_mm: f64,
    /// ↑ statistics.
    pub up: DirectionStats,
    /// ↓ statistics.
    pub down: DirectionStats,
    /// Mean bidirectional positional deviation x̄_i = (x̄_i↑ + x̄_i↓)/2, mm.
    pub mean_mm: Option<f64>,
    /// Reversal value B_i = x̄_i↑ − x̄_i↓, mm (signed).
    pub reversal_mm: Option<f64>,
    /// R_i↑ = 4 s_i↑, mm.
    pub repeatability_up_mm: Option<f64>,
    /// R_i↓ = 4 s_i↓, mm.
    pub repeatability_down_mm: Option<f64>,
    /// R_i = max(2 s_i↑ + 2 s_i↓ + |B_i|; R_i↑; R_i↓), mm.
    pub repeatability_mm: Option<f64>,
}

impl TargetStats {
    /// Statistics of one direction.
    pub fn direction(&self, direction: Direction) -> &DirectionStats {
        match direction {
            Direction::Up => &self.up,
            Direction::Down => &self.down,
        }
    }
}

/// The axis figures of ISO 230-2, mm; `None` where not evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisFigures {
    /// Bidirectional accuracy of positioning A.
    pub a_mm: Option<f64>,
    /// Unidirectional accuracy A↑.
    pub a_up_mm: Option<f64>,
    /// Unidirectional accuracy A↓.
    pub a_down_mm: Option<f64>,
    /// Bidirectional systematic positional deviation E.
    pub e_mm: Option<f64>,
    /// Unidirectional systematic positional deviation E↑.
    pub e_up_mm: Option<f64>,
    /// Unidirectional systematic positional deviation E↓.
    pub e_down_mm: Option<f64>,
    /// Mean bidirectional positional deviation M.
    pub m_mm: Option<f64>,
    /// Bidirectional repeatability R = max R_i.
    pub r_mm: Option<f64>,
    /// Unidirectional repeatability R↑ = max R_i↑.
    pub r_up_mm: Option<f64>,
    /// Unidirectional repeatability R↓ = max R_i↓.
    pub r_down_mm: Option<f64>,
    /// Reversal value B = max |B_i|.
    pub b_mm: Option<f64>,
    /// Mean reversal value B̄ = mean of B_i (signed).
    pub b_mean_mm: Option<f64>,
}

/// The result of evaluating a measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// Per-target statistics, in target order.
    pub per_target: Vec<TargetStats>,
    /// Axis figures.
    pub figures: AxisFigures,
    /// Number of ↑ runs.
    pub runs_up: usize,
    /// Number of ↓ runs.
    pub runs_down: usize,
    /// Runs that deviate from the others far more than the scatter; included in the figures.
    pub outliers: Vec<SuspectedOutlier>,
    /// The test against ISO 230-2's conditions (targets, runs, directions, spacing).
    pub conformance: TestConformance,
    /// Where the test falls short of ISO 230-2 ([`conformance`]), then what
    /// could not be evaluated, and why.
    pub warnings: Vec<Warning>,
}

impl Evaluation {
    /// The variance of one reading about its target's mean, pooled over
    /// every target and direction, s² = Σ (n − 1)·s_i² / Σ (n − 1), mm²;
    /// `None` without repeated runs. (Each target's own s rests on a handful
    /// of readings; where one σ serves the whole test, this is it.)
    pub fn pooled_variance_mm2(&self) -> Option<f64> {
        let (mut sum_sq, mut degrees) = (0.0, 0usize);
        for t in &self.per_target {
            for stats in [&t.up, &t.down] {
                if let Some(s) = stats.s_mm {
                    sum_sq += s * s * (stats.n - 1) as f64;
                    degrees += stats.n - 1;
                }
            }
        }
        (degrees > 0).then(|| sum_sq / degrees as f64)
    }
}

/// Evaluates a measurement per ISO 230-2.
///
/// # Example
/// ```
/// use axcomp::evaluate::evaluate;
/// use axcomp::measurement::{Direction, Measurement, Run};
/// let run = |direction, number, values: [f64; 2]| Run {
///     direction, number, start_time_s: None,
///     deviations_mm: values.iter().map(|v| Some(*v)).collect() };
/// let m = Measurement::new("X", vec![0.0, 100.0], vec![
///     run(Direction::Up, 1, [0.000, 0.004]), run(Direction::Down, 1, [-0.002, 0.002]),
///     run(Direction::Up, 2, [0.002, 0.006]), run(Direction::Down, 2, [0.000, 0.004]),
/// ], Default::default(), Default::default()).unwrap();
/// let e = evaluate(&m);
/// // x̄↑ = 1, 5 µm; x̄↓ = −1, 3 µm: B_i = 2 µm at both targets, E = 5 − (−1) = 6 µm.
/// assert!((e.figures.b_mm.unwrap() - 0.002).abs() < 1e-12);
/// assert!((e.figures.e_mm.unwrap() - 0.006).abs() < 1e-12);
/// ```
pub fn evaluate(measurement: &Measurement) -> Evaluation {
    let per_target = per_target_stats(measurement);
    let runs_up = measurement.run_count(Direction::Up);
    let runs_down = measurement.run_count(Direction::Down);
    let conformance = conformance::check_test(measurement);
    let mut warnings = conformance.warnings();
    warnings.extend(coverage_warnings(&per_target, runs_up, runs_down));
    Evaluation {
        conformance,
        figures: axis_figures(&per_target),
        outliers: outliers::suspected_outliers(measurement),
        per_target,
        runs_up,
        runs_down,
        warnings,
    }
}

fn per_target_stats(measurement: &Measurement) -> Vec<TargetStats> {
    let mut readings: Vec<f64> = Vec::with_capacity(measurement.runs().len());
    let mut stats_of = |target_index: usize, direction: Direction| {
        readings.clear();
        readings.extend(
            measurement
                .runs_in(direction)
                .filter_map(|run| run.deviations_mm[target_index]),
        );
        DirectionStats::of(&readings)
    };
    let mut per_target = Vec::with_capacity(measurement.targets_mm().len());
    for (index, &target_mm) in measurement.targets_mm().iter().enumerate() {
        let up = stats_of(index, Direction::Up);
        let down = stats_of(index, Direction::Down);
        per_target.push(target_stats(target_mm, up, down));
    }
    per_target
}

fn target_stats(target_mm: f64, up: DirectionStats, down: DirectionStats) -> TargetStats {
    let both_means = up.mean_mm.zip(down.mean_mm);
    let reversal_mm = both_means.map(|(u, d)| u - d);
    let repeatability_mm = match (up.s_mm, down.s_mm, reversal_mm) {
        (Some(s_up), Some(s_down), Some(b)) => Some(
            (2.0 * s_up + 2.0 * s_down + b.abs())
                .max(4.0 * s_up)
                .max(4.0 * s_down),
        ),
        _ => None,
    };
    TargetStats {
        target_mm,
        mean_mm: both_means.map(|(u, d)| (u + d) / 2.0),
        reversal_mm,
        repeatability_up_mm: up.repeatability(),
        repeatability_down_mm: down.repeatability(),
        repeatability_mm,
        up,
        down,
    }
}

/// Collects one value per target, or `None` if any target lacks it.
fn every_target<T>(
    per_target: &[TargetStats],
    value: impl Fn(&TargetStats) -> Option<T>,
) -> Option<Vec<T>> {
    per_target.iter().map(value).collect()
}

/// max(high) − min(low) over a set of (low, high) intervals.
fn span(intervals: impl IntoIterator<Item = (f64, f64)>) -> Option<f64> {
    let mut bounds: Option<(f64, f64)> = None;
    for (low, high) in intervals {
        bounds = Some(match bounds {
            None => (low, high),
            Some((lo, hi)) => (lo.min(low), hi.max(high)),
        });
    }
    bounds.map(|(lo, hi)| hi - lo)
}

fn max_of(values: Option<Vec<f64>>) -> Option<f64> {
    values?.into_iter().reduce(f64::max)
}

fn axis_figures(per_target: &[TargetStats]) -> AxisFigures {
    let points =
        |d: Direction| every_target(per_target, |t| t.direction(d).mean_mm.map(|m| (m, m)));
    let bands = |d: Direction| every_target(per_target, |t| t.direction(d).band());
    let pooled = |a: Option<Vec<(f64, f64)>>, b: Option<Vec<(f64, f64)>>| {
        let (a, b) = (a?, b?);
        span(a.into_iter().chain(b))
    };
    let reversals = every_target(per_target, |t| t.reversal_mm);
    AxisFigures {
        a_mm: pooled(bands(Direction::Up), bands(Direction::Down)),
        a_up_mm: bands(Direction::Up).and_then(span),
        a_down_mm: bands(Direction::Down).and_then(span),
        e_mm: pooled(points(Direction::Up), points(Direction::Down)),
        e_up_mm: points(Direction::Up).and_then(span),
        e_down_mm: points(Direction::Down).and_then(span),
        m_mm: every_target(per_target, |t| t.mean_mm.map(|m| (m, m))).and_then(span),
        r_mm: max_of(every_target(per_target, |t| t.repeatability_mm)),
        r_up_mm: max_of(every_target(per_target, |t| t.repeatability_up_mm)),
        r_down_mm: max_of(every_target(per_target, |t| t.repeatability_down_mm)),
        b_mm: max_of(
            reversals
                .clone()
                .map(|b| b.into_iter().map(f64::abs).collect()),
        ),
        b_mean_mm: reversals.map(|b| b.iter().sum::<f64>() / b.len() as f64),
    }
}

/// Says what is not evaluated and why: n = 1, or a target without enough
/// readings (one direction only is said by [`conformance`]).
fn coverage_warnings(per_target: &[TargetStats], runs_up: usize, runs_down: usize) -> Vec<Warning> {
    let mut warnings = Vec::new();
    let measured: Vec<Direction> = Direction::BOTH
        .into_iter()
        .filter(|d| match d {
            Direction::Up => runs_up > 0,
            Direction::Down => runs_down > 0,
        })
        .collect();
    for direction in measured {
        let most_readings = per_target
            .iter()
            .map(|t| t.direction(direction).n)
            .max()
            .unwrap_or(0);
        if most_readings == 1 {
            warnings.push(Warning::SingleRun { direction });
            continue;
        }
        for target in per_target {
            let missing = match target.direction(direction).n {
                0 => format!("{direction} reading"),
                1 => format!("second {direction} reading (s{direction} needs n ≥ 2)"),
                _ => continue,
            };
            warnings.push(Warning::TargetNotEvaluated {
                target_mm: target.target_mm,
                missing,
            });
        }
    }
    warnings
}

#[cfg(test)]
mod tests;
