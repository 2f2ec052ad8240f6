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

/// The late validation predicts the blocks of the last third only: with no
/// sensor chosen its cross-validated rms is the drift's rms over rows
/// 21–30 of 30 (the first 20 are never predicted); a log whose last third
/// cannot give each block two rows is refused.
#[test]
fn late_validation_predicts_only_the_last_third() {
    let drift: Vec<f64> = (0..30)
        .map(|k| f64::from(k % 7) - 0.5 * f64::from(k))
        .collect();
    let log = one_sensor_log(drift.clone());
    let mut options = FitOptions::over(0..30);
    options.max_sensors = 0;
    options.validation = Validation::Late;
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let late = fit(&log, &options).unwrap();
    assert!((late.fit.cv_rms_um - rms(&drift[20..])).abs() < 1e-12);
    assert_eq!(late.fit.validation.name(), "late");
    // 12 rows: the last third is 4 rows, too few for five blocks of two.
    options.rows = 0..12;
    let refused = fit(&log, &options).unwrap_err().to_string();
    assert!(
        refused.contains("each of the 5 blocks of the last third needs at least two"),
        "{refused}"
    );
}

fn one_sensor_log(drift: Vec<f64>) -> ThermalLog {
    let rows = drift.len();
    ThermalLog {
        times_s: (0..rows).map(|k| 60.0 * k as f64).collect(),
        drift: Some(Drift {
            name: "d".into(),
            um: drift,
        }),
        sensors: vec![Sensor {
            name: "T1".into(),
            celsius: vec![20.0; rows],
        }],
        lines: (2..rows + 2).collect(),
    }
}

/// Nonnegative least squares against solutions by hand.
#[test]
fn nonnegative_least_squares_by_hand() {
    use nalgebra::{DMatrix, DVector};
    // A = I, v = (1, −2): the free solution (1, −2); the second held at 0.
    let c = model::nonnegative(
        &DMatrix::identity(2, 2),
        &DVector::from_vec(vec![1.0, -2.0]),
    );
    assert_eq!(c.unwrap().as_slice(), [1.0, 0.0]);
    // A = [[2, 1], [1, 2]], v = (−1, 3): free solution A⁻¹v = (−5/3, 7/3);
    // with c₁ = 0, c₂ = 3/2, and the gradient v₁ − A₁₂·c₂ = −2.5 < 0 keeps c₁ at 0.
    let a = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 2.0]);
    let c = model::nonnegative(&a, &DVector::from_vec(vec![-1.0, 3.0])).unwrap();
    assert!(c[0] == 0.0 && (c[1] - 1.5).abs() < 1e-15, "{c}");
    // An interior solution is the free one: v = (4, 5) gives (1, 2).
    let c = model::nonnegative(&a, &DVector::from_vec(vec![4.0, 5.0])).unwrap();
    assert!(
        (c[0] - 1.0).abs() < 1e-14 && (c[1] - 2.0).abs() < 1e-14,
        "{c}"
    );
}

/// A log of a heated "bearing", a "chiller" that dips below the room once
/// but is warmer on average, and the "room" (the coldest on average), with
/// the drift `drift(bearing, room)`.
fn three_sensor_log(drift: impl Fn(f64, f64) -> f64) -> ThermalLog {
    let rows = 90;
    let bearing: Vec<f64> = (0..rows)
        .map(|k| {
            let k = f64::from(k);
            30.0 + 10.0 * (1.0 - (-k / 30.0).exp()) + 0.3 * (k / 5.0).sin()
        })
        .collect();
    let room: Vec<f64> = (0..rows)
        .map(|k| 18.0 + 0.5 * (f64::from(k) / 7.0).sin())
        .collect();
    let chiller: Vec<f64> = (0..rows)
        .map(|k| {
            if k == 40 {
                17.0
            } else {
                24.0 + 0.2 * (f64::from(k) / 3.0).cos()
            }
        })
        .collect();
    let um = bearing
        .iter()
        .zip(&room)
        .map(|(&b, &r)| drift(b - bearing[0], r - room[0]))
        .collect();
    let sensor = |name: &str, celsius: Vec<f64>| Sensor {
        name: name.into(),
        celsius,
    };
    ThermalLog {
        times_s: (0..rows).map(|k| 60.0 * f64::from(k)).collect(),
        drift: Some(Drift {
            name: "d".into(),
            um,
        }),
        sensors: vec![
            sensor("bearing", bearing),
            sensor("chiller", chiller),
            sensor("room", room),
        ],
        lines: (2..rows as usize + 2).collect(),
    }
}

/// The automatic reference is the coldest sensor on average over the fit
/// rows (the room, though the chiller dips below it once), kept when it
/// predicts better than none: a drift of 2 µm/K of the bearing's rise over
/// the room takes the room as the reference (coefficients +2 and −2, one
/// sensor allowed); a drift of the bearing alone takes none.
#[test]
fn automatic_reference_is_the_coldest_sensor() {
    let names: Vec<String> = ["bearing", "chiller", "room"].map(String::from).into();
    let difference = three_sensor_log(|b, r| 2.0 * (b - r));
    assert_eq!(
        coldest(&difference, &names, &(0..90)).as_deref(),
        Some("room")
    );
    // Over rows where the chiller's dip is all there is, it is the coldest.
    assert_eq!(
        coldest(&difference, &names, &(40..41)).as_deref(),
        Some("chiller")
    );
    let mut options = FitOptions::over(0..90);
    options.auto_reference = true;
    options.validation = Validation::Late;
    options.max_sensors = 1;
    let model = fit(&difference, &options).unwrap();
    assert_eq!(model.fit.reference.as_deref(), Some("room"));
    let terms: Vec<(&str, f64, f64)> = model
        .terms
        .iter()
        .map(|t| (t.sensor.as_str(), t.tau_s, t.coefficient_um_per_k))
        .collect();
    assert_eq!(terms.len(), 2, "{terms:?}");
    assert_eq!((terms[0].0, terms[0].1), ("bearing", 0.0));
    assert_eq!((terms[1].0, terms[1].1), ("room", 0.0));
    assert!((terms[0].2 - 2.0).abs() < 1e-9 && (terms[1].2 + 2.0).abs() < 1e-9);
    let alone = fit(&three_sensor_log(|b, _| 2.0 * b), &options).unwrap();
    assert_eq!(alone.fit.reference, None);
    assert_eq!(alone.terms[0].sensor, "bearing");
}

/// With `same_sign`, the rises over the reference take the drift's sign:
/// a drift of 2 µm/K of the bearing's rise over the room minus 3 µm/K of
/// the chiller's is fitted exactly by free least squares (+2, −3); held to
/// the drift's sign (it grows), the chiller cannot enter with −3.
#[test]
fn same_sign_keeps_every_rise_in_the_drift_direction() {
    let mut log = three_sensor_log(|b, r| 2.0 * (b - r));
    let chiller = log.sensors[1].celsius.clone();
    let room = log.sensors[2].celsius.clone();
    let drift = &mut log.drift.as_mut().unwrap().um;
    for k in 0..drift.len() {
        drift[k] -= 3.0 * ((chiller[k] - room[k]) - (chiller[0] - room[0]));
    }
    assert!(drift.iter().sum::<f64>() > 0.0, "the drift grows");
    let mut options = FitOptions::over(0..90);
    options.reference = Some("room".into());
    options.max_sensors = 2;
    let coefficient = |model: &ThermalModel, name: &str| {
        model
            .terms
            .iter()
            .find(|t| t.sensor == name)
            .map(|t| t.coefficient_um_per_k)
    };
    let free = fit(&log, &options).unwrap();
    assert!((coefficient(&free, "bearing").unwrap() - 2.0).abs() < 1e-9);
    assert!((coefficient(&free, "chiller").unwrap() + 3.0).abs() < 1e-9);
    options.same_sign = true;
    let signed = fit(&log, &options).unwrap();
    assert!(signed.terms.iter().any(|t| t.sensor == "bearing"));
    for term in signed.terms.iter().filter(|t| t.sensor != "room") {
        assert!(term.coefficient_um_per_k >= 0.0, "{term:?}");
    }
}
