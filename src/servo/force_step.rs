//! The force-step ("impact dynamic compliance") test of thesis §6.2 and a
//! constant-velocity run (§6.1).
//!
//! Force step: the axis stands under closed position control; at `at_s` a
//! constant external force starts to act on the mass (Mendřický (2006) imitated it
//! on the machine by a current step into the current controller; its
//! simulation put it on the motors: 1500 N, half the continuous force, at
//! t = 0.01 s). Mendřický (2006) reports a peak position deviation of ≈ 80 µm and a
//! return in ≈ 70 ms, with every friction model alike except B2.
//!
//! Constant velocity: one long jerk-limited move at the feed; in the middle of
//! the cruise the current is the friction over K_F3 (thesis Fig. 6.2, eq. 5.7).

use crate::servo::axis::Axis;
use crate::servo::friction::Friction;
use crate::servo::simulate::{ForceStep, Simulator, Snapshot, StepCounts, Stepping};
use crate::servo::trajectory::{MoveLimits, ProfileBuilder, Trajectory};

/// What the force step gives.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceStepResult {
    /// Peak |x_z − x|, m.
    pub peak_error_m: f64,
    /// When the peak came, after the step, s.
    pub peak_after_s: f64,
    /// Time after the step until |x_z − x| stays below 5 % of the peak, s.
    pub recovery_s: f64,
    /// Peak |current|, A.
    pub peak_current_a: f64,
    /// Friction force at the end, N.
    pub final_friction_n: f64,
    /// Largest |friction| change between consecutive macro steps in the last
    /// half of the run, N (B2's chatter in Mendřický (2006); none here).
    pub final_friction_ripple_n: f64,
    /// Simulated time, s.
    pub simulated_s: f64,
    /// How the time was stepped.
    pub counts: StepCounts,
    /// The state at every position sample (1 ms).
    pub trace: Vec<Snapshot>,
}

/// Runs the force step for `duration_s`.
pub fn run_force_step(
    axis: &Axis,
    friction: Friction,
    step: ForceStep,
    duration_s: f64,
    stepping: Stepping,
) -> ForceStepResult {
    let trajectory = Trajectory::Hold { position_m: 0.0 };
    let mut simulator = Simulator::new(axis, friction, &trajectory, stepping, Some(step));
    let mut errors = Vec::new();
    let mut peak_current_a = 0.0f64;
    let mut previous_friction = 0.0;
    let mut ripple = 0.0f64;
    let mut trace = Vec::new();
    simulator.run_until(duration_s, |snapshot| {
        if snapshot.is_position_sample {
            trace.push(*snapshot);
        }
        if snapshot.time_s >= step.at_s {
            errors.push((
                snapshot.time_s - step.at_s,
                snapshot.following_error_m().abs(),
            ));
        }
        peak_current_a = peak_current_a.max(snapshot.peak_current_a);
        if snapshot.time_s > duration_s / 2.0 {
            ripple = ripple.max((snapshot.friction_force_n - previous_friction).abs());
        }
        previous_friction = snapshot.friction_force_n;
    });
    let (peak_after_s, peak_error_m) =
        errors.iter().copied().fold(
            (0.0, 0.0),
            |best, (t, e)| if e > best.1 { (t, e) } else { best },
        );
    let recovery_s = errors
        .iter()
        .rev()
        .find(|(_, e)| *e >= 0.05 * peak_error_m)
        .map_or(0.0, |(t, _)| *t);
    ForceStepResult {
        peak_error_m,
        peak_after_s,
        recovery_s,
        peak_current_a,
        final_friction_n: simulator.snapshot().friction_force_n,
        final_friction_ripple_n: ripple,
        simulated_s: duration_s,
        counts: simulator.counts(),
        trace,
    }
}

/// What the constant-velocity run gives, averaged over the middle half of the cruise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantVelocityResult {
    /// Mean motor current, A.
    pub mean_current_a: f64,
    /// Mean friction force, N.
    pub mean_friction_n: f64,
    /// The model's steady friction at the feed, N (eq. 4.7 for LuGre).
    pub steady_friction_n: f64,
    /// Mean following error, m.
    pub mean_following_error_m: f64,
    /// Simulated time, s.
    pub simulated_s: f64,
    /// How the time was stepped.
    pub counts: StepCounts,
}

/// Moves `distance_m` at `limits.feed_m_per_s` and averages the middle of the cruise.
pub fn run_constant_velocity(
    axis: &Axis,
    friction: Friction,
    distance_m: f64,
    limits: MoveLimits,
    stepping: Stepping,
) -> ConstantVelocityResult {
    let mut builder = ProfileBuilder::new(0.0);
    builder.move_to(distance_m, limits);
    let end_s = builder.time_s();
    let trajectory = Trajectory::Profile(builder.build());
    let mut simulator = Simulator::new(axis, friction, &trajectory, stepping, None);
    let (from_s, to_s) = (0.3 * end_s, 0.7 * end_s);
    let (mut count, mut current, mut force, mut error) = (0.0, 0.0, 0.0, 0.0);
    simulator.run_until(to_s, |snapshot| {
        if snapshot.time_s >= from_s {
            count += 1.0;
            current += snapshot.current_a;
            force += snapshot.friction_force_n;
            error += snapshot.following_error_m();
        }
    });
    let count = f64::max(count, 1.0);
    ConstantVelocityResult {
        mean_current_a: current / count,
        mean_friction_n: force / count,
        steady_friction_n: friction.steady_force_n(limits.feed_m_per_s),
        mean_following_error_m: error / count,
        simulated_s: to_s,
        counts: simulator.counts(),
    }
}
