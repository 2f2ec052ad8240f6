//! Machine profiles: how one machine names its axes for each controller, its
//! units and its limits. One TOML file per machine, an example in
//! `fixtures/machines/`. Everything lives under a `[controller]` table, so the
//! same file can also hold the machine's kinematic description for `model`.
//!
//! ```toml
//! [controller]
//! units = "mm"              # machine units (LinuxCNC writes these)
//! max_points = 200          # Sinumerik MD38000 / MD18342, or any stricter limit
//! max_value_mm = 0.1        # refuse tables with larger |values|
//! cec_first_table = 0       # Sinumerik: the first CEC table number of the machine
//! cec_values = "correction" # or "error": the CEC sign, see formats/sinumerik840d
//! tnc640_columns = ["X", "Y", "Z"]  # the machine's CfgAxes/axisList
//! fanuc_parameters = "CNC-PARA.TXT" # a Fanuc control: its parameter backup
//!
//! [controller.axes.X]
//! itnc530_column = 1        # iTNC 530: the N of the N=F() column
//! tnc640_column = "X"       # TNC 640: the axis column name
//! sinumerik_axis = "X1"     # Sinumerik machine axis name (or AX1)
//! sinumerik_encoder = 0     # 0 = first measuring system
//! linuxcnc_joint = 0        # LinuxCNC [JOINT_n]
//! screw_lead_mm = 15.0      # ball-screw lead (Sinumerik MD31030 LEADSCREW_PITCH)
//! scale_period_mm = 0.02    # period of the linear scale or encoder along the axis
//! ```
//!
//! The two periods are what a periodic positioning error of the axis is
//! likely to repeat at; `diagnose --machine` looks for them first.
//!
//! Axes missing from the profile get defaults from their letter (X, Y, Z, A,
//! B, C, U, V, W → iTNC columns 1–9, TNC 640 column = the letter, Sinumerik
//! `X1`…, LinuxCNC joints 0–8), documented in docs/src/tables.md.
//!
//! Sinumerik CEC table numbers are allocated from the profile
//! ([`MachineProfile::cec_table`]), so the files of one machine never load
//! into the same table: the machine's axes are X, Y, Z and every other axis
//! `[controller.axes]` names; with n of them, axis i has the pair
//! `first + 2i` (↑) and `first + 2i + 1` (↓), and the cross-axis table
//! "output = F(input)" the number `first + 2n + i·(n − 1) + j'`, where i is
//! the input's index and j' the output's among the other axes.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::EmitError;
use crate::error::{ParseError, check_machine_profile_keys};
use crate::units::LengthUnit;

/// A machine profile as read from TOML (only the `[controller]` part).
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
pub struct MachineProfile {
    /// Controller settings.
    #[serde(default)]
    pub controller: ControllerProfile,
    /// The Fanuc parameter backup (`controller.fanuc_parameters` or
    /// `--fanuc-parameters`), read by the caller.
    #[serde(skip)]
    pub fanuc: Option<super::fanuc::ParameterBackup>,
}

/// The `[controller]` table.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerProfile {
    /// Machine units: `mm` or `inch`.
    #[serde(default, deserialize_with = "machine_unit")]
    pub units: Option<LengthUnit>,
    /// Largest number of compensation points the machine takes.
    pub max_points: Option<usize>,
    /// Largest |value| allowed, mm.
    pub max_value_mm: Option<f64>,
    /// Sinumerik CEC: the machine's first table number (the allocation starts there).
    pub cec_first_table: Option<usize>,
    /// Sinumerik CEC sign: `correction` or `error`.
    #[serde(default, deserialize_with = "cec_values")]
    pub cec_values: Option<CecValues>,
    /// TNC 640: the machine's axis columns, in order.
    pub tnc640_columns: Option<Vec<String>>,
    /// Fanuc: the parameter backup (`CNC-PARA.TXT`), relative to the profile.
    pub fanuc_parameters: Option<String>,
    /// Per-axis names and numbers.
    #[serde(default)]
    pub axes: BTreeMap<String, AxisProfileToml>,
}

/// What a Sinumerik CEC table holds (`cec_values`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CecValues {
    /// The correction the control adds (the default).
    Correction,
    /// The error the control subtracts.
    Error,
}

/// `units = "mm"` or `"inch"`, with the message the user reads otherwise.
fn machine_unit<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<Option<LengthUnit>, D::Error> {
    let name = String::deserialize(deserializer)?;
    LengthUnit::from_name(&name).map(Some).ok_or_else(|| {
        serde::de::Error::custom(format!(
            "controller.units must be \"mm\" or \"inch\", found {name:?}"
        ))
    })
}

/// `cec_values = "correction"` or `"error"`, with the message the user reads otherwise.
fn cec_values<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<Option<CecValues>, D::Error> {
    match String::deserialize(deserializer)?.as_str() {
        "correction" => Ok(Some(CecValues::Correction)),
        "error" => Ok(Some(CecValues::Error)),
        other => Err(serde::de::Error::custom(format!(
            "controller.cec_values must be \"correction\" or \"error\", found {other:?}"
        ))),
    }
}

/// One axis as written in the profile; every field optional.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisProfileToml {
    /// iTNC 530 column number (the N of `N=F()`).
    pub itnc530_column: Option<u32>,
    /// TNC 640 column name.
    pub tnc640_column: Option<String>,
    /// Sinumerik machine axis name.
    pub sinumerik_axis: Option<String>,
    /// Sinumerik measuring system (0 = first).
    pub sinumerik_encoder: Option<u32>,
    /// LinuxCNC joint number.
    pub linuxcnc_joint: Option<u32>,
    /// Lead of the axis' ball screw, mm (Sinumerik MD31030 `LEADSCREW_PITCH`).
    #[serde(default, deserialize_with = "period_mm")]
    pub screw_lead_mm: Option<f64>,
    /// Period of the axis' linear scale or encoder along the axis, mm.
    #[serde(default, deserialize_with = "period_mm")]
    pub scale_period_mm: Option<f64>,
}

/// A period, mm: positive and finite, with the message the user reads otherwise.
fn period_mm<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<Option<f64>, D::Error> {
    let value = f64::deserialize(deserializer)?;
    if value > 0.0 && value.is_finite() {
        Ok(Some(value))
    } else {
        Err(serde::de::Error::custom(format!(
            "a period must be a length in mm > 0, found {value}"
        )))
    }
}

/// The periods an axis' drive and scale repeat at, mm, as the profile gives them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisPeriods {
    /// The ball screw's lead.
    pub screw_lead_mm: Option<f64>,
    /// The scale's or encoder's period.
    pub scale_period_mm: Option<f64>,
}

/// One axis with every name resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisProfile {
    /// The axis letter as the measurement names it.
    pub axis: String,
    /// iTNC 530 column number.
    pub itnc530_column: u32,
    /// TNC 640 column name.
    pub tnc640_column: String,
    /// Sinumerik machine axis name.
    pub sinumerik_axis: String,
    /// Sinumerik measuring system.
    pub sinumerik_encoder: u32,
    /// LinuxCNC joint number.
    pub linuxcnc_joint: u32,
    /// Sinumerik CEC: the number of the axis's own ↑ table (↓ is the next),
    /// allocated from the profile; `None` for an axis the profile does not
    /// name among the machine's axes ([`MachineProfile::cec_table`]).
    pub cec_table: Option<usize>,
    /// Fanuc: the axis' pitch error compensation parameters, when the
    /// profile has a parameter backup.
    pub fanuc: Option<super::fanuc::AxisParameters>,
}

/// The letters whose position gives the default numbers.
const AXIS_LETTERS: [&str; 9] = ["X", "Y", "Z", "A", "B", "C", "U", "V", "W"];

impl MachineProfile {
    /// Parses a profile; unknown keys under `[controller]` are errors (a typo
    /// must not silently fall back to a default), and so are top-level tables
    /// that belong to no reader (`check_machine_profile_keys`); the other
    /// readers' tables are left to them.
    pub fn from_toml_str(text: &str) -> Result<MachineProfile, ParseError> {
        check_machine_profile_keys(text)?;
        toml::from_str(text).map_err(|e| ParseError::from_toml(text, &e))
    }

    /// The machine unit (default mm).
    pub fn machine_unit(&self) -> LengthUnit {
        self.controller.units.unwrap_or(LengthUnit::Millimetre)
    }

    /// The unit of a `controller` table on this machine: the profile's
    /// `units`; without it, for the Fagor 8055, whose file states no unit and
    /// holds the machine's, the unit the test was measured in (an inch laser
    /// file on an inch machine gives an inch table, as the real files in
    /// `formats/fagor8055/README.md` show); else mm.
    pub fn table_unit(&self, controller: super::Controller, test_unit: LengthUnit) -> LengthUnit {
        match (self.controller.units, controller) {
            (Some(unit), _) => unit,
            (None, super::Controller::Fagor8055) => test_unit,
            (None, _) => LengthUnit::Millimetre,
        }
    }

    /// The periods of an axis the profile gives (none for an axis it does not list).
    pub fn axis_periods(&self, axis: &str) -> AxisPeriods {
        self.controller
            .axes
            .get(axis)
            .map_or(AxisPeriods::default(), |entry| AxisPeriods {
                screw_lead_mm: entry.screw_lead_mm,
                scale_period_mm: entry.scale_period_mm,
            })
    }

    /// The machine's axes for the CEC table numbers: X, Y, Z, then every
    /// other axis `[controller.axes]` names, in the letters' order (X Y Z A
    /// B C U V W), other names after them alphabetically.
    pub fn cec_axes(&self) -> Vec<String> {
        let mut axes: Vec<String> = ["X", "Y", "Z"].map(String::from).to_vec();
        let mut named: Vec<&String> = self.controller.axes.keys().collect();
        named.sort_by_key(|name| {
            let letter = AXIS_LETTERS
                .iter()
                .position(|l| l.eq_ignore_ascii_case(name));
            (letter.unwrap_or(AXIS_LETTERS.len()), name.as_str())
        });
        for name in named {
            if !axes.iter().any(|a| a.eq_ignore_ascii_case(name)) {
                axes.push(name.clone());
            }
        }
        axes
    }

    /// The Sinumerik CEC table number of "`output` = F(`input`)": for
    /// `input == output` the axis's own ↑ table (↓ is the next), else the
    /// cross-axis table (module doc). Distinct for every pair of the
    /// machine's axes, so the files of one machine never overwrite each other.
    pub fn cec_table(&self, input: &str, output: &str) -> Result<usize, EmitError> {
        let axes = self.cec_axes();
        let index = |axis: &str| {
            axes.iter()
                .position(|a| a.eq_ignore_ascii_case(axis))
                .ok_or_else(|| {
                    EmitError::Profile(format!(
                        "axis {axis} has no Sinumerik CEC table number: the machine's axes are {} (name {axis} under [controller.axes.{axis}] in the machine profile, so every file of the machine numbers its tables alike)",
                        axes.join(", ")
                    ))
                })
        };
        let first = self.controller.cec_first_table.unwrap_or(0);
        let n = axes.len();
        let (i, j) = (index(input)?, index(output)?);
        Ok(match j.cmp(&i) {
            std::cmp::Ordering::Equal => first + 2 * i,
            std::cmp::Ordering::Less => first + 2 * n + i * (n - 1) + j,
            std::cmp::Ordering::Greater => first + 2 * n + i * (n - 1) + j - 1,
        })
    }

    /// The resolved names of an axis: profile entries first, defaults from the letter.
    pub fn axis(&self, axis: &str) -> Result<AxisProfile, EmitError> {
        let entry = self.controller.axes.get(axis).cloned().unwrap_or_default();
        let index = AXIS_LETTERS
            .iter()
            .position(|l| l.eq_ignore_ascii_case(axis));
        let need = |what: &'static str| EmitError::NoDefault {
            axis: axis.to_string(),
            what,
        };
        Ok(AxisProfile {
            axis: axis.to_string(),
            itnc530_column: match entry.itnc530_column {
                Some(column) => column,
                None => index
                    .map(|i| i as u32 + 1)
                    .ok_or_else(|| need("itnc530_column"))?,
            },
            tnc640_column: entry.tnc640_column.unwrap_or_else(|| axis.to_string()),
            sinumerik_axis: entry
                .sinumerik_axis
                .unwrap_or_else(|| format!("{}1", axis.to_ascii_uppercase())),
            sinumerik_encoder: entry.sinumerik_encoder.unwrap_or(0),
            linuxcnc_joint: match entry.linuxcnc_joint {
                Some(joint) => joint,
                None => index
                    .map(|i| i as u32)
                    .ok_or_else(|| need("linuxcnc_joint"))?,
            },
            cec_table: self.cec_table(axis, axis).ok(),
            fanuc: match &self.fanuc {
                Some(backup) => Some(backup.axis(axis).map_err(EmitError::Profile)?),
                None => None,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_come_from_the_axis_letter() {
        let profile = MachineProfile::default();
        let x = profile.axis("X").unwrap();
        assert_eq!(
            (
                x.itnc530_column,
                x.tnc640_column.as_str(),
                x.sinumerik_axis.as_str(),
                x.linuxcnc_joint
            ),
            (1, "X", "X1", 0)
        );
        let u = profile.axis("U").unwrap();
        assert_eq!((u.itnc530_column, u.linuxcnc_joint), (7, 6));
        assert!(
            profile
                .axis("Q")
                .unwrap_err()
                .to_string()
                .contains("[controller.axes.Q]")
        );
    }

    #[test]
    fn profile_entries_override_and_typos_are_errors() {
        let text = "[kinematics]\nchain = \"ZFYX\"\n\n[controller]\nunits = \"inch\"\nmax_points = 200\n\n[controller.axes.X]\nsinumerik_axis = \"AX1\"\nlinuxcnc_joint = 3\n";
        let profile = MachineProfile::from_toml_str(text).unwrap();
        assert_eq!(profile.machine_unit(), LengthUnit::Inch);
        let x = profile.axis("X").unwrap();
        assert_eq!((x.sinumerik_axis.as_str(), x.linuxcnc_joint), ("AX1", 3));
        assert!(MachineProfile::from_toml_str("[controller]\nmax_pionts = 3\n").is_err());
        assert_eq!(profile.axis_periods("X"), AxisPeriods::default());
        assert!(MachineProfile::from_toml_str("[controller]\nunits = \"furlong\"\n").is_err());
    }

    #[test]
    fn cec_tables_are_distinct_across_the_machine() {
        // By hand for X, Y, Z: own pairs 0/1, 2/3, 4/5; then Y=F(X) 6,
        // Z=F(X) 7, X=F(Y) 8, Z=F(Y) 9, X=F(Z) 10, Y=F(Z) 11.
        let profile = MachineProfile::default();
        let table = |i: &str, o: &str| profile.cec_table(i, o).unwrap();
        assert_eq!(
            (table("X", "X"), table("Y", "Y"), table("Z", "Z")),
            (0, 2, 4)
        );
        assert_eq!((table("X", "Y"), table("X", "Z")), (6, 7));
        assert_eq!((table("Y", "X"), table("Y", "Z")), (8, 9));
        assert_eq!((table("Z", "X"), table("Z", "Y")), (10, 11));
        assert!(profile.cec_table("C", "C").is_err());
        assert_eq!(profile.axis("C").unwrap().cec_table, None);
        // A profile naming C and starting at 10: n = 4.
        let text =
            "[controller]\ncec_first_table = 10\n\n[controller.axes.C]\nsinumerik_axis = \"C1\"\n";
        let profile = MachineProfile::from_toml_str(text).unwrap();
        assert_eq!(profile.cec_axes(), ["X", "Y", "Z", "C"]);
        let table = |i: &str, o: &str| profile.cec_table(i, o).unwrap();
        assert_eq!(
            (table("C", "C"), table("X", "Y"), table("C", "Z")),
            (16, 18, 29)
        );
        let mut all: Vec<usize> = ["X", "Y", "Z", "C"]
            .iter()
            .flat_map(|i| ["X", "Y", "Z", "C"].map(|o| (*i, o)))
            .flat_map(|(i, o)| {
                let t = table(i, o);
                if i == o { vec![t, t + 1] } else { vec![t] }
            })
            .collect();
        all.sort_unstable();
        assert_eq!(all, (10..30).collect::<Vec<_>>());
    }

    #[test]
    fn an_axis_gives_its_screw_lead_and_scale_period() {
        // Seed 001, Tab. 7: the VC1810's axes have a 15 mm lead.
        let text = "[controller.axes.X]\nscrew_lead_mm = 15.0\nscale_period_mm = 0.02\n";
        let profile = MachineProfile::from_toml_str(text).unwrap();
        assert_eq!(
            profile.axis_periods("X"),
            AxisPeriods {
                screw_lead_mm: Some(15.0),
                scale_period_mm: Some(0.02)
            }
        );
        assert_eq!(profile.axis_periods("Y"), AxisPeriods::default());
        let error = MachineProfile::from_toml_str("[controller.axes.X]\nscrew_lead_mm = -5.0\n")
            .unwrap_err();
        assert!(error.to_string().contains("> 0"), "{error}");
        assert!(error.to_string().starts_with("2:"), "{error}");
    }
}
