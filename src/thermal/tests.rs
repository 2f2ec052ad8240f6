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
