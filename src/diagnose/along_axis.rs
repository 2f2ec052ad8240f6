//! Structure along the axis: scale, periodic and Abbe, fitted on the pooled
//! per-target levels by generalised least squares with their known
//! covariance (the re-test's scatter plus the prediction's uncertainty,
//! shared between targets that interpolate the same points of the first test).
//!
//! Against a prediction the levels are residuals: a constant background, and
//! what an effect does not explain is unexplained structure. Without one the
//! levels are the test's own systematic curve, which the table is for; only a
//! periodic error short next to the stroke is looked for there, against a
//! smooth background (a regression spline with knots every span / 6), with the
//! background's misfit counted as noise.

use nalgebra::DMatrix;

use super::fit::{Design, WeightedFit, fit_gls};
use super::gates::{Periods, periods, set_rejection};
use super::levels::{Fold, Level};
use super::problem::Problem;
use super::selection::{Chosen, Search, forward_selection, shapes};
use super::stats::chi2_p;
use super::{Kind, LACK_OF_FIT_P, RejectedEffect, Shape};
use crate::effects::Reading;
use crate::measurement::{AxisKind, Direction};

/// Covariance of the per-target levels, µm²: each level's own scatter on the
/// diagonal, plus the prediction's, which targets share when they interpolate
/// the same points of the first test: C = diag(s²) + W D Wᵀ.
pub(super) fn level_covariance(problem: &Problem, levels: &[Level]) -> DMatrix<f64> {
    let m = levels.len();
    let mut covariance = DMatrix::zeros(m, m);
    for (a, la) in levels.iter().enumerate() {
        covariance[(a, a)] += la.scatter_variance_um2;
        for (b, lb) in levels.iter().enumerate() {
            let shared: f64 = problem.prediction_weights[la.target_index]
                .iter()
                .flat_map(|(ka, wa)| {
                    problem.prediction_weights[lb.target_index]
                        .iter()
                        .filter(move |(kb, _)| kb == ka)
                        .map(move |(_, wb)| wa * wb * problem.first_test_variance_um2[*ka])
                })
                .sum();
            covariance[(a, b)] += shared;
        }
    }
    covariance
}

/// What the effects along the axis are fitted against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Background {
    /// A constant: the levels are residuals against a prediction.
    Constant,
    /// A smooth curve: the levels are a test's own systematic curve.
    Smooth,
}

/// Knot spacing of the smooth background, as a fraction of the span: coarse
/// enough that it cannot follow [`super::MIN_PERIODS_IN_CURVE`] periods.
const SMOOTH_KNOTS_PER_SPAN: f64 = 6.0;

/// The background's columns over the levels; with `rows`, a smooth
/// background spans those rows only (the same knot spacing).
fn background_columns(
    background: Background,
    levels: &[Level],
    rows: Option<&[bool]>,
) -> Vec<Vec<f64>> {
    let m = levels.len();
    if background == Background::Constant {
        return vec![vec![1.0; m]];
    }
    let positions: Vec<f64> = levels.iter().map(|l| l.target_mm).collect();
    let span = positions[m - 1] - positions[0];
    let used: Vec<f64> = positions
        .iter()
        .enumerate()
        .filter(|(i, _)| rows.is_none_or(|r| r[*i]))
        .map(|(_, x)| *x)
        .collect();
    let (low, high) = (used[0], used[used.len() - 1]);
    let intervals = ((high - low) / (span / SMOOTH_KNOTS_PER_SPAN))
        .round()
        .max(1.0) as usize;
    let knots: Vec<f64> = (0..=intervals)
        .map(|k| low + (high - low) * k as f64 / intervals as f64)
        .collect();
    // The spline is linear in its knot values: one column per knot.
    let basis = crate::spline::basis_matrix(&knots, &positions);
    (0..knots.len())
        .map(|k| (0..m).map(|i| basis[i * knots.len() + k]).collect())
        .collect()
}

/// The columns of a position-dependent shape over the levels.
fn level_columns(problem: &Problem, levels: &[Level], shape: Shape) -> Vec<Vec<f64>> {
    let readings: Vec<Reading> = levels
        .iter()
        .map(|l| Reading {
            target_index: l.target_index,
            target_mm: l.target_mm,
            direction: Direction::Up,
            run: 0,
            run_index: 0,
            time_h: 0.0,
        })
        .collect();
    crate::effects::columns(shape, &readings, &problem.line())
}

/// Forward selection of scale, periodic and Abbe on the per-target levels.
pub(super) fn select_along_axis(
    problem: &Problem,
    levels: &[Level],
    folds: &[Fold],
    reversal_b: f64,
    kinds: &[Kind],
    background: Background,
    rejected: &mut Vec<RejectedEffect>,
) -> (Vec<Chosen>, WeightedFit) {
    let m = levels.len();
    let values: Vec<f64> = levels.iter().map(|l| l.value_um).collect();
    let base = Design {
        columns: background_columns(background, levels, None),
    };
    let mut covariance = level_covariance(problem, levels);
    if background == Background::Smooth {
        // The smooth curve only approximates the test's own systematic error:
        // its misfit counts as noise (the variance scaled by χ²/dof when > 1).
        let fit = fit_gls(&base, &values, &covariance, None);
        let dof = m.saturating_sub(fit.rank).max(1) as f64;
        covariance *= (fit.chi2 / dof).max(1.0);
    }
    let search = AlongAxis {
        problem,
        levels,
        folds,
        reversal_b,
        background,
        values: &values,
        covariance: &covariance,
        periods: periods(
            &problem.targets_mm,
            problem.kind,
            background == Background::Constant,
        ),
    };
    let (mut chosen, mut model_fit) = forward_selection(&search, base.clone(), kinds, rejected);
    // Never the nearest kind: what is accepted along the axis must leave no
    // structure there (against a prediction; a test's own curve is the table's).
    let p = chi2_p(model_fit.chi2, m.saturating_sub(model_fit.rank));
    if background == Background::Constant && p < LACK_OF_FIT_P && !chosen.is_empty() {
        for c in &chosen {
            set_rejection(
                rejected,
                c.shape.kind(),
                format!(
                    "fits part of the residual, but the structure along the axis is still not explained (lack of fit p = {p:.1e}); it is reported as unexplained rather than forced into this kind"
                ),
            );
        }
        chosen.clear();
        model_fit = fit_gls(&base, &values, &covariance, None);
    }
    (chosen, model_fit)
}

/// The search along the axis: generalised least squares on the per-target
/// levels with their known covariance, judged by χ².
struct AlongAxis<'a> {
    problem: &'a Problem,
    levels: &'a [Level],
    folds: &'a [Fold],
    reversal_b: f64,
    background: Background,
    values: &'a [f64],
    covariance: &'a DMatrix<f64>,
    periods: Option<Periods>,
}

impl Search for AlongAxis<'_> {
    type Fit = WeightedFit;

    /// Each position-dependent kind once.
    fn tries(&self, kind: Kind, chosen: &[Chosen]) -> bool {
        kind.is_positional() && !chosen.iter().any(|c| c.shape.kind() == kind)
    }

    fn shapes(&self, kind: Kind, chosen: &[Chosen]) -> Vec<Shape> {
        shapes(kind, &self.problem.targets_mm, self.periods, &[], chosen)
    }

    fn periods(&self) -> Option<(f64, f64)> {
        self.periods.and_then(Periods::range)
    }

    fn kind(&self) -> AxisKind {
        self.problem.kind
    }

    fn columns(&self, shape: Shape) -> Vec<Vec<f64>> {
        level_columns(self.problem, self.levels, shape)
    }

    fn fit(&self, design: &Design) -> WeightedFit {
        fit_gls(design, self.values, self.covariance, None)
    }

    fn statistic(fit: &WeightedFit) -> f64 {
        fit.chi2
    }

    /// −2 ln L = χ² with a known covariance: ΔBIC = Δχ² + Δk·ln m.
    fn delta_bic(&self, model: &WeightedFit, trial: &WeightedFit, shape: Shape) -> f64 {
        let added = self.columns(shape).len();
        trial.chi2 - model.chi2 + added as f64 * (self.levels.len() as f64).ln()
    }

    fn p_value(&self, model: &WeightedFit, trial: &WeightedFit, added: usize) -> f64 {
        chi2_p(model.chi2 - trial.chi2, added)
    }

    fn cross_validated_rmse(&self, design: &Design) -> f64 {
        along_axis_cv(
            self.problem,
            self.levels,
            design,
            self.folds,
            self.reversal_b,
        )
    }

    fn inconsistency(&self, shape: Shape) -> Option<String> {
        inconsistent_along_axis(
            self.problem,
            self.levels,
            self.values,
            self.covariance,
            self.background,
            shape,
        )
    }
}

/// A position-dependent effect must be the same along the whole axis: its
/// parameters fitted on each half of the span must agree (Wald χ², p ≥ [`LACK_OF_FIT_P`]).
fn inconsistent_along_axis(
    problem: &Problem,
    levels: &[Level],
    values: &[f64],
    covariance: &DMatrix<f64>,
    background: Background,
    shape: Shape,
) -> Option<String> {
    let columns = level_columns(problem, levels, shape);
    let k = columns.len();
    let middle = (levels[0].target_mm + levels[levels.len() - 1].target_mm) / 2.0;
    let mut halves = Vec::new();
    for first_half in [true, false] {
        let rows: Vec<bool> = levels
            .iter()
            .map(|l| (l.target_mm <= middle) == first_half)
            .collect();
        if rows.iter().filter(|r| **r).count() < k + 6 {
            return None;
        }
        let design = Design {
            columns: background_columns(background, levels, Some(&rows)),
        };
        let first = design.parameters();
        let fitted = fit_gls(&design.with(&columns), values, covariance, Some(&rows));
        if fitted.rank < first + k {
            return None;
        }
        halves.push((
            fitted.coefficients[first..].to_vec(),
            fitted.standard_errors[first..].to_vec(),
        ));
    }
    // The halves as independent (their shared prediction error is small next to their own):
    // χ² = Σ (θ₁ − θ₂)² / (σ₁² + σ₂²), the periodic's two coefficients treated as independent.
    let chi2: f64 = (0..k)
        .map(|j| {
            (halves[0].0[j] - halves[1].0[j]).powi(2)
                / (halves[0].1[j].powi(2) + halves[1].1[j].powi(2)).max(1e-300)
        })
        .sum();
    let p = chi2_p(chi2, k);
    let rounded = |v: &[f64]| {
        v.iter()
            .map(|x| (x * 100.0).round() / 100.0)
            .collect::<Vec<_>>()
    };
    (p < LACK_OF_FIT_P).then(|| {
        format!(
            "not the same along the axis: fitted on each half of the span it gives {:?} and {:?} (p = {p:.1e}); the structure is reported as unexplained",
            rounded(&halves[0].0),
            rounded(&halves[1].0)
        )
    })
}

/// Leave-one-run-out RMSE of a model along the axis (levels plus ±B/2).
pub(super) fn along_axis_cv(
    problem: &Problem,
    levels: &[Level],
    design: &Design,
    folds: &[Fold],
    reversal_b: f64,
) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for fold in folds {
        // The design's columns are over `levels`; take the rows of the fold's levels (same targets).
        let index: Vec<usize> = fold
            .levels
            .iter()
            .filter_map(|l| levels.iter().position(|m| m.target_index == l.target_index))
            .collect();
        let columns = Design {
            columns: design
                .columns
                .iter()
                .map(|c| index.iter().map(|&i| c[i]).collect())
                .collect(),
        };
        let values: Vec<f64> = fold.levels.iter().map(|l| l.value_um).collect();
        let fitted = fit_gls(
            &columns,
            &values,
            &level_covariance(problem, &fold.levels),
            None,
        );
        for (target, direction, value) in &fold.held_out {
            if let Some(at) = fold.levels.iter().position(|l| l.target_index == *target) {
                let half = direction.reversal_share(reversal_b);
                sum += (value - fitted.fitted[at] - half).powi(2);
                count += 1;
            }
        }
    }
    if count == 0 {
        0.0
    } else {
        (sum / count as f64).sqrt()
    }
}
