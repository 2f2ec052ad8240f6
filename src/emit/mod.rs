//! Controller compensation files: one module per format, each writes AND reads it.
//!
//! `write` turns a [`CompensationTable`] (axcomp's convention: axis error
//! actual − target, mm, zero at the reference) into the bytes the controller
//! loads; `read` turns such a file back into a table, to the format's
//! resolution. The formats, their sources and what is reconstructed are in
//! `formats/<controller>/README.md` next to their golden files.
//!
//! This module holds what they share: the [`Controller`] enum, the options
//! every writer takes ([`EmitOptions`]), the refusal rules that stop a table
//! the controller would reject ([`check_table`]), the number formats, and
//! format detection for reading an existing table ([`read_any`]).
//!
//! A rotary axis' table ([`EmitOptions::kind`]) holds degrees, written as
//! they are (no length unit applies): Heidenhain `.COM` with AXISPOS and
//! values in °, Sinumerik LEC with `$AA_ENC_COMP_IS_MODULO = 1` over a full
//! turn from 0° to 360° (equal values at both ends, refused otherwise),
//! LinuxCNC over the table's range with the ends held. The Fagor files show
//! no rotary form, so a rotary table is refused for them.

mod controller;
mod detect;
mod fagor;
pub mod fagor8055;
pub mod fagor8065;
pub mod fanuc;
mod heidenhain;
pub mod itnc530;
pub mod linuxcnc;
pub mod linuxcnc_thermal;
mod number;
mod one_machine;
pub mod profile;
mod refusal;
pub mod sinumerik840d;
pub mod tnc640;
mod written;

use crate::compensate::cross_axis::CrossAxisTable;
use crate::compensate::{CompensationTable, TableValues};
use crate::evaluate::conformance::FULL_TURN_DEG;
use crate::measurement::{AxisKind, Direction};
use crate::units::LengthUnit;
pub use controller::{BacklashAdvice, BacklashParameter, Controller, resolution_mm};
pub use detect::{detect, read_any};
pub use fagor::{TextEncoding, decode as decode_table, encode as encode_table};
pub use number::{minimal, signed_fixed, signed_minimal};
pub use one_machine::{MachineTable, overwrites};
pub use profile::{AxisPeriods, AxisProfile, CecValues, MachineProfile};
pub use refusal::{EmitError, check_table};
pub use written::{Written, check_request, fanuc_rescaled, grid, write_updated};

/// What every writer needs besides the table. Filled by the caller from the
/// command line and the machine profile; no `Default`.
#[derive(Clone, Debug, PartialEq)]
pub struct EmitOptions {
    /// The axes that get the table: the compensated axis first, then coupled
    /// axes (a gantry slave) that get the same values.
    pub axes: Vec<AxisProfile>,
    /// Table name written inside the file where the format has one (Heidenhain `BEGIN …`).
    pub table_name: String,
    /// Length unit of the machine (LinuxCNC writes machine units).
    pub machine_unit: LengthUnit,
    /// LinuxCNC `COMP_FILE_TYPE`: 0 (actual positions) or 1 (offsets).
    pub linuxcnc_type: u8,
    /// Largest number of points the machine takes (Sinumerik MD38000/MD18342, or a profile limit).
    pub max_points: Option<usize>,
    /// Largest |value| the machine builder allows, mm.
    pub max_value_mm: Option<f64>,
    /// Where the table comes from, written as a comment where the format
    /// has comments ([`Provenance`]); `None` writes none.
    pub provenance: Option<Provenance>,
    /// Sinumerik CEC sign: `true` writes the correction (−error), the
    /// reconstructed convention; `false` writes the error.
    pub cec_values_are_corrections: bool,
    /// TNC 640: the machine's axis columns (CfgAxes/axisList); empty for just
    /// the written axes.
    pub tnc640_columns: Vec<String>,
    /// Linear (positions and values mm) or rotary (degrees).
    pub kind: AxisKind,
}

impl EmitOptions {
    /// The options a machine profile gives for one axis's table: its names
    /// and units, the profile's limits and CEC convention, LinuxCNC type 0,
    /// no coupled axes. Callers change what their flags say (convert).
    pub fn for_axis(
        profile: &MachineProfile,
        axis: &str,
        table_name: &str,
    ) -> Result<EmitOptions, EmitError> {
        Ok(EmitOptions {
            axes: vec![profile.axis(axis)?],
            table_name: table_name.to_string(),
            machine_unit: profile.machine_unit(),
            linuxcnc_type: 0,
            max_points: profile.controller.max_points,
            max_value_mm: profile.controller.max_value_mm,
            provenance: None,
            cec_values_are_corrections: profile.controller.cec_values != Some(CecValues::Error),
            tnc640_columns: profile
                .controller
                .tnc640_columns
                .clone()
                .unwrap_or_default(),
            kind: AxisKind::Linear,
        })
    }

    /// The unit of the numbers in a file that converts them (LinuxCNC): the
    /// machine's length unit, or for a rotary axis degrees as they are,
    /// which is `Millimetre`'s identity conversion of the inner value.
    pub fn file_unit(&self) -> LengthUnit {
        match self.kind {
            AxisKind::Linear => self.machine_unit,
            AxisKind::Rotary => LengthUnit::Millimetre,
        }
    }

    /// Whether the table is a rotary axis' full turn from 0° to 360°, which
    /// a Sinumerik writes as a modulo table.
    pub fn is_full_turn(&self, table: &CompensationTable) -> bool {
        let (Some(first), Some(last)) = (table.positions.first(), table.positions.last()) else {
            return false;
        };
        self.kind == AxisKind::Rotary && (last - first - FULL_TURN_DEG).abs() < 1e-9
    }
}

/// What a table records of its source, where its format has comments
/// (Sinumerik `;`): the measurement file, the date the file records (never
/// the clock, so the same input gives the same bytes) and the axcomp version.
#[derive(Clone, Debug, PartialEq)]
pub struct Provenance {
    /// The measurement file(s) the table was made from, by file name.
    pub source: String,
    /// The test's date as the file records it; `None` when it records none.
    pub recorded: Option<String>,
}

impl Provenance {
    /// The provenance of a table made from `measurement`: its file's name
    /// and the date it records.
    pub fn of(measurement: &crate::measurement::Measurement) -> Provenance {
        let metadata = &measurement.metadata;
        Provenance {
            source: metadata
                .source_file
                .as_ref()
                .and_then(|path| path.file_name())
                .map_or_else(
                    || "a measurement without a file name".to_string(),
                    |name| name.to_string_lossy().into_owned(),
                ),
            recorded: metadata.date.as_ref().map(|date| date.raw.clone()),
        }
    }

    /// The lines to write, without the comment sign: `made by axcomp
    /// 0.1.0 from X.rtl (measured 2024-03-05 10:12)`.
    pub fn text(&self) -> String {
        let date = match &self.recorded {
            Some(date) => format!("measured {date}"),
            None => "its date not recorded".to_string(),
        };
        format!(
            "made by axcomp {} from {} ({date})",
            env!("CARGO_PKG_VERSION"),
            self.source
        )
    }
}

/// Writes a table in a controller's format: checks it first ([`check_table`]),
/// then reads the text back with the same module and compares it with the
/// table to the format's resolution, so a file that would not round-trip is
/// never handed out.
pub fn write(
    controller: Controller,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<String, EmitError> {
    check_table(controller, table, options)?;
    let text = match controller {
        Controller::Itnc530 => itnc530::write(table, options),
        Controller::Tnc640 => tnc640::write(table, options),
        Controller::Sinumerik840d => sinumerik840d::write(table, options),
        Controller::LinuxCnc => linuxcnc::write(table, options),
        Controller::Fagor8055 => fagor8055::write(table, options),
        Controller::Fagor8065 => fagor8065::write(table, options),
        Controller::Fanuc => fanuc::write(table, options),
    }?;
    check_read_back(controller, table, &text, options)?;
    Ok(text)
}

/// The bytes of the file to hand out: [`write`]'s text, except that a TNC
/// 640 table keeps the other filled columns of `existing` (the axis's one
/// active `.COM`, [`tnc640::update`]) and a Fagor 8065 table goes into `existing` (the `.mp` file that was active, when it
/// holds a leadscrew table) with every other line, the encoding, the
/// byte-order mark and the line ends kept, or into a new UTF-16LE file.
/// The result is read back like [`write`]'s.
pub fn write_bytes(
    controller: Controller,
    table: &CompensationTable,
    options: &EmitOptions,
    existing: Option<&[u8]>,
) -> Result<Vec<u8>, EmitError> {
    if controller == Controller::Tnc640
        && let Some(old) = existing.and_then(|bytes| std::str::from_utf8(bytes).ok())
    {
        // One active table per axis: the axis's other columns stay.
        check_table(controller, table, options)?;
        let text = tnc640::update(old, table, options)?;
        check_read_back(controller, table, &text, options)?;
        return Ok(text.into_bytes());
    }
    if controller == Controller::Fanuc {
        // A pitch file that was active gets the new points in place.
        let old = existing.and_then(|bytes| decode_table(bytes).ok());
        if let Some((old_text, encoding)) = old.filter(|(text, _)| fanuc::looks_like(text)) {
            check_table(controller, table, options)?;
            let text = fanuc::update(&old_text, table, options)?;
            fanuc::check_read_back(&text, table, options)?;
            return Ok(encode_table(&text, encoding));
        }
    }
    if controller != Controller::Fagor8065 {
        return Ok(write(controller, table, options)?.into_bytes());
    }
    let decoded = existing.and_then(|bytes| decode_table(bytes).ok());
    let Some((old_text, encoding)) = decoded.filter(|(text, _)| fagor8065::looks_like(text)) else {
        let text = write(controller, table, options)?;
        return Ok(encode_table(&text, TextEncoding::Utf16Le));
    };
    check_table(controller, table, options)?;
    let text = fagor8065::update(&old_text, table)?;
    check_read_back(controller, table, &text, options)?;
    Ok(encode_table(&text, encoding))
}

/// Reads `text` back as [`read_any`] does and compares it with `table` to the
/// format's resolution: a file that would not round-trip is never handed out.
fn check_read_back(
    controller: Controller,
    table: &CompensationTable,
    text: &str,
    options: &EmitOptions,
) -> Result<(), EmitError> {
    if controller == Controller::Fanuc {
        return fanuc::check_read_back(text, table, options);
    }
    let (_, back) = read_any(text, options, Some(options.linuxcnc_type)).map_err(|error| {
        EmitError::Internal(format!(
            "the written {} table does not read back: {error}",
            controller.name()
        ))
    })?;
    let tolerance_mm = resolution_mm(controller, options.file_unit()) / 2.0 + 1e-12;
    let same_points = back.positions.len() == table.positions.len()
        && back
            .positions
            .iter()
            .zip(&table.positions)
            .all(|(a, b)| (a - b).abs() <= tolerance_mm);
    let same_values = crate::measurement::Direction::BOTH.iter().all(|d| {
        back.values
            .for_direction(*d)
            .iter()
            .zip(table.values.for_direction(*d))
            .all(|(a, b)| (a - b).abs() <= tolerance_mm)
    });
    if !(same_points && same_values) {
        return Err(EmitError::Internal(format!(
            "the written {} table reads back different values",
            controller.name()
        )));
    }
    Ok(())
}

/// How to activate a written table on its controller, in one or a few lines.
pub fn activation(
    controller: Controller,
    table: &CompensationTable,
    file_name: &str,
    options: &EmitOptions,
) -> String {
    match controller {
        Controller::Itnc530 => itnc530::activation(file_name, options),
        Controller::Tnc640 => tnc640::activation(file_name, options),
        Controller::Sinumerik840d => sinumerik840d::activation(table, file_name, options),
        Controller::LinuxCnc => linuxcnc::activation(file_name, options),
        Controller::Fagor8055 => fagor8055::activation(file_name, options),
        Controller::Fagor8065 => fagor8065::activation(file_name, options),
        Controller::Fanuc => fanuc::activation(file_name, table, options),
    }
}

/// Writes a cross-axis table "`options.axes[0]` = F(`cross.table_axis`)"
/// for `controller`, checked as every table is ([`check_table`]: the
/// profile's point limit, spacing, value limits). TNC 640: the `.COM` of
/// the table axis, holding the table axis's own column too (one active
/// table per axis), `existing` its current `.COM` whose other columns are
/// kept. Sinumerik: a CEC table numbered from the profile
/// ([`MachineProfile::cec_table`]).
pub fn write_cross_axis(
    controller: Controller,
    cross: &CrossAxisTable,
    profile: &MachineProfile,
    options: &EmitOptions,
    existing: Option<&str>,
) -> Result<String, EmitError> {
    check_table(controller, &cross.table, options)?;
    let input = profile.axis(&cross.table_axis)?;
    let output = options.axes.first().ok_or_else(|| {
        EmitError::Profile("a cross-axis table needs the axis it moves".to_string())
    })?;
    match controller {
        Controller::Tnc640 => {
            tnc640::write_cross_axis(cross, &input.tnc640_column, options, existing)
        }
        Controller::Sinumerik840d => {
            let t = profile.cec_table(&cross.table_axis, &output.axis)?;
            sinumerik840d::write_cross_axis(cross, &input.sinumerik_axis, t, options)
        }
        _ => Err(EmitError::Profile(format!(
            "axcomp writes cross-axis tables for tnc640 and sinumerik840d, not {}",
            controller.name()
        ))),
    }
}

/// How to activate a cross-axis table written by [`write_cross_axis`]
/// (`existing`: into the table axis's existing table).
pub fn cross_axis_activation(
    controller: Controller,
    cross: &CrossAxisTable,
    profile: &MachineProfile,
    (file_name, existing): (&str, bool),
    options: &EmitOptions,
) -> Result<String, EmitError> {
    let input = profile.axis(&cross.table_axis)?;
    let output = options.axes.first().ok_or_else(|| {
        EmitError::Profile("a cross-axis table needs the axis it moves".to_string())
    })?;
    Ok(match controller {
        Controller::Sinumerik840d => {
            let t = profile.cec_table(&cross.table_axis, &output.axis)?;
            sinumerik840d::cross_axis_activation(
                cross,
                (&input.sinumerik_axis, &output.sinumerik_axis),
                t,
                file_name,
                options,
            )
        }
        _ => tnc640::cross_axis_activation(
            file_name,
            (&input.tnc640_column, &output.tnc640_column),
            existing,
        ),
    })
}

/// What a cross-axis file's values are, for a reader of the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrossAxisValues {
    /// The value in the file, times the table's error: −1 where a Sinumerik
    /// CEC holds corrections, else +1.
    pub sign: f64,
    /// What the values are called: `error`, or `correction (−error)`.
    pub name: &'static str,
}

/// What the cross-axis file [`write_cross_axis`] writes holds.
pub fn cross_axis_values(controller: Controller, options: &EmitOptions) -> CrossAxisValues {
    match controller {
        Controller::Sinumerik840d => sinumerik840d::cross_axis_values(options),
        _ => CrossAxisValues {
            sign: 1.0,
            name: "error",
        },
    }
}

/// A table as a controller file holds it: `values` at `positions_mm`, its
/// reference the first point where it is zero (else the first point), no
/// backlash suggestion, of a linear axis until [`read_any`] gives it the
/// axis' kind (a file does not tell mm from degrees). Every reader returns
/// its table through this.
pub(crate) fn table_as_read(
    axis: &str,
    positions_mm: Vec<f64>,
    values: TableValues,
) -> CompensationTable {
    let reference_mm = reference_of(&positions_mm, &values);
    CompensationTable {
        axis: axis.to_string(),
        kind: crate::measurement::AxisKind::Linear,
        positions: positions_mm,
        values,
        reference: reference_mm,
        suggested_backlash: None,
    }
}

/// The first point where the table is zero (its reference), else the first point.
fn reference_of(positions_mm: &[f64], values: &TableValues) -> f64 {
    let up = values.for_direction(Direction::Up);
    let down = values.for_direction(Direction::Down);
    positions_mm
        .iter()
        .enumerate()
        .find(|(i, _)| ((up[*i] + down[*i]) / 2.0).abs() < 1e-12)
        .map_or(positions_mm[0], |(_, p)| *p)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::compensate::TableValues;
    use crate::units::um_to_mm;

    #[test]
    fn backlash_values_are_rounded_in_the_controller_unit() {
        let options = options(Controller::Sinumerik840d, LengthUnit::Millimetre);
        // −B̄ = 3.179725 µm (fixtures/sample-x.rtl): 0.0032 mm to 4 decimals.
        let BacklashAdvice::Parameter(mm) =
            Controller::Sinumerik840d.backlash_parameter(0.003_179_725, &options)
        else {
            panic!("Sinumerik has MD32450")
        };
        assert_eq!((mm.value, mm.value_text().as_str()), (0.0032, "0.0032"));
        assert_eq!(mm.name, "MD32450 $MA_BACKLASH[0,X1]");
        // An overshooting axis gets a negative value; a rounded zero is 0, not -0.
        let negative =
            BacklashParameter::new(String::new(), -0.001, LengthUnit::Millimetre, 4, "", None);
        assert_eq!(negative.value_text(), "-0.0010");
        let tiny = BacklashParameter::new(
            String::new(),
            -0.000_01,
            LengthUnit::Millimetre,
            4,
            "",
            None,
        );
        assert_eq!(tiny.value_text(), "0.0000");
        // 0.003179725 mm / 25.4 = 0.00012519 inch.
        let inch =
            BacklashParameter::new(String::new(), 0.003_179_725, LengthUnit::Inch, 6, "", None);
        assert_eq!(inch.value_text(), "0.000125");
        assert!(matches!(
            Controller::LinuxCnc.backlash_parameter(0.003_179_725, &options),
            BacklashAdvice::NoParameter(_)
        ));
    }

    #[test]
    fn controller_names() {
        for controller in Controller::ALL {
            assert_eq!(Controller::from_name(controller.name()), Some(controller));
        }
        assert_eq!(Controller::from_name("fanuc"), Some(Controller::Fanuc));
        assert_eq!(Controller::from_name("heidenhain"), None);
    }

    fn options(controller: Controller, unit: LengthUnit) -> EmitOptions {
        EmitOptions {
            axes: vec![MachineProfile::default().axis("X").unwrap()],
            table_name: "X.COM".into(),
            machine_unit: unit,
            linuxcnc_type: 0,
            max_points: None,
            max_value_mm: None,
            provenance: None,
            cec_values_are_corrections: controller == Controller::Sinumerik840d,
            tnc640_columns: Vec::new(),
            kind: Default::default(),
        }
    }

    /// Tables every controller takes: an even grid, values within ±0.5 mm,
    /// zero at the first point (the iTNC datum), mean or bidirectional.
    fn arbitrary_table() -> impl Strategy<Value = (CompensationTable, bool)> {
        (
            -500_000i32..500_000,
            500u32..100_000,
            2usize..60,
            any::<bool>(),
        )
            .prop_flat_map(|(start_um, step_um, count, both)| {
                // Start and step on the 0.1 µm grid every format writes exactly.
                let (start, step) = (um_to_mm(f64::from(start_um)), um_to_mm(f64::from(step_um)));
                let column = || prop::collection::vec(-0.5f64..0.5, count);
                (column(), column()).prop_map(move |(mut up, mut down)| {
                    up[0] = 0.0;
                    down[0] = 0.0;
                    let positions_mm = (0..count).map(|k| start + k as f64 * step).collect();
                    let values = if both {
                        TableValues::Bidirectional { up, down }
                    } else {
                        TableValues::Mean(up)
                    };
                    let table = CompensationTable {
                        axis: "X".into(),
                        kind: crate::measurement::AxisKind::Linear,
                        positions: positions_mm,
                        values,
                        reference: start,
                        suggested_backlash: None,
                    };
                    (table, both)
                })
            })
    }

    #[test]
    fn a_step_the_format_would_round_is_refused() {
        let table = CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![0.0, 31.70933479667853, 63.41866959335706],
            values: TableValues::Mean(vec![0.0, 0.001, 0.002]),
            reference: 0.0,
            suggested_backlash: None,
        };
        let error = write(
            Controller::Itnc530,
            &table,
            &options(Controller::Itnc530, LengthUnit::Millimetre),
        )
        .unwrap_err();
        assert!(
            matches!(error, EmitError::StepNotRepresentable { .. }),
            "{error}"
        );
        // Free-position formats write each point and take it.
        assert!(
            write(
                Controller::Tnc640,
                &table,
                &options(Controller::Tnc640, LengthUnit::Millimetre)
            )
            .is_ok()
        );
    }

    #[test]
    fn a_point_beyond_the_heidenhain_position_range_is_refused() {
        // Found by fuzzing (fuzz/fuzz_targets/read_tables.rs): a TNC 640 table
        // with a point at 1.0e28 mm read, but its AXISPOS overflowed the
        // 14-character column when written.
        let table = CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![0.0, 58.557, 1.0055e28],
            values: TableValues::Bidirectional {
                up: vec![0.0014, 0.0031, 0.0013],
                down: vec![-0.0014, -0.0003, 0.0],
            },
            reference: 0.0,
            suggested_backlash: None,
        };
        let options = options(Controller::Tnc640, LengthUnit::Millimetre);
        let error = write(Controller::Tnc640, &table, &options).unwrap_err();
        assert_eq!(
            error.to_string(),
            "compensation point 10055000000000000000000000000 mm is beyond the tnc640 position range of ±99999.9999 mm"
        );
        let mut near = table.clone();
        near.positions[2] = 99_999.999_9;
        let text = write(Controller::Tnc640, &near, &options).unwrap();
        assert!(text.contains("+99999.9999"), "{text}");
    }

    #[test]
    fn numbers_a_double_cannot_hold_to_the_resolution_are_refused() {
        // Found by fuzzing: a LinuxCNC row at 8·10¹⁷ mm read, but point +
        // value lost its last digits in the double.
        let mut table = CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![0.0, 8e17],
            values: TableValues::Mean(vec![0.0, 0.001]),
            reference: 0.0,
            suggested_backlash: None,
        };
        let options = options(Controller::LinuxCnc, LengthUnit::Millimetre);
        let error = write(Controller::LinuxCnc, &table, &options).unwrap_err();
        assert_eq!(
            error.to_string(),
            "compensation point 800000000000000000 mm is beyond the linuxcnc position range of ±1000000000 mm"
        );
        // At the limit, point and value both at 10¹⁵ resolutions, it still round-trips.
        table.positions[1] = 1e9;
        table.values = TableValues::Mean(vec![0.0, -1e9]);
        write(Controller::LinuxCnc, &table, &options).unwrap();
        table.values = TableValues::Mean(vec![0.0, -1.000_000_001e9]);
        let error = write(Controller::LinuxCnc, &table, &options).unwrap_err();
        assert!(error.to_string().contains("15-digit range"), "{error}");
    }

    proptest! {
        #[test]
        fn every_controller_reads_back_what_it_writes((table, both) in arbitrary_table(), inch in any::<bool>()) {
            for controller in Controller::ALL {
                // Fanuc points hold −128 … 127 units each, which arbitrary values
                // exceed; its round trip is tested in `fanuc`.
                if (both && !controller.supports_bidirectional()) || controller == Controller::Fanuc {
                    continue;
                }
                let unit = if inch && controller == Controller::LinuxCnc { LengthUnit::Inch } else { LengthUnit::Millimetre };
                let options = options(controller, unit);
                // `write` itself reads the text back and compares within the resolution.
                let text = write(controller, &table, &options).map_err(|e| TestCaseError::fail(format!("{controller:?}: {e}")))?;
                let (detected, back) = read_any(&text, &options, Some(0)).map_err(|e| TestCaseError::fail(format!("{e}")))?;
                prop_assert_eq!(detected, controller);
                prop_assert_eq!(back.values.mode(), table.values.mode());
            }
        }
    }
}
