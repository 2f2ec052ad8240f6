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
    let n = positions.len();
    if n == 0 || periods.len() < 2 {
        return None;
    }
    // The base fit: β = (XᵀWX)⁺ XᵀWy, r = y − Xβ, v = W r.
    let weighted_fit = WeightedBase::new(base, weights, n);
    let b0 = DVector::from_iterator(
        base.len(),
        weighted_fit.weighted.iter().map(|c| dot(c, values)),
    );
    let beta = &weighted_fit.inverse * &b0;
    let residual: Vec<f64> = (0..n)
        .map(|i| values[i] - (0..base.len()).map(|j| base[j][i] * beta[j]).sum::<f64>())
        .collect();
    let v: Vec<f64> = residual.iter().zip(weights).map(|(r, w)| r * w).collect();
    let chi2_base = dot(&residual, &v);
    let reductions = weighted_fit.reductions(positions, weights, &v, periods)?;
    Some(reductions.iter().map(|r| chi2_base - r).collect())
}

/// Lower bounds of the χ² of the generalised least-squares fit of the `base`
/// columns with a sine and a cosine of each of `periods` (evenly spaced in
/// frequency) when the covariance C is not diagonal but C ≤ κ·S for a
/// diagonal S with inverse `weights` (`Covariance::diagonal_bound`). From the
/// base fit under C, its χ² `chi2_base` and v = C⁻¹r of its residual, a
/// period lowers χ² by bᵀA_C⁻¹b with b = Zᵀv exact (one transform of v), and
/// A_C = min over the base's coefficients of ZᵀC⁻¹Z ≥ A_S / κ, A_S the same
/// with S (the diagonal periodogram's): so by at most κ·bᵀA_S⁻¹b. These are
/// rigorous lower bounds, not estimates: a period whose bound is above the
/// exact χ² of another cannot be the best.
pub(super) fn bounded_gls_chi2(
    positions: &[f64],
    weights: &[f64],
    kappa: f64,
    base: &[Vec<f64>],
    fit: (f64, &[f64]),
    periods: &[f64],
) -> Option<Vec<f64>> {
    let n = positions.len();
    let (chi2_base, v) = fit;
    if n == 0 || periods.len() < 2 || kappa.is_nan() || kappa < 1.0 || !chi2_base.is_finite() {
        return None;
    }
    let reductions =
        WeightedBase::new(base, weights, n).reductions(positions, weights, v, periods)?;
    Some(
        reductions
            .iter()
            .map(|r| chi2_base - kappa * r - SCREEN_MARGIN * (chi2_base.abs() + 1.0))
            .collect(),
    )
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>()
}

/// The base columns X weighted by W (diagonal), XᵀWX and its pseudo-inverse.
struct WeightedBase {
    weighted: Vec<Vec<f64>>,
    inverse: DMatrix<f64>,
}

impl WeightedBase {
    fn new(base: &[Vec<f64>], weights: &[f64], n: usize) -> WeightedBase {
        let p = base.len();
        let weighted: Vec<Vec<f64>> = base
            .iter()
            .map(|c| c.iter().zip(weights).map(|(c, w)| c * w).collect())
            .collect();
        let gram = DMatrix::from_fn(p, p, |a, b| dot(&base[a], &weighted[b]));
        let gram = (&gram + gram.transpose()) * 0.5;
        let inverse = if p == 0 {
            DMatrix::zeros(0, 0)
        } else {
            solve_normal(gram, &DVector::zeros(p), n.max(p + 2)).2
        };
        WeightedBase { weighted, inverse }
    }

    /// bᵀA⁻¹b at each period: b = Zᵀv, A = ZᵀWZ − ZᵀWX (XᵀWX)⁺ XᵀWZ, with
    /// Z = (cos θ, sin θ), θ = 2πx/p; ZᵀWZ from the sums of the weights at
    /// twice the frequency (cos²θ = (1 + cos 2θ)/2; Press & Rybicki 1989),
    /// the rest from sums at the frequency. +∞ where A is nearly singular
    /// (the exact fit's rank decides there). `None` when the periods are not
    /// evenly spaced in frequency.
    fn reductions(
        &self,
        positions: &[f64],
        weights: &[f64],
        v: &[f64],
        periods: &[f64],
    ) -> Option<Vec<f64>> {
        let count = periods.len();
        let f0 = 1.0 / periods[0];
        let df = (1.0 / periods[count - 1] - f0) / (count - 1) as f64;
        let evenly = periods
            .iter()
            .enumerate()
            .all(|(k, p)| (1.0 / p - (f0 + k as f64 * df)).abs() <= 1e-9 * df.abs());
        if !evenly || df <= 0.0 {
            return None;
        }
        let p = self.weighted.len();
        let inverse = &self.inverse;
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
        let data = sums(v, 1.0)?;
        let columns: Vec<Vec<Complex<f64>>> = self
            .weighted
            .iter()
            .map(|c| sums(c, 1.0))
            .collect::<Option<_>>()?;
        Some(
            (0..count)
                .map(|k| {
                    // (cos, sin) against the base columns: XᵀWZ.
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
                        return f64::INFINITY;
                    }
                    let (bc, bs) = (data[k].re, data[k].im);
                    (ss * bc * bc - 2.0 * cs * bc * bs + cc * bs * bs) / det
                })
                .collect(),
        )
    }
}

/// Lower bounds of χ² from values within [`SCREEN_MARGIN`] of it
/// (`diagonal_gls_chi2`'s); −∞ stays −∞.
pub(super) fn below_margin(screened: &[f64]) -> Vec<f64> {
    screened
        .iter()
        .map(|v| v - SCREEN_MARGIN * (v.abs() + 1.0))
        .collect()
}

/// Which of a scan's periods may have the lowest χ² once fitted exactly,
/// from a lower bound of each one's χ² (`lower`; −∞ where there is none) and
/// the exact χ² `exact` of one of them: those whose bound is not above it
/// (any other is beaten by that one).
pub(super) fn may_be_lowest(lower: &[f64], exact: f64) -> Vec<bool> {
    lower
        .iter()
        .map(|l| l.is_nan() || exact.is_nan() || *l <= exact)
        .collect()
}

/// The period with the lowest finite bound (the one to fit exactly for
/// [`may_be_lowest`]), if any.
pub(super) fn lowest_bound(lower: &[f64]) -> Option<usize> {
    (0..lower.len())
        .filter(|i| lower[*i].is_finite())
        .min_by(|a, b| lower[*a].total_cmp(&lower[*b]))
}

/// What a scan's screen gives: a lower bound of the χ² at each period (−∞
/// where there is none) and an upper bound of all of them (the χ² of the
/// model without a period).
pub(super) struct Screen {
    pub(super) lower: Vec<f64>,
    pub(super) upper: f64,
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
/// period): local minima of χ² more than a peak's width away from it whose
/// parabola through the neighbours is within [`MIN_DELTA_BIC`] of its χ²,
/// best first, mm. `screened` bounds the χ² at every period of the scan
/// (`Screen`): then only the periods whose bound leaves them a chance, with
/// their neighbours, are fitted exactly; the result is that of every period
/// fitted.
pub(super) fn aliases(
    found_mm: f64,
    range: (f64, f64),
    span_mm: f64,
    chi2: impl Fn(f64) -> f64 + Sync,
    screened: impl FnOnce(&[f64]) -> Option<Screen>,
) -> Vec<f64> {
    let at_found = chi2(found_mm);
    let periods = scan_periods(range, span_mm);
    let exact: Vec<bool> = match screened(&periods) {
        Some(screen) => {
            // The parabola through a lowest m and neighbours l, r ≤ upper dips at most
            // (r − l)²/(8(l + r − 2m)) ≤ (upper − m)/8 below m: it cannot reach within
            // MIN_DELTA_BIC of the found χ² when m is above this.
            let threshold = (8.0 * (at_found + MIN_DELTA_BIC) + screen.upper) / 9.0
                + SCREEN_MARGIN * (screen.upper.abs() + 1.0);
            let mut exact = vec![false; periods.len()];
            for (i, lower) in screen.lower.iter().enumerate() {
                if lower.is_nan() || threshold.is_nan() || *lower <= threshold {
                    exact[i.saturating_sub(1)..(i + 2).min(periods.len())].fill(true);
                }
            }
            exact
        }
        None => vec![true; periods.len()],
    };
    let values: Vec<Option<f64>> = (0..periods.len())
        .into_par_iter()
        .map(|i| exact[i].then(|| chi2(periods[i])))
        .collect();
    let mut found: Vec<(f64, f64)> = Vec::new();
    for i in 1..values.len().saturating_sub(1) {
        // A period not fitted with both neighbours cannot be one (above).
        let (Some(left), Some(middle), Some(right)) = (values[i - 1], values[i], values[i + 1])
        else {
            continue;
        };
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
    use crate::diagnose::covariance::Covariance;
    use std::f64::consts::TAU as TAU_;

    /// The best of `periods` (refined within `refine`) fitting only the
    /// `marks`ed ones is the best fitting every one, by `exact` χ²; returns it.
    fn screened_best_is_every_best(
        periods: &[f64],
        marks: &[bool],
        refine: (f64, f64),
        exact: &(dyn Fn(f64) -> f64 + Sync),
    ) -> Shape {
        let set = ShapeSet {
            shapes: periods
                .iter()
                .map(|p| Shape::Period(*p, PeriodicIn::ReTest))
                .collect(),
            trials: 1.0,
            refine: Some(refine),
        };
        let score = |shape: Shape| {
            let Shape::Period(p, _) = shape else {
                unreachable!()
            };
            (exact(p), ())
        };
        let screened = crate::diagnose::selection::best_of(&set, Some(marks), score);
        let every = crate::diagnose::selection::best_of(&set, None, score);
        let (Some((a, chi2_a, _)), Some((b, chi2_b, _))) = (screened, every) else {
            panic!("no best")
        };
        assert_eq!(a, b);
        assert_eq!(chi2_a, chi2_b);
        a
    }

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
        let lowest = lowest_bound(&screened).unwrap();
        let marks = may_be_lowest(&below_margin(&screened), exact(periods[lowest]));
        let kept: Vec<f64> = periods
            .iter()
            .zip(&marks)
            .filter(|(_, m)| **m)
            .map(|(p, _)| *p)
            .collect();
        assert!(!kept.is_empty() && kept.len() <= 2, "{kept:?}");
        assert!((kept[0] - 37.0).abs() < 0.5, "{kept:?}");
        // The best of the scan, refined, is the one every period fitted exactly finds.
        screened_best_is_every_best(&periods, &marks, (10.0, span / 2.0), &exact);
    }

    /// 99 levels between the targets of a first test of 100 (7.5 mm apart, as a
    /// re-test between them): each level interpolates the first test's means by the
    /// spline, so the levels share their uncertainty (C = S + W D Wᵀ, D as large as S).
    /// A constant and a slope, a 47 mm sine and noise in them.
    fn correlated_levels(amplitude: f64) -> (Vec<f64>, Vec<f64>, Covariance, Vec<Vec<f64>>) {
        let first: Vec<f64> = (0..100).map(|k| 7.5 * k as f64).collect();
        let positions: Vec<f64> = (0..99).map(|j| 7.5 * j as f64 + 3.75).collect();
        let weights = crate::spline::basis_rows(&first, &positions);
        let own: Vec<f64> = (0..99).map(|j| 0.01 + 0.004 * (j % 4) as f64).collect();
        let shared: Vec<f64> = (0..100).map(|k| 0.012 + 0.003 * (k % 3) as f64).collect();
        let covariance = Covariance::new(own, weights, shared);
        let values: Vec<f64> = positions
            .iter()
            .enumerate()
            .map(|(j, x)| {
                0.4 + 0.002 * x
                    + amplitude * (TAU_ * x / 47.0 + 1.0).sin()
                    + 0.15 * (j as f64 * 12.9).sin()
                    + 0.1 * (j as f64 * 0.37).cos()
            })
            .collect();
        let base = vec![
            vec![1.0; 99],
            positions.iter().map(|x| x / 1000.0).collect(),
        ];
        (positions, values, covariance, base)
    }

    #[test]
    fn the_bounds_on_correlated_levels_are_below_every_exact_fit_and_keep_the_best() {
        use crate::diagnose::fit::{Design, fit_gls};
        for amplitude in [0.6, 0.0] {
            let (positions, values, covariance, base) = correlated_levels(amplitude);
            let (weights, kappa) = covariance.diagonal_bound().unwrap();
            // C ≤ κ·S: κ − 1 is λ_max of D^½WᵀS⁻¹WD^½, about D/S here (≈ 1.2); by the
            // dense matrices, no vector has vᵀC⁻¹v below vᵀS⁻¹v / κ.
            assert!(kappa > 1.5 && kappa < 3.5, "{kappa}");
            let m = positions.len();
            let dense = DMatrix::from_fn(m, m, |a, b| covariance.at(a, b));
            let s_half =
                DMatrix::from_fn(m, m, |a, b| if a == b { weights[a].sqrt() } else { 0.0 });
            let largest = (&s_half * &dense * &s_half)
                .symmetric_eigen()
                .eigenvalues
                .max();
            assert!(
                kappa >= largest && kappa <= 1.1 * largest,
                "{kappa} vs {largest}"
            );
            let model = Design::of_columns(base.clone());
            let fitted = fit_gls(&model, &values, &covariance, None);
            let residual: Vec<f64> = values
                .iter()
                .zip(&fitted.fitted)
                .map(|(y, f)| y - f)
                .collect();
            let v = covariance.solve(&residual).unwrap();
            let span = positions[m - 1] - positions[0];
            let periods = scan_periods((15.0, span / 2.0), span);
            let lower = bounded_gls_chi2(
                &positions,
                &weights,
                kappa,
                &base,
                (fitted.chi2, &v),
                &periods,
            )
            .unwrap();
            let exact = |p: f64| {
                let sine = |f: fn(f64) -> f64| positions.iter().map(|x| f(TAU_ * x / p)).collect();
                fit_gls(
                    &model.with(&[sine(f64::sin), sine(f64::cos)]),
                    &values,
                    &covariance,
                    None,
                )
                .chi2
            };
            let every: Vec<f64> = periods.iter().map(|p| exact(*p)).collect();
            for ((p, l), e) in periods.iter().zip(&lower).zip(&every) {
                assert!(l <= e, "{p} mm: bound {l} above the exact {e}");
            }
            // The best of the marked periods is the best of all, refined alike.
            let lowest = lowest_bound(&lower).unwrap();
            let marks = may_be_lowest(&lower, every[lowest]);
            let a = screened_best_is_every_best(&periods, &marks, (15.0, span / 2.0), &exact);
            let kept = marks.iter().filter(|m| **m).count();
            if amplitude > 0.0 {
                // A clear 47 mm error: only the periods of its peak are fitted.
                let Shape::Period(p, _) = a else {
                    unreachable!()
                };
                assert!((p - 47.0).abs() < 0.5, "{p}");
                assert!(kept <= 8, "{kept} of {}", periods.len());
                // The aliases from the bounds are those of every period fitted.
                let bounds = |_: &[f64]| {
                    Some(Screen {
                        lower: lower.clone(),
                        upper: fitted.chi2,
                    })
                };
                let range = (15.0, span / 2.0);
                assert_eq!(
                    aliases(p, range, span, exact, bounds),
                    aliases(p, range, span, exact, |_| None)
                );
            }
        }
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
