//! An update keeps what the control has: `convert --existing` on the real
//! Fagor tables (`../shared/data/api-xd/`) without `--reference` is referred
//! to the existing table's own zero, keeps every old point (outside the
//! measured range with its old value) and says so per range; a one-direction
//! test says where its curve went and that the reversal was not measured; the
//! 8065 writes no partial `.mp`. Expected numbers are computed here from the
//! files with plain text handling (the helpers of `fagor.rs`).

use std::path::Path;

use approx::abs_diff_eq;

use crate::fagor::{al_rows, data, laser_data, mp_rows};
use crate::util::axcomp;

const INCH_MM: f64 = 25.4;

/// (laser file, existing table, controller, axis).
const CASES: [(&str, &str, &str, &str); 4] = [
    (
        "example__8055__X Axis Forward.pos",
        "example__8055__ALX",
        "fagor8055",
        "X",
    ),
    (
        "example__8055__Y Axis Forward.pos",
        "example__8055__ALY",
        "fagor8055",
        "Y",
    ),
    (
        "example__8065__X Axis Forward.pos",
        "example__8065__X.mp",
        "fagor8065",
        "X",
    ),
    (
        "example__8065__Y Axis Forward.pos",
        "example__8065__Y.mp",
        "fagor8065",
        "Y",
    ),
];

/// `convert LASER --existing TABLE` with no `--reference`: (stdout, file bytes).
fn update(laser: &str, table: &str, controller: &str, axis: &str, out: &Path) -> (String, Vec<u8>) {
    let run = axcomp([
        "convert",
        &data(laser),
        "--axis",
        axis,
        "--existing",
        &data(table),
        "--controller",
        controller,
        "-o",
        &out.display().to_string(),
        "-q",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    (run.stdout, std::fs::read(out).unwrap())
}

/// (position, value) rows of a table file in its own unit, and the unit's
/// mm and its last digit (half of it is the file's rounding), mm.
fn rows_mm(bytes: &[u8], controller: &str) -> (Vec<(f64, f64)>, f64) {
    if controller == "fagor8055" {
        let text = String::from_utf8(bytes.to_vec()).unwrap();
        let rows = al_rows(&text)
            .into_iter()
            .map(|(p, v)| (p * INCH_MM, v * INCH_MM))
            .collect();
        (rows, 1e-5 * INCH_MM)
    } else {
        (mp_rows(bytes), 1e-4)
    }
}

#[test]
fn an_update_is_old_plus_residual_at_the_old_zero_and_keeps_every_old_point() {
    let directory = tempfile::tempdir().unwrap();
    for (laser, table, controller, axis) in CASES {
        let out = directory.path().join(format!("{table}.new"));
        let (_, new_bytes) = update(laser, table, controller, axis, &out);
        let (new, last_digit_mm) = rows_mm(&new_bytes, controller);
        let (old, _) = rows_mm(&std::fs::read(data(table)).unwrap(), controller);
        let errors: Vec<(f64, f64)> = laser_data(laser)
            .into_iter()
            .map(|(p, e)| (p * INCH_MM, e * INCH_MM))
            .collect();
        let at =
            |rows: &[(f64, f64)], p: f64| rows.iter().find(|r| (r.0 - p).abs() < 1e-6).map(|r| r.1);
        // The old tables are zero at the machine zero, 0 mm.
        assert_eq!(at(&old, 0.0), Some(0.0), "{table}");
        let e0 = at(&errors, 0.0).unwrap();
        let first = errors.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
        let last = errors.iter().map(|e| e.0).fold(f64::NEG_INFINITY, f64::max);
        let within = |got: f64, expected: f64, what: &str| {
            // The file's rounding: half its last digit (and 1 nm of arithmetic).
            assert!(
                abs_diff_eq!(got, expected, epsilon = last_digit_mm / 2.0 + 1e-6),
                "{table} {what}: {got} mm vs {expected} mm"
            );
        };
        // Every old point is in the new table: outside the measured range
        // as it was, inside it old + e − e(0).
        for (position, old_value) in &old {
            let new_value = at(&new, *position)
                .unwrap_or_else(|| panic!("{table}: the old point at {position} mm is lost"));
            match at(&errors, *position) {
                Some(e) => within(new_value, old_value + e - e0, &format!("at {position} mm")),
                None => {
                    assert!(*position < first || *position > last, "{table} {position}");
                    within(new_value, *old_value, &format!("kept at {position} mm"));
                }
            }
        }
        // A new point the old table did not have: the laser's e − e(0) on the
        // old table held at its end (the control holds the end value).
        for (position, new_value) in &new {
            if at(&old, *position).is_none() {
                let e = at(&errors, *position).expect("a new point is a measured target");
                let old_end = if *position > old.last().unwrap().0 {
                    old.last().unwrap().1
                } else {
                    old[0].1
                };
                within(
                    *new_value,
                    old_end + e - e0,
                    &format!("new at {position} mm"),
                );
            }
        }
        // At the machine zero the update adds nothing.
        assert_eq!(at(&new, 0.0), Some(0.0), "{table}");
    }
}

#[test]
fn the_update_says_per_range_what_it_kept() {
    let directory = tempfile::tempdir().unwrap();
    let (laser, table, controller, axis) = CASES[3];
    let (stdout, bytes) = update(
        laser,
        table,
        controller,
        axis,
        &directory.path().join("Y.mp"),
    );
    // Y.mp: 41 points −4953 … 127 mm (−195 … 5 in); the laser −2159 … 0 mm.
    assert_eq!(mp_rows(&bytes).len(), 41);
    assert!(
        stdout.contains(
            "Update: -4953…-2286 mm (22 points) and 127 mm (1 point): kept as they were (outside the measured -2159…0 mm)"
        ),
        "{stdout}"
    );
    assert!(
        stdout.contains(
            "referred to 0 mm (the existing table's zero), where the update adds nothing"
        ),
        "{stdout}"
    );
    let (laser, table, controller, axis) = CASES[2];
    let (stdout, bytes) = update(
        laser,
        table,
        controller,
        axis,
        &directory.path().join("X.mp"),
    );
    // X.mp: −127 … 3175 mm; the laser 0 … 3302 mm: the new grid adds 3302.
    assert_eq!(mp_rows(&bytes).len(), 28);
    assert!(
        stdout
            .contains("Update: -127 mm (1 point): kept as it was (outside the measured 0…3302 mm)"),
        "{stdout}"
    );
    assert!(
        stdout
            .contains("Update: grid changed: new points at 3302 mm (the old table had none there)"),
        "{stdout}"
    );
    // The printed table shows which rows are kept and which are new.
    let row = |position: &str| {
        stdout
            .lines()
            .find(|l| l.split_whitespace().next() == Some(position))
            .unwrap_or_else(|| panic!("no row {position}: {stdout}"))
            .to_string()
    };
    assert!(row("-127").ends_with("-12.70  kept"), "{}", row("-127"));
    assert!(row("3302").ends_with("  new"), "{}", row("3302"));
    assert!(row("0").ends_with(" 0.00"), "{}", row("0"));
    // The 8055 in inch: the ranges in inch, with mm.
    let (laser, table, controller, axis) = CASES[1];
    let (stdout, _) = update(
        laser,
        table,
        controller,
        axis,
        &directory.path().join("ALY"),
    );
    assert!(
        stdout.contains("Update: -85…0 in (-2159…0 mm) (18 points): the existing table plus the measured residual, referred to 0 in (0 mm) (the existing table's zero)"),
        "{stdout}"
    );
    assert!(!stdout.contains("kept as"), "{stdout}");
}

#[test]
fn a_one_direction_test_says_where_its_curve_went() {
    let directory = tempfile::tempdir().unwrap();
    // The 8055 Y test ran 0 → −85 in only (↓).
    let (laser, table, controller, axis) = CASES[1];
    let (stdout, bytes) = update(
        laser,
        table,
        controller,
        axis,
        &directory.path().join("ALY"),
    );
    assert!(
        stdout.contains("Note: the test ran ↓ only: the table is the ↓ curve, in the positive-direction column (the negative-direction column all zero), which the 8055 then applies in both directions; the reversal (backlash) was not measured, so leave the backlash parameter as it is"),
        "{stdout}"
    );
    // And it is there: every negative error 0.
    let text = String::from_utf8(bytes).unwrap();
    assert!(
        text.lines().all(|l| l.trim_end().ends_with("0.00000")),
        "{text}"
    );
    // The 8065 X test ran ↑ only.
    let (laser, table, controller, axis) = CASES[2];
    let (stdout, _) = update(
        laser,
        table,
        controller,
        axis,
        &directory.path().join("X.mp"),
    );
    assert!(
        stdout.contains("Note: the test ran ↑ only: the table is the ↑ curve, in POSERROR with BIDIR = 0 (NEGERROR all zero), which the 8065 then applies in both directions"),
        "{stdout}"
    );
    // A table with a column per direction is not updated from one direction:
    // ALY with a negative column (every positive error also written there, + 0.001 in).
    let bidirectional: String = std::fs::read_to_string(data(table_of(1)))
        .unwrap()
        .lines()
        .map(|l| format!("{}    0.00100\r\n", &l[..l.len() - 11]))
        .collect();
    let existing = directory.path().join("ALY-bidirectional");
    std::fs::write(&existing, bidirectional).unwrap();
    let out = directory.path().join("ALY2");
    let run = axcomp([
        "convert",
        &data(CASES[1].0),
        "--axis",
        "Y",
        "--existing",
        &existing.display().to_string(),
        "--controller",
        "fagor8055",
        "-o",
        &out.display().to_string(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr
            .contains("the existing table has a column per direction, and this test ran ↓ only"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
}

fn table_of(case: usize) -> &'static str {
    CASES[case].1
}

#[test]
fn the_8065_writes_no_partial_mp_file() {
    let directory = tempfile::tempdir().unwrap();
    let out = directory.path().join("X.mp");
    let run = axcomp([
        "convert",
        &data(CASES[2].0),
        "--controller",
        "fagor8065",
        "-o",
        &out.display().to_string(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("export the axis' .mp from the control (its machine-parameter table) and give it with --existing"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
}

#[test]
fn an_inch_backlash_beside_a_mm_table_is_explained() {
    let directory = tempfile::tempdir().unwrap();
    let out = directory.path().join("X.MPF");
    let run = axcomp([
        "convert",
        "fixtures/sample-x.rtl",
        "--controller",
        "sinumerik840d",
        "--machine",
        "fixtures/machines/gantry-inch.toml",
        "--step",
        "50",
        "-o",
        &out.display().to_string(),
        "-q",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    // The LEC file holds mm (50 mm step, 1.19 µm = 0.001194 mm at 50 mm) …
    let file = std::fs::read_to_string(&out).unwrap();
    assert!(file.contains("$AA_ENC_COMP_STEP[0,AX1]=50.0"), "{file}");
    assert!(file.contains("$AA_ENC_COMP[0,1,AX1]=0.001194"), "{file}");
    // … so the printed table is mm, and the inch backlash says why.
    assert!(
        !run.stdout.contains("The file is in inches"),
        "{}",
        run.stdout
    );
    assert!(
        run.stdout
            .contains("MD32450 $MA_BACKLASH[0,AX1] = 0.000125 inch"),
        "{}",
        run.stdout
    );
    assert!(
        run.stdout.contains(
            "unit: the parameter is in inch (the machine's unit) and the table file in mm"
        ),
        "{}",
        run.stdout
    );
}
