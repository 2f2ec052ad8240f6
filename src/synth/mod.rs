//! Measurements with a known truth: the deterministic fake that plays the
//! machine in tests, in `axcomp synth` and in the demo.
//!
//! From a [`Truth`] (the axis error the model knows, effects it does not,
//! noise, the ISO 230-2 cycle with its timing, the conditions) this builds the
//! first test and, given the compensation table the controller applies, the
//! re-test. Every reading is
//!
//! ```text
//! deviation = e(m) − v(x, d) + effects(x, d, run, t) + noise,   m = x − v(x, d)
//! ```
//!
//! with x the target, d the direction, t the time of the reading from the
//! cycle model (`crate::cycle`), e the declared axis error (zeroed at the first
//! target, where the laser is zeroed), v the table value the controller applies
//! (zero in the first test) and m the position the controller commands the
//! drive to. Readings are rounded to 0.001 µm (a laser's resolution), so the
//! files written read back to exactly the same measurement.
//!
//! The environment record follows the thermal state: a `scale` effect raises
//! the material temperature by scale/α, a `drift` warms it during the test.
//!
//! Pure: randomness comes from `ChaCha8Rng` seeded by the caller, one stream
//! per test and purpose, so the first test does not change when the re-test's
//! settings do.

pub mod geometry;
pub mod rotary;
pub mod thermal;
pub mod truth;

use chrono::{Duration, NaiveDateTime, Timelike};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Normal, Uniform};

use crate::compensate::{CompensationTable, interpolate_hold};
use crate::cycle::{self, CycleTiming};
use crate::error::ParseError;
use crate::evaluate::environment::{
    ASSUMED_VACUUM_WAVELENGTH_UM, REFERENCE_TEMPERATURE_C, environmental_factor_um,
};
use crate::measurement::{
    Direction, Environment, Measurement, MeasurementError, Metadata, Run, StartEnd, TestDate,
};
use crate::units::{mm_to_m, mm_to_um, per_m_over_mm, um_to_mm};
pub use rotary::{RotaryTruth, rotary_retest, rotary_test};
pub use truth::{EffectSpec, TargetSpec, TestKind, Truth};

/// Why a truth cannot be turned into measurements.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SynthError {
    /// The truth file is not valid TOML of its form, at a position.
    #[error(transparent)]
    Toml(#[from] ParseError),
    /// The truth file's values contradict each other.
    #[error("{0}")]
    Truth(String),
    /// The targets are not usable.
    #[error("{0}")]
    Targets(String),
    /// The noise cannot be drawn (checked when the truth is read).
    #[error("noise: {0}")]
    Noise(#[from] rand_distr::NormalError),
    /// The measurement would be invalid (a bug in the truth).
    #[error("{0}")]
    Measurement(#[from] MeasurementError),
}

/// Random streams, one per purpose (`ChaCha8Rng::set_stream`).
#[derive(Clone, Copy)]
enum Stream {
    BeforeTargets = 0,
    BeforeNoise = 1,
    AfterTargets = 2,
    AfterNoise = 3,
}

fn rng(seed: u64, stream: Stream) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream as u64);
    rng
}

/// The first test (no table).
pub fn before(truth: &Truth, seed: u64) -> Result<Measurement, SynthError> {
    let targets = targets(
        &truth.cycle.targets,
        &TargetSpec::default(),
        &mut rng(seed, Stream::BeforeTargets),
    )?;
    let runs = truth.cycle.targets.runs.unwrap_or(5);
    simulate(
        truth,
        TestKind::Before,
        &targets,
        runs,
        None,
        &mut rng(seed, Stream::BeforeNoise),
        0.0,
    )
}

/// The re-test of the compensated axis: the controller applies `table`.
pub fn after(
    truth: &Truth,
    table: &CompensationTable,
    seed: u64,
) -> Result<Measurement, SynthError> {
    let targets = targets(
        &truth.cycle.after,
        &truth.cycle.targets,
        &mut rng(seed, Stream::AfterTargets),
    )?;
    let runs = truth
        .cycle
        .after
        .runs
        .or(truth.cycle.targets.runs)
        .unwrap_or(5);
    let gap_s = truth.cycle.after_gap_h * 3600.0;
    simulate(
        truth,
        TestKind::After,
        &targets,
        runs,
        Some(table),
        &mut rng(seed, Stream::AfterNoise),
        gap_s,
    )
}

/// The targets of a test: `spec`'s fields, falling back to `base`'s.
fn targets(
    spec: &TargetSpec,
    base: &TargetSpec,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<f64>, SynthError> {
    if let Some(list) = spec.targets_mm.as_ref().or(if spec.count.is_none() {
        base.targets_mm.as_ref()
    } else {
        None
    }) {
        let mut list = list.clone();
        list.sort_by(f64::total_cmp);
        if list.len() < 2 || list.windows(2).any(|p| p[1] <= p[0]) {
            return Err(SynthError::Targets(
                "targets_mm must hold at least two different targets".into(),
            ));
        }
        return Ok(list);
    }
    let start = spec.start_mm.or(base.start_mm).ok_or_else(|| {
        SynthError::Targets("cycle: give targets_mm or start_mm, end_mm, count".into())
    })?;
    let end = spec
        .end_mm
        .or(base.end_mm)
        .ok_or_else(|| SynthError::Targets("cycle: end_mm missing".into()))?;
    let count = spec
        .count
        .or(base.count)
        .ok_or_else(|| SynthError::Targets("cycle: count missing".into()))?;
    let jitter = spec.jitter_mm.or(base.jitter_mm).unwrap_or(0.0);
    if count < 2 || end <= start {
        return Err(SynthError::Targets(
            "cycle: at least 2 targets and end_mm > start_mm".into(),
        ));
    }
    let step = (end - start) / (count - 1) as f64;
    if jitter < 0.0 || jitter >= step / 2.0 {
        return Err(SynthError::Targets(format!(
            "cycle: jitter_mm must be below half the spacing ({} mm)",
            step / 2.0
        )));
    }
    let mut list = Vec::with_capacity(count);
    for k in 0..count {
        let nominal = start + k as f64 * step;
        let moved = if k == 0 || k + 1 == count || jitter == 0.0 {
            nominal
        } else {
            let offset = Uniform::new_inclusive(-jitter, jitter)
                .map_err(|e| SynthError::Targets(e.to_string()))?;
            nominal + offset.sample(rng)
        };
        // Targets as a laser program writes them: 0.001 mm.
        list.push(um_to_mm(mm_to_um(moved).round()));
    }
    Ok(list)
}

/// Everything the truth says about one reading, µm (before rounding and noise).
struct Reading {
    direction: Direction,
    run: u32,
    time_s: f64,
}

fn simulate(
    truth: &Truth,
    test: TestKind,
    targets: &[f64],
    runs_per_direction: usize,
    table: Option<&CompensationTable>,
    rng: &mut ChaCha8Rng,
    start_offset_s: f64,
) -> Result<Measurement, SynthError> {
    let directions: Vec<Direction> = (0..runs_per_direction)
        .flat_map(|_| [Direction::Up, Direction::Down])
        .collect();
    let timing = CycleTiming {
        feed_mm_per_min: truth.cycle.feed_mm_per_min,
        dwell_s: truth.cycle.dwell_s,
        overrun_mm: truth.cycle.overrun_mm,
    };
    let times = cycle::reading_times_for(targets, &directions, timing);
    let noise = Normal::new(0.0, truth.noise.sigma_um)?;
    let stroke = (targets[0], targets[targets.len() - 1]);
    let datum_um = declared_error_um(truth, targets[0]);
    let mut runs = Vec::with_capacity(directions.len());
    let mut numbers = [0u32; 2];
    for (index, direction) in directions.iter().enumerate() {
        let slot = usize::from(*direction == Direction::Down);
        numbers[slot] += 1;
        let mut deviations_mm = Vec::with_capacity(targets.len());
        for (target_index, &x) in targets.iter().enumerate() {
            let reading = Reading {
                direction: *direction,
                run: numbers[slot],
                time_s: times[index][target_index],
            };
            let applied_mm = table.map_or(0.0, |t| t.value_at(x, *direction));
            let commanded_mm = x - applied_mm;
            let error_um = declared_error_um(truth, commanded_mm) - datum_um
                + effects_um(truth, test, &reading, commanded_mm, stroke);
            let deviation_um = error_um - mm_to_um(applied_mm) + noise.sample(rng);
            // A laser's resolution, 0.001 µm; converted as a reader converts it.
            deviations_mm.push(Some(crate::units::um_to_mm(
                (deviation_um * 1000.0).round() / 1000.0,
            )));
        }
        runs.push(Run {
            direction: *direction,
            number: numbers[slot],
            start_time_s: Some(times[index].iter().copied().fold(f64::INFINITY, f64::min)),
            deviations: deviations_mm,
        });
    }
    let duration_s = cycle::duration_s(&times);
    let environment = environment(truth, test, duration_s, stroke);
    let metadata = metadata(truth, test, start_offset_s, duration_s);
    Measurement::new(
        truth.axis.name.clone(),
        targets.to_vec(),
        runs,
        environment,
        metadata,
    )
    .map_err(SynthError::from)
}

/// The axis error the model declares, µm, at a position.
pub fn declared_error_um(truth: &Truth, x_mm: f64) -> f64 {
    let error = &truth.error;
    let mut value = per_m_over_mm(error.scale_um_per_m, x_mm);
    for p in &error.periodic {
        value += p.amplitude_um * (std::f64::consts::TAU * x_mm / p.period_mm + p.phase_rad).sin();
    }
    if let Some(points) = &error.points {
        value += interpolate_hold(&points.positions_mm, &points.values_um, x_mm);
    }
    value
}

/// The undeclared effects acting on one reading, µm. Position-dependent ones
/// act where the axis is (`at_mm`), run- and time-dependent ones on the reading.
fn effects_um(
    truth: &Truth,
    test: TestKind,
    reading: &Reading,
    at_mm: f64,
    stroke: (f64, f64),
) -> f64 {
    let mut value = 0.0;
    for effect in truth.effects.iter().filter(|e| e.acts_in(test)) {
        value += effect.value_um(
            reading.direction,
            reading.run,
            reading.time_s,
            at_mm,
            stroke,
        );
    }
    value
}

/// The angular error profile of the `abbe` effect, µrad: a bow over the stroke.
pub fn abbe_angle_urad(angle_urad: f64, x_mm: f64, stroke: (f64, f64)) -> f64 {
    let (first, last) = stroke;
    angle_urad * (std::f64::consts::PI * (x_mm - first) / (last - first)).sin()
}

/// The conditions of a test, following its thermal state.
fn environment(truth: &Truth, test: TestKind, duration_s: f64, stroke: (f64, f64)) -> Environment {
    let spec = truth.environment;
    let alpha = spec.expansion_coefficient_ppm_per_k;
    let stroke_m = mm_to_m(stroke.1 - stroke.0);
    let mut material_start = spec.material_temperature_c;
    let mut warming = 0.0;
    for effect in truth.effects.iter().filter(|e| e.acts_in(test)) {
        match effect {
            // An expansion of s µm/m is ΔT = s/α kelvin.
            EffectSpec::Scale { scale_um_per_m, .. } if alpha > 0.0 => {
                material_start += scale_um_per_m / alpha
            }
            // A drift of r µm/h at the far end of the stroke: the axis warms by r·h/(α·L).
            EffectSpec::Drift { rate_um_per_h, .. } if alpha > 0.0 && stroke_m > 0.0 => {
                warming += rate_um_per_h * duration_s / 3600.0 / (alpha * stroke_m)
            }
            _ => {}
        }
    }
    let round = |v: f64| (v * 1e6).round() / 1e6;
    let sensor = |start: f64, end: f64| StartEnd::new(Some(round(start)), Some(round(end)));
    let air_end = spec.air_temperature_c + warming / 2.0;
    // The factor the laser would record for these conditions, to its 8 decimals.
    let factor = |air_c: f64, material_c: f64| {
        let value = environmental_factor_um(
            round(air_c),
            spec.pressure_kpa,
            spec.humidity_pct,
            alpha * (round(material_c) - REFERENCE_TEMPERATURE_C),
            ASSUMED_VACUUM_WAVELENGTH_UM,
        );
        Some((value * 1e8).round() / 1e8)
    };
    Environment {
        air_temperature_c: sensor(spec.air_temperature_c, air_end),
        air_pressure_kpa: sensor(spec.pressure_kpa, spec.pressure_kpa),
        air_humidity_pct: sensor(spec.humidity_pct, spec.humidity_pct),
        material_temperature_c: [
            sensor(material_start, material_start + warming),
            StartEnd::default(),
            StartEnd::default(),
        ],
        expansion_coefficient_ppm_per_k: Some(alpha),
        environmental_factor_um: StartEnd::new(
            factor(spec.air_temperature_c, material_start),
            factor(air_end, material_start + warming),
        ),
        vacuum_wavelength_um: None,
    }
}

fn metadata(truth: &Truth, test: TestKind, start_offset_s: f64, duration_s: f64) -> Metadata {
    let start = truth
        .cycle
        .start
        .as_deref()
        .and_then(crate::read::parse_date)
        .unwrap_or_else(|| {
            NaiveDateTime::parse_from_str("2026-01-05 08:00:00", "%Y-%m-%d %H:%M:%S")
                .expect("a valid literal date")
        });
    // Whole minutes: the .rtl Date Time field has a resolution of one minute,
    // and a file must read back to the same measurement.
    let minutes = |seconds: f64| Duration::minutes((seconds / 60.0).round() as i64);
    let begin = start.with_second(0).unwrap_or(start) + minutes(start_offset_s);
    let end = begin + minutes(duration_s);
    let date = |at: NaiveDateTime| TestDate {
        raw: at.format("%Y-%m-%d %H:%M:%S").to_string(),
        parsed: Some(at),
    };
    let description = match test {
        TestKind::Before => "synthetic test (axcomp synth)",
        TestKind::After => "synthetic re-test after compensation (axcomp synth)",
    };
    Metadata {
        machine: truth.axis.machine.clone(),
        serial_number: truth.axis.serial.clone(),
        operator: truth.axis.operator.clone(),
        date: Some(date(begin)),
        end_date: Some(date(end)),
        location: truth.axis.location.clone(),
        description: Some(description.to_string()),
        // The truth file names the axis.
        axis_source: crate::measurement::AxisSource::Given,
        ..Metadata::default()
    }
}

#[cfg(test)]
mod tests;
