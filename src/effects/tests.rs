use super::*;

fn reading(target_mm: f64, direction: Direction, run: u32, time_h: f64) -> Reading {
    Reading {
        target_index: 0,
        target: target_mm,
        direction,
        run,
        run_index: 0,
        time_h,
    }
}

const ORIGIN: Line<'static> = Line {
    first_target_mm: 0.0,
    angle_urad: None,
    times_recorded: true,
    run_h: 0.5,
};

/// One effect of every kind (the registry's order).
fn one_of_each() -> Vec<Effect> {
    vec![
        Effect::Reversal(Reversal { b: -3.0 }),
        Effect::Scale(Scale {
            scale_um_per_m: 11.5,
        }),
        Effect::Drift(Drift::PerHour { rate_um_per_h: 2.0 }),
        Effect::Periodic(Periodic {
            period: 5.0,
            amplitude: 1.25,
            phase_rad: 0.5,
        }),
        Effect::OutlierRun(OutlierRun {
            run: 2,
            direction: Direction::Down,
            offset: 4.5,
        }),
        Effect::Abbe(Abbe {
            offset_mm: 100.0,
            angle_urad: 40.0,
        }),
    ]
}

#[test]
fn the_examples_cover_every_kind_of_the_registry() {
    let kinds: Vec<Kind> = one_of_each().iter().map(Effect::kind).collect();
    assert_eq!(kinds, Kind::ALL);
}

#[test]
fn columns_and_values_agree() {
    let readings = [
        reading(100.0, Direction::Up, 1, 0.5),
        reading(300.0, Direction::Down, 2, 1.0),
    ];
    let angles = [30.0];
    let line = Line {
        angle_urad: Some(&angles),
        ..ORIGIN
    };
    let cases = [
        (Shape::Fixed(Kind::Reversal), vec![4.0]),
        (Shape::Fixed(Kind::Scale), vec![10.0]),
        (Shape::Fixed(Kind::Drift), vec![2.0]),
        (Shape::Period(160.0, PeriodicIn::ReTest), vec![1.0, -0.5]),
        (Shape::Run(Direction::Down, 2), vec![3.0]),
        (Shape::Fixed(Kind::Abbe), vec![50.0]),
    ];
    assert_eq!(cases.len(), Kind::ALL.len(), "every kind");
    for (shape, coefficients) in cases {
        let columns = columns(shape, &readings, &line);
        let effect = Effect::from_fit(shape, &coefficients, &line);
        assert_eq!(effect.kind(), shape.kind());
        for (i, r) in readings.iter().enumerate() {
            let from_columns: f64 = columns
                .iter()
                .zip(&coefficients)
                .map(|(c, b)| c[i] * b)
                .sum();
            assert!(
                (effect.value(r, &line) - from_columns).abs() < 1e-12,
                "{shape:?}"
            );
        }
    }
}

#[test]
fn values_by_hand() {
    let up = reading(250.0, Direction::Up, 1, 0.25);
    assert_eq!(
        Effect::Reversal(Reversal { b: -3.0 }).value(&up, &ORIGIN),
        -1.5
    );
    let from_50 = Line {
        first_target_mm: 50.0,
        ..ORIGIN
    };
    assert_eq!(
        Effect::Scale(Scale {
            scale_um_per_m: 8.0
        })
        .value(&up, &from_50),
        1.6
    );
    assert_eq!(
        Effect::Drift(Drift::PerHour { rate_um_per_h: 4.0 }).value(&up, &ORIGIN),
        1.0
    );
    let periodic = Effect::Periodic(Periodic {
        period: 1000.0,
        amplitude: 2.0,
        phase_rad: 0.0,
    });
    assert!(
        (periodic.value(&up, &ORIGIN) - 2.0).abs() < 1e-12,
        "quarter period: the crest"
    );
}

#[test]
fn every_explanation_is_one_sentence_with_an_action() {
    let context = Context {
        expansion_coefficient_ppm_per_k: Some(11.5),
        table_step: Some(50.0),
        ..Context::default()
    };
    for effect in one_of_each() {
        let text = effect.explanation(&context);
        assert_eq!(text.matches(". ").count(), 0, "one sentence: {text}");
        assert!(text.ends_with('.'), "{text}");
        assert!(text.contains(';'), "what it is; what to do: {text}");
    }
    let scale = Effect::Scale(Scale {
        scale_um_per_m: 11.5,
    })
    .explanation(&context);
    assert!(scale.contains("+1.00 K"), "{scale}");
}

#[test]
fn every_kind_says_what_it_does_to_a_table() {
    let roles: Vec<TableRole> = one_of_each().iter().map(Effect::in_table).collect();
    assert_eq!(roles[0], TableRole::Bidirectional { b: -3.0 });
    assert!(matches!(roles[1], TableRole::TakenOut { .. }));
    assert!(matches!(roles[2], TableRole::NotATable { .. }));
    // A tenth of the period: linear interpolation leaves < 5 % of a sine.
    assert_eq!(roles[3], TableRole::AtPoints { finest_step: 0.5 });
    assert!(
        matches!(roles[4], TableRole::NotATable { ref note } if note.contains("--exclude-run 2:down"))
    );
    assert!(matches!(roles[5], TableRole::NotATable { .. }));
}

#[test]
fn every_kind_is_written_and_read_back() {
    let effects = one_of_each();
    let uncertainty: Vec<Vec<Uncertainty>> = effects
        .iter()
        .map(|e| vec![(e.parameters()[0].key, 0.05)])
        .collect();
    let text = write_effects(
        effects
            .iter()
            .zip(&uncertainty)
            .map(|(effect, u)| FileEntry {
                effect,
                uncertainty: u,
                explanation: "What it is; what to do.",
            }),
        "after.rtl",
    );
    assert_eq!(read_effects(&text).unwrap(), effects, "{text}");
    assert!(text.contains("B_um = -3.0000      # ± 0.0500"), "{text}");
    assert!(text.contains("run = 2            # ± 0.0500"), "{text}");
}

#[test]
fn bad_effects_are_refused_with_a_position() {
    let unknown = read_effects("[[effect]]\nkind = \"wobble\"\n").unwrap_err();
    assert_eq!(unknown.position.line, 2, "{unknown}");
    let missing = read_effects("[[effect]]\nkind = \"scale\"\n").unwrap_err();
    assert!(missing.message.contains("scale_um_per_m"), "{missing}");
    let direction = read_effects(
        "[[effect]]\nkind = \"outlier-run\"\nrun = 1\ndirection = \"left\"\noffset_um = 1.0\n",
    )
    .unwrap_err();
    assert!(
        direction.message.contains("\"up\" or \"down\""),
        "{direction}"
    );
    let typo = read_effects("[[effect]]\nkind = \"scale\"\nscale_um_per_m = 1.0\nsclae = 2\n")
        .unwrap_err();
    assert!(typo.message.contains("sclae"), "{typo}");
    let tests =
        read_effects("[[effect]]\nkind = \"drift\"\nrate_um_per_h = 1.0\ntests = [\"after\"]\n");
    assert_eq!(
        tests.unwrap(),
        [Effect::Drift(Drift::PerHour { rate_um_per_h: 1.0 })]
    );
    let period =
        read_effects("[[effect]]\nkind = \"periodic\"\nperiod_mm = 0.0\namplitude_um = 1.0\n")
            .unwrap_err();
    assert!(period.message.contains("period_mm must be > 0"), "{period}");
    let infinite = read_effects("[[effect]]\nkind = \"drift\"\nrate_um_per_h = inf\n").unwrap_err();
    assert!(infinite.message.contains("finite"), "{infinite}");
    assert!(read_effects("").unwrap().is_empty());
}

#[test]
fn every_kind_labels_itself_with_the_numbers_it_is_given() {
    let two_decimals = |v: f64| format!("{v:.2}");
    let labels: Vec<String> = one_of_each()
        .iter()
        .map(|e| e.model().label(&Context::default(), &two_decimals))
        .collect();
    assert_eq!(labels[0], "reversal B = -3.00 µm");
    assert_eq!(labels[3], "periodic 1.25 µm, period 5.00 mm");
    assert_eq!(labels[4], "run 2↓ offset 4.50 µm");
    for (label, kind) in labels.iter().zip(Kind::ALL) {
        assert!(
            label
                .to_lowercase()
                .contains(&kind.name().replace("outlier-", "")),
            "{label}"
        );
    }
}

#[test]
fn one_number_kinds_show_their_parameter_and_label() {
    let two_decimals = |v: f64| format!("{v:.2}");
    let scale = Effect::Scale(Scale {
        scale_um_per_m: 11.5,
    });
    let drift = Effect::Drift(Drift::PerHour { rate_um_per_h: 2.0 });
    assert_eq!(
        scale.parameters(),
        vec![Parameter::number("scale_um_per_m", "scale", "µm/m", 11.5)]
    );
    assert_eq!(
        drift.parameters(),
        vec![Parameter::number("rate_um_per_h", "rate", "µm/h", 2.0)]
    );
    let linear = Context::default();
    assert_eq!(
        scale.model().label(&linear, &two_decimals),
        "scale 11.50 µm/m"
    );
    assert_eq!(
        drift.model().label(&linear, &two_decimals),
        "drift 2.00 µm/h"
    );
}

/// A rotary axis' effects label themselves in its units: held in m° and °,
/// said in ″ (or µrad) and °, never in µm or mm.
#[test]
fn a_rotary_axis_effects_label_themselves_in_its_units() {
    let two_decimals = |v: f64| format!("{v:.2}");
    let rotary = |angle| Context {
        kind: AxisKind::Rotary,
        angle,
        ..Context::default()
    };
    let label = |effect: Effect, angle| effect.model().label(&rotary(angle), &two_decimals);
    // 10 m° = 0.01° = 36″ = 0.01·π/180·10⁶ µrad = 174.53 µrad.
    let reversal = Effect::Reversal(Reversal { b: 10.0 });
    assert_eq!(
        label(reversal.clone(), AngleUnit::Arcsec),
        "reversal B = 36.00″"
    );
    assert_eq!(label(reversal, AngleUnit::Urad), "reversal B = 174.53 µrad");
    // 1.25 m° = 4.5″, twice per revolution.
    let periodic = Effect::Periodic(Periodic {
        period: 180.0,
        amplitude: 1.25,
        phase_rad: 0.0,
    });
    assert_eq!(
        label(periodic, AngleUnit::Arcsec),
        "periodic 4.50″, period 180.00°"
    );
    // 4.5 m° = 16.2″.
    let run = Effect::OutlierRun(OutlierRun {
        run: 2,
        direction: Direction::Down,
        offset: 4.5,
    });
    assert_eq!(label(run, AngleUnit::Arcsec), "run 2↓ offset 16.20″");
}

/// A drift per run (a test that records no times) grows by its rate each
/// run: at 0.75 h on a clock of 0.5 h a run, 1.5 runs, 2 µm/run gives 3 µm;
/// its TOML takes one of the two rates, never both.
#[test]
fn a_drift_per_run_counts_runs_not_hours() {
    let drift = Effect::Drift(Drift::PerRun {
        rate_um_per_run: 2.0,
    });
    let late = reading(0.0, Direction::Up, 2, 0.75);
    assert!((drift.value(&late, &ORIGIN) - 3.0).abs() < 1e-12);
    assert_eq!(
        drift.parameters(),
        vec![Parameter::number("rate_um_per_run", "rate", "µm/run", 2.0)]
    );
    let read = read_effects("[[effect]]\nkind = \"drift\"\nrate_um_per_run = 2.0\n").unwrap();
    assert_eq!(read, [drift]);
    let both =
        read_effects("[[effect]]\nkind = \"drift\"\nrate_um_per_h = 1.0\nrate_um_per_run = 2.0\n")
            .unwrap_err();
    assert!(both.message.contains("one rate"), "{both}");
}
