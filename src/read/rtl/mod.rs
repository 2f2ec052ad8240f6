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
//!
//! `parser` reads the sections and checks the file is whole, `rows` reads the
//! deviation rows into runs, `write` writes a file.

mod parser;
mod rows;
mod write;

use parser::RtlParser;
pub use write::write;

use crate::error::{ParseError, Warning};
use crate::measurement::Measurement;

/// The `Owner` value taken to mark a rotary (XR20) test. No rotary `.rtl`
/// sample is public (`../shared/spec/standards.md` §6), so this is the one
/// assumption about one: its header says `Owner : Rotary`, and the rest of
/// its layout is unknown, so such a file is refused at that line.
pub const ROTARY_OWNER: &str = "Rotary";

/// Material temperature Renishaw writes when no sensor is fitted (°C).
const NO_SENSOR_C: f64 = -10.0;

/// Parses the text of an `.rtl` file.
pub fn parse(input: &str) -> Result<(Measurement, Vec<Warning>), ParseError> {
    let mut parser = RtlParser::default();
    parser.run(input)?;
    parser.finish(input)
}

#[cfg(test)]
mod tests;
