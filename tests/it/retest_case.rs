//! The re-test case of the report tests: a first test, a mean table written
//! for a TNC 640, and a re-test with the table applied, as files. Shared by
//! the report tests here and the browser tests (the `system` target).

use std::path::{Path, PathBuf};

use axcomp::compensate::{Extrapolate, GridSpec, TableMode, TableOptions, build_table};
use axcomp::cycle::CycleTiming;
use axcomp::diagnose::{DiagnoseInput, Diagnosis, diagnose};
use axcomp::emit::{self, Controller, EmitOptions, MachineProfile};
use axcomp::evaluate::{ISO_230_2, evaluate};
use axcomp::read::{read_path, rtl};
use axcomp::synth::{self, Truth};

use crate::util::axcomp;

/// A first test, a mean table written for a TNC 640, and a re-test with the
/// table applied, a reversal and a warm-up drift the model does not declare,
/// all written as files and read back as the report reads them.
pub(crate) struct RetestCase {
    pub(crate) directory: tempfile::TempDir,
    pub(crate) before: PathBuf,
    pub(crate) after: PathBuf,
    pub(crate) table: PathBuf,
}

const TRUTH: &str = r#"
[axis]
name = "X"
machine = "MCV 754 Quick <test & \"escape\">"

[cycle]
start_mm = 0.0
end_mm = 750.0
count = 16
jitter_mm = 9.0
runs = 5
start = "2026-11-20 09:14:00"

[error]
scale_um_per_m = 9.5
periodic = [{ period_mm = 200.0, amplitude_um = 1.8, phase_rad = 0.4 }]

[noise]
sigma_um = 0.35

[[effect]]
kind = "reversal"
B_um = -3.2

# The reversal grows by 1.5 µm after the first test: the change is what diagnose finds.
[[effect]]
kind = "reversal"
B_um = -1.5
tests = ["after"]

[[effect]]
kind = "drift"
rate_um_per_h = 4.0
tests = ["after"]
"#;

pub(crate) fn table_options() -> EmitOptions {
    EmitOptions::for_axis(&MachineProfile::default(), "X", "X.COM").unwrap()
}

impl RetestCase {
    pub(crate) fn new() -> RetestCase {
        let truth = Truth::from_toml_str(TRUTH).unwrap();
        let first = synth::before(&truth, 3).unwrap();
        let options = TableOptions {
            mode: TableMode::Mean,
            grid: GridSpec::Targets,
            reference: None,
            extrapolate: Extrapolate::Hold,
        };
        let table = build_table(&first, &evaluate(&first), &options).unwrap();
        let retest = synth::after(&truth, &table, 3).unwrap();
        let directory = tempfile::tempdir().unwrap();
        let case = RetestCase {
            before: directory.path().join("before.rtl"),
            after: directory.path().join("after.rtl"),
            table: directory.path().join("X.COM"),
            directory,
        };
        std::fs::write(&case.before, rtl::write(&first)).unwrap();
        std::fs::write(&case.after, rtl::write(&retest)).unwrap();
        let text = emit::write(Controller::Tnc640, &table, &table_options()).unwrap();
        std::fs::write(&case.table, text).unwrap();
        case
    }

    pub(crate) fn report(&self, extra: &[&str]) -> (PathBuf, crate::util::Run) {
        let output = self.directory.path().join("report.html");
        let mut args = vec![
            "report".to_string(),
            self.before.display().to_string(),
            "--after".into(),
            self.after.display().to_string(),
            "--table".into(),
            self.table.display().to_string(),
            "--diagnose".into(),
            "-o".into(),
            output.display().to_string(),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        (output, axcomp(args))
    }

    /// The diagnosis as the library gives it for the files as read back.
    pub(crate) fn diagnosis(&self) -> Diagnosis {
        let before = read_path(&self.before, None).unwrap().measurement;
        let after = read_path(&self.after, None).unwrap().measurement;
        let text = std::fs::read_to_string(&self.table).unwrap();
        let (_, table) = emit::read_any(&text, &table_options(), None).unwrap();
        diagnose(&DiagnoseInput {
            angle: Default::default(),
            after: &after,
            before: Some(&before),
            table: Some(&table),
            backlash_set: false,
            angular: None,
            known_periods: &[],
            timing: CycleTiming::ASSUMED,
            standard: &ISO_230_2,
        })
        .unwrap()
    }
}

/// A rotary truth over a full turn every 15°, 5 runs each way, with the
/// harmonics `(order, amplitude ″, phase rad)`.
fn rotary_truth(harmonics: &[(u32, f64, f64)]) -> axcomp::synth::RotaryTruth {
    let harmonics: Vec<String> = harmonics
        .iter()
        .map(|(order, amplitude, phase)| {
            format!("{{ per_revolution = {order}, amplitude_arcsec = {amplitude}, phase_rad = {phase} }}")
        })
        .collect();
    let text = format!(
        "[axis]\nname = \"C\"\n[rotary]\nstart_deg = 0.0\nend_deg = 360.0\ncount = 25\nruns = 5\n\
         reversal_arcsec = 2.4\nsigma_arcsec = 0.3\nharmonics = [{}]\n",
        harmonics.join(", ")
    );
    axcomp::synth::RotaryTruth::from_toml_str(&text).unwrap()
}

/// The first test of the fixture's truth (once per revolution 4″), a mean
/// LinuxCNC table from it written by `convert`, and the re-test with that
/// table of a truth with one more harmonic (`extra`: order, ″, phase), as
/// files in `directory`; returns (before, table, after).
pub(crate) fn rotary_retest_files(
    directory: &Path,
    extra: (u32, f64, f64),
    seed: u64,
) -> (PathBuf, PathBuf, PathBuf) {
    use axcomp::emit::{EmitOptions, MachineProfile, read_any};
    let first = (1, 4.0, 0.5);
    let before_truth = rotary_truth(&[first]);
    let after_truth = rotary_truth(&[first, extra]);
    let before = axcomp::synth::rotary_test(&before_truth, seed).unwrap();
    let before_path = directory.join(format!("before-{seed}.csv"));
    std::fs::write(&before_path, axcomp::read::csv::write(&before)).unwrap();
    let table_path = directory.join(format!("C-{seed}.comp"));
    let run = axcomp([
        "convert".as_ref(),
        before_path.as_os_str(),
        "--controller".as_ref(),
        "linuxcnc".as_ref(),
        "-o".as_ref(),
        table_path.as_os_str(),
        "--quiet".as_ref(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let mut options = EmitOptions::for_axis(&MachineProfile::default(), "C", "").unwrap();
    options.kind = axcomp::measurement::AxisKind::Rotary;
    let text = std::fs::read_to_string(&table_path).unwrap();
    let (_, table) = read_any(&text, &options, Some(0)).unwrap();
    let after = axcomp::synth::rotary_retest(&after_truth, &table, seed + 1000).unwrap();
    let after_path = directory.join(format!("after-{seed}.csv"));
    std::fs::write(&after_path, axcomp::read::csv::write(&after)).unwrap();
    (before_path, table_path, after_path)
}
