//! Parity of the front ends: each step run through the CLI binary and
//! through the web app in process (`server::App`) gives the same answer, the
//! same refusal with the same words, or the same bytes, on a linear and on a
//! rotary axis; and the demo's next table is the one `convert --effects`
//! writes. The CLI is the reference: every expected value is its output on
//! the same files.

use std::path::Path;

use crate::http::{Form, Response};
use crate::server::{App, read};
use crate::util::{axcomp, root, without_time};

/// Runs the CLI in `dir` (so files are named by their base names, as the
/// app names uploads) and returns the run.
pub(crate) fn cli(dir: &Path, args: &[&str]) -> crate::util::Run {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_axcomp"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    crate::util::Run {
        code: output.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

/// The CLI's JSON on stdout; the run must succeed.
pub(crate) fn cli_json(dir: &Path, args: &[&str]) -> serde_json::Value {
    let run = cli(dir, args);
    assert_eq!(run.code, 0, "axcomp {args:?}: {}", run.stderr);
    serde_json::from_str(&run.stdout).unwrap_or_else(|e| panic!("{e}: {}", run.stdout))
}

/// The CLI's error message as the app gives it (without `axcomp: error: `).
fn cli_refusal(dir: &Path, args: &[&str]) -> String {
    let run = cli(dir, args);
    assert_eq!(run.code, 2, "axcomp {args:?} should refuse: {}", run.stdout);
    run.stderr
        .trim()
        .trim_start_matches("axcomp: error: ")
        .to_string()
}

fn ok(answer: &Response, what: &str) {
    assert_eq!(answer.status, 200, "{what}: {}", answer.text());
}

/// The files of `dir` named `names`, as a form's `field` each.
pub(crate) fn form_of(dir: &Path, fields: &[(&str, &str)]) -> Form {
    fields.iter().fold(Form::new(), |form, (field, name)| {
        form.file(field, name, &read(&dir.join(name)))
    })
}

/// A rotary C axis (fixtures/rotary/c.csv, 0…360°): `evaluate` is the same
/// JSON in both (keys in ″ and °), and the table of each controller the
/// same bytes and the same `convert --json`.
#[test]
fn a_rotary_axis_is_evaluated_and_converted_alike() {
    let app = App::new();
    let dir = root().join("fixtures/rotary");
    let answer = app.post("/api/evaluate", form_of(&dir, &[("file", "c.csv")]), &[]);
    ok(&answer, "evaluate");
    let json = answer.json();
    let expected = cli_json(&dir, &["evaluate", "c.csv", "--json"]);
    assert_eq!(json["evaluation"], expected);
    assert!(expected["figures_arcsec"].is_object(), "{expected:#}");
    let work = tempfile::tempdir().unwrap();
    std::fs::copy(dir.join("c.csv"), work.path().join("c.csv")).unwrap();
    for (controller, name) in [
        ("tnc640", "C.COM"),
        ("linuxcnc", "c.comp"),
        ("sinumerik840d", "C.MPF"),
    ] {
        let form = || form_of(work.path(), &[("file", "c.csv")]).text("controller", controller);
        let table = app.post("/api/table", form(), &[]);
        ok(&table, controller);
        let convert = app.post("/api/convert", form(), &[]);
        ok(&convert, controller);
        let expected = cli_json(
            work.path(),
            &[
                "convert",
                "c.csv",
                "--controller",
                controller,
                "-o",
                name,
                "--json",
            ],
        );
        assert_eq!(convert.json()["convert"], expected, "{controller}");
        assert_eq!(table.body, read(&work.path().join(name)), "{controller}");
        assert!(table.body.len() > 50, "{controller}");
    }
}

/// A rotary re-test (a second-order term the first test did not have, as
/// tests/it/rotary.rs plants it) is diagnosed by both: the web app gives
/// `diagnose --json`'s object (it refused the re-test before), no effects
/// file (the CLI refuses `--write-effects` on a rotary axis) and the next
/// table `convert AFTER --existing TABLE` writes without one.
#[test]
fn a_rotary_retest_is_diagnosed_alike() {
    let app = App::new();
    let work = tempfile::tempdir().unwrap();
    let (before, table, after) =
        crate::retest_case::rotary_retest_files(work.path(), (2, 3.0, 0.3), 21);
    let name = |p: &Path| p.file_name().unwrap().to_str().unwrap().to_string();
    let (before, table, after) = (name(&before), name(&table), name(&after));
    let form = || {
        form_of(
            work.path(),
            &[("file", &before), ("after", &after), ("table", &table)],
        )
        .text("controller", "linuxcnc")
    };
    let answer = app.post("/api/retest", form(), &[]);
    ok(&answer, "retest");
    let json = answer.json();
    let expected = cli_json(
        work.path(),
        &[
            "diagnose", "--after", &after, "--before", &before, "--table", &table, "--json",
        ],
    );
    assert_eq!(json["diagnosis"], expected);
    // What the re-test holds (rotary.rs: the planted order), so neither side is empty.
    assert_eq!(expected["axis_kind"], "rotary");
    assert_eq!(expected["effects"][0]["params"]["per_revolution"], 2);
    assert!(json["effects_toml"].is_null(), "{}", json["effects_toml"]);
    let refused = cli_refusal(
        work.path(),
        &[
            "diagnose",
            "--after",
            &after,
            "--before",
            &before,
            "--write-effects",
            "E.toml",
        ],
    );
    assert!(refused.contains("is a rotary axis"), "{refused}");
    std::fs::create_dir(work.path().join("next")).unwrap();
    let run = cli(
        work.path(),
        &[
            "convert",
            &after,
            "--existing",
            &table,
            "--controller",
            "linuxcnc",
            "-o",
            "next/c.comp",
        ],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    let next = read(&work.path().join("next/c.comp"));
    assert_eq!(
        json["next"]["text"],
        String::from_utf8(next.clone()).unwrap()
    );
    let download = app.post("/api/table", form(), &[]);
    ok(&download, "next table");
    assert_eq!(download.body, next);
}

/// What the report refuses for a rotary axis, both refuse with the same
/// words: a table's predicted re-test, the diagnosis, another standard,
/// the ISO 14253-1 rule, a profile's limits (the web app checked only the
/// limits before). Without them the page is the same.
#[test]
fn the_report_of_a_rotary_axis_refuses_alike() {
    let app = App::new();
    let work = tempfile::tempdir().unwrap();
    let (before, table, after) =
        crate::retest_case::rotary_retest_files(work.path(), (2, 3.0, 0.3), 22);
    let name = |p: &Path| p.file_name().unwrap().to_str().unwrap().to_string();
    let (before, table, after) = (name(&before), name(&table), name(&after));
    std::fs::write(work.path().join("p.toml"), "[acceptance.axes.C]\nE = 5\n").unwrap();
    let cases: [(&[&str], Form, &str); 5] = [
        (
            &["--table", &table],
            form_of(work.path(), &[("file", &before), ("table", &table)]),
            "the predicted re-test of a table (--table)",
        ),
        (
            &["--after", &after, "--diagnose"],
            form_of(work.path(), &[("file", &before), ("after", &after)]).text("diagnose", "on"),
            "the diagnosis (--diagnose)",
        ),
        (
            &["--standard", "vdi3441"],
            form_of(work.path(), &[("file", &before)]).text("standard", "vdi3441"),
            "ISO 230-2 only so far (--standard)",
        ),
        (
            &["--decision", "iso14253-1"],
            form_of(work.path(), &[("file", &before)]).text("decision", "iso14253-1"),
            "the measurement uncertainty (--equipment, --decision)",
        ),
        (
            &["--machine", "p.toml"],
            form_of(work.path(), &[("file", &before), ("machine", "p.toml")]),
            "acceptance limits",
        ),
    ];
    for (flags, form, said) in cases {
        let mut args = vec!["report", &before, "-o", "r.html"];
        args.extend_from_slice(flags);
        let expected = cli_refusal(work.path(), &args);
        assert!(expected.contains(said), "{flags:?}: {expected}");
        assert!(
            expected.starts_with("axis C is a rotary axis: "),
            "{expected}"
        );
        let answer = app.post("/api/report", form, &[]);
        assert_eq!(answer.status, 400, "{flags:?}: {}", answer.text());
        assert_eq!(answer.json()["error"], expected.as_str(), "{flags:?}");
    }
    let run = cli(
        work.path(),
        &["report", &before, "--after", &after, "-o", "r.html"],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    let answer = app.post(
        "/api/report",
        form_of(work.path(), &[("file", &before), ("after", &after)]),
        &[],
    );
    ok(&answer, "report");
    let page = std::fs::read_to_string(work.path().join("r.html")).unwrap();
    assert_eq!(without_time(&answer.text()), without_time(&page));
    assert!(
        page.contains("Mean deviation around the circle"),
        "a rotary report draws its polar plot"
    );
}

/// The note a diagnosis gives a periodic error found at the profile's lead.
pub(crate) const LEAD_NOTE: &str = "the screw lead the machine profile gives (15 mm)";

/// Into `dir`: a first test, its TNC 640 table `X.COM` and a re-test with a
/// planted 15 mm lead error (`diagnose_periodic`'s seed 3), and seed 001's
/// VC1810 profile `vc1810.toml`, whose lead is 15 mm on every axis (Tab. 7).
pub(crate) fn screw_lead_retest(dir: &Path) {
    let case = crate::diagnose_periodic::case(15.0, 3, true);
    let truth = dir.join("truth.toml");
    std::fs::write(&truth, &case.truth).unwrap();
    crate::util::synth_loop_files(dir, &truth, Some("3"));
    let profile = root().join("fixtures/machines/vc1810.toml");
    std::fs::copy(profile, dir.join("vc1810.toml")).unwrap();
}

/// `diagnose --json` of [`screw_lead_retest`] with the profile, and its
/// periodic effect, which must be found at the lead with [`LEAD_NOTE`].
pub(crate) fn diagnose_with_the_lead(dir: &Path) -> serde_json::Value {
    let diagnosis = cli_json(
        dir,
        &[
            "diagnose",
            "--after",
            "after.rtl",
            "--before",
            "before.rtl",
            "--table",
            "X.COM",
            "--machine",
            "vc1810.toml",
            "--json",
        ],
    );
    let periodic = diagnosis["effects"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["kind"] == "periodic")
        .unwrap_or_else(|| panic!("{diagnosis:#}"));
    assert_eq!(periodic["params"]["period_mm"], 15.0);
    assert!(periodic["warnings"].to_string().contains(LEAD_NOTE));
    diagnosis
}

/// One re-test, one diagnosis: `diagnose --machine`, `report --diagnose
/// --machine` and the web app's report with the profile all search the
/// profile's screw lead first and find the planted 15 mm lead error there.
/// The report passed no known periods before, and found the error off the
/// lead, without the note.
#[test]
fn a_retest_gets_one_diagnosis_with_the_profiles_screw_lead() {
    let app = App::new();
    let work = tempfile::tempdir().unwrap();
    screw_lead_retest(work.path());
    diagnose_with_the_lead(work.path());
    let run = cli(
        work.path(),
        &[
            "report",
            "before.rtl",
            "--after",
            "after.rtl",
            "--table",
            "X.COM",
            "--diagnose",
            "--machine",
            "vc1810.toml",
            "-o",
            "r.html",
        ],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    let page = std::fs::read_to_string(work.path().join("r.html")).unwrap();
    assert!(
        page.contains(LEAD_NOTE),
        "report --diagnose --machine: no screw lead"
    );
    let answer = app.post(
        "/api/report",
        form_of(
            work.path(),
            &[
                ("file", "before.rtl"),
                ("after", "after.rtl"),
                ("table", "X.COM"),
                ("machine", "vc1810.toml"),
            ],
        )
        .text("diagnose", "on"),
        &[],
    );
    ok(&answer, "report");
    assert_eq!(without_time(&answer.text()), without_time(&page));
}

/// The demo's next table is byte for byte what `convert after.rtl
/// --existing X.COM --effects effects.toml --controller tnc640` writes from
/// the demo's own files (the demo forced a bidirectional table before), and
/// what the web app's re-test downloads from them.
#[test]
fn the_demos_next_table_is_what_convert_with_the_effects_writes() {
    let app = App::new();
    let work = tempfile::tempdir().unwrap();
    let out = work.path().join("demo");
    let run = axcomp(["demo", "--out", out.to_str().unwrap(), "--quiet"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    std::fs::create_dir(out.join("next")).unwrap();
    let run = cli(
        &out,
        &[
            "convert",
            "after.rtl",
            "--existing",
            "tables/tnc640/X.COM",
            "--effects",
            "effects.toml",
            "--controller",
            "tnc640",
            "-o",
            "next/X.COM",
        ],
    );
    assert_eq!(run.code, 0, "{}", run.stderr);
    let convert = read(&out.join("next/X.COM"));
    let demo = read(&out.join("tables/next/X.COM"));
    assert_eq!(
        String::from_utf8_lossy(&demo),
        String::from_utf8_lossy(&convert)
    );
    let download = app.post(
        "/api/table",
        Form::new()
            .file("file", "before.rtl", &read(&out.join("before.rtl")))
            .file("after", "after.rtl", &read(&out.join("after.rtl")))
            .file("table", "X.COM", &read(&out.join("tables/tnc640/X.COM")))
            .text("controller", "tnc640"),
        &[],
    );
    ok(&download, "next table");
    assert_eq!(download.body, demo);
}
