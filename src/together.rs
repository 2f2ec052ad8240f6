//! Whether two inputs belong together before they are joined or compared.
//!
//! Every place that puts two inputs side by side asks [`check_together`]:
//! the two files of one test that `read::read_paths` joins (forward and
//! reverse `.pos`), a first test and its re-test (`report --after`,
//! `diagnose --before`), and a compensation table and the test it is
//! applied to (`convert --existing`, `predict --table`). A clear mismatch is
//! refused ([`NotTogether`]): another axis, target ranges with nothing in
//! common, the same file or the same readings twice. A doubtful one is a
//! [`Warning::Doubtful`]: other machine names, other units in the original
//! files, a range that only partly overlaps. Plain data in and out: the
//! caller describes each input as an [`Input`] and names it as the user knows
//! it (a file name, or "the first test").

use std::path::Path;

use chrono::NaiveDateTime;

use crate::error::{Doubt, Warning};
use crate::measurement::{AxisKind, Measurement};
use crate::units::LengthUnit;

/// What the two inputs are to each other: it decides what is refused and
/// what is only doubtful.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pairing {
    /// Two files of one test, joined into one measurement (e.g. the forward
    /// and reverse `.pos` files of one axis).
    OneTest,
    /// A first test and its re-test, compared.
    BeforeAfter,
    /// A test (first) and a compensation table applied to it (second): the
    /// table active during the test, or the table predicted for its re-test.
    TableOnTest,
}

/// What one input says about itself, as far as belonging together goes.
#[derive(Clone, Debug)]
pub struct Input<'a> {
    /// How the user knows it: the file name, or "the first test".
    pub label: String,
    /// The axis it is of; `None` when the file does not record it (its name
    /// is then a placeholder, and nothing can be compared).
    pub axis: Option<&'a str>,
    /// The machine name it records, if any.
    pub machine: Option<&'a str>,
    /// The length unit of the original file, when it is a measurement file.
    pub length_unit: Option<LengthUnit>,
    /// First and last target (or compensation point), mm (° on a rotary axis).
    pub range_mm: (f64, f64),
    /// Linear or rotary, when a measurement says (a table's points are in
    /// the unit of the test it is paired with): the unit the messages say.
    pub kind: Option<AxisKind>,
    /// The file it was read from, if known.
    pub file: Option<&'a Path>,
    /// The readings, to recognise the same test given twice (tables have none).
    pub readings: Option<&'a Measurement>,
    /// When it was measured, as the file records it (parsed), if it does.
    pub date: Option<NaiveDateTime>,
}

impl<'a> Input<'a> {
    /// A measurement, named `label` in messages.
    pub fn measurement(measurement: &'a Measurement, label: impl Into<String>) -> Input<'a> {
        let targets = measurement.targets();
        Input {
            label: label.into(),
            axis: measurement.axis_recorded().then(|| measurement.axis()),
            machine: measurement.metadata.machine.as_deref(),
            length_unit: Some(measurement.metadata.length_unit),
            range_mm: (targets[0], targets[targets.len() - 1]),
            kind: Some(measurement.kind()),
            file: measurement.metadata.source_file.as_deref(),
            readings: Some(measurement),
            date: measurement.metadata.date.as_ref().and_then(|d| d.parsed),
        }
    }

    /// A compensation table of `axis` with its points, named `label` in
    /// messages. `positions_mm` must not be empty (a table has points).
    pub fn table(axis: &'a str, positions_mm: &[f64], label: impl Into<String>) -> Input<'a> {
        let first = positions_mm.first().copied().unwrap_or(f64::NAN);
        let last = positions_mm.last().copied().unwrap_or(f64::NAN);
        Input {
            label: label.into(),
            axis: Some(axis),
            machine: None,
            length_unit: None,
            range_mm: (first, last),
            kind: None,
            file: None,
            readings: None,
            date: None,
        }
    }
}

/// Why two inputs are refused together.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NotTogether {
    /// They are of different axes.
    #[error("{first} is of axis {first_axis}, {second} of axis {second_axis}: {what}")]
    DifferentAxes {
        /// The first input.
        first: String,
        /// Its axis.
        first_axis: String,
        /// The second input.
        second: String,
        /// Its axis.
        second_axis: String,
        /// What this means for the pairing.
        what: &'static str,
    },
    /// The same file twice.
    #[error("{first} is given twice: {what}")]
    SameFile {
        /// The file.
        first: String,
        /// What this means for the pairing.
        what: &'static str,
    },
    /// Two files with the very same readings.
    #[error("{first} and {second} hold the same readings (the same file, or a copy of it): {what}")]
    SameReadings {
        /// The first input.
        first: String,
        /// The second input.
        second: String,
        /// What this means for the pairing.
        what: &'static str,
    },
    /// The target ranges have nothing in common.
    #[error("{ranges}: the ranges do not overlap, so they are not {what}")]
    DisjointRanges {
        /// The two inputs and their ranges.
        ranges: Ranges,
        /// What they would have to be.
        what: &'static str,
    },
    /// A re-test that lies mostly where the first test measured nothing.
    #[error(
        "{ranges}: only {common_pct:.0} % of the re-test lies where the first test measured (at least {MIN_RETEST_COVERED_PCT} % is needed), so they are not a test and its re-test of the same stretch; measure the re-test over the first test's targets"
    )]
    RetestElsewhere {
        /// The first test and the re-test with their ranges.
        ranges: Ranges,
        /// The share of the re-test's range inside the first test's, %.
        common_pct: f64,
    },
    /// The "first" test was measured after the re-test, by the dates the files record.
    #[error(
        "{first} was measured on {first_date}, {second} on {second_date}: the first test is the later one by the dates the files record; give the earlier test as the first test (--before, or the report's FILE) and the later one as the re-test (--after)"
    )]
    SwappedDates {
        /// The first test.
        first: String,
        /// Its recorded date.
        first_date: NaiveDateTime,
        /// The re-test.
        second: String,
        /// Its recorded date.
        second_date: NaiveDateTime,
    },
}

/// Two inputs and their ranges, as a refusal names them: `a.rtl covers
/// 0 … 750 mm, b.rtl 400 … 1150 mm`.
#[derive(Clone, Debug, PartialEq)]
pub struct Ranges {
    /// After a position: ` mm`, or `°` on a rotary axis.
    pub unit: &'static str,
    /// The first input.
    pub first: String,
    /// Its range, mm (° on a rotary axis).
    pub first_mm: (f64, f64),
    /// The second input.
    pub second: String,
    /// Its range.
    pub second_mm: (f64, f64),
}

impl std::fmt::Display for Ranges {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Ranges {
            unit,
            first,
            first_mm,
            second,
            second_mm,
        } = self;
        write!(
            f,
            "{first} covers {} … {}{unit}, {second} {} … {}{unit}",
            first_mm.0, first_mm.1, second_mm.0, second_mm.1
        )
    }
}

/// The least share of a re-test's range, %, that must lie within the first
/// test's range: below it the prediction from the first test would cover
/// little of the re-test (beyond its targets only its end values, held), and
/// the two are tests of different stretches, not a test and its re-test.
pub const MIN_RETEST_COVERED_PCT: f64 = 10.0;

/// Checks that two inputs belong together for `pairing`: the refusal, or
/// the doubts as warnings (empty when nothing is odd).
///
/// Refused: another axis (compared case-insensitively); the same file
/// (same path) or the same readings twice (one test is not two, and a
/// re-test never repeats a test to the last digit); ranges without a common
/// stretch; for a test and its re-test, a re-test that lies mostly (more
/// than 100 − [`MIN_RETEST_COVERED_PCT`] % of its range) outside the first
/// test's range, or a first test whose recorded date is later than the
/// re-test's. Doubtful: other machine names; other units of the original files;
/// ranges that differ by more than 1 % of the longer one, or, for a table,
/// a test that reaches beyond the table's points (the controller holds the
/// end values there).
///
/// # Example
/// ```
/// use axcomp::together::{Input, Pairing, check_together};
/// let before = Input::table("X", &[0.0, 500.0], "X.COM");
/// let after = Input::table("Y", &[0.0, 500.0], "Y.COM");
/// let error = check_together(Pairing::BeforeAfter, &before, &after).unwrap_err();
/// assert!(error.to_string().starts_with("X.COM is of axis X, Y.COM of axis Y"));
/// ```
pub fn check_together(
    pairing: Pairing,
    first: &Input<'_>,
    second: &Input<'_>,
) -> Result<Vec<Warning>, NotTogether> {
    let what = match pairing {
        Pairing::OneTest => "two files of one test must be of one axis, from two different files",
        Pairing::BeforeAfter => "a re-test must be of the axis of the first test, and a new test",
        Pairing::TableOnTest => "a table applies to its own axis only",
    };
    if let (Some(first_axis), Some(second_axis)) = (first.axis, second.axis)
        && !first_axis.eq_ignore_ascii_case(second_axis)
    {
        return Err(NotTogether::DifferentAxes {
            first: first.label.clone(),
            first_axis: first_axis.to_string(),
            second: second.label.clone(),
            second_axis: second_axis.to_string(),
            what,
        });
    }
    if let (Some(a), Some(b)) = (first.file, second.file)
        && a == b
    {
        return Err(NotTogether::SameFile {
            first: first.label.clone(),
            what,
        });
    }
    if let (Some(a), Some(b)) = (first.readings, second.readings)
        && same_readings(a, b)
    {
        return Err(NotTogether::SameReadings {
            first: first.label.clone(),
            second: second.label.clone(),
            what,
        });
    }
    let (a_from, a_to) = first.range_mm;
    let (b_from, b_to) = second.range_mm;
    let unit = if [first.kind, second.kind].contains(&Some(AxisKind::Rotary)) {
        "°"
    } else {
        " mm"
    };
    let common_mm = a_to.min(b_to) - a_from.max(b_from);
    // A single common point is no common stretch (a table's end point on a test's start).
    let tolerance_mm = 1e-6;
    let ranges = || Ranges {
        unit,
        first: first.label.clone(),
        first_mm: first.range_mm,
        second: second.label.clone(),
        second_mm: second.range_mm,
    };
    if common_mm.is_nan() || common_mm <= tolerance_mm {
        return Err(NotTogether::DisjointRanges {
            ranges: ranges(),
            what: match pairing {
                Pairing::OneTest => "one test",
                Pairing::BeforeAfter => "a test and its re-test",
                Pairing::TableOnTest => "a table and a test it applies to",
            },
        });
    }
    if pairing == Pairing::BeforeAfter {
        let retest_mm = b_to - b_from;
        let common_pct = if retest_mm > 0.0 {
            100.0 * common_mm / retest_mm
        } else {
            100.0
        };
        if common_pct < MIN_RETEST_COVERED_PCT {
            return Err(NotTogether::RetestElsewhere {
                ranges: ranges(),
                common_pct,
            });
        }
        if let (Some(first_date), Some(second_date)) = (first.date, second.date)
            && first_date > second_date
        {
            return Err(NotTogether::SwappedDates {
                first: first.label.clone(),
                first_date,
                second: second.label.clone(),
                second_date,
            });
        }
    }
    let mut warnings = Vec::new();
    if let (Some(a), Some(b)) = (first.machine, second.machine)
        && !a.trim().eq_ignore_ascii_case(b.trim())
    {
        warnings.push(Warning::Doubtful(Doubt::DifferentMachines {
            first: first.label.clone(),
            first_machine: a.to_string(),
            second: second.label.clone(),
            second_machine: b.to_string(),
        }));
    }
    if let (Some(a), Some(b)) = (first.length_unit, second.length_unit)
        && a != b
    {
        warnings.push(Warning::Doubtful(Doubt::DifferentUnits {
            first: first.label.clone(),
            first_unit: a,
            second: second.label.clone(),
            second_unit: b,
        }));
    }
    // 1 % of the longer range: the same test program gives the same targets;
    // a re-test over another stretch of the axis compares different things.
    let slack_mm = 0.01 * (a_to - a_from).max(b_to - b_from);
    let partial = match pairing {
        Pairing::OneTest | Pairing::BeforeAfter => {
            (a_from - b_from).abs() > slack_mm || (a_to - b_to).abs() > slack_mm
        }
        // A table longer than the test is normal; a test beyond the table is not.
        Pairing::TableOnTest => a_from < b_from - slack_mm || a_to > b_to + slack_mm,
    };
    if partial {
        warnings.push(Warning::Doubtful(Doubt::PartialOverlap {
            unit,
            first: first.label.clone(),
            first_mm: first.range_mm,
            second: second.label.clone(),
            second_mm: second.range_mm,
            consequence: match pairing {
                Pairing::OneTest => "only common targets can be joined",
                Pairing::BeforeAfter => {
                    "the comparison covers different stretches of the axis; measure the re-test over the first test's targets"
                }
                Pairing::TableOnTest => {
                    "beyond the table's points the controller holds its end values"
                }
            },
        }));
    }
    Ok(warnings)
}

/// The same targets and the same runs, reading for reading.
fn same_readings(a: &Measurement, b: &Measurement) -> bool {
    a.targets() == b.targets() && a.runs() == b.runs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::{AxisSource, Direction, Environment, Metadata, Run};

    fn test(axis: &str, targets: Vec<f64>, offset_mm: f64, machine: &str) -> Measurement {
        let runs = Direction::BOTH
            .iter()
            .map(|&direction| Run {
                direction,
                number: 1,
                start_time_s: None,
                deviations: targets.iter().map(|_| Some(offset_mm)).collect(),
            })
            .collect();
        let metadata = Metadata {
            machine: Some(machine.to_string()),
            axis_source: AxisSource::Given,
            ..Metadata::default()
        };
        Measurement::new(axis, targets, runs, Environment::default(), metadata).unwrap()
    }

    #[test]
    fn an_unrecorded_axis_is_compared_with_nothing() {
        let z = test("Z", vec![0.0, 500.0, 1000.0], 0.001, "M1");
        let mut unnamed = test("X", vec![0.0, 500.0, 1000.0], 0.002, "M1");
        unnamed.metadata.axis_source = AxisSource::NotRecorded;
        // Its "X" is a placeholder: not another axis than Z.
        assert_eq!(check(Pairing::BeforeAfter, &z, &unnamed), Ok(Vec::new()));
    }

    fn check(
        pairing: Pairing,
        a: &Measurement,
        b: &Measurement,
    ) -> Result<Vec<Warning>, NotTogether> {
        check_together(
            pairing,
            &Input::measurement(a, "a.rtl"),
            &Input::measurement(b, "b.rtl"),
        )
    }

    /// A rotary axis' ranges are said in degrees, not mm.
    #[test]
    fn a_rotary_axis_ranges_are_in_degrees() {
        let rotary =
            |targets: Vec<f64>| test("C", targets, 0.0001, "M1").with_kind(AxisKind::Rotary);
        let (full, upper, part) = (
            rotary(vec![0.0, 90.0, 180.0, 270.0, 360.0]),
            rotary(vec![400.0, 450.0, 500.0]),
            rotary(vec![0.0, 90.0, 180.0]),
        );
        let refused = check(Pairing::BeforeAfter, &full, &upper).unwrap_err();
        assert_eq!(
            refused.to_string(),
            "a.rtl covers 0 … 360°, b.rtl 400 … 500°: the ranges do not overlap, so they are not a test and its re-test"
        );
        let doubts = check(Pairing::BeforeAfter, &full, &part).unwrap();
        assert!(
            doubts[0]
                .to_string()
                .starts_with("a.rtl covers 0 … 360°, b.rtl 0 … 180°: they overlap only in part"),
            "{}",
            doubts[0]
        );
        // A table (its kind unknown) takes the unit of the rotary test.
        let table = Input::table("C", &[400.0, 500.0], "C.comp");
        let refused = check_together(
            Pairing::TableOnTest,
            &table,
            &Input::measurement(&full, "c.csv"),
        )
        .unwrap_err();
        assert!(
            refused
                .to_string()
                .starts_with("C.comp covers 400 … 500°, c.csv 0 … 360°")
        );
    }

    #[test]
    fn clear_mismatches_are_refused() {
        let x = test("X", vec![0.0, 500.0, 1000.0], 0.001, "M1");
        let y = test("y", vec![0.0, 500.0, 1000.0], 0.002, "M1");
        assert!(matches!(
            check(Pairing::BeforeAfter, &x, &y),
            Err(NotTogether::DifferentAxes { .. })
        ));
        // Case does not make another axis.
        let lower_x = test("x", vec![0.0, 500.0, 1000.0], 0.002, "M1");
        assert_eq!(check(Pairing::BeforeAfter, &x, &lower_x), Ok(Vec::new()));
        assert!(matches!(
            check(Pairing::OneTest, &x, &x.clone()),
            Err(NotTogether::SameReadings { .. })
        ));
        let far = test("X", vec![1500.0, 2000.0], 0.002, "M1");
        let error = check(Pairing::BeforeAfter, &x, &far).unwrap_err();
        assert_eq!(
            error.to_string(),
            "a.rtl covers 0 … 1000 mm, b.rtl 1500 … 2000 mm: the ranges do not overlap, so they are not a test and its re-test"
        );
        // Touching at one point is no overlap.
        let touching = test("X", vec![1000.0, 2000.0], 0.002, "M1");
        assert!(check(Pairing::BeforeAfter, &x, &touching).is_err());
    }

    #[test]
    fn doubts_are_warnings() {
        let a = test("X", vec![0.0, 500.0, 1000.0], 0.001, "MCV 754");
        let mut b = test("X", vec![400.0, 1400.0], 0.002, "Other mill");
        b.metadata.length_unit = LengthUnit::Inch;
        let warnings = check(Pairing::BeforeAfter, &a, &b).unwrap();
        let texts: Vec<String> = warnings.iter().map(ToString::to_string).collect();
        assert_eq!(texts.len(), 3, "{texts:?}");
        assert!(texts[0].contains("\"MCV 754\", b.rtl \"Other mill\""));
        assert!(texts[1].contains("a.rtl was written in mm, b.rtl in inch"));
        assert!(texts[2].starts_with("a.rtl covers 0 … 1000 mm, b.rtl 400 … 1400 mm"));
    }

    #[test]
    fn a_table_may_be_longer_than_the_test_but_not_shorter() {
        let test_x = test("X", vec![0.0, 500.0, 1000.0], 0.001, "M1");
        let long = Input::table("X", &[-100.0, 1200.0], "T.COM");
        let short = Input::table("X", &[0.0, 600.0], "T.COM");
        let off = Input::table("X", &[1100.0, 1200.0], "T.COM");
        let measured = Input::measurement(&test_x, "a.rtl");
        assert_eq!(
            check_together(Pairing::TableOnTest, &measured, &long),
            Ok(Vec::new())
        );
        let warnings = check_together(Pairing::TableOnTest, &measured, &short).unwrap();
        assert!(warnings[0].to_string().contains("holds its end values"));
        assert!(check_together(Pairing::TableOnTest, &measured, &off).is_err());
    }

    /// By hand: the first test covers −20 … 20 mm, the re-test 0 … 750 mm;
    /// they share 0 … 20 mm, 20 / 750 = 2.7 % of the re-test.
    #[test]
    fn a_retest_mostly_elsewhere_is_refused() {
        let first = test("X", vec![-20.0, 0.0, 20.0], 0.001, "M1");
        let retest = test("X", vec![0.0, 375.0, 750.0], 0.002, "M1");
        let error = check(Pairing::BeforeAfter, &first, &retest).unwrap_err();
        assert_eq!(
            error.to_string(),
            "a.rtl covers -20 … 20 mm, b.rtl 0 … 750 mm: only 3 % of the re-test lies where the first test measured (at least 10 % is needed), so they are not a test and its re-test of the same stretch; measure the re-test over the first test's targets"
        );
        // The other way round the re-test lies wholly inside: a doubt only.
        assert!(check(Pairing::BeforeAfter, &retest, &first).is_ok());
        // Two files of one test are not judged by it.
        assert!(check(Pairing::OneTest, &first, &retest).is_ok());
    }

    #[test]
    fn a_first_test_dated_after_its_retest_is_refused() {
        let dated = |text: &str, offset: f64| {
            let mut m = test("X", vec![0.0, 500.0, 1000.0], offset, "M1");
            m.metadata.date = Some(crate::measurement::TestDate {
                raw: text.to_string(),
                parsed: NaiveDateTime::parse_from_str(text, "%Y-%m-%d %H:%M:%S").ok(),
            });
            m
        };
        let early = dated("2026-11-20 08:30:00", 0.001);
        let late = dated("2026-11-20 10:00:00", 0.002);
        assert_eq!(check(Pairing::BeforeAfter, &early, &late), Ok(Vec::new()));
        let error = check(Pairing::BeforeAfter, &late, &early).unwrap_err();
        assert_eq!(
            error.to_string(),
            "a.rtl was measured on 2026-11-20 10:00:00, b.rtl on 2026-11-20 08:30:00: the first test is the later one by the dates the files record; give the earlier test as the first test (--before, or the report's FILE) and the later one as the re-test (--after)"
        );
        // Without a recorded date nothing is said.
        let mut undated = late.clone();
        undated.metadata.date = None;
        assert!(check(Pairing::BeforeAfter, &undated, &early).is_ok());
    }
}
