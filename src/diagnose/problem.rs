//! The problem a diagnosis solves: the re-test's readings, the prediction
//! at each and its covariance (from the first test's scatter), the times of
//! the readings, and the design of one level per cell.

use std::sync::Arc;

use super::fit::{Design, Groups};
use super::selection::Chosen;
use super::{DiagnoseError, DiagnoseInput};
use crate::compensate::retest::{
    Applied, BacklashRefusal, KnownError, predicted_deviation, with_scatter,
};
use crate::compensate::{CompensateError, interpolate_hold};
use crate::cycle;
use crate::effects::{Line, Reading, Shape, position_as_deviation, variance_as_deviation};
use crate::evaluate::{Evaluation, evaluate};
use crate::measurement::{AxisKind, Direction, Measurement};
use crate::together::{Input, Pairing, check_together};
use crate::units::DeviationUnit;

/// The readings with their prediction, as one table. Its positions are in
/// the axis' unit (mm, or ° on a rotary axis) and its deviations in the
/// diagnosis' (µm, or m°, 1/1000 °; variances in their square): the
/// statistics are the same arithmetic in either.
pub(super) struct Problem {
    pub(super) readings: Vec<Reading>,
    /// Each reading's deviation as measured.
    pub(super) measured: Vec<f64>,
    /// Each reading's deviation as predicted (0 without a first test).
    pub(super) predicted: Vec<f64>,
    /// The prediction at each target of the re-test interpolates the first
    /// test's means: (index into `first_test_variance`, weight) pairs.
    pub(super) prediction_weights: Vec<Vec<(usize, f64)>>,
    /// The predicted re-test as `predict` gives it on the measured line: the
    /// first test's readings with the predicted systematic error.
    pub(super) first_test_prediction: Option<Measurement>,
    /// The first test's targets that `prediction_weights` index (none without one).
    pub(super) first_test_positions: Vec<f64>,
    /// Variance of the first test's bidirectional mean at each of its targets.
    pub(super) first_test_variance: Vec<f64>,
    /// Variance of the first test's reversal x̄↑ − x̄↓ at each of its targets
    /// (which the prediction carries); 0 for a unidirectional test.
    pub(super) first_test_reversal_variance: Vec<f64>,
    pub(super) run_count: usize,
    /// Whether the reading times are the cycle model's, not the file's.
    pub(super) time_assumed: bool,
    /// One run's mean duration on the clock of the readings' `time_h`, h.
    pub(super) run_h: f64,
    /// The re-test's targets.
    pub(super) targets: Vec<f64>,
    /// Linear or rotary: the units above, and of what the diagnosis derives
    /// from them (mm and µm, or ° and m°).
    pub(super) kind: AxisKind,
    /// The unit its sentences say a deviation in (µm, ″ or µrad).
    pub(super) deviation: DeviationUnit,
    pub(super) angle_urad: Option<Vec<f64>>,
    /// The cells (target, direction) that have readings, in column order.
    pub(super) cells: Vec<(usize, Direction)>,
    /// One level per cell: the ISO 230-2 systematic model x̄_i↑, x̄_i↓.
    pub(super) cell_design: Design,
}

impl Problem {
    pub(super) fn first_target_mm(&self) -> f64 {
        self.targets[0]
    }

    /// Covariance of the predicted reversals at the re-test's targets `a` and
    /// `b`: what they share of the first test's reversals.
    pub(super) fn shared_reversal_variance(&self, a: usize, b: usize) -> f64 {
        self.prediction_weights[a]
            .iter()
            .flat_map(|(ka, wa)| {
                self.prediction_weights[b]
                    .iter()
                    .filter(move |(kb, _)| kb == ka)
                    .map(move |(_, wb)| wa * wb * self.first_test_reversal_variance[*ka])
            })
            .sum()
    }

    /// Variance of the predicted reversal at the re-test's target `t`:
    /// the first test's reversals through the spline weights (independent
    /// between the first test's targets).
    pub(super) fn reversal_prediction_variance(&self, t: usize) -> f64 {
        self.shared_reversal_variance(t, t)
    }

    /// What the effects need of the test besides a reading.
    pub(super) fn line(&self) -> Line<'_> {
        Line {
            first_target_mm: self.first_target_mm(),
            angle_urad: self.angle_urad.as_deref(),
            times_recorded: !self.time_assumed,
            run_h: self.run_h,
        }
    }

    pub(super) fn columns(&self, shape: Shape) -> Vec<Vec<f64>> {
        crate::effects::columns(shape, &self.readings, &self.line())
    }

    pub(super) fn run_of(&self) -> Vec<usize> {
        self.readings.iter().map(|r| r.run_index).collect()
    }

    /// What the between-runs effects (drift, outlier runs) add to each reading.
    pub(super) fn between_runs(&self, chosen: &[Chosen], coefficients: &[f64]) -> Vec<f64> {
        let mut sum = vec![0.0; self.readings.len()];
        for c in chosen {
            for (j, column) in self.columns(c.shape).iter().enumerate() {
                let coefficient = coefficients[c.first_column + j];
                for (s, v) in sum.iter_mut().zip(column) {
                    *s += v * coefficient;
                }
            }
        }
        sum
    }
}

/// Builds the readings, their prediction and its covariance, and the cells.
pub(super) fn problem(input: &DiagnoseInput<'_>) -> Result<(Problem, bool), DiagnoseError> {
    let after = input.after;
    let (times, time_assumed) = cycle::reading_times_h(after, input.timing);
    let first = match input.before {
        Some(before) => {
            // The doubts (machine names, units, ranges) are the caller's to
            // show: the CLI runs the same check with the file names.
            check_together(
                Pairing::BeforeAfter,
                &Input::measurement(before, "the first test"),
                &Input::measurement(after, "the re-test"),
            )?;
            let evaluation = evaluate(before);
            let known =
                KnownError::from_evaluation(&evaluation).ok_or(DiagnoseError::NoKnownError)?;
            Some((known, mean_variances(&evaluation)))
        }
        None if input.backlash_set => {
            return Err(CompensateError::Backlash(BacklashRefusal::NoMeasuredReversal).into());
        }
        None => None,
    };
    let applied = Applied::with_backlash(
        input.table,
        first.as_ref().map(|(known, _)| known),
        input.backlash_set,
    )
    .map_err(CompensateError::Backlash)?;
    let first_test_prediction = match (input.before, &first) {
        (Some(before), Some((known, _))) => Some(
            with_scatter(before, &evaluate(before), |i, direction| {
                predicted_deviation(known, applied, before.targets()[i], direction)
            })
            .map_err(|e| DiagnoseError::Internal(e.to_string()))?,
        ),
        _ => None,
    };
    let mut readings = Vec::new();
    let mut measured = Vec::new();
    let mut predicted = Vec::new();
    for (run_index, run) in after.runs().iter().enumerate() {
        for (target_index, (value, &target)) in
            run.deviations.iter().zip(after.targets()).enumerate()
        {
            let Some(value) = value else { continue };
            readings.push(Reading {
                target_index,
                target,
                direction: run.direction,
                run: run.number,
                run_index,
                time_h: times[run_index][target_index],
            });
            measured.push(position_as_deviation(after.kind(), *value));
            let at_reading = first.as_ref().map_or(0.0, |(known, _)| {
                position_as_deviation(
                    after.kind(),
                    predicted_deviation(known, applied, target, run.direction),
                )
            });
            predicted.push(at_reading);
        }
    }
    if readings.len() < 4 || after.runs().len() < 2 {
        return Err(DiagnoseError::TooFewReadings(readings.len()));
    }
    let (
        prediction_weights,
        first_test_positions,
        first_test_variance,
        first_test_reversal_variance,
    ) = match &first {
        Some((_, variances)) => (
            interpolation_weights(&variances.positions, after.targets()),
            variances.positions.clone(),
            variances.mean.clone(),
            variances.reversal.clone(),
        ),
        None => (
            vec![Vec::new(); after.targets().len()],
            Vec::new(),
            Vec::new(),
            Vec::new(),
        ),
    };
    // The cells in column order (target, then ↑ before ↓), and each reading's.
    let direction_index = |d: Direction| usize::from(d != Direction::BOTH[0]);
    let mut cell_of = vec![[None; 2]; after.targets().len()];
    for r in &readings {
        cell_of[r.target_index][direction_index(r.direction)] = Some(0);
    }
    let mut cells: Vec<(usize, Direction)> = Vec::new();
    for (t, here) in cell_of.iter_mut().enumerate() {
        for direction in Direction::BOTH {
            let slot = &mut here[direction_index(direction)];
            if slot.is_some() {
                *slot = Some(cells.len());
                cells.push((t, direction));
            }
        }
    }
    let cell_design = Design {
        groups: Some(Arc::new(Groups {
            of_row: readings
                .iter()
                .map(|r| cell_of[r.target_index][direction_index(r.direction)].unwrap_or(0))
                .collect(),
            count: cells.len(),
        })),
        columns: Vec::new(),
    };
    let angle_urad = input.angular.map(|profile| {
        after
            .targets()
            .iter()
            .map(|&x| interpolate_hold(&profile.positions_mm, &profile.angle_urad, x))
            .collect()
    });
    let problem = Problem {
        readings,
        measured,
        predicted,
        prediction_weights,
        first_test_prediction,
        first_test_positions,
        first_test_variance,
        first_test_reversal_variance,
        run_count: after.runs().len(),
        time_assumed,
        run_h: cycle::run_h(&times),
        targets: after.targets().to_vec(),
        kind: after.kind(),
        deviation: after.kind().deviation_unit(input.angle),
        angle_urad,
        cells,
        cell_design,
    };
    Ok((problem, time_assumed))
}

/// The first test's uncertainty, per target where it has a mean.
pub(super) struct FirstTestVariances {
    /// The targets, mm (° on a rotary axis).
    pub(super) positions: Vec<f64>,
    /// Variance of the bidirectional mean, µm² (m°²).
    pub(super) mean: Vec<f64>,
    /// Variance of the reversal x̄↑ − x̄↓, µm² (m°²).
    pub(super) reversal: Vec<f64>,
}

/// Variance of the first test's means at each of its targets, µm²: of the
/// bidirectional mean σ²·(1/n↑ + 1/n↓)/4 and of the reversal σ²·(1/n↑ + 1/n↓),
/// or, for a unidirectional test, of its one direction's mean σ²/n and no
/// reversal; σ pooled over all targets and directions (each target's own s
/// rests on a handful of readings and would make the weights as noisy as the
/// data). The targets are those of `KnownError::from_evaluation`.
pub(super) fn mean_variances(evaluation: &Evaluation) -> FirstTestVariances {
    let both = evaluation.runs_up > 0 && evaluation.runs_down > 0;
    let pooled = evaluation.pooled_variance().map_or(0.0, |variance| {
        variance_as_deviation(evaluation.kind(), variance)
    });
    let inverse = |n: usize| if n == 0 { 0.0 } else { 1.0 / n as f64 };
    let mut variances = FirstTestVariances {
        positions: Vec::new(),
        mean: Vec::new(),
        reversal: Vec::new(),
    };
    for t in &evaluation.per_target {
        let has_mean = if both {
            t.mean.is_some()
        } else {
            t.up.mean.or(t.down.mean).is_some()
        };
        if !has_mean {
            continue;
        }
        let sum_of_inverses = inverse(t.up.n) + inverse(t.down.n);
        variances.positions.push(t.target);
        if both {
            variances.mean.push(pooled * sum_of_inverses / 4.0);
            variances.reversal.push(pooled * sum_of_inverses);
        } else {
            variances.mean.push(pooled * sum_of_inverses);
            variances.reversal.push(0.0);
        }
    }
    variances
}

/// The weights with which the prediction at each of `points` combines the
/// first test's means: rows of the not-a-knot spline basis (as
/// `KnownError::at` interpolates), as (index, weight) pairs.
pub(super) fn interpolation_weights(positions: &[f64], points: &[f64]) -> Vec<Vec<(usize, f64)>> {
    crate::spline::basis_rows(positions, points)
}
