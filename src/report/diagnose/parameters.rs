//! An accepted effect's parameters and their uncertainties on the wire and
//! in the terminal: a linear axis' under the keys the effect's parameter
//! definitions give, a rotary axis' in one angle unit, one struct per unit,
//! converted from the effect's typed parameters (`Effect::typed`).

use serde::Serialize;
use serde_json::{Map, Value};

use super::ReportedDeviation;
use crate::diagnose::AcceptedEffect;
use crate::effects::{Effect, EffectIn, ParameterValue};
use crate::units::{Arcsec, Deg, Mm, Um, Urad};

/// One parameter of an effect as the terminal shows it.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    /// A measured quantity, in the unit its key names.
    Number(f64),
    /// Anything else as JSON writes it (a run's number, `"up"`).
    Text(String),
}

/// An effect's parameters or their uncertainties as the terminal shows them.
pub trait Cells {
    /// (key, value), in the order written.
    fn cells(&self) -> Vec<(String, Cell)>;
}

/// An effect's parameters on the wire, under keys with their units: on an
/// axis whose positions are in `P` and deviations in `D`.
pub trait EffectParameters<P, D>: Cells + Serialize + Sized {
    /// The standard uncertainties of the same parameters, under the same keys.
    type Uncertainty: Cells + Serialize;

    /// An accepted effect's parameters and their uncertainties, given its
    /// typed parameters (`DiagnosisIn::effects`).
    fn of(accepted: &AcceptedEffect, typed: Option<EffectIn<P, D>>) -> (Self, Self::Uncertainty);
}

/// A linear axis' parameters: under the keys the effect's parameter
/// definitions give (`effects::Parameter::key`: `period_mm`, `B_um`, `run`;
/// its uncertainties by the same keys), in the order a JSON object keeps
/// them (by key). Every kind is looked for on a linear axis, and its keys
/// name the linear units the numbers are held in, so the typed parameters
/// are not needed.
impl EffectParameters<Mm, Um> for Map<String, Value> {
    type Uncertainty = Map<String, Value>;

    fn of(accepted: &AcceptedEffect, _: Option<EffectIn<Mm, Um>>) -> (Self, Self) {
        let mut params = Map::new();
        for parameter in accepted.effect.parameters() {
            let value = match parameter.value {
                ParameterValue::Run(run) => Value::from(run),
                ParameterValue::Number(value) => Value::from(value),
            };
            params.insert(parameter.key.to_string(), value);
        }
        if let Effect::OutlierRun(run) = &accepted.effect {
            params.insert("direction".into(), Value::from(run.direction.as_str()));
        }
        let uncertainty = accepted
            .uncertainty
            .iter()
            .map(|(key, sigma)| (key.to_string(), Value::from(*sigma)))
            .collect();
        (params, uncertainty)
    }
}

impl Cells for Map<String, Value> {
    fn cells(&self) -> Vec<(String, Cell)> {
        self.iter()
            .map(|(key, value)| {
                let cell = match value.as_f64() {
                    Some(number) if value.is_f64() => Cell::Number(number),
                    _ => Cell::Text(value.to_string()),
                };
                (key.clone(), cell)
            })
            .collect()
    }
}

/// Declares a rotary axis' effect parameters and their uncertainties in one
/// angle unit: each field's name is its JSON key, its type the unit the key
/// names. Fields are declared in the order of their keys, the order a linear
/// axis' parameters are written in. A rotary axis is diagnosed for its
/// per-revolution harmonics, its reversal and its outlier runs only
/// (`diagnose::gates`).
macro_rules! rotary_parameters {
    (
        $(#[$doc:meta])*
        $params:ident, $uncertainty:ident <$deviation:ty> { $amplitude:ident, $b:ident, $offset:ident $(,)? }
    ) => {
        $(#[$doc])*
        #[allow(non_snake_case)]
        #[derive(Clone, Copy, Debug, PartialEq, Serialize)]
        #[serde(untagged)]
        pub enum $params {
            /// A harmonic: its amplitude, whole order per revolution (when
            /// the period is one), period and phase.
            Periodic {
                /// Amplitude.
                $amplitude: $deviation,
                /// The whole order per revolution (2: twice, period 180°).
                #[serde(skip_serializing_if = "Option::is_none")]
                per_revolution: Option<u32>,
                /// Period, °.
                period_deg: Deg,
                /// Phase, rad.
                phase_rad: f64,
            },
            /// A direction-dependent offset B (↑ − ↓).
            Reversal {
                /// B.
                $b: $deviation,
            },
            /// A run off the others.
            OutlierRun {
                /// `up` or `down`.
                direction: &'static str,
                /// How far off.
                $offset: $deviation,
                /// Its number within its direction.
                run: u32,
            },
        }

        /// The standard uncertainties of the parameters of the same name.
        #[allow(non_snake_case)]
        #[derive(Clone, Copy, Debug, PartialEq, Serialize)]
        #[serde(untagged)]
        pub enum $uncertainty {
            /// A harmonic's amplitude, and its period where it is not a whole order.
            Periodic {
                /// Amplitude.
                $amplitude: $deviation,
                /// Period, °.
                #[serde(skip_serializing_if = "Option::is_none")]
                period_deg: Option<Deg>,
            },
            /// B.
            Reversal {
                /// B.
                $b: $deviation,
            },
            /// The offset.
            OutlierRun {
                /// The offset.
                $offset: $deviation,
            },
        }

        impl EffectParameters<Deg, $deviation> for $params {
            type Uncertainty = $uncertainty;

            fn of(
                accepted: &AcceptedEffect,
                typed: Option<EffectIn<Deg, $deviation>>,
            ) -> ($params, $uncertainty) {
                let Some(typed) = typed else {
                    unreachable!(
                        "{} is not looked for on a rotary axis (diagnose::gates)",
                        accepted.effect.kind().name()
                    )
                };
                let per_revolution = typed.per_revolution();
                match typed {
                    EffectIn::Periodic {
                        period,
                        period_uncertainty,
                        amplitude,
                        amplitude_uncertainty,
                        phase_rad,
                    } => (
                        $params::Periodic {
                            $amplitude: amplitude,
                            per_revolution,
                            period_deg: period,
                            phase_rad,
                        },
                        $uncertainty::Periodic {
                            $amplitude: amplitude_uncertainty,
                            period_deg: period_uncertainty,
                        },
                    ),
                    EffectIn::Reversal { b, b_uncertainty } => (
                        $params::Reversal { $b: b },
                        $uncertainty::Reversal { $b: b_uncertainty },
                    ),
                    EffectIn::OutlierRun {
                        run,
                        direction,
                        offset,
                        offset_uncertainty,
                    } => (
                        $params::OutlierRun {
                            direction: direction.as_str(),
                            $offset: offset,
                            run,
                        },
                        $uncertainty::OutlierRun {
                            $offset: offset_uncertainty,
                        },
                    ),
                }
            }
        }

        impl Cells for $params {
            fn cells(&self) -> Vec<(String, Cell)> {
                let angle = |key: &str, value: $deviation| (key.to_string(), Cell::Number(value.number()));
                match *self {
                    $params::Periodic { $amplitude, per_revolution, period_deg, phase_rad } => {
                        let mut cells = vec![angle(stringify!($amplitude), $amplitude)];
                        cells.extend(per_revolution.map(|order| ("per_revolution".to_string(), Cell::Text(order.to_string()))));
                        cells.push(("period_deg".to_string(), Cell::Number(period_deg.0)));
                        cells.push(("phase_rad".to_string(), Cell::Number(phase_rad)));
                        cells
                    }
                    $params::Reversal { $b } => vec![angle(stringify!($b), $b)],
                    $params::OutlierRun { direction, $offset, run } => vec![
                        ("direction".to_string(), Cell::Text(format!("\"{direction}\""))),
                        angle(stringify!($offset), $offset),
                        ("run".to_string(), Cell::Text(run.to_string())),
                    ],
                }
            }
        }

        impl Cells for $uncertainty {
            fn cells(&self) -> Vec<(String, Cell)> {
                let angle = |key: &str, value: $deviation| (key.to_string(), Cell::Number(value.number()));
                match *self {
                    $uncertainty::Periodic { $amplitude, period_deg } => {
                        let mut cells = vec![angle(stringify!($amplitude), $amplitude)];
                        cells.extend(period_deg.map(|period| ("period_deg".to_string(), Cell::Number(period.0))));
                        cells
                    }
                    $uncertainty::Reversal { $b } => vec![angle(stringify!($b), $b)],
                    $uncertainty::OutlierRun { $offset } => vec![angle(stringify!($offset), $offset)],
                }
            }
        }
    };
}

rotary_parameters!(
    /// A rotary axis' effect parameters, deviations in ″.
    ArcsecParameters, ArcsecUncertainty<Arcsec> { amplitude_arcsec, B_arcsec, offset_arcsec }
);

rotary_parameters!(
    /// A rotary axis' effect parameters, deviations in µrad.
    UradParameters, UradUncertainty<Urad> { amplitude_urad, B_urad, offset_urad }
);
