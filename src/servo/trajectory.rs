//! Command trajectories: where the control wants the axis, and how fast.
//!
//! A [`Trajectory`] gives the commanded position x_z and its first three
//! derivatives at any time ([`Setpoint`]); the simulation feeds v_z and a_z
//! forward (thesis §3.2.2) and samples x_z for the position loop.
//!
//! - [`Circle`]: one axis's share of the circular test (thesis eq. 6.1–6.6),
//!   CCW from a start angle, with the angular speed run up by a cosine ramp.
//!   Mendřický's jerk-limited run-up (Tab. 6.2) is used with parameters the
//!   text does not give; the notes' reproduction (§10) used a 0.3 s cosine
//!   ramp of ω from φ = π/2, which is what [`Circle::thesis`] does.
//! - [`Profile`]: piecewise constant-jerk motion built from point-to-point
//!   moves and dwells ([`ProfileBuilder`]). Each move has the shape of the
//!   Mendřický's run-up function (Tab. 6.2, eq. 6.7): jerk ±J for t_r = a/J,
//!   constant acceleration up to t_a = v/a, cruise, and the mirror image.
//!   The constant-velocity run and the ISO 230-2 cycle are profiles.
//! - [`Trajectory::Hold`]: standing still (the force-step test).

use std::f64::consts::PI;

/// Commanded position and derivatives at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Setpoint {
    /// x_z, m.
    pub position_m: f64,
    /// v_z, m/s.
    pub velocity_m_per_s: f64,
    /// a_z, m/s².
    pub acceleration_m_per_s2: f64,
    /// Jerk, m/s³.
    pub jerk_m_per_s3: f64,
}

/// Which coordinate of the circle an axis follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CircleAxis {
    /// x = R·cos φ.
    X,
    /// y = R·sin φ.
    Y,
}

/// The circular test for one axis (thesis §6.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Radius R, m.
    pub radius_m: f64,
    /// Path feed, m/s (ω = feed/R after the ramp).
    pub feed_m_per_s: f64,
    /// Duration of the cosine run-up of ω, s.
    pub ramp_time_s: f64,
    /// φ at t = 0, rad.
    pub start_angle_rad: f64,
    /// Which coordinate this axis follows.
    pub axis: CircleAxis,
}

/// One constant-jerk piece of a profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// When it starts, s.
    pub start_s: f64,
    /// Position, velocity and acceleration at its start; jerk throughout.
    pub start: Setpoint,
}

/// Piecewise constant-jerk motion; after the last segment's end it holds still.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    segments: Vec<Segment>,
    end_s: f64,
    end_position_m: f64,
}

/// A commanded motion.
#[derive(Clone, Debug, PartialEq)]
pub enum Trajectory {
    /// Stand still at a position, m.
    Hold {
        /// The position, m.
        position_m: f64,
    },
    /// One axis of the circular test.
    Circle(Circle),
    /// Moves and dwells.
    Profile(Profile),
}

/// Limits of a point-to-point move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveLimits {
    /// Feed v, m/s.
    pub feed_m_per_s: f64,
    /// Acceleration a, m/s².
    pub acceleration_m_per_s2: f64,
    /// Jerk J, m/s³.
    pub jerk_m_per_s3: f64,
}

/// Builds a [`Profile`] move by move.
#[derive(Clone, Debug)]
pub struct ProfileBuilder {
    segments: Vec<Segment>,
    time_s: f64,
    position_m: f64,
    at_rest: bool,
}

impl Trajectory {
    /// The setpoint at time t (s).
    pub fn at(&self, time_s: f64) -> Setpoint {
        let mut hint = 0;
        self.at_hinted(time_s, &mut hint)
    }

    /// If the command stands still at `time_s`, until when it does (s;
    /// infinity for good). `None` while it moves.
    pub fn rest_until(&self, time_s: f64) -> Option<f64> {
        match self {
            Trajectory::Hold { .. } => Some(f64::INFINITY),
            Trajectory::Circle(_) => None,
            Trajectory::Profile(profile) => profile.rest_until(time_s),
        }
    }

    /// The same, starting the search for the profile segment at `hint` and
    /// leaving the segment found there: a simulation asks for nearly
    /// increasing times, so this is O(1) instead of a binary search.
    pub fn at_hinted(&self, time_s: f64, hint: &mut usize) -> Setpoint {
        match self {
            Trajectory::Hold { position_m } => Setpoint {
                position_m: *position_m,
                ..Setpoint::default()
            },
            Trajectory::Circle(circle) => circle.at(time_s),
            Trajectory::Profile(profile) => profile.at(time_s, hint),
        }
    }
}

impl Circle {
    /// Mendřický's test (§6.3.4): R = 90 mm, CCW, feed in m/min, started at
    /// φ = π/2 with a 0.3 s cosine run-up (notes §10; Mendřický's run-up
    /// parameters are not in the text).
    pub fn thesis(feed_m_per_min: f64, axis: CircleAxis) -> Circle {
        Circle {
            radius_m: 0.09,
            feed_m_per_s: feed_m_per_min / 60.0,
            ramp_time_s: 0.3,
            start_angle_rad: PI / 2.0,
            axis,
        }
    }

    /// The final angular speed ω = feed/R, rad/s.
    pub fn angular_speed_rad_per_s(&self) -> f64 {
        self.feed_m_per_s / self.radius_m
    }

    /// φ, ω, ε = ω' and ε' at time t.
    pub fn angle(&self, time_s: f64) -> (f64, f64, f64, f64) {
        let omega0 = self.angular_speed_rad_per_s();
        let ramp = self.ramp_time_s;
        let t = time_s.max(0.0);
        if t >= ramp {
            let phi = self.start_angle_rad + omega0 * ramp / 2.0 + omega0 * (t - ramp);
            return (phi, omega0, 0.0, 0.0);
        }
        let k = PI / ramp;
        let phi = self.start_angle_rad + omega0 * (t / 2.0 - (k * t).sin() / (2.0 * k));
        let omega = omega0 * (1.0 - (k * t).cos()) / 2.0;
        let epsilon = omega0 * k / 2.0 * (k * t).sin();
        let epsilon_rate = omega0 * k * k / 2.0 * (k * t).cos();
        (phi, omega, epsilon, epsilon_rate)
    }

    /// The time at which φ reaches `angle_rad` (after the ramp), s.
    pub fn time_at_angle_s(&self, angle_rad: f64) -> f64 {
        let omega0 = self.angular_speed_rad_per_s();
        let angle_after_ramp = self.start_angle_rad + omega0 * self.ramp_time_s / 2.0;
        self.ramp_time_s + (angle_rad - angle_after_ramp) / omega0
    }

    fn at(&self, time_s: f64) -> Setpoint {
        let (phi, w, e, de) = self.angle(time_s);
        let r = self.radius_m;
        let (sin, cos) = phi.sin_cos();
        match self.axis {
            // Eq. 6.1, 6.3, 6.5 and one more derivative.
            CircleAxis::X => Setpoint {
                position_m: r * cos,
                velocity_m_per_s: -r * sin * w,
                acceleration_m_per_s2: -r * (cos * w * w + sin * e),
                jerk_m_per_s3: -r * (-sin * w * w * w + 3.0 * cos * w * e + sin * de),
            },
            // Eq. 6.2, 6.4, 6.6 and one more derivative.
            CircleAxis::Y => Setpoint {
                position_m: r * sin,
                velocity_m_per_s: r * cos * w,
                acceleration_m_per_s2: r * (cos * e - sin * w * w),
                jerk_m_per_s3: r * (cos * (de - w * w * w) - 3.0 * sin * w * e),
            },
        }
    }
}

impl Profile {
    /// When the last move or dwell ends, s.
    pub fn end_s(&self) -> f64 {
        self.end_s
    }

    /// The segments, in time order.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    fn rest_until(&self, time_s: f64) -> Option<f64> {
        if time_s >= self.end_s {
            return Some(f64::INFINITY);
        }
        let index = self.segments.partition_point(|s| s.start_s <= time_s);
        let segment = self.segments.get(index.checked_sub(1)?)?;
        let still = segment.start.velocity_m_per_s == 0.0
            && segment.start.acceleration_m_per_s2 == 0.0
            && segment.start.jerk_m_per_s3 == 0.0;
        if !still {
            return None;
        }
        Some(
            self.segments
                .get(index)
                .map_or(self.end_s, |next| next.start_s),
        )
    }

    fn at(&self, time_s: f64, hint: &mut usize) -> Setpoint {
        let hold = |position_m| Setpoint {
            position_m,
            ..Setpoint::default()
        };
        if time_s >= self.end_s {
            return hold(self.end_position_m);
        }
        let covers = |i: usize| {
            self.segments.get(i).is_some_and(|s| s.start_s <= time_s)
                && self.segments.get(i + 1).is_none_or(|s| s.start_s > time_s)
        };
        let index = if covers(*hint) {
            *hint + 1
        } else if covers(*hint + 1) {
            *hint + 2
        } else {
            self.segments.partition_point(|s| s.start_s <= time_s)
        };
        *hint = index.saturating_sub(1);
        let Some(segment) = index.checked_sub(1).and_then(|i| self.segments.get(i)) else {
            return hold(
                self.segments
                    .first()
                    .map_or(self.end_position_m, |s| s.start.position_m),
            );
        };
        advance(&segment.start, time_s - segment.start_s)
    }
}

/// State after `dt` of constant jerk.
fn advance(start: &Setpoint, dt: f64) -> Setpoint {
    let Setpoint {
        position_m: x,
        velocity_m_per_s: v,
        acceleration_m_per_s2: a,
        jerk_m_per_s3: j,
    } = *start;
    Setpoint {
        position_m: x + dt * (v + dt * (a / 2.0 + dt * j / 6.0)),
        velocity_m_per_s: v + dt * (a + dt * j / 2.0),
        acceleration_m_per_s2: a + dt * j,
        jerk_m_per_s3: j,
    }
}

impl ProfileBuilder {
    /// Starts at rest at `position_m`, time 0.
    pub fn new(position_m: f64) -> ProfileBuilder {
        ProfileBuilder {
            segments: Vec::new(),
            time_s: 0.0,
            position_m,
            at_rest: true,
        }
    }

    /// The time reached so far, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// The position reached so far, m.
    pub fn position_m(&self) -> f64 {
        self.position_m
    }

    /// Stands still for `duration_s`.
    pub fn dwell(&mut self, duration_s: f64) -> &mut ProfileBuilder {
        if duration_s > 0.0 {
            self.push(duration_s, 0.0);
            self.at_rest = true;
        }
        self
    }

    /// A jerk-limited move to `target_m`, starting and ending at rest
    /// (Tab. 6.2). Where the distance is too short to reach the feed, the
    /// top speed is lowered (and, if needed, the acceleration) so the move
    /// keeps its shape. Limits must be positive.
    pub fn move_to(&mut self, target_m: f64, limits: MoveLimits) -> &mut ProfileBuilder {
        let distance = (target_m - self.position_m).abs();
        if distance == 0.0 {
            return self;
        }
        let sign = (target_m - self.position_m).signum();
        let jerk = limits.jerk_m_per_s3;
        let mut accel = limits.acceleration_m_per_s2;
        let mut speed = limits.feed_m_per_s;
        // Distance to reach `speed` and stop again (accelerating and braking phases).
        let ramps_distance = |speed: f64, accel: f64| speed * (speed / accel + accel / jerk);
        if speed < accel * accel / jerk {
            accel = (speed * jerk).sqrt();
        }
        if ramps_distance(speed, accel) > distance {
            let a2j = accel * accel / jerk;
            speed = (-a2j + (a2j * a2j + 4.0 * distance * accel).sqrt()) / 2.0;
            if speed < accel * accel / jerk {
                // Triangular acceleration: D = 2·v·√(v/J).
                speed = (distance / 2.0).powf(2.0 / 3.0) * jerk.powf(1.0 / 3.0);
                accel = (speed * jerk).sqrt();
            }
        }
        let ramp_s = accel / jerk;
        let constant_accel_s = (speed / accel - ramp_s).max(0.0);
        let cruise_s = ((distance - ramps_distance(speed, accel)) / speed).max(0.0);
        let pieces = [
            (ramp_s, jerk),
            (constant_accel_s, 0.0),
            (ramp_s, -jerk),
            (cruise_s, 0.0),
            (ramp_s, -jerk),
            (constant_accel_s, 0.0),
            (ramp_s, jerk),
        ];
        for (duration_s, piece_jerk) in pieces {
            if duration_s > 0.0 {
                self.push(duration_s, sign * piece_jerk);
            }
        }
        self.position_m = target_m;
        self.at_rest = true;
        self
    }

    fn push(&mut self, duration_s: f64, jerk: f64) {
        // A move ends at rest on its target: start the next piece from there
        // exactly rather than from the rounded closed form.
        let start = match self.segments.last() {
            Some(last) if !self.at_rest => advance(&last.start, self.time_s - last.start_s),
            _ => Setpoint {
                position_m: self.position_m,
                ..Setpoint::default()
            },
        };
        self.segments.push(Segment {
            start_s: self.time_s,
            start: Setpoint {
                jerk_m_per_s3: jerk,
                ..start
            },
        });
        self.time_s += duration_s;
        self.at_rest = false;
    }

    /// The finished profile.
    pub fn build(&self) -> Profile {
        Profile {
            segments: self.segments.clone(),
            end_s: self.time_s,
            end_position_m: self.position_m,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMITS: MoveLimits = MoveLimits {
        feed_m_per_s: 2.0 / 60.0,
        acceleration_m_per_s2: 1.0,
        jerk_m_per_s3: 20.0,
    };

    #[test]
    fn a_move_reaches_its_target_at_rest_with_the_feed() {
        let mut builder = ProfileBuilder::new(0.0);
        builder.move_to(0.025, LIMITS).dwell(1.0);
        let profile = Trajectory::Profile(builder.build());
        // Duration by hand: speeding up and braking take v/a + a/J = 0.0333 + 0.05 s
        // each and cover v·(v/a + a/J); the cruise covers the rest at v.
        let v = LIMITS.feed_m_per_s;
        let move_s = 2.0 * (v / 1.0 + 1.0 / 20.0) + (0.025 - v * (v + 0.05)) / v;
        let end = profile.at(move_s);
        assert!((end.position_m - 0.025).abs() < 1e-12, "{end:?}");
        assert!(end.velocity_m_per_s.abs() < 1e-12);
        let middle = profile.at(move_s / 2.0);
        assert!((middle.velocity_m_per_s - v).abs() < 1e-12);
        assert!((profile.at(move_s + 0.5).position_m - 0.025).abs() < 1e-15);
    }

    #[test]
    fn short_moves_lower_speed_and_keep_their_shape() {
        for distance in [1e-6, 1e-4, 2e-3] {
            let mut builder = ProfileBuilder::new(0.1);
            builder.move_to(0.1 - distance, LIMITS);
            let profile = builder.build();
            let end = Trajectory::Profile(profile.clone()).at(profile.end_s() - 1e-12);
            assert!(
                (end.position_m - (0.1 - distance)).abs() < 1e-12,
                "{distance}: {end:?}"
            );
            assert!(end.velocity_m_per_s.abs() < 1e-9);
            assert!(
                profile
                    .segments()
                    .iter()
                    .all(|s| s.start.velocity_m_per_s <= 1e-12)
            );
        }
    }

    #[test]
    fn circle_derivatives_are_consistent() {
        // Central differences of the closed forms, during and after the ramp.
        let circle = Trajectory::Circle(Circle::thesis(24.0, CircleAxis::Y));
        let dt = 1e-6;
        for t in [0.05, 0.2, 0.31, 1.0] {
            let (before, now, after) = (circle.at(t - dt), circle.at(t), circle.at(t + dt));
            let dv = (after.position_m - before.position_m) / (2.0 * dt);
            let da = (after.velocity_m_per_s - before.velocity_m_per_s) / (2.0 * dt);
            let dj = (after.acceleration_m_per_s2 - before.acceleration_m_per_s2) / (2.0 * dt);
            assert!((dv - now.velocity_m_per_s).abs() < 1e-8);
            assert!((da - now.acceleration_m_per_s2).abs() < 1e-6);
            assert!((dj - now.jerk_m_per_s3).abs() < 1e-3);
        }
        // After the ramp |a| = v²/R at the X-axis reversal (φ = π): 0.4²/0.09 m/s².
        let x = Circle::thesis(24.0, CircleAxis::X);
        let at_reversal = Trajectory::Circle(x).at(x.time_at_angle_s(PI));
        assert!(at_reversal.velocity_m_per_s.abs() < 1e-12);
        assert!((at_reversal.acceleration_m_per_s2 - 0.16 / 0.09).abs() < 1e-9);
    }
}
