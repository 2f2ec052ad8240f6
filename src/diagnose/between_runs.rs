//! Structure between runs: drift and outlier runs, fitted on the readings
//! with one free level per cell (target × direction), and the reversal, tested
//! on those cell levels. No position-dependent error can pose as one of them:
//! every cell has its own level.

use super::fit::{self, Design, Fit, bic, leave_one_run_out_rmse};
use super::stats::{chi2_p, partial_f_p};
use super::{
    Cell, Chosen, Evidence, Kind, LACK_OF_FIT_P, Level, Problem, RejectedEffect, Shape, best_of,
    predicts_better, set_rejection, shapes, strong_evidence,
};
use crate::diagnose::along_axis::target_levels;
use nalgebra::{DMatrix, DVector};

use crate::measurement::{Direction, Run};

/// The reversal found between the directions, from the cell levels.
#[derive(Clone, Copy, Debug)]
pub(super) struct ReversalFit {
    pub(super) b_um: f64,
    pub(super) standard_error_um: f64,
    pub(super) evidence: Evidence,
}

/// Forward selection of drift and outlier runs on the readings, one level per cell.
pub(super) fn select_between_runs(
    problem: &Problem,
    y: &[f64],
    kinds: &[Kind],
    rejected: &mut Vec<RejectedEffect>,
) -> (Vec<Chosen>, Fit) {
    let n = y.len();
    let mut chosen: Vec<Chosen> = Vec::new();
    let mut model = problem.cell_design.clone();
    let mut model_fit = fit::fit(&model, y, None);
    let runs = runs_of(problem);
    loop {
        let mut candidates: Vec<(Shape, usize, f64, Fit)> = Vec::new();
        for &kind in kinds
            .iter()
            .filter(|k| matches!(k, Kind::Drift | Kind::OutlierRun))
        {
            if kind != Kind::OutlierRun && chosen.iter().any(|c| c.shape.kind() == kind) {
                continue;
            }
            let shapes = shapes(kind, &problem.targets_mm, None, &runs, &chosen);
            let Some((shape, rss, trial_fit)) = best_of(&shapes, None, |shape| {
                let f = fit::fit(&model.with(&problem.columns(shape)), y, None);
                (f.rss, f)
            }) else {
                continue;
            };
            let added = trial_fit.rank.saturating_sub(model_fit.rank).max(1);
            let look_elsewhere = if shapes.len() > 1 {
                2.0 * (shapes.len() as f64).ln()
            } else {
                0.0
            };
            let delta = bic(rss, n, model_fit.rank + added) - bic(model_fit.rss, n, model_fit.rank)
                + look_elsewhere;
            candidates.push((shape, shapes.len(), delta, trial_fit));
        }
        candidates.sort_by(|a, b| a.2.total_cmp(&b.2));
        let cv_without = leave_one_run_out_rmse(&model, y, &problem.run_of(), problem.run_count);
        let mut accepted = None;
        for (shape, trials, delta, trial_fit) in candidates {
            if !strong_evidence(rejected, shape.kind(), delta) {
                continue;
            }
            let with = model.with(&problem.columns(shape));
            let cv_with = leave_one_run_out_rmse(&with, y, &problem.run_of(), problem.run_count);
            if !predicts_better(rejected, shape.kind(), cv_with, cv_without) {
                continue;
            }
            let evidence = Evidence {
                delta_bic: delta,
                trials,
                p_value: partial_f_p(
                    model_fit.rss,
                    trial_fit.rss,
                    with.parameters() - model.parameters(),
                    n,
                    trial_fit.rank,
                ),
                cv_rmse_without_um: cv_without,
                cv_rmse_with_um: cv_with,
            };
            accepted = Some((
                Chosen {
                    shape,
                    first_column: model.parameters(),
                    evidence,
                },
                with,
                trial_fit,
            ));
            break;
        }
        let Some((c, with, with_fit)) = accepted else {
            break;
        };
        rejected.retain(|r| r.kind != c.shape.kind());
        chosen.push(c);
        model = with;
        model_fit = with_fit;
    }
    (chosen, model_fit)
}

/// The runs as the readings name them (direction, number), in order.
fn runs_of(problem: &Problem) -> Vec<Run> {
    let mut runs: Vec<Run> = Vec::new();
    for r in &problem.readings {
        if !runs
            .iter()
            .any(|run| run.direction == r.direction && run.number == r.run)
        {
            runs.push(Run {
                direction: r.direction,
                number: r.run,
                start_time_s: None,
                deviations_mm: Vec::new(),
            });
        }
    }
    runs
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
            value_um: fitted.coefficients[c],
            variance_um2: fitted.standard_errors[c].powi(2),
            reversal_prediction_variance_um2: problem.reversal_prediction_variance_um2(*t) / 2.0,
        })
        .collect()
}

/// The per-target difference ↑ − ↓ of the cell levels and its variance.
pub(super) fn reversals(cells: &[Cell]) -> Vec<(usize, f64, f64)> {
    let mut list = Vec::new();
    for up in cells.iter().filter(|c| c.direction == Direction::Up) {
        if let Some(down) = cells
            .iter()
            .find(|c| c.direction == Direction::Down && c.target_index == up.target_index)
        {
            list.push((
                up.target_index,
                up.value_um - down.value_um,
                up.variance_um2
                    + down.variance_um2
                    + up.reversal_prediction_variance_um2
                    + down.reversal_prediction_variance_um2,
            ));
        }
    }
    list
}

/// The generalised-least-squares mean of the per-target reversals, its
/// standard error, and χ² about 0 and about the mean. The covariance is each
/// difference's own variance on the diagonal plus, off it, what two targets
/// share through the predicted reversal: both interpolate the same targets of
/// the first test (C = diag(v) + the off-diagonal part of W R Wᵀ). Without
/// the shared part a dense re-test would count the few reversals of the
/// first test as many independent ones.
fn constant_reversal(problem: &Problem, differences: &[(usize, f64, f64)]) -> (f64, f64, f64, f64) {
    let m = differences.len();
    let covariance = DMatrix::from_fn(m, m, |a, b| {
        if a == b {
            differences[a].2.max(1e-300)
        } else {
            problem.shared_reversal_variance_um2(differences[a].0, differences[b].0)
        }
    });
    let d = DVector::from_iterator(m, differences.iter().map(|(_, d, _)| *d));
    let ones = DVector::from_element(m, 1.0);
    let Some(cholesky) = covariance.cholesky() else {
        // Not positive definite only if the variances are degenerate: treat them as independent.
        return independent_constant_reversal(differences);
    };
    let inverse_d = cholesky.solve(&d);
    let inverse_ones = cholesky.solve(&ones);
    let weight = ones.dot(&inverse_ones);
    let mean = ones.dot(&inverse_d) / weight;
    let about_zero = d.dot(&inverse_d);
    let residual = &d - &ones * mean;
    let about_mean = residual.dot(&cholesky.solve(&residual));
    (mean, (1.0 / weight).sqrt(), about_zero, about_mean)
}

/// [`constant_reversal`] with independent differences: the weighted mean.
fn independent_constant_reversal(differences: &[(usize, f64, f64)]) -> (f64, f64, f64, f64) {
    let weight: f64 = differences
        .iter()
        .map(|(_, _, v)| 1.0 / v.max(1e-300))
        .sum();
    let mean = differences
        .iter()
        .map(|(_, d, v)| d / v.max(1e-300))
        .sum::<f64>()
        / weight;
    let about_zero: f64 = differences
        .iter()
        .map(|(_, d, v)| d * d / v.max(1e-300))
        .sum();
    let about_mean: f64 = differences
        .iter()
        .map(|(_, d, v)| (d - mean).powi(2) / v.max(1e-300))
        .sum();
    (mean, (1.0 / weight).sqrt(), about_zero, about_mean)
}

/// Accepts a reversal if the directions differ by the same B at every target
/// (χ² with the cells' known variances), it predicts held-out runs better, and
/// it leaves no direction-dependent structure; returns it with the lack-of-fit
/// p-value of the direction-dependent structure that is left.
pub(super) fn select_reversal(
    problem: &Problem,
    cells: &[Cell],
    folds: &[Fold],
    kinds: &[Kind],
    rejected: &mut Vec<RejectedEffect>,
) -> (Option<ReversalFit>, f64) {
    let differences = reversals(cells);
    if differences.is_empty() {
        return (None, 1.0);
    }
    let (b, standard_error, about_zero, about_mean) = constant_reversal(problem, &differences);
    let m = differences.len();
    let p_without = chi2_p(about_zero, m);
    if !kinds.contains(&Kind::Reversal) {
        return (None, p_without);
    }
    let delta = about_mean - about_zero + (m as f64).ln();
    if !strong_evidence(rejected, Kind::Reversal, delta) {
        return (None, p_without);
    }
    let p_with = chi2_p(about_mean, m - 1);
    if p_with < LACK_OF_FIT_P {
        let (lowest, highest) = differences
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, d, _)| {
                (lo.min(*d), hi.max(*d))
            });
        set_rejection(
            rejected,
            Kind::Reversal,
            format!(
                "the directions differ, but not by one B: the reversal changes along the axis from {lowest:.2} to {highest:.2} µm (p = {p_with:.1e}); it is reported as unexplained structure"
            ),
        );
        return (None, p_without);
    }
    let cv = |with: bool| {
        let (mut sum, mut count) = (0.0, 0usize);
        for fold in folds {
            let b_fold = if with {
                constant_reversal(problem, &reversals(&fold.cells)).0
            } else {
                0.0
            };
            for (target, direction, value) in &fold.held_out {
                let Some(level) = fold.levels.iter().find(|l| l.target_index == *target) else {
                    continue;
                };
                let half = direction.reversal_share(b_fold);
                sum += (value - level.value_um - half).powi(2);
                count += 1;
            }
        }
        if count == 0 {
            0.0
        } else {
            (sum / count as f64).sqrt()
        }
    };
    let (cv_without, cv_with) = (cv(false), cv(true));
    if !predicts_better(rejected, Kind::Reversal, cv_with, cv_without) {
        return (None, p_without);
    }
    let evidence = Evidence {
        delta_bic: delta,
        trials: 1,
        p_value: chi2_p(about_zero - about_mean, 1),
        cv_rmse_without_um: cv_without,
        cv_rmse_with_um: cv_with,
    };
    (
        Some(ReversalFit {
            b_um: b,
            standard_error_um: standard_error,
            evidence,
        }),
        p_with,
    )
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
        let held: Vec<(usize, Direction, f64)> = (0..y.len())
            .filter(|&i| run_of[i] == held_out)
            .map(|i| {
                let effects: f64 = between
                    .iter()
                    .map(|c| problem.contribution(c, &fitted.coefficients, i))
                    .sum();
                let r = &problem.readings[i];
                (r.target_index, r.direction, y[i] - effects)
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
