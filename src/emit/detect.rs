//! Which controller wrote a table, from its content, and the table read
//! with that controller's reader.

use super::{
    Controller, EmitOptions, fagor8055, fagor8065, fanuc, itnc530, linuxcnc, sinumerik840d, tnc640,
};
use crate::compensate::CompensationTable;
use crate::error::ParseError;

/// Reads a table written by any supported controller format, detected from
/// the content: the table of `options.axes[0]`, of an axis of
/// `options.kind` (its numbers in mm, or ° on a rotary axis), in machine units
/// `options.machine_unit` (LinuxCNC) and with the profile's CEC sign.
/// `linuxcnc_type` must be given for LinuxCNC files whose type the numbers
/// do not tell.
pub fn read_any(
    text: &str,
    options: &EmitOptions,
    linuxcnc_type: Option<u8>,
) -> Result<(Controller, CompensationTable), ParseError> {
    let Some(axis) = options.axes.first() else {
        return Err(ParseError::new(1, 1, "no axis given to read the table of"));
    };
    if !fanuc::looks_like(text) && fanuc::looks_like_parameters(text) {
        return Err(ParseError::new(
            1,
            1,
            "this is a Fanuc parameter backup (N…Q1 lines), not the pitch error compensation data: give it with --fanuc-parameters and the pitch file (PITCH.TXT, N1…Q0 lines) as the table",
        ));
    }
    let Some(controller) = detect(text) else {
        return Err(ParseError::new(
            1,
            1,
            "unknown compensation table format: expected a Heidenhain .COM (BEGIN …), a Sinumerik .MPF (%_N_…), a LinuxCNC COMP_FILE (nominal forward reverse), a Fagor 8055 AL<axis> (P0001 X … EX … EX …), a Fagor 8065 .mp (/LSCRWDATA/…) or a Fanuc pitch file (%, N10000Q0P…)",
        ));
    };
    let mut table = match controller {
        Controller::Fanuc => {
            let Some(parameters) = &axis.fanuc else {
                return Err(ParseError::new(
                    1,
                    1,
                    "a Fanuc pitch error compensation file counts in units the parameter backup gives (3620–3624, 1820): give it with --fanuc-parameters CNC-PARA.TXT",
                ));
            };
            fanuc::read(text, parameters)?
        }
        Controller::Fagor8065 => fagor8065::read(text, &axis.axis)?,
        Controller::Fagor8055 => fagor8055::read(text, &axis.axis, options.machine_unit)?,
        Controller::Itnc530 => itnc530::read(text, axis.itnc530_column)?,
        Controller::Tnc640 => tnc640::read(text, &axis.tnc640_column)?,
        Controller::Sinumerik840d => sinumerik840d::read(
            text,
            &axis.sinumerik_axis,
            options.cec_values_are_corrections,
        )?,
        Controller::LinuxCnc => {
            linuxcnc::read(text, &axis.axis, linuxcnc_type, options.file_unit())?
        }
    };
    table.axis = axis.axis.clone();
    // A file does not say whether its numbers are mm or degrees: the axis does.
    table.kind = options.kind;
    Ok((controller, table))
}

/// The controller format of a table file, from its content.
pub fn detect(text: &str) -> Option<Controller> {
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("");
    if fanuc::looks_like(text) {
        Some(Controller::Fanuc)
    } else if fagor8065::looks_like(text) {
        Some(Controller::Fagor8065)
    } else if fagor8055::looks_like(text) {
        Some(Controller::Fagor8055)
    } else if first.starts_with("BEGIN") && first.contains("DATUM") {
        Some(Controller::Itnc530)
    } else if first.starts_with("BEGIN") {
        Some(Controller::Tnc640)
    } else if first.starts_with('%') || text.contains("$AA_ENC_COMP") || text.contains("$AN_CEC") {
        Some(Controller::Sinumerik840d)
    } else if first.split_whitespace().count() == 3 {
        Some(Controller::LinuxCnc)
    } else {
        None
    }
}
