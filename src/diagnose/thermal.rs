//! How much of a drift found in a re-test the temperatures recorded during
//! it explain.
//!
//! A drift is found as a rate (µm/h) fitted with one free level per target
//! and direction, so what it measures is how the readings at one place grow
//! with time. A thermal model (`thermal::fit`) run over the temperatures
//! logged during the re-test predicts a drift at each reading's time; that
//! prediction's rate, taken the same way (the least-squares slope within
//! each target and direction), is the part of the found drift the
//! temperatures explain. The log's first row is taken as the re-test's start
//! (the reading times count from there): a log started earlier must be cut
//! to the test first.
//!
//! Laser files record temperatures at the test's start and end only (the
//! `.rtl` environment: air and up to three material sensors): two values per
//! sensor cannot tell a drift's shape or apportion it, so without a log the
//! share is not computed ([`recorded_changes`] lists what the file has).

use crate::effects::{Drift, Reading};
use crate::measurement::Environment;
use crate::thermal::{Application, ThermalLog};

/// The found drift and the part a thermal model explains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalShare {
    /// The drift the diagnosis found, µm/h.
    pub found_um_per_h: f64,
    /// The model's drift at the readings' times, taken as the diagnosis
    /// takes a drift, µm/h.
    pub explained_um_per_h: f64,
    /// `explained / found` (1: the temperatures explain all of it).
    pub share: f64,
    /// The re-test's duration, first to last reading, h.
    pub span_h: f64,
}

/// Why the share cannot be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShareError {
    /// The drift is per run: the readings have no times to match the log's.
    #[error(
        "the drift is per run (the re-test records no times): the thermal log cannot be matched to the readings"
    )]
    NoTimes,
    /// The log ends before the re-test.
    #[error(
        "the thermal log covers {log_min:.1} min, the re-test's readings {test_min:.1} min: the log must cover the whole re-test from its first row"
    )]
    TooShort {
        /// The log's duration, min.
        log_min: f64,
        /// The re-test's, min.
        test_min: f64,
    },
    /// The model has nothing to say about the readings' times.
    #[error("the re-test's readings are all at one time")]
    OneTime,
}

/// The share of `found` that `applied` (a model run over `log`, the
/// temperatures recorded during the re-test) explains at the `readings`.
pub fn thermal_share(
    found: &Drift,
    readings: &[Reading],
    log: &ThermalLog,
    applied: &Application,
) -> Result<ThermalShare, ShareError> {
    let Drift::PerHour { rate_um_per_h } = *found else {
        return Err(ShareError::NoTimes);
    };
    let last_h = readings.iter().map(|r| r.time_h).fold(0.0, f64::max);
    let first_h = readings.iter().map(|r| r.time_h).fold(last_h, f64::min);
    let log_end_s = log.times_s.last().copied().unwrap_or(0.0);
    if last_h * 3600.0 > log_end_s {
        return Err(ShareError::TooShort {
            log_min: log_end_s / 60.0,
            test_min: last_h * 60.0,
        });
    }
    let predicted: Vec<f64> = readings
        .iter()
        .map(|r| at_time(&log.times_s, &applied.predicted_um, r.time_h * 3600.0))
        .collect();
    let explained = within_cell_slope(readings, &predicted).ok_or(ShareError::OneTime)?;
    Ok(ThermalShare {
        found_um_per_h: rate_um_per_h,
        explained_um_per_h: explained,
        share: explained / rate_um_per_h,
        span_h: last_h - first_h,
    })
}

/// `values` (one per time of `times_s`) at `t_s`, linear between rows.
fn at_time(times_s: &[f64], values: &[f64], t_s: f64) -> f64 {
    let after = times_s.partition_point(|&t| t < t_s);
    if after == 0 {
        return values[0];
    }
    if after >= times_s.len() {
        return values[values.len() - 1];
    }
    let (t0, t1) = (times_s[after - 1], times_s[after]);
    let w = (t_s - t0) / (t1 - t0);
    values[after - 1] + w * (values[after] - values[after - 1])
}

/// The least-squares slope of `values` against the readings' times with one
/// free level per target and direction, µm/h (`None`: no time spread).
fn within_cell_slope(readings: &[Reading], values: &[f64]) -> Option<f64> {
    let mut cells: Vec<((usize, bool), f64, f64, usize)> = Vec::new();
    for (r, v) in readings.iter().zip(values) {
        let key = (
            r.target_index,
            r.direction == crate::measurement::Direction::Up,
        );
        match cells.iter_mut().find(|c| c.0 == key) {
            Some(cell) => {
                cell.1 += r.time_h;
                cell.2 += v;
                cell.3 += 1;
            }
            None => cells.push((key, r.time_h, *v, 1)),
        }
    }
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (r, v) in readings.iter().zip(values) {
        let key = (
            r.target_index,
            r.direction == crate::measurement::Direction::Up,
        );
        let cell = cells.iter().find(|c| c.0 == key)?;
        let n = cell.3 as f64;
        let (dt, dv) = (r.time_h - cell.1 / n, v - cell.2 / n);
        sxy += dt * dv;
        sxx += dt * dt;
    }
    (sxx > 0.0).then(|| sxy / sxx)
}

/// A temperature the test file records at its start and end: its name and
/// both values, °C.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordedChange {
    /// `air`, `material 1`, …
    pub name: String,
    /// At the start, °C.
    pub start_c: f64,
    /// At the end, °C.
    pub end_c: f64,
}

/// The temperatures `environment` records at both start and end.
pub fn recorded_changes(environment: &Environment) -> Vec<RecordedChange> {
    let named = std::iter::once(("air".to_string(), &environment.air_temperature_c)).chain(
        environment
            .material_temperature_c
            .iter()
            .enumerate()
            .map(|(k, t)| (format!("material {}", k + 1), t)),
    );
    named
        .filter_map(|(name, t)| {
            Some(RecordedChange {
                name,
                start_c: t.start?,
                end_c: t.end?,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::Direction;
    use crate::thermal::{Drift as LogDrift, Sensor};

    fn reading(target_index: usize, direction: Direction, time_h: f64) -> Reading {
        Reading {
            target_index,
            target: 100.0 * target_index as f64,
            direction,
            run: 1,
            run_index: 0,
            time_h,
        }
    }

    /// A model predicting 3 µm/h (a straight line over the log) explains
    /// 3/4 of a found 4 µm/h, whatever the levels of the cells; reading times
    /// between log rows are interpolated.
    #[test]
    fn a_linear_prediction_explains_its_rate() {
        let times_s: Vec<f64> = (0..=10).map(|k| 600.0 * k as f64).collect();
        let log = ThermalLog {
            times_s: times_s.clone(),
            drift: None,
            sensors: vec![Sensor {
                name: "T".into(),
                celsius: vec![20.0; 11],
            }],
            lines: (2..13).collect(),
        };
        let applied = Application {
            predicted_um: times_s.iter().map(|t| 3.0 * t / 3600.0).collect(),
            measured_um: None,
        };
        let readings = [
            reading(0, Direction::Up, 0.05),
            reading(1, Direction::Up, 0.2),
            reading(1, Direction::Down, 0.3),
            reading(0, Direction::Up, 0.9),
            reading(1, Direction::Up, 1.1),
            reading(1, Direction::Down, 1.4),
        ];
        let share = thermal_share(
            &Drift::PerHour { rate_um_per_h: 4.0 },
            &readings,
            &log,
            &applied,
        )
        .unwrap();
        assert!((share.explained_um_per_h - 3.0).abs() < 1e-12);
        assert!((share.share - 0.75).abs() < 1e-12);
        assert!((share.span_h - 1.35).abs() < 1e-12);
        // A log that ends before the last reading is refused.
        let short = ThermalLog {
            times_s: times_s[..5].to_vec(),
            drift: Some(LogDrift {
                name: "d".into(),
                um: vec![0.0; 5],
            }),
            ..log.clone()
        };
        assert_eq!(
            thermal_share(
                &Drift::PerHour { rate_um_per_h: 4.0 },
                &readings,
                &short,
                &applied
            ),
            Err(ShareError::TooShort {
                log_min: 40.0,
                test_min: 1.4 * 60.0
            })
        );
        assert_eq!(
            thermal_share(
                &Drift::PerRun {
                    rate_um_per_run: 1.0
                },
                &readings,
                &log,
                &applied
            ),
            Err(ShareError::NoTimes)
        );
    }
}
