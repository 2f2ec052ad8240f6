//! Synthetic measurements against their truth, by hand.

use super::*;
use crate::compensate::TableValues;
use crate::evaluate::evaluate;
use crate::measurement::SourceFormat;
use crate::read::{parse_str, rtl};

fn truth(extra: &str) -> Truth {
    let text = format!(
        "[cycle]\nstart_mm = 0.0\nend_mm = 400.0\ncount = 5\nruns = 3\nstart = \"2026-03-02 10:00:00\"\n\n\
         [noise]\nsigma_um = 0.0\n\n{extra}"
    );
    Truth::from_toml_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn deviations_um(m: &Measurement, run: usize) -> Vec<f64> {
    m.runs()[run]
        .deviations
        .iter()
        .map(|v| v.unwrap() * 1000.0)
        .collect()
}

#[test]
fn declared_error_is_zeroed_at_the_first_target() {
    // 10 µm/m over 0 … 400 mm: 0, 1, 2, 3, 4 µm at 0, 100, 200, 300, 400.
    let m = before(&truth("[error]\nscale_um_per_m = 10.0\n"), 1).unwrap();
    assert_eq!(m.targets(), &[0.0, 100.0, 200.0, 300.0, 400.0]);
    for run in 0..6 {
        assert_eq!(deviations_um(&m, run), vec![0.0, 1.0, 2.0, 3.0, 4.0]);
    }
    let labels: Vec<String> = m.runs().iter().map(|r| r.label()).collect();
    assert_eq!(labels, ["1↑", "1↓", "2↑", "2↓", "3↑", "3↓"]);
}

#[test]
fn each_effect_by_hand() {
    let reversal = before(&truth("[[effect]]\nkind = \"reversal\"\nB_um = -3.0\n"), 1).unwrap();
    assert_eq!(deviations_um(&reversal, 0), vec![-1.5; 5]);
    assert_eq!(deviations_um(&reversal, 1), vec![1.5; 5]);
    assert!((evaluate(&reversal).figures.b_mean.unwrap() * 1000.0 + 3.0).abs() < 1e-9);

    let outlier = before(
        &truth(
            "[[effect]]\nkind = \"outlier-run\"\nrun = 2\ndirection = \"down\"\noffset_um = 4.0\n",
        ),
        1,
    )
    .unwrap();
    assert_eq!(deviations_um(&outlier, 3), vec![4.0; 5]);
    assert_eq!(deviations_um(&outlier, 1), vec![0.0; 5]);

    // Drift: rate·t with t from the cycle model (2000 mm/min, 3 s dwell, 5 mm overrun):
    // the first reading is at 5 mm / (2000/60 mm/s) + 3 s = 3.15 s.
    let drift = before(
        &truth("[[effect]]\nkind = \"drift\"\nrate_um_per_h = 3600.0\n"),
        1,
    )
    .unwrap();
    assert!(
        (deviations_um(&drift, 0)[0] - 3.15).abs() < 1e-9,
        "{:?}",
        deviations_um(&drift, 0)
    );

    let step = before(
        &truth("[[effect]]\nkind = \"step\"\nposition_mm = 250.0\nstep_um = 2.0\n"),
        1,
    )
    .unwrap();
    assert_eq!(deviations_um(&step, 0), vec![0.0, 0.0, 0.0, 2.0, 2.0]);

    // Sag 4 µm: 4·4·x(400−x)/400² = 0, 3, 4, 3, 0.
    let sag = before(
        &truth("[[effect]]\nkind = \"quadratic\"\nsag_um = 4.0\n"),
        1,
    )
    .unwrap();
    assert_eq!(deviations_um(&sag, 0), vec![0.0, 3.0, 4.0, 3.0, 0.0]);

    // Abbe: 100 mm × 20 µrad·sin(π·x/400) / 1000 = 0, 1.414, 2, 1.414, 0 µm.
    let abbe = before(
        &truth("[[effect]]\nkind = \"abbe\"\noffset_mm = 100.0\nangle_urad = 20.0\n"),
        1,
    )
    .unwrap();
    assert_eq!(deviations_um(&abbe, 0), vec![0.0, 1.414, 2.0, 1.414, 0.0]);
}

#[test]
fn effects_act_only_in_their_tests() {
    let t = truth("[[effect]]\nkind = \"scale\"\nscale_um_per_m = 10.0\ntests = [\"after\"]\n");
    let first = before(&t, 7).unwrap();
    assert!(
        first
            .runs()
            .iter()
            .all(|r| r.deviations.iter().all(|v| *v == Some(0.0)))
    );
    let zero = CompensationTable {
        axis: "X".into(),
        kind: crate::measurement::AxisKind::Linear,
        positions: vec![0.0, 400.0],
        values: TableValues::Mean(vec![0.0, 0.0]),
        reference: 0.0,
        suggested_backlash: None,
    };
    let second = after(&t, &zero, 7).unwrap();
    assert_eq!(deviations_um(&second, 0), vec![0.0, 1.0, 2.0, 3.0, 4.0]);
    // The material was warmer: 10 µm/m at 11.5 ppm/K is 0.87 K.
    let material = second.environment.material_temperature_c[0].start.unwrap();
    assert!((material - (20.0 + 10.0 / 11.5)).abs() < 1e-6, "{material}");
}

#[test]
fn the_table_is_applied_as_the_controller_does() {
    // The axis runs 10 µm/m long; a table holding exactly that leaves nothing.
    let t = truth("[error]\nscale_um_per_m = 10.0\n");
    let perfect = CompensationTable {
        axis: "X".into(),
        kind: crate::measurement::AxisKind::Linear,
        positions: vec![0.0, 400.0],
        values: TableValues::Mean(vec![0.0, 0.004]),
        reference: 0.0,
        suggested_backlash: None,
    };
    let retest = after(&t, &perfect, 1).unwrap();
    // e(m) − v with m = x − v: 10e-3·(x − v) − v·1000 leaves −1e-5·v µm ≈ 0 at 0.001 µm.
    assert!(
        retest
            .runs()
            .iter()
            .all(|r| r.deviations.iter().all(|v| v.unwrap().abs() < 1e-9))
    );
    // A bidirectional table acts per direction: ↓ gets 2 µm more correction everywhere.
    let both = CompensationTable {
        values: TableValues::Bidirectional {
            up: vec![0.0, 0.004],
            down: vec![0.002, 0.006],
        },
        ..perfect
    };
    let retest = after(&t, &both, 1).unwrap();
    assert_eq!(deviations_um(&retest, 1), vec![-2.0; 5]);
}

#[test]
fn seeded_and_reproducible() {
    let t = Truth::from_toml_str(
        "[cycle]\nstart_mm = 0.0\nend_mm = 750.0\ncount = 16\njitter_mm = 9.0\n[noise]\nsigma_um = 0.5\n",
    )
    .unwrap();
    let a = before(&t, 42).unwrap();
    assert_eq!(a, before(&t, 42).unwrap());
    assert_ne!(a.runs(), before(&t, 43).unwrap().runs());
    // Jittered interior targets, ends fixed, 0.001 mm resolution.
    assert_eq!((a.targets()[0], a.targets()[15]), (0.0, 750.0));
    assert!(
        a.targets()
            .iter()
            .all(|t| (t * 1000.0 - (t * 1000.0).round()).abs() < 1e-6)
    );
    assert!(a.targets().windows(2).all(|p| p[1] - p[0] > 50.0 - 18.0));
}

#[test]
fn written_files_read_back_exactly() {
    let t = Truth::from_toml_str(
        "[cycle]\nstart_mm = 0.0\nend_mm = 750.0\ncount = 16\njitter_mm = 9.0\nstart = \"2026-11-20 09:14:00\"\n\
         [noise]\nsigma_um = 0.5\n[[effect]]\nkind = \"drift\"\nrate_um_per_h = 2.0\n",
    )
    .unwrap();
    let m = before(&t, 5).unwrap();
    let (back, _) = parse_str(&rtl::write(&m), SourceFormat::Rtl).unwrap();
    assert_eq!(back.targets(), m.targets());
    for (a, b) in back.runs().iter().zip(m.runs()) {
        assert_eq!(a.deviations, b.deviations);
        assert_eq!((a.direction, a.number), (b.direction, b.number));
    }
    assert_eq!(back.environment, m.environment);
    assert_eq!(back.metadata.duration_s(), m.metadata.duration_s());
    assert_eq!(
        evaluate(&back),
        evaluate(&{
            // The written file has no per-run start times; evaluate does not use them.
            m.clone()
        })
    );
}

#[test]
fn bad_truths_are_refused() {
    for (text, needle) in [
        (
            "[cycle]\nstart_mm = 0.0\nend_mm = 10.0\ncount = 3\n[noise]\nsigma_um = -1.0\n",
            "sigma_um",
        ),
        (
            "[cycle]\nstart_mm = 0.0\nend_mm = 10.0\ncount = 3\n[noise]\nsigma_um = 1.0\n[[effect]]\nkind = \"gremlins\"\n",
            "unknown variant",
        ),
        (
            "[cycle]\nstart_mm = 0.0\nend_mm = 10.0\ncount = 3\n[noise]\nsigma_um = 1.0\n[[effect]]\nkind = \"outlier-run\"\nrun = 1\ndirection = \"sideways\"\noffset_um = 1.0\n",
            "direction",
        ),
        (
            "[cycle]\nstart_mm = 0.0\nend_mm = 10.0\ncount = 3\ntypo = 1\n[noise]\nsigma_um = 1.0\n",
            "unknown field",
        ),
    ] {
        let error = Truth::from_toml_str(text).unwrap_err().to_string();
        assert!(error.contains(needle), "{error}");
    }
    let jittery = Truth::from_toml_str("[cycle]\nstart_mm = 0.0\nend_mm = 10.0\ncount = 3\njitter_mm = 4.0\n[noise]\nsigma_um = 1.0\n").unwrap();
    assert!(
        before(&jittery, 1)
            .unwrap_err()
            .to_string()
            .contains("jitter_mm")
    );
}

#[test]
fn the_environmental_factor_matches_the_air_and_the_material() {
    // A warm material (a scale of 11.5 µm/m at 11.5 ppm/K is +1 K) and a
    // drift that warms the air: the factor follows both, and the report's
    // check finds it within the rounding of its 8 decimals.
    use crate::evaluate::environment::{IndexComparison, check_refractive_index};
    let truth = truth(
        "[environment]\nexpansion_coefficient_ppm_per_k = 11.5\n\n\
         [[effect]]\nkind = \"scale\"\nscale_um_per_m = 11.5\n\n\
         [[effect]]\nkind = \"drift\"\nrate_um_per_h = 20.0\n",
    );
    let m = before(&truth, 1).unwrap();
    let check = check_refractive_index(&m.environment);
    for comparison in [&check.start, &check.end] {
        let IndexComparison::Made(at) = comparison else {
            panic!("{comparison:?}")
        };
        assert!(at.difference_ppm.abs() < 0.05, "{at:?}");
        assert!(at.material_correction_ppm.unwrap() > 11.0, "{at:?}");
    }
    let factor = m.environment.environmental_factor_um;
    assert_ne!(factor.start, factor.end, "the air warmed");
}
