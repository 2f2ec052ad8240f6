//! Malformed inputs across every reader: each must give exit code 2 and an
//! error naming file, line and column and what was expected, through the
//! library and through the CLI.

use std::path::PathBuf;

use axcomp::read::read_path;

use crate::util::{axcomp, shared_data, test_data};

/// (file, line, column, what the message must say).
const CASES: &[(&str, usize, usize, &str)] = &[
    // Renishaw .rtl
    ("rtl-truncated.rtl", 70, 1, "the file is truncated"),
    // See: issue 14; no public sample: refused at the Owner line (read::rtl::ROTARY_OWNER).
    (
        "rtl-rotary.rtl",
        3,
        14,
        "a rotary axis test: the layout of Renishaw's rotary files is not public",
    ),
    // See: issue 15; no public sample of a straightness or angular .rtl.
    (
        "rtl-straightness.rtl",
        3,
        14,
        "a straightness or angular test: no sample of Renishaw's layout for it is public",
    ),
    (
        "rtl-target-count.rtl",
        8,
        15,
        "Target-count is 17 but 16 target(s) are listed",
    ),
    (
        "rtl-run-count.rtl",
        26,
        11,
        "Run-count is 11 but run 11 has no deviation rows",
    ),
    (
        "rtl-non-numeric.rtl",
        32,
        15,
        "expected a number (deviation in µm), found \"2.11O\"",
    ),
    (
        "rtl-decimal-comma.rtl",
        32,
        15,
        "with '.' as decimal point, found decimal comma",
    ),
    (
        "rtl-nan.rtl",
        32,
        15,
        "expected a number (deviation in µm), found \"NaN\"",
    ),
    ("rtl-overflow.rtl", 32, 15, "which overflows"),
    (
        "rtl-absurd.rtl",
        32,
        15,
        "expected a deviation within ±1000000 µm (±1 m), found 1e308 µm",
    ),
    (
        "rtl-duplicate-target.rtl",
        10,
        18,
        "duplicate target 58.557 mm (first listed at line 10, column 9)",
    ),
    (
        "rtl-two-fields.rtl",
        55,
        1,
        "deviation row has 2 field(s), expected run, target number, value",
    ),
    (
        "rtl-angular.rtl",
        3,
        14,
        "found Owner : Angular, a straightness or angular test",
    ),
    (
        "rtl-duplicate-row.rtl",
        89,
        5,
        "run 4 lists target 6 twice (first at line 88)",
    ),
    (
        "rtl-out-of-order.rtl",
        32,
        1,
        "run 1 visits the targets out of order",
    ),
    (
        "rtl-run-out-of-range.rtl",
        89,
        1,
        "run 14 is out of range: Run-count is 10",
    ),
    (
        "rtl-no-header.rtl",
        1,
        1,
        "unknown format: expected one of: rtl",
    ),
    ("rtl-after-eof.rtl", 204, 1, "expected nothing after EOF::"),
    (
        "junk-in-text.rtl",
        23,
        10,
        "found byte 0x07: this looks like a binary file",
    ),
    // ESS/PSI ecmc .dat
    ("ecmc-decimal-comma.dat", 22, 19, "found decimal comma"),
    (
        "ecmc-nan.dat",
        22,
        19,
        "expected a number (actual position), found \"nan\"",
    ),
    ("ecmc-non-numeric.dat", 22, 19, "found \"fifteen\""),
    (
        "ecmc-duplicate-target.dat",
        23,
        10,
        "duplicate target 15 (also TGT_DATA[1] at line 21)",
    ),
    (
        "ecmc-beyond-positions.dat",
        29,
        10,
        "index 6 is beyond POSITIONS=5",
    ),
    (
        "ecmc-beyond-cycles.dat",
        22,
        14,
        "cycle index 6 is beyond CYCLES=5",
    ),
    (
        "ecmc-bad-unit.dat",
        17,
        6,
        "expected UNIT=mm, UNIT=inch or, for a rotary axis, UNIT=deg",
    ),
    ("ecmc-truncated.dat", 63, 1, "expected KEY=VALUE"),
    (
        "ecmc-absurd.dat",
        22,
        19,
        "expected a deviation within ±1000000 µm (±1 m), found -1e308 mm",
    ),
    (
        "ecmc-missing-cycles.dat",
        3,
        8,
        "CYCLES=3 but the file holds no REF_DATA_FWD cycle(s) 2–3 and no REF_DATA_BWD cycle(s) 2–3: the file looks truncated",
    ),
    (
        "ecmc-repeated.dat",
        77,
        14,
        "REF_DATA_FWD[1,1] is given twice (first at line 22)",
    ),
    // API XD .pos
    ("pos-decimal-comma.pos", 22, 32, "found decimal comma"),
    (
        "pos-nan.pos",
        22,
        38,
        "expected a number (linear error), found \"nan\"",
    ),
    (
        "pos-short-row.pos",
        23,
        41,
        "data row has 3 column(s), expected 9",
    ),
    (
        "pos-point-count.pos",
        16,
        14,
        "NumofPoints is 26 but the data table has 27 rows",
    ),
    ("pos-unit.pos", 12, 7, "expected Unit: inch or mm"),
    (
        "pos-absurd.pos",
        22,
        36,
        "expected a deviation within ±1000000 µm (±1 m), found 2.54e304 µm",
    ),
    // axcomp CSV
    (
        "csv-decimal-comma.csv",
        3,
        1,
        "row has 5 field(s), expected 4",
    ),
    (
        "csv-direction.csv",
        3,
        7,
        "expected direction up or down, found \"forward\"",
    ),
    (
        "csv-duplicate.csv",
        4,
        1,
        "run 1↑ at 0 mm is listed twice (first at line 2)",
    ),
    (
        "csv-nan.csv",
        2,
        8,
        "expected a number (deviation in µm), found \"NaN\"",
    ),
    ("csv-no-rows.csv", 3, 1, "expected at least one data row"),
    (
        "csv-absurd.csv",
        2,
        8,
        "expected a deviation within ±1000000 µm (±1 m), found 1e308 µm",
    ),
    (
        "csv-absurd-target.csv",
        4,
        1,
        "expected a target within ±100000 mm (±100 m), found 2e9 mm",
    ),
    ("csv-bad-header.csv", 1, 1, "unknown format"),
    (
        "csv-mixed-decimal.csv",
        4,
        10,
        "expected a decimal comma as on line 2, found a decimal point in \"1.5\": the file mixes decimal marks",
    ),
    // Any format
    ("empty.rtl", 1, 1, "found an empty file"),
    ("blank.csv", 1, 1, "found an empty file"),
    (
        "binary.bin",
        1,
        3,
        "found byte 0x03: this looks like a binary file",
    ),
    ("utf16-bom.rtl", 1, 1, "found UTF-16"),
    ("utf16-no-bom.csv", 1, 1, "found UTF-16"),
    ("unknown.txt", 1, 1, "unknown format: expected one of"),
];

/// Real third-party files that are malformed as measurements.
const REAL_CASES: &[(&str, usize, usize, &str)] = &[
    // Upstream hand-edited the first positions (5 … −25, then 35 … 130 in).
    (
        "api-xd/example__V__V Axis Forward.pos",
        28,
        1,
        "position 35 after -25: expected the positions of a run to go all up or all down",
    ),
    (
        "api-xd/example__issue-01__X Axis Forward.pos",
        1,
        1,
        "found only a compensation table",
    ),
    (
        "api-xd/test__data__X Axis Forward.pos",
        1,
        1,
        "found only a compensation table",
    ),
];

fn all_cases() -> Vec<(PathBuf, usize, usize, &'static str)> {
    let bad = CASES
        .iter()
        .map(|(f, l, c, m)| (test_data(&format!("bad/{f}")), *l, *c, *m));
    let real = REAL_CASES
        .iter()
        .map(|(f, l, c, m)| (shared_data(f), *l, *c, *m));
    bad.chain(real).collect()
}

#[test]
fn every_bad_file_is_listed() {
    let listed: Vec<&str> = CASES.iter().map(|c| c.0).collect();
    for entry in std::fs::read_dir(test_data("bad")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        assert!(
            listed.contains(&name.as_str()),
            "tests/data/bad/{name} has no expected error"
        );
    }
    assert!(CASES.len() >= 25);
}

#[test]
fn library_reports_line_column_and_expectation() {
    for (path, line, column, needle) in all_cases() {
        let error = read_path(&path, None).expect_err(&path.display().to_string());
        let text = error.to_string();
        let prefix = format!("{}:{line}:{column}: ", path.display());
        assert!(
            text.starts_with(&prefix),
            "{text}\n  expected prefix {prefix}"
        );
        assert!(
            text.contains(needle),
            "{text}\n  expected to contain {needle:?}"
        );
    }
}

#[test]
fn cli_exits_2_with_the_same_message() {
    for (path, line, column, needle) in all_cases() {
        let run = axcomp(["evaluate".as_ref(), path.as_os_str()]);
        assert_eq!(run.code, 2, "{}: {}", path.display(), run.stderr);
        assert!(run.stdout.is_empty(), "nothing on stdout for a bad file");
        let location = format!("{}:{line}:{column}: ", path.display());
        assert!(
            run.stderr.contains(&location) && run.stderr.contains(needle),
            "{}",
            run.stderr
        );
        assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    }
}

/// Readings of ±1e308 once made `report` spin for minutes over its chart
/// scales: they are refused at reading, by every command.
#[test]
fn absurd_readings_stop_report_at_reading() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("r.html");
    let file = test_data("bad/rtl-absurd.rtl");
    let started = std::time::Instant::now();
    let run = axcomp([
        "report".as_ref(),
        file.as_os_str(),
        "-o".as_ref(),
        output.as_os_str(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(&format!(
            "{}:32:15: expected a deviation within ±1000000 µm",
            file.display()
        )),
        "{}",
        run.stderr
    );
    assert!(!output.exists());
    assert!(started.elapsed().as_secs() < 10);
}
