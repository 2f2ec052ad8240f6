//! axcomp's plain CSV measurement layout: parser and writer.
//!
//! For data from any other source. The layout (documented in README.md):
//! ```text
//! # axis: X
//! # machine: MCV 754 Quick
//! target_mm,run,direction,deviation_um
//! 0,1,up,0.0
//! 100,1,up,-2.31
//! 100,1,down,
//! ```
//! - Optional `# key: value` lines before the header carry metadata (`axis`,
//!   `machine`, `serial`, `operator`, `date`, `location`, `description`);
//!   other `#` lines are comments.
//! - One row per reading: target in mm, run number within its direction,
//!   `up` or `down` (`↑`/`↓` also accepted), deviation (actual − target) in µm.
//!   An empty deviation is a missing reading. Rows may come in any order; runs
//!   are taken in the order they first appear.
//! - Run numbers are per direction; if a direction's numbers are not 1, 2, 3, …
//!   (e.g. a file numbering all passes 1–10) they are renumbered in ascending
//!   order, with a warning.
//! - `.` is the decimal point; a comma is the field separator only.

use std::collections::HashMap;

use crate::error::{ParseError, Warning};
use crate::measurement::{
    AXIS_PLACEHOLDER, AxisSource, Direction, Environment, Measurement, Metadata, Run, SourceFormat,
    TestDate,
};
use crate::read::text::{
    self, Line, check_deviation_mm, check_target_mm, end_of_file_line, split_key,
};
use crate::read::{missing_readings_warning, parse_date};
use crate::units::{LengthUnit, um_text, um_to_mm};

/// The header line, lowercase, without spaces.
pub const HEADER: &str = "target_mm,run,direction,deviation_um";

/// Parses the text of an axcomp CSV file.
pub fn parse(input: &str) -> Result<(Measurement, Vec<Warning>), ParseError> {
    let mut metadata = Metadata::default();
    let mut axis = None;
    let mut header_seen = false;
    let mut readings: Vec<Reading> = Vec::new();
    let mut seen: HashMap<(Direction, u64, u64), usize> = HashMap::new();
    for line in text::lines(input) {
        let trimmed = line.text.trim();
        if trimmed.is_empty() {
            continue;
        }
        if let Some(comment) = trimmed.strip_prefix('#') {
            if !header_seen {
                comment_metadata(comment, &mut metadata, &mut axis);
            }
            continue;
        }
        if !header_seen {
            let compact: String = trimmed.chars().filter(|c| !c.is_whitespace()).collect();
            if !compact.eq_ignore_ascii_case(HEADER) {
                return Err(line.expected_at(trimmed, &format!("the header {HEADER}")));
            }
            header_seen = true;
            continue;
        }
        let reading = reading(&line)?;
        let key = (
            reading.direction,
            reading.run,
            (reading.target_mm + 0.0).to_bits(),
        );
        if let Some(first) = seen.insert(key, line.number) {
            return Err(line.error_at(
                trimmed,
                format!(
                    "run {}{} at {} mm is listed twice (first at line {first})",
                    reading.run, reading.direction, reading.target_mm
                ),
            ));
        }
        readings.push(reading);
    }
    if !header_seen {
        return Err(ParseError::new(
            end_of_file_line(input),
            1,
            format!("expected the header {HEADER}, found end of file"),
        ));
    }
    if readings.is_empty() {
        return Err(ParseError::new(
            end_of_file_line(input),
            1,
            "expected at least one data row, found end of file",
        ));
    }
    let mut warnings = Vec::new();
    let mut targets_mm: Vec<f64> = readings.iter().map(|r| r.target_mm).collect();
    targets_mm.sort_by(f64::total_cmp);
    targets_mm.dedup();
    let runs = assemble_runs(&readings, &targets_mm, &mut warnings);
    if let Some(warning) = missing_readings_warning(&runs, &targets_mm) {
        warnings.push(warning);
    }
    metadata.source_format = Some(SourceFormat::Csv);
    metadata.length_unit = LengthUnit::Millimetre;
    let axis = match axis {
        Some(axis) => {
            metadata.axis_source = AxisSource::file("# axis");
            axis
        }
        None => AXIS_PLACEHOLDER.to_string(),
    };
    let measurement = Measurement::new(axis, targets_mm, runs, Environment::default(), metadata)
        .map_err(|error| ParseError::new(1, 1, error.to_string()))?;
    Ok((measurement, warnings))
}

/// Writes a measurement in axcomp's CSV layout. Deviations use the shortest
/// text that reads back to the same value.
pub fn write(measurement: &Measurement) -> String {
    let mut out = String::new();
    out.push_str(&format!("# axis: {}\n", measurement.axis()));
    let metadata = &measurement.metadata;
    let fields = [
        ("machine", metadata.machine.clone()),
        ("serial", metadata.serial_number.clone()),
        ("operator", metadata.operator.clone()),
        ("date", metadata.date.as_ref().map(|d| d.raw.clone())),
        ("location", metadata.location.clone()),
        ("description", metadata.description.clone()),
    ];
    for (key, value) in fields {
        if let Some(value) = value {
            out.push_str(&format!("# {key}: {value}\n"));
        }
    }
    out.push_str(HEADER);
    out.push('\n');
    for run in measurement.runs() {
        for (target_mm, deviation_mm) in measurement.targets_mm().iter().zip(&run.deviations_mm) {
            let deviation = deviation_mm.map(um_text).unwrap_or_default();
            out.push_str(&format!(
                "{target_mm},{},{},{deviation}\n",
                run.number,
                run.direction.as_str()
            ));
        }
    }
    out
}

/// One data row.
#[derive(Clone, Copy, Debug)]
struct Reading {
    target_mm: f64,
    run: u64,
    direction: Direction,
    deviation_mm: Option<f64>,
}

fn reading(line: &Line<'_>) -> Result<Reading, ParseError> {
    let fields: Vec<&str> = line.text.split(',').map(str::trim).collect();
    if fields.len() != 4 {
        let hint = if fields.len() > 4 {
            " (a decimal comma? use '.' as the decimal point)"
        } else {
            ""
        };
        return Err(line.error_at(
            line.text.trim_start(),
            format!(
                "row has {} field(s), expected 4: target_mm,run,direction,deviation_um{hint}",
                fields.len()
            ),
        ));
    }
    let target_mm = text::number(line, fields[0], "target in mm")?;
    check_target_mm(target_mm, line.number, line.column_of(fields[0]))?;
    let run = text::integer(line, fields[1], "run number")?;
    if run == 0 {
        return Err(line.error_at(fields[1], "expected a run number from 1, found 0"));
    }
    let direction = match fields[2].to_ascii_lowercase().as_str() {
        "up" | "↑" => Direction::Up,
        "down" | "↓" => Direction::Down,
        _ => return Err(line.expected_at(fields[2], "direction up or down")),
    };
    let deviation_mm = if fields[3].is_empty() {
        None
    } else {
        let deviation_mm = um_to_mm(text::number(line, fields[3], "deviation in µm")?);
        Some(check_deviation_mm(
            deviation_mm,
            line.number,
            line.column_of(fields[3]),
        )?)
    };
    Ok(Reading {
        target_mm,
        run,
        direction,
        deviation_mm,
    })
}

fn comment_metadata(comment: &str, metadata: &mut Metadata, axis: &mut Option<String>) {
    let Some((key, value)) = split_key(comment, ':') else {
        return;
    };
    if value.is_empty() {
        return;
    }
    let value = value.to_string();
    match key.to_ascii_lowercase().as_str() {
        "axis" => *axis = Some(value),
        "machine" => metadata.machine = Some(value),
        "serial" => metadata.serial_number = Some(value),
        "operator" => metadata.operator = Some(value),
        "location" => metadata.location = Some(value),
        "description" => metadata.description = Some(value),
        "date" => {
            metadata.date = Some(TestDate {
                parsed: parse_date(&value),
                raw: value,
            })
        }
        _ => {}
    }
}

/// Builds the runs in order of first appearance, renumbered 1, 2, 3, … per direction.
fn assemble_runs(
    readings: &[Reading],
    targets_mm: &[f64],
    warnings: &mut Vec<Warning>,
) -> Vec<Run> {
    let mut order: Vec<(Direction, u64)> = Vec::new();
    for reading in readings {
        let key = (reading.direction, reading.run);
        if !order.contains(&key) {
            order.push(key);
        }
    }
    let mut runs = Vec::with_capacity(order.len());
    for direction in Direction::BOTH {
        let mut numbers: Vec<u64> = order
            .iter()
            .filter(|(d, _)| *d == direction)
            .map(|(_, n)| *n)
            .collect();
        numbers.sort_unstable();
        let consecutive = numbers.iter().enumerate().all(|(i, n)| *n == i as u64 + 1);
        if !consecutive {
            warnings.push(Warning::InconsistentMetadata {
                message: format!("runs {direction} are numbered {numbers:?} in the file; they are renumbered 1..{}", numbers.len()),
            });
        }
        for (index, file_number) in numbers.iter().enumerate() {
            let mut deviations_mm = vec![None; targets_mm.len()];
            for reading in readings
                .iter()
                .filter(|r| r.direction == direction && r.run == *file_number)
            {
                if let Ok(at) = targets_mm.binary_search_by(|t| t.total_cmp(&reading.target_mm)) {
                    deviations_mm[at] = reading.deviation_mm;
                }
            }
            let first_seen = order
                .iter()
                .position(|key| *key == (direction, *file_number))
                .unwrap_or(0);
            runs.push((
                first_seen,
                Run {
                    direction,
                    number: index as u32 + 1,
                    start_time_s: None,
                    deviations_mm,
                },
            ));
        }
    }
    runs.sort_by_key(|(first_seen, _)| *first_seen);
    runs.into_iter().map(|(_, run)| run).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_rows_in_any_order_with_missing_values() {
        let text = "# axis: Y\n# machine: Test mill\ntarget_mm,run,direction,deviation_um\n\
                    100,1,up,2.5\n0,1,up,0\n0,1,down,1.0\n100,1,down,\n";
        let (m, warnings) = parse(text).unwrap();
        assert_eq!(m.axis(), "Y");
        assert_eq!(m.metadata.machine.as_deref(), Some("Test mill"));
        assert_eq!(m.targets_mm(), &[0.0, 100.0]);
        assert_eq!(m.runs()[0].deviations_mm, vec![Some(0.0), Some(0.0025)]);
        assert_eq!(m.runs()[1].deviations_mm, vec![Some(0.001), None]);
        assert!(matches!(
            warnings[0],
            Warning::MissingReadings { count: 1, .. }
        ));
    }

    #[test]
    fn global_run_numbers_are_renumbered_with_a_warning() {
        let text =
            "target_mm,run,direction,deviation_um\n0,1,up,0\n0,2,down,1\n0,3,up,0\n0,4,down,1\n";
        let (m, warnings) = parse(text).unwrap();
        let labels: Vec<String> = m.runs().iter().map(|r| r.label()).collect();
        assert_eq!(labels, ["1↑", "1↓", "2↑", "2↓"]);
        assert_eq!(warnings.len(), 2);
    }

    #[test]
    fn write_then_parse_gives_the_measurement_back() {
        let text = "# axis: Z\ntarget_mm,run,direction,deviation_um\n0,1,up,0.1\n50.5,1,up,-3.25\n0,1,down,\n50.5,1,down,7\n";
        let (m, _) = parse(text).unwrap();
        let (again, _) = parse(&write(&m)).unwrap();
        assert_eq!(again.targets_mm(), m.targets_mm());
        assert_eq!(again.runs(), m.runs());
    }

    #[test]
    fn positioned_errors() {
        let cases = [
            ("x,y\n", (1, 1), "expected the header"),
            (
                "target_mm,run,direction,deviation_um\n0,1,up,1,5\n",
                (2, 1),
                "decimal comma",
            ),
            (
                "target_mm,run,direction,deviation_um\n0,1,sideways,1\n",
                (2, 5),
                "direction up or down",
            ),
            (
                "target_mm,run,direction,deviation_um\n0,0,up,1\n",
                (2, 3),
                "from 1",
            ),
            (
                "target_mm,run,direction,deviation_um\n0,1,up,1\n0,1,up,2\n",
                (3, 1),
                "listed twice",
            ),
            (
                "target_mm,run,direction,deviation_um\n",
                (2, 1),
                "at least one data row",
            ),
            (
                "target_mm,run,direction,deviation_um\n0,1,up,inf\n",
                (2, 8),
                "expected a number",
            ),
        ];
        for (text, (line, column), needle) in cases {
            let error = parse(text).unwrap_err();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "{text:?}: {error}"
            );
            assert!(error.message.contains(needle), "{text:?}: {error}");
        }
    }
}
