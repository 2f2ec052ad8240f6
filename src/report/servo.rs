//! The output of `axcomp servo-sim`: the `--json` wire format, the terminal
//! text and the `--csv` trace, all from the same structs.
//!
//! # Wire format
//!
//! One object; keys may be added, never renamed or removed. Units are in the
//! keys; one of `circle`, `force_step`, `constant_velocity`, `iso230_2` is
//! filled, the others are `null`.
//!
//! ```text
//! { "axis": "X", "axis_source": "mcfv5050-x", "friction": "lugre", "friction_label": "C",
//!   "test": "circle", "stepping": "adaptive" | "uniform-1us", "simulated_s": 2.1,
//!   "macro_steps": {"kept": 16000, "refined": 400, "skipped": 0},
//!   "circle": {"radius_mm": 90, "feed_m_min": 16, "reversal_error_um": 7.7, "reversal_current_a": 3.35,
//!              "reversals": [{"angle_deg": 180, "time_s": …, "direction_after": "up",
//!                             "peak_error_um": …, "peak_current_a": …}, …]},
//!   "force_step": {"force_n": 1500, "at_s": 0.01, "peak_error_um": …, "peak_after_s": …,
//!                  "recovery_s": …, "peak_current_a": …, "final_friction_n": …},
//!   "constant_velocity": {"feed_m_min": …, "mean_current_a": …, "mean_friction_n": …,
//!                         "steady_friction_n": …, "mean_following_error_um": …},
//!   "iso230_2": {"targets_mm": […], "runs": 5, "dwell_s": 1, "overrun_mm": 5, "feed_m_min": 2,
//!                "stiffness_n_per_um": 100 | null,
//!                "figures_um": {"A", "A_up", …, "B", "B_mean"},   (as in `evaluate --json`)
//!                "residual_friction_n": {"up": 89.7, "down": -89.7},
//!                "reversal_from_friction_um": 1.79,
//!                "readings": [{"run": 1, "direction": "up", "target_mm": 0, "time_s": …,
//!                              "deviation_um": …, "scale_deviation_um": …, "friction_n": …}, …]} }
//! ```
//!
//! `reversal_error_um` is Mendřický's (2006) quadrant error (Tab. 6.4 xe/ye): the
//! mean over this axis's reversals of the peak |following error|;
//! `reversal_current_a` likewise for |current|. In `iso230_2`, `B` is
//! max |B_i| and `B_mean` the signed mean (↑ minus ↓); `deviation_um` is what
//! the laser reads (scale minus F_T/k_c), `scale_deviation_um` the scale.
//! `reversal_from_friction_um` is 2·F_res/k_c with F_res the mean |friction|
//! held at the readings (the closed form of `servo::reversal`).
//!
//! `servo-sim --identify` prints another object (`IdentifyJson`):
//!
//! ```text
//! { "axis_source": "mcfv5050-x", "coulomb_n": 109.7, "viscous_n_s_per_m": 430.3,
//!   "force_rms_residual_n": 0.7, "rows": 14,
//!   "lugre_stiffness_n_per_m": 2.8e7 | null, "following_error_rms_residual_um": 0.11 | null,
//!   "samples": 21000 | null, "simulations": 37 | null,
//!   "circle_feed_m_min": 3.2 | null, "circle_radius_mm": 90 | null,
//!   "servo_sim": "--coulomb-n 109.7 --viscous-n-s-m 430.3 --lugre-stiffness-n-m 2.8e7" }
//! ```

use std::fmt::Write as _;

use serde::Serialize;

use crate::servo::friction_fit::Identified;
use crate::servo::trajectory::Circle;

use crate::report::json::FiguresJson;
use crate::servo::circle::CircleResult;
use crate::servo::force_step::{ConstantVelocityResult, ForceStepResult};
use crate::servo::iso_cycle::{IsoCycle, IsoResult};
use crate::servo::simulate::{Snapshot, StepCounts};
use crate::units::{m_to_mm, m_to_um};

/// The whole `servo-sim --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct ServoSimJson {
    /// Axis name from the axis file.
    pub axis: String,
    /// `--axis` as given (bundled name or file path).
    pub axis_source: String,
    /// Friction model: classic, ramp, power, lugre.
    pub friction: &'static str,
    /// Mendřický's (2006) label: A, B1, B2, C.
    pub friction_label: &'static str,
    /// Test: circle, step, constant-velocity, iso230-2.
    pub test: &'static str,
    /// `adaptive` or `uniform-1us`.
    pub stepping: &'static str,
    /// Simulated machine time, s.
    pub simulated_s: f64,
    /// How the macro steps were taken.
    pub macro_steps: MacroStepsJson,
    /// Circle test figures.
    pub circle: Option<CircleJson>,
    /// Force-step figures.
    pub force_step: Option<ForceStepJson>,
    /// Constant-velocity figures.
    pub constant_velocity: Option<ConstantVelocityJson>,
    /// ISO 230-2 cycle.
    pub iso230_2: Option<IsoJson>,
}

/// Macro steps kept whole, re-taken in 1 µs sub-steps, or skipped while settled.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MacroStepsJson {
    /// Kept whole.
    pub kept: u64,
    /// Re-taken finely.
    pub refined: u64,
    /// Skipped: the axis stood settled under a still command.
    pub skipped: u64,
}

/// Circle test.
#[derive(Clone, Debug, Serialize)]
pub struct CircleJson {
    /// Radius, mm.
    pub radius_mm: f64,
    /// Feed, m/min.
    pub feed_m_min: f64,
    /// Mean peak |following error| at this axis's reversals, µm (Tab. 6.4).
    pub reversal_error_um: f64,
    /// Mean peak |current| at this axis's reversals, A (Tab. 6.4).
    pub reversal_current_a: f64,
    /// Each reversal.
    pub reversals: Vec<ReversalJson>,
}

/// One reversal on the circle.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ReversalJson {
    /// φ, degrees.
    pub angle_deg: f64,
    /// Time of the command's reversal, s.
    pub time_s: f64,
    /// Direction after it: up or down.
    pub direction_after: &'static str,
    /// Peak |following error|, µm.
    pub peak_error_um: f64,
    /// Peak |current|, A.
    pub peak_current_a: f64,
}

/// Force step.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ForceStepJson {
    /// Step size, N.
    pub force_n: f64,
    /// Step time, s.
    pub at_s: f64,
    /// Peak |following error|, µm.
    pub peak_error_um: f64,
    /// When, after the step, s.
    pub peak_after_s: f64,
    /// Until |error| stays below 5 % of the peak, after the step, s.
    pub recovery_s: f64,
    /// Peak |current|, A.
    pub peak_current_a: f64,
    /// Friction at the end, N.
    pub final_friction_n: f64,
}

/// Constant-velocity run.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ConstantVelocityJson {
    /// Feed, m/min.
    pub feed_m_min: f64,
    /// Mean current over the middle of the cruise, A.
    pub mean_current_a: f64,
    /// Mean friction force, N.
    pub mean_friction_n: f64,
    /// The model's steady friction at the feed, N.
    pub steady_friction_n: f64,
    /// Mean following error, µm.
    pub mean_following_error_um: f64,
}

/// ISO 230-2 cycle.
#[derive(Clone, Debug, Serialize)]
pub struct IsoJson {
    /// Targets, mm.
    pub targets_mm: Vec<f64>,
    /// Bidirectional runs.
    pub runs: u32,
    /// Dwell, s.
    pub dwell_s: f64,
    /// Overrun, mm.
    pub overrun_mm: f64,
    /// Feed, m/min.
    pub feed_m_min: f64,
    /// k_c, N/µm; null for a rigid path.
    pub stiffness_n_per_um: Option<f64>,
    /// The same k_c under the key it had before 0.2 (a stiffness, misnamed;
    /// CHANGELOG.md), kept for scripts that read it.
    pub compliance_n_per_um: Option<f64>,
    /// The ISO 230-2 figures of the readings, µm.
    pub figures_um: FiguresJson,
    /// Mean friction held at the readings, per approach direction, N.
    pub residual_friction_n: ResidualJson,
    /// 2·F_res/k_c, µm (null for a rigid path).
    pub reversal_from_friction_um: Option<f64>,
    /// Every reading, in the order taken.
    pub readings: Vec<ReadingJson>,
}

/// Mean friction held per direction, N.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ResidualJson {
    /// After ↑ approaches.
    pub up: f64,
    /// After ↓ approaches.
    pub down: f64,
}

/// One ISO reading.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ReadingJson {
    /// Run number within its direction.
    pub run: u32,
    /// up or down.
    pub direction: &'static str,
    /// Target, mm.
    pub target_mm: f64,
    /// When, s.
    pub time_s: f64,
    /// What the laser reads, µm.
    pub deviation_um: f64,
    /// The scale's deviation, µm.
    pub scale_deviation_um: f64,
    /// Friction held, N.
    pub friction_n: f64,
}

impl MacroStepsJson {
    /// From the simulator's counts.
    pub fn new(counts: StepCounts) -> MacroStepsJson {
        MacroStepsJson {
            kept: counts.coarse,
            refined: counts.refined,
            skipped: counts.skipped,
        }
    }
}

impl CircleJson {
    /// From a circle result.
    pub fn new(radius_m: f64, feed_m_per_s: f64, result: &CircleResult) -> CircleJson {
        CircleJson {
            radius_mm: m_to_mm(radius_m),
            feed_m_min: feed_m_per_s * 60.0,
            reversal_error_um: m_to_um(result.reversal_error_m),
            reversal_current_a: result.reversal_current_a,
            reversals: result
                .reversals
                .iter()
                .map(|r| ReversalJson {
                    angle_deg: r.angle_rad.to_degrees(),
                    time_s: r.time_s,
                    direction_after: if r.direction_after > 0.0 {
                        "up"
                    } else {
                        "down"
                    },
                    peak_error_um: m_to_um(r.peak_error_m),
                    peak_current_a: r.peak_current_a,
                })
                .collect(),
        }
    }
}

impl ForceStepJson {
    /// From a force-step result.
    pub fn new(force_n: f64, at_s: f64, result: &ForceStepResult) -> ForceStepJson {
        ForceStepJson {
            force_n,
            at_s,
            peak_error_um: m_to_um(result.peak_error_m),
            peak_after_s: result.peak_after_s,
            recovery_s: result.recovery_s,
            peak_current_a: result.peak_current_a,
            final_friction_n: result.final_friction_n,
        }
    }
}

impl ConstantVelocityJson {
    /// From a constant-velocity result.
    pub fn new(feed_m_per_s: f64, result: &ConstantVelocityResult) -> ConstantVelocityJson {
        ConstantVelocityJson {
            feed_m_min: feed_m_per_s * 60.0,
            mean_current_a: result.mean_current_a,
            mean_friction_n: result.mean_friction_n,
            steady_friction_n: result.steady_friction_n,
            mean_following_error_um: m_to_um(result.mean_following_error_m),
        }
    }
}

impl IsoJson {
    /// From a simulated cycle.
    pub fn new(cycle: &IsoCycle, stiffness_n_per_um: Option<f64>, result: &IsoResult) -> IsoJson {
        let residual = result.residual_friction();
        IsoJson {
            targets_mm: cycle.targets_m.iter().map(|m| m_to_mm(*m)).collect(),
            runs: cycle.runs,
            dwell_s: cycle.dwell_s,
            overrun_mm: m_to_mm(cycle.overrun_m),
            feed_m_min: cycle.limits.feed_m_per_s * 60.0,
            stiffness_n_per_um,
            compliance_n_per_um: stiffness_n_per_um,
            figures_um: FiguresJson::of_linear(&result.evaluation.figures_typed()),
            residual_friction_n: ResidualJson {
                up: residual.up_n,
                down: residual.down_n,
            },
            reversal_from_friction_um: stiffness_n_per_um.map(|k| residual.reversal_um(k)),
            readings: result
                .readings
                .iter()
                .map(|r| ReadingJson {
                    run: r.run,
                    direction: r.direction.as_str(),
                    target_mm: m_to_mm(cycle.targets_m[r.target_index]),
                    time_s: r.time_s,
                    deviation_um: m_to_um(r.deviation_m),
                    scale_deviation_um: m_to_um(r.scale_deviation_m),
                    friction_n: r.friction_force_n,
                })
                .collect(),
        }
    }
}

/// The terminal report.
pub fn text(report: &ServoSimJson) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Axis         {} ({})\nFriction     {} (model {})\nTest         {}\nSimulated    {:.3} s ({} stepping; macro steps: {} kept, {} refined, {} skipped)",
        report.axis,
        report.axis_source,
        report.friction,
        report.friction_label,
        report.test,
        report.simulated_s,
        report.stepping,
        report.macro_steps.kept,
        report.macro_steps.refined,
        report.macro_steps.skipped
    );
    if let Some(c) = &report.circle {
        let _ = writeln!(
            out,
            "Circle       R = {} mm, {} m/min, CCW\n\nReversal error   {:.2} µm  (mean peak |x_z − x| at this axis's reversals; Tab. 6.4 xe/ye)\nReversal current {:.2} A",
            c.radius_mm, c.feed_m_min, c.reversal_error_um, c.reversal_current_a
        );
        for r in &c.reversals {
            let _ = writeln!(
                out,
                "  φ = {:>5.0}°  t = {:>7.3} s  → {:<4}  peak error {:>6.2} µm  peak current {:>6.2} A",
                r.angle_deg, r.time_s, r.direction_after, r.peak_error_um, r.peak_current_a
            );
        }
    }
    if let Some(s) = &report.force_step {
        let _ = writeln!(
            out,
            "Force step   {} N at {} s\n\nPeak error       {:.1} µm, {:.1} ms after the step\nRecovery         {:.1} ms (|error| < 5 % of peak)\nPeak current     {:.2} A\nFinal friction   {:.1} N",
            s.force_n,
            s.at_s,
            s.peak_error_um,
            s.peak_after_s * 1e3,
            s.recovery_s * 1e3,
            s.peak_current_a,
            s.final_friction_n
        );
    }
    if let Some(v) = &report.constant_velocity {
        let _ = writeln!(
            out,
            "Feed         {} m/min\n\nMean current     {:.3} A\nMean friction    {:.1} N (model steady value {:.1} N)\nFollowing error  {:.3} µm",
            v.feed_m_min,
            v.mean_current_a,
            v.mean_friction_n,
            v.steady_friction_n,
            v.mean_following_error_um
        );
    }
    if let Some(iso) = &report.iso230_2 {
        iso_text(&mut out, iso);
    }
    out
}

fn iso_text(out: &mut String, iso: &IsoJson) {
    let stiffness = iso
        .stiffness_n_per_um
        .map_or("rigid (laser reads the scale)".to_string(), |k| {
            format!("{k} N/µm")
        });
    let _ = writeln!(
        out,
        "Cycle        {} targets {}–{} mm, {} runs, dwell {} s, overrun {} mm, {} m/min\nStiffness    {stiffness}\n",
        iso.targets_mm.len(),
        iso.targets_mm.first().copied().unwrap_or(0.0),
        iso.targets_mm.last().copied().unwrap_or(0.0),
        iso.runs,
        iso.dwell_s,
        iso.overrun_mm,
        iso.feed_m_min
    );
    let _ = writeln!(
        out,
        " target [mm] | dir | run | deviation [µm] | scale [µm] | friction [N]"
    );
    for r in &iso.readings {
        let _ = writeln!(
            out,
            " {:>11.3} | {:<3} | {:>3} | {:>14.3} | {:>10.3} | {:>12.1}",
            r.target_mm,
            if r.direction == "up" { "↑" } else { "↓" },
            r.run,
            r.deviation_um,
            r.scale_deviation_um,
            r.friction_n
        );
    }
    let f = &iso.figures_um;
    let show = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.3}"));
    let _ = writeln!(
        out,
        "\nISO 230-2 figures [µm]: A {}  E {}  M {}  R {}  B {}  B̄ {}",
        show(f.get("A")),
        show(f.get("E")),
        show(f.get("M")),
        show(f.get("R")),
        show(f.get("B")),
        show(f.get("B_mean"))
    );
    let _ = writeln!(
        out,
        "Friction held at the readings: ↑ {:.1} N, ↓ {:.1} N; 2·F_res/k_c = {} µm",
        iso.residual_friction_n.up,
        iso.residual_friction_n.down,
        show(iso.reversal_from_friction_um)
    );
}

/// The trace at the position samples as CSV.
pub fn trace_csv(trace: &[Snapshot]) -> Vec<u8> {
    let mut out =
        String::from("time_s,command_mm,position_mm,following_error_um,current_a,friction_n\n");
    for s in trace {
        let _ = writeln!(
            out,
            "{:.6},{:.6},{:.6},{:.4},{:.4},{:.3}",
            s.time_s,
            m_to_mm(s.command.position_m),
            m_to_mm(s.position_m),
            m_to_um(s.following_error_m()),
            s.current_a,
            s.friction_force_n
        );
    }
    out.into_bytes()
}

/// The ISO readings as CSV in axcomp's measurement layout, so that
/// `axcomp evaluate` reads the simulated test like a measured one.
pub fn iso_csv(axis: &str, iso: &IsoJson) -> Vec<u8> {
    let mut out = format!(
        "# axis: {axis}\n# machine: simulated feed axis (axcomp servo-sim)\ntarget_mm,run,direction,deviation_um\n"
    );
    for r in &iso.readings {
        let _ = writeln!(
            out,
            "{},{},{},{:.4}",
            r.target_mm, r.run, r.direction, r.deviation_um
        );
    }
    out.into_bytes()
}

/// What `servo-sim --identify` found (wire format in the module doc).
#[derive(Clone, Debug, Serialize)]
pub struct IdentifyJson {
    /// `--axis` as given.
    pub axis_source: String,
    /// F_C, N.
    pub coulomb_n: f64,
    /// μ_v, N·s/m.
    pub viscous_n_s_per_m: f64,
    /// RMS of the record's forces about the line, N.
    pub force_rms_residual_n: f64,
    /// Rows of the constant-velocity record.
    pub rows: usize,
    /// k_s, N/m (with `--reversal`).
    pub lugre_stiffness_n_per_m: Option<f64>,
    /// RMS of the reversal record about the fitted simulation, µm.
    pub following_error_rms_residual_um: Option<f64>,
    /// Samples of the reversal record compared.
    pub samples: Option<usize>,
    /// Circle simulations run.
    pub simulations: Option<usize>,
    /// The circle's feed, m/min.
    pub circle_feed_m_min: Option<f64>,
    /// The circle's radius, mm.
    pub circle_radius_mm: Option<f64>,
    /// The servo-sim flags that start a simulation from these values.
    pub servo_sim: String,
}

impl IdentifyJson {
    /// Builds the wire object; `circle` is the reversal record's circle and feed (m/min).
    pub fn new(
        axis_source: &str,
        found: Identified,
        circle: Option<(&Circle, f64)>,
    ) -> IdentifyJson {
        let stiffness = found.stiffness;
        let mut servo_sim = format!(
            "--coulomb-n {:.1} --viscous-n-s-m {:.1}",
            found.coulomb_n, found.viscous_n_s_per_m
        );
        if let Some(k) = stiffness {
            let _ = write!(
                servo_sim,
                " --lugre-stiffness-n-m {:.3e}",
                k.stiffness_n_per_m
            );
        }
        IdentifyJson {
            axis_source: axis_source.to_string(),
            coulomb_n: found.coulomb_n,
            viscous_n_s_per_m: found.viscous_n_s_per_m,
            force_rms_residual_n: found.force_rms_residual_n,
            rows: found.rows,
            lugre_stiffness_n_per_m: stiffness.map(|k| k.stiffness_n_per_m),
            following_error_rms_residual_um: stiffness.map(|k| m_to_um(k.rms_residual_m)),
            samples: stiffness.map(|k| k.samples),
            simulations: stiffness.map(|k| k.simulations),
            circle_feed_m_min: circle.map(|(_, feed)| feed),
            circle_radius_mm: circle.map(|(c, _)| m_to_mm(c.radius_m)),
            servo_sim,
        }
    }
}

/// The terminal text of `servo-sim --identify`.
pub fn identify_text(json: &IdentifyJson) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Friction of {} identified (Mendřický 2006, ch. 5)",
        json.axis_source
    );
    let _ = writeln!(
        out,
        "  F_C  Coulomb friction     {:.1} N      (constant-velocity record, {} rows; F = F_C + μ_v·|v| rms {:.2} N)",
        json.coulomb_n, json.rows, json.force_rms_residual_n
    );
    let _ = writeln!(
        out,
        "  μ_v  viscous coefficient  {:.1} N·s/m",
        json.viscous_n_s_per_m
    );
    match (
        json.lugre_stiffness_n_per_m,
        json.following_error_rms_residual_um,
    ) {
        (Some(k), Some(rms)) => {
            let _ = writeln!(
                out,
                "  k_s  LuGre stiffness      {k:.3e} N/m  (circle R {} mm at {} m/min, {} samples, rms {:.3} µm after {} simulations)",
                json.circle_radius_mm.unwrap_or(f64::NAN),
                json.circle_feed_m_min.unwrap_or(f64::NAN),
                json.samples.unwrap_or(0),
                rms,
                json.simulations.unwrap_or(0)
            );
        }
        _ => {
            let _ = writeln!(
                out,
                "  k_s  not identified (give the circle's following error with --reversal)"
            );
        }
    }
    let _ = writeln!(
        out,
        "Start a simulation from them: axcomp servo-sim --axis {} {} --friction lugre --test …",
        json.axis_source, json.servo_sim
    );
    out
}
