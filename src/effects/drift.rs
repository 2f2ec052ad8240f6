//! Drift: a deviation growing with the time of the reading.

use serde::Deserialize;

use super::{Context, Fit, Line, Model, OneNumber, Parameter, Reading, Shape, TableRole, column};
use crate::measurement::Direction;

/// Drift, µm/h.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Drift {
    /// µm per hour from the start of the test.
    pub rate_um_per_h: f64,
}

/// The one parameter, as it is shown and saved.
const RATE: OneNumber = OneNumber {
    key: "rate_um_per_h",
    name: "rate",
    unit: "µm/h",
};

impl Model for Drift {
    fn value_um(&self, reading: &Reading, _: &Line<'_>) -> f64 {
        self.rate_um_per_h * reading.time_h
    }

    /// Not systematic in position: a table cannot take it.
    fn systematic_um(&self, _: f64, _: Direction, _: f64) -> Option<f64> {
        None
    }

    fn in_table(&self) -> TableRole {
        TableRole::NotATable {
            note: format!(
                "drift of {:.2} µm/h: not a table's business; measure again with the machine warm",
                self.rate_um_per_h
            ),
        }
    }

    fn explanation(&self, context: &Context) -> String {
        let assumed = if context.time_assumed {
            " (times assumed from a typical cycle: the file records no test duration)"
        } else {
            ""
        };
        format!(
            "Deviation growing by {:.2} µm/h during the test{assumed}: the machine was warming up; run the axis until it is warm before measuring and re-measure.",
            self.rate_um_per_h
        )
    }

    fn parameters(&self) -> Vec<Parameter> {
        RATE.parameters(self.rate_um_per_h)
    }

    fn label(&self, number: &dyn Fn(f64) -> String) -> String {
        RATE.label(Self::NAME, self.rate_um_per_h, number)
    }
}

impl Fit for Drift {
    const NAME: &'static str = "drift";
    const POSITIONAL: bool = false;

    fn columns(_: Shape, readings: &[Reading], _: &Line<'_>) -> Vec<Vec<f64>> {
        column(readings, |r| r.time_h)
    }

    fn from_fit(_: Shape, coefficients: &[f64], _: &Line<'_>) -> Drift {
        Drift {
            rate_um_per_h: coefficients[0],
        }
    }
}
