//! The pitch error compensation data written: a table of axcomp's turned
//! into the increments of the control's points, and a new pitch file.

use std::collections::BTreeMap;

use super::{AxisParameters, POINT_RANGE, data_line, magnification_for};
use crate::compensate::{CompensationTable, TableMode};
use crate::emit::{EmitError, EmitOptions};
use crate::measurement::{AxisKind, Direction};

/// The fewest of the control's points a test must cover to make a table.
const MIN_POINTS: usize = 3;

/// The control's points inside the measured range `first_mm ..= last_mm`:
/// the first one's position and their count; refused when the reference
/// point is not among them (the new compensation is zero there, which only
/// a measurement across it can tell).
pub fn points_in(p: &AxisParameters, first_mm: f64, last_mm: f64) -> Result<(f64, usize), String> {
    let inside: Vec<i64> = (p.first_point()..=p.most_positive)
        .filter(|n| {
            let x = p.position(*n);
            x >= first_mm - 1e-6 && x <= last_mm + 1e-6
        })
        .collect();
    let reference = p.position(p.reference_point);
    let all = p.most_positive - p.first_point() + 1;
    let (low, high) = (p.position(p.first_point()), p.position(p.most_positive));
    let unit = p.length_unit();
    // A table of one or two points is no compensation (one section, and a
    // test that far off the axis' points is most likely in other
    // coordinates than the control's machine coordinates).
    if inside.len() < MIN_POINTS {
        return Err(format!(
            "the measured range {first_mm} … {last_mm} {unit} holds {} of the {all} compensation points of axis {} ({low} … {high} {unit}, {}): too few for a table; check that the test's positions are the control's machine coordinates (1240 = {} {unit} at the reference point 3620 = {}) and measure over the axis' points",
            inside.len(),
            p.axis,
            p.source,
            p.reference_position,
            p.reference_point
        ));
    }
    match (inside.first(), inside.last()) {
        (Some(a), Some(b)) if (*a..=*b).contains(&p.reference_point) => {
            Ok((p.position(*a), inside.len()))
        }
        _ => Err(format!(
            "the reference point 3620 = {} of axis {} is at {reference} {unit} ({}), outside the measured range {first_mm} … {last_mm} {unit}: the Fanuc compensation is zero there, so the test must reach it",
            p.reference_point, p.axis, p.source
        )),
    }
}

/// What to tell the user of a table written with `p`: a magnification too
/// coarse for the error, with the one that would do (every point rescaled).
pub fn notes(table: &CompensationTable, options: &EmitOptions) -> Vec<String> {
    let Ok(p) = parameters_for(table, options) else {
        return Vec::new();
    };
    let values = table.values.for_direction(Direction::Up);
    let (low, high) = values
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let range = high - low;
    // The finest magnification whose points still hold every section's change.
    let finest = finest_for_sections(&[values], p.detection_unit);
    let mut notes = Vec::new();
    let all = (p.most_positive - p.first_point() + 1) as usize;
    if p.from_backup && table.positions.len() * 2 < all {
        notes.push(format!(
            "Fanuc: the test covers {} of the {all} compensation points of axis {} ({} … {} {}); this test does not check the others (an updated file keeps their increments, a new one holds none there: the values at the table's ends continue)",
            table.positions.len(),
            p.axis,
            p.position(p.first_point()),
            p.position(p.most_positive),
            p.length_unit()
        ));
    }
    if let Some(note) = unknown_bits_note(&p, BitsUse::Written) {
        notes.push(note);
    }
    if let Some(k) = closing_point(table, &p) {
        let closure = values[k] - values[0];
        if closure.abs() > p.unit() / 2.0 {
            notes.push(format!(
                "Fanuc: the points of one turn sum to zero (0i-PB parameter manual): the measured {}° between the start and the end of the turn is left out",
                crate::emit::minimal(closure, 6)
            ));
        }
    }
    if p.unit() > range / 10.0 && finest < p.magnification {
        notes.push(format!(
            "Fanuc: 3623 = {} gives steps of {}, coarse for an error of {} peak to valley; 3623 = {finest} would give {} steps (every point of the axis rescaled by {}/{finest}, the parameter changed with the data: convert --fanuc-rescaled FILE writes it)",
            p.magnification,
            p.unit_text(p.unit()),
            p.unit_text((range * 1e4).round() / 1e4),
            p.unit_text(p.detection_unit * finest as f64),
            p.magnification
        ));
    }
    notes
}

/// What axcomp did with pitch data under a 3605 it does not fully know.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BitsUse {
    /// Wrote a file (`convert`): the user checks before loading it.
    Written,
    /// Read the control's file and computed with it (`predict`,
    /// `diagnose`, `report`): the user checks before relying on the numbers.
    Read,
}

/// The bits of 3605 besides #0 the backup sets, said: their meaning on the
/// control was not found (`formats/fanuc/README.md`), so the user checks
/// them before loading a table axcomp computed without them, or before
/// relying on numbers computed from the control's table read without them.
pub fn unknown_bits_note(p: &AxisParameters, used: BitsUse) -> Option<String> {
    let bits = p.unknown_3605_bits();
    if bits.is_empty() {
        return None;
    }
    let list: Vec<String> = bits.iter().map(|b| format!("#{b}")).collect();
    // Between the points, the prediction and the diagnosis interpolate the
    // absolute compensation linearly (`CompensationTable::value_at`).
    let (done, before) = match used {
        BitsUse::Written => (
            "wrote the data as 3620–3627 alone describe them",
            "before loading the file",
        ),
        BitsUse::Read => (
            "read the data as 3620–3627 alone describe them (the compensation at each point, linear between the points)",
            "before relying on what is computed with this table",
        ),
    };
    Some(format!(
        "Fanuc: 3605 of axis {} is {} in the parameter backup ({}): {} {} set besides #0 (bidirectional pitch error compensation); axcomp does not know what {} changes (no public Fanuc manual page giving it was found) and {done}: check {} in the control's parameter manual {before}",
        p.axis,
        p.bits_3605,
        p.at_3605,
        if bits.len() == 1 { "bit" } else { "bits" },
        list.join(", "),
        if bits.len() == 1 { "it" } else { "they" },
        list.iter()
            .map(|b| format!("3605{b}"))
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// The parameters a table is written with: the backup's, or axcomp's
/// defaults for the table's own grid.
pub fn parameters_for(
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<AxisParameters, EmitError> {
    let axis = options.axes.first().map_or("X", |a| a.axis.as_str());
    let mut p = match options.axes.first().and_then(|a| a.fanuc.clone()) {
        Some(p) => p,
        None => default_parameters(table, options, axis)?,
    };
    if p.bidirectional && table.values.mode() == TableMode::Bidirectional {
        // 3627: the ↓ table's absolute compensation at the reference position.
        let at = table
            .positions
            .iter()
            .position(|x| (x - p.position(p.reference_point)).abs() < 1e-6);
        if let Some(k) = at {
            p.reference_negative = absolute_units_of(table, &p, Direction::Down)[k];
        }
    }
    Ok(p)
}

/// axcomp's numbering for a table without a parameter backup: its own
/// grid, points 0 … count − 1, with 3605#0 the ↓ table right after.
fn default_parameters(
    table: &CompensationTable,
    options: &EmitOptions,
    axis: &str,
) -> Result<AxisParameters, EmitError> {
    let step = table.regular_step().ok_or(EmitError::UnevenSpacing {
        controller: "fanuc",
    })?;
    let reference = table
        .positions
        .iter()
        .position(|x| (x - table.reference).abs() < 1e-9)
        .ok_or_else(|| {
            EmitError::Profile(format!(
                "a Fanuc table is zero at a compensation point (3620); {} mm is none: give --reference at a point",
                table.reference
            ))
        })?;
    let mut p = AxisParameters::default_for(
        axis,
        table.positions.len(),
        step,
        reference,
        table.reference,
    );
    p.rotary = options.kind == AxisKind::Rotary;
    if p.rotary {
        p.travel_per_turn = 360.0;
    }
    if table.values.mode() == TableMode::Bidirectional {
        p.bidirectional = true;
        p.negative_first = p.most_positive + 1;
    }
    Ok(p)
}

/// The new increments of the points the table covers, in units, by data
/// point (with 3605#0 the ↓ table's at 3626 …): the absolute compensation
/// −value rounded at each point (the rounding carried, never accumulated),
/// differenced. Only points whose section lies inside the table get one.
pub(super) fn new_increments(
    table: &CompensationTable,
    p: &AxisParameters,
) -> Result<BTreeMap<i64, i64>, EmitError> {
    check_mode(table, p)?;
    let mut points = Vec::with_capacity(table.positions.len());
    for position in &table.positions {
        let point = p
            .point_at(*position)
            .filter(|n| (p.first_point()..=p.most_positive).contains(n))
            .ok_or_else(|| {
                EmitError::Profile(format!(
                    "{position} is no compensation point of axis {} (1240 + (n − 3620) × 3624 for n = {} … {}; {}): build the table on the control's points",
                    p.axis,
                    p.first_point(),
                    p.most_positive,
                    p.source
                ))
            })?;
        points.push(point);
    }
    if (table.reference - p.position(p.reference_point)).abs() > 1e-9 {
        return Err(EmitError::Profile(format!(
            "the Fanuc compensation is zero at the reference point 3620 = {} ({} = {} mm); the table is zero at {} mm: give --reference {} (inside the measured range)",
            p.reference_point,
            p.axis,
            p.position(p.reference_point),
            table.reference,
            p.position(p.reference_point)
        )));
    }
    for k in 1..points.len() {
        if points[k] != points[k - 1] + 1 {
            return Err(EmitError::Profile(format!(
                "the table's points must be consecutive compensation points of axis {} ({} mm apart, 3624)",
                p.axis, p.interval
            )));
        }
    }
    let mut increments = BTreeMap::new();
    for direction in p.directions() {
        let absolute = absolute_units_of(table, p, *direction);
        for k in 1..points.len() {
            increments.insert(
                p.data_point(*direction, points[k]),
                absolute[k].saturating_sub(absolute[k - 1]),
            );
        }
    }
    check_limits(&increments, p)?;
    Ok(increments)
}

/// The absolute compensation the table asks for at its points in
/// `direction`, in units, rounded at each point.
fn absolute_units_of(
    table: &CompensationTable,
    p: &AxisParameters,
    direction: Direction,
) -> Vec<i64> {
    let unit = p.unit();
    wanted(table, p, direction)
        .iter()
        .map(|v| (-v / unit).round() as i64)
        .collect()
}

/// A table the axis' parameters hold: one column without 3605#0, one per
/// direction with it.
fn check_mode(table: &CompensationTable, p: &AxisParameters) -> Result<(), EmitError> {
    match (table.values.mode(), p.bidirectional) {
        (TableMode::Mean, false) | (TableMode::Bidirectional, true) => Ok(()),
        (TableMode::Bidirectional, false) => Err(EmitError::Profile(format!(
            "3605#0 of axis {} is 0 in the parameter backup (3605 = {} at {}): the control compensates pitch error the same in both directions; for a table per direction (if the control has bidirectional pitch error compensation) set 3605#0 = 1 and 3626 to the first of {} free points, give the changed backup and convert again; else use --mode mean and set the backlash parameters 1851/1852",
            p.axis,
            p.bits_3605,
            p.at_3605,
            p.most_positive - p.most_negative + 1
        ))),
        (TableMode::Mean, true) => Err(EmitError::Profile(format!(
            "3605#0 of axis {} is 1 in the parameter backup: the control holds a table per direction (3621 … 3622 and 3626 = {} …): convert with --mode bidirectional",
            p.axis, p.negative_first
        ))),
    }
}

/// The table's values in `direction` as the control can hold them: from
/// the ↑ value at the reference point (the control's zero), and \[manual\]
/// 0i-PB p.100, on a rotary axis the points of one turn sum to zero, else
/// the error accumulates turn after turn: the end of a full turn takes the
/// start's value (`notes` says what is dropped).
pub(super) fn wanted(
    table: &CompensationTable,
    p: &AxisParameters,
    direction: Direction,
) -> Vec<f64> {
    let zero = table.value_at(p.position(p.reference_point), Direction::Up);
    let mut values: Vec<f64> = table
        .values
        .for_direction(direction)
        .iter()
        .map(|v| v - zero)
        .collect();
    if let Some(k) = closing_point(table, p) {
        values[k] = values[0];
    }
    values
}

/// \[manual\] 0i-PB p.100: "If the sum of the compensation value from 61 to
/// 68 is not zero, the pitch error per rotation accumulates, resulting in a
/// positional shift": on a rotary axis whose points 3621 … 3622 span one
/// turn (3625, 0 for 360°), `increments` (theirs, in order) must sum to 0.
pub(super) fn check_turn(
    p: &AxisParameters,
    increments: impl Iterator<Item = i64>,
) -> Result<(), EmitError> {
    let turn = if p.travel_per_turn > 0.0 {
        p.travel_per_turn
    } else {
        360.0
    };
    let span = (p.most_positive - p.most_negative + 1) as f64 * p.interval;
    if !p.rotary || (span - turn).abs() > 1e-6 {
        return Ok(());
    }
    let sum: i64 = increments.sum();
    if sum == 0 {
        return Ok(());
    }
    Err(EmitError::Profile(format!(
        "the points {} … {} of rotary axis {} span one turn ({}°) and must sum to zero, or the error accumulates turn after turn (0i-PB parameter manual); with the new values they sum to {sum} units ({}°): measure the whole turn (0 … {}°) so that every point is new",
        p.most_negative,
        p.most_positive,
        p.axis,
        crate::emit::minimal(turn, 4),
        crate::emit::minimal(sum as f64 * p.unit(), 7),
        crate::emit::minimal(turn, 4)
    )))
}

/// On a rotary axis, the index of the table point one turn after its first
/// point (3625, 0 for 360°), when the table reaches it.
fn closing_point(table: &CompensationTable, p: &AxisParameters) -> Option<usize> {
    if !p.rotary {
        return None;
    }
    let turn = if p.travel_per_turn > 0.0 {
        p.travel_per_turn
    } else {
        360.0
    };
    let first = table.positions.first()?;
    table
        .positions
        .iter()
        .position(|x| (x - first - turn).abs() < 1e-6)
}

/// The finest magnification whose points hold every section of `columns`
/// (errors, mm or °): a section's increment is the change of the
/// compensation, the negative of the error's, in detection units.
pub(super) fn finest_for_sections(columns: &[&[f64]], detection_unit: f64) -> i64 {
    columns
        .iter()
        .flat_map(|c| c.windows(2).map(|w| -(w[1] - w[0]) / detection_unit))
        .map(magnification_for)
        .fold(1, i64::max)
}

/// Refuses increments beyond a point's range ([`POINT_RANGE`]), naming the
/// magnification that would hold them.
fn check_limits(increments: &BTreeMap<i64, i64>, p: &AxisParameters) -> Result<(), EmitError> {
    let Some((&point, &value)) = increments.iter().find(|(_, v)| !POINT_RANGE.contains(v)) else {
        return Ok(());
    };
    let needed = increments
        .values()
        .map(|v| magnification_for(*v as f64 * p.magnification as f64))
        .fold(1, i64::max);
    Err(EmitError::Profile(format!(
        "point {point} of axis {} needs {value} × {} = {}, beyond the {} … {} units a point holds (3623 = {}): set 3623 = {needed} (every point rescaled; units of {}) and convert again",
        p.axis,
        p.unit_text(p.unit()),
        p.unit_text(value as f64 * p.unit()),
        POINT_RANGE.start(),
        POINT_RANGE.end(),
        p.magnification,
        p.unit_text(p.detection_unit * needed as f64)
    )))
}

/// A new pitch file with the points of the table's axis: `%`, the data
/// lines of points 3621 − 1 … 3622 (the sections outside the table hold
/// the compensation: 0), with 3605#0 those of 3626 …, `%`, LF, as the
/// real backup.
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let p = parameters_for(table, options)?;
    let increments = new_increments(table, &p)?;
    let mut out = String::from("%\n");
    for direction in p.directions() {
        let first = match direction {
            Direction::Up => p.first_point(),
            Direction::Down => p.most_negative,
        };
        let mut turn = Vec::new();
        for point in first..=p.most_positive {
            let at = p.data_point(*direction, point);
            let value = increments.get(&at).copied().unwrap_or(0);
            let value = rotary_reference_value(&p, *direction, point, value, &increments);
            out.push_str(&data_line(at, value));
            out.push('\n');
            if point >= p.most_negative {
                turn.push(value);
            }
        }
        check_turn(&p, turn.into_iter())?;
    }
    out.push('%');
    Ok(out)
}

/// \[manual\] 0i-PB B-63980EN/01 p.100: on a rotary axis whose most negative
/// point is the reference point, the reference point holds the value of the
/// most positive one.
fn rotary_reference_value(
    p: &AxisParameters,
    direction: Direction,
    point: i64,
    value: i64,
    increments: &BTreeMap<i64, i64>,
) -> i64 {
    if p.rotary && point == p.reference_point && p.most_negative == p.reference_point {
        let last = p.data_point(direction, p.most_positive);
        return increments.get(&last).copied().unwrap_or(value);
    }
    value
}
