//! `table.html`: the compensation table, its plot and the predicted re-test.

use super::{Plot, signed};
use crate::compensate::TableMode;
use crate::evaluate::standard;
use crate::report::acceptance::{ReportInput, TableRecord};
use crate::report::format::{SourcedUm, um};
use crate::report::json::{FiguresJson, iso_keys};
use crate::units::mm_to_um;

/// `table.html`.
pub(super) struct TableView {
    pub(super) file: String,
    pub(super) controller: &'static str,
    pub(super) points: usize,
    pub(super) first_mm: f64,
    pub(super) last_mm: f64,
    pub(super) step_mm: Option<f64>,
    pub(super) mode: TableMode,
    pub(super) reference_mm: f64,
    pub(super) max_abs_um: String,
    pub(super) suggested_backlash_um: Option<String>,
    pub(super) plot: Option<Plot>,
    pub(super) prediction: Option<PredictionView>,
}

pub(super) struct PredictionView {
    pub(super) range_um: String,
    pub(super) uncompensated_range_um: String,
    /// (key, cell) of the figures the paragraph names: A, E, B, or every
    /// figure of another standard.
    pub(super) figures: Vec<(&'static str, SourcedUm)>,
    pub(super) plot: Option<Plot>,
}

pub(super) fn table_view(
    input: &ReportInput<'_>,
    record: &TableRecord<'_>,
    plot: &dyn Fn(&str) -> Option<Plot>,
) -> TableView {
    let table = record.table;
    let prediction = input.prediction.map(|predicted| {
        let iso_family = iso_keys(&predicted.figures);
        // µm: the prediction is of a linear axis (`workflow::rotary`).
        let kind = input.before.measurement.kind();
        let in_um = FiguresJson::of_linear(&standard::typed(&predicted.figures, kind));
        PredictionView {
            range_um: um(Some(predicted.range_um())),
            uncompensated_range_um: um(Some(predicted.uncompensated_range_um())),
            figures: in_um
                .values
                .iter()
                .filter(|(key, _)| !iso_family || ["A", "E", "B"].contains(key))
                .map(|&(key, value)| {
                    let data_key = format!("prediction.figures_um.{key}");
                    (key, SourcedUm::new(data_key, value))
                })
                .collect(),
            plot: plot("predicted"),
        }
    });
    TableView {
        file: record.file.to_string(),
        controller: record.controller.name(),
        points: table.positions.len(),
        first_mm: table.positions.first().copied().unwrap_or_default(),
        last_mm: table.positions.last().copied().unwrap_or_default(),
        step_mm: table.regular_step(),
        mode: table.values.mode(),
        reference_mm: table.reference,
        max_abs_um: signed(mm_to_um(table.max_abs()), 2),
        suggested_backlash_um: table.suggested_backlash.map(|b| signed(mm_to_um(b), 2)),
        plot: plot("table"),
        prediction,
    }
}
