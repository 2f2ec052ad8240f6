//! The effects file: what `diagnose --write-effects` saves and `predict
//! --effects` and `convert --effects` read, so that the next prediction and the
//! next table account for what the diagnosis found.
//!
//! The schema is `axcomp synth`'s `[[effect]]` (a truth file's effects), so a
//! diagnosis can also be replayed as a synthetic truth:
//!
//! ```toml
//! [[effect]]
//! kind = "reversal"
//! B_um = -3.02          # ± 0.05 (standard uncertainty)
//!
//! [[effect]]
//! kind = "periodic"
//! period_mm = 5.0
//! amplitude_um = 1.01
//! phase_rad = 0.69
//! ```
//!
//! Kinds and keys as in [`super::effects`]: `reversal` (`B_um`), `scale`
//! (`scale_um_per_m`), `drift` (`rate_um_per_h`), `periodic` (`period_mm`,
//! `amplitude_um`, `phase_rad`), `outlier-run` (`run`, `direction`,
//! `offset_um`), `abbe` (`offset_mm`, `angle_urad`). A `tests` key (synth's)
//! is accepted and ignored.

use std::fmt::Write;

use serde::Deserialize;

use super::AcceptedEffect;
use super::effects::Effect;
use crate::error::ParseError;
use crate::measurement::Direction;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EffectsFile {
    #[serde(default)]
    effect: Vec<RawEffect>,
}

#[allow(non_snake_case)]
#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
enum RawEffect {
    Reversal {
        B_um: f64,
        #[serde(default, rename = "tests")]
        _tests: Option<Vec<String>>,
    },
    Scale {
        scale_um_per_m: f64,
        #[serde(default, rename = "tests")]
        _tests: Option<Vec<String>>,
    },
    Drift {
        rate_um_per_h: f64,
        #[serde(default, rename = "tests")]
        _tests: Option<Vec<String>>,
    },
    Periodic {
        period_mm: f64,
        amplitude_um: f64,
        #[serde(default)]
        phase_rad: f64,
        #[serde(default, rename = "tests")]
        _tests: Option<Vec<String>>,
    },
    OutlierRun {
        run: u32,
        direction: String,
        offset_um: f64,
        #[serde(default, rename = "tests")]
        _tests: Option<Vec<String>>,
    },
    Abbe {
        offset_mm: f64,
        angle_urad: f64,
        #[serde(default, rename = "tests")]
        _tests: Option<Vec<String>>,
    },
}

/// Reads an effects file.
///
/// # Example
///
/// ```
/// use axcomp::diagnose::{Effect, read_effects};
///
/// let effects = read_effects("[[effect]]\nkind = \"reversal\"\nB_um = -3.0\n")?;
/// assert_eq!(effects, [Effect::Reversal { b_um: -3.0 }]);
/// # Ok::<(), axcomp::error::ParseError>(())
/// ```
pub fn read_effects(text: &str) -> Result<Vec<Effect>, ParseError> {
    let file: EffectsFile =
        toml::from_str(text).map_err(|error| ParseError::from_toml(text, &error))?;
    file.effect
        .into_iter()
        .enumerate()
        .map(|(index, raw)| {
            effect(raw).map_err(|m| ParseError::new(1, 1, format!("effect {}: {m}", index + 1)))
        })
        .collect()
}

fn effect(raw: RawEffect) -> Result<Effect, String> {
    let effect = match raw {
        RawEffect::Reversal { B_um, .. } => Effect::Reversal { b_um: B_um },
        RawEffect::Scale { scale_um_per_m, .. } => Effect::Scale { scale_um_per_m },
        RawEffect::Drift { rate_um_per_h, .. } => Effect::Drift { rate_um_per_h },
        RawEffect::Periodic {
            period_mm,
            amplitude_um,
            phase_rad,
            ..
        } => {
            if !(period_mm > 0.0 && period_mm.is_finite()) {
                return Err(format!("period_mm must be > 0, found {period_mm}"));
            }
            Effect::Periodic {
                period_mm,
                amplitude_um,
                phase_rad,
            }
        }
        RawEffect::OutlierRun {
            run,
            direction,
            offset_um,
            ..
        } => Effect::OutlierRun {
            run,
            direction: match direction.as_str() {
                "up" => Direction::Up,
                "down" => Direction::Down,
                other => {
                    return Err(format!(
                        "direction must be \"up\" or \"down\", found {other:?}"
                    ));
                }
            },
            offset_um,
        },
        RawEffect::Abbe {
            offset_mm,
            angle_urad,
            ..
        } => Effect::Abbe {
            offset_mm,
            angle_urad,
        },
    };
    match effect.parameters().iter().find(|(_, v)| !v.is_finite()) {
        Some((key, value)) => Err(format!("{key} must be a finite number, found {value}")),
        None => Ok(effect),
    }
}

/// The accepted effects as an effects file, with each parameter's standard
/// uncertainty and the explanation as comments.
pub fn write_effects(accepted: &[AcceptedEffect], source: &str) -> String {
    let mut out = format!(
        "# Effects found by axcomp diagnose in {source}: the residual of the re-test\n\
         # against the prediction. Read by predict --effects and convert --effects.\n"
    );
    for a in accepted {
        let _ = write!(
            out,
            "\n# {}\n[[effect]]\nkind = \"{}\"\n",
            a.explanation,
            a.effect.kind().name()
        );
        if let Effect::OutlierRun { direction, .. } = a.effect {
            let _ = writeln!(out, "direction = \"{}\"", direction.as_str());
        }
        for (key, value) in a.effect.parameters() {
            let text = if key == "run" {
                format!("{value:.0}")
            } else {
                format!("{value:.4}")
            };
            match a.uncertainty.iter().find(|(k, _)| *k == key) {
                Some((_, u)) => {
                    let _ = writeln!(out, "{key} = {text:<12} # ± {u:.4}");
                }
                None => {
                    let _ = writeln!(out, "{key} = {text}");
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::Evidence;

    #[test]
    fn written_effects_read_back() {
        let evidence = Evidence {
            delta_bic: -40.0,
            trials: 1,
            p_value: 1e-9,
            cv_rmse_without_um: 1.0,
            cv_rmse_with_um: 0.5,
        };
        let effects = [
            Effect::Reversal { b_um: -3.0 },
            Effect::Periodic {
                period_mm: 5.0,
                amplitude_um: 1.25,
                phase_rad: 0.5,
            },
            Effect::OutlierRun {
                run: 2,
                direction: Direction::Down,
                offset_um: 4.5,
            },
            Effect::Abbe {
                offset_mm: 100.0,
                angle_urad: 40.0,
            },
        ];
        let accepted: Vec<AcceptedEffect> = effects
            .iter()
            .map(|e| AcceptedEffect {
                effect: e.clone(),
                uncertainty: vec![(e.parameters()[0].0, 0.05)],
                evidence,
                explanation: "What it is; what to do.".into(),
                warnings: Vec::new(),
            })
            .collect();
        let text = write_effects(&accepted, "after.rtl");
        assert_eq!(read_effects(&text).unwrap(), effects, "{text}");
        assert!(text.contains("B_um = -3.0000      # ± 0.0500"), "{text}");
    }

    #[test]
    fn bad_effects_are_refused_with_a_position() {
        let unknown = read_effects("[[effect]]\nkind = \"wobble\"\n").unwrap_err();
        assert_eq!(unknown.position.line, 2, "{unknown}");
        let missing = read_effects("[[effect]]\nkind = \"scale\"\n").unwrap_err();
        assert!(missing.message.contains("scale_um_per_m"), "{missing}");
        let direction = read_effects(
            "[[effect]]\nkind = \"outlier-run\"\nrun = 1\ndirection = \"left\"\noffset_um = 1.0\n",
        )
        .unwrap_err();
        assert!(
            direction.message.contains("\"up\" or \"down\""),
            "{direction}"
        );
        assert!(read_effects("").unwrap().is_empty());
    }
}
