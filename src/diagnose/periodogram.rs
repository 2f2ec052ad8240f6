//! The search for a periodic error: a least-squares periodogram of the
//! per-target levels, which works on irregular targets as it does on even
//! ones (Lomb 1976, Scargle 1982: a sine and a cosine fitted at each trial
//! period, here by the same generalised least squares as every effect along
//! the axis, jointly with what is already in the model).
//!
//! - **Which tests.** Against a prediction from a first test, a periodic
//!   error may be new in the re-test, or in both tests: then the prediction
//!   carries the first test's samples of it, interpolated between targets
//!   too far apart to resolve it, and the re-test shows the error less those
//!   (`PeriodicIn`). Both are tried, each set's trials doubled for the choice;
//!   "both" only at periods shorter than twice the first test's median
//!   spacing, which it cannot resolve (a longer one its prediction carries
//!   nearly whole, and what it leaves is too small a column to fit: any
//!   structure would pose as it, at a huge amplitude).
//! - **Which periods.** The axis' known periods (the machine profile's
//!   screw lead and scale period) are one set, judged first with a penalty
//!   of 2·ln(how many there are); the scan of every period in the range
//!   (`gates::period_range`) is another, judged with 2·ln of the number of
//!   *independent* periods it searched, span · (1/shortest − 1/longest)
//!   (Horne & Baliunas 1986; VanderPlas 2018 §7.2), not the number of
//!   frequencies tried, which overlap. With known variances a single period's
//!   χ² drop 2z is χ²₂ (p = e^(−z)); over a continuous scan the best peak
//!   exceeds it about M·√z times as often (Davies 1987; Baluev 2008, eq. 14),
//!   so the selection counts M·√z trials and reports the false-alarm
//!   probability 1 − (1 − p)^(M·√z).
//! - **How well the period is known**, from the curvature of χ² in the
//!   frequency (Δχ² = 1), for the split-half check.
//! - **Aliasing**: the periods whose fit the targets cannot tell from the
//!   found one (χ² within [`MIN_DELTA_BIC`] of it), named in a warning.
//!
//! It does not look for two periodic errors at once.

use rayon::prelude::*;

use super::selection::ShapeSet;
use super::{KnownPeriod, MIN_DELTA_BIC};
use crate::effects::{PeriodicIn, Shape};

/// The trial frequencies are this many times finer than 1/span (the width
/// of a peak), so the best lies within a tenth of a peak of one of them
/// before it is refined.
const OVERSAMPLING: f64 = 5.0;

/// The sets of periods to try: the known ones that fit `min_periods` in the
/// span, then the scan of `range`, each in the re-test only and, with
/// `unresolved_below_mm` (twice the first test's median spacing), in both
/// tests at the periods shorter than that.
pub(super) fn period_sets(
    range: Option<(f64, f64)>,
    span_mm: f64,
    known: &[KnownPeriod],
    min_periods: f64,
    unresolved_below_mm: Option<f64>,
) -> Vec<ShapeSet> {
    let mut tests = vec![(PeriodicIn::ReTest, f64::INFINITY)];
    if let Some(limit) = unresolved_below_mm {
        tests.push((PeriodicIn::BothTests, limit));
    }
    let choices = tests.len() as f64;
    let mut sets = Vec::new();
    for &(which, below) in &tests {
        let shapes: Vec<Shape> = known
            .iter()
            .filter(|k| {
                k.period_mm > 0.0 && span_mm / k.period_mm >= min_periods && k.period_mm < below
            })
            .map(|k| Shape::Period(k.period_mm, which))
            .collect();
        if !shapes.is_empty() {
            sets.push(ShapeSet {
                trials: shapes.len() as f64 * choices,
                shapes,
                refine: None,
            });
        }
    }
    if let Some((shortest, longest)) = range {
        for &(which, below) in &tests {
            let longest = longest.min(below);
            if shortest < longest {
                sets.push(ShapeSet {
                    shapes: scan(shortest, longest, span_mm, which),
                    trials: independent_periods(shortest, longest, span_mm) * choices,
                    refine: Some((shortest, longest)),
                });
            }
        }
    }
    sets
}

/// The trial periods, evenly spaced in frequency from 1/longest to 1/shortest.
fn scan(shortest: f64, longest: f64, span_mm: f64, tests: PeriodicIn) -> Vec<Shape> {
    let step = 1.0 / (OVERSAMPLING * span_mm);
    let count = ((1.0 / shortest - 1.0 / longest) / step).floor() as usize;
    (0..=count)
        .map(|k| Shape::Period(1.0 / (1.0 / longest + k as f64 * step), tests))
        .collect()
}

/// How many independent periods a scan searches: peaks are 1/span wide in
/// frequency, so span · (1/shortest − 1/longest), at least 1.
pub(super) fn independent_periods(shortest: f64, longest: f64, span_mm: f64) -> f64 {
    (span_mm * (1.0 / shortest - 1.0 / longest)).max(1.0)
}

/// Standard uncertainty of the frequency of the best fit, 1/mm, from the
/// curvature of χ² there: σ_f² = 2 / (∂²χ²/∂f²) (Δχ² = 1). `chi2` gives
/// the χ² of the model at a period. `None` when χ² is not curved upwards.
pub(super) fn frequency_uncertainty(
    period_mm: f64,
    span_mm: f64,
    chi2: impl Fn(f64) -> f64,
) -> Option<f64> {
    // A fiftieth of a peak's width: well inside the parabola around the best.
    let h = 1.0 / (50.0 * span_mm);
    let f = 1.0 / period_mm;
    let curvature = (chi2(1.0 / (f + h)) + chi2(1.0 / (f - h)) - 2.0 * chi2(period_mm)) / (h * h);
    (curvature > 0.0).then(|| (2.0 / curvature).sqrt())
}

/// The periods of the scan of `range` whose fit the targets cannot tell from
/// the one at `found_mm` (`chi2` of the model with the periodic error at a
/// period): local minima of χ² more than a peak's width away from it and
/// within [`MIN_DELTA_BIC`] of its χ², best first, mm.
pub(super) fn aliases(
    found_mm: f64,
    range: (f64, f64),
    span_mm: f64,
    chi2: impl Fn(f64) -> f64 + Sync,
) -> Vec<f64> {
    let (shortest, longest) = range;
    let at_found = chi2(found_mm);
    let periods: Vec<f64> = scan(shortest, longest, span_mm, PeriodicIn::ReTest)
        .into_iter()
        .filter_map(|s| match s {
            Shape::Period(p, _) => Some(p),
            _ => None,
        })
        .collect();
    let values: Vec<f64> = periods.par_iter().map(|&p| chi2(p)).collect();
    let mut found: Vec<(f64, f64)> = Vec::new();
    for i in 1..values.len().saturating_sub(1) {
        let (left, middle, right) = (values[i - 1], values[i], values[i + 1]);
        if !(middle <= left && middle <= right) {
            continue;
        }
        if (1.0 / periods[i] - 1.0 / found_mm).abs() < 1.0 / span_mm {
            continue;
        }
        // The parabola through the three points: its vertex, in frequency.
        let curvature = left + right - 2.0 * middle;
        let (offset, minimum) = if curvature > 0.0 {
            (
                (left - right) / (2.0 * curvature),
                middle - (right - left).powi(2) / (8.0 * curvature),
            )
        } else {
            (0.0, middle)
        };
        if minimum - at_found < MIN_DELTA_BIC {
            let step = 1.0 / periods[i + 1] - 1.0 / periods[i];
            found.push((minimum, 1.0 / (1.0 / periods[i] + offset * step)));
        }
    }
    found.sort_by(|a, b| a.0.total_cmp(&b.0));
    found.into_iter().map(|(_, p)| p).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scan_counts_its_independent_periods_not_its_frequencies() {
        // 1000 mm from 5 to 500 mm: frequencies 0.002 to 0.2 /mm, peaks 0.001 /mm wide.
        assert!((independent_periods(5.0, 500.0, 1000.0) - 198.0).abs() < 1e-9);
        let shapes = scan(5.0, 500.0, 1000.0, PeriodicIn::ReTest);
        // Five frequencies per peak width (0.0002 /mm steps), both ends included.
        assert_eq!(shapes.len(), 991);
        assert_eq!(shapes[0], Shape::Period(500.0, PeriodicIn::ReTest));
        let Shape::Period(last, _) = shapes[shapes.len() - 1] else {
            unreachable!()
        };
        assert!((last - 5.0).abs() < 1e-9, "{last}");
    }

    #[test]
    fn known_periods_come_first_and_only_when_the_span_holds_enough_of_them() {
        let known = [
            KnownPeriod::screw_lead(15.0),
            KnownPeriod::scale_period(400.0),
        ];
        // A first test 40 mm apart: in both tests only below 80 mm.
        let sets = period_sets(Some((5.0, 500.0)), 1000.0, &known, 2.0, Some(80.0));
        assert_eq!(sets.len(), 4);
        // 400 mm fits 2.5 times in 1000 mm: kept; judged as 2 periods × 2 choices of tests.
        let re_test = |p| Shape::Period(p, PeriodicIn::ReTest);
        assert_eq!(sets[0].shapes, [re_test(15.0), re_test(400.0)]);
        assert_eq!(sets[0].trials, 4.0);
        assert!(sets[0].refine.is_none());
        assert_eq!(sets[1].shapes, [Shape::Period(15.0, PeriodicIn::BothTests)]);
        assert_eq!(sets[1].trials, 2.0);
        // The scans: 198 independent periods in the re-test; 187.5 below 80 mm in both.
        assert_eq!(sets[2].trials, 396.0);
        assert_eq!(
            sets[3].shapes[0],
            Shape::Period(80.0, PeriodicIn::BothTests)
        );
        assert_eq!(sets[3].trials, 375.0);
        let sets = period_sets(None, 1000.0, &known, 8.0, None);
        assert_eq!(sets.len(), 1);
        assert_eq!(sets[0].shapes, [re_test(15.0)]);
        assert_eq!(sets[0].trials, 1.0);
    }

    #[test]
    fn the_curvature_of_a_parabola_gives_its_width() {
        // χ² = 1 + ((f − 0.05)/0.001)²: Δχ² = 1 at σ_f = 0.001.
        let chi2 = |p: f64| 1.0 + ((1.0 / p - 0.05) / 0.001).powi(2);
        let sigma = frequency_uncertainty(20.0, 1000.0, chi2).unwrap();
        assert!((sigma - 0.001).abs() < 1e-9, "{sigma}");
        assert!(frequency_uncertainty(20.0, 1000.0, |p| -chi2(p)).is_none());
    }

    #[test]
    fn aliases_are_the_other_minima_as_deep_within_the_evidence() {
        // Minima at 20 mm (found), at 1/0.03 mm as deep + 3, at 1/0.1 mm deeper by 50.
        let chi2 = |p: f64| {
            let f = 1.0 / p;
            let well = |centre: f64, depth: f64| depth * (-((f - centre) / 0.0004).powi(2)).exp();
            100.0 - well(0.05, 80.0) - well(0.03, 77.0) - well(0.1, 30.0)
        };
        let found = aliases(20.0, (5.0, 500.0), 1000.0, chi2);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!((found[0] - 1.0 / 0.03).abs() < 0.05, "{found:?}");
    }
}
