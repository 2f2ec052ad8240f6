//! Heidenhain TNC 640 nonlinear axis error compensation table (`.COM`): writer and reader.
//!
//! Spec and sources: `formats/tnc640/README.md`. \[seen\] seed 001 Fig. 29 (the
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
//! is the mean measured deviation (actual − target), not negated; seed 001's
//! after-test confirms the sign (A 9.7 µm → 2.3 µm).

use crate::compensate::cross_axis::CrossAxisTable;
use crate::compensate::{CompensationTable, TableValues};
use crate::emit::heidenhain::{BACKLASH_DECIMALS, BACKLASH_SIGN, Envelope, empty_cell};
use crate::emit::{
    BacklashAdvice, BacklashParameter, EmitError, EmitOptions, signed_fixed, signed_minimal,
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

/// Writes the `.COM` table.
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let columns = columns(options);
    for axis in &options.axes {
        if !columns.contains(&axis.tnc640_column) {
            return Err(EmitError::Profile(format!(
                "axis column {:?} is not among the machine's TNC 640 columns {columns:?}",
                axis.tnc640_column
            )));
        }
    }
    let mut out = String::new();
    let mut line = |text: String| {
        out.push_str(text.trim_end());
        out.push_str("\r\n");
    };
    line(format!("BEGIN {} MM", options.table_name));
    let mut header = format!(
        "{:<NR_WIDTH$}{:<COLUMN_WIDTH$}{:<COLUMN_WIDTH$}",
        "NR", "AXISPOS", "BACKLASH"
    );
    for column in &columns {
        header.push_str(&format!("{column:<COLUMN_WIDTH$}"));
    }
    line(header);
    for (index, position_mm) in table.positions_mm.iter().enumerate() {
        let backlash = match &table.values {
            TableValues::Mean(_) => String::new(),
            TableValues::Bidirectional { down, .. } => signed_fixed(down[index], VALUE_DECIMALS),
        };
        let up = signed_fixed(
            table.values.for_direction(Direction::Up)[index],
            VALUE_DECIMALS,
        );
        let mut row = format!(
            "{:<NR_WIDTH$}{:<COLUMN_WIDTH$}{:<COLUMN_WIDTH$}",
            index,
            signed_minimal(*position_mm, 4),
            backlash
        );
        for column in &columns {
            let written = options.axes.iter().any(|a| &a.tnc640_column == column);
            row.push_str(&format!(
                "{:<COLUMN_WIDTH$}",
                if written { up.as_str() } else { "" }
            ));
        }
        line(row);
    }
    line("[END]".to_string());
    Ok(out)
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
pub fn write_cross_axis(
    cross: &CrossAxisTable,
    options: &EmitOptions,
) -> Result<String, EmitError> {
    write(&cross.table, options)
}

/// Reads a cross-axis `.COM`: the values of `column_axis`'s column as a
/// function of `table_axis`, which the file does not state (the `.CMA`
/// column it is entered in does). BACKLASH must be empty.
pub fn read_cross_axis(
    input: &str,
    table_axis: &str,
    column_axis: &str,
) -> Result<CrossAxisTable, ParseError> {
    let table = read(input, column_axis)?;
    if table.values.mode() != crate::compensate::TableMode::Mean {
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
            cec_first_table: 0,
            cec_values_are_corrections: true,
            tnc640_columns: Vec::new(),
            kind: Default::default(),
        }
    }

    #[test]
    fn mean_and_bidirectional_round_trip() {
        let mean = CompensationTable {
            axis: "X".into(),
            positions_mm: vec![-10.0, 12.5, 40.0],
            values: TableValues::Mean(vec![0.0, -0.0023, 0.0101]),
            reference_mm: -10.0,
            suggested_backlash_mm: None,
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
            positions_mm: vec![0.0, 5.0],
            values: TableValues::Mean(vec![0.0, 0.0005]),
            reference_mm: 0.0,
            suggested_backlash_mm: None,
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
                positions_mm: vec![0.0, 100.0],
                values: TableValues::Mean(vec![0.0, -0.0023]),
                reference_mm: 0.0,
                suggested_backlash_mm: None,
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
