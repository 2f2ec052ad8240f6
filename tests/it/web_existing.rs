//! Step 2 of the web page with the table that was active during the test:
//! the page offers it (`existing`) and sends it with the test as the API's
//! `table`, and the file the app then makes is byte for byte `convert FILE
//! --existing TABLE`'s, for the controllers whose update keeps the
//! control's own file (Fanuc's real pitch file with its parameter backup,
//! Fagor 8055 and 8065 tables of the API XD examples) and for a TNC 640
//! table. The CLI is the reference: every expected file is its output on
//! the same files, run where the files are named by their base names, as
//! the app names uploads. What the page's script does in a browser is the
//! `system` target's `web_page.rs`.

use std::path::Path;

use crate::fanuc::{data as fanuc_data, tests_with_the_pitch_file};
use crate::http::Form;
use crate::parity::cli;
use crate::server::{App, read, sample};
use crate::util::shared_data;

/// The page's step 2 `<section>` and the script, as the app serves them.
fn step_two_and_script(app: &App) -> (String, String) {
    let page = app.get("/", &[]).text();
    let start = page
        .find("<section id=\"step-table\"")
        .expect("step 2's section");
    let end = start + page[start..].find("</section>").unwrap();
    (page[start..end].to_string(), app.get("/app.js", &[]).text())
}

/// Step 2 has a file input for the table that was active during the test,
/// and its requests (the preview and the download) send it as `table`;
/// step 3's `table` input stays the re-test's.
#[test]
fn step_two_offers_and_sends_the_table_that_was_active() {
    let app = App::new();
    let (step_two, script) = step_two_and_script(&app);
    assert!(
        step_two.contains("<input type=\"file\" id=\"existing\">"),
        "{step_two}"
    );
    assert!(!step_two.contains("id=\"table\""), "{step_two}");
    // The form of step 2: the test's form with `existing` appended as `table`.
    let form_of_step_two = script
        .split("function convertForm() {")
        .nth(1)
        .and_then(|rest| rest.split("\n}\n").next())
        .expect("app.js has step 2's form");
    assert!(
        form_of_step_two.contains("tableForm([\"file\"])")
            && form_of_step_two.contains(
                "for (const file of files.existing) data.append(\"table\", file, file.name)"
            ),
        "{form_of_step_two}"
    );
    // The preview and the download send it; nothing else of step 2 builds its own form.
    assert!(
        script.contains("post(\"/api/convert\", request)"),
        "{script}"
    );
    assert!(
        script.contains("const request = convertForm();"),
        "{script}"
    );
    assert!(
        script.contains("download(\"/api/table\", convertForm(), \"table-error\")"),
        "{script}"
    );
    assert!(!script.contains("tableForm([\"file\"]), \"table-error\")"));
}

/// `file` (the test, base name `test`), `table` (`existing`) and the
/// extra files of `dir`, with `settings`, as step 2 sends them (the page
/// always sends `linuxcnc_type`).
fn step_two_form(dir: &Path, test: &str, existing: &str, files: &[(&str, &str)]) -> Form {
    let form = Form::new()
        .file("file", test, &read(&dir.join(test)))
        .file("table", existing, &read(&dir.join(existing)))
        .text("linuxcnc_type", "0");
    files.iter().fold(form, |form, (field, name)| {
        form.file(field, name, &read(&dir.join(name)))
    })
}

/// One update through the app (`/api/table` and `/api/convert`'s text)
/// against `convert TEST --existing EXISTING --controller C --axis A -o
/// NAME [flags]` in `dir`.
fn assert_update_alike(
    app: &App,
    dir: &Path,
    (test, existing, controller, axis, name): (&str, &str, &str, &str, &str),
    files: &[(&str, &str)],
    flags: &[&str],
) {
    // In a folder of its own: the file's name is the app's (a Heidenhain
    // table names itself after it).
    std::fs::create_dir_all(dir.join("cli")).unwrap();
    let output = format!("cli/{name}");
    let mut args = vec![
        "convert",
        test,
        "--existing",
        existing,
        "--controller",
        controller,
        "--axis",
        axis,
        "-o",
        &output,
        "-q",
    ];
    args.extend(flags);
    let run = cli(dir, &args);
    assert_eq!(run.code, 0, "axcomp {args:?}: {}", run.stderr);
    let expected = read(&dir.join(&output));
    let form = || {
        step_two_form(dir, test, existing, files)
            .text("controller", controller)
            .text("axis", axis)
    };
    let table = app.post("/api/table", form(), &[]);
    assert_eq!(table.status, 200, "{controller}: {}", table.text());
    assert!(
        table
            .header("content-disposition")
            .is_some_and(|d| d.contains(&format!("filename=\"{name}\""))),
        "{controller}"
    );
    assert!(
        table.body == expected,
        "{controller}: the download differs from the CLI's {name}"
    );
    let convert = app.post("/api/convert", form(), &[]);
    assert_eq!(convert.status, 200, "{controller}: {}", convert.text());
    let json = convert.json();
    // The preview is the file's text (the 8065's .mp is UTF-16 with a BOM).
    let (text, _) = axcomp::emit::decode_table(&expected).unwrap();
    assert_eq!(
        json["text"].as_str().unwrap(),
        text,
        "{controller}: the preview"
    );
}

#[test]
fn step_two_with_the_table_that_was_active_is_convert_existing() {
    let app = App::new();
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    // Fanuc: the test of X with the real pitch file active, its backup.
    tests_with_the_pitch_file(dir);
    for (name, copy) in [
        ("PITCH.TXT", "OLD-PITCH.TXT"),
        ("CNC-PARA.TXT", "CNC-PARA.TXT"),
    ] {
        std::fs::copy(fanuc_data(name), dir.join(copy)).unwrap();
    }
    assert_update_alike(
        &app,
        dir,
        ("before.rtl", "OLD-PITCH.TXT", "fanuc", "X", "PITCH.TXT"),
        &[("fanuc_parameters", "CNC-PARA.TXT")],
        &["--fanuc-parameters", "CNC-PARA.TXT"],
    );
    // Fagor 8055 and 8065: the API XD tests of X and the control's tables.
    for (folder, table, controller, name) in [
        ("8055", "ALX", "fagor8055", "ALX"),
        ("8065", "X.mp", "fagor8065", "X.mp"),
    ] {
        let test = format!("{folder}-X.pos");
        let old = format!("old-{table}");
        let from = |file: &str| shared_data(&format!("api-xd/example__{folder}__{file}"));
        std::fs::copy(from("X Axis Forward.pos"), dir.join(&test)).unwrap();
        std::fs::copy(from(table), dir.join(&old)).unwrap();
        assert_update_alike(&app, dir, (&test, &old, controller, "X", name), &[], &[]);
    }
    // TNC 640: a table of the sample made on a 50 mm step, then active.
    std::fs::copy(sample(), dir.join("sample-x.rtl")).unwrap();
    let run = cli(
        dir,
        &[
            "convert",
            "sample-x.rtl",
            "--controller",
            "tnc640",
            "--step",
            "50",
            "-o",
            "OLD.COM",
        ],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert_update_alike(
        &app,
        dir,
        ("sample-x.rtl", "OLD.COM", "tnc640", "X", "X.COM"),
        &[],
        &[],
    );
}
