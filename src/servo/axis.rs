//! Axis parameters: the feed-drive model of Mendřický (2006) ch. 3 as data, read from TOML.
//!
//! An [`Axis`] holds what the simulation needs (notes §3): the moving mass,
//! the DC-equivalent motor, the PI current loop with the converter's dead
//! time, the PI velocity loop, the sampled and quantised P position loop, the
//! feedforward weights, and one set of friction parameters from which each
//! of the four models is built ([`Axis::friction`]).
//!
//! Mendřický's two axes of the MCFV 5050 LN are bundled
//! (`fixtures/axes/mcfv5050-x.toml`, `mcfv5050-y.toml`, each value commented
//! with its source) and compiled in, so [`Axis::bundled`] works anywhere.
//! [`Axis::from_toml_str`] reads the same layout from text; it never sees a
//! path (the caller adds it to errors) and never panics on input.
//!
//! Deliberately not modelled, and so not in the file: the 2 kHz notch filter
//! of the velocity loop (its depth ζ_F1 is not given, notes §3.3), the scale
//! slider (0.5 kg at 2 kHz, far above the loops' bandwidth) and the
//! three-phase commutation (Mendřický (2006) calls the DC-equivalent motor
//! adequate, §3.1). The notes' independent re-implementation reproduces
//! Tab. 6.4 without them (notes §10).

use serde::Deserialize;

use super::ServoError;
use crate::error::ParseError;
use crate::servo::friction::{Classic, Friction, FrictionKind, LuGre, Power, Ramp};

/// The bundled MCFV 5050 LN X axis file.
pub const MCFV5050_X_TOML: &str = include_str!("../../fixtures/axes/mcfv5050-x.toml");
/// The bundled MCFV 5050 LN Y axis file.
pub const MCFV5050_Y_TOML: &str = include_str!("../../fixtures/axes/mcfv5050-y.toml");
/// Names of the bundled axes, as `--axis` takes them.
pub const BUNDLED_NAMES: [&str; 2] = ["mcfv5050-x", "mcfv5050-y"];

/// One feed axis.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    /// Axis name (`X`, `Y`, …); the circle test uses it to pick R·cos φ (X) or R·sin φ (Y).
    pub name: String,
    /// Moving mass m, kg (also the mass of the current feedforward).
    pub mass_kg: f64,
    /// The motor.
    pub motor: Motor,
    /// The current loop and converter.
    pub current_loop: CurrentLoop,
    /// The velocity loop.
    pub velocity_loop: VelocityLoop,
    /// The position loop.
    pub position_loop: PositionLoop,
    /// Feedforward weights.
    pub feedforward: Feedforward,
    /// Friction parameters shared by the four models.
    pub friction: FrictionParams,
}

/// DC-equivalent linear motor (eq. 3.1–3.4 with K_F3 of eq. 3.14).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motor {
    /// Resistance R, Ω.
    pub resistance_ohm: f64,
    /// Inductance L, H.
    pub inductance_h: f64,
    /// Back-EMF constant K_E, V·s/m.
    pub back_emf_v_s_per_m: f64,
    /// Force constant K_F3, N/A.
    pub force_constant_n_per_a: f64,
}

/// PI current controller and converter.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurrentLoop {
    /// Proportional gain k_pi, V/A.
    pub gain_v_per_a: f64,
    /// Integral time T_Ni, s.
    pub integral_time_s: f64,
    /// Converter transport delay T_d, s (a whole number of microseconds).
    pub dead_time_s: f64,
}

/// PI velocity controller.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VelocityLoop {
    /// Proportional gain k_pv, A·s/m (output is a current).
    pub gain_a_s_per_m: f64,
    /// Integral time T_Nv, s.
    pub integral_time_s: f64,
}

/// Sampled, quantised P position controller.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionLoop {
    /// Gain K_v, 1/s.
    pub gain_per_s: f64,
    /// Sampling period of the position error, s (a whole number of microseconds).
    pub sample_time_s: f64,
    /// Quantisation step of the measured position, m.
    pub increment_m: f64,
}

/// Feedforward weights K_wv and K_wi.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Feedforward {
    /// Velocity feedforward weight K_wv.
    pub velocity_weight: f64,
    /// Current feedforward weight K_wi (times a_z·m/K_F3).
    pub current_weight: f64,
}

/// Friction parameters (Tab. 6.3 layout); each model takes what it needs.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionParams {
    /// Coulomb friction F_C, N.
    pub coulomb_n: f64,
    /// Static friction F_Ts ≥ F_C, N.
    pub static_n: f64,
    /// Viscous coefficient μ_v, N·s/m.
    pub viscous_n_s_per_m: f64,
    /// B1 slope μ0 below v0 = F_C/μ0, N·s/m.
    pub ramp_slope_n_s_per_m: f64,
    /// B2 coefficient a, N at 1 m/s.
    pub power_coefficient_n: f64,
    /// B2 order n ≥ 1.
    pub power_order: f64,
    /// LuGre stiffness k_s, N/m.
    pub lugre_stiffness_n_per_m: f64,
    /// LuGre damping ratio ζ_s (b_s = 2 ζ_s √(k_s m), eq. 4.15).
    pub lugre_damping_ratio: f64,
    /// Stribeck velocity v_s, m/s.
    pub stribeck_velocity_m_per_s: f64,
}

impl Axis {
    /// A bundled axis by name (`mcfv5050-x`, `mcfv5050-y`).
    ///
    /// # Example
    /// ```
    /// use axcomp::servo::axis::Axis;
    /// let x = Axis::bundled("mcfv5050-x").unwrap();
    /// assert_eq!(x.name, "X");
    /// assert_eq!(x.mass_kg, 225.0); // Tab. 6.3
    /// assert!(Axis::bundled("mcfv5050-z").is_err());
    /// ```
    pub fn bundled(name: &str) -> Result<Axis, ServoError> {
        let text = match name.to_ascii_lowercase().as_str() {
            "mcfv5050-x" => MCFV5050_X_TOML,
            "mcfv5050-y" => MCFV5050_Y_TOML,
            _ => return Err(ServoError::UnknownBundled(name.to_string())),
        };
        Axis::from_toml_str(text)
    }

    /// Parses and validates an axis file.
    pub fn from_toml_str(text: &str) -> Result<Axis, ServoError> {
        let axis: Axis = toml::from_str(text)
            .map_err(|error| ServoError::Parse(ParseError::from_toml(text, &error)))?;
        axis.validate()?;
        Ok(axis)
    }

    /// The friction model of this kind with this axis's parameters.
    pub fn friction(&self, kind: FrictionKind) -> Friction {
        let p = &self.friction;
        match kind {
            FrictionKind::Classic => Friction::Classic(Classic {
                coulomb_n: p.coulomb_n,
                static_n: p.static_n,
                viscous_n_s_per_m: p.viscous_n_s_per_m,
            }),
            FrictionKind::Ramp => Friction::Ramp(Ramp {
                coulomb_n: p.coulomb_n,
                viscous_n_s_per_m: p.viscous_n_s_per_m,
                slope_n_s_per_m: p.ramp_slope_n_s_per_m,
            }),
            FrictionKind::Power => Friction::Power(Power {
                coefficient_n: p.power_coefficient_n,
                order: p.power_order,
            }),
            FrictionKind::LuGre => Friction::LuGre(LuGre {
                stiffness_n_per_m: p.lugre_stiffness_n_per_m,
                damping_n_s_per_m: crate::servo::identify::lugre_damping_n_s_per_m(
                    p.lugre_stiffness_n_per_m,
                    self.mass_kg,
                    p.lugre_damping_ratio,
                ),
                viscous_n_s_per_m: p.viscous_n_s_per_m,
                coulomb_n: p.coulomb_n,
                static_n: p.static_n,
                stribeck_velocity_m_per_s: p.stribeck_velocity_m_per_s,
            }),
        }
    }

    fn validate(&self) -> Result<(), ServoError> {
        let positive: [(&'static str, f64); 17] = [
            ("mass_kg", self.mass_kg),
            ("motor.resistance_ohm", self.motor.resistance_ohm),
            ("motor.inductance_h", self.motor.inductance_h),
            (
                "motor.force_constant_n_per_a",
                self.motor.force_constant_n_per_a,
            ),
            ("current_loop.gain_v_per_a", self.current_loop.gain_v_per_a),
            (
                "current_loop.integral_time_s",
                self.current_loop.integral_time_s,
            ),
            ("current_loop.dead_time_s", self.current_loop.dead_time_s),
            (
                "velocity_loop.gain_a_s_per_m",
                self.velocity_loop.gain_a_s_per_m,
            ),
            (
                "velocity_loop.integral_time_s",
                self.velocity_loop.integral_time_s,
            ),
            ("position_loop.gain_per_s", self.position_loop.gain_per_s),
            (
                "position_loop.sample_time_s",
                self.position_loop.sample_time_s,
            ),
            ("position_loop.increment_m", self.position_loop.increment_m),
            (
                "friction.ramp_slope_n_s_per_m",
                self.friction.ramp_slope_n_s_per_m,
            ),
            (
                "friction.power_coefficient_n",
                self.friction.power_coefficient_n,
            ),
            (
                "friction.lugre_stiffness_n_per_m",
                self.friction.lugre_stiffness_n_per_m,
            ),
            (
                "friction.stribeck_velocity_m_per_s",
                self.friction.stribeck_velocity_m_per_s,
            ),
            ("friction.coulomb_n", self.friction.coulomb_n),
        ];
        for (key, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(value_error(key, "a finite number > 0", value));
            }
        }
        let non_negative: [(&'static str, f64); 5] = [
            ("motor.back_emf_v_s_per_m", self.motor.back_emf_v_s_per_m),
            (
                "feedforward.velocity_weight",
                self.feedforward.velocity_weight,
            ),
            (
                "feedforward.current_weight",
                self.feedforward.current_weight,
            ),
            (
                "friction.viscous_n_s_per_m",
                self.friction.viscous_n_s_per_m,
            ),
            (
                "friction.lugre_damping_ratio",
                self.friction.lugre_damping_ratio,
            ),
        ];
        for (key, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(value_error(key, "a finite number ≥ 0", value));
            }
        }
        if !(self.friction.static_n.is_finite()
            && self.friction.static_n >= self.friction.coulomb_n)
        {
            return Err(value_error(
                "friction.static_n",
                "a finite number ≥ friction.coulomb_n",
                self.friction.static_n,
            ));
        }
        if !(self.friction.power_order.is_finite() && self.friction.power_order >= 1.0) {
            return Err(value_error(
                "friction.power_order",
                "a finite number ≥ 1",
                self.friction.power_order,
            ));
        }
        // The simulation steps on a 1 µs grid: the delay and the position
        // sampling must fall on it.
        for (key, value) in [
            ("current_loop.dead_time_s", self.current_loop.dead_time_s),
            (
                "position_loop.sample_time_s",
                self.position_loop.sample_time_s,
            ),
        ] {
            let micros = value * 1e6;
            if (micros - micros.round()).abs() > 1e-6 || micros.round() > 1e6 {
                return Err(value_error(
                    key,
                    "a whole number of microseconds, at most 1 s",
                    value,
                ));
            }
        }
        Ok(())
    }

    /// The dead time in whole microseconds.
    pub fn dead_time_us(&self) -> u64 {
        (self.current_loop.dead_time_s * 1e6).round() as u64
    }

    /// The position sampling period in whole microseconds.
    pub fn sample_time_us(&self) -> u64 {
        (self.position_loop.sample_time_s * 1e6).round() as u64
    }
}

fn value_error(key: &'static str, expected: &'static str, found: f64) -> ServoError {
    ServoError::Value {
        key,
        expected,
        found,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_axes_carry_the_thesis_values() {
        // Tab. 3.2, 6.3 and the DC-equivalent motor of §3.1 (notes §10).
        let x = Axis::bundled("mcfv5050-x").unwrap();
        let y = Axis::bundled("MCFV5050-Y").unwrap();
        assert_eq!((x.mass_kg, y.mass_kg), (225.0, 520.0));
        assert_eq!(
            (
                x.velocity_loop.gain_a_s_per_m,
                y.velocity_loop.gain_a_s_per_m
            ),
            (600.0, 1200.0)
        );
        assert_eq!(
            (x.current_loop.gain_v_per_a, y.current_loop.gain_v_per_a),
            (35.0, 17.0)
        );
        assert_eq!((x.motor.resistance_ohm, y.motor.resistance_ohm), (1.8, 0.9));
        assert_eq!((x.friction.coulomb_n, y.friction.coulomb_n), (90.0, 220.0));
        assert_eq!(x.dead_time_us(), 125);
        assert_eq!(x.sample_time_us(), 1000);
        // K_v = 5 m/min/mm = 5/60 m/s per 1e-3 m = 83.33 1/s (Tab. 3.2).
        assert!((x.position_loop.gain_per_s - 5.0 / 60.0 / 1e-3).abs() < 1e-9);
    }

    #[test]
    fn lugre_damping_follows_eq_4_15() {
        // b_s = 2·0.1·√(8e5·225) = 2683 N·s/m (notes §5.3.4 [CHK]).
        let x = Axis::bundled("mcfv5050-x").unwrap();
        let Friction::LuGre(lugre) = x.friction(FrictionKind::LuGre) else {
            unreachable!("asked for LuGre")
        };
        assert!((lugre.damping_n_s_per_m - 2683.28).abs() < 0.01);
    }

    #[test]
    fn bad_files_are_refused_with_a_position_or_a_key() {
        let bad_toml = MCFV5050_X_TOML.replace("mass_kg = 225.0", "mass_kg = heavy");
        match Axis::from_toml_str(&bad_toml) {
            Err(ServoError::Parse(error)) => {
                // `mass_kg` is on line 9 of the bundled file.
                assert_eq!(error.position.line, 9, "{error}");
            }
            other => panic!("expected a parse error, got {other:?}"),
        }
        let unknown = MCFV5050_X_TOML.replace("mass_kg", "masss_kg");
        assert!(matches!(
            Axis::from_toml_str(&unknown),
            Err(ServoError::Parse(_))
        ));
        let negative = MCFV5050_X_TOML.replace("resistance_ohm = 1.8", "resistance_ohm = -1.8");
        assert_eq!(
            Axis::from_toml_str(&negative).unwrap_err().to_string(),
            "motor.resistance_ohm: expected a finite number > 0, found -1.8"
        );
        let fractional =
            MCFV5050_X_TOML.replace("dead_time_s = 0.000125", "dead_time_s = 0.0000625");
        assert!(Axis::from_toml_str(&fractional).is_err());
        let stiction = MCFV5050_X_TOML.replace("static_n = 90.0", "static_n = 80.0");
        assert!(Axis::from_toml_str(&stiction).is_err());
    }
}
