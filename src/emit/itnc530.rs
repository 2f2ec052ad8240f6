//! Heidenhain iTNC 530 nonlinear axis error compensation table (`.COM`): writer and reader.
//!
//! Spec and sources: `formats/itnc530/README.md`. \[seen\] Kadlečík (2019) Fig. 28
//! (the control's table editor: `DATUM` = start of the compensated range,
//! `DISTANCE` = spacing in mm, columns `NR`, an unlabelled position column,
//! `1=F() 2=F() 3=F()`…, one value per point in the column of the axis
//! number), the iTNC 530 HSCI technical manual (position errors in "columns
//! 1-18 of the COM files"), the TNC 407 manual (at most 256 entries; the error
//! curve starts with 0 at the datum). \[reconstructed\] the raw file syntax,
//! which no public source shows: the first line and the column widths are
//! those the seed author's tool writes (`BEGIN AXIS-X.COM  DATUM:+0.0000
//! DISTANCE:+100.0000`, NR 5 wide, position 12, axis columns 11; the author
//! notes the widths are a guess), plus `[END]` and CRLF as every Heidenhain
//! table has.
//!
//! Numbers carry an explicit sign and 4 decimals (0.1 µm); the value is the
//! mean measured deviation (actual − target), not negated. One column per
//! axis only: no backlash column (set the backlash parameter, [`backlash_parameter`]).

use crate::compensate::{CompensationTable, TableValues};
use crate::emit::heidenhain::{BACKLASH_DECIMALS, BACKLASH_SIGN, Envelope, empty_cell};
use crate::emit::{BacklashAdvice, BacklashParameter, EmitError, EmitOptions, signed_fixed};
use crate::error::ParseError;
use crate::measurement::Direction;
use crate::read::text::{self, Line};
use crate::units::LengthUnit;

const NR_WIDTH: usize = 5;
const POSITION_WIDTH: usize = 12;
const COLUMN_WIDTH: usize = 11;
const DECIMALS: usize = 4;

/// Writes the `.COM` table (regular spacing and zero at the datum checked by `emit::check_table`).
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let step = table.regular_step().ok_or(EmitError::UnevenSpacing {
        controller: "itnc530",
    })?;
    let columns: Vec<u32> = options.axes.iter().map(|a| a.itnc530_column).collect();
    let last_column = columns.iter().copied().max().unwrap_or(1);
    if columns.iter().any(|c| !(1..=18).contains(c)) {
        return Err(EmitError::Profile(format!(
            "iTNC 530 axis columns are numbered 1 to 18, found {columns:?}"
        )));
    }
    let mut out = String::new();
    let mut line = |text: String| {
        out.push_str(text.trim_end());
        out.push_str("\r\n");
    };
    line(format!(
        "BEGIN {}  DATUM:{} DISTANCE:{}",
        options.table_name,
        signed_fixed(table.positions[0], DECIMALS),
        signed_fixed(step, DECIMALS)
    ));
    let mut header = format!("{:<NR_WIDTH$}{:<POSITION_WIDTH$}", "NR", "");
    for column in 1..=last_column {
        header.push_str(&format!("{:<COLUMN_WIDTH$}", format!("{column}=F()")));
    }
    line(header);
    let values = table.values.for_direction(Direction::Up);
    for (index, (position, value)) in table.positions.iter().zip(values).enumerate() {
        let mut row = format!(
            "{index:<NR_WIDTH$}{:<POSITION_WIDTH$}",
            signed_fixed(*position, DECIMALS)
        );
        for column in 1..=last_column {
            let cell = if columns.contains(&column) {
                signed_fixed(*value, DECIMALS)
            } else {
                String::new()
            };
            row.push_str(&format!("{cell:<COLUMN_WIDTH$}"));
        }
        line(row);
    }
    line("[END]".to_string());
    Ok(out)
}

/// The backlash parameter for the reversal a mean table leaves.
///
/// \[seen\] iTNC 530 HSCI technical manual (07/2013) §6.4.1: play outside
/// the control loop (position from the rotary encoder) goes into MP710.x
/// "Backlash compensation", input −1.0000 … +1.0000 mm (the TNC 426/430
/// manual p.6-36 words it identically), x = 0 … 8 for axes 1 … 9 (the axis
/// column number − 1); play within the loop, on an axis with a linear
/// encoder, into MP750.x "Backlash", −9.9999 … +9.9999 mm, with MP752.x the
/// time to traverse it (p.650). A laser test of a rotary-encoder axis sees
/// the first; the second is named in the note.
pub fn backlash_parameter(backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
    let indices: Vec<u32> = options
        .axes
        .iter()
        .map(|axis| axis.itnc530_column.saturating_sub(1))
        .collect();
    let list = |mp: u32| {
        indices
            .iter()
            .map(|index| format!("MP{mp}.{index}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    BacklashAdvice::Parameter(BacklashParameter::new(
        list(710),
        backlash_mm,
        LengthUnit::Millimetre,
        BACKLASH_DECIMALS,
        BACKLASH_SIGN,
        Some(format!(
            "MP710 is for play outside the control loop (position from the rotary encoder); on an axis with a linear encoder enter it in {} (backlash within the loop) with MP752 as its compensation time instead",
            list(750)
        )),
    ))
}

/// How to activate it: the `.COM` in the machine's `.CMA` and MP730 set for the axis.
pub fn activation(file_name: &str, options: &EmitOptions) -> String {
    let columns: Vec<String> = options
        .axes
        .iter()
        .map(|a| a.itnc530_column.to_string())
        .collect();
    format!(
        "enter {file_name} in the active line of the machine's .CMA file and set MP730 (nonlinear compensation) for axis {}",
        columns.join(", ")
    )
}

/// Reads an iTNC 530 `.COM` table: the values of axis column `column` (the N of `N=F()`).
pub fn read(input: &str, column: u32) -> Result<CompensationTable, ParseError> {
    let table = Envelope::split(input, "BEGIN <NAME>.COM  DATUM:… DISTANCE:…")?;
    let (datum, distance) = begin_line(&table.begin)?;
    let wanted = format!("{column}=F()");
    let Some(value_column) = table.column(&wanted) else {
        return Err(table.header.expected_at(
            table.header.text.trim_start(),
            &format!("a column {wanted}"),
        ));
    };
    let mut positions_mm = Vec::new();
    let mut values = Vec::new();
    for row in &table.rows {
        let mut fields = row.fields();
        let (Some(_number), Some(position_text)) = (fields.next(), fields.next()) else {
            return Err(row.expected_at(row.text.trim_start(), "NR, position and value"));
        };
        let position = text::number(row, position_text, "position")?;
        let expected = datum + positions_mm.len() as f64 * distance;
        if (position - expected).abs() > 0.5e-4 {
            return Err(row.error_at(
                position_text,
                format!("position {position} is not DATUM + NR·DISTANCE = {expected:.4}"),
            ));
        }
        let value_text = table.cell(row, value_column);
        if value_text.is_empty() {
            return Err(empty_cell(row, &wanted));
        }
        positions_mm.push(position);
        values.push(text::number(row, value_text, "compensation value")?);
    }
    Ok(CompensationTable {
        axis: String::new(),
        kind: crate::measurement::AxisKind::Linear,
        reference: positions_mm[0],
        positions: positions_mm,
        values: TableValues::Mean(values),
        suggested_backlash: None,
    })
}

/// `BEGIN <name>  DATUM:<mm> DISTANCE:<mm>` → (datum, distance).
fn begin_line(line: &Line<'_>) -> Result<(f64, f64), ParseError> {
    let trimmed = line.text.trim_start();
    if !trimmed.starts_with("BEGIN ") {
        return Err(line.expected_at(trimmed, "BEGIN <NAME>.COM  DATUM:… DISTANCE:…"));
    }
    let value_after = |key: &str| -> Result<f64, ParseError> {
        let Some(at) = line.text.find(key) else {
            return Err(line.error_at(
                &line.text[line.text.len()..],
                format!("expected {key} in the BEGIN line, found none"),
            ));
        };
        let rest = line.text[at + key.len()..].trim_start();
        let token = rest.split_whitespace().next().unwrap_or(rest);
        text::number(line, token, key.trim_end_matches(':'))
    };
    let datum = value_after("DATUM:")?;
    let distance = value_after("DISTANCE:")?;
    if distance <= 0.0 {
        return Err(line.error_at(
            trimmed,
            format!("expected a positive DISTANCE, found {distance}"),
        ));
    }
    Ok((datum, distance))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::profile::MachineProfile;
    use crate::units::LengthUnit;

    fn options(axes: &[&str]) -> EmitOptions {
        EmitOptions {
            axes: axes
                .iter()
                .map(|a| MachineProfile::default().axis(a).unwrap())
                .collect(),
            table_name: "AXIS-X.COM".into(),
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

    fn table() -> CompensationTable {
        CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![0.0, 100.0, 200.0],
            values: TableValues::Mean(vec![0.0, -0.0023, -0.0042]),
            reference: 0.0,
            suggested_backlash: None,
        }
    }

    #[test]
    fn layout_of_the_seed_tool() {
        let text = write(&table(), &options(&["X"])).unwrap();
        let lines: Vec<&str> = text.split("\r\n").collect();
        assert_eq!(
            lines[0],
            "BEGIN AXIS-X.COM  DATUM:+0.0000 DISTANCE:+100.0000"
        );
        assert_eq!(lines[1], "NR               1=F()");
        assert_eq!(lines[3], "1    +100.0000   -0.0023");
        assert_eq!(lines[5], "[END]");
        let back = read(&text, 1).unwrap();
        assert_eq!(
            (back.positions, back.values),
            (table().positions, table().values)
        );
    }

    #[test]
    fn coupled_axes_fill_their_columns() {
        // X (column 1) and its gantry slave U (column 7) get the same values.
        let text = write(&table(), &options(&["X", "U"])).unwrap();
        assert!(text.contains("7=F()"));
        assert_eq!(read(&text, 7).unwrap().values, table().values);
        assert!(read(&text, 3).unwrap_err().message.contains("empty cell"));
    }

    #[test]
    fn positioned_errors() {
        let good = write(&table(), &options(&["X"])).unwrap();
        let cases = [
            (
                good.replace("DISTANCE:+100.0000", "DISTANCE:+50.0000"),
                (4, 6),
                "DATUM + NR·DISTANCE",
            ),
            (good.replace("[END]\r\n", ""), (6, 1), "truncated"),
            (good.replace("1=F()", "X=F()"), (2, 1), "a column 1=F()"),
            (
                good.replace("DATUM:+0.0000", "DATUM:zero"),
                (1, 25),
                "expected a number (DATUM)",
            ),
        ];
        for (text, (line, column), needle) in cases {
            let error = read(&text, 1).unwrap_err();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "{error}"
            );
            assert!(error.message.contains(needle), "{error}");
        }
    }
}
