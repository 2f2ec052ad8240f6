//! What axcomp does for a rotary axis: one table, which every front end
//! asks before it starts a step, so the CLI and the web app accept and refuse
//! the same things with the same words.
//!
//! A rotary axis' targets are degrees and its deviations ″ (µrad with
//! `--angle-unit`): what is evaluated and written in those units works
//! (ISO 230-2 figures, the tables, the diagnosis of a re-test, whose periodic
//! errors are whole orders per revolution). What is still lengths does not:
//! acceptance limits (µm), the laser's uncertainty budget, the volumetric
//! model and with it the report's predicted re-test and its diagnosis
//! charts (µm and mm), the effects file, an angular (Abbe) profile and a
//! servo description (mm, µm, N).

use crate::evaluate::{ISO_230_2, Standard};
use crate::measurement::{AxisKind, Measurement};

/// A step, or an input to one, that may or may not apply to a rotary axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Use {
    /// The ISO 230-2 figures (`evaluate`, the report's figures).
    Evaluate,
    /// A compensation table written or read (`convert`, `--existing`, `--table`).
    Table,
    /// The diagnosis of a re-test (`diagnose`, the web app's re-test).
    Diagnose,
    /// Acceptance limits (`--limit`, a profile's `[acceptance]`).
    Limits,
    /// The measurement uncertainty (`--equipment`, `--decision`).
    Uncertainty,
    /// A standard other than ISO 230-2 in the report.
    OtherStandard,
    /// The report's predicted re-test of a table (`report --table`).
    ReportPrediction,
    /// The report's diagnosis (`report --diagnose`): residual charts in µm.
    ReportDiagnosis,
    /// The effects file (`diagnose --write-effects`, `convert --effects`).
    EffectsFile,
    /// An angular (Abbe) profile (`diagnose --angular`).
    AngularProfile,
    /// A servo description (`diagnose --servo-axis`).
    ServoAxis,
    /// The volumetric model's prediction (`predict`).
    Predict,
}

/// One row of [`ROTARY`]: whether a rotary axis has `what`, and if not, why.
#[derive(Clone, Copy, Debug)]
pub struct Support {
    /// The step or input.
    pub what: Use,
    /// `None`: supported; otherwise what is said when it is asked for.
    pub refused: Option<&'static str>,
}

/// What a rotary axis supports, step by step.
pub const ROTARY: [Support; 12] = [
    Support {
        what: Use::Evaluate,
        refused: None,
    },
    Support {
        what: Use::Table,
        refused: None,
    },
    Support {
        what: Use::Diagnose,
        refused: None,
    },
    Support {
        what: Use::Limits,
        refused: Some(
            "acceptance limits (--limit, a profile's [acceptance]) are µm, for linear axes only so far",
        ),
    },
    Support {
        what: Use::Uncertainty,
        refused: Some(
            "the measurement uncertainty (--equipment, --decision) is the laser's budget, for lengths only so far",
        ),
    },
    Support {
        what: Use::OtherStandard,
        refused: Some("a rotary axis is reported to ISO 230-2 only so far (--standard)"),
    },
    Support {
        what: Use::ReportPrediction,
        refused: Some("the predicted re-test of a table (--table) is for linear axes only so far"),
    },
    Support {
        what: Use::ReportDiagnosis,
        refused: Some("the diagnosis (--diagnose) is for linear axes only so far"),
    },
    Support {
        what: Use::EffectsFile,
        refused: Some(
            "--write-effects is for linear axes only so far (an effects file, an angular profile and a servo description are in mm, µm and N)",
        ),
    },
    Support {
        what: Use::AngularProfile,
        refused: Some(
            "--angular is for linear axes only so far (an effects file, an angular profile and a servo description are in mm, µm and N)",
        ),
    },
    Support {
        what: Use::ServoAxis,
        refused: Some(
            "--servo-axis is for linear axes only so far (an effects file, an angular profile and a servo description are in mm, µm and N)",
        ),
    },
    Support {
        what: Use::Predict,
        refused: Some(
            "predict handles linear axes only so far; `axcomp evaluate`, `convert`, `report` and `diagnose` take rotary axes",
        ),
    },
];

/// A rotary axis asked for what it does not support.
#[derive(Debug, thiserror::Error)]
#[error("axis {axis} is a rotary axis: {why}")]
pub struct RotaryRefusal {
    /// The axis.
    pub axis: String,
    /// Why ([`ROTARY`]).
    pub why: &'static str,
}

/// Whether a rotary axis supports `what`.
pub fn supports(what: Use) -> bool {
    refusal(what).is_none()
}

/// Whether `measurement` may have `what`: a linear axis always, a rotary
/// axis where [`ROTARY`] says so.
pub fn allows(measurement: &Measurement, what: Use) -> bool {
    measurement.kind() == AxisKind::Linear || supports(what)
}

fn refusal(what: Use) -> Option<&'static str> {
    ROTARY
        .iter()
        .find(|row| row.what == what)
        .and_then(|row| row.refused)
}

/// Refuses the first of `asked` (those that are `true`) that `measurement`,
/// if it is a rotary axis, does not support; a linear axis supports them all.
pub fn check(measurement: &Measurement, asked: &[(Use, bool)]) -> Result<(), RotaryRefusal> {
    if measurement.kind() != AxisKind::Rotary {
        return Ok(());
    }
    match asked
        .iter()
        .filter(|(_, given)| *given)
        .find_map(|(what, _)| refusal(*what))
    {
        Some(why) => Err(RotaryRefusal {
            axis: measurement.axis().to_string(),
            why,
        }),
        None => Ok(()),
    }
}

/// What the acceptance report is asked for, in the order it is refused.
#[derive(Clone, Copy, Debug)]
pub struct ReportAsks<'a> {
    /// Acceptance limits, given or from the profile.
    pub limits: bool,
    /// `--equipment` or a decision rule other than simple.
    pub uncertainty: bool,
    /// A table, whose predicted re-test the report draws.
    pub table: bool,
    /// The diagnosis of the re-test.
    pub diagnose: bool,
    /// The standard of the figures.
    pub standard: &'a dyn Standard,
}

/// The report's refusals for a rotary `measurement` ([`check`]).
pub fn check_report(measurement: &Measurement, asks: ReportAsks<'_>) -> Result<(), RotaryRefusal> {
    check(
        measurement,
        &[
            (Use::Limits, asks.limits),
            (Use::Uncertainty, asks.uncertainty),
            (Use::ReportPrediction, asks.table),
            (Use::ReportDiagnosis, asks.diagnose),
            (Use::OtherStandard, asks.standard.key() != ISO_230_2.key()),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_use_has_one_row() {
        let all = [
            Use::Evaluate,
            Use::Table,
            Use::Diagnose,
            Use::Limits,
            Use::Uncertainty,
            Use::OtherStandard,
            Use::ReportPrediction,
            Use::ReportDiagnosis,
            Use::EffectsFile,
            Use::AngularProfile,
            Use::ServoAxis,
            Use::Predict,
        ];
        for what in all {
            assert_eq!(
                ROTARY.iter().filter(|r| r.what == what).count(),
                1,
                "{what:?}"
            );
        }
        assert!(supports(Use::Diagnose) && supports(Use::Table));
        assert!(!supports(Use::Limits) && !supports(Use::ReportDiagnosis));
    }
}
