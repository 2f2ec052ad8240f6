//! Commands that write several files write all of them or none (issue 11):
//! an output that is refused (it exists without `--force`, it is named twice,
//! its folder is missing) must not leave the others behind, new or changed.

use std::path::Path;

use crate::util::axcomp;

const TRUTH: &str = "fixtures/demo/truth.toml";
const TABLE: &str = "fixtures/demo/X.COM";
const SAMPLE: &str = "fixtures/sample-x.rtl";

fn names_in(directory: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(directory)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn synth_with_an_existing_second_output_writes_neither() {
    let directory = tempfile::tempdir().unwrap();
    let before = directory.path().join("before.rtl");
    let after = directory.path().join("after.rtl");
    std::fs::write(&after, "an earlier re-test").unwrap();
    let args = |force: bool| {
        let mut args = vec![
            "synth".to_string(),
            "--truth".into(),
            TRUTH.into(),
            "-o".into(),
            before.display().to_string(),
            "--table".into(),
            TABLE.into(),
            "--o2".into(),
            after.display().to_string(),
        ];
        if force {
            args.push("--force".into());
        }
        args
    };
    let run = axcomp(args(false));
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr
            .contains(&format!("{}: already exists", after.display())),
        "{}",
        run.stderr
    );
    assert!(!before.exists(), "the first file was written anyway");
    assert_eq!(
        std::fs::read_to_string(&after).unwrap(),
        "an earlier re-test"
    );
    assert_eq!(names_in(directory.path()), ["after.rtl"]);

    // With --force both are written (and the re-test replaced).
    let run = axcomp(args(true));
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        std::fs::read_to_string(&before)
            .unwrap()
            .starts_with("HEADER::")
    );
    assert!(
        std::fs::read_to_string(&after)
            .unwrap()
            .starts_with("HEADER::")
    );
    assert_eq!(names_in(directory.path()), ["after.rtl", "before.rtl"]);
}

#[test]
fn synth_refuses_one_file_for_both_outputs() {
    let directory = tempfile::tempdir().unwrap();
    let both = directory.path().join("both.rtl");
    let run = axcomp([
        "synth",
        "--truth",
        TRUTH,
        "-o",
        both.to_str().unwrap(),
        "--table",
        TABLE,
        "--o2",
        both.to_str().unwrap(),
        "--force",
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("named for two outputs"),
        "{}",
        run.stderr
    );
    assert!(names_in(directory.path()).is_empty());
}

#[test]
fn report_with_an_existing_plot_writes_no_page() {
    let directory = tempfile::tempdir().unwrap();
    let page = directory.path().join("report.html");
    let plots = directory.path().join("plots");
    std::fs::create_dir(&plots).unwrap();
    std::fs::write(plots.join("deviation.png"), "an earlier plot").unwrap();
    let run = axcomp([
        "report",
        SAMPLE,
        "-o",
        page.to_str().unwrap(),
        "--png",
        plots.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("deviation.png: already exists"),
        "{}",
        run.stderr
    );
    assert!(!page.exists(), "the page was written anyway");
    assert_eq!(names_in(&plots), ["deviation.png"]);
    assert_eq!(
        std::fs::read_to_string(plots.join("deviation.png")).unwrap(),
        "an earlier plot"
    );
}

#[test]
fn report_into_a_missing_folder_leaves_no_plot_folder() {
    let directory = tempfile::tempdir().unwrap();
    let page = directory.path().join("no-such-folder").join("report.html");
    let plots = directory.path().join("plots");
    let run = axcomp([
        "report",
        SAMPLE,
        "-o",
        page.to_str().unwrap(),
        "--png",
        plots.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(run.stderr.contains("report.html"), "{}", run.stderr);
    assert!(
        !plots.exists(),
        "the plot folder this run made was left behind"
    );
    assert!(names_in(directory.path()).is_empty());
}
