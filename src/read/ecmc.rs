//! ESS/PSI ecmc ISO 230-2 data files (`report.md_ISO230.dat`): parser.
//!
//! The format, as the ecmc scripts write it and the real files under
//! `../shared/data/ecmc/` show (`../shared/data/SOURCES.md`, "Format quirks"):
//! `KEY=VALUE` lines, `#` comments, blank lines anywhere. Keys:
//! `UNIT` (mm, inch, or an angle: `deg`, `degree`, `degrees`, `°`, which
//! makes the measurement a rotary axis in degrees), `CYCLES` (n), `POSITIONS` (m), `DEC` (print decimals),
//! `REF_PV`/`TEST_PV`/`TGT_SET_PV` (EPICS names, kept), `TGT_DATA[i]` (target i),
//! `REF_DATA_FWD[i,j]` and `REF_DATA_BWD[i,j]` (actual position at target i in
//! cycle j). The first line of most files glues a comment onto a key
//! (`TEST_DATA=# Input data file…`); it is kept as a note. Spaces around `=`,
//! `[` and `,`, and trailing spaces after values, are accepted.
//!
//! Values are actual positions, so the deviation is REF − TGT
//! (`../shared/spec/iso230-2.md`, "Independent check values"). FWD runs are ↑,
//! BWD runs ↓; the ecmc report script swaps the two labels (a known bug), we do
//! not. `CYCLES` and `POSITIONS`, when given, must agree with the data; when
//! absent they are taken from the data. A file that declares `CYCLES=n` must
//! hold every cycle 1..n in both directions: one that stops early (the logger
//! was stopped, the file was cut) is refused, naming the missing cycles and
//! the declaration's line, not evaluated as a shorter test.
//!
//! # The axis
//!
//! The format has no axis field. The axis is taken from what the file states,
//! by one documented rule ([`axis_letter`]): a PV name or a file name states
//! an axis when one of its segments (split at anything but a letter or a
//! digit: `:`, `-`, `_`, `.`) is a single axis letter X, Y, Z, A, B, C, U, V
//! or W (either case), and only one such letter appears in it. In this order:
//! 1. `TGT_SET_PV`, the setpoint of the axis that moved
//!    (`TARGET_DU:Z-PosCmd` is Z);
//! 2. `REF_PV`, the reference system's position (`LAB:X-Enc-PosAct`);
//! 3. the file name, which only the front end knows
//!    ([`axis_from_file_name`], called by `read::read_path`):
//!    `b02__z__report_z.md_ISO230.dat` and `target_x_report.md_ISO230.dat`.
//!
//! Names that merely number a motor (`IOC_TEST:Axis1-PosSet`,
//! `sls-sioc-ecat01:M1-PosSet`) state no letter: the axis is then not
//! recorded ([`AxisSource::NotRecorded`]), and a table is written only once
//! the user names it. When two of the sources name different letters, the
//! first in the order above is used, with a warning.

use crate::error::{ParseError, Warning};
use crate::measurement::{
    AXIS_PLACEHOLDER, AxisKind, AxisSource, Direction, Environment, Measurement, Metadata, Run,
    SourceFormat,
};
use crate::read::missing_readings_warning_of;
use crate::read::text::{
    self, Line, check_deviation_deg, check_deviation_mm, check_target_mm, end_of_file_line,
    split_key,
};
use crate::units::LengthUnit;

/// What `evaluate` and the report say beside an ecmc file's figures: the
/// ecmc script's own `report.md` differs, and why (docs/src/input-formats.md "ecmc's own
/// reports", pinned by `tests/it/conformance.rs`).
pub const VENDOR_REPORT_NOTE: &str = "ecmc's own report of this file will differ: \
    it swaps ↑ and ↓ (REF_DATA_FWD is shown as backward, so B̄ changes sign and the ↑/↓ figures trade places), \
    takes the lower end of E from one direction only (the higher of the two minima), \
    and gives R as the larger of R↑ and R↓ without ISO 230-2's 2s↑ + 2s↓ + |B_i| term; \
    axcomp follows ISO 230-2 (A, M and B agree)";

/// The instrument an ecmc file names: the `REF_PV` its reference positions
/// were read from.
fn reference_instrument(extra: &[(String, String)]) -> Option<String> {
    extra
        .iter()
        .find(|(key, value)| key.eq_ignore_ascii_case("REF_PV") && !value.trim().is_empty())
        .map(|(_, pv)| format!("reference position {} (REF_PV)", pv.trim()))
}

/// Largest number of positions or cycles, and so largest index, accepted.
const MAX_COUNT: u64 = 100_000;

/// Parses the text of an ecmc ISO 230-2 data file.
pub fn parse(input: &str) -> Result<(Measurement, Vec<Warning>), ParseError> {
    let mut file = EcmcFile::default();
    for line in text::lines(input) {
        let trimmed = line.text.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        file.line(&line)?;
    }
    file.finish(end_of_file_line(input))
}

/// A count given in the file, with where.
#[derive(Clone, Copy, Debug)]
struct Declared {
    value: usize,
    line: usize,
    column: usize,
}

/// A value at an index, with where.
#[derive(Clone, Copy, Debug)]
struct Entry {
    position_index: usize,
    cycle_index: usize,
    value: f64,
    line: usize,
    /// Column of the first index (where errors about the key point).
    column: usize,
    /// Column of the value.
    value_column: usize,
}

#[derive(Default)]
struct EcmcFile {
    unit: Option<Unit>,
    cycles: Option<Declared>,
    positions: Option<Declared>,
    targets: Vec<Entry>,
    forward: Vec<Entry>,
    backward: Vec<Entry>,
    metadata: Metadata,
    warnings: Vec<Warning>,
}

/// The key of a line, split into its name and its bracketed indices.
struct Key<'a> {
    name: &'a str,
    indices: Vec<(usize, &'a str)>,
}

impl EcmcFile {
    fn line(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let Some((key_text, value)) = split_key(line.text, '=') else {
            return Err(line.expected_at(line.text.trim_start(), "KEY=VALUE or a # comment"));
        };
        let key = parse_key(line, key_text)?;
        match (key.name.to_ascii_uppercase().as_str(), key.indices.len()) {
            ("TEST_DATA", 0) => self.keep("TEST_DATA", value.trim_start_matches('#').trim()),
            ("REF_PV" | "TEST_PV" | "TGT_SET_PV", 0) => self.keep(key.name, value),
            ("UNIT", 0) => self.unit = Some(unit(line, value)?),
            ("CYCLES", 0) => self.cycles = Some(declared(line, value, "cycle count")?),
            ("POSITIONS", 0) => self.positions = Some(declared(line, value, "position count")?),
            ("DEC", 0) => {
                text::integer(line, value, "decimal count")?;
            }
            ("TGT_DATA", 1) => {
                let entry = entry(line, &key, value, "target position")?;
                self.targets.push(entry);
            }
            ("REF_DATA_FWD", 2) => {
                let entry = entry(line, &key, value, "actual position")?;
                self.forward.push(entry);
            }
            ("REF_DATA_BWD", 2) => {
                let entry = entry(line, &key, value, "actual position")?;
                self.backward.push(entry);
            }
            ("TGT_DATA" | "REF_DATA_FWD" | "REF_DATA_BWD", found) => {
                let expected = if key.name.eq_ignore_ascii_case("TGT_DATA") {
                    1
                } else {
                    2
                };
                let at = key_text.trim_start();
                return Err(line.error_at(
                    at,
                    format!(
                        "{} takes {expected} index(es) in brackets, found {found}",
                        key.name.to_ascii_uppercase()
                    ),
                ));
            }
            _ => self.warnings.push(Warning::UnknownKey {
                line: line.number,
                key: key_text.trim().to_string(),
            }),
        }
        Ok(())
    }

    /// The axis the PV names state (module doc, "The axis"); sets the
    /// metadata's axis source and warns when the two PVs disagree.
    fn axis(&mut self) -> String {
        let pv = |name: &'static str| {
            self.metadata
                .extra
                .iter()
                .find(|(key, _)| key.eq_ignore_ascii_case(name))
                .and_then(|(_, value)| axis_letter(value).map(|letter| (name, letter)))
        };
        let stated: Vec<(&str, char)> = ["TGT_SET_PV", "REF_PV"]
            .into_iter()
            .filter_map(pv)
            .collect();
        let Some(&(field, letter)) = stated.first() else {
            self.metadata.axis_source = AxisSource::NotRecorded;
            return AXIS_PLACEHOLDER.to_string();
        };
        if let Some(&(other_field, other)) = stated.iter().find(|(_, l)| *l != letter) {
            self.warnings.push(Warning::InconsistentMetadata {
                message: format!(
                    "{field} names axis {letter} but {other_field} names {other}; the axis is called {letter} (use --axis to rename it)"
                ),
            });
        }
        self.metadata.axis_source = AxisSource::file(field);
        letter.to_string()
    }

    fn keep(&mut self, key: &str, value: &str) {
        self.metadata
            .extra
            .push((key.to_string(), value.to_string()));
    }

    fn finish(mut self, end_line: usize) -> Result<(Measurement, Vec<Warning>), ParseError> {
        if self.targets.is_empty() {
            return Err(ParseError::new(
                end_line,
                1,
                "expected TGT_DATA[i]= lines, found none",
            ));
        }
        let position_count = declared_count(self.positions, &self.targets, "POSITIONS")?;
        let cycle_count = match self.cycles {
            Some(declared) => declared.value,
            None => self
                .forward
                .iter()
                .chain(&self.backward)
                .map(|e| e.cycle_index)
                .max()
                .unwrap_or(0),
        };
        for entry in self.forward.iter().chain(&self.backward) {
            check_range(entry, position_count, cycle_count)?;
        }
        let unit = self.unit.unwrap_or(Unit::Length(LengthUnit::Millimetre));
        let mut target_of_position = vec![None; position_count];
        for entry in &self.targets {
            if let Some(first) = target_of_position[entry.position_index - 1].replace(*entry) {
                return Err(ParseError::new(
                    entry.line,
                    entry.column,
                    format!(
                        "TGT_DATA[{}] is given twice (first at line {})",
                        entry.position_index, first.line
                    ),
                ));
            }
        }
        let mut targets: Vec<Entry> = Vec::with_capacity(position_count);
        for (index, target) in target_of_position.iter().enumerate() {
            match target {
                Some(target) => targets.push(*target),
                None => {
                    let (line, column) =
                        self.positions.map_or((end_line, 1), |p| (p.line, p.column));
                    return Err(ParseError::new(
                        line,
                        column,
                        format!(
                            "expected TGT_DATA[{}], found none: every position 1..{position_count} needs a target",
                            index + 1
                        ),
                    ));
                }
            }
        }
        let mut order: Vec<usize> = (0..position_count).collect();
        order.sort_by(|&a, &b| targets[a].value.total_cmp(&targets[b].value));
        for pair in order.windows(2) {
            let (first, second) = (targets[pair[0]], targets[pair[1]]);
            if first.value == second.value {
                let later = if second.line > first.line {
                    second
                } else {
                    first
                };
                let earlier = if second.line > first.line {
                    first
                } else {
                    second
                };
                return Err(ParseError::new(
                    later.line,
                    later.column,
                    format!(
                        "duplicate target {} (also TGT_DATA[{}] at line {})",
                        later.value, earlier.position_index, earlier.line
                    ),
                ));
            }
        }
        let targets_mm: Vec<f64> = order
            .iter()
            .map(|&i| {
                let target = targets[i];
                check_target_mm(
                    unit.to_inner(target.value),
                    target.line,
                    target.value_column,
                )
            })
            .collect::<Result<_, _>>()?;
        let grid = |entries: &[Entry], name: &str| -> Result<Vec<Vec<Option<f64>>>, ParseError> {
            let mut grid = vec![vec![None; position_count]; cycle_count];
            let mut lines = vec![vec![0usize; position_count]; cycle_count];
            for entry in entries {
                let (cycle, position) = (entry.cycle_index - 1, entry.position_index - 1);
                if grid[cycle][position].is_some() {
                    return Err(ParseError::new(
                        entry.line,
                        entry.column,
                        format!(
                            "{name}[{},{}] is given twice (first at line {})",
                            entry.position_index, entry.cycle_index, lines[cycle][position]
                        ),
                    ));
                }
                let deviation = unit.to_inner(entry.value - targets[position].value);
                let deviation = match unit {
                    Unit::Length(_) => {
                        check_deviation_mm(deviation, entry.line, entry.value_column)?
                    }
                    Unit::Degree => check_deviation_deg(deviation, entry.line, entry.value_column)?,
                };
                grid[cycle][position] = Some(deviation);
                lines[cycle][position] = entry.line;
            }
            Ok(grid)
        };
        let forward = grid(&self.forward, "REF_DATA_FWD")?;
        let backward = grid(&self.backward, "REF_DATA_BWD")?;
        if let Some(declared) = self.cycles {
            check_cycles_complete(
                declared,
                &[("REF_DATA_FWD", &forward), ("REF_DATA_BWD", &backward)],
            )?;
        }
        // Runs in the order measured: each cycle goes forward, then backward.
        let mut runs = Vec::with_capacity(2 * cycle_count);
        let mut numbers = [0u32; 2];
        for cycle in 0..cycle_count {
            for (direction, grid) in [(Direction::Up, &forward), (Direction::Down, &backward)] {
                let by_position = &grid[cycle];
                if by_position.iter().all(Option::is_none) {
                    continue;
                }
                let slot = usize::from(direction == Direction::Down);
                numbers[slot] += 1;
                runs.push(Run {
                    direction,
                    number: numbers[slot],
                    start_time_s: None,
                    deviations: order.iter().map(|&p| by_position[p]).collect(),
                });
            }
        }
        if runs.is_empty() {
            return Err(ParseError::new(
                end_line,
                1,
                "expected REF_DATA_FWD[i,j]= or REF_DATA_BWD[i,j]= lines, found none",
            ));
        }
        if let Some(warning) = missing_readings_warning_of(&runs, &targets_mm, unit.kind()) {
            self.warnings.push(warning);
        }
        self.metadata.source_format = Some(SourceFormat::Ecmc);
        // The reference measuring system is known only by the signal it was read from.
        self.metadata.setup.instrument = reference_instrument(&self.metadata.extra);
        if let Unit::Length(length_unit) = unit {
            self.metadata.length_unit = length_unit;
        }
        let kind = unit.kind();
        let axis = self.axis();
        let measurement = Measurement::new(
            axis,
            targets_mm,
            runs,
            Environment::default(),
            self.metadata,
        )
        .map_err(|error| ParseError::new(1, 1, error.to_string()))?
        .with_kind(kind);
        Ok((measurement, self.warnings))
    }
}

/// Letters that name an axis (ISO 841: X, Y, Z linear, A, B, C rotary about
/// them, U, V, W secondary linear).
const AXIS_LETTERS: &str = "XYZABCUVW";

/// The axis letter a PV name or a file name states, by the rule of the module
/// doc: a segment (between characters that are neither letters nor digits)
/// that is one axis letter, the only such letter in the name. Uppercase.
///
/// ```
/// use axcomp::read::ecmc::axis_letter;
/// assert_eq!(axis_letter("TARGET_DU:Z-PosCmd"), Some('Z'));
/// assert_eq!(axis_letter("b02__z__report_z.md_ISO230.dat"), Some('Z'));
/// assert_eq!(axis_letter("IOC_TEST:Axis1-PosSet"), None);
/// assert_eq!(axis_letter("sls-sioc-ecat01:M1-PosSet"), None);
/// assert_eq!(axis_letter("GANTRY:X-Y-Pos"), None);
/// ```
pub fn axis_letter(name: &str) -> Option<char> {
    let mut found = None;
    for segment in name.split(|c: char| !c.is_alphanumeric()) {
        let mut chars = segment.chars();
        let (Some(only), None) = (chars.next(), chars.next()) else {
            continue;
        };
        let letter = only.to_ascii_uppercase();
        if !AXIS_LETTERS.contains(letter) {
            continue;
        }
        match found {
            None => found = Some(letter),
            Some(previous) if previous == letter => {}
            Some(_) => return None,
        }
    }
    found
}

/// The last step of the axis rule (module doc), for the front end, which
/// knows the file name: names the axis of an ecmc measurement whose PVs state
/// none after the letter in `file_name`; warns when the PVs state another.
pub fn axis_from_file_name(measurement: &mut Measurement, file_name: &str) -> Option<Warning> {
    let letter = axis_letter(file_name)?;
    match measurement.axis_source() {
        AxisSource::NotRecorded => {
            measurement.set_axis_from(letter.to_string(), AxisSource::file("file name"));
            None
        }
        AxisSource::File { field }
            if !measurement.axis().eq_ignore_ascii_case(&letter.to_string()) =>
        {
            Some(Warning::InconsistentMetadata {
                message: format!(
                    "{field} names axis {} but the file name {file_name:?} names {letter}; the axis is called {} (use --axis to rename it)",
                    measurement.axis(),
                    measurement.axis()
                ),
            })
        }
        _ => None,
    }
}

/// Refuses a file that declares more cycles than it holds (a truncated
/// file), naming the missing cycles per direction and the declaration.
fn check_cycles_complete(
    declared: Declared,
    grids: &[(&str, &Vec<Vec<Option<f64>>>)],
) -> Result<(), ParseError> {
    let mut missing = Vec::new();
    for (name, grid) in grids {
        let absent: Vec<usize> = grid
            .iter()
            .enumerate()
            .filter(|(_, cycle)| cycle.iter().all(Option::is_none))
            .map(|(index, _)| index + 1)
            .collect();
        if !absent.is_empty() {
            missing.push(format!("{name} cycle(s) {}", ranges(&absent)));
        }
    }
    if missing.is_empty() {
        return Ok(());
    }
    Err(ParseError::new(
        declared.line,
        declared.column,
        format!(
            "CYCLES={} but the file holds no {}: the file looks truncated; re-export it or measure again",
            declared.value,
            missing.join(" and no ")
        ),
    ))
}

/// `2–5`, `1, 3`, `2, 4–5`: sorted whole numbers as ranges.
fn ranges(numbers: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut start = 0;
    while start < numbers.len() {
        let mut end = start;
        while end + 1 < numbers.len() && numbers[end + 1] == numbers[end] + 1 {
            end += 1;
        }
        parts.push(if end == start {
            numbers[start].to_string()
        } else {
            format!("{}–{}", numbers[start], numbers[end])
        });
        start = end + 1;
    }
    parts.join(", ")
}

/// The number of positions: as declared (checked against the data) or as found.
fn declared_count(
    declared: Option<Declared>,
    entries: &[Entry],
    name: &str,
) -> Result<usize, ParseError> {
    let found = entries.iter().map(|e| e.position_index).max().unwrap_or(0);
    let Some(declared) = declared else {
        return Ok(found);
    };
    if let Some(beyond) = entries.iter().find(|e| e.position_index > declared.value) {
        return Err(ParseError::new(
            beyond.line,
            beyond.column,
            format!(
                "index {} is beyond {name}={} (line {})",
                beyond.position_index, declared.value, declared.line
            ),
        ));
    }
    Ok(declared.value)
}

fn check_range(entry: &Entry, position_count: usize, cycle_count: usize) -> Result<(), ParseError> {
    if entry.position_index > position_count {
        return Err(ParseError::new(
            entry.line,
            entry.column,
            format!(
                "position index {} is beyond the {position_count} targets",
                entry.position_index
            ),
        ));
    }
    if entry.cycle_index > cycle_count {
        return Err(ParseError::new(
            entry.line,
            entry.column,
            format!(
                "cycle index {} is beyond CYCLES={cycle_count}",
                entry.cycle_index
            ),
        ));
    }
    Ok(())
}

/// `NAME`, `NAME[i]` or `NAME[i,j]`, with optional spaces inside.
fn parse_key<'a>(line: &Line<'a>, key: &'a str) -> Result<Key<'a>, ParseError> {
    let Some(open) = key.find('[') else {
        if key.is_empty() || !key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(line.expected_at(key.trim_start(), "a key name (letters, digits, _)"));
        }
        return Ok(Key {
            name: key,
            indices: Vec::new(),
        });
    };
    let name = key[..open].trim();
    let inner_and_rest = &key[open + 1..];
    let Some(close) = inner_and_rest.find(']') else {
        return Err(line.error_at(&key[open..], "expected ']' after the index"));
    };
    let trailing = inner_and_rest[close + 1..].trim();
    if !trailing.is_empty() {
        return Err(line.expected_at(trailing, "'=' after ']'"));
    }
    let mut indices = Vec::new();
    for part in inner_and_rest[..close].split(',') {
        let token = part.trim();
        let index = text::integer(line, token, "index")?;
        if index == 0 {
            return Err(line.error_at(token, "expected an index from 1, found 0"));
        }
        // Indices size the tables built from them: bound them like the declared counts.
        if index > MAX_COUNT {
            return Err(line.error_at(
                token,
                format!("index {index} is too large (at most {MAX_COUNT})"),
            ));
        }
        indices.push((index as usize, token));
    }
    Ok(Key { name, indices })
}

fn entry(line: &Line<'_>, key: &Key<'_>, value: &str, what: &str) -> Result<Entry, ParseError> {
    let number = text::number(line, value, what)?;
    Ok(Entry {
        position_index: key.indices[0].0,
        cycle_index: key.indices.get(1).map_or(0, |i| i.0),
        value: number,
        line: line.number,
        column: line.column_of(key.indices[0].1),
        value_column: line.column_of(value),
    })
}

fn declared(line: &Line<'_>, value: &str, what: &str) -> Result<Declared, ParseError> {
    let count = text::integer(line, value, what)?;
    if count == 0 || count > 100_000 {
        return Err(line.error_at(
            value,
            format!("expected a {what} from 1 to 100000, found {count}"),
        ));
    }
    Ok(Declared {
        value: count as usize,
        line: line.number,
        column: line.column_of(value),
    })
}

/// The unit of a file's values: a length (linear axis) or degrees (rotary).
#[derive(Clone, Copy, Debug)]
enum Unit {
    Length(LengthUnit),
    Degree,
}

impl Unit {
    /// The kind of axis a file in this unit measured.
    fn kind(self) -> AxisKind {
        match self {
            Unit::Length(_) => AxisKind::Linear,
            Unit::Degree => AxisKind::Rotary,
        }
    }

    /// A value of the file in axcomp's inner unit: mm, or degrees as they are.
    fn to_inner(self, value: f64) -> f64 {
        match self {
            Unit::Length(length_unit) => length_unit.to_mm(value),
            Unit::Degree => value,
        }
    }
}

fn unit(line: &Line<'_>, value: &str) -> Result<Unit, ParseError> {
    match value.to_lowercase().as_str() {
        "mm" => Ok(Unit::Length(LengthUnit::Millimetre)),
        "inch" | "in" => Ok(Unit::Length(LengthUnit::Inch)),
        "deg" | "degree" | "degrees" | "°" => Ok(Unit::Degree),
        _ => Err(line.error_at(
            value,
            format!("expected UNIT=mm, UNIT=inch or, for a rotary axis, UNIT=deg, found {value:?}"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "TEST_DATA=# Input data file\n\
        UNIT=mm\nCYCLES=2\nPOSITIONS=2\nDEC=5\n\
        TGT_DATA[1]=10\n REF_DATA_FWD[1,1] = 10.001\nTGT_DATA[2] =20\n\
        REF_DATA_FWD[2,1]=20.002 \nREF_DATA_FWD[1,2]=10.003\nREF_DATA_FWD[2,2]=20.004\n\
        REF_DATA_BWD[1,1]=9.999\nREF_DATA_BWD[2,1]=19.998\nREF_DATA_BWD[1,2]=9.997\nREF_DATA_BWD[2,2]=19.996\n  \n";

    fn parse_ok(text: &str) -> Measurement {
        parse(text).unwrap_or_else(|e| panic!("{e}")).0
    }

    #[test]
    fn values_are_actual_positions_and_fwd_is_up() {
        let m = parse_ok(SMALL);
        assert_eq!(m.targets(), &[10.0, 20.0]);
        let labels: Vec<String> = m.runs().iter().map(|r| r.label()).collect();
        assert_eq!(labels, ["1↑", "1↓", "2↑", "2↓"]);
        let first = m.runs()[0].deviations[0].unwrap();
        assert!((first - 0.001).abs() < 1e-12);
        let down = m.runs()[3].deviations[1].unwrap();
        assert!((down + 0.004).abs() < 1e-12);
    }

    #[test]
    fn the_axis_is_the_letter_a_pv_states() {
        let with = |lines: &str| parse_ok(&format!("{lines}\n{SMALL}"));
        let z = with("TGT_SET_PV=TARGET_DU:Z-PosCmd\nREF_PV=IOC_TEST:m0s011-Enc01-PosAct");
        assert_eq!(z.axis(), "Z");
        assert_eq!(z.axis_source(), &AxisSource::file("TGT_SET_PV"));
        let reference = with("TGT_SET_PV=IOC_TEST:Axis1-PosSet\nREF_PV=LAB:y-Enc-PosAct");
        assert_eq!(reference.axis(), "Y");
        assert_eq!(reference.axis_source(), &AxisSource::file("REF_PV"));
        let none = with("TGT_SET_PV=IOC_TEST:Axis1-PosSet");
        assert_eq!(none.axis(), AXIS_PLACEHOLDER);
        assert_eq!(none.axis_source(), &AxisSource::NotRecorded);
        let (_, warnings) = parse(&format!(
            "TGT_SET_PV=T:Z-PosCmd\nREF_PV=R:X-PosAct\n{SMALL}"
        ))
        .unwrap();
        assert!(
            warnings.iter().any(|w| w
                .to_string()
                .contains("TGT_SET_PV names axis Z but REF_PV names X")),
            "{warnings:?}"
        );
    }

    #[test]
    fn the_file_name_names_the_axis_only_when_the_pvs_do_not() {
        let mut m = parse_ok(SMALL);
        assert_eq!(axis_from_file_name(&mut m, "report_data.dat"), None);
        assert!(!m.axis_recorded());
        assert_eq!(
            axis_from_file_name(&mut m, "target_w_report.md_ISO230.dat"),
            None
        );
        assert_eq!(
            (m.axis(), m.axis_source()),
            ("W", &AxisSource::file("file name"))
        );
        let mut z = parse_ok(&format!("TGT_SET_PV=T:Z-PosCmd\n{SMALL}"));
        let warning = axis_from_file_name(&mut z, "x.dat").unwrap();
        assert!(warning.to_string().contains("names X"), "{warning}");
        assert_eq!(z.axis(), "Z");
    }

    #[test]
    fn an_angular_unit_makes_a_rotary_axis_in_degrees() {
        let text = "UNIT=deg\nTGT_DATA[1]=0\nTGT_DATA[2]=90\n\
            REF_DATA_FWD[1,1]=0.001\nREF_DATA_FWD[2,1]=89.998\n";
        let c = parse_ok(text);
        assert_eq!(c.kind(), AxisKind::Rotary);
        assert_eq!(c.targets(), &[0.0, 90.0]);
        // 89.998° − 90° = −0.002° = −7.2″, kept in degrees.
        let second = c.runs()[0].deviations[1].unwrap();
        assert!((second + 0.002).abs() < 1e-12, "{second}");
        assert_eq!(parse_ok(SMALL).kind(), AxisKind::Linear);
    }

    #[test]
    fn counts_are_inferred_when_absent() {
        let text = "TGT_DATA[1]=0\nTGT_DATA[2]=5\nREF_DATA_FWD[1,1]=0\nREF_DATA_FWD[2,1]=5.001\n";
        let m = parse_ok(text);
        assert_eq!(m.runs().len(), 1);
        assert_eq!(m.run_count(Direction::Down), 0);
    }

    #[test]
    fn positioned_errors() {
        #[rustfmt::skip]
        let cases = [
            ("TGT_DATA[1]=1,5\n", (1, 13), "decimal comma"),
            ("POSITIONS=1\nTGT_DATA[2]=1\nREF_DATA_FWD[2,1]=1\n", (2, 10), "beyond POSITIONS=1"),
            ("TGT_DATA[1]=1\nTGT_DATA[1]=2\nREF_DATA_FWD[1,1]=1\n", (2, 10), "given twice"),
            ("TGT_DATA[1]=1\nTGT_DATA[2]=1\nREF_DATA_FWD[1,1]=1\n", (2, 10), "duplicate target"),
            ("UNIT=rad\n", (1, 6), "for a rotary axis, UNIT=deg"),
            ("UNIT=deg\nTGT_DATA[1]=90\nREF_DATA_FWD[1,1]=91.5\n", (3, 19), "within ±3600″ (±1°), found 5400″"),
            // Found by fuzzing: an index that sized a table of gigabytes.
            ("TGT_DATA[99239814]=5\n", (1, 10), "index 99239814 is too large"),
            ("TGT_DATA[1,2]=1\n", (1, 1), "takes 1 index"),
            ("TGT_DATA[x]=1\n", (1, 10), "whole number"),
            ("just words\n", (1, 1), "KEY=VALUE"),
            // A truncated file: cycle 2 went forward but never came back.
            ("CYCLES=2\nTGT_DATA[1]=1\nREF_DATA_FWD[1,1]=1\nREF_DATA_BWD[1,1]=1\nREF_DATA_FWD[1,2]=1\n", (1, 8), "CYCLES=2 but the file holds no REF_DATA_BWD cycle(s) 2: the file looks truncated"),
            ("TGT_DATA[1]=2e5\nREF_DATA_FWD[1,1]=1\n", (1, 13), "within ±100000 mm"),
            ("TGT_DATA[1]=1\nREF_DATA_FWD[1,1]=1001.5\n", (2, 19), "found 1000500 µm"),
            ("TGT_DATA[1]=nan\n", (1, 13), "expected a number"),
            ("CYCLES=1\nTGT_DATA[1]=1\nREF_DATA_BWD[1,2]=1\n", (3, 14), "beyond CYCLES=1"),
        ];
        text::assert_errors_at(parse, &cases);
    }
}
