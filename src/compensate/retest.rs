//! The re-test a compensated axis should show, from the first test and the table.
//!
//! The model knows the axis error e(x, d) from the first test: its per-target
//! mean deviation in each direction, x̄_i↑ and x̄_i↓ (ISO 230-2), with a
//! not-a-knot cubic spline between the targets (an axis error is smooth;
//! straight lines between the targets would leave their own curvature error,
//! which a low-noise re-test sees) and the end values held outside. Both
//! directions are kept because the reversal the first test measured is part
//! of what the axis does: a mean table leaves it, a bidirectional table (or
//! the controller's backlash parameter) takes it out. A unidirectional first
//! test gives its one direction for both: its reversal is not known.
//!
//! The table, in contrast, is applied linearly, as controllers do. The
//! controller drives to m = x − v(x, d) for a compensation value v; the axis
//! then reaches m + e(m, d), so the re-test should read
//!
//! ```text
//! predicted(x, d) = e(x − v(x, d), d) − v(x, d)
//! ```
//!
//! A backlash parameter set to the suggested −B̄ adds B̄/2 to v moving ↑ and
//! −B̄/2 moving ↓ (any split of the constant B̄ between the directions gives
//! the same ISO figures, which do not depend on a constant offset).
//!
//! What changed since the first test (a reversal that grew, drift, anything
//! the first test could not show) is in the difference between this and the
//! re-test; that is what `diagnose` explains.
//!
//! Positions, deviations and compensation values are in the axis' unit: mm,
//! or ° on a rotary axis (a rotary re-test is diagnosed the same way).

use std::fmt;

use crate::compensate::CompensationTable;
use crate::evaluate::Evaluation;
use crate::measurement::{Direction, Measurement, MeasurementError};
use crate::spline::CubicSpline;

/// The axis error the model knows, from a first test: per direction.
#[derive(Clone, Debug, PartialEq)]
pub struct KnownError {
    /// Targets of the first test, in the axis' unit.
    positions: Vec<f64>,
    /// Mean deviation moving ↑ there, in the axis' unit.
    up_means: Vec<f64>,
    /// Mean deviation moving ↓ there, in the axis' unit.
    down_means: Vec<f64>,
    up: CubicSpline,
    down: CubicSpline,
    /// Whether both directions were measured (else the reversal is unknown).
    bidirectional: bool,
}

impl KnownError {
    /// From an evaluation: each direction's means at the targets where both
    /// directions have one; a unidirectional test's one direction for both.
    /// `None` if no target has a mean.
    pub fn from_evaluation(evaluation: &Evaluation) -> Option<KnownError> {
        let bidirectional = evaluation.runs_up > 0 && evaluation.runs_down > 0;
        let mut positions = Vec::new();
        let (mut up_means, mut down_means) = (Vec::new(), Vec::new());
        for t in &evaluation.per_target {
            let means = if bidirectional {
                t.up.mean.zip(t.down.mean)
            } else {
                t.up.mean.or(t.down.mean).map(|m| (m, m))
            };
            if let Some((up, down)) = means {
                positions.push(t.target);
                up_means.push(up);
                down_means.push(down);
            }
        }
        if positions.is_empty() {
            return None;
        }
        Some(KnownError::new(
            positions,
            up_means,
            down_means,
            bidirectional,
        ))
    }

    /// Through the given points: positions finite and strictly increasing, as
    /// many values per direction as positions, at least one (an evaluation's
    /// targets are). `bidirectional` says whether the two directions were
    /// measured apart.
    pub fn new(
        positions: Vec<f64>,
        up_means: Vec<f64>,
        down_means: Vec<f64>,
        bidirectional: bool,
    ) -> KnownError {
        let up = CubicSpline::new(&positions, &up_means);
        let down = CubicSpline::new(&positions, &down_means);
        KnownError {
            positions,
            up_means,
            down_means,
            up,
            down,
            bidirectional,
        }
    }

    /// The same error in both directions (no reversal), e.g. a geometric error.
    pub fn same_both_ways(positions: Vec<f64>, values: Vec<f64>) -> KnownError {
        KnownError::new(positions, values.clone(), values, false)
    }

    /// Targets of the first test, in the axis' unit.
    pub fn positions(&self) -> &[f64] {
        &self.positions
    }

    /// Bidirectional mean deviation x̄_i at each target, in the axis' unit.
    pub fn mean_values(&self) -> Vec<f64> {
        self.up_means
            .iter()
            .zip(&self.down_means)
            .map(|(up, down)| (up + down) / 2.0)
            .collect()
    }

    /// Whether the first test measured both directions, so that its reversal is known.
    pub fn is_bidirectional(&self) -> bool {
        self.bidirectional
    }

    /// The mean reversal value B̄ = mean of x̄_i↑ − x̄_i↓ over the targets, in the axis' unit
    /// (0 for a unidirectional test).
    pub fn mean_reversal(&self) -> f64 {
        let sum: f64 = self
            .up_means
            .iter()
            .zip(&self.down_means)
            .map(|(up, down)| up - down)
            .sum();
        sum / self.positions.len() as f64
    }

    /// e(x, d), in the axis' unit.
    pub fn at(&self, x: f64, direction: Direction) -> f64 {
        match direction {
            Direction::Up => self.up.value_at(x),
            Direction::Down => self.down.value_at(x),
        }
    }

    /// The bidirectional mean (e(x, ↑) + e(x, ↓)) / 2: the geometric part, in the axis' unit.
    pub fn mean_at(&self, x: f64) -> f64 {
        (self.up.value_at(x) + self.down.value_at(x)) / 2.0
    }

    /// The measured reversal's share at `x` in `direction`: e(x, d) − the mean, in the axis' unit.
    pub fn reversal_share_at(&self, x: f64, direction: Direction) -> f64 {
        self.at(x, direction) - self.mean_at(x)
    }
}

/// What the controller applies to an axis: a table and, optionally, its
/// backlash parameter.
#[derive(Clone, Copy, Debug, Default)]
pub struct Applied<'a> {
    /// The compensation table, if any.
    pub table: Option<&'a CompensationTable>,
    /// The mean reversal B̄ (x̄↑ − x̄↓) that the backlash parameter takes out,
    /// in the axis' unit; 0 when it is not set. Set as `convert` suggests (−B̄), it takes
    /// out the first test's B̄.
    pub backlash_reversal: f64,
}

/// Why the backlash parameter cannot be applied as said: the reason inside
/// [`CompensateError::Backlash`] and predict's per-axis message, a sentence's
/// predicate ("the backlash parameter …").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BacklashRefusal {
    /// A bidirectional table takes the reversal out already.
    WithBidirectionalTable,
    /// The first test does not give B̄.
    NoMeasuredReversal,
}

impl fmt::Display for BacklashRefusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BacklashRefusal::WithBidirectionalTable => {
                "must be 0 with a bidirectional table, which already takes the reversal out (drop --backlash-set)"
            }
            BacklashRefusal::NoMeasuredReversal => {
                "is set as convert suggests (−B̄), but there is no bidirectional first test of the axis to give B̄"
            }
        })
    }
}

impl<'a> Applied<'a> {
    /// Just a table.
    pub fn table(table: &'a CompensationTable) -> Applied<'a> {
        Applied {
            table: Some(table),
            backlash_reversal: 0.0,
        }
    }

    /// A table (if any) and, when `backlash_set`, the backlash parameter set
    /// as `convert` suggests from the first test `known` (−B̄): it takes out
    /// that test's mean reversal. Refused with a bidirectional table or
    /// without a bidirectional first test.
    pub fn with_backlash(
        table: Option<&'a CompensationTable>,
        known: Option<&KnownError>,
        backlash_set: bool,
    ) -> Result<Applied<'a>, BacklashRefusal> {
        if !backlash_set {
            return Ok(Applied {
                table,
                backlash_reversal: 0.0,
            });
        }
        if table.is_some_and(|t| t.values.mode() == crate::compensate::TableMode::Bidirectional) {
            return Err(BacklashRefusal::WithBidirectionalTable);
        }
        let known = known
            .filter(|k| k.is_bidirectional())
            .ok_or(BacklashRefusal::NoMeasuredReversal)?;
        Ok(Applied {
            table,
            backlash_reversal: known.mean_reversal(),
        })
    }

    /// The compensation value v(x, d) in the table's convention (actual − target), in the axis' unit.
    pub fn value_at(&self, x: f64, direction: Direction) -> f64 {
        self.table.map_or(0.0, |t| t.value_at(x, direction))
            + direction.reversal_share(self.backlash_reversal)
    }
}

/// A test with its readings' per-target, per-direction means replaced by
/// `systematic(target index, direction)`, in the axis' unit: the scatter about the means is
/// kept. With the first test and its predicted systematic error this is the
/// predicted re-test, whose R is the first test's and whose A and E compare
/// with a real re-test's (`predict` and `diagnose` give these figures).
pub fn with_scatter(
    test: &Measurement,
    evaluation: &Evaluation,
    systematic: impl Fn(usize, Direction) -> f64,
) -> Result<Measurement, MeasurementError> {
    test.map_readings(|run, i, value| {
        let cell = evaluation.per_target[i].direction(run.direction);
        // A reading's cell has a mean: the reading itself is in it.
        systematic(i, run.direction) + (value - cell.mean.unwrap_or(value))
    })
}

/// The deviation a re-test should show at `x` moving in `direction`, in the axis' unit.
pub fn predicted_deviation(
    error: &KnownError,
    applied: Applied<'_>,
    x: f64,
    direction: Direction,
) -> f64 {
    let v = applied.value_at(x, direction);
    error.at(x - v, direction) - v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::TableValues;

    fn mean_table(positions: Vec<f64>, values: Vec<f64>) -> CompensationTable {
        CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions,
            values: TableValues::Mean(values),
            reference: 0.0,
            suggested_backlash: None,
        }
    }

    #[test]
    fn a_curved_error_is_followed_between_the_targets() {
        // e(x) = x²/1e5 mm: a cubic spline through 0, 100, 200, 300 reproduces it exactly.
        let positions = vec![0.0, 100.0, 200.0, 300.0];
        let values = positions.iter().map(|x| x * x / 1e5).collect();
        let error = KnownError::same_both_ways(positions, values);
        for direction in Direction::BOTH {
            let at = error.at(150.0, direction);
            assert!((at - 0.225).abs() < 1e-15, "{at}");
        }
    }

    #[test]
    fn a_mean_table_leaves_nothing_at_the_points_by_hand() {
        let error = KnownError::same_both_ways(vec![0.0, 100.0], vec![0.0, 0.010]);
        let table = mean_table(vec![0.0, 100.0], vec![0.0, 0.010]);
        // At 50 mm the table holds 5 µm: e(50 − 0.005) − 0.005 = 0.0049995 − 0.005 = −0.5 nm.
        let predicted = predicted_deviation(&error, Applied::table(&table), 50.0, Direction::Up);
        assert!((predicted + 0.0000005).abs() < 1e-12, "{predicted}");
        // Without a table the prediction is the known error itself; beyond the ends it is held.
        assert_eq!(
            predicted_deviation(&error, Applied::default(), 150.0, Direction::Down),
            0.010
        );
    }

    /// A first test with B = x̄↑ − x̄↓ = −3.2 µm everywhere: ↑ 1.6 µm below the
    /// mean 0 → 10 µm, ↓ 1.6 µm above.
    fn with_reversal() -> KnownError {
        KnownError::new(
            vec![0.0, 100.0],
            vec![-0.0016, 0.0084],
            vec![0.0016, 0.0116],
            true,
        )
    }

    #[test]
    fn a_mean_table_leaves_the_measured_reversal_by_hand() {
        let error = with_reversal();
        assert!((error.mean_reversal() + 0.0032).abs() < 1e-15);
        let table = mean_table(vec![0.0, 100.0], vec![0.0, 0.010]);
        // At 100 mm v = 10 µm; e(x, ↑) = −1.6 µm + 0.1 µm/mm · x, so
        // ↑: −0.0016 + 0.009999 − 0.010 = −0.001601 mm; ↓: 0.0016 + 0.009999 − 0.010 = 0.001599 mm.
        let up = predicted_deviation(&error, Applied::table(&table), 100.0, Direction::Up);
        let down = predicted_deviation(&error, Applied::table(&table), 100.0, Direction::Down);
        assert!((up + 0.001601).abs() < 1e-12, "{up}");
        assert!((down - 0.001599).abs() < 1e-12, "{down}");
    }

    #[test]
    fn the_backlash_parameter_or_a_bidirectional_table_takes_the_reversal_out_by_hand() {
        let error = with_reversal();
        let table = mean_table(vec![0.0, 100.0], vec![0.0, 0.010]);
        let with_backlash = Applied {
            table: Some(&table),
            backlash_reversal: error.mean_reversal(),
        };
        // ↑: v = 0.010 − 0.0016 = 0.0084, e(99.9916, ↑) − v = −0.0016 + 0.00999916 − 0.0084 = −0.84 nm;
        // ↓: v = 0.0116, e(99.9884, ↓) − v = 0.0016 + 0.00999884 − 0.0116 = −1.16 nm.
        let up = predicted_deviation(&error, with_backlash, 100.0, Direction::Up);
        let down = predicted_deviation(&error, with_backlash, 100.0, Direction::Down);
        assert!((up + 0.00000084).abs() < 1e-12, "{up}");
        assert!((down + 0.00000116).abs() < 1e-12, "{down}");
        // A bidirectional table with the measured ↑ and ↓ means does the same.
        let bidirectional = CompensationTable {
            values: TableValues::Bidirectional {
                up: vec![-0.0016, 0.0084],
                down: vec![0.0016, 0.0116],
            },
            ..table
        };
        let up = predicted_deviation(&error, Applied::table(&bidirectional), 100.0, Direction::Up);
        assert!((up + 0.00000084).abs() < 1e-12, "{up}");
    }
}
