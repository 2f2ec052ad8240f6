//! `axcomp serve`, the local web app: its API answers with what the CLI
//! prints and writes (the same JSON, the same bytes), refuses what it must
//! (other origins, other host names, oversized uploads, bad files with the
//! CLI's `file:line:col` message), and the page works in a real headless
//! browser (upload, change the controller, download, see an error), with a
//! screenshot of each step.
//!
//! Every test starts its own server on a free port (`--port 0`), so they run
//! in parallel.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use crate::browser::{Pixels, WebDriver, artefacts};
use crate::http::{Form, Response, request};
use crate::util::{root, without_time};

/// A running `axcomp serve --port 0 --no-open`, stopped when dropped.
struct Server {
    child: Child,
    /// `127.0.0.1:PORT`.
    host: String,
}

impl Server {
    fn start() -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_axcomp"))
            .args(["serve", "--port", "0", "--no-open"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start axcomp serve");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        // "axcomp serve: http://127.0.0.1:PORT/ (Ctrl-C stops it)"
        let host = line
            .split("http://")
            .nth(1)
            .and_then(|rest| rest.split('/').next())
            .unwrap_or_else(|| panic!("no address in {line:?}"))
            .to_string();
        assert!(host.starts_with("127.0.0.1:"), "{line}");
        Server { child, host }
    }

    fn url(&self) -> String {
        format!("http://{}/", self.host)
    }

    /// A POST of `form` to `path` with extra `headers`.
    fn post(&self, path: &str, form: Form, headers: &[(&str, &str)]) -> Response {
        let (content_type, body) = form.finish();
        let mut all = vec![("Content-Type", content_type.as_str())];
        all.extend_from_slice(headers);
        request(&self.host, "POST", path, &all, body)
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn sample() -> PathBuf {
    root().join("fixtures/sample-x.rtl")
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Runs the CLI in `dir` (so that a file named by its base name is shown
/// as the app shows an upload) and returns its stdout.
fn cli_in(dir: &Path, args: &[&str]) -> Vec<u8> {
    let output = Command::new(env!("CARGO_BIN_EXE_axcomp"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "axcomp {args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output.stdout
}

#[test]
fn evaluate_answers_with_the_json_evaluate_prints() {
    let server = Server::start();
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
    let server = Server::start();
    let work = tempfile::tempdir().unwrap();
    let expected_names = [
        ("itnc530", "X.COM"),
        ("tnc640", "X.COM"),
        ("sinumerik840d", "X.MPF"),
        ("linuxcnc", "x.comp"),
        ("fagor8055", "ALX"),
        ("fagor8065", "X.mp"),
    ];
    for (controller, name) in expected_names {
        // The iTNC 530 takes neither a bidirectional table nor a datum
        // other than the first point: the defaults there.
        let others = controller != "itnc530";
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
    let server = Server::start();
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
    let server = Server::start();
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
    let server = Server::start();
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
    let server = Server::start();
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
            .text("controller", "fanuc"),
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
    let server = Server::start();
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
    let page = request(&server.host, "GET", "/", &[("Host", &rebound)], Vec::new());
    assert_eq!(page.status, 403);
    let localhost = format!("localhost:{port}");
    let page = request(
        &server.host,
        "GET",
        "/",
        &[("Host", &localhost)],
        Vec::new(),
    );
    assert_eq!(page.status, 200);
    assert!(page.text().contains("<script src=\"/app.js\""));
}

/// 50 MB is the limit: a little over it is refused with 413 and the server
/// goes on answering.
#[test]
fn uploads_over_the_limit_are_refused() {
    let server = Server::start();
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
    let server = Server::start();
    for path in ["/", "/app.js", "/app.css"] {
        let answer = request(&server.host, "GET", path, &[], Vec::new());
        assert_eq!(answer.status, 200, "{path}");
        let text = answer.text();
        for outside in ["https://", "http://", "//cdn", "@import"] {
            assert!(!text.contains(outside), "{path} has {outside}");
        }
    }
}

/// A screenshot of the page with something on it: at least `inked` of it
/// not white (the start page is about 0.015), and in `expect_blue` steps
/// the deviation plot's blue ↑ runs and bands (the start page's blue drop
/// zone alone is about 0.002).
fn check_screenshot(browser: &WebDriver, name: &str, inked: f64, expect_blue: bool) -> PathBuf {
    let path = artefacts().join(format!("serve-{name}.png"));
    browser.screenshot(&path);
    let pixels = Pixels::read(&path);
    // The window less the browser's own bars.
    assert!(
        pixels.size.0 == 1200 && pixels.size.1 > 1000,
        "{name}: {:?}",
        pixels.size
    );
    eprintln!(
        "{name}: {:.4} inked, {:.4} blue",
        pixels.inked(),
        pixels.blue()
    );
    assert!(
        pixels.inked() > inked,
        "{name}: {:.3} inked",
        pixels.inked()
    );
    if expect_blue {
        assert!(pixels.blue() > 0.004, "{name}: {:.4} blue", pixels.blue());
    }
    path
}

/// The engineer's steps in a real browser: open the page, pick the sample,
/// change the controller, download the table (equal to the CLI's), then
/// pick a malformed file and read the error.
#[test]
fn the_page_works_in_a_real_browser() {
    let server = Server::start();
    let browser = WebDriver::start((1200, 1400));
    browser.goto(&server.url());
    browser.wait_for(
        "return document.body.dataset.ready === 'yes'",
        "the page to load",
    );
    // The start page is mostly white: a heading, the drop zone, the settings.
    check_screenshot(&browser, "1-start", 0.01, false);

    let input = browser.find("#file");
    browser.send_keys(&input, &sample().display().to_string());
    browser.wait_for(
        "return document.body.dataset.converted === 'tnc640:X.COM' && document.body.dataset.busy === '0'",
        "the sample's figures and table",
    );
    let figures = browser.execute("return document.getElementById('figures').innerText");
    assert!(figures.as_str().unwrap().contains("13.19"), "{figures}");
    // The plot at the bottom of the window, the figures above it.
    browser.execute("document.getElementById('deviation').scrollIntoView(false); return true");
    check_screenshot(&browser, "2-evaluated", 0.05, true);
    // The Edlén check as evaluate --json has it: −0.01 ppm at the start.
    let edlen = browser.execute("return document.getElementById('edlen').innerText");
    assert!(edlen.as_str().unwrap().contains("-0.01 ✓"), "{edlen}");

    // A limit of 12 µm on A (the sample's A is 13.19 µm): FAIL, as
    // `evaluate --limit A=12` says.
    browser.click(&browser.find("#limit-A"));
    browser.send_keys(&browser.find("#limit-A"), "12\u{E007}");
    browser.wait_for(
        "return document.body.dataset.verdict === 'fail' && document.body.dataset.busy === '0'",
        "the verdict on A = 12 µm",
    );
    let verdict = browser.execute("return document.getElementById('verdict').innerText");
    assert_eq!(
        verdict.as_str().unwrap(),
        "FAIL (simple acceptance): A not within the limits"
    );
    let checks = browser.execute("return document.getElementById('checks').innerText");
    assert!(
        checks
            .as_str()
            .unwrap()
            .starts_with("A 13.19 µm against 12.00 µm"),
        "{checks}"
    );
    browser.execute("document.getElementById('figures').scrollIntoView(); return true");
    check_screenshot(&browser, "2b-verdict", 0.02, false);

    browser.click(&browser.find("#controller option[value='linuxcnc']"));
    browser.click(&browser.find("#step"));
    browser.send_keys(&browser.find("#step"), "50\u{E007}");
    browser.wait_for(
        "return document.body.dataset.converted === 'linuxcnc:x.comp' && document.body.dataset.busy === '0' \
         && /^50(\\.0+)? /m.test(document.getElementById('preview').textContent)",
        "the LinuxCNC table on a 50 mm step",
    );
    browser.execute("document.getElementById('step-table').scrollIntoView(); return true");
    // The table's plot is black and grey: ink, not blue.
    check_screenshot(&browser, "3-linuxcnc", 0.05, false);

    browser.click(&browser.find("#download"));
    let downloaded = browser.downloaded("x.comp");
    let work = tempfile::tempdir().unwrap();
    let cli_table = work.path().join("x.comp");
    cli_in(
        &root(),
        &[
            "convert",
            &sample().display().to_string(),
            "--controller",
            "linuxcnc",
            "--step",
            "50",
            "-o",
            &cli_table.display().to_string(),
        ],
    );
    assert_eq!(downloaded, read(&cli_table));

    let bad = root().join("tests/data/bad/junk-in-text.rtl");
    // A file input keeps what it was given: empty it, as a new pick does.
    browser
        .execute("document.getElementById('file').value = ''; window.scrollTo(0, 0); return true");
    browser.send_keys(&browser.find("#file"), &bad.display().to_string());
    browser.wait_for(
        "return !document.getElementById('error').hidden && document.body.dataset.busy === '0'",
        "the error of the malformed file",
    );
    let error = browser.execute("return document.getElementById('error').innerText");
    assert!(
        error
            .as_str()
            .unwrap()
            .starts_with("junk-in-text.rtl:23:10: expected text"),
        "{error}"
    );
    let shot = check_screenshot(&browser, "4-error", 0.01, false);
    // The error box's red is on the page.
    let red = Pixels::read(&shot).fraction(|r, g, b| r > 150 && g < 60 && b < 60);
    assert!(red > 0.0005, "{red:.4} red");
}

/// A machine profile with acceptance limits and a screw lead for X.
const PROFILE: &str = "[controller]\nunits = \"mm\"\n\n[controller.axes.X]\nscrew_lead_mm = 10\n\n\
[acceptance]\nA = { per_1000_mm_um = 10, min_um = 5 }\nR = 4\n";

/// Limits from the page and from the profile, under either decision rule:
/// the verdict is `evaluate --json --machine P --limit …`'s, key for key.
#[test]
fn the_verdict_is_what_evaluate_prints_with_the_same_limits() {
    let server = Server::start();
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
    let server = Server::start();
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
    let server = Server::start();
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
    let server = Server::start();
    let work = tempfile::tempdir().unwrap();
    let case = crate::diagnose_periodic::case(15.0, 3, true);
    let truth = work.path().join("truth.toml");
    std::fs::write(&truth, &case.truth).unwrap();
    crate::util::synth_loop_files(work.path(), &truth, Some("3"));
    let profile = root().join("fixtures/machines/vc1810.toml");
    std::fs::copy(&profile, work.path().join("vc1810.toml")).unwrap();
    let file = |name: &str| read(&work.path().join(name));
    let answer = server.post(
        "/api/retest",
        Form::new()
            .file("file", "before.rtl", &file("before.rtl"))
            .file("after", "after.rtl", &file("after.rtl"))
            .file("table", "X.COM", &file("X.COM"))
            .file("machine", "vc1810.toml", &read(&profile)),
        &[],
    );
    assert_eq!(answer.status, 200, "{}", answer.text());
    let cli: serde_json::Value = serde_json::from_slice(&cli_in(
        work.path(),
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
    ))
    .unwrap();
    let diagnosis = &answer.json()["diagnosis"];
    assert_eq!(*diagnosis, cli);
    let periodic = diagnosis["effects"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["kind"] == "periodic")
        .unwrap_or_else(|| panic!("{diagnosis:#}"));
    assert_eq!(periodic["params"]["period_mm"], 15.0);
    assert!(
        periodic["warnings"]
            .to_string()
            .contains("the screw lead the machine profile gives (15 mm)")
    );
}
