//! Renishaw LaserXL / Laser10 `.rtl` linear data: parser and writer.
//!
//! Implements `../shared/spec/renishaw-rtl.md`. No Renishaw specification is
//! public; the layout is the one five independent third-party programs agree
//! on (`../shared/notes/rtl-and-com-search.md`). What the spec calls lenient
//! is lenient here, each with a test:
//! - section names and keys match case-insensitively after trimming padding;
//! - LF or CRLF, blank lines anywhere (Latin-1 is handled by `read::decode`);
//! - an unknown section is skipped with a warning;
//! - targets may be negative, unsorted, several per line, or start on the
//!   `Targets :` line itself;
//! - deviation rows are split on any whitespace and keyed on their
//!   (run, target number) columns, never on row position; a missing pair is a
//!   missing reading, not zero.
//!
//! Everything else is an error with line and column: a row with the wrong
//! number of fields, a run or target number out of range, a pair listed twice,
//! a count that does not match, a run whose rows go neither up nor down, a
//! file without `EOF::` (truncated), an `Owner` other than `Linear`.
//!
//! A run's direction is inferred from the order its rows visit the targets:
//! towards larger target positions is ↑. A run with a single row falls back to
//! odd = ↑, even = ↓, as every known reader assumes.
//!
//! Deviations in the file are µm, actual minus target; targets are mm.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

/// The `Owner` value taken to mark a rotary (XR20) test. No rotary `.rtl`
/// sample is public (`../shared/spec/standards.md` §6), so this is the one
/// assumption about one: its header says `Owner : Rotary`, and the rest of
/// its layout is unknown, so such a file is refused at that line.
pub const ROTARY_OWNER: &str = "Rotary";

use nom::bytes::complete::{tag, take_while1};
use nom::character::complete::space0;
use nom::combinator::all_consuming;
use nom::sequence::terminated;
use nom::{IResult, Parser};

use crate::error::{ParseError, Warning, describe_found};
use crate::measurement::{
    AXIS_PLACEHOLDER, AxisSource, Direction, Environment, Measurement, Metadata, Run, SourceFormat,
    StartEnd, TestDate,
};
use crate::read::text::{
    self, Line, check_deviation_mm, check_target_mm, end_of_file_line, split_key,
};
use crate::read::{missing_readings_warning, parse_date};
use crate::units::{LengthUnit, um_text, um_to_mm};

/// Material temperature Renishaw writes when no sensor is fitted (°C).
const NO_SENSOR_C: f64 = -10.0;

/// Parses the text of an `.rtl` file.
pub fn parse(input: &str) -> Result<(Measurement, Vec<Warning>), ParseError> {
    let mut parser = RtlParser::default();
    parser.run(input)?;
    parser.finish(input)
}

/// Writes a measurement as an `.rtl` file (CRLF line ends, as Renishaw's software writes).
///
/// Runs are written in the order measured, one file run per direction pass;
/// rows go in the order the run visited the targets. Numbers use the shortest
/// text that reads back to the same value, so `parse(write(m))` gives `m` back.
pub fn write(measurement: &Measurement) -> String {
    let mut out = String::new();
    let mut line = |text: &str| {
        out.push_str(text);
        out.push_str("\r\n");
    };
    let metadata = &measurement.metadata;
    let field = |value: &Option<String>| value.clone().unwrap_or_default();
    let unidirectional =
        measurement.run_count(Direction::Up) == 0 || measurement.run_count(Direction::Down) == 0;

    line("HEADER::");
    line("File type  : rtl");
    line("Owner      : Linear");
    line("Version no : axcomp");
    line("");
    line("TARGET DATA::");
    line("Filetype  : ISO");
    line(&format!("Target-count: {}", measurement.targets_mm().len()));
    line("Targets :");
    for chunk in measurement.targets_mm().chunks(5) {
        let texts: Vec<String> = chunk.iter().map(|t| format!("{t}")).collect();
        line(&texts.join("  "));
    }
    line(if unidirectional {
        "Flags: 0 1 2 0"
    } else {
        "Flags: 0 0 2 0"
    });
    line("");
    line("USER-TEXT::");
    line(&format!("Machine: {}", field(&metadata.machine)));
    line(&format!("Serial No: {}", field(&metadata.serial_number)));
    let date = metadata
        .date
        .as_ref()
        .map(|d| d.raw.clone())
        .unwrap_or_default();
    line(&format!("Date: {date}"));
    line(&format!("By: {}", field(&metadata.operator)));
    // A placeholder name stays unrecorded: the file must not claim an axis.
    let axis = if measurement.axis_recorded() {
        measurement.axis()
    } else {
        ""
    };
    line(&format!("Axis: {axis}"));
    line(&format!("Location: {}", field(&metadata.location)));
    line(&format!("TITLE: {}", field(&metadata.description)));
    line("");
    line("RUNS::");
    line(&format!("Run-count:{}", measurement.runs().len()));
    line("");
    line("DEVIATIONS::");
    line("Run Target Data:");
    for (run_index, run) in measurement.runs().iter().enumerate() {
        let order: Vec<usize> = match run.direction {
            Direction::Up => (0..measurement.targets_mm().len()).collect(),
            Direction::Down => (0..measurement.targets_mm().len()).rev().collect(),
        };
        for target_index in order {
            if let Some(deviation_mm) = run.deviations_mm[target_index] {
                line(&format!(
                    "{:<3} {:<6} {}",
                    run_index + 1,
                    target_index + 1,
                    um_text(deviation_mm)
                ));
            }
        }
    }
    line("");
    line("ENVIRONMENT::");
    write_environment(&measurement.environment, &mut line);
    if let Some(times) = capture_times(metadata) {
        line(&times);
    }
    line("");
    line("EOF::");
    out
}

fn write_environment(environment: &Environment, line: &mut impl FnMut(&str)) {
    let pair = |value: StartEnd, missing: f64| {
        format!(
            "{:.6} {:.6}",
            value.start.unwrap_or(missing),
            value.end.unwrap_or(missing)
        )
    };
    if !environment.air_temperature_c.is_empty() {
        line(&format!(
            "Air temp   : {}",
            pair(environment.air_temperature_c, 0.0)
        ));
    }
    if !environment.air_pressure_kpa.is_empty() {
        line(&format!(
            "Air press  : {}",
            pair(environment.air_pressure_kpa, 0.0)
        ));
    }
    if !environment.air_humidity_pct.is_empty() {
        line(&format!(
            "Air humid  : {}",
            pair(environment.air_humidity_pct, 0.0)
        ));
    }
    for (index, sensor) in environment.material_temperature_c.iter().enumerate() {
        line(&format!(
            "Mat temp {} : {}",
            index + 1,
            pair(*sensor, NO_SENSOR_C)
        ));
    }
    if !environment.environmental_factor_um.is_empty() {
        let factor = environment.environmental_factor_um;
        line(&format!(
            "Env factor : {:.8} {:.8}",
            factor.start.unwrap_or(0.0),
            factor.end.unwrap_or(0.0)
        ));
    }
    if let Some(coefficient) = environment.expansion_coefficient_ppm_per_k {
        line(&format!("Exp coeff  : {coefficient:.6} {coefficient:.6}"));
    }
}

/// The `Date Time` line in the format of real files (`"10:46 Dec 12 2016"`),
/// when the start and end of the test are known.
fn capture_times(metadata: &Metadata) -> Option<String> {
    let start = metadata.date.as_ref()?.parsed?;
    let end = metadata.end_date.as_ref()?.parsed?;
    let format = |at: chrono::NaiveDateTime| at.format("%H:%M %b %d %Y").to_string();
    Some(format!(
        "Date Time  : \"{}\" \"{}\"",
        format(start),
        format(end)
    ))
}

/// The sections of an `.rtl` file, in the order the spec gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Section {
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
    fn from_name(name: &str) -> Section {
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
fn section_header(input: &str) -> IResult<&str, &str> {
    let name = take_while1(|c: char| c.is_ascii_alphanumeric() || c == ' ' || c == '-' || c == '_');
    all_consuming((space0, terminated(name, tag("::")), space0))
        .map(|(_, name, _)| name)
        .parse(input)
}

/// One file run's deviation rows as they are read: its readings, already
/// in place, and what its direction needs (the module doc), so that no list
/// of rows is kept (a large file has a hundred thousand).
#[derive(Debug, Default)]
struct RunRows {
    /// Deviations in mm, indexed like the sorted targets; `None` until listed.
    deviations_mm: Vec<Option<f64>>,
    /// Sorted position and target number of the run's last row so far.
    last: Option<(usize, usize)>,
    /// Whether the run goes towards larger targets, once it has two rows.
    up: Option<bool>,
    /// The run's first row that turns back (line, column, its target number
    /// and that of the row before it).
    turns_back: Option<(usize, usize, usize, usize)>,
}

/// A number with the line and column it came from.
#[derive(Clone, Copy, Debug)]
struct Located<T> {
    value: T,
    line: usize,
    column: usize,
}

#[derive(Default)]
struct RtlParser {
    section: Option<Section>,
    seen: HashMap<&'static str, usize>,
    collecting_targets: bool,
    target_count: Option<Located<usize>>,
    targets: Vec<Located<f64>>,
    /// Target value (as bits, -0 folded into +0) → index into `targets`.
    target_lookup: HashMap<u64, usize>,
    run_count: Option<Located<u32>>,
    /// Line of `DEVIATIONS::`, from where a pair listed twice is looked up.
    deviations_line: usize,
    /// Target number − 1 → position among the sorted targets; made on the
    /// first deviation row (the target list is complete by then: a row
    /// needs its target listed, and TARGET DATA:: appears once).
    sorted_index: Vec<usize>,
    /// Per file run, its rows so far (made on its first row). Boxed: a
    /// slot is made for every run up to the largest number read, and a row
    /// may name run 100 000 000 of a Run-count that large.
    run_rows: Vec<Option<Box<RunRows>>>,
    /// Deviation rows read, over all runs.
    row_count: usize,
    metadata: Metadata,
    axis: Option<String>,
    last_user_key: Option<String>,
    environment: Environment,
    capture_start: Option<String>,
    capture_end: Option<String>,
    saw_eof: Option<usize>,
    warnings: Vec<Warning>,
}

impl RtlParser {
    fn run(&mut self, input: &str) -> Result<(), ParseError> {
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

    fn enter_section(&mut self, line: &Line<'_>, name: &str) -> Result<(), ParseError> {
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

    fn header_line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let (key, value) = key_value(line)?;
        match key.to_ascii_lowercase().as_str() {
            "owner" => {
                if value.eq_ignore_ascii_case(ROTARY_OWNER) {
                    return Err(line.error_at(
                        value,
                        format!(
                            "found Owner : {value}, a rotary axis test: the layout of Renishaw's rotary files is not public, \
                             so it is not read; export the data as CSV with the header target_deg,run,direction,deviation_arcsec (README, CSV)"
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
                             with error columns (target_mm,run,direction,EYX_um,… or EBX_urad,…; README, Geometry tests)"
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

    fn target_data_line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
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

    fn target_values(&mut self, line: &Line<'_>, values: &str) -> Result<(), ParseError> {
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

    fn user_text_line(&mut self, line: &Line<'_>) {
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

    fn set_user_text(&mut self, line: &Line<'_>, key: &str, value: &str) {
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

    fn append_user_text(&mut self, key: &str, more: &str) {
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

    fn runs_line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
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

    fn deviation_line(&mut self, line: &Line<'_>, input: &str) -> Result<(), ParseError> {
        if line.text.contains(':') {
            let (key, _) = key_value(line)?;
            if !key.eq_ignore_ascii_case("run target data") {
                self.unknown_key(line, key);
            }
            return Ok(());
        }
        let [Some(run), Some(target), Some(value), None] = row_fields(line) else {
            let fields: Vec<&str> = line.fields().collect();
            let at = fields.get(3).copied().unwrap_or(line.text.trim_start());
            return Err(line.error_at(
                at,
                format!(
                    "deviation row has {} field(s), expected run, target number, value",
                    fields.len()
                ),
            ));
        };
        let file_run = text::integer(line, run, "run number")?;
        let Some(run_count) = self.run_count else {
            return Err(line.error_at(run, "deviation row before RUNS:: Run-count"));
        };
        if file_run == 0 || file_run > u64::from(run_count.value) {
            return Err(line.error_at(
                run,
                format!(
                    "run {file_run} is out of range: Run-count is {} (line {})",
                    run_count.value, run_count.line
                ),
            ));
        }
        let target_number = text::integer(line, target, "target number")?;
        let listed = self.targets.len() as u64;
        if target_number == 0 || target_number > listed {
            return Err(line.error_at(
                target,
                format!(
                    "target number {target_number} is out of range: {listed} targets are listed"
                ),
            ));
        }
        let deviation_um = text::number(line, value, "deviation in µm")?;
        let deviation_mm =
            check_deviation_mm(um_to_mm(deviation_um), line.number, line.column_of(value))?;
        let file_run = file_run as u32;
        let target_number = target_number as usize;
        let row = (line.number, line.column_of(run));
        if !self.record_row(row, file_run, target_number, deviation_mm) {
            let first_line = self.first_row_line(input, line.number, file_run, target_number);
            return Err(line.error_at(
                target,
                format!(
                    "run {file_run} lists target {target_number} twice (first at line {first_line})"
                ),
            ));
        }
        Ok(())
    }

    /// Reads and records a deviation row in its common form (ASCII, three
    /// fields separated by blanks, every check passed); whether it did. Any
    /// other line is left, unchanged, to `deviation_line`, which reads it the
    /// same way or refuses it with its message.
    fn plain_deviation_row(&mut self, line: &Line<'_>) -> bool {
        let Some(run_count) = self.run_count else {
            return false;
        };
        let Some(row) = PlainRow::of(line.text) else {
            return false;
        };
        if !self.names_a_listed_pair(run_count, row.file_run, row.target_number) {
            return false;
        }
        let Ok(deviation_um) = text::number(line, row.value, "deviation in µm") else {
            return false;
        };
        let Ok(deviation_mm) = check_deviation_mm(um_to_mm(deviation_um), 0, 0) else {
            return false;
        };
        // The line is ASCII: the column is the byte offset + 1.
        let at = (line.number, row.run_offset + 1);
        self.record_row(
            at,
            row.file_run as u32,
            row.target_number as usize,
            deviation_mm,
        )
    }

    /// Whether a row's run and target numbers are within `Run-count` and
    /// the targets listed (a row outside is left to `deviation_line`, which
    /// says which number is out of range).
    fn names_a_listed_pair(
        &self,
        run_count: Located<u32>,
        file_run: u64,
        target_number: u64,
    ) -> bool {
        (1..=u64::from(run_count.value)).contains(&file_run)
            && (1..=self.targets.len() as u64).contains(&target_number)
    }

    /// Reads the rows at the start of `text` (from line `number` on) that
    /// are [`SimpleRow`]s and records them, up to the first line that is not
    /// one or that `record_row` does not take; returns the text from that
    /// line on and its number, for the line-by-line reading to go on.
    ///
    /// One pass over each row's bytes, where the line-by-line reading makes
    /// three (the line end, the fields, the number): a large file's hundred
    /// thousand rows were most of the time it took to read. A simple row is
    /// a plain row that `plain_deviation_row` takes, read to the same values.
    fn simple_rows<'a>(&mut self, mut text: &'a str, mut number: usize) -> (&'a str, usize) {
        let Some(run_count) = self.run_count else {
            return (text, number);
        };
        while let Some((row, length)) = SimpleRow::of(text) {
            let in_range = self.names_a_listed_pair(run_count, row.file_run, row.target_number);
            let Some(deviation_mm) = in_range
                .then(|| check_deviation_mm(um_to_mm(row.deviation_um), 0, 0).ok())
                .flatten()
            else {
                break;
            };
            // ASCII: the column is the byte offset + 1.
            let at = (number, row.run_offset + 1);
            if !self.record_row(
                at,
                row.file_run as u32,
                row.target_number as usize,
                deviation_mm,
            ) {
                break;
            }
            text = &text[length..];
            number += 1;
        }
        (text, number)
    }

    /// Puts a checked row's reading in its run and follows the run's
    /// direction; false, with nothing changed, when the run lists the target
    /// already. `at` is the row's line and column.
    fn record_row(
        &mut self,
        at: (usize, usize),
        file_run: u32,
        target_number: usize,
        deviation_mm: f64,
    ) -> bool {
        if self.sorted_index.is_empty() {
            self.sorted_index = vec![0; self.targets.len()];
            for (index, target) in sorted_targets(&self.targets).iter().enumerate() {
                self.sorted_index[target.original_index] = index;
            }
        }
        let run_index = file_run as usize - 1;
        if self.run_rows.len() <= run_index {
            self.run_rows.resize_with(run_index + 1, || None);
        }
        let target_count = self.targets.len();
        let run = self.run_rows[run_index].get_or_insert_with(|| {
            Box::new(RunRows {
                deviations_mm: vec![None; target_count],
                ..RunRows::default()
            })
        });
        let position = self.sorted_index[target_number - 1];
        let cell = &mut run.deviations_mm[position];
        if cell.is_some() {
            return false;
        }
        *cell = Some(deviation_mm);
        if let Some((last_position, last_target_number)) = run.last {
            let forward = position > last_position;
            match run.up {
                None => run.up = Some(forward),
                Some(up) if up != forward && run.turns_back.is_none() => {
                    run.turns_back = Some((at.0, at.1, target_number, last_target_number));
                }
                Some(_) => {}
            }
        }
        run.last = Some((position, target_number));
        self.row_count += 1;
        true
    }

    /// The line of the first row of `file_run` for `target_number`, searched
    /// from `DEVIATIONS::` up to `before` (only for the message of a pair
    /// listed twice: every row there has been read without error).
    fn first_row_line(
        &self,
        input: &str,
        before: usize,
        file_run: u32,
        target_number: usize,
    ) -> usize {
        let same_pair = |line: &Line<'_>| {
            if line.text.contains(':') {
                return false;
            }
            let [Some(run), Some(target), Some(_), None] = row_fields(line) else {
                return false;
            };
            run.parse() == Ok(file_run) && target.parse() == Ok(target_number)
        };
        text::lines(input)
            .skip(self.deviations_line)
            .take_while(|line| line.number < before)
            .find(same_pair)
            .map_or(before, |line| line.number)
    }

    fn environment_line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
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

    fn keep(&mut self, key: &str, value: &str) {
        self.metadata
            .extra
            .push((key.to_string(), value.to_string()));
    }

    fn unknown_key(&mut self, line: &Line<'_>, key: &str) {
        self.warnings.push(Warning::UnknownKey {
            line: line.number,
            key: key.to_string(),
        });
    }

    fn finish(mut self, input: &str) -> Result<(Measurement, Vec<Warning>), ParseError> {
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

    /// Takes each file run's readings, tells its direction and numbers the
    /// runs per direction in the order measured.
    fn assemble_runs(&mut self, run_count: Located<u32>) -> Result<Vec<Run>, ParseError> {
        // Every run needs a row: refuse an impossible count before sizing anything by it.
        if run_count.value as usize > self.row_count {
            return Err(ParseError::new(
                run_count.line,
                run_count.column,
                format!(
                    "Run-count is {} but there are only {} deviation rows",
                    run_count.value, self.row_count
                ),
            ));
        }
        let mut runs = Vec::with_capacity(run_count.value as usize);
        let mut numbers = [0u32; 2];
        let mut run_rows = std::mem::take(&mut self.run_rows).into_iter();
        for file_run in 1..=run_count.value {
            let Some(rows) = run_rows.next().flatten() else {
                return Err(ParseError::new(
                    run_count.line,
                    run_count.column,
                    format!(
                        "Run-count is {} but run {file_run} has no deviation rows",
                        run_count.value
                    ),
                ));
            };
            let direction = run_direction(&rows, file_run)?;
            let slot = usize::from(direction == Direction::Down);
            numbers[slot] += 1;
            runs.push(Run {
                direction,
                number: numbers[slot],
                start_time_s: None,
                deviations_mm: rows.deviations_mm,
            });
        }
        Ok(runs)
    }
}

/// The direction of one run from the order of its rows (see the module doc).
fn run_direction(rows: &RunRows, file_run: u32) -> Result<Direction, ParseError> {
    if let Some((line, column, target_number, previous_target_number)) = rows.turns_back {
        return Err(ParseError::new(
            line,
            column,
            format!(
                "run {file_run} visits the targets out of order (target {target_number} after target {previous_target_number}): expected the rows of a run to go all up or all down"
            ),
        ));
    }
    let up = rows.up.unwrap_or(file_run % 2 == 1);
    Ok(if up { Direction::Up } else { Direction::Down })
}

/// The first four whitespace-separated fields of a deviation row.
///
/// A row is ASCII in every file seen; splitting it on ASCII blanks is the
/// same split and a good part faster than the Unicode one.
fn row_fields<'a>(line: &Line<'a>) -> [Option<&'a str>; 4] {
    fn first_four<'a>(mut fields: impl Iterator<Item = &'a str>) -> [Option<&'a str>; 4] {
        std::array::from_fn(|_| fields.next())
    }
    if line.text.is_ascii() {
        first_four(line.text.split_ascii_whitespace())
    } else {
        first_four(line.fields())
    }
}

/// The start of a deviation row, `run target ` with blanks (spaces or
/// tabs) before and between: where each part is, up to the value.
struct RowStart {
    /// Byte offset of the run number.
    run_offset: usize,
    file_run: u64,
    target_number: u64,
    /// Byte offset of the value's first byte.
    value_at: usize,
}

impl RowStart {
    /// The start of the row `bytes` begins with, or `None`: no blank
    /// between the fields, a run or target number missing or too long to
    /// be exact. Reads up to the first byte of the value (a line end ends
    /// nothing here: it is not a digit and not a blank).
    #[inline]
    fn of(bytes: &[u8]) -> Option<RowStart> {
        let run_offset = skip_blanks(bytes, 0);
        let (file_run, after_run) = digits_at(bytes, run_offset)?;
        let target_at = skip_blanks(bytes, after_run);
        let (target_number, after_target) = digits_at(bytes, target_at)?;
        let value_at = skip_blanks(bytes, after_target);
        if target_at == after_run || value_at == after_target {
            return None;
        }
        Some(RowStart {
            run_offset,
            file_run,
            target_number,
            value_at,
        })
    }
}

/// The number of the digits at `bytes[from..]` and the offset after them,
/// or `None`: no digit, or more than 18 (every such number fits a u64).
#[inline]
fn digits_at(bytes: &[u8], from: usize) -> Option<(u64, usize)> {
    let mut number = 0u64;
    let mut at = from;
    while let Some(&b) = bytes.get(at).filter(|b| b.is_ascii_digit()) {
        number = number * 10 + u64::from(b - b'0');
        at += 1;
        if at - from > 18 {
            return None;
        }
    }
    (at > from).then_some((number, at))
}

/// The first byte from `at` on that is not a blank (space or tab).
#[inline]
fn skip_blanks(bytes: &[u8], mut at: usize) -> usize {
    while bytes.get(at).is_some_and(|&b| b == b' ' || b == b'\t') {
        at += 1;
    }
    at
}

/// A deviation row in its common form, `run target value` separated by
/// spaces or tabs, read in one pass over its bytes.
struct PlainRow<'a> {
    /// Byte offset of the run number in the line.
    run_offset: usize,
    file_run: u64,
    target_number: u64,
    /// The value's text, not yet parsed.
    value: &'a str,
}

impl<'a> PlainRow<'a> {
    /// The row, or `None` for anything else: a line with another byte, a
    /// run or target number too long to be exact, fewer or more fields.
    fn of(text: &'a str) -> Option<PlainRow<'a>> {
        let bytes = text.as_bytes();
        let start = RowStart::of(bytes)?;
        let value_at = start.value_at;
        let value_end = value_at
            + bytes[value_at..]
                .iter()
                .position(|&b| {
                    !(b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E'))
                })
                .unwrap_or(bytes.len() - value_at);
        if value_end == value_at || skip_blanks(bytes, value_end) != bytes.len() {
            return None;
        }
        Some(PlainRow {
            run_offset: start.run_offset,
            file_run: start.file_run,
            target_number: start.target_number,
            value: &text[value_at..value_end],
        })
    }
}

/// A deviation row in its simplest form, as the large files are written:
/// `run target value`, separated by spaces or tabs, the value a decimal of
/// at most 15 digits without exponent, the line ended by `\n` or `\r\n`.
/// Every simple row is a [`PlainRow`] whose value `text::number` reads as
/// [`text::short_decimal`] does.
#[derive(Debug, PartialEq)]
struct SimpleRow {
    /// Byte offset of the run number in the line.
    run_offset: usize,
    file_run: u64,
    target_number: u64,
    deviation_um: f64,
}

impl SimpleRow {
    /// The row at the start of `text` and its length with its line end, or
    /// `None` when the first line of `text` is not a simple row.
    #[inline]
    fn of(text: &str) -> Option<(SimpleRow, usize)> {
        let bytes = text.as_bytes();
        let start = RowStart::of(bytes)?;
        let (deviation_um, value_end) = text::short_decimal_at(bytes, start.value_at)?;
        let mut end = skip_blanks(bytes, value_end);
        if bytes.get(end) == Some(&b'\r') {
            end += 1;
        }
        (bytes.get(end) == Some(&b'\n')).then_some((
            SimpleRow {
                run_offset: start.run_offset,
                file_run: start.file_run,
                target_number: start.target_number,
                deviation_um,
            },
            end + 1,
        ))
    }
}

#[derive(Clone, Copy)]
struct SortedTarget {
    value: f64,
    original_index: usize,
}

fn sorted_targets(targets: &[Located<f64>]) -> Vec<SortedTarget> {
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

fn section_key(section: Section) -> &'static str {
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
fn key_value<'a>(line: &Line<'a>) -> Result<(&'a str, &'a str), ParseError> {
    split_key(line.text, ':').ok_or_else(|| line.expected_at(line.text.trim_start(), "Key : value"))
}

/// `start end [flag]`: two numbers and an optional third of unknown meaning.
/// `sentinel` is the value that means "no sensor"; it becomes `None`.
fn start_end(line: &Line<'_>, value: &str, sentinel: Option<f64>) -> Result<StartEnd, ParseError> {
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

#[cfg(test)]
mod tests;
