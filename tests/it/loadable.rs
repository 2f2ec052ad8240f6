//! Every controller file is loadable as written: Sinumerik CEC table
//! numbers allocated from the machine profile and refused when two files
//! clash, the profile's point limit on cross-axis tables, the activation
//! steps and the one-move sign check, one TNC 640 table per axis, and the
//! source recorded where the format has comments.

use std::path::{Path, PathBuf};

use axcomp::emit::{sinumerik840d, tnc640};

use crate::util::{Run, axcomp, root};

/// A synthetic 6-DOF survey (X.csv, Y.csv, Z.csv over the MCV 754's strokes).
fn geometry(dir: &Path) -> PathBuf {
    let geo = dir.join("geo");
    let run = axcomp(["synth", "--geometry", geo.to_str().unwrap(), "--seed", "15"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    geo
}

/// `axcomp convert FILE --controller CONTROLLER -o OUT EXTRA…`.
fn convert(file: &Path, controller: &str, out: &Path, extra: &[&str]) -> Run {
    let mut args: Vec<std::ffi::OsString> = vec![
        "convert".into(),
        file.into(),
        "--controller".into(),
        controller.into(),
        "-o".into(),
        out.into(),
    ];
    args.extend(extra.iter().map(Into::into));
    axcomp(args)
}

fn tables_of(path: &Path) -> Vec<usize> {
    sinumerik840d::cec_tables(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn sample() -> PathBuf {
    root().join("fixtures/sample-x.rtl")
}

const GRID: [&str; 6] = ["--start", "0", "--step", "50", "--count", "16"];

#[test]
fn cec_table_numbers_are_distinct_across_the_files_of_one_machine() {
    let dir = tempfile::tempdir().unwrap();
    let geo = geometry(dir.path());
    let x_y = dir.path().join("X-Y.MPF");
    let x_z = dir.path().join("X-Z.MPF");
    for (out, name) in [(&x_y, "EYX"), (&x_z, "EZX")] {
        let run = convert(
            &geo.join("X.csv"),
            "sinumerik840d",
            out,
            &["--straightness", name],
        );
        assert_eq!(run.code, 0, "{}", run.stderr);
    }
    // Bidirectional pairs of X and Y (the sample test named Y for the second).
    let x_pair = dir.path().join("X.MPF");
    let y_pair = dir.path().join("Y.MPF");
    let mut flags = GRID.to_vec();
    flags.extend(["--mode", "bidirectional"]);
    assert_eq!(convert(&sample(), "sinumerik840d", &x_pair, &flags).code, 0);
    flags.extend(["--axis", "Y"]);
    assert_eq!(convert(&sample(), "sinumerik840d", &y_pair, &flags).code, 0);
    // By hand, machine axes X, Y, Z: pairs 0/1 (X), 2/3 (Y), 4/5 (Z); cross
    // tables after them, Y = F(X) 6, Z = F(X) 7.
    assert_eq!(tables_of(&x_pair), [0, 1]);
    assert_eq!(tables_of(&y_pair), [2, 3]);
    assert_eq!(tables_of(&x_y), [6]);
    assert_eq!(tables_of(&x_z), [7]);
    // predict takes the two cross tables together.
    let predict = |a: &Path, b: &Path| {
        axcomp([
            "predict".to_string(),
            "--survey".to_string(),
            geo.join("survey.toml").display().to_string(),
            "--cross-table".to_string(),
            format!("Y=F(X):{}", a.display()),
            "--cross-table".to_string(),
            format!("Z=F(X):{}", b.display()),
        ])
    };
    let run = predict(&x_y, &x_z);
    assert_eq!(run.code, 0, "{}", run.stderr);
    // Two programs with one table number (as both cross tables were once
    // numbered 0) overwrite each other in the control: refused, both named.
    let clash = dir.path().join("X-Z-clash.MPF");
    let text = std::fs::read_to_string(&x_z).unwrap().replace("[7", "[6");
    std::fs::write(&clash, text).unwrap();
    let run = predict(&x_y, &clash);
    assert_eq!(run.code, 2, "{}", run.stdout);
    assert!(
        run.stderr.contains("X-Y.MPF")
            && run.stderr.contains("X-Z-clash.MPF")
            && run.stderr.contains("CEC table 6"),
        "{}",
        run.stderr
    );
}

#[test]
fn a_cross_axis_table_keeps_the_profiles_point_limit() {
    let dir = tempfile::tempdir().unwrap();
    let geo = geometry(dir.path());
    // The MCV 754 profile: max_points = 200. --step 1 over 0…750 mm is 751 points.
    let machine = root().join("fixtures/machines/mcv754-quick.toml");
    for (controller, name) in [("sinumerik840d", "X-Y.MPF"), ("tnc640", "X.COM")] {
        let out = dir.path().join(name);
        let run = convert(
            &geo.join("X.csv"),
            controller,
            &out,
            &[
                "--straightness",
                "EYX",
                "--step",
                "1",
                "--machine",
                machine.to_str().unwrap(),
            ],
        );
        assert_eq!(run.code, 2, "{controller}: {}", run.stdout);
        assert!(
            run.stderr.contains("at most 200") && run.stderr.contains("751"),
            "{}",
            run.stderr
        );
        assert!(!out.exists(), "nothing written");
        // --step 5 gives 151 points: taken.
        let run = convert(
            &geo.join("X.csv"),
            controller,
            &out,
            &[
                "--straightness",
                "EYX",
                "--step",
                "5",
                "--machine",
                machine.to_str().unwrap(),
            ],
        );
        assert_eq!(run.code, 0, "{controller}: {}", run.stderr);
    }
}

#[test]
fn the_cec_activation_names_every_step_and_the_sign_check() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("X.MPF");
    let mut flags = GRID.to_vec();
    flags.extend(["--mode", "bidirectional"]);
    let run = convert(&sample(), "sinumerik840d", &out, &flags);
    assert_eq!(run.code, 0, "{}", run.stderr);
    // K3 03/2013 p.245 and p.264: per table MD18342 and SD41300, per axis MD32710.
    for needle in [
        "MD18342 $MN_MM_CEC_MAX_POINTS[0], $MN_MM_CEC_MAX_POINTS[1] ≥ 16",
        "MD32710 $MA_CEC_ENABLE[X1] = 0 while the program loads",
        "SD41300 $SN_CEC_TABLE_ENABLE[0], $SN_CEC_TABLE_ENABLE[1] = 1",
        "check the sign with one test move",
    ] {
        assert!(run.stdout.contains(needle), "{needle:?} in\n{}", run.stdout);
    }
    assert!(
        !run.stdout.contains("$MA_CEC_TABLE_ENABLE"),
        "{}",
        run.stdout
    );
    // The cross CEC: its sign is reconstructed too. Its largest value, by
    // the table the same run prints: the check names that point.
    let geo = geometry(dir.path());
    let cross = dir.path().join("X-Y.MPF");
    let run = convert(
        &geo.join("X.csv"),
        "sinumerik840d",
        &cross,
        &["--straightness", "EYX", "--json"],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let activation = json["activation"].as_str().unwrap();
    let largest = json["points"]
        .as_array()
        .unwrap()
        .iter()
        .max_by(|a, b| {
            let v = |p: &serde_json::Value| p["value_mm"].as_f64().unwrap().abs();
            v(a).total_cmp(&v(b))
        })
        .unwrap();
    for needle in [
        "CEC table 6 (Y1 = F(X1), both directions)".to_string(),
        "MD18342 $MN_MM_CEC_MAX_POINTS[6]".to_string(),
        "MD32710 $MA_CEC_ENABLE[Y1] = 0".to_string(),
        "SD41300 $SN_CEC_TABLE_ENABLE[6] = 1".to_string(),
        "check the sign with one test move".to_string(),
        format!("move X1 to {} mm", largest["position_mm"].as_f64().unwrap()),
    ] {
        assert!(activation.contains(&needle), "{needle:?} in\n{activation}");
    }
}

#[test]
fn one_tnc640_table_per_axis_holds_both_columns() {
    let dir = tempfile::tempdir().unwrap();
    let geo = geometry(dir.path());
    // Without --machine and without the axis's table: X.COM still has X's
    // own column (0: no positioning compensation) beside Y.
    let alone = dir.path().join("X-alone.COM");
    let run = convert(
        &geo.join("X.csv"),
        "tnc640",
        &alone,
        &["--straightness", "EYX", "--step", "50"],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    let text = std::fs::read_to_string(&alone).unwrap();
    assert!(
        text.contains("NR   AXISPOS       BACKLASH      X             Y\r\n"),
        "{text}"
    );
    assert!(run.stdout.contains("one active table"), "{}", run.stdout);
    // X's positioning table, then the straightness put into it.
    let positioning = dir.path().join("X.COM");
    let mut flags = GRID.to_vec();
    flags.extend(["--mode", "bidirectional"]);
    assert_eq!(convert(&sample(), "tnc640", &positioning, &flags).code, 0);
    let both = dir.path().join("X-both.COM");
    let run = convert(
        &geo.join("X.csv"),
        "tnc640",
        &both,
        &[
            "--straightness",
            "EYX",
            "--existing",
            positioning.to_str().unwrap(),
        ],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    let text = std::fs::read_to_string(&both).unwrap();
    let old = std::fs::read_to_string(&positioning).unwrap();
    // X and BACKLASH as they were, Y added: the positioning table reads back unchanged.
    assert_eq!(
        tnc640::read(&text, "X").unwrap(),
        tnc640::read(&old, "X").unwrap()
    );
    let alone_y =
        tnc640::read_cross_axis(&std::fs::read_to_string(&alone).unwrap(), "X", "Y").unwrap();
    let both_y = tnc640::read_cross_axis(&text, "X", "Y").unwrap();
    assert_eq!(both_y, alone_y, "the same Y = F(X) on the same points");
    // Updating X's positioning table keeps the Y column.
    let updated = dir.path().join("X-updated.COM");
    let mut flags = GRID.to_vec();
    flags.extend([
        "--mode",
        "bidirectional",
        "--existing",
        both.to_str().unwrap(),
    ]);
    let run = convert(&sample(), "tnc640", &updated, &flags);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let text = std::fs::read_to_string(&updated).unwrap();
    assert_eq!(tnc640::read_cross_axis(&text, "X", "Y").unwrap(), alone_y);
    // On other points the Y column would be lost: refused.
    let run = convert(
        &sample(),
        "tnc640",
        &dir.path().join("X-other.COM"),
        &[
            "--start",
            "0",
            "--step",
            "75",
            "--count",
            "11",
            "--existing",
            both.to_str().unwrap(),
        ],
    );
    assert_eq!(run.code, 2, "{}", run.stdout);
    assert!(
        run.stderr.contains("one active table per axis"),
        "{}",
        run.stderr
    );
    // predict refuses two tables of X for the TNC 640, naming both.
    let run = axcomp([
        "predict".to_string(),
        "--measured".to_string(),
        sample().display().to_string(),
        "--table".to_string(),
        format!("X={}", positioning.display()),
        "--cross-table".to_string(),
        format!("Y=F(X):{}", alone.display()),
    ]);
    assert_eq!(run.code, 2, "{}", run.stdout);
    assert!(
        run.stderr.contains("X.COM")
            && run.stderr.contains("X-alone.COM")
            && run
                .stderr
                .contains("one active compensation table per axis"),
        "{}",
        run.stderr
    );
}

#[test]
fn tables_record_their_source_where_the_format_has_comments() {
    let dir = tempfile::tempdir().unwrap();
    let version = env!("CARGO_PKG_VERSION");
    // sample-x.rtl records "Date: 2026-11-20 09:14:00" (line 19): that date, not today's.
    let lec = dir.path().join("X.MPF");
    assert_eq!(convert(&sample(), "sinumerik840d", &lec, &GRID).code, 0);
    let text = std::fs::read_to_string(&lec).unwrap();
    let line =
        format!("; made by axcomp {version} from sample-x.rtl (measured 2026-11-20 09:14:00)\n");
    assert!(
        text.starts_with(&format!("%_N_AX_EEC_INI\n{line}CHANDATA(1)\n")),
        "{text}"
    );
    // The reader skips the comment.
    assert_eq!(
        sinumerik840d::read(&text, "X1", true)
            .unwrap()
            .positions
            .len(),
        16
    );
    // A geometry CSV records no date.
    let geo = geometry(dir.path());
    let cross = dir.path().join("X-Y.MPF");
    let run = convert(
        &geo.join("X.csv"),
        "sinumerik840d",
        &cross,
        &["--straightness", "EYX"],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    let text = std::fs::read_to_string(&cross).unwrap();
    assert!(
        text.contains(&format!(
            "; made by axcomp {version} from X.csv (its date not recorded)\n"
        )),
        "{text}"
    );
    // Heidenhain .COM and LinuxCNC files have no comment syntax: nothing added.
    for (controller, name) in [("tnc640", "X.COM"), ("linuxcnc", "x.comp")] {
        let out = dir.path().join(name);
        assert_eq!(convert(&sample(), controller, &out, &[]).code, 0);
        assert!(!std::fs::read_to_string(&out).unwrap().contains("axcomp"));
    }
}
