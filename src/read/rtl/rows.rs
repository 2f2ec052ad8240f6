//! The `DEVIATIONS::` rows: each read, checked and put in its run, and each
//! run's direction told from the order of its rows (the module doc).

use crate::error::ParseError;
use crate::measurement::{Direction, Run};
use crate::read::text::{self, Line, check_deviation_mm};
use crate::units::um_to_mm;

use super::parser::{Located, RtlParser, RunRows, key_value, sorted_targets};

impl RtlParser {
    pub(super) fn deviation_line(
        &mut self,
        line: &Line<'_>,
        input: &str,
    ) -> Result<(), ParseError> {
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
    pub(super) fn plain_deviation_row(&mut self, line: &Line<'_>) -> bool {
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
    pub(super) fn names_a_listed_pair(
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
    /// three (the line end, the fields, the number). A simple row is a plain
    /// row that `plain_deviation_row` takes, read to the same values.
    /// Fast path: with it and the others of the evaluate report, a 10 000-target × 10-run `evaluate` takes 0.014 s cpu whole process, 0.028 s without.
    pub(super) fn simple_rows<'a>(
        &mut self,
        mut text: &'a str,
        mut number: usize,
    ) -> (&'a str, usize) {
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
    pub(super) fn record_row(
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
    pub(super) fn first_row_line(
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

    /// Takes each file run's readings, tells its direction and numbers the
    /// runs per direction in the order measured.
    pub(super) fn assemble_runs(
        &mut self,
        run_count: Located<u32>,
    ) -> Result<Vec<Run>, ParseError> {
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
                deviations: rows.deviations_mm,
            });
        }
        Ok(runs)
    }
}

/// The direction of one run from the order of its rows (see the module doc).
pub(super) fn run_direction(rows: &RunRows, file_run: u32) -> Result<Direction, ParseError> {
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
pub(super) fn row_fields<'a>(line: &Line<'a>) -> [Option<&'a str>; 4] {
    pub(super) fn first_four<'a>(
        mut fields: impl Iterator<Item = &'a str>,
    ) -> [Option<&'a str>; 4] {
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
pub(super) struct RowStart {
    /// Byte offset of the run number.
    pub(super) run_offset: usize,
    pub(super) file_run: u64,
    pub(super) target_number: u64,
    /// Byte offset of the value's first byte.
    pub(super) value_at: usize,
}

impl RowStart {
    /// The start of the row `bytes` begins with, or `None`: no blank
    /// between the fields, a run or target number missing or too long to
    /// be exact. Reads up to the first byte of the value (a line end ends
    /// nothing here: it is not a digit and not a blank).
    #[inline]
    pub(super) fn of(bytes: &[u8]) -> Option<RowStart> {
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
pub(super) fn digits_at(bytes: &[u8], from: usize) -> Option<(u64, usize)> {
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
pub(super) fn skip_blanks(bytes: &[u8], mut at: usize) -> usize {
    while bytes.get(at).is_some_and(|&b| b == b' ' || b == b'\t') {
        at += 1;
    }
    at
}

/// A deviation row in its common form, `run target value` separated by
/// spaces or tabs, read in one pass over its bytes.
pub(super) struct PlainRow<'a> {
    /// Byte offset of the run number in the line.
    pub(super) run_offset: usize,
    pub(super) file_run: u64,
    pub(super) target_number: u64,
    /// The value's text, not yet parsed.
    pub(super) value: &'a str,
}

impl<'a> PlainRow<'a> {
    /// The row, or `None` for anything else: a line with another byte, a
    /// run or target number too long to be exact, fewer or more fields.
    pub(super) fn of(text: &'a str) -> Option<PlainRow<'a>> {
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
pub(super) struct SimpleRow {
    /// Byte offset of the run number in the line.
    pub(super) run_offset: usize,
    pub(super) file_run: u64,
    pub(super) target_number: u64,
    pub(super) deviation_um: f64,
}

impl SimpleRow {
    /// The row at the start of `text` and its length with its line end, or
    /// `None` when the first line of `text` is not a simple row.
    #[inline]
    pub(super) fn of(text: &str) -> Option<(SimpleRow, usize)> {
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
