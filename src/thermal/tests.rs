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
fn drift_column_optional_reads_a_log_without_it_once() {
    let text = "time [s],T1\n0,20\n60,20.5\n";
    let mut options = LogOptions {
        drift: Some("d".to_string()),
        sample_interval_s: None,
        drift_optional: false,
    };
    let refused = parse_log(text, &options).unwrap_err();
    assert_eq!((refused.position.line, refused.position.column), (1, 1));
    options.drift_optional = true;
    let log = parse_log(text, &options).unwrap();
    assert_eq!(log.drift, None);
    assert_eq!(log.sensors[0].celsius, [20.0, 20.5]);
    // With the column present, it is the drift.
    let log = parse_log("time [s],d,T1\n0,0,20\n60,1.5,20.5\n", &options).unwrap();
    assert_eq!(log.drift.unwrap().um, [0.0, 1.5]);
}

/// A sensor named `T` (or `t [°C]`) is a temperature; `t [min]` is the time.
#[test]
fn a_column_named_t_is_a_time_only_with_a_time_unit() {
    let options = LogOptions {
        drift: Some("d".to_string()),
        sample_interval_s: Some(60.0),
        drift_optional: false,
    };
    let log = parse_log("d,T,t [°C]\n0,20,21\n1.5,20.5,21.5\n", &options).unwrap();
    assert_eq!(log.sensors.len(), 2);
    assert_eq!(log.sensors[0].celsius, [20.0, 20.5]);
    assert_eq!(log.sensors[1].celsius, [21.0, 21.5]);
    let options = LogOptions {
        sample_interval_s: None,
        ..options
    };
    let log = parse_log("t [min],d,T\n0,0,20\n2,1.5,20.5\n", &options).unwrap();
    assert_eq!(log.sensors.len(), 1);
    assert_eq!(log.times_s, [0.0, 120.0]);
    assert_eq!(log.drift.unwrap().um, [0.0, 1.5]);
}

/// With no sensor chosen the cross-validated rms is the drift's own rms
/// over the rows predicted: all of them for the blocked validation, all
/// but the first block for the forward one (it is never predicted).
#[test]
fn forward_validation_never_predicts_the_first_block() {
    let drift: Vec<f64> = vec![0.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 5.0, 6.0];
    let log = ThermalLog {
        times_s: (0..10).map(|k| 60.0 * k as f64).collect(),
        drift: Some(Drift {
            name: "d".into(),
            um: drift.clone(),
        }),
        sensors: vec![Sensor {
            name: "T1".into(),
            celsius: vec![20.0; 10],
        }],
        lines: (2..12).collect(),
    };
    let mut options = FitOptions::over(0..10);
    options.max_sensors = 0;
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let blocked = fit(&log, &options).unwrap();
    assert!((blocked.fit.cv_rms_um - rms(&drift)).abs() < 1e-12);
    options.validation = Validation::Forward;
    let forward = fit(&log, &options).unwrap();
    // Five blocks of two rows: rows 3–10 predicted.
    assert!((forward.fit.cv_rms_um - rms(&drift[2..])).abs() < 1e-12);
    assert_eq!(forward.fit.validation, Validation::Forward);
}
