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
//! - **How fast.** With independent levels (a re-test at the first test's
//!   targets, or without a first test) the scan's χ² at every period comes
//!   from trigonometric sums over the targets (the generalised Lomb–Scargle
//!   periodogram, Zechmeister & Kürster 2009, with the model's columns in
//!   place of their constant), all periods at once by a non-uniform FFT
//!   (`trig_sums`): O(n log n) instead of one fit per period. Those values
//!   only screen: the periods within [`SCREEN_MARGIN`] of the lowest (and any
//!   whose 2 × 2 system is ill-conditioned) are fitted exactly as before, so
//!   the period chosen and its fit are the exact ones.
//!
//! It does not look for two periodic errors at once.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use rustfft::num_complex::Complex;

use super::fit::solve_normal;
use super::selection::ShapeSet;
use super::trig_sums::trig_sums;
use super::{KnownPeriod, MIN_DELTA_BIC};
use crate::effects::{PeriodicIn, Shape};

/// How far above the lowest screened χ² a period is still fitted exactly,
/// relative to that χ² (plus as much absolute): a hundred thousand times the
/// error of the sums (about 1e-11 relative), so that no period whose exact χ² could be
/// the lowest is left out.
pub(super) const SCREEN_MARGIN: f64 = 1e-6;

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

/// The χ² of the generalised least-squares fit of the `base` columns with a
/// sine and a cosine of each of `periods` (mm, evenly spaced in frequency, as
/// a scan has them), for independent `values` at `positions` with inverse
/// variances `weights` (C⁻¹ diagonal): the generalised Lomb–Scargle
/// periodogram (Zechmeister & Kürster 2009) with the base's columns for its
/// constant. With the base fit's residual r and v = C⁻¹r, a period adds the
/// columns Z = (cos θ, sin θ), θ = 2πx/p, and lowers χ² by bᵀA⁻¹b,
/// b = Zᵀv, A = ZᵀC⁻¹Z − ZᵀC⁻¹X (XᵀC⁻¹X)⁺ XᵀC⁻¹Z; ZᵀC⁻¹Z from the sums of the
/// weights at twice the frequency (cos²θ = (1 + cos 2θ)/2; Press & Rybicki
/// 1989), the rest from sums at the frequency. `f64::NEG_INFINITY` where A is
/// nearly singular (the exact fit's rank decides there). `None` when the
/// periods are not evenly spaced in frequency.
pub(super) fn diagonal_gls_chi2(
    positions: &[f64],
    values: &[f64],
    weights: &[f64],
    base: &[Vec<f64>],
    periods: &[f64],
) -> Option<Vec<f64>> {
    let (n, count) = (positions.len(), periods.len());
    if n == 0 || count < 2 {
        return None;
    }
    let f0 = 1.0 / periods[0];
    let df = (1.0 / periods[count - 1] - f0) / (count - 1) as f64;
    let evenly = periods
        .iter()
        .enumerate()
        .all(|(k, p)| (1.0 / p - (f0 + k as f64 * df)).abs() <= 1e-9 * df.abs());
    if !evenly || df <= 0.0 {
        return None;
    }
    // The base fit: β = (XᵀWX)⁺ XᵀWy, r = y − Xβ, v = W r.
    let p = base.len();
    let weighted =
        |column: &[f64]| -> Vec<f64> { column.iter().zip(weights).map(|(c, w)| c * w).collect() };
    let weighted_base: Vec<Vec<f64>> = base.iter().map(|c| weighted(c)).collect();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let gram = DMatrix::from_fn(p, p, |a, b| dot(&base[a], &weighted_base[b]));
    let gram = (&gram + gram.transpose()) * 0.5;
    let b0 = DVector::from_iterator(p, weighted_base.iter().map(|c| dot(c, values)));
    let (beta, inverse) = if p == 0 {
        (DVector::zeros(0), DMatrix::zeros(0, 0))
    } else {
        let (beta, _, inverse) = solve_normal(gram, &b0, n.max(p + 2));
        (beta, inverse)
    };
    let residual: Vec<f64> = (0..n)
        .map(|i| values[i] - (0..p).map(|j| base[j][i] * beta[j]).sum::<f64>())
        .collect();
    let v = weighted(&residual);
    let chi2_base = dot(&residual, &v);
    let total_weight: f64 = weights.iter().sum();
    let origin = positions.iter().copied().fold(f64::INFINITY, f64::min);
    let complex = |values: &[f64]| -> Vec<Complex<f64>> {
        values.iter().map(|v| Complex::new(*v, 0.0)).collect()
    };
    let sums = |h: &[f64], twice: f64| {
        trig_sums(
            positions,
            &complex(h),
            origin,
            twice * f0,
            twice * df,
            count,
        )
    };
    let double = sums(weights, 2.0)?;
    let data = sums(&v, 1.0)?;
    let columns: Vec<Vec<Complex<f64>>> = weighted_base
        .iter()
        .map(|c| sums(c, 1.0))
        .collect::<Option<_>>()?;
    Some(
        (0..count)
            .map(|k| {
                // (cos, sin) against the base columns: XᵀC⁻¹Z.
                let cross: Vec<[f64; 2]> = columns.iter().map(|c| [c[k].re, c[k].im]).collect();
                let through = |a: usize, b: usize| -> f64 {
                    (0..p)
                        .map(|i| {
                            (0..p)
                                .map(|j| cross[i][a] * inverse[(i, j)] * cross[j][b])
                                .sum::<f64>()
                        })
                        .sum()
                };
                let cc = (total_weight + double[k].re) / 2.0 - through(0, 0);
                let ss = (total_weight - double[k].re) / 2.0 - through(1, 1);
                let cs = double[k].im / 2.0 - through(0, 1);
                let det = cc * ss - cs * cs;
                // Either column nearly in the span of the others: the exact fit's rank decides.
                let smallest = (cc + ss) / 2.0 - (((cc - ss) / 2.0).powi(2) + cs * cs).sqrt();
                if smallest.is_nan() || smallest <= 1e-8 * total_weight || !det.is_finite() {
                    return f64::NEG_INFINITY;
                }
                let (bc, bs) = (data[k].re, data[k].im);
                chi2_base - (ss * bc * bc - 2.0 * cs * bc * bs + cc * bs * bs) / det
            })
            .collect(),
    )
}

/// Which of a scan's screened χ² (`diagonal_gls_chi2`) may be the lowest
/// once fitted exactly: those within [`SCREEN_MARGIN`] of the lowest, and
/// those not screened (−∞).
pub(super) fn may_be_lowest(screened: &[f64]) -> Vec<bool> {
    let lowest = screened
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    let bound = lowest + SCREEN_MARGIN * (lowest.abs() + 1.0);
    screened.iter().map(|v| v.is_nan() || *v <= bound).collect()
}

/// The periods of the scan of `range`, mm (every shape of [`scan`] is a period).
pub(super) fn scan_periods(range: (f64, f64), span_mm: f64) -> Vec<f64> {
    scan(range.0, range.1, span_mm, PeriodicIn::ReTest)
        .into_iter()
        .filter_map(|s| match s {
            Shape::Period(p, _) => Some(p),
            _ => None,
        })
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
/// within [`MIN_DELTA_BIC`] of its χ², best first, mm. `screened` gives the
/// χ² at every period of the scan within [`SCREEN_MARGIN`] (or −∞ where it
/// cannot): then only the periods near a minimum that may count are fitted
/// exactly, with their neighbours.
pub(super) fn aliases(
    found_mm: f64,
    range: (f64, f64),
    span_mm: f64,
    chi2: impl Fn(f64) -> f64 + Sync,
    screened: impl FnOnce(&[f64]) -> Option<Vec<f64>>,
) -> Vec<f64> {
    let at_found = chi2(found_mm);
    let periods = scan_periods(range, span_mm);
    let values: Vec<f64> = match screened(&periods) {
        Some(mut values) => {
            let bound = at_found + MIN_DELTA_BIC + SCREEN_MARGIN * (at_found.abs() + 1.0);
            let mut exact = vec![false; values.len()];
            for (i, v) in values.iter().enumerate() {
                if v.is_nan() || *v <= bound {
                    exact[i.saturating_sub(1)..(i + 2).min(values.len())].fill(true);
                }
            }
            let fitted: Vec<(usize, f64)> = (0..values.len())
                .into_par_iter()
                .filter(|i| exact[*i])
                .map(|i| (i, chi2(periods[i])))
                .collect();
            for (i, v) in fitted {
                values[i] = v;
            }
            values
        }
        None => periods.par_iter().map(|&p| chi2(p)).collect(),
    };
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
    use std::f64::consts::TAU as TAU_;

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
    fn the_screened_chi2_is_the_exact_fit_of_every_period() {
        use crate::diagnose::covariance::Covariance;
        use crate::diagnose::fit::{Design, fit_gls};
        // 120 irregular levels over 600 mm with unequal variances: a constant, a slope and
        // a 37 mm sine in them; the base is the constant and the slope.
        let positions: Vec<f64> = (0..120)
            .map(|j| 5.0 * j as f64 + 1.5 * (j as f64 * 2.3).sin())
            .collect();
        let values: Vec<f64> = positions
            .iter()
            .enumerate()
            .map(|(j, x)| {
                0.4 + 0.002 * x
                    + 0.8 * (TAU_ * x / 37.0 + 0.3).sin()
                    + 0.2 * (j as f64 * 12.9).sin()
            })
            .collect();
        let variances: Vec<f64> = (0..120).map(|j| 0.04 + 0.02 * (j % 3) as f64).collect();
        let weights: Vec<f64> = variances.iter().map(|v| 1.0 / v).collect();
        // The slope over the span as scale's column is, in m: well conditioned next to the constant.
        let base = vec![
            vec![1.0; 120],
            positions.iter().map(|x| x / 1000.0).collect(),
        ];
        let span = positions[119] - positions[0];
        let periods = scan_periods((10.0, span / 2.0), span);
        let screened = diagonal_gls_chi2(&positions, &values, &weights, &base, &periods).unwrap();
        let covariance = Covariance::diagonal(variances);
        let exact = |p: f64| {
            let sine = |f: fn(f64) -> f64| positions.iter().map(|x| f(TAU_ * x / p)).collect();
            let design = Design::of_columns(base.clone()).with(&[sine(f64::sin), sine(f64::cos)]);
            fit_gls(&design, &values, &covariance, None).chi2
        };
        for (p, v) in periods.iter().zip(&screened) {
            let e = exact(*p);
            assert!((v - e).abs() <= 1e-8 * e, "{p} mm: {v} vs {e}");
        }
        // The lowest is at 37 mm, and only the periods next to it are fitted exactly.
        let marks = may_be_lowest(&screened);
        let kept: Vec<f64> = periods
            .iter()
            .zip(&marks)
            .filter(|(_, m)| **m)
            .map(|(p, _)| *p)
            .collect();
        assert!(!kept.is_empty() && kept.len() <= 2, "{kept:?}");
        assert!((kept[0] - 37.0).abs() < 0.5, "{kept:?}");
        // The best of the scan, refined, is the one every period fitted exactly finds.
        let set = ShapeSet {
            shapes: periods
                .iter()
                .map(|p| Shape::Period(*p, PeriodicIn::ReTest))
                .collect(),
            trials: 1.0,
            refine: Some((10.0, span / 2.0)),
        };
        let score = |shape: Shape| {
            let Shape::Period(p, _) = shape else {
                unreachable!()
            };
            (exact(p), ())
        };
        let screened_best = crate::diagnose::selection::best_of(&set, Some(&marks), score);
        let every_best = crate::diagnose::selection::best_of(&set, None, score);
        let (Some((a, chi2_a, _)), Some((b, chi2_b, _))) = (screened_best, every_best) else {
            panic!("no best")
        };
        assert_eq!(a, b);
        assert_eq!(chi2_a, chi2_b);
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
        let found = aliases(20.0, (5.0, 500.0), 1000.0, chi2, |_| None);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!((found[0] - 1.0 / 0.03).abs() < 0.05, "{found:?}");
    }
}
