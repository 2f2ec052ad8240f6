//! Thermal drift: logs of a machine's drift and its temperatures over time,
//! their ISO 230-3 view, and a compensation model a control can run.
//!
//! - `log.rs` reads a thermal log (CSV: a time column in s, min or h, or
//!   timestamps, or a sample interval the user gives; the drift column; any
//!   number of temperature columns) into a [`ThermalLog`], and writes one
//!   (for `synth`).
//! - `iso.rs` the ISO 230-3 view of a test: its type, duration, the largest
//!   drift and when, each sensor's rise ([`Iso230_3`]).
//! - `model.rs` the model: sensors through first-order lags, chosen by
//!   time-blocked cross-validation inside the rows it is fitted on
//!   ([`fit`]), applied from a log's first row ([`apply`]), and the model
//!   file read back ([`ThermalModel::from_toml`]; `report::thermal` writes it).
//! - `study.rs` a log studied as a whole ([`study`]): the ISO 230-3 view and
//!   the model (given or fitted) run over it, for the report, the web app
//!   and `diagnose`.
//!
//! Inside, time is in seconds, temperatures in °C and the drift in µm (the
//! field's unit for thermal drift; ISO 230-3 reports µm).

mod iso;
mod log;
mod model;
mod study;

pub use iso::{Iso230_3, SensorRise, TestType, evaluate};
pub use log::{LogOptions, parse_log, write_log};
pub use model::{
    Application, FitOptions, FitSummary, Term, ThermalModel, Validation, apply, coldest, fit,
    tau_grid_s,
};
pub use study::{ModelSource, Study, StudyRequest, parse_rows, study, study_text};

use crate::error::ParseError;

/// A thermal log: times, the drift (when the log has it) and temperatures.
///
/// Valid by construction ([`parse_log`]): at least two rows, times strictly
/// increasing without gaps, every value finite.
#[derive(Clone, Debug, PartialEq)]
pub struct ThermalLog {
    /// Time of each row from the first, s.
    pub times_s: Vec<f64>,
    /// The drift column: its name and one value per row, µm.
    pub drift: Option<Drift>,
    /// The temperature columns, in the file's order.
    pub sensors: Vec<Sensor>,
    /// The 1-based file line of each row (for messages about a row).
    pub lines: Vec<usize>,
}

/// The drift column of a log.
#[derive(Clone, Debug, PartialEq)]
pub struct Drift {
    /// The column's name (without its unit).
    pub name: String,
    /// One value per row, µm.
    pub um: Vec<f64>,
}

/// One temperature column.
#[derive(Clone, Debug, PartialEq)]
pub struct Sensor {
    /// The column's name (without its unit).
    pub name: String,
    /// One value per row, °C.
    pub celsius: Vec<f64>,
}

impl ThermalLog {
    /// The sensor named `name`.
    pub fn sensor(&self, name: &str) -> Option<&Sensor> {
        self.sensors.iter().find(|s| s.name == name)
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.times_s.len()
    }

    /// Whether the log has no rows (never, for a parsed log).
    pub fn is_empty(&self) -> bool {
        self.times_s.is_empty()
    }
}

/// Why a log or a model was refused.
#[derive(Debug, thiserror::Error)]
pub enum ThermalError {
    /// The text of a log or a model file, at a position.
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// A request the log cannot serve (a sensor it lacks, rows it does not have).
    #[error("{0}")]
    Request(String),
}

/// A first-order lag (a low-pass with time constant `tau_s`) of `values`
/// sampled at `times_s`, starting at the first value: `y₀ = x₀`,
/// `yₖ = yₖ₋₁ + (1 − e^(−Δt/τ))·(xₖ − yₖ₋₁)` (the exact step response of
/// `τ·ẏ + y = x` for an input held over each interval, the update LinuxCNC's
/// `lowpass` component makes with `gain = 1 − e^(−Δt/τ)`). `tau_s = 0` is no lag.
pub fn lag(values: &[f64], times_s: &[f64], tau_s: f64, out: &mut Vec<f64>) {
    out.clear();
    let Some(&first) = values.first() else {
        return;
    };
    if tau_s <= 0.0 {
        out.extend_from_slice(values);
        return;
    }
    let mut state = first;
    let mut previous_t = times_s[0];
    for (&value, &t) in values.iter().zip(times_s) {
        let gain = 1.0 - (-(t - previous_t) / tau_s).exp();
        state += gain * (value - state);
        previous_t = t;
        out.push(state);
    }
}

#[cfg(test)]
mod tests;
