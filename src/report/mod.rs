//! Reports: what users and scripts read.
//!
//! [`json`] holds the `--json` wire formats: dedicated serde structs whose
//! keys carry units (`A_um`, `target_mm`); internal types are never
//! serialised directly. [`terminal`] renders the same data as a readable
//! terminal report. [`convert`] is the summary of `axcomp convert` ([`cross_axis`]
//! for a cross-axis table),
//! [`predict`] and [`diagnose`] the wire formats and reports of `axcomp
//! predict` and `axcomp diagnose`;
//! [`tolerance`] the wire format and terminal report of `axcomp tolerance`,
//! and [`plot`] its histogram as SVG or PNG bytes; [`servo`] the output of
//! `servo-sim`. The acceptance report of `axcomp report`: [`acceptance`]
//! what it is made from and its charts, [`chart`] x–y charts as data drawn
//! as SVG or PNG, [`html`] the self-contained page. All convert mm to µm
//! through `crate::units`; [`verdict`] the acceptance verdict (JSON,
//! terminal lines, the report's box); [`uncertainty`] the measurement
//! uncertainty's budget (JSON, terminal table); nothing else in the crate depends on this module;
//! files are written by `crate::output`.
pub mod acceptance;
pub mod chart;
pub mod convert;
pub mod cross_axis;
pub mod diagnose;
pub mod format;
pub mod html;
pub mod json;
pub mod plot;
pub mod predict;
pub mod servo;
pub mod terminal;
pub mod thermal;
pub mod tolerance;
pub mod uncertainty;
pub mod update;
pub mod verdict;
pub mod web;
