//! API XD `.pos` files: sign and unit, checked row by row against the file's
//! own columns, and two files joined into one bidirectional measurement.

use std::path::Path;

use axcomp::measurement::Direction;
use axcomp::read::read_path;

use crate::util::{evaluate_json, shared_data};

const INCH_UM: f64 = 25_400.0;

#[test]
fn x_forward_rows_by_hand() {
    let path = shared_data("api-xd/example__8055__X Axis Forward.pos");
    let result = read_path(&path, None).unwrap();
    let m = result.measurement;
    assert_eq!(m.axis(), "X");
    assert_eq!(m.targets().len(), 27);
    assert_eq!(m.metadata.length_unit.as_str(), "inch");
    let run = &m.runs()[0];
    assert_eq!(run.direction, Direction::Up, "positions 0 → 130 in: ↑");
    // (Position [in], LasRead [in], LinearError [in]) as printed in the file.
    // The laser counts negative here: actual = −LasRead, and actual − target
    // must equal the file's LinearError.
    for (position, las_read, linear_error) in [
        (0.0, 0.000055, -0.000055),
        (5.0, -4.999953, -0.000047),
        (20.0, -20.000001, 0.000001),
        (130.0, -130.000026, 0.000026),
    ] {
        let index = m
            .targets()
            .iter()
            .position(|t| (t - position * 25.4).abs() < 1e-9)
            .unwrap();
        let actual_minus_target_in: f64 = -las_read - position;
        assert!(
            (actual_minus_target_in - linear_error).abs() < 1e-9,
            "the file is self-consistent at {position}"
        );
        let deviation_um = run.deviations[index].unwrap() * 1000.0;
        assert!(
            (deviation_um - linear_error * INCH_UM).abs() < 1e-9,
            "{position} in: {deviation_um} µm"
        );
    }
    // 68 °F and 29.92 inHg are 20 °C and 101.32 kPa.
    assert!((m.environment.air_temperature_c.start.unwrap() - 20.0).abs() < 1e-9);
    assert!((m.environment.air_pressure_kpa.start.unwrap() - 101.3208).abs() < 1e-3);
}

#[test]
fn y_forward_counts_the_other_way_and_moves_down() {
    let path = shared_data("api-xd/example__8055__Y Axis Forward.pos");
    let result = read_path(&path, None).unwrap();
    let m = &result.measurement;
    let run = &m.runs()[0];
    // Positions 0 → −85 in: the axis moved in the negative direction.
    assert_eq!(run.direction, Direction::Down);
    // Here actual = +LasRead: at −5 in LasRead −5.000178, LinearError −0.000178.
    let index = m
        .targets()
        .iter()
        .position(|t| (t + 127.0).abs() < 1e-9)
        .unwrap();
    assert!((run.deviations[index].unwrap() * 1000.0 - (-0.000178 * INCH_UM)).abs() < 1e-9);
    // The file says TestAxis (X) but is named "Y Axis Forward.pos": said, not hidden.
    assert!(
        result
            .warnings
            .iter()
            .any(|w| w.to_string().contains("TestAxis is (X)"))
    );
}

#[test]
fn unidirectional_single_run_figures() {
    let json = evaluate_json(&[&shared_data("api-xd/example__8055__X Axis Forward.pos")]);
    // E↑ = (0.000072 − (−0.000076)) in = 0.000148 in = 3.7592 µm; A↑ needs s.
    assert!((json["figures_um"]["E_up"].as_f64().unwrap() - 3.7592).abs() < 1e-9);
    for name in ["A", "A_up", "E", "M", "R", "B", "B_mean"] {
        assert!(json["figures_um"][name].is_null(), "{name}");
    }
    assert_eq!(json["length_unit"], "inch");
}

/// Writes a reverse file: the data rows of the forward file in reverse order,
/// each LinearError raised by 0.0001 in (2.54 µm).
fn reverse_of(forward: &Path, directory: &Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(forward).unwrap();
    let lines: Vec<&str> = text.split("\r\n").collect();
    let header = lines
        .iter()
        .position(|l| l.contains("LinearError"))
        .unwrap();
    let end = (header + 1..lines.len())
        .find(|&i| lines[i].starts_with("DecimalPoints"))
        .unwrap();
    let mut rows: Vec<String> = lines[header + 1..end]
        .iter()
        .map(|row| {
            let mut cells: Vec<String> = row.split('\t').map(str::to_string).collect();
            let error: f64 = cells[2].trim().parse().unwrap();
            cells[2] = format!("{:.6}", error + 0.0001);
            cells.join("\t")
        })
        .collect();
    rows.reverse();
    let mut out: Vec<String> = lines[..=header]
        .iter()
        .map(|s| s.replace("Direction: 1", "Direction: -1"))
        .collect();
    out.extend(rows);
    out.extend(lines[end..].iter().map(|s| s.to_string()));
    let path = directory.join("X Axis Reverse.pos");
    std::fs::write(&path, out.join("\r\n")).unwrap();
    path
}

#[test]
fn forward_and_reverse_files_join_into_one_bidirectional_test() {
    let directory = tempfile::tempdir().unwrap();
    let forward = shared_data("api-xd/example__8055__X Axis Forward.pos");
    let reverse = reverse_of(&forward, directory.path());
    let json = evaluate_json(&[&forward, &reverse]);
    assert_eq!(
        (json["runs"]["up"].as_u64(), json["runs"]["down"].as_u64()),
        (Some(1), Some(1))
    );
    // Every B_i = x̄↑ − x̄↓ = −0.0001 in = −2.54 µm.
    assert!((json["figures_um"]["B"].as_f64().unwrap() - 2.54).abs() < 1e-6);
    assert!((json["figures_um"]["B_mean"].as_f64().unwrap() + 2.54).abs() < 1e-6);
    // E spans both directions: E↑ 3.7592 µm widened by the 2.54 µm shift.
    assert!((json["figures_um"]["E"].as_f64().unwrap() - (3.7592 + 2.54)).abs() < 1e-6);
}

#[test]
fn files_of_different_targets_do_not_join() {
    let run = crate::util::axcomp([
        "evaluate".as_ref(),
        shared_data("api-xd/example__8055__X Axis Forward.pos").as_os_str(),
        shared_data("api-xd/example__8055__Y Axis Forward.pos").as_os_str(),
    ]);
    assert_eq!(run.code, 2);
    // 0 … 3302 mm against −2159 … 0 mm: refused before the targets are compared.
    assert!(
        run.stderr.contains("the ranges do not overlap"),
        "{}",
        run.stderr
    );
}
