//! Fanuc pitch error compensation data (`PITCH.TXT`, punch format): read,
//! written, and updated in place, with the parameters of the axis read from
//! the machine's parameter backup (`CNC-PARA.TXT`).
//!
//! Spec and sources: `formats/fanuc/README.md` (\[manual\] the 0i-PB and 30i
//! parameter manuals, Fanuc technical report A-77810E; \[file\] a real backup
//! of one machine in `../shared/data/fanuc/`). The pitch file is
//!
//! ```text
//! %
//! N10000Q0P0
//! N10001Q0P-1␠
//! …
//! %
//! ```
//!
//! one data number (10000 + compensation point) a line, its value an integer
//! in detection units × magnification (3623). The values are incremental: the
//! value of point n is the compensation output while the axis travels from
//! point n − 1 to point n, point n lying at 1240 + (n − 3620) × 3624, and the
//! absolute compensation is zero at the reference point 3620. The file holds
//! the points of every axis; an axis uses 3621 … 3622.
//!
//! The absolute compensation is the correction the control adds, so the
//! error it compensates (axcomp's table value) is its negative.

mod parameters;
mod pitch;
mod rescale;
mod table;
mod update;

pub use parameters::{AxisParameters, ParameterBackup, looks_like_parameters};
use pitch::{absolute_units, data_line, increments, parse_pitch};
pub use pitch::{looks_like, read};
pub use rescale::{Rescaled, rescaled};
pub use table::{BitsUse, notes, parameters_for, points_in, unknown_bits_note, write};
use table::{check_turn, finest_for_sections, new_increments, wanted};
use update::replace_lines;
pub use update::{check_read_back, update, update_summary};

use crate::compensate::CompensationTable;
use crate::emit::{BacklashAdvice, Controller, EmitOptions};
use crate::error::Warning;
use crate::measurement::AxisKind;

/// \[file\] Data number of compensation point 0 (`N10000` … in the real `PITCH.TXT`).
pub const DATA_NUMBER_OFFSET: i64 = 10_000;

/// \[file\] The values one point holds, in units of detection unit ×
/// magnification: one signed byte, −128 … 127 (Fanuc's FOCAS library header
/// `fwlib32.h`, `IODBPI`: the incremental pitch data of `cnc_rdpitchr` /
/// `cnc_wrpitchr` are `char data[]`); no manual page stating it was found.
pub const POINT_RANGE: std::ops::RangeInclusive<i64> = -128..=127;

/// The smallest magnification (≥ 1) at which a point holds `units` counted
/// at magnification 1 (detection units, signed): |units| / 128 for a
/// negative value, / 127 for a positive one, rounded up.
fn magnification_for(units: f64) -> i64 {
    let limit = if units < 0.0 {
        -*POINT_RANGE.start()
    } else {
        *POINT_RANGE.end()
    };
    ((units.abs() / limit as f64).ceil() as i64).max(1)
}

/// \[manual, secondary\] The number of points between the extremes an axis
/// may use (cnc.wiki "Setup Guide for Fanuc Pitch Error Compensation
/// Parameters": "maximum of 128 compensation points between extremes").
pub const MAX_POINTS: usize = 128;

/// The largest point a data number can name (N99999).
const MAX_POINT: i64 = 99_999 - DATA_NUMBER_OFFSET;

/// \[reconstructed\] The largest |value| a data line is read with: 8 digits,
/// as the parameters' (no file holds more; the sums then never overflow).
const READ_LIMIT: i64 = 99_999_999;

/// \[manual\] 0i-C B-64120EN/01 p.116: 1851 (cutting feed) and 1852 (rapid
/// traverse, with 1800#4 RBK = 1) in detection units, −9999 … 9999; "the
/// positive or negative direction for compensating values is the direction
/// of movement".
pub fn backlash_parameter(backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
    let axis = options.axes.first().map_or("X", |a| a.axis.as_str());
    let backup = options.axes.first().and_then(|a| a.fanuc.as_ref());
    let rotary = options.kind == AxisKind::Rotary || backup.is_some_and(|p| p.rotary);
    let length = if rotary { "°" } else { " mm" };
    let unit = backup.map_or(0.001, |p| p.detection_unit);
    let value = (backlash_mm / unit).round() as i64;
    let unit_text = crate::emit::minimal(unit, 7);
    let sign = "positive compensates lost motion, negative an axis that overshoots at a reversal (the value is output in the direction of movement after a reversal)";
    let rapid = "for rapid traverse set 1852 to the reversal measured at rapid traverse and 1800#4 (RBK) = 1";
    let Some(p) = backup else {
        return BacklashAdvice::NoParameter(format!(
            "set 1851 of axis {axis} (backlash, cutting feed) to {value} detection units of {unit_text}{length} (assumed: IS-B with 1820 = 2; give --fanuc-parameters for the machine's), = {}{length}; {sign}; {rapid}",
            crate::emit::minimal(value as f64 * unit, 7)
        ));
    };
    // [reconstructed] The backup's 1851 was active during the test, which
    // measured the reversal it left: the new value is the old one plus it.
    let (old, _) = p.backlash;
    let new = old + value;
    BacklashAdvice::NoParameter(format!(
        "set 1851 of axis {axis} (backlash, cutting feed) to {value} detection units of {unit_text}{length} more than the {old} of the parameter backup, active during the test: 1851 = {new} (= {}{length}); {sign}; {rapid} (the backup has 1852 = {})",
        crate::emit::minimal(new as f64 * unit, 7),
        p.backlash.1
    ))
}

/// What a table read as `controller`'s for `options`' axis rests on, when
/// it is Fanuc pitch data under a 3605 with bits axcomp does not know
/// ([`unknown_bits_note`]): said wherever the control's table is computed
/// with (`predict --table`, `diagnose --table`, `report --table`).
pub fn read_note(controller: Controller, options: &EmitOptions) -> Option<Warning> {
    let p = options.axes.first()?.fanuc.as_ref()?;
    (controller == Controller::Fanuc)
        .then(|| unknown_bits_note(p, BitsUse::Read))
        .flatten()
        .map(|note| Warning::TableReadAs { note })
}

/// What to do after loading the file.
pub fn activation(file_name: &str, table: &CompensationTable, options: &EmitOptions) -> String {
    let settings = parameters_for(table, options).map_or_else(
        |e| e.to_string(),
        |p| {
            let old_3627 = options
                .axes
                .first()
                .and_then(|a| a.fanuc.as_ref())
                .map(|old| old.reference_negative);
            let what = match old_3627 {
                Some(old) if p.bidirectional && old != p.reference_negative => format!(
                    "as in the parameter backup, except 3627: set it to {} (the backup has {old})",
                    p.reference_negative
                ),
                Some(_) => "as in the parameter backup".to_string(),
                None => "axcomp's numbering; detection unit assumed 0.001 mm (0.001° on a rotary axis): check 1013 and 1820".to_string(),
            };
            let backlash = if p.bidirectional {
                "; the tables hold the reversal left with the backlash parameters 1851/1852 active: leave them as they were during the test"
            } else {
                ""
            };
            format!(
                "{} ({what}); its values are increments per section in units of {} (detection unit {} × 3623 = {}){backlash}",
                p.settings(),
                p.unit_text(p.unit()),
                p.unit_text(p.detection_unit),
                p.magnification
            )
        },
    );
    format!(
        "load {file_name} as pitch error compensation data (punch format); parameters {settings}; then turn the power off and on and return the axis to the reference position"
    )
}

#[cfg(test)]
mod tests {
    use proptest::prelude::Just;

    use super::*;
    use crate::compensate::TableValues;

    /// The 0i-PB manual's linear example (B-63980EN/01 p.100): points 33 … 49
    /// around reference 40 (at 0 mm), 50 mm apart.
    fn manual_parameters() -> AxisParameters {
        AxisParameters {
            most_negative: 33,
            most_positive: 49,
            reference_point: 40,
            interval: 50.0,
            ..AxisParameters::default_for("X", 1, 50.0, 40, 0.0)
        }
    }

    #[test]
    fn the_manual_example_reads_to_its_absolute_curve() {
        let values = [2, 1, 1, -2, 0, -1, 0, -1, 2, 1, 0, -1, -1, -2, 0, 1, 2];
        let mut text = String::from("%\n");
        for (k, v) in values.iter().enumerate() {
            text.push_str(&data_line(33 + k as i64, *v));
            text.push('\n');
        }
        text.push('%');
        let table = read(&text, &manual_parameters()).unwrap();
        // Point 32 at −400 mm … point 49 at 450 mm.
        assert_eq!(table.positions[0], -400.0);
        assert_eq!(table.positions.len(), 18);
        // By hand: absolute at 0 = 0; at −50: −v40 = +1; at −100: 1 − v39 = 1;
        // at 50: v41 = 2; at 100: 3. The table holds −absolute × 1 µm.
        let at = |x: f64| table.value_at(x, crate::measurement::Direction::Up) * 1000.0;
        assert!((at(0.0)).abs() < 1e-9);
        assert!((at(-50.0) + 1.0).abs() < 1e-9);
        assert!((at(-100.0) + 1.0).abs() < 1e-9);
        assert!((at(50.0) + 2.0).abs() < 1e-9);
        assert!((at(100.0) + 3.0).abs() < 1e-9);
        // Written back from the table: the same increments at 33 … 49.
        let mut options = crate::emit::EmitOptions::for_axis(&Default::default(), "X", "").unwrap();
        options.axes[0].fanuc = Some(manual_parameters());
        let written = write(&table, &options).unwrap();
        assert_eq!(written, text.replacen("%\n", "%\nN10032Q0P0\n", 1));
    }

    fn table(positions_mm: Vec<f64>, values: Vec<f64>) -> CompensationTable {
        CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            reference: positions_mm[0],
            positions: positions_mm,
            values: TableValues::Mean(values),
            suggested_backlash: None,
        }
    }

    fn options_with(p: AxisParameters) -> EmitOptions {
        let mut options = EmitOptions::for_axis(&Default::default(), "X", "").unwrap();
        options.axes[0].fanuc = Some(p);
        options
    }

    #[test]
    fn the_worked_example() {
        // formats/fanuc/README.md: 2.3 µm long at 100 mm, 1 µm units: the
        // correction −2.3 µm rounds to −2 units at the point at 100 mm.
        let t = table(vec![0.0, 100.0], vec![0.0, 0.0023]);
        let p = AxisParameters::default_for("X", 2, 100.0, 0, 0.0);
        assert_eq!(
            write(&t, &options_with(p)).unwrap(),
            "%\nN10000Q0P0\nN10001Q0P-2 \n%"
        );
    }

    #[test]
    fn a_point_beyond_its_limit_names_the_magnification_that_holds_it() {
        // −0.2 mm over one section in 1 µm units: 200 > 127, 3623 = 2 holds it.
        let t = table(vec![0.0, 100.0], vec![0.0, -0.2]);
        let p = AxisParameters::default_for("X", 2, 100.0, 0, 0.0);
        let error = write(&t, &options_with(p)).unwrap_err().to_string();
        assert!(error.contains("needs 200"), "{error}");
        assert!(error.contains("set 3623 = 2"), "{error}");
    }

    #[test]
    fn a_point_holds_one_signed_byte() {
        // FOCAS fwlib32.h: a point's increment is a `char`, −128 … 127. In
        // 1 µm units an error rising 0.128 mm over a section is a
        // compensation of −128 units: held. Falling 0.128 mm is +128: one
        // beyond, and 3623 = 2 holds it (128 / 2 = 64 units).
        let p = AxisParameters::default_for("X", 2, 100.0, 0, 0.0);
        let t = table(vec![0.0, 100.0], vec![0.0, 0.128]);
        assert_eq!(
            write(&t, &options_with(p.clone())).unwrap(),
            "%\nN10000Q0P0\nN10001Q0P-128 \n%"
        );
        let t = table(vec![0.0, 100.0], vec![0.0, -0.128]);
        let error = write(&t, &options_with(p)).unwrap_err().to_string();
        assert!(error.contains("needs 128"), "{error}");
        assert!(error.contains("beyond the -128 … 127 units"), "{error}");
        assert!(error.contains("set 3623 = 2"), "{error}");
    }

    #[test]
    fn a_coarse_magnification_is_said_with_the_finer_one() {
        // Units of 0.001 mm × 10 = 0.01 mm for an error of 0.02 mm peak to
        // valley; 3623 = 1 holds its 0.01 mm sections (10 units).
        let t = table(vec![0.0, 100.0, 200.0], vec![0.0, 0.01, 0.02]);
        let p = AxisParameters {
            magnification: 10,
            ..AxisParameters::default_for("X", 3, 100.0, 0, 0.0)
        };
        let notes = notes(&t, &options_with(p.clone()));
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("3623 = 1 would give 0.001 mm steps"),
            "{notes:?}"
        );
        let fine = AxisParameters {
            magnification: 1,
            ..p
        };
        assert!(super::notes(&t, &options_with(fine)).is_empty());
    }

    #[test]
    fn a_rotary_reference_point_holds_the_last_points_value() {
        // 0i-PB p.100: reference 1 = most negative 1, 90° apart, 3622 = 1 + 360/90.
        let p = AxisParameters {
            most_negative: 1,
            most_positive: 5,
            rotary: true,
            ..AxisParameters::default_for("B", 5, 90.0, 1, 0.0)
        };
        // Errors in whole units of 0.001° (detection unit assumed, 3623 = 1).
        let t = table(
            vec![0.0, 90.0, 180.0, 270.0, 360.0],
            vec![0.0, 0.002, 0.001, -0.003, 0.0],
        );
        let text = write(&t, &options_with(p.clone())).unwrap();
        let values = increments_of(&text);
        // Absolute corrections 0, −2, −1, 3, 0: increments −2, 1, 4, −3; the
        // reference point 1 takes point 5's −3; they sum to 0 over the turn.
        assert_eq!(
            values,
            vec![(0, 0), (1, -3), (2, -2), (3, 1), (4, 4), (5, -3)]
        );
        let back = read(&text, &p).unwrap();
        assert_eq!(back.positions.len(), 6);
        // A turn that does not close (0.002° at 360°) is closed, and said.
        let open = table(
            vec![0.0, 90.0, 180.0, 270.0, 360.0],
            vec![0.0, 0.002, 0.001, -0.003, 0.002],
        );
        let mut options = options_with(p);
        options.kind = AxisKind::Rotary;
        let text = write(&open, &options).unwrap();
        // Points 2 … 5, one turn, sum to zero.
        let turn: i64 = increments_of(&text)[2..].iter().map(|(_, v)| v).sum();
        assert_eq!(turn, 0);
        check_read_back(&text, &open, &options).unwrap();
        let notes = notes(&open, &options);
        assert!(
            notes[0].contains("0.002° between the start and the end"),
            "{notes:?}"
        );
    }

    #[test]
    fn a_bidirectional_table_goes_to_3626_with_3627_at_the_reference() {
        // Without a backup: points 0 … 2 (3621 = 1, 3622 = 2), 1 µm units,
        // the ↓ table right after, 3626 = 3. Up is −0.001 mm at the
        // reference (the table's zero is the mean of both directions there):
        // by hand, from it, ↑ 0, 2, 3 µm and ↓ 2, 4, 10 µm; the absolute
        // compensation is their negative: ↑ 0, −2, −3 (increments −2, −1),
        // ↓ −2, −4, −10 (3627 = −2; increments −2, −6).
        let t = CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![0.0, 100.0, 200.0],
            values: TableValues::Bidirectional {
                up: vec![-0.001, 0.001, 0.002],
                down: vec![0.001, 0.003, 0.009],
            },
            reference: 0.0,
            suggested_backlash: None,
        };
        let options = EmitOptions::for_axis(&Default::default(), "X", "").unwrap();
        let text = write(&t, &options).unwrap();
        assert_eq!(
            text,
            "%\nN10000Q0P0\nN10001Q0P-2 \nN10002Q0P-1 \nN10003Q0P-2 \nN10004Q0P-6 \n%"
        );
        let p = parameters_for(&t, &options).unwrap();
        assert!(
            p.settings().ends_with("3605#0 = 1, 3626 = 3, 3627 = -2"),
            "{}",
            p.settings()
        );
        check_read_back(&text, &t, &options).unwrap();
        let back = read(&text, &p).unwrap();
        let at = |x: f64, d| back.value_at(x, d) * 1000.0;
        assert!((at(200.0, crate::measurement::Direction::Up) - 3.0).abs() < 1e-9);
        assert!((at(0.0, crate::measurement::Direction::Down) - 2.0).abs() < 1e-9);
        assert!((at(200.0, crate::measurement::Direction::Down) - 10.0).abs() < 1e-9);
        // A backup without 3605#0 refuses it, saying what to set.
        let mut options = options;
        options.axes[0].fanuc = Some(AxisParameters::default_for("X", 3, 100.0, 0, 0.0));
        let error = write(&t, &options).unwrap_err().to_string();
        assert!(error.contains("set 3605#0 = 1 and 3626"), "{error}");
    }

    /// What `fuzz/fuzz_targets/read_fanuc.rs` asks of any input, on
    /// backups and pitch files built from arbitrary numbers (cargo-fuzz
    /// mutates bytes; this reaches the arithmetic on parsed values): no
    /// panic; a pitch file that reads takes its own table back with
    /// `update`, and `rescaled` of it does not panic.
    fn fuzz_body(backup: &str, pitch: &str) {
        if let Ok(backup) = ParameterBackup::parse(backup, "fuzz") {
            for (_, name) in backup.axis_names() {
                if let Ok(p) = backup.axis(&name) {
                    round_trip(pitch, &p);
                }
            }
        }
    }

    fn round_trip(pitch: &str, p: &AxisParameters) {
        let Ok(table) = read(pitch, p) else { return };
        let mut options = EmitOptions::for_axis(&Default::default(), "X", "").unwrap();
        options.axes[0].fanuc = Some(p.clone());
        if let Ok(updated) = update(pitch, &table, &options) {
            let back = read(&updated, p).expect("an updated file reads back");
            assert_eq!(back.positions, table.positions);
        }
        let _ = rescaled(Some(pitch), &table, &options, None);
    }

    fn parameter_line(number: u32, value: &str) -> String {
        format!("N{number:05}Q1A1P{value}\n")
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]
        #[test]
        fn the_fuzz_body_holds_on_arbitrary_numbers(
            points in proptest::collection::vec(-3i64..1600, 6),
            magnification in proptest::prop_oneof![Just(10i64), -2i64..200, proptest::num::i64::ANY],
            interval in proptest::prop_oneof![Just("40.0".to_string()), "-?[0-9]{1,3}(\\.[0-9]{1,3})?", "[0-9]{20,40}"],
            cmr in 0i64..130,
            bits in "[01]{8}",
            extreme in proptest::prop_oneof![Just(i64::MIN), Just(i64::MAX), -5i64..5],
            values in proptest::collection::vec(proptest::prop_oneof![-200i64..200, Just(99_999_999i64), Just(i64::MIN)], 0..140),
        ) {
            let mut backup = String::from("%\n");
            backup.push_str(&parameter_line(1020, "88"));
            backup.push_str(&parameter_line(1820, &cmr.to_string()));
            backup.push_str(&parameter_line(1013, "00000000"));
            backup.push_str("N01001Q1L1P00000000\n");
            backup.push_str(&parameter_line(1006, &bits));
            backup.push_str(&parameter_line(3605, &bits));
            for (k, number) in [3620u32, 3621, 3622, 3626, 3627].iter().enumerate() {
                let value = if k == 4 { extreme } else { points[k] };
                backup.push_str(&parameter_line(*number, &value.to_string()));
            }
            backup.push_str(&parameter_line(3623, &magnification.to_string()));
            backup.push_str(&parameter_line(3624, &interval));
            backup.push_str(&parameter_line(3625, &points[5].to_string()));
            backup.push_str(&parameter_line(1240, "0.0"));
            backup.push_str(&parameter_line(1851, &extreme.to_string()));
            backup.push_str(&parameter_line(1852, "0"));
            backup.push('%');
            let mut pitch = String::from("%\n");
            for (n, v) in values.iter().enumerate() {
                pitch.push_str(&data_line(n as i64, *v));
                pitch.push('\n');
            }
            pitch.push('%');
            fuzz_body(&backup, &pitch);
            // And the bounds the reader has for any number in a parameter.
            let extreme_backup = backup.replace(&parameter_line(3621, &points[1].to_string()), &parameter_line(3621, &extreme.to_string()));
            fuzz_body(&extreme_backup, &pitch);
        }
    }

    #[test]
    fn the_smallest_integer_is_refused_not_negated() {
        // Found running the fuzz target's body: |i64::MIN| overflowed.
        let error = parse_pitch("%\nN10000Q0P-9223372036854775808\n%").unwrap_err();
        assert_eq!((error.position.line, error.position.column), (2, 10));
        let backup = "%\nN01020Q1A1P88\nN03621Q1A1P-9223372036854775808\n%";
        let backup = ParameterBackup::parse(backup, "P").unwrap();
        let error = backup.integer(3621, Some(('A', 1))).unwrap_err();
        assert!(
            error.contains("P:3:12: parameter 3621: expected an integer of at most 8 digits"),
            "{error}"
        );
    }

    fn increments_of(text: &str) -> Vec<(i64, i64)> {
        let (data, _) = parse_pitch(text).unwrap();
        data.iter().map(|(n, d)| (*n, d.value)).collect()
    }

    #[test]
    fn odd_lines_get_a_space_as_in_the_real_file() {
        assert_eq!(data_line(0, 0), "N10000Q0P0");
        assert_eq!(data_line(1, -1), "N10001Q0P-1 ");
        assert_eq!(data_line(310, 10), "N10310Q0P10 ");
        assert_eq!(data_line(311, -10), "N10311Q0P-10");
    }

    #[test]
    fn bad_lines_are_refused_at_their_column() {
        let error = parse_pitch("%\nN10000Q0P0\nN10001Q0Px\n%").unwrap_err();
        assert_eq!((error.position.line, error.position.column), (3, 10));
        let error = ParameterBackup::parse("%\nN01020Q1A1P88A2\n%", "P").unwrap_err();
        assert_eq!((error.position.line, error.position.column), (2, 16));
        assert!(looks_like("%\nN10000Q0P0\n%"));
        assert!(!looks_like("%_N_X_MPF\n"));
    }
}
