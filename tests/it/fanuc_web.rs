//! The web app's Fanuc options, in process (`server::App`): the mode
//! `bidirectional`, the parameter backup (`fanuc_parameters`, as
//! `--fanuc-parameters`) and the file at a finer magnification
//! (`fanuc_rescaled`, as `--fanuc-rescaled`) give the CLI's files byte for
//! byte, on the real backup of one machine (`../shared/data/fanuc/`). The
//! CLI is the reference: every expected file is its output on the same files.

use std::path::Path;

use crate::fanuc::{data, synthetic_x, update_x};
use crate::fanuc_modes::bidirectional_backup;
use crate::http::{Form, Response};
use crate::server::{App, cli_in, read};

fn ok(answer: &Response, what: &str) {
    assert_eq!(answer.status, 200, "{what}: {}", answer.text());
}

/// The update of X as the page sends it: the test after the real pitch
/// file was active (`file`), that file (`table`), the backup
/// (`fanuc_parameters`), Fanuc, axis X, and `settings`.
fn update_form(after: &str, backup: &str, settings: &[(&str, &str)]) -> Form {
    let form = Form::new()
        .file("file", "after.rtl", &read(Path::new(after)))
        .file("table", "PITCH.TXT", &read(Path::new(&data("PITCH.TXT"))))
        .file("fanuc_parameters", "CNC-PARA.TXT", &read(Path::new(backup)))
        .text("controller", "fanuc")
        .text("axis", "X");
    settings
        .iter()
        .fold(form, |form, (name, value)| form.text(name, value))
}

#[test]
fn bidirectional_on_the_web_is_the_clis_file() {
    let app = App::new();
    // Without a backup: axcomp's numbering, the ↓ table after the ↑ one.
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    synthetic_x(dir);
    cli_in(
        dir,
        &[
            "convert",
            "x.rtl",
            "--controller",
            "fanuc",
            "--mode",
            "bidirectional",
            "-o",
            "PITCH.TXT",
        ],
    );
    let expected = read(&dir.join("PITCH.TXT"));
    let form = Form::new()
        .file("file", "x.rtl", &read(&dir.join("x.rtl")))
        .text("controller", "fanuc")
        .text("mode", "bidirectional");
    let answer = app.post("/api/table", form, &[]);
    ok(&answer, "bidirectional without a backup");
    assert_eq!(answer.body, expected);
    assert!(answer.text().contains("N10026Q0P"), "{}", answer.text());
    // With the backup whose X has 3605#0 = 1 (3626 = 50), updating the
    // real pitch file that was active during the test.
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let backup = bidirectional_backup(dir);
    let new = dir.join("NEW.TXT").display().to_string();
    let (after, _) = update_x(
        dir,
        &backup,
        "31",
        &["--mode", "bidirectional", "-o", &new, "-q"],
    );
    let form = update_form(&after, &backup, &[("mode", "bidirectional")]);
    let answer = app.post("/api/table", form, &[]);
    ok(&answer, "bidirectional with the backup");
    assert_eq!(answer.body, read(Path::new(&new)));
}

#[test]
fn the_rescaled_file_on_the_web_is_the_clis() {
    let app = App::new();
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let [new, fine] = ["NEW.TXT", "FINE.TXT"].map(|n| dir.join(n).display().to_string());
    let (after, run) = update_x(
        dir,
        &data("CNC-PARA.TXT"),
        "30",
        &["--fanuc-rescaled", &fine, "-o", &new, "--json", "-q"],
    );
    // The CLI says the parameter change on stderr beside --json.
    let instruction = run
        .stderr
        .lines()
        .find_map(|line| line.strip_prefix(&format!("{fine}: ")))
        .unwrap_or_else(|| panic!("{}", run.stderr))
        .to_string();
    let form = update_form(&after, &data("CNC-PARA.TXT"), &[("fanuc_rescaled", "1")]);
    let answer = app.post("/api/convert", form, &[]);
    ok(&answer, "convert with fanuc_rescaled");
    let json = answer.json();
    let rescaled = &json["fanuc_rescaled"];
    assert_eq!(
        rescaled["text"].as_str().unwrap().as_bytes(),
        read(Path::new(&fine))
    );
    assert_eq!(rescaled["instruction"].as_str().unwrap(), instruction);
    // X's 3623 = 10 → 1 (0.1 µm units): the name says the new 3623.
    assert_eq!(rescaled["magnification"], 1);
    assert_eq!(rescaled["file_name"], "PITCH-3623-1.TXT");
    assert!(
        instruction.contains("set 3623 of axis X to 1"),
        "{instruction}"
    );
    assert_eq!(
        json["text"].as_str().unwrap().as_bytes(),
        read(Path::new(&new))
    );
    // The page shows `notes` (not `effects`): the unknown bit of 3605 among them.
    let notes = json["convert"]["notes"].to_string();
    assert!(notes.contains("3605 of axis X is 00000010"), "{notes}");
    // Without the option the answer has none; for another controller it is
    // refused with the CLI's words.
    let form = update_form(&after, &data("CNC-PARA.TXT"), &[]);
    let json = app.post("/api/convert", form, &[]).json();
    assert!(json["fanuc_rescaled"].is_null(), "{json:#}");
    let form = Form::new()
        .file("file", "after.rtl", &read(Path::new(&after)))
        .text("controller", "tnc640")
        .text("axis", "X")
        .text("fanuc_rescaled", "1");
    let answer = app.post("/api/convert", form, &[]);
    assert_eq!(answer.status, 400, "{}", answer.text());
    assert!(
        answer
            .text()
            .contains("--fanuc-rescaled is for --controller fanuc"),
        "{}",
        answer.text()
    );
}
