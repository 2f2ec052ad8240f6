//! Evaluator tests: a hand-computed example, the edge cases of the spec, and
//! property tests of the invariants in `../shared/spec/style.md` §6.

use proptest::prelude::*;

use super::*;
use crate::measurement::{Environment, Metadata, Run};

const TOLERANCE_MM: f64 = 1e-12;

/// The warnings after the test's conformance warnings, which come first:
/// what could not be evaluated.
fn coverage(e: &Evaluation) -> &[Warning] {
    let conformance = e.conformance.warnings();
    assert_eq!(e.warnings[..conformance.len()], conformance[..]);
    &e.warnings[conformance.len()..]
}

fn run(direction: Direction, number: u32, values_um: &[f64]) -> Run {
    Run {
        direction,
        number,
        start_time_s: None,
        deviations: values_um.iter().map(|v| Some(v / 1000.0)).collect(),
    }
}

fn measurement(runs: Vec<Run>) -> Measurement {
    let count = runs[0].deviations.len();
    let targets = (0..count).map(|i| i as f64 * 100.0).collect();
    Measurement::new(
        "X",
        targets,
        runs,
        Environment::default(),
        Metadata::default(),
    )
    .unwrap()
}

/// Runs given as [run][target] in µm.
fn bidirectional(up: &[&[f64]], down: &[&[f64]]) -> Measurement {
    let mut runs = Vec::new();
    for (j, values) in up.iter().enumerate() {
        runs.push(run(Direction::Up, j as u32 + 1, values));
    }
    for (j, values) in down.iter().enumerate() {
        runs.push(run(Direction::Down, j as u32 + 1, values));
    }
    measurement(runs)
}

fn assert_um(actual_mm: Option<f64>, expected_um: Option<f64>, what: &str) {
    match (actual_mm, expected_um) {
        (Some(a), Some(e)) => assert!(
            (a * 1000.0 - e).abs() < 1e-9,
            "{what}: {} µm, expected {e} µm",
            a * 1000.0
        ),
        (a, e) => assert_eq!(a.map(|v| v * 1000.0), e, "{what}"),
    }
}

/// The worked example, by hand (µm). Targets 0, 100, 200 mm; three runs each way.
///   ↑: t1 1 2 3 (x̄ 2, s 1)   t2 4 6 8 (x̄ 6, s 2)   t3 −1 0 1 (x̄ 0, s 1)
///   ↓: t1 −1 0 1 (x̄ 0, s 1)  t2 2 2 2 (x̄ 2, s 0)   t3 −4 −3 −2 (x̄ −3, s 1)
/// B_i = 2, 4, 3; x̄_i = 1, 4, −1.5; R_i↑ = 4, 8, 4; R_i↓ = 4, 0, 4;
/// R_i = max(2+2+2, 4, 4) = 6, max(4+0+4, 8, 0) = 8, max(2+2+3, 4, 4) = 7.
/// B = 4, B̄ = 3, R↑ = 8, R↓ = 4, R = 8, E↑ = 6 − 0 = 6, E↓ = 2 − (−3) = 5,
/// E = 6 − (−3) = 9, M = 4 − (−1.5) = 5.5,
/// A↑ = max(4, 10, 2) − min(0, 2, −2) = 12, A↓ = max(2, 2, −1) − min(−2, 2, −5) = 7,
/// A = 10 − (−5) = 15.
fn worked_example() -> Measurement {
    bidirectional(
        &[&[1.0, 4.0, -1.0], &[2.0, 6.0, 0.0], &[3.0, 8.0, 1.0]],
        &[&[-1.0, 2.0, -4.0], &[0.0, 2.0, -3.0], &[1.0, 2.0, -2.0]],
    )
}

#[test]
fn worked_example_per_target() {
    let e = evaluate(&worked_example());
    let expected = [
        // x̄↑, x̄↓, s↑, s↓, x̄, B_i, R_i↑, R_i↓, R_i
        [2.0, 0.0, 1.0, 1.0, 1.0, 2.0, 4.0, 4.0, 6.0],
        [6.0, 2.0, 2.0, 0.0, 4.0, 4.0, 8.0, 0.0, 8.0],
        [0.0, -3.0, 1.0, 1.0, -1.5, 3.0, 4.0, 4.0, 7.0],
    ];
    for (t, want) in e.per_target.iter().zip(expected) {
        let got = [
            t.up.mean_mm,
            t.down.mean_mm,
            t.up.s_mm,
            t.down.s_mm,
            t.mean_mm,
            t.reversal_mm,
            t.repeatability_up_mm,
            t.repeatability_down_mm,
            t.repeatability_mm,
        ];
        for (g, w) in got.into_iter().zip(want) {
            assert_um(g, Some(w), &format!("target {}", t.target_mm));
        }
        assert_eq!((t.up.n, t.down.n), (3, 3));
    }
}

#[test]
fn worked_example_axis_figures() {
    let f = evaluate(&worked_example()).figures;
    let expected = [
        (f.a_mm, 15.0, "A"),
        (f.a_up_mm, 12.0, "A↑"),
        (f.a_down_mm, 7.0, "A↓"),
        (f.e_mm, 9.0, "E"),
        (f.e_up_mm, 6.0, "E↑"),
        (f.e_down_mm, 5.0, "E↓"),
        (f.m_mm, 5.5, "M"),
        (f.r_mm, 8.0, "R"),
        (f.r_up_mm, 8.0, "R↑"),
        (f.r_down_mm, 4.0, "R↓"),
        (f.b_mm, 4.0, "B"),
        (f.b_mean_mm, 3.0, "B̄"),
    ];
    for (actual, want, name) in expected {
        assert_um(actual, Some(want), name);
    }
}

#[test]
fn unidirectional_test_has_no_bidirectional_figures() {
    let m = bidirectional(
        &[&[1.0, 4.0, -1.0], &[2.0, 6.0, 0.0], &[3.0, 8.0, 1.0]],
        &[],
    );
    let e = evaluate(&m);
    let f = e.figures;
    assert_um(f.a_up_mm, Some(12.0), "A↑");
    assert_um(f.e_up_mm, Some(6.0), "E↑");
    assert_um(f.r_up_mm, Some(8.0), "R↑");
    for (value, name) in [
        (f.a_mm, "A"),
        (f.a_down_mm, "A↓"),
        (f.e_mm, "E"),
        (f.e_down_mm, "E↓"),
        (f.m_mm, "M"),
        (f.r_mm, "R"),
        (f.r_down_mm, "R↓"),
        (f.b_mm, "B"),
        (f.b_mean_mm, "B̄"),
    ] {
        assert_eq!(value, None, "{name} must be null, never 0");
    }
    // Said once, by the conformance check (one direction only misses ISO 230-2's test).
    assert!(coverage(&e).is_empty());
    assert_eq!(
        e.warnings[0],
        Warning::Unidirectional {
            measured: Direction::Up
        }
    );
    assert_eq!((e.runs_up, e.runs_down), (3, 0));
}

#[test]
fn one_run_per_direction_evaluates_b_e_m_only() {
    // ↑ 1, 4, −1 and ↓ −1, 2, −4: B_i = 2, 2, 3; x̄_i = 0, 3, −2.5.
    let m = bidirectional(&[&[1.0, 4.0, -1.0]], &[&[-1.0, 2.0, -4.0]]);
    let e = evaluate(&m);
    let f = e.figures;
    assert_um(f.b_mm, Some(3.0), "B");
    assert_um(f.b_mean_mm, Some(7.0 / 3.0), "B̄");
    assert_um(f.e_mm, Some(8.0), "E");
    assert_um(f.e_up_mm, Some(5.0), "E↑");
    assert_um(f.m_mm, Some(5.5), "M");
    for (value, name) in [
        (f.a_mm, "A"),
        (f.a_up_mm, "A↑"),
        (f.r_mm, "R"),
        (f.r_up_mm, "R↑"),
        (f.r_down_mm, "R↓"),
    ] {
        assert_eq!(value, None, "{name}");
    }
    assert!(
        e.per_target
            .iter()
            .all(|t| t.up.s_mm.is_none() && t.repeatability_mm.is_none())
    );
    assert_eq!(
        coverage(&e),
        [
            Warning::SingleRun {
                direction: Direction::Up
            },
            Warning::SingleRun {
                direction: Direction::Down
            }
        ]
    );
}

#[test]
fn a_target_read_once_leaves_a_and_r_unevaluated_and_says_where() {
    let mut m = worked_example();
    let runs: Vec<Run> = m
        .runs()
        .iter()
        .map(|r| {
            let mut r = r.clone();
            if r.direction == Direction::Up && r.number > 1 {
                r.deviations[2] = None;
            }
            r
        })
        .collect();
    m = Measurement::new(
        "X",
        m.targets().to_vec(),
        runs,
        Environment::default(),
        Metadata::default(),
    )
    .unwrap();
    let e = evaluate(&m);
    assert_eq!(e.per_target[2].up.n, 1);
    assert_eq!(e.figures.a_mm, None);
    assert_eq!(e.figures.r_up_mm, None);
    // E and M need only the means, which exist everywhere.
    assert!(e.figures.e_mm.is_some() && e.figures.m_mm.is_some());
    assert!(
        matches!(coverage(&e), [Warning::TargetNotEvaluated { target_mm, .. }] if *target_mm == 200.0)
    );
}

#[test]
fn zero_spread_and_single_target() {
    let m = bidirectional(&[&[5.0], &[5.0]], &[&[5.0], &[5.0]]);
    let f = evaluate(&m).figures;
    for (value, name) in [
        (f.a_mm, "A"),
        (f.e_mm, "E"),
        (f.m_mm, "M"),
        (f.r_mm, "R"),
        (f.b_mm, "B"),
    ] {
        assert_um(value, Some(0.0), name);
    }
}

fn arbitrary_measurement() -> impl Strategy<Value = Measurement> {
    (1usize..8, 2usize..6, 2usize..6).prop_flat_map(|(targets, n_up, n_down)| {
        let values = prop::collection::vec(
            prop::collection::vec(-50.0f64..50.0, targets),
            n_up + n_down,
        );
        values.prop_map(move |rows| {
            let up: Vec<&[f64]> = rows[..n_up].iter().map(Vec::as_slice).collect();
            let down: Vec<&[f64]> = rows[n_up..].iter().map(Vec::as_slice).collect();
            bidirectional(&up, &down)
        })
    })
}

fn shifted(m: &Measurement, offset_mm: f64) -> Measurement {
    let runs = m
        .runs()
        .iter()
        .map(|r| Run {
            deviations: r
                .deviations
                .iter()
                .map(|v| v.map(|v| v + offset_mm))
                .collect(),
            ..r.clone()
        })
        .collect();
    Measurement::new(
        "X",
        m.targets().to_vec(),
        runs,
        Environment::default(),
        Metadata::default(),
    )
    .unwrap()
}

fn swapped(m: &Measurement) -> Measurement {
    let runs = m
        .runs()
        .iter()
        .map(|r| Run {
            direction: r.direction.reversed(),
            ..r.clone()
        })
        .collect();
    Measurement::new(
        "X",
        m.targets().to_vec(),
        runs,
        Environment::default(),
        Metadata::default(),
    )
    .unwrap()
}

proptest! {
    #[test]
    fn ordering_of_figures(m in arbitrary_measurement()) {
        let f = evaluate(&m).figures;
        let (a, e, mm, r, b) = (f.a_mm.unwrap(), f.e_mm.unwrap(), f.m_mm.unwrap(), f.r_mm.unwrap(), f.b_mm.unwrap());
        prop_assert!(mm <= e + TOLERANCE_MM, "M {mm} > E {e}");
        prop_assert!(e <= a + TOLERANCE_MM, "E {e} > A {a}");
        prop_assert!(r + TOLERANCE_MM >= f.r_up_mm.unwrap().max(f.r_down_mm.unwrap()));
        prop_assert!(r + TOLERANCE_MM >= b, "R {r} < B {b}");
        prop_assert!(f.e_up_mm.unwrap() <= e + TOLERANCE_MM && f.a_up_mm.unwrap() <= a + TOLERANCE_MM);
        prop_assert!(f.b_mean_mm.unwrap().abs() <= b + TOLERANCE_MM);
    }

    #[test]
    fn constant_offset_changes_nothing_but_the_means(m in arbitrary_measurement(), offset in -1.0f64..1.0) {
        let before = evaluate(&m).figures;
        let after = evaluate(&shifted(&m, offset)).figures;
        for (x, y) in [
            (before.a_mm, after.a_mm), (before.e_mm, after.e_mm), (before.m_mm, after.m_mm),
            (before.r_mm, after.r_mm), (before.b_mm, after.b_mm), (before.b_mean_mm, after.b_mean_mm),
        ] {
            prop_assert!((x.unwrap() - y.unwrap()).abs() < 1e-9);
        }
    }

    #[test]
    fn swapping_directions_negates_mean_reversal(m in arbitrary_measurement()) {
        let before = evaluate(&m).figures;
        let after = evaluate(&swapped(&m)).figures;
        prop_assert!((before.b_mean_mm.unwrap() + after.b_mean_mm.unwrap()).abs() < 1e-12);
        prop_assert!((before.a_up_mm.unwrap() - after.a_down_mm.unwrap()).abs() < 1e-12);
        prop_assert!((before.e_mm.unwrap() - after.e_mm.unwrap()).abs() < 1e-12);
        prop_assert!((before.r_mm.unwrap() - after.r_mm.unwrap()).abs() < 1e-12);
    }
}
