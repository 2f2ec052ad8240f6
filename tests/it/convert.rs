//! `axcomp convert`: golden files per controller (byte for byte), the read
//! back of every golden file, refusals, and the seed 001 Fig. 29 round trip.
//!
//! Golden files live in `formats/<controller>/golden/`; regenerate them
//! deliberately with `AXCOMP_UPDATE_GOLDEN=1 cargo test` and review the diff.

use std::path::{Path, PathBuf};

use axcomp::emit::{self, Controller, EmitOptions, MachineProfile};
use axcomp::measurement::Direction;

use crate::util::{assert_golden, axcomp, root, shared_data};

const SAMPLE: &str = "fixtures/sample-x.rtl";
const REGULAR: &str = "ecmc/ecmc_target_muts_logger/b02__x__target_x.md_ISO230.dat";
const INCH: &str = "api-xd/example__8055__X Axis Forward.pos";

/// One golden case: input, controller, extra flags, golden file name.
struct Case {
    input: PathBuf,
    controller: &'static str,
    flags: &'static [&'static str],
    golden: &'static str,
}

fn case(
    input: PathBuf,
    controller: &'static str,
    flags: &'static [&'static str],
    golden: &'static str,
) -> Case {
    Case {
        input,
        controller,
        flags,
        golden,
    }
}

fn cases() -> Vec<Case> {
    let sample = || root().join(SAMPLE);
    let regular = || shared_data(REGULAR);
    let inch = || shared_data(INCH);
    let grid_50: &'static [&'static str] = &["--start", "0", "--step", "50", "--count", "16"];
    vec![
        // Irregular targets: free-position formats take them as they are.
        case(sample(), "tnc640", &[], "sample-mean.COM"),
        case(
            sample(),
            "tnc640",
            &["--mode", "bidirectional"],
            "sample-bidirectional.COM",
        ),
        case(sample(), "linuxcnc", &[], "sample-mean-type0.txt"),
        case(
            sample(),
            "linuxcnc",
            &["--linuxcnc-type", "1"],
            "sample-mean-type1.txt",
        ),
        case(
            sample(),
            "linuxcnc",
            &["--mode", "bidirectional"],
            "sample-bidirectional-type0.txt",
        ),
        // Irregular targets on a regular grid for the one-step formats.
        case(sample(), "itnc530", grid_50, "sample-grid50.COM"),
        case(sample(), "sinumerik840d", grid_50, "sample-grid50-lec.MPF"),
        case(
            sample(),
            "sinumerik840d",
            &[
                "--start",
                "0",
                "--step",
                "50",
                "--count",
                "16",
                "--mode",
                "bidirectional",
            ],
            "sample-grid50-cec.MPF",
        ),
        // Regular targets (ESS b02 X axis, −20 … 20 mm step 5).
        case(regular(), "itnc530", &[], "b02x-mean.COM"),
        case(
            regular(),
            "tnc640",
            &["--mode", "bidirectional"],
            "b02x-bidirectional.COM",
        ),
        case(regular(), "sinumerik840d", &[], "b02x-lec.MPF"),
        case(
            regular(),
            "linuxcnc",
            &["--mode", "bidirectional"],
            "b02x-bidirectional-type0.txt",
        ),
        // Inch input (API XD, 0 … 130 in step 5): converted to mm.
        case(inch(), "itnc530", &[], "api-inch.COM"),
        case(inch(), "tnc640", &[], "api-inch.COM"),
        case(inch(), "sinumerik840d", &[], "api-inch-lec.MPF"),
        case(inch(), "linuxcnc", &[], "api-inch-type0.txt"),
        // Reference shift.
        case(
            sample(),
            "tnc640",
            &["--reference", "302.304"],
            "sample-reference302.COM",
        ),
        case(
            sample(),
            "sinumerik840d",
            &[
                "--start",
                "0",
                "--step",
                "50",
                "--count",
                "16",
                "--reference",
                "300",
            ],
            "sample-reference300-lec.MPF",
        ),
        // Coupled axes and machine profiles (an inch gantry: LinuxCNC writes inches).
        case(
            sample(),
            "tnc640",
            &[
                "--also",
                "U",
                "--machine",
                "fixtures/machines/gantry-inch.toml",
            ],
            "sample-gantry.COM",
        ),
        case(
            sample(),
            "itnc530",
            &[
                "--start",
                "0",
                "--step",
                "50",
                "--count",
                "16",
                "--also",
                "U",
                "--machine",
                "fixtures/machines/gantry-inch.toml",
            ],
            "sample-gantry.COM",
        ),
        case(
            sample(),
            "sinumerik840d",
            &[
                "--start",
                "0",
                "--step",
                "50",
                "--count",
                "16",
                "--also",
                "U",
                "--machine",
                "fixtures/machines/gantry-inch.toml",
            ],
            "sample-gantry-lec.MPF",
        ),
        case(
            sample(),
            "linuxcnc",
            &[
                "--machine",
                "fixtures/machines/gantry-inch.toml",
                "--mode",
                "bidirectional",
            ],
            "sample-gantry-inch-type0.txt",
        ),
        case(
            sample(),
            "tnc640",
            &["--machine", "fixtures/machines/mcv754-quick.toml"],
            "sample-mcv754.COM",
        ),
        // Measured with a table active: the old table plus the residual.
        case(
            sample(),
            "tnc640",
            &[
                "--existing",
                "formats/tnc640/golden/sample-reference302.COM",
            ],
            "sample-existing.COM",
        ),
        case(
            sample(),
            "linuxcnc",
            &[
                "--mode",
                "bidirectional",
                "--existing",
                "formats/linuxcnc/golden/sample-bidirectional-type0.txt",
            ],
            "sample-existing-type0.txt",
        ),
        // Fagor: the 8055 in the test's unit (inch here), the 8065 in mm,
        // a UTF-16LE file (the golden holds its decoded text).
        case(inch(), "fagor8055", &[], "api-inch-ALX"),
        case(
            inch(),
            "fagor8055",
            &[
                "--existing",
                "../shared/data/api-xd/example__8055__ALX",
                "--reference",
                "0",
            ],
            "api-existing-ALX",
        ),
        case(
            sample(),
            "fagor8055",
            &["--mode", "bidirectional"],
            "sample-bidirectional-ALX",
        ),
        // (An updated .mp would copy the third-party file's other lines into
        // the repository: tests/it/fagor.rs checks the update instead; without
        // the control's .mp no file is written, tests/it/fagor_update.rs.)
        // A hand-made .mp (fixtures/README.md) updated.
        case(
            inch(),
            "fagor8065",
            &["--existing", "fixtures/fagor8065/X.mp"],
            "api-update-X.mp",
        ),
        // A rotary C axis over a full turn (issue 14): degrees in every file,
        // a Sinumerik modulo table, LinuxCNC with the ends held.
        case(rotary(), "itnc530", &[], "rotary-c-mean.COM"),
        case(rotary(), "tnc640", &[], "rotary-c-mean.COM"),
        case(rotary(), "sinumerik840d", &[], "rotary-c-mean-lec.MPF"),
        case(rotary(), "linuxcnc", &[], "rotary-c-mean-type0.txt"),
    ]
}

/// The synthetic rotary test (fixtures/rotary/truth.toml).
const ROTARY: &str = "fixtures/rotary/c.csv";

fn rotary() -> PathBuf {
    root().join(ROTARY)
}

/// Runs convert into a temporary directory; returns (file bytes, --json object).
fn convert(
    input: &Path,
    controller: &str,
    flags: &[&str],
    name: &str,
) -> (String, serde_json::Value) {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join(name);
    let mut args: Vec<String> = vec![
        "convert".into(),
        input.display().to_string(),
        "--controller".into(),
        controller.into(),
    ];
    args.extend(flags.iter().map(|f| f.to_string()));
    args.extend([
        "-o".into(),
        output.display().to_string(),
        "--json".into(),
        "--quiet".into(),
    ]);
    let run = axcomp(&args);
    assert_eq!(run.code, 0, "convert {args:?}: {}", run.stderr);
    let json = serde_json::from_str(&run.stdout).unwrap();
    // Fagor 8065 files are UTF-16: compare their decoded text.
    let (text, _) = emit::decode_table(&std::fs::read(&output).unwrap()).unwrap();
    (text, json)
}

/// The options a module needs to read the file back, from the case's profile.
fn read_options(case: &Case) -> EmitOptions {
    let profile = case
        .flags
        .iter()
        .position(|f| *f == "--machine")
        .map(|i| {
            MachineProfile::from_toml_str(
                &std::fs::read_to_string(root().join(case.flags[i + 1])).unwrap(),
            )
            .unwrap()
        })
        .unwrap_or_default();
    let rotary = case.input.ends_with(ROTARY);
    EmitOptions {
        axes: vec![profile.axis(if rotary { "C" } else { "X" }).unwrap()],
        table_name: String::new(),
        // A Fagor 8055 table is in the test's unit (the API .pos files are inch).
        machine_unit: profile.table_unit(
            Controller::from_name(case.controller).unwrap(),
            if case.input.extension().is_some_and(|e| e == "pos") {
                axcomp::units::LengthUnit::Inch
            } else {
                axcomp::units::LengthUnit::Millimetre
            },
        ),
        linuxcnc_type: if case.flags.contains(&"1") { 1 } else { 0 },
        max_points: None,
        max_value_mm: None,
        provenance: None,
        cec_values_are_corrections: true,
        tnc640_columns: Vec::new(),
        kind: if rotary {
            axcomp::measurement::AxisKind::Rotary
        } else {
            axcomp::measurement::AxisKind::Linear
        },
    }
}

/// The table's values in µm (″ on a rotary axis, whose JSON says `values_arcsec`).
fn values_um(json: &serde_json::Value, key: &str) -> Vec<f64> {
    let values = json.get("values_um").unwrap_or(&json["values_arcsec"]);
    values[key]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

#[test]
fn golden_files_per_controller() {
    for case in cases() {
        let (text, json) = convert(&case.input, case.controller, case.flags, case.golden);
        let golden = root()
            .join("formats")
            .join(case.controller)
            .join("golden")
            .join(case.golden);
        assert_golden(&text, &golden);
        // The golden file reads back, with the same module, to the table convert reports.
        let options = read_options(&case);
        let (controller, table) =
            emit::read_any(&text, &options, Some(options.linuxcnc_type)).unwrap();
        assert_eq!(controller.name(), case.controller);
        // µm per mm, or ″ per ° on a rotary axis.
        let per_unit = if options.kind == axcomp::measurement::AxisKind::Rotary {
            3600.0
        } else {
            1000.0
        };
        let resolution_um = emit::resolution_mm(controller, options.file_unit()) * per_unit;
        let positions: Vec<f64> = json
            .get("positions_mm")
            .unwrap_or(&json["positions_deg"])
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(table.positions.len(), positions.len(), "{}", case.golden);
        for (a, b) in table.positions.iter().zip(&positions) {
            assert!(
                (a - b).abs() * per_unit <= resolution_um,
                "{}: position {a} vs {b}",
                case.golden
            );
        }
        let (up, down) = match json["mode"].as_str().unwrap() {
            "mean" => (values_um(&json, "mean"), values_um(&json, "mean")),
            _ => (values_um(&json, "up"), values_um(&json, "down")),
        };
        for (direction, expected) in [(Direction::Up, up), (Direction::Down, down)] {
            for (a, b) in table.values.for_direction(direction).iter().zip(&expected) {
                assert!(
                    (a * per_unit - b).abs() <= resolution_um / 2.0 + 1e-9,
                    "{}: {direction} value {a} mm vs {b} µm",
                    case.golden
                );
            }
        }
    }
}

#[test]
fn every_golden_file_has_a_case() {
    let names: Vec<(String, String)> = cases()
        .iter()
        .map(|c| (c.controller.to_string(), c.golden.to_string()))
        .collect();
    for controller in Controller::ALL {
        let folder = root()
            .join("formats")
            .join(controller.name())
            .join("golden");
        for entry in std::fs::read_dir(&folder).unwrap() {
            let name = entry.unwrap().file_name().into_string().unwrap();
            let cross_axis = crate::cross_axis::GOLDENS.contains(&(controller.name(), &name))
                || crate::fanuc::GOLDENS.contains(&name.as_str())
                || crate::thermal_hal::GOLDENS.contains(&(controller.name(), &name));
            assert!(
                cross_axis || names.contains(&(controller.name().to_string(), name.clone())),
                "{}/{name} is not produced by any case",
                folder.display()
            );
        }
    }
}

/// Seed 001 Fig. 29: the TNC 640 table of the X axis (AXISPOS 0 … 1000 step 100).
#[test]
fn seed_001_figure_29_round_trip() {
    let figure: [(&str, &str, &str); 11] = [
        ("0", "+0", "+0.0000"),
        ("1", "+100", "-0.0023"),
        ("2", "+200", "-0.0042"),
        ("3", "+300", "-0.0057"),
        ("4", "+400", "-0.0067"),
        ("5", "+500", "-0.0082"),
        ("6", "+600", "-0.0095"),
        ("7", "+700", "-0.0106"),
        ("8", "+800", "-0.0121"),
        ("9", "+900", "-0.0130"),
        ("10", "+1000", "-0.0144"),
    ];
    // A measurement whose means are those values: one run each way, the same values.
    let mut csv = String::from("# axis: X\ntarget_mm,run,direction,deviation_um\n");
    for direction in ["up", "down"] {
        for (_, position, value) in &figure {
            let um = value.parse::<f64>().unwrap() * 1000.0;
            csv.push_str(&format!(
                "{},1,{direction},{um}\n",
                position.trim_start_matches('+')
            ));
        }
    }
    let directory = tempfile::tempdir().unwrap();
    let input = directory.path().join("fig29.csv");
    std::fs::write(&input, csv).unwrap();
    let (text, _) = convert(&input, "tnc640", &[], "X.COM");
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(2)
        .take_while(|l| *l != "[END]")
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(rows.len(), figure.len());
    for (row, (nr, axispos, value)) in rows.iter().zip(figure) {
        assert_eq!(
            row,
            &vec![nr, axispos, value],
            "BACKLASH empty, as in the figure"
        );
    }
    assert_eq!(
        text.lines().nth(1).unwrap(),
        "NR   AXISPOS       BACKLASH      X"
    );
}

fn refused(args: &[&str], needle: &str) {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("out.txt");
    let mut all: Vec<String> = vec!["convert".into()];
    all.extend(args.iter().map(|a| a.to_string()));
    all.extend(["-o".into(), output.display().to_string()]);
    let run = axcomp(&all);
    assert_eq!(run.code, 2, "{args:?} must be refused: {}", run.stdout);
    assert!(run.stderr.contains(needle), "{args:?}: {}", run.stderr);
    assert!(
        !output.exists(),
        "nothing is written when the table is refused"
    );
    assert_eq!(
        std::fs::read_dir(directory.path()).unwrap().count(),
        0,
        "no temporary file left behind"
    );
}

#[test]
fn what_the_controllers_would_reject_is_refused() {
    refused(
        &[
            SAMPLE,
            "--controller",
            "itnc530",
            "--mode",
            "bidirectional",
            "--step",
            "50",
        ],
        "itnc530 tables hold one value per point; use --mode mean",
    );
    refused(
        &[SAMPLE, "--controller", "itnc530"],
        "the targets are unevenly spaced (16 targets from 0 to 750 mm) and itnc530 needs one step",
    );
    refused(
        &[SAMPLE, "--controller", "sinumerik840d"],
        "sinumerik840d needs one step",
    );
    refused(
        &[SAMPLE, "--controller", "linuxcnc", "--step", "2"],
        "linuxcnc takes at most 256 compensation points, the table has 376",
    );
    refused(
        &[SAMPLE, "--controller", "itnc530", "--step", "2.5"],
        "itnc530 takes at most 256 compensation points, the table has 301",
    );
    refused(
        &[
            SAMPLE,
            "--controller",
            "sinumerik840d",
            "--step",
            "50",
            "--max-points",
            "10",
        ],
        "takes at most 10 compensation points, the table has 16",
    );
    refused(
        &[
            SAMPLE,
            "--controller",
            "sinumerik840d",
            "--step",
            "2",
            "--machine",
            "fixtures/machines/mcv754-quick.toml",
        ],
        "takes at most 200 compensation points, the table has 376",
    );
    refused(
        &[
            SAMPLE,
            "--controller",
            "tnc640",
            "--start",
            "-50",
            "--step",
            "50",
        ],
        "compensation point -50 mm is outside the measured range 0 … 750 mm; use --extrapolate hold",
    );
    refused(
        &[
            SAMPLE,
            "--controller",
            "itnc530",
            "--step",
            "50",
            "--reference",
            "300",
        ],
        "itnc530 needs the value 0 at the first point",
    );
    refused(
        &[SAMPLE, "--controller", "tnc640", "--reference", "900"],
        "reference position 900 mm is outside the table 0 … 750 mm",
    );
    let unidirectional = shared_data(INCH).display().to_string();
    refused(
        &[
            &unidirectional,
            "--controller",
            "tnc640",
            "--mode",
            "bidirectional",
        ],
        "bidirectional tables need runs in both directions",
    );
    refused(
        &[SAMPLE, "--controller", "mazak"],
        "unknown controller \"mazak\"; supported: itnc530, tnc640, sinumerik840d, linuxcnc",
    );
    refused(
        &[SAMPLE, "--controller", "tnc640", "--also", "Q"],
        "axis \"Q\" has no default",
    );
}

#[test]
fn a_machine_value_limit_is_enforced() {
    let directory = tempfile::tempdir().unwrap();
    let profile = directory.path().join("tight.toml");
    std::fs::write(&profile, "[controller]\nmax_value_mm = 0.005\n").unwrap();
    refused(
        &[
            SAMPLE,
            "--controller",
            "tnc640",
            "--machine",
            profile.to_str().unwrap(),
        ],
        "beyond the machine profile range of ±0.005 mm",
    );
}

#[test]
fn extrapolation_on_request() {
    let (text, json) = convert(
        &root().join(SAMPLE),
        "tnc640",
        &[
            "--start",
            "-50",
            "--step",
            "50",
            "--count",
            "18",
            "--extrapolate",
            "hold",
        ],
        "X.COM",
    );
    assert!(text.contains("\r\n0    -50 "));
    let mean = values_um(&json, "mean");
    // Held ends: the value at −50 equals the value at 0 (zero, the reference is the first point −50).
    assert_eq!(mean[0], mean[1]);
    let (_, zero) = convert(
        &root().join(SAMPLE),
        "tnc640",
        &[
            "--start",
            "0",
            "--step",
            "50",
            "--count",
            "17",
            "--extrapolate",
            "zero",
        ],
        "X.COM",
    );
    assert_eq!(
        *values_um(&zero, "mean").last().unwrap(),
        0.0,
        "800 mm lies beyond the 750 mm measured"
    );
}

#[test]
fn existing_output_is_not_overwritten_without_force() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("X.COM");
    std::fs::write(&output, "keep me").unwrap();
    let args = |force: bool| {
        let mut a = vec![
            "convert",
            SAMPLE,
            "--controller",
            "tnc640",
            "-o",
            output.to_str().unwrap(),
            "--quiet",
        ];
        if force {
            a.push("--force");
        }
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let run = axcomp(args(false));
    assert_eq!(run.code, 2);
    assert!(
        run.stderr.contains("already exists; use --force"),
        "{}",
        run.stderr
    );
    assert_eq!(std::fs::read_to_string(&output).unwrap(), "keep me");
    assert_eq!(axcomp(args(true)).code, 0);
    assert!(
        std::fs::read_to_string(&output)
            .unwrap()
            .starts_with("BEGIN X.COM MM")
    );
}

#[test]
fn existing_table_formats_are_detected() {
    // Every golden file reads back through the format detection of --existing.
    let options = EmitOptions::for_axis(&MachineProfile::default(), "X", "").unwrap();
    for (file, controller) in [
        ("formats/itnc530/golden/b02x-mean.COM", Controller::Itnc530),
        ("formats/tnc640/golden/sample-mean.COM", Controller::Tnc640),
        (
            "formats/sinumerik840d/golden/sample-grid50-cec.MPF",
            Controller::Sinumerik840d,
        ),
        (
            "formats/linuxcnc/golden/sample-mean-type1.txt",
            Controller::LinuxCnc,
        ),
    ] {
        let text = std::fs::read_to_string(root().join(file)).unwrap();
        assert_eq!(
            emit::read_any(&text, &options, None).unwrap().0,
            controller,
            "{file}"
        );
    }
}
