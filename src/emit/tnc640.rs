//! Heidenhain TNC 640 nonlinear axis error compensation table (`.COM`): writer and reader.
//!
//! Spec and sources: `formats/tnc640/README.md`. \[seen\] Kadlečík (2019) Fig. 29 (the
//! table the seed's after-test on a real TNC 640 used), the MANUALplus 620
//! technical manual p.716/718 (same NC family: AXISPOS with respect to the
//! machine datum, BACKLASH with the values measured in the negative
//! direction, one column per axis of CfgAxes/axisList), and the generic
//! Heidenhain table envelope (`BEGIN <NAME>.<SUFFIX> MM`, fixed-width columns
//! sliced at the header's offsets, `[END]`). \[reconstructed\] the column
//! widths (NR 5, others 14, as the seed author's tool writes them), CRLF line
//! ends, and BACKLASH as absolute ↓ values.
//!
//! Numbers carry an explicit sign: AXISPOS with minimal digits (`+100`,
//! `+12.5`), values with 4 decimals (`-0.0023`), as Fig. 29 shows. The value
//! is the mean measured deviation (actual − target), not negated; Kadlečík's (2019)
//! after-test confirms the sign (A 9.7 µm → 2.3 µm).

use crate::compensate::cross_axis::CrossAxisTable;
use crate::compensate::{CompensationTable, TableValues};
use crate::emit::heidenhain::{BACKLASH_DECIMALS, BACKLASH_SIGN, Envelope, empty_cell};
use crate::emit::{
    BacklashAdvice, BacklashParameter, EmitError, EmitOptions, minimal, signed_fixed,
    signed_minimal,
};
use crate::error::ParseError;
use crate::measurement::Direction;
use crate::read::text;
use crate::units::LengthUnit;

/// Width of the NR column.
const NR_WIDTH: usize = 5;
/// Width of every other column.
const COLUMN_WIDTH: usize = 14;
/// Decimals of values (0.1 µm).
const VALUE_DECIMALS: usize = 4;

/// The axis columns of the file: the machine's CfgAxes/axisList when the
/// profile gives it (the file must have exactly those columns), else the
/// written axes.
fn columns(options: &EmitOptions) -> Vec<String> {
    if options.tnc640_columns.is_empty() {
        options
            .axes
            .iter()
            .map(|a| a.tnc640_column.clone())
            .collect()
    } else {
        options.tnc640_columns.clone()
    }
}

/// A `.COM` table as its columns: AXISPOS, BACKLASH, and one column per
/// axis, each cell a value or empty. What [`write`] renders, and what an
/// update keeps of a machine's table (one active table per axis holds the
/// axis's own column and its cross-axis columns together, MANUALplus 620
/// TM p.718).
#[derive(Clone, Debug, PartialEq)]
pub struct ComTable {
    /// Compensation points, mm.
    pub positions_mm: Vec<f64>,
    /// BACKLASH per point (empty cells `None`).
    pub backlash: Vec<Option<f64>>,
    /// The axis columns: name and a cell per point.
    pub columns: Vec<(String, Vec<Option<f64>>)>,
}

impl ComTable {
    /// The column `name`, added empty after the others when missing.
    fn column_mut(&mut self, name: &str) -> &mut Vec<Option<f64>> {
        let index = match self
            .columns
            .iter()
            .position(|(n, _)| n.eq_ignore_ascii_case(name))
        {
            Some(index) => index,
            None => {
                self.columns
                    .push((name.to_string(), vec![None; self.positions_mm.len()]));
                self.columns.len() - 1
            }
        };
        &mut self.columns[index].1
    }

    /// The columns other than `written` that hold values.
    fn filled_others(&self, written: &[String]) -> Vec<String> {
        self.columns
            .iter()
            .filter(|(name, cells)| {
                !written.iter().any(|w| w.eq_ignore_ascii_case(name))
                    && cells.iter().any(Option::is_some)
            })
            .map(|(name, _)| name.clone())
            .collect()
    }

    /// The columns in the machine's order (`tnc640_columns`) when given:
    /// refused when a filled column is not the machine's.
    fn in_machine_order(mut self, options: &EmitOptions) -> Result<ComTable, EmitError> {
        if options.tnc640_columns.is_empty() {
            return Ok(self);
        }
        let machine = &options.tnc640_columns;
        if let Some((name, _)) = self
            .columns
            .iter()
            .find(|(name, cells)| !machine.contains(name) && cells.iter().any(Option::is_some))
        {
            return Err(EmitError::Profile(format!(
                "axis column {name:?} is not among the machine's TNC 640 columns {machine:?}"
            )));
        }
        let n = self.positions_mm.len();
        let columns = machine
            .iter()
            .map(|name| {
                let cells = self
                    .columns
                    .iter()
                    .position(|(c, _)| c == name)
                    .map_or_else(|| vec![None; n], |i| std::mem::take(&mut self.columns[i].1));
                (name.clone(), cells)
            })
            .collect();
        self.columns = columns;
        Ok(self)
    }

    /// The file's text: `BEGIN name MM`, the header, the rows, `[END]`, CRLF.
    pub fn render(&self, name: &str) -> String {
        let mut out = String::new();
        let mut line = |text: String| {
            out.push_str(text.trim_end());
            out.push_str("\r\n");
        };
        line(format!("BEGIN {name} MM"));
        let mut header = format!(
            "{:<NR_WIDTH$}{:<COLUMN_WIDTH$}{:<COLUMN_WIDTH$}",
            "NR", "AXISPOS", "BACKLASH"
        );
        for (column, _) in &self.columns {
            header.push_str(&format!("{column:<COLUMN_WIDTH$}"));
        }
        line(header);
        let cell = |value: Option<f64>| {
            value.map_or_else(String::new, |v| signed_fixed(v, VALUE_DECIMALS))
        };
        for (index, position_mm) in self.positions_mm.iter().enumerate() {
            let mut row = format!(
                "{:<NR_WIDTH$}{:<COLUMN_WIDTH$}{:<COLUMN_WIDTH$}",
                index,
                signed_minimal(*position_mm, 4),
                cell(self.backlash[index])
            );
            for (_, cells) in &self.columns {
                row.push_str(&format!("{:<COLUMN_WIDTH$}", cell(cells[index])));
            }
            line(row);
        }
        line("[END]".to_string());
        out
    }
}

/// The `.COM` of `table` with the written axes' columns filled.
fn com_table(table: &CompensationTable, options: &EmitOptions) -> Result<ComTable, EmitError> {
    let columns = columns(options);
    for axis in &options.axes {
        if !columns.contains(&axis.tnc640_column) {
            return Err(EmitError::Profile(format!(
                "axis column {:?} is not among the machine's TNC 640 columns {columns:?}",
                axis.tnc640_column
            )));
        }
    }
    let up = table.values.for_direction(Direction::Up);
    let backlash = match &table.values {
        TableValues::Mean(_) => vec![None; up.len()],
        TableValues::Bidirectional { down, .. } => down.iter().copied().map(Some).collect(),
    };
    Ok(ComTable {
        positions_mm: table.positions.clone(),
        backlash,
        columns: columns
            .into_iter()
            .map(|column| {
                let written = options.axes.iter().any(|a| a.tnc640_column == column);
                let cells = up.iter().map(|v| written.then_some(*v)).collect();
                (column, cells)
            })
            .collect(),
    })
}

/// Writes the `.COM` table.
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    Ok(com_table(table, options)?.render(&options.table_name))
}

/// The new table of the axis in place of `existing` (the axis's `.COM` on
/// the control): the axis's column and BACKLASH from `table`, every other
/// filled column (a cross-axis column of the same table axis) kept. Those
/// are functions of the same points, so the points must be the existing
/// table's.
pub fn update(
    existing: &str,
    table: &CompensationTable,
    options: &EmitOptions,
) -> Result<String, EmitError> {
    let Ok(old) = parse(existing) else {
        return write(table, options);
    };
    let written: Vec<String> = options
        .axes
        .iter()
        .map(|a| a.tnc640_column.clone())
        .collect();
    let others = old.filled_others(&written);
    if others.is_empty() {
        return write(table, options);
    }
    same_points(&old.positions_mm, &table.positions, &others)?;
    let mut new = com_table(table, options)?;
    for name in &others {
        let cells = old
            .columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, c)| c.clone());
        *new.column_mut(name) = cells.unwrap_or_default();
    }
    Ok(new.in_machine_order(options)?.render(&options.table_name))
}

/// Refuses a table whose points are not `old`'s: the kept columns `others` hold values at those.
fn same_points(old: &[f64], new: &[f64], others: &[String]) -> Result<(), EmitError> {
    let same = old.len() == new.len() && old.iter().zip(new).all(|(a, b)| (a - b).abs() < 0.5e-4);
    if same {
        return Ok(());
    }
    let range = |p: &[f64]| {
        format!(
            "{} points {}…{} mm",
            p.len(),
            minimal(p[0], 4),
            minimal(p[p.len() - 1], 4)
        )
    };
    Err(EmitError::Profile(format!(
        "the existing table also holds column {} at its own points ({}), and the new table has {}: the TNC 640 has one active table per axis, so give the existing points (--start, --step, --count)",
        others.join(", "),
        range(old),
        range(new)
    )))
}

/// The `config.cma` line that activates the table: its file name entered in
/// the column of the axis it depends on, `*` in ACTIVE (MANUALplus 620 TM p.718).
pub fn activation(file_name: &str, options: &EmitOptions) -> String {
    let column = options
        .axes
        .first()
        .map_or("X", |a| a.tnc640_column.as_str());
    format!(
        "config.cma: a line with {file_name} in column {column} and * in column ACTIVE, e.g.\n{:<5}{:<8}{column}\n{:<5}{:<8}{file_name}",
        "NR", "ACTIVE", "0", "*"
    )
}

/// The backlash parameter for the reversal a mean table leaves.
///
/// \[seen\] MANUALplus 620 technical manual (01/2012) §6.10.1 p.707–708,
/// the TNC 640's NC family: `backLash` (MP 401802) in `CfgAxisComp` of the
/// axis's parameter set, "added to the position value at every reversal of
/// direction (even if it results from nonlinear axis-error compensation)",
/// so it acts next to the `.COM` table; `filterTime` (401805) is the time to
/// traverse it. \[reconstructed\] the same key on the TNC 640 (its
/// configuration editor has the same CfgAxisComp object).
pub fn backlash_parameter(backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
    let axes: Vec<&str> = options
        .axes
        .iter()
        .map(|axis| axis.tnc640_column.as_str())
        .collect();
    BacklashAdvice::Parameter(BacklashParameter::new(
        format!(
            "CfgAxisComp/backLash (MP 401802) of axis {}",
            axes.join(", ")
        ),
        backlash_mm,
        LengthUnit::Millimetre,
        BACKLASH_DECIMALS,
        BACKLASH_SIGN,
        Some(
            "filterTime (MP 401805) sets how fast it is traversed; or write the table with --mode bidirectional, which puts the ↓ values in the BACKLASH column instead"
                .to_string(),
        ),
    ))
}

/// Writes a cross-axis table: the `.COM` of the table axis (name it
/// `options.table_name`, e.g. `X.COM`) with the values in the column of the
/// axis they move (`options.axes`, e.g. Y), "[axis in column] = F(axis in
/// whose .CMA column the .COM is entered)" (MANUALplus 620 TM p.716/718).
/// The value is the column axis's error, not negated, as the axis's own
/// column (module doc).
///
/// An axis has one active table (p.718), so the file is the table axis's
/// whole table: `existing` (its `.COM` on the control) with every column
/// kept and this one set, on its points; without it the table axis's own
/// column (`table_column`) is 0 (no positioning compensation), never left out.
pub fn write_cross_axis(
    cross: &CrossAxisTable,
    table_column: &str,
    options: &EmitOptions,
    existing: Option<&str>,
) -> Result<String, EmitError> {
    let output = options.axes.first().ok_or_else(|| {
        EmitError::Profile("a cross-axis table needs the axis it moves".to_string())
    })?;
    let table = &cross.table;
    let values = table.values.for_direction(Direction::Up);
    let mut com = match existing {
        Some(text) => {
            let old =
                parse(text).map_err(|e| EmitError::Profile(format!("the existing table: {e}")))?;
            let others = old.filled_others(std::slice::from_ref(&output.tnc640_column));
            same_points(&old.positions_mm, &table.positions, &others)?;
            old
        }
        None => ComTable {
            positions_mm: table.positions.clone(),
            backlash: vec![None; values.len()],
            columns: vec![(table_column.to_string(), vec![Some(0.0); values.len()])],
        },
    };
    *com.column_mut(&output.tnc640_column) = values.iter().copied().map(Some).collect();
    Ok(com.in_machine_order(options)?.render(&options.table_name))
}

/// The `.CMA` entry of a cross-axis `.COM`: in the table axis's column,
/// the axis's one active table.
pub fn cross_axis_activation(
    file_name: &str,
    (input, output): (&str, &str),
    existing: bool,
) -> String {
    let own = if existing {
        "as in the existing table"
    } else {
        "0 here: give the table on the control with --existing to keep it"
    };
    format!(
        "enter {file_name} in the .CMA column of axis {input} (\"[axis in column] = F(axis in whose .CMA column the .COM is entered)\", MANUALplus 620 TM p.716/718): its {output} column moves {output} as a function of {input}. An axis has one active table (p.718): {file_name} is {input}'s whole table, its {input} column the positioning compensation ({own}); load it in place of {input}'s table, not beside it"
    )
}

/// The points of a `.COM` table (its AXISPOS), for a table written on them.
pub fn read_positions(input: &str) -> Result<Vec<f64>, ParseError> {
    Ok(parse(input)?.positions_mm)
}

/// Every column of a `.COM` table.
fn parse(input: &str) -> Result<ComTable, ParseError> {
    let table = Envelope::split(input, "BEGIN <NAME>.COM MM")?;
    let header = table.header;
    let Some(axispos) = table.column("AXISPOS") else {
        return Err(header.expected_at(header.text.trim_start(), "a header with AXISPOS"));
    };
    let backlash = table.column("BACKLASH");
    let names: Vec<(usize, String)> = table
        .offsets
        .iter()
        .enumerate()
        .filter(|(i, (n, _))| {
            *i != axispos && Some(*i) != backlash && !n.eq_ignore_ascii_case("NR")
        })
        .map(|(i, (n, _))| (i, n.clone()))
        .collect();
    let cell = |row, index: usize, what: &str| -> Result<Option<f64>, ParseError> {
        let text = table.cell(row, index);
        if text.is_empty() {
            Ok(None)
        } else {
            Ok(Some(text::number(row, text, what)?))
        }
    };
    let mut com = ComTable {
        positions_mm: Vec::new(),
        backlash: Vec::new(),
        columns: names.iter().map(|(_, n)| (n.clone(), Vec::new())).collect(),
    };
    for row in &table.rows {
        com.positions_mm
            .push(text::number(row, table.cell(row, axispos), "AXISPOS")?);
        com.backlash.push(match backlash {
            Some(index) => cell(row, index, "BACKLASH value")?,
            None => None,
        });
        for (k, (index, name)) in names.iter().enumerate() {
            let value = cell(row, *index, name)?;
            com.columns[k].1.push(value);
        }
    }
    Ok(com)
}

/// Reads a cross-axis `.COM`: the values of `column_axis`'s column as a
/// function of `table_axis`, which the file does not state (the `.CMA`
/// column it is entered in does). BACKLASH must be empty.
pub fn read_cross_axis(
    input: &str,
    table_axis: &str,
    column_axis: &str,
) -> Result<CrossAxisTable, ParseError> {
    let mut table = read(input, column_axis)?;
    // A file with the table axis's own column is that axis's whole table
    // (one active table per axis): its BACKLASH belongs to that column.
    let own_column = parse(input).is_ok_and(|com| {
        com.columns
            .iter()
            .any(|(n, _)| n.eq_ignore_ascii_case(table_axis))
    });
    if own_column {
        let up = table.values.for_direction(Direction::Up).to_vec();
        table = super::table_as_read(column_axis, table.positions, TableValues::Mean(up));
    } else if table.values.mode() != crate::compensate::TableMode::Mean {
        return Err(ParseError::new(
            2,
            1,
            format!(
                "a cross-axis table {column_axis} = F({table_axis}) has values in BACKLASH: a straightness has no direction, leave BACKLASH empty"
            ),
        ));
    }
    Ok(CrossAxisTable {
        table_axis: table_axis.to_string(),
        table,
    })
}

/// Reads a TNC 640 `.COM` table: the values of `column`, and BACKLASH as the ↓ values.
pub fn read(input: &str, column: &str) -> Result<CompensationTable, ParseError> {
    let table = Envelope::split(input, "BEGIN <NAME>.COM MM")?;
    if table
        .begin
        .text
        .split_whitespace()
        .any(|w| w.eq_ignore_ascii_case("INCH"))
    {
        return Err(table.begin.error_at(
            table.begin.text.trim_start(),
            "inch tables are not supported: axcomp writes and reads MM tables",
        ));
    }
    let header = table.header;
    let (Some(axispos), Some(value_column)) = (table.column("AXISPOS"), table.column(column))
    else {
        let axes: Vec<&str> = table
            .offsets
            .iter()
            .map(|(name, _)| name.as_str())
            .filter(|name| {
                !["NR", "AXISPOS", "BACKLASH"]
                    .iter()
                    .any(|n| n.eq_ignore_ascii_case(name))
            })
            .collect();
        if table.column("AXISPOS").is_some() && !axes.is_empty() {
            return Err(header.error_at(
                header.text.trim_start(),
                format!(
                    "the table is for axis {} (its value column), the test for axis {column}: give the table of axis {column}",
                    axes.join(", ")
                ),
            ));
        }
        return Err(header.expected_at(
            header.text.trim_start(),
            &format!("a header with AXISPOS and an axis column {column}"),
        ));
    };
    let backlash = table.column("BACKLASH");
    let mut positions_mm = Vec::new();
    let mut up = Vec::new();
    let mut down: Vec<Option<f64>> = Vec::new();
    for row in &table.rows {
        let position_text = table.cell(row, axispos);
        let position = text::number(row, position_text, "AXISPOS")?;
        let value_text = table.cell(row, value_column);
        if value_text.is_empty() {
            return Err(empty_cell(row, column));
        }
        if let Some(previous) = positions_mm.last()
            && position <= *previous
        {
            return Err(row.error_at(
                position_text,
                format!("AXISPOS {position} does not increase (previous {previous})"),
            ));
        }
        positions_mm.push(position);
        up.push(text::number(row, value_text, "compensation value")?);
        down.push(match backlash.map(|index| table.cell(row, index)) {
            Some(text) if !text.is_empty() => Some(text::number(row, text, "BACKLASH value")?),
            _ => None,
        });
    }
    let values = if down.iter().all(Option::is_none) {
        TableValues::Mean(up)
    } else if down.iter().all(Option::is_some) {
        TableValues::Bidirectional {
            up,
            down: down.into_iter().flatten().collect(),
        }
    } else {
        return Err(ParseError::new(
            header.number,
            1,
            "BACKLASH is filled in some rows only: fill it in every row or none",
        ));
    };
    Ok(super::table_as_read(column, positions_mm, values))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::profile::MachineProfile;
    use crate::units::LengthUnit;

    pub(crate) fn options() -> EmitOptions {
        EmitOptions {
            axes: vec![MachineProfile::default().axis("X").unwrap()],
            table_name: "AXIS_X.COM".into(),
            machine_unit: LengthUnit::Millimetre,
            linuxcnc_type: 0,
            max_points: None,
            max_value_mm: None,
            provenance: None,
            cec_values_are_corrections: true,
            tnc640_columns: Vec::new(),
            kind: Default::default(),
        }
    }

    #[test]
    fn mean_and_bidirectional_round_trip() {
        let mean = CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![-10.0, 12.5, 40.0],
            values: TableValues::Mean(vec![0.0, -0.0023, 0.0101]),
            reference: -10.0,
            suggested_backlash: None,
        };
        let text = write(&mean, &options()).unwrap();
        assert!(
            text.contains("1    +12.5                       -0.0023\r\n"),
            "{text}"
        );
        assert_eq!(read(&text, "X").unwrap(), mean);
        let both = CompensationTable {
            values: TableValues::Bidirectional {
                up: vec![0.0, 0.001, 0.002],
                down: vec![-0.003, -0.002, -0.001],
            },
            ..mean
        };
        let text = write(&both, &options()).unwrap();
        assert_eq!(read(&text, "X").unwrap().values, both.values);
    }

    #[test]
    fn other_machine_columns_stay_empty() {
        let table = CompensationTable {
            axis: "Y".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![0.0, 5.0],
            values: TableValues::Mean(vec![0.0, 0.0005]),
            reference: 0.0,
            suggested_backlash: None,
        };
        let mut opts = options();
        opts.axes = vec![MachineProfile::default().axis("Y").unwrap()];
        opts.tnc640_columns = vec!["X".to_string(), "Y".to_string(), "Z".to_string()];
        let text = write(&table, &opts).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[1],
            "NR   AXISPOS       BACKLASH      X             Y             Z"
        );
        assert_eq!(
            lines[3],
            "1    +5                                        +0.0005"
        );
        assert_eq!(read(&text, "Y").unwrap().values, table.values);
        opts.tnc640_columns.truncate(1);
        assert!(write(&table, &opts).is_err());
    }

    #[test]
    fn positioned_errors() {
        let good = write(
            &CompensationTable {
                axis: "X".into(),
                kind: crate::measurement::AxisKind::Linear,
                positions: vec![0.0, 100.0],
                values: TableValues::Mean(vec![0.0, -0.0023]),
                reference: 0.0,
                suggested_backlash: None,
            },
            &options(),
        )
        .unwrap();
        let cases = [
            (good.replace("[END]\r\n", ""), (5, 1), "truncated"),
            (good.replace("+100", "+0  "), (4, 6), "does not increase"),
            (good.replace("-0.0023", "-0,0023"), (4, 34), "decimal comma"),
            (good.replace("AXISPOS", "POSITION"), (2, 1), "AXISPOS"),
        ];
        for (text, (line, column), needle) in cases {
            let error = read(&text, "X").unwrap_err();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "{error}"
            );
            assert!(error.message.contains(needle), "{error}");
        }
    }
}
