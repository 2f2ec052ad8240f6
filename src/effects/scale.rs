//! Scale: a deviation linear in position, zero at the first target.

use serde::Deserialize;

use super::{Context, Fit, Line, Model, OneNumber, Parameter, Reading, Shape, TableRole, column};
use crate::measurement::Direction;
use crate::units::{mm_to_m, per_m_over_mm};

/// Scale, µm/m.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scale {
    /// µm per m of travel from the first target.
    pub scale_um_per_m: f64,
}

/// The one parameter, as it is shown and saved.
const SCALE: OneNumber = OneNumber {
    key: "scale_um_per_m",
    name: "scale",
    unit: "µm/m",
};

impl Model for Scale {
    fn value(&self, reading: &Reading, line: &Line<'_>) -> f64 {
        per_m_over_mm(self.scale_um_per_m, reading.target - line.first_target_mm)
    }

    fn systematic(&self, x_mm: f64, _: Direction, first_target_mm: f64) -> Option<f64> {
        Some(per_m_over_mm(self.scale_um_per_m, x_mm - first_target_mm))
    }

    fn in_table(&self) -> TableRole {
        TableRole::TakenOut {
            note: format!(
                "scale: {:.2} µm/m taken out; the table stays referred to the first test's conditions",
                self.scale_um_per_m
            ),
        }
    }

    fn explanation(&self, context: &Context) -> String {
        let scale_um_per_m = self.scale_um_per_m;
        let thermal = context
            .expansion_coefficient_ppm_per_k
            .filter(|a| *a > 0.0)
            .map(|alpha| {
                let delta = scale_um_per_m / alpha;
                let recorded = context
                    .material_change_k
                    .map(|k| format!("; the material sensors recorded {k:+.2} K between the tests"))
                    .unwrap_or_default();
                format!(", as a temperature change of {delta:+.2} K at {alpha} ppm/K would give{recorded}")
            });
        format!(
            "Deviation growing linearly by {scale_um_per_m:.2} µm/m along the axis{}: thermal expansion of axis or scale, a wrong expansion coefficient or a misaligned laser; refer the table to 20 °C (convert --effects) or re-measure at the temperature of the first test with the laser aligned.",
            thermal.unwrap_or_default()
        )
    }

    fn parameters(&self) -> Vec<Parameter> {
        SCALE.parameters(self.scale_um_per_m)
    }

    fn label(&self, _: &Context, number: &dyn Fn(f64) -> String) -> String {
        SCALE.label(Self::NAME, self.scale_um_per_m, number)
    }
}

impl Fit for Scale {
    const NAME: &'static str = "scale";
    const POSITIONAL: bool = true;

    fn columns(_: Shape, readings: &[Reading], line: &Line<'_>) -> Vec<Vec<f64>> {
        column(readings, |r| mm_to_m(r.target - line.first_target_mm))
    }

    fn from_fit(_: Shape, coefficients: &[f64], _: &Line<'_>) -> Scale {
        Scale {
            scale_um_per_m: coefficients[0],
        }
    }
}
