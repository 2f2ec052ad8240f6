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

use std::sync::{Arc, Mutex, OnceLock};

use nalgebra::{DMatrix, DVector};

use super::covariance::Covariance;
use super::fit::{Design, GlsBase, WeightedFit, fit_gls};
use super::gates::{period_range, rotary_orders, set_rejection};
use super::levels::{Fold, Level};
use super::periodogram::{
    Screen, aliases, below_margin, bounded_gls_chi2, diagonal_gls_chi2, frequency_uncertainty,
    lowest_bound, may_be_lowest, period_sets,
};
use super::problem::Problem;
use super::selection::{Chosen, Search, ShapeSet, forward_selection, shapes};
use super::stats::chi2_p;
use super::{Kind, KnownPeriod, LACK_OF_FIT_P, RejectedEffect, Shape};
use crate::effects::{PeriodicIn, Reading};
use crate::evaluate::conformance::FULL_TURN_DEG;
use crate::measurement::{AxisKind, Direction};
use crate::units::DeviationUnit;

/// Covariance of the per-target levels, µm²: each level's own scatter on the
/// diagonal, plus the prediction's, which targets share when they interpolate
/// the same points of the first test: C = diag(s²) + W D Wᵀ.
pub(super) fn level_covariance(problem: &Problem, levels: &[Level]) -> Covariance {
    Covariance::new(
        levels.iter().map(|l| l.scatter_variance).collect(),
        levels
            .iter()
            .map(|l| problem.prediction_weights[l.target_index].clone())
            .collect(),
        problem.first_test_variance.clone(),
    )
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
    let positions: Vec<f64> = levels.iter().map(|l| l.target).collect();
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

/// The columns of a position-dependent shape over the levels. A periodic
/// error in both tests is less what the prediction carries of it: its values
/// at the first test's targets, interpolated as the prediction is.
fn level_columns(problem: &Problem, levels: &[Level], shape: Shape) -> Vec<Vec<f64>> {
    // (target index, position): the index is the re-test's (Abbe's angles are per target).
    let at = |positions: &mut dyn Iterator<Item = (usize, f64)>| -> Vec<Reading> {
        positions
            .map(|(target_index, target)| Reading {
                target_index,
                target,
                direction: Direction::Up,
                run: 0,
                run_index: 0,
                time_h: 0.0,
            })
            .collect()
    };
    let readings = at(&mut levels.iter().map(|l| (l.target_index, l.target)));
    let mut columns = crate::effects::columns(shape, &readings, &problem.line());
    if let Shape::Period(_, PeriodicIn::BothTests) = shape {
        let first = at(&mut problem.first_test_positions.iter().map(|&x| (0, x)));
        let carried = crate::effects::columns(shape, &first, &problem.line());
        for (column, samples) in columns.iter_mut().zip(&carried) {
            for (value, level) in column.iter_mut().zip(levels) {
                *value -= problem.prediction_weights[level.target_index]
                    .iter()
                    .map(|(k, w)| w * samples[*k])
                    .sum::<f64>();
            }
        }
    }
    columns
}

/// What the selection along the axis found: the effects, the fit of the
/// grown model, and the periods the targets cannot tell from an accepted
/// periodic error's (mm, best first).
pub(super) struct AlongAxisSelection {
    pub(super) chosen: Vec<Chosen>,
    pub(super) fit: WeightedFit,
    pub(super) aliases_mm: Vec<f64>,
}

/// Forward selection of scale, periodic and Abbe on the per-target levels;
/// `known` are the axis' known periods, tried before the scan.
#[allow(clippy::too_many_arguments)]
pub(super) fn select_along_axis(
    problem: &Problem,
    levels: &[Level],
    folds: &[Fold],
    reversal_b: f64,
    kinds: &[Kind],
    known: &[KnownPeriod],
    background: Background,
    rejected: &mut Vec<RejectedEffect>,
) -> AlongAxisSelection {
    let m = levels.len();
    let values: Vec<f64> = levels.iter().map(|l| l.value).collect();
    let base = Design::of_columns(background_columns(background, levels, None));
    let mut covariance = level_covariance(problem, levels);
    if background == Background::Smooth {
        // The smooth curve only approximates the test's own systematic error:
        // its misfit counts as noise (the variance scaled by χ²/dof when > 1).
        let fit = fit_gls(&base, &values, &covariance, None);
        let dof = m.saturating_sub(fit.rank).max(1) as f64;
        covariance = covariance.scaled((fit.chi2 / dof).max(1.0));
    }
    let min_periods = match background {
        Background::Constant => super::MIN_PERIODS_IN_SPAN,
        Background::Smooth => super::MIN_PERIODS_IN_CURVE,
    };
    let search = AlongAxis {
        problem,
        levels,
        folds,
        reversal_b,
        background,
        values: &values,
        covariance: &covariance,
        // A rotary axis' orders are its own (`shape_sets`): no scan, no aliases in mm.
        periods: (problem.kind == AxisKind::Linear)
            .then(|| period_range(&problem.targets, min_periods))
            .flatten(),
        min_periods,
        known,
        base_fit: Mutex::new(None),
        diagonal_bound: OnceLock::new(),
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
    let aliases_mm = match (
        chosen.iter().find(|c| c.shape.kind() == Kind::Periodic),
        search.periods,
    ) {
        (Some(periodic), Some(range)) => {
            // The model with everything else that was accepted, and a period.
            let others = chosen
                .iter()
                .filter(|c| c.shape.kind() != Kind::Periodic)
                .fold(base.clone(), |d, c| d.with(&search.columns(c.shape)));
            let Shape::Period(found, tests) = periodic.shape else {
                unreachable!("a periodic effect's shape is its period")
            };
            aliases(
                found,
                range,
                search.span_mm(),
                |p| {
                    search
                        .fit_extended(&others, &search.columns(Shape::Period(p, tests)))
                        .chi2
                },
                |periods| search.screen(&others, periods, tests),
            )
        }
        _ => Vec::new(),
    };
    AlongAxisSelection {
        chosen,
        fit: model_fit,
        aliases_mm,
    }
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
    covariance: &'a Covariance,
    periods: Option<(f64, f64)>,
    min_periods: f64,
    known: &'a [KnownPeriod],
    /// The fit of the model the candidates extend, kept between them.
    base_fit: Mutex<Option<Arc<GlsBase>>>,
    /// `Covariance::diagonal_bound` of the covariance, once.
    diagonal_bound: OnceLock<Option<(Vec<f64>, f64)>>,
}

impl AlongAxis<'_> {
    fn span_mm(&self) -> f64 {
        let targets = &self.problem.targets;
        targets[targets.len() - 1] - targets[0]
    }

    /// Bounds of the χ² of `model` with a periodic error at each of
    /// `periods` (a scan), from the periodogram's sums: only for a periodic
    /// error new in the re-test (the sums need plain sines). With independent
    /// levels the sums give each χ² within [`SCREEN_MARGIN`](super::periodogram::SCREEN_MARGIN);
    /// with levels that share the prediction's uncertainty (C = S + W D Wᵀ)
    /// they bound it from below through C ≤ κ·S (`bounded_gls_chi2`).
    fn screen(&self, model: &Design, periods: &[f64], tests: PeriodicIn) -> Option<Screen> {
        if tests != PeriodicIn::ReTest || model.groups.is_some() {
            return None;
        }
        let positions: Vec<f64> = self.levels.iter().map(|l| l.target).collect();
        let fit = self.fit_extended(model, &[]);
        if let Some(weights) = self.covariance.inverse_diagonal() {
            let screened =
                diagonal_gls_chi2(&positions, self.values, &weights, &model.columns, periods)?;
            return Some(Screen {
                lower: below_margin(&screened),
                upper: fit.chi2,
            });
        }
        let (weights, kappa) = self
            .diagonal_bound
            .get_or_init(|| self.covariance.diagonal_bound())
            .as_ref()?;
        let residual: Vec<f64> = self
            .values
            .iter()
            .zip(&fit.fitted)
            .map(|(y, f)| y - f)
            .collect();
        let v = self.covariance.solve(&residual)?;
        let lower = bounded_gls_chi2(
            &positions,
            weights,
            *kappa,
            &model.columns,
            (fit.chi2, &v),
            periods,
        )?;
        Some(Screen {
            lower,
            upper: fit.chi2,
        })
    }
}

impl Search for AlongAxis<'_> {
    type Fit = WeightedFit;

    /// Each position-dependent kind once.
    fn tries(&self, kind: Kind, chosen: &[Chosen]) -> bool {
        kind.is_positional() && !chosen.iter().any(|c| c.shape.kind() == kind)
    }

    fn deviation(&self) -> DeviationUnit {
        self.problem.deviation
    }

    fn shape_sets(&self, kind: Kind, chosen: &[Chosen]) -> Vec<ShapeSet> {
        match kind {
            // A rotary axis' error repeats every turn: whole orders k per
            // revolution, the period 360°/k, each tried on its own.
            Kind::Periodic if self.problem.kind == AxisKind::Rotary => {
                let against_prediction = self.background == Background::Constant;
                let orders = rotary_orders(&self.problem.targets, against_prediction);
                vec![ShapeSet::each(orders.map_or_else(
                    Vec::new,
                    |(lowest, highest)| {
                        (lowest..=highest)
                            .map(|k| {
                                Shape::Period(FULL_TURN_DEG / f64::from(k), PeriodicIn::ReTest)
                            })
                            .collect()
                    },
                ))]
            }
            Kind::Periodic => {
                // Against a prediction, the error may be in both tests (see `periodogram`).
                let first = &self.problem.first_test_positions;
                let unresolved_below_mm = (first.len() >= 2).then(|| {
                    let mut gaps: Vec<f64> = first.windows(2).map(|p| p[1] - p[0]).collect();
                    gaps.sort_by(f64::total_cmp);
                    2.0 * gaps[gaps.len() / 2]
                });
                period_sets(
                    self.periods,
                    self.span_mm(),
                    self.known,
                    self.min_periods,
                    unresolved_below_mm,
                )
            }
            kind => vec![ShapeSet::each(shapes(kind, &[], chosen))],
        }
    }

    fn columns(&self, shape: Shape) -> Vec<Vec<f64>> {
        level_columns(self.problem, self.levels, shape)
    }

    fn fit(&self, design: &Design) -> WeightedFit {
        fit_gls(design, self.values, self.covariance, None)
    }

    /// The model's C⁻¹X is kept: a candidate costs a solve per column it adds.
    fn fit_extended(&self, model: &Design, extra: &[Vec<f64>]) -> WeightedFit {
        let base = {
            let mut cached = self.base_fit.lock().unwrap_or_else(|e| e.into_inner());
            if !cached.as_ref().is_some_and(|b| b.is_of(&model.columns)) {
                *cached = GlsBase::new(&model.columns, self.values, self.covariance).map(Arc::new);
            }
            cached.clone()
        };
        match base {
            Some(base) => base.fit_with(extra, self.covariance),
            None => self.fit(&model.with(extra)),
        }
    }

    /// A scan of periods new in the re-test is screened by the periodogram's sums.
    fn may_be_best(&self, model: &Design, set: &ShapeSet) -> Option<Vec<bool>> {
        set.refine?;
        let mut tests = None;
        let mut periods = Vec::with_capacity(set.shapes.len());
        for shape in &set.shapes {
            let Shape::Period(p, t) = *shape else {
                return None;
            };
            if tests.replace(t).is_some_and(|before| before != t) {
                return None;
            }
            periods.push(p);
        }
        let screen = self.screen(model, &periods, tests?)?;
        // The period of the lowest bound, fitted exactly: no period whose bound is above its χ² can be the best.
        let lowest = lowest_bound(&screen.lower)?;
        let exact = self
            .fit_extended(model, &self.columns(set.shapes[lowest]))
            .chi2;
        Some(may_be_lowest(&screen.lower, exact))
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

/// The largest turn of the phase between the halves, rad, that a period's
/// uncertainty may explain in the split-half check: 1 standard deviation of
/// half a radian keeps the first-order (linear) allowance honest.
const MAX_TURN_RAD: f64 = 0.5;

/// A position-dependent effect must be the same along the whole axis: its
/// parameters fitted on each half of the span must agree (Wald χ², p ≥ [`LACK_OF_FIT_P`]).
fn inconsistent_along_axis(
    problem: &Problem,
    levels: &[Level],
    values: &[f64],
    covariance: &Covariance,
    background: Background,
    shape: Shape,
) -> Option<String> {
    let columns = level_columns(problem, levels, shape);
    let k = columns.len();
    let middle = (levels[0].target + levels[levels.len() - 1].target) / 2.0;
    let mut halves = Vec::new();
    for first_half in [true, false] {
        let rows: Vec<bool> = levels
            .iter()
            .map(|l| (l.target <= middle) == first_half)
            .collect();
        if rows.iter().filter(|r| **r).count() < k + 6 {
            return None;
        }
        let design = Design::of_columns(background_columns(background, levels, Some(&rows)));
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
    // χ² = dᵀ S⁻¹ d of the difference d = θ₁ − θ₂, S = diag(σ₁² + σ₂²), the periodic's two
    // coefficients treated as independent.
    let difference = DVector::from_iterator(k, (0..k).map(|j| halves[0].0[j] - halves[1].0[j]));
    let mut spread = DMatrix::from_fn(k, k, |a, b| {
        if a == b {
            halves[0].1[a].powi(2) + halves[1].1[a].powi(2)
        } else {
            0.0
        }
    });
    if let Shape::Period(period, tests) = shape {
        // The period is fitted on the whole span; its error δf turns each half's phase by
        // 2π·δf·(the half's centre), so the halves' (a, b) differ by 2π·δf·Δc·(−b, a) even
        // when the error is the same along the axis: a period the whole span determines
        // well is not rejected for what its halves cannot (σ_f from χ²'s curvature).
        let base = Design::of_columns(background_columns(background, levels, None));
        let whole = |p: f64| {
            fit_gls(
                &base.with(&level_columns(problem, levels, Shape::Period(p, tests))),
                values,
                covariance,
                None,
            )
        };
        let fitted = whole(period);
        let (a, b) = (
            fitted.coefficients[base.parameters()],
            fitted.coefficients[base.parameters() + 1],
        );
        let span = levels[levels.len() - 1].target - levels[0].target;
        let centre = |first_half: bool| {
            let here: Vec<f64> = levels
                .iter()
                .filter(|l| (l.target <= middle) == first_half)
                .map(|l| l.target)
                .collect();
            here.iter().sum::<f64>() / here.len() as f64
        };
        // Only while the turn is small (the linearisation holds): a period the whole span
        // determines poorly gets no allowance, and a bow cannot pose as a long period.
        if let Some(sigma_f) = frequency_uncertainty(period, span, |p| whole(p).chi2)
            && let turn = std::f64::consts::TAU * sigma_f * (centre(true) - centre(false))
            && turn.abs() <= MAX_TURN_RAD
        {
            let direction = [-b, a];
            for (i, u) in direction.iter().enumerate() {
                for (j, v) in direction.iter().enumerate() {
                    spread[(i, j)] += turn * turn * u * v;
                }
            }
        }
    }
    let chi2 = spread.try_inverse().map_or(0.0, |inverse| {
        (difference.transpose() * inverse * &difference)[(0, 0)]
    });
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
    let targets = problem.targets.len();
    let mut row_of_target = vec![None; targets];
    for (row, l) in levels.iter().enumerate() {
        row_of_target[l.target_index].get_or_insert(row);
    }
    for fold in folds {
        // The design's columns are over `levels`; take the rows of the fold's levels (same targets).
        let index: Vec<usize> = fold
            .levels
            .iter()
            .filter_map(|l| row_of_target[l.target_index])
            .collect();
        let columns = Design::of_columns(
            design
                .columns
                .iter()
                .map(|c| index.iter().map(|&i| c[i]).collect())
                .collect(),
        );
        let values: Vec<f64> = fold.levels.iter().map(|l| l.value).collect();
        let fitted = fit_gls(
            &columns,
            &values,
            &level_covariance(problem, &fold.levels),
            None,
        );
        let mut fold_row = vec![None; targets];
        for (row, l) in fold.levels.iter().enumerate() {
            fold_row[l.target_index].get_or_insert(row);
        }
        for (target, direction, value) in &fold.held_out {
            if let Some(at) = fold_row[*target] {
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
