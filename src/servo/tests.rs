//! Reproducing Mendřický (2006) and checking the scheme: Mendřický's Tab. 6.4, the
//! notes' independent re-implementation (notes §10), the LuGre demonstrations
//! (§4.4.3), the force step (§6.2), and the adaptive scheme against the
//! uniform 1 µs reference on a short ISO 230-2 cycle.
//!
//! Expected numbers come from Mendřický (2006) (Tab. 6.4 as reconstructed in notes
//! §5.3.6) or from the notes' [CHK] re-simulation, never from this code.

use crate::measurement::Direction;
use crate::servo::axis::Axis;
use crate::servo::circle::run_circle;
use crate::servo::force_step::{run_constant_velocity, run_force_step};
use crate::servo::friction::{Classic, Friction, FrictionKind, LuGre, Power, Ramp};
use crate::servo::iso_cycle::{IsoCycle, IsoOptions, run_iso_cycle};
use crate::servo::reversal::reversal_from_friction_um;
use crate::servo::simulate::{ForceStep, Stepping};
use crate::servo::trajectory::{Circle, CircleAxis, MoveLimits};

const FEEDS_M_PER_MIN: [f64; 5] = [3.2, 8.0, 16.0, 24.0, 48.0];

/// Tab. 6.4 prints currents to 0.1 A: half a printed step.
const CURRENT_PRINTED_HALF_STEP_A: f64 = 0.05;

/// One row of Tab. 6.4 per model (A, B1, B2, C): simulated error µm and current A.
#[derive(serde::Deserialize)]
struct Tab64 {
    error_um: [[f64; 5]; 4],
    current_a: [[f64; 5]; 4],
    measured_error_um: [f64; 5],
    measured_current_a: [f64; 5],
    /// The notes' independent re-simulation (notes §10), same layout.
    check_error_um: [[f64; 5]; 4],
    check_current_a: [[f64; 5]; 4],
}

/// Tab. 6.4 and notes §10, both axes (X: xe, Ix; Y: ye, Iy).
#[derive(serde::Deserialize)]
struct Tab64Axes {
    x: Tab64,
    y: Tab64,
}

fn tab_6_4() -> Tab64Axes {
    toml::from_str(include_str!("../../fixtures/servo/tab-6-4.toml")).unwrap()
}

/// Simulates every model and feed on one axis: [model][feed] → (µm, A).
fn circle_table(axis_name: &str, circle_axis: CircleAxis) -> [[(f64, f64); 5]; 4] {
    let axis = Axis::bundled(axis_name).unwrap();
    let mut table = [[(0.0, 0.0); 5]; 4];
    for (model, kind) in FrictionKind::ALL.into_iter().enumerate() {
        for (column, feed) in FEEDS_M_PER_MIN.into_iter().enumerate() {
            let circle = Circle::thesis(feed, circle_axis);
            let result = run_circle(
                &axis,
                axis.friction(kind),
                &circle,
                Stepping::DEFAULT,
                &mut |_| {},
            );
            table[model][column] = (result.reversal_error_m * 1e6, result.reversal_current_a);
        }
    }
    table
}

/// Mean |sim − meas|/meas in %, Mendřický's row average (eq. 6.12 with the sign as tabulated).
fn mean_abs_error_pct(simulated: &[f64; 5], measured: &[f64; 5]) -> f64 {
    simulated
        .iter()
        .zip(measured)
        .map(|(s, m)| ((s - m) / m).abs() * 100.0)
        .sum::<f64>()
        / 5.0
}

fn check_tab_6_4(axis_name: &str, circle_axis: CircleAxis, expected: &Tab64) {
    let table = circle_table(axis_name, circle_axis);
    let mut failures = Vec::new();
    let mut error_pct = [0.0; 4];
    for (model, kind) in FrictionKind::ALL.into_iter().enumerate() {
        for column in 0..5 {
            let (error_um, current_a) = table[model][column];
            let label = format!(
                "{axis_name} {} {} m/min",
                kind.thesis_label(),
                FEEDS_M_PER_MIN[column]
            );
            // Within 1 µm of Mendřický's simulated values.
            if (error_um - expected.error_um[model][column]).abs() > 1.0 {
                failures.push(format!(
                    "{label}: error {error_um:.2} µm vs thesis {}",
                    expected.error_um[model][column]
                ));
            }
            // Mendřický (2006) prints currents to 0.1 A, so its simulated value lies
            // within ±0.05 A of the printed figure; the tolerance of 0.2 A is
            // measured from that interval. Two Y cells need it: B2 at 24 m/min
            // (13.69 A against a printed 13.9; the notes' independent model
            // also gets 13.69) and at 48 m/min (44.80 against 45.0), 0.01 and
            // 0.005 A beyond 0.2 A of the printed figure. Nothing in the text
            // closes that gap (notes §8.4), and no parameter is tuned to it.
            let outside_printed_a =
                (current_a - expected.current_a[model][column]).abs() - CURRENT_PRINTED_HALF_STEP_A;
            if outside_printed_a > 0.2 {
                failures.push(format!(
                    "{label}: current {current_a:.2} A vs thesis {}",
                    expected.current_a[model][column]
                ));
            }
            // The same model rebuilt independently (notes §10: explicit Euler
            // at 1 µs, friction from the previous step's velocity; here the
            // linear part is exact and friction implicit).
            if (error_um - expected.check_error_um[model][column]).abs() > 0.25 {
                failures.push(format!(
                    "{label}: error {error_um:.2} µm vs notes {}",
                    expected.check_error_um[model][column]
                ));
            }
            if (current_a - expected.check_current_a[model][column]).abs() > 0.15 {
                failures.push(format!(
                    "{label}: current {current_a:.2} A vs notes {}",
                    expected.check_current_a[model][column]
                ));
            }
        }
        let simulated: [f64; 5] = std::array::from_fn(|column| table[model][column].0);
        error_pct[model] = mean_abs_error_pct(&simulated, &expected.measured_error_um);
        let currents: [f64; 5] = std::array::from_fn(|column| table[model][column].1);
        // Mendřický (2006): "the mean current error is about 10 % for all models".
        let current_pct = mean_abs_error_pct(&currents, &expected.measured_current_a);
        if current_pct > 16.0 {
            failures.push(format!(
                "{axis_name} {}: mean current error {current_pct:.0} %",
                kind.thesis_label()
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // What Mendřický (2006) concludes (§6.3, Tab. 6.4 means: A 123/114 %, B1 26/26 %,
    // B2 6/6 %, C 6/8 %): B2 and LuGre best, B1 in between, classic worst by far.
    let [classic, ramp, power, lugre] = error_pct;
    assert!(
        classic > 100.0,
        "{axis_name}: classic mean error {classic:.0} %"
    );
    assert!(ramp > 15.0 && ramp < 40.0, "{axis_name}: ramp {ramp:.0} %");
    assert!(
        power < 12.0 && lugre < 12.0,
        "{axis_name}: power {power:.0} %, LuGre {lugre:.0} %"
    );
    assert!(power.max(lugre) < ramp && ramp < classic);
}

#[test]
fn tab_6_4_x_axis_all_models_all_feeds() {
    check_tab_6_4("mcfv5050-x", CircleAxis::X, &tab_6_4().x);
}

#[test]
fn tab_6_4_y_axis_all_models_all_feeds() {
    check_tab_6_4("mcfv5050-y", CircleAxis::Y, &tab_6_4().y);
}

/// The short cycle of the scheme test: 3 targets over 12 mm, 1 run, 0.4 s dwell, 2 m/min.
fn short_cycle() -> IsoCycle {
    IsoCycle {
        targets_m: vec![0.0, 0.005, 0.012],
        runs: 1,
        dwell_s: 0.4,
        overrun_m: 0.002,
        limits: MoveLimits {
            feed_m_per_s: 2.0 / 60.0,
            acceleration_m_per_s2: 1.0,
            jerk_m_per_s3: 20.0,
        },
    }
}

fn adaptive_matches_uniform(kind: FrictionKind) {
    let axis = Axis::bundled("mcfv5050-x").unwrap();
    let cycle = short_cycle();
    let run = |stepping| {
        let options = IsoOptions {
            stiffness_n_per_um: Some(100.0),
            stepping,
        };
        run_iso_cycle(&axis, axis.friction(kind), &cycle, options, &mut |_| {}).unwrap()
    };
    let fast = run(Stepping::DEFAULT);
    let reference = run(Stepping::Uniform);
    // The adaptive scheme must actually skip work to be worth testing.
    assert!(
        fast.counts.coarse > 10 * fast.counts.refined,
        "{:?}",
        fast.counts
    );
    for (a, b) in fast.readings.iter().zip(&reference.readings) {
        let difference_um = (a.deviation_m - b.deviation_m).abs() * 1e6;
        assert!(
            difference_um <= 0.05,
            "{kind:?} {}{} target {}: {:.4} vs {:.4} µm",
            a.run,
            a.direction,
            a.target_index,
            a.deviation_m * 1e6,
            b.deviation_m * 1e6
        );
    }
}

#[test]
fn adaptive_matches_uniform_reference_classic() {
    adaptive_matches_uniform(FrictionKind::Classic);
}

#[test]
fn adaptive_matches_uniform_reference_ramp() {
    adaptive_matches_uniform(FrictionKind::Ramp);
}

#[test]
fn adaptive_matches_uniform_reference_power() {
    adaptive_matches_uniform(FrictionKind::Power);
}

#[test]
fn adaptive_matches_uniform_reference_lugre() {
    adaptive_matches_uniform(FrictionKind::LuGre);
}

#[test]
fn iso_reversal_is_the_held_friction_through_the_compliance() {
    // Classic friction keeps ≈ F_C after each approach; velocity-only B2 lets
    // it decay (thesis §6.4). Halving k_c doubles the compliance part of B̄.
    let axis = Axis::bundled("mcfv5050-x").unwrap();
    let cycle = short_cycle();
    let run = |kind, k| {
        let options = IsoOptions {
            stiffness_n_per_um: k,
            stepping: Stepping::DEFAULT,
        };
        run_iso_cycle(&axis, axis.friction(kind), &cycle, options, &mut |_| {}).unwrap()
    };
    let classic = run(FrictionKind::Classic, Some(100.0));
    for reading in &classic.readings {
        let expected = match reading.direction {
            Direction::Up => 1.0,
            Direction::Down => -1.0,
        } * 90.0;
        assert!(
            (reading.friction_force_n - expected).abs() < 5.0,
            "{reading:?}"
        );
    }
    let b_mean =
        |r: &crate::servo::iso_cycle::IsoResult| r.evaluation.figures.b_mean.unwrap() * 1e3;
    let rigid = b_mean(&run(FrictionKind::Classic, None));
    let stiff = b_mean(&classic);
    let soft = b_mean(&run(FrictionKind::Classic, Some(50.0)));
    // B̄ − B̄_scale = −2·F_res/k_c (reversal.rs), F_res ≈ 89.7 N.
    assert!(
        (stiff - rigid + reversal_from_friction_um(89.7, 100.0)).abs() < 0.02,
        "{stiff} {rigid}"
    );
    assert!(
        (soft - rigid + reversal_from_friction_um(89.7, 50.0)).abs() < 0.04,
        "{soft} {rigid}"
    );
    let power = run(FrictionKind::Power, Some(100.0));
    assert!(
        power
            .readings
            .iter()
            .all(|r| r.friction_force_n.abs() < 5.0)
    );
}

#[test]
fn force_step_peak_and_recovery() {
    // Tab. 6.1 friction (X, §6.1) and a 1500 N step at t = 0.01 s (§6.2).
    let axis = Axis::bundled("mcfv5050-x").unwrap();
    let tab_6_1 = |kind| match kind {
        FrictionKind::Classic => Friction::Classic(Classic {
            coulomb_n: 115.0,
            static_n: 115.0,
            viscous_n_s_per_m: 430.0,
        }),
        FrictionKind::Ramp => Friction::Ramp(Ramp {
            coulomb_n: 115.0,
            viscous_n_s_per_m: 430.0,
            slope_n_s_per_m: 12_000.0,
        }),
        FrictionKind::Power => Friction::Power(Power {
            coefficient_n: 300.0,
            order: 4.0,
        }),
        FrictionKind::LuGre => Friction::LuGre(LuGre {
            stiffness_n_per_m: 1e7,
            damping_n_s_per_m: 0.2 * (1e7f64 * 225.0).sqrt(),
            viscous_n_s_per_m: 430.0,
            coulomb_n: 115.0,
            static_n: 115.0,
            stribeck_velocity_m_per_s: 1e-3,
        }),
    };
    let step = ForceStep {
        at_s: 0.01,
        force_n: 1500.0,
    };
    for kind in FrictionKind::ALL {
        let result = run_force_step(&axis, tab_6_1(kind), step, 0.4, Stepping::DEFAULT);
        let peak_um = result.peak_error_m * 1e6;
        // Thesis: ≈ 80 µm, back in ≈ 70 ms. The notes' simplified model (the
        // one built here: no notch, no scale slider) gives 92 µm with classic
        // friction and 99.5 µm without, back within 5 % in 47–50 ms (notes §9 S2).
        assert!(
            (85.0..=100.0).contains(&peak_um),
            "{kind:?}: peak {peak_um:.1} µm"
        );
        assert!(
            (0.035..=0.065).contains(&result.recovery_s),
            "{kind:?}: {result:?}"
        );
        // No chatter: Mendřický's B2 showed ±15 N at standstill from explicit stepping.
        assert!(result.final_friction_ripple_n < 1.0, "{kind:?}: {result:?}");
        // Residual friction after the transient (Fig. 6.5): B1 and B2 cannot
        // hold a force at rest, so theirs goes to zero (A and C keep some).
        // B2's decays slowly (creep under a force ∝ v^(1/n) is a power law in time).
        let limit_n = match kind {
            FrictionKind::Ramp => 5.0,
            FrictionKind::Power => 11.5,
            _ => f64::INFINITY,
        };
        assert!(
            result.final_friction_n.abs() < limit_n,
            "{kind:?}: {result:?}"
        );
    }
}

#[test]
fn constant_velocity_current_is_friction_over_the_force_constant() {
    // Eq. 5.7: at constant speed the motor force is the friction (Fig. 6.2).
    let axis = Axis::bundled("mcfv5050-x").unwrap();
    let limits = MoveLimits {
        feed_m_per_s: 5.0 / 60.0,
        acceleration_m_per_s2: 2.0,
        jerk_m_per_s3: 50.0,
    };
    for kind in FrictionKind::ALL {
        let result =
            run_constant_velocity(&axis, axis.friction(kind), 0.1, limits, Stepping::DEFAULT);
        let expected_a = result.steady_friction_n / 94.0;
        assert!(
            (result.mean_current_a - expected_a).abs() < 0.01 * expected_a,
            "{kind:?}: {result:?}"
        );
    }
}

/// Tab. 4.3: the "medium-size machine-tool feed axis" of the LuGre demonstrations.
const TAB_4_3: LuGre = LuGre {
    stiffness_n_per_m: 4e7,
    damping_n_s_per_m: 25_298.2,
    viscous_n_s_per_m: 200.0,
    coulomb_n: 400.0,
    static_n: 600.0,
    stribeck_velocity_m_per_s: 1e-3,
};
const TAB_4_3_MASS_KG: f64 = 400.0;

/// A free mass under an applied force and LuGre friction, advanced with the
/// same implicit friction step the axis uses: (x, v, F_T) at each step.
fn free_mass(
    mut applied_force_n: impl FnMut(f64, f64) -> f64,
    end_s: f64,
    h: f64,
) -> Vec<(f64, f64, f64, f64)> {
    let friction = Friction::LuGre(TAB_4_3);
    let (mut x, mut v, mut z) = (0.0, 0.0, 0.0);
    let mut trace = Vec::new();
    let steps = (end_s / h).round() as usize;
    for i in 1..=steps {
        let t = i as f64 * h;
        let force = applied_force_n(t, x);
        let free_velocity = v + h * force / TAB_4_3_MASS_KG;
        let step = friction.step(&mut z, free_velocity, h / TAB_4_3_MASS_KG, h);
        v = step.velocity_m_per_s;
        x += v * h;
        trace.push((t, x, v, step.force_n));
    }
    trace
}

#[test]
fn lugre_stick_slip_has_stick_phases() {
    // Fig. 4.15–4.17: m = 400 kg on a 5000 N/m spring pulled at 0.1 m/s.
    // The notes' RK4 (§2.10): first slip at 1.166 s (spring force ≈ 582 N),
    // stick again at ≈ 2.56 s, period ≈ 1.89 s (Mendřický (2006): stop at ≈ 2.4 s).
    let trace = free_mass(|t, x| 5000.0 * (0.1 * t - x), 5.0, 1e-5);
    let slipping = |v: f64| v > 1e-3;
    let first_slip = trace.iter().find(|s| slipping(s.2)).unwrap();
    assert!(
        (1.05..1.3).contains(&first_slip.0),
        "first slip at {}",
        first_slip.0
    );
    let stick = trace
        .iter()
        .find(|s| s.0 > first_slip.0 + 0.05 && s.2.abs() < 1e-4)
        .unwrap();
    assert!((2.3..2.8).contains(&stick.0), "stick at {}", stick.0);
    // A stick phase: the mass stays (nearly) at rest for a long while.
    let stuck_for = trace
        .iter()
        .filter(|s| s.0 > stick.0 && s.0 < stick.0 + 0.3)
        .all(|s| s.2.abs() < 1e-3);
    assert!(stuck_for, "no stick phase after {}", stick.0);
    let second_slip = trace
        .iter()
        .find(|s| s.0 > stick.0 && slipping(s.2))
        .unwrap();
    let period = second_slip.0 - first_slip.0;
    assert!((1.6..2.2).contains(&period), "period {period}");
}

#[test]
fn lugre_pre_sliding_leaves_a_residual_displacement() {
    // Fig. 4.9: a force ramped to 540 N (90 % of F_Ts), held, ramped to −540 N.
    // 1 s ramps and holds (not given in Mendřický (2006)); the notes get a peak of
    // 39.5 µm and 29.8 µm left when the force is back at 0.
    let force = |t: f64| match t {
        t if t < 1.0 => 540.0 * t,
        t if t < 2.0 => 540.0,
        t if t < 4.0 => 540.0 - 540.0 * (t - 2.0),
        _ => -540.0,
    };
    let trace = free_mass(|t, _| force(t), 5.0, 1e-5);
    let peak = trace.iter().map(|s| s.1).fold(f64::MIN, f64::max);
    assert!((30e-6..50e-6).contains(&peak), "peak {peak}");
    // No gross sliding: the speed never gets near sliding speeds.
    assert!(trace.iter().all(|s| s.2.abs() < 1e-3));
    let at_zero = trace.iter().find(|s| s.0 >= 3.0).unwrap();
    assert!(at_zero.1 > 15e-6 && at_zero.1 < 40e-6, "left {}", at_zero.1);
}
