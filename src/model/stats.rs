//! Summary statistics of Monte Carlo results: mean, median, extremes,
//! percentiles, a histogram and a least-squares slope.
//!
//! Percentiles interpolate linearly between order statistics (Hyndman and
//! Fan's type 7, the default of NumPy's `percentile` and of spreadsheets),
//! so the figures compare one to one with the NumPy reference `mc_peer.py`. Sums run in index
//! order, so a result does not depend on how the samples were computed.

/// Mean, median, extremes and the 10th and 90th percentiles of a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Number of values.
    pub count: usize,
    /// Arithmetic mean.
    pub mean: f64,
    /// 50th percentile.
    pub median: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// 10th percentile.
    pub p10: f64,
    /// 90th percentile (Valášek's "P90": 9 of 10 machines are at least this good).
    pub p90: f64,
}

impl Summary {
    /// The summary of `values`, or `None` when there are none. The values
    /// must be finite (the studies produce only finite numbers).
    pub fn of(values: &[f64]) -> Option<Summary> {
        if values.is_empty() {
            return None;
        }
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let count = values.len();
        Some(Summary {
            count,
            mean: values.iter().sum::<f64>() / count as f64,
            median: percentile_of_sorted(&sorted, 50.0),
            min: sorted[0],
            max: sorted[count - 1],
            p10: percentile_of_sorted(&sorted, 10.0),
            p90: percentile_of_sorted(&sorted, 90.0),
        })
    }
}

/// The `percent`-th percentile of sorted, non-empty values (type 7).
pub fn percentile_of_sorted(sorted: &[f64], percent: f64) -> f64 {
    let position = (sorted.len() - 1) as f64 * percent / 100.0;
    let below = position.floor() as usize;
    let above = (below + 1).min(sorted.len() - 1);
    let fraction = position - below as f64;
    sorted[below] + fraction * (sorted[above] - sorted[below])
}

/// Counts of values in equal bins between the smallest and the largest value.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    /// Bin edges, one more than bins; the last bin includes its upper edge.
    pub edges: Vec<f64>,
    /// Values per bin.
    pub counts: Vec<u64>,
}

impl Histogram {
    /// `bins` equal bins over [min, max] of `values` (one bin when all are
    /// equal); `None` when there are no values or no bins.
    pub fn of(values: &[f64], bins: usize) -> Option<Histogram> {
        let first = *values.first()?;
        if bins == 0 {
            return None;
        }
        let (low, high) = values
            .iter()
            .fold((first, first), |(low, high), v| (low.min(*v), high.max(*v)));
        if low == high {
            return Some(Histogram {
                edges: vec![low, high],
                counts: vec![values.len() as u64],
            });
        }
        let width = (high - low) / bins as f64;
        let edges = (0..=bins)
            .map(|i| {
                if i == bins {
                    high
                } else {
                    low + i as f64 * width
                }
            })
            .collect();
        let mut counts = vec![0; bins];
        for value in values {
            let bin = (((value - low) / width) as usize).min(bins - 1);
            counts[bin] += 1;
        }
        Some(Histogram { edges, counts })
    }
}

/// The least-squares slope of y over x (a straight line with intercept, as
/// a spreadsheet's linear trend line), or `None` when x has no spread.
pub fn linear_slope(x: &[f64], y: &[f64]) -> Option<f64> {
    if x.len() != y.len() || x.len() < 2 {
        return None;
    }
    let n = x.len() as f64;
    let mean_x = x.iter().sum::<f64>() / n;
    let mean_y = y.iter().sum::<f64>() / n;
    let spread: f64 = x.iter().map(|xi| (xi - mean_x) * (xi - mean_x)).sum();
    if spread == 0.0 {
        return None;
    }
    let covariance: f64 = x
        .iter()
        .zip(y)
        .map(|(xi, yi)| (xi - mean_x) * (yi - mean_y))
        .sum();
    Some(covariance / spread)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_by_hand() {
        // NumPy: np.percentile([3, 1, 4, 1, 5, 9, 2, 6], [10, 50, 90]) = [1.0, 3.5, 6.9].
        let summary = Summary::of(&[3.0, 1.0, 4.0, 1.0, 5.0, 9.0, 2.0, 6.0]).unwrap();
        assert_eq!(summary.count, 8);
        assert_eq!(summary.mean, 31.0 / 8.0);
        assert_eq!(summary.median, 3.5);
        assert_eq!((summary.min, summary.max), (1.0, 9.0));
        assert!((summary.p10 - 1.0).abs() < 1e-12);
        assert!((summary.p90 - 6.9).abs() < 1e-12);
    }

    #[test]
    fn degenerate_samples() {
        assert_eq!(Summary::of(&[]), None);
        let one = Summary::of(&[2.5]).unwrap();
        assert_eq!((one.median, one.p10, one.p90), (2.5, 2.5, 2.5));
        let equal = Histogram::of(&[1.0, 1.0, 1.0], 10).unwrap();
        assert_eq!((equal.edges, equal.counts), (vec![1.0, 1.0], vec![3]));
        assert_eq!(Histogram::of(&[], 10), None);
        assert_eq!(Histogram::of(&[1.0], 0), None);
    }

    #[test]
    fn histogram_counts_every_value_once() {
        let values: Vec<f64> = (0..100).map(f64::from).collect();
        let histogram = Histogram::of(&values, 4).unwrap();
        assert_eq!(histogram.counts, vec![25, 25, 25, 25]);
        assert_eq!(histogram.edges, vec![0.0, 24.75, 49.5, 74.25, 99.0]);
    }

    #[test]
    fn slope_of_the_thesis_x_vertical_table() {
        // Notes §4.5: the least-squares slope of Tab. 4.6 is 1170.5 µm/mm
        // (thesis trend line 1171.6, rounded table values).
        let tolerance_mm = [0.005, 0.015, 0.03, 0.045, 0.06];
        let p90_um = [75.4, 79.3, 93.4, 114.1, 139.0];
        let slope = linear_slope(&tolerance_mm, &p90_um).unwrap();
        assert!((slope - 1170.5).abs() < 0.05, "{slope}");
        assert_eq!(linear_slope(&[1.0, 1.0], &[2.0, 3.0]), None);
    }
}
