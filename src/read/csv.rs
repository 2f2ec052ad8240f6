//! axcomp's plain CSV measurement layout: parser and writer.
//!
//! For data from any other source. The layout (documented in docs/src/input-formats.md):
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
//! - The separator is the header's: `,` (then `.` is the decimal point),
//!   `;` or a tab. With `;` or a tab the decimal mark is `.` or `,`, whichever
//!   the file uses: Excel in a European locale saves "CSV" with `;` and a
//!   decimal comma, and "Text (tab delimited)" with a tab. A file that mixes
//!   the two marks, or writes both in one number (`1.234,5`), is refused at
//!   the number. Trailing separators after a `#` line (Excel pads every row
//!   to the width of the sheet) and rows of empty fields are ignored.
//! - A rotary axis has the header [`ROTARY_HEADER`],
//!   `target_deg,run,direction,deviation_arcsec`: targets in degrees,
//!   deviations in arc-seconds (″), otherwise the same layout; the header
//!   alone says which ([`AxisKind`]).

use std::collections::HashMap;

use crate::error::{ParseError, Warning, describe_found};
use crate::measurement::{
    AXIS_PLACEHOLDER, AxisKind, AxisSource, Direction, Environment, Measurement, Metadata, Run,
    SourceFormat, TestDate,
};
use crate::read::text::{
    self, Line, check_deviation_deg, check_deviation_mm, check_target_mm, end_of_file_line,
    split_key,
};
use crate::read::{missing_readings_warning_of, parse_date};
use crate::units::{LengthUnit, arcsec_text, arcsec_to_deg, um_text, um_to_mm};

/// The header line, lowercase, without spaces, as axcomp writes it.
pub const HEADER: &str = "target_mm,run,direction,deviation_um";

/// The header of a rotary axis: degrees and arc-seconds.
pub const ROTARY_HEADER: &str = "target_deg,run,direction,deviation_arcsec";

/// The header's field names, in order, per kind.
fn header_fields(kind: AxisKind) -> [&'static str; 4] {
    match kind {
        AxisKind::Linear => ["target_mm", "run", "direction", "deviation_um"],
        AxisKind::Rotary => ["target_deg", "run", "direction", "deviation_arcsec"],
    }
}

/// The field separator of a header line (`,`, `;` or tab), or `None` when
/// the line is not the header.
pub fn header_separator(line: &str) -> Option<char> {
    header_layout(line).map(|(separator, _)| separator)
}

/// The separator and the kind of axis a header line states.
fn header_layout(line: &str) -> Option<(char, AxisKind)> {
    [AxisKind::Linear, AxisKind::Rotary]
        .into_iter()
        .find_map(|kind| {
            [',', ';', '\t'].into_iter().find_map(|separator| {
                let mut fields = line.split(separator).map(str::trim);
                let matches = header_fields(kind)
                    .iter()
                    .all(|name| fields.next().is_some_and(|f| f.eq_ignore_ascii_case(name)))
                    && fields.next().is_none();
                matches.then_some((separator, kind))
            })
        })
}

/// How the file writes its rows: the header's separator and kind, and the
/// decimal mark the first number with a fraction used (with its line).
#[derive(Clone, Copy, Debug)]
struct Layout {
    separator: char,
    kind: AxisKind,
    decimal: Option<(char, usize)>,
}

impl Layout {
    /// Parses a number token; a decimal comma where the separator allows it.
    fn number(&mut self, line: &Line<'_>, token: &str, what: &str) -> Result<f64, ParseError> {
        let comma = token.contains(',');
        let point = token.contains('.');
        if comma && point {
            return Err(line.error_at(
                token,
                format!(
                    "expected a number ({what}) with one decimal mark, found both '.' and ',' in {} (no thousands separators)",
                    describe_found(token)
                ),
            ));
        }
        if !(comma || point) {
            return text::number(line, token, what);
        }
        let mark = if comma { ',' } else { '.' };
        match self.decimal {
            None => self.decimal = Some((mark, line.number)),
            Some((first, first_line)) if first != mark => {
                let name = |mark: char| if mark == ',' { "comma" } else { "point" };
                return Err(line.error_at(
                    token,
                    format!(
                        "expected a decimal {} as on line {first_line}, found a decimal {} in {}: the file mixes decimal marks",
                        name(first),
                        name(mark),
                        describe_found(token)
                    ),
                ));
            }
            Some(_) => {}
        }
        if !comma {
            return text::number(line, token, what);
        }
        // Same length, so the columns of the text stay those of the line.
        let with_point = token.replacen(',', ".", 1);
        let shadow = Line {
            number: line.number,
            text: &with_point,
        };
        text::number(&shadow, &with_point, what)
            .map_err(|_| line.expected_at(token, &format!("a number ({what})")))
    }
}

/// Parses the text of an axcomp CSV file.
pub fn parse(input: &str) -> Result<(Measurement, Vec<Warning>), ParseError> {
    let mut metadata = Metadata::default();
    let mut axis = None;
    let mut layout: Option<Layout> = None;
    let mut readings: Vec<Reading> = Vec::new();
    let mut seen: HashMap<(Direction, u64, u64), usize> = HashMap::new();
    for line in text::lines(input) {
        let trimmed = line.text.trim();
        if trimmed.is_empty() {
            continue;
        }
        if let Some(comment) = trimmed.strip_prefix('#') {
            if layout.is_none() {
                comment_metadata(comment, &mut metadata, &mut axis);
            }
            continue;
        }
        let Some(layout) = layout.as_mut() else {
            let Some((separator, kind)) = header_layout(trimmed) else {
                return Err(line.expected_at(
                    trimmed,
                    &format!(
                        "the header {HEADER} or {ROTARY_HEADER} (or with ';' or tabs between the names)"
                    ),
                ));
            };
            layout = Some(Layout {
                separator,
                kind,
                decimal: None,
            });
            continue;
        };
        if trimmed
            .split(layout.separator)
            .all(|field| field.trim().is_empty())
        {
            continue;
        }
        let reading = reading(&line, layout)?;
        let key = (
            reading.direction,
            reading.run,
            (reading.target_mm + 0.0).to_bits(),
        );
        if let Some(first) = seen.insert(key, line.number) {
            return Err(line.error_at(
                trimmed,
                format!(
                    "run {}{} at {} {} is listed twice (first at line {first})",
                    reading.run,
                    reading.direction,
                    reading.target_mm,
                    layout.kind.position_unit()
                ),
            ));
        }
        readings.push(reading);
    }
    let Some(layout) = layout else {
        return Err(ParseError::new(
            end_of_file_line(input),
            1,
            format!("expected the header {HEADER}, found end of file"),
        ));
    };
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
    if let Some(warning) = missing_readings_warning_of(&runs, &targets_mm, layout.kind) {
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
        .map_err(|error| ParseError::new(1, 1, error.to_string()))?
        .with_kind(layout.kind);
    Ok((measurement, warnings))
}

/// Writes a measurement in axcomp's CSV layout. Deviations use the shortest
/// text that reads back to the same value.
pub fn write(measurement: &Measurement) -> String {
    let mut out = String::new();
    // A placeholder name stays unrecorded: the file must not claim an axis.
    if measurement.axis_recorded() {
        out.push_str(&format!("# axis: {}\n", measurement.axis()));
    }
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
    let kind = measurement.kind();
    out.push_str(match kind {
        AxisKind::Linear => HEADER,
        AxisKind::Rotary => ROTARY_HEADER,
    });
    out.push('\n');
    for run in measurement.runs() {
        for (target_mm, deviation_mm) in measurement.targets().iter().zip(&run.deviations) {
            let deviation = deviation_mm
                .map(|value| match kind {
                    AxisKind::Linear => um_text(value),
                    AxisKind::Rotary => arcsec_text(value),
                })
                .unwrap_or_default();
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

fn reading(line: &Line<'_>, layout: &mut Layout) -> Result<Reading, ParseError> {
    let fields: Vec<&str> = line.text.split(layout.separator).map(str::trim).collect();
    if fields.len() != 4 {
        let hint = if fields.len() > 4 && layout.separator == ',' {
            " (a decimal comma? use '.' as the decimal point, or save with ';' between the fields)"
        } else {
            ""
        };
        return Err(line.error_at(
            line.text.trim_start(),
            format!(
                "row has {} field(s), expected 4: {}{hint}",
                fields.len(),
                header_fields(layout.kind).join(",")
            ),
        ));
    }
    let target_what = match layout.kind {
        AxisKind::Linear => "target in mm",
        AxisKind::Rotary => "target in degrees",
    };
    let target_mm = layout.number(line, fields[0], target_what)?;
    check_target_mm(target_mm, line.number, line.column_of(fields[0]))?;
    let (run, direction) = text::run_and_direction(line, fields[1], fields[2])?;
    let deviation_mm = if fields[3].is_empty() {
        None
    } else {
        let column = line.column_of(fields[3]);
        Some(match layout.kind {
            AxisKind::Linear => {
                let deviation_mm = um_to_mm(layout.number(line, fields[3], "deviation in µm")?);
                check_deviation_mm(deviation_mm, line.number, column)?
            }
            AxisKind::Rotary => {
                let deviation_deg =
                    arcsec_to_deg(layout.number(line, fields[3], "deviation in ″")?);
                check_deviation_deg(deviation_deg, line.number, column)?
            }
        })
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
    // Excel pads a one-cell row with separators to the width of the sheet.
    let value = value.trim_end_matches([',', ';', '\t']).trim_end();
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
                    deviations: deviations_mm,
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
        assert_eq!(m.targets(), &[0.0, 100.0]);
        assert_eq!(m.runs()[0].deviations, vec![Some(0.0), Some(0.0025)]);
        assert_eq!(m.runs()[1].deviations, vec![Some(0.001), None]);
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
        assert_eq!(again.targets(), m.targets());
        assert_eq!(again.runs(), m.runs());
        assert_eq!(again.axis_source(), &AxisSource::file("# axis"));
        // An axis the file did not record is not written as if it had been.
        let (unnamed, _) = parse(&text.replace("# axis: Z\n", "")).unwrap();
        let (again, _) = parse(&write(&unnamed)).unwrap();
        assert_eq!(again.axis_source(), &AxisSource::NotRecorded);
    }

    #[test]
    fn the_rotary_header_reads_degrees_and_arc_seconds() {
        let text = "# axis: C\ntarget_deg;run;direction;deviation_arcsec\n0;1;up;1,8\n90;1;up;-3,6\n0;1;down;0\n90;1;down;\n";
        let (c, warnings) = parse(text).unwrap();
        assert_eq!(c.kind(), AxisKind::Rotary);
        assert!(
            warnings[0].to_string().contains("run 1↓ at 90°"),
            "{warnings:?}"
        );
        assert_eq!(c.targets(), &[0.0, 90.0]);
        // 1.8″ = 0.0005°, −3.6″ = −0.001° (1° = 3600″, by hand).
        let up = &c.runs()[0].deviations;
        assert!((up[0].unwrap() - 0.0005).abs() < 1e-15 && (up[1].unwrap() + 0.001).abs() < 1e-15);
        let written = write(&c);
        assert!(
            written
                .contains("target_deg,run,direction,deviation_arcsec\n0,1,up,1.8\n90,1,up,-3.6\n"),
            "{written}"
        );
        let (again, _) = parse(&written).unwrap();
        assert_eq!((again.kind(), again.runs()), (AxisKind::Rotary, c.runs()));
        #[rustfmt::skip]
        let cases = [
            ("target_deg,run,direction,deviation_arcsec\n0,1,up,3601\n", (2, 8), "within ±3600″"),
            ("target_deg,run,direction,deviation_arcsec\n0,1,up\n", (2, 1), "expected 4: target_deg,run,direction,deviation_arcsec"),
            ("target_deg,run,direction,deviation_um\n", (1, 1), "or target_deg,run,direction,deviation_arcsec"),
        ];
        text::assert_errors_at(parse, &cases);
    }

    #[test]
    fn excel_layouts_read_the_same_values() {
        let comma = "# axis: Y\ntarget_mm,run,direction,deviation_um\n0,1,up,0.5\n12.5,1,up,-2.25\n0,1,down,1\n12.5,1,down,\n";
        let semicolon = "# axis: Y;;;\r\nTarget_mm;Run;Direction;Deviation_um\r\n0;1;up;0,5\r\n12,5;1;up;-2,25\r\n;;;\r\n0;1;down;1\r\n12,5;1;down;\r\n";
        let tab = "# axis: Y\ntarget_mm\trun\tdirection\tdeviation_um\n0\t1\tup\t0.5\n12.5\t1\tup\t-2.25\n0\t1\tdown\t1\n12.5\t1\tdown\t\n";
        let (expected, _) = parse(comma).unwrap();
        for text in [semicolon, tab] {
            let (m, _) = parse(text).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(m.axis(), "Y");
            assert_eq!(m.targets(), &[0.0, 12.5]);
            assert_eq!(m.runs(), expected.runs());
        }
        assert_eq!(
            header_separator("target_mm;run;direction;deviation_um"),
            Some(';')
        );
        assert_eq!(
            header_separator("target_mm\trun\tdirection\tdeviation_um"),
            Some('\t')
        );
        assert_eq!(header_separator("target_mm;run;direction"), None);
    }

    #[test]
    fn positioned_errors() {
        #[rustfmt::skip]
        let cases = [
            ("x,y\n", (1, 1), "expected the header"),
            ("target_mm,run,direction,deviation_um\n0,1,sideways,1\n", (2, 5), "direction up or down"),
            ("target_mm,run,direction,deviation_um\n0,0,up,1\n", (2, 3), "from 1"),
            ("target_mm,run,direction,deviation_um\n0,1,up,1\n0,1,up,2\n", (3, 1), "listed twice"),
            ("target_mm,run,direction,deviation_um\n", (2, 1), "at least one data row"),
            ("target_mm,run,direction,deviation_um\n0,1,up,inf\n", (2, 8), "expected a number"),
        ];
        text::assert_errors_at(parse, &cases);
    }

    /// A decimal comma where the layout has none, or a mixture of separators.
    #[test]
    fn decimal_separator_errors_are_positioned() {
        #[rustfmt::skip]
        let cases = [
            ("target_mm,run,direction,deviation_um\n0,1,up,1,5\n", (2, 1), "decimal comma"),
            ("target_mm;run;direction;deviation_um\n0;1;up;0,5\n10;1;up;1.5\n", (3, 9), "expected a decimal comma as on line 2, found a decimal point in \"1.5\""),
            ("target_mm;run;direction;deviation_um\n1.000,5;1;up;0\n", (2, 1), "found both '.' and ','"),
            ("target_mm;run;direction;deviation_um\n0;1;up;1,2,3\n", (2, 8), "expected a number (deviation in µm), found \"1,2,3\""),
        ];
        text::assert_errors_at(parse, &cases);
    }
}
