//! The form read into what the workflow takes: the measurements, the
//! standard, the machine profile, the limits and decision rule, the table
//! that was active and the table asked for, each refused as the CLI refuses
//! its flag.

use crate::compensate::plan::Request as TableGrid;
use crate::compensate::{Extrapolate, TableMode};
use crate::emit::fanuc::ParameterBackup;
use crate::emit::{Controller, MachineProfile};
use crate::error::Warning;
use crate::evaluate::verdict::{AcceptanceProfile, Decision, Figure, Limit, parse_limit};
use crate::evaluate::{self, Standard};
use crate::measurement::{Measurement, SourceFormat};
use crate::read;
use crate::workflow::table::{ActiveTable, ActiveTableFile, active_table as read_active};
use crate::workflow::{self, Test};

use super::error::ApiError;
use super::form::{Form, Upload};

/// The measurement of the form's `file` field(s), named by `axis` when given.
pub fn measurement(form: &Form, field: &str) -> Result<(Measurement, Vec<Warning>), ApiError> {
    let files = form.files(field);
    if files.is_empty() {
        return Err(ApiError::bad(format!(
            "no {field} file: drop or pick a measurement file"
        )));
    }
    let format = match form.text("format") {
        Some(name) => {
            Some(SourceFormat::from_name(name).ok_or_else(|| format!("unknown format {name:?}"))?)
        }
        None => None,
    };
    let read::ReadResult {
        mut measurement,
        warnings,
    } = read::read_all_bytes(files, format)?;
    if let Some(axis) = form.text("axis") {
        measurement.set_axis(axis);
    }
    Ok((measurement, warnings))
}

/// The test of the form's `field`, evaluated to `standard` (as the report has it).
pub fn test(form: &Form, field: &str, standard: &dyn Standard) -> Result<Test, ApiError> {
    let (measurement, warnings) = measurement(form, field)?;
    Ok(Test::new(measurement, warnings, standard, None)?)
}

/// The form's `standard` (`--standard`), ISO 230-2:2014 unless sent.
pub fn standard(form: &Form) -> Result<&'static dyn Standard, ApiError> {
    Ok(evaluate::by_name(
        form.text("standard").unwrap_or("iso230-2:2014"),
    )?)
}

/// The machine profile of the form's `machine` field (as `--machine`):
/// its `[controller]` part and its `[acceptance]` part; the defaults and no
/// limits when none is sent. A bad profile is refused as the CLI refuses
/// it: `NAME:LINE:COL: …`.
pub struct Profile {
    /// The file's name, which the limits' source names.
    pub file: String,
    /// The `[controller]` part.
    pub machine: MachineProfile,
    /// The `[acceptance]` part.
    pub acceptance: Option<AcceptanceProfile>,
}

/// The form's machine profile ([`Profile`]), with the Fanuc parameter
/// backup of `fanuc_parameters` (as `--fanuc-parameters`).
pub fn profile(form: &Form) -> Result<Profile, ApiError> {
    let mut profile = machine_profile(form)?;
    if let Some((name, bytes)) = form.one_file("fanuc_parameters")? {
        let file = name.display().to_string();
        let text = String::from_utf8_lossy(bytes);
        let backup = ParameterBackup::parse(&text, &file)
            .map_err(|error| ApiError::bad(format!("{file}:{error}")))?;
        profile.machine.fanuc = Some(backup);
    }
    Ok(profile)
}

/// The `machine` field's profile.
fn machine_profile(form: &Form) -> Result<Profile, ApiError> {
    let Some((name, bytes)) = form.one_file("machine")? else {
        return Ok(Profile {
            file: String::new(),
            machine: MachineProfile::default(),
            acceptance: None,
        });
    };
    let file = name.display().to_string();
    let text = std::str::from_utf8(bytes)
        .map_err(|_| ApiError::bad(format!("{file}: a machine profile is UTF-8 text (TOML)")))?;
    let at = |error: crate::error::ParseError| ApiError::bad(format!("{file}:{error}"));
    Ok(Profile {
        machine: MachineProfile::from_toml_str(text).map_err(at)?,
        acceptance: Some(AcceptanceProfile::from_toml_str(text).map_err(at)?),
        file,
    })
}

/// The form's `limits` (`A=12, E_up=6`: `--limit` each) on top of the
/// profile's `[acceptance]`, for `evaluation`'s axis and standard.
pub fn limits(
    form: &Form,
    profile: &Profile,
    axis: &str,
    evaluation: &evaluate::Evaluation,
) -> Result<Vec<Limit>, ApiError> {
    let given = form
        .text("limits")
        .unwrap_or_default()
        .split([',', ';', '\n'])
        .map(str::trim)
        .filter(|item| !item.is_empty())
        .map(|item| parse_limit(item).map_err(|error| format!("limits: {error}")))
        .collect::<Result<Vec<(Figure, f64)>, String>>()?;
    let acceptance = profile
        .acceptance
        .as_ref()
        .map(|acceptance| (acceptance, profile.file.as_str()));
    workflow::limits(acceptance, axis, evaluation, &given)
        .map_err(|error| ApiError::bad(error.to_string()))
}

/// The form's decision rule (`--decision`), simple acceptance unless sent.
pub fn decision(form: &Form) -> Result<Decision, ApiError> {
    match form.text("decision") {
        None => Ok(Decision::default()),
        Some(name) => Decision::from_name(name).ok_or_else(|| {
            ApiError::bad(format!(
                "decision: expected simple or iso14253-1, found {name:?}"
            ))
        }),
    }
}

/// The names of `files`, as messages and the JSON give them.
pub fn file_label(files: &[Upload]) -> String {
    files
        .iter()
        .map(|(name, _)| name.display().to_string())
        .collect::<Vec<_>>()
        .join(" + ")
}

/// The form's `linuxcnc_type`, 0 or 1, when sent.
pub fn linuxcnc_type(form: &Form) -> Result<Option<u8>, ApiError> {
    let linuxcnc_type: Option<u8> = form.number("linuxcnc_type", "0 or 1")?;
    if linuxcnc_type.is_some_and(|t| t > 1) {
        return Err(ApiError::bad("linuxcnc_type: expected 0 or 1"));
    }
    Ok(linuxcnc_type)
}

/// The active table of the form's `table` field with its upload, read for
/// `test`'s axis (`workflow::table::active_table`, as `convert --existing`
/// and `report --table` read it).
pub fn active_table<'a>(
    form: &'a Form,
    test: &Measurement,
    test_label: &str,
    profile: &MachineProfile,
    linuxcnc_type: Option<u8>,
) -> Result<Option<(&'a Upload, ActiveTable)>, ApiError> {
    let Some(upload) = form.one_file("table")? else {
        return Ok(None);
    };
    let (name, bytes) = upload;
    let active = read_active(
        ActiveTableFile {
            bytes,
            file: &name.display().to_string(),
            test_label,
            how_to_name_the_axis: "name it in the Axis field",
            linuxcnc_type,
        },
        test,
        profile,
    )?;
    Ok(Some((upload, active)))
}

/// The form's controller (`--controller`), the TNC 640 unless sent.
pub fn controller(form: &Form) -> Result<Controller, ApiError> {
    let name = form.text("controller").unwrap_or("tnc640");
    Ok(Controller::from_name(name).ok_or_else(|| format!("unknown controller {name:?}"))?)
}

/// What a grid position is typed in: the measured axis' unit.
const AXIS_NUMBER: &str = "a number in the axis' unit (mm, or ° on a rotary axis)";

/// The form's grid, mode, reference and extrapolation (`convert`'s flags).
pub fn grid(form: &Form) -> Result<TableGrid, ApiError> {
    Ok(TableGrid {
        mode: form
            .text("mode")
            .map(TableMode::from_name)
            .transpose()
            .map_err(|e| format!("mode: {e}"))?,
        step: form.number("step", AXIS_NUMBER)?,
        start: form.number("start", AXIS_NUMBER)?,
        count: form.number("count", "a whole number of points")?,
        reference: form.number("reference", AXIS_NUMBER)?,
        extrapolate: form
            .text("extrapolate")
            .map(Extrapolate::from_name)
            .transpose()
            .map_err(|e| format!("extrapolate: {e}"))?,
    })
}

/// The form's `fanuc_rescaled` (`--fanuc-rescaled`): on when sent as
/// `1`, `on` or `true`.
pub fn fanuc_rescaled(form: &Form) -> Result<bool, ApiError> {
    match form.text("fanuc_rescaled") {
        None | Some("0" | "off" | "false") => Ok(false),
        Some("1" | "on" | "true") => Ok(true),
        Some(other) => Err(ApiError::bad(format!(
            "fanuc_rescaled: expected 1 or 0, found {other:?}"
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_positions_are_asked_for_in_the_axis_unit() {
        let mut form = Form::default();
        form.text.insert("step", "15°".to_string());
        let error = format!("{:?}", grid(&form).unwrap_err());
        assert!(
            error.contains(
                "step: expected a number in the axis' unit (mm, or ° on a rotary axis), found \\\"15°\\\""
            ),
            "{error}"
        );
        form.text.insert("step", "15".to_string());
        assert_eq!(grid(&form).unwrap().step, Some(15.0));
    }
}
