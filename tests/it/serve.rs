//! `axcomp serve`, the local web app: its API answers with what the CLI
//! prints and writes (the same JSON, the same bytes), refuses what it must
//! (other origins, other host names, oversized uploads, bad files with the
//! CLI's `file:line:col` message). The page in a real headless browser is
//! the `system` target's (tests/system/web_page.rs).
//!
//! Every test calls the app in process (`server::App`, tower's `oneshot` on
//! the router), so they run in parallel; one starts `axcomp serve` itself
//! and talks to it over its socket.

use std::process::Command;

use crate::http::{Form, Response, request};
use crate::server::{App, Server, cli_in, read, sample};
use crate::util::{root, without_time};

/// `axcomp serve --port 0` binds a free port, says where, and answers there
/// over a real socket: the page, and the API with the port in `Host`.
#[test]
fn the_server_starts_and_answers_on_its_port() {
    let server = Server::start();
    assert_eq!(server.url(), format!("http://{}/", server.host));
    let page = request(&server.host, "GET", "/", &[], Vec::new());
    assert_eq!(page.status, 200);
    assert!(page.text().contains("<script src=\"/app.js\""));
    let options = request(&server.host, "GET", "/api/options", &[], Vec::new());
    assert_eq!(options.status, 200, "{}", options.text());
    assert!(options.json()["controllers"].to_string().contains("tnc640"));
}

#[test]
fn evaluate_answers_with_the_json_evaluate_prints() {
    let server = App::new();
    let answer = server.post(
        "/api/evaluate",
        Form::new().file("file", "sample-x.rtl", &read(&sample())),
        &[],
    );
    assert_eq!(answer.status, 200, "{}", answer.text());
    let json = answer.json();
    let cli: serde_json::Value = serde_json::from_slice(&cli_in(
        &root().join("fixtures"),
        &["evaluate", "--json", "sample-x.rtl"],
    ))
    .unwrap();
    assert_eq!(json["evaluation"], cli);
    // The README's figures of the sample, so neither side can be empty.
    assert_eq!(
        format!(
            "{:.2}",
            json["evaluation"]["figures_um"]["A"].as_f64().unwrap()
        ),
        "13.19"
    );
    let svg = json["deviation_svg"].as_str().unwrap();
    assert!(
        svg.starts_with("<svg") || svg.starts_with("<?xml"),
        "{}",
        &svg[..80]
    );
}

/// The downloaded table is byte for byte what `convert -o NAME` writes,
/// under the controller's usual name, for every controller.
#[test]
fn the_table_download_is_what_convert_writes() {
    let server = App::new();
    let work = tempfile::tempdir().unwrap();
    let expected_names = [
        ("itnc530", "X.COM"),
        ("tnc640", "X.COM"),
        ("sinumerik840d", "X.MPF"),
        ("linuxcnc", "x.comp"),
        ("fagor8055", "ALX"),
        ("fagor8065", "X.mp"),
        ("fanuc", "PITCH.TXT"),
    ];
    for (controller, name) in expected_names {
        // The iTNC 530 takes neither a bidirectional table nor a datum
        // other than the first point, Fanuc no bidirectional table: the
        // defaults there.
        let others = !matches!(controller, "itnc530" | "fanuc");
        let mut form = Form::new()
            .file("file", "sample-x.rtl", &read(&sample()))
            .text("controller", controller)
            .text("step", "50");
        if others {
            form = form
                .text("reference", "100")
                .text("mode", "bidirectional")
                .text("extrapolate", "hold");
        }
        let answer = server.post("/api/table", form, &[]);
        // A Fagor 8065 table goes into the control's own .mp export (--existing):
        // no file without one, and the advice, as convert says it.
        if controller == "fagor8065" {
            assert_eq!(answer.status, 400, "{controller}: {}", answer.text());
            assert!(
                answer.text().contains("export the axis' .mp"),
                "{}",
                answer.text()
            );
            continue;
        }
        assert_eq!(answer.status, 200, "{controller}: {}", answer.text());
        let disposition = answer.header("content-disposition").unwrap();
        assert!(
            disposition.contains(&format!("filename=\"{name}\"")),
            "{controller}: {disposition}"
        );
        let output = work.path().join(controller).join(name);
        std::fs::create_dir_all(output.parent().unwrap()).unwrap();
        let (sample, output_arg) = (sample().display().to_string(), output.display().to_string());
        let mut args = vec!["convert", &sample, "--controller", controller];
        args.extend(["--step", "50", "-o", &output_arg]);
        if others {
            args.extend(["--reference", "100", "--mode", "bidirectional"]);
            args.extend(["--extrapolate", "hold"]);
        }
        cli_in(&root(), &args);
        assert_eq!(answer.body, read(&output), "{controller}: {name} differs");
        assert!(
            answer.body.len() > 100,
            "{controller}: {} bytes",
            answer.body.len()
        );
    }
}

#[test]
fn the_preview_is_the_json_convert_prints_and_the_file_text() {
    let server = App::new();
    let answer = server.post(
        "/api/convert",
        Form::new()
            .file("file", "sample-x.rtl", &read(&sample()))
            .text("controller", "linuxcnc")
            .text("step", "50"),
        &[],
    );
    assert_eq!(answer.status, 200, "{}", answer.text());
    let json = answer.json();
    let work = tempfile::tempdir().unwrap();
    std::fs::copy(sample(), work.path().join("sample-x.rtl")).unwrap();
    let cli: serde_json::Value = serde_json::from_slice(&cli_in(
        work.path(),
        &[
            "convert",
            "sample-x.rtl",
            "--controller",
            "linuxcnc",
            "--step",
            "50",
            "-o",
            "x.comp",
            "--json",
        ],
    ))
    .unwrap();
    assert_eq!(json["convert"], cli);
    assert_eq!(json["file_name"], "x.comp");
    let written = std::fs::read_to_string(work.path().join("x.comp")).unwrap();
    assert_eq!(json["text"], written.as_str());
    assert!(json["table_svg"].as_str().unwrap().contains("<svg"));
}

/// The re-test of the demo: `diagnose --json` and the next table of
/// `convert AFTER --existing TABLE --effects E.toml`, byte for byte.
#[test]
fn the_retest_answers_as_diagnose_and_convert_do() {
    let server = App::new();
    let demo = root().join("fixtures/demo");
    let form = || {
        Form::new()
            .file("file", "before.rtl", &read(&demo.join("before.rtl")))
            .file("after", "after.rtl", &read(&demo.join("after.rtl")))
            .file("table", "X.COM", &read(&demo.join("X.COM")))
            .text("controller", "tnc640")
    };
    let answer = server.post("/api/retest", form(), &[]);
    assert_eq!(answer.status, 200, "{}", answer.text());
    let json = answer.json();
    let work = tempfile::tempdir().unwrap();
    for name in ["before.rtl", "after.rtl", "X.COM"] {
        std::fs::copy(demo.join(name), work.path().join(name)).unwrap();
    }
    let diagnosis: serde_json::Value = serde_json::from_slice(&cli_in(
        work.path(),
        &[
            "diagnose",
            "--after",
            "after.rtl",
            "--before",
            "before.rtl",
            "--table",
            "X.COM",
            "--write-effects",
            "E.toml",
            "--json",
        ],
    ))
    .unwrap();
    assert_eq!(json["diagnosis"], diagnosis);
    // The demo's planted drift is found (README: rate 4.25 µm/h).
    assert_eq!(json["diagnosis"]["effects"][0]["kind"], "drift");
    let effects = std::fs::read_to_string(work.path().join("E.toml")).unwrap();
    assert_eq!(json["effects_toml"], effects.as_str());
    std::fs::create_dir(work.path().join("next")).unwrap();
    cli_in(
        work.path(),
        &[
            "convert",
            "after.rtl",
            "--existing",
            "X.COM",
            "--effects",
            "E.toml",
            "--controller",
            "tnc640",
            "-o",
            "next/X.COM",
        ],
    );
    let next = std::fs::read(work.path().join("next/X.COM")).unwrap();
    assert_eq!(
        json["next"]["text"],
        String::from_utf8(next.clone()).unwrap()
    );
    let download = server.post("/api/table", form(), &[]);
    assert_eq!(download.status, 200, "{}", download.text());
    assert_eq!(download.body, next);
}

#[test]
fn the_report_download_is_the_acceptance_report() {
    let server = App::new();
    let answer = server.post(
        "/api/report",
        Form::new().file("file", "sample-x.rtl", &read(&sample())),
        &[],
    );
    assert_eq!(answer.status, 200, "{}", answer.text());
    assert!(
        answer
            .header("content-disposition")
            .unwrap()
            .contains("report.html")
    );
    let page = answer.text();
    let dir = tempfile::tempdir().unwrap();
    let cli_page = dir.path().join("report.html");
    cli_in(
        &root().join("fixtures"),
        &[
            "report",
            "sample-x.rtl",
            "-o",
            &cli_page.display().to_string(),
        ],
    );
    let cli_page = std::fs::read_to_string(cli_page).unwrap();
    // The same page but for the minute it was made in.
    assert_eq!(without_time(&page), without_time(&cli_page));
    assert!(page.contains("Edlén"));
}

#[test]
fn bad_input_is_a_400_with_the_clis_position() {
    let server = App::new();
    let bad = root().join("tests/data/bad/junk-in-text.rtl");
    let answer = server.post(
        "/api/evaluate",
        Form::new().file("file", "junk-in-text.rtl", &read(&bad)),
        &[],
    );
    assert_eq!(answer.status, 400);
    let message = answer.json()["error"].as_str().unwrap().to_string();
    let cli = crate::util::axcomp(["evaluate", bad.to_str().unwrap()]);
    assert_eq!(cli.code, 2);
    // The CLI names the path it was given, the app the uploaded file's name.
    let cli_message = cli
        .stderr
        .trim()
        .trim_start_matches("axcomp: error: ")
        .replace(&bad.display().to_string(), "junk-in-text.rtl");
    assert_eq!(message, cli_message);
    assert!(message.starts_with("junk-in-text.rtl:23:10: "), "{message}");
    // A path the browser sends is reduced to its base name.
    let answer = server.post(
        "/api/evaluate",
        Form::new().file("file", "C:\\fakepath\\..\\junk-in-text.rtl", &read(&bad)),
        &[],
    );
    assert!(
        answer.json()["error"]
            .as_str()
            .unwrap()
            .starts_with("junk-in-text.rtl:23:10: ")
    );
    // Settings are checked too; nothing is missing silently.
    let answer = server.post(
        "/api/convert",
        Form::new()
            .file("file", "sample-x.rtl", &read(&sample()))
            .text("controller", "mazak"),
        &[],
    );
    assert_eq!(answer.status, 400);
    assert!(answer.text().contains("unknown controller"));
    let answer = server.post(
        "/api/evaluate",
        Form::new().text("path", "/etc/passwd"),
        &[],
    );
    assert_eq!(answer.status, 400);
    assert!(
        answer.text().contains("unknown form field"),
        "{}",
        answer.text()
    );
}

#[test]
fn other_origins_and_host_names_are_refused() {
    let server = App::new();
    let form = || Form::new().file("file", "sample-x.rtl", &read(&sample()));
    let own = server.url().trim_end_matches('/').to_string();
    assert_eq!(
        server
            .post("/api/evaluate", form(), &[("Origin", &own)])
            .status,
        200
    );
    let other = server.post("/api/evaluate", form(), &[("Origin", "http://example.com")]);
    assert_eq!(other.status, 403);
    assert!(other.text().contains("another origin"), "{}", other.text());
    // DNS rebinding: a foreign name that resolves to 127.0.0.1.
    let port = server.host.split(':').nth(1).unwrap();
    let rebound = format!("attacker.example:{port}");
    let answer = server.post("/api/evaluate", form(), &[("Host", &rebound)]);
    assert_eq!(answer.status, 403);
    let page = server.get("/", &[("Host", &rebound)]);
    assert_eq!(page.status, 403);
    let localhost = format!("localhost:{port}");
    let page = server.get("/", &[("Host", &localhost)]);
    assert_eq!(page.status, 200);
    assert!(page.text().contains("<script src=\"/app.js\""));
}

/// 50 MB is the limit: a little over it is refused with 413 and the server
/// goes on answering.
#[test]
fn uploads_over_the_limit_are_refused() {
    let server = App::new();
    let big = vec![b'0'; 50 * 1024 * 1024 + 1];
    let answer = server.post(
        "/api/evaluate",
        Form::new().file("file", "big.rtl", &big),
        &[],
    );
    assert_eq!(answer.status, 413, "{}", answer.text());
    let after = server.post(
        "/api/evaluate",
        Form::new().file("file", "sample-x.rtl", &read(&sample())),
        &[],
    );
    assert_eq!(after.status, 200);
}

/// Everything the page needs comes from the app itself: no CDN, no other host.
#[test]
fn the_page_loads_nothing_from_elsewhere() {
    let server = App::new();
    for path in ["/", "/app.js", "/app.css"] {
        let answer = server.get(path, &[]);
        assert_eq!(answer.status, 200, "{path}");
        let text = answer.text();
        for outside in ["https://", "http://", "//cdn", "@import"] {
            assert!(!text.contains(outside), "{path} has {outside}");
        }
    }
}

/// A machine profile with acceptance limits and a screw lead for X.
const PROFILE: &str = "[controller]\nunits = \"mm\"\n\n[controller.axes.X]\nscrew_lead_mm = 10\n\n\
[acceptance]\nA = { per_1000_mm_um = 10, min_um = 5 }\nR = 4\n";

/// Limits from the page and from the profile, under either decision rule:
/// the verdict is `evaluate --json --machine P --limit …`'s, key for key.
#[test]
fn the_verdict_is_what_evaluate_prints_with_the_same_limits() {
    let server = App::new();
    let work = tempfile::tempdir().unwrap();
    std::fs::copy(sample(), work.path().join("sample-x.rtl")).unwrap();
    std::fs::write(work.path().join("p.toml"), PROFILE).unwrap();
    let cases: [(&[&str], &str, &str, bool); 3] = [
        (
            &["--limit", "A=14", "--limit", "R=3"],
            "A=14, R=3",
            "simple",
            false,
        ),
        (
            &["--machine", "p.toml", "--limit", "E=8"],
            "E=8",
            "iso14253-1",
            true,
        ),
        (
            &["--limit", "A=20", "--limit", "B_mean=5"],
            "A=20;B_mean=5",
            "simple",
            false,
        ),
    ];
    let mut outcomes = Vec::new();
    for (flags, limits, decision, with_profile) in cases {
        let mut form = Form::new()
            .file("file", "sample-x.rtl", &read(&sample()))
            .text("limits", limits)
            .text("decision", decision);
        if with_profile {
            form = form.file("machine", "p.toml", PROFILE.as_bytes());
        }
        let answer = server.post("/api/evaluate", form, &[]);
        assert_eq!(answer.status, 200, "{limits}: {}", answer.text());
        let mut args = vec!["evaluate", "--json", "sample-x.rtl", "--decision", decision];
        args.extend_from_slice(flags);
        let cli: serde_json::Value = serde_json::from_slice(&cli_in(work.path(), &args)).unwrap();
        let verdict = &answer.json()["evaluation"]["verdict"];
        assert!(verdict.is_object(), "{limits}: no verdict");
        assert_eq!(*verdict, cli["verdict"], "{limits}");
        assert_eq!(answer.json()["evaluation"], cli, "{limits}");
        outcomes.push(verdict["pass"].as_bool().unwrap());
    }
    // The sample (README): A 13.19 µm passes 14 but R 6.26 µm fails 3; |B̄| 3.18 µm passes 5.
    assert!(!outcomes[0]);
    assert!(outcomes[2]);
    let checks = |answer: &Response| answer.json()["evaluation"]["verdict"]["checks"].clone();
    let answer = server.post(
        "/api/evaluate",
        Form::new()
            .file("file", "sample-x.rtl", &read(&sample()))
            .file("machine", "p.toml", PROFILE.as_bytes()),
        &[],
    );
    // The profile alone: its two limits, named by the file.
    let checks = checks(&answer);
    assert_eq!(checks.as_array().unwrap().len(), 2, "{checks}");
    assert_eq!(checks[0]["limit_source"], "p.toml [acceptance]");
    // A bad limit is refused with what is valid.
    let answer = server.post(
        "/api/evaluate",
        Form::new()
            .file("file", "sample-x.rtl", &read(&sample()))
            .text("limits", "Q=3"),
        &[],
    );
    assert_eq!(answer.status, 400);
    assert!(
        answer.text().contains("unknown figure"),
        "{}",
        answer.text()
    );
}

/// The table with a machine profile (inch, as `--machine`) is byte for
/// byte `convert --machine P.toml`'s.
#[test]
fn the_table_with_a_profile_is_what_convert_writes_with_it() {
    let server = App::new();
    let work = tempfile::tempdir().unwrap();
    let profile = root().join("fixtures/machines/gantry-inch.toml");
    for (controller, name) in [
        ("tnc640", "X.COM"),
        ("linuxcnc", "x.comp"),
        ("sinumerik840d", "X.MPF"),
    ] {
        let answer = server.post(
            "/api/table",
            Form::new()
                .file("file", "sample-x.rtl", &read(&sample()))
                .file("machine", "gantry-inch.toml", &read(&profile))
                .text("controller", controller)
                .text("step", "50"),
            &[],
        );
        assert_eq!(answer.status, 200, "{controller}: {}", answer.text());
        let output = work.path().join(controller).join(name);
        std::fs::create_dir_all(output.parent().unwrap()).unwrap();
        let (sample_arg, output_arg) =
            (sample().display().to_string(), output.display().to_string());
        let profile_arg = profile.display().to_string();
        cli_in(
            &root(),
            &[
                "convert",
                &sample_arg,
                "--controller",
                controller,
                "--step",
                "50",
                "--machine",
                &profile_arg,
                "-o",
                &output_arg,
            ],
        );
        assert_eq!(answer.body, read(&output), "{controller}: {name} differs");
        // Without the profile the file is another (mm, not inch): the profile was used.
        let plain = server.post(
            "/api/table",
            Form::new()
                .file("file", "sample-x.rtl", &read(&sample()))
                .text("controller", controller)
                .text("step", "50"),
            &[],
        );
        assert_ne!(
            plain.body, answer.body,
            "{controller}: the profile changed nothing"
        );
    }
    let convert = server.post(
        "/api/convert",
        Form::new()
            .file("file", "sample-x.rtl", &read(&sample()))
            .file("machine", "gantry-inch.toml", &read(&profile))
            .text("controller", "linuxcnc"),
        &[],
    );
    // A LinuxCNC file holds machine units (a TNC 640 file states MM whatever the profile).
    assert_eq!(convert.json()["convert"]["file_unit"], "inch");
}

/// A bad profile is a 400 naming the upload, line and column, as the CLI
/// says it; the Edlén check is in the evaluation, as `evaluate --json` has it.
#[test]
fn a_bad_profile_is_refused_with_its_position() {
    let server = App::new();
    let bad = "[controller]\nunits = \"mm\"\nfrobnicate = 3\n";
    let work = tempfile::tempdir().unwrap();
    std::fs::write(work.path().join("bad.toml"), bad).unwrap();
    std::fs::copy(sample(), work.path().join("sample-x.rtl")).unwrap();
    for path in ["/api/evaluate", "/api/convert", "/api/table"] {
        let answer = server.post(
            path,
            Form::new()
                .file("file", "sample-x.rtl", &read(&sample()))
                .file("machine", "bad.toml", bad.as_bytes()),
            &[],
        );
        assert_eq!(answer.status, 400, "{path}");
        let message = answer.json()["error"].as_str().unwrap().to_string();
        assert!(message.starts_with("bad.toml:3:1: "), "{path}: {message}");
        let cli = Command::new(env!("CARGO_BIN_EXE_axcomp"))
            .args([
                "convert",
                "sample-x.rtl",
                "--controller",
                "tnc640",
                "--machine",
                "bad.toml",
                "-o",
                "out.com",
            ])
            .current_dir(work.path())
            .output()
            .unwrap();
        assert_eq!(cli.status.code(), Some(2));
        let stderr = String::from_utf8_lossy(&cli.stderr);
        assert_eq!(
            message,
            stderr.trim().trim_start_matches("axcomp: error: "),
            "{path}"
        );
    }
    let answer = server.post(
        "/api/evaluate",
        Form::new().file("file", "sample-x.rtl", &read(&sample())),
        &[],
    );
    let check = &answer.json()["evaluation"]["refractive_index"];
    // The sample at the start: the factor implies an index 0.01 ppm below Edlén's, which the report prints as −0.01.
    assert_eq!(check["start"]["agrees"], true);
    let difference = check["start"]["difference_ppm"].as_f64().unwrap();
    assert!((difference + 0.00999).abs() < 1e-4, "{difference}");
}

/// The re-test's diagnosis with a machine profile searches its screw lead
/// first, as `diagnose --machine` does: the same JSON, the lead found at
/// exactly 15 mm (seed 001's VC1810, Tab. 7) in a re-test with a planted
/// 15 mm lead error (seed 3 of `diagnose_periodic`).
#[test]
fn the_retest_with_a_profile_is_what_diagnose_prints_with_it() {
    let server = App::new();
    let work = tempfile::tempdir().unwrap();
    crate::parity::screw_lead_retest(work.path());
    let answer = server.post(
        "/api/retest",
        crate::parity::form_of(
            work.path(),
            &[
                ("file", "before.rtl"),
                ("after", "after.rtl"),
                ("table", "X.COM"),
                ("machine", "vc1810.toml"),
            ],
        ),
        &[],
    );
    assert_eq!(answer.status, 200, "{}", answer.text());
    // The CLI's diagnosis finds the lead error at exactly 15 mm and says
    // it is the profile's lead (`parity::diagnose_with_the_lead`).
    let cli = crate::parity::diagnose_with_the_lead(work.path());
    let diagnosis = &answer.json()["diagnosis"];
    assert_eq!(*diagnosis, cli);
}

/// The page's re-test refuses what `diagnose` refuses (a re-test of another
/// stretch, tests against their recorded dates) and shows every warning of
/// the two tests: the doubts of the pair and each test's own, naming its file.
#[test]
fn the_retest_refuses_and_warns_as_diagnose_does() {
    let server = App::new();
    let demo = root().join("fixtures/demo");
    let muts = crate::util::shared_data("ecmc/ecmc_target_muts_logger");
    let b02 = read(&muts.join("b02__x__target_x.md_ISO230.dat"));
    let ild50 = read(&muts.join("muts__data__week42_22__xyz__target_x_report_ILD50.md_ISO230.dat"));
    let retest = |first: (&str, &[u8]), after: (&str, &[u8])| {
        server.post(
            "/api/retest",
            Form::new()
                .file("file", first.0, first.1)
                .file("after", after.0, after.1),
            &[],
        )
    };
    let (before, after) = (
        read(&demo.join("before.rtl")),
        read(&demo.join("after.rtl")),
    );
    let elsewhere = retest(("b02.dat", &b02), ("after.rtl", &after));
    assert_eq!(elsewhere.status, 400, "{}", elsewhere.text());
    assert!(
        elsewhere
            .text()
            .contains("only 3 % of the re-test lies where the first test measured"),
        "{}",
        elsewhere.text()
    );
    let swapped = retest(("after.rtl", &after), ("before.rtl", &before));
    assert_eq!(swapped.status, 400, "{}", swapped.text());
    assert!(
        swapped
            .text()
            .contains("after.rtl was measured on 2026-11-20 10:00:00"),
        "{}",
        swapped.text()
    );
    // −20 … 20 mm then −4 … 4 mm: a doubt, shown with each test's warnings.
    let doubtful = retest(("b02.dat", &b02), ("ild50.dat", &ild50));
    assert_eq!(doubtful.status, 200, "{}", doubtful.text());
    let warnings = doubtful.json()["warnings"].to_string();
    for expected in [
        "ild50.dat: b02.dat covers -20 … 20 mm, ild50.dat -4 … 4 mm: they overlap only in part",
        "b02.dat: targets evenly spaced",
        "ild50.dat: targets evenly spaced",
    ] {
        assert!(
            warnings.contains(expected),
            "{expected:?} not in {warnings}"
        );
    }
}
