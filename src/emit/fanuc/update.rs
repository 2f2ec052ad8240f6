//! The machine's own pitch file updated in place: only the lines of the
//! points the table covers change.

use std::collections::BTreeMap;

use super::{
    check_turn, data_line, increments, new_increments, parameters_for, parse_pitch, read, wanted,
};
use crate::compensate::CompensationTable;
use crate::compensate::update::{DataLines, KeptAs, KeptRange, Moved, UpdatePlan, UpdateSummary};
use crate::emit::{EmitError, EmitOptions};
use crate::measurement::Direction;

/// The pitch file `existing` with the points the table covers replaced:
/// every other line, and every line end, as it was.
pub fn update(
    existing: &str,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<String, EmitError> {
    let (changed, _) = changed_lines(existing, table, options)?;
    Ok(replace_lines(existing, &changed))
}

/// What [`update`] changes in `existing` for `table` under `plan`: the
/// table's points updated (the data lines of their sections written, those
/// that differ counted), and every other point of the axis kept with its
/// increment, its value moved by the change at the end of the table next to
/// it: read from the file written and the file as it was.
pub fn update_summary(
    existing: &str,
    table: &CompensationTable,
    options: &EmitOptions,
    plan: &UpdatePlan,
) -> Result<UpdateSummary, EmitError> {
    let (changed, sections) = changed_lines(existing, table, options)?;
    let written = replace_lines(existing, &changed);
    let p = parameters_for(table, options)?;
    // The backup's 3627 read the existing ↓ data; the new one the written.
    let old_p = options
        .axes
        .first()
        .and_then(|a| a.fanuc.clone())
        .unwrap_or_else(|| p.clone());
    let internal = |e: crate::error::ParseError| EmitError::Internal(e.to_string());
    let old = read(existing, &old_p).map_err(internal)?;
    let new = read(&written, &p).map_err(internal)?;
    let (first, last) = (
        table.positions[0],
        table.positions[table.positions.len() - 1],
    );
    let moved_at = |x: f64| Moved {
        with: x,
        by: Direction::BOTH.map(|d| new.value_at(x, d) - old.value_at(x, d)),
    };
    let (mut kept, mut kept_points): (Vec<KeptRange>, Vec<f64>) = (Vec::new(), Vec::new());
    for &x in &old.positions {
        let end = match x {
            x if x < first - 1e-6 => first,
            x if x > last + 1e-6 => last,
            _ => continue,
        };
        kept_points.push(x);
        match kept.last_mut() {
            // One run a side: every point of it moved as its end did.
            Some(run) if (run.first < first) == (x < first) => {
                run.last = x;
                run.count += 1;
            }
            _ => kept.push(KeptRange {
                first: x,
                last: x,
                count: 1,
                moved: Some(moved_at(end)),
            }),
        }
    }
    Ok(UpdateSummary {
        kept_points,
        kept,
        kept_as: KeptAs::Increments,
        data_lines: Some(DataLines {
            sections,
            changed: changed.len(),
        }),
        measured: plan.measured,
        updated: table.positions.len(),
        reference: table.reference,
        existing_at_reference: old.value_at(table.reference, Direction::Up),
        // The Fanuc compensation is zero at the reference point 3620, the
        // only reference a Fanuc table takes (`new_increments`).
        at_existing_zero: true,
        dropped: Vec::new(),
        added: Vec::new(),
        kind: table.kind,
    })
}

/// The data lines [`update`] rewrites in `existing` (by line number, from
/// 1: those whose value changes), and how many sections the table covers.
fn changed_lines(
    existing: &str,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<(BTreeMap<usize, String>, usize), EmitError> {
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
    Ok((changed, increments.len()))
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
