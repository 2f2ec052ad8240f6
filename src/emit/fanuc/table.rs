//! The pitch error compensation data written: a table of axcomp's turned
//! into the increments of the control's points, and a new pitch file.

use std::collections::BTreeMap;

use super::{AxisParameters, POINT_LIMIT, data_line};
use crate::compensate::{CompensationTable, TableMode};
use crate::emit::{EmitError, EmitOptions};
use crate::measurement::AxisKind;

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
    match (inside.first(), inside.last()) {
        (Some(a), Some(b)) if (*a..=*b).contains(&p.reference_point) => {
            Ok((p.position(*a), inside.len()))
        }
        _ => Err(format!(
            "the reference point 3620 = {} of axis {} is at {reference} ({}), outside the measured range {first_mm} … {last_mm}: the Fanuc compensation is zero there, so the test must reach it",
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
    let values = table
        .values
        .for_direction(crate::measurement::Direction::Up);
    let (low, high) = values
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let range = high - low;
    let largest_step = values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    // The finest magnification whose points still hold every section's change.
    let finest = ((largest_step / p.detection_unit / POINT_LIMIT as f64).ceil() as i64).max(1);
    let mut notes = Vec::new();
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
            "Fanuc: 3623 = {} gives steps of {} mm, coarse for an error of {} mm peak to valley; 3623 = {finest} would give {} mm steps (every point of the axis rescaled by {}/{finest}, the parameter changed with the data)",
            p.magnification,
            crate::emit::minimal(p.unit(), 7),
            crate::emit::minimal(range, 4),
            crate::emit::minimal(p.detection_unit * finest as f64, 7),
            p.magnification
        ));
    }
    notes
}

/// The parameters a table is written with: the backup's, or axcomp's
/// defaults for the table's own grid.
pub fn parameters_for(
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<AxisParameters, EmitError> {
    let axis = options.axes.first().map_or("X", |a| a.axis.as_str());
    if let Some(p) = options.axes.first().and_then(|a| a.fanuc.clone()) {
        return Ok(p);
    }
    let step = table.regular_step_mm().ok_or(EmitError::UnevenSpacing {
        controller: "fanuc",
    })?;
    let reference = table
        .positions_mm
        .iter()
        .position(|x| (x - table.reference_mm).abs() < 1e-9)
        .ok_or_else(|| {
            EmitError::Profile(format!(
                "a Fanuc table is zero at a compensation point (3620); {} mm is none: give --reference at a point",
                table.reference_mm
            ))
        })?;
    let mut p = AxisParameters::default_for(
        axis,
        table.positions_mm.len(),
        step,
        reference,
        table.reference_mm,
    );
    p.rotary = options.kind == AxisKind::Rotary;
    if p.rotary {
        p.travel_per_turn = 360.0;
    }
    Ok(p)
}

/// The new increments of the points the table covers, in units: the
/// absolute compensation −value rounded at each point (the rounding
/// carried, never accumulated), differenced. Only points whose section lies
/// inside the table get one.
pub(super) fn new_increments(
    table: &CompensationTable,
    p: &AxisParameters,
) -> Result<BTreeMap<i64, i64>, EmitError> {
    if table.values.mode() == TableMode::Bidirectional {
        return Err(EmitError::NoBidirectional {
            controller: "fanuc",
        });
    }
    let mut points = Vec::with_capacity(table.positions_mm.len());
    for position in &table.positions_mm {
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
    if (table.reference_mm - p.position(p.reference_point)).abs() > 1e-9 {
        return Err(EmitError::Profile(format!(
            "the Fanuc compensation is zero at the reference point 3620 = {} ({} = {} mm); the table is zero at {} mm: give --reference {} (inside the measured range)",
            p.reference_point,
            p.axis,
            p.position(p.reference_point),
            table.reference_mm,
            p.position(p.reference_point)
        )));
    }
    let unit = p.unit();
    let absolute: Vec<i64> = wanted(table, p)
        .iter()
        .map(|v| (-v / unit).round() as i64)
        .collect();
    let mut increments = BTreeMap::new();
    for k in 1..points.len() {
        if points[k] != points[k - 1] + 1 {
            return Err(EmitError::Profile(format!(
                "the table's points must be consecutive compensation points of axis {} ({} mm apart, 3624)",
                p.axis, p.interval
            )));
        }
        increments.insert(points[k], absolute[k].saturating_sub(absolute[k - 1]));
    }
    check_limits(&increments, p)?;
    Ok(increments)
}

/// The table's values as the control can hold them: \[manual\] 0i-PB
/// p.100, on a rotary axis the points of one turn sum to zero, else the
/// error accumulates turn after turn: the end of a full turn takes the
/// start's value (`notes` says what is dropped).
pub(super) fn wanted(table: &CompensationTable, p: &AxisParameters) -> Vec<f64> {
    let mut values = table
        .values
        .for_direction(crate::measurement::Direction::Up)
        .to_vec();
    if let Some(k) = closing_point(table, p) {
        values[k] = values[0];
    }
    values
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
    let first = table.positions_mm.first()?;
    table
        .positions_mm
        .iter()
        .position(|x| (x - first - turn).abs() < 1e-6)
}

/// Refuses increments beyond a point's limit, naming the magnification that would hold them.
fn check_limits(increments: &BTreeMap<i64, i64>, p: &AxisParameters) -> Result<(), EmitError> {
    let Some((&point, &value)) = increments.iter().max_by_key(|(_, v)| v.unsigned_abs()) else {
        return Ok(());
    };
    if value.unsigned_abs() <= POINT_LIMIT as u64 {
        return Ok(());
    }
    let needed =
        (value.unsigned_abs() as f64 * p.magnification as f64 / POINT_LIMIT as f64).ceil() as i64;
    Err(EmitError::Profile(format!(
        "point {point} of axis {} needs {value} × {} = {} mm, beyond ±{POINT_LIMIT} units a point holds (3623 = {}): set 3623 = {needed} (every point rescaled; units of {} mm) and convert again",
        p.axis,
        crate::emit::minimal(p.unit(), 7),
        crate::emit::minimal(value as f64 * p.unit(), 7),
        p.magnification,
        crate::emit::minimal(p.detection_unit * needed as f64, 7)
    )))
}

/// A new pitch file with the points of the table's axis: `%`, the data
/// lines of points 3621 − 1 … 3622 (the sections outside the table hold
/// the compensation: 0), `%`, LF, as the real backup.
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let p = parameters_for(table, options)?;
    let increments = new_increments(table, &p)?;
    let mut out = String::from("%\n");
    for point in p.first_point()..=p.most_positive {
        let value = increments.get(&point).copied().unwrap_or(0);
        out.push_str(&data_line(
            point,
            rotary_reference_value(&p, point, value, &increments),
        ));
        out.push('\n');
    }
    out.push('%');
    Ok(out)
}

/// \[manual\] 0i-PB B-63980EN/01 p.100: on a rotary axis whose most negative
/// point is the reference point, the reference point holds the value of the
/// most positive one.
fn rotary_reference_value(
    p: &AxisParameters,
    point: i64,
    value: i64,
    increments: &BTreeMap<i64, i64>,
) -> i64 {
    if p.rotary && point == p.reference_point && p.most_negative == p.reference_point {
        return increments.get(&p.most_positive).copied().unwrap_or(value);
    }
    value
}
