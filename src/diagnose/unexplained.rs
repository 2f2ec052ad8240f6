//! Structure along the axis that no accepted effect explains: the lack-of-fit
//! test of the per-target residual levels and where they are largest.

use super::fit::WeightedFit;
use super::levels::{Cell, Level, reversals};
use super::problem::Problem;
use super::{LACK_OF_FIT_P, Unexplained};

/// The structure left: along the axis (the levels against the model, with a
/// prediction) and between the directions (reversals that are not one B).
#[allow(clippy::too_many_arguments)]
pub(super) fn unexplained(
    problem: &Problem,
    levels: &[Level],
    along_fit: &WeightedFit,
    cells: &[Cell],
    reversal_b: f64,
    along_p: f64,
    reversal_p: f64,
    with_prediction: bool,
) -> Unexplained {
    let along_significant = with_prediction && along_p < LACK_OF_FIT_P;
    let reversal_significant = reversal_p < LACK_OF_FIT_P;
    let mut flagged: Vec<(f64, f64)> = Vec::new();
    if along_significant {
        for (l, f) in levels.iter().zip(&along_fit.fitted) {
            let z = (l.value - f) / l.variance.max(1e-300).sqrt();
            if z.abs() > 3.0 {
                flagged.push((l.target, z.abs()));
            }
        }
    }
    if reversal_significant {
        for (t, d, v) in reversals(cells) {
            let z = (d - reversal_b) / v.max(1e-300).sqrt();
            if z.abs() > 3.0 {
                flagged.push((problem.targets[t], z.abs()));
            }
        }
    }
    flagged.sort_by(|a, b| b.1.total_cmp(&a.1));
    flagged.dedup_by(|a, b| a.0 == b.0);
    flagged.truncate(10);
    let mut flagged_targets: Vec<f64> = flagged.into_iter().map(|(x, _)| x).collect();
    flagged_targets.sort_by(f64::total_cmp);
    flagged_targets.dedup();
    let rms = if with_prediction {
        let squares: f64 = levels
            .iter()
            .zip(&along_fit.fitted)
            .map(|(l, f)| (l.value - f).powi(2))
            .sum();
        (squares / levels.len().max(1) as f64).sqrt()
    } else {
        let differences = reversals(cells);
        let squares: f64 = differences
            .iter()
            .map(|(_, d, _)| (d - reversal_b).powi(2) / 4.0)
            .sum();
        (squares / differences.len().max(1) as f64).sqrt()
    };
    Unexplained {
        significant: along_significant || reversal_significant,
        p_value: if with_prediction {
            along_p.min(reversal_p)
        } else {
            reversal_p
        },
        targets: flagged_targets,
        rms,
    }
}
