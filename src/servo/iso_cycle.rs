//! A simulated ISO 230-2 linear positioning test of one axis.
//!
//! The cycle is the standard's linear cycle (`../shared/spec/iso230-2.md`,
//! "Test cycle"): start below the first target by the overrun; per run, every
//! target in the ↑ direction with a dwell at each, past the last target by the
//! overrun, every target ↓ with a dwell, past the first target by the
//! overrun; `runs` times. Moves are Mendřický's jerk-limited run-up
//! (`trajectory`).
//!
//! The reading at a target is taken at the end of its dwell, as a laser
//! system triggers on standstill. What the laser sees is not the scale: a
//! structural compliance k_c between the motor's force line and the measured
//! point (say the table top or the tool, where the laser's reflector is)
//! carries the force the drive holds against friction, so the measured point
//! sits F_T/k_c behind the scale position in the direction of F_T:
//!
//! ```text
//! deviation = x − F_T/k_c − P_i        (x at the scale, F_T > 0 after moving in +x)
//! ```
//!
//! This is quasi-static (the part beyond the compliance is taken as
//! massless, and the closed loop as seeing a rigid axis): valid while the
//! structural mode, √(k_c/m) ≈ 670 rad/s for k_c = 100 N/µm and 225 kg, is
//! well above the velocity loop's bandwidth (≈ 40 Hz); readings after a
//! dwell do not depend on it. Mendřický (2006) gives no such compliance (notes
//! §6.2): [`DEFAULT_STIFFNESS_N_PER_UM`] is illustrative. With `None` the
//! laser reads the scale position.
//!
//! The readings make a [`Measurement`] (mm, as everywhere in axcomp), so
//! `evaluate::evaluate` gives the ISO 230-2 figures, B and B̄ among them.

use super::ServoError;
use crate::evaluate::{Evaluation, evaluate};
use crate::measurement::{Direction, Environment, Measurement, MeasurementError, Metadata, Run};
use crate::servo::axis::Axis;
use crate::servo::friction::Friction;
use crate::servo::reversal::reversal_from_friction_um;
use crate::servo::simulate::{Simulator, StepCounts, Stepping};
use crate::servo::trajectory::{MoveLimits, ProfileBuilder, Trajectory};
use crate::units::m_to_mm;

/// The structural stiffness between the motor's force line and the measured
/// point used when none is given, N/µm: illustrative (notes §6.2's example),
/// a plausible order for a machine-tool table; not from Mendřický (2006).
pub const DEFAULT_STIFFNESS_N_PER_UM: f64 = 100.0;

/// The test.
#[derive(Clone, Debug, PartialEq)]
pub struct IsoCycle {
    /// Targets P_i, m, strictly increasing.
    pub targets_m: Vec<f64>,
    /// Bidirectional runs n (ISO 230-2: 5).
    pub runs: u32,
    /// Dwell at each target before the reading, s.
    pub dwell_s: f64,
    /// Overrun beyond the first and last target, m.
    pub overrun_m: f64,
    /// Feed, acceleration and jerk of every move.
    pub limits: MoveLimits,
}

/// Options of the simulated test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoOptions {
    /// k_c, N/µm; `None` for a rigid path (the laser reads the scale).
    pub stiffness_n_per_um: Option<f64>,
    /// How time is stepped.
    pub stepping: Stepping,
}

/// One reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// Run number within its direction, from 1.
    pub run: u32,
    /// Approach direction.
    pub direction: Direction,
    /// Index of the target in `IsoCycle::targets_m`.
    pub target_index: usize,
    /// When it was taken, s.
    pub time_s: f64,
    /// x − P_i at the scale, m.
    pub scale_deviation_m: f64,
    /// Friction force held at that moment, N.
    pub friction_force_n: f64,
    /// What the laser reads, x − F_T/k_c − P_i, m.
    pub deviation_m: f64,
}

/// The simulated test.
#[derive(Clone, Debug, PartialEq)]
pub struct IsoResult {
    /// Readings in the order taken.
    pub readings: Vec<Reading>,
    /// The readings as a measurement (mm).
    pub measurement: Measurement,
    /// Its ISO 230-2 evaluation.
    pub evaluation: Evaluation,
    /// Machine time of the whole cycle, s.
    pub simulated_s: f64,
    /// How the time was stepped.
    pub counts: StepCounts,
}

/// The friction force the drive holds at the readings, per approach
/// direction (the mean over that direction's readings), N: what is left of
/// friction at standstill, which a structural compliance turns into a
/// reversal ([`super::reversal`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResidualFriction {
    /// After ↑ approaches, N.
    pub up_n: f64,
    /// After ↓ approaches, N.
    pub down_n: f64,
}

impl ResidualFriction {
    /// Its magnitude, (↑ − ↓)/2, N.
    pub fn magnitude_n(&self) -> f64 {
        (self.up_n - self.down_n) / 2.0
    }

    /// The reversal it leaves through a structure of `stiffness_n_per_um`,
    /// B ≈ 2·F_res/k_c, µm.
    pub fn reversal_um(&self, stiffness_n_per_um: f64) -> f64 {
        reversal_from_friction_um(self.magnitude_n(), stiffness_n_per_um)
    }
}

impl IsoResult {
    /// The friction held at the readings, per approach direction.
    pub fn residual_friction(&self) -> ResidualFriction {
        let mean = |direction: Direction| {
            let forces: Vec<f64> = self
                .readings
                .iter()
                .filter(|r| r.direction == direction)
                .map(|r| r.friction_force_n)
                .collect();
            forces.iter().sum::<f64>() / forces.len().max(1) as f64
        };
        ResidualFriction {
            up_n: mean(Direction::Up),
            down_n: mean(Direction::Down),
        }
    }
}

impl IsoCycle {
    /// `count` targets evenly spaced from `first_m` to `last_m`.
    pub fn evenly_spaced(first_m: f64, last_m: f64, count: usize) -> Vec<f64> {
        if count < 2 {
            return vec![first_m];
        }
        let step = (last_m - first_m) / (count - 1) as f64;
        (0..count).map(|i| first_m + step * i as f64).collect()
    }

    fn check(&self) -> Result<(), ServoError> {
        let finite_increasing = self
            .targets_m
            .windows(2)
            .all(|pair| pair[0].is_finite() && pair[1].is_finite() && pair[1] > pair[0]);
        if self.targets_m.is_empty() || !finite_increasing {
            return Err(ServoError::Invalid(
                "targets must be finite and strictly increasing",
            ));
        }
        if self.runs == 0 {
            return Err(ServoError::Invalid("at least one run is needed"));
        }
        if !(self.dwell_s.is_finite() && self.dwell_s >= 0.0) {
            return Err(ServoError::Invalid("dwell must be a finite number ≥ 0 s"));
        }
        if !(self.overrun_m.is_finite() && self.overrun_m > 0.0) {
            return Err(ServoError::Invalid(
                "overrun must be > 0 so that each direction starts with a reversal",
            ));
        }
        let limits = [
            self.limits.feed_m_per_s,
            self.limits.acceleration_m_per_s2,
            self.limits.jerk_m_per_s3,
        ];
        if limits.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(ServoError::Invalid(
                "feed, acceleration and jerk must be finite and > 0",
            ));
        }
        Ok(())
    }

    /// The command profile and the (time, run, direction, target) of each reading.
    fn profile(&self) -> (Trajectory, Vec<(f64, u32, Direction, usize)>) {
        let first = self.targets_m[0];
        let last = self.targets_m[self.targets_m.len() - 1];
        let mut builder = ProfileBuilder::new(first - self.overrun_m);
        let mut plan = Vec::new();
        for run in 1..=self.runs {
            for (index, &target) in self.targets_m.iter().enumerate() {
                builder.move_to(target, self.limits).dwell(self.dwell_s);
                plan.push((builder.time_s(), run, Direction::Up, index));
            }
            builder.move_to(last + self.overrun_m, self.limits);
            for (index, &target) in self.targets_m.iter().enumerate().rev() {
                builder.move_to(target, self.limits).dwell(self.dwell_s);
                plan.push((builder.time_s(), run, Direction::Down, index));
            }
            builder.move_to(first - self.overrun_m, self.limits);
        }
        (Trajectory::Profile(builder.build()), plan)
    }
}

/// Simulates the cycle and evaluates it per ISO 230-2.
///
/// # Example
/// ```
/// use axcomp::servo::{axis::Axis, friction::FrictionKind, simulate::Stepping};
/// use axcomp::servo::iso_cycle::{run_iso_cycle, IsoCycle, IsoOptions};
/// use axcomp::servo::trajectory::MoveLimits;
///
/// let axis = Axis::bundled("mcfv5050-x").unwrap();
/// let cycle = IsoCycle {
///     targets_m: vec![0.0, 0.01],
///     runs: 1,
///     dwell_s: 0.3,
///     overrun_m: 0.002,
///     limits: MoveLimits { feed_m_per_s: 0.05, acceleration_m_per_s2: 1.0, jerk_m_per_s3: 20.0 },
/// };
/// let options = IsoOptions { stiffness_n_per_um: Some(100.0), stepping: Stepping::DEFAULT };
/// let result = run_iso_cycle(&axis, axis.friction(FrictionKind::Classic), &cycle, options, &mut |_| {})
///     .unwrap();
/// // Classic friction holds about F_C = 90 N after each approach: B ≈ 2·90/100 = 1.8 µm.
/// let b_um = result.evaluation.figures.b.unwrap() * 1000.0;
/// assert!(b_um > 1.0 && b_um < 3.0, "{b_um}");
/// ```
pub fn run_iso_cycle(
    axis: &Axis,
    friction: Friction,
    cycle: &IsoCycle,
    options: IsoOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<IsoResult, ServoError> {
    cycle.check()?;
    if let Some(k) = options.stiffness_n_per_um
        && !(k.is_finite() && k > 0.0)
    {
        return Err(ServoError::Invalid(
            "compliance stiffness must be finite and > 0",
        ));
    }
    let (trajectory, plan) = cycle.profile();
    let end_s = match &trajectory {
        Trajectory::Profile(profile) => profile.end_s(),
        _ => 0.0,
    };
    let compliance_m_per_n = options.stiffness_n_per_um.map_or(0.0, |k| 1.0 / (k * 1e6));
    let mut simulator = Simulator::new(axis, friction, &trajectory, options.stepping, None);
    let macro_s = simulator.macro_step_s();
    let mut readings = Vec::with_capacity(plan.len());
    for &(time_s, run, direction, target_index) in &plan {
        // Readings fall on the macro-step grid (125 µs for the bundled axes).
        let at_s = (time_s / macro_s).round() * macro_s;
        simulator.advance_to(at_s);
        let snapshot = simulator.snapshot();
        let target_m = cycle.targets_m[target_index];
        let scale_deviation_m = snapshot.position_m - target_m;
        readings.push(Reading {
            run,
            direction,
            target_index,
            time_s: snapshot.time_s,
            scale_deviation_m,
            friction_force_n: snapshot.friction_force_n,
            deviation_m: scale_deviation_m - snapshot.friction_force_n * compliance_m_per_n,
        });
        progress(snapshot.time_s / end_s.max(f64::MIN_POSITIVE));
    }
    simulator.advance_to(end_s);
    progress(1.0);
    let measurement = to_measurement(axis, cycle, &readings)?;
    let evaluation = evaluate(&measurement);
    Ok(IsoResult {
        readings,
        measurement,
        evaluation,
        simulated_s: end_s,
        counts: simulator.counts(),
    })
}

fn to_measurement(
    axis: &Axis,
    cycle: &IsoCycle,
    readings: &[Reading],
) -> Result<Measurement, MeasurementError> {
    let targets_mm: Vec<f64> = cycle.targets_m.iter().map(|m| m_to_mm(*m)).collect();
    let mut runs = Vec::new();
    for run in 1..=cycle.runs {
        for direction in Direction::BOTH {
            let mut deviations_mm = vec![None; targets_mm.len()];
            let mut start_time_s = None;
            for reading in readings
                .iter()
                .filter(|r| r.run == run && r.direction == direction)
            {
                deviations_mm[reading.target_index] = Some(m_to_mm(reading.deviation_m));
                start_time_s =
                    Some(start_time_s.map_or(reading.time_s, |t: f64| t.min(reading.time_s)));
            }
            runs.push(Run {
                direction,
                number: run,
                start_time_s,
                deviations: deviations_mm,
            });
        }
    }
    let metadata = Metadata {
        machine: Some("simulated feed axis (axcomp servo-sim)".to_string()),
        description: Some("ISO 230-2 linear cycle simulated with a friction model".to_string()),
        // The axis file names the axis.
        axis_source: crate::measurement::AxisSource::Given,
        ..Metadata::default()
    };
    Measurement::new(
        axis.name.clone(),
        targets_mm,
        runs,
        Environment::default(),
        metadata,
    )
}
