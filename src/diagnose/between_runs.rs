//! Structure between runs: drift and outlier runs, fitted on the readings
//! with one free level per cell (target × direction), and the reversal, tested
//! on those cell levels. No position-dependent error can pose as one of them:
//! every cell has its own level.

use super::covariance::Covariance;
use super::fit::{self, Design, Fit, bic, leave_one_run_out_rmse};
use super::gates::{predicts_better, set_rejection, strong_evidence};
use super::levels::{Cell, Fold, reversals};
use super::problem::Problem;
use super::selection::{Chosen, Search, ShapeSet, forward_selection, shapes};
use super::stats::{chi2_p, partial_f_p};
use super::{Evidence, Kind, LACK_OF_FIT_P, RejectedEffect, Shape};

use crate::effects::deviation_text;
use crate::measurement::Run;
use crate::units::DeviationUnit;

/// The reversal found between the directions, from the cell levels.
#[derive(Clone, Copy, Debug)]
pub(super) struct ReversalFit {
    /// B (↑ − ↓), µm (m° on a rotary axis).
    pub(super) b: f64,
    /// Its standard error, in the same unit.
    pub(super) standard_error: f64,
    pub(super) evidence: Evidence,
}

/// Forward selection of drift and outlier runs on the readings, one level per cell.
pub(super) fn select_between_runs(
    problem: &Problem,
    y: &[f64],
    kinds: &[Kind],
    rejected: &mut Vec<RejectedEffect>,
) -> (Vec<Chosen>, Fit) {
    let search = BetweenRuns {
        problem,
        y,
        runs: runs_of(problem),
    };
    forward_selection(&search, problem.cell_design.clone(), kinds, rejected)
}

/// The search between runs: least squares on the readings, judged by the
/// residual sum of squares.
struct BetweenRuns<'a> {
    problem: &'a Problem,
    y: &'a [f64],
    runs: Vec<Run>,
}

impl Search for BetweenRuns<'_> {
    type Fit = Fit;

    /// Drift once; outlier runs as many as there are.
    fn tries(&self, kind: Kind, chosen: &[Chosen]) -> bool {
        match kind {
            Kind::OutlierRun => true,
            Kind::Drift => !chosen.iter().any(|c| c.shape.kind() == kind),
            _ => false,
        }
    }

    fn shape_sets(&self, kind: Kind, chosen: &[Chosen]) -> Vec<ShapeSet> {
        vec![ShapeSet::each(shapes(kind, &self.runs, chosen))]
    }

    fn deviation(&self) -> DeviationUnit {
        self.problem.deviation
    }

    fn columns(&self, shape: Shape) -> Vec<Vec<f64>> {
        self.problem.columns(shape)
    }

    fn fit(&self, design: &Design) -> Fit {
        fit::fit(design, self.y, None)
    }

    fn statistic(fit: &Fit) -> f64 {
        fit.rss
    }

    fn delta_bic(&self, model: &Fit, trial: &Fit, _: Shape) -> f64 {
        let n = self.y.len();
        let added = trial.rank.saturating_sub(model.rank).max(1);
        bic(trial.rss, n, model.rank + added) - bic(model.rss, n, model.rank)
    }

    fn p_value(&self, model: &Fit, trial: &Fit, added: usize) -> f64 {
        partial_f_p(model.rss, trial.rss, added, self.y.len(), trial.rank)
    }

    fn cross_validated_rmse(&self, design: &Design) -> f64 {
        leave_one_run_out_rmse(
            design,
            self.y,
            &self.problem.run_of(),
            self.problem.run_count,
        )
    }
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
                deviations: Vec::new(),
            });
        }
    }
    runs
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
    // Each difference's variance less what it shares (the diagonal of W R Wᵀ), plus W R Wᵀ.
    let covariance = Covariance::new(
        differences
            .iter()
            .map(|(t, _, v)| v.max(1e-300) - problem.reversal_prediction_variance(*t))
            .collect(),
        differences
            .iter()
            .map(|(t, _, _)| problem.prediction_weights[*t].clone())
            .collect(),
        problem.first_test_reversal_variance.clone(),
    );
    let d: Vec<f64> = differences.iter().map(|(_, d, _)| *d).collect();
    let (Some(inverse_d), Some(inverse_ones)) =
        (covariance.solve(&d), covariance.solve(&vec![1.0; m]))
    else {
        // Not positive definite only if the variances are degenerate: treat them as independent.
        return independent_constant_reversal(differences);
    };
    let weight: f64 = inverse_ones.iter().sum();
    let mean = inverse_d.iter().sum::<f64>() / weight;
    let about_zero: f64 = d.iter().zip(&inverse_d).map(|(a, b)| a * b).sum();
    // C⁻¹(d − 1·mean) = C⁻¹d − mean · C⁻¹1.
    let about_mean: f64 = d
        .iter()
        .zip(inverse_d.iter().zip(&inverse_ones))
        .map(|(d, (id, io))| (d - mean) * (id - mean * io))
        .sum();
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
                "the directions differ, but not by one B: the reversal changes along the axis from {} to {} (p = {p_with:.1e}); it is reported as unexplained structure",
                deviation_text(problem.deviation, lowest, 2),
                deviation_text(problem.deviation, highest, 2)
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
                sum += (value - level.value - half).powi(2);
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
    if !predicts_better(
        rejected,
        Kind::Reversal,
        problem.deviation,
        cv_with,
        cv_without,
    ) {
        return (None, p_without);
    }
    let evidence = Evidence {
        delta_bic: delta,
        trials: 1,
        p_value: chi2_p(about_zero - about_mean, 1),
        cv_rmse_without: cv_without,
        cv_rmse_with: cv_with,
    };
    (
        Some(ReversalFit {
            b,
            standard_error,
            evidence,
        }),
        p_with,
    )
}
