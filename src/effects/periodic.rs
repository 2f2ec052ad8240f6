//! Periodic error in position: `amplitude · sin(2πx/period + phase)` (a screw
//! lead, a scale period). On a rotary axis the period is 360°/k,
//! a whole order k per revolution (once from eccentricity, twice from the
//! encoder's mounting, a worm gear's tooth count), and the sentences say so
//! in ° and ″ ([`super::EffectIn::per_revolution`]).

use std::f64::consts::{PI, TAU};

use serde::Deserialize;

use super::{
    Context, Fit, FitSummary, Line, Model, Parameter, Reading, Shape, TableRole, Uncertainty,
};
use crate::evaluate::conformance::FULL_TURN_DEG;
use crate::measurement::{AxisKind, Direction};

/// The period's key in the effects file and in a linear axis' JSON, and
/// among a fit's uncertainties ([`super::Uncertainty`]); it names mm, the
/// unit of the period on a linear axis, the only one these are written for.
pub const PERIOD_KEY: &str = "period_mm";
/// The amplitude's key, as [`PERIOD_KEY`]: µm on a linear axis.
pub const AMPLITUDE_KEY: &str = "amplitude_um";

/// Periodic error `amplitude · sin(2πx/period + phase)`, in the axis'
/// units: period in mm and amplitude in µm, or on a rotary axis period in °
/// and amplitude in m° (1/1000 °) ([`super::Effect::typed`]).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Periodic {
    /// Period: mm, or ° on a rotary axis. The effects file (a linear axis'
    /// only) keys it `period_mm`.
    #[serde(rename = "period_mm")]
    pub period: f64,
    /// Amplitude: µm, or m° on a rotary axis. The effects file keys it
    /// `amplitude_um`.
    #[serde(rename = "amplitude_um")]
    pub amplitude: f64,
    /// rad.
    #[serde(default)]
    pub phase_rad: f64,
}

impl Periodic {
    /// On a rotary axis, the whole number of periods per revolution
    /// (360°/period), when the period is one.
    fn per_revolution(&self) -> Option<u32> {
        per_revolution(self.period)
    }

    fn at(&self, x_mm: f64) -> f64 {
        self.amplitude * (TAU * x_mm / self.period + self.phase_rad).sin()
    }
}

/// The whole number of periods of `period_deg` in a revolution
/// (360°/period), when it is one.
pub(super) fn per_revolution(period_deg: f64) -> Option<u32> {
    let order = FULL_TURN_DEG / period_deg;
    ((order - order.round()).abs() < 1e-9 && order >= 0.5).then(|| order.round() as u32)
}

impl Model for Periodic {
    fn value(&self, reading: &Reading, _: &Line<'_>) -> f64 {
        self.at(reading.target)
    }

    fn systematic(&self, x_mm: f64, _: Direction, _: f64) -> Option<f64> {
        Some(self.at(x_mm))
    }

    /// Linear interpolation between points h apart leaves up to
    /// A·(1 − cos(πh/p)) of a sine: under 5 % of A for h ≤ p/10.
    fn in_table(&self) -> TableRole {
        TableRole::AtPoints {
            finest_step: self.period / 10.0,
        }
    }

    fn explanation(&self, context: &Context) -> String {
        if context.kind == AxisKind::Rotary {
            return self.rotary_explanation(context);
        }
        let table = context
            .table_step
            .map(|s| format!("; the table's step of {s} mm cannot follow it"))
            .unwrap_or_default();
        format!(
            "Periodic error of {:.2} µm amplitude and {:.2} mm period (screw lead or scale period){table}; compensate with a step of at most {:.2} mm (convert --effects) or the control's pitch compensation, or check the screw.",
            self.amplitude,
            self.period,
            self.period / 10.0
        )
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::number(PERIOD_KEY, "period", "mm", self.period),
            Parameter::number(AMPLITUDE_KEY, "amplitude", "µm", self.amplitude),
            Parameter::number("phase_rad", "phase", "rad", self.phase_rad),
        ]
    }

    fn label(&self, context: &Context, number: &dyn Fn(f64) -> String) -> String {
        format!(
            "periodic {}, period {}",
            context.deviation_label(self.amplitude, number),
            context.position_label(self.period, number)
        )
    }

    fn check(&self) -> Result<(), String> {
        if self.period > 0.0 && self.period.is_finite() {
            Ok(())
        } else {
            Err(format!("period_mm must be > 0, found {}", self.period))
        }
    }
}

impl Periodic {
    /// The sentence on a rotary axis: the order per revolution and what
    /// commonly causes it (Kadlečík (2019) and `../shared/spec/standards.md` §6:
    /// eccentricity once, encoder mounting twice per revolution).
    fn rotary_explanation(&self, context: &Context) -> String {
        let order = match self.per_revolution() {
            Some(1) => "Once-per-revolution error (1 per revolution: eccentricity of the encoder or the table)".to_string(),
            Some(2) => "Twice-per-revolution error (2 per revolution: the encoder's mounting, an elliptic scale)".to_string(),
            Some(k) => format!("{k}-per-revolution error ({k} per revolution: a worm gear's or a scale's period)"),
            None => "Periodic error".to_string(),
        };
        // Linear interpolation follows the order within 5 % at a step of
        // period/10 (`in_table`); a coarser table cannot.
        let table = context
            .table_step
            .filter(|s| *s > self.period / 10.0)
            .map(|s| format!("; the table's step of {s}° cannot follow it"))
            .unwrap_or_default();
        format!(
            "{order} of {} amplitude and {:.2}° period{table}; the re-test's own table takes it out at a step of at most {:.2}° (convert the re-test with --existing and the active table), or check the encoder's mounting and the table's run-out.",
            context.deviation(self.amplitude),
            self.period,
            self.period / 10.0
        )
    }
}

impl Fit for Periodic {
    const NAME: &'static str = "periodic";
    const POSITIONAL: bool = true;

    fn columns(shape: Shape, readings: &[Reading], _: &Line<'_>) -> Vec<Vec<f64>> {
        let Shape::Period(period, _) = shape else {
            return Vec::new();
        };
        vec![
            readings
                .iter()
                .map(|r| (TAU * r.target / period).sin())
                .collect(),
            readings
                .iter()
                .map(|r| (TAU * r.target / period).cos())
                .collect(),
        ]
    }

    fn from_fit(shape: Shape, coefficients: &[f64], _: &Line<'_>) -> Periodic {
        let Shape::Period(period, _) = shape else {
            unreachable!("a periodic effect's shape is its period")
        };
        // a·sin θ + b·cos θ = A·sin(θ + φ) with A cos φ = a, A sin φ = b.
        let (a, b) = (coefficients[0], coefficients[1]);
        Periodic {
            period,
            amplitude: a.hypot(b),
            phase_rad: b.atan2(a),
        }
    }

    /// Amplitude from its two coefficients; period from the frequency
    /// estimate's variance 6σ²/(π²A²T²N) (Rife & Boorstyn 1974), σ² from the
    /// fit (χ²/dof with known variances, RSS/dof otherwise). Evenly spaced
    /// targets alias: the caveat names the periods that give the same readings.
    fn uncertainty(&self, fit: &FitSummary<'_>) -> (Vec<Uncertainty>, Vec<String>) {
        let (coefficients, errors, n) = (fit.coefficients, fit.errors, fit.n);
        let (a, b) = (coefficients[0], coefficients[1]);
        let sigma_amplitude =
            ((a * errors[0]).powi(2) + (b * errors[1]).powi(2)).sqrt() / self.amplitude.max(1e-12);
        let noise = sigma_amplitude * (n as f64 / 2.0).sqrt();
        let sigma_frequency =
            6f64.sqrt() * noise / (PI * self.amplitude.max(1e-12) * fit.span * (n as f64).sqrt());
        let mut warnings = Vec::new();
        match (fit.target_spacing, fit.kind, self.per_revolution()) {
            // Samples N = 360°/spacing per revolution: orders N − k and N + k
            // give the same readings as k.
            (Some(spacing), AxisKind::Rotary, Some(k)) => {
                let samples = (FULL_TURN_DEG / spacing).round() as i64;
                let k = i64::from(k);
                warnings.push(format!(
                    "the targets are evenly spaced ({spacing}°): orders {} and {} per revolution give the same readings (aliasing); measure with irregular spacing to tell them apart",
                    (samples - k).abs(),
                    samples + k
                ));
            }
            (Some(spacing), _, _) => {
                let aliases: Vec<String> = (1..=2)
                    .map(|k| 1.0 / (f64::from(k) / spacing - 1.0 / self.period).abs())
                    .filter(|p| p.is_finite())
                    .map(|p| format!("{p:.2} mm"))
                    .collect();
                warnings.push(format!(
                    "the targets are evenly spaced ({spacing} mm): periods {} give the same readings (aliasing); measure with irregular spacing to tell them apart",
                    aliases.join(", ")
                ));
            }
            (None, _, _) => {}
        }
        // A rotary order is chosen among whole numbers, not estimated: its
        // period has no uncertainty to give.
        let uncertainty = match (fit.kind, self.per_revolution()) {
            (AxisKind::Rotary, Some(_)) => vec![(AMPLITUDE_KEY, sigma_amplitude)],
            _ => vec![
                (PERIOD_KEY, self.period * self.period * sigma_frequency),
                (AMPLITUDE_KEY, sigma_amplitude),
            ],
        };
        (uncertainty, warnings)
    }
}
