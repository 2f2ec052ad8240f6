//! The LinuxCNC table on a real controller: LinuxCNC 2.9 (Debian package
//! `linuxcnc-uspace`), simulated mill, headless.
//!
//! `axcomp convert` writes the COMP_FILE; the test writes a LinuxCNC config
//! around it (`tests/data/linuxcnc/`), starts LinuxCNC as an unprivileged
//! user (it refuses root) with a Python "display" that homes, moves X to
//! 21 positions going up and 21 going down (inside, between, on and beyond
//! the compensation points) and reads with halcmd the correction LinuxCNC
//! applies (`joint.0.motor-pos-cmd − joint.0.pos-cmd`, formed in HAL). Every
//! correction must equal axcomp's own prediction, −(table value at that
//! position in that direction) as the module reads the file back, within
//! 1e-6 mm.
//!
//! Observed on LinuxCNC 2.9 (Debian 2.9.0~pre1): right after homing the
//! correction is computed at once (`joint.0.backlash-corr`) but not applied
//! (`joint.0.backlash-filt` stays 0) until a longer move; a long warm-up move
//! (to 400 mm and back below the table) comes first, and every measured
//! point must show the applied correction settled on the computed one.
//!
//! The test installs nothing: `scripts/test` installs LinuxCNC and creates the
//! user `axcomp-ci`. If LinuxCNC cannot start, the test fails.

use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use axcomp::emit::linuxcnc;
use axcomp::measurement::Direction;
use axcomp::units::LengthUnit;

use crate::util::{axcomp, test_data};

/// The user LinuxCNC runs as when the tests run as root (created by `scripts/test`).
const USER: &str = "axcomp-ci";
const TOLERANCE_MM: f64 = 1e-6;
/// Moves before the measured ones (see the module doc).
const WARM_UP: [(&str, Direction); 2] = [
    ("400.000000", Direction::Up),
    ("-50.000000", Direction::Down),
];

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// The moves: start below the table, 21 positions up, 21 down (the sample's
/// table spans 0…750 mm; −20 and 780 lie beyond it, 302.304 is a point).
fn positions() -> Vec<(String, Direction)> {
    let up: Vec<f64> = vec![
        -20.0, 0.0, 12.5, 58.557, 75.0, 100.089, 130.0, 203.029, 222.2, 302.304, 333.3, 394.083,
        420.0, 499.86, 525.0, 596.385, 620.0, 707.927, 730.0, 750.0, 780.0,
    ];
    let down: Vec<f64> = vec![
        765.0, 750.0, 740.0, 707.927, 680.0, 650.51, 600.0, 552.366, 510.0, 449.962, 400.0,
        355.475, 320.0, 241.652, 210.0, 152.276, 110.0, 58.557, 30.0, 0.0, -25.0,
    ];
    let mut moves: Vec<(String, Direction)> =
        WARM_UP.iter().map(|(p, d)| (p.to_string(), *d)).collect();
    moves.extend(up.iter().map(|p| (format!("{p:.6}"), Direction::Up)));
    moves.extend(down.iter().map(|p| (format!("{p:.6}"), Direction::Down)));
    moves
}

/// Writes the config into `dir` and runs LinuxCNC there; returns result.json.
fn run_linuxcnc(dir: &Path, comp_file: &str, comp_type: u8) -> serde_json::Value {
    let template = std::fs::read_to_string(test_data("linuxcnc/sim.ini")).unwrap();
    let ini = template
        .replace("@DRIVER@", &dir.join("driver.py").display().to_string())
        .replace("@COMP_FILE@", comp_file)
        .replace("@COMP_FILE_TYPE@", &comp_type.to_string());
    std::fs::write(dir.join("sim.ini"), ini).unwrap();
    for file in ["sim.hal", "driver.py"] {
        std::fs::copy(test_data(&format!("linuxcnc/{file}")), dir.join(file)).unwrap();
    }
    let moves: Vec<String> = positions().into_iter().map(|(p, _)| p).collect();
    std::fs::write(
        dir.join("positions.json"),
        serde_json::to_string(&moves).unwrap(),
    )
    .unwrap();
    let _ = std::fs::remove_file(dir.join("result.json"));
    // LinuxCNC runs as another user when we are root: let it write here.
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o777)).unwrap();
    }
    std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o777)).unwrap();

    let linuxcnc = ["/usr/bin/linuxcnc", "/usr/local/bin/linuxcnc"]
        .into_iter()
        .find(|p| Path::new(p).exists())
        .unwrap_or_else(|| {
            panic!("LinuxCNC is not installed: install the Debian package linuxcnc-uspace (apt-get install linuxcnc-uspace), or run the tests with scripts/test, which installs it")
        });
    let mut command = if is_root() {
        let exists = Command::new("id")
            .arg(USER)
            .output()
            .is_ok_and(|o| o.status.success());
        assert!(
            exists,
            "running as root and user {USER} does not exist: LinuxCNC refuses to run as root; create it (useradd --create-home {USER}), or run the tests with scripts/test, which creates it"
        );
        let mut c = Command::new("runuser");
        c.args(["-u", USER, "--", "env"])
            .arg(format!("HOME={}", dir.display()))
            .arg(linuxcnc);
        c
    } else {
        let mut c = Command::new(linuxcnc);
        c.env("HOME", dir);
        c
    };
    command
        .arg(dir.join("sim.ini"))
        .current_dir(dir)
        .env_remove("DISPLAY");
    let log = std::fs::File::create(dir.join("linuxcnc.log")).unwrap();
    let mut child = command
        .stdout(log.try_clone().unwrap())
        .stderr(log)
        .spawn()
        .expect("start linuxcnc");
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > Duration::from_secs(180) {
            let _ = child.kill();
            panic!(
                "LinuxCNC did not finish within 180 s; log:\n{}",
                std::fs::read_to_string(dir.join("linuxcnc.log")).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let log = std::fs::read_to_string(dir.join("linuxcnc.log")).unwrap_or_default();
    let result = std::fs::read_to_string(dir.join("result.json"))
        .unwrap_or_else(|_| panic!("LinuxCNC did not run the test ({status}); log:\n{log}"));
    let json: serde_json::Value = serde_json::from_str(&result).unwrap();
    assert!(
        json.get("error").is_none(),
        "the LinuxCNC driver failed: {}\nlog:\n{log}",
        json["error"]
    );
    json
}

/// Converts the bundled sample, runs it on LinuxCNC and compares every point.
fn check_type(dir: &Path, mode: &str, comp_type: u8) {
    let comp = dir.join(format!("comp-{mode}-{comp_type}.txt"));
    let run = axcomp([
        "convert",
        "fixtures/sample-x.rtl",
        "--controller",
        "linuxcnc",
        "--mode",
        mode,
        "--linuxcnc-type",
        &comp_type.to_string(),
        "-o",
        comp.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let text = std::fs::read_to_string(&comp).unwrap();
    let table = linuxcnc::read(&text, "X", Some(comp_type), LengthUnit::Millimetre).unwrap();
    let json = run_linuxcnc(dir, comp.file_name().unwrap().to_str().unwrap(), comp_type);
    let points = json["points"].as_array().unwrap();
    let moves = positions();
    assert_eq!(points.len(), moves.len());
    let mut checked = [0usize; 2];
    for (point, (x_text, direction)) in points.iter().zip(&moves).skip(WARM_UP.len()) {
        let x: f64 = x_text.parse().unwrap();
        let (computed, applied) = (
            point["computed"].as_f64().unwrap(),
            point["applied"].as_f64().unwrap(),
        );
        assert!(
            (computed - applied).abs() <= TOLERANCE_MM,
            "X{x}: LinuxCNC computed {computed} mm but applies {applied} mm"
        );
        let applied =
            point["correction"].as_f64().unwrap() - point["motor_offset"].as_f64().unwrap();
        let predicted = -table.value_at(x, *direction);
        assert!(
            (applied - predicted).abs() <= TOLERANCE_MM,
            "{mode} type {comp_type}: X{x} {direction}: LinuxCNC applied {applied} mm, axcomp predicts {predicted} mm"
        );
        assert!(
            (point["pos_cmd"].as_f64().unwrap() - x).abs() < 1e-3,
            "the move reached X{x}"
        );
        checked[usize::from(*direction == Direction::Down)] += 1;
    }
    assert!(checked[0] >= 20 && checked[1] >= 20, "{checked:?}");
    // The table is not trivially zero where it was checked.
    assert!(
        points
            .iter()
            .any(|p| p["correction"].as_f64().unwrap().abs() > 1e-3)
    );
}

#[test]
fn linuxcnc_applies_the_table_as_axcomp_predicts() {
    let dir = tempfile::Builder::new()
        .prefix("axcomp-linuxcnc")
        .tempdir()
        .unwrap();
    check_type(dir.path(), "bidirectional", 0);
    check_type(dir.path(), "mean", 1);
}

#[test]
fn the_spec_example_prediction() {
    // controllers.md: with `100 100.010 99.990` and `0 0 0`, X50 in + gives motor 49.995.
    let table = linuxcnc::read(
        "0 0 0\n100 100.010 99.990\n",
        "X",
        Some(0),
        LengthUnit::Millimetre,
    )
    .unwrap();
    assert!((50.0 - table.value_at(50.0, Direction::Up) - 49.995).abs() < 1e-12);
}
