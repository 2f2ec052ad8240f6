//! `predict` against independent expectations: the first test's own
//! prediction (`compensate::retest`), hand-derived Abbe terms and a
//! scale error compensated by hand.

use super::*;
use crate::compensate::retest::{Applied, predicted_deviation};
use crate::compensate::{Extrapolate, GridSpec, TableMode, TableOptions, build_table};
use crate::effects::Reversal;
use crate::evaluate::ISO_230_2;
use crate::synth::{self, Truth};

/// A synthetic X test on the bundled machine (0 … 750 mm, 16 irregular targets).
fn x_test(effects: &str) -> Measurement {
    let text = format!(
        "[cycle]\nstart_mm = 0.0\nend_mm = 750.0\ncount = 16\njitter_mm = 8.0\nruns = 3\n\
         [error]\nscale_um_per_m = 9.5\nperiodic = [{{ period_mm = 300.0, amplitude_um = 2.0, phase_rad = 0.4 }}]\n\
         [noise]\nsigma_um = 0.3\n\n{effects}"
    );
    synth::before(&Truth::from_toml_str(&text).unwrap(), 7).unwrap()
}

fn table(measurement: &Measurement, mode: TableMode) -> CompensationTable {
    let options = TableOptions {
        mode,
        grid: GridSpec::Targets,
        reference: None,
        extrapolate: Extrapolate::Hold,
    };
    build_table(measurement, &evaluate(measurement), &options).unwrap()
}

fn input<'a>(
    machine: &'a Machine,
    errors: &'a GeometricErrors,
    measured: &'a [MeasuredAxis<'a>],
    tables: &'a [CompensationTable],
    line_mm: [f64; 3],
) -> PredictInput<'a> {
    PredictInput {
        machine,
        errors,
        measured,
        tables,
        cross_tables: &[],
        line_mm,
        retest_tool_offset_mm: None,
        grid_step_mm: 50.0,
        effects: &[],
        backlash_set: false,
        standard: &ISO_230_2,
    }
}

#[test]
fn on_the_measured_line_it_is_the_first_tests_own_prediction() {
    let machine = Machine::bundled();
    let before = x_test("[[effect]]\nkind = \"reversal\"\nB_um = -3.0\n");
    let errors = GeometricErrors::default();
    let line = [0.0, 250.0, -275.0];
    let measured = [MeasuredAxis {
        measurement: &before,
        line_mm: line,
        optics: Optics::AT_TOOL_TIP,
    }];
    for mode in [TableMode::Mean, TableMode::Bidirectional] {
        let tables = [table(&before, mode)];
        let prediction = predict(&input(&machine, &errors, &measured, &tables, line)).unwrap();
        let known = KnownError::from_evaluation(&evaluate(&before)).unwrap();
        let retest = &prediction.retests[0];
        for (t, target) in retest.per_target.iter().zip(before.targets()) {
            for (direction, value) in [(Direction::Up, t.up_mm), (Direction::Down, t.down_mm)] {
                let expected =
                    predicted_deviation(&known, Applied::table(&tables[0]), *target, direction);
                assert!(
                    (value - expected).abs() < 1e-9,
                    "{mode:?} {target} {direction:?}: {value} vs {expected}"
                );
            }
            // Without the table, the line reads the measured means, per direction.
            assert!((t.before_up_mm - known.at(*target, Direction::Up)).abs() < 1e-9);
            assert!((t.before_down_mm - known.at(*target, Direction::Down)).abs() < 1e-9);
        }
        // The predicted re-test keeps the first test's scatter: the same R per direction.
        let first = evaluate(&before).figures;
        assert!((retest.figures.r_up.unwrap() - first.r_up.unwrap()).abs() < 1e-12);
        assert!((retest.figures.r_down.unwrap() - first.r_down.unwrap()).abs() < 1e-12);
        // Without the table the model's line is the measurement: the same M and B̄.
        assert!((retest.figures_before.m.unwrap() - first.m.unwrap()).abs() < 1e-9);
        assert!((retest.figures_before.b_mean.unwrap() - first.b_mean.unwrap()).abs() < 1e-9);
        // The measured reversal (−3 µm in the truth) is carried: a mean table leaves it,
        // a bidirectional table takes it out. An effect's reversal (a change found by
        // diagnose) adds to it.
        let b = retest.figures.b_mean.unwrap() * 1000.0;
        let b_measured = first.b_mean.unwrap() * 1000.0;
        assert!((retest.measured_mean_reversal_mm.unwrap() * 1000.0 - b_measured).abs() < 1e-9);
        let b_with_effect = predict(&PredictInput {
            effects: &[Effect::Reversal(Reversal { b: -1.0 })],
            ..input(&machine, &errors, &measured, &tables, line)
        })
        .unwrap()
        .retests[0]
            .figures
            .b_mean
            .unwrap()
            * 1000.0;
        match mode {
            TableMode::Mean => {
                // Equal up to second order: the table moves each direction's curve by the
                // same v, and the two curves' slopes differ by the reversal's slope
                // (nm per mm) × v (µm): below 1e-3 µm.
                assert!((b - b_measured).abs() < 1e-3, "{b} vs {b_measured}");
                assert!(
                    (b_with_effect - (b_measured - 1.0)).abs() < 1e-3,
                    "{b_with_effect}"
                );
            }
            TableMode::Bidirectional => {
                assert!(b.abs() < 0.05, "{b}");
                assert!((b_with_effect + 1.0).abs() < 0.05, "{b_with_effect}");
            }
        }
    }
}

#[test]
fn pitch_changes_the_reading_on_another_line_by_hand() {
    // EBX rising linearly from 0 to 20 µrad over the stroke. On the bundled
    // machine the X pitch acts with the lever Z + z4 + 550 (notes §2.5; the
    // `volumetric_error` example), so 500 mm lower (Z = −500 instead of 0) the
    // reading changes by EBX(x) × (−500 mm): −10 µm at 750 mm, −5 µm at 375 mm.
    let machine = Machine::bundled();
    let before = x_test("");
    let mut errors = GeometricErrors::default();
    let ebx = ErrorTable::new(vec![0.0, 750.0], vec![0.0, 20e-6], Interpolation::Linear).unwrap();
    errors
        .set(ErrorName::EBX, ErrorFunction::Table(ebx))
        .unwrap();
    let measured_line = [0.0, 250.0, 0.0];
    let measured = [MeasuredAxis {
        measurement: &before,
        line_mm: measured_line,
        optics: Optics::AT_TOOL_TIP,
    }];
    let tables = [table(&before, TableMode::Mean)];
    let same = predict(&input(&machine, &errors, &measured, &tables, measured_line)).unwrap();
    let lower = predict(&input(
        &machine,
        &errors,
        &measured,
        &tables,
        [0.0, 250.0, -500.0],
    ))
    .unwrap();
    let known = KnownError::from_evaluation(&evaluate(&before)).unwrap();
    for (a, b) in same.retests[0]
        .per_target
        .iter()
        .zip(&lower.retests[0].per_target)
    {
        let x = a.target_mm;
        // On the measured line the model gives back the measurement …
        assert!(
            (a.before_up_mm - known.at(x, Direction::Up)).abs() < 1e-9,
            "{x}: {} vs {}",
            a.before_up_mm,
            known.at(x, Direction::Up)
        );
        // … and 500 mm lower the Abbe term of the pitch.
        let abbe = 20e-6 * x / 750.0 * -500.0;
        assert!(
            (b.before_up_mm - a.before_up_mm - abbe).abs() < 1e-9,
            "{x}: {} vs {abbe}",
            b.before_up_mm - a.before_up_mm
        );
        // The table cannot know: the re-test there shows the Abbe term, where the axis is (x − v).
        let v = tables[0].value_at(x, Direction::Up);
        let abbe_there = 20e-6 * (x - v) / 750.0 * -500.0;
        assert!((b.up_mm - a.up_mm - abbe_there).abs() < 1e-9, "{x}");
    }
    // A longer tool: in the ZFYX chain X carries the workpiece, and its errors act at the
    // workpiece point (eq. 60), which the tool does not move: the X re-test is unchanged.
    let long_tool = PredictInput {
        retest_tool_offset_mm: Some([0.0, -280.0, -350.0]),
        ..input(&machine, &errors, &measured, &tables, measured_line)
    };
    let tool = predict(&long_tool).unwrap();
    for (a, b) in same.retests[0]
        .per_target
        .iter()
        .zip(&tool.retests[0].per_target)
    {
        assert!((a.up_mm - b.up_mm).abs() < 1e-12);
    }
}

#[test]
fn a_scale_error_compensated_exactly_leaves_its_square() {
    // EXX = k·x with k = 10 µm/m, described (no measurement); the table is the
    // same straight line. The axis then reaches EXX(x − v) − v = −k²·x: 75 pm
    // at 750 mm. The volumetric maximum before is EXX(750) = 7.5 µm, at X = 750.
    let machine = Machine::bundled();
    let k = 1e-5;
    let mut errors = GeometricErrors::default();
    let exx = ErrorTable::new(
        vec![0.0, 750.0],
        vec![0.0, 750.0 * k],
        Interpolation::Linear,
    )
    .unwrap();
    errors
        .set(ErrorName::EXX, ErrorFunction::Table(exx))
        .unwrap();
    let tables = [CompensationTable {
        axis: "X".into(),
        kind: crate::measurement::AxisKind::Linear,
        positions: vec![0.0, 750.0],
        values: crate::compensate::TableValues::Mean(vec![0.0, 750.0 * k]),
        reference: 0.0,
        suggested_backlash: None,
    }];
    let prediction = predict(&input(&machine, &errors, &[], &tables, [0.0; 3])).unwrap();
    assert!((prediction.volumetric_before.max_mm - 0.0075).abs() < 1e-12);
    assert_eq!(prediction.volumetric_before.at_mm[0], 750.0);
    assert!(
        (prediction.volumetric_after.max_mm - k * k * 750.0).abs() < 1e-13,
        "{}",
        prediction.volumetric_after.max_mm
    );
    let retest = &prediction.retests[0];
    assert!(!retest.with_measured_scatter);
    assert_eq!(retest.per_target.len(), 2);
    assert!((retest.per_target[1].up_mm + k * k * 750.0).abs() < 1e-13);
    assert_eq!(retest.figures.r, None, "one run each way: no repeatability");
}

#[test]
fn refusals() {
    let machine = Machine::bundled();
    let before = x_test("");
    let measured = [MeasuredAxis {
        measurement: &before,
        line_mm: [0.0; 3],
        optics: Optics::AT_TOOL_TIP,
    }];
    let tables = [table(&before, TableMode::Mean)];
    let mut errors = GeometricErrors::default();
    errors
        .set(ErrorName::EXX, ErrorFunction::Constant(1e-3))
        .unwrap();
    assert_eq!(
        predict(&input(&machine, &errors, &measured, &tables, [0.0; 3])).unwrap_err(),
        PredictError::GivenTwice(ErrorName::EXX)
    );
    let none = GeometricErrors::default();
    assert_eq!(
        predict(&input(&machine, &none, &measured, &[], [0.0; 3])).unwrap_err(),
        PredictError::NoTable
    );
    let two = [tables[0].clone(), tables[0].clone()];
    assert_eq!(
        predict(&input(&machine, &none, &measured, &two, [0.0; 3])).unwrap_err(),
        PredictError::TwoTables(Axis::X)
    );
    let mut rotary = tables[0].clone();
    rotary.axis = "C".into();
    assert!(matches!(
        predict(&input(&machine, &none, &measured, &[rotary], [0.0; 3])).unwrap_err(),
        PredictError::UnknownAxis { .. }
    ));
}

#[test]
fn the_positioning_error_enters_with_plus_one_in_every_chain() {
    for chain in ["ZFYX", "FXYZ", "YFXZ", "XYFZ"] {
        let text =
            Machine::bundled_toml().replace("chain = \"ZFYX\"", &format!("chain = \"{chain}\""));
        let machine = Machine::from_toml_str(&text).unwrap();
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            assert_eq!(
                positioning_sign(&machine, axis).unwrap(),
                1.0,
                "{chain} {axis}"
            );
        }
    }
}
