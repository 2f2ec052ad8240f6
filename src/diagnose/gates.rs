//! The gates an effect passes: which kinds apply to these tests, a drop of
//! the BIC beyond [`MIN_DELTA_BIC`](super::MIN_DELTA_BIC), and a better
//! prediction of the runs left out; each refusal is recorded with its reason.

use super::{
    DiagnoseInput, MIN_DELTA_BIC, MIN_PERIODS_IN_CURVE, MIN_PERIODS_IN_SPAN, RejectedEffect,
};
use crate::effects::{Kind, deviation_text};
use crate::evaluate::conformance::FULL_TURN_DEG;
use crate::measurement::{AxisKind, Direction};

/// The kinds that can be looked for here; the others go to `rejected` with the reason.
pub(super) fn applicable_kinds(
    input: &DiagnoseInput<'_>,
    rejected: &mut Vec<RejectedEffect>,
) -> Vec<Kind> {
    let after = input.after;
    let rotary = after.kind() == AxisKind::Rotary;
    let mut kinds = Vec::new();
    for &kind in Kind::ALL {
        let reason = match kind {
            // A rotary axis' errors are per-revolution harmonics and the
            // reversal (issue 14); these kinds are lengths and times.
            Kind::Scale | Kind::Drift | Kind::Abbe if rotary => Some(
                "not looked for on a rotary axis: modelled for linear axes only so far".to_string(),
            ),
            Kind::Reversal if after.run_count(Direction::Up) == 0 || after.run_count(Direction::Down) == 0 => {
                Some("needs runs in both directions".to_string())
            }
            Kind::Scale | Kind::Abbe if input.before.is_none() => Some(
                "needs a prediction (--before and --table): in a test alone a position-dependent error is part of the systematic curve the table compensates".to_string(),
            ),
            Kind::Abbe if input.angular.is_none() => Some("needs the axis' angular error along the stroke (--angular)".to_string()),
            Kind::Periodic if rotary && periods(after.targets_mm(), after.kind(), input.before.is_some()).is_none() => Some(format!(
                "the targets are too coarse, or the range too short, to hold {} period(s) of a whole order per revolution",
                min_periods(after.kind(), input.before.is_some())
            )),
            Kind::Periodic if periods(after.targets_mm(), after.kind(), input.before.is_some()).is_none() => Some(format!(
                "the targets are too coarse to resolve a period shorter than 1/{} of the measured span",
                min_periods(after.kind(), input.before.is_some())
            )),
            Kind::OutlierRun if after.run_count(Direction::Up) < 3 && after.run_count(Direction::Down) < 3 => {
                Some("needs at least 3 runs in a direction to tell one apart".to_string())
            }
            _ => None,
        };
        match reason {
            Some(why) => rejected.push(RejectedEffect { kind, why }),
            None => kinds.push(kind),
        }
    }
    kinds
}

/// How many periods the span must hold: fewer against a prediction (a
/// constant background) than in a test's own curve (a smooth background).
/// On a rotary axis one against a prediction: over a full turn a
/// once-per-revolution term is periodic by the geometry, not a slope.
pub(super) fn min_periods(kind: AxisKind, against_prediction: bool) -> f64 {
    match (against_prediction, kind) {
        (true, AxisKind::Linear) => MIN_PERIODS_IN_SPAN,
        (true, AxisKind::Rotary) => 1.0,
        (false, _) => MIN_PERIODS_IN_CURVE,
    }
}

/// The first gate: the BIC drops by at least [`MIN_DELTA_BIC`] (with the
/// look-elsewhere term already in `delta`); records why not.
pub(super) fn strong_evidence(rejected: &mut Vec<RejectedEffect>, kind: Kind, delta: f64) -> bool {
    let strong = delta <= -MIN_DELTA_BIC;
    if !strong {
        let change = if delta < 0.0 {
            format!("the BIC drops by {:.1}", -delta)
        } else {
            format!("the BIC rises by {delta:.1}")
        };
        set_rejection(
            rejected,
            kind,
            format!("not enough evidence: {change}, a drop of {MIN_DELTA_BIC} is needed"),
        );
    }
    strong
}

/// The second gate: the runs left out of the fit are predicted better with
/// the effect than without (leave-one-run-out RMSE, µm); records why not.
pub(super) fn predicts_better(
    rejected: &mut Vec<RejectedEffect>,
    kind: Kind,
    axis: AxisKind,
    cv_with: f64,
    cv_without: f64,
) -> bool {
    let better = cv_with < cv_without;
    if !better {
        set_rejection(
            rejected,
            kind,
            format!(
                "improves the fit but not the prediction of runs it was not fitted on ({} vs {})",
                deviation_text(axis, cv_with, 3),
                deviation_text(axis, cv_without, 3)
            ),
        );
    }
    better
}

pub(super) fn set_rejection(rejected: &mut Vec<RejectedEffect>, kind: Kind, why: String) {
    match rejected.iter_mut().find(|r| r.kind == kind) {
        Some(existing) => existing.why = why,
        None => rejected.push(RejectedEffect { kind, why }),
    }
}

/// The periods a periodic error is looked for at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Periods {
    /// A linear axis: any period from the shortest to the longest, mm,
    /// scanned and the best refined.
    Range(f64, f64),
    /// A rotary axis: whole orders per revolution, lowest to highest, the
    /// period 360°/order (a rotary error repeats every turn).
    Orders(u32, u32),
}

impl Periods {
    /// The range a best period is refined within; none for whole orders.
    pub(super) fn range(self) -> Option<(f64, f64)> {
        match self {
            Periods::Range(shortest, longest) => Some((shortest, longest)),
            Periods::Orders(..) => None,
        }
    }
}

/// The periods a periodic error is looked for at: from twice the median target
/// spacing (Nyquist) to the span / [`min_periods`]; on a rotary axis the
/// whole orders per revolution whose period lies within that.
pub(super) fn periods(
    targets_mm: &[f64],
    kind: AxisKind,
    against_prediction: bool,
) -> Option<Periods> {
    if targets_mm.len() < 8 {
        return None;
    }
    let mut gaps: Vec<f64> = targets_mm.windows(2).map(|p| p[1] - p[0]).collect();
    gaps.sort_by(f64::total_cmp);
    let median = gaps[gaps.len() / 2];
    let span = targets_mm[targets_mm.len() - 1] - targets_mm[0];
    let (shortest, longest) = (2.0 * median, span / min_periods(kind, against_prediction));
    match kind {
        AxisKind::Linear => (shortest < longest).then_some(Periods::Range(shortest, longest)),
        AxisKind::Rotary => {
            // 1e-9: a full turn of 360° holds order 1 exactly once.
            let lowest = (FULL_TURN_DEG / longest - 1e-9).ceil().max(1.0) as u32;
            let highest = (FULL_TURN_DEG / shortest + 1e-9).floor() as u32;
            (lowest <= highest).then_some(Periods::Orders(lowest, highest))
        }
    }
}
