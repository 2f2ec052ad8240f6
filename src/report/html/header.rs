//! `header.html`: machine, axis, operator, date, the tests' files and the standard.

use super::{axis_shown, recorded};
use crate::evaluate::standard::Vdi3441;
use crate::evaluate::{Standard, StandardUsed};
use crate::measurement::{AxisKind, Direction, Measurement};
use crate::report::acceptance::ReportInput;

/// `header.html`. Text from the file is `None` when it does not record it.
pub(super) struct Header {
    pub(super) axis: String,
    pub(super) kind: String,
    pub(super) machine: Option<String>,
    pub(super) serial_number: Option<String>,
    pub(super) operator: Option<String>,
    pub(super) date: Option<String>,
    pub(super) location: Option<String>,
    /// Present when the file has a title (which may still be blank).
    pub(super) title: Option<Option<String>>,
    /// ("Measurement" or "Re-test", its file).
    pub(super) sources: Vec<(&'static str, SourceLine)>,
    pub(super) table: Option<TableFile>,
    /// The standard, as the header names it.
    pub(super) standard: String,
    /// Whether its definitions are reconstructed from public sources.
    pub(super) reconstructed: bool,
}

/// A test's file, its format and size.
pub(super) struct SourceLine {
    pub(super) file: Option<String>,
    pub(super) format: &'static str,
    pub(super) unit: &'static str,
    pub(super) targets: usize,
    pub(super) runs_up: usize,
    pub(super) runs_down: usize,
}

pub(super) struct TableFile {
    pub(super) file: String,
    pub(super) controller: &'static str,
}

pub(super) fn header(input: &ReportInput<'_>) -> Header {
    let measurement = input.before.measurement;
    let metadata = &measurement.metadata;
    let mut sources = vec![("Measurement", source_line(measurement))];
    if let Some(after) = &input.after {
        sources.push(("Re-test", source_line(after.measurement)));
    }
    Header {
        axis: axis_shown(measurement),
        // What the test is, and whether it meets ISO 230-2 (`evaluate::conformance`).
        kind: input.before.evaluation.conformance.title(),
        machine: recorded(metadata.machine.as_deref()),
        serial_number: recorded(metadata.serial_number.as_deref()),
        operator: recorded(metadata.operator.as_deref()),
        date: recorded(metadata.date.as_ref().map(|d| d.raw.as_str())),
        location: recorded(metadata.location.as_deref()),
        title: metadata
            .description
            .as_deref()
            .map(|description| recorded(Some(description))),
        sources,
        table: input.table.as_ref().map(|table| TableFile {
            file: table.file.to_string(),
            controller: table.controller.name(),
        }),
        standard: standard_line(&input.before.evaluation.standard),
        reconstructed: input.before.evaluation.standard.reconstructed,
    }
}

/// The header's line on the standard: its name, and what A and R mean in it.
pub(super) fn standard_line(standard: &StandardUsed) -> String {
    let iso = format!(
        "test of accuracy and repeatability of positioning of numerically controlled axes; A and R with the coverage of that edition (x̄ ± {k}s, R = {r}s)",
        k = standard.k,
        r = 2.0 * standard.k
    );
    if standard.key == Vdi3441.key() {
        return format!(
            "{}: P, Pa, Ps and U of each direction's statistics; the ISO 230-2:2014 figures beside them ({iso})",
            standard.name
        );
    }
    format!("{}, {iso}", standard.name)
}

pub(super) fn source_line(measurement: &Measurement) -> SourceLine {
    let metadata = &measurement.metadata;
    SourceLine {
        file: metadata
            .source_file
            .as_ref()
            .map(|p| p.display().to_string()),
        format: metadata.source_format.map_or("", |f| f.name()),
        unit: match measurement.kind() {
            AxisKind::Linear => metadata.length_unit.as_str(),
            AxisKind::Rotary => "°",
        },
        targets: measurement.targets().len(),
        runs_up: measurement.run_count(Direction::Up),
        runs_down: measurement.run_count(Direction::Down),
    }
}
