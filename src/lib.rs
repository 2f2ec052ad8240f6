//! axcomp: from a laser-interferometer log to ISO 230-2 figures and controller
//! compensation tables.
//!
//! # Brief overview
//!
//! Data flows through one module per stage:
//!
//! - [`read`] opens a measurement file (Renishaw `.rtl`, ESS/PSI ecmc `.dat`,
//!   API XD `.pos`, axcomp CSV), detects its format and returns a validated
//!   [`measurement::Measurement`]: targets in mm, runs with their direction,
//!   deviations in mm (`None` where a reading is missing), environment and
//!   metadata.
//! - [`evaluate`] computes the ISO 230-2 figures (A, E, M, R, B per direction
//!   and per target) as an [`evaluate::Evaluation`], with `None` wherever the
//!   standard leaves a figure undefined, and flags suspected outlier runs.
//! - [`compensate`] builds the compensation table (actual − target, zero at
//!   the reference) and [`emit`] writes and reads it for each controller.
//! - [`model`] is the geometric model of a three-axis machine (Valášek (2021)):
//!   the 21 errors, the kinematic chain as data, the volumetric error, the
//!   guideway model and the Monte Carlo tolerance study; [`predict`] applies
//!   tables to it and predicts the re-test and the residual volumetric error.
//! - [`diagnose`] traces the residual of a re-test to the effects the model
//!   lacks (reversal, scale, drift, periodic, outlier run, Abbe).
//! - [`servo`] simulates a feed axis with friction (Mendřický (2006)) and gives the
//!   reversal B ≈ 2·F_res/k_c that friction leaves through a compliance.
//! - [`synth`] writes measurements from a known truth, with the ISO 230-2
//!   cycle's timing from [`cycle`].
//! - [`report`] turns all of them into terminal reports, the `--json` wire
//!   formats (µm, unit-suffixed keys) and the acceptance report (HTML, PNG).
//! - [`output`] is the one place that creates files: via a temporary file and
//!   a rename, never overwriting without `force`.
//!
//! Lengths are mm inside; [`units`] holds every conversion factor.
//!
//! # Example
//!
//! ```
//! use axcomp::{evaluate::evaluate, measurement::SourceFormat, read};
//!
//! let csv = "target_mm,run,direction,deviation_um\n\
//!            0,1,up,0\n100,1,up,4\n0,1,down,-2\n100,1,down,2\n\
//!            0,2,up,2\n100,2,up,6\n0,2,down,0\n100,2,down,4\n";
//! let (measurement, _warnings) = read::parse_str(csv, SourceFormat::Csv).unwrap();
//! let evaluation = evaluate(&measurement);
//! // B_i = x̄↑ − x̄↓ = 2 µm at both targets.
//! assert!((evaluation.figures.b.unwrap() - 0.002).abs() < 1e-12);
//! ```

#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod compensate;
pub mod cycle;
pub mod diagnose;
pub mod effects;
pub mod emit;
pub mod error;
pub mod evaluate;
pub mod measurement;
pub mod model;
pub mod output;
pub mod predict;
pub mod read;
pub mod report;
pub mod serve;
pub mod servo;
pub mod spline;
pub mod synth;
pub mod thermal;
pub mod together;
pub mod units;
pub mod workflow;
