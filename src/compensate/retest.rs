//! The re-test a compensated axis should show, from the first test and the table.
//!
//! The model knows the axis error e(x) from the first test: its per-target
//! mean deviation (the bidirectional mean x̄_i, as a geometric error is the
//! same in both directions; a unidirectional test gives its one direction),
//! with a not-a-knot cubic spline between the targets (an axis error is
//! smooth; straight lines between the targets would leave their own
//! curvature error, which a low-noise re-test sees) and the end values held
//! outside. The table, in contrast, is applied linearly, as controllers do. The
//! controller drives to m = x − v(x, d) for a table value v; the axis then
//! reaches m + e(m), so the re-test should read
//!
//! ```text
//! predicted(x, d) = e(x − v(x, d)) − v(x, d)
//! ```
//!
//! Anything direction-dependent (reversal), time-dependent (drift) or not in
//! the first test shows in the difference between this and the re-test; that
//! is what `diagnose` explains.

use crate::compensate::CompensationTable;
use crate::evaluate::Evaluation;
use crate::measurement::Direction;
use crate::spline::CubicSpline;

/// The axis error the model knows, from a first test.
#[derive(Clone, Debug, PartialEq)]
pub struct KnownError {
    /// Targets of the first test, mm.
    positions_mm: Vec<f64>,
    /// Mean deviation there, mm.
    values_mm: Vec<f64>,
    spline: CubicSpline,
}

impl KnownError {
    /// From an evaluation: the bidirectional means where both directions were
    /// measured, else the one direction's means. `None` if no target has a mean.
    pub fn from_evaluation(evaluation: &Evaluation) -> Option<KnownError> {
        let both = evaluation.runs_up > 0 && evaluation.runs_down > 0;
        let (positions_mm, values_mm): (Vec<f64>, Vec<f64>) = evaluation
            .per_target
            .iter()
            .filter_map(|t| {
                let mean = if both {
                    t.mean_mm
                } else {
                    t.up.mean_mm.or(t.down.mean_mm)
                };
                mean.map(|m| (t.target_mm, m))
            })
            .unzip();
        (!positions_mm.is_empty()).then(|| KnownError::new(positions_mm, values_mm))
    }

    /// Through the given points: positions finite and strictly increasing, as
    /// many values as positions, at least one (an evaluation's targets are).
    pub fn new(positions_mm: Vec<f64>, values_mm: Vec<f64>) -> KnownError {
        let spline = CubicSpline::new(&positions_mm, &values_mm);
        KnownError {
            positions_mm,
            values_mm,
            spline,
        }
    }

    /// Targets of the first test, mm.
    pub fn positions_mm(&self) -> &[f64] {
        &self.positions_mm
    }

    /// Mean deviation at each target, mm.
    pub fn values_mm(&self) -> &[f64] {
        &self.values_mm
    }

    /// e(x), mm.
    pub fn at(&self, x_mm: f64) -> f64 {
        self.spline.value_at(x_mm)
    }
}

/// The deviation a re-test should show at `x_mm` moving in `direction`, mm.
pub fn predicted_deviation_mm(
    error: &KnownError,
    table: Option<&CompensationTable>,
    x_mm: f64,
    direction: Direction,
) -> f64 {
    let applied = table.map_or(0.0, |t| t.value_at(x_mm, direction));
    error.at(x_mm - applied) - applied
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::TableValues;

    #[test]
    fn a_curved_error_is_followed_between_the_targets() {
        // e(x) = x²/1e5 mm: a cubic spline through 0, 100, 200, 300 reproduces it exactly.
        let positions = vec![0.0, 100.0, 200.0, 300.0];
        let values = positions.iter().map(|x| x * x / 1e5).collect();
        let error = KnownError::new(positions, values);
        assert!(
            (error.at(150.0) - 0.225).abs() < 1e-15,
            "{}",
            error.at(150.0)
        );
    }

    #[test]
    fn a_mean_table_leaves_nothing_at_the_points_by_hand() {
        let error = KnownError::new(vec![0.0, 100.0], vec![0.0, 0.010]);
        let table = CompensationTable {
            axis: "X".into(),
            positions_mm: vec![0.0, 100.0],
            values: TableValues::Mean(vec![0.0, 0.010]),
            reference_mm: 0.0,
            suggested_backlash_mm: None,
        };
        // At 50 mm the table holds 5 µm: e(50 − 0.005) − 0.005 = 0.0049995 − 0.005 = −0.5 nm.
        let predicted = predicted_deviation_mm(&error, Some(&table), 50.0, Direction::Up);
        assert!((predicted + 0.0000005).abs() < 1e-12, "{predicted}");
        // Without a table the prediction is the known error itself; beyond the ends it is held.
        assert_eq!(
            predicted_deviation_mm(&error, None, 150.0, Direction::Down),
            0.010
        );
    }
}
