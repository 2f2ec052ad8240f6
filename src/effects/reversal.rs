//! Reversal: a direction-dependent offset, +B/2 moving ↑ and −B/2 moving ↓.

use serde::Deserialize;

use super::{Context, Fit, Line, Model, Parameter, Reading, Shape, TableRole, column};
use crate::measurement::Direction;
use crate::units::um_to_mm;

/// Reversal B = ↑ − ↓, µm.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reversal {
    /// B = ↑ − ↓, µm.
    #[serde(rename = "B_um")]
    pub b_um: f64,
}

impl Model for Reversal {
    fn value_um(&self, reading: &Reading, _: &Line<'_>) -> f64 {
        reading.direction.reversal_share(self.b_um)
    }

    fn systematic_um(&self, _: f64, direction: Direction, _: f64) -> Option<f64> {
        Some(direction.reversal_share(self.b_um))
    }

    fn in_table(&self) -> TableRole {
        TableRole::Bidirectional { b_um: self.b_um }
    }

    fn explanation(&self, context: &Context) -> String {
        let b_um = self.b_um;
        let how = if b_um < 0.0 {
            "the axis falls short in the direction it moves: lost motion from backlash, or friction force × drive compliance"
        } else {
            "the axis overshoots in the direction it moves (a leading encoder, or an elastic preload released at reversal)"
        };
        // Controllers take the backlash parameter in mm (or inch), not µm:
        // `convert` prints each one's own line (`Controller::backlash_parameter`).
        // On a rotary axis the parameter is in degrees (`emit`'s rotary tables).
        let parameter = context.position(um_to_mm(-b_um), 4);
        let b = context.deviation(b_um);
        match context.first_test_reversal_um {
            Some(before_um) => format!(
                "The reversal changed since the first test by B = {b} (B̄ {} then, about {} now; {how}); a bidirectional table from the re-test (convert --existing --effects) takes the new value out, or change the backlash parameter by {parameter} (convert prints it in the controller's own terms).",
                context.deviation(before_um),
                context.deviation(before_um + b_um),
            ),
            None => format!(
                "Direction-dependent offset of B = {b} ({how}); write a bidirectional table (convert --effects or --mode bidirectional) or change the backlash parameter by {parameter} (convert prints it in the controller's own terms)."
            ),
        }
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![Parameter::number("B_um", "B", "µm", self.b_um)]
    }

    fn label(&self, number: &dyn Fn(f64) -> String) -> String {
        format!("reversal B = {} µm", number(self.b_um))
    }
}

impl Fit for Reversal {
    const NAME: &'static str = "reversal";
    const POSITIONAL: bool = false;

    fn columns(_: Shape, readings: &[Reading], _: &Line<'_>) -> Vec<Vec<f64>> {
        column(readings, |r| r.direction.reversal_share(1.0))
    }

    fn from_fit(_: Shape, coefficients: &[f64], _: &Line<'_>) -> Reversal {
        Reversal {
            b_um: coefficients[0],
        }
    }
}
