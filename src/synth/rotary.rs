//! A rotary axis' truth and its synthetic test: the errors a
//! rotary axis has, in degrees and arc-seconds (`../shared/spec/standards.md`
//! §6), for tests with a known answer.
//!
//! ```toml
//! [axis]
//! name = "C"
//! machine = "5-axis trunnion (synthetic)"
//!
//! [rotary]
//! start_deg = 0.0               # targets start_deg + k·step, k = 0 … count − 1
//! end_deg = 360.0
//! count = 25
//! runs = 5
//! reversal_arcsec = 2.4         # B = x̄↑ − x̄↓ (↑ readings B/2 above the mean)
//! sigma_arcsec = 0.3            # scatter of one reading
//! harmonics = [                 # amplitude · sin(order·θ + phase)
//!   { per_revolution = 1, amplitude_arcsec = 4.0, phase_rad = 0.5 },   # eccentricity
//!   { per_revolution = 2, amplitude_arcsec = 1.5, phase_rad = -1.1 },  # encoder mounting
//! ]
//! ```
//!
//! The error is zero at the first target (the test's datum), as a laser
//! test reads it; readings are rounded to 0.001″. Runs go ↑ then ↓, cycle by
//! cycle, with one seeded noise stream. Not modelled yet: a worm-gear period
//! (a harmonic of its order serves), the timing of the readings and the
//! re-test with a table.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Normal};
use serde::Deserialize;

use super::SynthError;
use super::truth::AxisInfo;
use crate::compensate::CompensationTable;
use crate::error::ParseError;
use crate::measurement::{AxisKind, AxisSource, Direction, Measurement, Metadata, Run};
use crate::units::{arcsec_to_deg, deg_to_arcsec};

/// A rotary truth file (module doc).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotaryTruth {
    /// Axis and machine names for the files.
    #[serde(default)]
    pub axis: AxisInfo,
    /// The test and the errors.
    pub rotary: RotarySpec,
}

/// The rotary test cycle and the axis' errors.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotarySpec {
    /// First target, °.
    pub start_deg: f64,
    /// Last target, °.
    pub end_deg: f64,
    /// Number of targets, evenly spaced (≥ 2).
    pub count: usize,
    /// Runs per direction (≥ 1).
    pub runs: usize,
    /// Reversal value B = x̄↑ − x̄↓, ″.
    #[serde(default)]
    pub reversal_arcsec: f64,
    /// Standard deviation of one reading, ″.
    pub sigma_arcsec: f64,
    /// Per-revolution harmonics.
    #[serde(default)]
    pub harmonics: Vec<Harmonic>,
}

/// `amplitude · sin(per_revolution · θ + phase)`, θ in radians.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Harmonic {
    /// Cycles per revolution (1: eccentricity, 2: encoder mounting, …).
    pub per_revolution: u32,
    /// Amplitude, ″.
    pub amplitude_arcsec: f64,
    /// Phase, rad.
    #[serde(default)]
    pub phase_rad: f64,
}

impl RotaryTruth {
    /// Whether a truth file's text is a rotary one (it has a `[rotary]`
    /// table), which `axcomp synth` reads with [`RotaryTruth::from_toml_str`].
    pub fn is_rotary(text: &str) -> bool {
        text.parse::<toml::Table>()
            .is_ok_and(|table| table.contains_key("rotary"))
    }

    /// Parses a rotary truth file.
    pub fn from_toml_str(text: &str) -> Result<RotaryTruth, SynthError> {
        let truth: RotaryTruth =
            toml::from_str(text).map_err(|e| ParseError::from_toml(text, &e))?;
        let spec = &truth.rotary;
        let ascending =
            spec.end_deg.is_finite() && spec.start_deg.is_finite() && spec.end_deg > spec.start_deg;
        if spec.count < 2 || spec.runs == 0 || !ascending {
            return Err(SynthError::Truth(format!(
                "rotary: needs count ≥ 2, runs ≥ 1 and end_deg > start_deg, found count {}, runs {}, {}° … {}°",
                spec.count, spec.runs, spec.start_deg, spec.end_deg
            )));
        }
        if !(spec.sigma_arcsec >= 0.0 && spec.sigma_arcsec.is_finite()) {
            return Err(SynthError::Truth(format!(
                "rotary.sigma_arcsec must be ≥ 0, found {}",
                spec.sigma_arcsec
            )));
        }
        Ok(truth)
    }

    /// The targets, °.
    pub fn targets_deg(&self) -> Vec<f64> {
        let spec = &self.rotary;
        let step = (spec.end_deg - spec.start_deg) / (spec.count - 1) as f64;
        (0..spec.count)
            .map(|k| spec.start_deg + step * k as f64)
            .collect()
    }

    /// The harmonics' error at `angle_deg`, ″ (without the datum shift).
    pub fn harmonics_arcsec(&self, angle_deg: f64) -> f64 {
        self.rotary
            .harmonics
            .iter()
            .map(|h| {
                h.amplitude_arcsec
                    * (f64::from(h.per_revolution) * angle_deg.to_radians() + h.phase_rad).sin()
            })
            .sum()
    }
}

/// The synthetic test of a rotary truth, seeded.
pub fn rotary_test(truth: &RotaryTruth, seed: u64) -> Result<Measurement, SynthError> {
    simulate(truth, None, seed)
}

/// The re-test of the compensated rotary axis, seeded: the controller
/// applies `table` (°, actual − target, interpolated with its ends held as
/// [`CompensationTable::value_at`]): it commands θ − v, where the axis errs
/// by the truth's error at θ − v, and the reading is that error − v.
pub fn rotary_retest(
    truth: &RotaryTruth,
    table: &CompensationTable,
    seed: u64,
) -> Result<Measurement, SynthError> {
    simulate(truth, Some(table), seed)
}

fn simulate(
    truth: &RotaryTruth,
    table: Option<&CompensationTable>,
    seed: u64,
) -> Result<Measurement, SynthError> {
    let spec = &truth.rotary;
    let targets = truth.targets_deg();
    let datum_arcsec = truth.harmonics_arcsec(targets[0]);
    let noise = Normal::new(0.0, spec.sigma_arcsec)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut runs = Vec::with_capacity(2 * spec.runs);
    for number in 1..=spec.runs as u32 {
        for direction in Direction::BOTH {
            let deviations = targets
                .iter()
                .map(|&angle| {
                    let applied_deg = table.map_or(0.0, |t| t.value_at(angle, direction));
                    let arcsec = truth.harmonics_arcsec(angle - applied_deg)
                        - datum_arcsec
                        - deg_to_arcsec(applied_deg)
                        + direction.reversal_share(spec.reversal_arcsec)
                        + noise.sample(&mut rng);
                    // An encoder's resolution, 0.001″; converted as a reader converts it.
                    Some(arcsec_to_deg((arcsec * 1000.0).round() / 1000.0))
                })
                .collect();
            runs.push(Run {
                direction,
                number,
                start_time_s: None,
                deviations,
            });
        }
    }
    let metadata = Metadata {
        machine: truth.axis.machine.clone(),
        serial_number: truth.axis.serial.clone(),
        operator: truth.axis.operator.clone(),
        location: truth.axis.location.clone(),
        description: Some("synthetic rotary test (axcomp synth)".to_string()),
        // The truth file names the axis.
        axis_source: AxisSource::Given,
        ..Metadata::default()
    };
    let measurement = Measurement::new(
        truth.axis.name.clone(),
        targets,
        runs,
        Default::default(),
        metadata,
    )?;
    Ok(measurement.with_kind(AxisKind::Rotary))
}
