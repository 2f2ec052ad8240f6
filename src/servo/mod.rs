//! Feed-drive friction and servo model (Mendřický 2006), and what
//! friction does to an ISO 230-2 positioning test.
//!
//! # Brief overview
//!
//! - [`friction`]: the four friction models A (classic), B1 (ramp), B2
//!   (power law) and C (LuGre), each a small type, with an implicit update
//!   over a step that stays stable at machine speeds.
//! - [`axis`]: the axis parameters (mass, motor, cascade gains, sampling,
//!   quantisation, dead time, friction), read from TOML; Mendřický's MCFV
//!   5050 LN X and Y axes are bundled.
//! - [`trajectory`]: circle, point-to-point moves with dwells, standstill.
//! - [`simulate`]: the cascade in time, exact for the linear part, with
//!   1 µs sub-steps only where friction is active.
//! - [`circle`]: the circular test and its reversal figures (Tab. 6.4).
//! - [`iso_cycle`]: a simulated ISO 230-2 linear test (a `Measurement`,
//!   evaluated), with a structural compliance between drive and laser.
//! - [`reversal`]: B ≈ 2·F_res/k_c (the simulated ISO cycle's report uses
//!   it) and its inverse (`diagnose::friction` reads a measured B as the
//!   friction force held through the structure with it).
//! - [`force_step`]: the force-step (impact compliance) test; and a
//!   constant-velocity run.
//! - [`identify`]: Mendřický's identification arithmetic (every axis
//!   file uses the LuGre damping; [`friction_fit`] the linear fit of the
//!   constant-velocity currents).
//! - [`friction_fit`]: `servo-sim --identify`, F_C and μ_v from a
//!   constant-velocity record and k_s from a measured circle reversal.
//!
//! Lengths are metres inside this module (the model is SI throughout);
//! results that leave it for a `Measurement` are converted to mm through
//! `crate::units`.
//!
//! Pure: no I/O, no printing, no clock, no randomness. Long runs report
//! progress through a plain callback.

pub mod axis;
pub mod circle;
pub mod force_step;
pub mod friction;
pub mod friction_fit;
pub mod identify;
pub mod iso_cycle;
pub mod linear;
pub mod reversal;
pub mod simulate;
pub mod trajectory;

use crate::error::ParseError;
use crate::measurement::MeasurementError;

/// Why the servo stage refuses: an axis file, a bundled name, or a cycle's
/// parameters (one error type for the stage).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ServoError {
    /// The TOML did not parse or did not match the layout.
    #[error("{0}")]
    Parse(ParseError),
    /// A value is out of its physical range.
    #[error("{key}: expected {expected}, found {found}")]
    Value {
        /// The key, as `motor.resistance_ohm`.
        key: &'static str,
        /// What is allowed.
        expected: &'static str,
        /// The value found.
        found: f64,
    },
    /// `--axis NAME` names no bundled axis.
    #[error("unknown axis {0:?}; bundled: mcfv5050-x, mcfv5050-y (or give a .toml file)")]
    UnknownBundled(String),

    /// A parameter out of range.
    #[error("{0}")]
    Invalid(&'static str),
    /// The readings did not make a valid measurement (not expected).
    #[error("simulated readings: {0}")]
    Measurement(#[from] MeasurementError),
}

#[cfg(test)]
mod tests;
