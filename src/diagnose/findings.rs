//! What a diagnosis reports of its effects: the accepted effect with its
//! uncertainty and sentence, the context the sentences need, the residual's
//! statistics and the ISO 230-2 figures with and without the effects.

use super::problem::Problem;
use super::selection::Chosen;
use super::{AcceptedEffect, DiagnoseError, DiagnoseInput, FigureSet, ResidualStats};
use crate::compensate::CompensationTable;
use crate::compensate::retest::KnownError;
use crate::effects::{
    Context, Effect, FitSummary, Kind, Shape, deviation_as_position, position_as_deviation,
};
use crate::evaluate::{AxisFigures, StandardFigure, evaluate, evaluate_with};
use crate::measurement::{Measurement, Run};

/// The mean reversal B̄ of the first test, µm (m° on a rotary axis), when it
/// measured both directions.
pub(super) fn first_test_reversal_of(input: &DiagnoseInput<'_>) -> Option<f64> {
    let before = input.before?;
    let known = KnownError::from_evaluation(&evaluate(before))?;
    known
        .is_bidirectional()
        .then(|| position_as_deviation(before.kind(), known.mean_reversal()))
}

pub(super) fn context(input: &DiagnoseInput<'_>, time_assumed: bool) -> Context {
    let material = |m: &Measurement| m.environment.material_temperature_c[0].start;
    let material_change_k = match (input.before, material(input.after)) {
        (Some(before), Some(after)) => material(before).map(|b| after - b),
        _ => None,
    };
    Context {
        kind: input.after.kind(),
        angle: input.angle,
        table_step: input.table.and_then(CompensationTable::regular_step),
        target_spacing: crate::compensate::regular_step(input.after.targets()),
        expansion_coefficient_ppm_per_k: input.after.environment.expansion_coefficient_ppm_per_k,
        material_change_k,
        time_assumed,
        first_test_reversal: first_test_reversal_of(input),
        // Known once the figures are: `diagnose` says them then.
        retest_mean_reversal: None,
    }
}

pub(super) fn accepted_effect(
    chosen: Chosen,
    coefficients: &[f64],
    errors: &[f64],
    problem: &Problem,
    context: &Context,
    n: usize,
) -> AcceptedEffect {
    let width = match chosen.shape {
        Shape::Period(..) => 2,
        _ => 1,
    };
    let coefficients = &coefficients[chosen.first_column..chosen.first_column + width];
    let errors = &errors[chosen.first_column..chosen.first_column + width];
    let effect = Effect::from_fit(chosen.shape, coefficients, &problem.line());
    let (uncertainty, mut warnings) = effect.uncertainty(&FitSummary {
        coefficients,
        errors,
        span: problem.targets[problem.targets.len() - 1] - problem.targets[0],
        n,
        target_spacing: context.target_spacing,
        kind: context.kind,
    });
    if context.time_assumed && effect.kind() == Kind::Drift {
        warnings.push("the file records no test duration: the drift is per run, in the order the runs were measured (the readings within a run spaced as a typical cycle: 3 s dwell, 2000 mm/min)".to_string());
    }
    AcceptedEffect {
        explanation: effect.explanation(context),
        effect,
        uncertainty,
        evidence: chosen.evidence,
        warnings,
    }
}

pub(super) fn stats(values: &[f64]) -> ResidualStats {
    let n = values.len().max(1) as f64;
    ResidualStats {
        rms: (values.iter().map(|v| v * v).sum::<f64>() / n).sqrt(),
        max_abs: values.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
    }
}

/// Figures of the re-test as measured, as predicted and as predicted with
/// the effects, ISO 230-2:2014's and `input.standard`'s of the same three
/// tests; `value(i, with_effects)` gives reading i of the model (µm, with
/// the measured scatter, so A and R stay comparable).
pub(super) fn figures(
    input: &DiagnoseInput<'_>,
    problem: &Problem,
    value: impl Fn(usize, bool) -> f64,
) -> Result<(FigureSet, FigureSet<Vec<StandardFigure>>), DiagnoseError> {
    let after = input.after;
    let build = |with_effects: bool| -> Result<Measurement, DiagnoseError> {
        let mut runs: Vec<Run> = after
            .runs()
            .iter()
            .map(|run| Run {
                deviations: vec![None; after.targets().len()],
                ..run.clone()
            })
            .collect();
        for (i, reading) in problem.readings.iter().enumerate() {
            runs[reading.run_index].deviations[reading.target_index] =
                Some(deviation_as_position(after.kind(), value(i, with_effects)));
        }
        Measurement::new(
            after.axis(),
            after.targets().to_vec(),
            runs,
            after.environment.clone(),
            after.metadata.clone(),
        )
        .map_err(|e| DiagnoseError::Internal(e.to_string()))
    };
    let built;
    let predicted = match &problem.first_test_prediction {
        Some(prediction) => prediction,
        None => {
            built = build(false)?;
            &built
        }
    };
    let with_effects = build(true)?;
    let both = |test: &Measurement| -> (AxisFigures, Vec<StandardFigure>) {
        (
            evaluate(test).figures,
            evaluate_with(test, input.standard).standard_figures,
        )
    };
    let (measured, predicted, with_effects) = (both(after), both(predicted), both(&with_effects));
    Ok((
        FigureSet {
            measured: measured.0,
            predicted: predicted.0,
            predicted_with_effects: with_effects.0,
        },
        FigureSet {
            measured: measured.1,
            predicted: predicted.1,
            predicted_with_effects: with_effects.1,
        },
    ))
}
