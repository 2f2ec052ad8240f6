//! Reading measurement files: the only place that opens inputs.
//!
//! The front end ([`read_path`], [`read_paths`]) reads bytes, decodes them
//! ([`decode`]: UTF-8 with or without BOM, else Latin-1; UTF-16 and binary
//! data are refused with a position), detects the format from the content
//! ([`detect`]) unless the caller names it, hands the text to that format's
//! pure parser, and adds the path to any error. The parsers take `&str` and
//! never see a path, so they are tested and fuzzed on strings.
//!
//! One module per format, each with its parser and, where axcomp writes the
//! format too, its writer: [`rtl`], [`ecmc`], [`api_pos`], [`csv`].
//! Geometry tests (straightness, angular, multi-error) are not a
//! `Measurement` of one positioning error: [`read_geometry_path`] reads
//! them into a [`geometry::GeometryTest`].

pub mod api_pos;
pub mod csv;
pub mod ecmc;
pub mod geometry;
pub mod rtl;
pub mod text;

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use chrono::NaiveDateTime;

use crate::error::{ParseError, Warning};
use crate::measurement::{AxisKind, Measurement, MeasurementError, Run, SourceFormat};
use crate::together::{Input, NotTogether, Pairing, check_together};

/// A measurement read from one or more files, with what the readers noticed.
#[derive(Clone, Debug)]
pub struct ReadResult {
    /// The measurement.
    pub measurement: Measurement,
    /// Non-fatal findings, for the user.
    pub warnings: Vec<Warning>,
}

/// Reads one measurement file. `format` overrides detection.
pub fn read_path(path: &Path, format: Option<SourceFormat>) -> Result<ReadResult, ReadError> {
    let bytes = std::fs::read(path).map_err(|error| ReadError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    read_bytes(path, &bytes, format)
}

/// Reads a measurement file's content that is already in memory (an upload
/// to `axcomp serve`), named `path` in messages and in the measurement, as
/// [`read_path`] reads the file.
pub fn read_bytes(
    path: &Path,
    bytes: &[u8],
    format: Option<SourceFormat>,
) -> Result<ReadResult, ReadError> {
    let located = |error: ParseError| ReadError::Parse {
        path: path.to_path_buf(),
        error,
    };
    let text = decode(bytes).map_err(located)?;
    let format = match format {
        Some(format) => format,
        None => detect(&text).ok_or_else(|| located(not_a_positioning_test(&text)))?,
    };
    let (mut measurement, mut warnings) = parse_str(&text, format).map_err(located)?;
    // The file name is the last place an ecmc file can state its axis
    // (`ecmc` module doc); only this front end knows it.
    if format == SourceFormat::Ecmc
        && let Some(name) = path.file_name().and_then(|name| name.to_str())
    {
        warnings.extend(ecmc::axis_from_file_name(&mut measurement, name));
    }
    measurement.metadata.source_file = Some(path.to_path_buf());
    Ok(ReadResult {
        measurement,
        warnings,
    })
}

/// Reads a geometry test (straightness, angular or several errors of one
/// axis, [`geometry`]): the CSV layout with error columns.
pub fn read_geometry_path(path: &Path) -> Result<geometry::GeometryTest, ReadError> {
    let text = read_text(path)?;
    geometry::parse(&text).map_err(|error| ReadError::Parse {
        path: path.to_path_buf(),
        error,
    })
}

/// Whether a file is a geometry test: its first line that is not blank or a
/// `#` comment is a geometry header ([`geometry::is_header`]).
pub fn is_geometry_path(path: &Path) -> Result<bool, ReadError> {
    let text = read_text(path)?;
    Ok(text::lines(&text)
        .map(|line| line.text.trim())
        .find(|line| !line.is_empty() && !line.starts_with('#'))
        .is_some_and(geometry::is_header))
}

/// The decoded text of a file ([`decode`]), errors with the path.
fn read_text(path: &Path) -> Result<Cow<'static, str>, ReadError> {
    let bytes = std::fs::read(path).map_err(|error| ReadError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    match decode(&bytes) {
        Ok(text) => Ok(Cow::Owned(text.into_owned())),
        Err(error) => Err(ReadError::Parse {
            path: path.to_path_buf(),
            error,
        }),
    }
}

/// The error for a file no positioning reader takes: a geometry test is
/// named as one (at its header line), anything else lists the formats.
fn not_a_positioning_test(text: &str) -> ParseError {
    let header = text::lines(text).find(|line| {
        let trimmed = line.text.trim();
        !trimmed.is_empty() && !trimmed.starts_with('#')
    });
    match header {
        Some(line) if geometry::is_header(line.text.trim()) => line.error_at(
            line.text.trim(),
            "this is a geometry test (straightness or angular error columns), not a positioning test: \
             list it in a survey and give predict --survey S.toml (docs/src/geometry.md)",
        ),
        _ => unknown_format_error(),
    }
}

/// An error from reading a measurement file: the parse error plus the path.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read at all.
    ///
    /// The operating system's message is part of the text, not a `source`:
    /// an error chain printed with both said it twice.
    #[error("cannot read {path}: {error}", path = path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        error: std::io::Error,
    },
    /// The file was read but its content is wrong at a position.
    #[error("{path}:{error}", path = path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What is wrong, and where.
        error: ParseError,
    },
    /// No file was given.
    #[error("no input file given")]
    NoInput,
    /// Two files that do not belong to one test.
    #[error("{path}: {error}", path = path.display())]
    NotTogether {
        /// The second file.
        path: PathBuf,
        /// Why they do not belong together.
        error: Box<NotTogether>,
    },
    /// Two files of one test whose readings cannot be one measurement.
    #[error("{path}: {error}", path = path.display())]
    Merge {
        /// The second file.
        path: PathBuf,
        /// Why they do not fit together.
        error: MeasurementError,
    },
}

/// Reads one file, or two files of one axis that together make one
/// bidirectional measurement (e.g. the forward and reverse `.pos` files).
pub fn read_paths(
    paths: &[PathBuf],
    format: Option<SourceFormat>,
) -> Result<ReadResult, ReadError> {
    join(
        paths,
        |index| read_path(&paths[index], format),
        |path| std::fs::canonicalize(path).ok(),
    )
}

/// Reads files whose contents are in memory, each `(name, bytes)`, as
/// [`read_paths`] reads files: one, or two of one axis joined.
pub fn read_all_bytes(
    files: &[(PathBuf, Vec<u8>)],
    format: Option<SourceFormat>,
) -> Result<ReadResult, ReadError> {
    let names: Vec<PathBuf> = files.iter().map(|(name, _)| name.clone()).collect();
    join(
        &names,
        |index| read_bytes(&files[index].0, &files[index].1, format),
        |_| None,
    )
}

/// Reads the first of `paths` with `read` (by index), and joins each further one to it.
/// The files are compared by their `canonical` paths where there are such
/// (`a.rtl` and `./a.rtl` are one file); a copy is caught by its readings.
fn join(
    paths: &[PathBuf],
    read: impl Fn(usize) -> Result<ReadResult, ReadError>,
    canonical: impl Fn(&Path) -> Option<PathBuf>,
) -> Result<ReadResult, ReadError> {
    let Some((first, rest)) = paths.split_first() else {
        return Err(ReadError::NoInput);
    };
    let mut result = read(0)?;
    for (index, path) in rest.iter().enumerate() {
        let next = read(index + 1)?;
        // Two files of one test: one axis, two files, the same stretch.
        let canonical = [canonical(first), canonical(path)];
        let mut inputs = [
            Input::measurement(&result.measurement, first.display().to_string()),
            Input::measurement(&next.measurement, path.display().to_string()),
        ];
        for (input, canonical) in inputs.iter_mut().zip(&canonical) {
            input.file = canonical.as_deref().or(input.file);
        }
        let doubts = check_together(Pairing::OneTest, &inputs[0], &inputs[1]).map_err(|error| {
            ReadError::NotTogether {
                path: path.clone(),
                error: Box::new(error),
            }
        })?;
        result.warnings.extend(doubts);
        let merged = result
            .measurement
            .merge(&next.measurement)
            .map_err(|error| ReadError::Merge {
                path: path.clone(),
                error,
            })?;
        result.measurement = merged;
        result.warnings.extend(next.warnings);
    }
    Ok(result)
}

/// Parses decoded text in a known format (no I/O).
pub fn parse_str(
    text: &str,
    format: SourceFormat,
) -> Result<(Measurement, Vec<Warning>), ParseError> {
    match format {
        SourceFormat::Rtl => rtl::parse(text),
        SourceFormat::Ecmc => ecmc::parse(text),
        SourceFormat::ApiPos => api_pos::parse(text),
        SourceFormat::Csv => csv::parse(text),
    }
}

/// Guesses the format from the content, or `None` if nothing fits.
pub fn detect(text: &str) -> Option<SourceFormat> {
    let first = text.lines().map(str::trim).find(|line| !line.is_empty())?;
    if first.eq_ignore_ascii_case("HEADER::") {
        return Some(SourceFormat::Rtl);
    }
    if first.starts_with("API ") && first.contains("Laser") {
        return Some(SourceFormat::ApiPos);
    }
    let first_data = text
        .lines()
        .map(str::trim)
        .find(|line| !line.is_empty() && !line.starts_with('#'));
    if first_data.and_then(csv::header_separator).is_some() {
        return Some(SourceFormat::Csv);
    }
    if text.contains("TGT_DATA[")
        || text.contains("REF_DATA_FWD[")
        || text.contains("REF_DATA_BWD[")
    {
        return Some(SourceFormat::Ecmc);
    }
    if text
        .lines()
        .any(|line| line.trim_start().starts_with("API Linear"))
    {
        return Some(SourceFormat::ApiPos);
    }
    None
}

/// The error for content that matches no format: it lists what is supported.
pub fn unknown_format_error() -> ParseError {
    let list: Vec<String> = SourceFormat::ALL
        .iter()
        .map(|format| format!("{} ({})", format.name(), format.description()))
        .collect();
    ParseError::new(
        1,
        1,
        format!(
            "unknown format: expected one of: {}; name one with --format",
            list.join("; ")
        ),
    )
}

/// Decodes file bytes to text.
///
/// UTF-8 (a BOM is dropped) is taken as is; other bytes are read as Latin-1,
/// which older Windows laser software writes. UTF-16 and binary data are
/// refused: the error names the line and column of the first offending byte.
pub fn decode(bytes: &[u8]) -> Result<Cow<'_, str>, ParseError> {
    if bytes.starts_with(&[0xFF, 0xFE])
        || bytes.starts_with(&[0xFE, 0xFF])
        || looks_like_utf16(bytes)
    {
        return Err(ParseError::new(
            1,
            1,
            "expected UTF-8, ASCII or Latin-1 text, found UTF-16: convert the file first (e.g. iconv -f UTF-16 -t UTF-8)",
        ));
    }
    let bytes = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(bytes);
    if let Some(offset) = first_binary_byte(bytes) {
        let (line, column) = line_column_of_byte(bytes, offset);
        return Err(ParseError::new(
            line,
            column,
            format!(
                "expected text, found byte 0x{:02X}: this looks like a binary file, not a measurement",
                bytes[offset]
            ),
        ));
    }
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(ParseError::expected(1, 1, "a measurement", "an empty file"));
    }
    Ok(match std::str::from_utf8(bytes) {
        Ok(text) => Cow::Borrowed(text),
        Err(_) => Cow::Owned(bytes.iter().map(|&b| char::from(b)).collect()),
    })
}

/// UTF-16 without a BOM: ASCII text in which every other byte is zero.
fn looks_like_utf16(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(64) & !1];
    if head.len() < 4 {
        return false;
    }
    let all_zero = |parity: usize| head.iter().skip(parity).step_by(2).all(|&b| b == 0);
    let none_zero = |parity: usize| head.iter().skip(parity).step_by(2).all(|&b| b != 0);
    (all_zero(1) && none_zero(0)) || (all_zero(0) && none_zero(1))
}

/// The offset of the first [binary byte](is_binary_byte), if any.
///
/// A block of bytes is first checked as a whole, without stopping at the
/// first hit (a loop the compiler vectorises); only a block that has one is
/// searched byte by byte. A large file is 2 MB of text without one.
fn first_binary_byte(bytes: &[u8]) -> Option<usize> {
    const BLOCK: usize = 256;
    bytes
        .chunks(BLOCK)
        .enumerate()
        .find_map(|(block_index, block)| {
            let any = block
                .iter()
                .fold(0u8, |any, &b| any | u8::from(is_binary_byte(b)));
            if any == 0 {
                return None;
            }
            let offset = block.iter().position(|&b| is_binary_byte(b))?;
            Some(block_index * BLOCK + offset)
        })
}

/// Control characters that never occur in the text formats axcomp reads.
fn is_binary_byte(byte: u8) -> bool {
    matches!(byte, 0x00..=0x08 | 0x0E..=0x1A | 0x1C..=0x1F | 0x7F)
}

/// 1-based line and column (in bytes, as the text is not yet decoded) of a byte offset.
fn line_column_of_byte(bytes: &[u8], offset: usize) -> (usize, usize) {
    let before = &bytes[..offset];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    (line, offset - line_start + 1)
}

/// Parses the date patterns seen in `.rtl` files (`../shared/spec/renishaw-rtl.md`,
/// USER-TEXT); `None` for anything else, which stays as raw text.
pub fn parse_date(raw: &str) -> Option<NaiveDateTime> {
    const PATTERNS: [&str; 4] = [
        "%Y-%m-%d %H:%M:%S",
        "%H:%M %b %d %Y",
        "%d/%m/%Y %H:%M:%S",
        "%Y-%m-%dT%H:%M:%S",
    ];
    let raw = raw.trim();
    PATTERNS
        .iter()
        .find_map(|pattern| NaiveDateTime::parse_from_str(raw, pattern).ok())
        .or_else(|| {
            chrono::NaiveDate::parse_from_str(raw, "%Y-%m-%d")
                .ok()
                .and_then(|date| date.and_hms_opt(0, 0, 0))
        })
}

/// A warning listing missing readings, or `None` when every reading is there.
pub(crate) fn missing_readings_warning(runs: &[Run], targets_mm: &[f64]) -> Option<Warning> {
    missing_readings_warning_of(runs, targets_mm, AxisKind::Linear)
}

/// [`missing_readings_warning`] for an axis of `kind` (its targets in ° on a rotary axis).
pub(crate) fn missing_readings_warning_of(
    runs: &[Run],
    targets_mm: &[f64],
    kind: AxisKind,
) -> Option<Warning> {
    let mut count = 0;
    let mut examples = Vec::new();
    for run in runs {
        for (target_mm, value) in targets_mm.iter().zip(&run.deviations) {
            if value.is_none() {
                count += 1;
                if examples.len() < 3 {
                    examples.push(match kind {
                        AxisKind::Linear => format!("run {} at {target_mm} mm", run.label()),
                        AxisKind::Rotary => format!("run {} at {target_mm}°", run.label()),
                    });
                }
            }
        }
    }
    (count > 0).then_some(Warning::MissingReadings { count, examples })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decoding_accepts_utf8_bom_and_latin1() {
        assert_eq!(decode(b"\xEF\xBB\xBFHEADER::\n").unwrap(), "HEADER::\n");
        assert_eq!(
            decode(b"Machine: Kovosvit \xB5\n").unwrap(),
            "Machine: Kovosvit µ\n"
        );
    }

    #[test]
    fn decoding_refuses_utf16_binary_and_empty() {
        let utf16: Vec<u8> = "HEADER::\r\n"
            .encode_utf16()
            .flat_map(u16::to_le_bytes)
            .collect();
        assert!(decode(&utf16).unwrap_err().message.contains("UTF-16"));
        let mut with_bom = vec![0xFF, 0xFE];
        with_bom.extend(&utf16);
        assert!(decode(&with_bom).unwrap_err().message.contains("UTF-16"));
        let binary = decode(b"HEADER::\nab\x00c").unwrap_err();
        assert_eq!((binary.position.line, binary.position.column), (2, 3));
        assert!(
            decode(b"  \n\r\n")
                .unwrap_err()
                .message
                .contains("empty file")
        );
    }

    #[test]
    fn formats_are_detected_from_content() {
        assert_eq!(
            detect("\n  HEADER::\r\nFile type : rtl"),
            Some(SourceFormat::Rtl)
        );
        assert_eq!(
            detect("TEST_DATA=# x\nTGT_DATA[1]=15\n"),
            Some(SourceFormat::Ecmc)
        );
        assert_eq!(
            detect("API X-D Laser Measurement Linear Data Table (Company Name: )\n"),
            Some(SourceFormat::ApiPos)
        );
        assert_eq!(
            detect("# axis: X\ntarget_mm, run, direction, deviation_um\n"),
            Some(SourceFormat::Csv)
        );
        assert_eq!(
            detect("Target_mm;Run;Direction;Deviation_um\r\n0;1;up;0,5\r\n"),
            Some(SourceFormat::Csv)
        );
        assert_eq!(
            detect("target_mm\trun\tdirection\tdeviation_um\n"),
            Some(SourceFormat::Csv)
        );
        assert_eq!(detect("hello\nworld\n"), None);
    }

    #[test]
    fn dates_in_known_patterns() {
        let parsed = parse_date("10:46 Dec 12 2016").unwrap();
        assert_eq!(parsed.to_string(), "2016-12-12 10:46:00");
        assert_eq!(
            parse_date("2021-11-10 13:45:57").unwrap().to_string(),
            "2021-11-10 13:45:57"
        );
        assert_eq!(
            parse_date("12/12/2016 10:46:00").unwrap().to_string(),
            "2016-12-12 10:46:00"
        );
        assert_eq!(parse_date("sometime"), None);
    }
}
