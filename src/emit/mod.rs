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

mod fagor;
pub mod fagor8055;
pub mod fagor8065;
pub mod fanuc;
mod heidenhain;
pub mod itnc530;
pub mod linuxcnc;
pub mod linuxcnc_thermal;
pub mod profile;
pub mod sinumerik840d;
pub mod tnc640;

use crate::compensate::cross_axis::CrossAxisTable;
use crate::compensate::plan::Capabilities;
use crate::compensate::{CompensationTable, TableMode, TableValues};
use crate::error::ParseError;
use crate::evaluate::conformance::FULL_TURN_DEG;
use crate::measurement::{AxisKind, Direction};
use crate::units::LengthUnit;
pub use fagor::{TextEncoding, decode as decode_table, encode as encode_table};
pub use profile::{AxisPeriods, AxisProfile, CecValues, MachineProfile};

/// The controllers axcomp writes tables for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Controller {
    /// Heidenhain iTNC 530 nonlinear axis error compensation (`.COM`).
    Itnc530,
    /// Heidenhain TNC 640 (`.COM` + a `config.cma` line).
    Tnc640,
    /// Siemens Sinumerik 840D: LEC (`$AA_ENC_COMP`) or, bidirectional, CEC (`$AN_CEC`).
    Sinumerik840d,
    /// LinuxCNC `[JOINT_n] COMP_FILE` (type 0 or 1).
    LinuxCnc,
    /// Fagor 8055 leadscrew table `AL<axis>`.
    Fagor8055,
    /// Fagor 8065 axis parameter file `<axis>.mp` (its `/LSCRWDATA` table).
    Fagor8065,
    /// Fanuc pitch error compensation data (`PITCH.TXT`, punch format).
    Fanuc,
}

impl Controller {
    /// Every controller, in the order they are listed to users.
    pub const ALL: [Controller; 7] = [
        Controller::Itnc530,
        Controller::Tnc640,
        Controller::Sinumerik840d,
        Controller::LinuxCnc,
        Controller::Fagor8055,
        Controller::Fagor8065,
        Controller::Fanuc,
    ];

    /// The `--controller` name.
    pub fn name(self) -> &'static str {
        match self {
            Controller::Itnc530 => "itnc530",
            Controller::Tnc640 => "tnc640",
            Controller::Sinumerik840d => "sinumerik840d",
            Controller::LinuxCnc => "linuxcnc",
            Controller::Fagor8055 => "fagor8055",
            Controller::Fagor8065 => "fagor8065",
            Controller::Fanuc => "fanuc",
        }
    }

    /// The name a table for `axis` usually has on this controller: what the
    /// demo writes and `axcomp serve` downloads (`X.COM`, `X.MPF`, `x.comp`,
    /// `ALX`, `X.mp`; see `formats/<controller>/`).
    pub fn file_name(self, axis: &str) -> String {
        match self {
            Controller::Itnc530 | Controller::Tnc640 => format!("{axis}.COM"),
            Controller::Sinumerik840d => format!("{axis}.MPF"),
            Controller::LinuxCnc => format!("{}.comp", axis.to_ascii_lowercase()),
            Controller::Fagor8055 => format!("AL{axis}"),
            Controller::Fagor8065 => format!("{axis}.mp"),
            Controller::Fanuc => "PITCH.TXT".to_string(),
        }
    }

    /// Looks a controller up by name.
    pub fn from_name(name: &str) -> Option<Controller> {
        Controller::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(name))
    }

    /// Whether the format takes free (uneven) compensation points.
    pub fn accepts_free_positions(self) -> bool {
        matches!(
            self,
            Controller::Tnc640
                | Controller::LinuxCnc
                | Controller::Fagor8055
                | Controller::Fagor8065
        )
    }

    /// Whether a table for this controller is written into the control's
    /// own file, which axcomp cannot write from nothing: a Fagor 8065 table
    /// is part of the axis' `.mp` export, and a Fanuc table counts in units
    /// and points the parameter backup gives. `convert --existing` (with
    /// `--fanuc-parameters` for Fanuc) updates them.
    pub fn needs_the_controls_file(self) -> bool {
        matches!(self, Controller::Fagor8065 | Controller::Fanuc)
    }

    /// Whether the format holds separate ↑ and ↓ values.
    pub fn supports_bidirectional(self) -> bool {
        !matches!(self, Controller::Itnc530 | Controller::Fanuc)
    }

    /// What a table's plan needs to know of this controller
    /// (`compensate::plan`), for a machine in `machine_unit`.
    pub fn capabilities(self, machine_unit: LengthUnit) -> Capabilities {
        Capabilities {
            name: self.name(),
            bidirectional: self.supports_bidirectional(),
            free_positions: self.accepts_free_positions(),
            resolution_mm: resolution_mm(self, machine_unit),
            mean_table: self.mean_table(),
        }
    }

    /// The unit of the lengths in its file on a machine in `machine_unit`:
    /// the machine's for the Fagor 8055 and LinuxCNC, whose files hold
    /// machine units (Fanuc: counts of the machine's detection unit); mm for the others, whose files state mm (Heidenhain
    /// `MM`, the Fagor 8065's 4-decimal mm) or are written in mm as the
    /// manufacturer's example (Sinumerik LEC and CEC).
    pub fn file_unit(self, machine_unit: LengthUnit) -> LengthUnit {
        match self {
            Controller::Fagor8055 | Controller::LinuxCnc | Controller::Fanuc => machine_unit,
            _ => LengthUnit::Millimetre,
        }
    }

    /// Where the controller keeps a mean table and how it applies it (the
    /// facts are in each controller's `formats/` folder).
    fn mean_table(self) -> &'static str {
        match self {
            Controller::Itnc530 => "the axis column, which the iTNC 530 applies in both directions",
            Controller::Tnc640 => {
                "the axis column with the BACKLASH column empty, which the TNC 640 applies in both directions"
            }
            Controller::Sinumerik840d => {
                "one LEC table ($AA_ENC_COMP), which the control applies in both directions"
            }
            Controller::LinuxCnc => "both the forward and the reverse column alike",
            Controller::Fagor8055 => {
                "the positive-direction column (the negative-direction column all zero), which the 8055 then applies in both directions"
            }
            Controller::Fagor8065 => {
                "POSERROR with BIDIR = 0 (NEGERROR all zero), which the 8065 then applies in both directions"
            }
            Controller::Fanuc => {
                "the pitch error compensation data, which the control applies in both directions"
            }
        }
    }

    /// What to do on this controller with the reversal a mean table leaves:
    /// the backlash parameter to set, in the controller's own name, unit,
    /// resolution and sign, or why there is none. `backlash_mm` is the
    /// suggested backlash −B̄ (`CompensationTable::suggested_backlash_mm`),
    /// positive for the usual lost motion; the knowledge of each parameter
    /// lives in its controller's file.
    pub fn backlash_parameter(self, backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
        match self {
            Controller::Itnc530 => itnc530::backlash_parameter(backlash_mm, options),
            Controller::Tnc640 => tnc640::backlash_parameter(backlash_mm, options),
            Controller::Sinumerik840d => sinumerik840d::backlash_parameter(backlash_mm, options),
            Controller::LinuxCnc => linuxcnc::backlash_parameter(backlash_mm, options),
            Controller::Fagor8055 => fagor8055::backlash_parameter(backlash_mm, options),
            Controller::Fagor8065 => fagor8065::backlash_parameter(backlash_mm, options),
            Controller::Fanuc => fanuc::backlash_parameter(backlash_mm, options),
        }
    }

    /// The most points the controller takes, when known.
    pub fn max_points(self) -> Option<usize> {
        match self {
            // TNC 407 technical manual p.622: "Compensation value table (.COM) has more than 256 entries".
            Controller::Itnc530 => Some(256),
            // LinuxCNC motion.h: EMCMOT_COMP_SIZE 256.
            Controller::LinuxCnc => Some(256),
            Controller::Fagor8055 => Some(fagor8055::MAX_POINTS),
            Controller::Fanuc => Some(fanuc::MAX_POINTS),
            // TNC 640: not documented publicly; Sinumerik: MD38000,
            // machine-specific; Fagor 8065: no public limit found.
            Controller::Tnc640 | Controller::Sinumerik840d | Controller::Fagor8065 => None,
        }
    }
}

/// What to do with the reversal a mean table leaves ([`Controller::backlash_parameter`]).
#[derive(Clone, Debug, PartialEq)]
pub enum BacklashAdvice {
    /// Set this parameter of the controller.
    Parameter(BacklashParameter),
    /// The controller has no parameter that works next to the table; the
    /// sentence says why and what to do instead.
    NoParameter(String),
}

/// A controller's backlash parameter with the value to type into it.
#[derive(Clone, Debug, PartialEq)]
pub struct BacklashParameter {
    /// Where it is set, in the controller's own words (`MD32450 $MA_BACKLASH[0,X1]`).
    pub name: String,
    /// The value to type, in `unit`, already rounded to `decimals`.
    pub value: f64,
    /// The unit the controller reads it in.
    pub unit: LengthUnit,
    /// Decimals the value is given to (the controller's input resolution).
    pub decimals: usize,
    /// What a positive value means, in the controller's documentation's words.
    pub sign: String,
    /// What else to know (another parameter for another set-up, when it acts).
    pub note: Option<String>,
}

impl BacklashParameter {
    /// A parameter whose value is `backlash_mm` in `unit`, rounded to `decimals`.
    pub fn new(
        name: String,
        backlash_mm: f64,
        unit: LengthUnit,
        decimals: usize,
        sign: &str,
        note: Option<String>,
    ) -> BacklashParameter {
        let scale = 10f64.powi(decimals as i32);
        let value = (unit.from_mm(backlash_mm) * scale).round() / scale;
        BacklashParameter {
            name,
            // Never -0.
            value: if value == 0.0 { 0.0 } else { value },
            unit,
            decimals,
            sign: sign.to_string(),
            note,
        }
    }

    /// The value as the user types it: `0.0032`, `-0.0010`.
    pub fn value_text(&self) -> String {
        format!("{:.*}", self.decimals, self.value)
    }
}

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
        let (Some(first), Some(last)) = (table.positions_mm.first(), table.positions_mm.last())
        else {
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

/// Why a table is refused for a controller.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EmitError {
    /// An axis whose letter gives no default for a name the controller needs.
    #[error(
        "axis {axis:?} has no default {what}; give it in the machine profile under [controller.axes.{axis}]"
    )]
    NoDefault {
        /// The axis.
        axis: String,
        /// The profile key it needs.
        what: &'static str,
    },
    /// More points than the controller takes.
    #[error(
        "{controller} takes at most {max} compensation points, the table has {count}; use a larger --step"
    )]
    TooManyPoints {
        /// The controller.
        controller: &'static str,
        /// The limit.
        max: usize,
        /// The table's points.
        count: usize,
    },
    /// Points not strictly increasing.
    #[error(
        "compensation positions must be strictly increasing: {position_mm} mm follows {previous_mm} mm"
    )]
    NotIncreasing {
        /// The offending point.
        position_mm: f64,
        /// The one before.
        previous_mm: f64,
    },
    /// Uneven spacing where the format has one step.
    #[error(
        "{controller} needs evenly spaced points (one step for the whole table); give --step (and --start, --count)"
    )]
    UnevenSpacing {
        /// The controller.
        controller: &'static str,
    },
    /// A step the format cannot write exactly.
    #[error(
        "{controller} writes the step to {resolution_mm} mm; a step of {step_mm} mm would shift the points along the table: give --step as a multiple of {resolution_mm} mm"
    )]
    StepNotRepresentable {
        /// The controller.
        controller: &'static str,
        /// The step.
        step_mm: f64,
        /// The format's resolution.
        resolution_mm: f64,
    },
    /// A compensation point beyond the positions the format can hold.
    #[error(
        "compensation point {position_mm} mm is beyond the {controller} position range of ±{limit_mm} mm"
    )]
    PositionOutOfRange {
        /// The controller.
        controller: &'static str,
        /// The point.
        position_mm: f64,
        /// The limit.
        limit_mm: f64,
    },
    /// A value beyond the format's or the machine's range.
    #[error("value {value_mm} mm at {position_mm} mm is beyond the {what} range of ±{limit_mm} mm")]
    ValueOutOfRange {
        /// The value.
        value_mm: f64,
        /// Where.
        position_mm: f64,
        /// Whose range.
        what: &'static str,
        /// The limit.
        limit_mm: f64,
    },
    /// The format has one column only.
    #[error(
        "{controller} tables hold one value per point; use --mode mean (and set the backlash parameter to the suggested value)"
    )]
    NoBidirectional {
        /// The controller.
        controller: &'static str,
    },
    /// The format needs zero at its first point.
    #[error(
        "{controller} needs the value 0 at the first point (the datum); the table is {value_mm} mm there: use --reference at the first point"
    )]
    NotZeroAtDatum {
        /// The controller.
        controller: &'static str,
        /// The value at the first point.
        value_mm: f64,
    },
    /// A rotary axis for a format that shows no rotary form.
    #[error(
        "{controller} tables are written for linear axes only: the format's documents show no rotary table (formats/{controller}/README.md)"
    )]
    RotaryNotSupported {
        /// The controller.
        controller: &'static str,
    },
    /// A full-turn modulo table must go from 0° to 360°.
    #[error(
        "a Sinumerik modulo table of a rotary axis goes from 0° to 360° ($AA_ENC_COMP_MIN 0, MAX 360); this one goes from {first_deg}° to {last_deg}°: build it on a 0…360° grid (--start 0 --step …)"
    )]
    ModuloRange {
        /// The first point, °.
        first_deg: f64,
        /// The last point, °.
        last_deg: f64,
    },
    /// A modulo table whose ends, one physical position, differ.
    #[error(
        "a Sinumerik modulo table repeats every turn, so its values at 0° and 360° must be equal; this one has {first_deg}° at 0° and {last_deg}° at 360°"
    )]
    ModuloEndsDiffer {
        /// The value at 0°, °.
        first_deg: f64,
        /// The value at 360°, °.
        last_deg: f64,
    },
    /// A profile value the format cannot use.
    #[error("{0}")]
    Profile(String),
    /// A bug: the written text does not read back to the table.
    #[error("internal error, please report: {0}")]
    Internal(String),
}

/// The largest |compensation point| and |value| a format holds, mm; the value
/// limit comes with the name of its range, for the message.
fn format_limits_mm(
    controller: Controller,
    machine_unit: LengthUnit,
) -> (f64, (&'static str, f64)) {
    match controller {
        // [reconstructed] Points: ±99 999.9999 mm, the input range of the
        // iTNC 530's traverse limits (MP910–MP921); beyond it a point is no
        // axis position and would overflow the 14-character AXISPOS column of
        // a TNC 640 table. Values: ±9.9999 mm, the range of the backlash
        // parameter MP750 and of a signed 4-decimal field; no COM-specific
        // limit is public.
        Controller::Itnc530 | Controller::Tnc640 => (99_999.999_9, ("Heidenhain", 9.9999)),
        // No published limit, but both controllers parse numbers as doubles,
        // which hold every multiple of the resolution up to 9·10¹⁵ of them:
        // 10¹⁵ resolutions keeps every written digit, also where a LinuxCNC
        // type-0 row writes point + value.
        Controller::Sinumerik840d | Controller::LinuxCnc => {
            let digits_mm = resolution_mm(controller, machine_unit) * 1e15;
            (digits_mm, ("15-digit", digits_mm))
        }
        Controller::Fagor8055 | Controller::Fagor8065 => {
            (fagor::LIMIT_MM, ("Fagor", fagor::LIMIT_MM))
        }
        // [reconstructed] 3624 and 1240 hold ±99 999.999 mm (IS-B); each
        // point's own limit is checked by `fanuc` in its units.
        Controller::Fanuc => (99_999.999, ("Fanuc", 99_999.999)),
    }
}

/// Checks what the controller would reject, before anything is written.
pub fn check_table(
    controller: Controller,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<(), EmitError> {
    let name = controller.name();
    check_rotary(controller, table, options)?;
    let count = table.positions_mm.len();
    let limit = match (controller.max_points(), options.max_points) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };
    if let Some(max) = limit
        && count > max
    {
        return Err(EmitError::TooManyPoints {
            controller: name,
            max,
            count,
        });
    }
    for pair in table.positions_mm.windows(2) {
        if pair[1] <= pair[0] {
            return Err(EmitError::NotIncreasing {
                position_mm: pair[1],
                previous_mm: pair[0],
            });
        }
    }
    if !controller.accepts_free_positions() {
        let Some(step) = table.regular_step_mm() else {
            return Err(EmitError::UnevenSpacing { controller: name });
        };
        // One step for the whole table, written to the format's resolution:
        // a rounded step would shift point k by k times the rounding.
        let resolution = resolution_mm(controller, options.file_unit());
        if ((step / resolution).round() * resolution - step).abs() > 1e-9 {
            return Err(EmitError::StepNotRepresentable {
                controller: name,
                step_mm: step,
                resolution_mm: resolution,
            });
        }
    }
    if table.values.mode() == TableMode::Bidirectional && !controller.supports_bidirectional() {
        return Err(EmitError::NoBidirectional { controller: name });
    }
    // TNC 335/407 manuals: "The error curve must always start with correction value = 0 at the datum point."
    let first_value = table.values.for_direction(Direction::Up)[0];
    if controller == Controller::Itnc530 && first_value.abs() >= 0.5e-4 {
        return Err(EmitError::NotZeroAtDatum {
            controller: name,
            value_mm: first_value,
        });
    }
    let (position_limit_mm, value_limit) = format_limits_mm(controller, options.file_unit());
    if let Some(position_mm) = table
        .positions_mm
        .iter()
        .find(|position| position.abs() > position_limit_mm)
    {
        return Err(EmitError::PositionOutOfRange {
            controller: name,
            position_mm: *position_mm,
            limit_mm: position_limit_mm,
        });
    }
    let machine_limit = options.max_value_mm.map(|limit| ("machine profile", limit));
    for (what, limit_mm) in std::iter::once(value_limit).chain(machine_limit) {
        for direction in crate::measurement::Direction::BOTH {
            let column = table.values.for_direction(direction);
            if let Some((value, position)) = column
                .iter()
                .zip(&table.positions_mm)
                .find(|(value, _)| value.abs() > limit_mm)
            {
                return Err(EmitError::ValueOutOfRange {
                    value_mm: *value,
                    position_mm: *position,
                    what,
                    limit_mm,
                });
            }
        }
    }
    Ok(())
}

/// What a rotary table must be for `controller` (module doc).
fn check_rotary(
    controller: Controller,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<(), EmitError> {
    if options.kind != AxisKind::Rotary {
        return Ok(());
    }
    match controller {
        Controller::Fagor8055 | Controller::Fagor8065 => {
            return Err(EmitError::RotaryNotSupported {
                controller: controller.name(),
            });
        }
        Controller::Sinumerik840d => {}
        Controller::Itnc530 | Controller::Tnc640 | Controller::LinuxCnc | Controller::Fanuc => {
            return Ok(());
        }
    }
    let (first, last) = (
        table.positions_mm[0],
        table.positions_mm[table.positions_mm.len() - 1],
    );
    if !options.is_full_turn(table) {
        return Ok(());
    }
    if first.abs() > 1e-9 {
        return Err(EmitError::ModuloRange {
            first_deg: first,
            last_deg: last,
        });
    }
    let resolution = resolution_mm(controller, options.file_unit());
    for direction in crate::measurement::Direction::BOTH {
        let column = table.values.for_direction(direction);
        let (first_deg, last_deg) = (column[0], column[column.len() - 1]);
        if (first_deg - last_deg).abs() > resolution / 2.0 {
            return Err(EmitError::ModuloEndsDiffer {
                first_deg,
                last_deg,
            });
        }
    }
    Ok(())
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
    let same_points = back.positions_mm.len() == table.positions_mm.len()
        && back
            .positions_mm
            .iter()
            .zip(&table.positions_mm)
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

/// The smallest step a format writes, mm.
pub fn resolution_mm(controller: Controller, machine_unit: LengthUnit) -> f64 {
    match controller {
        Controller::Itnc530 | Controller::Tnc640 => 1e-4,
        Controller::Sinumerik840d => 1e-6,
        Controller::LinuxCnc => match machine_unit {
            LengthUnit::Millimetre => 1e-6,
            LengthUnit::Inch => crate::units::inch_to_mm(1e-7),
        },
        Controller::Fagor8055 => {
            machine_unit.to_mm(10f64.powi(-(fagor8055::decimals(machine_unit) as i32)))
        }
        Controller::Fagor8065 => 1e-4,
        // [manual] IS-B: least input increment 0.001 mm (B-63943EN-1/02
        // p.109), the resolution of the interval 3624.
        Controller::Fanuc => 1e-3,
    }
}

/// Reads a table written by any supported controller format, detected from
/// the content: the table of `options.axes[0]`, in machine units
/// `options.machine_unit` (LinuxCNC) and with the profile's CEC sign.
/// `linuxcnc_type` must be given for LinuxCNC files whose type the numbers
/// do not tell.
pub fn read_any(
    text: &str,
    options: &EmitOptions,
    linuxcnc_type: Option<u8>,
) -> Result<(Controller, CompensationTable), ParseError> {
    let Some(axis) = options.axes.first() else {
        return Err(ParseError::new(1, 1, "no axis given to read the table of"));
    };
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("");
    let (controller, mut table) = if fanuc::looks_like(text) {
        let Some(parameters) = &axis.fanuc else {
            return Err(ParseError::new(
                1,
                1,
                "a Fanuc pitch error compensation file counts in units the parameter backup gives (3620–3624, 1820): give it with --fanuc-parameters CNC-PARA.TXT",
            ));
        };
        (Controller::Fanuc, fanuc::read(text, parameters)?)
    } else if fanuc::looks_like_parameters(text) {
        return Err(ParseError::new(
            1,
            1,
            "this is a Fanuc parameter backup (N…Q1 lines), not the pitch error compensation data: give it with --fanuc-parameters and the pitch file (PITCH.TXT, N1…Q0 lines) as the table",
        ));
    } else if fagor8065::looks_like(text) {
        (Controller::Fagor8065, fagor8065::read(text, &axis.axis)?)
    } else if fagor8055::looks_like(text) {
        let table = fagor8055::read(text, &axis.axis, options.machine_unit)?;
        (Controller::Fagor8055, table)
    } else if first.starts_with("BEGIN") && first.contains("DATUM") {
        (
            Controller::Itnc530,
            itnc530::read(text, axis.itnc530_column)?,
        )
    } else if first.starts_with("BEGIN") {
        (Controller::Tnc640, tnc640::read(text, &axis.tnc640_column)?)
    } else if first.starts_with('%') || text.contains("$AA_ENC_COMP") || text.contains("$AN_CEC") {
        let table = sinumerik840d::read(
            text,
            &axis.sinumerik_axis,
            options.cec_values_are_corrections,
        )?;
        (Controller::Sinumerik840d, table)
    } else if first.split_whitespace().count() == 3 {
        let table = linuxcnc::read(text, &axis.axis, linuxcnc_type, options.file_unit())?;
        (Controller::LinuxCnc, table)
    } else {
        return Err(ParseError::new(
            1,
            1,
            "unknown compensation table format: expected a Heidenhain .COM (BEGIN …), a Sinumerik .MPF (%_N_…), a LinuxCNC COMP_FILE (nominal forward reverse), a Fagor 8055 AL<axis> (P0001 X … EX … EX …), a Fagor 8065 .mp (/LSCRWDATA/…) or a Fanuc pitch file (%, N10000Q0P…)",
        ));
    };
    table.axis = axis.axis.clone();
    Ok((controller, table))
}

/// The controller format of a table file, from its content.
pub fn detect(text: &str) -> Option<Controller> {
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("");
    if fanuc::looks_like(text) {
        Some(Controller::Fanuc)
    } else if fagor8065::looks_like(text) {
        Some(Controller::Fagor8065)
    } else if fagor8055::looks_like(text) {
        Some(Controller::Fagor8055)
    } else if first.starts_with("BEGIN") && first.contains("DATUM") {
        Some(Controller::Itnc530)
    } else if first.starts_with("BEGIN") {
        Some(Controller::Tnc640)
    } else if first.starts_with('%') || text.contains("$AA_ENC_COMP") || text.contains("$AN_CEC") {
        Some(Controller::Sinumerik840d)
    } else if first.split_whitespace().count() == 3 {
        Some(Controller::LinuxCnc)
    } else {
        None
    }
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

/// What a cross-axis file holds, times the table's error: −1 where a
/// Sinumerik CEC holds corrections, else +1.
pub fn cross_axis_file_sign(controller: Controller, options: &EmitOptions) -> f64 {
    match controller {
        Controller::Sinumerik840d if options.cec_values_are_corrections => -1.0,
        _ => 1.0,
    }
}

/// `+0.0023` / `-0.0023` with a fixed number of decimals; never `-0.0000`.
pub fn signed_fixed(value: f64, decimals: usize) -> String {
    let text = format!("{value:+.decimals$}");
    if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
        return format!("+{}", &text[1..]);
    }
    text
}

/// Minimal digits, up to `max_decimals`, with an explicit sign: `+100`, `+12.5`, `-0.25`.
pub fn signed_minimal(value: f64, max_decimals: usize) -> String {
    let unsigned = minimal(value.abs(), max_decimals);
    let negative = value < 0.0 && unsigned.chars().any(|c| c.is_ascii_digit() && c != '0');
    format!("{}{unsigned}", if negative { '-' } else { '+' })
}

/// Minimal digits, up to `max_decimals`, no sign for positives: `100`, `12.5`, `-0.25`.
pub fn minimal(value: f64, max_decimals: usize) -> String {
    let text = format!("{value:.max_decimals$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    if text == "-0" {
        "0".to_string()
    } else {
        text.to_string()
    }
}

/// A table as a controller file holds it: `values` at `positions_mm`, its
/// reference the first point where it is zero (else the first point), no
/// backlash suggestion. Every reader returns its table through this.
pub(crate) fn table_as_read(
    axis: &str,
    positions_mm: Vec<f64>,
    values: TableValues,
) -> CompensationTable {
    let reference_mm = reference_of(&positions_mm, &values);
    CompensationTable {
        axis: axis.to_string(),
        positions_mm,
        values,
        reference_mm,
        suggested_backlash_mm: None,
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
    fn number_formats() {
        assert_eq!(signed_fixed(-0.0023, 4), "-0.0023");
        assert_eq!(signed_fixed(0.0, 4), "+0.0000");
        assert_eq!(signed_fixed(-0.00004, 4), "+0.0000");
        assert_eq!(signed_fixed(0.00005001, 4), "+0.0001");
        assert_eq!(signed_minimal(100.0, 4), "+100");
        assert_eq!(signed_minimal(-12.5, 4), "-12.5");
        assert_eq!(signed_minimal(-0.00001, 4), "+0");
        assert_eq!(minimal(-200.0, 6), "-200");
        assert_eq!(minimal(0.0030000001, 6), "0.003");
        assert_eq!(minimal(-0.0000001, 6), "0");
    }

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
                        positions_mm,
                        values,
                        reference_mm: start,
                        suggested_backlash_mm: None,
                    };
                    (table, both)
                })
            })
    }

    #[test]
    fn a_step_the_format_would_round_is_refused() {
        let table = CompensationTable {
            axis: "X".into(),
            positions_mm: vec![0.0, 31.70933479667853, 63.41866959335706],
            values: TableValues::Mean(vec![0.0, 0.001, 0.002]),
            reference_mm: 0.0,
            suggested_backlash_mm: None,
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
            positions_mm: vec![0.0, 58.557, 1.0055e28],
            values: TableValues::Bidirectional {
                up: vec![0.0014, 0.0031, 0.0013],
                down: vec![-0.0014, -0.0003, 0.0],
            },
            reference_mm: 0.0,
            suggested_backlash_mm: None,
        };
        let options = options(Controller::Tnc640, LengthUnit::Millimetre);
        let error = write(Controller::Tnc640, &table, &options).unwrap_err();
        assert_eq!(
            error.to_string(),
            "compensation point 10055000000000000000000000000 mm is beyond the tnc640 position range of ±99999.9999 mm"
        );
        let mut near = table.clone();
        near.positions_mm[2] = 99_999.999_9;
        let text = write(Controller::Tnc640, &near, &options).unwrap();
        assert!(text.contains("+99999.9999"), "{text}");
    }

    #[test]
    fn numbers_a_double_cannot_hold_to_the_resolution_are_refused() {
        // Found by fuzzing: a LinuxCNC row at 8·10¹⁷ mm read, but point +
        // value lost its last digits in the double.
        let mut table = CompensationTable {
            axis: "X".into(),
            positions_mm: vec![0.0, 8e17],
            values: TableValues::Mean(vec![0.0, 0.001]),
            reference_mm: 0.0,
            suggested_backlash_mm: None,
        };
        let options = options(Controller::LinuxCnc, LengthUnit::Millimetre);
        let error = write(Controller::LinuxCnc, &table, &options).unwrap_err();
        assert_eq!(
            error.to_string(),
            "compensation point 800000000000000000 mm is beyond the linuxcnc position range of ±1000000000 mm"
        );
        // At the limit, point and value both at 10¹⁵ resolutions, it still round-trips.
        table.positions_mm[1] = 1e9;
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
                // Fanuc points hold ±127 units each, which arbitrary values
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
