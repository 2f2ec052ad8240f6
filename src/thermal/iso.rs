//! The ISO 230-3 view of a thermal test: what a test report states.
//!
//! ISO 230-3:2020 names three tests: the environmental temperature variation
//! error (ETVE, the machine at rest while the room changes), the thermal
//! distortion caused by a rotating spindle, and that caused by moving linear
//! axes. Each reports the drift over the test's duration: its largest value
//! from the start and when it occurred, and the temperatures recorded. The
//! type is what the user says it was: a log does not show it.

use super::ThermalLog;

/// The ISO 230-3 test a log records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestType {
    /// Environmental temperature variation error (machine at rest).
    Etve,
    /// Thermal distortion caused by a rotating spindle.
    Spindle,
    /// Thermal distortion caused by moving linear axes.
    LinearAxis,
}

impl TestType {
    /// Every test type, in the order the flags and the web form list them.
    pub const ALL: [TestType; 3] = [TestType::Etve, TestType::Spindle, TestType::LinearAxis];

    /// The flag value: `etve`, `spindle`, `linear-axis`.
    pub fn name(self) -> &'static str {
        match self {
            TestType::Etve => "etve",
            TestType::Spindle => "spindle",
            TestType::LinearAxis => "linear-axis",
        }
    }

    /// The test type a flag value names.
    pub fn from_name(name: &str) -> Option<TestType> {
        TestType::ALL.into_iter().find(|t| t.name() == name)
    }

    /// How a report names it.
    pub fn title(self) -> &'static str {
        match self {
            TestType::Etve => "environmental temperature variation error (ETVE)",
            TestType::Spindle => "thermal distortion caused by a rotating spindle",
            TestType::LinearAxis => "thermal distortion caused by moving linear axes",
        }
    }
}

/// A sensor's temperatures over the test.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorRise {
    /// The sensor's name.
    pub name: String,
    /// At the first row, °C.
    pub start_c: f64,
    /// At the last row, °C.
    pub end_c: f64,
    /// Largest minus smallest, K.
    pub range_k: f64,
    /// The largest rise over the start (end − start when it never rose), K,
    /// and the time it was reached, s.
    pub max_rise_k: f64,
    /// When the largest rise was reached, s from the start.
    pub max_rise_at_s: f64,
}

/// The ISO 230-3 figures of a log.
#[derive(Clone, Debug, PartialEq)]
pub struct Iso230_3 {
    /// What the user says the test was.
    pub test_type: Option<TestType>,
    /// Last row's time minus the first's, s.
    pub duration_s: f64,
    /// Rows.
    pub rows: usize,
    /// The drift from the first row: largest in size (signed), µm, and when, s.
    pub max_drift: Option<(f64, f64)>,
    /// The drift's largest minus smallest value over the test, µm.
    pub drift_range_um: Option<f64>,
    /// Each temperature, in the log's order.
    pub sensors: Vec<SensorRise>,
}

/// The ISO 230-3 view of `log`.
pub fn evaluate(log: &ThermalLog, test_type: Option<TestType>) -> Iso230_3 {
    let times = &log.times_s;
    let max_drift = log.drift.as_ref().map(|drift| {
        let start = drift.um[0];
        let (at, value) = largest_by(&drift.um, |v| (v - start).abs());
        (value - start, times[at])
    });
    let drift_range_um = log.drift.as_ref().map(|drift| range(&drift.um));
    let sensors = log
        .sensors
        .iter()
        .map(|sensor| {
            let start = sensor.celsius[0];
            let (at, value) = largest_by(&sensor.celsius, |v| v - start);
            SensorRise {
                name: sensor.name.clone(),
                start_c: start,
                end_c: *sensor.celsius.last().unwrap_or(&start),
                range_k: range(&sensor.celsius),
                max_rise_k: value - start,
                max_rise_at_s: times[at],
            }
        })
        .collect();
    Iso230_3 {
        test_type,
        duration_s: times.last().copied().unwrap_or(0.0) - times.first().copied().unwrap_or(0.0),
        rows: log.len(),
        max_drift,
        drift_range_um,
        sensors,
    }
}

/// The index and value of the first element where `key` is largest.
fn largest_by(values: &[f64], key: impl Fn(f64) -> f64) -> (usize, f64) {
    let mut best = (0, values[0]);
    for (index, &value) in values.iter().enumerate() {
        if key(value) > key(best.1) {
            best = (index, value);
        }
    }
    best
}

fn range(values: &[f64]) -> f64 {
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    max - min
}
