//! Abbe error: the offset of the measuring line times the angular error.

use serde::Deserialize;

use super::{Context, Fit, Line, Model, Parameter, Reading, Shape, TableRole, column};
use crate::measurement::Direction;
use crate::units::urad_times_mm_to_um;

/// Abbe: measuring-line offset × angular error.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Abbe {
    /// Offset from the line of the first test, mm.
    pub offset_mm: f64,
    /// Largest |angular error| along the stroke, µrad.
    pub angle_urad: f64,
}

/// The angular error at a reading's target, µrad (0 without a profile).
fn angle_at(reading: &Reading, line: &Line<'_>) -> f64 {
    line.angle_urad
        .and_then(|a| a.get(reading.target_index))
        .copied()
        .unwrap_or(0.0)
}

impl Model for Abbe {
    fn value(&self, reading: &Reading, line: &Line<'_>) -> f64 {
        urad_times_mm_to_um(self.offset_mm * angle_at(reading, line))
    }

    /// The volumetric model gives it from the line and the angular errors
    /// rather than from an effect.
    fn systematic(&self, _: f64, _: Direction, _: f64) -> Option<f64> {
        None
    }

    fn in_table(&self) -> TableRole {
        TableRole::NotATable {
            note: "abbe: not a table's business; measure on the functional line or compensate pitch and yaw".to_string(),
        }
    }

    fn explanation(&self, _: &Context) -> String {
        format!(
            "Positioning error that depends on the offset of the measuring line: {:.1} mm from the line of the first test, times an angular error of up to {:.1} µrad (Abbe error); measure on the functional line of the tool or let the model's pitch and yaw compensate it.",
            self.offset_mm, self.angle_urad
        )
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::number("offset_mm", "offset", "mm", self.offset_mm),
            Parameter::number("angle_urad", "angle", "µrad", self.angle_urad),
        ]
    }

    fn label(&self, _: &Context, number: &dyn Fn(f64) -> String) -> String {
        format!("Abbe, offset {} mm", number(self.offset_mm))
    }
}

impl Fit for Abbe {
    const NAME: &'static str = "abbe";
    const POSITIONAL: bool = true;

    fn columns(_: Shape, readings: &[Reading], line: &Line<'_>) -> Vec<Vec<f64>> {
        column(readings, |r| urad_times_mm_to_um(angle_at(r, line)))
    }

    fn from_fit(_: Shape, coefficients: &[f64], line: &Line<'_>) -> Abbe {
        Abbe {
            offset_mm: coefficients[0],
            angle_urad: line
                .angle_urad
                .unwrap_or(&[])
                .iter()
                .fold(0.0, |m: f64, a| m.max(a.abs())),
        }
    }
}
