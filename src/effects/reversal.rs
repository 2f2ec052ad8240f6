//! Reversal: a direction-dependent offset, +B/2 moving ↑ and −B/2 moving ↓.

use serde::Deserialize;

use super::{Context, Fit, Line, Model, Parameter, Reading, Shape, TableRole, column};
use crate::measurement::Direction;

/// B's key in the effects file and in a linear axis' JSON, and among a
/// fit's uncertainties ([`super::Uncertainty`]); it names µm, the unit of B
/// on a linear axis, the only one these files and keys are written for.
pub const B_KEY: &str = "B_um";

/// Reversal B = ↑ − ↓, in the axis' deviation unit: µm, or m° (1/1000 °)
/// on a rotary axis ([`super::Effect::typed`]).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reversal {
    /// B = ↑ − ↓: µm, or m° on a rotary axis. The effects file (a linear
    /// axis' only) keys it `B_um`.
    #[serde(rename = "B_um")]
    pub b: f64,
}

impl Model for Reversal {
    fn value(&self, reading: &Reading, _: &Line<'_>) -> f64 {
        reading.direction.reversal_share(self.b)
    }

    fn systematic(&self, _: f64, direction: Direction, _: f64) -> Option<f64> {
        Some(direction.reversal_share(self.b))
    }

    fn in_table(&self) -> TableRole {
        TableRole::Bidirectional { b: self.b }
    }

    fn explanation(&self, context: &Context) -> String {
        // What the re-test measures when the diagnosis gives it (its figures'
        // B̄), else the fitted B: the sentence's numbers are the output's own,
        // µm (m° on a rotary axis).
        let (predicted, measured) = context.retest_mean_reversal.unwrap_or_else(|| {
            let before = context.first_test_reversal.unwrap_or(0.0);
            (before, before + self.b)
        });
        let change = match context.first_test_reversal {
            Some(_) => measured - predicted,
            None => measured,
        };
        // What the axis does now, by the sign of the B̄ measured now.
        let how = if measured < 0.0 {
            "the axis falls short in the direction it moves: lost motion from backlash, or friction force × drive compliance"
        } else {
            "the axis overshoots in the direction it moves (a leading encoder, or an elastic preload released at reversal)"
        };
        // Controllers take the backlash parameter in mm (or inch), not µm:
        // `convert` prints each one's own line (`Controller::backlash_parameter`).
        // On a rotary axis the parameter is in degrees (`emit`'s rotary tables).
        // Whatever the parameter was during the re-test, −B̄ measured now
        // takes out what is left.
        let parameter = context.position(context.deviation_as_position(-measured), 4);
        let d = |v: f64| context.deviation(v);
        match context.first_test_reversal {
            Some(_) => format!(
                "The reversal changed since the first test: B̄ {} predicted, {} measured now, a change of {} ({how}); a bidirectional table from the re-test (convert --existing --effects) takes it out, or change the backlash parameter by {parameter} (−B̄ now; convert prints it in the controller's own terms).",
                d(predicted),
                d(measured),
                d(change),
            ),
            None => format!(
                "Direction-dependent offset: B̄ {} measured ({how}); write a bidirectional table (convert --effects or --mode bidirectional) or change the backlash parameter by {parameter} (−B̄; convert prints it in the controller's own terms).",
                d(measured)
            ),
        }
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![Parameter::number(B_KEY, "B", "µm", self.b)]
    }

    fn label(&self, context: &Context, number: &dyn Fn(f64) -> String) -> String {
        format!("reversal B = {}", context.deviation_label(self.b, number))
    }
}

impl Fit for Reversal {
    const NAME: &'static str = "reversal";
    const POSITIONAL: bool = false;

    fn columns(_: Shape, readings: &[Reading], _: &Line<'_>) -> Vec<Vec<f64>> {
        column(readings, |r| r.direction.reversal_share(1.0))
    }

    fn from_fit(_: Shape, coefficients: &[f64], _: &Line<'_>) -> Reversal {
        Reversal { b: coefficients[0] }
    }
}
