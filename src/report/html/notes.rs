//! `notes.html`: the warnings and suspected outliers, naming their test.

use super::{signed_plus, tests_of};
use crate::measurement::{Direction, Measurement};
use crate::report::acceptance::ReportInput;
use crate::units::{AngleUnit, DeviationUnit};

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
        offset_um: String,
        worst_target_mm: f64,
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
            notes.push(Note {
                test,
                what: NoteText::Outlier {
                    run: outlier.run,
                    direction: outlier.direction,
                    score: format!("{:.1}", outlier.score),
                    offset_um: signed_plus(
                        deviation_shown(record.measurement, input.angle)
                            .from_internal(outlier.offset),
                        2,
                    ),
                    worst_target_mm: outlier.worst_target,
                },
            });
        }
    }
    notes
}

/// The unit the report shows a test's deviations in (held in the `_mm`
/// fields as mm, or ° on a rotary axis): µm, or ″ or µrad.
pub(super) fn deviation_shown(measurement: &Measurement, angle: AngleUnit) -> DeviationUnit {
    measurement.kind().deviation_unit(angle)
}
