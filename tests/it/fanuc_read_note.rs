//! The unknown bit of 3605 said wherever the machine's pitch file is
//! computed with, not only where a file is written: `predict --table`,
//! `diagnose --table`, `report --table` and the web app's re-test and
//! report, on the real backup of one machine (`../shared/data/fanuc/`,
//! SOURCES.md). The backup's line 1411 is `N03605Q1A1P00000010A2…`: X's
//! value `00000010` (bit 1 set, bit 0 not) starts at column 12, after the
//! 11 characters `N03605Q1A1P`. With X's 3605 cleared to `00000000` nothing
//! is said.

use std::path::Path;

use crate::fanuc::{
    cleared_3605_backup, data, machine_of_the_backup, ok, tests_with_the_pitch_file, update_x,
};
use crate::http::Form;
use crate::server::{App, read};

/// What the notes say of a table read: the backup's value and position,
/// the bit, what axcomp assumed and what to check.
fn assert_said(text: &str, backup_name: &str) {
    for part in [
        "Fanuc: 3605 of axis X is 00000010 in the parameter backup (",
        &format!("{backup_name}:1411:12): bit #1 set besides #0"),
        "read the data as 3620–3627 alone describe them (the compensation at each point, linear between the points)",
        "check 3605#1 in the control's parameter manual before relying on what is computed with this table",
    ] {
        assert!(text.contains(part), "{part:?} missing from: {text}");
    }
}

#[test]
fn predict_diagnose_and_report_say_the_unknown_bit() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let (before, after) = tests_with_the_pitch_file(dir);
    let machine = machine_of_the_backup(dir);
    let cleared_dir = tempfile::tempdir().unwrap();
    let cleared = cleared_3605_backup(cleared_dir.path());
    let pitch = data("PITCH.TXT");
    let table = format!("X={pitch}");
    for (backup, said) in [(data("CNC-PARA.TXT"), true), (cleared, false)] {
        // predict: among the JSON's notes (with the other doubts of the table).
        let run = ok(&[
            "predict",
            "--measured",
            &format!("X={before}"),
            "--table",
            &table,
            "--fanuc-parameters",
            &backup,
            "--machine",
            &machine,
            "--json",
        ]);
        let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
        let notes = json["notes"].to_string();
        // diagnose: with the table's doubts, on stderr.
        let diagnose = ok(&[
            "diagnose",
            "--after",
            &after,
            "--before",
            &before,
            "--table",
            &pitch,
            "--fanuc-parameters",
            &backup,
        ]);
        // report: with the test's warnings, on stderr and in the page.
        let page = dir.join(if said { "said.html" } else { "cleared.html" });
        let report = ok(&[
            "report",
            &before,
            "--table",
            &pitch,
            "--fanuc-parameters",
            &backup,
            "-o",
            &page.display().to_string(),
        ]);
        let html = std::fs::read_to_string(&page).unwrap();
        if said {
            assert_said(&notes, "HM100TS__CNC-PARA.TXT");
            assert_said(&diagnose.stderr, "HM100TS__CNC-PARA.TXT");
            assert_said(&report.stderr, "HM100TS__CNC-PARA.TXT");
            assert!(
                html.contains("check 3605#1 in the control&#x27;s parameter manual")
                    || html.contains("check 3605#1 in the control's parameter manual"),
                "the report's page does not say it"
            );
        } else {
            for text in [&notes, &diagnose.stderr, &report.stderr, &html] {
                assert!(!text.contains("3605"), "{text}");
            }
        }
    }
}

/// `convert --existing` says it once, for the file it writes (its notes),
/// not again for the pitch file it reads (its warnings).
#[test]
fn convert_says_the_unknown_bit_once() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("NEW.TXT").display().to_string();
    let (_, run) = update_x(
        directory.path(),
        &data("CNC-PARA.TXT"),
        "30",
        &["-o", &output, "--json"],
    );
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(
        json["notes"].to_string().matches("3605 of axis X").count(),
        1
    );
    assert!(!json["warnings"].to_string().contains("3605"), "{json:#}");
    assert_eq!(
        run.stderr.matches("3605 of axis X").count(),
        0,
        "{}",
        run.stderr
    );
}

/// The web app's re-test and report read the table as `diagnose --table`
/// and `report --table` do: the same sentence among the re-test's
/// warnings and in the report, the backup named as uploaded.
#[test]
fn the_web_retest_and_report_say_the_unknown_bit() {
    let directory = tempfile::tempdir().unwrap();
    let (before, after) = tests_with_the_pitch_file(directory.path());
    let app = App::new();
    let first_test_and_table = || {
        Form::new()
            .file("file", "before.rtl", &read(Path::new(&before)))
            .file("table", "PITCH.TXT", &read(Path::new(&data("PITCH.TXT"))))
            .file(
                "fanuc_parameters",
                "CNC-PARA.TXT",
                &read(Path::new(&data("CNC-PARA.TXT"))),
            )
    };
    let report = app.post("/api/report", first_test_and_table(), &[]);
    assert_eq!(report.status, 200, "{}", report.text());
    assert!(
        report
            .text()
            .contains("CNC-PARA.TXT:1411:12): bit #1 set besides #0"),
        "the web report does not say it"
    );
    let form = first_test_and_table()
        .file("after", "after.rtl", &read(Path::new(&after)))
        .text("controller", "fanuc")
        .text("axis", "X");
    let answer = app.post("/api/retest", form, &[]);
    assert_eq!(answer.status, 200, "{}", answer.text());
    let warnings = answer.json()["warnings"].to_string();
    assert_said(&warnings, "CNC-PARA.TXT");
}
