//! The predicted re-test of a compensated axis on its laser line (the
//! module doc's "The table", "The measured reversal" and "Scatter").

use super::calibrate::{line_deviation, positioning_sign};
use super::{PredictError, PredictInput};
use crate::compensate::retest::{Applied, KnownError};
use crate::compensate::{CompensationTable, TableMode};
use crate::evaluate::{AxisFigures, StandardFigure, evaluate, evaluate_with};
use crate::measurement::{Direction, Measurement, Run};
use crate::model::{Axis, GeometricErrors, Machine};
use crate::units::um_to_mm;

/// The predicted re-test of one compensated axis.
#[derive(Clone, Debug, PartialEq)]
pub struct PredictedRetest {
    /// The axis.
    pub axis: Axis,
    /// The line, mm.
    pub line_mm: [f64; 3],
    /// Per target: the deviation without and with the table.
    pub per_target: Vec<PredictedTarget>,
    /// The predicted re-test as readings (with the measured scatter when the
    /// axis was measured).
    pub retest: Measurement,
    /// Its ISO 230-2:2014 figures.
    pub figures: AxisFigures,
    /// The ISO 230-2:2014 figures of the same line without the table.
    pub figures_before: AxisFigures,
    /// Its figures as [`PredictInput::standard`] reports them (its keys):
    /// `evaluate_with` of [`PredictedRetest::retest`].
    pub standard_figures: Vec<StandardFigure>,
    /// The same line without the table, as that standard reports it.
    pub standard_figures_before: Vec<StandardFigure>,
    /// Whether the readings carry a measured test's scatter (else one run per
    /// direction, no repeatability).
    pub with_measured_scatter: bool,
    /// The mean reversal B̄ the first test of the axis measured, which the
    /// prediction carries, mm; `None` without a bidirectional first test.
    pub measured_mean_reversal_mm: Option<f64>,
    /// The mean reversal the controller's backlash parameter takes out, mm (0 if not set).
    pub backlash_reversal_mm: f64,
    /// Whether the table is mean or bidirectional.
    pub table_mode: TableMode,
}

/// One target of a predicted re-test, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PredictedTarget {
    /// Target, mm.
    pub target_mm: f64,
    /// Deviation on the line without the table moving ↑, mm.
    pub before_up_mm: f64,
    /// The same moving ↓ (differs from ↑ only by effects), mm.
    pub before_down_mm: f64,
    /// Predicted deviation with the table moving ↑, mm.
    pub up_mm: f64,
    /// Predicted deviation with the table moving ↓, mm.
    pub down_mm: f64,
}

impl PredictedTarget {
    /// With the table, in a direction, mm.
    pub fn after(&self, direction: Direction) -> f64 {
        match direction {
            Direction::Up => self.up_mm,
            Direction::Down => self.down_mm,
        }
    }

    /// Without the table, in a direction, mm.
    pub fn before(&self, direction: Direction) -> f64 {
        match direction {
            Direction::Up => self.before_up_mm,
            Direction::Down => self.before_down_mm,
        }
    }
}

/// An axis and the line its re-test runs on.
#[derive(Clone, Copy, Debug)]
pub(super) struct Line {
    pub(super) axis: Axis,
    pub(super) line_mm: [f64; 3],
}

/// The re-test of one compensated axis on the line.
pub(super) fn predicted_retest(
    machine: &Machine,
    errors: &GeometricErrors,
    line: Line,
    table: &CompensationTable,
    measured: Option<&Measurement>,
    input: &PredictInput<'_>,
) -> Result<PredictedRetest, PredictError> {
    let Line { axis, line_mm } = line;
    let (effects, backlash_set, standard) = (input.effects, input.backlash_set, input.standard);
    let sign = positioning_sign(machine, axis)?;
    let targets: Vec<f64> = match measured {
        Some(m) => m.targets().to_vec(),
        None => table.positions.clone(),
    };
    // The first test's own error, per direction: the reversal it measured.
    let known = measured.and_then(|m| KnownError::from_evaluation(&evaluate(m)));
    let measured_mean_reversal_mm = known
        .as_ref()
        .filter(|k| k.is_bidirectional())
        .map(KnownError::mean_reversal);
    let applied = Applied::with_backlash(Some(table), known.as_ref(), backlash_set)
        .map_err(|why| PredictError::Backlash { axis, why })?;
    let first_target = targets.first().copied().unwrap_or(0.0);
    // D(x, d): the model's reading, the measured reversal and the effects it lacks, mm.
    let deviation = |x: f64, direction: Direction| {
        let effects_um: f64 = effects
            .iter()
            .filter_map(|e| e.systematic(x, direction, first_target))
            .sum();
        let reversal = known
            .as_ref()
            .map_or(0.0, |k| k.reversal_share_at(x, direction));
        line_deviation(machine, errors, axis, sign, line_mm, x) + reversal + um_to_mm(effects_um)
    };
    let compensated = |x: f64, direction: Direction| {
        let v = applied.value_at(x, direction);
        deviation(x - v, direction) - v
    };
    let per_target: Vec<PredictedTarget> = targets
        .iter()
        .map(|&x| PredictedTarget {
            target_mm: x,
            before_up_mm: deviation(x, Direction::Up),
            before_down_mm: deviation(x, Direction::Down),
            up_mm: compensated(x, Direction::Up),
            down_mm: compensated(x, Direction::Down),
        })
        .collect();
    let (retest, before) = match measured {
        Some(m) => (
            with_scatter(m, |i, d| per_target[i].after(d))?,
            with_scatter(m, |i, d| per_target[i].before(d))?,
        ),
        None => (
            one_run_each_way(axis, &per_target, PredictedTarget::after)?,
            one_run_each_way(axis, &per_target, PredictedTarget::before)?,
        ),
    };
    Ok(PredictedRetest {
        axis,
        line_mm,
        figures: evaluate(&retest).figures,
        figures_before: evaluate(&before).figures,
        standard_figures: evaluate_with(&retest, standard).standard_figures,
        standard_figures_before: evaluate_with(&before, standard).standard_figures,
        per_target,
        retest,
        with_measured_scatter: measured.is_some(),
        measured_mean_reversal_mm,
        backlash_reversal_mm: applied.backlash_reversal,
        table_mode: table.values.mode(),
    })
}

/// The measured readings with their per-target, per-direction mean replaced
/// by `systematic(target index, direction)`: the scatter is kept.
pub(super) fn with_scatter(
    measured: &Measurement,
    systematic: impl Fn(usize, Direction) -> f64,
) -> Result<Measurement, PredictError> {
    Ok(crate::compensate::retest::with_scatter(
        measured,
        &evaluate(measured),
        systematic,
    )?)
}

/// A re-test of one run each way holding the predicted values.
pub(super) fn one_run_each_way(
    axis: Axis,
    per_target: &[PredictedTarget],
    value: fn(&PredictedTarget, Direction) -> f64,
) -> Result<Measurement, PredictError> {
    let runs = Direction::BOTH
        .into_iter()
        .map(|direction| Run {
            direction,
            number: 1,
            start_time_s: None,
            deviations: per_target
                .iter()
                .map(|t| Some(value(t, direction)))
                .collect(),
        })
        .collect();
    let metadata = crate::measurement::Metadata {
        axis_source: crate::measurement::AxisSource::Given,
        ..Default::default()
    };
    Measurement::new(
        axis.letter().to_string(),
        per_target.iter().map(|t| t.target_mm).collect(),
        runs,
        Default::default(),
        metadata,
    )
    .map_err(PredictError::from)
}
