//! A machine profile's `[acceptance]` table (the format is in the parent
//! module's doc) and its TOML form.

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde::de::{self, DeserializeSeed, MapAccess, Visitor};

use crate::error::{ParseError, check_machine_profile_keys};
use crate::units::um_to_mm;

use super::{Figure, Limit, LimitSource, Permissible, with_overrides};

/// The `[acceptance]` table of a machine profile (see the module doc).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AcceptanceProfile {
    /// `[acceptance]`: for every axis.
    pub general: Vec<(Figure, Permissible)>,
    /// `[acceptance.axes.NAME]`: for one axis, replacing the general ones.
    pub axes: BTreeMap<String, Vec<(Figure, Permissible)>>,
}

impl AcceptanceProfile {
    /// Reads the `[acceptance]` table of a machine profile; an empty profile
    /// when the file has none. Errors carry the line and column.
    ///
    /// # Example
    /// ```
    /// use axcomp::evaluate::verdict::{AcceptanceProfile, Figure};
    /// let text = "[acceptance]\nA = { per_1000_mm_um = 10, min_um = 5 }\nR = 4\n\
    ///             [acceptance.axes.X]\nA = 12\n";
    /// let profile = AcceptanceProfile::from_toml_str(text).unwrap();
    /// let limits = profile.limits_for("X", "m.toml");
    /// assert_eq!(limits.len(), 2);
    /// // X's own A replaces the general one: 12 µm at any travel.
    /// assert!((limits[0].permissible.limit_mm(750.0) - 0.012).abs() < 1e-15);
    /// let error = AcceptanceProfile::from_toml_str("[acceptance]\nQ = 3\n").unwrap_err();
    /// assert_eq!(error.position.line, 2);
    /// ```
    pub fn from_toml_str(text: &str) -> Result<AcceptanceProfile, ParseError> {
        check_machine_profile_keys(text)?;
        let raw: RawFile = toml::from_str(text).map_err(|e| ParseError::from_toml(text, &e))?;
        let Some(acceptance) = raw.acceptance else {
            return Ok(AcceptanceProfile::default());
        };
        Ok(AcceptanceProfile {
            general: acceptance.figures,
            axes: acceptance.axes,
        })
    }

    /// Whether the profile sets no limit at all.
    pub fn is_empty(&self) -> bool {
        self.general.is_empty() && self.axes.values().all(Vec::is_empty)
    }

    /// The limits for one axis: the general ones, replaced per figure by the
    /// axis table's. `file` names the profile in the limits' source.
    pub fn limits_for(&self, axis: &str, file: &str) -> Vec<Limit> {
        let limits = |entries: &[(Figure, Permissible)], axis: Option<&str>| -> Vec<Limit> {
            entries
                .iter()
                .map(|&(figure, permissible)| Limit {
                    figure,
                    permissible,
                    source: LimitSource::Profile {
                        file: file.to_string(),
                        axis: axis.map(str::to_string),
                    },
                })
                .collect()
        };
        let general = limits(&self.general, None);
        let own = self
            .axes
            .get(axis)
            .map(|entries| limits(entries, Some(axis)))
            .unwrap_or_default();
        with_overrides(general, own)
    }
}

// --- TOML -------------------------------------------------------------------
//
// Hand-written visitors so that every error names the key or value it is
// about: toml attaches the span of the key (unknown figure or key) or of the
// value (bad number) to an error raised while deserialising it.

/// The whole file: only `[acceptance]`; other tables belong to other readers
/// (and a table no reader knows is refused first: `check_machine_profile_keys`).
#[derive(Deserialize)]
struct RawFile {
    acceptance: Option<RawLimits<true>>,
}

/// A figure table; `AXES` allows the `axes` key (only in `[acceptance]`).
struct RawLimits<const AXES: bool> {
    figures: Vec<(Figure, Permissible)>,
    axes: BTreeMap<String, Vec<(Figure, Permissible)>>,
}

impl<'de, const AXES: bool> Deserialize<'de> for RawLimits<AXES> {
    fn deserialize<D: de::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_map(LimitsVisitor::<AXES>)
    }
}

struct LimitsVisitor<const AXES: bool>;

impl<'de, const AXES: bool> Visitor<'de> for LimitsVisitor<AXES> {
    type Value = RawLimits<AXES>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a table of figure limits")
    }

    fn visit_map<M: MapAccess<'de>>(self, mut map: M) -> Result<Self::Value, M::Error> {
        let mut out = RawLimits {
            figures: Vec::new(),
            axes: BTreeMap::new(),
        };
        while let Some(key) = map.next_key_seed(KeySeed { axes: AXES })? {
            match key {
                Key::Figure(figure) => {
                    let RawPermissible(permissible) = map.next_value()?;
                    out.figures.push((figure, permissible));
                }
                Key::Axes => {
                    let axes: BTreeMap<String, RawLimits<false>> = map.next_value()?;
                    out.axes = axes.into_iter().map(|(k, v)| (k, v.figures)).collect();
                }
            }
        }
        out.figures.sort_by_key(|(figure, _)| *figure);
        Ok(out)
    }
}

enum Key {
    Figure(Figure),
    Axes,
}

/// Reads a key of a figure table: a figure name, or `axes` where allowed.
struct KeySeed {
    axes: bool,
}

impl<'de> DeserializeSeed<'de> for KeySeed {
    type Value = Key;

    fn deserialize<D: de::Deserializer<'de>>(self, deserializer: D) -> Result<Key, D::Error> {
        deserializer.deserialize_str(self)
    }
}

impl Visitor<'_> for KeySeed {
    type Value = Key;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a figure name")
    }

    fn visit_str<E: de::Error>(self, name: &str) -> Result<Key, E> {
        if let Some(figure) = Figure::from_name(name) {
            return Ok(Key::Figure(figure));
        }
        if self.axes && name == "axes" {
            return Ok(Key::Axes);
        }
        let axes = if self.axes {
            " (or [acceptance.axes.NAME])"
        } else {
            ""
        };
        Err(E::custom(format!(
            "unknown figure `{name}`; expected one of {}{axes}",
            Figure::names()
        )))
    }
}

/// A limit: a number of µm, or `{ um = … }`, or `{ per_1000_mm_um = …, min_um = … }`.
struct RawPermissible(Permissible);

impl<'de> Deserialize<'de> for RawPermissible {
    fn deserialize<D: de::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(PermissibleVisitor)
    }
}

struct PermissibleVisitor;

impl<'de> Visitor<'de> for PermissibleVisitor {
    type Value = RawPermissible;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(
            "a number of µm above 0, or a table { um = … } or { per_1000_mm_um = …, min_um = … }",
        )
    }

    fn visit_i64<E: de::Error>(self, value: i64) -> Result<RawPermissible, E> {
        self.visit_f64(value as f64)
    }

    fn visit_u64<E: de::Error>(self, value: u64) -> Result<RawPermissible, E> {
        self.visit_f64(value as f64)
    }

    fn visit_f64<E: de::Error>(self, value: f64) -> Result<RawPermissible, E> {
        Ok(RawPermissible(Permissible::Fixed {
            limit_mm: um_to_mm(positive_um(value)?),
        }))
    }

    fn visit_map<M: MapAccess<'de>>(self, map: M) -> Result<RawPermissible, M::Error> {
        let table = RawPermissibleTable::deserialize(de::value::MapAccessDeserializer::new(map))?;
        let permissible = match (table.um, table.per_1000_mm_um, table.min_um) {
            (Some(Um(um)), None, None) => Permissible::Fixed {
                limit_mm: um_to_mm(um),
            },
            (None, Some(Um(per)), min) => Permissible::PerLength {
                per_1000_mm_mm: um_to_mm(per),
                min_mm: min.map(|Um(m)| um_to_mm(m)),
            },
            (Some(_), _, _) => {
                return Err(de::Error::custom(
                    "give either um (fixed) or per_1000_mm_um (per length, with min_um), not both",
                ));
            }
            (None, None, _) => {
                return Err(de::Error::custom(
                    "expected um (fixed) or per_1000_mm_um (per length, optionally with min_um)",
                ));
            }
        };
        Ok(RawPermissible(permissible))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPermissibleTable {
    um: Option<Um>,
    per_1000_mm_um: Option<Um>,
    min_um: Option<Um>,
}

/// A number of µm above 0, integer or not.
struct Um(f64);

impl<'de> Deserialize<'de> for Um {
    fn deserialize<D: de::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct UmVisitor;
        impl Visitor<'_> for UmVisitor {
            type Value = Um;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number of µm above 0")
            }
            fn visit_i64<E: de::Error>(self, value: i64) -> Result<Um, E> {
                self.visit_f64(value as f64)
            }
            fn visit_u64<E: de::Error>(self, value: u64) -> Result<Um, E> {
                self.visit_f64(value as f64)
            }
            fn visit_f64<E: de::Error>(self, value: f64) -> Result<Um, E> {
                positive_um(value).map(Um)
            }
        }
        deserializer.deserialize_any(UmVisitor)
    }
}

fn positive_um<E: de::Error>(value: f64) -> Result<f64, E> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(E::custom(format!(
            "expected a number of µm above 0, found {value}"
        )))
    }
}
