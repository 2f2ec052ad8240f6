//! API (Automated Precision Inc.) XD laser `.pos` linear data tables: parser.
//!
//! What is known of the format (`../shared/notes/controller-and-laser-formats.md` §2,
//! real files in `../shared/data/api-xd/`): CRLF, tab-separated; a header of
//! `Key: value` cells (`Unit: inch`, `TestAxis: (X)`, `RunNum: 1`,
//! `NumofPoints: 27`, `Humidity: 50`, `ExpCoef: 6.7`, …); a data table whose
//! header names the columns `Position LasRead LinearError Status AirTemp
//! AirPress MatTemp MatTemp2 MatTemp3`; then summary tables this reader does
//! not need (compensation, standard deviation, analysis), and `ErrorUnit:`.
//!
//! The deviation is the `LinearError` column: actual − target, in `ErrorUnit`
//! (default `Unit`). The laser may count either way (`LasRead` is −Position in
//! the X file and +Position in the Y file), which `LinearError` already
//! accounts for; positions were hand-edited in some upstream copies, so the
//! reader does not cross-check them against `LasRead`.
//!
//! One file holds one direction. Rows are split into runs of `NumofPoints`
//! rows (or `RunNum` equal parts); a run's direction comes from the order of its
//! positions, as for `.rtl`. Two files (forward and reverse) of one axis are
//! joined by `read::read_paths`.
//!
//! \[reconstructed\] In inch files the temperatures are °F and the pressure
//! inHg (68.00 and 29.92 are the standard values in those units) and
//! `ExpCoef` is ppm/°F; they are converted to °C, kPa and ppm/°C. A material
//! temperature of −1 means "no sensor" (the files use it for sensors 2 and 3).

use chrono::NaiveDateTime;

use crate::error::{ParseError, Warning};
use crate::measurement::{
    AXIS_PLACEHOLDER, AxisSource, Direction, Environment, Measurement, Metadata, Run, SourceFormat,
    StartEnd, TestDate,
};
use crate::read::missing_readings_warning;
use crate::read::text::{self, Line, check_deviation_mm, check_target_mm, end_of_file_line};
use crate::units::{self, LengthUnit};

/// Material temperature the files write when no sensor is fitted.
const NO_SENSOR: f64 = -1.0;

/// Parses the text of an API XD `.pos` file.
pub fn parse(input: &str) -> Result<(Measurement, Vec<Warning>), ParseError> {
    let all: Vec<Line<'_>> = text::lines(input).collect();
    let header = HeaderFields::collect(&all);
    let Some(table_at) = all.iter().position(is_data_table_header) else {
        return Err(missing_table_error(&all, end_of_file_line(input)));
    };
    let columns = Columns::from_header(&all[table_at])?;
    let unit = header.length_unit("Unit")?.unwrap_or_default();
    let error_unit = header.length_unit("ErrorUnit")?.unwrap_or(unit);
    let mut warnings = Vec::new();
    let mut rows = Vec::new();
    for line in &all[table_at + 1..] {
        let first = line.text.split('\t').next().unwrap_or("").trim();
        if line.is_blank() || text::number(line, first, "position").is_err() {
            break;
        }
        rows.push(columns.row(line, unit, error_unit, &mut warnings)?);
    }
    if rows.is_empty() {
        let line = &all[table_at];
        return Err(ParseError::new(
            line.number + 1,
            1,
            "expected data rows after the column header, found none",
        ));
    }
    let runs_of_rows = split_runs(&rows, &header)?;
    let (targets_mm, runs) = assemble(&runs_of_rows)?;
    if let Some(warning) = missing_readings_warning(&runs, &targets_mm) {
        warnings.push(warning);
    }
    let environment = environment(&rows, &header, unit)?;
    let (axis, metadata) = metadata(&header, unit, &mut warnings);
    let measurement = Measurement::new(axis, targets_mm, runs, environment, metadata)
        .map_err(|error| ParseError::new(1, 1, error.to_string()))?;
    Ok((measurement, warnings))
}

/// One data row, converted to mm.
#[derive(Clone, Copy, Debug)]
struct Row {
    line: usize,
    /// The position as written, in the file's unit.
    position: f64,
    position_mm: f64,
    deviation_mm: f64,
    air_temperature: Option<f64>,
    air_pressure: Option<f64>,
    material: [Option<f64>; 3],
}

/// Column indices of the data table.
struct Columns {
    count: usize,
    position: usize,
    linear_error: usize,
    status: Option<usize>,
    air_temperature: Option<usize>,
    air_pressure: Option<usize>,
    material: [Option<usize>; 3],
}

impl Columns {
    fn from_header(line: &Line<'_>) -> Result<Columns, ParseError> {
        let names: Vec<&str> = line.text.split('\t').map(str::trim).collect();
        let find = |name: &str| names.iter().position(|n| n.eq_ignore_ascii_case(name));
        let position = find("Position")
            .ok_or_else(|| line.expected_at(line.text.trim_start(), "a Position column"))?;
        let linear_error = find("LinearError")
            .ok_or_else(|| line.expected_at(line.text.trim_start(), "a LinearError column"))?;
        Ok(Columns {
            count: names.len(),
            position,
            linear_error,
            status: find("Status"),
            air_temperature: find("AirTemp"),
            air_pressure: find("AirPress"),
            material: [find("MatTemp"), find("MatTemp2"), find("MatTemp3")],
        })
    }

    fn row(
        &self,
        line: &Line<'_>,
        unit: LengthUnit,
        error_unit: LengthUnit,
        warnings: &mut Vec<Warning>,
    ) -> Result<Row, ParseError> {
        let cells: Vec<&str> = line.text.split('\t').map(str::trim).collect();
        if cells.len() != self.count {
            let at = cells
                .get(self.count)
                .copied()
                .unwrap_or(line.text.trim_end());
            let at = if cells.len() > self.count {
                at
            } else {
                &line.text[line.text.len()..]
            };
            return Err(line.error_at(
                at,
                format!(
                    "data row has {} column(s), expected {} as in the table header",
                    cells.len(),
                    self.count
                ),
            ));
        }
        let value = |index: usize, what: &str| text::number(line, cells[index], what);
        let optional = |index: Option<usize>, what: &str| -> Result<Option<f64>, ParseError> {
            index.map(|i| value(i, what)).transpose()
        };
        if let Some(index) = self.status {
            let status =
                text::integer(line, cells[index].trim_start_matches('-'), "laser status")? as i64;
            if status != 0 {
                warnings.push(Warning::LaserStatus {
                    line: line.number,
                    status,
                    meaning: status_meaning(status),
                });
            }
        }
        let material = |slot: usize| -> Result<Option<f64>, ParseError> {
            Ok(optional(self.material[slot], "material temperature")?.filter(|t| *t != NO_SENSOR))
        };
        let position = value(self.position, "position")?;
        let column = |index: usize| line.column_of(cells[index]);
        let position_mm =
            check_target_mm(unit.to_mm(position), line.number, column(self.position))?;
        let deviation_mm = check_deviation_mm(
            error_unit.to_mm(value(self.linear_error, "linear error")?),
            line.number,
            column(self.linear_error),
        )?;
        Ok(Row {
            line: line.number,
            position,
            position_mm,
            deviation_mm,
            air_temperature: optional(self.air_temperature, "air temperature")?,
            air_pressure: optional(self.air_pressure, "air pressure")?,
            material: [material(0)?, material(1)?, material(2)?],
        })
    }
}

/// The legend the files print under "Laser status comments".
fn status_meaning(status: i64) -> &'static str {
    match status {
        0 => "laser normal",
        1 => "warm up",
        2 => "path error",
        3 => "over speed",
        4 => "wireless error",
        _ => "unknown status",
    }
}

fn is_data_table_header(line: &Line<'_>) -> bool {
    let cells: Vec<&str> = line.text.split('\t').map(str::trim).collect();
    cells.iter().any(|c| c.eq_ignore_ascii_case("Position"))
        && cells.iter().any(|c| c.eq_ignore_ascii_case("LinearError"))
}

fn missing_table_error(all: &[Line<'_>], end_line: usize) -> ParseError {
    if let Some(line) = all.iter().find(|l| {
        l.text
            .trim_start()
            .starts_with("API Linear Error Compensation Table")
    }) {
        return line.error_at(
            line.text.trim_start(),
            "expected the linear data table (Position … LinearError columns), found only a compensation table: export the full .pos file",
        );
    }
    ParseError::new(
        end_line,
        1,
        "expected a data table with Position and LinearError columns, found none",
    )
}

/// The `Key: value` cells of the file, with where each was found.
struct HeaderFields<'a> {
    fields: Vec<(String, &'a str, Line<'a>)>,
}

impl<'a> HeaderFields<'a> {
    fn collect(all: &[Line<'a>]) -> HeaderFields<'a> {
        let mut fields = Vec::new();
        for line in all {
            let cells: Vec<&'a str> = line.text.split('\t').collect();
            let mut index = 0;
            while index < cells.len() {
                let cell = cells[index];
                index += 1;
                let Some((key, value)) = key_cell(cell) else {
                    continue;
                };
                let mut value = value;
                if value.is_empty() && index < cells.len() && key_cell(cells[index]).is_none() {
                    value = cells[index].trim();
                    index += 1;
                }
                fields.push((key.to_ascii_lowercase(), value, *line));
            }
        }
        HeaderFields { fields }
    }

    fn get(&self, key: &str) -> Option<(&'a str, Line<'a>)> {
        let key = key.to_ascii_lowercase();
        self.fields
            .iter()
            .find(|(k, _, _)| *k == key)
            .map(|(_, value, line)| (*value, *line))
    }

    fn text(&self, key: &str) -> Option<String> {
        self.get(key)
            .map(|(value, _)| value.to_string())
            .filter(|v| !v.is_empty())
    }

    fn number(&self, key: &str, what: &str) -> Result<Option<f64>, ParseError> {
        match self.get(key) {
            Some((value, line)) if !value.is_empty() => Ok(Some(text::number(&line, value, what)?)),
            _ => Ok(None),
        }
    }

    fn count(
        &self,
        key: &str,
        what: &str,
    ) -> Result<Option<(usize, Line<'a>, &'a str)>, ParseError> {
        match self.get(key) {
            Some((value, line)) if !value.is_empty() => {
                let count = text::integer(&line, value, what)?;
                Ok(Some((count as usize, line, value)))
            }
            _ => Ok(None),
        }
    }

    fn length_unit(&self, key: &str) -> Result<Option<LengthUnit>, ParseError> {
        let Some((value, line)) = self.get(key) else {
            return Ok(None);
        };
        let word = value.split_whitespace().next().unwrap_or("");
        match word.to_ascii_lowercase().as_str() {
            "inch" | "in" => Ok(Some(LengthUnit::Inch)),
            "mm" => Ok(Some(LengthUnit::Millimetre)),
            _ => Err(line.error_at(
                if word.is_empty() { value } else { word },
                format!("expected {key}: inch or mm, found {value:?}"),
            )),
        }
    }
}

/// `Key: value` in one tab-separated cell; a key has a letter before the colon
/// (so `15:48:52` is a value, not a key).
fn key_cell(cell: &str) -> Option<(&str, &str)> {
    let colon = cell.find(':')?;
    let key = cell[..colon].trim();
    key.chars()
        .any(|c| c.is_ascii_alphabetic())
        .then(|| (key, cell[colon + 1..].trim()))
}

/// Splits the rows into runs: `NumofPoints` rows each, or else `RunNum` equal
/// parts. How `RunNum` counts the passes of a bidirectional file is not known,
/// so it is not checked when `NumofPoints` is given.
fn split_runs<'r>(
    rows: &'r [Row],
    header: &HeaderFields<'_>,
) -> Result<Vec<&'r [Row]>, ParseError> {
    let points = match header.count("NumofPoints", "point count")? {
        Some(points) => Some(points),
        None => header.count("NumofPos", "point count")?,
    };
    let size = if let Some((points, line, value)) = points {
        if points == 0 || !rows.len().is_multiple_of(points) {
            return Err(line.error_at(
                value,
                format!("NumofPoints is {points} but the data table has {} rows, not a whole number of runs", rows.len()),
            ));
        }
        points
    } else if let Some((runs, line, value)) = header.count("RunNum", "run count")? {
        if runs == 0 || !rows.len().is_multiple_of(runs) {
            return Err(line.error_at(
                value,
                format!(
                    "RunNum is {runs} but the data table has {} rows, not a whole number per run",
                    rows.len()
                ),
            ));
        }
        rows.len() / runs
    } else {
        rows.len()
    };
    Ok(rows.chunks(size).collect())
}

/// Targets from the first run; every run must visit the same targets, in one direction.
fn assemble(runs_of_rows: &[&[Row]]) -> Result<(Vec<f64>, Vec<Run>), ParseError> {
    const SAME_TARGET_MM: f64 = 1e-9;
    let mut targets_mm: Vec<f64> = runs_of_rows[0].iter().map(|r| r.position_mm).collect();
    targets_mm.sort_by(f64::total_cmp);
    let mut runs = Vec::with_capacity(runs_of_rows.len());
    let mut numbers = [0u32; 2];
    for rows in runs_of_rows {
        let direction = row_direction(rows)?;
        let mut deviations_mm = vec![None; targets_mm.len()];
        for row in rows.iter() {
            let index = targets_mm
                .iter()
                .position(|t| (t - row.position_mm).abs() <= SAME_TARGET_MM)
                .ok_or_else(|| {
                    ParseError::new(
                        row.line,
                        1,
                        format!(
                            "position {} mm is not a target of the first run",
                            row.position_mm
                        ),
                    )
                })?;
            deviations_mm[index] = Some(row.deviation_mm);
        }
        let slot = usize::from(direction == Direction::Down);
        numbers[slot] += 1;
        runs.push(Run {
            direction,
            number: numbers[slot],
            start_time_s: None,
            deviations: deviations_mm,
        });
    }
    Ok((targets_mm, runs))
}

fn row_direction(rows: &[Row]) -> Result<Direction, ParseError> {
    if rows.len() < 2 {
        return Ok(Direction::Up);
    }
    let direction = if rows[1].position_mm > rows[0].position_mm {
        Direction::Up
    } else {
        Direction::Down
    };
    for pair in rows.windows(2) {
        let step = pair[1].position_mm - pair[0].position_mm;
        let ok = match direction {
            Direction::Up => step > 0.0,
            Direction::Down => step < 0.0,
        };
        if !ok {
            return Err(ParseError::new(
                pair[1].line,
                1,
                format!(
                    "position {} after {}: expected the positions of a run to go all up or all down",
                    pair[1].position, pair[0].position
                ),
            ));
        }
    }
    Ok(direction)
}

fn environment(
    rows: &[Row],
    header: &HeaderFields<'_>,
    unit: LengthUnit,
) -> Result<Environment, ParseError> {
    let imperial = unit == LengthUnit::Inch;
    let temperature = |value: f64| {
        if imperial {
            units::fahrenheit_to_celsius(value)
        } else {
            value
        }
    };
    let pressure = |value: f64| {
        if imperial {
            units::inhg_to_kpa(value)
        } else {
            value
        }
    };
    let start_end = |pick: &dyn Fn(&Row) -> Option<f64>, convert: &dyn Fn(f64) -> f64| {
        StartEnd::new(
            rows.first().and_then(pick).map(convert),
            rows.last().and_then(pick).map(convert),
        )
    };
    let humidity = header.number("Humidity", "humidity")?;
    let coefficient = header.number("ExpCoef", "expansion coefficient")?.map(|c| {
        if imperial {
            units::per_fahrenheit_to_per_celsius(c)
        } else {
            c
        }
    });
    Ok(Environment {
        air_temperature_c: start_end(&|r| r.air_temperature, &temperature),
        air_pressure_kpa: start_end(&|r| r.air_pressure, &pressure),
        air_humidity_pct: StartEnd::new(humidity, humidity),
        material_temperature_c: [
            start_end(&|r| r.material[0], &temperature),
            start_end(&|r| r.material[1], &temperature),
            start_end(&|r| r.material[2], &temperature),
        ],
        expansion_coefficient_ppm_per_k: coefficient,
        environmental_factor_um: StartEnd::default(),
        // The files give the vacuum wavelength in mm whatever their unit (0.000632990350).
        vacuum_wavelength_um: header
            .number("WaveLength", "wavelength")?
            .map(units::mm_to_um),
    })
}

fn metadata(
    header: &HeaderFields<'_>,
    unit: LengthUnit,
    warnings: &mut Vec<Warning>,
) -> (String, Metadata) {
    let axis_of = |text: &str| {
        text.trim()
            .trim_start_matches('(')
            .trim_end_matches(')')
            .trim()
            .to_string()
    };
    let test_axis = header
        .text("TestAxis")
        .map(|a| axis_of(&a))
        .filter(|a| !a.is_empty());
    let file_name = header.text("File Name");
    let named_axis = file_name
        .as_deref()
        .and_then(|name| name.split_whitespace().next())
        .filter(|word| word.len() == 1 && word.chars().all(|c| c.is_ascii_alphabetic()))
        .map(str::to_string);
    let (axis, axis_source) = match (&test_axis, &named_axis) {
        (Some(test), Some(named)) if !test.eq_ignore_ascii_case(named) => {
            warnings.push(Warning::InconsistentMetadata {
                message: format!(
                    "TestAxis is ({test}) but File Name is {:?}; the axis is called {test} (use --axis to rename it)",
                    file_name.clone().unwrap_or_default()
                ),
            });
            (test.clone(), AxisSource::file("TestAxis"))
        }
        (Some(test), _) => (test.clone(), AxisSource::file("TestAxis")),
        (None, Some(named)) => (named.clone(), AxisSource::file("File Name")),
        (None, None) => (AXIS_PLACEHOLDER.to_string(), AxisSource::NotRecorded),
    };
    let date = match (header.text("TestDate"), header.text("TestTime")) {
        (Some(date), time) => {
            let raw = match &time {
                Some(time) => format!("{date} {time}"),
                None => date.clone(),
            };
            // API software is American: month/day/year.
            let parsed = NaiveDateTime::parse_from_str(&raw, "%m/%d/%Y %H:%M:%S")
                .ok()
                .or_else(|| {
                    chrono::NaiveDate::parse_from_str(&date, "%m/%d/%Y")
                        .ok()
                        .and_then(|d| d.and_hms_opt(0, 0, 0))
                });
            Some(TestDate { raw, parsed })
        }
        (None, _) => None,
    };
    let mut extra = Vec::new();
    for key in [
        "Instrument(S/N)",
        "File Name",
        "File Version",
        "TestType",
        "TestMode",
        "Dwell",
        "FeedRate",
        "CNCProg",
    ] {
        if let Some(value) = header.text(key) {
            extra.push((key.to_string(), value));
        }
    }
    let metadata = Metadata {
        machine: header.text("MachName"),
        serial_number: header.text("MachID"),
        operator: header.text("Operator"),
        date,
        end_date: None,
        location: None,
        description: header.text("Comments").filter(|c| c != "None"),
        source_file: None,
        source_format: Some(SourceFormat::ApiPos),
        length_unit: unit,
        extra,
        axis_source,
        setup: test_setup(header, unit),
    };
    (axis, metadata)
}

/// The instrument and set-up the header records: the laser model from the
/// title line (`API X-D Laser Measurement Linear Data Table`), `Instrument(S/N)`,
/// `FeedRate` and `Dwell`, and `AxesLoc` (`(Y) 0  (Z) 0 …`, the other axes'
/// positions in the file's unit). Read leniently: a value that is not a
/// number (`FeedRate: None`) is "not recorded", never an error.
/// \[reconstructed\] Dwell is in seconds and a numeric feed in the file's
/// unit per minute; the real files have `Dwell: 3` and `FeedRate: None`.
fn test_setup(header: &HeaderFields<'_>, unit: LengthUnit) -> crate::measurement::TestSetup {
    let number = |key: &str| {
        header
            .text(key)
            .and_then(|v| v.parse::<f64>().ok())
            .filter(|v| v.is_finite())
    };
    let instrument = header
        .fields
        .iter()
        .find(|(key, _, _)| key.starts_with("api "))
        .and_then(|(_, _, line)| {
            let title = line.text.trim();
            let end = title.to_ascii_lowercase().find("laser")? + "laser".len();
            Some(title[..end].to_string())
        });
    let other_axes_mm = header
        .get("AxesLoc")
        .map(|(_, line)| {
            line.text
                .split('\t')
                .filter_map(|cell| {
                    let (name, value) = cell.trim().strip_prefix('(')?.split_once(')')?;
                    let value: f64 = value.trim().parse().ok().filter(|v: &f64| v.is_finite())?;
                    Some((name.trim().to_string(), unit.to_mm(value)))
                })
                .collect()
        })
        .unwrap_or_default();
    crate::measurement::TestSetup {
        instrument,
        instrument_serial: header.text("Instrument(S/N)"),
        feed_mm_per_min: number("FeedRate").map(|feed| unit.to_mm(feed)),
        dwell_s: number("Dwell"),
        other_axes_mm,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(rows: &str, header_extra: &str) -> String {
        format!(
            "API X-D Laser Measurement Linear Data Table (Company Name: )\r\n\
             File Name:\tZ Axis Forward.pos\r\nTestDate: \t07/19/2016\r\nTestTime:\t15:48:52\r\n\
             MachID: DMS# 2247\tMachName: Mill\tOperator: MKM\r\nTestAxis: \t(Z)\r\n\
             Unit:\tmm\t0\r\n{header_extra}\
             Direction: 1\tHumidity: 45\tExpCoef: 11.5\r\n\r\n\
             Position\tLasRead\tLinearError\tStatus\tAirTemp\tAirPress\tMatTemp\tMatTemp2\tMatTemp3\r\n\
             {rows}DecimalPoints:\t4\r\n"
        )
    }

    const ROWS: &str = "0.0\t0.001\t0.001\t0\t20.1\t101.3\t20.0\t-1.00\t-1.00\r\n\
                        10.0\t10.002\t0.002\t0\t20.2\t101.2\t20.1\t-1.00\t-1.00\r\n";

    #[test]
    fn millimetre_file_reads_as_is() {
        let (m, warnings) = parse(&file(ROWS, "")).unwrap();
        assert_eq!(m.axis(), "Z");
        assert_eq!(m.targets(), &[0.0, 10.0]);
        assert_eq!(m.runs()[0].deviations, vec![Some(0.001), Some(0.002)]);
        assert_eq!(m.runs()[0].direction, Direction::Up);
        assert_eq!(
            m.environment.air_temperature_c,
            StartEnd::new(Some(20.1), Some(20.2))
        );
        assert_eq!(m.environment.material_temperature_c[1], StartEnd::default());
        assert_eq!(m.environment.expansion_coefficient_ppm_per_k, Some(11.5));
        assert_eq!(
            m.metadata
                .date
                .as_ref()
                .unwrap()
                .parsed
                .unwrap()
                .to_string(),
            "2016-07-19 15:48:52"
        );
        assert!(warnings.is_empty(), "{warnings:?}");
    }

    #[test]
    fn rows_split_into_runs_by_point_count() {
        let rows = "0.0\t0\t0.001\t0\t20\t101\t20\t-1\t-1\r\n10.0\t0\t0.002\t0\t20\t101\t20\t-1\t-1\r\n\
                    0.0\t0\t0.003\t0\t20\t101\t20\t-1\t-1\r\n10.0\t0\t0.004\t2\t20\t101\t20\t-1\t-1\r\n";
        let (m, warnings) = parse(&file(rows, "NumofPoints:\t2\r\n")).unwrap();
        assert_eq!(m.run_count(Direction::Up), 2);
        assert!(matches!(
            warnings[0],
            Warning::LaserStatus { status: 2, .. }
        ));
        let bad = parse(&file(rows, "NumofPoints:\t3\r\n")).unwrap_err();
        assert!(bad.message.contains("not a whole number of runs"), "{bad}");
    }

    #[test]
    fn reverse_file_is_down() {
        let rows = "10.0\t10\t-0.002\t0\t20\t101\t20\t-1\t-1\r\n0.0\t0\t-0.001\t0\t20\t101\t20\t-1\t-1\r\n";
        let (m, _) = parse(&file(rows, "")).unwrap();
        assert_eq!(m.runs()[0].direction, Direction::Down);
        assert_eq!(m.runs()[0].deviations, vec![Some(-0.001), Some(-0.002)]);
    }

    #[test]
    fn positioned_errors() {
        let short = "0.0\t0.001\t0.001\t0\r\n";
        let error = parse(&file(short, "")).unwrap_err();
        assert!(error.message.contains("4 column(s), expected 9"), "{error}");
        let zigzag = "0\t0\t0\t0\t20\t101\t20\t-1\t-1\r\n10\t0\t0\t0\t20\t101\t20\t-1\t-1\r\n5\t0\t0\t0\t20\t101\t20\t-1\t-1\r\n";
        let error = parse(&file(zigzag, "")).unwrap_err();
        assert_eq!(error.position.line, 13);
        assert!(error.message.contains("all up or all down"), "{error}");
        let unit = parse(&file(ROWS, "").replace("Unit:\tmm", "Unit:\tfurlong")).unwrap_err();
        assert!(unit.message.contains("inch or mm"), "{unit}");
    }
}
