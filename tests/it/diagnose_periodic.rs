//! Issue 16: a screw's periodic error between irregular targets.
//!
//! The re-test of ISO 230-2's recommendation: 19–25 irregular targets over
//! 600–1000 mm (25–55 mm apart), 5 runs each way, σ 0.3–0.6 µm; a periodic
//! error of a 10, 15 or 20 mm lead and 1.5–3 µm amplitude present in the
//! re-test and not in the model (as the other kinds in `diagnose.rs`), or
//! in both tests, whose first test's targets (drawn alike, other places)
//! sample it without resolving it (issue 16's case: the prediction carries
//! those samples).
//! Each case is drawn from its seed (ChaCha8, one stream per lead); found
//! means the period within 2 % and the amplitude within 10 %.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Uniform};
use rayon::prelude::*;
use std::path::Path;

use axcomp::cycle::CycleTiming;
use axcomp::diagnose::{DiagnoseInput, Diagnosis, KnownPeriod, diagnose};
use axcomp::effects::{Effect, Periodic};
use axcomp::evaluate::ISO_230_2;
use axcomp::synth::Truth;

use crate::util::{synth_loop, synth_loop_files};

const SEEDS: u64 = 20;
const LEADS_MM: [f64; 3] = [10.0, 15.0, 20.0];

/// One drawn case: its truth file and the planted error.
pub(crate) struct Case {
    pub(crate) truth: String,
    period_mm: f64,
    amplitude_um: f64,
}

fn draw(rng: &mut ChaCha8Rng, low: f64, high: f64) -> f64 {
    Uniform::new_inclusive(low, high).unwrap().sample(rng)
}

/// The case of `seed`: a lead's periodic error (or none, `lead_mm` = 0) in
/// the re-test of a drawn cycle. The targets move by up to ±30 % of their
/// nominal step (irregular, as ISO 230-2 recommends).
pub(crate) fn case(lead_mm: f64, seed: u64, in_both: bool) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(lead_mm.to_bits());
    let count = Uniform::new_inclusive(19usize, 25)
        .unwrap()
        .sample(&mut rng);
    let span = draw(&mut rng, 600.0, 1000.0);
    let amplitude_um = draw(&mut rng, 1.5, 3.0);
    let sigma_um = draw(&mut rng, 0.3, 0.6);
    let phase_rad = draw(&mut rng, 0.0, std::f64::consts::TAU);
    let jitter = 0.3 * span / (count - 1) as f64;
    let tests = if in_both { "" } else { "tests = [\"after\"]\n" };
    let effect = if lead_mm > 0.0 {
        format!(
            "[[effect]]\nkind = \"periodic\"\nperiod_mm = {lead_mm}\namplitude_um = {amplitude_um}\nphase_rad = {phase_rad}\n{tests}"
        )
    } else {
        String::new()
    };
    let truth = format!(
        "[cycle]\nstart_mm = 0.0\nend_mm = {span}\ncount = {count}\njitter_mm = {jitter}\nruns = 5\nstart = \"2026-11-20 09:00:00\"\n\n\
         [error]\nscale_um_per_m = 9.5\nperiodic = [{{ period_mm = 300.0, amplitude_um = 2.0, phase_rad = 0.4 }}]\n\n\
         [noise]\nsigma_um = {sigma_um}\n\n{effect}"
    );
    Case {
        truth,
        period_mm: lead_mm,
        amplitude_um,
    }
}

/// The first test, a mean table at its targets, the re-test with the table
/// applied, and the diagnosis with the axis' known periods.
fn run(case: &Case, seed: u64, known: &[KnownPeriod]) -> Diagnosis {
    let truth = Truth::from_toml_str(&case.truth).unwrap();
    let (before, table, after) = synth_loop(&truth, seed);
    let input = DiagnoseInput {
        angle: Default::default(),
        after: &after,
        before: Some(&before),
        table: Some(&table),
        backlash_set: false,
        angular: None,
        known_periods: known,
        timing: CycleTiming::ASSUMED,
        standard: &ISO_230_2,
    };
    diagnose(&input).unwrap()
}

/// What the diagnosis made of a case: `None` when found within 2 % and 10 %.
fn miss(case: &Case, d: &Diagnosis) -> Option<String> {
    let found = d.accepted.iter().find_map(|a| match a.effect {
        Effect::Periodic(p) => Some(p),
        _ => None,
    });
    match found {
        Some(Periodic {
            period, amplitude, ..
        }) if (period / case.period_mm - 1.0).abs() <= 0.02
            && (amplitude / case.amplitude_um - 1.0).abs() <= 0.10 =>
        {
            None
        }
        _ => Some(format!(
            "truth {:.2} mm {:.2} µm: accepted {:?}, rejected {:?}",
            case.period_mm,
            case.amplitude_um,
            d.accepted.iter().map(|a| &a.effect).collect::<Vec<_>>(),
            d.rejected
                .iter()
                .filter(|r| r.kind.name() == "periodic")
                .map(|r| &r.why)
                .collect::<Vec<_>>()
        )),
    }
}

/// A seed and the other kinds accepted in it.
type Extra = (u64, Vec<&'static str>);

/// The seeds (1..=20) in which a lead's error is missed, with or without the
/// lead given as a known period,
/// and the seeds where another kind was accepted beside it.
fn misses(lead_mm: f64, with_lead: bool, in_both: bool) -> (Vec<(u64, String)>, Vec<Extra>) {
    let known = [KnownPeriod::screw_lead(lead_mm)];
    let known: &[KnownPeriod] = if with_lead { &known } else { &[] };
    let results: Vec<(u64, Option<String>, Vec<&'static str>)> = (1..=SEEDS)
        .into_par_iter()
        .map(|seed| {
            let case = case(lead_mm, seed, in_both);
            let d = run(&case, seed, known);
            let others = d
                .accepted
                .iter()
                .map(|a| a.effect.kind().name())
                .filter(|k| *k != "periodic")
                .collect();
            (seed, miss(&case, &d), others)
        })
        .collect();
    let mut missed = Vec::new();
    let mut extras = Vec::new();
    for (seed, why, others) in results {
        if let Some(why) = why {
            missed.push((seed, why));
        }
        if !others.is_empty() {
            extras.push((seed, others));
        }
    }
    (missed, extras)
}

/// Each lead over the seeds, the error in the re-test only and in both
/// tests: at most `allowed` misses of 20. Beside it another kind may be
/// accepted by chance, in at most 10 % of the runs. Measured: in 7 of the
/// 120 runs with or without the profile, a reversal of 0.2–0.4 µm (seeds 5
/// and 10, whose noise the synthesis draws the same for every lead) and once
/// a scale of 0.74 µm/m (lead 15 mm in both tests, seed 17, p = 0.0017):
/// above issue 6's 5 %, from the gates of those kinds, not the periodic's.
fn check(with_lead: bool, allowed: usize) {
    let mut extras = Vec::new();
    for in_both in [false, true] {
        for lead in LEADS_MM {
            let (missed, extra) = misses(lead, with_lead, in_both);
            assert!(
                missed.len() <= allowed,
                "lead {lead} mm, profile {with_lead}, in both tests {in_both}: missed {} of {SEEDS}: {missed:#?}",
                missed.len()
            );
            extras.extend(
                extra
                    .into_iter()
                    .map(|(seed, kinds)| (lead, in_both, seed, kinds)),
            );
        }
    }
    assert!(
        extras.len() * 10 <= 2 * LEADS_MM.len() * SEEDS as usize,
        "another kind accepted beside the periodic error in {extras:?}"
    );
}

#[test]
fn a_lead_error_between_irregular_targets_is_found_in_18_of_20() {
    // Measured: 20 of 20 for each lead, in the re-test only and in both tests (seeds 1–20).
    check(false, 2);
}

#[test]
fn a_lead_error_given_by_the_profile_is_found_in_20_of_20() {
    check(true, 0);
}

#[test]
fn clean_irregular_retests_give_no_false_alarm_in_100() {
    // With and without a lead in the profile: neither may conjure a periodic
    // error. Other kinds are held to issue 6's clean-data criterion (at most
    // 5 of 100); at these settings an outlier run is accepted in seeds 74 and
    // 87 (offsets of 0.27 and 0.42 µm, false-alarm probability 0.0015 and 0.002).
    let known = [KnownPeriod::screw_lead(15.0)];
    let alarms: Vec<(u64, bool, Vec<&'static str>)> = (1..=100u64)
        .into_par_iter()
        .flat_map_iter(|seed| {
            let case = case(0.0, seed, false);
            [false, true].into_iter().filter_map(move |with_lead| {
                let known: &[KnownPeriod] = if with_lead { &known } else { &[] };
                let d = run(&case, seed, known);
                (!d.accepted.is_empty()).then(|| {
                    (
                        seed,
                        with_lead,
                        d.accepted.iter().map(|a| a.effect.kind().name()).collect(),
                    )
                })
            })
        })
        .collect();
    let periodic: Vec<_> = alarms
        .iter()
        .filter(|(_, _, kinds)| kinds.contains(&"periodic"))
        .collect();
    assert!(periodic.is_empty(), "periodic false alarms: {periodic:?}");
    let seeds: std::collections::BTreeSet<u64> = alarms.iter().map(|a| a.0).collect();
    assert!(seeds.len() <= 5, "false alarms: {alarms:?}");
}

/// Through the binary: the machine profile's screw lead reaches `diagnose`,
/// which finds the error at it and says so.
#[test]
fn diagnose_takes_the_screw_lead_from_the_machine_profile() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let case = case(15.0, 3, true);
    std::fs::write(path("truth.toml"), &case.truth).unwrap();
    let ok = |args: &[&str]| {
        let run = crate::util::axcomp(args);
        assert_eq!(run.code, 0, "axcomp {}: {}", args.join(" "), run.stderr);
        run.stdout
    };
    synth_loop_files(dir.path(), Path::new(&path("truth.toml")), Some("3"));
    let diagnose = |machine: bool| -> serde_json::Value {
        let mut args = vec![
            "diagnose".to_string(),
            "--after".into(),
            path("after.rtl"),
            "--before".into(),
            path("before.rtl"),
            "--table".into(),
            path("X.COM"),
            "--json".into(),
        ];
        if machine {
            // Seed 001's VC1810: a 15 mm lead on every axis (Tab. 7).
            let profile = crate::util::root().join("fixtures/machines/vc1810.toml");
            args.extend(["--machine".into(), profile.to_str().unwrap().to_string()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        serde_json::from_str(&ok(&args)).unwrap()
    };
    let periodic = |json: &serde_json::Value| {
        json["effects"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["kind"] == "periodic")
            .cloned()
            .unwrap_or_else(|| panic!("{json:#}"))
    };
    let with = periodic(&diagnose(true));
    assert_eq!(with["params"]["period_mm"], 15.0);
    let amplitude = with["params"]["amplitude_um"].as_f64().unwrap();
    assert!(
        (amplitude / case.amplitude_um - 1.0).abs() < 0.1,
        "{with:#}"
    );
    let notes = with["warnings"].to_string();
    assert!(
        notes.contains("the screw lead the machine profile gives (15 mm)"),
        "{notes}"
    );
    assert!(notes.contains("in both tests"), "{notes}");
    // Without the profile the scan finds it too, not exactly at the lead, and says nothing of a profile.
    let without = periodic(&diagnose(false));
    let period = without["params"]["period_mm"].as_f64().unwrap();
    assert!((period / 15.0 - 1.0).abs() < 0.02, "{without:#}");
    assert!(!without["warnings"].to_string().contains("machine profile"));
}

/// Targets 25 mm apart moved by at most ±0.5 mm cannot tell a 15 mm lead
/// from its alias at 1/(1/15 − 1/25) = 37.5 mm: the diagnosis says so, and
/// with the lead in the profile takes the lead.
#[test]
fn nearly_even_targets_name_the_periods_they_cannot_separate() {
    let truth = "[cycle]\nstart_mm = 0.0\nend_mm = 750.0\ncount = 31\njitter_mm = 0.5\nruns = 5\n\n\
                 [error]\nscale_um_per_m = 9.5\n\n[noise]\nsigma_um = 0.3\n\n\
                 [[effect]]\nkind = \"periodic\"\nperiod_mm = 15.0\namplitude_um = 2.0\nphase_rad = 0.3\ntests = [\"after\"]\n";
    let case = Case {
        truth: truth.to_string(),
        period_mm: 15.0,
        amplitude_um: 2.0,
    };
    let d = run(&case, 1, &[KnownPeriod::screw_lead(15.0)]);
    assert_eq!(miss(&case, &d), None);
    let periodic = d
        .accepted
        .iter()
        .find(|a| a.effect.kind().name() == "periodic")
        .unwrap();
    let notes = periodic.warnings.join("\n");
    let alias: f64 = notes
        .split("cannot tell a period of 15.00 mm from ")
        .nth(1)
        .and_then(|rest| rest.split(" mm").next())
        .and_then(|number| number.parse().ok())
        .unwrap_or_else(|| panic!("{notes}"));
    assert!((alias / 37.5 - 1.0).abs() < 0.005, "{notes}");
    assert!(notes.contains("the profile's period was taken"), "{notes}");
}
