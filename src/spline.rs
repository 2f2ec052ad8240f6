//! Interpolating cubic splines with the not-a-knot end condition, and their
//! basis matrices: shared by `compensate::retest` (the known axis error between
//! the targets of a test) and `model` (random rail and positioning profiles).
//!
//! Seed 000 fits "a smooth spline" through the knots of its random profile
//! generator (§3.2.2; `../shared/notes/seed000-volumetric-model.md` §3.7); the
//! thesis worked in MATLAB, whose `spline` is the not-a-knot cubic, and the
//! NumPy peer (`../shared/tools/mc_peer.py`) uses SciPy's
//! `CubicSpline(bc_type="not-a-knot")`. This is that spline: C² everywhere,
//! with the third derivative also continuous at the second and the
//! second-to-last knot, so that it reproduces any cubic exactly.
//!
//! A spline is linear in its values, so its value at a fixed point is a dot
//! product of a row of weights with the knot values. [`basis_matrix`] builds
//! those rows once; the Monte Carlo study then evaluates thousands of random
//! profiles with one small matrix-vector product each, as the peer does.
//!
//! Outside the knot range the end values are held (a profile is generated
//! over more than its use, and a table from a measurement must not be
//! extrapolated by a cubic). Knots must be finite and strictly increasing;
//! the callers ([`crate::model::components::ErrorTable`], the profile
//! generator, `compensate::retest`) guarantee it.

/// A not-a-knot cubic spline through `(knots, values)`.
#[derive(Clone, Debug, PartialEq)]
pub struct CubicSpline {
    knots: Vec<f64>,
    values: Vec<f64>,
    /// Second derivative at each knot (the usual "moments" M_i).
    moments: Vec<f64>,
}

impl CubicSpline {
    /// The spline through the points; `knots` finite and strictly increasing,
    /// as many values as knots, at least one.
    ///
    /// One knot gives a constant, two a straight line and three the parabola
    /// through them (the not-a-knot condition with three knots, as in MATLAB
    /// and SciPy).
    pub fn new(knots: &[f64], values: &[f64]) -> CubicSpline {
        debug_assert_eq!(knots.len(), values.len());
        debug_assert!(knots.windows(2).all(|pair| pair[0] < pair[1]));
        CubicSpline {
            knots: knots.to_vec(),
            values: values.to_vec(),
            moments: not_a_knot_moments(knots, values),
        }
    }

    /// The spline's value at `x`; the end values outside the knots.
    pub fn value_at(&self, x: f64) -> f64 {
        let n = self.knots.len();
        if x <= self.knots[0] {
            return self.values[0];
        }
        if x >= self.knots[n - 1] {
            return self.values[n - 1];
        }
        // Index of the interval [x_i, x_{i+1}] that holds x: 0 ≤ i ≤ n − 2,
        // because x lies strictly inside the knot range here.
        let i = self.knots.partition_point(|knot| *knot <= x) - 1;
        cubic_between(
            (self.knots[i], self.knots[i + 1]),
            (self.values[i], self.values[i + 1]),
            (self.moments[i], self.moments[i + 1]),
            x,
        )
    }
}

/// The cubic between two knots (x0, x1) in terms of its end values (y0, y1)
/// and moments (m0, m1), at x.
fn cubic_between((x0, x1): (f64, f64), (y0, y1): (f64, f64), (m0, m1): (f64, f64), x: f64) -> f64 {
    let h = x1 - x0;
    let (left, right) = (x1 - x, x - x0);
    m0 * left.powi(3) / (6.0 * h)
        + m1 * right.powi(3) / (6.0 * h)
        + (y0 / h - m0 * h / 6.0) * left
        + (y1 / h - m1 * h / 6.0) * right
}

/// Weights `B` (row-major, `points.len()` rows × `knots.len()` columns) such
/// that the not-a-knot spline through `(knots, v)` has the value
/// `Σ_j B[p][j] · v[j]` at `points[p]`.
///
/// Column j is the spline through the j-th unit vector, as the peer's `basis`
/// builds it.
pub fn basis_matrix(knots: &[f64], points: &[f64]) -> Vec<f64> {
    let n_knots = knots.len();
    let mut basis = vec![0.0; points.len() * n_knots];
    let mut unit = vec![0.0; n_knots];
    for column in 0..n_knots {
        unit.fill(0.0);
        unit[column] = 1.0;
        let spline = CubicSpline::new(knots, &unit);
        for (row, point) in points.iter().enumerate() {
            basis[row * n_knots + column] = spline.value_at(*point);
        }
    }
    basis
}

/// The rows of [`basis_matrix`] as (knot index, weight) pairs, without the
/// weights below 1e-18 (smaller than the rounding of any value the spline
/// gives: the weights of a not-a-knot spline decay by about 0.27 a knot away
/// from the point).
///
/// A point on a knot (or outside the knots) takes that knot's value alone:
/// one weight of 1. Between knots, each knot's weights come from the moments
/// of the spline through its unit vector solved over [`WINDOW`] knots a side
/// of it (the rest of its moments are below any weight kept), so the cost is
/// O(knots · WINDOW + points · WINDOW), not knots × points.
pub fn basis_rows(knots: &[f64], points: &[f64]) -> Vec<Vec<(usize, f64)>> {
    let n_knots = knots.len();
    // The interval [x_i, x_{i+1}] strictly inside which a point lies, if it does.
    let interval = |x: f64| -> Option<usize> {
        if x <= knots[0] || x >= knots[n_knots - 1] {
            return None;
        }
        let i = knots.partition_point(|knot| *knot < x);
        (knots[i] != x).then(|| i - 1)
    };
    let on_knot = |x: f64| -> usize {
        if x <= knots[0] {
            0
        } else if x >= knots[n_knots - 1] {
            n_knots - 1
        } else {
            knots.partition_point(|knot| *knot < x)
        }
    };
    let mut rows: Vec<Vec<(usize, f64)>> = points
        .iter()
        .map(|&x| interval(x).map_or_else(|| vec![(on_knot(x), 1.0)], |_| Vec::new()))
        .collect();
    let mut by_interval: Vec<Vec<usize>> = vec![Vec::new(); n_knots.saturating_sub(1)];
    for (p, &x) in points.iter().enumerate() {
        if let Some(i) = interval(x) {
            by_interval[i].push(p);
        }
    }
    if by_interval.iter().all(Vec::is_empty) {
        return rows;
    }
    let system = (n_knots >= 4).then(|| MomentSystem::new(knots));
    let mut unit = vec![0.0; n_knots];
    for column in 0..n_knots {
        // The unit spline's moments over the knots first ..= last (0 beyond).
        let (first, moments) = match &system {
            Some(system) => windowed_unit_moments(system, column),
            None => {
                unit.fill(0.0);
                unit[column] = 1.0;
                (0, not_a_knot_moments(knots, &unit))
            }
        };
        let last = first + moments.len() - 1;
        for i in first..last {
            for &p in &by_interval[i] {
                let y = |j: usize| f64::from(u8::from(j == column));
                let weight = cubic_between(
                    (knots[i], knots[i + 1]),
                    (y(i), y(i + 1)),
                    (moments[i - first], moments[i + 1 - first]),
                    points[p],
                );
                if weight.abs() >= 1e-18 {
                    rows[p].push((column, weight));
                }
            }
        }
    }
    rows
}

/// Knots a side of a unit value over which [`basis_rows`] solves its
/// spline's moments: the moment system is diagonally dominant by a factor 2,
/// so a unit spline's moments fall at least by half a knot away from it
/// (Demko, Moss & Smith 1984), about 0.27 on even knots; 100 knots away they
/// are below 1e-30 of the largest, far under the 1e-18 kept.
const WINDOW: usize = 100;

/// The moments of the not-a-knot spline through the unit vector at
/// `column` (n ≥ 4 knots), solved over the interior equations within
/// [`WINDOW`] of it: (first knot, moments from it on).
fn windowed_unit_moments(system: &MomentSystem, column: usize) -> (usize, Vec<f64>) {
    let h = &system.h;
    let m = system.diag.len();
    let value = |j: usize| f64::from(u8::from(j == column));
    let slope = |i: usize| (value(i + 1) - value(i)) / h[i];
    // Interior equation `row` is knot row + 1's.
    let lo = column.saturating_sub(WINDOW).min(m - 1);
    let hi = (column + WINDOW).min(m - 1);
    let rhs = (lo..=hi)
        .map(|row| 6.0 * (slope(row + 1) - slope(row)))
        .collect();
    system.solve(lo..=hi, rhs)
}

/// The tridiagonal system of the interior moments M_1 … M_{n−2} of a
/// not-a-knot spline on n ≥ 4 knots, the ends substituted (see
/// [`not_a_knot_moments`]).
struct MomentSystem {
    sub: Vec<f64>,
    diag: Vec<f64>,
    sup: Vec<f64>,
    /// The knot spacings.
    h: Vec<f64>,
}

impl MomentSystem {
    fn new(knots: &[f64]) -> MomentSystem {
        let n = knots.len();
        let h: Vec<f64> = knots.windows(2).map(|pair| pair[1] - pair[0]).collect();
        let m = n - 2;
        let mut sub = vec![0.0; m];
        let mut diag = vec![0.0; m];
        let mut sup = vec![0.0; m];
        for row in 0..m {
            let i = row + 1;
            sub[row] = h[i - 1];
            diag[row] = 2.0 * (h[i - 1] + h[i]);
            sup[row] = h[i];
        }
        let left = h[0] / h[1];
        diag[0] += h[0] * (1.0 + left);
        sup[0] -= h[0] * left;
        let right = h[n - 2] / h[n - 3];
        diag[m - 1] += h[n - 2] * (1.0 + right);
        sub[m - 1] -= h[n - 2] * right;
        MomentSystem { sub, diag, sup, h }
    }

    /// The moments from the interior equations `rows` with right-hand sides
    /// `rhs` (the others taken as 0): (first knot, moments from it on), with
    /// the end moments when the rows reach an end.
    fn solve(&self, rows: std::ops::RangeInclusive<usize>, mut rhs: Vec<f64>) -> (usize, Vec<f64>) {
        let (lo, hi) = (*rows.start(), *rows.end());
        let (m, h) = (self.diag.len(), &self.h);
        let n = m + 2;
        let sup = &self.sup[lo..=hi];
        // Thomas algorithm: forward elimination, then back substitution.
        let mut diag = self.diag[lo..=hi].to_vec();
        for row in 1..diag.len() {
            let factor = self.sub[lo + row] / diag[row - 1];
            diag[row] -= factor * sup[row - 1];
            rhs[row] -= factor * rhs[row - 1];
        }
        let len = diag.len();
        let mut interior = vec![0.0; len];
        interior[len - 1] = rhs[len - 1] / diag[len - 1];
        for row in (0..len - 1).rev() {
            interior[row] = (rhs[row] - sup[row] * interior[row + 1]) / diag[row];
        }
        let mut moments = Vec::with_capacity(len + 2);
        let first = if lo == 0 {
            let left = h[0] / h[1];
            moments.push((1.0 + left) * interior[0] - left * interior[1]);
            0
        } else {
            lo + 1
        };
        moments.extend_from_slice(&interior);
        if hi == m - 1 {
            let right = h[n - 2] / h[n - 3];
            moments.push((1.0 + right) * interior[len - 1] - right * interior[len - 2]);
        }
        (first, moments)
    }
}

/// The second derivatives at the knots of the not-a-knot spline.
///
/// Interior knots i = 1 … n−2 satisfy the C² conditions
/// h_{i−1} M_{i−1} + 2 (h_{i−1} + h_i) M_i + h_i M_{i+1} = 6 (Δ_i − Δ_{i−1}),
/// with h_i = x_{i+1} − x_i and Δ_i = (y_{i+1} − y_i) / h_i. Not-a-knot makes
/// the third derivative continuous at x_1 and x_{n−2}, i.e.
/// M_0 = (1 + h_0/h_1) M_1 − (h_0/h_1) M_2 and the mirror image at the other
/// end; substituting these into the first and last equation leaves a
/// tridiagonal system in M_1 … M_{n−2}, which is diagonally dominant, so the
/// Thomas algorithm needs no pivoting.
fn not_a_knot_moments(knots: &[f64], values: &[f64]) -> Vec<f64> {
    let n = knots.len();
    if n <= 2 {
        return vec![0.0; n];
    }
    let h: Vec<f64> = knots.windows(2).map(|pair| pair[1] - pair[0]).collect();
    let slope: Vec<f64> = (0..n - 1)
        .map(|i| (values[i + 1] - values[i]) / h[i])
        .collect();
    if n == 3 {
        // One parabola: its second derivative is twice the second divided difference.
        let curvature = 2.0 * (slope[1] - slope[0]) / (h[0] + h[1]);
        return vec![curvature; 3];
    }
    let rhs: Vec<f64> = (1..n - 1)
        .map(|i| 6.0 * (slope[i] - slope[i - 1]))
        .collect();
    MomentSystem::new(knots).solve(0..=n - 3, rhs).1
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn cubic(x: f64) -> f64 {
        0.3 - 1.2 * x + 0.05 * x * x - 0.002 * x * x * x
    }

    #[test]
    fn reproduces_a_cubic_exactly_on_uneven_knots() {
        // Not-a-knot splines reproduce every cubic (closed form: the cubic itself).
        let knots = [-3.0, -1.0, 0.5, 2.0, 6.0, 7.5];
        let values: Vec<f64> = knots.iter().map(|x| cubic(*x)).collect();
        let spline = CubicSpline::new(&knots, &values);
        for step in 0..=105 {
            let x = -3.0 + f64::from(step) * 0.1;
            assert!((spline.value_at(x) - cubic(x)).abs() < 1e-12, "x = {x}");
        }
    }

    #[test]
    fn four_knots_are_the_interpolating_cubic() {
        // With four knots both not-a-knot conditions make one cubic through all four.
        let knots = [0.0, 1.0, 3.0, 4.0];
        let values: Vec<f64> = knots.iter().map(|x| cubic(*x)).collect();
        let spline = CubicSpline::new(&knots, &values);
        assert!((spline.value_at(2.0) - cubic(2.0)).abs() < 1e-13);
    }

    #[test]
    fn degenerate_knot_counts() {
        assert_eq!(CubicSpline::new(&[2.0], &[5.0]).value_at(-1.0), 5.0);
        let line = CubicSpline::new(&[0.0, 2.0], &[1.0, 5.0]);
        assert_eq!(line.value_at(0.5), 2.0);
        // Three knots: the parabola y = x² through (0,0), (1,1), (3,9).
        let parabola = CubicSpline::new(&[0.0, 1.0, 3.0], &[0.0, 1.0, 9.0]);
        assert!((parabola.value_at(2.0) - 4.0).abs() < 1e-13);
    }

    #[test]
    fn end_values_are_held_outside_the_knots() {
        let spline = CubicSpline::new(&[0.0, 1.0, 2.0, 3.0, 4.0], &[1.0, 3.0, 2.0, 0.0, 4.0]);
        assert_eq!(spline.value_at(-10.0), 1.0);
        assert_eq!(spline.value_at(4.5), 4.0);
    }

    #[test]
    fn matches_scipy_not_a_knot() {
        // SciPy 1.17.1: CubicSpline([0, 100, 200, 300, 400, 500],
        // [0.01, -0.005, 0.012, 0.0, -0.015, 0.003], bc_type="not-a-knot")
        // evaluated at 37.5, 150, 333.3, 480 (an independent implementation).
        let knots = [0.0, 100.0, 200.0, 300.0, 400.0, 500.0];
        let values = [0.01, -0.005, 0.012, 0.0, -0.015, 0.003];
        let spline = CubicSpline::new(&knots, &values);
        let expected = [
            (37.5, SCIPY_AT_37_5),
            (150.0, SCIPY_AT_150),
            (333.3, SCIPY_AT_333_3),
            (480.0, SCIPY_AT_480),
        ];
        for (x, value) in expected {
            assert!((spline.value_at(x) - value).abs() < 1e-15, "x = {x}");
        }
    }

    const SCIPY_AT_37_5: f64 = -0.004677408854166666;
    const SCIPY_AT_150: f64 = 0.004720833333333335;
    const SCIPY_AT_333_3: f64 = -0.0066316347751000015;
    const SCIPY_AT_480: f64 = -0.004817600000000002;

    #[test]
    fn basis_rows_reproduce_the_spline() {
        let knots = [-50.0, 40.0, 130.0, 220.0, 310.0];
        let values = [0.2, -0.1, 0.4, 0.0, 0.3];
        let points = [-50.0, 0.0, 99.0, 310.0, 400.0];
        let basis = basis_matrix(&knots, &points);
        let spline = CubicSpline::new(&knots, &values);
        for (row, point) in points.iter().enumerate() {
            let dot: f64 = (0..knots.len())
                .map(|j| basis[row * knots.len() + j] * values[j])
                .sum();
            assert!((dot - spline.value_at(*point)).abs() < 1e-14);
        }
    }

    #[test]
    fn sparse_basis_rows_are_the_basis_matrix() {
        // 40 uneven knots; points on knots, between them and outside.
        let knots: Vec<f64> = (0..40)
            .map(|i| 10.0 * i as f64 + (i as f64 * 1.7).sin())
            .collect();
        let points = [
            -5.0, knots[0], knots[7], 73.3, knots[20], 201.0, knots[39], 500.0,
        ];
        let rows = basis_rows(&knots, &points);
        let dense = basis_matrix(&knots, &points);
        // On a knot or outside: that knot alone, with weight 1.
        for (p, knot) in [(0, 0), (1, 0), (2, 7), (4, 20), (6, 39), (7, 39)] {
            assert_eq!(rows[p], [(knot, 1.0)], "point {p}");
        }
        for (p, row) in rows.iter().enumerate() {
            let mut full = vec![0.0; knots.len()];
            for (j, w) in row {
                full[*j] = *w;
            }
            for (j, w) in full.iter().enumerate() {
                assert!(
                    (w - dense[p * knots.len() + j]).abs() < 1e-15,
                    "point {p} knot {j}"
                );
            }
        }
        // Between knots the weights reach a few knots away, and fall below 1e-18 far away.
        assert!(
            rows[3].len() > 4 && rows[3].len() < knots.len(),
            "{}",
            rows[3].len()
        );
    }

    proptest! {
        #[test]
        fn interpolates_its_knots(
            gaps in proptest::collection::vec(0.1f64..100.0, 1..12),
            seed_values in proptest::collection::vec(-1.0f64..1.0, 13),
        ) {
            let mut knots = vec![0.0];
            for gap in &gaps {
                knots.push(knots[knots.len() - 1] + gap);
            }
            let values = &seed_values[..knots.len()];
            let spline = CubicSpline::new(&knots, values);
            for (knot, value) in knots.iter().zip(values) {
                prop_assert!((spline.value_at(*knot) - value).abs() < 1e-9);
            }
        }
    }
}
