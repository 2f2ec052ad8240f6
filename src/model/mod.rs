//! The geometric model of a three-axis machine: 21 errors → volumetric error
//! (Valášek 2021), rail mounting surfaces and the saddle's carriage mounting
//! faces → axis errors (guideway model), and the Monte Carlo tolerance study
//! built on both.
//!
//! The source is Valášek (2021), extracted with every equation, typo and
//! check value in `../shared/notes/seed000-volumetric-model.md`; equation
//! numbers in this module's comments are Valášek's.
//!
//! - [`components`]: the 21 errors with their ISO 230-1 names
//!   ([`ErrorName`]), each a function of its own axis ([`ErrorFunction`]:
//!   a constant or an [`ErrorTable`], linear or spline), gathered in
//!   [`GeometricErrors`].
//! - [`error_description`]: the error description file (`predict --errors`).
//! - [`machine`]: the machine description ([`Machine`], from TOML), with the
//!   kinematic chain as data (ZFYX, FXYZ, YFXZ, …).
//! - [`volumetric`]: the chain evaluated with full homogeneous transforms or
//!   to first order ([`Method`]), at a point or over a [`Grid`].
//! - [`guideway`]: one axis on two rails and four carriages ([`Guideway`]),
//!   and the carriage side: the saddle's carriage mounting faces
//!   ([`SaddleFaces`], the carriage-side thesis (references.md) Obr. 8).
//! - [`profile`]: the random profile generator ([`ProfileShape`]).
//! - [`monte_carlo`]: the tolerance study (rail and carriage-side
//!   tolerances), its sensitivity sweep and ranking, and the single-axis
//!   study; seeded, parallel and bit-identical at any thread count.
//!
//! Pure: no I/O, no printing, no clock, no unseeded randomness. Lengths are
//! mm, angles rad, forces N.
//!
//! # For `axcomp predict`: errors from tables, error at a point, error map
//!
//! ```
//! use axcomp::model::{
//!     ErrorFunction, ErrorName, ErrorTable, GeometricErrors, Grid, Interpolation, Machine, Method,
//! };
//!
//! // (a) The 21 errors from tables: EXX from a positioning test along X
//! // (targets mm, mean deviations mm; linear, end values held outside).
//! let machine = Machine::bundled(); // or Machine::from_toml_str(&text)?
//! let mut errors = GeometricErrors::default(); // all 21 zero
//! let exx = ErrorTable::new(vec![0.0, 375.0, 750.0], vec![0.0, 0.006, 0.004], Interpolation::Linear)?;
//! errors.set(ErrorName::EXX, ErrorFunction::Table(exx))?;
//! errors.set(ErrorName::EBX, ErrorFunction::Constant(5e-6))?; // pitch of X, rad
//!
//! // (b) The volumetric error at a point for a given tool: Abbe offsets come
//! // from the chain, so a longer tool changes what pitch and yaw do.
//! let long_tool = machine.with_tool_offset([0.0, -280.0, -350.0])?;
//! let error = long_tool.volumetric_error(&errors, [375.0, 250.0, -275.0], Method::Full);
//! // E_X = EXX(375) − EXX(0) + EBX·ΔZ: 6 µm + 5 µrad × (−275 mm).
//! assert!((error.translation_mm.x - (0.006 - 5e-6 * 275.0)).abs() < 1e-9);
//!
//! // (c) The error map over a 50 mm grid and its maximum ‖E‖ (eq. 71).
//! let grid = Grid::over_strokes(&machine, 50.0)?;
//! let map = machine.error_map(&errors, &grid, Method::FirstOrder);
//! let (max_mm, where_mm) = map.max_translation();
//! // The grid point nearest EXX's peak: X = 400 (EXX = 0.006 − 0.002 · 25/375), Z = 0.
//! assert!((max_mm - (0.006 - 0.002 * 25.0 / 375.0)).abs() < 1e-12);
//! assert_eq!((where_mm[0], where_mm[2]), (400.0, 0.0));
//! # Ok::<(), axcomp::model::ModelError>(())
//! ```
//!
//! The volumetric error is zero at the machine's reference position (eq. 68;
//! the origin unless the description says otherwise); the rotational
//! components (eq. 69) are not zeroed. Set [`BranchDeviations::Difference`]
//! for the tool-relative-to-workpiece convention instead of Valášek's sum.

pub mod components;
pub mod description;
pub mod error_description;
pub mod guideway;
pub mod machine;
pub mod monte_carlo;
pub mod profile;
pub mod stats;
pub mod volumetric;

pub use components::{
    Axis, AxisErrors, ErrorComponent, ErrorFunction, ErrorName, ErrorTable, ErrorValues,
    GeometricErrors, Interpolation, Squareness, SquarenessPair,
};
pub use description::{
    AxisDescription, BranchDeviations, ChainCode, ErrorFrame, MappingSigns, Optics, OpticsBody,
};
pub use error_description::read_error_description;
pub use guideway::{
    CarriageDeviations, Guideway, GuidewayMap, GuidewayResponse, OutputWeights, RailProfiles,
    SaddleFaces,
};
pub use machine::Machine;
pub use profile::ProfileShape;
pub use volumetric::{ErrorMap, Grid, Method, VolumetricError};

use crate::error::ParseError;

/// Why a model could not be built or run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// The machine description is not valid TOML or has a wrong type, at a
    /// position (the CLI adds the path in front).
    #[error("{0}")]
    Toml(ParseError),
    /// A value that the model cannot use.
    #[error("{what}: expected {expected}, found {found}")]
    Invalid {
        /// What the value is (a TOML key such as `axes.X.stroke_mm`, or a name).
        what: String,
        /// What would be accepted.
        expected: String,
        /// What was given.
        found: String,
    },
}

impl ModelError {
    /// An [`ModelError::Invalid`].
    pub(crate) fn invalid(
        what: impl Into<String>,
        expected: impl Into<String>,
        found: impl Into<String>,
    ) -> ModelError {
        ModelError::Invalid {
            what: what.into(),
            expected: expected.into(),
            found: found.into(),
        }
    }

    /// The same error with `context: ` in front of what it is about.
    pub(crate) fn within(self, context: &str) -> ModelError {
        match self {
            ModelError::Invalid {
                what,
                expected,
                found,
            } => ModelError::Invalid {
                what: format!("{context}: {what}"),
                expected,
                found,
            },
            other => other,
        }
    }
}

/// `Ok` when `value` is finite and above zero, else an error naming it.
pub(crate) fn check_positive(what: &str, value: f64, expected: &str) -> Result<(), ModelError> {
    if value.is_finite() && value > 0.0 {
        return Ok(());
    }
    Err(ModelError::invalid(what, expected, value.to_string()))
}

#[cfg(test)]
mod tests;
