//! The effects `diagnose` knows: each a parametric model of a residual with
//! physical parameters, linear once its shape (a period, a run) is fixed.
//!
//! | kind          | column(s) over the readings                  | parameter                |
//! |---------------|----------------------------------------------|--------------------------|
//! | `reversal`    | +½ moving ↑, −½ moving ↓                      | B (↑ − ↓), µm            |
//! | `scale`       | (x − first target) in m                      | µm/m                     |
//! | `drift`       | time of the reading in h                     | µm/h                     |
//! | `periodic`    | sin(2πx/p), cos(2πx/p) for a scanned period p | amplitude µm, phase      |
//! | `outlier-run` | 1 on the readings of one run, else 0         | offset µm                |
//! | `abbe`        | the angular error ε(x) in µrad / 1000        | offset of the line, mm   |
//!
//! Each kind also says in one sentence what it is physically and what to do
//! about it at the machine ([`Effect::explanation`]).

use std::f64::consts::TAU;

use crate::measurement::Direction;

/// The kinds, in the order they are tried and listed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Direction-dependent offset.
    Reversal,
    /// Deviation linear in position.
    Scale,
    /// Deviation growing with time.
    Drift,
    /// Periodic error in position.
    Periodic,
    /// One run offset from the others.
    OutlierRun,
    /// Measuring-line offset × angular error.
    Abbe,
}

impl Kind {
    /// All kinds.
    pub const ALL: [Kind; 6] = [
        Kind::Reversal,
        Kind::Scale,
        Kind::Drift,
        Kind::Periodic,
        Kind::OutlierRun,
        Kind::Abbe,
    ];

    /// The name used in JSON and TOML.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Reversal => "reversal",
            Kind::Scale => "scale",
            Kind::Drift => "drift",
            Kind::Periodic => "periodic",
            Kind::OutlierRun => "outlier-run",
            Kind::Abbe => "abbe",
        }
    }

    /// Whether the effect depends on position only (and so competes with the
    /// position-dependent systematic error in a lack-of-fit test).
    pub fn is_positional(self) -> bool {
        matches!(self, Kind::Scale | Kind::Periodic | Kind::Abbe)
    }
}

/// One reading, as the effects see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// Index of its target.
    pub target_index: usize,
    /// Target, mm.
    pub target_mm: f64,
    /// ↑ or ↓.
    pub direction: Direction,
    /// Run number within its direction.
    pub run: u32,
    /// Index of its run in the order measured.
    pub run_index: usize,
    /// Time from the start of the test, h.
    pub time_h: f64,
}

/// The nonlinear part of an effect's shape, fixed before the linear fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// No free shape.
    Fixed(Kind),
    /// A periodic error of this period, mm.
    Period(f64),
    /// One run: (direction, number).
    Run(Direction, u32),
}

impl Shape {
    /// The kind of effect.
    pub fn kind(self) -> Kind {
        match self {
            Shape::Fixed(kind) => kind,
            Shape::Period(_) => Kind::Periodic,
            Shape::Run(..) => Kind::OutlierRun,
        }
    }
}

/// The columns of an effect of a given shape over the readings.
/// `angle_urad` is the angular profile at each target (for Abbe).
pub fn columns(
    shape: Shape,
    readings: &[Reading],
    first_target_mm: f64,
    angle_urad: Option<&[f64]>,
) -> Vec<Vec<f64>> {
    match shape {
        Shape::Fixed(Kind::Reversal) => vec![
            readings
                .iter()
                .map(|r| {
                    if r.direction == Direction::Up {
                        0.5
                    } else {
                        -0.5
                    }
                })
                .collect(),
        ],
        Shape::Fixed(Kind::Scale) => vec![
            readings
                .iter()
                .map(|r| (r.target_mm - first_target_mm) / 1000.0)
                .collect(),
        ],
        Shape::Fixed(Kind::Drift) => vec![readings.iter().map(|r| r.time_h).collect()],
        Shape::Fixed(Kind::Abbe) => {
            let angles = angle_urad.unwrap_or(&[]);
            vec![
                readings
                    .iter()
                    .map(|r| angles.get(r.target_index).copied().unwrap_or(0.0) / 1000.0)
                    .collect(),
            ]
        }
        Shape::Period(period) => vec![
            readings
                .iter()
                .map(|r| (TAU * r.target_mm / period).sin())
                .collect(),
            readings
                .iter()
                .map(|r| (TAU * r.target_mm / period).cos())
                .collect(),
        ],
        Shape::Run(direction, run) => vec![
            readings
                .iter()
                .map(|r| {
                    if r.direction == direction && r.run == run {
                        1.0
                    } else {
                        0.0
                    }
                })
                .collect(),
        ],
        Shape::Fixed(Kind::Periodic | Kind::OutlierRun) => Vec::new(),
    }
}

/// An effect with its fitted parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Effect {
    /// Reversal B = ↑ − ↓, µm.
    Reversal {
        /// µm.
        b_um: f64,
    },
    /// Scale, µm/m.
    Scale {
        /// µm/m.
        scale_um_per_m: f64,
    },
    /// Drift, µm/h.
    Drift {
        /// µm/h.
        rate_um_per_h: f64,
    },
    /// Periodic error `amplitude · sin(2πx/period + phase)`.
    Periodic {
        /// mm.
        period_mm: f64,
        /// µm.
        amplitude_um: f64,
        /// rad.
        phase_rad: f64,
    },
    /// One run offset.
    OutlierRun {
        /// Run number within its direction.
        run: u32,
        /// ↑ or ↓.
        direction: Direction,
        /// µm.
        offset_um: f64,
    },
    /// Abbe: measuring-line offset × angular error.
    Abbe {
        /// mm.
        offset_mm: f64,
        /// Largest |angular error| along the stroke, µrad.
        angle_urad: f64,
    },
}

/// Context for the sentence a user reads.
#[derive(Clone, Copy, Debug, Default)]
pub struct Context {
    /// The table's step, mm, if a regular table was applied.
    pub table_step_mm: Option<f64>,
    /// Spacing of the targets, when regular, mm.
    pub target_spacing_mm: Option<f64>,
    /// Expansion coefficient the laser used, ppm/K.
    pub expansion_coefficient_ppm_per_k: Option<f64>,
    /// Material temperature change between the tests, K, if both recorded.
    pub material_change_k: Option<f64>,
    /// Whether the times of the readings are assumed (no recorded duration).
    pub time_assumed: bool,
    /// The first test's mean reversal B̄, µm, which the prediction carries (a
    /// reversal found is then the change since that test).
    pub first_test_reversal_um: Option<f64>,
}

/// A reversal's share of a reading in `direction`, µm
/// ([`Direction::reversal_share`]).
pub(crate) fn reversal_share_um(b_um: f64, direction: Direction) -> f64 {
    direction.reversal_share(b_um)
}

impl Effect {
    /// The kind.
    pub fn kind(&self) -> Kind {
        match self {
            Effect::Reversal { .. } => Kind::Reversal,
            Effect::Scale { .. } => Kind::Scale,
            Effect::Drift { .. } => Kind::Drift,
            Effect::Periodic { .. } => Kind::Periodic,
            Effect::OutlierRun { .. } => Kind::OutlierRun,
            Effect::Abbe { .. } => Kind::Abbe,
        }
    }

    /// Builds the effect from a shape and its fitted coefficients.
    pub fn from_fit(shape: Shape, coefficients: &[f64], angle_urad: Option<&[f64]>) -> Effect {
        match shape {
            Shape::Fixed(Kind::Reversal) => Effect::Reversal {
                b_um: coefficients[0],
            },
            Shape::Fixed(Kind::Scale) => Effect::Scale {
                scale_um_per_m: coefficients[0],
            },
            Shape::Fixed(Kind::Drift) => Effect::Drift {
                rate_um_per_h: coefficients[0],
            },
            Shape::Fixed(Kind::Abbe) => Effect::Abbe {
                offset_mm: coefficients[0],
                angle_urad: angle_urad
                    .unwrap_or(&[])
                    .iter()
                    .fold(0.0, |m: f64, a| m.max(a.abs())),
            },
            Shape::Period(period_mm) => {
                // a·sin θ + b·cos θ = A·sin(θ + φ) with A cos φ = a, A sin φ = b.
                let (a, b) = (coefficients[0], coefficients[1]);
                Effect::Periodic {
                    period_mm,
                    amplitude_um: a.hypot(b),
                    phase_rad: b.atan2(a),
                }
            }
            Shape::Run(direction, run) => Effect::OutlierRun {
                run,
                direction,
                offset_um: coefficients[0],
            },
            Shape::Fixed(Kind::Periodic | Kind::OutlierRun) => {
                unreachable!("periodic and outlier-run effects always have a shape")
            }
        }
    }

    /// The effect's contribution to one reading, µm.
    pub fn value_um(
        &self,
        reading: &Reading,
        first_target_mm: f64,
        angle_urad: Option<&[f64]>,
    ) -> f64 {
        match *self {
            Effect::Reversal { b_um } => reversal_share_um(b_um, reading.direction),
            Effect::Scale { scale_um_per_m } => {
                scale_um_per_m * (reading.target_mm - first_target_mm) / 1000.0
            }
            Effect::Drift { rate_um_per_h } => rate_um_per_h * reading.time_h,
            Effect::Periodic {
                period_mm,
                amplitude_um,
                phase_rad,
            } => amplitude_um * (TAU * reading.target_mm / period_mm + phase_rad).sin(),
            Effect::OutlierRun {
                run,
                direction,
                offset_um,
            } => {
                if reading.run == run && reading.direction == direction {
                    offset_um
                } else {
                    0.0
                }
            }
            Effect::Abbe { offset_mm, .. } => {
                offset_mm
                    * angle_urad
                        .and_then(|a| a.get(reading.target_index))
                        .copied()
                        .unwrap_or(0.0)
                    / 1000.0
            }
        }
    }

    /// The effect's systematic part at `x_mm` moving in `direction`, µm:
    /// what a table or a prediction can account for (`predict --effects`).
    /// `None` for what is not systematic in position (a drift, an outlier
    /// run) and for Abbe, which the volumetric model gives from the line and
    /// the angular errors rather than from an effect.
    pub fn systematic_um(
        &self,
        x_mm: f64,
        direction: Direction,
        first_target_mm: f64,
    ) -> Option<f64> {
        match *self {
            Effect::Reversal { b_um } => Some(reversal_share_um(b_um, direction)),
            Effect::Scale { scale_um_per_m } => {
                Some(scale_um_per_m * (x_mm - first_target_mm) / 1000.0)
            }
            Effect::Periodic {
                period_mm,
                amplitude_um,
                phase_rad,
            } => Some(amplitude_um * (TAU * x_mm / period_mm + phase_rad).sin()),
            Effect::Drift { .. } | Effect::OutlierRun { .. } | Effect::Abbe { .. } => None,
        }
    }

    /// What it is physically and what to do about it at the machine, in one sentence.
    pub fn explanation(&self, context: &Context) -> String {
        match *self {
            Effect::Reversal { b_um } => {
                let how = if b_um < 0.0 {
                    "the axis falls short in the direction it moves: lost motion from backlash, or friction force × drive compliance"
                } else {
                    "the axis overshoots in the direction it moves (a leading encoder, or an elastic preload released at reversal)"
                };
                // Controllers take the backlash parameter in mm (or inch), not µm:
                // `convert` prints each one's own line (`Controller::backlash_parameter`).
                match context.first_test_reversal_um {
                    Some(before_um) => format!(
                        "The reversal changed since the first test by B = {b_um:.2} µm (B̄ {before_um:.2} µm then, about {:.2} µm now; {how}); a bidirectional table from the re-test (convert --existing --effects) takes the new value out, or change the backlash parameter by {:.4} mm (convert prints it in the controller's own terms).",
                        before_um + b_um,
                        crate::units::um_to_mm(-b_um)
                    ),
                    None => format!(
                        "Direction-dependent offset of B = {b_um:.2} µm ({how}); write a bidirectional table (convert --effects or --mode bidirectional) or change the backlash parameter by {:.4} mm (convert prints it in the controller's own terms).",
                        crate::units::um_to_mm(-b_um)
                    ),
                }
            }
            Effect::Scale { scale_um_per_m } => {
                let thermal = context.expansion_coefficient_ppm_per_k.filter(|a| *a > 0.0).map(|alpha| {
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
            Effect::Drift { rate_um_per_h } => {
                let assumed = if context.time_assumed {
                    " (times assumed from a typical cycle: the file records no test duration)"
                } else {
                    ""
                };
                format!(
                    "Deviation growing by {rate_um_per_h:.2} µm/h during the test{assumed}: the machine was warming up; run the axis until it is warm before measuring and re-measure."
                )
            }
            Effect::Periodic {
                period_mm,
                amplitude_um,
                ..
            } => {
                let table = context
                    .table_step_mm
                    .map(|s| format!("; the table's step of {s} mm cannot follow it"))
                    .unwrap_or_default();
                // Linear interpolation between points h apart leaves up to
                // A·(1 − cos(πh/p)) of a sine: under 5 % of A for h ≤ p/10.
                format!(
                    "Periodic error of {amplitude_um:.2} µm amplitude and {period_mm:.2} mm period (screw lead or scale period){table}; compensate with a step of at most {:.2} mm (convert --effects) or the control's pitch compensation, or check the screw.",
                    period_mm / 10.0
                )
            }
            Effect::OutlierRun {
                run,
                direction,
                offset_um,
            } => format!(
                "Run {run}{direction} sits {offset_um:+.2} µm off the others (typically the first run after start-up, before the axis is warm); leave it out with --exclude-run {run}:{} if that is why, or warm the axis up before the test.",
                direction.as_str()
            ),
            Effect::Abbe {
                offset_mm,
                angle_urad,
            } => format!(
                "Positioning error that depends on the offset of the measuring line: {offset_mm:.1} mm from the line of the first test, times an angular error of up to {angle_urad:.1} µrad (Abbe error); measure on the functional line of the tool or let the model's pitch and yaw compensate it."
            ),
        }
    }

    /// The parameters as (JSON/TOML key, value) pairs.
    pub fn parameters(&self) -> Vec<(&'static str, f64)> {
        match *self {
            Effect::Reversal { b_um } => vec![("B_um", b_um)],
            Effect::Scale { scale_um_per_m } => vec![("scale_um_per_m", scale_um_per_m)],
            Effect::Drift { rate_um_per_h } => vec![("rate_um_per_h", rate_um_per_h)],
            Effect::Periodic {
                period_mm,
                amplitude_um,
                phase_rad,
            } => {
                vec![
                    ("period_mm", period_mm),
                    ("amplitude_um", amplitude_um),
                    ("phase_rad", phase_rad),
                ]
            }
            Effect::OutlierRun { run, offset_um, .. } => {
                vec![("run", f64::from(run)), ("offset_um", offset_um)]
            }
            Effect::Abbe {
                offset_mm,
                angle_urad,
            } => vec![("offset_mm", offset_mm), ("angle_urad", angle_urad)],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reading(target_mm: f64, direction: Direction, run: u32, time_h: f64) -> Reading {
        Reading {
            target_index: 0,
            target_mm,
            direction,
            run,
            run_index: 0,
            time_h,
        }
    }

    #[test]
    fn columns_and_values_agree() {
        let readings = [
            reading(100.0, Direction::Up, 1, 0.5),
            reading(300.0, Direction::Down, 2, 1.0),
        ];
        let cases = [
            (Shape::Fixed(Kind::Reversal), vec![4.0]),
            (Shape::Fixed(Kind::Scale), vec![10.0]),
            (Shape::Fixed(Kind::Drift), vec![2.0]),
            (Shape::Period(160.0), vec![1.0, -0.5]),
            (Shape::Run(Direction::Down, 2), vec![3.0]),
        ];
        for (shape, coefficients) in cases {
            let columns = columns(shape, &readings, 0.0, None);
            let effect = Effect::from_fit(shape, &coefficients, None);
            for (i, r) in readings.iter().enumerate() {
                let from_columns: f64 = columns
                    .iter()
                    .zip(&coefficients)
                    .map(|(c, b)| c[i] * b)
                    .sum();
                assert!(
                    (effect.value_um(r, 0.0, None) - from_columns).abs() < 1e-12,
                    "{shape:?}"
                );
            }
        }
    }

    #[test]
    fn values_by_hand() {
        let up = reading(250.0, Direction::Up, 1, 0.25);
        assert_eq!(
            Effect::Reversal { b_um: -3.0 }.value_um(&up, 0.0, None),
            -1.5
        );
        assert_eq!(
            Effect::Scale {
                scale_um_per_m: 8.0
            }
            .value_um(&up, 50.0, None),
            1.6
        );
        assert_eq!(
            Effect::Drift { rate_um_per_h: 4.0 }.value_um(&up, 0.0, None),
            1.0
        );
        let periodic = Effect::Periodic {
            period_mm: 1000.0,
            amplitude_um: 2.0,
            phase_rad: 0.0,
        };
        assert!(
            (periodic.value_um(&up, 0.0, None) - 2.0).abs() < 1e-12,
            "quarter period: the crest"
        );
    }

    #[test]
    fn every_explanation_is_one_sentence_with_an_action() {
        let context = Context {
            expansion_coefficient_ppm_per_k: Some(11.5),
            table_step_mm: Some(50.0),
            ..Context::default()
        };
        for effect in [
            Effect::Reversal { b_um: -3.0 },
            Effect::Scale {
                scale_um_per_m: 11.5,
            },
            Effect::Drift { rate_um_per_h: 2.0 },
            Effect::Periodic {
                period_mm: 5.0,
                amplitude_um: 1.0,
                phase_rad: 0.0,
            },
            Effect::OutlierRun {
                run: 1,
                direction: Direction::Down,
                offset_um: 4.0,
            },
            Effect::Abbe {
                offset_mm: 50.0,
                angle_urad: 20.0,
            },
        ] {
            let text = effect.explanation(&context);
            assert_eq!(text.matches(". ").count(), 0, "one sentence: {text}");
            assert!(text.ends_with('.'), "{text}");
            assert!(text.contains(';'), "what it is; what to do: {text}");
        }
        let scale = Effect::Scale {
            scale_um_per_m: 11.5,
        }
        .explanation(&context);
        assert!(scale.contains("+1.00 K"), "{scale}");
    }
}
