//! Straightness and squareness from straightness tests (ISO 230-1).
//!
//! A straightness test reads the lateral deviation of a moving axis along
//! its travel relative to the laser's reference (the straightness optics).
//! ISO 230-1:2012 (via Renishaw white paper TE328, `../shared/notes/anchors-and-standards.md`
//! §1.1 and "ISO 230-1") takes the straightness relative to a reference
//! straight line, the least-squares line or the line through the end points
//! ([`ReferenceLine`]); the straightness deviation is the range of the
//! residuals. The line's slope is not straightness: it is the alignment of
//! the optics to the axis and, against a second axis measured with the same
//! reference (an optical square), the squareness of the pair. So the slope is
//! returned apart ([`Straightness::slope`]), never left in the residuals.
//!
//! **Squareness.** Axis A is measured for its straightness in the direction
//! of B (slope `b_ab`: deviation in B per unit of A), and B in the direction
//! of A (slope `b_ba`), both against one reference (the optical square turns
//! the beam by 90°). In the A–B plane, A moves along (1, b_ab) and B along
//! (b_ba, 1), so the angle between the positive directions of A and B is
//! 90° − (b_ab + b_ba) to first order: a common rotation of the reference
//! changes one slope by +φ and the other by −φ and cancels. Renishaw's
//! CARTO states the sign as a choice, "Squareness is positive:
//! RIGHT_HANDED (xwz > 0: angle X-Z smaller than 90°) / LARGER_THAN_90"
//! (`../shared/notes/anchors-and-standards.md` §1.1); [`SquarenessConvention`]
//! gives both. \[reconstructed\] that RIGHT_HANDED means "smaller than 90°"
//! for the X–Y and Y–Z pairs as the guide states it for X–Z.
//!
//! Pure arithmetic; positions mm, deviations mm, slopes and angles rad.

/// The reference straight line of a straightness test (ISO 230-1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ReferenceLine {
    /// The least-squares line through every mean deviation (the default:
    /// it uses every reading, so one noisy end does not tilt it).
    #[default]
    LeastSquares,
    /// The line through the first and the last target's deviation.
    EndPoints,
}

impl ReferenceLine {
    /// `least-squares` or `end-points`, as in the survey file.
    pub fn as_str(self) -> &'static str {
        match self {
            ReferenceLine::LeastSquares => "least-squares",
            ReferenceLine::EndPoints => "end-points",
        }
    }

    /// The line named by [`ReferenceLine::as_str`].
    pub fn from_name(name: &str) -> Option<ReferenceLine> {
        [ReferenceLine::LeastSquares, ReferenceLine::EndPoints]
            .into_iter()
            .find(|line| line.as_str() == name)
    }
}

/// A straightness test evaluated against its reference line.
#[derive(Clone, Debug, PartialEq)]
pub struct Straightness {
    /// The line used.
    pub reference: ReferenceLine,
    /// Its value at position 0, mm.
    pub intercept_mm: f64,
    /// Its slope, rad (mm per mm): alignment or squareness, not straightness.
    pub slope: f64,
    /// The deviations from the line, mm, one per position.
    pub residuals_mm: Vec<f64>,
}

impl Straightness {
    /// The straightness deviation: the range of the residuals, mm (ISO 230-1).
    pub fn deviation_mm(&self) -> f64 {
        let max = self
            .residuals_mm
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let min = self
            .residuals_mm
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        max - min
    }
}

/// Fits the reference line to `deviations_mm` at `positions_mm` (at least two
/// positions, strictly increasing, as a `GeometryTest`'s targets are).
///
/// # Example
///
/// ```
/// use axcomp::evaluate::straightness::{ReferenceLine, straightness};
///
/// // A bow of 2 µm on a line tilted by 10 µrad: the slope is kept apart.
/// let x = [0.0, 100.0, 200.0];
/// let d = [0.0, 0.001 + 0.002, 0.002];
/// let ends = straightness(&x, &d, ReferenceLine::EndPoints);
/// assert!((ends.slope - 10e-6).abs() < 1e-15);
/// assert!((ends.deviation_mm() - 0.002).abs() < 1e-15);
/// ```
pub fn straightness(
    positions_mm: &[f64],
    deviations_mm: &[f64],
    reference: ReferenceLine,
) -> Straightness {
    let n = positions_mm.len().min(deviations_mm.len());
    let (slope, intercept_mm) = match (reference, n) {
        (_, 0) => (0.0, 0.0),
        (_, 1) => (0.0, deviations_mm[0]),
        (ReferenceLine::EndPoints, _) => {
            let slope =
                (deviations_mm[n - 1] - deviations_mm[0]) / (positions_mm[n - 1] - positions_mm[0]);
            (slope, deviations_mm[0] - slope * positions_mm[0])
        }
        (ReferenceLine::LeastSquares, _) => {
            // Centred sums: the textbook normal equations, stable for
            // positions far from 0.
            let mean_x = positions_mm[..n].iter().sum::<f64>() / n as f64;
            let mean_y = deviations_mm[..n].iter().sum::<f64>() / n as f64;
            let (mut sxy, mut sxx) = (0.0, 0.0);
            for (x, y) in positions_mm.iter().zip(deviations_mm).take(n) {
                sxy += (x - mean_x) * (y - mean_y);
                sxx += (x - mean_x) * (x - mean_x);
            }
            let slope = sxy / sxx;
            (slope, mean_y - slope * mean_x)
        }
    };
    let residuals_mm = positions_mm
        .iter()
        .zip(deviations_mm)
        .take(n)
        .map(|(x, y)| y - (intercept_mm + slope * x))
        .collect();
    Straightness {
        reference,
        intercept_mm,
        slope,
        residuals_mm,
    }
}

/// How a squareness value is signed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SquarenessConvention {
    /// Renishaw's RIGHT_HANDED: positive when the angle between the positive
    /// directions of the two axes is smaller than 90°.
    #[default]
    RightHanded,
    /// Renishaw's LARGER_THAN_90: positive when that angle is larger than 90°.
    LargerThan90,
}

impl SquarenessConvention {
    /// `right-handed` or `larger-than-90`, as in the survey file.
    pub fn as_str(self) -> &'static str {
        match self {
            SquarenessConvention::RightHanded => "right-handed",
            SquarenessConvention::LargerThan90 => "larger-than-90",
        }
    }

    /// The convention named by [`SquarenessConvention::as_str`].
    pub fn from_name(name: &str) -> Option<SquarenessConvention> {
        [
            SquarenessConvention::RightHanded,
            SquarenessConvention::LargerThan90,
        ]
        .into_iter()
        .find(|c| c.as_str() == name)
    }

    /// The signed squareness, rad, of a pair whose angle is 90° + `excess_rad`.
    pub fn signed(self, excess_rad: f64) -> f64 {
        match self {
            SquarenessConvention::RightHanded => -excess_rad,
            SquarenessConvention::LargerThan90 => excess_rad,
        }
    }

    /// The angle's excess over 90°, rad, of a value signed in this convention.
    pub fn excess(self, signed_rad: f64) -> f64 {
        // Each convention is its own inverse: a sign.
        self.signed(signed_rad)
    }
}

/// The angle between the positive directions of axes A and B minus 90°,
/// rad, from the slopes of A's straightness towards B (`slope_ab`) and B's
/// towards A (`slope_ba`), both against one reference (module doc).
///
/// # Example
///
/// ```
/// use axcomp::evaluate::straightness::{SquarenessConvention, angle_excess};
///
/// // X drifts +10 µrad towards +Y, Y drifts +5 µrad towards +X: the axes
/// // close by 15 µrad, an angle of 90° − 15 µrad.
/// let excess = angle_excess(10e-6, 5e-6);
/// assert!((excess + 15e-6).abs() < 1e-18);
/// assert!((SquarenessConvention::RightHanded.signed(excess) - 15e-6).abs() < 1e-18);
/// assert!((SquarenessConvention::LargerThan90.signed(excess) + 15e-6).abs() < 1e-18);
/// ```
pub fn angle_excess(slope_ab: f64, slope_ba: f64) -> f64 {
    -(slope_ab + slope_ba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_by_hand() {
        // y = 1 + 0.5 x plus a residual pattern (+1, −2, +1) orthogonal to
        // 1 and x over x = (0, 1, 2): the fit returns the line exactly.
        let x = [0.0, 1.0, 2.0];
        let y = [1.0 + 1.0, 1.5 - 2.0, 2.0 + 1.0];
        let fit = straightness(&x, &y, ReferenceLine::LeastSquares);
        assert!((fit.slope - 0.5).abs() < 1e-15);
        assert!((fit.intercept_mm - 1.0).abs() < 1e-15);
        assert_eq!(fit.residuals_mm, vec![1.0, -2.0, 1.0]);
        assert_eq!(fit.deviation_mm(), 3.0);
        // End points: the line through (0, 2) and (2, 3), slope 0.5; the
        // middle residual is −0.5 − 2.5 = −3.
        let ends = straightness(&x, &y, ReferenceLine::EndPoints);
        assert_eq!((ends.slope, ends.intercept_mm), (0.5, 2.0));
        assert_eq!(ends.residuals_mm, vec![0.0, -3.0, 0.0]);
    }

    #[test]
    fn a_common_rotation_of_the_reference_cancels() {
        let (a, b, phi) = (7e-6, -3e-6, 40e-6);
        assert!((angle_excess(a + phi, b - phi) - angle_excess(a, b)).abs() < 1e-18);
        for convention in [
            SquarenessConvention::RightHanded,
            SquarenessConvention::LargerThan90,
        ] {
            assert_eq!(convention.excess(convention.signed(1e-6)), 1e-6);
            assert_eq!(
                SquarenessConvention::from_name(convention.as_str()),
                Some(convention)
            );
        }
    }
}
