//! Fagor 8055 and 8065 against the real files of one machine
//! (`../shared/data/api-xd/`, see SOURCES.md): every table reads, the
//! malformed one is refused with its position, `convert --existing` gives
//! the old table plus the measured residual, and the 8065 update changes only
//! the leadscrew lines. The expected numbers are computed here from the
//! files with plain text handling, not with axcomp's readers.

use std::path::Path;

use axcomp::emit::{self, Controller, EmitOptions, MachineProfile, TextEncoding};
use axcomp::units::LengthUnit;

use crate::util::{axcomp, shared_data};

pub(crate) fn data(name: &str) -> String {
    shared_data(&format!("api-xd/{name}")).display().to_string()
}

/// (file, axis the file states, format) for every Fagor table in the folder.
const TABLES: &[(&str, &str, Controller)] = &[
    ("example__8055__ALX", "X", Controller::Fagor8055),
    ("example__8055__ALX.out", "X", Controller::Fagor8055),
    ("example__8055__ALY", "Y", Controller::Fagor8055),
    ("example__8055__ALY.out", "Y", Controller::Fagor8055),
    ("example__8055__ALV", "V", Controller::Fagor8055),
    // Named ALZ, but its lines say X (an identical copy of ALX upstream).
    ("example__8055__ALZ", "X", Controller::Fagor8055),
    ("example__V__ALV", "V", Controller::Fagor8055),
    ("example__V__ALV.out", "V", Controller::Fagor8055),
    ("example__issue-01__ALX", "X", Controller::Fagor8055),
    ("example__issue-01__ALX.out", "X", Controller::Fagor8055),
    (
        "example__issue-01__ALX.out-orig",
        "X",
        Controller::Fagor8055,
    ),
    ("test__data__ALX", "X", Controller::Fagor8055),
    ("test__data__ALA", "A", Controller::Fagor8055),
    ("example__8065__X.mp", "X", Controller::Fagor8065),
    ("example__8065__X.mp.out", "X", Controller::Fagor8065),
    ("example__8065__Y.mp", "Y", Controller::Fagor8065),
    ("example__8065__Y.mp.out", "Y", Controller::Fagor8065),
    ("test__data__X.mp", "X", Controller::Fagor8065),
];

fn options(axis: &str) -> EmitOptions {
    let mut options = EmitOptions::for_axis(&MachineProfile::default(), axis, "").unwrap();
    options.machine_unit = LengthUnit::Inch;
    options
}

#[test]
fn every_real_fagor_table_reads() {
    for (file, axis, controller) in TABLES {
        let bytes = std::fs::read(data(file)).unwrap();
        let (text, _) = emit::decode_table(&bytes).unwrap();
        let (found, table) =
            emit::read_any(&text, &options(axis), None).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(found, *controller, "{file}");
        assert!(table.positions.len() >= 3, "{file}");
    }
    // By hand: ALX P002 is 5 in = 127 mm, −0.00127 in = −0.032258 mm;
    // X.mp POSITION 1 = −127.0000 mm, POSERROR 1 = −0.0127 mm.
    let alx = std::fs::read_to_string(data("example__8055__ALX")).unwrap();
    let (_, table) = emit::read_any(&alx, &options("X"), None).unwrap();
    assert_eq!(table.positions[1], 127.0);
    assert!(
        (table
            .values
            .for_direction(axcomp::measurement::Direction::Up)[1]
            + 0.032_258)
            .abs()
            < 1e-12
    );
    let (text, encoding) =
        emit::decode_table(&std::fs::read(data("example__8065__X.mp")).unwrap()).unwrap();
    assert_eq!(encoding, TextEncoding::Utf16Le);
    let (_, table) = emit::read_any(&text, &options("X"), None).unwrap();
    assert_eq!((table.positions[0], table.positions.len()), (-127.0, 27));
    let (_, encoding) =
        emit::decode_table(&std::fs::read(data("example__8065__Y.mp.out")).unwrap()).unwrap();
    assert_eq!(encoding, TextEncoding::Utf16Be);
}

#[test]
fn the_malformed_real_files_are_refused_with_their_position() {
    let directory = tempfile::tempdir().unwrap();
    let laser = data("example__8055__X Axis Forward.pos");
    let out = directory.path().join("A.mp").display().to_string();
    // test/data/A.mp: NPOINTS 27 (line 87) but only 10 POSITION entries.
    let mp = data("test__data__A.mp");
    let run = axcomp([
        "convert",
        &laser,
        "--axis",
        "A",
        "--existing",
        &mp,
        "--controller",
        "fagor8065",
        "-o",
        &out,
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(&format!(
            "{mp}:87:54: NPOINTS is 27, but POSITION 11 is missing"
        )),
        "{}",
        run.stderr
    );
    // ALZ holds axis X lines: refused for the Z axis at the axis letter.
    let alz = data("example__8055__ALZ");
    let run = axcomp([
        "convert",
        &laser,
        "--axis",
        "Z",
        "--existing",
        &alz,
        "--controller",
        "fagor8055",
        "-o",
        &out,
    ]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr
            .contains(&format!("{alz}:1:21: this is a table of axis X")),
        "{}",
        run.stderr
    );
    assert!(!Path::new(&out).exists());
}

/// The `API Linear Error Compensation Table` of a `.pos` file: (inch, inch).
pub(crate) fn laser_errors(file: &str) -> Vec<(f64, f64)> {
    number_rows(
        file,
        |l| l.contains("Unidirectional Avg Error"),
        |f| (f.len() == 2).then(|| (f[0], f[1])),
    )
}

/// The measured data of a `.pos` file: (target, LinearError), inch. (Its
/// compensation table can be an edited copy: the 8065 X file's is −5 … 125 in
/// where the data are 0 … 130 in.)
pub(crate) fn laser_data(file: &str) -> Vec<(f64, f64)> {
    number_rows(
        file,
        |l| l.trim_start().starts_with("Position"),
        |f| (f.len() >= 3).then(|| (f[0], f[2])),
    )
}

/// The rows of numbers after the first line `header` accepts, while `pick` takes them.
fn number_rows(
    file: &str,
    header: impl Fn(&str) -> bool,
    pick: impl Fn(&[f64]) -> Option<(f64, f64)>,
) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(data(file)).unwrap();
    text.lines()
        .skip_while(|l| !header(l))
        .skip(1)
        .map_while(|l| {
            let f: Vec<f64> = l
                .split_whitespace()
                .filter_map(|t| t.parse().ok())
                .collect();
            pick(&f)
        })
        .collect()
}

/// (position, positive error) of an 8055 table, in its unit (inch).
pub(crate) fn al_rows(text: &str) -> Vec<(f64, f64)> {
    text.lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            (f.len() == 7).then(|| (f[2].parse().unwrap(), f[4].parse().unwrap()))
        })
        .collect()
}

/// (position, POSERROR) of an .mp file, mm.
pub(crate) fn mp_rows(bytes: &[u8]) -> Vec<(f64, f64)> {
    let (text, _) = emit::decode_table(bytes).unwrap();
    let value = |list: &str| -> Vec<f64> {
        text.lines()
            .filter(|l| l.contains(&format!("/DATA/{list} ")))
            .map(|l| l.rsplit(';').next().unwrap().trim().parse().unwrap())
            .collect()
    };
    value("POSITION")
        .into_iter()
        .zip(value("POSERROR"))
        .collect()
}

fn convert(laser: &str, table: &str, controller: &str, axis: &str, out: &Path) -> Vec<u8> {
    let run = axcomp([
        "convert",
        &data(laser),
        "--axis",
        axis,
        "--existing",
        &data(table),
        "--controller",
        controller,
        "--reference",
        "0",
        "-o",
        &out.display().to_string(),
        "-q",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    std::fs::read(out).unwrap()
}

/// The new table is the old one plus the laser's residual e, zero at the
/// machine zero (−e(0)): old + e − e(0) at every common point, to 0.5 µm.
/// laser_adjust's outputs are old + k·e (8055 X, Y: k = N + 2 − j for the
/// j-th laser row of N, a repeated addition) and, on the 8065, k·e with the
/// inch numbers taken as mm: the differences from them are listed in
/// formats/fagor8055/README.md and formats/fagor8065/README.md.
#[test]
fn existing_tables_take_the_measured_residual() {
    let directory = tempfile::tempdir().unwrap();
    let cases = [
        (
            "example__8055__X Axis Forward.pos",
            "example__8055__ALX",
            "fagor8055",
            "X",
            49.022,
        ),
        (
            "example__8055__Y Axis Forward.pos",
            "example__8055__ALY",
            "fagor8055",
            "Y",
            176.276,
        ),
        (
            "example__8065__X Axis Forward.pos",
            "example__8065__X.mp",
            "fagor8065",
            "X",
            3.1,
        ),
        (
            "example__8065__Y Axis Forward.pos",
            "example__8065__Y.mp",
            "fagor8065",
            "Y",
            16.4,
        ),
    ];
    for (laser, table, controller, axis, tool_difference_um) in cases {
        let out = directory.path().join(format!("{table}.new"));
        let new = convert(laser, table, controller, axis, &out);
        let old_bytes = std::fs::read(data(table)).unwrap();
        let tool_bytes = std::fs::read(data(&format!("{table}.out"))).unwrap();
        // Everything in mm.
        let (new, old, tool) = if controller == "fagor8055" {
            let mm = |rows: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
                rows.into_iter()
                    .map(|(p, v)| (p * 25.4, v * 25.4))
                    .collect()
            };
            let text = |b: &[u8]| String::from_utf8(b.to_vec()).unwrap();
            (
                mm(al_rows(&text(&new))),
                mm(al_rows(&text(&old_bytes))),
                mm(al_rows(&text(&tool_bytes))),
            )
        } else {
            (mp_rows(&new), mp_rows(&old_bytes), mp_rows(&tool_bytes))
        };
        let at =
            |rows: &[(f64, f64)], p: f64| rows.iter().find(|r| (r.0 - p).abs() < 1e-6).map(|r| r.1);
        let errors: Vec<(f64, f64)> = laser_errors(laser)
            .into_iter()
            .map(|(p, e)| (p * 25.4, e * 25.4))
            .collect();
        let e0 = at(&errors, 0.0).unwrap();
        let measured: Vec<f64> = laser_data(laser).iter().map(|r| r.0 * 25.4).collect();
        let (mut compared, mut worst_tool_um) = (0, 0.0f64);
        for (position, value) in &new {
            let (Some(old_value), Some(e)) = (at(&old, *position), at(&errors, *position)) else {
                continue;
            };
            // Outside the measured targets the old value is kept (fagor_update.rs).
            if !measured.iter().any(|m| (m - position).abs() < 1e-6) {
                continue;
            }
            let expected = old_value + e - e0;
            assert!(
                (value - expected).abs() * 1000.0 <= 0.5,
                "{table} at {position} mm: {value} vs {expected}"
            );
            compared += 1;
            if let Some(tool_value) = at(&tool, *position) {
                worst_tool_um = worst_tool_um.max((value - tool_value).abs() * 1000.0);
            }
        }
        assert!(compared >= 17, "{table}: {compared} points compared");
        // The largest difference from the tool's output, as documented.
        assert!(
            (worst_tool_um - tool_difference_um).abs() < 0.05,
            "{table}: {worst_tool_um} µm"
        );
    }
}

/// Splits raw bytes into lines at the encoding's line feed, keeping it.
fn byte_lines(bytes: &[u8], encoding: TextEncoding) -> Vec<&[u8]> {
    let unit = match encoding {
        TextEncoding::Utf16Le => [b'\n', 0],
        _ => [0, b'\n'],
    };
    let mut lines = Vec::new();
    let mut start = 2;
    let mut k = 2;
    while k + 1 < bytes.len() {
        if bytes[k..k + 2] == unit {
            lines.push(&bytes[start..k + 2]);
            start = k + 2;
        }
        k += 2;
    }
    if start < bytes.len() {
        lines.push(&bytes[start..]);
    }
    lines
}

#[test]
fn the_8065_update_changes_only_the_leadscrew_lines() {
    let directory = tempfile::tempdir().unwrap();
    for (laser, table, axis, encoding) in [
        (
            "example__8065__X Axis Forward.pos",
            "example__8065__X.mp",
            "X",
            TextEncoding::Utf16Le,
        ),
        (
            "example__8065__Y Axis Forward.pos",
            "example__8065__Y.mp",
            "Y",
            TextEncoding::Utf16Le,
        ),
        // The tool's big-endian output without a final line feed as the active file.
        (
            "example__8065__Y Axis Forward.pos",
            "example__8065__Y.mp.out",
            "Y",
            TextEncoding::Utf16Be,
        ),
    ] {
        let out = directory.path().join(format!("{table}.new"));
        let new = convert(laser, table, "fagor8065", axis, &out);
        let old = std::fs::read(data(table)).unwrap();
        assert_eq!(new[..2], old[..2], "{table}: byte-order mark");
        assert_eq!(emit::decode_table(&new).unwrap().1, encoding);
        let is_table_line = |line: &[u8]| {
            let text: String = line
                .iter()
                .filter(|b| **b != 0)
                .map(|b| char::from(*b))
                .collect();
            text.contains("/LSCRWDATA/DATA/") || text.contains("/LSCRWDATA/NPOINTS")
        };
        let kept = |bytes: &[u8]| -> Vec<Vec<u8>> {
            byte_lines(bytes, encoding)
                .into_iter()
                .filter(|l| !is_table_line(l))
                .map(<[u8]>::to_vec)
                .collect()
        };
        assert_eq!(
            kept(&new),
            kept(&old),
            "{table}: a line outside the table changed"
        );
        assert_eq!(
            new.ends_with(&[0, b'\r']) || new.ends_with(&[b'\r', 0]),
            old.ends_with(&[0, b'\r']) || old.ends_with(&[b'\r', 0])
        );
        // NPOINTS says how many points there are.
        let (text, _) = emit::decode_table(&new).unwrap();
        let positions = text.matches("/DATA/POSITION ").count();
        assert!(
            text.contains(&format!(
                "/LSCRWDATA/NPOINTS                                ;{positions}\r"
            )),
            "{table}"
        );
    }
}
