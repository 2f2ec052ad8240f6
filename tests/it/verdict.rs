//! The acceptance verdict end to end (issue 11): `--limit` and a machine
//! profile's `[acceptance]` table give permissible values; `evaluate` prints
//! a PASS/FAIL line and `"verdict"` in its JSON, `report` a verdict box at the
//! top. A figure that is not evaluated fails; without limits there is no
//! verdict anywhere. Expected figures are the README's for the sample (A =
//! 13.19 µm, R = 6.26 µm) or computed by hand below.

use std::path::{Path, PathBuf};

use approx::{abs_diff_eq, assert_abs_diff_eq};
use serde_json::{Value, json};

use crate::report::{check_against_json, embedded_data};
use crate::util::{axcomp, evaluate_json_with};

const SAMPLE: &str = "fixtures/sample-x.rtl";

/// A first test over 0–200 mm, 2 runs each way (µm):
/// ↑ 0 4 8 / 2 6 10, ↓ 2 6 10 / 4 8 12. By hand: x̄↑ = 1, 5, 9; x̄↓ = 3, 7, 11;
/// s↑ = s↓ = √2; E = 11 − 1 = 10; A = (11 + 2√2) − (1 − 2√2) = 10 + 4√2 = 15.657.
const BEFORE: &str = "# axis: X\n# machine: Test mill\ntarget_mm,run,direction,deviation_um\n\
    0,1,up,0\n100,1,up,4\n200,1,up,8\n0,2,up,2\n100,2,up,6\n200,2,up,10\n\
    0,1,down,2\n100,1,down,6\n200,1,down,10\n0,2,down,4\n100,2,down,8\n200,2,down,12\n";

/// Its re-test: ↑ and ↓ both 0 1 2 / 1 2 3. By hand: x̄ = 0.5, 1.5, 2.5,
/// s = √0.5; E = 2; A = 2 + 4·√0.5 = 2 + 2√2 = 4.828.
const AFTER: &str = "# axis: X\n# machine: Test mill\ntarget_mm,run,direction,deviation_um\n\
    0,1,up,0\n100,1,up,1\n200,1,up,2\n0,2,up,1\n100,2,up,2\n200,2,up,3\n\
    0,1,down,0\n100,1,down,1\n200,1,down,2\n0,2,down,1\n100,2,down,2\n200,2,down,3\n";

/// One run each way: ↑ 0 4 8, ↓ 2 6 10. R is not evaluated; E = 10 − 0 = 10.
const ONE_RUN: &str = "# axis: X\ntarget_mm,run,direction,deviation_um\n\
    0,1,up,0\n100,1,up,4\n200,1,up,8\n0,1,down,2\n100,1,down,6\n200,1,down,10\n";

/// A over 200 mm: 10 µm per 1000 mm gives 2 µm, raised to the 5 µm minimum;
/// E: 60 µm per 1000 mm gives 12 µm.
const PROFILE: &str = "[controller]\nunits = \"mm\"\n\n[acceptance]\n\
    A = { per_1000_mm_um = 10, min_um = 5 }\nE = { per_1000_mm_um = 60 }\n\n\
    [acceptance.axes.Y]\nA = 100\n";

fn write(directory: &Path, name: &str, text: &str) -> PathBuf {
    let path = directory.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn close(value: &Value, expected: f64) -> bool {
    value
        .as_f64()
        .is_some_and(|v| abs_diff_eq!(v, expected, epsilon = 1e-9))
}

#[test]
fn a_limit_below_the_sample_fails_and_limits_above_pass() {
    // A = 13.19 µm > 12: FAIL, named; the exit status stays 0.
    let run = axcomp(["evaluate", SAMPLE, "--limit", "A=12", "-q"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stdout.ends_with("FAIL: A above the limit\n"),
        "{}",
        run.stdout
    );
    assert!(
        run.stdout.contains(" A      | 13.19 | 1.82 | 12.00 | FAIL"),
        "{}",
        run.stdout
    );
    let json = evaluate_json_with(&[SAMPLE, "--limit", "A=12"]);
    let verdict = &json["verdict"];
    assert_eq!(verdict["pass"], json!(false));
    assert_eq!(verdict["failed"], json!(["A"]));
    assert_eq!(verdict["decision"], json!("simple acceptance"));
    assert!(close(&verdict["travel_mm"], 750.0));
    let check = &verdict["checks"][0];
    assert_eq!(check["figure"], json!("A"));
    assert_eq!(check["value_um"], json["figures_um"]["A"]);
    assert!(close(&check["limit_um"], 12.0));
    assert_eq!(check["pass"], json!(false));
    assert_eq!(check["outcome"], json!("exceeds"));
    assert_eq!(check["reason"], json!("13.19 µm is above the limit 12 µm"));
    assert_eq!(check["limit_source"], json!("--limit"));
    assert_eq!(check["limit_derivation"], json!("12 µm"));

    // A = 13.19 ≤ 14 and R = 6.26 ≤ 7: PASS.
    let run = axcomp([
        "evaluate", SAMPLE, "--limit", "A=14", "--limit", "R=7", "-q",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stdout.ends_with("PASS: A, R within the limits\n"),
        "{}",
        run.stdout
    );
    let json = evaluate_json_with(&[SAMPLE, "--limit", "R=7", "--limit", "A=14"]);
    let verdict = &json["verdict"];
    assert_eq!(verdict["pass"], json!(true));
    assert_eq!(verdict["failed"], json!([]));
    let figures: Vec<&Value> = verdict["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| &c["figure"])
        .collect();
    assert_eq!(figures, [&json!("A"), &json!("R")], "in figures_um order");
    let keys: Vec<&String> = verdict["checks"][1].as_object().unwrap().keys().collect();
    for key in [
        "figure",
        "value_um",
        "limit_um",
        "pass",
        "reason",
        "limit_source",
    ] {
        assert!(keys.iter().any(|k| *k == key), "{key} in {keys:?}");
    }
    assert_eq!(verdict["checks"][1]["value_um"], json["figures_um"]["R"]);
    assert_eq!(verdict["checks"][1]["reason"], Value::Null);

    // B_mean compares |B̄| (B̄ = −3.18 µm): 3.18 > 3 fails.
    let json = evaluate_json_with(&[SAMPLE, "--limit", "B_mean=3"]);
    let b_mean = json["figures_um"]["B_mean"].as_f64().unwrap();
    assert!(b_mean < 0.0);
    assert_eq!(json["verdict"]["checks"][0]["value_um"], json!(-b_mean));
    assert_eq!(json["verdict"]["pass"], json!(false));

    // No limits: no verdict, in the JSON or on the terminal.
    let json = evaluate_json_with(&[SAMPLE]);
    assert!(json.get("verdict").is_none());
    let run = axcomp(["evaluate", SAMPLE, "-q"]);
    assert!(!run.stdout.contains("PASS") && !run.stdout.contains("FAIL"));
}

#[test]
fn a_figure_that_is_not_evaluated_fails() {
    let directory = tempfile::tempdir().unwrap();
    let file = write(directory.path(), "one-run.csv", ONE_RUN);
    let file = file.to_str().unwrap();
    let run = axcomp(["evaluate", file, "--limit", "R=4", "--limit", "E=12", "-q"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stdout
            .ends_with("FAIL: R not evaluated (cannot pass)\n"),
        "{}",
        run.stdout
    );
    let json = evaluate_json_with(&[file, "--limit", "R=4", "--limit", "E=12"]);
    let verdict = &json["verdict"];
    assert_eq!(verdict["pass"], json!(false));
    assert_eq!(verdict["failed"], json!(["R"]));
    // E = 10 by hand, within 12.
    assert!(close(&verdict["checks"][0]["value_um"], 10.0));
    assert_eq!(verdict["checks"][0]["pass"], json!(true));
    let r = &verdict["checks"][1];
    assert_eq!(r["figure"], json!("R"));
    assert_eq!(r["value_um"], Value::Null);
    assert_eq!(r["pass"], json!(false));
    assert_eq!(r["outcome"], json!("not evaluated"));
    assert!(r["reason"].as_str().unwrap().contains("cannot pass"));
}

#[test]
fn a_profile_gives_per_length_limits_and_the_command_line_overrides_them() {
    let directory = tempfile::tempdir().unwrap();
    let before = write(directory.path(), "before.csv", BEFORE);
    let profile = write(directory.path(), "machine.toml", PROFILE);
    let (before, profile) = (before.to_str().unwrap(), profile.to_str().unwrap());
    let json = evaluate_json_with(&[before, "--machine", profile]);
    assert!(close(&json["figures_um"]["A"], 10.0 + 4.0 * 2f64.sqrt()));
    assert!(close(&json["figures_um"]["E"], 10.0));
    let verdict = &json["verdict"];
    assert!(close(&verdict["travel_mm"], 200.0));
    let (a, e) = (&verdict["checks"][0], &verdict["checks"][1]);
    // A: 10 µm/1000 mm × 200 mm = 2 µm, raised to 5 µm; 15.66 > 5.
    assert!(close(&a["limit_um"], 5.0));
    assert_eq!(a["pass"], json!(false));
    assert_eq!(a["limit_source"], json!(format!("{profile} [acceptance]")));
    assert_eq!(
        a["limit_derivation"],
        json!("10 µm per 1000 mm × 200 mm of travel = 2 µm, raised to the minimum 5 µm")
    );
    // E: 60 µm/1000 mm × 200 mm = 12 µm; 10 ≤ 12.
    assert!(close(&e["limit_um"], 12.0));
    assert_eq!(e["pass"], json!(true));
    assert_eq!(verdict["failed"], json!(["A"]));

    // --limit A=16 replaces the profile's A (Y's own A is for another axis).
    let json = evaluate_json_with(&[before, "--machine", profile, "--limit", "A=16"]);
    let verdict = &json["verdict"];
    assert_eq!(verdict["pass"], json!(true));
    assert_eq!(verdict["checks"][0]["limit_source"], json!("--limit"));
    assert_eq!(
        verdict["checks"][1]["limit_source"],
        json!(format!("{profile} [acceptance]"))
    );

    // The same file read as axis Y gets [acceptance.axes.Y]'s A = 100 µm.
    let json = evaluate_json_with(&[before, "--machine", profile, "--axis", "Y"]);
    let a = &json["verdict"]["checks"][0];
    assert!(close(&a["limit_um"], 100.0));
    assert_eq!(
        a["limit_source"],
        json!(format!("{profile} [acceptance.axes.Y]"))
    );

    // A profile without [acceptance]: no limits, no verdict.
    let json = evaluate_json_with(&[before, "--machine", "fixtures/machines/mcv754-quick.toml"]);
    assert!(json.get("verdict").is_none());
}

#[test]
fn bad_limits_are_refused_with_exit_code_2() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("r.html");
    let out = output.to_str().unwrap();
    for (args, message) in [
        (
            vec!["evaluate", SAMPLE, "--limit", "Q=3"],
            "unknown figure \"Q\"; the figures are A, A_up, A_down, E, E_up, E_down, M, R, R_up, R_down, B, B_mean",
        ),
        (
            vec!["evaluate", SAMPLE, "--limit", "A=abc"],
            "a number of µm above 0",
        ),
        (
            vec!["evaluate", SAMPLE, "--limit", "A=0"],
            "a number of µm above 0",
        ),
        (vec!["evaluate", SAMPLE, "--limit", "A"], "FIGURE=UM"),
        (
            vec!["evaluate", SAMPLE, "--limit", "A=3", "--limit", "A=4"],
            "--limit A is given twice",
        ),
        (
            vec!["report", SAMPLE, "--limit", "R_sideways=3", "-o", out],
            "unknown figure \"R_sideways\"",
        ),
    ] {
        let run = axcomp(&args);
        assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
        assert!(run.stderr.contains(message), "{args:?}: {}", run.stderr);
        assert!(run.stdout.is_empty(), "{args:?}: {}", run.stdout);
    }
    // A profile with a typo: file, line and column; nothing written.
    let profile = write(
        directory.path(),
        "typo.toml",
        "[acceptance]\nA = { per_1000_mm_um = 10, mn_um = 5 }\n",
    );
    let profile = profile.to_str().unwrap();
    for args in [
        vec!["evaluate", SAMPLE, "--machine", profile],
        vec!["report", SAMPLE, "--machine", profile, "-o", out],
    ] {
        let run = axcomp(&args);
        assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
        assert!(
            run.stderr
                .contains(&format!("{profile}:2:28: unknown field `mn_um`")),
            "{}",
            run.stderr
        );
    }
    assert!(!output.exists());
}

/// The `<section id="verdict">` of a page.
fn verdict_box(html: &str) -> &str {
    let start = html.find("<section id=\"verdict\"").expect("a verdict box");
    let end = start + html[start..].find("</section>").unwrap();
    &html[start..end]
}

#[test]
fn the_report_has_a_verdict_box_at_the_top() {
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("report.html");
    let out = output.to_str().unwrap();
    let limits = ["--limit", "A=12", "--limit", "R=7"];
    let mut args = vec!["report", SAMPLE, "-o", out];
    args.extend(limits);
    let run = axcomp(&args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&output).unwrap();
    let verdict = verdict_box(&html);
    assert!(verdict.contains("data-verdict=\"fail\""), "{verdict}");
    assert!(verdict.contains("<h2>Acceptance verdict: FAIL</h2>"));
    assert!(verdict.contains("FAIL: A above the limit"));
    assert!(verdict.contains("--limit: 12 µm"));
    assert!(verdict.contains("simple acceptance"));
    // At the top: after the header, before everything else.
    let at = |needle: &str| html.find(needle).unwrap();
    assert!(
        at("</header>") < at("id=\"verdict\"") && at("id=\"verdict\"") < at("id=\"conditions\"")
    );
    // Its cells are those of evaluate --json with the same limits: 12 figures,
    // 16 × 9 per-target values, 2 × (value, U, limit) of the checks, and
    // U with the 5 contributors of the uncertainty budget.
    let mut evaluate_args = vec![SAMPLE];
    evaluate_args.extend(limits);
    let evaluation = evaluate_json_with(&evaluate_args);
    assert_eq!(
        check_against_json(&html, "before", &evaluation),
        12 + 16 * 9 + 2 * 3 + 1 + 5
    );
    assert_eq!(embedded_data(&html)["before"], evaluation);
    // Each check row names the figure cell it checks, which shows the same value.
    let value_of = |key: &str| {
        let pattern = format!("data-key=\"{key}\" data-um=\"");
        let at = html.find(&pattern).unwrap_or_else(|| panic!("{key}"));
        let rest = &html[at + pattern.len()..];
        rest[..rest.find('"').unwrap()].to_string()
    };
    for (index, figure) in ["A", "R"].iter().enumerate() {
        assert!(verdict.contains(&format!(
            "data-figure=\"{figure}\" data-figure-key=\"before.figures_um.{figure}\""
        )));
        assert_eq!(
            value_of(&format!("before.verdict.checks.{index}.value_um")),
            value_of(&format!("before.figures_um.{figure}"))
        );
    }

    // Without limits: no verdict, and the box says so.
    let run = axcomp(["report", SAMPLE, "-o", out, "--force"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&output).unwrap();
    let verdict = verdict_box(&html);
    assert!(verdict.contains("data-verdict=\"none\""));
    assert!(verdict.contains("No acceptance limits given: no verdict."));
    assert!(!html.contains("PASS") && !html.contains("Acceptance verdict"));
}

#[test]
fn a_before_after_report_judges_the_retest() {
    let directory = tempfile::tempdir().unwrap();
    let before = write(directory.path(), "before.csv", BEFORE);
    let after = write(directory.path(), "after.csv", AFTER);
    let profile = write(directory.path(), "machine.toml", PROFILE);
    let output = directory.path().join("report.html");
    let (before, after, profile) = (
        before.to_str().unwrap(),
        after.to_str().unwrap(),
        profile.to_str().unwrap(),
    );
    let run = axcomp([
        "report",
        before,
        "--after",
        after,
        "--machine",
        profile,
        "-o",
        output.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let html = std::fs::read_to_string(&output).unwrap();
    let verdict = verdict_box(&html);
    // The re-test: A = 2 + 2√2 = 4.83 ≤ 5 and E = 2 ≤ 12: PASS; the first
    // test (A = 15.66 > 5) failed, and the box says so.
    assert!(verdict.contains("data-verdict=\"pass\""), "{verdict}");
    assert!(verdict.contains("PASS: A, E within the limits"));
    assert!(verdict.contains(&format!("(re-test {after})")));
    assert!(verdict.contains("The first test, before compensation: FAIL: A above the limit."));
    assert!(
        verdict.contains("data-key=\"after.verdict.checks.0.value_um\" data-um=\"4.82842712474619")
    );
    let data = embedded_data(&html);
    assert_eq!(
        data["after"],
        evaluate_json_with(&[after, "--machine", profile])
    );
    assert_eq!(data["before"]["verdict"]["pass"], json!(false));
    assert_eq!(data["after"]["verdict"]["pass"], json!(true));
}

// --- Measurement uncertainty and ISO 14253-1 (issue 13) ----------------------

/// The sample's E is 11.21 µm (README). Its U with the bundled equipment,
/// by hand: L = 750 mm, α = 11.7 (the file), u_Tmat = 0.1 °C:
/// u_M,MACHINE = 0.75 · 11.7 · 0.1 = 0.8775 µm; u_DEVICE = 0.5/2 · 0.75 =
/// 0.1875 µm; the others (u_E,MACHINE from the file's ~20.3 °C, θ, E_VE = 0)
/// are small; U = 2 √Σu² ≈ 1.82 µm. So against E = 12 µm: simple passes,
/// ISO 14253-1 proves nothing (11.21 + 1.82 > 12 ≥ 11.21 − 1.82); against
/// 14 µm conformance and against 9 µm non-conformance are proven.
#[test]
fn iso_14253_1_pass_fail_and_not_proven_with_the_json_keys() {
    let json = evaluate_json_with(&[SAMPLE]);
    let u = &json["uncertainty_um"];
    let budget = u["budget"].as_array().unwrap();
    let named = |name: &str| {
        budget.iter().find(|c| c["name"] == name).unwrap()["u_um"]
            .as_f64()
            .unwrap()
    };
    assert_abs_diff_eq!(named("u_M,MACHINE"), 0.8775, epsilon = 1e-9);
    assert_abs_diff_eq!(named("u_DEVICE"), 0.1875, epsilon = 1e-9);
    // Largest first, and U = 2 √Σu² from the rows themselves.
    let sizes: Vec<f64> = budget.iter().map(|c| c["u_um"].as_f64().unwrap()).collect();
    assert!(sizes.windows(2).all(|w| w[0] >= w[1]), "{sizes:?}");
    let expanded = 2.0 * sizes.iter().map(|s| s * s).sum::<f64>().sqrt();
    for figure in ["E", "M", "A"] {
        assert_abs_diff_eq!(u[figure].as_f64().unwrap(), expanded, epsilon = 1e-9);
    }
    assert!(abs_diff_eq!(expanded, 1.82, epsilon = 0.01), "{expanded}");
    assert_eq!(u["R"], Value::Null);
    assert_eq!(u["B"], Value::Null);
    for contributor in budget {
        assert!(
            contributor["source"]
                .as_str()
                .is_some_and(|s| !s.is_empty())
        );
    }

    let verdict = |limit: &str, rule: &str| {
        let limit = format!("E={limit}");
        evaluate_json_with(&[SAMPLE, "--limit", &limit, "--decision", rule])["verdict"].clone()
    };
    let simple = verdict("12", "simple");
    assert_eq!(simple["rule"], "simple");
    assert_eq!(simple["checks"][0]["conformance"], "pass");
    assert_eq!(simple["pass"], true);
    let straddles = verdict("12", "iso14253-1");
    assert_eq!(straddles["rule"], "iso14253-1");
    assert_eq!(straddles["conformance"], "not-proven");
    assert_eq!(straddles["pass"], false);
    let check = &straddles["checks"][0];
    assert_eq!(check["conformance"], "not-proven");
    assert_eq!(check["outcome"], "pass");
    assert_abs_diff_eq!(check["U_um"].as_f64().unwrap(), expanded, epsilon = 1e-9);
    assert!(
        check["reason"].as_str().unwrap().contains("not proven")
            || check["reason"].as_str().unwrap().contains("neither")
    );
    assert_eq!(
        verdict("14", "iso14253-1")["checks"][0]["conformance"],
        "pass"
    );
    assert_eq!(verdict("14", "iso14253-1")["conformance"], "pass");
    assert_eq!(
        verdict("9", "iso14253-1")["checks"][0]["conformance"],
        "fail"
    );
    // R has no U: `null`, decided by its value (6.26 ≤ 7).
    let r = evaluate_json_with(&[SAMPLE, "--limit", "R=7", "--decision", "iso14253-1"]);
    assert_eq!(r["verdict"]["checks"][0]["U_um"], Value::Null);
    assert_eq!(r["verdict"]["checks"][0]["conformance"], "pass");

    // The terminal: U beside E, M, A and the rule named.
    let run = axcomp([
        "evaluate",
        SAMPLE,
        "--limit",
        "E=12",
        "--decision",
        "iso14253-1",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stdout.contains("11.21 ± 1.82"), "{}", run.stdout);
    assert!(run.stdout.contains("rule iso14253-1"));
    assert!(run.stdout.contains("NOT PROVEN"));
    let bad = axcomp(["evaluate", SAMPLE, "--decision", "iso"]);
    assert_eq!(bad.code, 2);
    assert!(bad.stderr.contains("simple, iso14253-1"), "{}", bad.stderr);
}

/// An equipment file: its values used, a bad value refused at its line and
/// column with exit 2, a drift test read relative to the profile.
#[test]
fn an_equipment_file_and_its_errors() {
    let directory = tempfile::tempdir().unwrap();
    let bundled = std::fs::read_to_string("fixtures/equipment/hene-default.toml").unwrap();
    // E_VE = 6 µm: u_EVE = 6/(2√3) = 1.7321 µm.
    let given = write(
        directory.path(),
        "e.toml",
        &bundled.replace("eve_um = 0", "eve_um = 6"),
    );
    let json = evaluate_json_with(&[SAMPLE, "--equipment", given.to_str().unwrap()]);
    let budget = json["uncertainty_um"]["budget"].as_array().unwrap();
    assert_eq!(budget[0]["name"], "u_EVE");
    assert_abs_diff_eq!(
        budget[0]["u_um"].as_f64().unwrap(),
        1.732_051,
        epsilon = 1e-6
    );
    // A drift test: BEFORE's deviations span 0–12 µm, E_VE = 12, u_EVE = 3.4641 µm.
    write(directory.path(), "drift.csv", BEFORE);
    let drift = write(
        directory.path(),
        "d.toml",
        &bundled.replace("eve_um = 0", "drift_test = \"drift.csv\""),
    );
    let json = evaluate_json_with(&[SAMPLE, "--equipment", drift.to_str().unwrap()]);
    let first = &json["uncertainty_um"]["budget"][0];
    assert_abs_diff_eq!(first["u_um"].as_f64().unwrap(), 3.464_102, epsilon = 1e-6);
    assert!(first["source"].as_str().unwrap().contains("drift.csv"));
    // A negative value: PATH:LINE:COL, exit 2.
    let bad = write(
        directory.path(),
        "bad.toml",
        &bundled.replace("k = 2", "k = -2"),
    );
    let run = axcomp(["evaluate", SAMPLE, "--equipment", bad.to_str().unwrap()]);
    assert_eq!(run.code, 2);
    let line = bundled.lines().position(|l| l == "k = 2").unwrap() + 1;
    assert!(
        run.stderr
            .contains(&format!("bad.toml:{line}:5: expected a number above 0")),
        "{}",
        run.stderr
    );
}

/// Limits on VDI/DGQ 3441's own keys (`--standard vdi3441`), judged on its
/// figures. BEFORE by hand (standards.md §3): U_i = |x̄↑ − x̄↓| = 2 at every
/// target, Ps_i = 6·(√2 + √2)/2 = 6√2 = 8.485, x̄_i = 2, 6, 10, so Pa = 8
/// and P = (10 + (2 + 6√2)/2) − (2 − (2 + 6√2)/2) = 10 + 6√2 = 18.485 µm.
/// U of a VDI figure is not evaluated (standards.md gives no form): null,
/// and ISO 14253-1 then compares the value alone.
#[test]
fn limits_on_a_standards_own_keys_and_keys_it_does_not_have() {
    let directory = tempfile::tempdir().unwrap();
    let before = write(directory.path(), "before.csv", BEFORE);
    let before = before.to_str().unwrap();
    let p = 10.0 + 6.0 * 2f64.sqrt();
    let json = evaluate_json_with(&[
        before,
        "--standard",
        "vdi3441",
        "--limit",
        "U_max=1.5",
        "--limit",
        "P=20",
        "--decision",
        "iso14253-1",
    ]);
    assert!(close(&json["figures_um"]["P"], p));
    let checks = json["verdict"]["checks"].as_array().unwrap();
    assert_eq!(checks.len(), 2);
    assert_eq!(checks[0]["figure"], "P");
    assert!(close(&checks[0]["value_um"], p));
    assert_eq!(checks[0]["U_um"], Value::Null);
    assert_eq!(checks[0]["conformance"], "pass");
    assert_eq!(checks[1]["figure"], "U_max");
    assert!(close(&checks[1]["value_um"], 2.0));
    assert_eq!(checks[1]["conformance"], "fail");
    assert_eq!(json["verdict"]["failed"], json!(["U_max"]));
    // The profile's [acceptance] the same way: Pa = 8 against 7.5.
    let vdi_profile = write(directory.path(), "vdi.toml", "[acceptance]\nPa = 7.5\n");
    let vdi_profile = vdi_profile.to_str().unwrap();
    let json = evaluate_json_with(&[before, "--standard", "vdi3441", "--machine", vdi_profile]);
    assert!(close(&json["verdict"]["checks"][0]["value_um"], 8.0));
    assert_eq!(json["verdict"]["pass"], false);
    // A key the standard does not have: refused, naming its keys.
    let iso_keys = "A, A_up, A_down, E, E_up, E_down, M, R, R_up, R_down, B, B_mean";
    let vdi_keys = "P, Pa, Ps_max, Ps_mean, U_max, U_mean";
    for (args, message) in [
        (
            vec![
                "evaluate",
                before,
                "--standard",
                "vdi3441",
                "--limit",
                "A=12",
            ],
            format!(
                "--limit: a limit on A, which VDI/DGQ 3441 (1977) does not report; its figures are {vdi_keys}"
            ),
        ),
        (
            vec!["evaluate", before, "--limit", "P=20"],
            format!(
                "a limit on P, which ISO 230-2:2014 does not report; its figures are {iso_keys}"
            ),
        ),
        (
            vec!["evaluate", before, "--machine", vdi_profile],
            format!("{vdi_profile} [acceptance]: a limit on Pa"),
        ),
        (
            vec!["report", before, "--limit", "Ps_max=9", "-o", "never.html"],
            "a limit on Ps_max, which ISO 230-2:2014 does not report".to_string(),
        ),
    ] {
        let run = axcomp(&args);
        assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
        assert!(run.stderr.contains(&message), "{args:?}: {}", run.stderr);
        assert!(run.stdout.is_empty());
    }
    assert!(!Path::new("never.html").exists());
}
