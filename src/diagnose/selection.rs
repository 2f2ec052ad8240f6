//! Forward selection of effects: the shapes a kind can take, the best of
//! them, and the one loop that adds effects while the evidence is strong
//! (used between runs and along the axis).

use rayon::prelude::*;

use super::fit::Design;
use super::gates::{predicts_better, set_rejection, strong_evidence};
use super::{Evidence, RejectedEffect};
use crate::effects::{Kind, Shape};
use crate::measurement::{Direction, Run};
use crate::units::DeviationUnit;

/// An accepted shape, where its columns start in its model, and why.
#[derive(Clone, Copy, Debug)]
pub(super) struct Chosen {
    pub(super) shape: Shape,
    pub(super) first_column: usize,
    pub(super) evidence: Evidence,
}

/// Shapes of one kind tried together: the best of them is the candidate,
/// judged with 2·ln(`trials`) added to its ΔBIC for having been chosen among
/// them (the look-elsewhere effect) and its p-value the chance that the best
/// of `trials` independent shapes of pure noise fits as well (Šidák).
#[derive(Clone, Debug)]
pub(super) struct ShapeSet {
    pub(super) shapes: Vec<Shape>,
    /// How many independent shapes the set holds (for a scan of periods
    /// fewer than the frequencies tried, which overlap).
    pub(super) trials: f64,
    /// For a scan of periods: the range (shortest, longest), mm, within
    /// which the best is refined.
    pub(super) refine: Option<(f64, f64)>,
}

impl ShapeSet {
    /// Shapes each tried on its own.
    pub(super) fn each(shapes: Vec<Shape>) -> ShapeSet {
        let trials = shapes.len() as f64;
        ShapeSet {
            shapes,
            trials,
            refine: None,
        }
    }
}

/// The shapes of a kind between runs or of a fixed shape (a periodic error
/// has its own sets, `periodogram::period_sets`).
pub(super) fn shapes(kind: Kind, runs: &[Run], chosen: &[Chosen]) -> Vec<Shape> {
    match kind {
        Kind::Periodic => Vec::new(),
        Kind::OutlierRun => {
            let count = |d: Direction| runs.iter().filter(|r| r.direction == d).count();
            runs.iter()
                .filter(|run| count(run.direction) >= 3)
                .map(|run| Shape::Run(run.direction, run.number))
                .filter(|shape| !chosen.iter().any(|c| c.shape == *shape))
                .collect()
        }
        kind => vec![Shape::Fixed(kind)],
    }
}

/// Tries every shape of the set and returns the one with the lowest score
/// (the first of equal ones); a period of a scan is refined around the best,
/// within its range. With `may_be_best` (one per shape, from a screen of the
/// scan) only the shapes it marks are scored: the others cannot be the best.
/// The shapes are scored in parallel (rayon), chosen in order.
pub(super) fn best_of<T: Send>(
    set: &ShapeSet,
    may_be_best: Option<&[bool]>,
    score: impl Fn(Shape) -> (f64, T) + Sync,
) -> Option<(Shape, f64, T)> {
    let lowest = |shapes: Vec<Shape>, best: Option<(Shape, f64, T)>| {
        let scored: Vec<(f64, T)> = shapes.par_iter().map(|s| score(*s)).collect();
        shapes
            .into_iter()
            .zip(scored)
            .fold(best, |best, (shape, (value, extra))| {
                if best.as_ref().is_none_or(|b| value < b.1) {
                    Some((shape, value, extra))
                } else {
                    best
                }
            })
    };
    let tried: Vec<Shape> = match may_be_best {
        Some(marks) => set
            .shapes
            .iter()
            .zip(marks)
            .filter(|(_, m)| **m)
            .map(|(s, _)| *s)
            .collect(),
        None => set.shapes.clone(),
    };
    let best = lowest(tried, None);
    if let (
        Some((Shape::Period(period, tests), _, _)),
        Some((shortest, longest)),
        [Shape::Period(a, _), Shape::Period(b, _), ..],
    ) = (&best, set.refine, set.shapes.as_slice())
    {
        let step = (1.0 / b - 1.0 / a).abs();
        let (centre, tests) = (1.0 / period, *tests);
        let refined: Vec<Shape> = (-10..=10)
            .map(|k| centre + f64::from(k) * step / 10.0)
            .filter(|f| *f >= 1.0 / longest && *f <= 1.0 / shortest)
            .map(|f| Shape::Period(1.0 / f, tests))
            .collect();
        return lowest(refined, best);
    }
    best
}

/// One search of the forward selection: the model it grows and how it judges
/// a candidate. Between runs the model is fitted to the readings by least
/// squares and judged by its residual sum of squares (partial F); along the
/// axis it is fitted to the per-target levels by generalised least squares
/// with their known covariance and judged by χ².
pub(super) trait Search: Sync {
    /// A fit of a design.
    type Fit: Send;

    /// Whether to try `kind` now, given what is chosen.
    fn tries(&self, kind: Kind, chosen: &[Chosen]) -> bool;

    /// The unit the sentences say a deviation in.
    fn deviation(&self) -> DeviationUnit;

    /// The shapes of `kind` to try, in sets each judged on its own.
    fn shape_sets(&self, kind: Kind, chosen: &[Chosen]) -> Vec<ShapeSet>;

    /// A shape's columns.
    fn columns(&self, shape: Shape) -> Vec<Vec<f64>>;

    /// The fit of a design.
    fn fit(&self, design: &Design) -> Self::Fit;

    /// The fit of `model` with the columns `extra` added: a search may keep
    /// its work on `model` between the candidates that extend it.
    fn fit_extended(&self, model: &Design, extra: &[Vec<f64>]) -> Self::Fit {
        self.fit(&model.with(extra))
    }

    /// For a scan of periods: which of its shapes may give the lowest
    /// statistic extending `model`, from a cheaper computation of all of
    /// them at once; `None`: every shape is fitted.
    fn may_be_best(&self, _model: &Design, _set: &ShapeSet) -> Option<Vec<bool>> {
        None
    }

    /// What the best shape of a kind minimises (RSS or χ²).
    fn statistic(fit: &Self::Fit) -> f64;

    /// The change of the BIC from `model` to `trial`, which adds `shape`.
    fn delta_bic(&self, model: &Self::Fit, trial: &Self::Fit, shape: Shape) -> f64;

    /// The p-value of the `added` parameters from `model` to `trial`.
    fn p_value(&self, model: &Self::Fit, trial: &Self::Fit, added: usize) -> f64;

    /// The prediction error of the runs left out with `design`, µm.
    fn cross_validated_rmse(&self, design: &Design) -> f64;

    /// Why `shape` is not the same along the axis, if it is not.
    fn inconsistency(&self, _shape: Shape) -> Option<String> {
        None
    }
}

/// Adds effects to `base` one at a time, the best first, while one passes
/// every gate: a ΔBIC beyond [`MIN_DELTA_BIC`](super::MIN_DELTA_BIC) with
/// 2·ln(trials) for a shape chosen among many (the look-elsewhere effect),
/// the same along the axis, and a better prediction of the runs left out.
/// Returns what was chosen and the fit of the grown model.
pub(super) fn forward_selection<S: Search>(
    search: &S,
    base: Design,
    kinds: &[Kind],
    rejected: &mut Vec<RejectedEffect>,
) -> (Vec<Chosen>, S::Fit) {
    let mut chosen: Vec<Chosen> = Vec::new();
    let mut model_fit = search.fit(&base);
    let mut model = base;
    loop {
        let mut candidates: Vec<(Shape, f64, f64, S::Fit)> = Vec::new();
        for &kind in kinds {
            if !search.tries(kind, &chosen) {
                continue;
            }
            for set in search.shape_sets(kind, &chosen) {
                let screened = search.may_be_best(&model, &set);
                let Some((shape, _, trial_fit)) = best_of(&set, screened.as_deref(), |shape| {
                    let f = search.fit_extended(&model, &search.columns(shape));
                    (S::statistic(&f), f)
                }) else {
                    continue;
                };
                // A scan over a continuous period: its peaks are not independent
                // trials but the upcrossings of a random field, e^(−z)·√z per
                // independent period for a χ² drop of 2z with known variances
                // (Davies 1987; Baluev 2008, eq. 14): the trials grow by √z.
                let trials = if set.refine.is_some() {
                    let z = (S::statistic(&model_fit) - S::statistic(&trial_fit)) / 2.0;
                    set.trials * z.max(1.0).sqrt()
                } else {
                    set.trials
                };
                let look_elsewhere = 2.0 * trials.max(1.0).ln();
                let delta = search.delta_bic(&model_fit, &trial_fit, shape) + look_elsewhere;
                candidates.push((shape, trials, delta, trial_fit));
            }
        }
        candidates.sort_by(|a, b| a.2.total_cmp(&b.2));
        let cv_without = search.cross_validated_rmse(&model);
        let mut accepted = None;
        for (shape, trials, delta, trial_fit) in candidates {
            if !strong_evidence(rejected, shape.kind(), delta) {
                continue;
            }
            if let Some(why) = search.inconsistency(shape) {
                set_rejection(rejected, shape.kind(), why);
                continue;
            }
            let with = model.with(&search.columns(shape));
            let cv_with = search.cross_validated_rmse(&with);
            if !predicts_better(
                rejected,
                shape.kind(),
                search.deviation(),
                cv_with,
                cv_without,
            ) {
                continue;
            }
            let p_one = search.p_value(
                &model_fit,
                &trial_fit,
                with.parameters() - model.parameters(),
            );
            let evidence = Evidence {
                delta_bic: delta,
                trials: trials.max(1.0).round() as usize,
                // The chance that the best of `trials` independent shapes of noise fits
                // as well: 1 − (1 − p)^trials (Šidák 1967), without the cancellation.
                p_value: -(trials.max(1.0) * (-p_one).ln_1p()).exp_m1(),
                cv_rmse_without: cv_without,
                cv_rmse_with: cv_with,
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
