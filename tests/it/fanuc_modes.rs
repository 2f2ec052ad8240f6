//! Fanuc beyond the one-direction update (`tests/it/fanuc.rs`), on the real
//! backup of one machine (`../shared/data/fanuc/`): bidirectional pitch
//! error compensation (3605#0, 3626, 3627), the table rescaled to a finer
//! magnification (3623), a rotary axis' turn and backlash, and a test that
//! covers too few of the control's points. Expected numbers are computed
//! here from the files' data lines and the measurement's readings.

use std::collections::BTreeMap;
use std::path::Path;

use axcomp::measurement::{Direction, Measurement};

use crate::fanuc::{absolute, data, increments, ok, synthetic_x, update_x};
use crate::util::{axcomp, root};

/// The mean reading of `direction` (all directions: `None`) at target `i`, µm.
fn mean_um(m: &Measurement, i: usize, direction: Option<Direction>) -> f64 {
    let readings: Vec<f64> = m
        .runs()
        .iter()
        .filter(|r| direction.is_none_or(|d| r.direction == d))
        .filter_map(|r| r.deviations[i])
        .collect();
    readings.iter().sum::<f64>() / readings.len() as f64 * 1000.0
}

/// The 3627 the activation line says to set.
fn setting_3627(activation: &str) -> i64 {
    activation
        .split("3627 = ")
        .nth(1)
        .and_then(|rest| rest.split([',', ' ', ')']).next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{activation}"))
}

fn read(path: &str) -> Measurement {
    axcomp::read::read_path(Path::new(path), None)
        .unwrap()
        .measurement
}

/// The real backup with X's bidirectional pitch error compensation on
/// (3605 = 00000011) and its table for travel in the negative direction at
/// points 50 … 90 (3626 = 50; the real pitch file holds 0 there), 3627 = 0.
pub(crate) fn bidirectional_backup(directory: &Path) -> String {
    let text = std::fs::read_to_string(data("CNC-PARA.TXT")).unwrap();
    let changed = text
        .replace("N03605Q1A1P00000010A2", "N03605Q1A1P00000011A2")
        .replace("N03626Q1A1P0A2", "N03626Q1A1P50A2");
    assert_eq!(changed.len(), text.len() + 1);
    let path = directory.join("CNC-PARA.TXT");
    std::fs::write(&path, changed).unwrap();
    path.display().to_string()
}

#[test]
fn bidirectional_compensation_needs_3605_and_goes_to_3626() {
    let directory = tempfile::tempdir().unwrap();
    let path = |name: &str| directory.path().join(name).display().to_string();
    let pitch = data("PITCH.TXT");
    // The real backup has 3605#0 = 0 on X: refused, with what to set.
    synthetic_x(directory.path());
    let run = axcomp([
        "convert",
        &path("x.rtl"),
        "--controller",
        "fanuc",
        "--fanuc-parameters",
        &data("CNC-PARA.TXT"),
        "--mode",
        "bidirectional",
        "-o",
        &path("B.TXT"),
    ]);
    assert_eq!(run.code, 2, "{}", run.stdout);
    assert!(
        run.stderr
            .contains("3605#0 of axis X is 0 in the parameter backup (3605 = 00000010 at ")
            && run.stderr.contains("HM100TS__CNC-PARA.TXT:1411:12)")
            && run.stderr.contains("set 3605#0 = 1 and 3626"),
        "{}",
        run.stderr
    );
    assert!(!Path::new(&path("B.TXT")).exists());
    // With 3605#0 = 1 and 3626 = 50: the test with both tables active.
    let parameters = bidirectional_backup(directory.path());
    let out = path("NEW.TXT");
    let flags = ["--mode", "bidirectional", "-o", &out, "--json", "-q"];
    let (after, run) = update_x(directory.path(), &parameters, "31", &flags);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let activation = json["activation"].as_str().unwrap();
    let reference_negative = setting_3627(activation);
    assert!(activation.contains("3605#0 = 1, 3626 = 50"), "{activation}");
    assert!(
        activation.contains("leave them as they were"),
        "{activation}"
    );
    let old_text = std::fs::read_to_string(&pitch).unwrap();
    let new_text = std::fs::read_to_string(path("NEW.TXT")).unwrap();
    // Sections 16 … 40 of both tables are new (↓ at 50 + n − 1 = 65 … 89);
    // every other line is byte for byte the old one.
    only_these_points_changed(&old_text, &new_text, |n| {
        (16..=40).contains(&n) || (65..=89).contains(&n)
    });
    assert_eq!(old_text.len() - old_text.trim_end_matches('%').len(), 1);
    let (old, new) = (increments(&old_text), increments(&new_text));
    // The ↓ table's absolute compensation: 3627 at the reference point 40,
    // the increments of 50 + (n − 1) summed from there.
    let absolute_down = |inc: &BTreeMap<i64, i64>, at_reference: i64, n: i64| -> i64 {
        let shifted: BTreeMap<i64, i64> = (1..=41).map(|k| (k, inc[&(49 + k)])).collect();
        at_reference + absolute(&shifted, n)
    };
    let after = read(&after);
    let targets = after.targets().to_vec();
    let reference = targets.iter().position(|t| *t == 0.0).unwrap();
    let up_at_reference = mean_um(&after, reference, Some(Direction::Up));
    for (i, target) in targets.iter().enumerate() {
        let n = 40 + (target / 40.0).round() as i64;
        // ↑: old − (e↑ − e↑(ref)); ↓: old↓ − (e↓ − e↑(ref)), 1 µm units,
        // within half a unit.
        let up = absolute(&new, n) as f64;
        let wanted_up =
            absolute(&old, n) as f64 - (mean_um(&after, i, Some(Direction::Up)) - up_at_reference);
        assert!(
            (up - wanted_up).abs() <= 0.5 + 1e-9,
            "↑ point {n}: {up} µm, {wanted_up} µm"
        );
        let down = absolute_down(&new, reference_negative, n) as f64;
        let wanted_down = absolute_down(&old, 0, n) as f64
            - (mean_um(&after, i, Some(Direction::Down)) - up_at_reference);
        assert!(
            (down - wanted_down).abs() <= 0.5 + 1e-9,
            "↓ point {n}: {down} µm, {wanted_down} µm"
        );
    }
    // The reversal at the reference: ↓ minus ↑ there, in the ↓ table's
    // 3627 (the truth's B = −3.2 µm: e↓ − e↑ = +3.2 µm, compensated −3).
    let at_reference = mean_um(&after, reference, Some(Direction::Down)) - up_at_reference;
    assert_eq!(reference_negative, (-at_reference).round() as i64);
    assert!(
        (-4..=-2).contains(&reference_negative),
        "{reference_negative}"
    );
    // The update says it: 2 × 25 sections written, the differing lines
    // counted; −1600 … −1040 mm and 40 mm kept with their increments, each
    // direction's values moved by its change at −1000 mm (point 15) and at
    // 0 mm (point 40), where ↓ moves by −(3627 − 0) units of 1 µm.
    let update = &json["update"];
    let differing = old_text
        .lines()
        .zip(new_text.lines())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(update["data_lines"]["sections"], 50, "{update:#}");
    assert_eq!(update["data_lines"]["changed"], differing);
    assert_eq!(update["updated"], 26);
    let change_um = |n: i64| {
        [
            -(absolute(&new, n) - absolute(&old, n)),
            -(absolute_down(&new, reference_negative, n) - absolute_down(&old, 0, n)),
        ]
    };
    assert_eq!(change_um(40), [0, -reference_negative]);
    for (k, (first, last, end)) in [(-1600.0, -1040.0, 15), (40.0, 40.0, 40)]
        .into_iter()
        .enumerate()
    {
        let run = &update["kept_mm"][k];
        assert_eq!((&run["first"], &run["last"]), (&first.into(), &last.into()));
        assert_eq!(run["moved"]["with"], (end - 40) as f64 * 40.0);
        for d in 0..2 {
            let said = run["moved"]["by"][d].as_f64().unwrap() * 1000.0;
            assert!(
                (said - change_um(end)[d] as f64).abs() < 1e-9,
                "{run}: {:?}",
                change_um(end)
            );
        }
    }
    let lines = update["lines"].to_string();
    assert!(
        lines.contains(&format!(
            "new value at 0 mm: its value moved by 0 µm ↑, {:+} µm ↓",
            -reference_negative
        )),
        "{lines}"
    );
    // It reads back as a table per direction (what predict and diagnose take).
    let backup = std::fs::read_to_string(&parameters).unwrap();
    let backup = axcomp::emit::fanuc::ParameterBackup::parse(&backup, "CNC-PARA.TXT").unwrap();
    let mut options = axcomp::emit::EmitOptions::for_axis(&Default::default(), "X", "").unwrap();
    // The file does not carry 3627: read with the value activation says to set.
    let mut x = backup.axis("X").unwrap();
    x.reference_negative = reference_negative;
    options.axes[0].fanuc = Some(x);
    let (_, table) = axcomp::emit::read_any(&new_text, &options, None).unwrap();
    let gap = table.value_at(0.0, Direction::Down) - table.value_at(0.0, Direction::Up);
    assert!(
        (gap * 1000.0 + reference_negative as f64).abs() < 1e-9,
        "{gap}"
    );
}

#[test]
fn the_rescaled_alternative_keeps_the_compensation_in_a_finer_unit() {
    let directory = tempfile::tempdir().unwrap();
    let path = |name: &str| directory.path().join(name).display().to_string();
    let (pitch, parameters) = (data("PITCH.TXT"), data("CNC-PARA.TXT"));
    let (new, fine) = (path("NEW.TXT"), path("FINE.TXT"));
    let flags = ["-o", &new, "--fanuc-rescaled", &fine];
    let (after, run) = update_x(directory.path(), &parameters, "30", &flags);
    // X: 3623 = 10 × 0.0001 mm = 1 µm; the finest magnification holding its
    // sections (at most 5 units × 10 = 50 of 0.1 µm) is 1.
    assert!(
        run.stdout
            .contains("set 3623 of axis X to 1 (it is 10: units of 0.0001 mm instead of 0.001 mm)"),
        "{}",
        run.stdout
    );
    let old_text = std::fs::read_to_string(&pitch).unwrap();
    let fine_text = std::fs::read_to_string(path("FINE.TXT")).unwrap();
    // Only X's points 1 … 41 change; every other line is byte for byte.
    only_these_points_changed(&old_text, &fine_text, |n| (1..=41).contains(&n));
    assert_eq!(old_text.lines().count(), fine_text.lines().count());
    let (old, fine) = (increments(&old_text), increments(&fine_text));
    // Outside the test (sections 1 … 15 and 41) the old increments, ten times.
    for n in (1..=15).chain([41]) {
        assert_eq!(fine[&n], 10 * old[&n], "point {n}");
    }
    // Inside: the same compensation as the update at 3623 = 10 asks for,
    // old − (e − e(ref)), within half the new unit (0.05 µm).
    let after = read(&after);
    let targets = after.targets().to_vec();
    let reference = targets.iter().position(|t| *t == 0.0).unwrap();
    for (i, target) in targets.iter().enumerate() {
        let n = 40 + (target / 40.0).round() as i64;
        let implied = absolute(&fine, n) as f64 * 0.1;
        let wanted = absolute(&old, n) as f64
            - (mean_um(&after, i, None) - mean_um(&after, reference, None));
        assert!(
            (implied - wanted).abs() <= 0.05 + 1e-9,
            "point {n}: {implied} µm, {wanted} µm"
        );
    }
    // Read back with 3623 = 1: the same table as NEW.TXT with 3623 = 10, to
    // half a unit of the coarse one at every point of the axis.
    let backup = std::fs::read_to_string(&parameters).unwrap();
    let backup = axcomp::emit::fanuc::ParameterBackup::parse(&backup, "CNC-PARA.TXT").unwrap();
    let coarse = backup.axis("X").unwrap();
    let finer = axcomp::emit::fanuc::AxisParameters {
        magnification: 1,
        ..coarse.clone()
    };
    let new_text = std::fs::read_to_string(path("NEW.TXT")).unwrap();
    let a = axcomp::emit::fanuc::read(&new_text, &coarse).unwrap();
    let b = axcomp::emit::fanuc::read(&fine_text, &finer).unwrap();
    assert_eq!(a.positions, b.positions);
    for (x, y) in a
        .values
        .for_direction(Direction::Up)
        .iter()
        .zip(b.values.for_direction(Direction::Up))
    {
        assert!((x - y).abs() <= 0.0005 + 1e-12, "{x} {y}");
    }
}

#[test]
fn a_test_that_covers_two_of_the_axis_points_is_refused() {
    let directory = tempfile::tempdir().unwrap();
    let out = directory.path().join("PITCH.TXT").display().to_string();
    // The sample test measured 0 … 750 mm; X's points lie at −1600 … 40 mm
    // ((n − 40) × 40 mm, n = 0 … 41): only 40 and 41 are inside.
    let run = axcomp([
        "convert",
        "fixtures/sample-x.rtl",
        "--controller",
        "fanuc",
        "--fanuc-parameters",
        &data("CNC-PARA.TXT"),
        "-o",
        &out,
    ]);
    assert_eq!(run.code, 2, "{}", run.stdout);
    assert!(
        run.stderr.contains(
            "the measured range 0 … 750 mm holds 2 of the 42 compensation points of axis X (-1600 … 40 mm"
        ),
        "{}",
        run.stderr
    );
    assert!(run.stderr.contains("machine coordinates"), "{}", run.stderr);
    assert!(!Path::new(&out).exists());
}

/// The B axis of the backup: 3620 = 300 at 0°, points 301 … 312 every 30°
/// (one turn), 3623 = 1 of 0.0001°, 1851 = −4.
#[test]
fn a_rotary_axis_turn_sums_to_zero_and_its_backlash_is_in_degrees() {
    let directory = tempfile::tempdir().unwrap();
    let path = |name: &str| directory.path().join(name).display().to_string();
    let truth = |end: f64, count: usize| {
        axcomp::synth::RotaryTruth::from_toml_str(&format!(
            "[axis]\nname = \"B\"\n[rotary]\nstart_deg = 0.0\nend_deg = {end}\ncount = {count}\nruns = 5\n\
             reversal_arcsec = 2.4\nsigma_arcsec = 0.3\nharmonics = [{{ per_revolution = 1, amplitude_arcsec = 4.0, phase_rad = 0.5 }}]\n"
        ))
        .unwrap()
    };
    let test = axcomp::synth::rotary_test(&truth(360.0, 13), 7).unwrap();
    std::fs::write(path("b.csv"), axcomp::read::csv::write(&test)).unwrap();
    let run = ok(&[
        "convert",
        &path("b.csv"),
        "--controller",
        "fanuc",
        "--fanuc-parameters",
        &data("CNC-PARA.TXT"),
        "--axis",
        "B",
        "-o",
        &path("B.TXT"),
        "--json",
        "-q",
    ]);
    let written = increments(&std::fs::read_to_string(path("B.TXT")).unwrap());
    // 0i-PB p.100: the points of one turn (301 … 312) sum to zero.
    assert_eq!((301..=312).map(|n| written[&n]).sum::<i64>(), 0);
    // The reversal −B̄, B̄ the mean over the targets of x̄↑ − x̄↓, in
    // detection units of 0.0001°, added to the backup's −4 (active during
    // the test).
    let count = test.targets().len();
    let reversal_deg = (0..count)
        .map(|i| {
            (mean_um(&test, i, Some(Direction::Up)) - mean_um(&test, i, Some(Direction::Down)))
                / 1000.0
        })
        .sum::<f64>()
        / count as f64;
    let units = (-reversal_deg / 0.0001).round() as i64;
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let note = json["backlash_note"].as_str().unwrap();
    assert!(
        note.contains(&format!("to {units} detection units of 0.0001° more than the -4 of the parameter backup, active during the test: 1851 = {}", units - 4)),
        "{note}"
    );
    assert!(note.contains("negative an axis that overshoots"), "{note}");
    // B's unit in degrees: 1820 = 20 (CMR 10), 0.001° / 10 × 3623 = 1.
    let activation = json["activation"].as_str().unwrap();
    assert!(
        activation.contains("in units of 0.0001° (detection unit 0.0001° × 3623 = 1)"),
        "{activation}"
    );
    // Half a turn updated into the real file: B's old points 307 … 312 with
    // the new 301 … 306 no longer sum to zero over the turn: refused.
    let half = axcomp::synth::rotary_test(&truth(180.0, 7), 8).unwrap();
    std::fs::write(path("half.csv"), axcomp::read::csv::write(&half)).unwrap();
    let run = axcomp([
        "convert",
        &path("half.csv"),
        "--controller",
        "fanuc",
        "--existing",
        &data("PITCH.TXT"),
        "--fanuc-parameters",
        &data("CNC-PARA.TXT"),
        "--axis",
        "B",
        "-o",
        &path("HALF.TXT"),
    ]);
    assert_eq!(run.code, 2, "{}", run.stdout);
    assert!(
        run.stderr.contains(
            "the points 301 … 312 of rotary axis B span one turn (360°) and must sum to zero"
        ),
        "{}",
        run.stderr
    );
    // The real file's own B turn sums to zero (10 at 310, −10 at 311).
    let real = increments(&std::fs::read_to_string(data("PITCH.TXT")).unwrap());
    assert_eq!((301..=312).map(|n| real[&n]).sum::<i64>(), 0);
}

/// The golden files of the new output forms (`formats/fanuc/golden/`),
/// each read back: the bidirectional table in axcomp's numbering, and the
/// synthetic X at HM100TS's points rescaled to 3623 = 1.
#[test]
fn the_new_golden_files_read_back() {
    use axcomp::emit::fanuc::AxisParameters;
    use axcomp::emit::{EmitOptions, MachineProfile};
    let directory = tempfile::tempdir().unwrap();
    let path = |name: &str| directory.path().join(name).display().to_string();
    synthetic_x(directory.path());
    // Bidirectional without a backup: X's 26 targets −1000 … 0 mm are
    // points 0 … 25 (3620 = 0 at −1000 mm, 3621 = 1, 3622 = 25), the ↓
    // table right after (3626 = 26 … 50), 1 µm units (0.001 mm, 3623 = 1).
    let out = path("BIDIR.TXT");
    let run = ok(&[
        "convert",
        &path("x.rtl"),
        "--controller",
        "fanuc",
        "--mode",
        "bidirectional",
        "-o",
        &out,
        "--json",
        "-q",
    ]);
    let written = std::fs::read_to_string(&out).unwrap();
    crate::util::assert_golden(
        &written,
        &root().join("formats/fanuc/golden/synth-x-bidirectional.TXT"),
    );
    let values = increments(&written);
    assert_eq!(values.len(), 51);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let activation = json["activation"].as_str().unwrap();
    let at_reference = setting_3627(activation);
    assert!(activation.contains("3605#0 = 1, 3626 = 26"), "{activation}");
    let mut options = EmitOptions::for_axis(&MachineProfile::default(), "X", "").unwrap();
    let mut p = AxisParameters::default_for("X", 26, 40.0, 0, -1000.0);
    p.bidirectional = true;
    p.negative_first = 26;
    p.reference_negative = at_reference;
    options.axes[0].fanuc = Some(p);
    let (_, table) = axcomp::emit::read_any(&written, &options, None).unwrap();
    // The ↓ curve at −1000 mm is 3627 units of 1 µm from the ↑ one: the
    // ↓ absolute compensation there is 3627 (its error, −3627 µm).
    let gap = table.value_at(-1000.0, Direction::Down) - table.value_at(-1000.0, Direction::Up);
    assert!((gap * 1000.0 + at_reference as f64).abs() < 1e-9, "{gap}");
    // By hand from the file: the ↓ absolute at point 25 is 3627 + Σ 26 … 50.
    let down_25 = at_reference + (26..=50).map(|n| values[&n]).sum::<i64>();
    assert!((table.value_at(0.0, Direction::Down) * 1000.0 + down_25 as f64).abs() < 1e-9);
    // Rescaled, with HM100TS's parameters (no --existing: a new file):
    // X's points 0 … 41 in units of 0.0001 mm (3623 = 1).
    let (coarse, fine) = (path("PITCH.TXT"), path("FINE.TXT"));
    let run = ok(&[
        "convert",
        &path("x.rtl"),
        "--controller",
        "fanuc",
        "--fanuc-parameters",
        &data("CNC-PARA.TXT"),
        "-o",
        &coarse,
        "--fanuc-rescaled",
        &fine,
    ]);
    assert!(
        run.stdout.contains("set 3623 of axis X to 1"),
        "{}",
        run.stdout
    );
    let written = std::fs::read_to_string(&fine).unwrap();
    crate::util::assert_golden(
        &written,
        &root().join("formats/fanuc/golden/synth-x-HM100TS-rescaled.TXT"),
    );
    // Read back at 3623 = 1, it is the golden at 3623 = 10 to half its unit.
    let backup = std::fs::read_to_string(data("CNC-PARA.TXT")).unwrap();
    let backup = axcomp::emit::fanuc::ParameterBackup::parse(&backup, "CNC-PARA.TXT").unwrap();
    let x = backup.axis("X").unwrap();
    let x_fine = AxisParameters {
        magnification: 1,
        ..x.clone()
    };
    let a = axcomp::emit::fanuc::read(&std::fs::read_to_string(&coarse).unwrap(), &x).unwrap();
    let b = axcomp::emit::fanuc::read(&written, &x_fine).unwrap();
    assert_eq!(a.positions, b.positions);
    let up =
        |t: &axcomp::compensate::CompensationTable| t.values.for_direction(Direction::Up).to_vec();
    for (x, y) in up(&a).iter().zip(up(&b)) {
        assert!((x - y).abs() <= 0.0005 + 1e-12, "{x} {y}");
    }
    assert_eq!(
        std::fs::read_to_string(&coarse).unwrap(),
        std::fs::read_to_string(root().join("formats/fanuc/golden/synth-x-HM100TS.TXT")).unwrap()
    );
}

/// Every line of `new` is byte for byte `old`'s (trailing spaces, line
/// ends, `%`) except the data numbers 10000 + n whose point n is `changed`.
fn only_these_points_changed(old: &str, new: &str, changed: impl Fn(i64) -> bool) {
    for (a, b) in old.split_inclusive('\n').zip(new.split_inclusive('\n')) {
        let point = a
            .get(1..6)
            .and_then(|d| d.parse::<i64>().ok())
            .map(|d| d - 10_000);
        if !point.is_some_and(&changed) {
            assert_eq!(a, b);
        }
    }
}
