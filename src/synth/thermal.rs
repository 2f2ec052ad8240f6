//! Thermal logs from a known truth: sensors driven by a spindle's duty cycle,
//! a coolant's own cycle and the room, and a drift that is a sum of lagged
//! sensors (the form `thermal::fit` looks for), with noise.
//!
//! Pure: the duty cycles' switching times and the noise come from
//! `ChaCha8Rng` streams of the caller's seed.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Normal, Uniform};

use crate::thermal::{Drift, Sensor, ThermalLog, lag};

/// How a sensor's temperature is made: the room, plus `gain_k` times a
/// source (the spindle's or the coolant's duty cycle, 0 or 1) through a lag.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorTruth {
    /// Column name.
    pub name: String,
    /// The source: spindle duty, coolant duty, or none (the room alone).
    pub source: Source,
    /// K at full duty, steady state.
    pub gain_k: f64,
    /// The sensor's lag behind its source, s.
    pub tau_s: f64,
}

/// What heats a sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The spindle's on/off cycle.
    Spindle,
    /// The coolant chiller's on/off cycle.
    Coolant,
    /// Nothing: the room, through the lag.
    Room,
}

/// A drift term: µm per K of a sensor's lagged rise from its first value.
#[derive(Clone, Debug, PartialEq)]
pub struct DriftTerm {
    /// The sensor's name.
    pub sensor: String,
    /// The lag, s.
    pub tau_s: f64,
    /// µm/K.
    pub coefficient_um_per_k: f64,
}

/// The truth of a thermal log.
#[derive(Clone, Debug, PartialEq)]
pub struct ThermalTruth {
    /// Rows.
    pub rows: usize,
    /// Seconds between rows.
    pub interval_s: f64,
    /// The room's mean, °C, and its daily swing (amplitude), K.
    pub room_c: f64,
    /// Amplitude of the room's daily cycle, K.
    pub room_swing_k: f64,
    /// On and off periods of the duty cycles are drawn between these, s.
    pub duty_period_s: (f64, f64),
    /// The sensors.
    pub sensors: Vec<SensorTruth>,
    /// The drift's terms.
    pub drift: Vec<DriftTerm>,
    /// Standard deviation of the drift's noise, µm.
    pub drift_noise_um: f64,
    /// Standard deviation of each temperature's noise, K.
    pub sensor_noise_k: f64,
}

impl Default for ThermalTruth {
    /// Three days at one row a minute; five sensors (bearing, housing,
    /// coolant, base, air); the drift from the bearing lagged 40 min and the
    /// air lagged 320 min (the structure between tool and table).
    fn default() -> ThermalTruth {
        let sensor = |name: &str, source, gain_k, tau_min: f64| SensorTruth {
            name: name.to_string(),
            source,
            gain_k,
            tau_s: tau_min * 60.0,
        };
        ThermalTruth {
            rows: 4320,
            interval_s: 60.0,
            room_c: 20.0,
            room_swing_k: 1.5,
            duty_period_s: (3600.0, 6.0 * 3600.0),
            sensors: vec![
                sensor("bearing", Source::Spindle, 12.0, 15.0),
                sensor("housing", Source::Spindle, 6.0, 120.0),
                sensor("coolant", Source::Coolant, 3.0, 5.0),
                sensor("base", Source::Room, 0.0, 240.0),
                sensor("air", Source::Room, 0.0, 0.0),
            ],
            drift: vec![
                DriftTerm {
                    sensor: "bearing".to_string(),
                    tau_s: 40.0 * 60.0,
                    coefficient_um_per_k: 1.2,
                },
                DriftTerm {
                    sensor: "air".to_string(),
                    tau_s: 320.0 * 60.0,
                    coefficient_um_per_k: -3.0,
                },
            ],
            drift_noise_um: 0.3,
            sensor_noise_k: 0.02,
        }
    }
}

/// A 0/1 duty cycle: on and off in turn, each for a time drawn uniformly.
fn duty(times: &[f64], period_s: (f64, f64), rng: &mut ChaCha8Rng) -> Vec<f64> {
    let draw = Uniform::new(period_s.0, period_s.1).expect("a valid period range");
    let mut on = true;
    let mut until = draw.sample(rng);
    times
        .iter()
        .map(|&t| {
            while t >= until {
                on = !on;
                until += draw.sample(rng);
            }
            if on { 1.0 } else { 0.0 }
        })
        .collect()
}

/// The log of `truth` (drift column `drift`, the sensors in order) for `seed`.
pub fn thermal_log(truth: &ThermalTruth, seed: u64) -> ThermalLog {
    let stream = |n: u64| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(n);
        rng
    };
    let times: Vec<f64> = (0..truth.rows)
        .map(|k| k as f64 * truth.interval_s)
        .collect();
    let spindle = duty(&times, truth.duty_period_s, &mut stream(1));
    let coolant = duty(&times, truth.duty_period_s, &mut stream(2));
    let day = 86_400.0;
    let room: Vec<f64> = times
        .iter()
        .map(|t| truth.room_c + truth.room_swing_k * (std::f64::consts::TAU * t / day).sin())
        .collect();
    let mut lagged = Vec::new();
    let clean: Vec<Vec<f64>> = truth
        .sensors
        .iter()
        .map(|s| match s.source {
            Source::Room => {
                lag(&room, &times, s.tau_s, &mut lagged);
                lagged.clone()
            }
            Source::Spindle | Source::Coolant => {
                let input = if s.source == Source::Spindle {
                    &spindle
                } else {
                    &coolant
                };
                lag(input, &times, s.tau_s, &mut lagged);
                room.iter()
                    .zip(&lagged)
                    .map(|(r, l)| r + s.gain_k * l)
                    .collect()
            }
        })
        .collect();
    let mut drift = vec![0.0; truth.rows];
    for term in &truth.drift {
        let index = truth
            .sensors
            .iter()
            .position(|s| s.name == term.sensor)
            .expect("a drift term names a sensor of the truth");
        let values = &clean[index];
        lag(values, &times, term.tau_s, &mut lagged);
        for (d, l) in drift.iter_mut().zip(&lagged) {
            *d += term.coefficient_um_per_k * (l - values[0]);
        }
    }
    let mut noise_rng = stream(3);
    let drift_noise = Normal::new(0.0, truth.drift_noise_um).expect("a finite noise");
    let sensor_noise = Normal::new(0.0, truth.sensor_noise_k).expect("a finite noise");
    for d in drift.iter_mut().skip(1) {
        *d += drift_noise.sample(&mut noise_rng);
    }
    let sensors = truth
        .sensors
        .iter()
        .zip(clean)
        .map(|(s, values)| Sensor {
            name: s.name.clone(),
            celsius: values
                .iter()
                .map(|v| v + sensor_noise.sample(&mut noise_rng))
                .collect(),
        })
        .collect();
    ThermalLog {
        lines: (2..truth.rows + 2).collect(),
        times_s: times,
        drift: Some(Drift {
            name: "drift".to_string(),
            um: drift,
        }),
        sensors,
    }
}
