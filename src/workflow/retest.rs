//! The re-test: its diagnosis against the first test and the table that was
//! active, with the machine profile's known periods, and the effects file the
//! next table is made from. `diagnose`, `report --diagnose`, the web app and
//! the demo all diagnose through [`diagnosis`], so one re-test gets one
//! diagnosis.

use crate::compensate::CompensationTable;
use crate::cycle::CycleTiming;
use crate::diagnose::{AngularProfile, DiagnoseError, DiagnoseInput, Diagnosis, diagnose};
use crate::effects::{Effect, read_effects};
use crate::emit::MachineProfile;
use crate::error::ParseError;
use crate::evaluate::Standard;
use crate::measurement::Measurement;
use crate::units::AngleUnit;

use super::known_periods;

/// How a re-test is diagnosed besides its tests and table.
#[derive(Clone, Copy)]
pub struct DiagnoseSettings<'a> {
    /// The unit a rotary axis' sentences are in.
    pub angle: AngleUnit,
    /// The backlash parameter was set as `convert` suggested.
    pub backlash_set: bool,
    /// The axis' pitch or yaw (`--angular`).
    pub angular: Option<&'a AngularProfile>,
    /// The standard of the figures.
    pub standard: &'a dyn Standard,
}

impl<'a> DiagnoseSettings<'a> {
    /// The settings every front end has: no backlash set, no angular
    /// profile, a rotary axis in ″.
    pub fn plain(standard: &'a dyn Standard) -> DiagnoseSettings<'a> {
        DiagnoseSettings {
            angle: AngleUnit::default(),
            backlash_set: false,
            angular: None,
            standard,
        }
    }
}

/// The diagnosis of `after` against `before` (when given) with `table`
/// active during the re-test, searching the profile's screw lead and scale
/// period of the re-test's axis first ([`known_periods`]).
pub fn diagnosis(
    after: &Measurement,
    before: Option<&Measurement>,
    table: Option<&CompensationTable>,
    profile: &MachineProfile,
    settings: DiagnoseSettings<'_>,
) -> Result<Diagnosis, DiagnoseError> {
    let known_periods = known_periods(profile, after);
    diagnose(&DiagnoseInput {
        angle: settings.angle,
        after,
        before,
        table,
        backlash_set: settings.backlash_set,
        angular: settings.angular,
        known_periods: &known_periods,
        timing: CycleTiming::ASSUMED,
        standard: settings.standard,
    })
}

/// The effects file of `diagnosis` (what `diagnose --write-effects` writes,
/// naming the re-test `after_label`) and its effects read back from it, as
/// `convert --effects` reads them: the next table is made from the file's numbers.
pub fn effects_file(
    diagnosis: &Diagnosis,
    after_label: &str,
) -> Result<(String, Vec<Effect>), ParseError> {
    let text = diagnosis.effects_file(after_label);
    let effects = read_effects(&text)?;
    Ok((text, effects))
}
