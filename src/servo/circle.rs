//! The circular test (thesis §6.3, Tab. 6.4): simulate one axis's share of a
//! circle and read the quadrant error at its reversals.
//!
//! Mendřický (2006) tabulates, per axis and feed, the "quadrant error" of the
//! following error (the spike when the axis reverses, xe and ye) and the
//! current (Ix, Iy), the mean of the + and − reversal where they differ. Here:
//! the simulation runs the 0.3 s run-up and two revolutions (notes §10); each
//! reversal of this axis (φ = kπ for X, π/2 + kπ for Y) whose window
//! φ ± π/2 lies wholly after the run-up is evaluated for the peak |x_z − x|
//! at the 1 ms position samples and the peak |I| (continuous in time); the
//! figures are the means over those reversals.

use std::f64::consts::PI;

use crate::servo::axis::Axis;
use crate::servo::friction::Friction;
use crate::servo::simulate::{Simulator, Snapshot, StepCounts, Stepping};
use crate::servo::trajectory::{Circle, CircleAxis, Trajectory};

/// What one circle simulation gives.
#[derive(Clone, Debug, PartialEq)]
pub struct CircleResult {
    /// Mean over the reversals of the peak |following error|, m (Tab. 6.4 xe/ye).
    pub reversal_error_m: f64,
    /// Mean over the reversals of the peak |current|, A (Tab. 6.4 Ix/Iy).
    pub reversal_current_a: f64,
    /// Each evaluated reversal.
    pub reversals: Vec<Reversal>,
    /// Simulated (machine) time, s.
    pub simulated_s: f64,
    /// How the time was stepped.
    pub counts: StepCounts,
    /// The state at every position sample (1 ms), for plots and CSV.
    pub trace: Vec<Snapshot>,
}

/// One reversal of the axis on the circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reversal {
    /// φ at the reversal, rad.
    pub angle_rad: f64,
    /// When the command reverses, s.
    pub time_s: f64,
    /// Direction of motion after the reversal: +1 or −1.
    pub direction_after: f64,
    /// Peak |x_z − x| in the window, m.
    pub peak_error_m: f64,
    /// Peak |I| in the window, A.
    pub peak_current_a: f64,
}

/// Simulates the circle and evaluates the reversals. `progress` gets the
/// fraction done, now and then.
pub fn run_circle(
    axis: &Axis,
    friction: Friction,
    circle: &Circle,
    stepping: Stepping,
    progress: &mut dyn FnMut(f64),
) -> CircleResult {
    let trajectory = Trajectory::Circle(*circle);
    let omega = circle.angular_speed_rad_per_s();
    let end_s = circle.ramp_time_s + 2.0 * 2.0 * PI / omega;
    let (first_angle, _, _, _) = circle.angle(circle.ramp_time_s);
    let (last_angle, _, _, _) = circle.angle(end_s);
    let offset = match circle.axis {
        CircleAxis::X => 0.0,
        CircleAxis::Y => PI / 2.0,
    };
    let mut reversals = Vec::new();
    let mut k = ((first_angle + PI / 2.0 - offset) / PI).ceil();
    loop {
        let angle_rad = offset + k * PI;
        if angle_rad + PI / 2.0 > last_angle {
            break;
        }
        // The commanded velocity just after the reversal: −R ω sin φ for X,
        // R ω cos φ for Y, evaluated a little past the reversal angle.
        let direction_after = match circle.axis {
            CircleAxis::X => -(angle_rad + 1e-3).sin().signum(),
            CircleAxis::Y => (angle_rad + 1e-3).cos().signum(),
        };
        reversals.push(Reversal {
            angle_rad,
            time_s: circle.time_at_angle_s(angle_rad),
            direction_after,
            peak_error_m: 0.0,
            peak_current_a: 0.0,
        });
        k += 1.0;
    }
    let half_window_s = PI / 2.0 / omega;
    let mut simulator = Simulator::new(axis, friction, &trajectory, stepping, None);
    let report_every = (0.02 * end_s / simulator.macro_step_s()).max(1.0) as u64;
    let mut steps = 0u64;
    let mut trace = Vec::new();
    simulator.run_until(end_s, |snapshot| {
        steps += 1;
        if snapshot.is_position_sample {
            trace.push(*snapshot);
        }
        if steps.is_multiple_of(report_every) {
            progress(snapshot.time_s / end_s);
        }
        for reversal in reversals.iter_mut() {
            if (snapshot.time_s - reversal.time_s).abs() > half_window_s {
                continue;
            }
            reversal.peak_current_a = reversal.peak_current_a.max(snapshot.peak_current_a);
            if snapshot.is_position_sample {
                let error = snapshot.following_error_m().abs();
                reversal.peak_error_m = reversal.peak_error_m.max(error);
            }
        }
    });
    progress(1.0);
    let count = reversals.len().max(1) as f64;
    CircleResult {
        reversal_error_m: reversals.iter().map(|r| r.peak_error_m).sum::<f64>() / count,
        reversal_current_a: reversals.iter().map(|r| r.peak_current_a).sum::<f64>() / count,
        reversals,
        simulated_s: end_s,
        counts: simulator.counts(),
        trace,
    }
}
