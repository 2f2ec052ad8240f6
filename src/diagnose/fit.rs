//! Linear least squares over the readings, and leave-one-run-out prediction.
//!
//! Every effect `diagnose` knows is linear in its parameters once its shape
//! is fixed (a period, a run), so a model is a set of columns over the
//! readings and a fit is ordinary least squares (SVD, so collinear columns
//! give the minimum-norm solution instead of a failure).
//!
//! A design may start with one level per group (a cell: target × direction),
//! as many parameters as there are cells. Those are not built as columns:
//! by the Frisch–Waugh–Lovell theorem the fit of the other columns is the fit
//! of their deviations from the group means, and each group's level the mean
//! of what those leave (Davidson & MacKinnon 2004, §2.4; the "within"
//! estimator of panel data). A fit then costs O(rows · columns²), not the
//! cube of the number of cells.
//!
//! Generalised least squares ([`fit_gls`]) takes its covariance as a
//! [`Covariance`], which solves C⁻¹v in time linear in the levels.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::covariance::Covariance;

/// A design: one level per group (if any), then one column per parameter,
/// one row per reading.
#[derive(Clone, Debug, Default)]
pub struct Design {
    /// One level per group ahead of the columns.
    pub groups: Option<Arc<Groups>>,
    /// Columns, each as long as the readings.
    pub columns: Vec<Vec<f64>>,
}

/// The group of every row: its level is a parameter of the design.
#[derive(Clone, Debug, PartialEq)]
pub struct Groups {
    /// The group of each row, `< count`.
    pub of_row: Vec<usize>,
    /// How many groups (parameters).
    pub count: usize,
}

impl Design {
    /// A design of columns only.
    pub fn of_columns(columns: Vec<Vec<f64>>) -> Design {
        Design {
            groups: None,
            columns,
        }
    }

    /// Appends columns.
    pub fn with(&self, more: &[Vec<f64>]) -> Design {
        let mut columns = self.columns.clone();
        columns.extend(more.iter().cloned());
        Design {
            groups: self.groups.clone(),
            columns,
        }
    }

    /// Number of parameters.
    pub fn parameters(&self) -> usize {
        self.groups.as_ref().map_or(0, |g| g.count) + self.columns.len()
    }
}

/// The result of a fit.
#[derive(Clone, Debug)]
pub struct Fit {
    /// Coefficients, one per column.
    pub coefficients: Vec<f64>,
    /// Residual sum of squares.
    pub rss: f64,
    /// Rank of the design (identifiable parameters).
    pub rank: usize,
    /// Standard errors of the coefficients (σ̂ · √diag((XᵀX)⁺)).
    pub standard_errors: Vec<f64>,
    /// Fitted values.
    pub fitted: Vec<f64>,
}

/// The minimum-norm least-squares solution of a small system given by its
/// Gram matrix G = XᵀX and b = Xᵀy: the singular values of X are √eig(G),
/// those above `largest · 1e-10 · scale` count (the rank), and (XᵀX)⁺ is
/// V Λ⁻¹ Vᵀ over them. Returns (β, rank, (XᵀX)⁺).
pub(super) fn solve_normal(
    gram: DMatrix<f64>,
    b: &DVector<f64>,
    scale: usize,
) -> (DVector<f64>, usize, DMatrix<f64>) {
    let k = gram.nrows();
    let eigen = SymmetricEigen::new(gram);
    let singular: Vec<f64> = eigen
        .eigenvalues
        .iter()
        .map(|l| l.max(0.0).sqrt())
        .collect();
    let largest = singular.iter().fold(0.0f64, |m, v| m.max(*v));
    let tolerance = largest * 1e-10 * (scale as f64);
    let mut inverse = DMatrix::zeros(k, k);
    let mut rank = 0;
    for (j, s) in singular.iter().enumerate() {
        if *s > tolerance {
            rank += 1;
            let v = eigen.eigenvectors.column(j);
            inverse += v * v.transpose() / (s * s);
        }
    }
    let beta = &inverse * b;
    (beta, rank, inverse)
}

/// The minimum-norm least-squares solution of X β = y by SVD, with the
/// rank and (XᵀX)⁺ over the singular values above `largest · 1e-10 · scale`
/// (`largest` at least `floor`).
fn solve_svd(
    x: DMatrix<f64>,
    y: &DVector<f64>,
    scale: usize,
    floor: f64,
) -> (DVector<f64>, usize, DMatrix<f64>) {
    let k = x.ncols();
    let svd = x.svd(true, true);
    let largest = svd.singular_values.iter().fold(floor, |m, v| m.max(*v));
    let tolerance = largest * 1e-10 * (scale as f64);
    let rank = svd
        .singular_values
        .iter()
        .filter(|v| **v > tolerance)
        .count();
    let beta = svd
        .solve(y, tolerance)
        .unwrap_or_else(|_| DVector::zeros(k));
    // (XᵀX)⁺ = V Σ⁻² Vᵀ over the non-negligible singular values.
    let mut inverse = DMatrix::zeros(k, k);
    if let Some(v_t) = &svd.v_t {
        for (j, s) in svd.singular_values.iter().enumerate() {
            if *s > tolerance {
                let v = v_t.row(j).transpose();
                inverse += &v * v.transpose() / (s * s);
            }
        }
    }
    (beta, rank, inverse)
}

/// Fits `y` on the design, using only the rows where `rows[i]` is true.
pub fn fit(design: &Design, y: &[f64], rows: Option<&[bool]>) -> Fit {
    let selected: Vec<usize> = (0..y.len())
        .filter(|&i| rows.is_none_or(|r| r[i]))
        .collect();
    let k = design.parameters();
    let n = selected.len();
    if k == 0 || n == 0 {
        let rss = selected.iter().map(|&i| y[i] * y[i]).sum();
        return Fit {
            coefficients: vec![0.0; k],
            rss,
            rank: 0,
            standard_errors: vec![0.0; k],
            fitted: vec![0.0; y.len()],
        };
    }
    let columns = &design.columns;
    let c = columns.len();
    // Group means over the selected rows (none: every row its own deviation from 0).
    let (group_count, of_row) = match &design.groups {
        Some(g) => (g.count, Some(&g.of_row)),
        None => (0, None),
    };
    let mut count = vec![0usize; group_count];
    let mut mean_y = vec![0.0; group_count];
    let mut mean_x = vec![vec![0.0; c]; group_count];
    if let Some(of_row) = of_row {
        for &i in &selected {
            let g = of_row[i];
            count[g] += 1;
            mean_y[g] += y[i];
            for (j, column) in columns.iter().enumerate() {
                mean_x[g][j] += column[i];
            }
        }
        for g in 0..group_count {
            if count[g] > 0 {
                let n_g = count[g] as f64;
                mean_y[g] /= n_g;
                mean_x[g].iter_mut().for_each(|v| *v /= n_g);
            }
        }
    }
    let centre = |i: usize| of_row.map(|o| o[i]);
    let x = DMatrix::from_fn(n, c, |r, j| {
        let i = selected[r];
        columns[j][i] - centre(i).map_or(0.0, |g| mean_x[g][j])
    });
    let target = DVector::from_iterator(
        n,
        selected
            .iter()
            .map(|&i| y[i] - centre(i).map_or(0.0, |g| mean_y[g])),
    );
    let levels_used = count.iter().filter(|n_g| **n_g > 0).count();
    // A group's indicator has the singular value √n_g: the scale of the whole design.
    let floor = count
        .iter()
        .map(|n_g| (*n_g as f64).sqrt())
        .fold(0.0, f64::max);
    let (beta, rank_columns, inverse) = if c == 0 {
        (DVector::zeros(0), 0, DMatrix::zeros(0, 0))
    } else {
        solve_svd(x, &target, n.max(k), floor)
    };
    let rank = levels_used + rank_columns;
    let levels: Vec<f64> = (0..group_count)
        .map(|g| {
            if count[g] == 0 {
                0.0
            } else {
                mean_y[g] - (0..c).map(|j| mean_x[g][j] * beta[j]).sum::<f64>()
            }
        })
        .collect();
    let fitted: Vec<f64> = (0..y.len())
        .map(|i| {
            centre(i).map_or(0.0, |g| levels[g])
                + (0..c).map(|j| columns[j][i] * beta[j]).sum::<f64>()
        })
        .collect();
    let rss: f64 = selected.iter().map(|&i| (y[i] - fitted[i]).powi(2)).sum();
    let sigma2 = if n > rank {
        rss / (n - rank) as f64
    } else {
        0.0
    };
    // (XᵀX)⁺ by blocks: a level's variance is 1/n_g plus what the columns'
    // uncertainty adds through its means, x̄_gᵀ (Z̃ᵀZ̃)⁺ x̄_g.
    let mut standard_errors: Vec<f64> = (0..group_count)
        .map(|g| {
            if count[g] == 0 {
                return 0.0;
            }
            let m = DVector::from_column_slice(&mean_x[g]);
            let through_columns = if c == 0 {
                0.0
            } else {
                (m.transpose() * &inverse * &m)[(0, 0)]
            };
            (sigma2 * (1.0 / count[g] as f64 + through_columns)).sqrt()
        })
        .collect();
    standard_errors.extend((0..c).map(|j| (sigma2 * inverse[(j, j)]).sqrt()));
    let mut coefficients = levels;
    coefficients.extend(beta.iter().copied());
    Fit {
        coefficients,
        rss,
        rank,
        standard_errors,
        fitted,
    }
}

/// A generalised least-squares fit with a known covariance (the per-target levels of `diagnose`).
#[derive(Clone, Debug)]
pub struct WeightedFit {
    /// Coefficients, one per column.
    pub coefficients: Vec<f64>,
    /// χ² = rᵀ C⁻¹ r of the residual r.
    pub chi2: f64,
    /// Rank of the design.
    pub rank: usize,
    /// Standard errors from the known covariance, √diag((Xᵀ C⁻¹ X)⁺).
    pub standard_errors: Vec<f64>,
    /// Fitted values, for every row (also the ones not used).
    pub fitted: Vec<f64>,
}

/// What a generalised least-squares fit of a design keeps to be extended by
/// more columns: C⁻¹ of the data and of each column, so that a candidate's
/// one or two columns cost one solve each and their products with these
/// (the periodogram's frequencies share the base's work).
pub struct GlsBase {
    columns: Vec<Vec<f64>>,
    inverse_columns: Vec<Vec<f64>>,
    y: Vec<f64>,
    inverse_y: Vec<f64>,
}

impl GlsBase {
    /// The base of `columns` (every row) with the data `y`; `None` if the
    /// covariance cannot be factored.
    pub fn new(columns: &[Vec<f64>], y: &[f64], covariance: &Covariance) -> Option<GlsBase> {
        let inverse_y = covariance.solve(y)?;
        let inverse_columns = columns
            .iter()
            .map(|c| covariance.solve(c))
            .collect::<Option<Vec<_>>>()?;
        Some(GlsBase {
            columns: columns.to_vec(),
            inverse_columns,
            y: y.to_vec(),
            inverse_y,
        })
    }

    /// Whether this is the base of `columns`.
    pub fn is_of(&self, columns: &[Vec<f64>]) -> bool {
        self.columns == columns
    }

    /// The fit of the base's columns and `extra`.
    pub fn fit_with(&self, extra: &[Vec<f64>], covariance: &Covariance) -> WeightedFit {
        let inverse_extra: Option<Vec<Vec<f64>>> =
            extra.iter().map(|c| covariance.solve(c)).collect();
        let Some(inverse_extra) = inverse_extra else {
            return failed_fit(self.columns.len() + extra.len(), self.y.len());
        };
        let columns: Vec<&[f64]> = self
            .columns
            .iter()
            .chain(extra)
            .map(Vec::as_slice)
            .collect();
        let inverse: Vec<&[f64]> = self
            .inverse_columns
            .iter()
            .chain(&inverse_extra)
            .map(Vec::as_slice)
            .collect();
        gls_solution(&columns, &inverse, &self.y, &self.inverse_y)
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn failed_fit(k: usize, rows: usize) -> WeightedFit {
    WeightedFit {
        coefficients: vec![0.0; k],
        chi2: f64::INFINITY,
        rank: 0,
        standard_errors: vec![0.0; k],
        fitted: vec![0.0; rows],
    }
}

/// GLS from the columns X, C⁻¹X, the data y and C⁻¹y (all over the used rows):
/// β = (XᵀC⁻¹X)⁺ XᵀC⁻¹y, χ² = rᵀC⁻¹r with C⁻¹r = C⁻¹y − C⁻¹X β.
fn gls_solution(
    columns: &[&[f64]],
    inverse_columns: &[&[f64]],
    y: &[f64],
    inverse_y: &[f64],
) -> WeightedFit {
    let k = columns.len();
    let n = y.len();
    let gram = DMatrix::from_fn(k, k, |a, b| dot(columns[a], inverse_columns[b]));
    // Symmetric to the last bit, as the eigen-decomposition expects.
    let gram = (&gram + gram.transpose()) * 0.5;
    let b = DVector::from_iterator(k, columns.iter().map(|c| dot(c, inverse_y)));
    let (beta, rank, inverse) = if k == 0 {
        (DVector::zeros(0), 0, DMatrix::zeros(0, 0))
    } else {
        solve_normal(gram, &b, n.max(k))
    };
    let mut fitted = vec![0.0; n];
    let mut inverse_residual = inverse_y.to_vec();
    for j in 0..k {
        for i in 0..n {
            fitted[i] += beta[j] * columns[j][i];
            inverse_residual[i] -= beta[j] * inverse_columns[j][i];
        }
    }
    let residual: Vec<f64> = y.iter().zip(&fitted).map(|(y, f)| y - f).collect();
    WeightedFit {
        coefficients: beta.iter().copied().collect(),
        chi2: dot(&residual, &inverse_residual),
        rank,
        standard_errors: (0..k).map(|j| inverse[(j, j)].max(0.0).sqrt()).collect(),
        fitted,
    }
}

/// Generalised least squares with a known covariance `covariance` (n × n):
/// β = (Xᵀ C⁻¹ X)⁺ Xᵀ C⁻¹ y (the least squares of the data whitened by C's
/// Cholesky factor, with the standard errors of a known covariance). Only
/// the rows where `rows[i]` is true are used.
pub fn fit_gls(
    design: &Design,
    y: &[f64],
    covariance: &Covariance,
    rows: Option<&[bool]>,
) -> WeightedFit {
    let k = design.parameters();
    let restricted;
    let (covariance, selected): (&Covariance, Vec<usize>) = match rows {
        Some(r) => {
            restricted = covariance.restricted(r);
            (&restricted, (0..y.len()).filter(|&i| r[i]).collect())
        }
        None => (covariance, (0..y.len()).collect()),
    };
    let take = |values: &[f64]| selected.iter().map(|&i| values[i]).collect::<Vec<f64>>();
    let columns: Vec<Vec<f64>> = design.columns.iter().map(|c| take(c)).collect();
    let Some(base) = GlsBase::new(&columns, &take(y), covariance) else {
        return failed_fit(k, y.len());
    };
    let result = base.fit_with(&[], covariance);
    // Fitted values for every row, also the ones not used.
    let fitted = (0..y.len())
        .map(|i| {
            (0..k)
                .map(|c| design.columns[c][i] * result.coefficients[c])
                .sum()
        })
        .collect();
    WeightedFit { fitted, ..result }
}

/// Leave-one-run-out: for each run, fit on the other runs and predict the
/// readings of this one; returns the root mean square of those predictions'
/// errors. `run_of[i]` is the run of reading i.
pub fn leave_one_run_out_rmse(
    design: &Design,
    y: &[f64],
    run_of: &[usize],
    run_count: usize,
) -> f64 {
    let mut sum_sq = 0.0;
    let mut count = 0usize;
    for held_out in 0..run_count {
        let training: Vec<bool> = run_of.iter().map(|&r| r != held_out).collect();
        if !training.iter().any(|&t| t) {
            continue;
        }
        let fitted = fit(design, y, Some(&training));
        for (i, &run) in run_of.iter().enumerate() {
            if run == held_out {
                sum_sq += (y[i] - fitted.fitted[i]).powi(2);
                count += 1;
            }
        }
    }
    if count == 0 {
        0.0
    } else {
        (sum_sq / count as f64).sqrt()
    }
}

/// Bayesian information criterion of a Gaussian fit: n·ln(RSS/n) + k·ln(n).
pub fn bic(rss: f64, n: usize, parameters: usize) -> f64 {
    let n_f = n as f64;
    n_f * (rss.max(1e-300) / n_f).ln() + parameters as f64 * n_f.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_by_hand() {
        // y = 1 + 2x at x = 0, 1, 2, 3 with residuals +0.1, −0.1, −0.1, +0.1.
        let x = vec![0.0, 1.0, 2.0, 3.0];
        let y = vec![1.1, 2.9, 4.9, 7.1];
        let design = Design::of_columns(vec![vec![1.0; 4], x]);
        let result = fit(&design, &y, None);
        assert!(
            (result.coefficients[0] - 1.0).abs() < 1e-12
                && (result.coefficients[1] - 2.0).abs() < 1e-12,
            "{:?}",
            result.coefficients
        );
        assert!((result.rss - 0.04).abs() < 1e-12);
        assert_eq!(result.rank, 2);
        // σ̂² = 0.04/2; Var(slope) = σ̂²/Σ(x − x̄)² = 0.02/5.
        assert!((result.standard_errors[1] - (0.02f64 / 5.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn collinear_columns_do_not_fail() {
        let design = Design::of_columns(vec![vec![1.0; 3], vec![2.0; 3]]);
        let result = fit(&design, &[1.0, 2.0, 3.0], None);
        assert_eq!(result.rank, 1);
        assert!((result.rss - 2.0).abs() < 1e-9);
    }

    #[test]
    fn weighted_mean_by_hand() {
        // Two levels 1 ± 1 and 4 ± 2 (variances 1 and 4): weights 1 and 1/4,
        // mean (1 + 1) / 1.25 = 1.6 with variance 1/1.25 = 0.8;
        // χ² = 0.6²/1 + 2.4²/4 = 1.8.
        let design = Design::of_columns(vec![vec![1.0, 1.0]]);
        let covariance = Covariance::diagonal(vec![1.0, 4.0]);
        let result = fit_gls(&design, &[1.0, 4.0], &covariance, None);
        assert!((result.coefficients[0] - 1.6).abs() < 1e-12);
        assert!((result.standard_errors[0] - 0.8f64.sqrt()).abs() < 1e-12);
        assert!((result.chi2 - 1.8).abs() < 1e-12);
    }

    #[test]
    fn correlated_errors_by_hand() {
        // Two readings sharing an error of variance 1 on top of independent
        // errors of variance 1: C = [[2, 1], [1, 2]]. Their mean has variance
        // (2 + 2 + 2·1)/4 = 1.5, and GLS of a constant gives the plain mean.
        let design = Design::of_columns(vec![vec![1.0, 1.0]]);
        // C = diag(1, 1) + (1, 1)ᵀ · 1 · (1, 1).
        let covariance = Covariance::new(
            vec![1.0, 1.0],
            vec![vec![(0, 1.0)], vec![(0, 1.0)]],
            vec![1.0],
        );
        let result = fit_gls(&design, &[1.0, 3.0], &covariance, None);
        assert!((result.coefficients[0] - 2.0).abs() < 1e-12);
        assert!((result.standard_errors[0] - 1.5f64.sqrt()).abs() < 1e-12);
        // χ² = rᵀ C⁻¹ r with r = (−1, 1): C⁻¹ = [[2, −1], [−1, 2]]/3 → (2 + 2 + 2)/3 = 2.
        assert!((result.chi2 - 2.0).abs() < 1e-12);
    }

    /// 30 targets × 2 directions × 4 runs, a drift column in hours and an
    /// outlier-run column: the levels absorbed by groups against the same
    /// design with one indicator column per cell (the dense SVD).
    fn grouped_and_dense() -> (Design, Design, Vec<f64>, Vec<usize>) {
        let (targets, runs) = (30, 8);
        let mut of_row = Vec::new();
        let mut run_of = Vec::new();
        let (mut drift, mut outlier, mut y) = (Vec::new(), Vec::new(), Vec::new());
        for run in 0..runs {
            for t in 0..targets {
                let cell = 2 * t + run % 2;
                let hours = (run * targets + t) as f64 / 40.0;
                of_row.push(cell);
                run_of.push(run);
                drift.push(hours);
                outlier.push(f64::from(u8::from(run == 4)));
                let noise = ((run * 31 + t * 7) as f64 * 1.3).sin() * 0.3;
                y.push(0.1 * cell as f64 + 2.0 * hours + 1.5 * outlier[outlier.len() - 1] + noise);
            }
        }
        let count = 2 * targets;
        let indicators: Vec<Vec<f64>> = (0..count)
            .map(|c| {
                of_row
                    .iter()
                    .map(|&g| f64::from(u8::from(g == c)))
                    .collect()
            })
            .collect();
        let grouped = Design {
            groups: Some(Arc::new(Groups { of_row, count })),
            columns: vec![drift.clone(), outlier.clone()],
        };
        let dense = Design::of_columns(indicators).with(&[drift, outlier]);
        (grouped, dense, y, run_of)
    }

    #[test]
    fn levels_absorbed_by_groups_fit_as_the_dense_design_does() {
        let (grouped, dense, y, run_of) = grouped_and_dense();
        // All rows, and without run 4 (its outlier column all 0: rank deficient) or run 1.
        for held_out in [None, Some(4), Some(1)] {
            let rows: Vec<bool> = run_of.iter().map(|r| Some(*r) != held_out).collect();
            let a = fit(&grouped, &y, Some(&rows));
            let b = fit(&dense, &y, Some(&rows));
            assert_eq!(a.rank, b.rank);
            assert!((a.rss - b.rss).abs() < 1e-12 * b.rss, "{} {}", a.rss, b.rss);
            for (u, v) in a.coefficients.iter().zip(&b.coefficients) {
                assert!((u - v).abs() < 1e-10 * v.abs().max(1.0), "{u} {v}");
            }
            for (u, v) in a.standard_errors.iter().zip(&b.standard_errors) {
                assert!((u - v).abs() < 1e-10 * v.abs().max(1e-3), "{u} {v}");
            }
            for (u, v) in a.fitted.iter().zip(&b.fitted) {
                assert!((u - v).abs() < 1e-10 * v.abs().max(1.0), "{u} {v}");
            }
        }
        let a = leave_one_run_out_rmse(&grouped, &y, &run_of, 8);
        let b = leave_one_run_out_rmse(&dense, &y, &run_of, 8);
        assert!((a - b).abs() < 1e-12 * b, "{a} {b}");
    }

    #[test]
    fn leave_one_run_out_by_hand() {
        // Two runs, a constant model: run 0 reads 0, run 1 reads 2 → each
        // predicted by the other: errors 2 and 2, RMSE 2.
        let design = Design::of_columns(vec![vec![1.0; 4]]);
        let rmse = leave_one_run_out_rmse(&design, &[0.0, 0.0, 2.0, 2.0], &[0, 0, 1, 1], 2);
        assert!((rmse - 2.0).abs() < 1e-12);
    }
}
