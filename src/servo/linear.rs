//! Exact discretisation of the linear part of the axis model.
//!
//! Between two friction updates the axis (mass, motor, current and velocity
//! PI controllers) is a linear time-invariant system `s' = A s + B u`. With
//! the converter's dead time, the voltage reaching the motor over a step of
//! length h ≤ T_d was computed one dead time earlier, so it is a known input,
//! and the step is an exact linear map once each input is written as a
//! polynomial in the time τ since the start of the step:
//!
//! ```text
//! u(τ) = c0 + c1·τ + c2·τ²/2 + c3·τ³/6
//! s(h) = Φ·s(0) + Γ0·c0 + Γ1·c1 + Γ2·c2 + Γ3·c3
//! ```
//!
//! Φ and Γk come from one matrix exponential of the augmented matrix
//! `[[A, B, 0, 0, 0], [0, 0, I, 0, 0], [0, 0, 0, I, 0], [0, 0, 0, 0, I], [0; 5]]`
//! (Van Loan's construction; the augmented state carries u and its first three
//! derivatives). The exponential is taken once per step length when a
//! simulation starts, by nalgebra's `exp` (scaling and squaring with a Padé
//! approximant, Higham 2005); it is not in the inner loop.
//!
//! This module knows nothing about friction or control; `simulate` does.

use nalgebra::SMatrix;

/// States of the axis: position, velocity, current, velocity-PI state, current-PI state.
pub const N_STATES: usize = 5;
/// Inputs: delayed converter voltage, velocity command, acceleration command, force on the mass.
pub const N_INPUTS: usize = 4;
/// Polynomial degree of the inputs within one step, plus one.
pub const N_COEFFS: usize = 4;

/// The augmented matrix of Van Loan's construction: the states, then the
/// inputs' polynomial coefficients.
type Augmented =
    SMatrix<f64, { N_STATES + N_INPUTS * N_COEFFS }, { N_STATES + N_INPUTS * N_COEFFS }>;

/// The linear system `s' = A s + B u`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearSystem {
    /// State matrix, N_STATES × N_STATES.
    pub a: [[f64; N_STATES]; N_STATES],
    /// Input matrix, N_STATES × N_INPUTS.
    pub b: [[f64; N_INPUTS]; N_STATES],
}

/// The exact step map over one step length.
#[derive(Clone, Debug, PartialEq)]
pub struct StepMap {
    /// Step length, s.
    pub h_s: f64,
    /// State transition Φ = e^{A h}.
    pub phi: [[f64; N_STATES]; N_STATES],
    /// Γk for input j and coefficient k, stored as gamma[state][j * N_COEFFS + k].
    pub gamma: [[f64; N_INPUTS * N_COEFFS]; N_STATES],
}

impl LinearSystem {
    /// The exact map over a step of `h_s` seconds for inputs that are cubic in τ.
    pub fn step_map(&self, h_s: f64) -> StepMap {
        let mut m = Augmented::zeros();
        for i in 0..N_STATES {
            for j in 0..N_STATES {
                m[(i, j)] = self.a[i][j] * h_s;
            }
            for j in 0..N_INPUTS {
                m[(i, N_STATES + j)] = self.b[i][j] * h_s;
            }
        }
        // The input chain: d/dτ of coefficient block k is block k + 1.
        for k in 0..N_COEFFS - 1 {
            for j in 0..N_INPUTS {
                m[(
                    N_STATES + k * N_INPUTS + j,
                    N_STATES + (k + 1) * N_INPUTS + j,
                )] = h_s;
            }
        }
        // Time is scaled by h (σ = τ/h), so every block carries one factor h
        // and block k of the exponential multiplies the unscaled c_k directly.
        let e = m.exp();
        let mut map = StepMap {
            h_s,
            phi: [[0.0; N_STATES]; N_STATES],
            gamma: [[0.0; N_INPUTS * N_COEFFS]; N_STATES],
        };
        for i in 0..N_STATES {
            for j in 0..N_STATES {
                map.phi[i][j] = e[(i, j)];
            }
            for k in 0..N_COEFFS {
                for j in 0..N_INPUTS {
                    map.gamma[i][j * N_COEFFS + k] = e[(i, N_STATES + k * N_INPUTS + j)];
                }
            }
        }
        map
    }
}

impl StepMap {
    /// s(h) = Φ s(0) + Σ Γ·coefficients.
    #[inline]
    pub fn apply(
        &self,
        state: &[f64; N_STATES],
        coefficients: &[f64; N_INPUTS * N_COEFFS],
    ) -> [f64; N_STATES] {
        let mut out = [0.0; N_STATES];
        for (i, row) in out.iter_mut().enumerate() {
            let mut acc = 0.0;
            for (p, x) in self.phi[i].iter().zip(state) {
                acc += p * x;
            }
            for (g, c) in self.gamma[i].iter().zip(coefficients) {
                acc += g * c;
            }
            *row = acc;
        }
        out
    }

    /// The column of Γ0 for one input: how a constant unit input moves each state over the step.
    #[inline]
    pub fn constant_input_response(&self, input: usize) -> [f64; N_STATES] {
        let mut out = [0.0; N_STATES];
        for (i, value) in out.iter_mut().enumerate() {
            *value = self.gamma[i][input * N_COEFFS];
        }
        out
    }
}

/// Taylor coefficients [p, p', p'', p'''] at τ = 0 of the cubic Hermite
/// interpolant through (0, p0, d0) and (h, p1, d1).
#[inline]
pub fn hermite(p0: f64, d0: f64, p1: f64, d1: f64, h: f64) -> [f64; N_COEFFS] {
    let gap = p1 - p0 - d0 * h;
    let slope_change = d1 - d0;
    let c3 = (6.0 * slope_change * h - 12.0 * gap) / (h * h * h);
    let c2 = slope_change / h - c3 * h / 2.0;
    [p0, d0, c2, c3]
}

/// The same cubic re-expanded about τ = `shift`.
#[inline]
pub fn taylor_shift(c: &[f64; N_COEFFS], shift: f64) -> [f64; N_COEFFS] {
    let [c0, c1, c2, c3] = *c;
    [
        c0 + shift * (c1 + shift * (c2 / 2.0 + shift * c3 / 6.0)),
        c1 + shift * (c2 + shift * c3 / 2.0),
        c2 + shift * c3,
        c3,
    ]
}

/// Value and first derivative of the cubic at τ.
#[inline]
pub fn cubic_value_slope(c: &[f64; N_COEFFS], tau: f64) -> (f64, f64) {
    let shifted = taylor_shift(c, tau);
    (shifted[0], shifted[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_of_a_rotation_is_cos_and_sin() {
        // e^{[[0, −θ], [θ, 0]]} = [[cos θ, −sin θ], [sin θ, cos θ]] (closed form).
        let theta: f64 = 7.3;
        let m = nalgebra::Matrix2::new(0.0, -theta, theta, 0.0);
        let e = m.exp();
        assert!((e[(0, 0)] - theta.cos()).abs() < 1e-13);
        assert!((e[(1, 0)] - theta.sin()).abs() < 1e-13);
        assert!((e[(0, 1)] + theta.sin()).abs() < 1e-13);
    }

    #[test]
    fn step_map_of_a_double_integrator_is_exact_for_a_cubic_force() {
        // x' = v, v' = u with u(τ) = c0 + c1 τ + c2 τ²/2 + c3 τ³/6:
        // v(h) = v0 + c0 h + c1 h²/2 + c2 h³/6 + c3 h⁴/24 and
        // x(h) = x0 + v0 h + c0 h²/2 + c1 h³/6 + c2 h⁴/24 + c3 h⁵/120 (by hand).
        let mut system = LinearSystem {
            a: [[0.0; N_STATES]; N_STATES],
            b: [[0.0; N_INPUTS]; N_STATES],
        };
        system.a[0][1] = 1.0;
        system.b[1][3] = 1.0;
        let h = 0.37;
        let map = system.step_map(h);
        let mut coefficients = [0.0; N_INPUTS * N_COEFFS];
        let c = [1.5, -2.0, 3.0, 0.7];
        coefficients[3 * N_COEFFS..].copy_from_slice(&c);
        let state = [0.2, -0.4, 0.0, 0.0, 0.0];
        let out = map.apply(&state, &coefficients);
        let v = -0.4
            + c[0] * h
            + c[1] * h.powi(2) / 2.0
            + c[2] * h.powi(3) / 6.0
            + c[3] * h.powi(4) / 24.0;
        let x = 0.2 - 0.4 * h
            + c[0] * h.powi(2) / 2.0
            + c[1] * h.powi(3) / 6.0
            + c[2] * h.powi(4) / 24.0
            + c[3] * h.powi(5) / 120.0;
        assert!((out[1] - v).abs() < 1e-14, "{} vs {v}", out[1]);
        assert!((out[0] - x).abs() < 1e-14, "{} vs {x}", out[0]);
    }

    #[test]
    fn hermite_reproduces_a_cubic_and_shifts_consistently() {
        // p(τ) = 1 − 2τ + 3τ²/2 + 4τ³/6; values and slopes at 0 and h by hand.
        let p = |t: f64| 1.0 - 2.0 * t + 1.5 * t * t + 4.0 * t.powi(3) / 6.0;
        let dp = |t: f64| -2.0 + 3.0 * t + 2.0 * t * t;
        let h = 0.8;
        let c = hermite(p(0.0), dp(0.0), p(h), dp(h), h);
        for (got, want) in c.iter().zip([1.0, -2.0, 3.0, 4.0]) {
            assert!((got - want).abs() < 1e-12);
        }
        let (value, slope) = cubic_value_slope(&c, 0.3);
        assert!((value - p(0.3)).abs() < 1e-14 && (slope - dp(0.3)).abs() < 1e-14);
    }
}
