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
