//! The `--json` wire format and the terminal summary of `axcomp convert`.
//!
//! # Wire format
//!
//! ```text
//! { "controller": "tnc640", "file": "X.COM", "axis": "X", "also": ["U"],
//!   "mode": "mean" | "bidirectional", "positions_mm": [...], "count": 16,
//!   "start_mm": 0.0, "step_mm": 50.0 | null, "reference_mm": 0.0,
//!   "values_um": {"mean": [...]} | {"up": [...], "down": [...]},
//!   "suggested_backlash_um": 3.2 | null, "activation": "…",
//!   "effects": ["…what --effects changed…"], "warnings": [...] }
//! ```
//! Values are the axis error actual − target in µm, zero at the reference,
//! before each controller's own sign convention (see `formats/`).

use std::fmt::Write;

use serde::Serialize;

use crate::compensate::{CompensationTable, TableValues};
use crate::report::terminal::um;
use crate::units::mm_to_um;

/// The table's values, µm.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum ValuesJson {
    /// One column.
    Mean {
        /// Per point.
        mean: Vec<f64>,
    },
    /// One column per direction.
    Bidirectional {
        /// Moving +.
        up: Vec<f64>,
        /// Moving −.
        down: Vec<f64>,
    },
}

/// The whole `convert --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct ConvertJson {
    /// `--controller` name.
    pub controller: &'static str,
    /// The file written.
    pub file: String,
    /// The compensated axis.
    pub axis: String,
    /// Coupled axes that got the same table.
    pub also: Vec<String>,
    /// `mean` or `bidirectional`.
    pub mode: &'static str,
    /// Compensation points, mm.
    pub positions_mm: Vec<f64>,
    /// Number of points.
    pub count: usize,
    /// First point, mm.
    pub start_mm: f64,
    /// Spacing, mm, or `null` when uneven.
    pub step_mm: Option<f64>,
    /// Where the table is zero, mm.
    pub reference_mm: f64,
    /// The values, µm.
    pub values_um: ValuesJson,
    /// Suggested backlash parameter, µm (mean mode).
    pub suggested_backlash_um: Option<f64>,
    /// How to activate the table on the controller.
    pub activation: String,
    /// What `--effects` changed, as sentences (empty without it).
    pub effects: Vec<String>,
    /// Warnings from reading and evaluating.
    pub warnings: Vec<String>,
}

impl ConvertJson {
    /// Builds the wire object.
    pub fn new(
        controller: &'static str,
        file: String,
        table: &CompensationTable,
        also: Vec<String>,
        activation: String,
        warnings: Vec<String>,
    ) -> ConvertJson {
        let to_um = |values: &[f64]| values.iter().copied().map(mm_to_um).collect();
        ConvertJson {
            controller,
            file,
            axis: table.axis.clone(),
            also,
            mode: table.values.mode().as_str(),
            positions_mm: table.positions_mm.clone(),
            count: table.positions_mm.len(),
            start_mm: table.positions_mm[0],
            step_mm: table.regular_step_mm(),
            reference_mm: table.reference_mm,
            values_um: match &table.values {
                TableValues::Mean(values) => ValuesJson::Mean {
                    mean: to_um(values),
                },
                TableValues::Bidirectional { up, down } => ValuesJson::Bidirectional {
                    up: to_um(up),
                    down: to_um(down),
                },
            },
            suggested_backlash_um: table.suggested_backlash_mm.map(mm_to_um),
            activation,
            effects: Vec::new(),
            warnings,
        }
    }

    /// The terminal summary: what was written, the table, how to activate it.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        let step = self
            .step_mm
            .map_or("uneven spacing".to_string(), |s| format!("step {s} mm"));
        let also = if self.also.is_empty() {
            String::new()
        } else {
            format!(" (also {})", self.also.join(", "))
        };
        let _ = writeln!(
            out,
            "Wrote {} for {}: {} table of axis {}{also}, {} points from {} to {} mm, {step}, zero at {} mm",
            self.file,
            self.controller,
            self.mode,
            self.axis,
            self.count,
            self.start_mm,
            self.positions_mm[self.count - 1],
            self.reference_mm
        );
        for effect in &self.effects {
            let _ = writeln!(out, "Effect: {effect}");
        }
        if let Some(backlash) = self.suggested_backlash_um {
            let _ = writeln!(
                out,
                "Suggested backlash parameter: {backlash:.2} µm (−B̄; Heidenhain backlash MP, Siemens MD32450 $MA_BACKLASH)"
            );
        }
        let _ = writeln!(
            out,
            "\nCompensation table [µm] (axis error actual − target, zero at the reference)"
        );
        match &self.values_um {
            ValuesJson::Mean { mean } => {
                let _ = writeln!(out, "{:>12}  {:>9}", "position mm", "value");
                for (p, v) in self.positions_mm.iter().zip(mean) {
                    let _ = writeln!(out, "{p:>12}  {:>9}", um(Some(*v)));
                }
            }
            ValuesJson::Bidirectional { up, down } => {
                let _ = writeln!(out, "{:>12}  {:>9}  {:>9}", "position mm", "↑", "↓");
                for ((p, u), d) in self.positions_mm.iter().zip(up).zip(down) {
                    let _ = writeln!(out, "{p:>12}  {:>9}  {:>9}", um(Some(*u)), um(Some(*d)));
                }
            }
        }
        let _ = writeln!(out, "\nActivation:\n{}", self.activation);
        out
    }
}
