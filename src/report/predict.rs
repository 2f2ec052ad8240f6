//! The `--json` wire format and the terminal report of `axcomp predict`.
//!
//! # Wire format
//!
//! One object; keys may be added, never renamed or removed. The re-test of the
//! first `--table`'s axis is at the top level; further tables' re-tests are
//! in `also`, with the same keys.
//!
//! ```text
//! { "machine": "MCV 754 Quick", "chain": "ZFYX",
//!   "standard": "iso230-2:2014", "standard_name": "ISO 230-2:2014",
//!   "definitions_reconstructed": false,      (as in evaluate: --standard)
//!   "axis": "X", "line_mm": {"x": 0.0, "y": 250.0, "z": -275.0},
//!   "with_measured_scatter": true, "table_mode": "mean",
//!   "measured_B_mean_um": -3.18,              (the first test's B̄, which the prediction carries; null if unknown)
//!   "backlash_set": false,                    (--backlash-set: the backlash parameter takes B̄ out)
//!   "predicted_figures_um": {"A": …, … as in evaluate: the standard's keys},
//!   "figures_before_um": {…},                 (the same line without the table)
//!   "per_target": [{"target_mm": …, "predicted_up_um": …, "predicted_down_um": …,
//!                   "before_up_um": …, "before_down_um": …}, …],
//!   "also": [{"axis": "Y", …}],
//!   "volumetric_max_um": …, "volumetric_max_at_mm": {"x", "y", "z"},
//!   "volumetric_max_before_um": …, "volumetric_max_before_at_mm": {…},
//!   "grid_step_mm": 50.0, "grid_points": 2112,
//!   "effects": ["reversal"], "notes": ["…"] }
//! ```
//!
//! Deviations are actual − target as the laser reads them on the line, µm.

use std::fmt::Write;

use serde::Serialize;

use crate::predict::{PredictedRetest, Prediction};
use crate::report::format::{pad_name, um};
use crate::report::json::FiguresJson;
use crate::units::mm_to_um;

/// A machine position, mm.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct PositionJson {
    /// X, mm.
    pub x: f64,
    /// Y, mm.
    pub y: f64,
    /// Z, mm.
    pub z: f64,
}

impl From<[f64; 3]> for PositionJson {
    fn from(p: [f64; 3]) -> PositionJson {
        PositionJson {
            x: p[0],
            y: p[1],
            z: p[2],
        }
    }
}

/// One target of a predicted re-test, µm.
#[derive(Clone, Debug, Serialize)]
pub struct PredictedTargetJson {
    /// Target, mm.
    pub target_mm: f64,
    /// With the table, moving ↑.
    pub predicted_up_um: f64,
    /// With the table, moving ↓.
    pub predicted_down_um: f64,
    /// Without the table, moving ↑.
    pub before_up_um: f64,
    /// Without the table, moving ↓.
    pub before_down_um: f64,
}

/// The re-test of one axis.
#[derive(Clone, Debug, Serialize)]
pub struct RetestJson {
    /// The axis.
    pub axis: String,
    /// The line, mm.
    pub line_mm: PositionJson,
    /// Whether the readings carry the measured test's scatter.
    pub with_measured_scatter: bool,
    /// `mean` or `bidirectional`.
    pub table_mode: &'static str,
    /// The mean reversal B̄ the first test measured, which the prediction
    /// carries, µm; `null` without a bidirectional first test.
    #[serde(rename = "measured_B_mean_um")]
    pub measured_b_mean_um: Option<f64>,
    /// Whether the controller's backlash parameter takes B̄ out (`--backlash-set`).
    pub backlash_set: bool,
    /// Figures of the predicted re-test under the standard's keys, µm.
    pub predicted_figures_um: FiguresJson,
    /// The same line without the table, under the standard's keys, µm.
    pub figures_before_um: FiguresJson,
    /// Per target.
    pub per_target: Vec<PredictedTargetJson>,
}

impl RetestJson {
    /// From a predicted re-test.
    pub fn new(retest: &PredictedRetest) -> RetestJson {
        RetestJson {
            axis: retest.axis.letter().to_string(),
            line_mm: retest.line_mm.into(),
            with_measured_scatter: retest.with_measured_scatter,
            table_mode: retest.table_mode.as_str(),
            measured_b_mean_um: retest.measured_mean_reversal_mm.map(mm_to_um),
            backlash_set: retest.backlash_reversal_mm != 0.0,
            predicted_figures_um: FiguresJson::from_standard(&retest.standard_figures),
            figures_before_um: FiguresJson::from_standard(&retest.standard_figures_before),
            per_target: retest
                .per_target
                .iter()
                .map(|t| PredictedTargetJson {
                    target_mm: t.target_mm,
                    predicted_up_um: mm_to_um(t.up_mm),
                    predicted_down_um: mm_to_um(t.down_mm),
                    before_up_um: mm_to_um(t.before_up_mm),
                    before_down_um: mm_to_um(t.before_down_mm),
                })
                .collect(),
        }
    }
}

/// The whole `predict --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct PredictJson {
    /// Machine name.
    pub machine: String,
    /// Chain code.
    pub chain: String,
    /// The `--standard` the figures follow (`iso230-2:2014`, `vdi3441`).
    pub standard: &'static str,
    /// Its name and edition.
    pub standard_name: &'static str,
    /// Whether its definitions are reconstructed from public sources.
    pub definitions_reconstructed: bool,
    /// The first table's re-test.
    #[serde(flatten)]
    pub retest: RetestJson,
    /// The other tables' re-tests.
    pub also: Vec<RetestJson>,
    /// Largest volumetric error with the tables, µm.
    pub volumetric_max_um: f64,
    /// Where, mm.
    pub volumetric_max_at_mm: PositionJson,
    /// Largest volumetric error without the tables, µm.
    pub volumetric_max_before_um: f64,
    /// Where, mm.
    pub volumetric_max_before_at_mm: PositionJson,
    /// Step of the map, mm.
    pub grid_step_mm: f64,
    /// Points of the map.
    pub grid_points: usize,
    /// Kinds of the effects added from `--effects`.
    pub effects: Vec<&'static str>,
    /// What the reader should know, as sentences.
    pub notes: Vec<String>,
}

impl PredictJson {
    /// Builds the wire object; `prediction` has at least one re-test.
    pub fn new(
        machine: &str,
        chain: &str,
        prediction: &Prediction,
        grid_step_mm: f64,
        effects: Vec<&'static str>,
        notes: Vec<String>,
    ) -> PredictJson {
        let mut retests = prediction.retests.iter().map(RetestJson::new);
        let first = retests
            .next()
            .expect("predict returns one re-test per table, and needs a table");
        PredictJson {
            machine: machine.to_string(),
            chain: chain.to_string(),
            standard: prediction.standard.key,
            standard_name: prediction.standard.name,
            definitions_reconstructed: prediction.standard.reconstructed,
            retest: first,
            also: retests.collect(),
            volumetric_max_um: mm_to_um(prediction.volumetric_after.max_mm),
            volumetric_max_at_mm: prediction.volumetric_after.at_mm.into(),
            volumetric_max_before_um: mm_to_um(prediction.volumetric_before.max_mm),
            volumetric_max_before_at_mm: prediction.volumetric_before.at_mm.into(),
            grid_step_mm,
            grid_points: prediction.grid_points,
            effects,
            notes,
        }
    }
}

/// The terminal report.
pub fn render(report: &PredictJson) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "Machine      {} ({})", report.machine, report.chain);
    let _ = writeln!(out, "Figures      {}", report.standard_name);
    if report.definitions_reconstructed {
        let _ = writeln!(
            out,
            "             definitions reconstructed from public sources, not read in the standard (README, Standards)"
        );
    }
    for retest in std::iter::once(&report.retest).chain(&report.also) {
        render_retest(&mut out, retest);
    }
    let at = |p: &PositionJson| format!("X {} Y {} Z {} mm", p.x, p.y, p.z);
    let _ = writeln!(
        out,
        "\nVolumetric error, max ‖E‖ over a {} mm grid ({} points)\n  without the tables {} µm at {}\n  with the tables    {} µm at {}",
        report.grid_step_mm,
        report.grid_points,
        um(Some(report.volumetric_max_before_um)),
        at(&report.volumetric_max_before_at_mm),
        um(Some(report.volumetric_max_um)),
        at(&report.volumetric_max_at_mm),
    );
    if !report.effects.is_empty() {
        let _ = writeln!(out, "Effects      {}", report.effects.join(", "));
    }
    for note in &report.notes {
        let _ = writeln!(out, "Note: {note}");
    }
    out
}

fn render_retest(out: &mut String, retest: &RetestJson) {
    let line = &retest.line_mm;
    let _ = writeln!(
        out,
        "\nRe-test of {} on the line X {} Y {} Z {} mm{}",
        retest.axis,
        line.x,
        line.y,
        line.z,
        if retest.with_measured_scatter {
            " (with the first test's scatter)"
        } else {
            " (systematic only: one run each way, no R)"
        }
    );
    let _ = writeln!(out, " figure [µm] | no table | with the table");
    let _ = writeln!(out, "-------------+----------+---------------");
    let (b, p) = (&retest.figures_before_um, &retest.predicted_figures_um);
    for (name, key) in p.terminal_rows() {
        let _ = writeln!(
            out,
            " {} | {:>8} | {:>14}",
            pad_name(name, 11),
            um(b.get(key)),
            um(p.get(key))
        );
    }
}
