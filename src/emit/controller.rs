//! The controller registry: the controllers axcomp writes tables for, what
//! each one takes (points, resolution, directions) and the backlash parameter
//! each one has for the reversal a mean table leaves.

use super::{EmitOptions, fagor8055, fagor8065, fanuc, itnc530, linuxcnc, sinumerik840d, tnc640};
use crate::compensate::plan::Capabilities;
use crate::units::LengthUnit;

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

    /// Whether the format holds separate ↑ and ↓ values (a Fanuc control
    /// does with 3605#0, which only its parameters tell: `--mode
    /// bidirectional` asks for it).
    pub fn supports_bidirectional(self) -> bool {
        !matches!(self, Controller::Itnc530 | Controller::Fanuc)
    }

    /// Whether axcomp writes a straightness test's cross-axis table for it:
    /// a TNC 640 `.COM` with a dependent column, a Sinumerik CEC table with
    /// another output axis.
    pub fn writes_cross_axis(self) -> bool {
        matches!(self, Controller::Tnc640 | Controller::Sinumerik840d)
    }

    /// Whether a cross-axis table goes into the axis' existing table (the
    /// TNC 640's one active `.COM` per axis) rather than a file of its own.
    pub fn cross_axis_into_existing(self) -> bool {
        self == Controller::Tnc640
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
    /// suggested backlash −B̄ (`CompensationTable::suggested_backlash`),
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
