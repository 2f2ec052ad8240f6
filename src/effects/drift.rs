//! Drift: a deviation growing with the time of the reading.
//!
//! Its clock is the one the test records: hours when the file records the
//! test's start and end (the cycle model scaled to them, `cycle`), or, when
//! it does not, the runs in the order measured (one run = the cycle model's
//! mean run): a rate per hour from a clock the file does not have would be
//! the assumed feed and dwell's number, not the machine's.

use serde::Deserialize;

use super::{Context, Fit, Line, Model, OneNumber, Parameter, Reading, Shape, TableRole, column};
use crate::measurement::Direction;

/// Drift, µm per hour or per run.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "DriftFile")]
pub enum Drift {
    /// The test's times are recorded: µm per hour from the start of the test.
    PerHour {
        /// µm/h.
        rate_um_per_h: f64,
    },
    /// The test's times are not recorded: µm per run, in the order measured.
    PerRun {
        /// µm per run.
        rate_um_per_run: f64,
    },
}

/// The TOML form: one of the two keys.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DriftFile {
    rate_um_per_h: Option<f64>,
    rate_um_per_run: Option<f64>,
}

impl TryFrom<DriftFile> for Drift {
    type Error = String;

    fn try_from(file: DriftFile) -> Result<Drift, String> {
        match (file.rate_um_per_h, file.rate_um_per_run) {
            (Some(rate_um_per_h), None) => Ok(Drift::PerHour { rate_um_per_h }),
            (None, Some(rate_um_per_run)) => Ok(Drift::PerRun { rate_um_per_run }),
            _ => Err(
                "a drift has one rate: rate_um_per_h (the test's times recorded) or rate_um_per_run"
                    .to_string(),
            ),
        }
    }
}

/// The one parameter, as it is shown and saved.
const PER_HOUR: OneNumber = OneNumber {
    key: "rate_um_per_h",
    name: "rate",
    unit: "µm/h",
};

/// The same per run.
const PER_RUN: OneNumber = OneNumber {
    key: "rate_um_per_run",
    name: "rate",
    unit: "µm/run",
};

impl Drift {
    /// Its rate and the parameter that names it.
    fn rate(self) -> (f64, OneNumber) {
        match self {
            Drift::PerHour { rate_um_per_h } => (rate_um_per_h, PER_HOUR),
            Drift::PerRun { rate_um_per_run } => (rate_um_per_run, PER_RUN),
        }
    }
}

impl Model for Drift {
    fn value(&self, reading: &Reading, line: &Line<'_>) -> f64 {
        match *self {
            Drift::PerHour { rate_um_per_h } => rate_um_per_h * reading.time_h,
            Drift::PerRun { rate_um_per_run } => rate_um_per_run * line.runs_at(reading.time_h),
        }
    }

    /// Not systematic in position: a table cannot take it.
    fn systematic(&self, _: f64, _: Direction, _: f64) -> Option<f64> {
        None
    }

    fn in_table(&self) -> TableRole {
        let (rate, parameter) = self.rate();
        TableRole::NotATable {
            note: format!(
                "drift of {rate:.2} {}: not a table's business; measure again with the machine warm",
                parameter.unit
            ),
        }
    }

    fn explanation(&self, context: &Context) -> String {
        let (rate, _) = self.rate();
        // The sign of a thermal drift depends on where the laser and the
        // scale sit, not only on warming or cooling: the sentence says the
        // deviation's direction and no more of the cause than that.
        let change = if rate < 0.0 { "falling" } else { "growing" };
        let amount = context.deviation(rate.abs());
        let per = match self {
            Drift::PerHour { .. } => "/h during the test",
            Drift::PerRun { .. } => {
                " per run during the test (per run, not per hour: the file records no times)"
            }
        };
        format!(
            "Deviation {change} by {amount}{per}: the machine's temperature was changing (most often, it is warming up); let it reach a steady temperature (run the axis until it is warm) before measuring, and re-measure."
        )
    }

    fn parameters(&self) -> Vec<Parameter> {
        let (rate, parameter) = self.rate();
        parameter.parameters(rate)
    }

    fn label(&self, _: &Context, number: &dyn Fn(f64) -> String) -> String {
        let (rate, parameter) = self.rate();
        parameter.label(Self::NAME, rate, number)
    }
}

impl Fit for Drift {
    const NAME: &'static str = "drift";
    const POSITIONAL: bool = false;

    fn columns(_: Shape, readings: &[Reading], line: &Line<'_>) -> Vec<Vec<f64>> {
        if line.times_recorded {
            column(readings, |r| r.time_h)
        } else {
            column(readings, |r| line.runs_at(r.time_h))
        }
    }

    fn from_fit(_: Shape, coefficients: &[f64], line: &Line<'_>) -> Drift {
        if line.times_recorded {
            Drift::PerHour {
                rate_um_per_h: coefficients[0],
            }
        } else {
            Drift::PerRun {
                rate_um_per_run: coefficients[0],
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::AxisKind;

    fn context() -> Context {
        Context {
            kind: AxisKind::Linear,
            angle: Default::default(),
            table_step: None,
            target_spacing: None,
            expansion_coefficient_ppm_per_k: None,
            material_change_k: None,
            time_assumed: false,
            first_test_reversal: None,
            retest_mean_reversal: None,
        }
    }

    #[test]
    fn a_falling_deviation_is_said_falling_with_its_size() {
        let text = Drift::PerHour {
            rate_um_per_h: -3.0,
        }
        .explanation(&context());
        assert!(
            text.starts_with("Deviation falling by 3.00 µm/h during the test"),
            "{text}"
        );
        let text = Drift::PerRun {
            rate_um_per_run: 0.5,
        }
        .explanation(&context());
        assert!(
            text.starts_with("Deviation growing by 0.50 µm per run during the test (per run,"),
            "{text}"
        );
    }
}
