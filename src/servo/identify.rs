//! The identification arithmetic of Mendřický (2006) ch. 5 and the derived
//! parameters of ch. 3–4, as small functions (SI units throughout).
//!
//! These are the closed forms Mendřický (2006) uses to get friction, mass and
//! stiffness from currents, dial-gauge readings and catalogue data; the unit
//! tests check each against Mendřický's own numbers (notes §9). Callers:
//! `axis` (the LuGre damping of eq. 4.15 for every axis file) and
//! `friction_fit` (`servo-sim --identify`: the linear fit of the
//! constant-velocity currents, [`coulomb_viscous_fit`], the feed conversion
//! and the damping again); the other closed forms (guide estimate, current
//! jump, circle mass, slider, motor and loop constants) are Mendřický's
//! arithmetic, checked here and not called elsewhere.

/// Guide friction estimate (eq. 5.1, 5.2): equivalent load per carriage
/// P = F_p + (F_mag + F_g)/p, friction μ·P·p, N. Seals and covers excluded.
pub fn guide_friction_n(
    preload_n: f64,
    magnetic_attraction_n: f64,
    weight_n: f64,
    carriages: f64,
    friction_coefficient: f64,
) -> f64 {
    let load_per_carriage_n = preload_n + (magnetic_attraction_n + weight_n) / carriages;
    friction_coefficient * load_per_carriage_n * carriages
}

/// Coulomb friction from the current jump at a reversal, F_C = (I_C/2)·K_F3 (eq. 5.3), N.
pub fn coulomb_from_current_jump_n(current_jump_a: f64, force_constant_n_per_a: f64) -> f64 {
    current_jump_a / 2.0 * force_constant_n_per_a
}

/// Viscous coefficient from the current at the speed maximum of a circle,
/// μ_v = (I_T·K_F3 − F_C)/v (eq. 5.7–5.9), N·s/m.
pub fn viscous_from_current_n_s_per_m(
    current_a: f64,
    force_constant_n_per_a: f64,
    coulomb_n: f64,
    velocity_m_per_s: f64,
) -> f64 {
    (current_a * force_constant_n_per_a - coulomb_n) / velocity_m_per_s
}

/// F_C and μ_v from the friction force at constant speeds, Mendřický's
/// linear fit of Fig. 5.1 (§5.2): least squares of F = F_C + μ_v·|v| over
/// the rows, with F the force against the motion (sgn v · K_F3 · I, so runs
/// in both directions count alike). `None` with fewer than two distinct
/// speeds. Returns (F_C N, μ_v N·s/m).
pub fn coulomb_viscous_fit(speeds_m_per_s: &[f64], forces_n: &[f64]) -> Option<(f64, f64)> {
    let n = speeds_m_per_s.len().min(forces_n.len());
    if n < 2 {
        return None;
    }
    let mean_v = speeds_m_per_s[..n].iter().sum::<f64>() / n as f64;
    let mean_f = forces_n[..n].iter().sum::<f64>() / n as f64;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (v, f) in speeds_m_per_s[..n].iter().zip(&forces_n[..n]) {
        sxy += (v - mean_v) * (f - mean_f);
        sxx += (v - mean_v) * (v - mean_v);
    }
    if sxx <= 1e-24 {
        return None;
    }
    let viscous = sxy / sxx;
    Some((mean_f - viscous * mean_v, viscous))
}

/// Moving mass from the current step at a circle reversal (eq. 5.10–5.12):
/// m = (I_a/2)·K_F3 / (v²/R), kg.
pub fn mass_from_circle_kg(
    current_step_a: f64,
    force_constant_n_per_a: f64,
    radius_m: f64,
    feed_m_per_s: f64,
) -> f64 {
    current_step_a / 2.0 * force_constant_n_per_a / (feed_m_per_s * feed_m_per_s / radius_m)
}

/// LuGre bristle damping b_s = 2·ζ_s·√(k_s·m) (eq. 4.15), N·s/m.
pub fn lugre_damping_n_s_per_m(stiffness_n_per_m: f64, mass_kg: f64, damping_ratio: f64) -> f64 {
    2.0 * damping_ratio * (stiffness_n_per_m * mass_kg).sqrt()
}

/// Stiffness and damping of a mass on a spring with natural frequency f and
/// damping ratio ζ (eq. 3.17, 3.18, the scale slider): (k, b) in N/m and N·s/m.
pub fn spring_damper(mass_kg: f64, natural_frequency_hz: f64, damping_ratio: f64) -> (f64, f64) {
    let omega = 2.0 * std::f64::consts::PI * natural_frequency_hz;
    let stiffness = omega * omega * mass_kg;
    (
        stiffness,
        2.0 * damping_ratio * (stiffness * mass_kg).sqrt(),
    )
}

/// Three-phase motor force constant K_F3 = (3/2)·K_F of one coil (eq. 3.14), N/A.
pub fn three_phase_force_constant_n_per_a(coil_force_constant_n_per_a: f64) -> f64 {
    1.5 * coil_force_constant_n_per_a
}

/// Converter dead time as half a PWM period, T_d = 1/(2·f_PWM) (§3.2.2.1), s.
pub fn converter_dead_time_s(pwm_frequency_hz: f64) -> f64 {
    1.0 / (2.0 * pwm_frequency_hz)
}

/// Position gain from the machine-tool unit m/min per mm to 1/s.
pub fn position_gain_per_s(gain_m_per_min_per_mm: f64) -> f64 {
    gain_m_per_min_per_mm / 60.0 / 1e-3
}

/// Feed from m/min to m/s.
pub fn m_per_min_to_m_per_s(feed_m_per_min: f64) -> f64 {
    feed_m_per_min / 60.0
}

#[cfg(test)]
mod tests {
    //! Every expected number is Mendřický's, as listed in notes §9 (row numbers in comments).

    use super::*;
    use crate::servo::friction::{Power, Ramp};
    use approx::assert_abs_diff_eq;

    #[test]
    fn guide_friction_estimate() {
        // §9 row 1: P = 2950 + (15000 + 2000)/6 = 5783 N; F_Tx = 0.003·5783·6 = 104.1 N.
        assert_abs_diff_eq!(
            guide_friction_n(2950.0, 15_000.0, 2000.0, 6.0, 0.003),
            104.1,
            epsilon = 0.05
        );
    }

    #[test]
    fn coulomb_friction_from_fit_and_current_jump() {
        // §9 row 2: F_C = μ0·v0 = 12000·0.55/60 = 110 N (linear fit of Fig. 5.1).
        let ramp = Ramp {
            coulomb_n: 110.0,
            viscous_n_s_per_m: 430.0,
            slope_n_s_per_m: 12_000.0,
        };
        assert_abs_diff_eq!(ramp.corner_velocity_m_per_s() * 60.0, 0.55, epsilon = 1e-12);
        assert_abs_diff_eq!(12_000.0 * m_per_min_to_m_per_s(0.55), 110.0, epsilon = 1e-9);
        // §9 row 3: I_C = 2.2 A, K_F3 = 94: F_C = 103.4 N (eq. 5.3).
        assert_abs_diff_eq!(
            coulomb_from_current_jump_n(2.2, 94.0),
            103.4,
            epsilon = 1e-9
        );
    }

    #[test]
    fn viscous_coefficients_of_tab_5_2() {
        // §9 row 4 (Tab. 5.2): F_C = 103.4 N; I_T at 3.2, 8, 16, 24 m/min;
        // F_T = 94·I_T. The table prints v rounded (0.05 m/s …) but computes
        // μ_v with the exact feed/60.
        let rows = [
            (3.2, 1.42, 133.48, 564.0),
            (8.0, 1.72, 161.68, 437.1),
            (16.0, 2.12, 199.28, 359.6),
            (24.0, 2.56, 240.64, 343.1),
        ];
        for (feed, current, force, viscous) in rows {
            let v = m_per_min_to_m_per_s(feed);
            assert_abs_diff_eq!(current * 94.0, force, epsilon = 1e-9);
            // The table rounds to 0.1 N·s/m (359.55 → 359.6).
            let identified = viscous_from_current_n_s_per_m(current, 94.0, 103.4, v);
            assert_abs_diff_eq!(identified, viscous, epsilon = 0.0501);
        }
    }

    #[test]
    fn linear_fit_of_tab_5_1() {
        // Tab. 5.1 (notes §4.2) from 1 m/min up, F = 94·I as tabulated: the
        // least-squares line computed by hand (Python, two-pass means) is
        // F_C = 125.03 N, μ_v = 313.03 N·s/m (Mendřický's B1 fit reads
        // 110 N and 430 N·s/m off the same curve with its corner v0).
        let feeds = [1.0, 3.2, 5.0, 8.0, 10.0, 16.0, 24.0];
        let forces = [117.5, 141.9, 159.8, 166.4, 188.0, 205.9, 246.3];
        let speeds: Vec<f64> = feeds.iter().map(|&f| m_per_min_to_m_per_s(f)).collect();
        let (coulomb, viscous) = coulomb_viscous_fit(&speeds, &forces).unwrap();
        assert_abs_diff_eq!(coulomb, 125.029, epsilon = 0.001);
        assert_abs_diff_eq!(viscous, 313.035, epsilon = 0.001);
        assert_eq!(coulomb_viscous_fit(&[0.1, 0.1], &[5.0, 6.0]), None);
        assert_eq!(coulomb_viscous_fit(&[0.1], &[5.0]), None);
    }

    #[test]
    fn mass_and_centripetal_force_from_the_circle() {
        // §9 row 5: I_a = 8.4 A, R = 0.09 m, 24 m/min: m = 222.1 kg (eq. 5.12).
        assert_abs_diff_eq!(
            mass_from_circle_kg(8.4, 94.0, 0.09, m_per_min_to_m_per_s(24.0)),
            222.1,
            epsilon = 0.05
        );
        // §9 row 6: a = v²/R = 0.1975 and 1.778 m/s² at 8 and 24 m/min; F_a = 43.5 and 391 N with m = 220 kg.
        for (feed, acceleration, force) in [(8.0, 0.1975, 43.5), (24.0, 1.778, 391.0)] {
            let v = m_per_min_to_m_per_s(feed);
            assert_abs_diff_eq!(v * v / 0.09, acceleration, epsilon = 5e-4);
            assert_abs_diff_eq!(220.0 * v * v / 0.09, force, epsilon = 0.5);
        }
    }

    #[test]
    fn pre_sliding_stiffness_and_lugre_damping() {
        // §9 row 8 (Tab. 5.3): 120 N / 4.3 µm ≈ 2.8e7 N/m, 100 N / 47 µm ≈ 2.1e6 N/m.
        assert_abs_diff_eq!(120.0 / 4.3e-6, 2.8e7, epsilon = 0.01e7);
        assert_abs_diff_eq!(100.0 / 47e-6, 2.1e6, epsilon = 0.05e6);
        // §9 row 9: Tab. 4.3, b_s = 0.2·√(4e7·400) = 25 298 N·s/m.
        assert_abs_diff_eq!(
            lugre_damping_n_s_per_m(4e7, 400.0, 0.1),
            25_298.2,
            epsilon = 0.1
        );
    }

    #[test]
    fn slider_motor_and_loop_constants() {
        // §9 row 10: m_j = 0.5 kg, 2 kHz, ζ 0.05: k_j = 7.896e7 N/m, b_j = 628.3 N·s/m.
        let (k, b) = spring_damper(0.5, 2000.0, 0.05);
        assert_abs_diff_eq!(k, 7.896e7, epsilon = 0.001e7);
        assert_abs_diff_eq!(b, 628.3, epsilon = 0.05);
        // §9 rows 11–13: K_F3 = 1.5·62.8 = 94.2 N/A; T_d = 0.125 ms; K_v = 83.3 1/s.
        assert_abs_diff_eq!(
            three_phase_force_constant_n_per_a(62.8),
            94.2,
            epsilon = 1e-9
        );
        assert_abs_diff_eq!(converter_dead_time_s(4000.0), 0.125e-3, epsilon = 1e-15);
        assert_abs_diff_eq!(position_gain_per_s(5.0), 83.33, epsilon = 0.005);
    }

    #[test]
    fn b2_force_steps_near_zero_velocity() {
        // §9 row 14: a = 300, n = 4: F(2e-5) − F(1e-5) = 3.19 N, F(1e-5) − F(0) = 16.87 N.
        let b2 = Power {
            coefficient_n: 300.0,
            order: 4.0,
        };
        assert_abs_diff_eq!(b2.force_n(2e-5) - b2.force_n(1e-5), 3.19, epsilon = 0.005);
        assert_abs_diff_eq!(b2.force_n(1e-5) - b2.force_n(0.0), 16.87, epsilon = 0.005);
        // Mendřický's B1 figure of 0.07 N does not follow from μ0 = 12 000:
        // the same 1e-5 m/s step gives 0.12 N (notes §5.2, an inconsistency in the text).
        let b1 = Ramp {
            coulomb_n: 115.0,
            viscous_n_s_per_m: 430.0,
            slope_n_s_per_m: 12_000.0,
        };
        assert_abs_diff_eq!(b1.force_n(1e-5) - b1.force_n(0.0), 0.12, epsilon = 1e-9);
    }
}
