//! What a controller's format adds to writing a table, so that no caller
//! decides by controller: the requests a format cannot take, the grid a
//! control's own parameters fix, an update of the table that was active
//! (into the table, or point by point into the active file itself), and the
//! notes its user reads before loading the file.

use crate::compensate::CompensationTable;
use crate::compensate::plan::Request;
use crate::compensate::update::{UpdatePlan, UpdateSummary};

use super::{Controller, EmitError, EmitOptions, decode_table, fagor8065, fanuc, write_bytes};

/// Refuses what `controller` cannot be asked for: a Fagor 8065 table
/// without its exported parameter file (`existing`), and a rescaled file
/// (`rescaled`) of a controller other than Fanuc.
pub fn check_request(
    controller: Controller,
    existing: Option<&[u8]>,
    rescaled: bool,
) -> Result<(), EmitError> {
    if controller == Controller::Fagor8065 && !existing.is_some_and(fagor8065::is_parameter_file) {
        return Err(EmitError::Profile(fagor8065::NEEDS_EXPORT.to_string()));
    }
    if rescaled && controller != Controller::Fanuc {
        return Err(EmitError::Profile(
            "--fanuc-rescaled is for --controller fanuc".into(),
        ));
    }
    Ok(())
}

/// The grid of a table: `request`, or for a Fanuc control with a parameter
/// backup (`options`), the points its parameters fix over the targets
/// (3620–3624); a grid asked for beside the backup is refused.
pub fn grid(
    controller: Controller,
    request: &Request,
    options: &EmitOptions,
    targets_mm: &[f64],
) -> Result<Request, EmitError> {
    let parameters = match (
        controller,
        options.axes.first().and_then(|a| a.fanuc.as_ref()),
    ) {
        (Controller::Fanuc, Some(parameters)) => parameters,
        _ => return Ok(*request),
    };
    if request.step.is_some() || request.start.is_some() || request.reference.is_some() {
        return Err(EmitError::Profile(format!(
            "the Fanuc parameter backup fixes the compensation points and the reference ({}): leave out --step, --start, --count and --reference",
            parameters.settings()
        )));
    }
    let (Some(first), Some(last)) = (targets_mm.first(), targets_mm.last()) else {
        return Ok(*request);
    };
    let (start_mm, count) =
        fanuc::points_in(parameters, *first, *last).map_err(EmitError::Profile)?;
    Ok(Request {
        step: Some(parameters.interval),
        start: Some(start_mm),
        count: Some(count),
        reference: Some(parameters.position(parameters.reference_point)),
        ..*request
    })
}

/// A table as written for its controller.
#[derive(Debug)]
pub struct Written {
    /// What the controller loads, byte for byte.
    pub bytes: Vec<u8>,
    /// The table the file holds (an update applied).
    pub table: CompensationTable,
    /// What the update of the table that was active did, when there was one.
    pub update: Option<UpdateSummary>,
    /// What the user reads before loading the file (Fanuc: the
    /// magnification, the points, the 3605 bits).
    pub notes: Vec<String>,
    /// Whether `notes` say what the table that was active was read as (the
    /// 3605 bits of a Fanuc backup), so that a note of reading it is not
    /// said again.
    pub notes_say_how_read: bool,
}

/// Writes `table` for `controller` ([`write_bytes`]), with `update` (the
/// plan's update of the table that was active, `existing` its file) made
/// where the format keeps it: into the table, whose values the file holds,
/// or, for a Fanuc pitch file, whose data are increments, point by point
/// into the active file itself, where the points outside the new table keep
/// their increments (`fanuc::update`, `fanuc::update_summary`).
pub fn write_updated(
    controller: Controller,
    table: CompensationTable,
    options: &EmitOptions,
    existing: Option<&[u8]>,
    update: Option<&UpdatePlan>,
) -> Result<Written, EmitError> {
    if controller == Controller::Fanuc {
        let bytes = write_bytes(controller, &table, options, existing)?;
        let pitch_file = existing
            .and_then(|bytes| decode_table(bytes).ok())
            .filter(|(text, _)| fanuc::looks_like(text));
        let update = match (update, pitch_file) {
            (Some(plan), Some((text, _))) => {
                Some(fanuc::update_summary(&text, &table, options, plan)?)
            }
            _ => None,
        };
        let notes = fanuc::notes(&table, options);
        return Ok(Written {
            bytes,
            table,
            update,
            notes,
            notes_say_how_read: true,
        });
    }
    let (table, update) = match update {
        Some(plan) => {
            let (updated, summary) = plan.apply(table);
            (updated, Some(summary))
        }
        None => (table, None),
    };
    let bytes = write_bytes(controller, &table, options, existing)?;
    Ok(Written {
        bytes,
        table,
        update,
        notes: Vec::new(),
        notes_say_how_read: false,
    })
}

/// The Fanuc pitch file at a finer magnification (3623) beside `table`,
/// `existing` the file that was active (`fanuc::rescaled`).
pub fn fanuc_rescaled(
    existing: Option<&[u8]>,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<fanuc::Rescaled, EmitError> {
    let existing = existing.and_then(|bytes| decode_table(bytes).ok());
    let existing = existing.as_ref().map(|(text, _)| text.as_str());
    fanuc::rescaled(existing, table, options, None)
}
