//! Time simulation of one feed axis: the cascade of Mendřický (2006) ch. 3 with a
//! friction model, following a trajectory.
//!
//! # The model (notes §3, §10)
//!
//! ```text
//! position loop, every T_s:  v_pos = K_v·(x_z − Q(x))          Q: round to the increment
//! velocity PI:               e_v = v_pos + K_wv·v_z − v,  I_z = k_pv·(e_v + q_v) + K_wi·a_z·m/K_F3,  q_v' = e_v/T_Nv
//! current PI:                e_i = I_z − I,  U = k_pi·(e_i + q_i),  q_i' = e_i/T_Ni
//! converter:                 U_d(t) = U(t − T_d)
//! motor:                     L·I' = U_d − K_E·v − R·I,  F_m = K_F3·I
//! mass:                      m·v' = F_m − F_T − F_ext,  x' = v
//! ```
//!
//! The feedforward is continuous (the notes found that holding it with the
//! 1 ms sample raises every circle spike by 4–5 µm and does not reproduce
//! Tab. 6.4); the velocity loop uses the true velocity (Mendřický (2006) does not
//! say which signal it used).
//!
//! # The scheme
//!
//! Time advances in macro steps of H = gcd(T_s, T_d), capped at 125 µs
//! (125 µs for the bundled axes), so every position sample and every delayed
//! voltage jump falls on a step boundary. Over a step the voltage reaching
//! the motor was computed one dead time earlier and is known; it is stored
//! as a cubic (Hermite from the values and slopes at the ends of that
//! earlier step), the commands are cubics in the same way, and the linear
//! part advances exactly (`linear`). Friction is held over the step at its
//! end value and solved implicitly (`friction`).
//!
//! [`Stepping::Uniform`] takes every macro step as 1 µs sub-steps: the
//! reference. [`Stepping::Adaptive`] takes each macro step whole and keeps
//! it unless the friction force changed by more than a tolerance or the
//! velocity crossed a corner of the friction law (a reversal, a stick/slip
//! switch, B1's corner); then it re-takes that step as 1 µs sub-steps. So
//! the fast dynamics are stepped finely only where they are active, and
//! exactly elsewhere. The `servo::tests` module checks that the two agree.
//!
//! Pure: no I/O, no clock, no randomness.

use crate::servo::axis::Axis;
use crate::servo::friction::Friction;
use crate::servo::linear::{
    LinearSystem, N_COEFFS, N_INPUTS, N_STATES, StepMap, cubic_value_slope, hermite, taylor_shift,
};
use crate::servo::trajectory::{Setpoint, Trajectory};

/// Fine step, µs: the reference step and the sub-step of re-taken macro steps.
pub const FINE_STEP_US: u64 = 1;
/// Largest macro step, µs.
pub const MAX_MACRO_STEP_US: u64 = 125;

/// How time is stepped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stepping {
    /// Every step 1 µs: the reference.
    Uniform,
    /// Macro steps, re-taken at 1 µs where friction is active.
    Adaptive {
        /// Largest change of the friction force over one kept macro step, N.
        max_force_change_n: f64,
    },
}

impl Stepping {
    /// The adaptive scheme with the tolerance the speed and accuracy figures
    /// are stated for (docs/src/servo.md): a change of 2 N over 125 µs is a smooth
    /// change (acceleration times μ_v) that the implicit step follows to well
    /// under 0.01 µm; a friction jump at a reversal is 100 N or more.
    pub const DEFAULT: Stepping = Stepping::Adaptive {
        max_force_change_n: 2.0,
    };
}

/// A constant external force on the mass from a given time (the force-step test, thesis §6.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceStep {
    /// When it starts, s (rounded to the macro-step grid).
    pub at_s: f64,
    /// The force, N, acting in +x.
    pub force_n: f64,
}

/// What the simulation looks like at the end of a macro step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Snapshot {
    /// Time, s.
    pub time_s: f64,
    /// Position x at the scale, m.
    pub position_m: f64,
    /// Velocity, m/s.
    pub velocity_m_per_s: f64,
    /// Motor (module) current, A.
    pub current_a: f64,
    /// Friction force F_T over the last step, N (opposes motion; see `friction`).
    pub friction_force_n: f64,
    /// The command at this time.
    pub command: Setpoint,
    /// Whether the position loop samples at this instant.
    pub is_position_sample: bool,
    /// Largest |current| during the macro step that just ended, A (the
    /// current's Hermite cubic over a whole step, its 1 µs samples over a
    /// re-taken one): a peak between step ends is not missed.
    pub peak_current_a: f64,
}

impl Snapshot {
    /// Following error x_z − x, m.
    pub fn following_error_m(&self) -> f64 {
        self.command.position_m - self.position_m
    }
}

/// Work counters, for the benchmark and the speed figures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepCounts {
    /// Macro steps kept whole.
    pub coarse: u64,
    /// Macro steps taken as fine sub-steps.
    pub refined: u64,
    /// Macro steps skipped because the axis stood settled under a still command.
    pub skipped: u64,
}

/// Below these changes over one kept macro step, under a still command, the
/// axis counts as settled and time is skipped: what is left of the decay
/// then moves the axis by less than 1e-5 µm (the slowest closed-loop mode
/// decays faster than 5 1/s, and 1e-14 m per 125 µs step summed over it is
/// ≈ 2e-11 m).
const SETTLED_POSITION_M: f64 = 1e-14;
const SETTLED_VELOCITY_M_PER_S: f64 = 1e-12;
const SETTLED_CURRENT_A: f64 = 1e-9;
const SETTLED_FORCE_N: f64 = 1e-7;
const SETTLED_VOLTAGE_V: f64 = 1e-8;

/// A running simulation.
#[derive(Clone, Debug)]
pub struct Simulator<'a> {
    friction: Friction,
    trajectory: &'a Trajectory,
    stepping: Stepping,
    force_step: Option<(u64, f64)>,
    constants: Constants,
    coarse: StepMap,
    fine: StepMap,
    step_index: u64,
    state: [f64; N_STATES],
    bristle_m: f64,
    friction_force_n: f64,
    position_command_m_per_s: f64,
    history: Vec<Vec<[f64; N_COEFFS]>>,
    pieces: Vec<[f64; N_COEFFS]>,
    counts: StepCounts,
    segment_hint: usize,
    step_peak_current_a: f64,
    settled_until_index: u64,
}

/// Everything derived from the axis that the inner loop reads.
#[derive(Clone, Copy, Debug)]
struct Constants {
    macro_us: u64,
    substeps: u64,
    samples_every: u64,
    system: LinearSystem,
    /// U = c·s + d_w·w + d_az·a_z.
    u_state: [f64; N_STATES],
    u_command: f64,
    u_acceleration: f64,
    /// U' = c·A·s + c·B·u + d_w·w' + d_az·a_z'.
    du_state: [f64; N_STATES],
    du_input: [f64; N_INPUTS],
    velocity_weight: f64,
    position_gain_per_s: f64,
    increment_m: f64,
}

const X: usize = 0;
const V: usize = 1;
const I: usize = 2;
const IN_UD: usize = 0;
const IN_W: usize = 1;
const IN_AZ: usize = 2;
const IN_F: usize = 3;

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

impl Constants {
    fn new(axis: &Axis) -> Constants {
        let m = axis.mass_kg;
        let motor = &axis.motor;
        let kf = motor.force_constant_n_per_a;
        let l = motor.inductance_h;
        let kpi = axis.current_loop.gain_v_per_a;
        let tni = axis.current_loop.integral_time_s;
        let kpv = axis.velocity_loop.gain_a_s_per_m;
        let tnv = axis.velocity_loop.integral_time_s;
        let current_ff = axis.feedforward.current_weight * m / kf;
        let mut a = [[0.0; N_STATES]; N_STATES];
        let mut b = [[0.0; N_INPUTS]; N_STATES];
        // x' = v
        a[X][V] = 1.0;
        // m v' = K_F I − F
        a[V][I] = kf / m;
        b[V][IN_F] = -1.0 / m;
        // L I' = U_d − K_E v − R I
        a[I][V] = -motor.back_emf_v_s_per_m / l;
        a[I][I] = -motor.resistance_ohm / l;
        b[I][IN_UD] = 1.0 / l;
        // q_v' = (w − v)/T_Nv
        a[3][V] = -1.0 / tnv;
        b[3][IN_W] = 1.0 / tnv;
        // q_i' = (I_z − I)/T_Ni with I_z = k_pv (w − v + q_v) + c_a a_z
        a[4][V] = -kpv / tni;
        a[4][I] = -1.0 / tni;
        a[4][3] = kpv / tni;
        b[4][IN_W] = kpv / tni;
        b[4][IN_AZ] = current_ff / tni;
        let system = LinearSystem { a, b };
        let u_state = [0.0, -kpi * kpv, -kpi, kpi * kpv, kpi];
        let mut du_state = [0.0; N_STATES];
        let mut du_input = [0.0; N_INPUTS];
        for (k, c) in u_state.iter().enumerate() {
            for j in 0..N_STATES {
                du_state[j] += c * a[k][j];
            }
            for j in 0..N_INPUTS {
                du_input[j] += c * b[k][j];
            }
        }
        let dead_us = axis.dead_time_us();
        let sample_us = axis.sample_time_us();
        let common = gcd(dead_us, sample_us);
        let macro_us = (1..=MAX_MACRO_STEP_US.min(common))
            .rev()
            .find(|d| common.is_multiple_of(*d))
            .unwrap_or(1);
        Constants {
            macro_us,
            substeps: macro_us / FINE_STEP_US,
            samples_every: sample_us / macro_us,
            system,
            u_state,
            u_command: kpi * kpv,
            u_acceleration: kpi * current_ff,
            du_state,
            du_input,
            velocity_weight: axis.feedforward.velocity_weight,
            position_gain_per_s: axis.position_loop.gain_per_s,
            increment_m: axis.position_loop.increment_m,
        }
    }
}

/// The inputs of one (sub-)step as cubics in τ.
struct StepInputs {
    delayed_voltage: [f64; N_COEFFS],
    velocity_command: [f64; N_COEFFS],
    acceleration_command: [f64; N_COEFFS],
    external_force_n: f64,
}

impl<'a> Simulator<'a> {
    /// Starts at rest on the trajectory's position at t = 0.
    pub fn new(
        axis: &Axis,
        friction: Friction,
        trajectory: &'a Trajectory,
        stepping: Stepping,
        force_step: Option<ForceStep>,
    ) -> Simulator<'a> {
        let constants = Constants::new(axis);
        let macro_s = constants.macro_us as f64 * 1e-6;
        let fine_s = FINE_STEP_US as f64 * 1e-6;
        let delay_steps = (axis.dead_time_us() / constants.macro_us) as usize;
        let mut state = [0.0; N_STATES];
        state[X] = trajectory.at(0.0).position_m;
        let force_step = force_step.map(|step| {
            let index = (step.at_s * 1e6 / constants.macro_us as f64)
                .round()
                .max(0.0) as u64;
            (index, step.force_n)
        });
        Simulator {
            friction,
            trajectory,
            stepping,
            force_step,
            coarse: constants.system.step_map(macro_s),
            fine: constants.system.step_map(fine_s),
            constants,
            step_index: 0,
            state,
            bristle_m: 0.0,
            friction_force_n: 0.0,
            position_command_m_per_s: 0.0,
            history: vec![vec![[0.0; N_COEFFS]]; delay_steps.max(1)],
            pieces: Vec::with_capacity(constants.substeps as usize),
            counts: StepCounts::default(),
            segment_hint: 0,
            step_peak_current_a: 0.0,
            settled_until_index: 0,
        }
    }

    /// The macro step, s.
    pub fn macro_step_s(&self) -> f64 {
        self.constants.macro_us as f64 * 1e-6
    }

    /// Time now, s.
    pub fn time_s(&self) -> f64 {
        (self.step_index * self.constants.macro_us) as f64 * 1e-6
    }

    /// How many macro steps were kept whole and how many re-taken.
    pub fn counts(&self) -> StepCounts {
        self.counts
    }

    /// The state now.
    pub fn snapshot(&self) -> Snapshot {
        let time_s = self.time_s();
        Snapshot {
            time_s,
            position_m: self.state[X],
            velocity_m_per_s: self.state[V],
            current_a: self.state[I],
            friction_force_n: self.friction_force_n,
            command: self.trajectory.at(time_s),
            is_position_sample: self.step_index.is_multiple_of(self.constants.samples_every),
            peak_current_a: self.step_peak_current_a,
        }
    }

    /// Advances macro step by macro step until `end_s`, calling `observe`
    /// after each step.
    pub fn run_until(&mut self, end_s: f64, mut observe: impl FnMut(&Snapshot)) {
        let end_index = self.index_at(end_s);
        while self.step_index < end_index {
            self.step();
            observe(&self.snapshot());
        }
    }

    /// Advances until `end_s` without looking.
    pub fn advance_to(&mut self, end_s: f64) {
        let end_index = self.index_at(end_s);
        while self.step_index < end_index {
            self.step();
        }
    }

    fn index_at(&self, time_s: f64) -> u64 {
        (time_s * 1e6 / self.constants.macro_us as f64)
            .round()
            .max(0.0) as u64
    }

    fn command_at(&mut self, time_s: f64) -> Setpoint {
        self.trajectory.at_hinted(time_s, &mut self.segment_hint)
    }

    /// Advances one macro step.
    pub fn step(&mut self) {
        let c = self.constants;
        let macro_s = c.macro_us as f64 * 1e-6;
        if self.step_index < self.settled_until_index {
            // Settled under a still command: nothing changes (the position
            // samples read the same quantised position and give the same
            // command, the delayed voltage is flat).
            self.counts.skipped += 1;
            self.step_peak_current_a = self.state[I].abs();
            self.step_index += 1;
            return;
        }
        let t0 = self.time_s();
        if self.step_index.is_multiple_of(c.samples_every) {
            // Position loop: error sampled and held for T_s, the measured
            // position quantised (Fig. 3.10; notes §10 rounds x to 1 µm).
            let measured = (self.state[X] / c.increment_m).round() * c.increment_m;
            let command = self.command_at(t0).position_m;
            self.position_command_m_per_s = c.position_gain_per_s * (command - measured);
        }
        let external_force_n = match self.force_step {
            Some((index, force_n)) if self.step_index >= index => force_n,
            _ => 0.0,
        };
        let history_slot = (self.step_index % self.history.len() as u64) as usize;
        self.step_peak_current_a = self.state[I].abs();
        let mut pieces = std::mem::take(&mut self.pieces);
        pieces.clear();
        let kept = match self.stepping {
            Stepping::Uniform => false,
            Stepping::Adaptive { max_force_change_n } => {
                let saved = (self.state, self.bristle_m, self.friction_force_n);
                let start = self.command_at(t0);
                let end = self.command_at(t0 + macro_s);
                let inputs = StepInputs {
                    delayed_voltage: merged(&self.history[history_slot], c.macro_us),
                    velocity_command: self.command_cubic(&start, &end, macro_s),
                    acceleration_command: acceleration_cubic(&start, &end, macro_s),
                    external_force_n,
                };
                let v0 = self.state[V];
                let force_before = self.friction_force_n;
                let peak_before = self.step_peak_current_a;
                let piece = self.sub_step(true, &inputs, macro_s);
                let keep = (self.friction_force_n - force_before).abs() <= max_force_change_n
                    && !self.friction.crossed_corner(v0, self.state[V], macro_s);
                if keep {
                    pieces.push(piece);
                    self.settled_until_index =
                        self.settled_until(&saved.0, force_before, &piece, t0);
                } else {
                    (self.state, self.bristle_m, self.friction_force_n) = saved;
                    self.step_peak_current_a = peak_before;
                }
                keep
            }
        };
        if kept {
            self.counts.coarse += 1;
        } else {
            self.counts.refined += 1;
            let fine_s = FINE_STEP_US as f64 * 1e-6;
            let mut start = self.command_at(t0);
            for sub in 0..c.substeps {
                let offset_s = sub as f64 * fine_s;
                let end = self.command_at(t0 + offset_s + fine_s);
                let inputs = StepInputs {
                    delayed_voltage: piece_at(&self.history[history_slot], sub as usize, offset_s),
                    velocity_command: self.command_cubic(&start, &end, fine_s),
                    acceleration_command: acceleration_cubic(&start, &end, fine_s),
                    external_force_n,
                };
                let piece = self.sub_step(false, &inputs, fine_s);
                pieces.push(piece);
                start = end;
            }
        }
        // This step's voltage reaches the motor one dead time later.
        std::mem::swap(&mut self.history[history_slot], &mut pieces);
        self.pieces = pieces;
        self.step_index += 1;
    }

    /// After a kept macro step from `before`: the step index until which the
    /// axis stays as it is, if it has settled under a still command (else 0).
    fn settled_until(
        &self,
        before: &[f64; N_STATES],
        force_before_n: f64,
        voltage: &[f64; N_COEFFS],
        t0: f64,
    ) -> u64 {
        let s = &self.state;
        let h = self.macro_step_s();
        // How much a stored voltage cubic varies over a step (its value aside).
        let variation = |c: &[f64; N_COEFFS]| {
            c[1].abs() * h + c[2].abs() * h * h / 2.0 + c[3].abs() * h * h * h / 6.0
        };
        let settled = self.stepping != Stepping::Uniform
            && (s[X] - before[X]).abs() < SETTLED_POSITION_M
            && s[V].abs() < SETTLED_VELOCITY_M_PER_S
            && (s[I] - before[I]).abs() < SETTLED_CURRENT_A
            && (s[3] - before[3]).abs() < SETTLED_VELOCITY_M_PER_S
            && (s[4] - before[4]).abs() < SETTLED_CURRENT_A
            && (self.friction_force_n - force_before_n).abs() < SETTLED_FORCE_N
            && variation(voltage) < SETTLED_VOLTAGE_V
            && self.history.iter().all(|slot| {
                slot.iter().all(|piece| {
                    (piece[0] - voltage[0]).abs() < SETTLED_VOLTAGE_V
                        && variation(piece) < SETTLED_VOLTAGE_V
                })
            });
        if !settled {
            return 0;
        }
        let Some(rest_until_s) = self.trajectory.rest_until(t0) else {
            return 0;
        };
        let mut until = if rest_until_s.is_finite() {
            // Stop skipping one step before the command moves again.
            (self.index_at(rest_until_s)).saturating_sub(1)
        } else {
            u64::MAX
        };
        if let Some((index, _)) = self.force_step
            && index > self.step_index
        {
            until = until.min(index);
        }
        until
    }

    /// w = v_pos + K_wv·v_z over a step, as a cubic.
    fn command_cubic(&self, start: &Setpoint, end: &Setpoint, h: f64) -> [f64; N_COEFFS] {
        let weight = self.constants.velocity_weight;
        let held = self.position_command_m_per_s;
        hermite(
            held + weight * start.velocity_m_per_s,
            weight * start.acceleration_m_per_s2,
            held + weight * end.velocity_m_per_s,
            weight * end.acceleration_m_per_s2,
            h,
        )
    }

    /// Advances one (sub-)step with the coarse or the fine map; returns the
    /// converter voltage over the step as a cubic (for the delay line).
    fn sub_step(&mut self, coarse: bool, inputs: &StepInputs, h: f64) -> [f64; N_COEFFS] {
        let c = &self.constants;
        let map = if coarse { &self.coarse } else { &self.fine };
        let mut coefficients = [0.0; N_INPUTS * N_COEFFS];
        coefficients[IN_UD * N_COEFFS..(IN_UD + 1) * N_COEFFS]
            .copy_from_slice(&inputs.delayed_voltage);
        coefficients[IN_W * N_COEFFS..(IN_W + 1) * N_COEFFS]
            .copy_from_slice(&inputs.velocity_command);
        coefficients[IN_AZ * N_COEFFS..(IN_AZ + 1) * N_COEFFS]
            .copy_from_slice(&inputs.acceleration_command);
        let start = self.state;
        let free = map.apply(&start, &coefficients);
        // The force on the mass enters linearly: s(h) = free + g·F.
        let g = map.constant_input_response(IN_F);
        let alpha = -g[V];
        let free_velocity = free[V] - alpha * inputs.external_force_n;
        let friction = self
            .friction
            .step(&mut self.bristle_m, free_velocity, alpha, h);
        let force = friction.force_n + inputs.external_force_n;
        let mut end = [0.0; N_STATES];
        for k in 0..N_STATES {
            end[k] = free[k] + g[k] * force;
        }
        // The velocity is the friction solution itself (no rounding through g).
        end[V] = friction.velocity_m_per_s;
        self.state = end;
        self.friction_force_n = friction.force_n;
        // Converter voltage U and its slope at both ends of the step.
        let w0 = inputs.velocity_command;
        let a0 = inputs.acceleration_command;
        let (w1, dw1) = cubic_value_slope(&w0, h);
        let (az1, daz1) = cubic_value_slope(&a0, h);
        let (ud1, _) = cubic_value_slope(&inputs.delayed_voltage, h);
        let voltage = |s: &[f64; N_STATES], w: f64, az: f64| -> f64 {
            dot(&c.u_state, s) + c.u_command * w + c.u_acceleration * az
        };
        let slope = |s: &[f64; N_STATES], ud: f64, w: f64, az: f64, dw: f64, daz: f64| -> f64 {
            dot(&c.du_state, s)
                + c.du_input[IN_UD] * ud
                + c.du_input[IN_W] * w
                + c.du_input[IN_AZ] * az
                + c.du_input[IN_F] * force
                + c.u_command * dw
                + c.u_acceleration * daz
        };
        // The current's peak over the step, from its cubic through the ends.
        let current_slope = |s: &[f64; N_STATES], ud: f64| {
            c.system.a[I][V] * s[V] + c.system.a[I][I] * s[I] + c.system.b[I][IN_UD] * ud
        };
        let current = hermite(
            start[I],
            current_slope(&start, inputs.delayed_voltage[0]),
            end[I],
            current_slope(&end, ud1),
            h,
        );
        self.step_peak_current_a = self.step_peak_current_a.max(cubic_peak_abs(&current, h));
        let u0 = voltage(&start, w0[0], a0[0]);
        let du0 = slope(
            &start,
            inputs.delayed_voltage[0],
            w0[0],
            a0[0],
            w0[1],
            a0[1],
        );
        let u1 = voltage(&end, w1, az1);
        let du1 = slope(&end, ud1, w1, az1, dw1, daz1);
        hermite(u0, du0, u1, du1, h)
    }
}

/// Largest |p(τ)| of a cubic on [0, h]: at the ends or where p' = 0.
fn cubic_peak_abs(c: &[f64; N_COEFFS], h: f64) -> f64 {
    let [_, c1, c2, c3] = *c;
    let mut peak = c[0].abs().max(cubic_value_slope(c, h).0.abs());
    // p'(τ) = c1 + c2·τ + c3·τ²/2.
    let (a, b) = (c3 / 2.0, c2);
    let mut roots = [f64::NAN; 2];
    if a.abs() < 1e-300 {
        if b != 0.0 {
            roots[0] = -c1 / b;
        }
    } else {
        let discriminant = b * b - 4.0 * a * c1;
        if discriminant >= 0.0 {
            let root = discriminant.sqrt();
            roots = [(-b + root) / (2.0 * a), (-b - root) / (2.0 * a)];
        }
    }
    for tau in roots {
        if tau > 0.0 && tau < h {
            peak = peak.max(cubic_value_slope(c, tau).0.abs());
        }
    }
    peak
}

/// a_z over a step, as a cubic.
fn acceleration_cubic(start: &Setpoint, end: &Setpoint, h: f64) -> [f64; N_COEFFS] {
    hermite(
        start.acceleration_m_per_s2,
        start.jerk_m_per_s3,
        end.acceleration_m_per_s2,
        end.jerk_m_per_s3,
        h,
    )
}

/// The delayed voltage over a whole macro step: the stored cubic, or, if
/// that step was taken in sub-steps, the Hermite cubic through its two ends.
fn merged(pieces: &[[f64; N_COEFFS]], macro_us: u64) -> [f64; N_COEFFS] {
    match pieces {
        [single] => *single,
        [first, .., last] => {
            let fine_s = FINE_STEP_US as f64 * 1e-6;
            let (u1, du1) = cubic_value_slope(last, fine_s);
            hermite(first[0], first[1], u1, du1, macro_us as f64 * 1e-6)
        }
        [] => [0.0; N_COEFFS],
    }
}

/// The delayed voltage over sub-step `index` (starting `offset_s` into the macro step).
fn piece_at(pieces: &[[f64; N_COEFFS]], index: usize, offset_s: f64) -> [f64; N_COEFFS] {
    match pieces {
        [single] => taylor_shift(single, offset_s),
        _ => pieces.get(index).copied().unwrap_or([0.0; N_COEFFS]),
    }
}

fn dot(a: &[f64; N_STATES], b: &[f64; N_STATES]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
