//! The web app's page in a real headless browser, driven over WebDriver
//! (chromedriver): upload, change the controller, download, see an error,
//! with a screenshot of each step.

use std::path::PathBuf;

use crate::browser::WebDriver;
use crate::pixels::{Pixels, artefacts};
use crate::retest_case::rotary_retest_files;
use crate::server::{Server, cli_in, read, sample};
use crate::util::{root, shared_data};

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

/// The page of `server` in a new browser, once its script is ready.
fn open_page(server: &Server) -> WebDriver {
    let browser = WebDriver::start((1200, 1400));
    browser.goto(&server.url());
    browser.wait_for(
        "return document.body.dataset.ready === 'yes'",
        "the page to load",
    );
    browser
}

/// The engineer's steps in a real browser: open the page, pick the sample,
/// change the controller, download the table (equal to the CLI's), then
/// pick a malformed file and read the error.
#[test]
fn the_page_works_in_a_real_browser() {
    let server = Server::start();
    let browser = open_page(&server);
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

/// Step 2 with the table that was active during the test, in a real
/// browser: the test of X measured with the real Fanuc pitch file active,
/// the machine's parameter backup and that pitch file picked in step 2; the
/// preview is the whole pitch file updated (B's points 301 … 312 still in
/// it) and the download is byte for byte `convert --existing`'s.
#[test]
fn step_two_updates_the_table_that_was_active() {
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    let pitch = shared_data("fanuc/HM100TS__PITCH.TXT");
    let backup = shared_data("fanuc/HM100TS__CNC-PARA.TXT");
    for (from, name) in [(&pitch, "PITCH-OLD.TXT"), (&backup, "CNC-PARA.TXT")] {
        std::fs::copy(from, dir.join(name)).unwrap();
    }
    let truth = root().join("tests/data/fanuc/x-truth.toml");
    let truth = truth.display().to_string();
    cli_in(
        dir,
        &[
            "synth",
            "--truth",
            &truth,
            "-o",
            "x.rtl",
            "--table",
            "PITCH-OLD.TXT",
            "--fanuc-parameters",
            "CNC-PARA.TXT",
            "--o2",
            "after.rtl",
        ],
    );
    std::fs::create_dir(dir.join("cli")).unwrap();
    cli_in(
        dir,
        &[
            "convert",
            "x.rtl",
            "--controller",
            "fanuc",
            "--existing",
            "PITCH-OLD.TXT",
            "--fanuc-parameters",
            "CNC-PARA.TXT",
            "-o",
            "cli/PITCH.TXT",
            "-q",
        ],
    );
    let expected = read(&dir.join("cli/PITCH.TXT"));

    let server = Server::start();
    let browser = open_page(&server);
    browser.send_keys(
        &browser.find("#file"),
        &dir.join("x.rtl").display().to_string(),
    );
    browser.wait_for(
        "return document.body.dataset.evaluated === 'x.rtl' && document.body.dataset.busy === '0'",
        "the test's figures",
    );
    browser.click(&browser.find("#controller option[value='fanuc']"));
    let path = |name: &str| dir.join(name).display().to_string();
    browser.send_keys(&browser.find("#fanuc_parameters"), &path("CNC-PARA.TXT"));
    browser.send_keys(&browser.find("#existing"), &path("PITCH-OLD.TXT"));
    browser.wait_for(
        "return document.body.dataset.converted === 'fanuc:PITCH.TXT' && document.body.dataset.busy === '0' \
         && document.getElementById('preview').textContent.includes('N10312Q0P')",
        "the updated pitch file",
    );
    browser.execute("document.getElementById('step-table').scrollIntoView(); return true");
    check_screenshot(&browser, "5-fanuc-update", 0.03, false);
    browser.click(&browser.find("#download"));
    assert!(
        browser.downloaded("PITCH.TXT") == expected,
        "the page's PITCH.TXT differs from convert --existing's"
    );
}

/// A rotary axis on the page is said as the commands say it: the table's
/// step and zero in degrees, an outlier run's worst target in degrees, the
/// re-test's residual in ″ (the page used to print them as mm and µm, or
/// stop at the re-test).
#[test]
fn a_rotary_axis_is_said_in_degrees_and_arcseconds() {
    let work = tempfile::tempdir().unwrap();
    let (before, table, after) = rotary_retest_files(work.path(), (2, 3.0, 0.3), 23);
    let server = Server::start();
    let browser = open_page(&server);
    browser.send_keys(&browser.find("#file"), &before.display().to_string());
    browser.wait_for(
        "return document.body.dataset.converted === 'tnc640:C.COM' && document.body.dataset.busy === '0'",
        "the rotary test's table",
    );
    let summary = browser.execute("return document.getElementById('table-summary').innerText");
    assert_eq!(
        summary.as_str().unwrap(),
        "C.COM: 25 points, mean, step 15°, zero at 0.000°, file in deg"
    );

    browser.send_keys(&browser.find("#after"), &after.display().to_string());
    browser.send_keys(&browser.find("#table"), &table.display().to_string());
    browser.wait_for(
        "return !document.getElementById('retest-result').hidden && document.body.dataset.busy === '0'",
        "the rotary re-test's diagnosis",
    );
    let residual = browser.execute("return document.getElementById('residual').innerText");
    let residual = residual.as_str().unwrap();
    assert!(
        residual.starts_with("Residual rms ")
            && residual.contains("″ → ")
            && !residual.contains("µm"),
        "{residual}"
    );

    let outlier_run = root().join("tests/data/rotary/c-outlier-run.csv");
    browser.execute("document.getElementById('file').value = ''; return true");
    browser.send_keys(&browser.find("#file"), &outlier_run.display().to_string());
    browser.wait_for(
        "return document.body.dataset.evaluated === 'c-outlier-run.csv' && document.body.dataset.busy === '0'",
        "the outlier run's test",
    );
    let outliers = browser.execute("return document.getElementById('outliers').innerText");
    assert!(
        outliers
            .as_str()
            .unwrap()
            .contains("run 1 down: score 66.12, worst at 90°"),
        "{outliers}"
    );
}
