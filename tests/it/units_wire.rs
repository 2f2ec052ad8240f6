//! The published `evaluate --json` keys, byte for byte, for linear and rotary
//! axes: the unit of each value is in its key (`targets_mm`/`targets_deg`,
//! `mean_up_um`/`mean_up_arcsec`/`mean_up_urad`, `worst_target_deg`,
//! `offset_arcsec`, `length_deg`, `figures_urad`, …), a promise to scripts.
//! The golden files were written by the binary before positions and
//! deviations carried their unit in their type, so they show that the typed
//! wire structs write exactly what the run-time renaming wrote. (The plain
//! ISO 230-2 reports of `fixtures/rotary/c.csv` and `fixtures/sample-x.rtl`
//! are in `rotary.rs` and `cli.rs`.)

use crate::util::{assert_golden, axcomp, test_data};

/// `evaluate` with `args`, its output compared with `golden/units/<name>`.
fn assert_evaluate_golden(name: &str, args: &[&str]) {
    let run = axcomp(std::iter::once("evaluate").chain(args.iter().copied()));
    assert_eq!(run.code, 0, "{name}: {}", run.stderr);
    assert_golden(&run.stdout, &test_data(&format!("golden/units/{name}")));
}

#[test]
fn rotary_json_in_microradians_keeps_its_keys() {
    assert_evaluate_golden(
        "rotary-c-urad.json",
        &["--json", "--angle-unit", "urad", "fixtures/rotary/c.csv"],
    );
}

#[test]
fn rotary_json_of_another_standard_keeps_its_keys() {
    assert_evaluate_golden(
        "rotary-c-vdi3441.json",
        &["--json", "--standard", "vdi3441", "fixtures/rotary/c.csv"],
    );
}

/// A rotary test with an outlier run (the fixture with 25″ added to run 1↓
/// at 90°): `worst_target_deg` and `offset_arcsec` (`offset_urad`).
#[test]
fn rotary_outliers_keep_their_keys() {
    let file = "tests/data/rotary/c-outlier-run.csv";
    assert_evaluate_golden("rotary-outlier-run.json", &["--json", file]);
    assert_evaluate_golden(
        "rotary-outlier-run-urad.json",
        &["--json", "--angle-unit", "urad", file],
    );
    assert_evaluate_golden("rotary-outlier-run.txt", &[file]);
    assert_evaluate_golden(
        "rotary-outlier-run-urad.txt",
        &["--angle-unit", "urad", file],
    );
}

#[test]
fn rotary_ecmc_json_keeps_its_keys() {
    assert_evaluate_golden(
        "rotary-ecmc-deg.json",
        &["--json", "tests/data/rotary/ecmc-deg.dat"],
    );
}

#[test]
fn linear_json_keeps_its_keys() {
    assert_evaluate_golden(
        "linear-sample-x-vdi3441.json",
        &["--json", "--standard", "vdi3441", "fixtures/sample-x.rtl"],
    );
    assert_evaluate_golden(
        "linear-sample-x-limits.json",
        &[
            "--json",
            "--limit",
            "A=12",
            "--limit",
            "B=3",
            "--limit",
            "E_up=8",
            "fixtures/sample-x.rtl",
        ],
    );
    assert_evaluate_golden(
        "linear-demo-before.json",
        &["--json", "fixtures/demo/before.rtl"],
    );
}

/// A real ecmc test (ESS, `../shared/data`) with a suspected outlier run:
/// `worst_target_mm` and `offset_um`.
#[test]
fn linear_outliers_keep_their_keys() {
    let file = "../shared/data/ecmc/ecmc_target_muts_logger/b02__z__report_z.md_ISO230.dat";
    assert_evaluate_golden("linear-ecmc-outlier-run.json", &["--json", file]);
    assert_evaluate_golden("linear-ecmc-outlier-run.txt", &[file]);
}

/// `convert` to a file in a temporary folder with `args`, its output (the
/// folder written as `OUT`) compared with `golden/units/<name>`.
fn assert_convert_golden(name: &str, args: &[&str]) {
    let directory = tempfile::tempdir().unwrap();
    let out = directory.path().join("out.tab");
    let out = out.to_str().unwrap();
    let run = axcomp(["convert", "--force", "-o", out].iter().chain(args));
    assert_eq!(run.code, 0, "{name}: {}", run.stderr);
    let folder = directory.path().to_str().unwrap();
    assert_golden(
        &run.stdout.replace(folder, "OUT"),
        &test_data(&format!("golden/units/{name}")),
    );
}

/// `convert --json` of a rotary axis: `positions_deg`, `start_deg`,
/// `step_deg`, `reference_deg`, `values_arcsec`, `suggested_backlash_arcsec`.
#[test]
fn rotary_convert_json_keeps_its_keys() {
    let file = "fixtures/rotary/c.csv";
    assert_convert_golden(
        "convert-rotary-tnc640.json",
        &["--json", "--controller", "tnc640", file],
    );
    assert_convert_golden(
        "convert-rotary-tnc640.txt",
        &["--controller", "tnc640", file],
    );
    let bidirectional = ["--controller", "linuxcnc", "--mode", "bidirectional", file];
    assert_convert_golden(
        "convert-rotary-bidirectional-linuxcnc.json",
        &[&["--json"][..], &bidirectional].concat(),
    );
    assert_convert_golden("convert-rotary-bidirectional-linuxcnc.txt", &bidirectional);
    assert_convert_golden(
        "convert-rotary-inch-machine.json",
        &[
            "--json",
            "--controller",
            "linuxcnc",
            "--machine",
            "fixtures/machines/gantry-inch.toml",
            file,
        ],
    );
}

/// `convert --json` of a linear axis: `positions_mm`, …, `values_um`.
#[test]
fn linear_convert_json_keeps_its_keys() {
    let file = "fixtures/sample-x.rtl";
    assert_convert_golden(
        "convert-linear-tnc640.json",
        &["--json", "--controller", "tnc640", file],
    );
    assert_convert_golden(
        "convert-linear-tnc640.txt",
        &["--controller", "tnc640", file],
    );
    assert_convert_golden(
        "convert-linear-bidirectional-sinumerik840d.json",
        &[
            "--json",
            "--controller",
            "sinumerik840d",
            "--mode",
            "bidirectional",
            "--step",
            "50",
            file,
        ],
    );
    let inch = [
        "--controller",
        "linuxcnc",
        "--machine",
        "fixtures/machines/gantry-inch.toml",
        "--axis",
        "X",
        file,
    ];
    assert_convert_golden(
        "convert-linear-inch-machine.json",
        &[&["--json"][..], &inch].concat(),
    );
    assert_convert_golden("convert-linear-inch-machine.txt", &inch);
}

/// k_c is a stiffness (N/µm): servo-sim's terminal names it so, as its JSON
/// key `stiffness_n_per_um` does.
#[test]
fn servo_sim_names_the_stiffness_a_stiffness() {
    let run = axcomp([
        "servo-sim",
        "--axis",
        "mcfv5050-x",
        "--friction",
        "classic",
        "--test",
        "iso230-2",
        "--targets",
        "3",
        "--last-mm",
        "20",
        "--runs",
        "2",
        "--dwell-s",
        "0.3",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stdout.contains("\nStiffness    100 N/µm\n"),
        "{}",
        run.stdout
    );
    assert!(!run.stdout.contains("Compliance"), "{}", run.stdout);
}
