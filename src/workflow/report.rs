//! The acceptance report's inputs, put together once for `report`, the web
//! app and the demo: the tests, the table with its predicted re-test, the
//! diagnosis, the verdict's limits.

use crate::compensate::CompensationTable;
use crate::compensate::retest::{Applied, KnownError, predicted_deviation, with_scatter};
use crate::diagnose::Diagnosis;
use crate::evaluate::verdict::{Decision, Limit};
use crate::evaluate::{Standard, evaluate_with};
use crate::measurement::Direction;
use crate::report::acceptance::{Prediction, ReportInput, TableRecord, TestRecord};
use crate::units::{AngleUnit, mm_to_um};

use super::Test;

/// What the report is made from, as the front end has it.
#[derive(Clone, Copy)]
pub struct ReportParts<'a> {
    /// The test reported (the first test when there is a re-test).
    pub before: &'a Test,
    /// The re-test.
    pub after: Option<&'a Test>,
    /// The table that was active in the re-test.
    pub table: Option<TableRecord<'a>>,
    /// The diagnosis of the re-test.
    pub diagnosis: Option<&'a Diagnosis>,
    /// The verdict's limits; empty: no verdict.
    pub limits: &'a [Limit],
    /// The verdict's decision rule.
    pub decision: Decision,
    /// The standard of the figures.
    pub standard: &'a dyn Standard,
    /// A rotary axis' deviation unit.
    pub angle: AngleUnit,
    /// What made the report and when.
    pub generator: &'a str,
}

impl<'a> ReportParts<'a> {
    /// A report of `before` alone to `standard`: no re-test, table,
    /// diagnosis or limits, a rotary axis in ″, no generator line.
    pub fn of(before: &'a Test, standard: &'a dyn Standard) -> ReportParts<'a> {
        ReportParts {
            before,
            after: None,
            table: None,
            diagnosis: None,
            limits: &[],
            decision: Decision::default(),
            standard,
            angle: AngleUnit::default(),
            generator: "",
        }
    }
}

/// The report's inputs with the predicted re-test of its table.
pub struct Report<'a> {
    parts: ReportParts<'a>,
    prediction: Option<Prediction>,
}

impl<'a> Report<'a> {
    /// The report of `parts`, its table's re-test predicted.
    pub fn new(parts: ReportParts<'a>) -> Report<'a> {
        let prediction = parts.table.and_then(|table| {
            predicted_retest(&parts.before.record(), table.table, parts.standard)
        });
        Report { parts, prediction }
    }

    /// What `report::html` and `report::acceptance::charts` take.
    pub fn input(&self) -> ReportInput<'_> {
        let parts = &self.parts;
        ReportInput {
            before: parts.before.record(),
            after: parts.after.map(Test::record),
            table: parts.table,
            prediction: self.prediction.as_ref(),
            diagnosis: parts.diagnosis,
            limits: parts.limits,
            decision: parts.decision,
            standard: parts.standard,
            angle: parts.angle,
            generator: parts.generator,
        }
    }
}

/// The report's "made by" line: axcomp's version and `when` (the caller
/// reads the clock; the library reads none).
pub fn generator(when: chrono::DateTime<chrono::Local>) -> String {
    format!(
        "axcomp {} on {}",
        env!("CARGO_PKG_VERSION"),
        when.format("%Y-%m-%d %H:%M")
    )
}

/// Points at which the prediction is sampled: fine enough that linear
/// interpolation between table points shows as it is.
const PREDICTION_SAMPLES: usize = 600;

/// The predicted re-test of the first test with the table applied
/// (`compensate::retest`, with the reversal the first test measured), over
/// the measured span, its figures per `standard`; `None` if the first test
/// has no mean deviation anywhere.
pub fn predicted_retest(
    before: &TestRecord<'_>,
    table: &CompensationTable,
    standard: &dyn Standard,
) -> Option<Prediction> {
    let known = KnownError::from_evaluation(before.evaluation)?;
    let targets_mm = before.measurement.targets();
    let retest = with_scatter(before.measurement, before.evaluation, |i, direction| {
        predicted_deviation(&known, Applied::table(table), targets_mm[i], direction)
    })
    .ok()?;
    let first = *known.positions().first()?;
    let last = *known.positions().last()?;
    let positions_mm: Vec<f64> = (0..PREDICTION_SAMPLES)
        .map(|k| first + (last - first) * k as f64 / (PREDICTION_SAMPLES - 1) as f64)
        .collect();
    let predict = |direction| {
        positions_mm
            .iter()
            .map(|&x| {
                mm_to_um(predicted_deviation(
                    &known,
                    Applied::table(table),
                    x,
                    direction,
                ))
            })
            .collect()
    };
    Some(Prediction {
        up_um: predict(Direction::Up),
        down_um: predict(Direction::Down),
        uncompensated_um: positions_mm
            .iter()
            .map(|&x| mm_to_um(known.mean_at(x)))
            .collect(),
        positions_mm,
        figures: evaluate_with(&retest, standard).standard_figures,
    })
}
