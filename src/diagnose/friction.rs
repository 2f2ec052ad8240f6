//! The friction force behind a reversal the diagnosis found, for an axis
//! with a servo description (Mendřický (2006); docs/src/servo.md "What friction does to an ISO
//! 230-2 positioning test").
//!
//! A drive with its scale in the loop holds, after each approach, the force
//! F_res it needed against friction, pointing the way it last moved; through
//! the structure's stiffness k_c between the drive's force line and the
//! laser that shifts the reading by −F_res/k_c after ↑ and +F_res/k_c after
//! ↓, so **B̄ = B̄_scale − 2·F_res/k_c** (`servo::reversal`). The scale's own
//! part B̄_scale is at most one position increment (where the quantised loop
//! comes to rest); it is not known, so F_res is read from B with
//! B̄_scale = 0 and the increment's worth is given as a bound beside it.
//! For the classic and LuGre models F_res ≈ F_C (89.7 and 90.0 N for the
//! bundled X axis's 90 N), so the force is also the F_C that `servo-sim`
//! starts from.
//!
//! With a first test the reversal found is the change since then, and so
//! is the force: the friction held grew (B more negative) or fell by it.
//! Without one, only a negative reversal can be friction through a
//! compliance (the measured point lags the scale the way the axis moved); a
//! positive one is not explained here.

use super::Diagnosis;
use crate::effects::{Effect, EffectIn};
use crate::servo::axis::Axis;
use crate::servo::reversal::{friction_from_reversal_n, reversal_from_friction_um};
use crate::units::{Um, m_to_um};

/// The friction force a found reversal means.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReversalFriction {
    /// The reversal found, B = ↑ − ↓, µm (the change since the first test when there was one).
    pub reversal_um: f64,
    /// Its standard uncertainty, µm.
    pub reversal_uncertainty_um: f64,
    /// Whether the reversal (and the force) is the change since the first test.
    pub change_since_first_test: bool,
    /// F_res = −B·k_c/2, N: the force held against friction (its change, with a first test).
    pub friction_n: f64,
    /// Its standard uncertainty from B's, N.
    pub friction_uncertainty_n: f64,
    /// What one position increment of the scale's own reversal would be worth, ± N.
    pub scale_part_n: f64,
    /// k_c, N/µm.
    pub stiffness_n_per_um: f64,
    /// The servo description's F_C, N.
    pub axis_coulomb_n: f64,
    /// The reversal the description's F_C would give through k_c,
    /// −2·F_C/k_c, µm (F_res ≈ F_C for the classic and LuGre models).
    pub expected_reversal_um: f64,
    /// F_C for `servo-sim` to start from, N: F_res, or the description's
    /// F_C changed by it when the reversal is a change.
    pub start_coulomb_n: f64,
}

/// The friction behind the diagnosis's reversal, if it found one that
/// friction through k_c (N/µm) can explain; `None` otherwise.
pub fn friction_behind_reversal(
    diagnosis: &Diagnosis,
    axis: &Axis,
    stiffness_n_per_um: f64,
) -> Option<ReversalFriction> {
    let accepted = diagnosis
        .accepted
        .iter()
        .find(|a| matches!(a.effect, Effect::Reversal(_)))?;
    // A servo description's friction is a linear axis' (N against µm).
    let EffectIn::Reversal {
        b: Um(reversal_um),
        b_uncertainty: Um(uncertainty_um),
    } = accepted
        .effect
        .typed(diagnosis.kind, &accepted.uncertainty)?
        .linear()?
    else {
        return None;
    };
    let change = diagnosis.predicted_from_first_test;
    if !change && reversal_um >= 0.0 {
        return None;
    }
    // B = −2·F/k_c: the force is the inverse of the (negative) reversal.
    let friction_n = friction_from_reversal_n(-reversal_um, stiffness_n_per_um);
    let increment_um = m_to_um(axis.position_loop.increment_m);
    let axis_coulomb_n = axis.friction.coulomb_n;
    Some(ReversalFriction {
        reversal_um,
        reversal_uncertainty_um: uncertainty_um,
        change_since_first_test: change,
        friction_n,
        friction_uncertainty_n: friction_from_reversal_n(uncertainty_um, stiffness_n_per_um),
        scale_part_n: friction_from_reversal_n(increment_um, stiffness_n_per_um),
        stiffness_n_per_um,
        axis_coulomb_n,
        expected_reversal_um: -reversal_from_friction_um(axis_coulomb_n, stiffness_n_per_um),
        start_coulomb_n: if change {
            (axis_coulomb_n + friction_n).max(0.0)
        } else {
            friction_n
        },
    })
}
