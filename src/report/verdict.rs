//! The acceptance verdict as users and scripts read it: its `--json` wire
//! format ([`VerdictJson`], the `verdict` key of `evaluate --json`), its
//! terminal lines ([`terminal`]) and the report's verdict box ([`verdict_box`]).
//!
//! # Wire format
//!
//! Present only when acceptance limits are given (no limits, no verdict, and
//! no `verdict` key); keys may be added, never renamed:
//!
//! ```text
//! "verdict": { "pass": false, "rule": "simple",      // or "iso14253-1" (--decision)
//!   "decision": "simple acceptance",               // or "ISO 14253-1"
//!   "decision_rule": "simple acceptance: value ≤ limit, measurement uncertainty not considered",
//!   "conformance": "fail",                         // or "pass", "not-proven"
//!   "travel_mm": 750.0, "failed": ["A"],
//!   "checks": [{ "figure": "A", "value_um": 13.19, "limit_um": 12.0, "pass": false,
//!                "U_um": 3.49,                    // null where U is not evaluated (R, B, ↑, ↓, VDI 3441 but Pa, unknown instrument)
//!                "U_note": null,                  // iso14253-1 without U: why ("U(R) not evaluated: …")
//!                "conformance": "fail",           // or "pass", "not-proven" (under the rule)
//!                "outcome": "exceeds",            // value against limit alone: or "pass", "not evaluated"
//!                "reason": "13.19 µm is above the limit 12 µm",   // null when it passes
//!                "limit_source": "--limit",       // or "M.toml [acceptance]", "M.toml [acceptance.axes.X]"
//!                "limit_derivation": "12 µm" }, …] }
//! ```
//!
//! `value_um` is the value compared: the figure, |B̄| for `B_mean`, `null`
//! when not evaluated (such a check fails). Checks come in the order of
//! `figures_um`. `pass` is `conformance == "pass"`: under ISO 14253-1 a
//! check passes only when value + U ≤ limit, and `not-proven` is no pass.

use serde::Serialize;

use crate::evaluate::Evaluation;
use crate::evaluate::uncertainty::Budget;
use crate::evaluate::verdict::{
    Check, Conformance, Decision, Limit, Outcome, Permissible, Verdict, verdict_with,
};
use crate::report::acceptance::{ReportInput, TestRecord};
use crate::report::format::{SourcedUm, um};
use crate::units::mm_to_um;
use crate::units::per_m_over_mm;

/// The verdict on an evaluation as JSON under `decision`, with the
/// uncertainty of `budget`; `None` without limits.
pub fn judge(
    evaluation: &Evaluation,
    limits: &[Limit],
    decision: Decision,
    budget: Option<&Budget>,
) -> Option<VerdictJson> {
    verdict_with(evaluation, limits, decision, budget).map(|v| VerdictJson::from_verdict(&v))
}

/// The verdict on one test.
#[derive(Clone, Debug, Serialize)]
pub struct VerdictJson {
    /// Every check passed (conformance proven for every check).
    pub pass: bool,
    /// The decision rule: `simple` or `iso14253-1`.
    pub rule: &'static str,
    /// The decision rule's label: `simple acceptance` or `ISO 14253-1`.
    pub decision: &'static str,
    /// The decision rule in words.
    pub decision_rule: &'static str,
    /// `pass`, `fail` or `not-proven`.
    pub conformance: &'static str,
    /// The measured travel per-length limits use, last − first target, mm.
    pub travel_mm: f64,
    /// The figures that did not pass, in check order.
    pub failed: Vec<&'static str>,
    /// One per limit.
    pub checks: Vec<CheckJson>,
}

/// One figure against its limit.
#[allow(non_snake_case)]
#[derive(Clone, Debug, Serialize)]
pub struct CheckJson {
    /// The figure, as in `figures_um`.
    pub figure: &'static str,
    /// The value compared, µm (|B̄| for B_mean); `null` when not evaluated.
    pub value_um: Option<f64>,
    /// The limit for this test, µm.
    pub limit_um: f64,
    /// Whether it passed (conformance proven).
    pub pass: bool,
    /// The figure's expanded uncertainty, µm; `null` where not evaluated.
    pub U_um: Option<f64>,
    /// Under ISO 14253-1, why a figure has no U (and is compared by its
    /// value alone); `null` otherwise.
    pub U_note: Option<String>,
    /// `pass`, `fail` or `not-proven`, under the rule.
    pub conformance: &'static str,
    /// The value against the limit alone: `pass`, `exceeds` or `not evaluated`.
    pub outcome: &'static str,
    /// Why it did not pass; `null` when it passed.
    pub reason: Option<String>,
    /// Where the limit was given.
    pub limit_source: String,
    /// How the limit for this test follows from what was given.
    pub limit_derivation: String,
}

impl VerdictJson {
    /// Converts a verdict to µm and sentences.
    pub fn from_verdict(verdict: &Verdict) -> VerdictJson {
        VerdictJson {
            pass: verdict.pass(),
            rule: verdict.decision.name(),
            decision: verdict.decision.label(),
            decision_rule: verdict.decision.description(),
            conformance: verdict.conformance().name(),
            travel_mm: verdict.travel_mm,
            failed: verdict.failed().map(|c| c.figure().name()).collect(),
            checks: verdict
                .checks
                .iter()
                .map(|c| CheckJson::from_check(c, verdict))
                .collect(),
        }
    }
}

impl CheckJson {
    fn from_check(check: &Check, verdict: &Verdict) -> CheckJson {
        let (travel_mm, decision) = (verdict.travel_mm, verdict.decision);
        let figure = check.figure();
        let limit_um = mm_to_um(check.limit_mm);
        let value_um = check.value_mm.map(mm_to_um);
        let u_um = check.uncertainty_mm.map(mm_to_um);
        // U enters the reason only where the rule used it.
        let u_used = u_um.filter(|_| decision == Decision::Iso14253_1);
        let reason = match (check.conformance, check.outcome, value_um, u_used) {
            (Conformance::Pass, ..) => None,
            (Conformance::NotProven, _, Some(value), Some(u)) => Some(format!(
                "{} ± {} µm straddles the limit {} µm: neither conformance nor \
                 non-conformance is proven (ISO 14253-1)",
                um(Some(value)),
                um(Some(u)),
                short(limit_um)
            )),
            (_, Outcome::Exceeds, Some(value), Some(u)) => Some(format!(
                "{} − {} µm is above the limit {} µm (ISO 14253-1: non-conformance proven)",
                um(Some(value)),
                um(Some(u)),
                short(limit_um)
            )),
            (_, Outcome::Exceeds, Some(value), None) => Some(format!(
                "{} µm is above the limit {} µm",
                um(Some(value)),
                short(limit_um)
            )),
            _ => Some(format!(
                "{figure} is not evaluated for this test (see the warnings); \
                 a figure that is not evaluated cannot pass"
            )),
        };
        // Under ISO 14253-1 a figure judged without a U says why.
        let u_note = match (decision, u_um, verdict.budget) {
            (Decision::Iso14253_1, None, false) => Some(format!(
                "U({figure}) not evaluated: instrument unknown (give --equipment); compared by its value alone"
            )),
            (Decision::Iso14253_1, None, true) => Some(format!(
                "U({figure}) not evaluated: no published form of its uncertainty; compared by its value alone"
            )),
            _ => None,
        };
        CheckJson {
            figure: figure.name(),
            value_um,
            limit_um,
            pass: check.pass(),
            U_um: u_um,
            U_note: u_note,
            conformance: check.conformance.name(),
            outcome: match check.outcome {
                Outcome::Pass => "pass",
                Outcome::Exceeds => "exceeds",
                Outcome::NotEvaluated => "not evaluated",
            },
            reason,
            limit_source: check.limit.source.to_string(),
            limit_derivation: derivation(&check.limit.permissible, travel_mm),
        }
    }
}

/// A µm or mm number without trailing zeros, to three decimals: 7.5, 12, 0.125.
fn short(value: f64) -> String {
    let text = format!("{value:.3}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// "12 µm", or "10 µm per 1000 mm × 750 mm of travel = 7.5 µm (at least 5 µm)".
fn derivation(permissible: &Permissible, travel_mm: f64) -> String {
    match *permissible {
        Permissible::Fixed { limit_mm } => format!("{} µm", short(mm_to_um(limit_mm))),
        Permissible::PerLength {
            per_1000_mm_mm,
            min_mm,
        } => {
            let proportional = mm_to_um(per_m_over_mm(per_1000_mm_mm, travel_mm));
            let base = format!(
                "{} µm per 1000 mm × {} mm of travel = {} µm",
                short(mm_to_um(per_1000_mm_mm)),
                short(travel_mm),
                short(proportional)
            );
            match min_mm {
                None => base,
                Some(min) if permissible.minimum_applies(travel_mm) => {
                    format!("{base}, raised to the minimum {} µm", short(mm_to_um(min)))
                }
                Some(min) => format!("{base} (at least {} µm)", short(mm_to_um(min))),
            }
        }
    }
}

/// The one-line verdict: `PASS: A, R within the limits`,
/// `FAIL: A above the limit; R not evaluated (cannot pass)` or
/// `NOT PROVEN: E within U of the limit (ISO 14253-1)`.
pub fn headline(verdict: &VerdictJson) -> String {
    let figures = |checks: &[&CheckJson]| {
        checks
            .iter()
            .map(|c| c.figure)
            .collect::<Vec<_>>()
            .join(", ")
    };
    if verdict.pass {
        let all: Vec<&CheckJson> = verdict.checks.iter().collect();
        return format!("PASS: {} within the limits", figures(&all));
    }
    let of = |outcome: &str| -> Vec<&CheckJson> {
        verdict
            .checks
            .iter()
            .filter(|c| c.outcome == outcome)
            .collect()
    };
    let mut parts = Vec::new();
    let failed = |c: &&CheckJson| c.conformance == "fail";
    let exceeds: Vec<&CheckJson> = of("exceeds").into_iter().filter(failed).collect();
    if !exceeds.is_empty() {
        parts.push(format!("{} above the limit", figures(&exceeds)));
    }
    let missing = of("not evaluated");
    if !missing.is_empty() {
        parts.push(format!("{} not evaluated (cannot pass)", figures(&missing)));
    }
    let straddle: Vec<&CheckJson> = verdict
        .checks
        .iter()
        .filter(|c| c.conformance == "not-proven")
        .collect();
    if !straddle.is_empty() {
        parts.push(format!(
            "{} within U of the limit (ISO 14253-1: not proven)",
            figures(&straddle)
        ));
    }
    format!("{}: {}", verdict_word(verdict), parts.join("; "))
}

/// `PASS`, `FAIL` or `NOT PROVEN`.
fn verdict_word(verdict: &VerdictJson) -> &'static str {
    match verdict.conformance {
        "pass" => "PASS",
        "not-proven" => "NOT PROVEN",
        _ => "FAIL",
    }
}

/// The terminal lines of `evaluate`: the checks and the verdict line.
pub fn terminal(verdict: &VerdictJson) -> String {
    use tabled::builder::Builder;
    use tabled::settings::object::Columns;
    use tabled::settings::{Alignment, Style};

    let mut builder = Builder::default();
    builder.push_record(["figure", "value", "U", "limit", "result", "limit from"]);
    for c in &verdict.checks {
        builder.push_record([
            c.figure.to_string(),
            um(c.value_um),
            um(c.U_um),
            um(Some(c.limit_um)),
            result_word(c).to_string(),
            format!("{}: {}", c.limit_source, c.limit_derivation),
        ]);
    }
    let mut table = builder.build();
    table
        .with(Style::psql())
        .modify(Columns::new(1..4), Alignment::right());
    format!(
        "\nAcceptance [µm] (rule {}: {})\n{table}\n{}\n",
        verdict.rule,
        verdict.decision_rule,
        headline(verdict)
    )
}

fn result_word(check: &CheckJson) -> &'static str {
    match (check.conformance, check.outcome) {
        ("pass", _) => "pass",
        ("not-proven", _) => "NOT PROVEN",
        (_, "not evaluated") => "FAIL (not evaluated)",
        _ => "FAIL",
    }
}

/// The report's verdict box (`templates/report/verdict.html`), at the top:
/// the verdict on the re-test when there is one (the state being accepted),
/// else on the test; `None` without limits, and the box then says so: no
/// verdict, never an implied pass.
pub fn verdict_box(input: &ReportInput<'_>) -> Option<Judged> {
    let name = |what: &str, test: &TestRecord<'_>| match &test.measurement.metadata.source_file {
        Some(file) => format!("{what} {}", file.display()),
        None => what.to_string(),
    };
    let judge_test =
        |test: &TestRecord<'_>| judge(test.evaluation, input.limits, input.decision, test.budget);
    let before = judge_test(&input.before);
    match &input.after {
        Some(after) => {
            let judged = judge_test(after)?;
            Some(Judged::new(
                "after",
                name("re-test", after),
                &judged,
                before.as_ref(),
            ))
        }
        None => Some(Judged::new(
            "before",
            name("test", &input.before),
            &before?,
            None,
        )),
    }
}

/// The verdict box of the test being accepted.
#[derive(Clone, Debug, PartialEq)]
pub struct Judged {
    /// `pass`, `fail` or `not-proven`, the box's class and `data-verdict`.
    pub class: &'static str,
    /// `PASS`, `FAIL` or `NOT PROVEN`.
    pub word: &'static str,
    /// The verdict in one line ([`headline`]).
    pub headline: String,
    /// `test FILE` or `re-test FILE`.
    pub test_name: String,
    /// One row per check, in the order of `figures_um`.
    pub checks: Vec<CheckRow>,
    /// The decision rule's name (`simple`, `iso14253-1`).
    pub rule: &'static str,
    /// The decision rule in words.
    pub decision: &'static str,
    /// The measured travel that per-length limits use, mm.
    pub travel_mm: String,
    /// The first test's headline in a before/after report.
    pub first_test: Option<String>,
}

/// A check's row: the figure, its value and limit with their sources.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckRow {
    /// The figure's key in `figures_um` (`A`, `R_up`, `B_mean`).
    pub figure: &'static str,
    /// The figure's cell in the figures table (`after.figures_um.A`).
    pub figure_key: String,
    /// `A`, `R↑`, `|B̄|`.
    pub label: String,
    /// The value compared (`value_um`).
    pub value: SourcedUm,
    /// The permissible value (`limit_um`).
    pub limit: SourcedUm,
    /// The figure's expanded uncertainty (`U_um`), `—` where not evaluated.
    pub uncertainty: SourcedUm,
    /// `pass`, `fail` or `not-proven`.
    pub class: &'static str,
    /// `pass`, `FAIL`, `NOT PROVEN` or `FAIL (not evaluated)`.
    pub result: &'static str,
    /// Why it fails; `None` when it passes.
    pub reason: Option<String>,
    /// Where the limit comes from (`--limit`, the machine profile).
    pub limit_source: String,
    /// How the limit follows from the permissible value.
    pub limit_derivation: String,
}

impl Judged {
    /// `prefix` is the `evaluate --json` key of the test being accepted
    /// (`before`, `after`); `first_test` the first test's verdict in a
    /// before/after report.
    fn new(
        prefix: &str,
        test_name: String,
        verdict: &VerdictJson,
        first_test: Option<&VerdictJson>,
    ) -> Judged {
        let checks = verdict
            .checks
            .iter()
            .enumerate()
            .map(|(index, c)| {
                let key = |what: &str| format!("{prefix}.verdict.checks.{index}.{what}");
                CheckRow {
                    figure: c.figure,
                    figure_key: format!("{prefix}.figures_um.{}", c.figure),
                    label: if c.figure == "B_mean" {
                        "|B̄|".to_string()
                    } else {
                        c.figure.replace("_up", "↑").replace("_down", "↓")
                    },
                    value: SourcedUm::new(key("value_um"), c.value_um),
                    limit: SourcedUm::new(key("limit_um"), Some(c.limit_um)),
                    uncertainty: SourcedUm::new(key("U_um"), c.U_um),
                    class: c.conformance,
                    result: result_word(c),
                    reason: c.reason.clone().filter(|_| !c.pass),
                    limit_source: c.limit_source.clone(),
                    limit_derivation: c.limit_derivation.clone(),
                }
            })
            .collect();
        Judged {
            class: verdict.conformance,
            word: verdict_word(verdict),
            headline: headline(verdict),
            test_name,
            checks,
            rule: verdict.rule,
            decision: verdict.decision_rule,
            travel_mm: short(verdict.travel_mm),
            first_test: first_test.map(headline),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluate::AxisFigures;
    use crate::evaluate::verdict::{Figure, Limit, LimitSource};
    use crate::report::json::FiguresJson;
    use crate::units::um_to_mm;

    #[test]
    fn derivations_say_how_the_limit_follows() {
        let per = |per_um: f64, min_um: Option<f64>| Permissible::PerLength {
            per_1000_mm_mm: um_to_mm(per_um),
            min_mm: min_um.map(um_to_mm),
        };
        assert_eq!(
            derivation(&Permissible::Fixed { limit_mm: 0.012 }, 750.0),
            "12 µm"
        );
        assert_eq!(
            derivation(&per(10.0, None), 750.0),
            "10 µm per 1000 mm × 750 mm of travel = 7.5 µm"
        );
        assert_eq!(
            derivation(&per(10.0, Some(5.0)), 200.0),
            "10 µm per 1000 mm × 200 mm of travel = 2 µm, raised to the minimum 5 µm"
        );
        assert_eq!(
            derivation(&per(10.0, Some(5.0)), 750.0),
            "10 µm per 1000 mm × 750 mm of travel = 7.5 µm (at least 5 µm)"
        );
    }

    #[test]
    fn headlines_name_the_failing_figures() {
        let figures = AxisFigures {
            a: Some(0.013),
            e: Some(0.004),
            ..Default::default()
        };
        let evaluation = crate::evaluate::Evaluation::of_figures(figures, Vec::new(), 1, 0.0);
        let limit = |figure, um: f64| Limit {
            figure,
            permissible: Permissible::Fixed {
                limit_mm: um_to_mm(um),
            },
            source: LimitSource::CommandLine,
        };
        let limits = [
            limit(Figure::R, 7.0),
            limit(Figure::A, 12.0),
            limit(Figure::E, 5.0),
        ];
        let verdict = crate::evaluate::verdict::verdict(&evaluation, &limits).unwrap();
        let json = VerdictJson::from_verdict(&verdict);
        assert_eq!(
            headline(&json),
            "FAIL: A above the limit; R not evaluated (cannot pass)"
        );
        assert_eq!(json.failed, ["A", "R"]);
        assert_eq!(json.checks[1].reason, None);
        assert_eq!(
            json.checks[0].reason.as_deref(),
            Some("13.00 µm is above the limit 12 µm")
        );
        let passing = crate::evaluate::verdict::verdict(&evaluation, &limits[2..]).unwrap();
        assert_eq!(
            headline(&VerdictJson::from_verdict(&passing)),
            "PASS: E within the limits"
        );
    }

    #[test]
    fn figure_names_are_the_keys_of_figures_um() {
        let figures = AxisFigures::default().typed(crate::measurement::AxisKind::Linear);
        let json = serde_json::to_value(FiguresJson::of_linear(&figures)).unwrap();
        let mut keys: Vec<&str> = json
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        // ISO 230-2's figures; VDI 3441's are its standard's keys (tests/it/verdict.rs).
        let mut names: Vec<&str> = Figure::ALL[..12].iter().map(|f| f.name()).collect();
        keys.sort_unstable();
        names.sort_unstable();
        assert_eq!(names, keys);
    }
}
