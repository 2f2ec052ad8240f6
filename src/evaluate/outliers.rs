//! Suspected outlier runs: a run that deviates from the others by far more than the scatter.
//!
//! `../shared/spec/iso230-2.md` ("Edge cases"): the first run after start-up
//! often differs; flag it with its score, keep it in the figures unless the
//! user excludes it.
//!
//! Method (leave one run out, per direction with at least 3 runs): for run j,
//! at each target i, compare x_ij with the mean of the other runs x̄_i(−j).
//! Under the hypothesis that all runs scatter alike, that difference has the
//! standard deviation σ·√(1 + 1/(n_i − 1)); σ is estimated by the standard
//! deviation of the *other* runs, pooled over all targets, so the run under
//! test cannot hide itself by inflating it. The run's score is the largest
//! |difference| / that standard deviation over its targets. A score above
//! [`OUTLIER_SCORE`] flags the run. Under the hypothesis the score is a
//! maximum of Student-t variables with m(n − 2) degrees of freedom; with 5
//! targets × 5 runs the chance that a clean run exceeds 5 is below 0.5 %.
//!
//! When the other runs agree exactly (quantised data, pooled s = 0) there is no
//! scatter to compare with and the run gets no score.

use crate::measurement::{AxisKind, ByKind, Direction, Measurement};
use crate::units::{Deg, Mm};

/// Score above which a run is flagged.
pub const OUTLIER_SCORE: f64 = 5.0;

/// A run flagged as a suspected outlier.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SuspectedOutlier {
    /// ↑ or ↓.
    pub direction: Direction,
    /// Run number within its direction.
    pub run: u32,
    /// Largest standardised difference from the other runs.
    pub score: f64,
    /// The target where it differs most, in the axis' unit (mm, or ° on a
    /// rotary axis: [`SuspectedOutlier::typed`]).
    pub worst_target: f64,
    /// Its deviation there minus the mean of the other runs, in the axis' unit.
    pub offset: f64,
}

impl SuspectedOutlier {
    /// The flagged run with its position and offset typed by the axis' kind.
    pub fn typed(&self, kind: AxisKind) -> ByKind<OutlierIn<Mm>, OutlierIn<Deg>> {
        match kind {
            AxisKind::Linear => ByKind::Linear(self.in_unit(Mm)),
            AxisKind::Rotary => ByKind::Rotary(self.in_unit(Deg)),
        }
    }

    fn in_unit<U>(&self, unit: fn(f64) -> U) -> OutlierIn<U> {
        OutlierIn {
            direction: self.direction,
            run: self.run,
            score: self.score,
            worst_target: unit(self.worst_target),
            offset: unit(self.offset),
        }
    }
}

/// A flagged run with its unit as a type: the position in `P` (`Mm` or
/// `Deg`), the offset in `D` (the axis' unit or the reported one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutlierIn<P, D = P> {
    /// ↑ or ↓.
    pub direction: Direction,
    /// Run number within its direction.
    pub run: u32,
    /// Largest standardised difference from the other runs.
    pub score: f64,
    /// The target where it differs most.
    pub worst_target: P,
    /// Its deviation there minus the mean of the other runs.
    pub offset: D,
}

impl<P, D> OutlierIn<P, D> {
    /// The same with the offset converted by `convert` (`Mm::to_um`, …).
    pub fn map_offset<E>(self, convert: fn(D) -> E) -> OutlierIn<P, E> {
        OutlierIn {
            direction: self.direction,
            run: self.run,
            score: self.score,
            worst_target: self.worst_target,
            offset: convert(self.offset),
        }
    }
}

/// Scores every run of every direction with at least 3 runs; returns the flagged ones.
pub fn suspected_outliers(measurement: &Measurement) -> Vec<SuspectedOutlier> {
    let mut flagged = Vec::new();
    for direction in Direction::BOTH {
        for score in run_scores(measurement, direction) {
            if score.score > OUTLIER_SCORE {
                flagged.push(score);
            }
        }
    }
    flagged
}

/// The score of every run in one direction (empty with fewer than 3 runs).
pub fn run_scores(measurement: &Measurement, direction: Direction) -> Vec<SuspectedOutlier> {
    let runs: Vec<&[Option<f64>]> = measurement
        .runs_in(direction)
        .map(|run| run.deviations.as_slice())
        .collect();
    if runs.len() < 3 {
        return Vec::new();
    }
    let targets = measurement.targets();
    let totals = TargetTotals::of(&runs, targets.len());
    let pooled = pooled_squares(&runs, &totals);
    let mut scores = Vec::with_capacity(runs.len());
    for ((j, run), (sum_sq, degrees)) in measurement.runs_in(direction).enumerate().zip(pooled) {
        if degrees == 0 || sum_sq <= 0.0 {
            continue;
        }
        let sigma = (sum_sq / degrees as f64).sqrt();
        // The standard deviation of a difference depends on the target only
        // through its number of other readings: worked out once per number.
        let difference_sd: Vec<f64> = (0..runs.len())
            .map(|others| sigma * (1.0 + 1.0 / others as f64).sqrt())
            .collect();
        let mut worst: Option<(f64, usize, f64)> = None;
        for (i, own) in runs[j].iter().enumerate() {
            let (Some(own), others) = (own, totals.others(i, own)) else {
                continue;
            };
            if others < 2 {
                continue;
            }
            let offset = own - (totals.sum[i] - own) / others as f64;
            let z = offset.abs() / difference_sd[others];
            if worst.is_none_or(|(best, _, _)| z > best) {
                worst = Some((z, i, offset));
            }
        }
        if let Some((score, i, offset)) = worst {
            scores.push(SuspectedOutlier {
                direction,
                run: run.number,
                score,
                worst_target: targets[i],
                offset,
            });
        }
    }
    scores
}

/// Per target, the sum and the number of the readings of all runs, so that
/// the mean without one run is a subtraction away.
struct TargetTotals {
    sum: Vec<f64>,
    count: Vec<usize>,
}

impl TargetTotals {
    fn of(runs: &[&[Option<f64>]], targets: usize) -> TargetTotals {
        let mut sum = vec![0.0; targets];
        let mut count = vec![0usize; targets];
        for run in runs {
            for (i, value) in run.iter().enumerate() {
                if let Some(v) = value {
                    sum[i] += v;
                    count[i] += 1;
                }
            }
        }
        TargetTotals { sum, count }
    }

    /// The number of readings at target `i` besides a run's `own`.
    fn others(&self, i: usize, own: &Option<f64>) -> usize {
        self.count[i] - usize::from(own.is_some())
    }
}

/// Per run, the pooled squares of the other runs about their mean at each
/// target (two-pass, for accuracy) and their degrees of freedom.
///
/// Every run's sums go over the targets, and at each over the other runs in
/// order, as when one run is scored at a time (so to the bit the same
/// figures); they are made side by side in one pass over the targets, as
/// independent sums rather than one long chain of additions per run (a
/// large test has ten thousand targets). Each target's readings are first
/// copied into one small column, run by run: the sums then read it rather
/// than a reading of every run's slice, checked against its length, for
/// each pair of runs.
fn pooled_squares(runs: &[&[Option<f64>]], totals: &TargetTotals) -> Vec<(f64, usize)> {
    let mut pooled = vec![(0.0, 0usize); runs.len()];
    let mut column: Vec<Option<f64>> = vec![None; runs.len()];
    for (i, sum) in totals.sum.iter().enumerate() {
        for (reading, run) in column.iter_mut().zip(runs) {
            *reading = run[i];
        }
        for (j, ((sum_sq, degrees), own)) in pooled.iter_mut().zip(&column).enumerate() {
            let others = totals.others(i, own);
            if others < 2 {
                continue;
            }
            let mean_others = (sum - own.unwrap_or(0.0)) / others as f64;
            // Summed in a local: through `sum_sq` each addition waited for
            // the store of the one before.
            let mut squares = *sum_sq;
            for (k, other) in column.iter().enumerate() {
                if k != j
                    && let Some(v) = other
                {
                    squares += (v - mean_others) * (v - mean_others);
                }
            }
            *sum_sq = squares;
            *degrees += others - 1;
        }
    }
    pooled
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::Run;

    fn measurement(up_runs: &[[f64; 3]]) -> Measurement {
        let runs = up_runs
            .iter()
            .enumerate()
            .map(|(j, values)| Run {
                direction: Direction::Up,
                number: j as u32 + 1,
                start_time_s: None,
                deviations: values.iter().map(|v| Some(*v)).collect(),
            })
            .collect();
        Measurement::new(
            "X",
            vec![0.0, 1.0, 2.0],
            runs,
            Default::default(),
            Default::default(),
        )
        .unwrap()
    }

    #[test]
    fn an_offset_first_run_is_flagged_by_hand() {
        // Runs 2–5 scatter ±1 µm; run 1 sits 20 µm high at target 2.
        let m = measurement(&[
            [0.001, 0.021, 0.000],
            [0.001, 0.000, 0.000],
            [-0.001, 0.001, 0.001],
            [0.000, -0.001, -0.001],
            [0.000, 0.000, 0.000],
        ]);
        let flagged = suspected_outliers(&m);
        assert_eq!(flagged.len(), 1);
        assert_eq!((flagged[0].run, flagged[0].worst_target), (1, 1.0));
        // Offset at target 2: 0.021 − mean(0, 0.001, −0.001, 0) = 0.021.
        assert!((flagged[0].offset - 0.021).abs() < 1e-12);
        // Pooled s of runs 2–5 by hand: per-target sums of squares 2e-6, 2e-6,
        // 2e-6 with 3 degrees of freedom each: s² = 6e-6/9, s = 0.8165e-3.
        // Score = 0.021 / (0.8165e-3 · √(1 + 1/4)) = 23.0.
        assert!(
            (flagged[0].score - 23.0).abs() < 0.05,
            "{}",
            flagged[0].score
        );
    }

    #[test]
    fn clean_runs_and_too_few_runs_are_not_flagged() {
        let clean = measurement(&[
            [0.001, 0.0, 0.0],
            [0.0, 0.001, 0.0],
            [0.0, 0.0, 0.001],
            [-0.001, 0.0, 0.0],
        ]);
        assert!(suspected_outliers(&clean).is_empty());
        let two = measurement(&[[0.0, 0.0, 0.0], [0.1, 0.1, 0.1]]);
        assert!(run_scores(&two, Direction::Up).is_empty());
    }

    /// The pooled squares as the method states them, one run at a time (as
    /// `run_scores` first made them): what `pooled_squares` must give, to the bit.
    fn pooled_squares_one_run_at_a_time(
        runs: &[&[Option<f64>]],
        totals: &TargetTotals,
    ) -> Vec<(f64, usize)> {
        let mut pooled = Vec::new();
        for (j, run) in runs.iter().enumerate() {
            let mut sum_sq = 0.0;
            let mut degrees = 0usize;
            for (i, own) in run.iter().enumerate() {
                let others = totals.others(i, own);
                if others < 2 {
                    continue;
                }
                let mean_others = (totals.sum[i] - own.unwrap_or(0.0)) / others as f64;
                let other_runs = runs.iter().enumerate().filter(|(k, _)| *k != j);
                for v in other_runs.filter_map(|(_, other)| other[i]) {
                    sum_sq += (v - mean_others) * (v - mean_others);
                }
                degrees += others - 1;
            }
            pooled.push((sum_sq, degrees));
        }
        pooled
    }

    proptest::proptest! {
        /// Pooling every run's squares in one pass changes no bit: runs of
        /// 3 to 6, readings missing here and there, an outlier or not.
        #[test]
        fn pooled_squares_are_those_of_one_run_at_a_time(
            mut readings in proptest::collection::vec(
                proptest::collection::vec(proptest::option::weighted(0.9, -0.01f64..0.01), 7),
                3..7,
            ),
            outlier in proptest::option::of((0usize..6, 0usize..7, 0.01f64..0.1)),
        ) {
            if let Some((run, target, size)) = outlier {
                let count = readings.len();
                readings[run % count][target] = Some(size);
            }
            let runs: Vec<&[Option<f64>]> = readings.iter().map(Vec::as_slice).collect();
            let totals = TargetTotals::of(&runs, 7);
            let bits = |pooled: Vec<(f64, usize)>| -> Vec<(u64, usize)> {
                pooled.into_iter().map(|(sum_sq, degrees)| (sum_sq.to_bits(), degrees)).collect()
            };
            proptest::prop_assert_eq!(
                bits(pooled_squares(&runs, &totals)),
                bits(pooled_squares_one_run_at_a_time(&runs, &totals))
            );
        }
    }

    #[test]
    fn identical_other_runs_give_no_score() {
        let quantised = measurement(&[
            [0.005, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
        ]);
        let scores = run_scores(&quantised, Direction::Up);
        assert!(scores.iter().all(|s| s.run != 1));
    }
}
