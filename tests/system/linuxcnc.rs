//! The LinuxCNC table on a real controller: LinuxCNC 2.9 (Debian package
//! `linuxcnc-uspace`), simulated machine, headless.
//!
//! `axcomp convert` writes the COMP_FILE; the test writes a LinuxCNC config
//! around it (`tests/data/linuxcnc/`), starts LinuxCNC as an unprivileged
//! user (it refuses root) with a Python "display" that homes, moves the joint
//! under test (joint 0) to positions going up and going down (inside,
//! between, on and beyond the compensation points) and reads with halcmd the
//! correction LinuxCNC applies (`joint.0.motor-pos-cmd − joint.0.pos-cmd`,
//! formed in HAL). Every correction must equal axcomp's own prediction,
//! −(table value at that position in that direction) as the module reads the
//! file back, within 1e-6 of the joint's unit.
//!
//! Two joints: a linear X (the bundled `.rtl` sample, 21 positions up and 21
//! down, in mm) and, for issue 14, an angular C (the synthetic rotary
//! fixture, 0–360° every 15°): `[JOINT_0]TYPE = ANGULAR` without
//! `WRAPPED_ROTARY`, so LinuxCNC does not wrap the table and holds its end
//! values beyond 0° and 360° (`formats/linuxcnc/README.md`, "Rotary joints");
//! seeded random angles over −20…380°, each approached going up and going
//! down, within 1e-6°.
//!
//! Observed on LinuxCNC 2.9 (Debian 2.9.0~pre1): right after homing the
//! correction is computed at once (`joint.0.backlash-corr`) but not applied
//! (`joint.0.backlash-filt` stays 0) until a longer move; a long warm-up move
//! (to 400 and back below the table) comes first, and every measured point
//! must show the applied correction settled on the computed one.
//!
//! The test installs nothing: `scripts/test` installs LinuxCNC and creates the
//! user `axcomp-ci`. If LinuxCNC cannot start, the test fails.

use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use axcomp::emit::{self, EmitOptions, MachineProfile, linuxcnc};
use axcomp::measurement::{AxisKind, Direction};
use axcomp::units::LengthUnit;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Uniform};

use crate::util::{axcomp, test_data};

/// The user LinuxCNC runs as when the tests run as root (created by `scripts/test`).
const USER: &str = "axcomp-ci";
/// In the joint's unit: mm for the linear joint, ° for the angular one.
const TOLERANCE: f64 = 1e-6;

/// Joint 0 of the simulated machine, the one under test, and the
/// measurement whose table it gets.
struct Joint {
    /// The axis LinuxCNC moves (`[AXIS_…]`, `G1 …`) and the table is for.
    axis: &'static str,
    /// `[JOINT_0]TYPE`.
    joint_type: &'static str,
    kind: AxisKind,
    /// The unit of its positions and corrections, for the messages.
    unit: &'static str,
    /// The measurement `axcomp convert` turns into the table.
    measurement: &'static str,
}

const LINEAR: Joint = Joint {
    axis: "X",
    joint_type: "LINEAR",
    kind: AxisKind::Linear,
    unit: "mm",
    measurement: "fixtures/sample-x.rtl",
};

const ANGULAR: Joint = Joint {
    axis: "C",
    joint_type: "ANGULAR",
    kind: AxisKind::Rotary,
    unit: "°",
    measurement: "fixtures/rotary/c.csv",
};

/// Moves before the measured ones (see the module doc): both tables lie
/// within 0…750, so 400 and −50 are long moves ending below the table.
const WARM_UP: [(f64, Direction); 2] = [(400.0, Direction::Up), (-50.0, Direction::Down)];

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// The warm-up, then `up` going up and `down` going down, as the driver
/// types them (6 decimals) and with the direction of their approach.
fn moves(up: &[f64], down: &[f64]) -> Vec<(String, Direction)> {
    WARM_UP
        .iter()
        .copied()
        .chain(up.iter().map(|p| (*p, Direction::Up)))
        .chain(down.iter().map(|p| (*p, Direction::Down)))
        .map(|(p, d)| (format!("{p:.6}"), d))
        .collect()
}

/// The linear moves: start below the table, 21 positions up, 21 down (the
/// sample's table spans 0…750 mm; −20 and 780 lie beyond it, 302.304 is a
/// point).
fn linear_moves() -> Vec<(String, Direction)> {
    moves(
        &[
            -20.0, 0.0, 12.5, 58.557, 75.0, 100.089, 130.0, 203.029, 222.2, 302.304, 333.3,
            394.083, 420.0, 499.86, 525.0, 596.385, 620.0, 707.927, 730.0, 750.0, 780.0,
        ],
        &[
            765.0, 750.0, 740.0, 707.927, 680.0, 650.51, 600.0, 552.366, 510.0, 449.962, 400.0,
            355.475, 320.0, 241.652, 210.0, 152.276, 110.0, 58.557, 30.0, 0.0, -25.0,
        ],
    )
}

/// The angular moves: 20 angles drawn uniformly over −20…380° (ChaCha8,
/// seed `seed`), beyond both ends of the 0…360° table included, with 0° and
/// 360° themselves; each visited going up (ascending, then on to 390°) and
/// going down (descending from there, then on to −30°).
fn angular_moves(seed: u64) -> Vec<(String, Direction)> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let uniform = Uniform::new(-20.0, 380.0).unwrap();
    let mut angles: Vec<f64> = (0..20).map(|_| uniform.sample(&mut rng)).collect();
    angles.extend([0.0, 360.0]);
    angles.sort_by(f64::total_cmp);
    let mut up = angles.clone();
    up.push(390.0);
    let mut down: Vec<f64> = angles.into_iter().rev().collect();
    down.push(-30.0);
    moves(&up, &down)
}

/// Writes the config for `joint` into `dir` and runs LinuxCNC there, making
/// `moves`; returns result.json.
/// One LinuxCNC (or halrun) at a time: two instances on one machine share
/// its HAL shared memory and NML channels and break each other ("move to …
/// timed out"), and cargo runs the linear, the rotary and the thermal
/// (`linuxcnc_thermal.rs`) test in parallel.
pub static ONE_LINUXCNC: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn run_linuxcnc(
    dir: &Path,
    joint: &Joint,
    moves: &[(String, Direction)],
    comp_file: &str,
    comp_type: u8,
) -> serde_json::Value {
    let template = std::fs::read_to_string(test_data("linuxcnc/sim.ini")).unwrap();
    let ini = template
        .replace("@DRIVER@", &dir.join("driver.py").display().to_string())
        .replace("@AXIS@", joint.axis)
        .replace("@JOINT_TYPE@", joint.joint_type)
        .replace("@COMP_FILE@", comp_file)
        .replace("@COMP_FILE_TYPE@", &comp_type.to_string());
    std::fs::write(dir.join("sim.ini"), ini).unwrap();
    for file in ["sim.hal", "driver.py", "machine.py"] {
        std::fs::copy(test_data(&format!("linuxcnc/{file}")), dir.join(file)).unwrap();
    }
    let positions: Vec<&str> = moves.iter().map(|(p, _)| p.as_str()).collect();
    std::fs::write(
        dir.join("positions.json"),
        serde_json::json!({"axis": joint.axis, "positions": positions}).to_string(),
    )
    .unwrap();
    run_config(dir, "sim.ini")
}

/// Runs LinuxCNC on the config `ini` in `dir` (its "display" a driver that
/// writes `result.json` there and exits) and returns result.json.
pub fn run_config(dir: &Path, ini: &str) -> serde_json::Value {
    // A test that failed while holding the lock has already said why.
    let _one = ONE_LINUXCNC
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
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
        .arg(dir.join(ini))
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

/// Converts the joint's measurement, runs it on LinuxCNC making `moves` and
/// compares every point with the table as axcomp reads it back.
fn check_type(dir: &Path, joint: &Joint, moves: &[(String, Direction)], mode: &str, comp_type: u8) {
    let comp = dir.join(format!("comp-{}-{mode}-{comp_type}.txt", joint.axis));
    let run = axcomp([
        "convert",
        joint.measurement,
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
    let mut options = EmitOptions::for_axis(&MachineProfile::default(), joint.axis, "").unwrap();
    options.kind = joint.kind;
    let (_, table) = emit::read_any(&text, &options, Some(comp_type)).unwrap();
    let json = run_linuxcnc(
        dir,
        joint,
        moves,
        comp.file_name().unwrap().to_str().unwrap(),
        comp_type,
    );
    let (axis, unit) = (joint.axis, joint.unit);
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), moves.len());
    let mut checked = [0usize; 2];
    for (point, (x_text, direction)) in points.iter().zip(moves).skip(WARM_UP.len()) {
        let x: f64 = x_text.parse().unwrap();
        let (computed, applied) = (
            point["computed"].as_f64().unwrap(),
            point["applied"].as_f64().unwrap(),
        );
        assert!(
            (computed - applied).abs() <= TOLERANCE,
            "{axis}{x}: LinuxCNC computed {computed} {unit} but applies {applied} {unit}"
        );
        let applied =
            point["correction"].as_f64().unwrap() - point["motor_offset"].as_f64().unwrap();
        let predicted = -table.value_at(x, *direction);
        assert!(
            (applied - predicted).abs() <= TOLERANCE,
            "{mode} type {comp_type}: {axis}{x} {direction}: LinuxCNC applied {applied} {unit}, axcomp predicts {predicted} {unit}"
        );
        assert!(
            (point["pos_cmd"].as_f64().unwrap() - x).abs() < 1e-3,
            "the move reached {axis}{x}"
        );
        checked[usize::from(*direction == Direction::Down)] += 1;
    }
    assert!(checked[0] >= 20 && checked[1] >= 20, "{checked:?}");
    // The table is not trivially zero where it was checked: the linear
    // sample's table reaches 1e-3 mm, the rotary fixture's 1.18e-3° (4.3″) at 90°.
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
    check_type(dir.path(), &LINEAR, &linear_moves(), "bidirectional", 0);
    check_type(dir.path(), &LINEAR, &linear_moves(), "mean", 1);
}

/// Issue 14: the rotary table on an angular joint, at random angles
/// approached in both directions, ends held beyond 0° and 360°.
#[test]
fn linuxcnc_applies_the_rotary_table_as_axcomp_predicts() {
    let dir = tempfile::Builder::new()
        .prefix("axcomp-linuxcnc-rotary")
        .tempdir()
        .unwrap();
    check_type(dir.path(), &ANGULAR, &angular_moves(14), "bidirectional", 0);
    check_type(dir.path(), &ANGULAR, &angular_moves(15), "mean", 1);
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
