//! `notes.html`: the warnings and suspected outliers, naming their test.

use super::{signed_plus, tests_of};
use crate::measurement::Direction;
use crate::report::acceptance::ReportInput;
use crate::report::json::OutlierJson;

/// `notes.html`: a line of the warnings, naming its test.
pub(super) struct Note {
    pub(super) test: &'static str,
    pub(super) what: NoteText,
}

pub(super) enum NoteText {
    Warning(String),
    Outlier {
        run: u32,
        direction: Direction,
        score: String,
        /// In the report's deviation unit (µm, or ″ or µrad on a rotary axis).
        offset: String,
        /// In the axis' unit (mm, or °).
        worst_target: f64,
    },
}

pub(super) fn notes(input: &ReportInput<'_>) -> Vec<Note> {
    let mut notes = Vec::new();
    for (test, record) in tests_of(input) {
        for warning in record.warnings {
            notes.push(Note {
                test,
                what: NoteText::Warning(warning.text_in(input.angle)),
            });
        }
        for outlier in &record.evaluation.outliers {
            // Typed by the axis' kind, as `evaluate --json` writes it.
            let shown =
                OutlierJson::from_outlier(outlier, record.measurement.kind(), input.angle).shown();
            notes.push(Note {
                test,
                what: NoteText::Outlier {
                    run: outlier.run,
                    direction: outlier.direction,
                    score: format!("{:.1}", outlier.score),
                    offset: signed_plus(shown.offset, 2),
                    worst_target: shown.worst_target,
                },
            });
        }
    }
    notes
}
