//! The machine's own pitch file updated in place: only the lines of the
//! points the table covers change.

use std::collections::BTreeMap;

use super::{
    check_turn, data_line, increments, new_increments, parameters_for, parse_pitch, read, wanted,
};
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
    for direction in p.directions() {
        increments(&data, &end, &p, *direction).map_err(|e| EmitError::Profile(e.to_string()))?;
    }
    let increments = new_increments(table, &p)?;
    for direction in p.directions() {
        let turn = (p.most_negative..=p.most_positive).map(|point| {
            let at = p.data_point(*direction, point);
            increments.get(&at).copied().unwrap_or(data[&at].value)
        });
        check_turn(&p, turn)?;
    }
    let changed: BTreeMap<usize, String> = increments
        .iter()
        .filter(|(point, value)| data[point].value != **value)
        .map(|(point, value)| (data[point].line.number, data_line(*point, *value)))
        .collect();
    Ok(replace_lines(existing, &changed))
}

/// `text` with the lines numbered in `changed` (from 1) replaced, each
/// keeping its line end; every other byte as it was.
pub(super) fn replace_lines(text: &str, changed: &BTreeMap<usize, String>) -> String {
    let mut out = String::with_capacity(text.len() + 16);
    for (index, segment) in text.split_inclusive('\n').enumerate() {
        match changed.get(&(index + 1)) {
            Some(line) => {
                let content_end = segment.trim_end_matches(['\n', '\r']).len();
                out.push_str(line);
                out.push_str(&segment[content_end..]);
            }
            None => out.push_str(segment),
        }
    }
    out
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
    for direction in p.directions() {
        for (position, value) in table.positions.iter().zip(wanted(table, &p, *direction)) {
            let read = back.value_at(*position, *direction);
            if (read - value).abs() > p.unit() / 2.0 + 1e-12 {
                return Err(EmitError::Internal(format!(
                    "the written fanuc table reads {read} at {position} ({direction:?}), not {value}"
                )));
            }
        }
    }
    Ok(())
}
