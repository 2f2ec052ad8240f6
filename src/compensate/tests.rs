//! Table-building tests, with values computed by hand.

use proptest::prelude::*;

use super::*;
use crate::evaluate::evaluate;
use crate::measurement::{ByKind, Environment, Metadata, Run};
use crate::units::{Deg, Mm};

/// Targets 0, 40, 100 mm; one run each way. Deviations in µm.
fn measurement(up_um: [f64; 3], down_um: Option<[f64; 3]>) -> Measurement {
    let run = |direction, values: [f64; 3]| Run {
        direction,
        number: 1,
        start_time_s: None,
        deviations: values.iter().map(|v| Some(v / 1000.0)).collect(),
    };
    let mut runs = vec![run(Direction::Up, up_um)];
    if let Some(down) = down_um {
        runs.push(run(Direction::Down, down));
    }
    Measurement::new(
        "X",
        vec![0.0, 40.0, 100.0],
        runs,
        Environment::default(),
        Metadata::default(),
    )
    .unwrap()
}

fn build(
    m: &Measurement,
    mode: TableMode,
    grid: GridSpec,
    reference_mm: Option<f64>,
    extrapolate: Extrapolate,
) -> Result<CompensationTable, CompensateError> {
    let options = TableOptions {
        mode,
        grid,
        reference: reference_mm.map(|r| AxisKind::Linear.position(r)),
        extrapolate,
    };
    build_table(m, &evaluate(m), &options)
}

const GRID_0_TO_100: GridSpec = GridSpec::Regular {
    start: ByKind::Linear(Mm(0.0)),
    step: ByKind::Linear(Mm(25.0)),
    count: 5,
};

fn assert_um(values: &[f64], expected_um: &[f64]) {
    assert_eq!(values.len(), expected_um.len());
    for (v, e) in values.iter().zip(expected_um) {
        assert!(
            (v * 1000.0 - e).abs() < 1e-9,
            "{} µm, expected {e} µm (all: {values:?})",
            v * 1000.0
        );
    }
}

#[test]
fn mean_curve_interpolated_onto_a_grid_by_hand() {
    // x̄ = (↑ + ↓)/2 = 0, 6, 3 µm at 0, 40, 100 mm.
    // At 25: 6·25/40 = 3.75; at 50: 6 − 3·10/60 = 5.5; at 75: 6 − 3·35/60 = 4.25.
    let m = measurement([1.0, 8.0, 4.0], Some([-1.0, 4.0, 2.0]));
    let table = build(
        &m,
        TableMode::Mean,
        GRID_0_TO_100,
        None,
        Extrapolate::Refuse,
    )
    .unwrap();
    assert_eq!(table.positions, vec![0.0, 25.0, 50.0, 75.0, 100.0]);
    let TableValues::Mean(values) = &table.values else {
        panic!("mean mode gives one column")
    };
    assert_um(values, &[0.0, 3.75, 5.5, 4.25, 3.0]);
    assert_eq!(table.reference, 0.0);
    // B_i = 2, 4, 2 µm: B̄ = 8/3 µm, suggested backlash −B̄.
    assert!((table.suggested_backlash.unwrap() * 1000.0 + 8.0 / 3.0).abs() < 1e-9);
}

#[test]
fn reference_shift_makes_the_reference_zero() {
    let m = measurement([1.0, 8.0, 4.0], Some([-1.0, 4.0, 2.0]));
    let table = build(
        &m,
        TableMode::Mean,
        GRID_0_TO_100,
        Some(50.0),
        Extrapolate::Refuse,
    )
    .unwrap();
    assert_um(
        table.values.for_direction(Direction::Up),
        &[-5.5, -1.75, 0.0, -1.25, -2.5],
    );
    // Between points, as controllers interpolate: at 60 mm, halfway 0 → −1.25 after 50.
    assert!((table.value_at(60.0, Direction::Up) * 1000.0 + 0.5).abs() < 1e-9);
    let outside = build(
        &m,
        TableMode::Mean,
        GRID_0_TO_100,
        Some(120.0),
        Extrapolate::Refuse,
    );
    assert!(matches!(
        outside,
        Err(CompensateError::ReferenceOutside { .. })
    ));
}

#[test]
fn points_outside_the_measured_range() {
    let m = measurement([1.0, 8.0, 4.0], Some([-1.0, 4.0, 2.0]));
    let beyond = GridSpec::Regular {
        start: ByKind::Linear(Mm(0.0)),
        step: ByKind::Linear(Mm(25.0)),
        count: 6,
    };
    let refused = build(&m, TableMode::Mean, beyond, None, Extrapolate::Refuse).unwrap_err();
    assert!(
        refused
            .to_string()
            .contains("125 mm is outside the measured range 0 … 100 mm"),
        "{refused}"
    );
    let hold = build(&m, TableMode::Mean, beyond, None, Extrapolate::Hold).unwrap();
    assert_um(
        hold.values.for_direction(Direction::Up),
        &[0.0, 3.75, 5.5, 4.25, 3.0, 3.0],
    );
    let zero = build(&m, TableMode::Mean, beyond, Some(25.0), Extrapolate::Zero).unwrap();
    // Shifted by 3.75 inside the range; the point beyond stays 0.
    assert_um(
        zero.values.for_direction(Direction::Up),
        &[-3.75, 0.0, 1.75, 0.5, -0.75, 0.0],
    );
}

#[test]
fn a_rotary_table_says_its_positions_in_degrees() {
    // The targets 0, 40, 100 read as degrees: the point 125° of the grid
    // 0 … 125° lies past the last target, 100°; a reference at 120° past
    // the table 0 … 100°.
    let m = measurement([1.0, 8.0, 4.0], Some([-1.0, 4.0, 2.0])).with_kind(AxisKind::Rotary);
    let beyond = GridSpec::Regular {
        start: ByKind::Rotary(Deg(0.0)),
        step: ByKind::Rotary(Deg(25.0)),
        count: 6,
    };
    let refused = build_rotary(&m, beyond, None).unwrap_err();
    assert_eq!(
        refused.to_string(),
        "compensation point 125° is outside the measured range 0 … 100°; \
         use --extrapolate hold or --extrapolate zero, or a grid inside the range"
    );
    let outside = build_rotary(&m, GridSpec::Targets, Some(120.0)).unwrap_err();
    assert_eq!(
        outside.to_string(),
        "reference position 120° is outside the table 0 … 100°"
    );
    let step = GridSpec::Regular {
        start: ByKind::Rotary(Deg(0.0)),
        step: ByKind::Rotary(Deg(-5.0)),
        count: 3,
    };
    assert_eq!(
        build_rotary(&m, step, None).unwrap_err().to_string(),
        "invalid grid: step must be positive, found -5°"
    );
}

fn build_rotary(
    m: &Measurement,
    grid: GridSpec,
    reference_deg: Option<f64>,
) -> Result<CompensationTable, CompensateError> {
    let options = TableOptions {
        mode: TableMode::Mean,
        grid,
        reference: reference_deg.map(|r| ByKind::Rotary(Deg(r))),
        extrapolate: Extrapolate::Refuse,
    };
    build_table(m, &evaluate(m), &options)
}

#[test]
fn options_of_an_axis_of_the_other_kind_are_refused() {
    let linear = measurement([1.0, 8.0, 4.0], Some([-1.0, 4.0, 2.0]));
    let rotary = linear.clone().with_kind(AxisKind::Rotary);
    // A reference in degrees for a linear axis, inside 0 … 100 as a number.
    assert_eq!(
        build_rotary(&linear, GridSpec::Targets, Some(40.0)),
        Err(CompensateError::KindMismatch {
            what: "reference",
            given: AxisKind::Rotary,
            measured: AxisKind::Linear
        })
    );
    // A grid in mm for a rotary axis.
    let refused = build(
        &rotary,
        TableMode::Mean,
        GRID_0_TO_100,
        None,
        Extrapolate::Refuse,
    )
    .unwrap_err();
    assert_eq!(
        refused.to_string(),
        "the grid's start is in mm (a linear axis' unit), but the test measured a rotary axis, in °: they do not belong together"
    );
    // A step of the other kind behind a start of the right one.
    let mixed = GridSpec::Regular {
        start: ByKind::Rotary(Deg(0.0)),
        step: ByKind::Linear(Mm(25.0)),
        count: 5,
    };
    assert!(matches!(
        build_rotary(&rotary, mixed, None),
        Err(CompensateError::KindMismatch {
            what: "grid's step",
            ..
        })
    ));
    // Of the right kind, the same numbers build.
    assert!(build_rotary(&rotary, GridSpec::Targets, Some(40.0)).is_ok());
}

#[test]
fn bidirectional_keeps_the_reversal_and_centres_the_reference() {
    // ↑ 1, 8, 4 and ↓ −1, 4, 2 µm at the targets; reference 0 mm where
    // ↑ = 1 and ↓ = −1: both shift by their mean, 0.
    let m = measurement([1.0, 8.0, 4.0], Some([-1.0, 4.0, 2.0]));
    let table = build(
        &m,
        TableMode::Bidirectional,
        GridSpec::Targets,
        None,
        Extrapolate::Refuse,
    )
    .unwrap();
    assert_um(table.values.for_direction(Direction::Up), &[1.0, 8.0, 4.0]);
    assert_um(
        table.values.for_direction(Direction::Down),
        &[-1.0, 4.0, 2.0],
    );
    assert_eq!(table.suggested_backlash, None);
    let at_40 = build(
        &m,
        TableMode::Bidirectional,
        GridSpec::Targets,
        Some(40.0),
        Extrapolate::Refuse,
    )
    .unwrap();
    assert_um(
        at_40.values.for_direction(Direction::Up),
        &[-5.0, 2.0, -2.0],
    );
    assert_um(
        at_40.values.for_direction(Direction::Down),
        &[-7.0, -2.0, -4.0],
    );
}

#[test]
fn unidirectional_tests() {
    let m = measurement([1.0, 8.0, 4.0], None);
    let mean = build(
        &m,
        TableMode::Mean,
        GridSpec::Targets,
        None,
        Extrapolate::Refuse,
    )
    .unwrap();
    assert_um(mean.values.for_direction(Direction::Up), &[0.0, 7.0, 3.0]);
    assert_eq!(
        mean.suggested_backlash, None,
        "no reversal measured, no backlash suggested"
    );
    let both = build(
        &m,
        TableMode::Bidirectional,
        GridSpec::Targets,
        None,
        Extrapolate::Refuse,
    );
    assert_eq!(both, Err(CompensateError::OneDirectionOnly(Direction::Up)));
}

#[test]
fn invalid_grids() {
    let m = measurement([1.0, 8.0, 4.0], None);
    for grid in [
        GridSpec::Regular {
            start: ByKind::Linear(Mm(0.0)),
            step: ByKind::Linear(Mm(0.0)),
            count: 5,
        },
        GridSpec::Regular {
            start: ByKind::Linear(Mm(0.0)),
            step: ByKind::Linear(Mm(10.0)),
            count: 1,
        },
        GridSpec::Regular {
            start: ByKind::Linear(Mm(f64::NAN)),
            step: ByKind::Linear(Mm(10.0)),
            count: 3,
        },
    ] {
        assert!(matches!(
            build(&m, TableMode::Mean, grid, None, Extrapolate::Refuse),
            Err(CompensateError::Grid(_))
        ));
    }
}

#[test]
fn existing_table_is_added_back_per_direction() {
    // Residual 0, 1, −1 µm measured with an active table ↑ 0, 10, 20 µm / ↓ 0, 12, 22 µm
    // at 0, 50, 100 mm: at 40 mm ↑ the table holds 8 µm, ↓ 9.6 µm.
    let m = measurement([0.0, 1.0, -1.0], Some([0.0, 1.0, -1.0]));
    let active = CompensationTable {
        axis: "X".into(),
        kind: crate::measurement::AxisKind::Linear,
        positions: vec![0.0, 50.0, 100.0],
        values: TableValues::Bidirectional {
            up: vec![0.0, 0.010, 0.020],
            down: vec![0.0, 0.012, 0.022],
        },
        reference: 0.0,
        suggested_backlash: None,
    };
    let raw = add_existing_table(&m, &active).unwrap();
    assert_um(
        &raw.runs()[0]
            .deviations
            .iter()
            .map(|v| v.unwrap())
            .collect::<Vec<_>>(),
        &[0.0, 9.0, 19.0],
    );
    assert_um(
        &raw.runs()[1]
            .deviations
            .iter()
            .map(|v| v.unwrap())
            .collect::<Vec<_>>(),
        &[0.0, 10.6, 21.0],
    );
}

#[test]
fn regular_steps() {
    assert_eq!(regular_step(&[0.0, 25.0, 50.0]), Some(25.0));
    assert_eq!(regular_step(&[0.0, 25.0, 51.0]), None);
    assert_eq!(regular_step(&[5.0]), None);
}

proptest! {
    #[test]
    fn interpolation_hits_the_points_and_stays_between_neighbours(
        steps in prop::collection::vec(0.1f64..50.0, 1..20),
        values in prop::collection::vec(-0.05f64..0.05, 21),
        at in 0.0f64..1.0,
    ) {
        let mut xs = vec![-10.0];
        for step in &steps {
            xs.push(xs[xs.len() - 1] + step);
        }
        let ys = &values[..xs.len()];
        for (x, y) in xs.iter().zip(ys) {
            prop_assert_eq!(interpolate_hold(&xs, ys, *x), *y);
        }
        let span = xs[xs.len() - 1] - xs[0];
        let x = xs[0] - 5.0 + at * (span + 10.0);
        let v = interpolate_hold(&xs, ys, x);
        let i = xs.partition_point(|p| *p <= x).clamp(1, xs.len() - 1);
        let (lo, hi) = (ys[i - 1].min(ys[i]), ys[i - 1].max(ys[i]));
        let (lo, hi) = if x < xs[0] { (ys[0], ys[0]) } else if x > xs[xs.len() - 1] { (ys[ys.len() - 1], ys[ys.len() - 1]) } else { (lo, hi) };
        prop_assert!(v >= lo - 1e-15 && v <= hi + 1e-15);
    }
}

#[test]
fn a_table_carries_its_axis_kind_and_types_its_numbers_by_it() {
    use crate::measurement::ByKind;
    use crate::units::{Deg, Mm};
    // The same numbers as a linear X (mm) and as a rotary C (°): x̄ = 1.5,
    // 0, 1 (×10⁻³); −B̄ = mean(x̄↓ − x̄↑) = mean(1, −2, 2)·10⁻³ = 1/3·10⁻³.
    let linear = measurement([1.0, 1.0, 0.0], Some([2.0, -1.0, 2.0]));
    let rotary = linear.clone().with_kind(AxisKind::Rotary);
    let mean = |m: &Measurement| {
        build(
            m,
            TableMode::Mean,
            GridSpec::Targets,
            None,
            Extrapolate::Refuse,
        )
        .unwrap()
    };
    let (x, c) = (mean(&linear), mean(&rotary));
    assert_eq!((x.kind, c.kind), (AxisKind::Linear, AxisKind::Rotary));
    assert_eq!(
        c.positions_typed().collect::<Vec<_>>(),
        [0.0, 40.0, 100.0].map(|p| ByKind::Rotary(Deg(p)))
    );
    assert_eq!(x.reference_typed(), ByKind::Linear(Mm(0.0)));
    assert_eq!(c.reference_typed(), ByKind::Rotary(Deg(0.0)));
    assert_eq!(c.regular_step_typed(), None);
    let Some(ByKind::Rotary(Deg(backlash))) = c.suggested_backlash_typed() else {
        panic!("a rotary axis' backlash is in degrees");
    };
    assert!((backlash - 1.0 / 3000.0).abs() < 1e-15);
    assert!(matches!(
        x.suggested_backlash_typed(),
        Some(ByKind::Linear(Mm(_)))
    ));
}
