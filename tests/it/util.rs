//! Test harness: paths to shared data, running the binary, comparing text.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A file under `../shared/data` (the real third-party measurements).
pub fn shared_data(relative: &str) -> PathBuf {
    let path = root().join("../shared/data").join(relative);
    assert!(
        path.exists(),
        "shared test data missing: {}",
        path.display()
    );
    path
}

/// Every file in a `../shared/data` folder whose name ends with `suffix`.
pub fn shared_files(folder: &str, suffix: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(shared_data(folder))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.to_string_lossy().ends_with(suffix))
        .collect();
    files.sort();
    files
}

/// A file under `tests/data`.
pub fn test_data(relative: &str) -> PathBuf {
    root().join("tests/data").join(relative)
}

/// What the binary did.
pub struct Run {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `axcomp` with arguments, in the repository root.
pub fn axcomp<I, S>(args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let output = Command::new(env!("CARGO_BIN_EXE_axcomp"))
        .args(args)
        .output()
        .expect("run axcomp");
    Run {
        code: output.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

/// Runs `axcomp evaluate --json FILE…` and parses the object.
pub fn evaluate_json(files: &[&Path]) -> serde_json::Value {
    let mut args: Vec<&std::ffi::OsStr> = vec!["evaluate".as_ref(), "--json".as_ref()];
    args.extend(files.iter().map(|f| f.as_os_str()));
    let run = axcomp(args);
    assert_eq!(run.code, 0, "stderr: {}", run.stderr);
    serde_json::from_str(&run.stdout).expect("evaluate --json prints one JSON object")
}

/// `evaluate --json` with extra arguments (limits, a profile, a decision rule).
pub fn evaluate_json_with(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["evaluate", "--json"];
    all.extend_from_slice(args);
    let run = axcomp(all);
    assert_eq!(run.code, 0, "{}", run.stderr);
    serde_json::from_str(&run.stdout).unwrap()
}

/// Compares a text with a golden file; `AXCOMP_UPDATE_GOLDEN=1` rewrites it.
/// A missing golden file is a failure, not a silent pass.
pub fn assert_golden(actual: &str, golden: &Path) {
    if std::env::var_os("AXCOMP_UPDATE_GOLDEN").is_some() {
        std::fs::create_dir_all(golden.parent().unwrap()).unwrap();
        std::fs::write(golden, actual).unwrap();
        return;
    }
    let expected = std::fs::read_to_string(golden).unwrap_or_else(|_| {
        panic!(
            "golden file {} missing; run with AXCOMP_UPDATE_GOLDEN=1 and review it",
            golden.display()
        )
    });
    if expected != actual {
        panic!(
            "{} differs from the output.\n--- expected\n{expected}\n--- actual\n{actual}\n(rerun with AXCOMP_UPDATE_GOLDEN=1 to accept a deliberate change)",
            golden.display()
        );
    }
}

/// The loop's files from a truth through the binary, into `dir`: the first
/// test `before.rtl` (`synth`), its TNC 640 table `X.COM` (`convert`), and
/// the re-test `after.rtl` with the table applied (`synth --table`, which
/// writes the first test again as `before2.rtl`); `seed` as `synth --seed`.
pub fn synth_loop_files(dir: &Path, truth: &Path, seed: Option<&str>) {
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let truth = truth.to_str().unwrap();
    let ok = |args: Vec<&str>| {
        let run = axcomp(&args);
        assert_eq!(run.code, 0, "axcomp {}: {}", args.join(" "), run.stderr);
    };
    let seed: Vec<&str> = seed.map_or(Vec::new(), |s| vec!["--seed", s]);
    let before = path("before.rtl");
    ok([vec!["synth", "--truth", truth, "-o", &before], seed.clone()].concat());
    let table = path("X.COM");
    ok(vec![
        "convert",
        &before,
        "--controller",
        "tnc640",
        "-o",
        &table,
        "-q",
    ]);
    let (before2, after) = (path("before2.rtl"), path("after.rtl"));
    ok([
        vec!["synth", "--truth", truth, "-o", &before2],
        seed,
        vec!["--table", &table, "--o2", &after],
    ]
    .concat());
}

/// The first test of a truth, a mean table at its targets, and the re-test
/// with that table applied (the library's `synth`, as `synth_loop_files`).
pub fn synth_loop(
    truth: &axcomp::synth::Truth,
    seed: u64,
) -> (
    axcomp::measurement::Measurement,
    axcomp::compensate::CompensationTable,
    axcomp::measurement::Measurement,
) {
    use axcomp::compensate::{Extrapolate, GridSpec, TableMode, TableOptions, build_table};
    let before = axcomp::synth::before(truth, seed).unwrap();
    let options = TableOptions {
        mode: TableMode::Mean,
        grid: GridSpec::Targets,
        reference: None,
        extrapolate: Extrapolate::Hold,
    };
    let table = build_table(&before, &axcomp::evaluate::evaluate(&before), &options).unwrap();
    let after = axcomp::synth::after(truth, &table, seed).unwrap();
    (before, table, after)
}

/// A report page without the line that says when it was made (two runs
/// may straddle a minute).
pub fn without_time(page: &str) -> String {
    page.lines()
        .filter(|line| !line.contains(concat!("axcomp ", env!("CARGO_PKG_VERSION"), " on ")))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The real spindle log (`../shared/data/thermal/`, SOURCES.md).
pub const THERMAL_LOG: &str = "thermal/data__thermal expansion error original.csv";

/// `thermal fit` on the real spindle log's warm-up (rows 1–1500, one-minute
/// rows, drift "delta L") with `extra` flags, writing `model`; must succeed.
pub fn fit_warm_up(model: &Path, extra: &[&str]) {
    let log = shared_data(THERMAL_LOG);
    let mut args = vec!["thermal", "fit", log.to_str().unwrap()];
    args.extend(["--drift", "delta L", "--sample-interval", "60"]);
    args.extend(["--rows", "1-1500", "-o", model.to_str().unwrap()]);
    args.extend(extra);
    let fit = axcomp(&args);
    assert_eq!(fit.code, 0, "{}", fit.stderr);
}
