//! Levels of the residual: per cell (target × direction) from the
//! between-runs fit, per target (both directions pooled), and the same for
//! each run held out (the folds of the cross-validation). Targets are in the
//! axis' unit (mm, or ° on a rotary axis), levels in µm (m°), variances in
//! their squares.

use super::fit::{self, Design, Fit};
use super::problem::Problem;
use super::selection::Chosen;
use crate::measurement::Direction;

/// A cell level of the between-runs fit: one target in one direction.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cell {
    pub(super) target_index: usize,
    pub(super) direction: Direction,
    /// The level, µm (m°).
    pub(super) value: f64,
    /// Variance of the level from the re-test's scatter, µm² (m°²).
    pub(super) variance: f64,
    /// This cell's half of the variance of the predicted reversal at its
    /// target (the first test's x̄↑ − x̄↓, interpolated), µm² (m°²): a reversal
    /// found is the change since the first test, uncertain by both tests.
    pub(super) reversal_prediction_variance: f64,
}

/// One per-target level (both directions pooled): the position-dependent part.
#[derive(Clone, Copy, Debug)]
pub(super) struct Level {
    pub(super) target_index: usize,
    /// The target, mm (°).
    pub(super) target: f64,
    /// The level, µm (m°).
    pub(super) value: f64,
    /// Variance of the level from the re-test's scatter alone, µm² (m°²).
    pub(super) scatter_variance: f64,
    /// Its total variance, scatter plus prediction, µm² (m°²).
    pub(super) variance: f64,
}

/// The cell levels of a between-runs fit, with their variance from the scatter.
pub(super) fn cell_levels(problem: &Problem, fitted: &Fit) -> Vec<Cell> {
    problem
        .cells
        .iter()
        .enumerate()
        .map(|(c, (t, d))| Cell {
            target_index: *t,
            direction: *d,
            value: fitted.coefficients[c],
            variance: fitted.standard_errors[c].powi(2),
            reversal_prediction_variance: problem.reversal_prediction_variance(*t) / 2.0,
        })
        .collect()
}

/// The per-target difference ↑ − ↓ of the cell levels and its variance.
pub(super) fn reversals(cells: &[Cell]) -> Vec<(usize, f64, f64)> {
    let targets = cells.iter().map(|c| c.target_index + 1).max().unwrap_or(0);
    let mut down_at = vec![None; targets];
    for c in cells.iter().filter(|c| c.direction == Direction::Down) {
        down_at[c.target_index].get_or_insert(c);
    }
    let mut list = Vec::new();
    for up in cells.iter().filter(|c| c.direction == Direction::Up) {
        if let Some(down) = down_at[up.target_index] {
            list.push((
                up.target_index,
                up.value - down.value,
                up.variance
                    + down.variance
                    + up.reversal_prediction_variance
                    + down.reversal_prediction_variance,
            ));
        }
    }
    list
}

/// For each run held out: the cell and per-target levels fitted on the other
/// runs, and the held-out readings less the between-runs effects fitted without them.
pub(super) struct Fold {
    pub(super) cells: Vec<Cell>,
    pub(super) levels: Vec<Level>,
    pub(super) held_out: Vec<(usize, Direction, f64)>,
}

pub(super) fn cross_validation_folds(
    problem: &Problem,
    y: &[f64],
    between_model: &Design,
    between: &[Chosen],
) -> Vec<Fold> {
    let run_of = problem.run_of();
    let mut folds = Vec::new();
    for held_out in 0..problem.run_count {
        let training: Vec<bool> = run_of.iter().map(|&r| r != held_out).collect();
        if !training.iter().any(|t| *t) {
            continue;
        }
        let fitted = fit::fit(between_model, y, Some(&training));
        let cells = cell_levels(problem, &fitted);
        let levels = target_levels(problem, &cells);
        let effects = problem.between_runs(between, &fitted.coefficients);
        let held: Vec<(usize, Direction, f64)> = (0..y.len())
            .filter(|&i| run_of[i] == held_out)
            .map(|i| {
                let r = &problem.readings[i];
                (r.target_index, r.direction, y[i] - effects[i])
            })
            .collect();
        folds.push(Fold {
            cells,
            levels,
            held_out: held,
        });
    }
    folds
}

/// The per-target levels: both directions pooled (their mean), with the
/// variance of the scatter and of the prediction.
pub(super) fn target_levels(problem: &Problem, cells: &[Cell]) -> Vec<Level> {
    let mut at_target: Vec<Vec<&Cell>> = vec![Vec::new(); problem.targets.len()];
    for c in cells {
        at_target[c.target_index].push(c);
    }
    let mut levels = Vec::new();
    for (t, here) in at_target.iter().enumerate() {
        if here.is_empty() {
            continue;
        }
        let k = here.len() as f64;
        let value = here.iter().map(|c| c.value).sum::<f64>() / k;
        let scatter = here.iter().map(|c| c.variance).sum::<f64>() / (k * k);
        let prediction: f64 = problem.prediction_weights[t]
            .iter()
            .map(|(i, w)| w * w * problem.first_test_variance[*i])
            .sum();
        levels.push(Level {
            target_index: t,
            target: problem.targets[t],
            value,
            scatter_variance: scatter,
            variance: scatter + prediction,
        });
    }
    levels
}
