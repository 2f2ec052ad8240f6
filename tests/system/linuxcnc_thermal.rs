//! The thermal model's HAL file in a whole LinuxCNC (2.9, the simulated
//! machine of `linuxcnc.rs`, motion controller loaded, machine on, homed,
//! MDI mode): a recorded sequence of temperatures (the real spindle log,
//! every tenth row: 469 rows 10 min apart over its 4 682 min, the drift
//! growing to 17 µm and back) is driven into the file's temperature
//! signals, one row per step, and at every step the offset the motion
//! controller applies to
//! Z (`axis.z.eoffset`, once it has settled on `axis.z.eoffset-request`)
//! is compared with `axcomp thermal apply` on the same rows.
//!
//! The file runs every servo period; to make each step one row of the
//! sequence (its `--period` is the sequence's 600 s), the test puts a gate before each
//! lowpass: a `mux2` passes the temperature only in the one period an
//! `edge` pulse marks when the driver toggles a step signal (an `updown`
//! counts the pulses, so the driver knows the row was taken), and otherwise
//! feeds the lowpass its own output (no change). Everything else is the
//! file as written, loaded as a second `HALFILE` after the machine's.
//! LinuxCNC refuses root: as root the test runs it as the user `axcomp-ci`
//! (`scripts/test` creates it).

use serde_json::Value;

use crate::util::{THERMAL_LOG as REAL, axcomp, fit_warm_up, shared_data, test_data};

/// Every this many rows of the log (one minute apart) make the sequence.
const STRIDE: usize = 10;
/// `axis.z.eoffset-scale` as the file sets it: mm per count.
const SCALE_MM: f64 = 1e-6;
/// `[AXIS_Z]OFFSET_AV_RATIO`: the share of Z's velocity and acceleration
/// (`MAX_VELOCITY = 500`, `MAX_ACCELERATION = 5000` in sim.ini) the offset
/// may use. Small, so that its ramp stops close to the request.
const OFFSET_AV_RATIO: f64 = 0.01;
/// Where the offset's ramp stops short of its request at most, mm: the
/// stopping criterion of LinuxCNC's simple planner, `TINY_DP(max_acc,
/// period) = max_acc·period²·0.001` (`src/emc/motion/simple_tp.h`) with
/// `max_acc` = OFFSET_AV_RATIO × 5000 mm/s² and the 1 ms servo period: 5e-8 mm.
const STOP_MM: f64 = OFFSET_AV_RATIO * 5000.0 * 1e-3 * 1e-3 * 0.001;
/// halcmd prints floats to 7 significant digits: offsets under 0.1 mm
/// (this drift reaches 0.017 mm) within 1e-8 mm.
const PRINT_MM: f64 = 1e-8;

/// The generated file with a gate before each lowpass and a counter of the steps.
fn gated(hal: &str) -> String {
    let mut out = String::new();
    let mut gates = Vec::new();
    for line in hal.lines() {
        // `net thermal-T0 => thermal-lag-0.in`
        if let Some((signal, lag)) = line
            .strip_prefix("net thermal-")
            .and_then(|rest| rest.split_once(" => "))
            .filter(|(_, lag)| lag.ends_with(".in") && lag.starts_with("thermal-lag-"))
        {
            let k = gates.len();
            let lag_name = lag.trim_end_matches(".in");
            gates.push(format!(
                "net thermal-{signal} => gate-{k}.in1\n\
                 net thermal-pulse => gate-{k}.sel\n\
                 net gated-{k} gate-{k}.out => {lag}\n\
                 net held-{k} {lag_name}.out => gate-{k}.in0\n"
            ));
            continue;
        }
        if line.starts_with("net thermal-lagged-") {
            // The lowpass output now also feeds its gate: name it there.
            let k = gates.len() - 1;
            let target = line.split(" => ").nth(1).unwrap();
            out.push_str(&format!("net held-{k} => {target}\n"));
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    assert!(!gates.is_empty(), "no temperature input in:\n{hal}");
    let names: Vec<String> = (0..gates.len()).map(|k| format!("gate-{k}")).collect();
    out.push_str(&format!("loadrt mux2 names={}\n", names.join(",")));
    // Position 1 puts a function first in the thread: the last added runs
    // first, so the edge, then the counter, then the gates, then the rest.
    for name in &names {
        out.push_str(&format!("addf {name} servo-thread 1\n"));
    }
    out.push_str(
        "loadrt updown names=step-count\naddf step-count servo-thread 1\n\
         loadrt edge names=step-edge\nsetp step-edge.both 1\naddf step-edge servo-thread 1\n\
         net thermal-step => step-edge.in\n\
         net thermal-pulse step-edge.out => step-count.countup\n\
         net thermal-steps step-count.count\n",
    );
    for gate in gates {
        out.push_str(&gate);
    }
    out
}

/// The simulated machine's INI (`tests/data/linuxcnc/sim.ini`) with Z's
/// external offset allowed and the test's HAL file loaded after the
/// machine's, in two passes.
fn thermal_ini(driver: &std::path::Path) -> String {
    let template = std::fs::read_to_string(test_data("linuxcnc/sim.ini")).unwrap();
    let ini: String = template
        .replace("@DRIVER@", &driver.display().to_string())
        .replace("@AXIS@", "X")
        .replace("@JOINT_TYPE@", "LINEAR")
        .lines()
        .filter(|line| !line.contains("COMP_FILE"))
        .map(|line| format!("{line}\n"))
        .collect();
    let edits: [(&str, String); 2] = [
        // Part of Z's velocity and acceleration for the offset (the rest
        // for programmed motion): the External Axis Offsets chapter.
        (
            "[AXIS_Z]\n",
            format!("[AXIS_Z]\nOFFSET_AV_RATIO = {OFFSET_AV_RATIO}\n"),
        ),
        // The machine loads sum2 too: LinuxCNC loads a component once, and
        // two-pass processing combines the two files' `loadrt sum2`.
        (
            "HALFILE = sim.hal\n",
            "TWOPASS = on\nHALFILE = sim.hal\nHALFILE = thermal-test.hal\n".to_string(),
        ),
    ];
    edits.iter().fold(ini, |ini, (from, to)| {
        assert!(ini.contains(from), "sim.ini has no {from:?}");
        ini.replacen(from, to, 1)
    })
}

#[test]
fn linuxcnc_hal_offset_equals_thermal_apply_at_every_step() {
    let dir = tempfile::Builder::new()
        .prefix("axcomp-linuxcnc-thermal")
        .tempdir()
        .unwrap();
    let path = |name: &str| dir.path().join(name);
    let real = shared_data(REAL);
    // The model of the README: fitted on the warm-up.
    fit_warm_up(
        &path("model.toml"),
        &["--sensors", "T0,T1,T2,T3,T4", "--reference", "T14"],
    );
    let hal = axcomp([
        "thermal",
        "hal",
        path("model.toml").to_str().unwrap(),
        "--axis",
        "z",
        "--period",
        &(STRIDE * 60).to_string(),
        "-o",
        path("thermal.hal").to_str().unwrap(),
    ]);
    assert_eq!(hal.code, 0, "{}", hal.stderr);
    // The recorded sequence: every STRIDE-th row of the log, with its time column.
    let text = std::fs::read_to_string(&real).unwrap();
    let mut lines = text.trim_start_matches('\u{feff}').lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .step_by(STRIDE)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 469);
    let mut csv = format!("time [min],{}\n", header.join(","));
    for (k, row) in rows.iter().enumerate() {
        let cells: Vec<String> = row.iter().map(|v| v.to_string()).collect();
        csv.push_str(&format!("{},{}\n", k * STRIDE, cells.join(",")));
    }
    std::fs::write(path("rows.csv"), csv).unwrap();
    let apply = axcomp([
        "thermal",
        "apply",
        path("model.toml").to_str().unwrap(),
        path("rows.csv").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(apply.code, 0, "{}", apply.stderr);
    let json: Value = serde_json::from_str(&apply.stdout).unwrap();
    let predicted: Vec<f64> = json["predicted_um"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();

    let generated = std::fs::read_to_string(path("thermal.hal")).unwrap();
    // Every temperature the file reads, once each, in the file's order.
    let mut signals: Vec<String> = Vec::new();
    for line in generated.lines() {
        if let Some(signal) = line
            .strip_prefix("net ")
            .and_then(|rest| rest.split_once(" => "))
            .filter(|(_, to)| to.starts_with("thermal-lag-") && to.ends_with(".in"))
            .map(|(signal, _)| signal.to_string())
            .filter(|signal| !signals.contains(signal))
        {
            signals.push(signal);
        }
    }
    let steps: Vec<Vec<f64>> = rows
        .iter()
        .map(|row| {
            signals
                .iter()
                .map(|signal| {
                    let sensor = signal.strip_prefix("thermal-").unwrap();
                    row[header.iter().position(|h| *h == sensor).unwrap()]
                })
                .collect()
        })
        .collect();
    std::fs::write(path("thermal-test.hal"), gated(&generated)).unwrap();
    std::fs::write(
        path("steps.json"),
        serde_json::json!({
            "axis": "z", "joint": 2, "scale": SCALE_MM, "stop_mm": STOP_MM + PRINT_MM,
            "signals": signals, "rows": steps,
        })
        .to_string(),
    )
    .unwrap();
    for file in ["thermal_driver.py", "machine.py"] {
        std::fs::copy(test_data(&format!("linuxcnc/{file}")), path(file)).unwrap();
    }
    // Two-pass processing combines loadrt lines of one form only, and the
    // thermal file names its instances: the machine's sum2 too, by the
    // name `count=1` gave it.
    let machine = std::fs::read_to_string(test_data("linuxcnc/sim.hal")).unwrap();
    assert!(machine.contains("loadrt sum2 count=1\n"));
    std::fs::write(
        path("sim.hal"),
        machine.replace("loadrt sum2 count=1\n", "loadrt sum2 names=sum2.0\n"),
    )
    .unwrap();
    std::fs::write(path("thermal.ini"), thermal_ini(&path("thermal_driver.py"))).unwrap();
    let json = crate::linuxcnc::run_config(dir.path(), "thermal.ini");

    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), rows.len());
    let mut largest = 0.0f64;
    for (k, point) in points.iter().enumerate() {
        let value = |name: &str| point[name].as_f64().unwrap();
        let expected_mm = -predicted[k] / 1000.0;
        // The model in HAL: halcmd prints floats to 7 significant digits.
        let offset_mm = value("thermal-offset");
        assert!(
            (offset_mm - expected_mm).abs() < 1e-8,
            "row {k}: HAL {offset_mm} mm, apply {expected_mm} mm"
        );
        let counts = value("thermal-offset-counts");
        assert!(
            (counts - expected_mm / SCALE_MM).abs() < 1.0 + 1e-6,
            "row {k}: {counts} counts, apply {} counts",
            expected_mm / SCALE_MM
        );
        // The motion controller: its request is the counts × scale, the
        // offset it applies has stopped at the request, equals the model
        // within one count (and the ramp's stop), and is in Z's joint
        // position command.
        let request = value("axis.z.eoffset-request");
        let applied = value("axis.z.eoffset");
        assert!(
            (request - counts * SCALE_MM).abs() < 1e-12,
            "row {k}: requested {request} mm for {counts} counts"
        );
        assert!(applied.abs() < 0.1, "row {k}: {applied} mm");
        assert!(
            (applied - request).abs() <= STOP_MM + PRINT_MM,
            "row {k}: applied {applied} mm, requested {request} mm"
        );
        assert!(
            (applied - expected_mm).abs() < SCALE_MM + STOP_MM + PRINT_MM,
            "row {k}: LinuxCNC applies {applied} mm to Z, apply predicts {expected_mm} mm"
        );
        let in_joint = value("joint.2.pos-cmd") - value("axis.z.pos-cmd");
        assert!(
            (in_joint - applied).abs() <= PRINT_MM,
            "row {k}: the joint moved {in_joint} mm for an offset of {applied} mm"
        );
        // "Active" is an offset beyond the ramp's stopping distance.
        assert_eq!(
            value("motion.eoffset-active"),
            f64::from(u8::from(applied.abs() > STOP_MM)),
            "row {k}: {applied} mm"
        );
        largest = largest.max((applied - expected_mm).abs());
    }
    eprintln!(
        "{} rows: LinuxCNC's Z offset against thermal apply, largest difference {largest:.3e} mm",
        rows.len()
    );
    // The sequence moves the offset over most of the drift's 17 µm.
    let reach = predicted.iter().fold(0.0f64, |m, p| m.max(p.abs()));
    assert!(reach > 10.0, "the model reaches {reach} µm");
}
