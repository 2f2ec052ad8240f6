//! Tail probabilities of the tests the selection uses.

use statrs::distribution::{ChiSquared, ContinuousCDF, FisherSnedecor};

/// p-value of the partial F-test for adding `added` parameters.
pub(super) fn partial_f_p(
    rss_without: f64,
    rss_with: f64,
    added: usize,
    n: usize,
    rank_with: usize,
) -> f64 {
    let denominator_df = n.saturating_sub(rank_with);
    if added == 0 || denominator_df == 0 || rss_with <= 0.0 {
        return 0.0;
    }
    let f = ((rss_without - rss_with) / added as f64) / (rss_with / denominator_df as f64);
    FisherSnedecor::new(added as f64, denominator_df as f64)
        .map_or(f64::NAN, |d| 1.0 - d.cdf(f.max(0.0)))
}

/// Upper tail of χ² with `df` degrees of freedom (1 when df = 0).
pub(super) fn chi2_p(chi2: f64, df: usize) -> f64 {
    if df == 0 {
        return 1.0;
    }
    ChiSquared::new(df as f64).map_or(1.0, |d| 1.0 - d.cdf(chi2.max(0.0)))
}
