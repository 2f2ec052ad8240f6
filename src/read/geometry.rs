//! axcomp's CSV layout for geometry tests: straightness, angular and
//! multi-error (6-DOF) measurements of one linear axis, parser and writer.
//!
//! The positioning CSV ([`super::csv`]) with one column per measured error
//! instead of `deviation_um` (documented in docs/src/input-formats.md, "Geometry tests"):
//! ```text
//! # axis: X
//! target_mm,run,direction,EYX_um,EZX_um,EBX_urad,ECX_arcsec
//! 0,1,up,0.0,0.0,0.0,0.0
//! 50,1,up,0.41,-0.2,1.3,0.25
//! ```
//! - Each error column is an ISO 230-1 name as the model writes it
//!   (`../shared/notes/seed000-volumetric-model.md` §1: `E<direction><axis>`
//!   for a translation, `E<A|B|C><axis>` for a rotation about X, Y, Z) and
//!   its unit: `_um` for a straightness (or positioning, `EXX_um`) in µm in
//!   the direction the name states, `_urad` or `_arcsec` for an angle (pitch,
//!   yaw, roll). All columns are of one moving axis, the name's last letter;
//!   a `# axis:` line, if any, must agree with it.
//! - Values are as the instrument reads them: actual − nominal, the angle
//!   right-handed about the named axis. An empty field is a missing reading.
//!   Targets mm, run numbers per direction, `up`/`down` as in the
//!   positioning CSV; separator `,`, decimal point `.`.
//! - Squareness is not a column: it comes from two straightness tests of a
//!   pair of axes (`evaluate::straightness`, `predict::survey`).
//!
//! Inside, translations are mm and angles rad (the model's units), through
//! `units.rs`. This module reads text only; `read_geometry_path` in
//! `read/mod.rs` opens the file.

use std::collections::HashMap;

use crate::error::{ParseError, describe_found};
use crate::measurement::Direction;
use crate::read::text::{self, Line, check_deviation_mm, check_target_mm, end_of_file_line};
use crate::units::{arcsec_to_urad, mm_to_um, rad_to_um_per_m, um_per_m_to_rad, um_to_mm};

/// The largest angle a reading may hold, rad (about 0.57°: an error motion
/// of a machine axis is µrad; anything near this is a unit mistake).
pub const MAX_ANGLE_RAD: f64 = 0.01;

/// The three fields before the error columns.
const LEADING: [&str; 3] = ["target_mm", "run", "direction"];

/// What a column measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// A translation in the direction `X`, `Y` or `Z` (straightness, or
    /// positioning when it is the moving axis itself), mm inside.
    Translation(char),
    /// A rotation about `X`, `Y` or `Z` (roll, pitch, yaw), rad inside.
    Rotation(char),
}

/// The unit a column is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnUnit {
    /// µm (translations).
    Micrometre,
    /// µrad (angles).
    Microradian,
    /// Arc-seconds (angles).
    Arcsecond,
}

impl ColumnUnit {
    /// The suffix in the header: `um`, `urad`, `arcsec`.
    pub fn suffix(self) -> &'static str {
        match self {
            ColumnUnit::Micrometre => "um",
            ColumnUnit::Microradian => "urad",
            ColumnUnit::Arcsecond => "arcsec",
        }
    }
}

/// One run of one error column: values per target (mm or rad), `None` where
/// missing.
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryRun {
    /// Run number within its direction (1, 2, …).
    pub number: u64,
    /// Direction of approach.
    pub direction: Direction,
    /// One value per target of the test: mm (translation) or rad (rotation).
    pub values: Vec<Option<f64>>,
}

/// One error column of a test.
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryColumn {
    /// The ISO 230-1 name, upper case: `EYX`, `EBX`, `EXX`.
    pub name: String,
    /// What it measures.
    pub quantity: Quantity,
    /// The unit the file wrote it in (values inside are mm or rad).
    pub unit: ColumnUnit,
    /// The runs, in the order they first appear.
    pub runs: Vec<GeometryRun>,
}

impl GeometryColumn {
    /// Per target, the mean over every run of both directions (mm or rad);
    /// `None` where no run has a reading. Straightness and angles have no
    /// direction in the model, so both directions average.
    pub fn means(&self) -> Vec<Option<f64>> {
        let n = self.runs.first().map_or(0, |r| r.values.len());
        (0..n)
            .map(|i| {
                let values: Vec<f64> = self.runs.iter().filter_map(|r| r.values[i]).collect();
                (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
            })
            .collect()
    }
}

/// A geometry test of one linear axis.
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryTest {
    /// The moving axis: `X`, `Y` or `Z`.
    pub axis: char,
    /// Targets, mm, strictly increasing.
    pub targets_mm: Vec<f64>,
    /// The error columns, in the file's order.
    pub columns: Vec<GeometryColumn>,
    /// `# machine:`, if given.
    pub machine: Option<String>,
}

impl GeometryTest {
    /// The column of an error name (`EYX`), if the test has it.
    pub fn column(&self, name: &str) -> Option<&GeometryColumn> {
        self.columns
            .iter()
            .find(|c| c.name.eq_ignore_ascii_case(name))
    }
}

/// The error column a header field names, or why not.
fn column_of(field: &str) -> Result<(String, Quantity, ColumnUnit), String> {
    let expected = "an error column NAME_UNIT: EYX_um (straightness of X in Y, µm), EBX_urad or EBX_arcsec (pitch of X), … (ISO 230-1 names)";
    let Some((name, unit)) = field.rsplit_once('_') else {
        return Err(format!(
            "expected {expected}, found {}",
            describe_found(field)
        ));
    };
    let name = name.to_ascii_uppercase();
    let letters: Vec<char> = name.chars().collect();
    let axis_letter = |c: char| matches!(c, 'X' | 'Y' | 'Z');
    if letters.len() != 3 || letters[0] != 'E' || !axis_letter(letters[2]) {
        return Err(format!(
            "expected {expected}, found {}",
            describe_found(field)
        ));
    }
    let quantity = match letters[1] {
        c if axis_letter(c) => Quantity::Translation(c),
        'A' => Quantity::Rotation('X'),
        'B' => Quantity::Rotation('Y'),
        'C' => Quantity::Rotation('Z'),
        _ => {
            return Err(format!(
                "expected {expected}, found {}",
                describe_found(field)
            ));
        }
    };
    let unit = match (quantity, unit.to_ascii_lowercase().as_str()) {
        (Quantity::Translation(_), "um") => ColumnUnit::Micrometre,
        (Quantity::Rotation(_), "urad") => ColumnUnit::Microradian,
        (Quantity::Rotation(_), "arcsec") => ColumnUnit::Arcsecond,
        (Quantity::Translation(_), _) => {
            return Err(format!(
                "expected {name}_um ({name} is a translation, in µm), found {}",
                describe_found(field)
            ));
        }
        (Quantity::Rotation(_), _) => {
            return Err(format!(
                "expected {name}_urad or {name}_arcsec ({name} is an angle), found {}",
                describe_found(field)
            ));
        }
    };
    Ok((name, quantity, unit))
}

/// Whether a line is a geometry header (`target_mm,run,direction,E…_…`).
pub fn is_header(line: &str) -> bool {
    let fields: Vec<&str> = line.split(',').map(str::trim).collect();
    fields.len() > 3
        && LEADING
            .iter()
            .zip(&fields)
            .all(|(a, b)| a.eq_ignore_ascii_case(b))
        && fields[3..].iter().all(|f| column_of(f).is_ok())
}

/// A header's error column: name, quantity, unit.
type ColumnSpec = (String, Quantity, ColumnUnit);

/// One data row of a run: target, values, line number.
type Row = (f64, Vec<Option<f64>>, usize);

/// Parses the text of a geometry test.
pub fn parse(input: &str) -> Result<GeometryTest, ParseError> {
    let mut stated_axis: Option<(String, usize)> = None;
    let mut machine = None;
    let mut header: Option<(Vec<ColumnSpec>, Line<'_>)> = None;
    // (direction, run) → index in `runs`; per run, (target, values) rows.
    let mut run_index: HashMap<(Direction, u64), usize> = HashMap::new();
    let mut runs: Vec<(Direction, u64, Vec<Row>)> = Vec::new();
    for line in text::lines(input) {
        let trimmed = line.text.trim();
        if trimmed.is_empty() {
            continue;
        }
        if let Some(comment) = trimmed.strip_prefix('#') {
            if header.is_none()
                && let Some((key, value)) = text::split_key(comment, ':')
            {
                match key.trim().to_ascii_lowercase().as_str() {
                    "axis" => stated_axis = Some((value.trim().to_string(), line.number)),
                    "machine" => machine = Some(value.trim().to_string()),
                    _ => {}
                }
            }
            continue;
        }
        let Some((columns, header_line)) = header.as_ref() else {
            let fields: Vec<&str> = trimmed.split(',').map(str::trim).collect();
            let leading_ok = fields.len() > 3
                && LEADING
                    .iter()
                    .zip(&fields)
                    .all(|(a, b)| a.eq_ignore_ascii_case(b));
            if !leading_ok {
                return Err(line.expected_at(
                    trimmed,
                    "the header target_mm,run,direction followed by error columns (EYX_um, EBX_urad, …)",
                ));
            }
            let mut columns = Vec::new();
            for field in &fields[3..] {
                let column = column_of(field).map_err(|m| line.error_at(field, m))?;
                if columns.iter().any(|(n, _, _)| *n == column.0) {
                    return Err(line.error_at(field, format!("{} is listed twice", column.0)));
                }
                if let Some((first, _, _)) = columns.first() {
                    let first: &String = first;
                    if first.chars().last() != column.0.chars().last() {
                        return Err(line.error_at(
                            field,
                            format!(
                                "{} is of another axis than {first}: a test holds the errors of one moving axis",
                                column.0
                            ),
                        ));
                    }
                }
                columns.push(column);
            }
            header = Some((columns, line));
            continue;
        };
        let fields: Vec<&str> = line.text.split(',').map(str::trim).collect();
        if fields.iter().all(|f| f.is_empty()) {
            continue;
        }
        if fields.len() != 3 + columns.len() {
            return Err(line.error_at(
                line.text.trim_start(),
                format!(
                    "row has {} field(s), expected {} as the header on line {}",
                    fields.len(),
                    3 + columns.len(),
                    header_line.number
                ),
            ));
        }
        let target_mm = text::number(&line, fields[0], "target in mm")?;
        check_target_mm(target_mm, line.number, line.column_of(fields[0]))?;
        let (run, direction) = text::run_and_direction(&line, fields[1], fields[2])?;
        let mut values = Vec::with_capacity(columns.len());
        for ((name, quantity, unit), field) in columns.iter().zip(&fields[3..]) {
            if field.is_empty() {
                values.push(None);
                continue;
            }
            let what = format!("{name} in {}", unit.suffix());
            let value = text::number(&line, field, &what)?;
            let column = line.column_of(field);
            values.push(Some(match (quantity, unit) {
                (Quantity::Translation(_), _) => {
                    check_deviation_mm(um_to_mm(value), line.number, column)?
                }
                (Quantity::Rotation(_), unit) => {
                    let urad = match unit {
                        ColumnUnit::Arcsecond => arcsec_to_urad(value),
                        _ => value,
                    };
                    let rad = um_per_m_to_rad(urad);
                    if rad.abs() > MAX_ANGLE_RAD {
                        return Err(line.error_at(
                            field,
                            format!(
                                "{name} {value} {} is beyond ±{} µrad: an error motion is a few µrad (a unit mistake?)",
                                unit.suffix(),
                                rad_to_um_per_m(MAX_ANGLE_RAD)
                            ),
                        ));
                    }
                    rad
                }
            }));
        }
        let index = *run_index.entry((direction, run)).or_insert_with(|| {
            runs.push((direction, run, Vec::new()));
            runs.len() - 1
        });
        let rows = &mut runs[index].2;
        if let Some((_, _, first)) = rows.iter().find(|(t, _, _)| *t == target_mm) {
            return Err(line.error_at(
                trimmed,
                format!(
                    "run {run}{direction} at {target_mm} mm is listed twice (first at line {first})"
                ),
            ));
        }
        rows.push((target_mm, values, line.number));
    }
    let Some((columns, header_line)) = header else {
        return Err(ParseError::new(
            end_of_file_line(input),
            1,
            "expected the header target_mm,run,direction,E…_um/_urad/_arcsec, found end of file",
        ));
    };
    if runs.is_empty() {
        return Err(ParseError::new(
            end_of_file_line(input),
            1,
            "expected at least one data row, found end of file",
        ));
    }
    let axis = columns[0].0.chars().last().unwrap_or('X');
    if let Some((stated, line)) = stated_axis
        && !stated.eq_ignore_ascii_case(&axis.to_string())
    {
        return Err(ParseError::new(
            line,
            1,
            format!(
                "# axis: {stated} but the columns ({}) are errors of axis {axis}",
                columns
                    .iter()
                    .map(|c| c.0.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    let mut targets_mm: Vec<f64> = runs
        .iter()
        .flat_map(|(_, _, rows)| rows.iter().map(|(t, _, _)| *t))
        .collect();
    targets_mm.sort_by(f64::total_cmp);
    targets_mm.dedup();
    if targets_mm.len() < 2 {
        return Err(ParseError::new(
            header_line.number,
            1,
            "expected at least two targets: a geometry error is a function along the axis",
        ));
    }
    let columns = columns
        .into_iter()
        .enumerate()
        .map(|(k, (name, quantity, unit))| GeometryColumn {
            name,
            quantity,
            unit,
            runs: runs
                .iter()
                .map(|(direction, number, rows)| {
                    let mut values = vec![None; targets_mm.len()];
                    for (target, row, _) in rows {
                        let i = targets_mm.partition_point(|t| t < target);
                        values[i] = row[k];
                    }
                    GeometryRun {
                        number: *number,
                        direction: *direction,
                        values,
                    }
                })
                .collect(),
        })
        .collect();
    Ok(GeometryTest {
        axis,
        targets_mm,
        columns,
        machine,
    })
}

/// Writes a test in the layout [`parse`] reads; every number in the
/// shortest text that reads back to the same value.
pub fn write(test: &GeometryTest) -> String {
    let mut out = format!("# axis: {}\n", test.axis);
    if let Some(machine) = &test.machine {
        out.push_str(&format!("# machine: {machine}\n"));
    }
    out.push_str(&LEADING.join(","));
    for column in &test.columns {
        out.push_str(&format!(",{}_{}", column.name, column.unit.suffix()));
    }
    out.push('\n');
    let Some(first) = test.columns.first() else {
        return out;
    };
    for (r, run) in first.runs.iter().enumerate() {
        for (i, target) in test.targets_mm.iter().enumerate() {
            out.push_str(&format!(
                "{target},{},{}",
                run.number,
                run.direction.as_str()
            ));
            for column in &test.columns {
                let value = column.runs[r].values[i].map(|v| match column.unit {
                    ColumnUnit::Micrometre => mm_to_um(v),
                    ColumnUnit::Microradian => rad_to_um_per_m(v),
                    ColumnUnit::Arcsecond => rad_to_um_per_m(v) / arcsec_to_urad(1.0),
                });
                out.push(',');
                if let Some(value) = value {
                    out.push_str(&format!("{value}"));
                }
            }
            out.push('\n');
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = "# axis: X\n# machine: test\ntarget_mm,run,direction,EYX_um,EBX_urad,ECX_arcsec\n\
        0,1,up,0,0,0\n100,1,up,1.5,2,1\n0,1,down,0.2,0,\n100,1,down,1.7,4,1\n";

    #[test]
    fn reads_units_into_mm_and_rad() {
        let test = parse(SAMPLE).unwrap();
        assert_eq!(test.axis, 'X');
        assert_eq!(test.targets_mm, vec![0.0, 100.0]);
        let eyx = test.column("EYX").unwrap();
        assert_eq!(eyx.quantity, Quantity::Translation('Y'));
        // By hand: (1.5 + 1.7) / 2 µm = 1.6 µm = 0.0016 mm.
        assert!((eyx.means()[1].unwrap() - 0.0016).abs() < 1e-15);
        assert!((eyx.means()[0].unwrap() - 0.0001).abs() < 1e-15);
        let ebx = test.column("ebx").unwrap();
        assert_eq!(ebx.quantity, Quantity::Rotation('Y'));
        assert!((ebx.means()[1].unwrap() - 3e-6).abs() < 1e-18);
        // 1″ = π/648000 rad = 4.8481 µrad; the ↓ reading at 0 mm is missing.
        let ecx = test.column("ECX").unwrap();
        assert!((ecx.means()[1].unwrap() - 4.848_136_8e-6).abs() < 1e-12);
        assert_eq!(ecx.runs[1].values[0], None);
    }

    #[test]
    fn written_text_reads_back() {
        let test = parse(SAMPLE).unwrap();
        let again = parse(&write(&test)).unwrap();
        assert_eq!(again.targets_mm, test.targets_mm);
        for (a, b) in again.columns.iter().zip(&test.columns) {
            for (ra, rb) in a.runs.iter().zip(&b.runs) {
                for (va, vb) in ra.values.iter().zip(&rb.values) {
                    match (va, vb) {
                        (Some(x), Some(y)) => assert!((x - y).abs() < 1e-15),
                        (x, y) => assert_eq!(x, y),
                    }
                }
            }
        }
    }

    #[test]
    fn bad_files_name_line_and_column() {
        let cases = [
            (
                "target_mm,run,direction,EYX_urad\n0,1,up,1\n",
                (1, 25),
                "EYX_um",
            ),
            (
                "target_mm,run,direction,EBX_um\n0,1,up,1\n",
                (1, 25),
                "EBX_urad",
            ),
            (
                "target_mm,run,direction,EYX_um,EZY_um\n",
                (1, 32),
                "another axis",
            ),
            ("target_mm,run,direction,EQX_um\n", (1, 25), "error column"),
            (
                "target_mm,run,direction,EYX_um\n0,1,up,x\n",
                (2, 8),
                "EYX in um",
            ),
            (
                "target_mm,run,direction,EBX_urad\n0,1,up,1\n9,1,up,20000\n",
                (3, 8),
                "unit mistake",
            ),
            (
                "target_mm,run,direction,EYX_um\n0,1,up\n",
                (2, 1),
                "expected 4",
            ),
            (
                "# axis: Y\ntarget_mm,run,direction,EYX_um\n0,1,up,1\n5,1,up,1\n",
                (1, 1),
                "axis X",
            ),
            (
                "target_mm,run,direction,EYX_um\n0,1,up,1\n0,1,up,2\n",
                (3, 1),
                "twice",
            ),
            ("target_mm,run,direction\n", (1, 1), "header"),
            (
                "target_mm,run,direction,EYX_um\n0,1,up,1\n",
                (1, 1),
                "two targets",
            ),
        ];
        for (text, (line, column), needle) in cases {
            let error = parse(text).unwrap_err();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "{text}: {error}"
            );
            assert!(error.message.contains(needle), "{text}: {error}");
        }
        assert!(is_header("target_mm,run,direction,EYX_um,ECX_urad"));
        assert!(!is_header("target_mm,run,direction,deviation_um"));
    }
}
