//! The `--json` wire format and the terminal summary of `axcomp convert`.
//!
//! # Wire format
//!
//! ```text
//! { "controller": "tnc640", "file": "X.COM", "axis": "X", "also": ["U"],
//!   "mode": "mean" | "bidirectional", "positions_mm": [...], "count": 16,
//!   "start_mm": 0.0, "step_mm": 50.0 | null, "reference_mm": 0.0,
//!   "values_um": {"mean": [...]} | {"up": [...], "down": [...]},
//!   "suggested_backlash_um": 3.2 | null,
//!   "backlash_parameter": {"name": "MD32450 $MA_BACKLASH[0,X1]", "value": 0.0032,
//!                          "unit": "mm" | "inch", "sign": "…", "note": "…" | null} | null,
//!   "backlash_note": "…" | null, "activation": "…", "file_unit": "mm" | "inch",
//!   "effects": ["…what --effects changed…"], "notes": ["…"],
//!   "update": {…} | null (`report::update`), "warnings": [...] }
//! ```
//! Values are the axis error actual − target in µm, zero at the reference,
//! before each controller's own sign convention (see `formats/`).
//! `suggested_backlash_um` is −B̄ (mean mode); `backlash_parameter` is the
//! same reversal as the value to type into the controller, in its unit
//! (`value` in `unit`), and is null where the controller has no parameter
//! that works next to the table (LinuxCNC), when `backlash_note` says why.
//!
//! A rotary axis' object carries its units in its keys: `file_unit`
//! `deg`, `positions_deg`, `start_deg`, `step_deg`, `reference_deg`,
//! `values_arcsec`, `suggested_backlash_arcsec`; its backlash is a
//! `backlash_note` (the parameters' rotary inputs are degrees). The two
//! forms are two wire structs (`LinearTableJson`, `RotaryTableJson`),
//! whose fields are typed in the unit their key names.

use std::fmt::Write;

use serde::Serialize;

use crate::compensate::{CompensationTable, TableValues};
use crate::emit::BacklashAdvice;
use crate::measurement::AxisKind;
use crate::report::format::{inch_text_places, um};
use crate::units::{Arcsec, Deg, LengthUnit, Mm, Um, um_to_mm};

/// The table's values, in `V` (µm, or ″ on a rotary axis).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ValuesJson<V = f64> {
    /// One column.
    Mean {
        /// Per point.
        mean: Vec<V>,
    },
    /// One column per direction.
    Bidirectional {
        /// Moving +.
        up: Vec<V>,
        /// Moving −.
        down: Vec<V>,
    },
}

impl<V: Copy> ValuesJson<V> {
    /// The values of `table` (mm, or ° on a rotary axis), typed by `unit` and
    /// converted by `shown`.
    fn of<P>(table: &TableValues, unit: fn(f64) -> P, shown: fn(P) -> V) -> ValuesJson<V> {
        let column = |values: &[f64]| values.iter().map(|&v| shown(unit(v))).collect();
        match table {
            TableValues::Mean(values) => ValuesJson::Mean {
                mean: column(values),
            },
            TableValues::Bidirectional { up, down } => ValuesJson::Bidirectional {
                up: column(up),
                down: column(down),
            },
        }
    }

    /// The same as bare numbers, for the terminal.
    fn numbers(&self, number: fn(V) -> f64) -> ValuesJson<f64> {
        let column = |values: &[V]| values.iter().map(|&v| number(v)).collect();
        match self {
            ValuesJson::Mean { mean } => ValuesJson::Mean { mean: column(mean) },
            ValuesJson::Bidirectional { up, down } => ValuesJson::Bidirectional {
                up: column(up),
                down: column(down),
            },
        }
    }
}

/// Declares the wire form of a table's points and values in one pair of
/// units: each field's name is its JSON key, its type the unit the key names.
macro_rules! table_json {
    (
        $(#[$doc:meta])*
        $name:ident<$position:ty, $value:ty> {
            $positions:ident, $start:ident, $step:ident, $reference:ident, $values:ident,
            $backlash:ident $(,)?
        }
    ) => {
        $(#[$doc])*
        #[derive(Clone, Debug, PartialEq, Serialize)]
        pub struct $name {
            /// Compensation points.
            pub $positions: Vec<$position>,
            /// Number of points.
            pub count: usize,
            /// First point.
            pub $start: $position,
            /// Spacing, or `null` when uneven.
            pub $step: Option<$position>,
            /// Where the table is zero.
            pub $reference: $position,
            /// The values.
            pub $values: ValuesJson<$value>,
            /// Suggested backlash parameter (mean mode): −B̄.
            pub $backlash: Option<$value>,
        }

        impl $name {
            /// The points and values of `table` (mm, or ° on a rotary axis),
            /// typed by `unit`, the values converted by `shown`.
            fn of(
                table: &CompensationTable,
                unit: fn(f64) -> $position,
                shown: fn($position) -> $value,
            ) -> $name {
                $name {
                    $positions: table.positions.iter().map(|&p| unit(p)).collect(),
                    count: table.positions.len(),
                    $start: unit(table.positions[0]),
                    $step: table.regular_step().map(unit),
                    $reference: unit(table.reference),
                    $values: ValuesJson::of(&table.values, unit, shown),
                    $backlash: table.suggested_backlash.map(|b| shown(unit(b))),
                }
            }

            fn numbers(&self) -> TableNumbers {
                TableNumbers {
                    positions: self.$positions.iter().map(|p| p.0).collect(),
                    count: self.count,
                    start: self.$start.0,
                    step: self.$step.map(|s| s.0),
                    reference: self.$reference.0,
                    values: self.$values.numbers(|v| v.0),
                    suggested_backlash: self.$backlash.map(|b| b.0),
                }
            }
        }
    };
}

table_json!(
    /// A linear axis' table: points in mm, values in µm.
    LinearTableJson<Mm, Um> {
        positions_mm, start_mm, step_mm, reference_mm, values_um, suggested_backlash_um,
    }
);

table_json!(
    /// A rotary axis' table: points in °, values in ″.
    RotaryTableJson<Deg, Arcsec> {
        positions_deg, start_deg, step_deg, reference_deg, values_arcsec,
        suggested_backlash_arcsec,
    }
);

/// A table's points and values in the units of its axis, the keys naming them.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum TableJson {
    /// mm and µm.
    Linear(LinearTableJson),
    /// ° and ″.
    Rotary(RotaryTableJson),
}

impl TableJson {
    /// The points and values of `table`, in the units of its axis.
    pub fn of(table: &CompensationTable) -> TableJson {
        match table.kind {
            AxisKind::Linear => TableJson::Linear(LinearTableJson::of(table, Mm, Mm::to_um)),
            AxisKind::Rotary => TableJson::Rotary(RotaryTableJson::of(table, Deg, Deg::to_arcsec)),
        }
    }

    /// The points and values as the terminal prints them (mm or °, µm or ″).
    pub fn numbers(&self) -> TableNumbers {
        match self {
            TableJson::Linear(table) => table.numbers(),
            TableJson::Rotary(table) => table.numbers(),
        }
    }
}

/// A table's points and values as bare numbers in their units (mm or °,
/// µm or ″), for the terminal.
#[derive(Clone, Debug, PartialEq)]
pub struct TableNumbers {
    /// Compensation points.
    pub positions: Vec<f64>,
    /// Number of points.
    pub count: usize,
    /// First point.
    pub start: f64,
    /// Spacing, or `None` when uneven.
    pub step: Option<f64>,
    /// Where the table is zero.
    pub reference: f64,
    /// The values.
    pub values: ValuesJson<f64>,
    /// −B̄ (mean mode).
    pub suggested_backlash: Option<f64>,
}

/// A controller's backlash parameter and the value to type into it.
#[derive(Clone, Debug, Serialize)]
pub struct BacklashParameterJson {
    /// The parameter, in the controller's words.
    pub name: String,
    /// The value to type, in `unit`, rounded to the controller's input resolution.
    pub value: f64,
    /// `mm` or `inch`: the unit the controller reads the parameter in.
    pub unit: &'static str,
    /// What a positive value means.
    pub sign: String,
    /// What else to know, or null.
    pub note: Option<String>,
    /// The value as text with the controller's decimals (`0.0032`), for the terminal.
    #[serde(skip)]
    pub value_text: String,
}

/// The whole `convert --json` object; a rotary axis' ([`TableJson`]) in °
/// and ″ under `_deg` and `_arcsec` keys (module doc).
#[derive(Clone, Debug, Serialize)]
pub struct ConvertJson {
    /// Linear or rotary: the unit of the values and of the keys.
    #[serde(skip)]
    pub kind: AxisKind,
    /// The unit of the positions and values in the file written: `mm` or
    /// `inch` (the controller's, from the machine profile; for a Fagor 8055
    /// without one, the test's).
    pub file_unit: &'static str,
    /// `--controller` name.
    pub controller: &'static str,
    /// The file written.
    pub file: String,
    /// The compensated axis.
    pub axis: String,
    /// Coupled axes that got the same table.
    pub also: Vec<String>,
    /// `mean` or `bidirectional`.
    pub mode: &'static str,
    /// The points and values, in the axis' units (`positions_mm`, …,
    /// `values_um`, `suggested_backlash_um`, or their `_deg` and `_arcsec`
    /// forms).
    #[serde(flatten)]
    pub table: TableJson,
    /// The same as the controller's parameter, in its unit; null without a
    /// suggestion or where the controller has none (then `backlash_note`).
    pub backlash_parameter: Option<BacklashParameterJson>,
    /// Why the controller has no backlash parameter for the table, and what to do instead.
    pub backlash_note: Option<String>,
    /// How to activate the table on the controller.
    pub activation: String,
    /// What `--effects` changed, as sentences (empty without it).
    pub effects: Vec<String>,
    /// What the table must say of itself (a one-direction test), as sentences.
    pub notes: Vec<String>,
    /// What an update (`--existing`) kept and changed, or `None`.
    pub update: Option<super::update::UpdateJson>,
    /// Warnings from reading and evaluating.
    pub warnings: Vec<String>,
    /// The decimals of the file's lengths (an inch table is shown with them).
    #[serde(skip)]
    pub file_decimals: usize,
}

impl ConvertJson {
    /// Builds the wire object of `table`, in its axis' units (values in ″ on a rotary axis).
    pub fn new(
        controller: &'static str,
        file: String,
        table: &CompensationTable,
        also: Vec<String>,
        activation: String,
        warnings: Vec<String>,
    ) -> ConvertJson {
        ConvertJson {
            kind: table.kind,
            file_unit: match table.kind {
                AxisKind::Linear => LengthUnit::Millimetre.as_str(),
                AxisKind::Rotary => "deg",
            },
            controller,
            file,
            axis: table.axis.clone(),
            also,
            mode: table.values.mode().as_str(),
            table: TableJson::of(table),
            backlash_parameter: None,
            backlash_note: None,
            activation,
            effects: Vec::new(),
            notes: Vec::new(),
            update: None,
            warnings,
            file_decimals: 6,
        }
    }

    /// Sets what the controller does with the suggested backlash
    /// ([`crate::emit::Controller::backlash_parameter`]). A rotary axis'
    /// parameters take degrees, which the advice (in lengths) does not say:
    /// it gets a note with the value in ° instead (Fanuc's advice counts
    /// detection units of the axis, ° on a rotary one: kept).
    pub fn set_backlash(&mut self, advice: BacklashAdvice) {
        if let (TableJson::Rotary(table), false) = (&self.table, self.controller == "fanuc") {
            let backlash_arcsec = table.suggested_backlash_arcsec.unwrap_or_default().0;
            self.backlash_parameter = None;
            self.backlash_note = Some(format!(
                "a rotary axis: enter −B̄ = {backlash_arcsec:.2}″ = {:.4}° in the controller's backlash parameter for the axis, whose rotary input is degrees, or write the table with --mode bidirectional",
                backlash_arcsec / 3600.0
            ));
            return;
        }
        match advice {
            BacklashAdvice::Parameter(parameter) => {
                self.backlash_parameter = Some(BacklashParameterJson {
                    value_text: parameter.value_text(),
                    name: parameter.name,
                    value: parameter.value,
                    unit: parameter.unit.as_str(),
                    sign: parameter.sign,
                    note: parameter.note,
                });
                self.backlash_note = None;
            }
            BacklashAdvice::NoParameter(note) => {
                self.backlash_parameter = None;
                self.backlash_note = Some(note);
            }
        }
    }

    /// The terminal summary: what was written, the table, how to activate it.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        let table = self.table.numbers();
        let (position_unit, value_unit) = match self.kind {
            AxisKind::Linear => (" mm", "µm"),
            AxisKind::Rotary => ("°", "″"),
        };
        let step = table.step.map_or("uneven spacing".to_string(), |s| {
            format!("step {s}{position_unit}")
        });
        let also = if self.also.is_empty() {
            String::new()
        } else {
            format!(" (also {})", self.also.join(", "))
        };
        // An update referred to a point where the old table was not zero keeps that value there.
        let zero = match &self.update {
            Some(update) if !update.zero_at_reference => "as it was",
            _ => "zero",
        };
        let _ = writeln!(
            out,
            "Wrote {} for {}: {} table of axis {}{also}, {} points from {} to {}{position_unit}, {step}, {zero} at {}{position_unit}",
            self.file,
            self.controller,
            self.mode,
            self.axis,
            table.count,
            table.start,
            table.positions[table.count - 1],
            table.reference
        );
        for effect in &self.effects {
            let _ = writeln!(out, "Effect: {effect}");
        }
        for line in self.update.iter().flat_map(|u| u.lines()) {
            let _ = writeln!(out, "Update: {line}");
        }
        for note in &self.notes {
            let _ = writeln!(out, "Note: {note}");
        }
        if let Some(backlash_um) = table.suggested_backlash {
            match (&self.backlash_parameter, &self.backlash_note) {
                (Some(parameter), _) => {
                    let _ = writeln!(
                        out,
                        "Backlash parameter: {} = {} {} (−B̄ = {backlash_um:.2} {value_unit})\n  sign: {}",
                        parameter.name, parameter.value_text, parameter.unit, parameter.sign
                    );
                    if let Some(note) = &parameter.note {
                        let _ = writeln!(out, "  note: {note}");
                    }
                    if parameter.unit != self.file_unit && self.kind == AxisKind::Linear {
                        let _ = writeln!(
                            out,
                            "  unit: the parameter is in {} (the machine's unit) and the table file in {} (the unit its format is written in): both are right as printed",
                            parameter.unit, self.file_unit
                        );
                    }
                }
                (None, Some(note)) => {
                    let _ = writeln!(out, "Backlash: {note}");
                }
                (None, None) => {
                    let _ = writeln!(
                        out,
                        "Reversal left by the mean table: −B̄ = {backlash_um:.2} {value_unit} (set the controller's backlash parameter to it, in the controller's unit)"
                    );
                }
            }
        }
        let _ = writeln!(
            out,
            "\nCompensation table [{value_unit}] (axis error actual − target, zero at the reference{})",
            self.update.as_ref().map_or("", |u| u.legend)
        );
        let position_header = format!("position {}", position_unit.trim_start());
        if self.file_unit == LengthUnit::Inch.as_str() {
            return self.inch_table(out, &table);
        }
        match &table.values {
            ValuesJson::Mean { mean } => {
                let _ = writeln!(out, "{position_header:>12}  {:>9}", "value");
                for (p, v) in table.positions.iter().zip(mean) {
                    let mark = self.row_mark(*p);
                    let _ = writeln!(out, "{p:>12}  {:>9}{mark}", um(Some(*v)));
                }
            }
            ValuesJson::Bidirectional { up, down } => {
                let _ = writeln!(out, "{position_header:>12}  {:>9}  {:>9}", "↑", "↓");
                for ((p, u), d) in table.positions.iter().zip(up).zip(down) {
                    let mark = self.row_mark(*p);
                    let _ = writeln!(
                        out,
                        "{p:>12}  {:>9}  {:>9}{mark}",
                        um(Some(*u)),
                        um(Some(*d))
                    );
                }
            }
        }
        let _ = writeln!(out, "\nActivation:\n{}", self.activation);
        out
    }

    /// How an update's row came about (`kept`, `new`, or nothing).
    fn row_mark(&self, position_mm: f64) -> &'static str {
        self.update.as_ref().map_or("", |u| u.row_mark(position_mm))
    }

    /// The table of an inch file: positions and values in inches, as the
    /// file holds them and the controller shows them, beside the µm.
    fn inch_table(&self, mut out: String, table: &TableNumbers) -> String {
        let inch = |mm: f64| inch_text_places(LengthUnit::Inch.from_mm(mm), self.file_decimals);
        let _ = writeln!(
            out,
            "The file is in inches (the controller's unit); µm beside them."
        );
        let columns: Vec<(&str, &Vec<f64>)> = match &table.values {
            ValuesJson::Mean { mean } => vec![("value", mean)],
            ValuesJson::Bidirectional { up, down } => vec![("↑", up), ("↓", down)],
        };
        let _ = write!(out, "{:>12}  {:>12}", "position in", "position mm");
        for (name, _) in &columns {
            let _ = write!(
                out,
                "  {:>10}  {:>9}",
                format!("{name} in"),
                format!("{name} µm")
            );
        }
        out.push('\n');
        for (index, p) in table.positions.iter().enumerate() {
            let _ = write!(out, "{:>12}  {p:>12}", inch(*p));
            for (_, values) in &columns {
                let value_um = values[index];
                let _ = write!(
                    out,
                    "  {:>10}  {:>9}",
                    inch(um_to_mm(value_um)),
                    um(Some(value_um))
                );
            }
            out.push_str(self.row_mark(*p));
            out.push('\n');
        }
        let _ = writeln!(out, "\nActivation:\n{}", self.activation);
        out
    }
}
