//! The table envelope every Heidenhain table shares (`.COM`, `.CMA`, `.T`):
//! a `BEGIN <NAME>.<SUFFIX> …` line, a fixed-width column header whose
//! offsets slice the rows, the rows, and `[END]`
//! (`../shared/notes/controller-and-laser-formats.md` §4.1, from pyLSV2's
//! reader and real table files). Used by `itnc530` and `tnc640`.

use crate::error::ParseError;
use crate::read::text::{self, Line};

/// What a positive Heidenhain backlash value means, in the technical
/// manuals' words (iTNC 530 HSCI TM 07/2013 §6.4.1 p.647; TNC 426/430 TM
/// p.6-36; MANUALplus 620 TM p.707, same NC family as the TNC 640): the same
/// as axcomp's suggested backlash −B̄, which is positive when the axis falls
/// short in the direction it moves.
pub(crate) const BACKLASH_SIGN: &str = "positive when the rotary encoder reading is ahead of the table, so the table traverse is too short after a reversal (lost motion, the usual case); negative when it is behind";

/// Heidenhain backlash parameters are entered in mm (\[seen\] "Input: [mm] or
/// [°]" in the manuals above) to 4 decimals, whatever unit the machine
/// displays: an inch machine gets mm too. \[reconstructed\] that the input
/// stays mm on an inch machine: no manual gives the parameters an inch input.
pub(crate) const BACKLASH_DECIMALS: usize = 4;

/// A Heidenhain table split into its parts.
pub(crate) struct Envelope<'a> {
    /// The `BEGIN …` line.
    pub begin: Line<'a>,
    /// The column header.
    pub header: Line<'a>,
    /// Column names and their start offsets (characters) in the header.
    pub offsets: Vec<(String, usize)>,
    /// The rows between the header and `[END]`.
    pub rows: Vec<Line<'a>>,
}

impl<'a> Envelope<'a> {
    /// Splits the text; `begin_syntax` says what the `BEGIN` line should look like.
    pub fn split(input: &'a str, begin_syntax: &str) -> Result<Envelope<'a>, ParseError> {
        let lines: Vec<Line<'a>> = text::lines(input).filter(|l| !l.is_blank()).collect();
        let Some(begin) = lines.first().copied() else {
            return Err(ParseError::new(
                1,
                1,
                format!("expected {begin_syntax}, found an empty file"),
            ));
        };
        if !begin.text.trim_start().starts_with("BEGIN ") {
            return Err(begin.expected_at(begin.text.trim_start(), begin_syntax));
        }
        let Some(header) = lines.get(1).copied() else {
            return Err(ParseError::new(
                begin.number + 1,
                1,
                "expected the column header, found end of file",
            ));
        };
        let Some(end) = lines.iter().position(|l| l.text.trim() == "[END]") else {
            let last = lines.last().map_or(1, |l| l.number + 1);
            return Err(ParseError::new(
                last,
                1,
                "expected [END], found end of file: the table is truncated",
            ));
        };
        let rows: Vec<Line<'a>> = lines.get(2..end).unwrap_or_default().to_vec();
        if rows.len() < 2 {
            return Err(ParseError::new(
                header.number + 1,
                1,
                "expected at least two rows",
            ));
        }
        Ok(Envelope {
            begin,
            header,
            offsets: header_offsets(&header),
            rows,
        })
    }

    /// The index of a column by name.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.offsets
            .iter()
            .position(|(n, _)| n.eq_ignore_ascii_case(name))
    }

    /// The trimmed text of column `index` in a row: from its header offset to the next one.
    pub fn cell(&self, row: &Line<'a>, index: usize) -> &'a str {
        let start = self.offsets[index].1;
        let end = self.offsets.get(index + 1).map_or(usize::MAX, |(_, o)| *o);
        let byte = |chars: usize| {
            row.text
                .char_indices()
                .nth(chars)
                .map_or(row.text.len(), |(b, _)| b)
        };
        let (from, to) = (byte(start), byte(end));
        row.text.get(from..to.max(from)).unwrap_or("").trim()
    }
}

/// Column names and their start offsets (in characters) from a header line.
fn header_offsets(header: &Line<'_>) -> Vec<(String, usize)> {
    let mut offsets = Vec::new();
    let chars: Vec<char> = header.text.chars().collect();
    let mut index = 0;
    while index < chars.len() {
        if chars[index].is_whitespace() {
            index += 1;
            continue;
        }
        let start = index;
        while index < chars.len() && !chars[index].is_whitespace() {
            index += 1;
        }
        offsets.push((chars[start..index].iter().collect(), start));
    }
    offsets
}

/// The error for a row whose value cell is empty, at the end of the row.
pub(crate) fn empty_cell(row: &Line<'_>, column: &str) -> ParseError {
    row.error_at(
        &row.text[row.text.len()..],
        format!("expected a value in column {column}, found an empty cell"),
    )
}
