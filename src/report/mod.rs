//! Reports: what users and scripts read.
//!
//! [`json`] holds the `--json` wire formats: dedicated serde structs whose
//! keys carry units (`A_um`, `target_mm`); internal types are never
//! serialised directly. [`terminal`] renders the same data as a readable
//! terminal report; [`servo`] is the output of `servo-sim`. All convert mm
//! to µm through `crate::units`; nothing else in the crate depends on this
//! module.

pub mod json;
pub mod servo;
pub mod terminal;
