//! No silent default behind a number the engineer loads or signs: a file is
//! never both input and output, the uncertainty comes from a known
//! instrument, profiles are checked, users read references (the acceptance
//! tests of these rules, through the binary, on the real files where the
//! problems were found).

use std::path::{Path, PathBuf};

use crate::util::{axcomp, shared_data};

const SAMPLE: &str = "fixtures/sample-x.rtl";

/// A copy of `source` in a fresh folder, as the engineer's only copy.
fn only_copy(source: &Path, name: &str) -> (tempfile::TempDir, PathBuf) {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join(name);
    std::fs::copy(source, &path).unwrap();
    (directory, path)
}

fn strings(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Vec<std::ffi::OsString> {
    args.iter().map(|a| a.as_ref().to_os_string()).collect()
}

// --- a file is never both input and output ----------------------------------

#[test]
fn convert_and_report_never_replace_the_measurement_they_read() {
    let (directory, measurement) = only_copy(Path::new(SAMPLE), "X.rtl");
    let original = std::fs::read(&measurement).unwrap();
    // The same path, and the same file by another spelling.
    let other_spelling = directory.path().join(".").join("X.rtl");
    for output in [&measurement, &other_spelling] {
        for args in [
            strings(&[
                &"convert",
                &measurement,
                &"--controller",
                &"tnc640",
                &"-o",
                output,
                &"--force",
            ]),
            strings(&[&"report", &measurement, &"-o", output, &"--force"]),
        ] {
            let run = axcomp(&args);
            assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
            assert!(
                run.stderr.contains("is also an input of this command"),
                "{args:?}: {}",
                run.stderr
            );
            assert_eq!(std::fs::read(&measurement).unwrap(), original, "{args:?}");
        }
    }
    // A real ecmc test as `report --after` and as the output: refused too.
    let (directory, first) = only_copy(
        &shared_data(
            "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__target_x_report_ILD50.md_ISO230.dat",
        ),
        "first.dat",
    );
    let after = directory.path().join("after.dat");
    std::fs::copy(
        shared_data(
            "ecmc/ecmc_target_muts_logger/muts__data__week42_22__xyz__back__target_x_report_2.md_ISO230.dat",
        ),
        &after,
    )
    .unwrap();
    let kept = std::fs::read(&after).unwrap();
    let run = axcomp(strings(&[
        &"report", &first, &"--after", &after, &"-o", &after, &"--force",
    ]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("after.dat: is also an input"),
        "{}",
        run.stderr
    );
    assert_eq!(std::fs::read(&after).unwrap(), kept);
}

#[test]
fn report_png_into_a_missing_parent_folder_is_refused() {
    let directory = tempfile::tempdir().unwrap();
    let html = directory.path().join("report.html");
    let deep = directory.path().join("no").join("such").join("dir");
    let run = axcomp(strings(&[
        &"report", &SAMPLE, &"-o", &html, &"--png", &deep,
    ]));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(&format!(
            "the folder {} does not exist",
            directory.path().join("no").join("such").display()
        )),
        "{}",
        run.stderr
    );
    assert!(!directory.path().join("no").exists(), "no folder is made");
    assert!(!html.exists(), "nothing is written");
    // A missing last folder whose parent exists is still made.
    let plots = directory.path().join("plots");
    let run = axcomp(strings(&[
        &"report", &SAMPLE, &"-o", &html, &"--png", &plots,
    ]));
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(plots.join("deviation.png").exists());
}
