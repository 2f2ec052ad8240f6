//! Fagor 8065 axis machine-parameter file `<axis>.mp`: its leadscrew table
//! read, updated in place, or written as a new file.
//!
//! Spec and sources: `formats/fagor8065/README.md` (\[seen\] real exports of
//! one machine in `../shared/data/api-xd/`). The file is the axis's whole
//! parameter table, one parameter a line, `;`-separated
//! (`<level>;<path padded to 50>;<value>[ padded to 20;<comment>]`), UTF-16
//! with a byte-order mark and CRLF (the encoding is [`super::fagor`]'s). The
//! leadscrew table is the lines
//!
//! ```text
//! 2;/LSCRWDATA/NPOINTS                                ;27
//! 2;/LSCRWDATA/BIDIR                                  ;0                   ;No
//! 2;/LSCRWDATA/DATA/POSITION 1                        ;-127.0000
//! … every POSITION n, then every POSERROR n, then every NEGERROR n
//! ```
//!
//! in mm with 4 decimals whatever the machine unit (\[seen\]: the positions of
//! an inch machine are its inch targets × 25.4). The errors are actual −
//! target, written as they are, as on the 8055.
//!
//! [`update`] replaces only those lines (and the values of `NPOINTS` and
//! `BIDIR`); every other character of the file is kept.

use crate::compensate::CompensationTable;
use crate::emit::fagor::{self, LIMIT_MM};
use crate::emit::{BacklashAdvice, BacklashParameter, EmitError, EmitOptions};
use crate::error::ParseError;
use crate::read::text::{self, Line};
use crate::units::LengthUnit;

/// Decimals of positions and errors (\[seen\]: `-127.0000`, `-0.0127`).
pub const DECIMALS: usize = 4;

/// Width of the parameter-path cell (\[seen\]: the value starts in column 54).
const PATH_WIDTH: usize = 50;

/// Width of a value cell followed by a comment (\[seen\]).
const VALUE_WIDTH: usize = 20;

const NPOINTS: &str = "/LSCRWDATA/NPOINTS";
const BIDIR: &str = "/LSCRWDATA/BIDIR";
const DATA: &str = "/LSCRWDATA/DATA/";

/// The three lists of the table, in the order the file holds them.
const LISTS: [&str; 3] = ["POSITION", "POSERROR", "NEGERROR"];

/// Whether the text holds an 8065 leadscrew table.
pub fn looks_like(text: &str) -> bool {
    text.contains("/LSCRWDATA/")
}

/// Why `convert` writes no new `.mp` file: the control's `.mp` is the axis'
/// whole parameter table, and a file of the leadscrew lines alone, under
/// header lines whose meaning is not known, is not known to load (no public
/// 8065 manual page describes the file); the control's own export, updated
/// in place, is.
pub const NEEDS_EXPORT: &str = "a Fagor 8065 takes the axis' whole parameter table (<axis>.mp), not the leadscrew lines alone: export the axis' .mp from the control (its machine-parameter table) and give it with --existing; axcomp then changes only its leadscrew lines (/LSCRWDATA) and keeps every other parameter";

/// Whether `bytes` are an `.mp` file with a leadscrew table to update.
pub fn is_parameter_file(bytes: &[u8]) -> bool {
    super::decode_table(bytes).is_ok_and(|(text, _)| looks_like(&text))
}

/// A new `.mp` file holding only the leadscrew table, CRLF (encoded UTF-16LE
/// by `emit::write_bytes`). \[reconstructed\] The four header lines are
/// copied in form from the real export; what `3100`, `MM ;0` and
/// `MPVersionID ;100` mean is not known. Updating the machine's own export
/// (`--existing X.mp`) is the safer way.
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let axis = options.axes.first().map_or("X", |a| a.axis.as_str());
    let bidirectional = table.values.mode() == crate::compensate::TableMode::Bidirectional;
    let mut lines = vec![
        format!("{:<30};3100", format!("{axis} AXIS")),
        format!("{:<30};0", "MM"),
        format!("{:<30};100", "MPVersionID"),
        format!(
            " ;{:<PATH_WIDTH$};{:<VALUE_WIDTH$};Comment;",
            "Parameter", "Value"
        ),
        parameter("2", "/LSCRWCOMP", "1", Some("Yes")),
        parameter("2", NPOINTS, &table.positions.len().to_string(), None),
        parameter("2", "/LSCRWDATA/TYPCROSS", "1", Some("Theoretical")),
        parameter(
            "2",
            BIDIR,
            bidir_value(bidirectional),
            Some(yes_no(bidirectional)),
        ),
        parameter("2", "/LSCRWDATA/REFNEED", "0", Some("No")),
    ];
    lines.extend(data_lines("2", table));
    let mut out = lines.join("\r\n");
    out.push_str("\r\n");
    Ok(out)
}

/// The existing file `existing` with its leadscrew table replaced by `table`:
/// the `DATA` lines go where the first of the old ones was, `NPOINTS` and
/// `BIDIR` get the new count and mode; every other line, and every line end,
/// stays as it was.
pub fn update(existing: &str, table: &CompensationTable) -> Result<String, EmitError> {
    let segments: Vec<(&str, &str)> = existing.split_inclusive('\n').map(split_line_end).collect();
    let is_data = |content: &str| key_of(content).starts_with(DATA);
    let missing = |what: &str| {
        EmitError::Profile(format!(
            "the existing file has no {what} line: it is no Fagor 8065 leadscrew table to update; write a new file without --existing"
        ))
    };
    let first_data = segments
        .iter()
        .position(|(content, _)| is_data(content))
        .ok_or_else(|| missing("/LSCRWDATA/DATA/"))?;
    let last_data = segments
        .iter()
        .rposition(|(content, _)| is_data(content))
        .unwrap_or(first_data);
    let bidirectional = table.values.mode() == crate::compensate::TableMode::Bidirectional;
    if bidirectional && !segments.iter().any(|(c, _)| key_of(c) == BIDIR) {
        return Err(missing(BIDIR));
    }
    let line_end = segments
        .iter()
        .map(|(_, end)| *end)
        .find(|end| !end.is_empty())
        .unwrap_or("\r\n");
    let level = segments[first_data].0.split(';').next().unwrap_or("2");
    let mut out = String::with_capacity(existing.len());
    for (index, (content, end)) in segments.iter().enumerate() {
        if is_data(content) {
            if index == first_data {
                let new_lines = data_lines(level, table);
                let count = new_lines.len();
                for (k, line) in new_lines.into_iter().enumerate() {
                    out.push_str(&line);
                    out.push_str(if k + 1 == count {
                        segments[last_data].1
                    } else {
                        line_end
                    });
                }
            }
            continue;
        }
        match key_of(content) {
            key if key == NPOINTS => {
                out.push_str(&replace_cells(
                    content,
                    &table.positions.len().to_string(),
                    None,
                ));
            }
            key if key == BIDIR => {
                out.push_str(&replace_cells(
                    content,
                    bidir_value(bidirectional),
                    Some(yes_no(bidirectional)),
                ));
            }
            _ => out.push_str(content),
        }
        out.push_str(end);
    }
    Ok(out)
}

/// The parameter path of a line (its second `;` cell), trimmed.
fn key_of(content: &str) -> &str {
    content.split(';').nth(1).map_or("", str::trim)
}

/// A line's text and its line end (`\r\n`, `\n`, a lone `\r` at the end of
/// the file, or nothing).
fn split_line_end(segment: &str) -> (&str, &str) {
    for end in ["\r\n", "\n", "\r"] {
        if let Some(content) = segment.strip_suffix(end) {
            return (content, &segment[content.len()..]);
        }
    }
    (segment, "")
}

/// The line with its value cell replaced (padded to the old width when a
/// comment follows) and, when given and the old comment is Yes/No, its comment.
fn replace_cells(content: &str, value: &str, comment: Option<&str>) -> String {
    let cells: Vec<&str> = content.split(';').collect();
    let mut out: Vec<String> = cells.iter().map(|c| c.to_string()).collect();
    if let Some(old) = cells.get(2) {
        out[2] = if cells.len() > 3 {
            format!("{value:<width$}", width = old.len())
        } else {
            value.to_string()
        };
    }
    if let (Some(new), Some(old)) = (comment, cells.get(3))
        && matches!(old.trim(), "Yes" | "No")
    {
        out[3] = new.to_string();
    }
    out.join(";")
}

fn bidir_value(bidirectional: bool) -> &'static str {
    if bidirectional { "1" } else { "0" }
}

fn yes_no(flag: bool) -> &'static str {
    if flag { "Yes" } else { "No" }
}

/// One parameter line: `level;path padded;value[ padded;comment]`.
fn parameter(level: &str, path: &str, value: &str, comment: Option<&str>) -> String {
    match comment {
        Some(comment) => format!("{level};{path:<PATH_WIDTH$};{value:<VALUE_WIDTH$};{comment}"),
        None => format!("{level};{path:<PATH_WIDTH$};{value}"),
    }
}

/// Every POSITION n, then every POSERROR n, then every NEGERROR n, mm.
fn data_lines(level: &str, table: &CompensationTable) -> Vec<String> {
    let (positive, negative) = fagor::columns_mm(table);
    let mm = |value: f64| fagor::fixed(value, DECIMALS);
    let mut lines = Vec::with_capacity(3 * positive.len());
    for (list, values) in LISTS.iter().zip([&table.positions, &positive, &negative]) {
        for (index, value) in values.iter().enumerate() {
            let path = format!("{DATA}{list} {}", index + 1);
            lines.push(parameter(level, &path, &mm(*value), None));
        }
    }
    lines
}

/// \[seen\] the 8065 export holds `/SET 1/BACKLASH ;0.0076` among the axis
/// parameters, in mm with 4 decimals like every length in the file.
pub fn backlash_parameter(backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
    let axes: Vec<&str> = options.axes.iter().map(|a| a.axis.as_str()).collect();
    BacklashAdvice::Parameter(BacklashParameter::new(
        format!("/SET 1/BACKLASH in {}.mp", axes.join(".mp, ")),
        backlash_mm,
        LengthUnit::Millimetre,
        DECIMALS,
        crate::emit::fagor8055::BACKLASH_SIGN,
        Some("or write the table with --mode bidirectional (BIDIR = 1): the NEGERROR list then carries the reversal".to_string()),
    ))
}

/// How to load the file.
pub fn activation(file_name: &str, options: &EmitOptions) -> String {
    let axis = options.axes.first().map_or("X", |a| a.axis.as_str());
    format!(
        "load {file_name} into the machine parameters of axis {axis} (the leadscrew table /LSCRWDATA, LSCRWCOMP = Yes), validate the parameters and home the axis"
    )
}

/// Reads the leadscrew table of `axis` from the text of an `.mp` file.
pub fn read(input: &str, axis: &str) -> Result<CompensationTable, ParseError> {
    let lines: Vec<Line<'_>> = text::lines(input).collect();
    if let Some(first) = lines.first()
        && let Some(name) = first
            .text
            .split(';')
            .next()
            .map(|c| c.trim().trim_start_matches('\u{feff}'))
            .and_then(|c| c.strip_suffix(" AXIS"))
        && name.trim() != axis
    {
        return Err(first.error_at(
            first.text,
            format!(
                "this is the parameter file of axis {}, not of the measured axis {axis}: give --axis {} if the test measured it",
                name.trim(),
                name.trim()
            ),
        ));
    }
    let mut npoints: Option<(usize, Line<'_>, &str)> = None;
    let mut bidirectional = false;
    // Per list, the value and line of each index.
    let mut lists: [Vec<Option<(f64, usize)>>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    for line in &lines {
        let cells: Vec<&str> = line.text.split(';').collect();
        let Some(key) = cells.get(1).map(|k| k.trim()) else {
            continue;
        };
        if !key.starts_with("/LSCRWDATA/") {
            continue;
        }
        let Some(value) = cells.get(2).map(|v| v.trim()) else {
            return Err(line.error_at(
                line.text,
                format!("{key}: expected ;value after the name, found the end of the line"),
            ));
        };
        if key == NPOINTS {
            let count = text::integer(line, value, "number of points")? as usize;
            npoints = Some((count, *line, value));
        } else if key == BIDIR {
            bidirectional = match value {
                "0" => false,
                "1" => true,
                _ => return Err(line.expected_at(value, "BIDIR 0 or 1")),
            };
        } else if let Some(rest) = key.strip_prefix(DATA) {
            let (list, index) = rest.split_once(' ').unwrap_or((rest, ""));
            let Some(which) = LISTS.iter().position(|l| *l == list) else {
                continue;
            };
            let index_token = &cells[1][cells[1].find(index).unwrap_or(0)..];
            let index: usize = match index.trim().parse() {
                Ok(i) if i >= 1 => i,
                _ => return Err(line.expected_at(index_token.trim_end(), "an index 1, 2, 3, …")),
            };
            let number = text::number(line, value, "value")?;
            let number_mm = if which == 0 {
                text::check_target_mm(number, line.number, line.column_of(value))?
            } else {
                text::check_deviation_mm(number, line.number, line.column_of(value))?
            };
            if number_mm.abs() > LIMIT_MM {
                return Err(line.error_at(value, "beyond ±99999.9999 mm, the 8065's range"));
            }
            let slots = &mut lists[which];
            if slots.len() < index {
                slots.resize(index, None);
            }
            if slots[index - 1].is_some() {
                return Err(line.error_at(line.text, format!("{list} {index} is given twice")));
            }
            slots[index - 1] = Some((number_mm, line.number));
        }
    }
    // Without NPOINTS (upstream's cut-down test file) the lists give the count.
    let count = match &npoints {
        Some((count, _, _)) => *count,
        None if !lists[0].is_empty() => lists[0].len(),
        None => {
            return Err(ParseError::new(
                1,
                1,
                "expected a Fagor 8065 leadscrew table (/LSCRWDATA/NPOINTS and its DATA lines), found none",
            ));
        }
    };
    let at_npoints = |message: String| match &npoints {
        Some((_, line, token)) => line.error_at(token, message),
        None => ParseError::new(1, 1, message),
    };
    if count < 2 {
        return Err(at_npoints("NPOINTS must be at least 2".to_string()));
    }
    let mut columns: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    for (which, slots) in lists.iter().enumerate() {
        if let Some((line_number, index)) = slots
            .iter()
            .enumerate()
            .skip(count)
            .find_map(|(i, s)| s.map(|(_, l)| (l, i + 1)))
        {
            return Err(ParseError::new(
                line_number,
                1,
                format!("{} {index} is beyond NPOINTS = {count}", LISTS[which]),
            ));
        }
        for index in 0..count {
            match slots.get(index).copied().flatten() {
                Some((value, _)) => columns[which].push(value),
                None => {
                    return Err(at_npoints(format!(
                        "NPOINTS is {count}, but {} {} is missing",
                        LISTS[which],
                        index + 1
                    )));
                }
            }
        }
    }
    let [positions_mm, positive, negative] = columns;
    for (k, pair) in positions_mm.windows(2).enumerate() {
        if pair[1] <= pair[0] {
            let line_number = lists[0][k + 1].map_or(1, |(_, l)| l);
            return Err(ParseError::new(
                line_number,
                1,
                format!(
                    "POSITION {} = {} mm does not increase (previous {} mm): the 8065 needs the points in ascending order",
                    k + 2,
                    pair[1],
                    pair[0]
                ),
            ));
        }
    }
    Ok(fagor::table_of(
        axis,
        positions_mm,
        positive,
        negative,
        bidirectional,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::TableValues;

    /// The lines of `../shared/data/api-xd/test__data__X.mp` (upstream's
    /// 13-line fragment), CRLF.
    const FRAGMENT: &str = "X AXIS                        ;3100\r\nMM                            ;0\r\n2;/LSCRWDATA/NPOINTS                                ;3\r\n2;/LSCRWDATA/BIDIR                                  ;0                   ;No\r\n2;/LSCRWDATA/DATA/POSITION 1                        ;-127.0000\r\n2;/LSCRWDATA/DATA/POSITION 2                        ;0.0000\r\n2;/LSCRWDATA/DATA/POSITION 3                        ;127.0000\r\n2;/LSCRWDATA/DATA/POSERROR 1                        ;-0.0127\r\n2;/LSCRWDATA/DATA/POSERROR 2                        ;0.0000\r\n2;/LSCRWDATA/DATA/POSERROR 3                        ;0.0028\r\n2;/LSCRWDATA/DATA/NEGERROR 1                        ;0.0000\r\n2;/LSCRWDATA/DATA/NEGERROR 2                        ;0.0000\r\n2;/LSCRWDATA/DATA/NEGERROR 3                        ;0.0000\r\n2;/FILTER/FILTER 1/ORDER                            ;0\r\n";

    #[test]
    fn a_fragment_reads_by_hand() {
        let table = read(FRAGMENT, "X").unwrap();
        assert_eq!(table.positions, vec![-127.0, 0.0, 127.0]);
        assert_eq!(table.values, TableValues::Mean(vec![-0.0127, 0.0, 0.0028]));
        assert_eq!(table.reference, 0.0);
        assert!(
            read(FRAGMENT, "Y")
                .unwrap_err()
                .to_string()
                .contains("axis X")
        );
    }

    #[test]
    fn an_update_changes_only_the_table_lines() {
        let table = CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![0.0, 127.0, 254.0, 381.0],
            values: TableValues::Bidirectional {
                up: vec![0.0, 0.001, 0.002, 0.003],
                down: vec![0.0005, 0.0015, 0.0025, -0.00001],
            },
            reference: 0.0,
            suggested_backlash: None,
        };
        let updated = update(FRAGMENT, &table).unwrap();
        let lines: Vec<&str> = updated.split("\r\n").collect();
        assert_eq!(lines[0], "X AXIS                        ;3100");
        assert_eq!(
            lines[2],
            "2;/LSCRWDATA/NPOINTS                                ;4"
        );
        assert_eq!(
            lines[3],
            "2;/LSCRWDATA/BIDIR                                  ;1                   ;Yes"
        );
        assert_eq!(
            lines[4],
            "2;/LSCRWDATA/DATA/POSITION 1                        ;0.0000"
        );
        assert_eq!(
            lines[11],
            "2;/LSCRWDATA/DATA/POSERROR 4                        ;0.0030"
        );
        // −0.00001 mm rounds to 0.0000, not −0.0000.
        assert_eq!(
            lines[15],
            "2;/LSCRWDATA/DATA/NEGERROR 4                        ;0.0000"
        );
        assert_eq!(
            lines[16],
            "2;/FILTER/FILTER 1/ORDER                            ;0"
        );
        assert_eq!(lines.len(), 18);
        assert_eq!(
            read(&updated, "X").unwrap().values.mode(),
            table.values.mode()
        );
    }

    #[test]
    fn incomplete_tables_are_refused_at_npoints() {
        let short = FRAGMENT.replace(
            "2;/LSCRWDATA/DATA/POSERROR 3                        ;0.0028\r\n",
            "",
        );
        let error = read(&short, "X").unwrap_err();
        assert_eq!((error.position.line, error.position.column), (3, 54));
        assert!(
            error.to_string().contains("POSERROR 3 is missing"),
            "{error}"
        );
        let garbled = FRAGMENT.replace(";0.0028", ";0.00x8");
        assert_eq!(read(&garbled, "X").unwrap_err().position.line, 10);
        assert!(read("X AXIS ;3100\r\n", "X").is_err());
        assert!(update("X AXIS ;3100\r\n", &read(FRAGMENT, "X").unwrap()).is_err());
    }
}
