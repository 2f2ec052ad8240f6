//! Siemens Sinumerik 840D compensation programs (`.MPF`): LEC writer/reader
//! (`%_N_AX_EEC_INI`, `$AA_ENC_COMP`) for one table, CEC (`%_N_NC_CEC_INI`,
//! `$AN_CEC`) for direction-dependent tables.
//!
//! Spec and sources: `formats/sinumerik840d/README.md`. \[seen\] the Siemens
//! Function Manual Extended Functions K3 (03/2013) examples: the LEC program
//! skeleton, index order `[encoder, point, axis]`, points N = 0…(MAX−MIN)/STEP,
//! end values held outside MIN…MAX, "a positive compensation value causes the
//! machine axis to move in the negative direction" (so an LEC value is the
//! measured error with its own sign); the CEC table parameters with
//! `$AN_CEC_DIRECTION` = 1 / −1 for position-dependent backlash with two
//! tables. \[reconstructed\] the CEC sign: the K3 sag examples enter the value
//! that moves the compensation axis (a correction, −error); it is a profile
//! setting (`cec_values`) because no public page states it outright.
//!
//! Numbers: mm, minimal digits with at least one decimal (`0.0023`,
//! `100.0`), as the manual's examples; 1 nm resolution. A rotary axis'
//! table is in degrees; over a full turn it is a modulo table
//! (`IS_MODULO = 1`, MIN 0, MAX 360, equal values at both ends: \[seen\]
//! 840D / 808D function manuals, `../shared/spec/standards.md` §6).

use std::collections::BTreeMap;

use crate::compensate::cross_axis::CrossAxisTable;
use crate::compensate::{CompensationTable, TableValues};
use crate::emit::{
    AxisProfile, BacklashAdvice, BacklashParameter, CrossAxisValues, EmitError, EmitOptions,
    minimal,
};
use crate::error::ParseError;
use crate::read::text::{self, Line};
use crate::units::LengthUnit;

/// Decimals written (1 nm).
const DECIMALS: usize = 6;

/// A Siemens number: minimal digits, at least one decimal.
fn number(value: f64) -> String {
    let text = minimal(value, DECIMALS);
    if text.contains('.') {
        text
    } else {
        format!("{text}.0")
    }
}

/// The program's first lines: its name and, where the caller gives it, a
/// comment with the table's source (`;` starts a comment in a Siemens part
/// program; the K3 example programs comment every line).
fn head(name: &str, options: &EmitOptions) -> String {
    let mut out = format!("{name}\n");
    if let Some(provenance) = &options.provenance {
        out.push_str(&format!("; {}\n", provenance.text()));
    }
    out.push_str("CHANDATA(1)\n");
    out
}

/// +1 or −1: what a CEC value is, times the table's error (corrections −error).
fn cec_sign(options: &EmitOptions) -> f64 {
    if options.cec_values_are_corrections {
        -1.0
    } else {
        1.0
    }
}

/// The axis's own ↑ CEC table number (↓ is the next), from the profile.
fn own_cec_table(axis: &AxisProfile) -> Result<usize, EmitError> {
    axis.cec_table.ok_or_else(|| {
        EmitError::Profile(format!(
            "axis {0} has no Sinumerik CEC table number: name it under [controller.axes.{0}] in the machine profile (the machine's axes get distinct tables, formats/sinumerik840d/README.md)",
            axis.axis
        ))
    })
}

/// Writes LEC for a mean table, CEC for a bidirectional one.
pub fn write(table: &CompensationTable, options: &EmitOptions) -> Result<String, EmitError> {
    let step = table.regular_step().ok_or(EmitError::UnevenSpacing {
        controller: "sinumerik840d",
    })?;
    let first = table.positions[0];
    let last = table.positions[table.positions.len() - 1];
    // A rotary axis' full turn repeats: the table is cyclic, MIN 0°, MAX 360°
    // with equal end values (checked by `emit::check_table`).
    let modulo = u8::from(options.is_full_turn(table));
    let mut out = String::new();
    let mut line = |text: String| {
        out.push_str(&text);
        out.push('\n');
    };
    match &table.values {
        TableValues::Mean(values) => {
            line(head("%_N_AX_EEC_INI", options).trim_end().to_string());
            for axis in &options.axes {
                let (e, name) = (axis.sinumerik_encoder, &axis.sinumerik_axis);
                for (n, value) in values.iter().enumerate() {
                    line(format!("$AA_ENC_COMP[{e},{n},{name}]={}", number(*value)));
                }
                line(format!("$AA_ENC_COMP_STEP[{e},{name}]={}", number(step)));
                line(format!("$AA_ENC_COMP_MIN[{e},{name}]={}", number(first)));
                line(format!("$AA_ENC_COMP_MAX[{e},{name}]={}", number(last)));
                line(format!("$AA_ENC_COMP_IS_MODULO[{e},{name}]={modulo}"));
            }
        }
        TableValues::Bidirectional { up, down } => {
            line(head("%_N_NC_CEC_INI", options).trim_end().to_string());
            let sign = cec_sign(options);
            for axis in &options.axes {
                let own = own_cec_table(axis)?;
                for (t, direction, values) in [(own, 1, up), (own + 1, -1, down)] {
                    for (n, value) in values.iter().enumerate() {
                        line(format!("$AN_CEC[{t},{n}]={}", number(sign * value)));
                    }
                    let name = &axis.sinumerik_axis;
                    line(format!("$AN_CEC_INPUT_AXIS[{t}]=({name})"));
                    line(format!("$AN_CEC_OUTPUT_AXIS[{t}]=({name})"));
                    line(format!("$AN_CEC_STEP[{t}]={}", number(step)));
                    line(format!("$AN_CEC_MIN[{t}]={}", number(first)));
                    line(format!("$AN_CEC_MAX[{t}]={}", number(last)));
                    line(format!("$AN_CEC_DIRECTION[{t}]={direction}"));
                    line(format!("$AN_CEC_MULT_BY_TABLE[{t}]=0"));
                    line(format!("$AN_CEC_IS_MODULO[{t}]={modulo}"));
                }
            }
        }
    }
    line("M17".to_string());
    Ok(out)
}

/// What a CEC table's values are: the correction (−error) under the
/// reconstructed convention, else the error.
pub fn cross_axis_values(options: &EmitOptions) -> CrossAxisValues {
    CrossAxisValues {
        sign: cec_sign(options),
        name: if options.cec_values_are_corrections {
            "correction (−error)"
        } else {
            "error"
        },
    }
}

/// Writes a cross-axis table as one CEC table, number `t` (the profile's
/// [`MachineProfile::cec_table`](crate::emit::MachineProfile::cec_table) of
/// the pair): `$AN_CEC_INPUT_AXIS` the table axis (`input_axis`, its
/// Sinumerik name), `$AN_CEC_OUTPUT_AXIS` the column axis
/// (`options.axes[0]`), `$AN_CEC_DIRECTION` 0 (a straightness has no
/// direction), values signed as `options.cec_values_are_corrections` says,
/// as the axis's own CEC tables (K3 p.248, the sag example).
pub fn write_cross_axis(
    cross: &CrossAxisTable,
    input_axis: &str,
    t: usize,
    options: &EmitOptions,
) -> Result<String, EmitError> {
    let table = &cross.table;
    let step = table.regular_step().ok_or(EmitError::UnevenSpacing {
        controller: "sinumerik840d",
    })?;
    let output = options.axes.first().ok_or_else(|| {
        EmitError::Profile("a cross-axis table needs the axis it moves".to_string())
    })?;
    let sign = cec_sign(options);
    let values = table
        .values
        .for_direction(crate::measurement::Direction::Up);
    let mut out = head("%_N_NC_CEC_INI", options);
    for (n, value) in values.iter().enumerate() {
        out.push_str(&format!("$AN_CEC[{t},{n}]={}\n", number(sign * value)));
    }
    let first = table.positions[0];
    let last = table.positions[table.positions.len() - 1];
    for (key, value) in [
        ("INPUT_AXIS", format!("({input_axis})")),
        ("OUTPUT_AXIS", format!("({})", output.sinumerik_axis)),
        ("STEP", number(step)),
        ("MIN", number(first)),
        ("MAX", number(last)),
        ("DIRECTION", "0".to_string()),
        ("MULT_BY_TABLE", "0".to_string()),
        ("IS_MODULO", "0".to_string()),
    ] {
        out.push_str(&format!("$AN_CEC_{key}[{t}]={value}\n"));
    }
    out.push_str("M17\n");
    Ok(out)
}

/// The CEC table numbers a program writes (`$AN_CEC…[t]`), in order: what
/// must not clash with another program of the same machine.
pub fn cec_tables(input: &str) -> Result<Vec<usize>, ParseError> {
    let (_, cec) = raw_tables(input)?;
    Ok(cec.keys().copied().collect())
}

/// Reads the CEC table with `$AN_CEC_INPUT_AXIS` = `input_axis` and
/// `$AN_CEC_OUTPUT_AXIS` = `output_axis` (Sinumerik names); the table's axes
/// in the result are `table_axis` and `column_axis` (the model's letters).
pub fn read_cross_axis(
    input: &str,
    (input_axis, output_axis): (&str, &str),
    (table_axis, column_axis): (&str, &str),
    cec_values_are_corrections: bool,
) -> Result<CrossAxisTable, ParseError> {
    let (_, cec) = raw_tables(input)?;
    let table = cec
        .values()
        .find(|t| {
            t.input_axis.as_deref() == Some(input_axis)
                && t.output_axis.as_deref() == Some(output_axis)
        })
        .ok_or_else(|| {
            ParseError::new(
                1,
                1,
                format!(
                    "expected a CEC table with $AN_CEC_INPUT_AXIS ({input_axis}) and $AN_CEC_OUTPUT_AXIS ({output_axis}), found none"
                ),
            )
        })?;
    if table.direction != 0 {
        let at = table.first_line.map_or(1, |l| l.number);
        return Err(ParseError::new(
            at,
            1,
            format!(
                "the cross-axis table {output_axis} = F({input_axis}) applies in one direction only ($AN_CEC_DIRECTION {}): a straightness table applies in both (0)",
                table.direction
            ),
        ));
    }
    let (positions, values) = columns(table)?;
    let sign = if cec_values_are_corrections {
        -1.0
    } else {
        1.0
    };
    let values: Vec<f64> = values.iter().map(|v| sign * v).collect();
    let read = super::table_as_read(column_axis, positions, TableValues::Mean(values));
    Ok(CrossAxisTable {
        table_axis: table_axis.to_string(),
        table: read,
    })
}

/// The backlash parameter for the reversal a mean (LEC) table leaves.
///
/// \[seen\] SINUMERIK 808D Advanced parameter manual (08/2013) p.228/241:
/// MD32450 `$MA_BACKLASH[n]`, one per measuring system n, in mm (degrees on
/// rotary axes), "positive, if the encoder is leading the machine part
/// (normal situation); negative, if the encoder is behind the machine part",
/// active after the reference point approach. p.33: with MD10240
/// `$MN_SCALING_SYSTEM_IS_METRIC` = 0 length machine data are read in inch,
/// so an inch machine gets inch. Decimals: 0.1 µm (4 in mm, 6 in inch, the
/// nearest), finer than the measurement of B̄ and than the default
/// computational resolution (MD10200 `INT_INCR_PER_MM` = 1000, 1 µm).
pub fn backlash_parameter(backlash_mm: f64, options: &EmitOptions) -> BacklashAdvice {
    let names: Vec<String> = options
        .axes
        .iter()
        .map(|axis| {
            format!(
                "$MA_BACKLASH[{},{}]",
                axis.sinumerik_encoder, axis.sinumerik_axis
            )
        })
        .collect();
    let unit = options.machine_unit;
    let (decimals, unit_note) = match unit {
        LengthUnit::Millimetre => (4, ""),
        LengthUnit::Inch => (
            6,
            " The value is in inch because the machine profile says inch (MD10240 $MN_SCALING_SYSTEM_IS_METRIC = 0); on a metric control enter it in mm.",
        ),
    };
    BacklashAdvice::Parameter(BacklashParameter::new(
        format!("MD32450 {}", names.join(", ")),
        backlash_mm,
        unit,
        decimals,
        "positive when the encoder is leading the machine part (the normal situation: the axis falls short after a reversal); negative when it is behind",
        Some(format!(
            "active after the axis is referenced; or write the table with --mode bidirectional (two CEC tables, one per direction) instead.{unit_note}"
        )),
    ))
}

/// What the machine needs before the program loads, and how to activate it.
///
/// \[seen\] K3 03/2013: LEC p.237–242 (MD38000 ≥ points, load while MD32700
/// = 0); CEC p.245 (MD32710 `$MA_CEC_ENABLE[<AXi>]` enables the sum of the
/// axis's compensation relationships, SD41300 `$SN_CEC_TABLE_ENABLE[<t>]`
/// the evaluation of table t), p.264 (MD18342 `$MN_MM_CEC_MAX_POINTS[t]`
/// per table), p.237 (tables load only while MD32700 / MD32710 = 0; a
/// changed MD18342 / MD38000 reformats the static memory at the next
/// power on). The CEC sign is \[reconstructed\], so the text says how to
/// check it with one move.
pub fn activation(table: &CompensationTable, file_name: &str, options: &EmitOptions) -> String {
    let points = table.positions.len();
    match &table.values {
        TableValues::Mean(_) => {
            let axes: Vec<String> = options
                .axes
                .iter()
                .map(|a| a.sinumerik_axis.clone())
                .collect();
            format!(
                "needs MD38000 $MA_MM_ENC_COMP_MAX_POINTS ≥ {points} for {}; load with MD32700 $MA_ENC_COMP_ENABLE = 0, then set it to 1 and reference the axis",
                axes.join(", ")
            )
        }
        TableValues::Bidirectional { up, .. } => {
            let tables: Vec<(usize, &str)> = options
                .axes
                .iter()
                .filter_map(|a| a.cec_table.map(|t| (t, a.sinumerik_axis.as_str())))
                .flat_map(|(t, axis)| [(t, axis), (t + 1, axis)])
                .collect();
            let axis = options
                .axes
                .first()
                .map_or("X1", |a| a.sinumerik_axis.as_str());
            let check = sign_check(
                table,
                up,
                (axis, axis),
                tables.first().map_or(0, |t| t.0),
                options,
            );
            cec_activation(
                file_name,
                &tables,
                points,
                &format!(
                    "tables {} (↑ DIRECTION 1, ↓ DIRECTION -1)",
                    table_list(&tables)
                ),
                &check,
            )
        }
    }
}

/// The activation of a cross-axis CEC table `t`: "`output` = F(`input`)"
/// (Sinumerik names), with the one-move check of its reconstructed sign.
pub fn cross_axis_activation(
    cross: &CrossAxisTable,
    (input, output): (&str, &str),
    t: usize,
    file_name: &str,
    options: &EmitOptions,
) -> String {
    let table = &cross.table;
    let values = table
        .values
        .for_direction(crate::measurement::Direction::Up);
    let check = sign_check(table, values, (input, output), t, options);
    cec_activation(
        file_name,
        &[(t, output)],
        table.positions.len(),
        &format!("table {t} ({output} = F({input}), both directions)"),
        &check,
    )
}

/// `0 and 1`, `6`.
fn table_list(tables: &[(usize, &str)]) -> String {
    let numbers: Vec<String> = tables.iter().map(|(t, _)| t.to_string()).collect();
    match numbers.as_slice() {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// The CEC steps in the order the control needs them (K3 p.237, p.245, p.264).
fn cec_activation(
    file_name: &str,
    tables: &[(usize, &str)],
    points: usize,
    what: &str,
    check: &str,
) -> String {
    let mut axes: Vec<&str> = tables.iter().map(|(_, a)| *a).collect();
    axes.dedup();
    let per_table = |text: &str| {
        tables
            .iter()
            .map(|(t, _)| format!("{text}[{t}]"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let enable = |text: &str| {
        axes.iter()
            .map(|a| format!("{text}[{a}]"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(
        "{file_name} writes CEC {what}; it needs the CEC option (alarm 8040 without it), then:\n\
         1. MD18342 {} ≥ {points} (a changed value takes effect at the next power on, which reformats the static user memory);\n\
         2. MD32710 {} = 0 while the program loads (tables load only then): run {file_name};\n\
         3. SD41300 {} = 1 (evaluate the tables), then MD32710 {} = 1 and reset;\n\
         4. {check}",
        per_table("$MN_MM_CEC_MAX_POINTS"),
        enable("$MA_CEC_ENABLE"),
        per_table("$SN_CEC_TABLE_ENABLE"),
        enable("$MA_CEC_ENABLE"),
    )
}

/// "Check the sign with one test move" where the table's value is largest:
/// with table `t` on and off the reading must move by the written value
/// (toward the nominal); twice the error means the sign is reversed.
fn sign_check(
    table: &CompensationTable,
    errors_mm: &[f64],
    (input, output): (&str, &str),
    t: usize,
    options: &EmitOptions,
) -> String {
    let (position, error) = table
        .positions
        .iter()
        .zip(errors_mm)
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map_or((0.0, 0.0), |(p, e)| (*p, *e));
    let written = cec_sign(options) * error;
    let approach = if input == output {
        ", approaching in + (the ↑ table)"
    } else {
        ""
    };
    let other = if options.cec_values_are_corrections {
        "error"
    } else {
        "correction"
    };
    format!(
        "check the sign with one test move before use (the CEC sign is reconstructed, formats/sinumerik840d/README.md): move {input} to {} mm{approach}, where table {t} holds {} mm, and read {output} with SD41300 $SN_CEC_TABLE_ENABLE[{t}] = 0 and = 1: the reading must move by {} µm toward the nominal; if the error doubles instead, set cec_values = \"{other}\" in the machine profile and write the table again",
        minimal(position, 4),
        number(written),
        minimal(crate::units::mm_to_um(error.abs()), 1),
    )
}

/// One `$NAME[indices]=value` assignment.
struct Assignment<'a> {
    line: Line<'a>,
    name: String,
    indices: Vec<&'a str>,
    value: &'a str,
}

fn assignment<'a>(line: &Line<'a>) -> Result<Option<Assignment<'a>>, ParseError> {
    let code = line.text.split(';').next().unwrap_or("").trim();
    if code.is_empty() || !code.starts_with('$') {
        return Ok(None);
    }
    let (Some(open), Some(close), Some(equals)) = (code.find('['), code.find(']'), code.find('='))
    else {
        return Err(line.expected_at(code, "$NAME[indices]=value"));
    };
    if !(open < close && close < equals) {
        return Err(line.expected_at(code, "$NAME[indices]=value"));
    }
    Ok(Some(Assignment {
        line: *line,
        name: code[1..open].trim().to_ascii_uppercase(),
        indices: code[open + 1..close].split(',').map(str::trim).collect(),
        value: code[equals + 1..].trim(),
    }))
}

/// The points and parameters of one table as read.
#[derive(Default)]
struct RawTable<'a> {
    points: BTreeMap<usize, (f64, Line<'a>)>,
    step: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    direction: i32,
    output_axis: Option<String>,
    input_axis: Option<String>,
    first_line: Option<Line<'a>>,
}

/// Reads the table of `axis` (a Sinumerik machine axis name) from an LEC or a
/// CEC program. `cec_values_are_corrections` as in [`EmitOptions`].
pub fn read(
    input: &str,
    axis: &str,
    cec_values_are_corrections: bool,
) -> Result<CompensationTable, ParseError> {
    let (lec, cec) = raw_tables(input)?;
    if let Some(table) = lec.get(axis) {
        let (positions_mm, values) = columns(table)?;
        return Ok(super::table_as_read(
            axis,
            positions_mm,
            TableValues::Mean(values),
        ));
    }
    let sign = if cec_values_are_corrections {
        -1.0
    } else {
        1.0
    };
    let mut up = None;
    let mut down = None;
    for table in cec
        .values()
        // A cross-axis table (input ≠ output) is not the axis's own.
        .filter(|t| {
            t.output_axis.as_deref() == Some(axis)
                && t.input_axis.as_deref().is_none_or(|input| input == axis)
        })
    {
        let (positions, values) = columns(table)?;
        let values: Vec<f64> = values.iter().map(|v| sign * v).collect();
        match table.direction {
            1 => up = Some((positions, values)),
            -1 => down = Some((positions, values)),
            _ => {
                up = Some((positions.clone(), values.clone()));
                down = Some((positions, values));
            }
        }
    }
    match (up, down) {
        (Some((positions, up)), Some((down_positions, down))) if positions == down_positions => {
            let values = if up == down {
                TableValues::Mean(up)
            } else {
                TableValues::Bidirectional { up, down }
            };
            Ok(super::table_as_read(axis, positions, values))
        }
        (Some(_), Some(_)) => Err(ParseError::new(
            1,
            1,
            format!("the ↑ and ↓ CEC tables of {axis} have different points"),
        )),
        _ => Err(ParseError::new(
            1,
            1,
            format!(
                "no $AA_ENC_COMP table and no complete pair of $AN_CEC tables (DIRECTION 1 and -1) for axis {axis}"
            ),
        )),
    }
}

/// The LEC tables by axis name and the CEC tables by index, as written.
type RawTables<'a> = (
    BTreeMap<String, RawTable<'a>>,
    BTreeMap<usize, RawTable<'a>>,
);

fn raw_tables(input: &str) -> Result<RawTables<'_>, ParseError> {
    let mut lec: BTreeMap<String, RawTable<'_>> = BTreeMap::new();
    let mut cec: BTreeMap<usize, RawTable<'_>> = BTreeMap::new();
    for line in text::lines(input) {
        let Some(a) = assignment(&line)? else {
            continue;
        };
        let number = |token: &str, what: &str| text::number(&a.line, token, what);
        let index = |i: usize, what: &str| -> Result<usize, ParseError> {
            let token = a.indices.get(i).copied().unwrap_or("");
            Ok(text::integer(&a.line, token, what)? as usize)
        };
        match a.name.as_str() {
            "AA_ENC_COMP" | "AA_ENC_COMP_STEP" | "AA_ENC_COMP_MIN" | "AA_ENC_COMP_MAX" => {
                let axis_name = a.indices.last().copied().unwrap_or("").to_string();
                let table = lec.entry(axis_name).or_default();
                table.first_line.get_or_insert(a.line);
                match a.name.as_str() {
                    "AA_ENC_COMP" => {
                        let n = index(1, "interpolation point")?;
                        table
                            .points
                            .insert(n, (number(a.value, "compensation value")?, a.line));
                    }
                    "AA_ENC_COMP_STEP" => table.step = Some(number(a.value, "step")?),
                    "AA_ENC_COMP_MIN" => table.min = Some(number(a.value, "start position")?),
                    _ => table.max = Some(number(a.value, "end position")?),
                }
            }
            name if name.starts_with("AN_CEC") => {
                let t = index(0, "table index")?;
                let table = cec.entry(t).or_default();
                table.first_line.get_or_insert(a.line);
                match name {
                    "AN_CEC" => {
                        let n = index(1, "interpolation point")?;
                        table
                            .points
                            .insert(n, (number(a.value, "compensation value")?, a.line));
                    }
                    "AN_CEC_STEP" => table.step = Some(number(a.value, "step")?),
                    "AN_CEC_MIN" => table.min = Some(number(a.value, "start position")?),
                    "AN_CEC_MAX" => table.max = Some(number(a.value, "end position")?),
                    "AN_CEC_DIRECTION" => {
                        table.direction = match a.value {
                            "0" => 0,
                            "1" => 1,
                            "-1" => -1,
                            other => {
                                return Err(a
                                    .line
                                    .expected_at(other, "$AN_CEC_DIRECTION 0, 1 or -1"));
                            }
                        }
                    }
                    "AN_CEC_INPUT_AXIS" => {
                        table.input_axis =
                            Some(a.value.trim_matches(|c| c == '(' || c == ')').to_string())
                    }
                    "AN_CEC_OUTPUT_AXIS" => {
                        table.output_axis =
                            Some(a.value.trim_matches(|c| c == '(' || c == ')').to_string())
                    }
                    _ => {}
                }
            }
            _ => {}
        }
    }
    Ok((lec, cec))
}

/// Positions MIN + N·STEP and the values, checking the table is complete.
fn columns(table: &RawTable<'_>) -> Result<(Vec<f64>, Vec<f64>), ParseError> {
    let at = table.first_line.map_or((1, 1), |l| (l.number, 1));
    let (Some(step), Some(min), Some(max)) = (table.step, table.min, table.max) else {
        return Err(ParseError::new(
            at.0,
            at.1,
            "expected STEP, MIN and MAX for the table, found only some",
        ));
    };
    let count = table.points.len();
    if count < 2 || table.points.keys().enumerate().any(|(i, n)| i != *n) {
        return Err(ParseError::new(
            at.0,
            at.1,
            "expected interpolation points 0, 1, 2, … without gaps",
        ));
    }
    let expected_max = min + (count - 1) as f64 * step;
    if step <= 0.0 || (expected_max - max).abs() > 1e-6 {
        return Err(ParseError::new(
            at.0,
            at.1,
            format!(
                "MAX is {max} but MIN + {}·STEP is {expected_max}",
                count - 1
            ),
        ));
    }
    let positions = (0..count).map(|n| min + n as f64 * step).collect();
    let values = table.points.values().map(|(v, _)| *v).collect();
    Ok((positions, values))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::profile::MachineProfile;
    use crate::units::LengthUnit;

    fn options() -> EmitOptions {
        EmitOptions {
            axes: vec![MachineProfile::default().axis("X").unwrap()],
            table_name: String::new(),
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

    fn table(values: TableValues) -> CompensationTable {
        CompensationTable {
            axis: "X".into(),
            kind: crate::measurement::AxisKind::Linear,
            positions: vec![-200.0, -199.0, -198.0],
            values,
            reference: -200.0,
            suggested_backlash: None,
        }
    }

    #[test]
    fn lec_as_the_manual_example() {
        // K3 03/2013 p.240: +3 µm, +10 µm, +12 µm at −200, −199, −198 mm, step 1.0.
        let lec = table(TableValues::Mean(vec![0.003, 0.01, 0.012]));
        let text = write(&lec, &options()).unwrap();
        assert_eq!(
            text,
            "%_N_AX_EEC_INI\nCHANDATA(1)\n$AA_ENC_COMP[0,0,X1]=0.003\n$AA_ENC_COMP[0,1,X1]=0.01\n$AA_ENC_COMP[0,2,X1]=0.012\n\
             $AA_ENC_COMP_STEP[0,X1]=1.0\n$AA_ENC_COMP_MIN[0,X1]=-200.0\n$AA_ENC_COMP_MAX[0,X1]=-198.0\n$AA_ENC_COMP_IS_MODULO[0,X1]=0\nM17\n"
        );
        let back = read(&text, "X1", true).unwrap();
        assert_eq!((back.positions, back.values), (lec.positions, lec.values));
    }

    #[test]
    fn cross_axis_values_say_what_the_cec_holds() {
        // Corrections: the file holds −error; otherwise the error itself.
        let corrections = options();
        let errors = EmitOptions {
            cec_values_are_corrections: false,
            ..options()
        };
        assert_eq!(
            cross_axis_values(&corrections),
            CrossAxisValues {
                sign: -1.0,
                name: "correction (−error)"
            }
        );
        assert_eq!(
            cross_axis_values(&errors),
            CrossAxisValues {
                sign: 1.0,
                name: "error"
            }
        );
    }

    #[test]
    fn cec_pair_round_trips_and_negates() {
        let both = table(TableValues::Bidirectional {
            up: vec![0.0, 0.001, 0.002],
            down: vec![-0.004, -0.003, -0.002],
        });
        let text = write(&both, &options()).unwrap();
        assert!(
            text.starts_with(
                "%_N_NC_CEC_INI\nCHANDATA(1)\n$AN_CEC[0,0]=0.0\n$AN_CEC[0,1]=-0.001\n"
            ),
            "{text}"
        );
        assert!(
            text.contains("$AN_CEC_DIRECTION[0]=1\n") && text.contains("$AN_CEC_DIRECTION[1]=-1\n")
        );
        assert!(text.contains("$AN_CEC[1,0]=0.004\n"));
        assert_eq!(read(&text, "X1", true).unwrap().values, both.values);
        // Read with the other sign convention, every value flips.
        let flipped = read(&text, "X1", false).unwrap();
        assert_eq!(
            flipped
                .values
                .for_direction(crate::measurement::Direction::Down)[0],
            0.004
        );
    }

    #[test]
    fn incomplete_tables_are_refused() {
        let text = "%_N_AX_EEC_INI\nCHANDATA(1)\n$AA_ENC_COMP[0,0,X1]=0.0\n$AA_ENC_COMP[0,2,X1]=0.0\n$AA_ENC_COMP_STEP[0,X1]=1.0\n$AA_ENC_COMP_MIN[0,X1]=0.0\n$AA_ENC_COMP_MAX[0,X1]=2.0\nM17\n";
        assert!(
            read(text, "X1", true)
                .unwrap_err()
                .message
                .contains("without gaps")
        );
        let wrong_max = text.replace("[0,2,X1]", "[0,1,X1]");
        assert!(
            read(&wrong_max, "X1", true)
                .unwrap_err()
                .message
                .contains("MAX is 2")
        );
        assert!(
            read(&wrong_max, "Y1", true)
                .unwrap_err()
                .message
                .contains("for axis Y1")
        );
        let bad = text.replace("=0.0\n$AA_ENC_COMP[0,2", "=0,5\n$AA_ENC_COMP[0,2");
        assert!(
            read(&bad, "X1", true)
                .unwrap_err()
                .message
                .contains("decimal comma")
        );
    }
}
