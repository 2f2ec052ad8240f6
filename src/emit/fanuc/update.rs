//! The machine's own pitch file updated in place: only the lines of the
//! points the table covers change.

use std::collections::BTreeMap;

use super::{data_line, increments, new_increments, parameters_for, parse_pitch, read, wanted};
use crate::compensate::CompensationTable;
use crate::emit::{EmitError, EmitOptions};

/// The pitch file `existing` with the points the table covers replaced:
/// every other line, and every line end, as it was.
pub fn update(
    existing: &str,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<String, EmitError> {
    let p = parameters_for(table, options)?;
    let (data, end) = parse_pitch(existing).map_err(|e| EmitError::Profile(e.to_string()))?;
    increments(&data, &end, &p).map_err(|e| EmitError::Profile(e.to_string()))?;
    let increments = new_increments(table, &p)?;
    let changed: BTreeMap<usize, String> = increments
        .iter()
        .filter(|(point, value)| data[point].value != **value)
        .map(|(point, value)| (data[point].line.number, data_line(*point, *value)))
        .collect();
    let mut out = String::with_capacity(existing.len() + 16);
    for (index, segment) in existing.split_inclusive('\n').enumerate() {
        match changed.get(&(index + 1)) {
            Some(line) => {
                let content_end = segment.trim_end_matches(['\n', '\r']).len();
                out.push_str(line);
                out.push_str(&segment[content_end..]);
            }
            None => out.push_str(segment),
        }
    }
    Ok(out)
}

/// Whether the written text reads back to the table at its points, within
/// half a unit.
pub fn check_read_back(
    text: &str,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<(), EmitError> {
    let p = parameters_for(table, options)?;
    let back = read(text, &p).map_err(|e| {
        EmitError::Internal(format!("the written fanuc table does not read back: {e}"))
    })?;
    for (position, value) in table.positions_mm.iter().zip(wanted(table, &p)) {
        let read = back.value_at(*position, crate::measurement::Direction::Up);
        if (read - value).abs() > p.unit() / 2.0 + 1e-12 {
            return Err(EmitError::Internal(format!(
                "the written fanuc table reads {read} at {position}, not {value}"
            )));
        }
    }
    Ok(())
}
