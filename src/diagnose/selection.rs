//! Forward selection of effects: the shapes a kind can take, the best of
//! them, and the one loop that adds effects while the evidence is strong
//! (used between runs and along the axis).

use super::fit::Design;
use super::gates::{Periods, predicts_better, set_rejection, strong_evidence};
use super::{Evidence, RejectedEffect};
use crate::effects::{Kind, Shape};
use crate::evaluate::conformance::FULL_TURN_DEG;
use crate::measurement::{AxisKind, Direction, Run};

/// An accepted shape, where its columns start in its model, and why.
#[derive(Clone, Copy, Debug)]
pub(super) struct Chosen {
    pub(super) shape: Shape,
    pub(super) first_column: usize,
    pub(super) evidence: Evidence,
}

/// The shapes of a kind to try.
pub(super) fn shapes(
    kind: Kind,
    after_targets: &[f64],
    periods: Option<Periods>,
    runs: &[Run],
    chosen: &[Chosen],
) -> Vec<Shape> {
    match kind {
        Kind::Periodic => {
            let (shortest, longest) = match periods {
                None => return Vec::new(),
                Some(Periods::Orders(lowest, highest)) => {
                    return (lowest..=highest)
                        .map(|k| Shape::Period(FULL_TURN_DEG / f64::from(k)))
                        .collect();
                }
                Some(Periods::Range(shortest, longest)) => (shortest, longest),
            };
            let span = after_targets[after_targets.len() - 1] - after_targets[0];
            // Frequencies 5 times finer than 1/span; the best is refined afterwards.
            let step = 1.0 / (5.0 * span);
            let mut frequency = 1.0 / longest;
            let mut list = Vec::new();
            while frequency <= 1.0 / shortest {
                list.push(Shape::Period(1.0 / frequency));
                frequency += step;
            }
            list
        }
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

/// Tries every shape and returns the one with the lowest score; a period is
/// refined around the best, within the period range.
pub(super) fn best_of<T>(
    shapes: &[Shape],
    range: Option<(f64, f64)>,
    mut score: impl FnMut(Shape) -> (f64, T),
) -> Option<(Shape, f64, T)> {
    let mut best: Option<(Shape, f64, T)> = None;
    for shape in shapes {
        let (value, extra) = score(*shape);
        if best.as_ref().is_none_or(|b| value < b.1) {
            best = Some((*shape, value, extra));
        }
    }
    if let (
        Some((Shape::Period(period), _, _)),
        Some((shortest, longest)),
        [Shape::Period(a), Shape::Period(b), ..],
    ) = (&best, range, shapes)
    {
        let step = (1.0 / b - 1.0 / a).abs();
        let centre = 1.0 / period;
        for k in -10..=10 {
            let frequency = centre + f64::from(k) * step / 10.0;
            if frequency < 1.0 / longest || frequency > 1.0 / shortest {
                continue;
            }
            let shape = Shape::Period(1.0 / frequency);
            let (value, extra) = score(shape);
            if best.as_ref().is_none_or(|b| value < b.1) {
                best = Some((shape, value, extra));
            }
        }
    }
    best
}

/// One search of the forward selection: the model it grows and how it judges
/// a candidate. Between runs the model is fitted to the readings by least
/// squares and judged by its residual sum of squares (partial F); along the
/// axis it is fitted to the per-target levels by generalised least squares
/// with their known covariance and judged by χ².
pub(super) trait Search {
    /// A fit of a design.
    type Fit;

    /// Whether to try `kind` now, given what is chosen.
    fn tries(&self, kind: Kind, chosen: &[Chosen]) -> bool;

    /// The shapes of `kind` to try.
    fn shapes(&self, kind: Kind, chosen: &[Chosen]) -> Vec<Shape>;

    /// The range a best period is refined within (shortest, longest), mm, if any.
    fn periods(&self) -> Option<(f64, f64)>;

    /// Linear or rotary (the unit of the sentences).
    fn kind(&self) -> AxisKind;

    /// A shape's columns.
    fn columns(&self, shape: Shape) -> Vec<Vec<f64>>;

    /// The fit of a design.
    fn fit(&self, design: &Design) -> Self::Fit;

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
        let mut candidates: Vec<(Shape, usize, f64, S::Fit)> = Vec::new();
        for &kind in kinds {
            if !search.tries(kind, &chosen) {
                continue;
            }
            let shapes = search.shapes(kind, &chosen);
            let Some((shape, _, trial_fit)) = best_of(&shapes, search.periods(), |shape| {
                let f = search.fit(&model.with(&search.columns(shape)));
                (S::statistic(&f), f)
            }) else {
                continue;
            };
            let look_elsewhere = if shapes.len() > 1 {
                2.0 * (shapes.len() as f64).ln()
            } else {
                0.0
            };
            let delta = search.delta_bic(&model_fit, &trial_fit, shape) + look_elsewhere;
            candidates.push((shape, shapes.len(), delta, trial_fit));
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
            if !predicts_better(rejected, shape.kind(), search.kind(), cv_with, cv_without) {
                continue;
            }
            let evidence = Evidence {
                delta_bic: delta,
                trials,
                p_value: search.p_value(
                    &model_fit,
                    &trial_fit,
                    with.parameters() - model.parameters(),
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
