//! Linear least squares over the readings, and leave-one-run-out prediction.
//!
//! Every effect `diagnose` knows is linear in its parameters once its shape
//! is fixed (a period, a run), so a model is a set of columns over the
//! readings and a fit is ordinary least squares (SVD, so collinear columns
//! give the minimum-norm solution instead of a failure).

use nalgebra::{DMatrix, DVector};

/// A design: one column per parameter, one row per reading.
#[derive(Clone, Debug, Default)]
pub struct Design {
    /// Columns, each as long as the readings.
    pub columns: Vec<Vec<f64>>,
}

impl Design {
    /// Appends columns.
    pub fn with(&self, more: &[Vec<f64>]) -> Design {
        let mut columns = self.columns.clone();
        columns.extend(more.iter().cloned());
        Design { columns }
    }

    /// Number of parameters.
    pub fn parameters(&self) -> usize {
        self.columns.len()
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
    let x = DMatrix::from_fn(n, k, |r, c| design.columns[c][selected[r]]);
    let target = DVector::from_iterator(n, selected.iter().map(|&i| y[i]));
    let svd = x.clone().svd(true, true);
    let largest = svd.singular_values.iter().fold(0.0f64, |m, v| m.max(*v));
    let tolerance = largest * 1e-10 * (n.max(k) as f64);
    let rank = svd
        .singular_values
        .iter()
        .filter(|v| **v > tolerance)
        .count();
    let beta = svd
        .solve(&target, tolerance)
        .unwrap_or_else(|_| DVector::zeros(k));
    let fitted: Vec<f64> = (0..y.len())
        .map(|i| (0..k).map(|c| design.columns[c][i] * beta[c]).sum())
        .collect();
    let rss: f64 = selected.iter().map(|&i| (y[i] - fitted[i]).powi(2)).sum();
    // Covariance (XᵀX)⁺ = V Σ⁻² Vᵀ over the non-negligible singular values.
    let sigma2 = if n > rank {
        rss / (n - rank) as f64
    } else {
        0.0
    };
    let standard_errors = match &svd.v_t {
        Some(v_t) => (0..k)
            .map(|c| {
                let variance: f64 = svd
                    .singular_values
                    .iter()
                    .enumerate()
                    .filter(|(_, s)| **s > tolerance)
                    .map(|(j, s)| (v_t[(j, c)] / s).powi(2))
                    .sum();
                (sigma2 * variance).sqrt()
            })
            .collect(),
        None => vec![0.0; k],
    };
    Fit {
        coefficients: beta.iter().copied().collect(),
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

/// Generalised least squares with a known covariance `covariance` (n × n):
/// ordinary least squares on the data whitened by the Cholesky factor L
/// (C = L Lᵀ, rows and columns multiplied by L⁻¹), with the standard errors of
/// a known covariance. Only the rows where `rows[i]` is true are used.
pub fn fit_gls(
    design: &Design,
    y: &[f64],
    covariance: &DMatrix<f64>,
    rows: Option<&[bool]>,
) -> WeightedFit {
    let selected: Vec<usize> = (0..y.len())
        .filter(|&i| rows.is_none_or(|r| r[i]))
        .collect();
    let n = selected.len();
    let k = design.parameters();
    let sub = DMatrix::from_fn(n, n, |a, b| covariance[(selected[a], selected[b])]);
    let Some(cholesky) = sub.cholesky() else {
        return WeightedFit {
            coefficients: vec![0.0; k],
            chi2: f64::INFINITY,
            rank: 0,
            standard_errors: vec![0.0; k],
            fitted: vec![0.0; y.len()],
        };
    };
    let l = cholesky.l();
    let whiten = |values: DVector<f64>| {
        l.solve_lower_triangular(&values)
            .unwrap_or_else(|| DVector::zeros(n))
    };
    let y_white = whiten(DVector::from_iterator(n, selected.iter().map(|&i| y[i])));
    let columns: Vec<Vec<f64>> = design
        .columns
        .iter()
        .map(|c| {
            whiten(DVector::from_iterator(n, selected.iter().map(|&i| c[i])))
                .iter()
                .copied()
                .collect()
        })
        .collect();
    let result = fit(&Design { columns }, y_white.as_slice(), None);
    // `fit` scaled the errors by σ̂ = √(χ²/(n − rank)); a known covariance means σ = 1.
    let sigma_hat = if n > result.rank {
        (result.rss / (n - result.rank) as f64).sqrt()
    } else {
        0.0
    };
    let standard_errors = result
        .standard_errors
        .iter()
        .map(|e| if sigma_hat > 0.0 { e / sigma_hat } else { 0.0 })
        .collect();
    let fitted = (0..y.len())
        .map(|i| {
            (0..k)
                .map(|c| design.columns[c][i] * result.coefficients[c])
                .sum()
        })
        .collect();
    WeightedFit {
        coefficients: result.coefficients,
        chi2: result.rss,
        rank: result.rank,
        standard_errors,
        fitted,
    }
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
        let design = Design {
            columns: vec![vec![1.0; 4], x],
        };
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
        let design = Design {
            columns: vec![vec![1.0; 3], vec![2.0; 3]],
        };
        let result = fit(&design, &[1.0, 2.0, 3.0], None);
        assert_eq!(result.rank, 1);
        assert!((result.rss - 2.0).abs() < 1e-9);
    }

    #[test]
    fn weighted_mean_by_hand() {
        // Two levels 1 ± 1 and 4 ± 2 (variances 1 and 4): weights 1 and 1/4,
        // mean (1 + 1) / 1.25 = 1.6 with variance 1/1.25 = 0.8;
        // χ² = 0.6²/1 + 2.4²/4 = 1.8.
        let design = Design {
            columns: vec![vec![1.0, 1.0]],
        };
        let covariance = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 4.0]));
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
        let design = Design {
            columns: vec![vec![1.0, 1.0]],
        };
        let covariance = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 2.0]);
        let result = fit_gls(&design, &[1.0, 3.0], &covariance, None);
        assert!((result.coefficients[0] - 2.0).abs() < 1e-12);
        assert!((result.standard_errors[0] - 1.5f64.sqrt()).abs() < 1e-12);
        // χ² = rᵀ C⁻¹ r with r = (−1, 1): C⁻¹ = [[2, −1], [−1, 2]]/3 → (2 + 2 + 2)/3 = 2.
        assert!((result.chi2 - 2.0).abs() < 1e-12);
    }

    #[test]
    fn leave_one_run_out_by_hand() {
        // Two runs, a constant model: run 0 reads 0, run 1 reads 2 → each
        // predicted by the other: errors 2 and 2, RMSE 2.
        let design = Design {
            columns: vec![vec![1.0; 4]],
        };
        let rmse = leave_one_run_out_rmse(&design, &[0.0, 0.0, 2.0, 2.0], &[0, 0, 1, 1], 2);
        assert!((rmse - 2.0).abs() < 1e-12);
    }
}
