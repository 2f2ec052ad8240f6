//! The thermal front ends say the same things the same way: the ISO 230-3
//! test type (`thermal evaluate --test`, `report --thermal-test`, the web
//! form's `test`: one set of names), and the web form's automatic
//! reference and forward validation, which fit the very model `thermal fit`
//! writes.

use crate::http::Form;
use crate::server::App;
use crate::util::{THERMAL_LOG as REAL, axcomp, fit_warm_up, root, shared_data, test_data};

/// The names of ISO 230-3 (2020) clause 5's tests, as the report shows them.
const TYPES: [(&str, &str); 3] = [
    ("etve", "environmental temperature variation error (ETVE)"),
    ("spindle", "thermal distortion caused by a rotating spindle"),
    (
        "linear-axis",
        "thermal distortion caused by moving linear axes",
    ),
];

/// `html` with its five escapes undone (the page's `<pre>`).
fn unescape(html: &str) -> String {
    html.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&amp;", "&")
}

/// The report's thermal section for the sample test with the real log, the
/// hand-written model run over it, and `flags`.
fn report_section(dir: &std::path::Path, flags: &[&str]) -> String {
    let out = dir.join("report.html");
    let sample = root().join("fixtures/sample-x.rtl");
    let mut args = vec![
        "report".to_string(),
        sample.display().to_string(),
        "--thermal".to_string(),
        shared_data(REAL).display().to_string(),
        "--thermal-sample-interval".to_string(),
        "60".to_string(),
        "--thermal-model".to_string(),
        test_data("thermal/two-terms.toml").display().to_string(),
        "--force".to_string(),
        "-o".to_string(),
        out.display().to_string(),
    ];
    args.extend(flags.iter().map(|f| f.to_string()));
    let run = axcomp(&args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&out).unwrap();
    let start = html
        .find("<section id=\"thermal\">")
        .expect("thermal section");
    let end = start + html[start..].find("</section>").unwrap();
    html[start..end].to_string()
}

#[test]
fn the_report_states_the_iso_230_3_test_type() {
    let dir = tempfile::tempdir().unwrap();
    let section = report_section(dir.path(), &[]);
    assert!(section.contains("<p>test type not stated;"), "{section}");
    for (name, title) in TYPES {
        let section = report_section(dir.path(), &["--thermal-test", name]);
        assert!(
            section.contains(&format!("<p>{title};")),
            "{name}: {section}"
        );
        // thermal evaluate names it the same.
        let run = axcomp([
            "thermal",
            "evaluate",
            shared_data(REAL).to_str().unwrap(),
            "--sample-interval",
            "60",
            "--test",
            name,
            "--json",
        ]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
        assert_eq!(json["test_type"], title);
    }
    // A name neither knows is refused by both with the same list.
    for flag in [["report", "--thermal-test"], ["thermal", "--test"]] {
        let mut args = vec![flag[0]];
        let real = shared_data(REAL);
        if flag[0] == "report" {
            args.extend(["fixtures/sample-x.rtl", "--thermal", real.to_str().unwrap()]);
        } else {
            args.extend(["evaluate", real.to_str().unwrap()]);
        }
        args.extend([flag[1], "warm-up"]);
        let run = axcomp(&args);
        assert_eq!(run.code, 2, "{}", run.stderr);
        assert!(
            run.stderr
                .contains("expected one of etve, spindle, linear-axis, found \"warm-up\""),
            "{}",
            run.stderr
        );
    }
}

#[test]
fn the_web_form_offers_what_the_cli_takes() {
    let app = App::new();
    let page = app.get("/thermal", &[]).text();
    for (name, title) in TYPES {
        assert!(
            page.contains(&format!("<option value=\"{name}\">{title}</option>")),
            "{name}"
        );
    }
    assert!(page.contains("<select name=\"test\"><option value=\"\">not stated</option>"));
    assert!(page.contains("<select name=\"validation\"><option value=\"blocked\">"));
    assert!(page.contains("<option value=\"forward\">"));
    assert!(page.contains("<option value=\"late\">"));
    assert!(page.contains("placeholder=\"T14 or auto\""));
}

/// The automatic reference and forward validation on the web page fit the
/// model `thermal fit` writes, byte for byte (the page shows the model
/// file), and the page states the test type; bad choices are a 400 that
/// says what was expected.
#[test]
fn the_web_fit_with_auto_reference_and_forward_validation_equals_the_cli_fit() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model.toml");
    let real = shared_data(REAL);
    fit_warm_up(
        &model,
        &[
            "--sensors",
            "T0,T1,T2,T3,T4,T14",
            "--reference",
            "auto",
            "--validation",
            "forward",
        ],
    );
    let cli = std::fs::read_to_string(&model).unwrap();
    assert!(cli.contains("validation = \"forward\""), "{cli}");
    let app = App::new();
    let log = std::fs::read(&real).unwrap();
    let form = |validation: &str, test: &str| {
        Form::new()
            .file("log", "spindle.csv", &log)
            .text("drift", "delta L")
            .text("sample_interval", "60")
            .text("rows", "1-1500")
            .text("sensors", "T0,T1,T2,T3,T4,T14")
            .text("reference", "auto")
            .text("validation", validation)
            .text("test", test)
    };
    let answer = app.post("/thermal", form("forward", "spindle"), &[]);
    assert_eq!(answer.status, 200, "{}", answer.text());
    let page = answer.text();
    let start = page
        .find("<pre id=\"model-toml\">")
        .expect("the model file")
        + 21;
    let end = start + page[start..].find("</pre>").unwrap();
    assert_eq!(unescape(&page[start..end]), cli);
    assert!(page.contains("<p>thermal distortion caused by a rotating spindle;"));
    // Blocked validation is another model: the choice reached the fit.
    let blocked = app.post("/thermal", form("blocked", ""), &[]).text();
    assert!(blocked.contains("<p>test type not stated;"));
    assert!(!blocked.contains(&page[start..end]));
    for (field, value, message) in [
        (
            "validation",
            "k-fold",
            "cross-validation: expected one of blocked, forward, late, found &quot;k-fold&quot;",
        ),
        (
            "test",
            "warm-up",
            "ISO 230-3 test: expected one of etve, spindle, linear-axis, found &quot;warm-up&quot;",
        ),
    ] {
        let (validation, test) = if field == "test" {
            ("forward", value)
        } else {
            (value, "")
        };
        let refused = app.post("/thermal", form(validation, test), &[]);
        assert_eq!(refused.status, 400);
        assert!(refused.text().contains(message), "{}", refused.text());
    }
}
