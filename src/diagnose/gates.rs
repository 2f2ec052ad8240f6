//! The gates an effect passes: which kinds apply to these tests, a drop of
//! the BIC beyond [`MIN_DELTA_BIC`](super::MIN_DELTA_BIC), and a better
//! prediction of the runs left out; each refusal is recorded with its reason.

use super::{
    DiagnoseInput, MIN_DELTA_BIC, MIN_PERIODS_IN_CURVE, MIN_PERIODS_IN_SPAN, RejectedEffect,
    SHORTEST_PERIOD_MM,
};
use crate::effects::{Kind, deviation_text};
use crate::evaluate::conformance::FULL_TURN_DEG;
use crate::measurement::{AxisKind, Direction};
use crate::units::DeviationUnit;

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
            // reversal; these kinds are lengths and times.
            Kind::Scale | Kind::Drift | Kind::Abbe if rotary => Some(
                "not looked for on a rotary axis: modelled for linear axes only so far".to_string(),
            ),
            Kind::Periodic if rotary && rotary_orders(after.targets(), input.before.is_some()).is_none() => Some(
                "the targets are too coarse, or the range too short, to hold a whole order per revolution".to_string(),
            ),
            Kind::Periodic if rotary => None,
            Kind::Reversal if after.run_count(Direction::Up) == 0 || after.run_count(Direction::Down) == 0 => {
                Some("needs runs in both directions".to_string())
            }
            Kind::Scale | Kind::Abbe if input.before.is_none() => Some(
                "needs a prediction (--before and --table): in a test alone a position-dependent error is part of the systematic curve the table compensates".to_string(),
            ),
            Kind::Abbe if input.angular.is_none() => Some("needs the axis' angular error along the stroke (--angular)".to_string()),
            Kind::Periodic if period_range(after.targets(), min_periods(input)).is_none() && !knows_a_period(input) => Some(format!(
                "the targets are too coarse to resolve a period shorter than 1/{} of the measured span",
                min_periods(input)
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

/// Whether a known period of the axis fits enough times in the re-test's span.
fn knows_a_period(input: &DiagnoseInput<'_>) -> bool {
    let targets = input.after.targets();
    let span = targets[targets.len() - 1] - targets[0];
    input
        .known_periods
        .iter()
        .any(|k| k.period_mm > 0.0 && span / k.period_mm >= min_periods(input))
}

/// How many periods the span must hold: fewer against a prediction (a
/// constant background) than in a test's own curve (a smooth background).
pub(super) fn min_periods(input: &DiagnoseInput<'_>) -> f64 {
    if input.before.is_some() {
        MIN_PERIODS_IN_SPAN
    } else {
        MIN_PERIODS_IN_CURVE
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
    unit: DeviationUnit,
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
                deviation_text(unit, cv_with, 3),
                deviation_text(unit, cv_without, 3)
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

/// The periods a periodic error is looked for at, up to the span /
/// `min_periods` ([`MIN_PERIODS_IN_SPAN`] against a prediction,
/// [`MIN_PERIODS_IN_CURVE`] in a test's own curve), from twice the step of
/// evenly spaced targets (below it every period has an alias above: Nyquist)
/// or, on irregular targets, which tell a period from its aliases (ISO
/// 230-2's reason to recommend them; Eyer & Bartholdi 1999), from
/// [`SHORTEST_PERIOD_MM`] or twice the median spacing if that is shorter.
pub(super) fn period_range(targets_mm: &[f64], min_periods: f64) -> Option<(f64, f64)> {
    let (median, span) = median_gap_and_span(targets_mm)?;
    let shortest = match crate::compensate::regular_step(targets_mm) {
        Some(step) => 2.0 * step,
        None => (2.0 * median).min(SHORTEST_PERIOD_MM),
    };
    let longest = span / min_periods;
    (shortest < longest).then_some((shortest, longest))
}

/// The median spacing and the span of at least 8 targets (fewer resolve no period).
fn median_gap_and_span(targets: &[f64]) -> Option<(f64, f64)> {
    if targets.len() < 8 {
        return None;
    }
    let mut gaps: Vec<f64> = targets.windows(2).map(|p| p[1] - p[0]).collect();
    gaps.sort_by(f64::total_cmp);
    Some((
        gaps[gaps.len() / 2],
        targets[targets.len() - 1] - targets[0],
    ))
}

/// A rotary axis' periods: the whole orders per revolution (lowest,
/// highest), the period 360°/order, from one period within the range
/// against a prediction (over a full turn a once-per-revolution term is
/// periodic by the geometry, not a slope; [`MIN_PERIODS_IN_CURVE`] in a
/// test's own curve) up to twice the median spacing (Nyquist).
pub(super) fn rotary_orders(targets_deg: &[f64], against_prediction: bool) -> Option<(u32, u32)> {
    let (median, span) = median_gap_and_span(targets_deg)?;
    let periods_in_range = if against_prediction {
        1.0
    } else {
        MIN_PERIODS_IN_CURVE
    };
    // 1e-9: a full turn of 360° holds order 1 exactly once.
    let lowest = (periods_in_range * FULL_TURN_DEG / span - 1e-9)
        .ceil()
        .max(1.0) as u32;
    let highest = (FULL_TURN_DEG / (2.0 * median) + 1e-9).floor() as u32;
    (lowest <= highest).then_some((lowest, highest))
}
