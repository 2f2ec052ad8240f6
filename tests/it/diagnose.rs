//! `diagnose` against synthetic re-tests whose truth is known, and on the
//! real ESS/PSI files.
//!
//! Issue 6's criteria: for each effect kind, present in the re-test but not
//! declared in the model, the diagnosis names the kind and estimates its
//! parameter within 10 % (or 0.2 in its unit, whichever is larger) over 20
//! seeds, at realistic noise, also with two effects at once; on clean data it
//! accepts an effect in at most 5 % of 100 seeds; a step or a sag (no kind in
//! the list) is reported as unexplained structure, never as a wrong kind.
//!
//! "Realistic noise (repeatability 0.5–2 µm)" is read as the ISO 230-2
//! repeatability R = 4σ: σ cycles through 0.125, 0.25 and 0.5 µm.

use approx::abs_diff_eq;
use axcomp::cycle::CycleTiming;
use axcomp::diagnose::{AngularProfile, DiagnoseInput, Diagnosis, diagnose};
use axcomp::effects::{Abbe, Drift, Effect, OutlierRun, Periodic, Reversal, Scale};
use axcomp::evaluate::ISO_230_2;
use axcomp::measurement::Direction;
use axcomp::read::read_path;
use axcomp::synth::{self, EffectSpec, Truth};

use crate::util::{shared_files, synth_loop};

const SIGMAS_UM: [f64; 3] = [0.125, 0.25, 0.5];
const SEEDS: u64 = 20;

/// The first test, a mean table from it at its targets, the re-test with the
/// table applied, and the diagnosis (with the Abbe effect's angular profile
/// when asked for, as an angular measurement at 16 points would give it).
fn run(truth_text: &str, seed: u64, angular: bool) -> Diagnosis {
    let truth = Truth::from_toml_str(truth_text).unwrap_or_else(|e| panic!("{e}\n{truth_text}"));
    let (before, table, after) = synth_loop(&truth, seed);
    let profile = angular.then(|| {
        let targets = before.targets();
        let stroke = (targets[0], targets[targets.len() - 1]);
        let positions_mm: Vec<f64> = (0..=15)
            .map(|k| stroke.0 + (stroke.1 - stroke.0) * f64::from(k) / 15.0)
            .collect();
        let angle = truth
            .effects
            .iter()
            .find_map(|e| {
                if let EffectSpec::Abbe { angle_urad, .. } = e {
                    Some(*angle_urad)
                } else {
                    None
                }
            })
            .unwrap_or(0.0);
        let angle_urad = positions_mm
            .iter()
            .map(|&x| synth::abbe_angle_urad(angle, x, stroke))
            .collect();
        AngularProfile {
            positions_mm,
            angle_urad,
        }
    });
    let input = DiagnoseInput {
        angle: Default::default(),
        after: &after,
        before: Some(&before),
        table: Some(&table),
        backlash_set: false,
        angular: profile.as_ref(),
        known_periods: &[],
        timing: CycleTiming::ASSUMED,
        standard: &ISO_230_2,
    };
    let diagnosis = diagnose(&input).unwrap();
    assert_found_or_not(&diagnosis);
    diagnosis
}

/// A kind is under Found or under Not found, never both (issue 11).
fn assert_found_or_not(d: &Diagnosis) {
    for a in &d.accepted {
        let kind = a.effect.kind();
        assert!(
            d.rejected.iter().all(|r| r.kind != kind),
            "{} is accepted and rejected: {:?}",
            kind.name(),
            d.rejected
        );
    }
}

/// The re-test alone (no first test, no table): structure between runs and
/// periodic errors in its own curve.
fn run_alone(truth_text: &str, seed: u64) -> Diagnosis {
    let truth = Truth::from_toml_str(truth_text).unwrap();
    let (_, _, after) = synth_loop(&truth, seed);
    let input = DiagnoseInput {
        angle: Default::default(),
        after: &after,
        before: None,
        table: None,
        backlash_set: false,
        angular: None,
        known_periods: &[],
        timing: CycleTiming::ASSUMED,
        standard: &ISO_230_2,
    };
    let diagnosis = diagnose(&input).unwrap();
    assert_found_or_not(&diagnosis);
    diagnosis
}

/// A 750 mm axis, 31 irregular targets, 5 runs each way; `cycle` adds to [cycle].
fn truth(sigma_um: f64, cycle: &str, effects: &str) -> String {
    format!(
        "[cycle]\nstart_mm = 0.0\nend_mm = 750.0\ncount = 31\njitter_mm = 8.0\nruns = 5\nstart = \"2026-11-20 09:00:00\"\n{cycle}\n\
         [error]\nscale_um_per_m = 9.5\nperiodic = [{{ period_mm = 300.0, amplitude_um = 2.0, phase_rad = 0.4 }}]\n\
         [noise]\nsigma_um = {sigma_um}\n\n{effects}"
    )
}

/// A screw with a 5 mm lead error: the first test at an even 25 mm spacing
/// (which aliases it away), the re-test at 1.5 mm steps over 150 mm.
fn periodic_truth(sigma_um: f64, effects: &str) -> String {
    format!(
        "[cycle]\nstart_mm = 0.0\nend_mm = 750.0\ncount = 31\njitter_mm = 0.0\nruns = 5\n\
         [cycle.after]\nstart_mm = 0.0\nend_mm = 150.0\ncount = 101\njitter_mm = 0.4\nruns = 3\n\
         [error]\nscale_um_per_m = 9.5\n[noise]\nsigma_um = {sigma_um}\n\n\
         [[effect]]\nkind = \"periodic\"\nperiod_mm = 5.0\namplitude_um = 1.0\nphase_rad = 0.7\n{effects}"
    )
}

/// Within 10 % of `expected`, and never closer than 0.2 asked.
fn within(actual: f64, expected: f64) -> bool {
    abs_diff_eq!(actual, expected, epsilon = (0.1 * expected.abs()).max(0.2))
}

/// Finds the effect of a kind among the accepted ones.
fn find<'a>(d: &'a Diagnosis, kind: &str) -> Option<&'a Effect> {
    d.accepted
        .iter()
        .map(|a| &a.effect)
        .find(|e| e.kind().name() == kind)
}

/// An effect kind expected in a diagnosis, and the test of its parameters.
type Expected<'a> = (&'a str, &'a dyn Fn(&Effect) -> bool);

/// Extra effects accepted beside the expected ones, over many runs: a
/// diagnosis may, as on clean data, accept a small extra effect by chance,
/// at most in 5 % of the runs (the clean-data criterion), never instead of
/// the expected ones.
#[derive(Default)]
struct Extras {
    runs: usize,
    extra: Vec<String>,
}

impl Extras {
    fn check(&mut self, name: &str, d: &Diagnosis, expected: &[Expected], seed: u64, sigma: f64) {
        let found: Vec<&str> = d.accepted.iter().map(|a| a.effect.kind().name()).collect();
        for (kind, parameter_ok) in expected {
            let effect = find(d, kind).unwrap_or_else(|| panic!("{name}, seed {seed}, σ {sigma}: {kind} not found; accepted {found:?}, rejected {:?}", d.rejected));
            assert!(
                parameter_ok(effect),
                "{name}, seed {seed}, σ {sigma}: {effect:?}"
            );
        }
        for accepted in &d.accepted {
            assert!(!accepted.explanation.is_empty());
        }
        self.runs += 1;
        if found.len() > expected.len() {
            self.extra.push(format!(
                "{name}, seed {seed}, σ {sigma}: {:?}",
                d.accepted.iter().map(|a| &a.effect).collect::<Vec<_>>()
            ));
        }
    }

    fn finish(self) {
        assert!(
            self.extra.len() * 20 <= self.runs,
            "extra effects in {} of {} runs: {:#?}",
            self.extra.len(),
            self.runs,
            self.extra
        );
    }
}

fn for_each_seed(mut body: impl FnMut(u64, f64)) {
    for seed in 1..=SEEDS {
        body(seed, SIGMAS_UM[(seed % 3) as usize]);
    }
}

#[test]
fn reversal_is_found_and_measured() {
    // A reversal that appears after the first test (which the prediction
    // carries): e.g. a worn nut, or friction of a cold axis.
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        let d = run(
            &truth(
                sigma,
                "",
                "[[effect]]\nkind = \"reversal\"\nB_um = -4.0\ntests = [\"after\"]\n",
            ),
            seed,
            false,
        );
        extras.check(
            "reversal",
            &d,
            &[(
                "reversal",
                &|e| matches!(e, Effect::Reversal(Reversal { b }) if within(*b, -4.0)),
            )],
            seed,
            sigma,
        );
        assert!(d.residual_after.rms < d.residual_before.rms);
    });
    extras.finish();
}

#[test]
fn a_reversal_both_tests_measured_is_carried_and_only_its_change_is_found() {
    let mut carried_as_change = Vec::new();
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        // −3 µm in both tests: the prediction carries it, so no reversal is reported.
        let d = run(
            &truth(sigma, "", "[[effect]]\nkind = \"reversal\"\nB_um = -3.0\n"),
            seed,
            false,
        );
        if d.accepted
            .iter()
            .any(|a| a.effect.kind().name() == "reversal")
        {
            carried_as_change.push(seed);
        }
        let rejected = d
            .rejected
            .iter()
            .find(|r| r.kind.name() == "reversal")
            .expect("the reversal is looked for");
        let carried: f64 = rejected
            .why
            .strip_prefix("no change since the first test, whose B̄ = ")
            .and_then(|rest| rest.split(' ').next())
            .and_then(|number| number.parse().ok())
            .unwrap_or_else(|| panic!("seed {seed}: {}", rejected.why));
        assert!((carried + 3.0).abs() < 0.3, "seed {seed}: {}", rejected.why);
        // −3 µm in both and 2 µm more in the re-test: the change, −2 µm, is found.
        let grown = "[[effect]]\nkind = \"reversal\"\nB_um = -3.0\n\n\
                     [[effect]]\nkind = \"reversal\"\nB_um = -2.0\ntests = [\"after\"]\n";
        let d = run(&truth(sigma, "", grown), seed, false);
        extras.check(
            "grown reversal",
            &d,
            &[(
                "reversal",
                &|e| matches!(e, Effect::Reversal(Reversal { b }) if within(*b, -2.0)),
            )],
            seed,
            sigma,
        );
    });
    assert!(
        carried_as_change.is_empty(),
        "a measured, unchanged reversal reported as a change in seeds {carried_as_change:?}"
    );
    extras.finish();
}

#[test]
fn thermal_scale_is_found_and_measured() {
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        let d = run(
            &truth(
                sigma,
                "",
                "[[effect]]\nkind = \"scale\"\nscale_um_per_m = 6.0\ntests = [\"after\"]\n",
            ),
            seed,
            false,
        );
        extras.check(
            "scale",
            &d,
            &[(
                "scale",
                &|e| matches!(e, Effect::Scale(Scale { scale_um_per_m }) if within(*scale_um_per_m, 6.0)),
            )],
            seed,
            sigma,
        );
    });
    extras.finish();
}

#[test]
fn warm_up_drift_is_found_and_measured() {
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        let d = run(
            &truth(
                sigma,
                "dwell_s = 6.0\n",
                "[[effect]]\nkind = \"drift\"\nrate_um_per_h = 15.0\ntests = [\"after\"]\n",
            ),
            seed,
            false,
        );
        extras.check(
            "drift",
            &d,
            &[(
                "drift",
                &|e| matches!(e, Effect::Drift(Drift::PerHour { rate_um_per_h }) if within(*rate_um_per_h, 15.0)),
            )],
            seed,
            sigma,
        );
    });
    extras.finish();
}

#[test]
fn an_outlier_run_is_found_and_measured() {
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        let effect = "[[effect]]\nkind = \"outlier-run\"\nrun = 1\ndirection = \"down\"\noffset_um = 5.0\ntests = [\"after\"]\n";
        let d = run(&truth(sigma, "", effect), seed, false);
        let ok = |e: &Effect| matches!(e, Effect::OutlierRun(OutlierRun { run: 1, direction: Direction::Down, offset }) if within(*offset, 5.0));
        extras.check("outlier-run", &d, &[("outlier-run", &ok)], seed, sigma);
    });
    extras.finish();
}

#[test]
fn a_screw_lead_error_is_found_and_measured() {
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        let d = run(&periodic_truth(sigma, ""), seed, false);
        let ok = |e: &Effect| matches!(e, Effect::Periodic(Periodic { period, amplitude, .. }) if within(*period, 5.0) && within(*amplitude, 1.0));
        extras.check("periodic", &d, &[("periodic", &ok)], seed, sigma);
    });
    extras.finish();
}

#[test]
fn a_screw_lead_error_is_found_in_the_retest_alone() {
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        let d = run_alone(&periodic_truth(sigma, ""), seed);
        let ok = |e: &Effect| matches!(e, Effect::Periodic(Periodic { period, amplitude, .. }) if within(*period, 5.0) && within(*amplitude, 1.0));
        extras.check("periodic alone", &d, &[("periodic", &ok)], seed, sigma);
    });
    extras.finish();
}

#[test]
fn a_clean_retest_alone_rarely_accepts_an_effect() {
    // The dense re-test of the screw case without the screw error: a smooth
    // curve (9.5 µm/m left by the table's interpolation, nothing periodic).
    let mut false_alarms = Vec::new();
    for seed in 1..=60u64 {
        let sigma = SIGMAS_UM[(seed % 3) as usize];
        let text = periodic_truth(sigma, "").replace(
            "kind = \"periodic\"\nperiod_mm = 5.0\namplitude_um = 1.0",
            "kind = \"periodic\"\nperiod_mm = 5.0\namplitude_um = 0.0",
        );
        let d = run_alone(&text, seed);
        if !d.accepted.is_empty() {
            false_alarms.push((
                seed,
                d.accepted
                    .iter()
                    .map(|a| a.effect.kind().name())
                    .collect::<Vec<_>>(),
            ));
        }
    }
    assert!(
        false_alarms.len() * 20 <= 60,
        "{} of 60 clean seeds accepted an effect: {false_alarms:?}",
        false_alarms.len()
    );
}

#[test]
fn an_abbe_offset_is_found_and_measured_with_angular_data() {
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        let effect = "[[effect]]\nkind = \"abbe\"\noffset_mm = 100.0\nangle_urad = 40.0\ntests = [\"after\"]\n";
        let d = run(&truth(sigma, "", effect), seed, true);
        extras.check(
            "abbe",
            &d,
            &[(
                "abbe",
                &|e| matches!(e, Effect::Abbe(Abbe { offset_mm, .. }) if within(*offset_mm, 100.0)),
            )],
            seed,
            sigma,
        );
        // Without angular data the same bow is unexplained structure, not a wrong kind.
        let blind = run(&truth(sigma, "", effect), seed, false);
        assert!(
            blind.accepted.is_empty() && blind.unexplained.significant,
            "seed {seed}: {:?}",
            blind.accepted
        );
    });
    extras.finish();
}

#[test]
fn two_effects_at_once() {
    let mut extras = Extras::default();
    for_each_seed(|seed, sigma| {
        let effects = "[[effect]]\nkind = \"reversal\"\nB_um = -3.0\ntests = [\"after\"]\n\n[[effect]]\nkind = \"drift\"\nrate_um_per_h = 15.0\ntests = [\"after\"]\n";
        let d = run(&truth(sigma, "dwell_s = 6.0\n", effects), seed, false);
        extras.check(
            "reversal + drift",
            &d,
            &[
                ("reversal", &|e| matches!(e, Effect::Reversal(Reversal { b }) if within(*b, -3.0))),
                ("drift", &|e| matches!(e, Effect::Drift(Drift::PerHour { rate_um_per_h }) if within(*rate_um_per_h, 15.0))),
            ],
            seed,
            sigma,
        );
        let effects = "[[effect]]\nkind = \"scale\"\nscale_um_per_m = 8.0\ntests = [\"after\"]\n\n[[effect]]\nkind = \"outlier-run\"\nrun = 2\ndirection = \"up\"\noffset_um = -4.0\ntests = [\"after\"]\n";
        let d = run(&truth(sigma, "", effects), seed, false);
        extras.check(
            "scale + outlier-run",
            &d,
            &[
                ("scale", &|e| matches!(e, Effect::Scale(Scale { scale_um_per_m }) if within(*scale_um_per_m, 8.0))),
                ("outlier-run", &|e| matches!(e, Effect::OutlierRun(OutlierRun { run: 2, direction: Direction::Up, offset }) if within(*offset, -4.0))),
            ],
            seed,
            sigma,
        );
        let d = run(
            &periodic_truth(
                sigma,
                "[[effect]]\nkind = \"reversal\"\nB_um = -2.0\ntests = [\"after\"]\n",
            ),
            seed,
            false,
        );
        extras.check(
            "periodic + reversal",
            &d,
            &[
                ("periodic", &|e| matches!(e, Effect::Periodic(Periodic { period, amplitude, .. }) if within(*period, 5.0) && within(*amplitude, 1.0))),
                ("reversal", &|e| matches!(e, Effect::Reversal(Reversal { b }) if within(*b, -2.0))),
            ],
            seed,
            sigma,
        );
    });
    extras.finish();
}

#[test]
fn clean_retests_rarely_accept_an_effect() {
    let mut false_alarms = Vec::new();
    for seed in 1..=100u64 {
        let sigma = SIGMAS_UM[(seed % 3) as usize];
        let d = run(&truth(sigma, "", ""), seed, false);
        // What is left is the noise put in: σ estimated from 310 readings within 25 %.
        assert!(
            (d.noise / sigma - 1.0).abs() < 0.25,
            "seed {seed}: noise {} µm for σ {sigma}",
            d.noise
        );
        if !d.accepted.is_empty() {
            false_alarms.push((
                seed,
                d.accepted
                    .iter()
                    .map(|a| a.effect.kind().name())
                    .collect::<Vec<_>>(),
            ));
        }
    }
    assert!(
        false_alarms.len() <= 5,
        "{} of 100 clean seeds accepted an effect: {false_alarms:?}",
        false_alarms.len()
    );
}

#[test]
fn a_step_or_a_sag_is_unexplained_not_a_wrong_kind() {
    for_each_seed(|seed, sigma| {
        for effect in [
            "[[effect]]\nkind = \"step\"\nposition_mm = 400.0\nstep_um = 3.0\ntests = [\"after\"]\n",
            "[[effect]]\nkind = \"quadratic\"\nsag_um = 3.0\ntests = [\"after\"]\n",
        ] {
            let d = run(&truth(sigma, "", effect), seed, false);
            let positional: Vec<&str> = d
                .accepted
                .iter()
                .map(|a| a.effect.kind().name())
                .filter(|k| ["scale", "periodic", "abbe"].contains(k))
                .collect();
            assert!(
                positional.is_empty(),
                "seed {seed}, σ {sigma}, {effect}: forced into {positional:?}"
            );
            assert!(
                d.unexplained.significant,
                "seed {seed}, σ {sigma}, {effect}: structure not reported"
            );
            assert!(!d.unexplained.targets.is_empty());
        }
    });
}

/// The real ESS/PSI tests, without a first test: structure between runs only.
#[test]
fn real_ess_files_get_a_stated_diagnosis() {
    let mut files = shared_files("ecmc/ecmccfg", ".dat");
    files.extend(shared_files("ecmc/ecmc_target_muts_logger", ".dat"));
    files.extend(shared_files("ecmc/ecmccomgui", ".dat"));
    for path in &files {
        let m = read_path(path, None).unwrap().measurement;
        let input = DiagnoseInput {
            angle: Default::default(),
            after: &m,
            before: None,
            table: None,
            backlash_set: false,
            angular: None,
            known_periods: &[],
            timing: CycleTiming::ASSUMED,
            standard: &ISO_230_2,
        };
        let d = diagnose(&input).unwrap();
        assert_found_or_not(&d);
        for effect in &d.accepted {
            assert!(
                !effect.explanation.is_empty()
                    && !matches!(
                        effect.effect,
                        Effect::Scale(Scale { .. }) | Effect::Periodic(Periodic { .. })
                    )
            );
        }
        // Position-dependent kinds are not looked for without a prediction, and say so.
        assert!(
            d.rejected
                .iter()
                .any(|r| r.kind.name() == "scale" && r.why.contains("--before"))
        );
        if path
            .to_string_lossy()
            .ends_with("examples__mcu1025_fat_sat__report.md_ISO230.dat")
        {
            // The start-up run (anchors-and-standards.md §3.1, DS2): run 1↑ here.
            let outlier = d.accepted.iter().find_map(|a| {
                if let Effect::OutlierRun(OutlierRun {
                    run,
                    direction,
                    offset,
                }) = a.effect
                {
                    Some((run, direction, offset))
                } else {
                    None
                }
            });
            assert!(
                matches!(outlier, Some((1, Direction::Up, _))),
                "{:?}",
                d.accepted
            );
        }
    }
}

#[test]
fn tests_of_different_axes_are_refused() {
    let truth = Truth::from_toml_str(&truth(0.25, "", "")).unwrap();
    let mut before = synth::before(&truth, 1).unwrap();
    let after = before.clone();
    before.set_axis("Y");
    let input = DiagnoseInput {
        angle: Default::default(),
        after: &after,
        before: Some(&before),
        table: None,
        backlash_set: false,
        angular: None,
        known_periods: &[],
        timing: CycleTiming::ASSUMED,
        standard: &ISO_230_2,
    };
    let error = diagnose(&input).unwrap_err();
    assert_eq!(
        error.to_string(),
        "the first test is of axis Y, the re-test of axis X: a re-test must be of the axis of the first test, and a new test"
    );
}

/// Issue 11: on the real file with a start-up run, `diagnose` listed
/// outlier-run under Found (run 1↑) and under Not found (the next run failed
/// the gate). Through the binary, in the terminal and in JSON.
#[test]
fn an_accepted_kind_is_not_also_listed_as_not_found() {
    let file =
        crate::util::shared_data("ecmc/ecmccfg/examples__mcu1025_fat_sat__report.md_ISO230.dat");
    let run = crate::util::axcomp(["diagnose", "--after", file.to_str().unwrap(), "--json"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let kinds = |key: &str| -> Vec<String> {
        json[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["kind"].as_str().unwrap().to_string())
            .collect()
    };
    let (found, not_found) = (kinds("effects"), kinds("rejected"));
    assert_eq!(found, ["outlier-run"], "the start-up run 1↑");
    assert!(
        !not_found.contains(&"outlier-run".to_string()),
        "{not_found:?}"
    );
    // The other kinds are still said to be looked for and not found.
    assert!(not_found.contains(&"drift".to_string()), "{not_found:?}");

    let run = crate::util::axcomp(["diagnose", "--after", file.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let (found, rest) = run.stdout.split_once("\nNot found\n").unwrap();
    let not_found = rest.split("\n\n").next().unwrap();
    assert!(found.contains("\n  outlier-run "), "{found}");
    assert!(!not_found.contains("outlier-run"), "{not_found}");
    assert!(not_found.contains("  drift "), "{not_found}");
}

/// README's rates at higher noise (σ = 1 and 2 µm, R = 4 and 8 µm), seeds
/// 1–20 for each kind and 1–40 clean. Measured: every kind found in 20 of
/// 20; within 10 % at σ = 1 µm in 19–20 (scale, outlier run, Abbe 19), at
/// σ = 2 µm in 11–19 (outlier run 11, Abbe 13, scale 15, reversal and drift
/// 18, periodic 19); no effect accepted on the 40 clean seeds at either.
/// About two minutes on two busy cores.
#[test]
fn at_higher_noise_every_kind_is_still_found() {
    use rayon::prelude::*;
    type Check = (
        &'static str,
        String,
        bool,
        &'static (dyn Fn(&Effect) -> bool + Sync),
    );
    let after = |effect: &str| format!("[[effect]]\n{effect}\ntests = [\"after\"]\n");
    let cases: Vec<Check> = vec![
        (
            "reversal",
            after("kind = \"reversal\"\nB_um = -4.0"),
            false,
            &|e| matches!(e, Effect::Reversal(Reversal { b }) if within(*b, -4.0)),
        ),
        (
            "scale",
            after("kind = \"scale\"\nscale_um_per_m = 6.0"),
            false,
            &|e| matches!(e, Effect::Scale(Scale { scale_um_per_m }) if within(*scale_um_per_m, 6.0)),
        ),
        (
            "drift",
            after("kind = \"drift\"\nrate_um_per_h = 15.0"),
            false,
            &|e| matches!(e, Effect::Drift(Drift::PerHour { rate_um_per_h }) if within(*rate_um_per_h, 15.0)),
        ),
        (
            "outlier-run",
            after("kind = \"outlier-run\"\nrun = 1\ndirection = \"down\"\noffset_um = 5.0"),
            false,
            &|e| matches!(e, Effect::OutlierRun(OutlierRun { run: 1, direction: Direction::Down, offset }) if within(*offset, 5.0)),
        ),
        (
            "abbe",
            after("kind = \"abbe\"\noffset_mm = 100.0\nangle_urad = 40.0"),
            true,
            &|e| matches!(e, Effect::Abbe(Abbe { offset_mm, .. }) if within(*offset_mm, 100.0)),
        ),
        (
            "periodic",
            String::new(),
            false,
            &|e| matches!(e, Effect::Periodic(Periodic { period, amplitude, .. }) if within(*period, 5.0) && within(*amplitude, 1.0)),
        ),
    ];
    for (sigma, least_within) in [(1.0, 19), (2.0, 11)] {
        for (kind, effect, angular, ok) in &cases {
            let results: Vec<(bool, bool)> = (1..=SEEDS)
                .into_par_iter()
                .map(|seed| {
                    let text = match *kind {
                        "periodic" => periodic_truth(sigma, ""),
                        "drift" => truth(sigma, "dwell_s = 6.0\n", effect),
                        _ => truth(sigma, "", effect),
                    };
                    let found = find(&run(&text, seed, *angular), kind).cloned();
                    (found.is_some(), found.as_ref().is_some_and(ok))
                })
                .collect();
            let found = results.iter().filter(|r| r.0).count();
            let within = results.iter().filter(|r| r.1).count();
            assert_eq!(found, 20, "σ {sigma} µm, {kind}: found in {found} of 20");
            assert!(
                within >= least_within,
                "σ {sigma} µm, {kind}: within 10 % in {within} of 20"
            );
        }
        let alarms: Vec<u64> = (1..=40u64)
            .into_par_iter()
            .filter(|&seed| !run(&truth(sigma, "", ""), seed, false).accepted.is_empty())
            .collect();
        assert!(
            alarms.is_empty(),
            "σ {sigma} µm: false alarms in seeds {alarms:?}"
        );
    }
}

/// With a bidirectional table the prediction does not carry the first
/// test's B̄ but what the table leaves of it: a reversal unchanged is said
/// against that, not against the first test's B̄.
#[test]
fn an_unchanged_reversal_under_a_bidirectional_table_quotes_the_predicted_b() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let truth_file = path("truth.toml");
    std::fs::write(
        &truth_file,
        truth(0.3, "", "[[effect]]\nkind = \"reversal\"\nB_um = -3.0\n"),
    )
    .unwrap();
    let ok = |args: &[&str]| {
        let run = crate::util::axcomp(args);
        assert_eq!(run.code, 0, "axcomp {}: {}", args.join(" "), run.stderr);
        run
    };
    let (before, table, after) = (path("before.rtl"), path("X.COM"), path("after.rtl"));
    ok(&[
        "synth",
        "--truth",
        &truth_file,
        "--seed",
        "3",
        "-o",
        &before,
    ]);
    ok(&[
        "convert",
        &before,
        "--controller",
        "tnc640",
        "--mode",
        "bidirectional",
        "-o",
        &table,
        "-q",
    ]);
    ok(&[
        "synth",
        "--truth",
        &truth_file,
        "--seed",
        "3",
        "-o",
        &path("before2.rtl"),
        "--table",
        &table,
        "--o2",
        &after,
    ]);
    let run = ok(&[
        "diagnose", "--after", &after, "--before", &before, "--table", &table, "--json",
    ]);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let predicted = json["figures_um"]["predicted"]["B_mean"].as_f64().unwrap();
    let first = crate::numbers::mean_reversal_um(
        &read_path(std::path::Path::new(&before), None)
            .unwrap()
            .measurement,
    );
    // By hand: the first test's −3 µm is in the table, the prediction near 0.
    assert!((first + 3.0).abs() < 0.3, "{first}");
    assert!(predicted.abs() < 0.3, "{predicted}");
    let why = json["rejected"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["kind"] == "reversal")
        .expect("the reversal is looked for")["why"]
        .as_str()
        .unwrap()
        .to_string();
    let expected = format!(
        "no change since the first test: its B̄ = {first:.2} µm less what the table takes out leaves the B̄ = {predicted:.2} µm the prediction carries ("
    );
    assert!(why.starts_with(&expected), "{why}\nexpected {expected}");
}
