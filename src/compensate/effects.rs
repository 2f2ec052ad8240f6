//! A table that accounts for the effects a diagnosis found (`convert
//! --effects`): what the geometric curve of a test misses.
//!
//! - **periodic**: the test's targets (and a table at them, linear in
//!   between) cannot follow a short period. The periodic error is taken out of
//!   the readings, the smooth rest is interpolated to the table's points, and
//!   the periodic error is put back *at the points*: with a step of at most
//!   period / 10 ([`finest_step`]) the controller's linear interpolation
//!   leaves less than 5 % of its amplitude (A·(1 − cos(π·h/p)) for a step h).
//! - **scale**: a scale the re-test showed beyond the prediction is the
//!   thermal or alignment state of that test, not the machine's: it is taken
//!   out of the table, which stays referred to the conditions of the first test
//!   (20 °C when the laser's material compensation held then).
//! - **reversal**: the caller chooses a bidirectional table (`convert` does
//!   when the controller takes one); nothing changes here.
//! - drift, outlier run and Abbe are not a table's business: the caller says
//!   what to do instead.
//!
//! The table is zero at its reference point afterwards, as every table.

use super::{CompensateError, CompensationTable, TableOptions, build_table};
use crate::effects::{Effect, TableRole};
use crate::evaluate::{Evaluation, evaluate};
use crate::measurement::Measurement;
use crate::units::{per_m_over_mm, um_to_mm};

/// The finest step the periodic effects ask for: the shortest period / 10,
/// in the axis' unit (mm: the effects come from an effects file, a linear
/// axis' only, `workflow::rotary`).
pub fn finest_step(effects: &[Effect]) -> Option<f64> {
    effects
        .iter()
        .filter_map(|e| match e.in_table() {
            TableRole::AtPoints { finest_step } => Some(finest_step),
            _ => None,
        })
        .min_by(f64::total_cmp)
}

/// The table from `measurement` (whose evaluation is `evaluation`) with the
/// periodic and scale effects accounted for.
pub fn build_table_with_effects(
    measurement: &Measurement,
    evaluation: &Evaluation,
    options: &TableOptions,
    effects: &[Effect],
) -> Result<CompensationTable, CompensateError> {
    let periodic_um = |x: f64| -> f64 {
        effects
            .iter()
            .filter(|e| matches!(e.in_table(), TableRole::AtPoints { .. }))
            .filter_map(|e| e.systematic(x, crate::measurement::Direction::Up, 0.0))
            .sum()
    };
    let scale_um_per_m: f64 = effects
        .iter()
        .map(|e| match e {
            Effect::Scale(scale) => scale.scale_um_per_m,
            _ => 0.0,
        })
        .sum();
    let mut table = if finest_step(effects).is_some() {
        // The readings less the periodic error at their targets.
        let targets = measurement.targets();
        let smooth = measurement.map_readings(|_, i, v| v - um_to_mm(periodic_um(targets[i])))?;
        build_table(&smooth, &evaluate(&smooth), options)?
    } else {
        build_table(measurement, evaluation, options)?
    };
    let reference = table.reference;
    // What the effects add at a point, relative to the reference, mm.
    let added = |p: f64| {
        um_to_mm(
            periodic_um(p) - periodic_um(reference) - per_m_over_mm(scale_um_per_m, p - reference),
        )
    };
    let positions = table.positions.clone();
    table.values = table.values.map(|column| {
        column
            .iter()
            .zip(&positions)
            .map(|(value, &p)| value + added(p))
            .collect()
    });
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::{Extrapolate, GridSpec, TableMode};
    use crate::effects::{Periodic, Scale};
    use crate::measurement::{ByKind, Direction, Run};
    use crate::units::Mm;

    /// Two runs each way of e(x) = 2 µm · sin(2πx/5) + 10 µm/m · x at 0, 1, … 20 mm.
    fn screw() -> Measurement {
        let targets: Vec<f64> = (0..=20).map(f64::from).collect();
        let value = |x: f64| (2.0 * (std::f64::consts::TAU * x / 5.0).sin() + 0.01 * x) / 1000.0;
        let runs = [
            Direction::Up,
            Direction::Down,
            Direction::Up,
            Direction::Down,
        ]
        .iter()
        .enumerate()
        .map(|(i, &direction)| Run {
            direction,
            number: 1 + i as u32 / 2,
            start_time_s: None,
            deviations: targets.iter().map(|&x| Some(value(x))).collect(),
        })
        .collect();
        Measurement::new("X", targets, runs, Default::default(), Default::default()).unwrap()
    }

    #[test]
    fn the_periodic_error_is_put_back_at_the_finer_points_by_hand() {
        let effects = [Effect::Periodic(Periodic {
            period: 5.0,
            amplitude: 2.0,
            phase_rad: 0.0,
        })];
        assert_eq!(finest_step(&effects), Some(0.5));
        let options = TableOptions {
            mode: TableMode::Mean,
            grid: GridSpec::Regular {
                start: ByKind::Linear(Mm(0.0)),
                step: ByKind::Linear(Mm(0.5)),
                count: 41,
            },
            reference: None,
            extrapolate: Extrapolate::Refuse,
        };
        let table =
            build_table_with_effects(&screw(), &evaluate(&screw()), &options, &effects).unwrap();
        // At the point 0.5 mm, between the targets 0 and 1 mm:
        // 2 µm · sin(π/5) + 10 µm/m · 0.5 mm = 1.175571 + 0.005 µm.
        let expected = (2.0 * (std::f64::consts::PI / 5.0).sin() + 0.005) / 1000.0;
        let at = table.value_at(0.5, Direction::Up);
        assert!((at - expected).abs() < 1e-12, "{at} vs {expected}");
        // Without the effect the table interpolates the targets: 0.956 µm there.
        let plain = build_table(&screw(), &evaluate(&screw()), &options).unwrap();
        assert!((plain.value_at(0.5, Direction::Up) - expected).abs() > 1e-4);
    }

    #[test]
    fn a_scale_is_taken_out() {
        let options = TableOptions {
            mode: TableMode::Mean,
            grid: GridSpec::Targets,
            reference: None,
            extrapolate: Extrapolate::Refuse,
        };
        let effects = [Effect::Scale(Scale {
            scale_um_per_m: 10.0,
        })];
        let plain = build_table(&screw(), &evaluate(&screw()), &options).unwrap();
        let table =
            build_table_with_effects(&screw(), &evaluate(&screw()), &options, &effects).unwrap();
        // 10 µm/m over 20 mm: 0.2 µm less at the end, nothing at the reference (0 mm).
        let difference = plain.value_at(20.0, Direction::Up) - table.value_at(20.0, Direction::Up);
        assert!((difference - 0.0002).abs() < 1e-12, "{difference}");
        assert_eq!(table.value_at(0.0, Direction::Down), 0.0);
    }
}
