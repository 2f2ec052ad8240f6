//! The ISO 230-2 linear test cycle: when each reading is taken.
//!
//! `../shared/spec/iso230-2.md` ("Test cycle"): all targets ↑, overrun past the
//! last target, all targets ↓, overrun past the first; repeated n times. Each
//! move runs at the feed, each reading is taken at the end of a dwell.
//! Drift (a machine warming up) acts through time, so both `synth` (to
//! generate it) and `diagnose` (to recognise it) need the time of every
//! reading; a file rarely records it, so both use this one model. When a file
//! records the start and end of the test, `diagnose` scales the model's times
//! to that duration.
//!
//! Pure: no clock.

use crate::measurement::{Direction, Measurement};

/// How the machine was programmed for the test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CycleTiming {
    /// Feed between targets, mm/min.
    pub feed_mm_per_min: f64,
    /// Dwell at each target before the reading, s.
    pub dwell_s: f64,
    /// Overrun past the end targets at each reversal, mm.
    pub overrun_mm: f64,
}

impl CycleTiming {
    /// The timing axcomp assumes when a file does not say: 2000 mm/min, 3 s
    /// dwell, 5 mm overrun (typical of laser tests; only the ratios matter once
    /// a recorded duration is known).
    pub const ASSUMED: CycleTiming = CycleTiming {
        feed_mm_per_min: 2000.0,
        dwell_s: 3.0,
        overrun_mm: 5.0,
    };
}

/// Time of every reading, in seconds from the start of the test, as
/// `[run][target]` (run order and target order of the measurement). The axis
/// starts at the first target minus the overrun.
pub fn reading_times(measurement: &Measurement, timing: CycleTiming) -> Vec<Vec<f64>> {
    let targets = measurement.targets();
    let directions: Vec<Direction> = measurement.runs().iter().map(|run| run.direction).collect();
    reading_times_for(targets, &directions, timing)
}

/// [`reading_times`] for targets and the directions of the runs in order.
pub fn reading_times_for(
    targets_mm: &[f64],
    run_directions: &[Direction],
    timing: CycleTiming,
) -> Vec<Vec<f64>> {
    let speed_mm_per_s = timing.feed_mm_per_min / 60.0;
    let first = targets_mm[0];
    let last = targets_mm[targets_mm.len() - 1];
    let mut position = first - timing.overrun_mm;
    let mut time = 0.0;
    let mut times = Vec::with_capacity(run_directions.len());
    for direction in run_directions {
        let mut run_times = vec![0.0; targets_mm.len()];
        let order: Vec<usize> = match direction {
            Direction::Up => (0..targets_mm.len()).collect(),
            Direction::Down => (0..targets_mm.len()).rev().collect(),
        };
        // Approach from beyond the end, as the cycle's overrun does.
        let start = match direction {
            Direction::Up => first - timing.overrun_mm,
            Direction::Down => last + timing.overrun_mm,
        };
        time += (start - position).abs() / speed_mm_per_s;
        position = start;
        for index in order {
            time += (targets_mm[index] - position).abs() / speed_mm_per_s + timing.dwell_s;
            position = targets_mm[index];
            run_times[index] = time;
        }
        times.push(run_times);
    }
    times
}

/// Reading times in hours, as `[run][target]`, and whether they are assumed:
/// the cycle model ([`reading_times`]) scaled to the duration the file
/// records when it differs from the model's by more than its one-minute
/// resolution. The one clock of `diagnose` and of effects added to a
/// measured test (`Effect::added_to`), so a drift put in is the drift found.
pub fn reading_times_h(measurement: &Measurement, timing: CycleTiming) -> (Vec<Vec<f64>>, bool) {
    let seconds = reading_times(measurement, timing);
    let model = duration_s(&seconds);
    let (scale, assumed) = match measurement.metadata.duration_s() {
        Some(recorded) if (recorded - model).abs() > 60.0 && model > 0.0 => {
            (recorded / model, false)
        }
        Some(_) => (1.0, false),
        None => (1.0, true),
    };
    let hours = seconds
        .iter()
        .map(|run| run.iter().map(|t| t * scale / 3600.0).collect())
        .collect();
    (hours, assumed)
}

/// One run's mean duration on the clock of `times` (`[run][target]`, any
/// unit): the time of the last reading over the number of runs. A drift of a
/// test whose times are not recorded is per run, on this clock.
pub fn run_h(times: &[Vec<f64>]) -> f64 {
    if times.is_empty() {
        0.0
    } else {
        duration_s(times) / times.len() as f64
    }
}

/// The time of the last reading, s.
pub fn duration_s(times: &[Vec<f64>]) -> f64 {
    times.iter().flatten().fold(0.0, |max: f64, t| max.max(*t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_cycle_by_hand() {
        // Targets 0, 100 mm; 6000 mm/min = 100 mm/s; dwell 2 s; overrun 10 mm.
        // Start at −10. ↑: to 0 (0.1 s) + 2 → 2.1; to 100 (1 s) + 2 → 5.1.
        // Overrun to 110 (0.1 s) → 5.2. ↓: to 100 (0.1 s) + 2 → 7.3; to 0 (1 s) + 2 → 10.3.
        let timing = CycleTiming {
            feed_mm_per_min: 6000.0,
            dwell_s: 2.0,
            overrun_mm: 10.0,
        };
        let times = reading_times_for(&[0.0, 100.0], &[Direction::Up, Direction::Down], timing);
        let close = |a: f64, b: f64| approx::abs_diff_eq!(a, b, epsilon = 1e-12);
        assert!(
            close(times[0][0], 2.1) && close(times[0][1], 5.1),
            "{times:?}"
        );
        assert!(
            close(times[1][1], 7.3) && close(times[1][0], 10.3),
            "{times:?}"
        );
        assert!(close(duration_s(&times), 10.3));
        // The next ↑ run starts from −10 again: 0 is reached at 10.3 + 0.1 + 0.1 + 2.
        let two = reading_times_for(
            &[0.0, 100.0],
            &[Direction::Up, Direction::Down, Direction::Up],
            timing,
        );
        assert!(close(two[2][0], 12.5), "{two:?}");
        // One run's mean duration: 10.3 s over 2 runs.
        assert!(close(run_h(&times), 5.15));
    }
}
