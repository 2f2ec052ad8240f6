//! The thermal stage against hand-computed values.

use super::*;

#[test]
fn lag_is_the_exact_first_order_step() {
    // A step from 0 to 1 at t = 0 held: y(t) = 1 − e^(−t/τ); the first row is the start.
    let times = [0.0, 10.0, 20.0, 30.0];
    let values = [0.0, 1.0, 1.0, 1.0];
    let mut out = Vec::new();
    lag(&values, &times, 10.0, &mut out);
    let e = (-1.0f64).exp();
    // y1 = 0 + (1 − e⁻¹)(1 − 0); y2 = y1 + (1 − e⁻¹)(1 − y1) = 1 − e⁻², …
    assert!((out[0] - 0.0).abs() < 1e-15);
    assert!((out[1] - (1.0 - e)).abs() < 1e-15);
    assert!((out[2] - (1.0 - e * e)).abs() < 1e-15);
    assert!((out[3] - (1.0 - e * e * e)).abs() < 1e-15);
    lag(&values, &times, 0.0, &mut out);
    assert_eq!(out, values);
}

#[test]
#[ignore]
fn explore_real_log() {
    let text = std::fs::read_to_string(
        "../shared/data/thermal/data__thermal expansion error original.csv",
    )
    .unwrap();
    let log = parse_log(
        &text,
        &LogOptions {
            drift: Some("delta L".into()),
            sample_interval_s: Some(60.0),
        },
    )
    .unwrap();
    for (sensors, reference) in [
        (vec![], None),
        (vec![], Some("T14")),
        (vec!["T0", "T1", "T2", "T3", "T4"], Some("T14")),
        (vec!["T0", "T1", "T2", "T3", "T4"], Some("T15")),
        (vec!["T0", "T1", "T2", "T3", "T4"], None),
    ] {
        let mut options = FitOptions::over(0..1500);
        options.sensors = sensors.iter().map(|s| s.to_string()).collect();
        options.reference = reference.map(str::to_string);
        let model = fit(&log, &options).unwrap();
        let applied = apply(&model, &log).unwrap();
        let r = applied.residual_um().unwrap();
        let held = &r[1500..];
        let rms = (held.iter().map(|v| v * v).sum::<f64>() / held.len() as f64).sqrt();
        let max = held.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        println!(
            "{sensors:?} {reference:?}: cv {:.3} fit {:.3} held {rms:.3} / {max:.3}",
            model.fit.cv_rms_um, model.fit.fit_rms_um
        );
        for t in &model.terms {
            println!(
                "   {} tau {} min c {:.3}",
                t.sensor,
                t.tau_s / 60.0,
                t.coefficient_um_per_k
            );
        }
    }
}
