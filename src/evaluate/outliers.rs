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

use crate::measurement::{Direction, Measurement};

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
    /// The target where it differs most, mm.
    pub worst_target_mm: f64,
    /// Its deviation there minus the mean of the other runs, mm.
    pub offset_mm: f64,
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
    let runs: Vec<_> = measurement.runs_in(direction).collect();
    if runs.len() < 3 {
        return Vec::new();
    }
    let targets = measurement.targets_mm();
    // Per target: sum, sum of squares and count over all runs, so that the
    // statistics without run j are a subtraction away.
    let mut sum = vec![0.0; targets.len()];
    let mut count = vec![0usize; targets.len()];
    for run in &runs {
        for (i, value) in run.deviations_mm.iter().enumerate() {
            if let Some(v) = value {
                sum[i] += v;
                count[i] += 1;
            }
        }
    }
    let mut scores = Vec::with_capacity(runs.len());
    for (run_index, run) in runs.iter().enumerate() {
        // The other runs' readings, in their order (sliced once: this loop
        // visits every reading of every other run).
        let other_runs: Vec<&[Option<f64>]> = runs
            .iter()
            .enumerate()
            .filter(|(other_index, _)| *other_index != run_index)
            .map(|(_, other)| other.deviations_mm.as_slice())
            .collect();
        // Pooled variance of the other runs, two-pass for accuracy.
        let mut sum_sq = 0.0;
        let mut degrees = 0usize;
        for (i, own) in run.deviations_mm.iter().enumerate() {
            let others = count[i] - usize::from(own.is_some());
            if others < 2 {
                continue;
            }
            let mean_others = (sum[i] - own.unwrap_or(0.0)) / others as f64;
            for other in &other_runs {
                if let Some(v) = other[i] {
                    sum_sq += (v - mean_others) * (v - mean_others);
                }
            }
            degrees += others - 1;
        }
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
        for (i, own) in run.deviations_mm.iter().enumerate() {
            let (Some(own), others) = (own, count[i] - usize::from(own.is_some())) else {
                continue;
            };
            if others < 2 {
                continue;
            }
            let offset = own - (sum[i] - own) / others as f64;
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
                worst_target_mm: targets[i],
                offset_mm: offset,
            });
        }
    }
    scores
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
                deviations_mm: values.iter().map(|v| Some(*v)).collect(),
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
        assert_eq!((flagged[0].run, flagged[0].worst_target_mm), (1, 1.0));
        // Offset at target 2: 0.021 − mean(0, 0.001, −0.001, 0) = 0.021.
        assert!((flagged[0].offset_mm - 0.021).abs() < 1e-12);
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
