//! Outlier run: one run offset from the others (typically the first run
//! after start-up, before the axis is warm).

use serde::{Deserialize, Deserializer};

use super::{
    Context, Fit, FitSummary, Line, Model, Parameter, ParameterValue, Reading, Shape, TableRole,
    Uncertainty,
};
use crate::measurement::Direction;

/// The offset's key in the effects file and in a linear axis' JSON, and
/// among a fit's uncertainties ([`super::Uncertainty`]); it names µm, the
/// unit of the offset on a linear axis, the only one these are written for.
pub const OFFSET_KEY: &str = "offset_um";

/// One run offset.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutlierRun {
    /// Run number within its direction.
    pub run: u32,
    /// ↑ or ↓.
    #[serde(deserialize_with = "direction")]
    pub direction: Direction,
    /// How far the run sits off the others: µm, or m° (1/1000 °) on a
    /// rotary axis ([`super::Effect::typed`]). The effects file (a linear
    /// axis' only) keys it `offset_um`.
    #[serde(rename = "offset_um")]
    pub offset: f64,
}

/// `"up"` or `"down"`.
fn direction<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Direction, D::Error> {
    let name = String::deserialize(deserializer)?;
    match name.as_str() {
        "up" => Ok(Direction::Up),
        "down" => Ok(Direction::Down),
        other => Err(serde::de::Error::custom(format!(
            "outlier-run: direction must be \"up\" or \"down\", found {other:?}"
        ))),
    }
}

impl Model for OutlierRun {
    fn value(&self, reading: &Reading, _: &Line<'_>) -> f64 {
        if reading.run == self.run && reading.direction == self.direction {
            self.offset
        } else {
            0.0
        }
    }

    /// Not systematic in position: a table cannot take it.
    fn systematic(&self, _: f64, _: Direction, _: f64) -> Option<f64> {
        None
    }

    fn in_table(&self) -> TableRole {
        let (run, direction) = (self.run, self.direction);
        TableRole::NotATable {
            note: format!(
                "outlier run {run}{direction}: left in; give --exclude-run {run}:{} if it was the start-up run",
                direction.as_str()
            ),
        }
    }

    fn explanation(&self, context: &Context) -> String {
        let (run, direction) = (self.run, self.direction);
        let sign = if self.offset.is_sign_negative() {
            ""
        } else {
            "+"
        };
        format!(
            "Run {run}{direction} sits {sign}{} off the others (typically the first run after start-up, before the axis is warm); leave it out with --exclude-run {run}:{} if that is why, or warm the axis up before the test.",
            context.deviation(self.offset),
            direction.as_str()
        )
    }

    /// The run and its offset; the direction is part of the run's name, not
    /// a parameter (JSON and TOML write it as `direction`).
    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter {
                key: "run",
                name: "run",
                unit: "",
                value: ParameterValue::Run(self.run),
            },
            Parameter::number(OFFSET_KEY, "offset", "µm", self.offset),
        ]
    }

    fn label(&self, context: &Context, number: &dyn Fn(f64) -> String) -> String {
        format!(
            "run {}{} offset {}",
            self.run,
            self.direction,
            context.deviation_label(self.offset, number)
        )
    }
}

impl Fit for OutlierRun {
    const NAME: &'static str = "outlier-run";
    const POSITIONAL: bool = false;

    fn columns(shape: Shape, readings: &[Reading], _: &Line<'_>) -> Vec<Vec<f64>> {
        let Shape::Run(direction, run) = shape else {
            return Vec::new();
        };
        super::column(readings, |r| {
            if r.direction == direction && r.run == run {
                1.0
            } else {
                0.0
            }
        })
    }

    fn from_fit(shape: Shape, coefficients: &[f64], _: &Line<'_>) -> OutlierRun {
        let Shape::Run(direction, run) = shape else {
            unreachable!("an outlier run's shape is its run")
        };
        OutlierRun {
            run,
            direction,
            offset: coefficients[0],
        }
    }

    fn uncertainty(&self, fit: &FitSummary<'_>) -> (Vec<Uncertainty>, Vec<String>) {
        (vec![(OFFSET_KEY, fit.errors[0])], Vec::new())
    }
}
