//! The thermal log as CSV: read and written.
//!
//! One header line names the columns; a unit may follow a name in brackets
//! or parentheses (`time [min]`, `drift (mm)`, `T3 [°C]`). The time column is
//! `time` or `elapsed` (or `t`) with a unit s, min or h, or
//! `timestamp`/`date`/`datetime` with ISO 8601 date-times (`2024-05-01
//! 12:00:00` or `…T…`); a bare `T` or `t` is a temperature. A log
//! without a time column needs the sample interval (`LogOptions::sample_interval_s`). The
//! drift column is the one the user names; every other column is a
//! temperature (°C unless its header says K or °F). The delimiter is a
//! comma, or `;` or a tab when the header has no comma.
//!
//! A log is refused, at the line and column, for: a row with too few or too
//! many values, a value that is not a number, an empty row between rows, a
//! time that does not increase, a gap (a step more than twice the log's
//! median step: rows are missing, and a lag run across the gap would be
//! wrong), a temperature outside −100…500 °C, a drift beyond ±1 m.

use crate::error::{ParseError, describe_found};
use crate::read::text::{Line, lines, number};
use crate::units::{fahrenheit_to_celsius, mm_to_um};

use super::{Drift, Sensor, ThermalLog};

/// What the user says about a log the file does not.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LogOptions {
    /// The drift column's name (without its unit).
    pub drift: Option<String>,
    /// Read a log without the drift column too (its drift is then `None`):
    /// a model is run over temperatures alone. Without this, a named drift
    /// column the log lacks is refused.
    pub drift_optional: bool,
    /// The time between rows, s, for a log without a time column.
    pub sample_interval_s: Option<f64>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum TimeUnit {
    Seconds(f64),
    Timestamp,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Time(TimeUnit),
    /// The drift, with the factor to µm.
    Drift(f64),
    Temperature(TemperatureUnit),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum TemperatureUnit {
    Celsius,
    Kelvin,
    Fahrenheit,
}

impl TemperatureUnit {
    fn to_celsius(self, value: f64) -> f64 {
        match self {
            TemperatureUnit::Celsius => value,
            TemperatureUnit::Kelvin => value - 273.15,
            TemperatureUnit::Fahrenheit => fahrenheit_to_celsius(value),
        }
    }
}

struct Column {
    name: String,
    role: Role,
}

/// Reads a thermal log from its text.
pub fn parse_log(text: &str, options: &LogOptions) -> Result<ThermalLog, ParseError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut rows = lines(text);
    let header = rows.by_ref().find(|line| !line.is_blank()).ok_or_else(|| {
        ParseError::new(
            1,
            1,
            "expected a header line naming the columns, found an empty file",
        )
    })?;
    let delimiter = delimiter_of(header.text);
    let columns = header_columns(&header, delimiter, options)?;
    let time_column = columns.iter().position(|c| matches!(c.role, Role::Time(_)));
    match (time_column, options.sample_interval_s) {
        (Some(_), Some(_)) => {
            return Err(ParseError::new(
                header.number,
                1,
                "the log has a time column; a sample interval is only for a log without one",
            ));
        }
        (None, None) => {
            return Err(ParseError::new(
                header.number,
                1,
                "the log has no time column (time [s], time [min] or timestamp); give the sample interval (--sample-interval S)",
            ));
        }
        (None, Some(interval)) if !(interval.is_finite() && interval > 0.0) => {
            return Err(ParseError::new(
                header.number,
                1,
                format!("expected a sample interval above 0 s, found {interval}"),
            ));
        }
        _ => {}
    }

    let mut values: Vec<Vec<f64>> = vec![Vec::new(); columns.len()];
    let mut time_cells: Vec<(usize, usize)> = Vec::new();
    let mut row_lines = Vec::new();
    let mut blank: Option<usize> = None;
    let mut first_timestamp: Option<chrono::NaiveDateTime> = None;
    for line in rows {
        if line.is_blank() {
            blank.get_or_insert(line.number);
            continue;
        }
        if let Some(blank_line) = blank {
            return Err(ParseError::new(
                blank_line,
                1,
                "expected a row of values, found an empty line between rows",
            ));
        }
        let cells: Vec<&str> = line.text.split(delimiter).collect();
        if cells.len() != columns.len() {
            let column = if cells.len() > columns.len() {
                line.column_of(cells[columns.len()])
            } else {
                line.end_column()
            };
            return Err(ParseError::new(
                line.number,
                column,
                format!(
                    "expected {} values (one per column of the header), found {}",
                    columns.len(),
                    cells.len()
                ),
            ));
        }
        for ((column, cell), store) in columns.iter().zip(&cells).zip(values.iter_mut()) {
            let token = cell.trim().trim_matches('"');
            let value = cell_value(&line, token, column, &mut first_timestamp)?;
            if let Role::Time(_) = column.role {
                time_cells.push((line.number, line.column_of(token)));
            }
            store.push(value);
        }
        row_lines.push(line.number);
    }
    if row_lines.len() < 2 {
        return Err(ParseError::new(
            crate::read::text::end_of_file_line(text),
            1,
            format!(
                "expected at least two rows of values, found {}",
                row_lines.len()
            ),
        ));
    }
    let times_s = match (time_column, options.sample_interval_s) {
        (Some(index), _) => {
            let times = std::mem::take(&mut values[index]);
            check_times(&times, &time_cells)?;
            let start = times[0];
            times.iter().map(|t| t - start).collect()
        }
        (None, Some(interval)) => (0..row_lines.len()).map(|k| k as f64 * interval).collect(),
        (None, None) => unreachable!("refused above"),
    };
    let mut drift = None;
    let mut sensors = Vec::new();
    for (column, column_values) in columns.into_iter().zip(values) {
        match column.role {
            Role::Time(_) => {}
            Role::Drift(_) => {
                drift = Some(Drift {
                    name: column.name,
                    um: column_values,
                })
            }
            Role::Temperature(_) => sensors.push(Sensor {
                name: column.name,
                celsius: column_values,
            }),
        }
    }
    Ok(ThermalLog {
        times_s,
        drift,
        sensors,
        lines: row_lines,
    })
}

fn delimiter_of(header: &str) -> char {
    if header.contains(',') {
        ','
    } else if header.contains(';') {
        ';'
    } else if header.contains('\t') {
        '\t'
    } else {
        ','
    }
}

/// A header cell's name and unit: `T3 [°C]` → ("T3", Some("°C")).
fn name_and_unit(cell: &str) -> (&str, Option<&str>) {
    let cell = cell.trim().trim_matches('"').trim();
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let Some(stripped) = cell.strip_suffix(close)
            && let Some(at) = stripped.rfind(open)
        {
            return (stripped[..at].trim(), Some(stripped[at + 1..].trim()));
        }
    }
    (cell, None)
}

fn header_columns(
    header: &Line<'_>,
    delimiter: char,
    options: &LogOptions,
) -> Result<Vec<Column>, ParseError> {
    let mut columns: Vec<Column> = Vec::new();
    for cell in header.text.split(delimiter) {
        let (name, unit) = name_and_unit(cell);
        let at = |message: String| header.error_at(cell.trim_start(), message);
        if name.is_empty() {
            return Err(at(
                "expected a column name, found an empty header cell".to_string()
            ));
        }
        if columns.iter().any(|c| c.name == name) {
            return Err(at(format!("the column {name:?} is named twice")));
        }
        let role = if options.drift.as_deref() == Some(name) {
            Role::Drift(drift_factor(unit).ok_or_else(|| {
                at(format!(
                    "expected the drift's unit µm, um, mm or nm, found {}",
                    describe_found(unit.unwrap_or_default())
                ))
            })?)
        } else if let Some(time) = time_unit(name, unit) {
            Role::Time(time.map_err(at)?)
        } else {
            Role::Temperature(temperature_unit(unit).ok_or_else(|| {
                at(format!(
                    "expected a temperature unit °C, C, K or °F for {name:?}, found {}",
                    describe_found(unit.unwrap_or_default())
                ))
            })?)
        };
        columns.push(Column {
            name: name.to_string(),
            role,
        });
    }
    if let Some(drift) = &options.drift
        && !options.drift_optional
        && !columns.iter().any(|c| matches!(c.role, Role::Drift(_)))
    {
        let names: Vec<&str> = columns.iter().map(|c| c.name.as_str()).collect();
        return Err(ParseError::new(
            header.number,
            1,
            format!(
                "expected a column named {drift:?} (the drift), found the columns {}",
                names.join(", ")
            ),
        ));
    }
    if columns
        .iter()
        .filter(|c| matches!(c.role, Role::Time(_)))
        .count()
        > 1
    {
        return Err(ParseError::new(
            header.number,
            1,
            "the log has two time columns",
        ));
    }
    Ok(columns)
}

/// `None`: not a time column; `Some(Err)`: a time column with a unit axcomp does not know.
fn time_unit(name: &str, unit: Option<&str>) -> Option<Result<TimeUnit, String>> {
    let lower = name.to_ascii_lowercase();
    if matches!(
        lower.as_str(),
        "timestamp" | "date" | "datetime" | "date time"
    ) {
        return Some(Ok(TimeUnit::Timestamp));
    }
    // `t` is a time only with a time unit: `T` or `t [°C]` is a temperature.
    let time_units = ["s", "min", "h"];
    if lower == "t" && !unit.is_some_and(|u| time_units.contains(&u)) {
        return None;
    }
    if !matches!(lower.as_str(), "time" | "t" | "elapsed") {
        return None;
    }
    Some(match unit {
        Some("s") => Ok(TimeUnit::Seconds(1.0)),
        Some("min") => Ok(TimeUnit::Seconds(60.0)),
        Some("h") => Ok(TimeUnit::Seconds(3600.0)),
        None => Err(format!(
            "expected the time column's unit ({name} [s], [min] or [h]), found none"
        )),
        Some(other) => Err(format!(
            "expected the time unit s, min or h, found {}",
            describe_found(other)
        )),
    })
}

fn drift_factor(unit: Option<&str>) -> Option<f64> {
    match unit {
        None | Some("µm" | "um" | "μm") => Some(1.0),
        Some("mm") => Some(mm_to_um(1.0)),
        Some("nm") => Some(1e-3),
        Some(_) => None,
    }
}

fn temperature_unit(unit: Option<&str>) -> Option<TemperatureUnit> {
    match unit {
        None | Some("°C" | "C" | "degC" | "℃") => Some(TemperatureUnit::Celsius),
        Some("K") => Some(TemperatureUnit::Kelvin),
        Some("°F" | "F" | "degF") => Some(TemperatureUnit::Fahrenheit),
        Some(_) => None,
    }
}

fn cell_value(
    line: &Line<'_>,
    token: &str,
    column: &Column,
    first_timestamp: &mut Option<chrono::NaiveDateTime>,
) -> Result<f64, ParseError> {
    if token.is_empty() {
        let at = line.text.find(token).map_or(1, |_| line.column_of(token));
        return Err(ParseError::new(
            line.number,
            at,
            format!("expected a value of {:?}, found an empty cell", column.name),
        ));
    }
    match column.role {
        Role::Time(TimeUnit::Timestamp) => {
            let stamp = timestamp(token)
                .ok_or_else(|| line.expected_at(token, "a date-time like 2024-05-01 12:00:00"))?;
            let first = *first_timestamp.get_or_insert(stamp);
            let since = stamp - first;
            Ok(since.num_milliseconds() as f64 / 1000.0)
        }
        Role::Time(TimeUnit::Seconds(factor)) => Ok(number(line, token, "time")? * factor),
        Role::Drift(factor) => {
            let um = number(line, token, "drift")? * factor;
            if um.abs() > 1e6 {
                return Err(line.error_at(token, format!("a drift of {um:.0} µm is beyond ±1 m")));
            }
            Ok(um)
        }
        Role::Temperature(unit) => {
            let celsius = unit.to_celsius(number(line, token, "temperature")?);
            if !(-100.0..=500.0).contains(&celsius) {
                return Err(line.error_at(
                    token,
                    format!("a temperature of {celsius:.2} °C is outside −100…500 °C"),
                ));
            }
            Ok(celsius)
        }
    }
}

fn timestamp(token: &str) -> Option<chrono::NaiveDateTime> {
    [
        "%Y-%m-%dT%H:%M:%S%.f",
        "%Y-%m-%d %H:%M:%S%.f",
        "%Y-%m-%dT%H:%M",
        "%Y-%m-%d %H:%M",
    ]
    .iter()
    .find_map(|format| chrono::NaiveDateTime::parse_from_str(token, format).ok())
}

/// Times strictly increasing, and no step more than twice the median step.
fn check_times(times: &[f64], cells: &[(usize, usize)]) -> Result<(), ParseError> {
    for (k, pair) in times.windows(2).enumerate() {
        if pair[1] <= pair[0] {
            let (line, column) = cells[k + 1];
            return Err(ParseError::new(
                line,
                column,
                format!(
                    "expected a time after the previous row's, found {} s after it",
                    pair[1] - pair[0]
                ),
            ));
        }
    }
    let mut steps: Vec<f64> = times.windows(2).map(|p| p[1] - p[0]).collect();
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    for (k, pair) in times.windows(2).enumerate() {
        let step = pair[1] - pair[0];
        if step > 2.0 * median {
            let (line, column) = cells[k + 1];
            return Err(ParseError::new(
                line,
                column,
                format!(
                    "a gap: {step} s after the previous row, where the log's step is {median} s; rows are missing"
                ),
            ));
        }
    }
    Ok(())
}

/// A thermal log as CSV (`time [s]`, the drift in µm, the temperatures in
/// °C), which [`parse_log`] reads back with the drift's name.
pub fn write_log(log: &ThermalLog) -> String {
    let mut text = String::from("time [s]");
    if let Some(drift) = &log.drift {
        text.push_str(&format!(",{} [µm]", drift.name));
    }
    for sensor in &log.sensors {
        text.push_str(&format!(",{} [°C]", sensor.name));
    }
    text.push('\n');
    for (row, t) in log.times_s.iter().enumerate() {
        text.push_str(&format!("{t}"));
        if let Some(drift) = &log.drift {
            text.push_str(&format!(",{:.4}", drift.um[row]));
        }
        for sensor in &log.sensors {
            text.push_str(&format!(",{:.4}", sensor.celsius[row]));
        }
        text.push('\n');
    }
    text
}
