//! The effects: parametric models of what a re-test shows beyond the
//! geometric model, each in its own file, below every stage that
//! closes the loop. `diagnose` fits them, `compensate` and `predict` account
//! for them, `report` shows them, `synth` plants them; all through this
//! module, which depends only on `measurement` and `units` (and the full
//! turn of `evaluate::conformance`, for a rotary axis' orders).
//!
//! | kind          | column(s) over the readings                  | parameter                |
//! |---------------|----------------------------------------------|--------------------------|
//! | `reversal`    | +½ moving ↑, −½ moving ↓                      | B (↑ − ↓), µm            |
//! | `scale`       | (x − first target) in m                      | µm/m                     |
//! | `drift`       | time of the reading in h, or in runs         | µm/h, or µm/run          |
//! | `periodic`    | sin(2πx/p), cos(2πx/p) for a scanned period p | amplitude µm, phase      |
//! | `outlier-run` | 1 on the readings of one run, else 0         | offset µm                |
//! | `abbe`        | the angular error ε(x) in µrad / 1000        | offset of the line, mm   |
//!
//! Each kind's file declares, in one place, what the effect is: its
//! parameters (a typed struct, which is also its TOML form), its columns,
//! its value at a reading, its systematic value at a position (what a table
//! or a prediction can take), what it does to a table, the uncertainty of
//! its parameters and its one-sentence explanation ([`Model`], [`Fit`]).
//! Adding a kind is a new file here, a line in the registry below and its
//! synthetic truth (`synth::truth`); the compiler then names every match
//! that must decide something about it (there is no catch-all arm).

pub mod abbe;
pub mod drift;
pub mod file;
pub mod outlier_run;
pub mod periodic;
pub mod reversal;
pub mod scale;
pub mod typed;

use serde::Deserialize;

use crate::measurement::{AxisKind, Direction, Measurement, MeasurementError};
use crate::units::{
    AngleUnit, DeviationUnit, deg_to_millideg, deg2_to_millideg2, mm_to_um, mm2_to_um2, um_to_mm,
};

pub use abbe::Abbe;
pub use drift::Drift;
pub use file::{FileEntry, read_effects, write_effects};
pub use outlier_run::OutlierRun;
pub use periodic::Periodic;
pub use reversal::Reversal;
pub use scale::Scale;
pub use typed::{EffectIn, held_angle};

/// One reading, as the effects see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// Index of its target.
    pub target_index: usize,
    /// Target, in the axis' unit: mm, or ° on a rotary axis.
    pub target: f64,
    /// ↑ or ↓.
    pub direction: Direction,
    /// Run number within its direction.
    pub run: u32,
    /// Index of its run in the order measured.
    pub run_index: usize,
    /// Time from the start of the test, h.
    pub time_h: f64,
}

/// What the effects need to know of the test besides a reading: where the
/// stroke starts (scale is zero there) and the angular profile (Abbe).
#[derive(Clone, Copy, Debug, Default)]
pub struct Line<'a> {
    /// The first target, mm: only a scale error reads it, and a scale error
    /// is looked for on a linear axis only (`diagnose::gates`).
    pub first_target_mm: f64,
    /// The angular error at each target, µrad (Abbe), if given.
    pub angle_urad: Option<&'a [f64]>,
    /// Whether the file records the test's times ([`Reading::time_h`] then
    /// follows them); otherwise a drift is per run.
    pub times_recorded: bool,
    /// One run's mean duration on the clock of [`Reading::time_h`], h
    /// (`cycle::run_h`): a time in runs is `time_h / run_h`.
    pub run_h: f64,
}

impl Line<'_> {
    /// Runs from the start of the test at `time_h` (0 when no run has a duration).
    pub fn runs_at(&self, time_h: f64) -> f64 {
        if self.run_h > 0.0 {
            time_h / self.run_h
        } else {
            0.0
        }
    }
}

/// Which tests a periodic error is in, as a diagnosis fits it: its columns
/// at the readings are the same; against a prediction from a first test they
/// differ by what that prediction carries of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeriodicIn {
    /// The re-test only: a change since the first test (or no first test).
    ReTest,
    /// Both tests: the prediction carries the first test's samples of it,
    /// interpolated between its targets (too far apart to resolve it).
    BothTests,
}

/// The nonlinear part of an effect's shape, fixed before the linear fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// No free shape.
    Fixed(Kind),
    /// A periodic error of this period (mm, or °), in these tests.
    Period(f64, PeriodicIn),
    /// One run: (direction, number).
    Run(Direction, u32),
}

impl Shape {
    /// The kind of effect.
    pub fn kind(self) -> Kind {
        match self {
            Shape::Fixed(kind) => kind,
            Shape::Period(..) => Kind::Periodic,
            Shape::Run(..) => Kind::OutlierRun,
        }
    }
}

/// Context for the sentence a user reads. Its positions are in the axis'
/// unit (mm, or ° on a rotary axis) and its deviations in the effects'
/// deviation unit (µm, or m°, 1/1000 °, on a rotary axis); the sentences say
/// them in mm and µm, or ° and ″ (µrad) ([`Context::position`],
/// [`Context::deviation`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Context {
    /// Linear or rotary: the units of the values below.
    pub kind: AxisKind,
    /// The unit a rotary axis' deviations are said in (″ or µrad).
    pub angle: AngleUnit,
    /// The table's step (mm, or °), if a regular table was applied.
    pub table_step: Option<f64>,
    /// Spacing of the targets (mm, or °), when regular.
    pub target_spacing: Option<f64>,
    /// Expansion coefficient the laser used, ppm/K.
    pub expansion_coefficient_ppm_per_k: Option<f64>,
    /// Material temperature change between the tests, K, if both recorded.
    pub material_change_k: Option<f64>,
    /// Whether the times of the readings are assumed (no recorded duration).
    pub time_assumed: bool,
    /// The first test's mean reversal B̄ (µm, or m°), which the prediction
    /// carries (a reversal found is then the change since that test).
    pub first_test_reversal: Option<f64>,
    /// The re-test's mean reversal B̄ as predicted and as measured (µm, or
    /// m°; the diagnosis' figures): the sentence says these, and the
    /// backlash parameter follows the measured one.
    pub retest_mean_reversal: Option<(f64, f64)>,
}

/// A deviation held in the effects' unit (µm, or m°, 1/1000 °, with an
/// angle `unit`) as a sentence writes it in `unit` with `decimals`:
/// `2.40 µm`, or in arc-seconds `8.64″` (`41.89 µrad`).
pub fn deviation_text(unit: DeviationUnit, value: f64, decimals: usize) -> String {
    format!("{:.decimals$}{}", in_unit(unit, value), unit.suffix())
}

/// A deviation held in the effects' unit (µm, or m° on a rotary axis) in
/// the unit of the axis' positions and readings (mm, or °): a thousandth of
/// it either way.
pub fn deviation_as_position(kind: AxisKind, value: f64) -> f64 {
    match kind {
        AxisKind::Linear => um_to_mm(value),
        AxisKind::Rotary => held_angle(value).0,
    }
}

/// A deviation in the unit of the axis' readings (mm, or °) in the effects'
/// unit (µm, or m°): the inverse of [`deviation_as_position`].
pub fn position_as_deviation(kind: AxisKind, value: f64) -> f64 {
    match kind {
        AxisKind::Linear => mm_to_um(value),
        AxisKind::Rotary => deg_to_millideg(value),
    }
}

/// A variance in the square of the axis' unit (mm², or °²) in the effects'
/// (µm², or m°²).
pub fn variance_as_deviation(kind: AxisKind, value: f64) -> f64 {
    match kind {
        AxisKind::Linear => mm2_to_um2(value),
        AxisKind::Rotary => deg2_to_millideg2(value),
    }
}

/// A deviation held in µm (with an angle `unit`, m°) in `unit`.
fn in_unit(unit: DeviationUnit, value: f64) -> f64 {
    match unit {
        DeviationUnit::Micrometre => value,
        DeviationUnit::Angle(angle) => angle.from_deg(held_angle(value).0),
    }
}

impl Context {
    /// A deviation (µm, or m°) as a sentence writes it ([`deviation_text`],
    /// 2 decimals).
    pub fn deviation(&self, value: f64) -> String {
        deviation_text(self.kind.deviation_unit(self.angle), value, 2)
    }

    /// A deviation (µm, or m°) for a legend label, written by `number` in
    /// the unit the sentences say it in: `2.5 µm`, `9″`.
    pub fn deviation_label(&self, value: f64, number: &dyn Fn(f64) -> String) -> String {
        let unit = self.kind.deviation_unit(self.angle);
        format!("{}{}", number(in_unit(unit, value)), unit.suffix())
    }

    /// A position or a length (mm, or °) for a legend label, written by
    /// `number`: `5 mm`, `180°`.
    pub fn position_label(&self, value: f64, number: &dyn Fn(f64) -> String) -> String {
        format!("{}{}", number(value), self.kind.unit_after_number())
    }

    /// A deviation (µm, or m°) in the axis' position unit ([`deviation_as_position`]).
    pub fn deviation_as_position(&self, value: f64) -> f64 {
        deviation_as_position(self.kind, value)
    }

    /// A position or a length (mm, or °): `18 mm`, `18°`.
    pub fn position(&self, value: f64, decimals: usize) -> String {
        format!("{value:.decimals$}{}", self.kind.unit_after_number())
    }
}

/// What the fit knows that a parameter's uncertainty needs.
#[derive(Clone, Copy, Debug)]
pub struct FitSummary<'a> {
    /// The fitted coefficients of this effect's columns.
    pub coefficients: &'a [f64],
    /// Their standard errors.
    pub errors: &'a [f64],
    /// The stroke, last − first target (mm, or °).
    pub span: f64,
    /// Number of readings.
    pub n: usize,
    /// Spacing of the targets (mm, or °), when regular.
    pub target_spacing: Option<f64>,
    /// Linear or rotary: the unit of the span and the spacing.
    pub kind: AxisKind,
}

/// One parameter as it is shown and saved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameter {
    /// Its key in the effects file and in a linear axis' JSON, with the
    /// linear unit (`B_um`, `period_mm`, `run`): both are written for a
    /// linear axis only. On a rotary axis the key only names the parameter
    /// (among a fit's [`Uncertainty`]); its value and the keys a report
    /// writes come from [`Effect::typed`].
    pub key: &'static str,
    /// Its name in a sentence or a table (`B`, `period`, `run`).
    pub name: &'static str,
    /// The unit of a number on a linear axis, as a reader writes it (`µm`,
    /// `µm/m`), empty for a run.
    pub unit: &'static str,
    /// Its value.
    pub value: ParameterValue,
}

/// A parameter's value: a number in the unit the key names on a linear axis
/// (a rotary axis' µm and mm are m° and °: [`Effect::typed`]), or a run's
/// number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParameterValue {
    /// A measured quantity, in the unit its key names on a linear axis.
    Number(f64),
    /// A run, by its number within its direction.
    Run(u32),
}

impl Parameter {
    /// A measured quantity.
    pub fn number(
        key: &'static str,
        name: &'static str,
        unit: &'static str,
        value: f64,
    ) -> Parameter {
        Parameter {
            key,
            name,
            unit,
            value: ParameterValue::Number(value),
        }
    }
}

/// The one parameter of a kind that has a single number (scale, drift): its
/// key, name and unit, from which the kind's [`Model::parameters`] and
/// [`Model::label`] follow.
struct OneNumber {
    key: &'static str,
    name: &'static str,
    unit: &'static str,
}

impl OneNumber {
    /// [`Model::parameters`]: this parameter with its value.
    fn parameters(&self, value: f64) -> Vec<Parameter> {
        vec![Parameter::number(self.key, self.name, self.unit, value)]
    }

    /// [`Model::label`]: the kind's name, the number and its unit
    /// (`drift 2.00 µm/h`).
    fn label(&self, kind: &str, value: f64, number: &dyn Fn(f64) -> String) -> String {
        format!("{kind} {} {}", number(value), self.unit)
    }
}

/// The standard uncertainty of one parameter, by its key
/// ([`Parameter::key`]: a linear axis' key, the parameter's name on a rotary
/// one), in the parameter's unit.
pub type Uncertainty = (&'static str, f64);

/// What an effect does to a compensation table (`compensate::plan`).
#[derive(Clone, Debug, PartialEq)]
pub enum TableRole {
    /// A direction-dependent offset B: a bidirectional table, or the
    /// backlash parameter where the controller takes no such table.
    Bidirectional {
        /// B = ↑ − ↓ (µm, or m° on a rotary axis, as [`Reversal::b`]).
        b: f64,
    },
    /// An error the table's points must follow: put back at each point, the
    /// points at most `finest_step` apart.
    AtPoints {
        /// The largest step that still follows it (mm, or °).
        finest_step: f64,
    },
    /// Taken out of the table; the note says why.
    TakenOut {
        /// What the user reads.
        note: String,
    },
    /// Not a table's business; the note says what to do instead.
    NotATable {
        /// What the user reads.
        note: String,
    },
}

/// What an effect with its parameters is: the part every user of an effect
/// asks of it.
pub trait Model {
    /// The effect's contribution to one reading: µm, or m° on a rotary axis.
    fn value(&self, reading: &Reading, line: &Line<'_>) -> f64;

    /// The effect's systematic part at `x` (mm, or °) moving in
    /// `direction` (µm, or m°): what a table or a prediction can account for
    /// (`predict --effects`). `None` for what is not systematic in position.
    /// `first_target_mm` is [`Line::first_target_mm`].
    fn systematic(&self, x: f64, direction: Direction, first_target_mm: f64) -> Option<f64>;

    /// What it does to a compensation table.
    fn in_table(&self) -> TableRole;

    /// What it is physically and what to do about it at the machine, in one sentence.
    fn explanation(&self, context: &Context) -> String;

    /// The parameters, in the order they are shown and saved.
    fn parameters(&self) -> Vec<Parameter>;

    /// A short legend label with the fitted parameters, each number written
    /// by `number` (the plot's own tick format) in the unit `context` says
    /// it in (a rotary axis' deviations in ″ or µrad, its positions in °;
    /// the kinds looked for on a linear axis only say mm and µm).
    fn label(&self, context: &Context, number: &dyn Fn(f64) -> String) -> String;

    /// A check beyond the types, for an effect read from a file.
    fn check(&self) -> Result<(), String> {
        Ok(())
    }
}

/// How a kind is fitted: the part `diagnose` asks of it.
pub trait Fit: Model + Sized {
    /// The name used in JSON and TOML.
    const NAME: &'static str;

    /// Whether it depends on position only (and so competes with the
    /// position-dependent systematic error in a lack-of-fit test).
    const POSITIONAL: bool;

    /// Its columns over the readings for a shape of its kind.
    fn columns(shape: Shape, readings: &[Reading], line: &Line<'_>) -> Vec<Vec<f64>>;

    /// The effect from a shape of its kind and its fitted coefficients.
    fn from_fit(shape: Shape, coefficients: &[f64], line: &Line<'_>) -> Self;

    /// The standard uncertainty of its parameters, and caveats.
    fn uncertainty(&self, fit: &FitSummary<'_>) -> (Vec<Uncertainty>, Vec<String>) {
        let key = self.parameters()[0].key;
        (vec![(key, fit.errors[0])], Vec::new())
    }
}

/// The registry: one line a kind, in the order they are tried and listed.
macro_rules! registry {
    ($($variant:ident => $ty:ty),* $(,)?) => {
        /// The kinds, in the order they are tried and listed.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Kind {
            $(
                #[doc = concat!("See [`", stringify!($ty), "`].")]
                $variant,
            )*
        }

        /// An effect with its fitted parameters.
        #[derive(Clone, Debug, PartialEq)]
        pub enum Effect {
            $(
                #[doc = concat!("See [`", stringify!($ty), "`].")]
                $variant($ty),
            )*
        }

        impl Kind {
            /// All kinds.
            pub const ALL: &'static [Kind] = &[$(Kind::$variant),*];

            /// The name used in JSON and TOML.
            pub fn name(self) -> &'static str {
                match self {
                    $(Kind::$variant => <$ty as Fit>::NAME,)*
                }
            }

            /// Whether the effect depends on position only (and so competes
            /// with the position-dependent systematic error in a lack-of-fit test).
            pub fn is_positional(self) -> bool {
                match self {
                    $(Kind::$variant => <$ty as Fit>::POSITIONAL,)*
                }
            }
        }

        impl Effect {
            /// The kind.
            pub fn kind(&self) -> Kind {
                match self {
                    $(Effect::$variant(_) => Kind::$variant,)*
                }
            }

            /// The effect as its kind's [`Model`].
            pub fn model(&self) -> &dyn Model {
                match self {
                    $(Effect::$variant(effect) => effect,)*
                }
            }

            /// The effect from a shape and its fitted coefficients.
            pub fn from_fit(shape: Shape, coefficients: &[f64], line: &Line<'_>) -> Effect {
                match shape.kind() {
                    $(Kind::$variant => Effect::$variant(<$ty>::from_fit(shape, coefficients, line)),)*
                }
            }

            /// The standard uncertainty of its parameters, and caveats.
            pub fn uncertainty(&self, fit: &FitSummary<'_>) -> (Vec<Uncertainty>, Vec<String>) {
                match self {
                    $(Effect::$variant(effect) => effect.uncertainty(fit),)*
                }
            }
        }

        /// The columns of an effect of a given shape over the readings.
        pub fn columns(shape: Shape, readings: &[Reading], line: &Line<'_>) -> Vec<Vec<f64>> {
            match shape.kind() {
                $(Kind::$variant => <$ty>::columns(shape, readings, line),)*
            }
        }

        /// An `[[effect]]` of a file, by its `kind`.
        #[derive(Deserialize)]
        #[serde(tag = "kind", rename_all = "kebab-case")]
        enum Entry {
            $($variant(file::Tested<$ty>),)*
        }

        impl From<Entry> for Effect {
            fn from(entry: Entry) -> Effect {
                match entry {
                    $(Entry::$variant(tested) => Effect::$variant(tested.0),)*
                }
            }
        }
    };
}

registry! {
    Reversal => Reversal,
    Scale => Scale,
    Drift => Drift,
    Periodic => Periodic,
    OutlierRun => OutlierRun,
    Abbe => Abbe,
}

impl Effect {
    /// The effect's contribution to one reading ([`Model::value`]).
    pub fn value(&self, reading: &Reading, line: &Line<'_>) -> f64 {
        self.model().value(reading, line)
    }

    /// The effect's systematic part at `x` moving in `direction`
    /// ([`Model::systematic`]).
    pub fn systematic(&self, x: f64, direction: Direction, first_target_mm: f64) -> Option<f64> {
        self.model().systematic(x, direction, first_target_mm)
    }

    /// The measurement with this effect added to every reading, at the
    /// times `times_h` (`[run][target]`, hours, as `cycle::reading_times_h`
    /// gives them): a known effect put into a measured test, defined by the
    /// same [`Model::value`] the diagnosis fits (tests on real files).
    pub fn added_to(
        &self,
        measurement: &Measurement,
        times_h: &[Vec<f64>],
    ) -> Result<Measurement, MeasurementError> {
        let targets = measurement.targets();
        let line = Line {
            first_target_mm: targets.first().copied().unwrap_or(0.0),
            angle_urad: None,
            times_recorded: measurement.metadata.duration_s().is_some(),
            run_h: crate::cycle::run_h(times_h),
        };
        let runs = measurement.runs();
        let kind = measurement.kind();
        measurement.map_readings(|run, target_index, value| {
            // Runs are unique by direction and number (`Measurement`'s invariant).
            let run_index = runs
                .iter()
                .position(|r| r.direction == run.direction && r.number == run.number)
                .unwrap_or(0);
            let reading = Reading {
                target_index,
                target: targets[target_index],
                direction: run.direction,
                run: run.number,
                run_index,
                time_h: times_h
                    .get(run_index)
                    .and_then(|run_times| run_times.get(target_index))
                    .copied()
                    .unwrap_or(0.0),
            };
            value + deviation_as_position(kind, self.value(&reading, &line))
        })
    }

    /// What it does to a compensation table.
    pub fn in_table(&self) -> TableRole {
        self.model().in_table()
    }

    /// What it is physically and what to do about it at the machine, in one sentence.
    pub fn explanation(&self, context: &Context) -> String {
        self.model().explanation(context)
    }

    /// The parameters, in the order they are shown and saved.
    pub fn parameters(&self) -> Vec<Parameter> {
        self.model().parameters()
    }
}

/// The columns of a single-column effect: `f` of each reading.
fn column(readings: &[Reading], f: impl Fn(&Reading) -> f64) -> Vec<Vec<f64>> {
    vec![readings.iter().map(f).collect()]
}

#[cfg(test)]
mod tests;
