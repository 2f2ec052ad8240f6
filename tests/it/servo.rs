//! `axcomp servo-sim` end to end: the thesis's circle figures through the
//! CLI, the ISO 230-2 cycle and its CSV read back by `evaluate`, and errors.
//! See: issue 5.

use crate::util::{axcomp, root};

fn json(args: &[&str]) -> serde_json::Value {
    let mut argv = vec!["servo-sim", "--json", "--quiet"];
    argv.extend_from_slice(args);
    let run = axcomp(argv);
    assert_eq!(run.code, 0, "stderr: {}", run.stderr);
    serde_json::from_str(&run.stdout).expect("servo-sim --json prints one object")
}

#[test]
fn circle_json_has_the_thesis_figures() {
    // Tab. 6.4, LuGre (C), 16 m/min: xe = 7 µm, Ix = 3.3 A; ye = 9 µm, Iy = 8.0 A.
    for (axis, error_um, current_a) in [("mcfv5050-x", 7.0, 3.3), ("mcfv5050-y", 9.0, 8.0)] {
        let report = json(&[
            "--axis",
            axis,
            "--friction",
            "lugre",
            "--test",
            "circle",
            "--feed-m-min",
            "16",
        ]);
        let circle = &report["circle"];
        let error = circle["reversal_error_um"].as_f64().unwrap();
        let current = circle["reversal_current_a"].as_f64().unwrap();
        assert!((error - error_um).abs() <= 1.0, "{axis}: {error} µm");
        assert!((current - current_a).abs() <= 0.2, "{axis}: {current} A");
        assert_eq!(report["friction_label"], "C");
        assert!(report["iso230_2"].is_null());
        assert!(circle["reversals"].as_array().unwrap().len() >= 2);
    }
}

#[test]
fn iso_cycle_csv_reads_back_with_the_same_figures() {
    let directory = tempfile::tempdir().unwrap();
    let csv = directory.path().join("sim.csv");
    let csv_arg = csv.to_str().unwrap();
    let args = [
        "--axis",
        "mcfv5050-x",
        "--friction",
        "classic",
        "--test",
        "iso230-2",
        "--targets",
        "3",
        "--last-mm",
        "20",
        "--runs",
        "2",
        "--dwell-s",
        "0.3",
        "--csv",
        csv_arg,
    ];
    let report = json(&args);
    let iso = &report["iso230_2"];
    assert_eq!(iso["readings"].as_array().unwrap().len(), 12);
    // Classic friction holds ≈ F_C = 90 N; through 100 N/µm that is ≈ 1.8 µm of B.
    let b = iso["figures_um"]["B"].as_f64().unwrap();
    assert!((1.0..2.6).contains(&b), "B = {b}");
    assert!(iso["figures_um"]["B_mean"].as_f64().unwrap() < 0.0);
    let closed_form = iso["reversal_from_friction_um"].as_f64().unwrap();
    assert!((closed_form - 1.79).abs() < 0.05, "{closed_form}");
    // The CSV is a measurement: evaluate gives the same B.
    let evaluated = crate::util::evaluate_json(&[csv.as_path()]);
    let b_read = evaluated["figures_um"]["B"].as_f64().unwrap();
    assert!((b_read - b).abs() < 1e-3, "{b_read} vs {b}");
    // An existing CSV is not replaced without --force.
    let mut argv = vec!["servo-sim", "--quiet"];
    argv.extend_from_slice(&args);
    let refused = axcomp(&argv);
    assert_eq!(refused.code, 2);
    assert!(refused.stderr.contains("--force"), "{}", refused.stderr);
    argv.push("--force");
    assert_eq!(axcomp(&argv).code, 0);
}

#[test]
fn a_user_axis_file_works_and_a_bad_one_says_where() {
    let directory = tempfile::tempdir().unwrap();
    let good = directory.path().join("axis.toml");
    let text = std::fs::read_to_string(root().join("fixtures/axes/mcfv5050-x.toml")).unwrap();
    std::fs::write(&good, text.replace("name = \"X\"", "name = \"U\"")).unwrap();
    let run = axcomp([
        "servo-sim",
        "--axis",
        good.to_str().unwrap(),
        "--friction",
        "power",
        "--test",
        "circle",
        "--circle-axis",
        "x",
        "--feed-m-min",
        "48",
        "--quiet",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stdout.contains("Reversal error"), "{}", run.stdout);
    // Without --circle-axis an axis named U cannot be placed on the circle.
    let unplaced = axcomp([
        "servo-sim",
        "--axis",
        good.to_str().unwrap(),
        "--friction",
        "power",
        "--test",
        "circle",
    ]);
    assert_eq!(unplaced.code, 2);
    assert!(
        unplaced.stderr.contains("--circle-axis"),
        "{}",
        unplaced.stderr
    );
    let bad = directory.path().join("bad.toml");
    std::fs::write(&bad, text.replace("mass_kg = 225.0", "mass_kg = \"heavy\"")).unwrap();
    let run = axcomp([
        "servo-sim",
        "--axis",
        bad.to_str().unwrap(),
        "--friction",
        "lugre",
        "--test",
        "step",
    ]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.contains("bad.toml:9:"), "{}", run.stderr);
    let missing = axcomp([
        "servo-sim",
        "--axis",
        "mcfv9999",
        "--friction",
        "lugre",
        "--test",
        "step",
    ]);
    assert_eq!(missing.code, 2);
    assert!(
        missing.stderr.contains("not a bundled axis"),
        "{}",
        missing.stderr
    );
}

#[test]
fn force_step_reports_peak_and_recovery() {
    let report = json(&[
        "--axis",
        "mcfv5050-x",
        "--friction",
        "classic",
        "--test",
        "step",
    ]);
    let step = &report["force_step"];
    // The notes' independent model: ≈ 92 µm, back within 5 % in ≈ 47–50 ms (thesis: 80 µm, 70 ms).
    let peak = step["peak_error_um"].as_f64().unwrap();
    assert!((85.0..100.0).contains(&peak), "{peak}");
    let recovery = step["recovery_s"].as_f64().unwrap();
    assert!((0.035..0.065).contains(&recovery), "{recovery}");
}

/// Issue 16: `servo-sim --identify` recovers the friction it was simulated
/// with. The thesis's identified X axis (notes §4.2–4.5: F_C 103–110 N,
/// μ_v 430 N·s/m from the linear fit, k_s 2.8·10⁷ N/m with the force along
/// the previous motion and 2.1·10⁶ N/m against it, Tab. 5.3) is simulated
/// (`servo::force_step::run_constant_velocity` at the feeds of Tab. 5.1 in
/// both directions, `servo::circle::run_circle` at 3.2 m/min), noise is
/// added (0.01 A on each mean current, 0.1 µm on each following-error
/// sample; ChaCha8 seed 16), and the fit must give each parameter back
/// within 10 %.
mod identify {
    use axcomp::servo::axis::Axis;
    use axcomp::servo::circle::run_circle;
    use axcomp::servo::force_step::run_constant_velocity;
    use axcomp::servo::friction::FrictionKind;
    use axcomp::servo::friction_fit::{
        ConstantVelocityRow, FollowingErrorSample, axis_with_friction, identify,
    };
    use axcomp::servo::simulate::Stepping;
    use axcomp::servo::trajectory::{Circle, CircleAxis, MoveLimits};
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// The records of the thesis's X axis with F_C = 110 N, μ_v = 430 N·s/m and this k_s.
    pub(super) fn records(
        stiffness_n_per_m: f64,
        seed: u64,
    ) -> (Vec<ConstantVelocityRow>, Vec<FollowingErrorSample>) {
        let axis = axis_with_friction(
            &Axis::bundled("mcfv5050-x").unwrap(),
            Some(110.0),
            Some(430.0),
            Some(stiffness_n_per_m),
        );
        let friction = axis.friction(FrictionKind::LuGre);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let current_noise = Normal::new(0.0, 0.01).unwrap();
        let mut rows = Vec::new();
        for feed in [1.0, 3.2, 5.0, 8.0, 10.0, 16.0, 24.0] {
            for sign in [1.0, -1.0] {
                let limits = MoveLimits {
                    feed_m_per_s: feed / 60.0,
                    acceleration_m_per_s2: 1.0,
                    jerk_m_per_s3: 20.0,
                };
                let run =
                    run_constant_velocity(&axis, friction, sign * 0.45, limits, Stepping::DEFAULT);
                rows.push(ConstantVelocityRow {
                    feed_m_per_min: sign * feed,
                    current_a: run.mean_current_a + current_noise.sample(&mut rng),
                });
            }
        }
        let circle = Circle::thesis(3.2, CircleAxis::X);
        let error_noise = Normal::new(0.0, 0.1e-6).unwrap();
        let trace = run_circle(&axis, friction, &circle, Stepping::DEFAULT, &mut |_| {}).trace;
        let samples = trace
            .iter()
            .map(|s| FollowingErrorSample {
                time_s: s.time_s,
                following_error_m: s.following_error_m() + error_noise.sample(&mut rng),
            })
            .collect();
        (rows, samples)
    }

    #[test]
    fn the_thesis_x_axis_friction_is_recovered_within_10_percent() {
        let axis = Axis::bundled("mcfv5050-x").unwrap();
        let circle = Circle::thesis(3.2, CircleAxis::X);
        for stiffness in [2.8e7, 2.1e6] {
            let (rows, samples) = records(stiffness, 16);
            let found = identify(&axis, &rows, Some((&circle, &samples)), &mut |_| {}).unwrap();
            let k = found.stiffness.unwrap();
            println!(
                "k_s {stiffness:e}: F_C {:.2} N, μ_v {:.1} N·s/m, k_s {:.4e} N/m ({} simulations, rms {:.3} µm)",
                found.coulomb_n,
                found.viscous_n_s_per_m,
                k.stiffness_n_per_m,
                k.simulations,
                k.rms_residual_m * 1e6
            );
            let within =
                |found: f64, truth: f64| approx::abs_diff_eq!(found, truth, epsilon = 0.1 * truth);
            assert!(within(found.coulomb_n, 110.0), "F_C {}", found.coulomb_n);
            assert!(
                within(found.viscous_n_s_per_m, 430.0),
                "μ_v {}",
                found.viscous_n_s_per_m
            );
            assert!(
                within(k.stiffness_n_per_m, stiffness),
                "k_s {:e}",
                k.stiffness_n_per_m
            );
        }
    }
}

/// Issue 16 through the binary: `servo-sim --identify` on records written
/// as CSV, and `diagnose --servo-axis` reading a reversal as friction.
mod identify_cli {
    use serde_json::Value;

    use super::identify::records;
    use crate::util::axcomp;

    #[test]
    fn identify_reads_the_records_and_gives_the_flags_to_start_from() {
        let dir = tempfile::tempdir().unwrap();
        let (rows, samples) = records(2.1e6, 17);
        let mut cv = String::from("# simulated, seed 17\nfeed_m_per_min,current_a\n");
        for row in &rows {
            cv += &format!("{},{}\n", row.feed_m_per_min, row.current_a);
        }
        let mut circle = String::from("time_s,following_error_um\n");
        for sample in &samples {
            circle += &format!("{},{}\n", sample.time_s, sample.following_error_m * 1e6);
        }
        let cv_path = dir.path().join("cv.csv");
        let circle_path = dir.path().join("circle.csv");
        std::fs::write(&cv_path, cv).unwrap();
        std::fs::write(&circle_path, circle).unwrap();
        let run = axcomp([
            "servo-sim",
            "--axis",
            "mcfv5050-x",
            "--identify",
            cv_path.to_str().unwrap(),
            "--reversal",
            circle_path.to_str().unwrap(),
            "--feed-m-min",
            "3.2",
            "--json",
        ]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        let json: Value = serde_json::from_str(&run.stdout).unwrap();
        let value = |key: &str| json[key].as_f64().unwrap();
        assert!((value("coulomb_n") - 110.0).abs() <= 11.0, "{json}");
        assert!((value("viscous_n_s_per_m") - 430.0).abs() <= 43.0, "{json}");
        assert!(
            (value("lugre_stiffness_n_per_m") - 2.1e6).abs() <= 2.1e5,
            "{json}"
        );
        assert!(
            json["servo_sim"]
                .as_str()
                .unwrap()
                .starts_with("--coulomb-n ")
        );

        // A bad record: the path, line and column, exit code 2.
        std::fs::write(&cv_path, "feed_m_per_min,current_a\n1,1.2\n3.2,nan\n").unwrap();
        let run = axcomp([
            "servo-sim",
            "--axis",
            "mcfv5050-x",
            "--identify",
            cv_path.to_str().unwrap(),
        ]);
        assert_eq!(run.code, 2);
        assert!(
            run.stderr
                .contains("cv.csv:3:5: expected a number for current_a"),
            "{}",
            run.stderr
        );
    }

    /// A reversal of −3 µm that appears after the first test, on an axis
    /// described by the bundled X axis with k_c = 100 N/µm: the friction
    /// held grew by −B·k_c/2 = 150 N (by hand); without the first test the
    /// whole reversal is the force, and the bundled F_C of 90 N would give
    /// −2·90/100 = −1.8 µm.
    #[test]
    fn diagnose_reads_the_reversal_as_friction() {
        let dir = tempfile::tempdir().unwrap();
        let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
        std::fs::write(
            path("truth.toml"),
            "[axis]\nname = \"X\"\n\n[cycle]\nstart_mm = 0.0\nend_mm = 750.0\ncount = 21\njitter_mm = 6.0\nruns = 5\n\n\
             [error]\nscale_um_per_m = 9.5\n\n[noise]\nsigma_um = 0.25\n\n\
             [[effect]]\nkind = \"reversal\"\nB_um = -3.0\ntests = [\"after\"]\n",
        )
        .unwrap();
        let ok = |args: &[&str]| {
            let run = axcomp(args);
            assert_eq!(run.code, 0, "{}", run.stderr);
            run.stdout
        };
        ok(&[
            "synth",
            "--truth",
            &path("truth.toml"),
            "-o",
            &path("before.rtl"),
            "-q",
        ]);
        ok(&[
            "convert",
            &path("before.rtl"),
            "--controller",
            "tnc640",
            "-o",
            &path("X.COM"),
            "-q",
        ]);
        ok(&[
            "synth",
            "--truth",
            &path("truth.toml"),
            "-o",
            &path("b2.rtl"),
            "--table",
            &path("X.COM"),
            "--o2",
            &path("after.rtl"),
            "-q",
        ]);
        let servo = ["--servo-axis", "mcfv5050-x", "--stiffness-n-per-um", "100"];
        let (after, before, table) = (path("after.rtl"), path("before.rtl"), path("X.COM"));
        let mut args = vec!["diagnose", "--after", &after];
        args.extend(["--before", &before, "--table", &table, "--json"]);
        args.extend(servo);
        let json: Value = serde_json::from_str(&ok(&args)).unwrap();
        let friction = &json["friction"];
        assert_eq!(friction["change_since_first_test"], true, "{json}");
        let force = friction["friction_n"].as_f64().unwrap();
        assert!((force - 150.0).abs() <= 15.0, "{friction}");
        assert_eq!(friction["expected_reversal_um"].as_f64().unwrap(), -1.8);
        assert_eq!(friction["scale_part_n"].as_f64().unwrap(), 50.0);
        // The start value: the description's 90 N plus the change.
        assert!((friction["start_coulomb_n"].as_f64().unwrap() - (90.0 + force)).abs() < 1e-9);
        // k_c is a stiffness, under its own key; the key and the flag it had
        // before 0.2 still work (CHANGELOG.md).
        assert_eq!(friction["stiffness_n_per_um"].as_f64(), Some(100.0));
        assert_eq!(friction["compliance_n_per_um"].as_f64(), Some(100.0));
        let mut old_flag = args.clone();
        let at = old_flag
            .iter()
            .position(|a| *a == "--stiffness-n-per-um")
            .unwrap();
        old_flag[at] = "--compliance-n-um";
        let old: Value = serde_json::from_str(&ok(&old_flag)).unwrap();
        assert_eq!(old["friction"], json["friction"]);

        let text = ok(&[
            "diagnose",
            "--after",
            &after,
            "--servo-axis",
            "mcfv5050-x",
            "--stiffness-n-per-um",
            "100",
        ]);
        assert!(
            text.contains("friction: B̄ = B̄_scale − 2·F_res/k_c with k_c = 100 N/µm"),
            "{text}"
        );
        assert!(
            text.contains("servo-sim starts from it: axcomp servo-sim --axis mcfv5050-x"),
            "{text}"
        );
        // Without the servo description, no friction line and no key.
        let json: Value =
            serde_json::from_str(&ok(&["diagnose", "--after", &after, "--json"])).unwrap();
        assert!(json.get("friction").is_none());
    }
}
