//! Cross-axis (straightness) tables: Heidenhain TNC 640 `.COM` with a
//! dependent column and Sinumerik CEC with INPUT ≠ OUTPUT axis, written
//! against golden files and read back (issue 15).

use axcomp::compensate::cross_axis::CrossAxisTable;
use axcomp::emit::{EmitOptions, MachineProfile, sinumerik840d, tnc640};

use crate::util::{assert_golden, root};

/// The golden files these tests write (controller folder, file name);
/// `convert::every_golden_file_has_a_case` counts them as produced here.
pub const GOLDENS: [(&str, &str); 2] = [
    ("tnc640", "cross-Y-of-X.COM"),
    ("sinumerik840d", "cross-Y-of-X-cec.MPF"),
];

fn golden(index: usize) -> std::path::PathBuf {
    let (controller, name) = GOLDENS[index];
    root()
        .join("formats")
        .join(controller)
        .join("golden")
        .join(name)
}

/// EYX by hand: X's straightness in Y, a 3 µm bow over 0 … 750 mm at 150 mm.
fn eyx() -> CrossAxisTable {
    CrossAxisTable::new(
        "X",
        "Y",
        vec![0.0, 150.0, 300.0, 450.0, 600.0, 750.0],
        vec![0.0, 0.0017, 0.0028, 0.003, 0.0021, 0.0004],
        0.0,
    )
}

#[test]
fn tnc640_dependent_column_round_trips() {
    let profile = MachineProfile::default();
    let options = EmitOptions::for_axis(&profile, "Y", "X.COM").unwrap();
    let text = tnc640::write_cross_axis(&eyx(), "X", &options, None).unwrap();
    // The values sit in column Y of X.COM: Y = F(X), not negated; X.COM is
    // X's one table, so its X column is there too (0 without an existing table).
    assert!(text.starts_with("BEGIN X.COM MM\r\n"), "{text}");
    assert!(
        text.contains("2    +300                        +0.0000       +0.0028\r\n"),
        "{text}"
    );
    assert_golden(&text, &golden(0));
    let back = tnc640::read_cross_axis(&text, "X", "Y").unwrap();
    assert_eq!(back, eyx());
    // A direction in BACKLASH of a file with only the dependent column is
    // refused: a straightness has none.
    let y_only = text
        .replace("BACKLASH      X             Y", "BACKLASH      Y")
        .replace("+0.0000       +", "+");
    let with_backlash = y_only.replace(
        "2    +300                        +0.0028",
        "2    +300          +0.0001       +0.0028",
    );
    assert_ne!(with_backlash, y_only);
    let error = tnc640::read_cross_axis(&with_backlash, "X", "Y").unwrap_err();
    assert!(error.message.contains("BACKLASH"), "{error}");
}

#[test]
fn sinumerik_cec_with_another_output_axis_round_trips() {
    let profile = MachineProfile::default();
    let options = EmitOptions::for_axis(&profile, "Y", "CEC").unwrap();
    let input = profile.axis("X").unwrap().sinumerik_axis;
    let output = options.axes[0].sinumerik_axis.clone();
    // Y = F(X) is table 6 on an X, Y, Z machine: after the own pairs 0…5.
    let t = profile.cec_table("X", "Y").unwrap();
    assert_eq!(t, 6);
    let text = sinumerik840d::write_cross_axis(&eyx(), &input, t, &options).unwrap();
    assert!(
        text.contains(&format!("$AN_CEC_INPUT_AXIS[6]=({input})\n")),
        "{text}"
    );
    assert!(
        text.contains(&format!("$AN_CEC_OUTPUT_AXIS[6]=({output})\n")),
        "{text}"
    );
    // Corrections (the profile's default): −error.
    assert!(text.contains("$AN_CEC[6,2]=-0.0028\n"), "{text}");
    assert_golden(&text, &golden(1));
    let back = sinumerik840d::read_cross_axis(&text, (&input, &output), ("X", "Y"), true).unwrap();
    assert_eq!(back, eyx());
    // The cross table is not Y's own table.
    let own = sinumerik840d::read(&text, &output, true).unwrap_err();
    assert!(own.message.contains("no $AA_ENC_COMP table"), "{own}");
    let missing =
        sinumerik840d::read_cross_axis(&text, (&output, &input), ("Y", "X"), true).unwrap_err();
    assert!(missing.message.contains("found none"), "{missing}");
}

/// `convert` of a straightness test (issue 15's cross-axis tables from the
/// command line).
mod convert {
    use std::path::Path;

    use axcomp::compensate::cross_axis::CrossAxisTable;
    use axcomp::emit::{EmitOptions, MachineProfile, sinumerik840d, tnc640};
    use axcomp::model::{ErrorName, GeometricErrors, Machine};
    use axcomp::predict::cross_axis_table_at;
    use axcomp::predict::survey::{Survey, SurveyFile, assemble};
    use axcomp::read::geometry;

    use crate::util::{Run, axcomp};

    const GOLDEN_MM: [f64; 6] = [0.0, 0.0017, 0.0028, 0.003, 0.0021, 0.0004];

    /// A straightness-only test of X: EYX read as the golden's bow, one run each way.
    fn eyx_file(dir: &Path) -> std::path::PathBuf {
        let mut text = String::from("# axis: X\ntarget_mm,run,direction,EYX_um\n");
        for direction in ["up", "down"] {
            for (i, value) in GOLDEN_MM.iter().enumerate() {
                text.push_str(&format!("{},1,{direction},{}\n", i * 150, value * 1000.0));
            }
        }
        let path = dir.join("X-EYX.csv");
        std::fs::write(&path, text).unwrap();
        path
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

    #[test]
    fn a_straightness_test_gives_the_table_less_its_slope_by_hand() {
        let dir = tempfile::tempdir().unwrap();
        let file = eyx_file(dir.path());
        let out = dir.path().join("X.COM");
        let run = convert(&file, "tnc640", &out, &[]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        // The least-squares slope of the bow, by hand: Σ(x − 375)·g / Σ(x − 375)²
        // = 0.255 mm² / 393 750 mm² = 0.6476 µrad; the table is g − b·x
        // (zero at X = 0, the reference): 0.0016029, 0.0026057, 0.0027086,
        // 0.0017114, −0.0000857 mm.
        assert!(
            run.stdout.contains("Cross-axis table Y = F(X)"),
            "{}",
            run.stdout
        );
        assert!(run.stdout.contains("slope 0.65 µrad"), "{}", run.stdout);
        assert!(run.stdout.contains("not compensated"), "{}", run.stdout);
        let text = std::fs::read_to_string(&out).unwrap();
        for row in [
            "0    +0                          +0.0000       +0.0000\r\n",
            "1    +150                        +0.0000       +0.0016\r\n",
            "2    +300                        +0.0000       +0.0026\r\n",
            "3    +450                        +0.0000       +0.0027\r\n",
            "4    +600                        +0.0000       +0.0017\r\n",
            "5    +750                        +0.0000       -0.0001\r\n",
        ] {
            assert!(text.contains(row), "{row:?} in\n{text}");
        }
        assert!(
            text.contains("NR   AXISPOS       BACKLASH      X             Y\r\n"),
            "{text}"
        );
        // The library's writer on the table by hand gives the same bytes.
        let b = 0.255 / 393_750.0;
        let by_hand = CrossAxisTable::new(
            "X",
            "Y",
            (0..6).map(|i| f64::from(i) * 150.0).collect(),
            GOLDEN_MM
                .iter()
                .enumerate()
                .map(|(i, g)| g - b * i as f64 * 150.0)
                .collect(),
            0.0,
        );
        let options = EmitOptions::for_axis(&MachineProfile::default(), "Y", "X.COM").unwrap();
        assert_eq!(
            text,
            tnc640::write_cross_axis(&by_hand, "X", &options, None).unwrap()
        );
        // Sinumerik: the same table as a CEC X → Y, read back.
        let cec = dir.path().join("X-Y.MPF");
        let run = convert(&file, "sinumerik840d", &cec, &[]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        assert!(run.stdout.contains("correction (−error)"), "{}", run.stdout);
        let text = std::fs::read_to_string(&cec).unwrap();
        let back = sinumerik840d::read_cross_axis(&text, ("X1", "Y1"), ("X", "Y"), true).unwrap();
        for x in [0.0, 150.0, 300.0, 450.0, 600.0, 750.0] {
            assert!(
                (back.value_at(x) - by_hand.value_at(x)).abs() < 0.6e-6,
                "{x}"
            );
        }
    }

    #[test]
    fn a_synthetic_6dof_test_gives_the_surveys_table_and_predict_reads_it() {
        let dir = tempfile::tempdir().unwrap();
        let geo = dir.path().join("geo");
        let run = axcomp(["synth", "--geometry", geo.to_str().unwrap(), "--seed", "15"]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        // What predict --survey holds for EYX, on the grid convert is given.
        let machine = Machine::bundled();
        let survey_text = std::fs::read_to_string(geo.join("survey.toml")).unwrap();
        let survey = Survey::from_toml_str(&survey_text).unwrap();
        let files: Vec<SurveyFile> = survey
            .tests
            .iter()
            .map(|t| {
                let text = std::fs::read_to_string(geo.join(&t.file)).unwrap();
                SurveyFile::Geometry(geometry::parse(&text).unwrap())
            })
            .collect();
        let state = assemble(&machine, &survey, &GeometricErrors::default(), &files).unwrap();
        let positions: Vec<f64> = (0..16).map(|i| f64::from(i) * 50.0).collect();
        let expected = cross_axis_table_at(&state.errors, ErrorName::EYX, positions, 0.0).unwrap();
        let options = EmitOptions::for_axis(&MachineProfile::default(), "Y", "X-Y.COM").unwrap();
        let expected_text = tnc640::write_cross_axis(&expected, "X", &options, None).unwrap();
        // The line and optics as the survey states them for X.csv.
        let out = geo.join("X-Y.COM");
        let run = convert(
            &geo.join("X.csv"),
            "tnc640",
            &out,
            &[
                "--straightness",
                "EYX",
                "--line",
                "y=100,z=-120",
                "--optics-offset",
                "y=120,z=-150",
                "--step",
                "50",
            ],
        );
        assert_eq!(run.code, 0, "{}", run.stderr);
        assert_eq!(std::fs::read_to_string(&out).unwrap(), expected_text);
        // Without the optics offset the Abbe terms of X's angles stay in: another table.
        let wrong = geo.join("X-Y-no-optics.COM");
        let run = convert(
            &geo.join("X.csv"),
            "tnc640",
            &wrong,
            &["--straightness", "EYX", "--step", "50"],
        );
        assert_eq!(run.code, 0, "{}", run.stderr);
        assert_ne!(std::fs::read_to_string(&wrong).unwrap(), expected_text);
        // predict takes it back.
        let run = axcomp([
            "predict".to_string(),
            "--survey".to_string(),
            geo.join("survey.toml").display().to_string(),
            "--cross-table".to_string(),
            format!("Y=F(X):{}", out.display()),
            "--json".to_string(),
        ]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
        assert!(json["volumetric_max_um"].as_f64().unwrap() > 0.0, "{json}");
        let back = tnc640::read_cross_axis(&expected_text, "X", "Y").unwrap();
        for x in [0.0, 175.0, 400.0, 750.0] {
            assert!(
                (back.value_at(x) - expected.value_at(x)).abs() <= 0.5e-4 + 1e-12,
                "{x}"
            );
        }
    }

    #[test]
    fn what_it_cannot_write_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let file = eyx_file(dir.path());
        let out = dir.path().join("X.COM");
        let run = convert(&file, "itnc530", &out, &[]);
        assert_eq!(run.code, 2, "{}", run.stdout);
        assert!(
            run.stderr.contains("tnc640") && run.stderr.contains("sinumerik840d"),
            "{}",
            run.stderr
        );
        assert!(run.stderr.contains("itnc530 has none"), "{}", run.stderr);
        // An angular-only test has no straightness.
        let angular = dir.path().join("X-pitch.csv");
        std::fs::write(
            &angular,
            "# axis: X\ntarget_mm,run,direction,EBX_urad\n0,1,up,0\n375,1,up,2.5\n750,1,up,1\n",
        )
        .unwrap();
        let run = convert(&angular, "tnc640", &out, &[]);
        assert_eq!(run.code, 2, "{}", run.stdout);
        assert!(
            run.stderr.contains("written from a straightness") && run.stderr.contains("EBX"),
            "{}",
            run.stderr
        );
        // A positioning flag has no meaning here.
        let run = convert(&file, "tnc640", &out, &["--mode", "bidirectional"]);
        assert_eq!(run.code, 2, "{}", run.stdout);
        assert!(run.stderr.contains("--mode"), "{}", run.stderr);
        assert!(!out.exists(), "nothing written");
    }
}
