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
//! Each kind's keys are its struct's fields, under names with a linear
//! axis' units ([`super::Reversal`]'s `b` as `B_um`, [`super::Scale`]'s
//! `scale_um_per_m`, …): the file is written and read for linear axes only
//! (`workflow::rotary`). A `tests` key (synth's) is accepted and ignored.

use std::fmt::Write;

use serde::{Deserialize, Deserializer};

use super::{Effect, Entry, ParameterValue, Uncertainty};
use crate::error::ParseError;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EffectsFile {
    #[serde(default)]
    effect: Vec<Entry>,
}

/// A kind's parameters with synth's `tests` key allowed beside them.
pub(super) struct Tested<T>(pub(super) T);

impl<'de, T: serde::de::DeserializeOwned> Deserialize<'de> for Tested<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Tested<T>, D::Error> {
        let mut table = toml::Table::deserialize(deserializer)?;
        table.remove("tests");
        T::deserialize(toml::Value::Table(table))
            .map(Tested)
            .map_err(|e| serde::de::Error::custom(e.message()))
    }
}

/// Reads an effects file.
///
/// # Example
///
/// ```
/// use axcomp::effects::{Effect, Reversal, read_effects};
///
/// let effects = read_effects("[[effect]]\nkind = \"reversal\"\nB_um = -3.0\n")?;
/// assert_eq!(effects, [Effect::Reversal(Reversal { b: -3.0 })]);
/// # Ok::<(), axcomp::error::ParseError>(())
/// ```
pub fn read_effects(text: &str) -> Result<Vec<Effect>, ParseError> {
    let file: EffectsFile =
        toml::from_str(text).map_err(|error| ParseError::from_toml(text, &error))?;
    file.effect
        .into_iter()
        .map(Effect::from)
        .enumerate()
        .map(|(index, effect)| {
            checked(&effect)
                .map(|()| effect)
                .map_err(|m| ParseError::new(1, 1, format!("effect {}: {m}", index + 1)))
        })
        .collect()
}

fn checked(effect: &Effect) -> Result<(), String> {
    effect.model().check()?;
    for parameter in effect.parameters() {
        if let ParameterValue::Number(value) = parameter.value
            && !value.is_finite()
        {
            return Err(format!(
                "{} must be a finite number, found {value}",
                parameter.key
            ));
        }
    }
    Ok(())
}

/// One effect as the file saves it.
#[derive(Clone, Copy, Debug)]
pub struct FileEntry<'a> {
    /// The effect.
    pub effect: &'a Effect,
    /// The standard uncertainty of its parameters, by key.
    pub uncertainty: &'a [Uncertainty],
    /// What it is and what to do, one sentence (a comment in the file).
    pub explanation: &'a str,
}

/// Effects as an effects file, with each parameter's standard uncertainty
/// and the explanation as comments; `source` names the re-test.
pub fn write_effects<'a>(entries: impl IntoIterator<Item = FileEntry<'a>>, source: &str) -> String {
    let mut out = format!(
        "# Effects found by axcomp diagnose in {source}: the residual of the re-test\n\
         # against the prediction. Read by predict --effects and convert --effects.\n"
    );
    for entry in entries {
        let _ = write!(
            out,
            "\n# {}\n[[effect]]\nkind = \"{}\"\n",
            entry.explanation,
            entry.effect.kind().name()
        );
        if let Effect::OutlierRun(run) = entry.effect {
            let _ = writeln!(out, "direction = \"{}\"", run.direction.as_str());
        }
        for parameter in entry.effect.parameters() {
            let key = parameter.key;
            let text = match parameter.value {
                ParameterValue::Run(run) => run.to_string(),
                ParameterValue::Number(value) => format!("{value:.4}"),
            };
            match entry.uncertainty.iter().find(|(k, _)| *k == key) {
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
