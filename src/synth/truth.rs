//! The ground truth `axcomp synth` generates measurements from (a TOML file).
//!
//! ```toml
//! [axis]
//! name = "X"
//! machine = "MCV 754 Quick"
//!
//! [cycle]                       # the ISO 230-2 linear cycle of the test
//! start_mm = 0.0                # or targets_mm = [...]
//! end_mm = 750.0
//! count = 16
//! jitter_mm = 9.0               # random part of the spacing (interior targets)
//! runs = 5
//! feed_mm_per_min = 2000.0
//! dwell_s = 3.0
//! overrun_mm = 5.0
//! start = "2026-11-20 09:14:00"
//!
//! [cycle.after]                 # the re-test, where it differs (e.g. finer targets)
//! count = 151
//! jitter_mm = 1.0
//!
//! [error]                       # the axis error the model knows
//! scale_um_per_m = 9.5
//! periodic = [{ period_mm = 200.0, amplitude_um = 1.8, phase_rad = 0.4 }]
//!
//! [noise]
//! sigma_um = 0.35               # scatter of one reading
//!
//! [environment]
//! air_temperature_c = 20.4
//! material_temperature_c = 20.2
//! expansion_coefficient_ppm_per_k = 11.7
//!
//! [[effect]]                    # effects the model does not declare
//! kind = "reversal"             # reversal, scale, drift, periodic, outlier-run, abbe,
//! B_um = -3.2                   # and, to test "unexplained": quadratic, step
//! tests = ["before", "after"]   # default: both
//! ```
//!
//! Effect parameters carry the names `axcomp diagnose` reports (`B_um`,
//! `scale_um_per_m`, `rate_um_per_h`, `period_mm`/`amplitude_um`,
//! `run`/`direction`/`offset_um`, `offset_mm`/`angle_urad`), so a test can
//! compare them directly.

use serde::Deserialize;

use super::SynthError;
use crate::effects::{Abbe, Drift, Effect, OutlierRun, Periodic, Reversal, Scale};
use crate::error::ParseError;
use crate::measurement::Direction;
use crate::units::{per_m_over_mm, urad_times_mm_to_um};

/// The whole truth file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Truth {
    /// Axis and machine names for the files.
    #[serde(default)]
    pub axis: AxisInfo,
    /// The test cycle.
    pub cycle: CycleSpec,
    /// The axis error the model knows.
    #[serde(default)]
    pub error: ErrorSpec,
    /// Scatter.
    pub noise: NoiseSpec,
    /// Conditions.
    #[serde(default)]
    pub environment: EnvironmentSpec,
    /// Effects the model does not declare.
    #[serde(default, rename = "effect")]
    pub effects: Vec<EffectSpec>,
}

/// Names written into the files.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisInfo {
    /// Axis name.
    #[serde(default = "default_axis")]
    pub name: String,
    /// Machine.
    pub machine: Option<String>,
    /// Serial number.
    pub serial: Option<String>,
    /// Operator.
    pub operator: Option<String>,
    /// Location.
    pub location: Option<String>,
}

impl Default for AxisInfo {
    fn default() -> AxisInfo {
        AxisInfo {
            name: default_axis(),
            machine: None,
            serial: None,
            operator: None,
            location: None,
        }
    }
}

fn default_axis() -> String {
    "X".to_string()
}

/// Targets of a test: a list, or `count` targets from `start_mm` to `end_mm`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetSpec {
    /// Explicit targets, mm.
    pub targets_mm: Option<Vec<f64>>,
    /// First target, mm.
    pub start_mm: Option<f64>,
    /// Last target, mm.
    pub end_mm: Option<f64>,
    /// Number of targets.
    pub count: Option<usize>,
    /// Interior targets move by up to ± this, mm (uniform, seeded).
    pub jitter_mm: Option<f64>,
    /// Runs per direction.
    pub runs: Option<usize>,
}

/// The test cycle.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CycleSpec {
    /// Targets and runs of the first test.
    #[serde(flatten)]
    pub targets: TargetSpec,
    /// Feed, mm/min.
    #[serde(default = "default_feed")]
    pub feed_mm_per_min: f64,
    /// Dwell, s.
    #[serde(default = "default_dwell")]
    pub dwell_s: f64,
    /// Overrun, mm.
    #[serde(default = "default_overrun")]
    pub overrun_mm: f64,
    /// Start of the first test (`yyyy-mm-dd HH:MM:SS`).
    pub start: Option<String>,
    /// Hours between the start of the first test and the re-test.
    #[serde(default = "default_gap")]
    pub after_gap_h: f64,
    /// How the re-test differs.
    #[serde(default)]
    pub after: TargetSpec,
}

fn default_feed() -> f64 {
    crate::cycle::CycleTiming::ASSUMED.feed_mm_per_min
}
fn default_dwell() -> f64 {
    crate::cycle::CycleTiming::ASSUMED.dwell_s
}
fn default_overrun() -> f64 {
    crate::cycle::CycleTiming::ASSUMED.overrun_mm
}
fn default_gap() -> f64 {
    2.0
}

/// The axis error along the stroke that the model declares, µm.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorSpec {
    /// Linear part, µm/m.
    #[serde(default)]
    pub scale_um_per_m: f64,
    /// Sine components.
    #[serde(default)]
    pub periodic: Vec<PeriodicSpec>,
    /// A table, linearly interpolated (end values held).
    pub points: Option<PointsSpec>,
}

/// A sine component `amplitude · sin(2π·x/period + phase)`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodicSpec {
    /// Period, mm.
    pub period_mm: f64,
    /// Amplitude, µm.
    pub amplitude_um: f64,
    /// Phase, rad.
    #[serde(default)]
    pub phase_rad: f64,
}

/// A tabulated error.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointsSpec {
    /// Positions, mm, increasing.
    pub positions_mm: Vec<f64>,
    /// Values, µm.
    pub values_um: Vec<f64>,
}

/// Scatter of the readings.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// Standard deviation of one reading, µm (repeatability R ≈ 4σ).
    pub sigma_um: f64,
}

/// Test conditions (before any thermal effect).
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Air, °C.
    #[serde(default = "twenty")]
    pub air_temperature_c: f64,
    /// Material, °C.
    #[serde(default = "twenty")]
    pub material_temperature_c: f64,
    /// Expansion coefficient the laser software used, ppm/K.
    #[serde(default = "default_alpha")]
    pub expansion_coefficient_ppm_per_k: f64,
    /// Air pressure, kPa.
    #[serde(default = "default_pressure")]
    pub pressure_kpa: f64,
    /// Humidity, %.
    #[serde(default = "default_humidity")]
    pub humidity_pct: f64,
}

impl Default for EnvironmentSpec {
    fn default() -> EnvironmentSpec {
        EnvironmentSpec {
            air_temperature_c: twenty(),
            material_temperature_c: twenty(),
            expansion_coefficient_ppm_per_k: default_alpha(),
            pressure_kpa: default_pressure(),
            humidity_pct: default_humidity(),
        }
    }
}

fn twenty() -> f64 {
    20.0
}
fn default_alpha() -> f64 {
    11.5
}
fn default_pressure() -> f64 {
    101.325
}
fn default_humidity() -> f64 {
    45.0
}

/// Which tests an effect acts in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TestKind {
    /// The first test.
    Before,
    /// The re-test after compensation.
    After,
}

fn both() -> Vec<TestKind> {
    vec![TestKind::Before, TestKind::After]
}

/// An effect the model does not declare.
#[allow(non_snake_case)]
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum EffectSpec {
    /// Direction-dependent offset: ↑ gets +B/2, ↓ −B/2.
    Reversal {
        /// ↑ minus ↓, µm.
        B_um: f64,
        /// Tests it acts in.
        #[serde(default = "both")]
        tests: Vec<TestKind>,
    },
    /// Deviation linear in position (thermal expansion, misalignment).
    Scale {
        /// µm/m.
        scale_um_per_m: f64,
        /// Tests it acts in.
        #[serde(default = "both")]
        tests: Vec<TestKind>,
    },
    /// Deviation growing with time during the test.
    Drift {
        /// µm/h.
        rate_um_per_h: f64,
        /// Tests it acts in.
        #[serde(default = "both")]
        tests: Vec<TestKind>,
    },
    /// Periodic error in position.
    Periodic {
        /// mm.
        period_mm: f64,
        /// µm.
        amplitude_um: f64,
        /// rad.
        #[serde(default)]
        phase_rad: f64,
        /// Tests it acts in.
        #[serde(default = "both")]
        tests: Vec<TestKind>,
    },
    /// One run offset from the others.
    OutlierRun {
        /// Run number within its direction.
        run: u32,
        /// `up` or `down`.
        direction: String,
        /// µm.
        offset_um: f64,
        /// Tests it acts in.
        #[serde(default = "both")]
        tests: Vec<TestKind>,
    },
    /// Abbe error: the measuring line offset × the axis' angular error,
    /// whose profile is a bow `angle · sin(π·(x − first)/(last − first))`.
    Abbe {
        /// Offset of the measuring line from the line the model describes, mm.
        offset_mm: f64,
        /// Largest angular error (pitch or yaw) along the stroke, µrad.
        angle_urad: f64,
        /// Tests it acts in.
        #[serde(default = "both")]
        tests: Vec<TestKind>,
    },
    /// A sag no kind in diagnose's list describes: `sag · 4(x−a)(b−x)/(b−a)²`.
    Quadratic {
        /// At mid stroke, µm.
        sag_um: f64,
        /// Tests it acts in.
        #[serde(default = "both")]
        tests: Vec<TestKind>,
    },
    /// A step in the scale at one position.
    Step {
        /// Where, mm.
        position_mm: f64,
        /// Height, µm.
        step_um: f64,
        /// Tests it acts in.
        #[serde(default = "both")]
        tests: Vec<TestKind>,
    },
}

impl EffectSpec {
    /// The effect `diagnose` should find for this truth, with the truth's
    /// parameters (`None` for what no kind describes: a sag, a step).
    pub fn as_effect(&self) -> Option<Effect> {
        Some(match *self {
            EffectSpec::Reversal { B_um, .. } => Effect::Reversal(Reversal { b: B_um }),
            EffectSpec::Scale { scale_um_per_m, .. } => Effect::Scale(Scale { scale_um_per_m }),
            EffectSpec::Drift { rate_um_per_h, .. } => {
                Effect::Drift(Drift::PerHour { rate_um_per_h })
            }
            EffectSpec::Periodic {
                period_mm,
                amplitude_um,
                phase_rad,
                ..
            } => Effect::Periodic(Periodic {
                period: period_mm,
                amplitude: amplitude_um,
                phase_rad,
            }),
            EffectSpec::OutlierRun {
                run,
                ref direction,
                offset_um,
                ..
            } => Effect::OutlierRun(OutlierRun {
                run,
                direction: if direction == "up" {
                    Direction::Up
                } else {
                    Direction::Down
                },
                offset: offset_um,
            }),
            EffectSpec::Abbe {
                offset_mm,
                angle_urad,
                ..
            } => Effect::Abbe(Abbe {
                offset_mm,
                angle_urad,
            }),
            EffectSpec::Quadratic { .. } | EffectSpec::Step { .. } => return None,
        })
    }

    /// What the effect adds to a reading, µm: taken `time_s` into the test
    /// in run `run_number` moving `direction`, with the axis at `at_mm` of
    /// `stroke` (first, last target). Position-dependent effects act where
    /// the axis is, run- and time-dependent ones on the reading. This is the
    /// truth's own arithmetic, independent of `crate::effects`.
    pub fn value_um(
        &self,
        direction: Direction,
        run_number: u32,
        time_s: f64,
        at_mm: f64,
        stroke: (f64, f64),
    ) -> f64 {
        let (first, last) = stroke;
        match self {
            EffectSpec::Reversal { B_um, .. } => match direction {
                Direction::Up => B_um / 2.0,
                Direction::Down => -B_um / 2.0,
            },
            EffectSpec::Scale { scale_um_per_m, .. } => {
                per_m_over_mm(*scale_um_per_m, at_mm - first)
            }
            EffectSpec::Drift { rate_um_per_h, .. } => rate_um_per_h * time_s / 3600.0,
            EffectSpec::Periodic {
                period_mm,
                amplitude_um,
                phase_rad,
                ..
            } => amplitude_um * (std::f64::consts::TAU * at_mm / period_mm + phase_rad).sin(),
            EffectSpec::OutlierRun {
                run,
                direction: of_run,
                offset_um,
                ..
            } => {
                let matches = *run == run_number && of_run == direction.as_str();
                if matches { *offset_um } else { 0.0 }
            }
            EffectSpec::Abbe {
                offset_mm,
                angle_urad,
                ..
            } => {
                urad_times_mm_to_um(offset_mm * super::abbe_angle_urad(*angle_urad, at_mm, stroke))
            }
            EffectSpec::Quadratic { sag_um, .. } => {
                sag_um * 4.0 * (at_mm - first) * (last - at_mm) / ((last - first) * (last - first))
            }
            EffectSpec::Step {
                position_mm,
                step_um,
                ..
            } => {
                if at_mm >= *position_mm {
                    *step_um
                } else {
                    0.0
                }
            }
        }
    }

    /// Whether the effect acts in a test.
    pub fn acts_in(&self, test: TestKind) -> bool {
        let tests = match self {
            EffectSpec::Reversal { tests, .. }
            | EffectSpec::Scale { tests, .. }
            | EffectSpec::Drift { tests, .. }
            | EffectSpec::Periodic { tests, .. }
            | EffectSpec::OutlierRun { tests, .. }
            | EffectSpec::Abbe { tests, .. }
            | EffectSpec::Quadratic { tests, .. }
            | EffectSpec::Step { tests, .. } => tests,
        };
        tests.contains(&test)
    }
}

impl Truth {
    /// Parses a truth file.
    pub fn from_toml_str(text: &str) -> Result<Truth, SynthError> {
        let truth: Truth = toml::from_str(text).map_err(|e| ParseError::from_toml(text, &e))?;
        truth.check().map_err(SynthError::Truth)?;
        Ok(truth)
    }

    fn check(&self) -> Result<(), String> {
        if !(self.noise.sigma_um >= 0.0 && self.noise.sigma_um.is_finite()) {
            return Err(format!(
                "noise.sigma_um must be ≥ 0, found {}",
                self.noise.sigma_um
            ));
        }
        if self.cycle.feed_mm_per_min <= 0.0
            || self.cycle.dwell_s < 0.0
            || self.cycle.overrun_mm < 0.0
        {
            return Err("cycle: feed must be positive, dwell and overrun not negative".to_string());
        }
        for effect in &self.effects {
            match effect {
                EffectSpec::Periodic { period_mm, .. } if *period_mm <= 0.0 => {
                    return Err(format!(
                        "periodic effect: period_mm must be positive, found {period_mm}"
                    ));
                }
                EffectSpec::OutlierRun { direction, run, .. } => {
                    if direction != "up" && direction != "down" {
                        return Err(format!(
                            "outlier-run effect: direction must be \"up\" or \"down\", found {direction:?}"
                        ));
                    }
                    if *run == 0 {
                        return Err("outlier-run effect: runs are numbered from 1".to_string());
                    }
                }
                _ => {}
            }
        }
        if let Some(points) = &self.error.points
            && (points.positions_mm.len() != points.values_um.len()
                || points.positions_mm.len() < 2
                || points.positions_mm.windows(2).any(|p| p[1] <= p[0]))
        {
            return Err(
                "error.points: positions must increase and match the values, at least two"
                    .to_string(),
            );
        }
        Ok(())
    }
}
