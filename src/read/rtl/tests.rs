//! `.rtl` parser tests: the composite example of the spec, each leniency the
//! spec allows, each error it asks for, and the write → parse round trip.

use approx::assert_abs_diff_eq;
use proptest::prelude::*;

use super::rows::{PlainRow, SimpleRow};
use super::*;
use crate::measurement::{Direction, Environment, Metadata, Run, SourceFormat, StartEnd};
use crate::read::text::{self, Line};
use crate::units::um_to_mm;

/// The composite example of `../shared/notes/rtl-and-com-search.md` A.6
/// (assembled from five readers and writers; the ENVIRONMENT lines are from a
/// real file of Kadlečík (2019)).
pub(crate) const COMPOSITE: &str = "HEADER::\r\n\
File type  : rtl\r\n\
Owner      : Linear\r\n\
Version no : <unknown>\r\n\
\r\n\
TARGET DATA::\r\n\
Filetype  : ISO\r\n\
Target-count: 3\r\n\
Targets :\r\n\
0.0000  50.0000  100.0000\r\n\
Flags: 0 0 2 0\r\n\
\r\n\
USER-TEXT::\r\n\
Machine:\r\n\
Serial No:\r\n\
Date:<unknown format>\r\n\
By:\r\n\
Axis:X\r\n\
Location:\r\n\
TITLE:\r\n\
\r\n\
RUNS::\r\n\
Run-count:2\r\n\
\r\n\
DEVIATIONS::\r\n\
Run Target Data:\r\n\
1   1      0.000\r\n\
1   2      1.270\r\n\
1   3      2.050\r\n\
2   3      1.980\r\n\
2   2      1.310\r\n\
2   1     -0.060\r\n\
\r\n\
ENVIRONMENT::\r\n\
Air temp   : 20.337280 20.384956 0\r\n\
Air press  : 99.039005 99.049346 1\r\n\
Air humid  : 46.954897 46.893887\r\n\
Mat temp 1 : 20.203292 20.321342 0\r\n\
Mat temp 2 : -10.000000 -10.000000 0\r\n\
Mat temp 3 : -10.000000 -10.000000 0\r\n\
Env factor : 0.31641096 0.31641067\r\n\
Exp coeff  : 8.000000 8.000000 0\r\n\
Date Time  : \"10:46 Dec 12 2016\" \"11:01 Dec 12 2016\"\r\n\
Final Data : 1 0\r\n\
\r\n\
EOF::\r\n";

fn parse_ok(text: &str) -> (Measurement, Vec<Warning>) {
    parse(text).unwrap_or_else(|error| panic!("{error}"))
}

#[test]
fn composite_example_reads_with_directions_from_row_order() {
    let (m, warnings) = parse_ok(COMPOSITE);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(m.axis(), "X");
    assert_eq!(m.targets(), &[0.0, 50.0, 100.0]);
    let runs = m.runs();
    assert_eq!((runs[0].direction, runs[0].number), (Direction::Up, 1));
    assert_eq!((runs[1].direction, runs[1].number), (Direction::Down, 1));
    // µm in the file, mm inside: 1.270 µm = 0.00127 mm.
    assert_abs_diff_eq!(runs[0].deviations[1].unwrap(), 0.00127, epsilon = 1e-12);
    // Run 2 lists target 1 last: keyed on the target column, not the row.
    assert_abs_diff_eq!(runs[1].deviations[0].unwrap(), -0.00006, epsilon = 1e-12);
    assert_abs_diff_eq!(runs[1].deviations[2].unwrap(), 0.00198, epsilon = 1e-12);
}

#[test]
fn composite_example_environment_and_metadata() {
    let (m, _) = parse_ok(COMPOSITE);
    let env = &m.environment;
    assert_eq!(
        env.air_temperature_c,
        StartEnd::new(Some(20.337280), Some(20.384956))
    );
    assert_eq!(env.air_pressure_kpa.start, Some(99.039005));
    assert_eq!(env.air_humidity_pct.end, Some(46.893887));
    assert_eq!(env.material_temperature_c[0].start, Some(20.203292));
    // −10 means "no sensor fitted".
    assert_eq!(env.material_temperature_c[1], StartEnd::default());
    assert_eq!(env.environmental_factor_um.start, Some(0.31641096));
    assert_eq!(env.expansion_coefficient_ppm_per_k, Some(8.0));
    // The USER-TEXT date is kept raw; it matches no known pattern.
    let date = m.metadata.date.as_ref().unwrap();
    assert_eq!((date.raw.as_str(), date.parsed), ("<unknown format>", None));
    assert!(
        m.metadata
            .extra
            .contains(&("Flags".to_string(), "0 0 2 0".to_string()))
    );
    assert_eq!(m.metadata.source_format, Some(SourceFormat::Rtl));
}

#[test]
fn capture_date_is_used_when_user_text_has_none() {
    let text = COMPOSITE.replace("Date:<unknown format>\r\n", "");
    let (m, _) = parse_ok(&text);
    let date = m.metadata.date.unwrap();
    assert_eq!(date.parsed.unwrap().to_string(), "2016-12-12 10:46:00");
}

#[test]
fn leniencies_of_the_spec() {
    // LF line ends, lowercase keys and sections, padded keys, no blank lines,
    // negative unsorted targets starting on the Targets line and wrapping,
    // ragged whitespace in rows, an unknown section.
    let text = "header::\nFILE TYPE : rtl\nowner : linear\ntarget data::\ntarget-count: 6\n\
                targets : -10.5  0\n 20  -5.25\n30  10\nflags: 0 0 2 0\n\
                user-text::\naxis: Z\nruns::\nrun-count: 2\ndeviations::\nrun target data:\n\
                1 1   2\n1   4   -0.250\n  1 2      1.5\n1 6 3\n\
                2 6    4\n2  1 5\n\
                EQUIPMENT::\nLaser : XL-80\nenvironment::\nair TEMP : 20 21\neof::\n";
    let (m, warnings) = parse_ok(text);
    assert_eq!(m.axis(), "Z");
    assert_eq!(m.targets(), &[-10.5, -5.25, 0.0, 10.0, 20.0, 30.0]);
    // Run 1 visits −10.5, −5.25, 0, 10 mm: ↑. Run 2 visits 10, −10.5 mm: ↓.
    let up = &m.runs()[0];
    assert_eq!(up.direction, Direction::Up);
    assert_abs_diff_eq!(up.deviations[1].unwrap(), -0.00025, epsilon = 1e-12);
    assert_abs_diff_eq!(up.deviations[2].unwrap(), 0.0015, epsilon = 1e-12);
    assert_eq!(up.deviations[4], None);
    assert_eq!(m.runs()[1].direction, Direction::Down);
    assert_abs_diff_eq!(m.runs()[1].deviations[0].unwrap(), 0.005, epsilon = 1e-12);
    assert_eq!(
        m.environment.air_temperature_c,
        StartEnd::new(Some(20.0), Some(21.0))
    );
    assert!(
        warnings
            .iter()
            .any(|w| matches!(w, Warning::UnknownSection { line: 22, .. })),
        "{warnings:?}"
    );
    assert!(
        warnings
            .iter()
            .any(|w| matches!(w, Warning::MissingReadings { count: 6, .. })),
        "{warnings:?}"
    );
}

#[test]
fn unknown_section_is_skipped_with_a_warning() {
    let text = COMPOSITE.replace(
        "ENVIRONMENT::",
        "EQUIPMENT::\r\nLaser : XL-80\r\nENVIRONMENT::",
    );
    let (_, warnings) = parse_ok(&text);
    assert!(
        matches!(warnings.as_slice(), [Warning::UnknownSection { name, .. }] if name == "EQUIPMENT"),
        "{warnings:?}"
    );
}

#[test]
fn single_row_runs_fall_back_to_odd_up_even_down() {
    let text = COMPOSITE
        .replace("Target-count: 3", "Target-count: 1")
        .replace("0.0000  50.0000  100.0000", "0.0000")
        .replace(
            "1   2      1.270\r\n1   3      2.050\r\n2   3      1.980\r\n2   2      1.310\r\n",
            "",
        );
    let (m, _) = parse_ok(&text);
    assert_eq!(m.runs()[0].direction, Direction::Up);
    assert_eq!(m.runs()[1].direction, Direction::Down);
}

#[test]
fn a_missing_pair_is_a_missing_reading_not_zero() {
    let text = COMPOSITE.replace("2   2      1.310\r\n", "");
    let (m, warnings) = parse_ok(&text);
    assert_eq!(m.runs()[1].deviations[1], None);
    assert!(matches!(
        warnings.as_slice(),
        [Warning::MissingReadings { count: 1, .. }]
    ));
}

#[test]
fn descending_target_list_gives_physical_directions() {
    // Targets listed 100, 50, 0: a run visiting target numbers 1, 2, 3 moves −, so ↓.
    let text = COMPOSITE.replace("0.0000  50.0000  100.0000", "100  50  0");
    let (m, _) = parse_ok(&text);
    assert_eq!(m.targets(), &[0.0, 50.0, 100.0]);
    assert_eq!(m.runs()[0].direction, Direction::Down);
    // File run 1, target number 2 (= 50 mm) is 1.270 µm.
    assert_abs_diff_eq!(m.runs()[0].deviations[1].unwrap(), 0.00127, epsilon = 1e-12);
    assert_abs_diff_eq!(m.runs()[0].deviations[2].unwrap(), 0.0, epsilon = 1e-12);
}

/// Each bad variant of the composite example, with where and what the error must say.
#[test]
fn errors_name_line_column_and_what_was_expected() {
    let cases: &[(&str, &str, (usize, usize), &str)] = &[
        (
            "HEADER::\r\n",
            "TARGET DATA::\r\n",
            (1, 1),
            "HEADER:: as the first line",
        ),
        (
            "Owner      : Linear",
            "Owner      : Angular",
            (3, 14),
            "a straightness or angular test",
        ),
        (
            "Owner      : Linear",
            "Owner      : Velocity",
            (3, 14),
            "only linear measurements",
        ),
        (
            "Owner      : Linear",
            "Owner      : Rotary",
            (3, 14),
            "a rotary axis test: the layout of Renishaw's rotary files is not public",
        ),
        (
            "1   2      1.270",
            "1   2",
            (28, 1),
            "deviation row has 2 field(s), expected run, target number, value",
        ),
        (
            "1   2      1.270",
            "1   2      1.270  9",
            (28, 19),
            "4 field(s)",
        ),
        (
            "1   2      1.270",
            "1   2      1,270",
            (28, 12),
            "decimal comma",
        ),
        (
            "1   2      1.270",
            "1   2      NaN",
            (28, 12),
            "expected a number (deviation in µm)",
        ),
        (
            "1   2      1.270",
            "3   2      1.270",
            (28, 1),
            "run 3 is out of range",
        ),
        (
            "1   2      1.270",
            "1   7      1.270",
            (28, 5),
            "target number 7 is out of range",
        ),
        (
            "1   2      1.270",
            "1   1      1.270",
            (28, 5),
            "run 1 lists target 1 twice (first at line 27)",
        ),
        (
            "Target-count: 3",
            "Target-count: 4",
            (8, 15),
            "Target-count is 4 but 3 target(s) are listed",
        ),
        (
            "Target-count: 3",
            "Target-count: three",
            (8, 15),
            "whole number (target count)",
        ),
        (
            "0.0000  50.0000  100.0000",
            "0.0000  50.0000  50.0000",
            (10, 18),
            "duplicate target 50 mm",
        ),
        (
            "Run-count:2",
            "Run-count:3",
            (23, 11),
            "run 3 has no deviation rows",
        ),
        (
            "Air temp   : 20.337280 20.384956 0",
            "Air temp   : 20.337280",
            (35, 14),
            "start and end values",
        ),
        ("EOF::\r\n", "", (46, 1), "the file is truncated"),
        (
            "EOF::\r\n",
            "EOF::\r\nmore\r\n",
            (47, 1),
            "expected nothing after EOF::",
        ),
        (
            "RUNS::",
            "TARGET DATA::",
            (22, 1),
            "section TARGET DATA:: appears twice (first at line 6)",
        ),
    ];
    for (from, to, (line, column), needle) in cases {
        let text = COMPOSITE.replacen(from, to, 1);
        assert_ne!(text, COMPOSITE, "case {from:?} did not change the file");
        let error = parse(&text).unwrap_err();
        assert!(error.message.contains(needle), "{from:?} → {to:?}: {error}");
        assert_eq!(
            (error.position.line, error.position.column),
            (*line, *column),
            "{from:?} → {to:?}: {error}"
        );
    }
}

#[test]
fn non_monotonic_run_is_refused() {
    let text = COMPOSITE.replace(
        "1   2      1.270\r\n1   3      2.050",
        "1   3      2.050\r\n1   2      1.270",
    );
    let error = parse(&text).unwrap_err();
    assert_eq!(error.position.line, 29);
    assert!(error.message.contains("out of order"), "{error}");
}

#[test]
fn write_then_parse_round_trips_the_composite() {
    let (m, _) = parse_ok(COMPOSITE);
    let (again, warnings) = parse_ok(&write(&m));
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(again.targets(), m.targets());
    assert_eq!(again.runs(), m.runs());
    assert_eq!(again.axis(), m.axis());
    assert_eq!(again.environment, m.environment);
}

fn arbitrary_measurement() -> impl Strategy<Value = Measurement> {
    let targets = prop::collection::btree_set(-5000i32..5000, 1..12);
    (targets, 1usize..5, 0usize..5).prop_flat_map(|(targets, n_up, n_down)| {
        let m = targets.len();
        let values = prop::collection::vec(
            prop::collection::vec(prop::option::weighted(0.9, -200.0f64..200.0), m),
            n_up + n_down,
        );
        values.prop_filter_map("every run needs a reading", move |rows| {
            let targets_mm: Vec<f64> = targets.iter().map(|t| f64::from(*t) * 0.25).collect();
            let mut runs = Vec::new();
            for (index, row) in rows.iter().enumerate() {
                let (direction, number) = if index < n_up {
                    (Direction::Up, index + 1)
                } else {
                    (Direction::Down, index - n_up + 1)
                };
                runs.push(Run {
                    direction,
                    number: number as u32,
                    start_time_s: None,
                    deviations: row.iter().map(|v| v.map(um_to_mm)).collect(),
                });
            }
            Measurement::new(
                "Y",
                targets_mm,
                runs,
                Environment::default(),
                Metadata::default(),
            )
            .ok()
        })
    })
}

proptest! {
    #[test]
    fn write_then_parse_gives_the_same_runs(m in arbitrary_measurement()) {
        let text = write(&m);
        let (again, _) = parse(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(again.targets(), m.targets());
        prop_assert_eq!(again.runs().len(), m.runs().len());
        for (a, b) in again.runs().iter().zip(m.runs()) {
            // Runs with a single reading fall back to odd/even directions.
            if b.deviations.iter().flatten().count() > 1 {
                prop_assert_eq!(a.direction, b.direction);
            }
            for (x, y) in a.deviations.iter().zip(&b.deviations) {
                prop_assert_eq!(x.is_some(), y.is_some());
                if let (Some(x), Some(y)) = (x, y) {
                    prop_assert!((x - y).abs() <= 1e-15 * y.abs().max(1.0));
                }
            }
        }
    }

    #[test]
    fn parser_never_panics_on_mutated_files(cut in 0usize..1400, insert in "[ -~\r\n]{0,8}") {
        let mut text: Vec<char> = COMPOSITE.chars().collect();
        let at = cut.min(text.len());
        text.splice(at..at, insert.chars());
        let text: String = text.into_iter().collect();
        let _ = parse(&text);
    }
}

/// The row [`PlainRow`] and `text::number` read from the first line of
/// `text`: what [`SimpleRow`] must give (or nothing, leaving the line to them).
fn as_plain_row(text: &str) -> Option<(usize, u64, u64, u64)> {
    let line = text.split('\n').next()?;
    let line = line.strip_suffix('\r').unwrap_or(line);
    let row = PlainRow::of(line)?;
    let located = Line {
        number: 1,
        text: line,
    };
    let value = text::number(&located, row.value, "deviation in µm").ok()?;
    Some((
        row.run_offset,
        row.file_run,
        row.target_number,
        value.to_bits(),
    ))
}

fn as_simple_row(text: &str) -> Option<((usize, u64, u64, u64), usize)> {
    let (row, length) = SimpleRow::of(text)?;
    let fields = (
        row.run_offset,
        row.file_run,
        row.target_number,
        row.deviation_um.to_bits(),
    );
    Some((fields, length))
}

#[test]
fn simple_rows_are_plain_rows_with_their_line_end() {
    let simple = [
        ("1   2      1.270\r\nnext", 18),
        ("  12\t3 -0.125 \n", 15),
        ("1 1 +.5\n", 8),
        ("1 1 5.\r\n", 8),
        ("1 1 123456789012345\n", 20),
    ];
    for (text, length) in simple {
        let (fields, read) = as_simple_row(text).unwrap_or_else(|| panic!("{text:?}"));
        assert_eq!(read, length, "{text:?}");
        assert_eq!(Some(fields), as_plain_row(text), "{text:?}");
    }
    // Left to the line-by-line reading: no line end, an exponent, 16 digits,
    // a field too many, a stray carriage return, a sign inside, no value.
    for text in [
        "1 1 1.5",
        "1 1 1e-3\n",
        "1 1 1234567890123456\n",
        "1 1 1.5 2\n",
        "1 1 1.5\r\r\n",
        "1 1 1-5\n",
        "1 1 .\n",
        "1 1\n",
        "11.5\n",
        "1 1234567890123456789 1\n",
    ] {
        assert_eq!(as_simple_row(text), None, "{text:?}");
    }
}

proptest! {
    #[test]
    fn a_simple_row_reads_as_the_plain_row_reading_does(
        text in "[ \t]{0,2}[0-9]{1,3}[ \t]{0,2}[0-9]{1,20}[ \t]{0,2}[-+]?[0-9.]{0,17}[eE]?[0-9]{0,2}[ \t]{0,2}\r?\r?\n?x"
    ) {
        if let Some((fields, length)) = as_simple_row(&text) {
            prop_assert_eq!(Some(fields), as_plain_row(&text));
            prop_assert_eq!(text[..length].matches('\n').count(), 1);
            prop_assert!(text[..length].ends_with('\n'));
        }
    }
}
