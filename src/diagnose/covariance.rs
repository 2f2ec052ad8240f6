//! The covariance of quantities per target of the re-test (levels,
//! reversals): each one's own variance, plus what they share through the
//! prediction, which interpolates the first test's means with the spline's
//! weights W (independent between the first test's targets, variances D):
//!
//! ```text
//! C = diag(s) + W · diag(D) · Wᵀ
//! ```
//!
//! C is dense when W is (a first test of few targets), so it is never
//! formed: C⁻¹v comes from the Woodbury identity (Golub & Van Loan 2013,
//! §2.1.4), C⁻¹ = S⁻¹ − S⁻¹W (D⁻¹ + WᵀS⁻¹W)⁻¹ WᵀS⁻¹, whose core is as large
//! as the first test and banded as W is (each target of the re-test draws on
//! neighbouring targets of the first), factored once by band Cholesky
//! (Golub & Van Loan 2013, Alg. 4.3.5). A solve then costs O(m · w + K · b)
//! for m targets with w weights each and a first test of K targets with
//! band b, instead of the m³ of a dense Cholesky.

use nalgebra::{DMatrix, DVector};

/// C = scale · (diag(own) + W diag(shared) Wᵀ), ready to solve.
#[derive(Clone, Debug)]
pub struct Covariance {
    own: Vec<f64>,
    weights: Vec<Vec<(usize, f64)>>,
    shared: Vec<f64>,
    scale: f64,
    factor: Factor,
}

#[derive(Clone, Debug)]
enum Factor {
    /// C is diagonal (no two rows share a variance): C⁻¹ element by element.
    Diagonal(Vec<f64>),
    /// The Woodbury core, by band Cholesky.
    Woodbury(BandCholesky),
    /// A dense Cholesky factor of C: only when an own variance is not
    /// positive (S⁻¹ does not exist), e.g. noise-free data.
    Dense(DMatrix<f64>),
    /// C is not positive definite.
    Singular,
}

impl Covariance {
    /// `own` variances (one per row), each row's `weights` (index into
    /// `shared`, weight) and the `shared` variances.
    pub fn new(own: Vec<f64>, weights: Vec<Vec<(usize, f64)>>, shared: Vec<f64>) -> Covariance {
        let factor = factor(&own, &weights, &shared);
        Covariance {
            own,
            weights,
            shared,
            scale: 1.0,
            factor,
        }
    }

    /// Independent rows: C = diag(own).
    pub fn diagonal(own: Vec<f64>) -> Covariance {
        let m = own.len();
        Covariance::new(own, vec![Vec::new(); m], Vec::new())
    }

    /// The same covariance times `factor`.
    pub fn scaled(&self, factor: f64) -> Covariance {
        Covariance {
            scale: self.scale * factor,
            ..self.clone()
        }
    }

    /// The covariance of the rows where `rows[i]` is true.
    pub fn restricted(&self, rows: &[bool]) -> Covariance {
        let pick = |i: &usize| rows[*i];
        let own: Vec<f64> = (0..self.own.len())
            .filter(pick)
            .map(|i| self.own[i])
            .collect();
        let weights: Vec<Vec<(usize, f64)>> = (0..self.own.len())
            .filter(pick)
            .map(|i| self.weights[i].clone())
            .collect();
        Covariance {
            scale: self.scale,
            ..Covariance::new(own, weights, self.shared.clone())
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.own.len()
    }

    /// Whether it has no rows.
    pub fn is_empty(&self) -> bool {
        self.own.is_empty()
    }

    /// C⁻¹ v; `None` if C is not positive definite.
    pub fn solve(&self, v: &[f64]) -> Option<Vec<f64>> {
        let mut x = match &self.factor {
            Factor::Singular => return None,
            Factor::Diagonal(inverse) => v.iter().zip(inverse).map(|(v, i)| v * i).collect(),
            Factor::Dense(l) => {
                let b = DVector::from_column_slice(v);
                let z = l.solve_lower_triangular(&b)?;
                let x = l.tr_solve_lower_triangular(&z)?;
                x.iter().copied().collect::<Vec<f64>>()
            }
            Factor::Woodbury(core) => {
                let u: Vec<f64> = v.iter().zip(&self.own).map(|(v, s)| v / s).collect();
                let mut t = vec![0.0; self.shared.len()];
                for (row, ui) in self.weights.iter().zip(&u) {
                    for &(k, w) in row {
                        if self.shared[k] > 0.0 {
                            t[k] += w * ui;
                        }
                    }
                }
                let s = core.solve(t);
                u.iter()
                    .zip(&self.weights)
                    .zip(&self.own)
                    .map(|((ui, row), own)| {
                        let through: f64 = row
                            .iter()
                            .filter(|(k, _)| self.shared[*k] > 0.0)
                            .map(|(k, w)| w * s[*k])
                            .sum();
                        ui - through / own
                    })
                    .collect()
            }
        };
        if self.scale != 1.0 {
            x.iter_mut().for_each(|v| *v /= self.scale);
        }
        Some(x)
    }

    /// The diagonal of C⁻¹ when C is diagonal (rows that share nothing).
    pub fn inverse_diagonal(&self) -> Option<Vec<f64>> {
        match &self.factor {
            Factor::Diagonal(inverse) => Some(inverse.iter().map(|i| i / self.scale).collect()),
            _ => None,
        }
    }

    /// For a covariance with shared variances (C = S + W D Wᵀ, S = diag(own),
    /// scaled): the diagonal of S⁻¹ and a number κ ≥ 1 with C ≤ κ·S in the
    /// Loewner order, so that vᵀC⁻¹v ≥ vᵀS⁻¹v / κ for every v. κ = 1 + ρ
    /// with ρ ≥ λ_max(D^½ WᵀS⁻¹W D^½): an estimate by power iteration,
    /// raised until the band Cholesky of ρ·D⁻¹ − WᵀS⁻¹W succeeds (which
    /// proves ρ above every eigenvalue), else Gershgorin's bound. `None` for a
    /// diagonal or a dense covariance.
    pub fn diagonal_bound(&self) -> Option<(Vec<f64>, f64)> {
        if !matches!(self.factor, Factor::Woodbury(_)) {
            return None;
        }
        let inverse: Vec<f64> = self.own.iter().map(|s| 1.0 / (s * self.scale)).collect();
        let rho = largest_shared_eigenvalue(&self.own, &self.weights, &self.shared)?;
        Some((inverse, 1.0 + rho))
    }

    /// Element (a, b) of C.
    pub fn at(&self, a: usize, b: usize) -> f64 {
        let shared: f64 = self.weights[a]
            .iter()
            .flat_map(|(ka, wa)| {
                self.weights[b]
                    .iter()
                    .filter(move |(kb, _)| kb == ka)
                    .map(move |(_, wb)| wa * wb * self.shared[*ka])
            })
            .sum();
        self.scale * (if a == b { self.own[a] } else { 0.0 } + shared)
    }
}

fn factor(own: &[f64], weights: &[Vec<(usize, f64)>], shared: &[f64]) -> Factor {
    if let Some(diagonal) = diagonal(own, weights, shared) {
        return if diagonal.iter().all(|c| *c > 0.0 && c.is_finite()) {
            Factor::Diagonal(diagonal.iter().map(|c| 1.0 / c).collect())
        } else {
            Factor::Singular
        };
    }
    if own.iter().all(|s| *s > 0.0 && s.is_finite())
        && let Some(core) = woodbury_core(own, weights, shared)
    {
        return Factor::Woodbury(core);
    }
    // C itself, as a dense matrix (rows with a zero variance of their own).
    let m = own.len();
    let c = Covariance {
        own: own.to_vec(),
        weights: weights.to_vec(),
        shared: shared.to_vec(),
        scale: 1.0,
        factor: Factor::Singular,
    };
    let dense = DMatrix::from_fn(m, m, |a, b| c.at(a, b));
    match dense.cholesky() {
        Some(cholesky) => Factor::Dense(cholesky.l()),
        None => Factor::Singular,
    }
}

/// The diagonal of C when no two rows share a variance (a re-test at the
/// first test's targets: each level draws on its own target's mean alone).
fn diagonal(own: &[f64], weights: &[Vec<(usize, f64)>], shared: &[f64]) -> Option<Vec<f64>> {
    let mut taken = vec![false; shared.len()];
    let mut diagonal = own.to_vec();
    for (row, c) in weights.iter().zip(&mut diagonal) {
        for &(k, w) in row.iter().filter(|(k, _)| shared[*k] != 0.0) {
            if std::mem::replace(&mut taken[k], true) {
                return None;
            }
            *c += w * w * shared[k];
        }
    }
    Some(diagonal)
}

/// D⁻¹ + WᵀS⁻¹W over the shared variances that are positive (the others
/// share nothing), by band Cholesky.
fn woodbury_core(
    own: &[f64],
    weights: &[Vec<(usize, f64)>],
    shared: &[f64],
) -> Option<BandCholesky> {
    // A shared variance of 0 leaves its row of the core as the identity (unused).
    BandCholesky::new(band_gram(own, weights, shared, |d| {
        if d > 0.0 { 1.0 / d } else { 1.0 }
    }))
}

/// diag(diagonal(D)) + WᵀS⁻¹W over the shared variances that are positive,
/// as a band matrix as wide as W's rows reach.
fn band_gram(
    own: &[f64],
    weights: &[Vec<(usize, f64)>],
    shared: &[f64],
    diagonal: impl Fn(f64) -> f64,
) -> BandMatrix {
    let used = |j: &usize| shared[*j] > 0.0;
    let band = weights
        .iter()
        .map(|row| {
            let (low, high) = row
                .iter()
                .map(|(j, _)| *j)
                .filter(used)
                .fold((usize::MAX, 0), |(lo, hi), j| (lo.min(j), hi.max(j)));
            high.saturating_sub(low)
        })
        .max()
        .unwrap_or(0);
    let mut gram = BandMatrix::zeros(shared.len(), band);
    for (j, d) in shared.iter().enumerate() {
        *gram.at_mut(j, j) = diagonal(*d);
    }
    for (row, s) in weights.iter().zip(own) {
        for &(a, wa) in row.iter().filter(|(j, _)| used(j)) {
            for &(b, wb) in row.iter().filter(|(j, _)| used(j)) {
                if b <= a {
                    *gram.at_mut(a, b) += wa * wb / s;
                }
            }
        }
    }
    gram
}

/// A number ρ ≥ λ_max(B), B = D^½ WᵀS⁻¹W D^½ (the shared variances' share of
/// C relative to S), within a few per cent of it.
fn largest_shared_eigenvalue(
    own: &[f64],
    weights: &[Vec<(usize, f64)>],
    shared: &[f64],
) -> Option<f64> {
    let gram = band_gram(own, weights, shared, |_| 0.0);
    let root: Vec<f64> = shared.iter().map(|d| d.max(0.0).sqrt()).collect();
    let k = shared.len();
    // Gershgorin: the largest absolute row sum of B.
    let gershgorin = (0..k)
        .map(|i| {
            let lo = i.saturating_sub(gram.band);
            let hi = (i + gram.band).min(k - 1);
            (lo..=hi)
                .map(|j| (root[i] * gram.sym(i, j) * root[j]).abs())
                .sum::<f64>()
        })
        .fold(0.0, f64::max);
    if !gershgorin.is_finite() {
        return None;
    }
    // Power iteration from the constant (the smooth errors the shared variances add most to).
    let mut x: Vec<f64> = root.iter().map(|r| f64::from(u8::from(*r > 0.0))).collect();
    let mut estimate = 0.0;
    for _ in 0..60 {
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm == 0.0 {
            return Some(0.0);
        }
        x.iter_mut().for_each(|v| *v /= norm);
        let scaled: Vec<f64> = x.iter().zip(&root).map(|(v, r)| v * r).collect();
        let y: Vec<f64> = gram
            .times(&scaled)
            .iter()
            .zip(&root)
            .map(|(v, r)| v * r)
            .collect();
        estimate = x.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>();
        x = y;
    }
    // ρ·D⁻¹ − WᵀS⁻¹W positive definite ⇔ ρ > λ_max(B) (on the used variances).
    let proven = |rho: f64| {
        let mut test = gram.clone();
        test.values.iter_mut().for_each(|v| *v = -*v);
        for (j, d) in shared.iter().enumerate() {
            *test.at_mut(j, j) += if *d > 0.0 { rho / d } else { 1.0 };
        }
        BandCholesky::new(test).is_some()
    };
    [1.02, 1.1, 1.3]
        .iter()
        .map(|f| estimate * f)
        .take_while(|rho| *rho < gershgorin)
        .find(|rho| *rho > 0.0 && proven(*rho))
        .or(Some(gershgorin))
}

/// A symmetric band matrix: its lower triangle within `band` of the diagonal.
#[derive(Clone, Debug)]
struct BandMatrix {
    size: usize,
    band: usize,
    /// Row i holds (i, i − band) … (i, i), at i·(band + 1) + band − (i − j).
    values: Vec<f64>,
}

impl BandMatrix {
    fn zeros(size: usize, band: usize) -> BandMatrix {
        BandMatrix {
            size,
            band,
            values: vec![0.0; size * (band + 1)],
        }
    }

    fn index(&self, i: usize, j: usize) -> usize {
        debug_assert!(j <= i && i - j <= self.band);
        i * (self.band + 1) + self.band - (i - j)
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        self.values[self.index(i, j)]
    }

    fn at_mut(&mut self, i: usize, j: usize) -> &mut f64 {
        let index = self.index(i, j);
        &mut self.values[index]
    }

    /// Element (i, j) of the symmetric matrix, 0 outside the band.
    fn sym(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if j <= i { (i, j) } else { (j, i) };
        if i - j > self.band {
            0.0
        } else {
            self.at(i, j)
        }
    }

    /// A x.
    fn times(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.size];
        for i in 0..self.size {
            for j in i.saturating_sub(self.band)..=i {
                let a = self.at(i, j);
                y[i] += a * x[j];
                if j != i {
                    y[j] += a * x[i];
                }
            }
        }
        y
    }
}

/// The Cholesky factor L (A = L Lᵀ) of a symmetric positive definite band
/// matrix, which keeps A's band (Golub & Van Loan 2013, Alg. 4.3.5).
#[derive(Clone, Debug)]
struct BandCholesky {
    l: BandMatrix,
}

impl BandCholesky {
    fn new(a: BandMatrix) -> Option<BandCholesky> {
        let (n, p) = (a.size, a.band);
        let mut l = a;
        for i in 0..n {
            for j in i.saturating_sub(p)..=i {
                let first = i.saturating_sub(p);
                let mut sum = l.at(i, j);
                for k in first..j {
                    sum -= l.at(i, k) * l.at(j, k);
                }
                if i == j {
                    if sum <= 0.0 || !sum.is_finite() {
                        return None;
                    }
                    *l.at_mut(i, i) = sum.sqrt();
                } else {
                    *l.at_mut(i, j) = sum / l.at(j, j);
                }
            }
        }
        Some(BandCholesky { l })
    }

    /// A⁻¹ b: L z = b forward, then Lᵀ x = z backward (within the band).
    #[allow(clippy::needless_range_loop)]
    fn solve(&self, mut b: Vec<f64>) -> Vec<f64> {
        let (n, p, l) = (self.l.size, self.l.band, &self.l);
        for i in 0..n {
            let mut sum = b[i];
            for k in i.saturating_sub(p)..i {
                sum -= l.at(i, k) * b[k];
            }
            b[i] = sum / l.at(i, i);
        }
        for i in (0..n).rev() {
            let mut sum = b[i];
            for k in i + 1..n.min(i + p + 1) {
                sum -= l.at(k, i) * b[k];
            }
            b[i] = sum / l.at(i, i);
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// C formed densely and inverted by nalgebra's Cholesky.
    fn dense_solve(c: &Covariance, v: &[f64]) -> Vec<f64> {
        let m = c.len();
        let dense = DMatrix::from_fn(m, m, |a, b| c.at(a, b));
        let x = dense
            .cholesky()
            .unwrap()
            .solve(&DVector::from_column_slice(v));
        x.iter().copied().collect()
    }

    #[test]
    fn two_readings_sharing_an_error_by_hand() {
        // C = [[2, 1], [1, 2]]: C⁻¹ = [[2, −1], [−1, 2]] / 3, so C⁻¹ (1, 0) = (2, −1)/3.
        let c = Covariance::new(
            vec![1.0, 1.0],
            vec![vec![(0, 1.0)], vec![(0, 1.0)]],
            vec![1.0],
        );
        let x = c.solve(&[1.0, 0.0]).unwrap();
        assert!(
            (x[0] - 2.0 / 3.0).abs() < 1e-15 && (x[1] + 1.0 / 3.0).abs() < 1e-15,
            "{x:?}"
        );
        // Scaled by 3: C⁻¹ / 3.
        let x = c.scaled(3.0).solve(&[1.0, 0.0]).unwrap();
        assert!((x[0] - 2.0 / 9.0).abs() < 1e-15, "{x:?}");
    }

    #[test]
    fn woodbury_with_a_band_agrees_with_a_dense_cholesky() {
        // 40 rows drawing on 3 neighbouring shared variances each (band 2), some of
        // them 0, and a few rows with none.
        let k = 20;
        let shared: Vec<f64> = (0..k)
            .map(|j| {
                if j % 7 == 3 {
                    0.0
                } else {
                    0.5 + 0.1 * j as f64
                }
            })
            .collect();
        let weights: Vec<Vec<(usize, f64)>> = (0..40)
            .map(|i| {
                if i % 11 == 5 {
                    return Vec::new();
                }
                let centre = (i / 2).min(k - 3);
                (0..3)
                    .map(|d| (centre + d, 0.3 + 0.2 * d as f64 - 0.01 * i as f64))
                    .collect()
            })
            .collect();
        let own: Vec<f64> = (0..40).map(|i| 0.2 + 0.05 * (i % 5) as f64).collect();
        let c = Covariance::new(own, weights, shared);
        assert!(matches!(c.factor, Factor::Woodbury(ref core) if core.l.band == 2));
        let v: Vec<f64> = (0..40).map(|i| (i as f64 * 0.7).sin()).collect();
        let fast = c.solve(&v).unwrap();
        let dense = dense_solve(&c, &v);
        for (a, b) in fast.iter().zip(&dense) {
            assert!((a - b).abs() < 1e-12 * b.abs().max(1.0), "{a} vs {b}");
        }
        // A subset of the rows: the covariance of those.
        let rows: Vec<bool> = (0..40).map(|i| i % 3 != 0).collect();
        let sub = c.restricted(&rows);
        let w: Vec<f64> = v
            .iter()
            .zip(&rows)
            .filter(|(_, r)| **r)
            .map(|(v, _)| *v)
            .collect();
        let fast = sub.solve(&w).unwrap();
        let dense = dense_solve(&sub, &w);
        for (a, b) in fast.iter().zip(&dense) {
            assert!((a - b).abs() < 1e-12 * b.abs().max(1.0), "{a} vs {b}");
        }
    }

    #[test]
    fn rows_that_share_nothing_are_a_diagonal() {
        // Each row its own shared variance: C = diag(1 + 0.25·2, 2 + 1·3) = diag(1.5, 5).
        let c = Covariance::new(
            vec![1.0, 2.0],
            vec![vec![(1, 0.5)], vec![(0, 1.0)]],
            vec![3.0, 2.0],
        );
        assert!(matches!(c.factor, Factor::Diagonal(_)));
        let x = c.solve(&[3.0, 5.0]).unwrap();
        assert!(
            (x[0] - 2.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15,
            "{x:?}"
        );
    }

    #[test]
    fn a_row_without_its_own_variance_falls_back_to_the_dense_factor() {
        // C = [[0 + 1, 1], [1, 1 + 1]] = [[1, 1], [1, 2]]: C⁻¹ = [[2, −1], [−1, 1]].
        let c = Covariance::new(
            vec![0.0, 1.0],
            vec![vec![(0, 1.0)], vec![(0, 1.0)]],
            vec![1.0],
        );
        let x = c.solve(&[1.0, 0.0]).unwrap();
        assert!(
            (x[0] - 2.0).abs() < 1e-12 && (x[1] + 1.0).abs() < 1e-12,
            "{x:?}"
        );
        assert!(Covariance::diagonal(vec![0.0]).solve(&[1.0]).is_none());
    }
}
