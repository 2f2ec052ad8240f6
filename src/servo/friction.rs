//! The four friction models of Mendřický (2006, ch. 4;
//! `../shared/notes/seed004-friction-model.md` §2.6–2.9), each a small type
//! with its parameters in SI units, and their implicit update over one step.
//!
//! - [`Classic`] (model A, §4.2): static friction F_Ts at v = 0 (the friction
//!   takes the applied force up to ±F_Ts), Coulomb plus viscous F_C + μ_v|v|
//!   while sliding.
//! - [`Ramp`] (model B1, §4.3.1.1): μ0·v for |v| ≤ v0 = F_C/μ0, then
//!   F_C + μ_v(|v| − v0); velocity only, no stick state.
//! - [`Power`] (model B2, eq. 4.1): a·|v|^(1/n)·sgn v, v in m/s; infinite
//!   slope at v = 0.
//! - [`LuGre`] (model C, eq. 4.2–4.6): bristle state z with
//!   ż = v − |v|·z/g(v), k_s·g(v) = F_C + (F_Ts − F_C)·exp(−v²/v_s²),
//!   F_T = k_s z + b_s ż + μ_v v.
//!
//! Sign convention (thesis Fig. 2.1): F_T opposes motion, m·v' = F_motor − F_T
//! (− an external force), so F_T > 0 while moving in +x.
//!
//! # Why an implicit step
//!
//! The simulation advances the linear part of the axis exactly (`linear`), so
//! over a step of length h the end velocity is `v = v_free − α·F_T` with F_T
//! held over the step and α ≈ h/m. Each model here solves that equation with
//! F_T evaluated at the end of the step (implicit Euler in the friction
//! force). That makes the stiff parts unconditionally stable without a tiny
//! step: the stick of model A is the set-valued law at v = 0 (the force that
//! brings the mass to rest, if it is within ±F_Ts), B2's infinite slope does
//! not chatter (Mendřický's ±15 N chatter, §6.2, is an artefact of explicit
//! stepping), and LuGre's bristle state is advanced by the exact solution of
//! ż = v − |v| z/g with v held (notes §7), which stays bounded (|z| ≤ g,
//! property 1 of Mendřický's ref. 13) at any step. With Mendřický's F_Ts = F_C, g is
//! constant and every equation solved here is monotone, so the solution is
//! unique.

/// Model A, "classic": static + Coulomb + viscous friction with a stick state (thesis §4.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Classic {
    /// Coulomb friction F_C, N.
    pub coulomb_n: f64,
    /// Static (break-away) friction F_Ts ≥ F_C, N.
    pub static_n: f64,
    /// Viscous coefficient μ_v, N·s/m.
    pub viscous_n_s_per_m: f64,
}

/// Model B1, "linear ramp": two slopes through zero (thesis §4.3.1.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ramp {
    /// Coulomb friction F_C reached at v0, N.
    pub coulomb_n: f64,
    /// Viscous coefficient μ_v above v0, N·s/m.
    pub viscous_n_s_per_m: f64,
    /// Slope μ0 below v0, N·s/m; v0 = F_C/μ0.
    pub slope_n_s_per_m: f64,
}

/// Model B2, "parabolic" power law F = a·|v|^(1/n)·sgn v with v in m/s (thesis eq. 4.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Power {
    /// Coefficient a, N at 1 m/s.
    pub coefficient_n: f64,
    /// Order n ≥ 1 (the exponent is 1/n).
    pub order: f64,
}

/// Model C, LuGre (thesis §4.4, eq. 4.2–4.6; Canudas de Wit et al. 1995).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LuGre {
    /// Bristle (pre-sliding) stiffness k_s, N/m.
    pub stiffness_n_per_m: f64,
    /// Bristle damping b_s, N·s/m (eq. 4.15: 2·ζ_s·√(k_s·m)).
    pub damping_n_s_per_m: f64,
    /// Viscous coefficient μ_v, N·s/m.
    pub viscous_n_s_per_m: f64,
    /// Coulomb friction F_C, N.
    pub coulomb_n: f64,
    /// Static friction F_Ts ≥ F_C, N.
    pub static_n: f64,
    /// Stribeck velocity v_s, m/s.
    pub stribeck_velocity_m_per_s: f64,
}

/// One of the four models.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Friction {
    /// Model A.
    Classic(Classic),
    /// Model B1.
    Ramp(Ramp),
    /// Model B2.
    Power(Power),
    /// Model C.
    LuGre(LuGre),
}

/// Which model, without parameters: what `--friction` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FrictionKind {
    /// Model A, `classic`.
    Classic,
    /// Model B1, `ramp`.
    Ramp,
    /// Model B2, `power`.
    Power,
    /// Model C, `lugre`.
    LuGre,
}

impl FrictionKind {
    /// All four, in Mendřický's order A, B1, B2, C.
    pub const ALL: [FrictionKind; 4] = [
        FrictionKind::Classic,
        FrictionKind::Ramp,
        FrictionKind::Power,
        FrictionKind::LuGre,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            FrictionKind::Classic => "classic",
            FrictionKind::Ramp => "ramp",
            FrictionKind::Power => "power",
            FrictionKind::LuGre => "lugre",
        }
    }

    /// Mendřický's label (A, B1, B2, C).
    pub fn thesis_label(self) -> &'static str {
        match self {
            FrictionKind::Classic => "A",
            FrictionKind::Ramp => "B1",
            FrictionKind::Power => "B2",
            FrictionKind::LuGre => "C",
        }
    }

    /// Looks a model up by its command-line name.
    pub fn from_name(name: &str) -> Option<FrictionKind> {
        FrictionKind::ALL
            .into_iter()
            .find(|kind| kind.name().eq_ignore_ascii_case(name))
    }
}

/// The friction force over one step and the velocity it leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionStep {
    /// Velocity at the end of the step, m/s.
    pub velocity_m_per_s: f64,
    /// Friction force held over the step, N.
    pub force_n: f64,
}

/// Below this |v|·h (m) a sign change within a step moves too little to matter.
const NEGLIGIBLE_TRAVEL_M: f64 = 1e-12;

impl Friction {
    /// Which model this is.
    pub fn kind(&self) -> FrictionKind {
        match self {
            Friction::Classic(_) => FrictionKind::Classic,
            Friction::Ramp(_) => FrictionKind::Ramp,
            Friction::Power(_) => FrictionKind::Power,
            Friction::LuGre(_) => FrictionKind::LuGre,
        }
    }

    /// The steady-state friction force at constant velocity v, N
    /// (for LuGre eq. 4.7; for the classic model at v = 0, 0).
    ///
    /// # Example
    /// ```
    /// use axcomp::servo::friction::{Classic, Friction};
    /// let a = Friction::Classic(Classic { coulomb_n: 90.0, static_n: 90.0, viscous_n_s_per_m: 500.0 });
    /// // F_C + μ_v·v at 0.4 m/s: 90 + 200 N.
    /// assert!((a.steady_force_n(0.4) - 290.0).abs() < 1e-12);
    /// ```
    pub fn steady_force_n(&self, velocity_m_per_s: f64) -> f64 {
        let v = velocity_m_per_s;
        match self {
            Friction::Classic(_) if v == 0.0 => 0.0,
            Friction::Classic(c) => v.signum() * (c.coulomb_n + c.viscous_n_s_per_m * v.abs()),
            Friction::Ramp(r) => r.force_n(v),
            Friction::Power(p) => p.force_n(v),
            Friction::LuGre(_) if v == 0.0 => 0.0,
            Friction::LuGre(l) => {
                l.stiffness_n_per_m * l.g_m(v) * v.signum() + l.viscous_n_s_per_m * v
            }
        }
    }

    /// Solves one implicit step (see the module doc): the end velocity v and
    /// the friction force F_T with `v = v_free − α·F_T` and F_T = the model's
    /// force at the end of the step. `bristle_m` is LuGre's z, advanced in
    /// place (other models leave it alone). `h_s` is the step length.
    pub fn step(
        &self,
        bristle_m: &mut f64,
        free_velocity_m_per_s: f64,
        alpha_m_per_s_per_n: f64,
        h_s: f64,
    ) -> FrictionStep {
        let v_free = free_velocity_m_per_s;
        let alpha = alpha_m_per_s_per_n;
        match self {
            Friction::Classic(c) => c.step(v_free, alpha),
            Friction::Ramp(r) => r.step(v_free, alpha),
            Friction::Power(p) => p.step(v_free, alpha),
            Friction::LuGre(l) => l.step(bristle_m, v_free, alpha, h_s),
        }
    }

    /// Whether a step from velocity `v0` to `v1` crossed a point where the
    /// model's force is not smooth in v (a sign change; B1's corner at v0;
    /// A's stick/slip switch), far enough to matter. The adaptive scheme
    /// re-takes such steps with fine sub-steps.
    pub fn crossed_corner(&self, v0: f64, v1: f64, h_s: f64) -> bool {
        let class = |v: f64| -> i8 {
            match self {
                Friction::Ramp(r) if v.abs() <= r.corner_velocity_m_per_s() => 0,
                Friction::Ramp(_) => 2 * v.signum() as i8,
                _ if v == 0.0 => 0,
                _ => v.signum() as i8,
            }
        };
        if class(v0) == class(v1) {
            return false;
        }
        match self {
            // A stuck mass is exactly at rest; any change of state matters.
            Friction::Classic(_) => true,
            _ => v0.abs().max(v1.abs()) * h_s > NEGLIGIBLE_TRAVEL_M,
        }
    }
}

impl Classic {
    fn step(&self, v_free: f64, alpha: f64) -> FrictionStep {
        // Stick: the force that stops the mass within the step is within ±F_Ts.
        if v_free.abs() <= alpha * self.static_n {
            return FrictionStep {
                velocity_m_per_s: 0.0,
                force_n: v_free / alpha,
            };
        }
        let sign = v_free.signum();
        let speed =
            (v_free.abs() - alpha * self.coulomb_n) / (1.0 + alpha * self.viscous_n_s_per_m);
        FrictionStep {
            velocity_m_per_s: sign * speed,
            force_n: sign * (self.coulomb_n + self.viscous_n_s_per_m * speed),
        }
    }
}

impl Ramp {
    /// The corner velocity v0 = F_C/μ0, m/s (the Fcn string of §4.3.2.1 derives it so).
    pub fn corner_velocity_m_per_s(&self) -> f64 {
        self.coulomb_n / self.slope_n_s_per_m
    }

    /// F_T(v), N.
    pub fn force_n(&self, v: f64) -> f64 {
        let v0 = self.corner_velocity_m_per_s();
        if v.abs() <= v0 {
            return self.slope_n_s_per_m * v;
        }
        v.signum() * (self.coulomb_n + (v.abs() - v0) * self.viscous_n_s_per_m)
    }

    fn step(&self, v_free: f64, alpha: f64) -> FrictionStep {
        let v0 = self.corner_velocity_m_per_s();
        let inner = v_free / (1.0 + alpha * self.slope_n_s_per_m);
        let velocity = if inner.abs() <= v0 {
            inner
        } else {
            let offset_n = self.coulomb_n - self.viscous_n_s_per_m * v0;
            v_free.signum() * (v_free.abs() - alpha * offset_n)
                / (1.0 + alpha * self.viscous_n_s_per_m)
        };
        FrictionStep {
            velocity_m_per_s: velocity,
            force_n: self.force_n(velocity),
        }
    }
}

impl Power {
    /// F_T(v) = a·|v|^(1/n)·sgn v, N.
    pub fn force_n(&self, v: f64) -> f64 {
        let root = if self.order == 3.0 {
            v.abs().cbrt()
        } else {
            v.abs().powf(1.0 / self.order)
        };
        v.signum() * self.coefficient_n * root
    }

    /// u^(n−1), without `powf` for Mendřický's orders 3 and 4 (it is in the inner loop).
    fn power_below_order(&self, u: f64) -> f64 {
        if self.order == 3.0 {
            u * u
        } else if self.order == 4.0 {
            u * u * u
        } else {
            u.powf(self.order - 1.0)
        }
    }

    fn step(&self, v_free: f64, alpha: f64) -> FrictionStep {
        // Solve y + α·a·y^(1/n) = |v_free| for y = |v| through u = y^(1/n):
        // u^n + α·a·u = V is convex and increasing, and Newton started to the
        // right of the root (the smaller of the two one-term solutions) goes
        // down to it monotonically.
        let target = v_free.abs();
        if target == 0.0 {
            return FrictionStep {
                velocity_m_per_s: 0.0,
                force_n: 0.0,
            };
        }
        let n = self.order;
        let slope = alpha * self.coefficient_n;
        let mut u = (target / slope).min(self.force_n(target) / self.coefficient_n);
        for _ in 0..60 {
            let un1 = self.power_below_order(u);
            let residual = un1 * u + slope * u - target;
            let next = u - residual / (n * un1 + slope);
            let converged = (u - next).abs() <= 1e-15 * u;
            u = next.max(0.0);
            if converged {
                break;
            }
        }
        let speed = self.power_below_order(u) * u;
        FrictionStep {
            velocity_m_per_s: v_free.signum() * speed,
            force_n: v_free.signum() * self.coefficient_n * u,
        }
    }
}

impl LuGre {
    /// The steady bristle deflection g(v) = (F_C + (F_Ts − F_C)·e^{−(v/v_s)²})/k_s, m (eq. 4.6).
    pub fn g_m(&self, v: f64) -> f64 {
        self.g_and_slope(v).0
    }

    /// g(v) and dg/dv. With F_Ts = F_C (Mendřický's Tab. 6.1 and 6.3) g is
    /// constant; far beyond v_s the Stribeck term is below 1e-300 and skipped
    /// (also to keep `exp` off its slow underflow path).
    fn g_and_slope(&self, v: f64) -> (f64, f64) {
        let stribeck_n = self.static_n - self.coulomb_n;
        let ratio = v / self.stribeck_velocity_m_per_s;
        if stribeck_n == 0.0 || ratio * ratio > 690.0 {
            return (self.coulomb_n / self.stiffness_n_per_m, 0.0);
        }
        let bump = stribeck_n * (-ratio * ratio).exp();
        let g = (self.coulomb_n + bump) / self.stiffness_n_per_m;
        let slope = -2.0 * ratio / self.stribeck_velocity_m_per_s * bump / self.stiffness_n_per_m;
        (g, slope)
    }

    /// z after a step of h with v held (exact solution of eq. 4.2), and dz/dv.
    fn bristle_after(&self, z0: f64, v: f64, h: f64) -> (f64, f64) {
        let (g, dg) = self.g_and_slope(v);
        if v == 0.0 {
            // One-sided slope in the direction that moves z least (the kink of |v|).
            return (z0, h * (1.0 - z0.abs() / g).max(0.0));
        }
        let sign = v.signum();
        let z_ss = sign * g;
        let decay = (-v.abs() * h / g).exp();
        let z = z_ss + (z0 - z_ss) * decay;
        let d_rate = sign / g - v.abs() * dg / (g * g);
        let dz = sign * dg * (1.0 - decay) - (z0 - z_ss) * decay * h * d_rate;
        (z, dz)
    }

    fn step(&self, bristle_m: &mut f64, v_free: f64, alpha: f64, h: f64) -> FrictionStep {
        let z0 = *bristle_m;
        let force = |v: f64| -> (f64, f64, f64) {
            let (z, dz) = self.bristle_after(z0, v, h);
            let f = self.stiffness_n_per_m * z
                + self.damping_n_s_per_m * (z - z0) / h
                + self.viscous_n_s_per_m * v;
            let df =
                (self.stiffness_n_per_m + self.damping_n_s_per_m / h) * dz + self.viscous_n_s_per_m;
            (f, df, z)
        };
        // φ(v) = v − v_free + α·F(v) is increasing when F is (always for
        // F_Ts = F_C); its root lies between v_free and the explicit guess
        // v_free − α·F(v_free). Newton, kept inside that bracket by bisection.
        let (f_free, _, _) = force(v_free);
        let guess = v_free - alpha * f_free;
        let (mut lo, mut hi) = if guess < v_free {
            (guess, v_free)
        } else {
            (v_free, guess)
        };
        let mut v = guess;
        let mut result = force(v);
        for _ in 0..60 {
            let (f, df, _) = result;
            let phi = v - v_free + alpha * f;
            if phi > 0.0 {
                hi = v;
            } else {
                lo = v;
            }
            let slope = 1.0 + alpha * df;
            let newton_step = phi / slope;
            if newton_step.abs() <= 1e-17 + 1e-14 * v.abs() || hi - lo <= 1e-18 {
                break;
            }
            let mut next = v - newton_step;
            if !(next >= lo && next <= hi) || slope <= 0.0 {
                next = 0.5 * (lo + hi);
            }
            v = next;
            result = force(v);
        }
        let (f, _, z) = result;
        *bristle_m = z;
        FrictionStep {
            velocity_m_per_s: v,
            force_n: f,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Tab. 6.3, X axis (thesis §6.3.4).
    const CLASSIC_X: Classic = Classic {
        coulomb_n: 90.0,
        static_n: 90.0,
        viscous_n_s_per_m: 500.0,
    };
    const RAMP_X: Ramp = Ramp {
        coulomb_n: 90.0,
        viscous_n_s_per_m: 500.0,
        slope_n_s_per_m: 12_000.0,
    };

    #[test]
    fn classic_sticks_within_static_friction_and_slides_beyond() {
        let a = Friction::Classic(CLASSIC_X);
        let alpha = 1e-3;
        let mut z = 0.0;
        // Free velocity 0.05 m/s needs 50 N to stop: within F_Ts = 90 N, so it sticks.
        let stuck = a.step(&mut z, 0.05, alpha, 1e-3);
        assert_eq!(stuck.velocity_m_per_s, 0.0);
        assert!((stuck.force_n - 50.0).abs() < 1e-12);
        // 0.2 m/s: v = (0.2 − 0.09)/(1 + 0.5) = 0.07333 m/s, F = 90 + 500·v (by hand).
        let slid = a.step(&mut z, 0.2, alpha, 1e-3);
        assert!((slid.velocity_m_per_s - 0.11 / 1.5).abs() < 1e-12);
        assert!((slid.force_n - (90.0 + 500.0 * 0.11 / 1.5)).abs() < 1e-9);
    }

    #[test]
    fn ramp_is_continuous_at_its_corner() {
        // v0 = F_C/μ0 = 90/12000 m/s = 0.45 m/min (Tab. 6.3 gives v0 = 0.45 m/min).
        let v0 = RAMP_X.corner_velocity_m_per_s();
        assert!((v0 * 60.0 - 0.45).abs() < 1e-12);
        assert!((RAMP_X.force_n(v0) - 90.0).abs() < 1e-9);
        assert!((RAMP_X.force_n(v0 * (1.0 + 1e-12)) - 90.0).abs() < 1e-6);
        // Implicit step lands on v − v_free + α·F(v) = 0 in both branches.
        for v_free in [-0.3, -0.004, 0.001, 0.02, 1.0] {
            let alpha = 2e-6;
            let step = RAMP_X.step(v_free, alpha);
            let residual = step.velocity_m_per_s - v_free + alpha * step.force_n;
            assert!(
                residual.abs() < 1e-15,
                "v_free {v_free}: residual {residual}"
            );
        }
    }

    #[test]
    fn power_law_step_solves_its_equation_without_chatter() {
        let b2 = Power {
            coefficient_n: 300.0,
            order: 3.0,
        };
        for v_free in [1e-12, -3e-7, 2e-4, 0.5] {
            let alpha = 5e-7;
            let step = b2.step(v_free, alpha);
            let residual = step.velocity_m_per_s - v_free + alpha * step.force_n;
            assert!(
                residual.abs() < 1e-15 * (1.0 + v_free.abs() * 1e6),
                "{v_free}: {residual}"
            );
            assert!((step.force_n - b2.force_n(step.velocity_m_per_s)).abs() < 1e-9);
            assert_eq!(step.velocity_m_per_s.signum(), v_free.signum());
        }
    }

    #[test]
    fn lugre_bristle_stays_bounded_and_reaches_its_steady_state() {
        // Tab. 6.3 X: g = F_C/k_s = 90/8e5 = 112.5 µm (notes §2.9).
        let lugre = LuGre {
            stiffness_n_per_m: 8e5,
            damping_n_s_per_m: 2683.0,
            viscous_n_s_per_m: 500.0,
            coulomb_n: 90.0,
            static_n: 90.0,
            stribeck_velocity_m_per_s: 1e-3,
        };
        assert!((lugre.g_m(0.3) - 112.5e-6).abs() < 1e-15);
        let model = Friction::LuGre(lugre);
        let mut z = -112.5e-6;
        let mut v = 0.0;
        for _ in 0..20_000 {
            // A mass driven at 0.2 m/s free velocity each step, h = 1e-4 s.
            let step = model.step(&mut z, 0.2, 1e-4 / 225.0, 1e-4);
            v = step.velocity_m_per_s;
            assert!(z.abs() <= 112.5e-6 * (1.0 + 1e-12));
        }
        assert!((z - 112.5e-6).abs() < 1e-12);
        // Steady force F_C + μ_v v (eq. 4.7 with F_Ts = F_C).
        assert!((model.steady_force_n(v) - (90.0 + 500.0 * v)).abs() < 1e-9);
    }

    #[test]
    fn names_round_trip() {
        for kind in FrictionKind::ALL {
            assert_eq!(FrictionKind::from_name(kind.name()), Some(kind));
        }
        assert_eq!(FrictionKind::from_name("LuGre"), Some(FrictionKind::LuGre));
        assert_eq!(FrictionKind::from_name("dahl"), None);
    }
}
