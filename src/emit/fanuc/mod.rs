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
mod table;
mod update;

pub use parameters::{AxisParameters, ParameterBackup, looks_like_parameters};
use pitch::{data_line, increments, parse_pitch};
pub use pitch::{looks_like, read};
use table::{new_increments, wanted};
pub use table::{notes, parameters_for, points_in, write};
pub use update::{check_read_back, update};

use crate::compensate::CompensationTable;
use crate::emit::{BacklashAdvice, EmitOptions};

/// \[file\] Data number of compensation point 0 (`N10000` … in the real `PITCH.TXT`).
pub const DATA_NUMBER_OFFSET: i64 = 10_000;

/// \[reconstructed\] Largest |value| of one point, in units of detection unit ×
/// magnification: no public manual page giving it was found; a signed byte
/// (−128 … 127) is assumed, the range of the other controllers' incremental
/// tables of this kind (Mitsubishi E68 manual p. II-292: "Range: –128 to 127").
pub const POINT_LIMIT: i64 = 127;

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
    let (unit, known) = match options.axes.first().and_then(|a| a.fanuc.as_ref()) {
        Some(p) => (p.detection_unit, true),
        None => (0.001, false),
    };
    let value = (backlash_mm / unit).round() as i64;
    let unit_text = crate::emit::minimal(unit, 7);
    let assumed = if known {
        String::new()
    } else {
        " (assumed: IS-B with 1820 = 2; give --fanuc-parameters for the machine's)".to_string()
    };
    BacklashAdvice::NoParameter(format!(
        "set 1851 of axis {axis} (backlash, cutting feed) to {value} detection units of {unit_text} mm{assumed}, = {} mm; positive compensates lost motion (the value is output in the direction of movement after a reversal); for rapid traverse set 1852 to the reversal measured at rapid traverse and 1800#4 (RBK) = 1",
        crate::emit::minimal(value as f64 * unit, 7)
    ))
}

/// What to do after loading the file.
pub fn activation(file_name: &str, table: &CompensationTable, options: &EmitOptions) -> String {
    let settings = parameters_for(table, options).map_or_else(
        |e| e.to_string(),
        |p| {
            let what = if p.from_backup {
                "as in the parameter backup"
            } else {
                "axcomp's numbering; detection unit assumed 0.001 mm (0.001° on a rotary axis): check 1013 and 1820"
            };
            format!("{} ({what})", p.settings())
        },
    );
    format!(
        "load {file_name} as pitch error compensation data (punch format); parameters {settings}; then turn the power off and on and return the axis to the reference position"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::TableValues;
    use crate::measurement::AxisKind;

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
        assert_eq!(table.positions_mm[0], -400.0);
        assert_eq!(table.positions_mm.len(), 18);
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
            reference_mm: positions_mm[0],
            positions_mm,
            values: TableValues::Mean(values),
            suggested_backlash_mm: None,
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
        assert_eq!(back.positions_mm.len(), 6);
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
