//! `per_target.html`: the per-target table of each test.

use super::tests_of;
use crate::measurement::AxisKind;
use crate::report::acceptance::{ReportInput, TestRecord};
use crate::report::format::{SourcedUm, inch_beside};
use crate::report::json::PerTargetJson;
use crate::units::AngleUnit;

/// `per_target.html`: one table per test.
pub(super) struct PerTargetTable {
    pub(super) heading: Option<&'static str>,
    pub(super) rows: Vec<PerTargetRow>,
}

pub(super) struct PerTargetRow {
    pub(super) target: String,
    pub(super) n_up: usize,
    pub(super) n_down: usize,
    pub(super) cells: Vec<SourcedUm>,
}

pub(super) fn per_target(input: &ReportInput<'_>) -> Vec<PerTargetTable> {
    tests_of(input)
        .into_iter()
        .zip(["before", "after"])
        .map(|((name, test), prefix)| PerTargetTable {
            heading: input.after.as_ref().map(|_| name),
            rows: per_target_rows(test, prefix, input.angle),
        })
        .collect()
}

pub(super) fn per_target_rows(
    test: &TestRecord<'_>,
    prefix: &str,
    angle: AngleUnit,
) -> Vec<PerTargetRow> {
    let length_unit = test.measurement.metadata.length_unit.as_str();
    let kind = test.measurement.kind();
    let rotary = kind == AxisKind::Rotary;
    let mut rows = Vec::new();
    for (index, stats) in test.evaluation.per_target.iter().enumerate() {
        let t = PerTargetJson::from_stats_of(stats, kind, angle);
        // The JSON key: `mean_up_um`, or `mean_up_arcsec` (`_urad`) on a rotary axis.
        let cells = t.cells().map(|(key, value)| {
            SourcedUm::new(format!("{prefix}.per_target.{index}.{key}"), value)
        });
        let (n_up, n_down) = t.readings();
        rows.push(PerTargetRow {
            target: if rotary {
                format!("{}°", t.target())
            } else {
                format!("{}{}", t.target(), inch_beside(length_unit, &[t.target()]))
            },
            n_up,
            n_down,
            cells: cells.to_vec(),
        });
    }
    rows
}
