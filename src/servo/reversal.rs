//! What friction does to a positioning test: the reversal it leaves through
//! a structural compliance, B ≈ 2·F_res/k_c, and its inverse.
//!
//! A direct drive with a linear scale in the position loop has no lost motion
//! of its own: the loop drives the scale reading to the target within one
//! increment, whichever way the axis came (notes §6.2). What remains after an
//! approach is the force the drive holds against friction at standstill,
//! F_res, pointing the way the axis last moved (Mendřický (2006) measured it just
//! below the Coulomb force, §6.4; LuGre and the classic model keep it, the
//! velocity-only models B1 and B2 let it decay to zero). That force passes
//! through the structure between the motor's force line and the point the
//! laser measures; with a stiffness k_c there, the measured point lags the
//! scale by F_res/k_c after a ↑ approach and leads it by as much after a ↓
//! approach, so the reversal value is
//!
//! ```text
//! B_i = x̄_i↑ − x̄_i↓ ≈ −2·F_res/k_c,   B = max|B_i| ≈ 2·F_res/k_c
//! ```
//!
//! on top of whatever the scale itself contributes (up to one position
//! increment from where the quantised loop comes to rest). `iso_cycle`
//! simulates this in full; these two functions are the closed form. The
//! first turns a simulated cycle's residual friction into a reversal
//! ([`super::iso_cycle::ResidualFriction`]); the inverse reads the reversal
//! `diagnose` finds as the friction force behind it (`diagnose::friction`,
//! given the axis's servo description and k_c). Both work with magnitudes: B ≥ 0, F ≥ 0, k_c > 0.

/// B ≈ 2·F_res/k_c, µm, for a residual friction force in N and a structural
/// stiffness in N/µm.
///
/// # Example
/// ```
/// use axcomp::servo::reversal::reversal_from_friction_um;
/// // 90 N held against a 100 N/µm structure: 1.8 µm.
/// assert!((reversal_from_friction_um(90.0, 100.0) - 1.8).abs() < 1e-12);
/// ```
pub fn reversal_from_friction_um(residual_force_n: f64, stiffness_n_per_um: f64) -> f64 {
    2.0 * residual_force_n / stiffness_n_per_um
}

/// The inverse: F_res ≈ B·k_c/2, N, for a reversal in µm and a stiffness in N/µm.
///
/// # Example
/// ```
/// use axcomp::servo::reversal::{friction_from_reversal_n, reversal_from_friction_um};
/// assert!((friction_from_reversal_n(1.8, 100.0) - 90.0).abs() < 1e-12);
/// let force = 37.0;
/// assert!((friction_from_reversal_n(reversal_from_friction_um(force, 40.0), 40.0) - force).abs() < 1e-12);
/// ```
pub fn friction_from_reversal_n(reversal_um: f64, stiffness_n_per_um: f64) -> f64 {
    reversal_um * stiffness_n_per_um / 2.0
}

/// The stiffness that turns a residual force into a reversal: k_c ≈ 2·F_res/B, N/µm.
///
/// # Example
/// ```
/// use axcomp::servo::reversal::stiffness_from_reversal_n_per_um;
/// assert!((stiffness_from_reversal_n_per_um(1.8, 90.0) - 100.0).abs() < 1e-12);
/// ```
pub fn stiffness_from_reversal_n_per_um(reversal_um: f64, residual_force_n: f64) -> f64 {
    2.0 * residual_force_n / reversal_um
}
