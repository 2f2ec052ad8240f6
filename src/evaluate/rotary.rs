//! What ISO 230-2 asks of a rotary axis beyond a linear one
//! (`../shared/spec/standards.md` §6), checked on the evaluated targets:
//!
//! - over 360° ISO 230-2 takes one approach per direction and target
//!   (n = 1; ГОСТ ISO 230-2-2016 cl. 6.2), so the repeatabilities and A are
//!   not evaluated: [`FIGURES_NEEDING_REPEATS`] are taken out of the figures,
//!   with a warning, however many runs the file holds;
//! - the principal angles 0°, 90°, 180° and 270° (every multiple of 90°
//!   within the range) should be among the targets;
//! - on a full turn 0° and 360° are one physical position: when a file
//!   holds both ends of a turn and their mean deviations x̄_i differ by more
//!   than the larger bidirectional repeatability R_i of the two, it says so.
//!
//! Angles are degrees, as the rotary measurement holds them. Pure: no I/O.

use crate::error::Warning;
use crate::evaluate::TargetStats;
use crate::evaluate::conformance::FULL_TURN_DEG;

/// The figure keys (ISO 230-2's, VDI 3441's) that rest on the scatter of
/// repeated runs: not evaluated on a rotary axis over 360°.
pub const FIGURES_NEEDING_REPEATS: [&str; 9] = [
    "A", "A_up", "A_down", "R", "R_up", "R_down", "P", "Ps_max", "Ps_mean",
];

/// Two angles closer than this are one target, °: 0.36″.
const SAME_ANGLE_DEG: f64 = 1e-4;

/// The principal angle step, °.
const PRINCIPAL_STEP_DEG: f64 = 90.0;

/// Whether the targets span more than a full turn (the n = 1 rule applies).
pub fn over_full_turn(targets_deg: &[f64]) -> bool {
    range_deg(targets_deg) > FULL_TURN_DEG
}

/// The rotary warnings for a test with these per-target statistics: over a
/// full turn, principal angles missing, the two ends of a turn disagreeing.
pub fn warnings(per_target: &[TargetStats]) -> Vec<Warning> {
    let targets_deg: Vec<f64> = per_target.iter().map(|t| t.target).collect();
    let mut warnings = Vec::new();
    if over_full_turn(&targets_deg) {
        warnings.push(Warning::RotaryOverFullTurn {
            range_deg: range_deg(&targets_deg),
        });
    }
    let missing_deg = missing_principal_angles(&targets_deg);
    if !missing_deg.is_empty() {
        warnings.push(Warning::PrincipalAnglesMissing { missing_deg });
    }
    warnings.extend(full_turn_ends(per_target));
    warnings
}

fn range_deg(targets_deg: &[f64]) -> f64 {
    match (targets_deg.first(), targets_deg.last()) {
        (Some(first), Some(last)) => last - first,
        _ => 0.0,
    }
}

/// Every multiple of 90° within the targets' range that no target is at.
fn missing_principal_angles(targets_deg: &[f64]) -> Vec<f64> {
    let (Some(&first), Some(&last)) = (targets_deg.first(), targets_deg.last()) else {
        return Vec::new();
    };
    let mut missing = Vec::new();
    let mut k = (first / PRINCIPAL_STEP_DEG - 1e-9).ceil() as i64;
    while (k as f64) * PRINCIPAL_STEP_DEG <= last + SAME_ANGLE_DEG {
        let angle = k as f64 * PRINCIPAL_STEP_DEG;
        if !targets_deg
            .iter()
            .any(|target| (target - angle).abs() < SAME_ANGLE_DEG)
        {
            missing.push(angle + 0.0);
        }
        k += 1;
    }
    missing
}

/// Every pair of targets one turn apart whose mean deviations differ by more
/// than the larger of their bidirectional repeatabilities.
fn full_turn_ends(per_target: &[TargetStats]) -> Vec<Warning> {
    let mut warnings = Vec::new();
    for (index, first) in per_target.iter().enumerate() {
        for last in &per_target[index + 1..] {
            if (last.target - first.target - FULL_TURN_DEG).abs() >= SAME_ANGLE_DEG {
                continue;
            }
            let (Some(mean_first_deg), Some(mean_last_deg)) = (first.mean, last.mean) else {
                continue;
            };
            let (Some(r_first), Some(r_last)) = (first.repeatability, last.repeatability) else {
                continue;
            };
            let repeatability_deg = r_first.max(r_last);
            if (mean_last_deg - mean_first_deg).abs() > repeatability_deg {
                warnings.push(Warning::FullTurnEndsDisagree {
                    first_deg: first.target,
                    last_deg: last.target,
                    mean_first_deg,
                    mean_last_deg,
                    repeatability_deg,
                });
            }
        }
    }
    warnings
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn principal_angles_within_the_range() {
        // By hand: 0…360 every 45° has them all; 10…350 every 20° hits 90°
        // (10 + 4·20) and 270° (10 + 13·20) but not 180° (0° and 360° are
        // outside); −180…180 asks −180° … 180°.
        let every = |first: f64, last: f64, step: f64| -> Vec<f64> {
            let n = ((last - first) / step).round() as usize;
            (0..=n).map(|i| first + step * i as f64).collect()
        };
        assert!(missing_principal_angles(&every(0.0, 360.0, 45.0)).is_empty());
        assert_eq!(missing_principal_angles(&every(10.0, 350.0, 20.0)), [180.0]);
        assert_eq!(
            missing_principal_angles(&[-180.0, -100.0, 0.0, 100.0, 180.0]),
            [-90.0, 90.0]
        );
        assert!(!over_full_turn(&[0.0, 360.0]));
        assert!(over_full_turn(&[0.0, 360.5]));
    }
}
