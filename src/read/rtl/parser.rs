//! The `.rtl` reader: its sections, header, targets, user text, run count,
//! environment, and the checks that make a file whole.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use nom::bytes::complete::{tag, take_while1};
use nom::character::complete::space0;
use nom::combinator::all_consuming;
use nom::sequence::terminated;
use nom::{IResult, Parser};

use crate::error::{ParseError, Warning, describe_found};
use crate::measurement::{
    AXIS_PLACEHOLDER, AxisSource, Environment, Measurement, Metadata, SourceFormat, StartEnd,
    TestDate,
};
use crate::read::text::{self, Line, check_target_mm, end_of_file_line, split_key};
use crate::read::{missing_readings_warning, parse_date};
use crate::units::LengthUnit;

use super::{NO_SENSOR_C, ROTARY_OWNER};

/// The sections of an `.rtl` file, in the order the spec gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Section {
    Header,
    TargetData,
    UserText,
    Runs,
    Deviations,
    Environment,
    Eof,
    /// A section the reader does not know; its lines are skipped.
    Unknown,
}

impl Section {
    pub(super) fn from_name(name: &str) -> Section {
        let normalised = name.trim().to_ascii_uppercase().replace('_', " ");
        match normalised.as_str() {
            "HEADER" => Section::Header,
            "TARGET DATA" => Section::TargetData,
            "USER-TEXT" | "USER TEXT" => Section::UserText,
            "RUNS" => Section::Runs,
            "DEVIATIONS" => Section::Deviations,
            "ENVIRONMENT" => Section::Environment,
            "EOF" => Section::Eof,
            _ => Section::Unknown,
        }
    }
}

/// `NAME::` with optional surrounding blanks: a section header line.
pub(super) fn section_header(input: &str) -> IResult<&str, &str> {
    let name = take_while1(|c: char| c.is_ascii_alphanumeric() || c == ' ' || c == '-' || c == '_');
    all_consuming((space0, terminated(name, tag("::")), space0))
        .map(|(_, name, _)| name)
        .parse(input)
}
/// One file run's deviation rows as they are read: its readings, already
/// in place, and what its direction needs (the module doc), so that no list
/// of rows is kept (a large file has a hundred thousand).
#[derive(Debug, Default)]
pub(super) struct RunRows {
    /// Deviations in mm, indexed like the sorted targets; `None` until listed.
    pub(super) deviations_mm: Vec<Option<f64>>,
    /// Sorted position and target number of the run's last row so far.
    pub(super) last: Option<(usize, usize)>,
    /// Whether the run goes towards larger targets, once it has two rows.
    pub(super) up: Option<bool>,
    /// The run's first row that turns back (line, column, its target number
    /// and that of the row before it).
    pub(super) turns_back: Option<(usize, usize, usize, usize)>,
}

/// A number with the line and column it came from.
#[derive(Clone, Copy, Debug)]
pub(super) struct Located<T> {
    pub(super) value: T,
    pub(super) line: usize,
    pub(super) column: usize,
}

#[derive(Default)]
pub(super) struct RtlParser {
    pub(super) section: Option<Section>,
    pub(super) seen: HashMap<&'static str, usize>,
    pub(super) collecting_targets: bool,
    pub(super) target_count: Option<Located<usize>>,
    pub(super) targets: Vec<Located<f64>>,
    /// Target value (as bits, -0 folded into +0) → index into `targets`.
    pub(super) target_lookup: HashMap<u64, usize>,
    pub(super) run_count: Option<Located<u32>>,
    /// Line of `DEVIATIONS::`, from where a pair listed twice is looked up.
    pub(super) deviations_line: usize,
    /// Target number − 1 → position among the sorted targets; made on the
    /// first deviation row (the target list is complete by then: a row
    /// needs its target listed, and TARGET DATA:: appears once).
    pub(super) sorted_index: Vec<usize>,
    /// Per file run, its rows so far (made on its first row). Boxed: a
    /// slot is made for every run up to the largest number read, and a row
    /// may name run 100 000 000 of a Run-count that large.
    pub(super) run_rows: Vec<Option<Box<RunRows>>>,
    /// Deviation rows read, over all runs.
    pub(super) row_count: usize,
    pub(super) metadata: Metadata,
    pub(super) axis: Option<String>,
    pub(super) last_user_key: Option<String>,
    pub(super) environment: Environment,
    pub(super) capture_start: Option<String>,
    pub(super) capture_end: Option<String>,
    pub(super) saw_eof: Option<usize>,
    pub(super) warnings: Vec<Warning>,
}

impl RtlParser {
    pub(super) fn run(&mut self, input: &str) -> Result<(), ParseError> {
        let mut lines = text::lines(input);
        while let Some(line) = lines.next() {
            // Most lines of a large file are plain deviation rows: the ones
            // after a plain row are read straight off the text.
            if self.section == Some(Section::Deviations) && self.plain_deviation_row(&line) {
                if let Some((rest, number)) = lines.remaining() {
                    let (rest, number) = self.simple_rows(rest, number);
                    lines.resume_at(rest, number);
                }
                continue;
            }
            if line.is_blank() {
                continue;
            }
            if let Some(eof_line) = self.saw_eof {
                return Err(line.error_at(
                    line.text.trim_start(),
                    format!(
                        "expected nothing after EOF:: (line {eof_line}), found {}",
                        describe_found(line.text.trim())
                    ),
                ));
            }
            // Only a line ending in `::` can be a section header; a large
            // file is a hundred thousand deviation rows that are not.
            if line.text.trim_end().ends_with("::")
                && let Ok((_, name)) = section_header(line.text)
            {
                self.enter_section(&line, name)?;
                continue;
            }
            let Some(section) = self.section else {
                return Err(line.expected_at(
                    line.text.trim_start(),
                    "HEADER:: as the first line of an .rtl file",
                ));
            };
            match section {
                Section::Header => self.header_line(&line)?,
                Section::TargetData => self.target_data_line(&line)?,
                Section::UserText => self.user_text_line(&line),
                Section::Runs => self.runs_line(&line)?,
                Section::Deviations => self.deviation_line(&line, input)?,
                Section::Environment => self.environment_line(&line)?,
                Section::Eof | Section::Unknown => {}
            }
        }
        Ok(())
    }

    pub(super) fn enter_section(&mut self, line: &Line<'_>, name: &str) -> Result<(), ParseError> {
        let section = Section::from_name(name);
        let name_at = line.text.trim_start();
        if self.section.is_none() && section != Section::Header {
            return Err(line.expected_at(name_at, "HEADER:: as the first line of an .rtl file"));
        }
        self.collecting_targets = false;
        if section == Section::Unknown {
            self.warnings.push(Warning::UnknownSection {
                line: line.number,
                name: name.trim().to_string(),
            });
            self.section = Some(section);
            return Ok(());
        }
        let key = section_key(section);
        if let Some(first) = self.seen.insert(key, line.number) {
            return Err(line.error_at(
                name_at,
                format!("section {key}:: appears twice (first at line {first})"),
            ));
        }
        if section == Section::Eof {
            self.saw_eof = Some(line.number);
        }
        if section == Section::Deviations {
            self.deviations_line = line.number;
        }
        self.section = Some(section);
        Ok(())
    }

    pub(super) fn header_line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let (key, value) = key_value(line)?;
        match key.to_ascii_lowercase().as_str() {
            "owner" => {
                if value.eq_ignore_ascii_case(ROTARY_OWNER) {
                    return Err(line.error_at(
                        value,
                        format!(
                            "found Owner : {value}, a rotary axis test: the layout of Renishaw's rotary files is not public, \
                             so it is not read; export the data as CSV with the header target_deg,run,direction,deviation_arcsec (docs/src/input-formats.md, The CSV layout)"
                        ),
                    ));
                }
                let geometry = [
                    "straightness",
                    "angular",
                    "pitch",
                    "yaw",
                    "roll",
                    "squareness",
                ];
                if geometry
                    .iter()
                    .any(|word| value.to_ascii_lowercase().contains(word))
                {
                    return Err(line.error_at(
                        value,
                        format!(
                            "found Owner : {value}, a straightness or angular test: no sample of Renishaw's layout for it is public, \
                             so it is not read (a wrong guess would put the wrong error in the model); export the readings as CSV \
                             with error columns (target_mm,run,direction,EYX_um,… or EBX_urad,…; docs/src/input-formats.md, Geometry tests)"
                        ),
                    ));
                }
                if !value.eq_ignore_ascii_case("linear") {
                    return Err(line.error_at(
                        value,
                        format!(
                            "expected Owner : Linear, found {}: only linear measurements are supported (angular and straightness files are not)",
                            describe_found(value)
                        ),
                    ));
                }
            }
            "file type" | "version no" => self.keep(key, value),
            _ => self.unknown_key(line, key),
        }
        Ok(())
    }

    pub(super) fn target_data_line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        // A target value line has no colon; any `Key:` line ends the target list.
        let Some((key, value)) = split_key(line.text, ':') else {
            if !self.collecting_targets {
                return Err(
                    line.expected_at(line.text.trim_start(), "Key : value in TARGET DATA::")
                );
            }
            return self.target_values(line, line.text);
        };
        self.collecting_targets = false;
        match key.to_ascii_lowercase().as_str() {
            "target-count" => {
                let count = text::integer(line, value, "target count")?;
                self.target_count = Some(Located {
                    value: count as usize,
                    line: line.number,
                    column: line.column_of(value),
                });
            }
            "targets" => {
                self.collecting_targets = true;
                self.target_values(line, value)?;
            }
            "filetype" | "flags" => self.keep(key, value),
            _ => self.unknown_key(line, key),
        }
        Ok(())
    }

    pub(super) fn target_values(
        &mut self,
        line: &Line<'_>,
        values: &str,
    ) -> Result<(), ParseError> {
        if self.targets.is_empty()
            && let Some(count) = self.target_count
        {
            // Room for the targets the file announces, made once (bounded: a
            // Target-count of a billion must not reserve gigabytes).
            let room = count.value.min(1 << 16);
            self.targets.reserve(room);
            self.target_lookup.reserve(room);
        }
        for token in values.split_whitespace() {
            let value = text::number(line, token, "target position in mm")?;
            let column = line.column_of(token);
            check_target_mm(value, line.number, column)?;
            let key = (value + 0.0).to_bits();
            match self.target_lookup.entry(key) {
                Entry::Occupied(first) => {
                    let first = self.targets[*first.get()];
                    return Err(ParseError::new(
                        line.number,
                        column,
                        format!(
                            "duplicate target {value} mm (first listed at line {}, column {})",
                            first.line, first.column
                        ),
                    ));
                }
                Entry::Vacant(slot) => {
                    slot.insert(self.targets.len());
                }
            }
            self.targets.push(Located {
                value,
                line: line.number,
                column,
            });
        }
        Ok(())
    }

    pub(super) fn user_text_line(&mut self, line: &Line<'_>) {
        let Some((key, value)) = split_key(line.text, ':') else {
            // USER-TEXT is free text: a line without a key continues the previous value.
            if let Some(key) = self.last_user_key.clone() {
                self.append_user_text(&key, line.text.trim());
            }
            return;
        };
        let key = key.to_ascii_lowercase();
        self.set_user_text(line, &key, value);
        self.last_user_key = Some(key);
    }

    pub(super) fn set_user_text(&mut self, line: &Line<'_>, key: &str, value: &str) {
        let value = (!value.is_empty()).then(|| value.to_string());
        match key {
            "machine" => self.metadata.machine = value,
            "serial no" => self.metadata.serial_number = value,
            "by" => self.metadata.operator = value,
            "axis" => self.axis = value,
            "location" => self.metadata.location = value,
            "title" => self.metadata.description = value,
            "date" => {
                self.metadata.date = value.map(|raw| TestDate {
                    parsed: parse_date(&raw),
                    raw,
                })
            }
            _ => self.unknown_key(line, key),
        }
    }

    pub(super) fn append_user_text(&mut self, key: &str, more: &str) {
        let target = match key {
            "machine" => &mut self.metadata.machine,
            "location" => &mut self.metadata.location,
            "title" => &mut self.metadata.description,
            _ => return,
        };
        let joined = match target.take() {
            Some(previous) => format!("{previous} {more}"),
            None => more.to_string(),
        };
        *target = Some(joined);
    }

    pub(super) fn runs_line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let (key, value) = key_value(line)?;
        if !key.eq_ignore_ascii_case("run-count") {
            self.unknown_key(line, key);
            return Ok(());
        }
        let count = text::integer(line, value, "run count")?;
        let Ok(count) = u32::try_from(count) else {
            return Err(line.error_at(value, format!("run count {count} is too large")));
        };
        self.run_count = Some(Located {
            value: count,
            line: line.number,
            column: line.column_of(value),
        });
        Ok(())
    }

    pub(super) fn environment_line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let (key, value) = key_value(line)?;
        let key_normalised = key
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
            .to_ascii_lowercase();
        let environment = &mut self.environment;
        match key_normalised.as_str() {
            "air temp" => environment.air_temperature_c = start_end(line, value, None)?,
            "air press" => environment.air_pressure_kpa = start_end(line, value, None)?,
            "air humid" => environment.air_humidity_pct = start_end(line, value, None)?,
            "mat temp 1" | "mat temp 2" | "mat temp 3" => {
                let index = usize::from(key_normalised.as_bytes()[9] - b'1');
                environment.material_temperature_c[index] =
                    start_end(line, value, Some(NO_SENSOR_C))?;
            }
            "env factor" => environment.environmental_factor_um = start_end(line, value, None)?,
            "exp coeff" => {
                environment.expansion_coefficient_ppm_per_k = start_end(line, value, None)?.start
            }
            "date time" => {
                let quoted: Vec<&str> = value.split('"').skip(1).step_by(2).collect();
                self.capture_start = quoted.first().map(|s| s.to_string());
                self.capture_end = quoted.get(1).map(|s| s.to_string());
            }
            "final data" => self.keep(key, value),
            _ => self.unknown_key(line, key),
        }
        Ok(())
    }

    pub(super) fn keep(&mut self, key: &str, value: &str) {
        self.metadata
            .extra
            .push((key.to_string(), value.to_string()));
    }

    pub(super) fn unknown_key(&mut self, line: &Line<'_>, key: &str) {
        self.warnings.push(Warning::UnknownKey {
            line: line.number,
            key: key.to_string(),
        });
    }

    pub(super) fn finish(mut self, input: &str) -> Result<(Measurement, Vec<Warning>), ParseError> {
        // Only a message needs it (counting the lines of a large file again
        // is not free).
        let end_line = || end_of_file_line(input);
        if self.section.is_none() {
            return Err(ParseError::expected(
                1,
                1,
                "HEADER:: as the first line of an .rtl file",
                "an empty file",
            ));
        }
        if self.saw_eof.is_none() {
            return Err(ParseError::new(
                end_line(),
                1,
                "expected EOF:: at the end of the file, found end of file: the file is truncated",
            ));
        }
        for (key, name) in [
            ("TARGET DATA", "TARGET DATA::"),
            ("RUNS", "RUNS::"),
            ("DEVIATIONS", "DEVIATIONS::"),
        ] {
            if !self.seen.contains_key(key) {
                return Err(ParseError::new(
                    end_line(),
                    1,
                    format!("expected a {name} section, found none"),
                ));
            }
        }
        let Some(target_count) = self.target_count else {
            let line = self.seen["TARGET DATA"];
            return Err(ParseError::new(
                line,
                1,
                "expected Target-count: in TARGET DATA::, found none",
            ));
        };
        if target_count.value != self.targets.len() {
            return Err(ParseError::new(
                target_count.line,
                target_count.column,
                format!(
                    "Target-count is {} but {} target(s) are listed",
                    target_count.value,
                    self.targets.len()
                ),
            ));
        }
        let Some(run_count) = self.run_count else {
            let line = self.seen["RUNS"];
            return Err(ParseError::new(
                line,
                1,
                "expected Run-count: in RUNS::, found none",
            ));
        };
        if run_count.value == 0 {
            return Err(ParseError::new(
                run_count.line,
                run_count.column,
                "expected at least one run, found Run-count:0",
            ));
        }
        let runs = self.assemble_runs(run_count)?;
        let axis = match self.axis.take() {
            Some(axis) => {
                self.metadata.axis_source = AxisSource::file("Axis");
                axis
            }
            None => {
                self.warnings.push(Warning::InconsistentMetadata {
                    message:
                        "no Axis: in USER-TEXT::; the axis is not recorded (give --axis to name it)"
                            .to_string(),
                });
                self.metadata.axis_source = AxisSource::NotRecorded;
                AXIS_PLACEHOLDER.to_string()
            }
        };
        let capture = |raw: String| TestDate {
            parsed: parse_date(&raw),
            raw,
        };
        // The USER-TEXT date names the test; the capture times say how long it took.
        let start = self.capture_start.take().map(capture);
        if self.metadata.date.is_none() {
            self.metadata.date = start;
        }
        self.metadata.end_date = self.capture_end.take().map(capture);
        self.metadata.source_format = Some(SourceFormat::Rtl);
        self.metadata.length_unit = LengthUnit::Millimetre;
        let targets_mm: Vec<f64> = sorted_targets(&self.targets)
            .iter()
            .map(|t| t.value)
            .collect();
        if let Some(warning) = missing_readings_warning(&runs, &targets_mm) {
            self.warnings.push(warning);
        }
        let measurement = Measurement::new(axis, targets_mm, runs, self.environment, self.metadata)
            .map_err(|error| ParseError::new(1, 1, error.to_string()))?;
        Ok((measurement, self.warnings))
    }
}

#[derive(Clone, Copy)]
pub(super) struct SortedTarget {
    pub(super) value: f64,
    pub(super) original_index: usize,
}

pub(super) fn sorted_targets(targets: &[Located<f64>]) -> Vec<SortedTarget> {
    let mut sorted: Vec<SortedTarget> = targets
        .iter()
        .enumerate()
        .map(|(original_index, t)| SortedTarget {
            value: t.value,
            original_index,
        })
        .collect();
    sorted.sort_by(|a, b| a.value.total_cmp(&b.value));
    sorted
}

pub(super) fn section_key(section: Section) -> &'static str {
    match section {
        Section::Header => "HEADER",
        Section::TargetData => "TARGET DATA",
        Section::UserText => "USER-TEXT",
        Section::Runs => "RUNS",
        Section::Deviations => "DEVIATIONS",
        Section::Environment => "ENVIRONMENT",
        Section::Eof => "EOF",
        Section::Unknown => "?",
    }
}

/// `Key : value`, or an error saying a key was expected.
pub(super) fn key_value<'a>(line: &Line<'a>) -> Result<(&'a str, &'a str), ParseError> {
    split_key(line.text, ':').ok_or_else(|| line.expected_at(line.text.trim_start(), "Key : value"))
}

/// `start end [flag]`: two numbers and an optional third of unknown meaning.
/// `sentinel` is the value that means "no sensor"; it becomes `None`.
pub(super) fn start_end(
    line: &Line<'_>,
    value: &str,
    sentinel: Option<f64>,
) -> Result<StartEnd, ParseError> {
    let tokens: Vec<&str> = value.split_whitespace().collect();
    if tokens.len() < 2 {
        let at = tokens.first().copied().unwrap_or(value);
        return Err(line.error_at(
            at,
            format!(
                "expected start and end values, found {} value(s)",
                tokens.len()
            ),
        ));
    }
    let read = |token: &str| -> Result<Option<f64>, ParseError> {
        let number = text::number(line, token, "environment value")?;
        Ok((Some(number) != sentinel).then_some(number))
    };
    Ok(StartEnd::new(read(tokens[0])?, read(tokens[1])?))
}
