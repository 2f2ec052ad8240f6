//! Diagnosis of a re-test: the residual between what the model predicted and
//! what was measured, traced to the physical effects the model lacks.
//!
//! 1. **Prediction.** With the first test (and the table), each reading of the
//!    re-test is predicted by `compensate::retest`: the known axis error minus
//!    the table, as the controller applies it. Without them, the model is the
//!    re-test's own per-target systematic error, and only structure *between
//!    runs* can be found.
//! 2. **Residual** = measured − predicted, per reading.
//! 3. **Between runs** (reversal, drift, outlier runs): fitted on the
//!    readings with one free level per target, so no position-dependent error
//!    can pose as one of them.
//! 4. **Along the axis** (scale, periodic, Abbe; only with a prediction):
//!    fitted on those per-target levels by weighted least squares with their
//!    *known* variance, the re-test's scatter plus the uncertainty of the
//!    prediction (the first test's mean at each target, which every run of the
//!    re-test shares and which would otherwise pose as structure).
//! 5. A candidate is accepted only if it lowers the Bayesian information
//!    criterion by at least [`MIN_DELTA_BIC`] (strong evidence, Kass & Raftery
//!    1995), plus 2·ln(trials) when its shape was chosen among many (periods,
//!    runs: the look-elsewhere effect), and predicts the runs it was not
//!    fitted on better (leave-one-run-out). Several can be accepted.
//! 6. **Never the nearest kind.** A position-dependent effect must be the same
//!    along the whole axis (its parameters on the two halves of the span agree,
//!    p ≥ [`LACK_OF_FIT_P`]), and after selection the per-target levels must be
//!    explained (χ² lack of fit p ≥ [`LACK_OF_FIT_P`]); otherwise the
//!    position-dependent effects are moved to `rejected` and the structure is
//!    reported as unexplained, with where and how large.
//!
//! Pure: values in, values out.

mod along_axis;
mod between_runs;
pub mod fit;
mod stats;

use crate::compensate::retest::{
    Applied, BacklashError, KnownError, predicted_deviation_mm, with_scatter,
};
use crate::compensate::{CompensationTable, interpolate_hold};
use crate::cycle::{self, CycleTiming};
use crate::effects::{
    Context, Effect, FileEntry, FitSummary, Kind, Line, Reading, Reversal, Shape,
};
use crate::error::{ParseError, describe_found};
use crate::evaluate::{AxisFigures, Evaluation, evaluate};
use crate::measurement::together::{Input, NotTogether, Pairing, check_together};
use crate::measurement::{Direction, Measurement, Run};
use along_axis::{Background, select_along_axis, target_levels};
use between_runs::{
    cell_levels, cross_validation_folds, reversals, select_between_runs, select_reversal,
};
use fit::{Design, WeightedFit};
use stats::chi2_p;

/// Minimum drop of the BIC for an effect to be accepted.
pub const MIN_DELTA_BIC: f64 = 6.0;
/// Below this p-value a model lacks fit, or an effect is not the same along the axis.
pub const LACK_OF_FIT_P: f64 = 0.001;
/// A periodic error must fit at least this many periods in the measured span.
pub const MIN_PERIODS_IN_SPAN: f64 = 2.0;
/// Without a prediction, a periodic error is told from the smooth curve of the
/// test itself (a regression spline with knots every span / 6), so it must be
/// short next to it: at least this many periods in the span.
pub const MIN_PERIODS_IN_CURVE: f64 = 8.0;

/// What `diagnose` is given.
#[derive(Clone, Copy, Debug)]
pub struct DiagnoseInput<'a> {
    /// The re-test.
    pub after: &'a Measurement,
    /// The first test, when the model predicts from it.
    pub before: Option<&'a Measurement>,
    /// The table active during the re-test.
    pub table: Option<&'a CompensationTable>,
    /// The controller's backlash parameter was set during the re-test as
    /// `convert` suggests from the first test (−B̄).
    pub backlash_set: bool,
    /// The axis' angular error (pitch or yaw) along the stroke, for Abbe.
    pub angular: Option<&'a AngularProfile>,
    /// Cycle timing to assume when the file records no duration.
    pub timing: CycleTiming,
}

/// An angular error along the axis, µrad at positions, mm.
#[derive(Clone, Debug, PartialEq)]
pub struct AngularProfile {
    /// Positions, mm, increasing.
    pub positions_mm: Vec<f64>,
    /// Angle there, µrad.
    pub angle_urad: Vec<f64>,
}

impl AngularProfile {
    /// Reads `position_mm,angle_urad` lines (that header first; `#` starts a
    /// comment), positions strictly increasing, at least two: the pitch or
    /// yaw of the axis from an angular laser measurement.
    ///
    /// ```
    /// use axcomp::diagnose::AngularProfile;
    ///
    /// let profile = AngularProfile::from_csv_str("position_mm,angle_urad\n0,0\n375,12.5\n750,0\n")?;
    /// assert_eq!(profile.angle_urad, [0.0, 12.5, 0.0]);
    /// # Ok::<(), axcomp::error::ParseError>(())
    /// ```
    pub fn from_csv_str(text: &str) -> Result<AngularProfile, ParseError> {
        let mut rows = text
            .lines()
            .enumerate()
            .map(|(i, line)| (i + 1, line.split('#').next().unwrap_or("").trim()))
            .filter(|(_, line)| !line.is_empty());
        let header: Vec<&str> = rows
            .next()
            .map_or(Vec::new(), |(_, l)| l.split(',').map(str::trim).collect());
        if header != ["position_mm", "angle_urad"] {
            return Err(ParseError::expected(
                1,
                1,
                "the header position_mm,angle_urad",
                &header.join(","),
            ));
        }
        let mut profile = AngularProfile {
            positions_mm: Vec::new(),
            angle_urad: Vec::new(),
        };
        for (number, line) in rows {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            let [position, angle] = fields[..] else {
                return Err(ParseError::expected(
                    number,
                    1,
                    "two fields: position_mm,angle_urad",
                    line,
                ));
            };
            let parse = |field: &str, column: usize| {
                field
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        ParseError::expected(number, column, "a number", &describe_found(field))
                    })
            };
            let x = parse(position, 1)?;
            if profile.positions_mm.last().is_some_and(|last| x <= *last) {
                return Err(ParseError::expected(
                    number,
                    1,
                    "positions strictly increasing",
                    position,
                ));
            }
            profile.positions_mm.push(x);
            profile.angle_urad.push(parse(angle, position.len() + 2)?);
        }
        if profile.positions_mm.len() < 2 {
            return Err(ParseError::new(
                1,
                1,
                "expected at least two positions with an angle",
            ));
        }
        Ok(profile)
    }
}

/// RMS and largest |value| of a residual, µm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResidualStats {
    /// Root mean square, µm.
    pub rms_um: f64,
    /// Largest absolute value, µm.
    pub max_abs_um: f64,
}

/// Why an accepted effect was accepted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evidence {
    /// Change of the BIC when it was added (negative is better).
    pub delta_bic: f64,
    /// How many shapes were tried (periods, runs), 1 otherwise.
    pub trials: usize,
    /// p-value of the partial F-test of adding it.
    pub p_value: f64,
    /// Leave-one-run-out prediction error without it, µm.
    pub cv_rmse_without_um: f64,
    /// The same with it, µm.
    pub cv_rmse_with_um: f64,
}

/// An effect found in the residual.
#[derive(Clone, Debug, PartialEq)]
pub struct AcceptedEffect {
    /// The effect and its parameters.
    pub effect: Effect,
    /// Standard uncertainty of each parameter, by key.
    pub uncertainty: Vec<(&'static str, f64)>,
    /// Why it was accepted.
    pub evidence: Evidence,
    /// What it is and what to do, one sentence.
    pub explanation: String,
    /// Caveats (aliasing, assumed times).
    pub warnings: Vec<String>,
}

/// An effect that was tried and not accepted.
#[derive(Clone, Debug, PartialEq)]
pub struct RejectedEffect {
    /// The kind.
    pub kind: Kind,
    /// Why, in words.
    pub why: String,
}

/// Structure left after the accepted effects.
#[derive(Clone, Debug, PartialEq)]
pub struct Unexplained {
    /// Whether it is significant (lack-of-fit p < [`LACK_OF_FIT_P`]).
    pub significant: bool,
    /// p-value of the lack-of-fit test.
    pub p_value: f64,
    /// Targets where it is largest (|mean residual| > 3 standard errors), mm.
    pub where_mm: Vec<f64>,
    /// RMS of the per-target mean residual, µm.
    pub rms_um: f64,
}

/// The ISO 230-2 figures of the re-test as measured and as the model predicts it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FigureSet {
    /// As measured.
    pub measured: AxisFigures,
    /// Predicted by the model, as `predict` gives them: the first test's
    /// readings with the predicted systematic error (so the first test's
    /// scatter and R). Without a first test: the re-test's own systematic
    /// curve with its scatter.
    pub predicted: AxisFigures,
    /// What the prediction with the accepted effects explains of this
    /// re-test: its systematic part with this re-test's scatter.
    pub predicted_with_effects: AxisFigures,
}

/// The diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnosis {
    /// Whether a prediction from a first test was used.
    pub predicted_from_first_test: bool,
    /// The model's error before adding effects.
    pub residual_before: ResidualStats,
    /// Effects found.
    pub accepted: Vec<AcceptedEffect>,
    /// Effects tried and not found: never a kind that is in `accepted`.
    pub rejected: Vec<RejectedEffect>,
    /// The model's error with the effects.
    pub residual_after: ResidualStats,
    /// Figures.
    pub figures: FigureSet,
    /// What none of the effects explains.
    pub unexplained: Unexplained,
    /// Scatter of one reading left at the end, µm.
    pub noise_um: f64,
    /// Whether reading times were assumed from a typical cycle.
    pub time_assumed: bool,
    /// Every reading of the re-test in the order measured, with its residual
    /// and the fitted model (for plots).
    pub readings: Vec<ReadingResidual>,
}

impl Diagnosis {
    /// The accepted effects as an effects file (`--write-effects`), for
    /// `predict --effects` and `convert --effects`; `source` names the re-test.
    pub fn effects_file(&self, source: &str) -> String {
        crate::effects::write_effects(
            self.accepted.iter().map(|a| FileEntry {
                effect: &a.effect,
                uncertainty: &a.uncertainty,
                explanation: &a.explanation,
            }),
            source,
        )
    }
}

/// One reading of the re-test and what the diagnosis made of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadingResidual {
    /// Where, in which direction and run, and when it was taken.
    pub reading: Reading,
    /// Measured − predicted, µm.
    pub residual_um: f64,
    /// The fitted model of the residual there: the level along the axis, the
    /// reversal and the between-runs effects, µm.
    pub fitted_um: f64,
}

/// Why a diagnosis cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DiagnoseError {
    /// Too few readings.
    #[error(
        "the re-test has {0} readings; a diagnosis needs at least 2 runs over at least 2 targets"
    )]
    TooFewReadings(usize),
    /// The first test has no usable means.
    #[error("the first test has no target with a mean deviation")]
    NoKnownError,
    /// The backlash parameter cannot be applied as said.
    #[error("the backlash parameter {0}")]
    Backlash(#[from] BacklashError),
    /// The two tests (or the table) do not belong together: another axis,
    /// ranges without a common stretch, the same readings twice.
    #[error(transparent)]
    NotTogether(#[from] NotTogether),
    /// A measurement could not be rebuilt (a bug).
    #[error("{0}")]
    Internal(String),
}

/// The readings with their prediction, as one table.
struct Problem {
    readings: Vec<Reading>,
    measured_um: Vec<f64>,
    predicted_um: Vec<f64>,
    /// The prediction at each target of the re-test interpolates the first
    /// test's means: (index into `first_test_variance_um2`, weight) pairs.
    prediction_weights: Vec<Vec<(usize, f64)>>,
    /// The predicted re-test as `predict` gives it on the measured line: the
    /// first test's readings with the predicted systematic error.
    first_test_prediction: Option<Measurement>,
    /// Variance of the first test's bidirectional mean at each of its targets, µm².
    first_test_variance_um2: Vec<f64>,
    /// Variance of the first test's reversal x̄↑ − x̄↓ at each of its targets
    /// (which the prediction carries), µm²; 0 for a unidirectional test.
    first_test_reversal_variance_um2: Vec<f64>,
    run_count: usize,
    targets_mm: Vec<f64>,
    angle_urad: Option<Vec<f64>>,
    /// The cells (target, direction) that have readings, in column order.
    cells: Vec<(usize, Direction)>,
    /// One column per cell: the ISO 230-2 systematic model x̄_i↑, x̄_i↓.
    cell_design: Design,
}

impl Problem {
    fn first_target_mm(&self) -> f64 {
        self.targets_mm[0]
    }

    /// Covariance of the predicted reversals at the re-test's targets `a` and
    /// `b`, µm²: what they share of the first test's reversals.
    fn shared_reversal_variance_um2(&self, a: usize, b: usize) -> f64 {
        self.prediction_weights[a]
            .iter()
            .flat_map(|(ka, wa)| {
                self.prediction_weights[b]
                    .iter()
                    .filter(move |(kb, _)| kb == ka)
                    .map(move |(_, wb)| wa * wb * self.first_test_reversal_variance_um2[*ka])
            })
            .sum()
    }

    /// Variance of the predicted reversal at the re-test's target `t`, µm²:
    /// the first test's reversals through the spline weights (independent
    /// between the first test's targets).
    fn reversal_prediction_variance_um2(&self, t: usize) -> f64 {
        self.shared_reversal_variance_um2(t, t)
    }

    /// What the effects need of the test besides a reading.
    fn line(&self) -> Line<'_> {
        Line {
            first_target_mm: self.first_target_mm(),
            angle_urad: self.angle_urad.as_deref(),
        }
    }

    fn columns(&self, shape: Shape) -> Vec<Vec<f64>> {
        crate::effects::columns(shape, &self.readings, &self.line())
    }

    fn run_of(&self) -> Vec<usize> {
        self.readings.iter().map(|r| r.run_index).collect()
    }

    /// The contribution of a between-runs effect (drift, outlier run) to reading `i`.
    fn contribution(&self, chosen: &Chosen, coefficients: &[f64], i: usize) -> f64 {
        let columns = self.columns(chosen.shape);
        columns
            .iter()
            .enumerate()
            .map(|(j, column)| column[i] * coefficients[chosen.first_column + j])
            .sum()
    }
}

/// An accepted shape, where its columns start in its model, and why.
#[derive(Clone, Copy, Debug)]
struct Chosen {
    shape: Shape,
    first_column: usize,
    evidence: Evidence,
}

/// A cell level of the between-runs fit: one target in one direction.
#[derive(Clone, Copy, Debug)]
struct Cell {
    target_index: usize,
    direction: Direction,
    value_um: f64,
    /// Variance of the level from the re-test's scatter, µm².
    variance_um2: f64,
    /// This cell's half of the variance of the predicted reversal at its
    /// target (the first test's x̄↑ − x̄↓, interpolated), µm²: a reversal
    /// found is the change since the first test, uncertain by both tests.
    reversal_prediction_variance_um2: f64,
}

/// One per-target level (both directions pooled): the position-dependent part.
#[derive(Clone, Copy, Debug)]
struct Level {
    target_index: usize,
    target_mm: f64,
    value_um: f64,
    /// Variance of the level from the re-test's scatter alone, µm².
    scatter_variance_um2: f64,
    /// Its total variance, scatter plus prediction, µm².
    variance_um2: f64,
}

/// Diagnoses a re-test.
pub fn diagnose(input: &DiagnoseInput<'_>) -> Result<Diagnosis, DiagnoseError> {
    let (problem, time_assumed) = problem(input)?;
    let y: Vec<f64> = problem
        .measured_um
        .iter()
        .zip(&problem.predicted_um)
        .map(|(m, p)| m - p)
        .collect();
    let n = y.len();
    let mut rejected: Vec<RejectedEffect> = Vec::new();
    let kinds = applicable_kinds(input, &mut rejected);
    let with_prediction = input.before.is_some();

    // 1. Between runs (drift, outlier runs) on the readings, one level per cell.
    let (between, between_fit) = select_between_runs(&problem, &y, &kinds, &mut rejected);
    let between_model = between.iter().fold(problem.cell_design.clone(), |d, c| {
        d.with(&problem.columns(c.shape))
    });
    let cells = cell_levels(&problem, &between_fit);
    let folds = cross_validation_folds(&problem, &y, &between_model, &between);

    // 2. The reversal: the same difference between the directions at every target.
    let (reversal, reversal_p) = select_reversal(&problem, &cells, &folds, &kinds, &mut rejected);
    let reversal_b = reversal.map_or(0.0, |r| r.b_um);
    let context = context(input, time_assumed);
    // With a first test the prediction carries its reversal: a reversal found is a change.
    if let (None, Some(before_um)) = (&reversal, context.first_test_reversal_um)
        && let Some(entry) = rejected.iter_mut().find(|r| r.kind == Kind::Reversal)
    {
        entry.why = format!(
            "no change since the first test, whose B̄ = {before_um:.2} µm the prediction carries ({})",
            entry.why
        );
    }

    // 3. Along the axis (scale, periodic, Abbe) on the pooled per-target levels, with a prediction only.
    let levels = target_levels(&problem, &cells);
    // Without a prediction only a periodic error is looked for there, in the test's own curve.
    let background = if with_prediction {
        Background::Constant
    } else {
        Background::Smooth
    };
    let (along, along_fit) = select_along_axis(
        &problem,
        &levels,
        &folds,
        reversal_b,
        &kinds,
        background,
        &mut rejected,
    );
    let along_p = chi2_p(along_fit.chi2, levels.len().saturating_sub(along_fit.rank));

    let mut accepted: Vec<AcceptedEffect> = Vec::new();
    if let Some(r) = reversal {
        let effect = Effect::Reversal(Reversal { b_um: r.b_um });
        accepted.push(AcceptedEffect {
            explanation: effect.explanation(&context),
            effect,
            uncertainty: vec![("B_um", r.standard_error_um)],
            evidence: r.evidence,
            warnings: Vec::new(),
        });
    }
    for c in &between {
        accepted.push(accepted_effect(
            *c,
            &between_fit.coefficients,
            &between_fit.standard_errors,
            &problem,
            &context,
            n,
        ));
    }
    for c in &along {
        accepted.push(accepted_effect(
            *c,
            &along_fit.coefficients,
            &along_fit.standard_errors,
            &problem,
            &context,
            levels.len(),
        ));
    }

    // The model: per target, the level along the axis (with a prediction: the constant and the
    // effects along the axis; without: the re-test's own level), ±B/2 by direction, and the
    // between-runs effects of each reading. The scatter is what the cells leave.
    let mut level_at_target = vec![0.0; problem.targets_mm.len()];
    let mut model_at_target = vec![0.0; problem.targets_mm.len()];
    for (level, fitted) in levels.iter().zip(&along_fit.fitted) {
        level_at_target[level.target_index] = level.value_um;
        model_at_target[level.target_index] = if with_prediction {
            *fitted
        } else {
            level.value_um
        };
    }
    let half_reversal = |d: Direction| d.reversal_share(reversal_b);
    let between_um: Vec<f64> = (0..n)
        .map(|i| {
            between
                .iter()
                .map(|c| problem.contribution(c, &between_fit.coefficients, i))
                .sum()
        })
        .collect();
    let scatter: Vec<f64> = y
        .iter()
        .zip(&between_fit.fitted)
        .map(|(v, f)| v - f)
        .collect();
    let model_um: Vec<f64> = problem
        .readings
        .iter()
        .enumerate()
        .map(|(i, r)| model_at_target[r.target_index] + half_reversal(r.direction) + between_um[i])
        .collect();
    let residual_after: Vec<f64> = y.iter().zip(&model_um).map(|(v, m)| v - m).collect();
    let residual_before: Vec<f64> = if with_prediction {
        let mean = y.iter().sum::<f64>() / n as f64;
        y.iter().map(|v| v - mean).collect()
    } else {
        problem
            .readings
            .iter()
            .zip(&y)
            .map(|(r, v)| v - level_at_target[r.target_index])
            .collect()
    };
    let noise_um = (between_fit.rss / n.saturating_sub(between_fit.rank).max(1) as f64).sqrt();
    let unexplained = unexplained(
        &problem,
        &levels,
        &along_fit,
        &cells,
        reversal_b,
        along_p,
        reversal_p,
        with_prediction,
    );
    let figures = figures(input.after, &problem, |i, with_effects| {
        let r = &problem.readings[i];
        // Without effects this is only asked without a first test (see `figures`).
        let systematic = if with_effects {
            model_at_target[r.target_index] + half_reversal(r.direction) + between_um[i]
        } else {
            level_at_target[r.target_index]
        };
        problem.predicted_um[i] + systematic + scatter[i]
    })?;
    // A kind is either found or not: a second outlier run that fails a gate
    // after the first was accepted records a rejection of the same kind.
    rejected.retain(|r| !accepted.iter().any(|a| a.effect.kind() == r.kind));
    Ok(Diagnosis {
        predicted_from_first_test: with_prediction,
        residual_before: stats(&residual_before),
        accepted,
        rejected,
        residual_after: stats(&residual_after),
        figures,
        unexplained,
        noise_um,
        time_assumed,
        readings: problem
            .readings
            .iter()
            .zip(y.iter().zip(&model_um))
            .map(|(reading, (residual_um, fitted_um))| ReadingResidual {
                reading: *reading,
                residual_um: *residual_um,
                fitted_um: *fitted_um,
            })
            .collect(),
    })
}

/// Builds the readings, their prediction and its covariance, and the cells.
fn problem(input: &DiagnoseInput<'_>) -> Result<(Problem, bool), DiagnoseError> {
    let after = input.after;
    let (times, time_assumed) = times_h(after, input.timing);
    let first = match input.before {
        Some(before) => {
            // The doubts (machine names, units, ranges) are the caller's to
            // show: the CLI runs the same check with the file names.
            check_together(
                Pairing::BeforeAfter,
                &Input::measurement(before, "the first test"),
                &Input::measurement(after, "the re-test"),
            )?;
            let evaluation = evaluate(before);
            let known =
                KnownError::from_evaluation(&evaluation).ok_or(DiagnoseError::NoKnownError)?;
            Some((known, mean_variances(&evaluation)))
        }
        None if input.backlash_set => return Err(BacklashError::NoMeasuredReversal.into()),
        None => None,
    };
    let applied = Applied::with_backlash(
        input.table,
        first.as_ref().map(|(known, _)| known),
        input.backlash_set,
    )?;
    let first_test_prediction = match (input.before, &first) {
        (Some(before), Some((known, _))) => Some(
            with_scatter(before, &evaluate(before), |i, direction| {
                predicted_deviation_mm(known, applied, before.targets_mm()[i], direction)
            })
            .map_err(|e| DiagnoseError::Internal(e.to_string()))?,
        ),
        _ => None,
    };
    let mut readings = Vec::new();
    let mut measured_um = Vec::new();
    let mut predicted_um = Vec::new();
    for (run_index, run) in after.runs().iter().enumerate() {
        for (target_index, (value, &target_mm)) in
            run.deviations_mm.iter().zip(after.targets_mm()).enumerate()
        {
            let Some(value) = value else { continue };
            readings.push(Reading {
                target_index,
                target_mm,
                direction: run.direction,
                run: run.number,
                run_index,
                time_h: times[run_index][target_index],
            });
            measured_um.push(value * 1000.0);
            let predicted = first.as_ref().map_or(0.0, |(known, _)| {
                predicted_deviation_mm(known, applied, target_mm, run.direction) * 1000.0
            });
            predicted_um.push(predicted);
        }
    }
    if readings.len() < 4 || after.runs().len() < 2 {
        return Err(DiagnoseError::TooFewReadings(readings.len()));
    }
    let (prediction_weights, first_test_variance_um2, first_test_reversal_variance_um2) =
        match &first {
            Some((_, variances)) => (
                after
                    .targets_mm()
                    .iter()
                    .map(|&x| interpolation_weights(&variances.positions_mm, x))
                    .collect(),
                variances.mean_um2.clone(),
                variances.reversal_um2.clone(),
            ),
            None => (
                vec![Vec::new(); after.targets_mm().len()],
                Vec::new(),
                Vec::new(),
            ),
        };
    let mut cells: Vec<(usize, Direction)> = Vec::new();
    for t in 0..after.targets_mm().len() {
        for direction in Direction::BOTH {
            if readings
                .iter()
                .any(|r| r.target_index == t && r.direction == direction)
            {
                cells.push((t, direction));
            }
        }
    }
    let cell_design = Design {
        columns: cells
            .iter()
            .map(|(t, d)| {
                readings
                    .iter()
                    .map(|r| f64::from(u8::from(r.target_index == *t && r.direction == *d)))
                    .collect()
            })
            .collect(),
    };
    let angle_urad = input.angular.map(|profile| {
        after
            .targets_mm()
            .iter()
            .map(|&x| interpolate_hold(&profile.positions_mm, &profile.angle_urad, x))
            .collect()
    });
    let problem = Problem {
        readings,
        measured_um,
        predicted_um,
        prediction_weights,
        first_test_prediction,
        first_test_variance_um2,
        first_test_reversal_variance_um2,
        run_count: after.runs().len(),
        targets_mm: after.targets_mm().to_vec(),
        angle_urad,
        cells,
        cell_design,
    };
    Ok((problem, time_assumed))
}

/// The first test's uncertainty, per target where it has a mean.
struct FirstTestVariances {
    /// The targets, mm.
    positions_mm: Vec<f64>,
    /// Variance of the bidirectional mean, µm².
    mean_um2: Vec<f64>,
    /// Variance of the reversal x̄↑ − x̄↓, µm².
    reversal_um2: Vec<f64>,
}

/// Variance of the first test's means at each of its targets, µm²: of the
/// bidirectional mean σ²·(1/n↑ + 1/n↓)/4 and of the reversal σ²·(1/n↑ + 1/n↓),
/// or, for a unidirectional test, of its one direction's mean σ²/n and no
/// reversal; σ pooled over all targets and directions (each target's own s
/// rests on a handful of readings and would make the weights as noisy as the
/// data). The targets are those of `KnownError::from_evaluation`.
fn mean_variances(evaluation: &Evaluation) -> FirstTestVariances {
    let both = evaluation.runs_up > 0 && evaluation.runs_down > 0;
    let pooled_um2 = evaluation
        .pooled_variance_mm2()
        .map_or(0.0, crate::units::mm2_to_um2);
    let inverse = |n: usize| if n == 0 { 0.0 } else { 1.0 / n as f64 };
    let mut variances = FirstTestVariances {
        positions_mm: Vec::new(),
        mean_um2: Vec::new(),
        reversal_um2: Vec::new(),
    };
    for t in &evaluation.per_target {
        let has_mean = if both {
            t.mean_mm.is_some()
        } else {
            t.up.mean_mm.or(t.down.mean_mm).is_some()
        };
        if !has_mean {
            continue;
        }
        let sum_of_inverses = inverse(t.up.n) + inverse(t.down.n);
        variances.positions_mm.push(t.target_mm);
        if both {
            variances.mean_um2.push(pooled_um2 * sum_of_inverses / 4.0);
            variances.reversal_um2.push(pooled_um2 * sum_of_inverses);
        } else {
            variances.mean_um2.push(pooled_um2 * sum_of_inverses);
            variances.reversal_um2.push(0.0);
        }
    }
    variances
}

/// The weights with which the prediction at `x` combines the first test's
/// means: a row of the not-a-knot spline basis (as `KnownError::at`
/// interpolates), as (index, weight) pairs.
fn interpolation_weights(positions: &[f64], x: f64) -> Vec<(usize, f64)> {
    crate::spline::basis_matrix(positions, &[x])
        .into_iter()
        .enumerate()
        .filter(|(_, w)| *w != 0.0)
        .collect()
}

/// Reading times in hours from the cycle model, scaled to the recorded
/// duration when the file records one that differs from the model's by more
/// than its one-minute resolution.
fn times_h(measurement: &Measurement, timing: CycleTiming) -> (Vec<Vec<f64>>, bool) {
    let seconds = cycle::reading_times(measurement, timing);
    let model = cycle::duration_s(&seconds);
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

/// The kinds that can be looked for here; the others go to `rejected` with the reason.
fn applicable_kinds(input: &DiagnoseInput<'_>, rejected: &mut Vec<RejectedEffect>) -> Vec<Kind> {
    let after = input.after;
    let mut kinds = Vec::new();
    for &kind in Kind::ALL {
        let reason = match kind {
            Kind::Reversal if after.run_count(Direction::Up) == 0 || after.run_count(Direction::Down) == 0 => {
                Some("needs runs in both directions".to_string())
            }
            Kind::Scale | Kind::Abbe if input.before.is_none() => Some(
                "needs a prediction (--before and --table): in a test alone a position-dependent error is part of the systematic curve the table compensates".to_string(),
            ),
            Kind::Abbe if input.angular.is_none() => Some("needs the axis' angular error along the stroke (--angular)".to_string()),
            Kind::Periodic if period_range(after.targets_mm(), min_periods(input)).is_none() => Some(format!(
                "the targets are too coarse to resolve a period shorter than 1/{} of the measured span",
                min_periods(input)
            )),
            Kind::OutlierRun if after.run_count(Direction::Up) < 3 && after.run_count(Direction::Down) < 3 => {
                Some("needs at least 3 runs in a direction to tell one apart".to_string())
            }
            _ => None,
        };
        match reason {
            Some(why) => rejected.push(RejectedEffect { kind, why }),
            None => kinds.push(kind),
        }
    }
    kinds
}

/// How many periods the span must hold: fewer against a prediction (a
/// constant background) than in a test's own curve (a smooth background).
fn min_periods(input: &DiagnoseInput<'_>) -> f64 {
    if input.before.is_some() {
        MIN_PERIODS_IN_SPAN
    } else {
        MIN_PERIODS_IN_CURVE
    }
}

/// The periods a periodic error is looked for at: from twice the median target
/// spacing to the span / `min_periods` ([`MIN_PERIODS_IN_SPAN`] against a
/// prediction, [`MIN_PERIODS_IN_CURVE`] in a test's own curve).
fn period_range(targets_mm: &[f64], min_periods: f64) -> Option<(f64, f64)> {
    if targets_mm.len() < 8 {
        return None;
    }
    let mut gaps: Vec<f64> = targets_mm.windows(2).map(|p| p[1] - p[0]).collect();
    gaps.sort_by(f64::total_cmp);
    let median = gaps[gaps.len() / 2];
    let span = targets_mm[targets_mm.len() - 1] - targets_mm[0];
    let (shortest, longest) = (2.0 * median, span / min_periods);
    (shortest < longest).then_some((shortest, longest))
}

/// The shapes of a kind to try.
fn shapes(
    kind: Kind,
    after_targets: &[f64],
    periods: Option<(f64, f64)>,
    runs: &[Run],
    chosen: &[Chosen],
) -> Vec<Shape> {
    match kind {
        Kind::Periodic => {
            let Some((shortest, longest)) = periods else {
                return Vec::new();
            };
            let span = after_targets[after_targets.len() - 1] - after_targets[0];
            // Frequencies 5 times finer than 1/span; the best is refined afterwards.
            let step = 1.0 / (5.0 * span);
            let mut frequency = 1.0 / longest;
            let mut list = Vec::new();
            while frequency <= 1.0 / shortest {
                list.push(Shape::Period(1.0 / frequency));
                frequency += step;
            }
            list
        }
        Kind::OutlierRun => {
            let count = |d: Direction| runs.iter().filter(|r| r.direction == d).count();
            runs.iter()
                .filter(|run| count(run.direction) >= 3)
                .map(|run| Shape::Run(run.direction, run.number))
                .filter(|shape| !chosen.iter().any(|c| c.shape == *shape))
                .collect()
        }
        kind => vec![Shape::Fixed(kind)],
    }
}

/// Tries every shape and returns the one with the lowest score; a period is
/// refined around the best, within the period range.
fn best_of<T>(
    shapes: &[Shape],
    range: Option<(f64, f64)>,
    mut score: impl FnMut(Shape) -> (f64, T),
) -> Option<(Shape, f64, T)> {
    let mut best: Option<(Shape, f64, T)> = None;
    for shape in shapes {
        let (value, extra) = score(*shape);
        if best.as_ref().is_none_or(|b| value < b.1) {
            best = Some((*shape, value, extra));
        }
    }
    if let (
        Some((Shape::Period(period), _, _)),
        Some((shortest, longest)),
        [Shape::Period(a), Shape::Period(b), ..],
    ) = (&best, range, shapes)
    {
        let step = (1.0 / b - 1.0 / a).abs();
        let centre = 1.0 / period;
        for k in -10..=10 {
            let frequency = centre + f64::from(k) * step / 10.0;
            if frequency < 1.0 / longest || frequency > 1.0 / shortest {
                continue;
            }
            let shape = Shape::Period(1.0 / frequency);
            let (value, extra) = score(shape);
            if best.as_ref().is_none_or(|b| value < b.1) {
                best = Some((shape, value, extra));
            }
        }
    }
    best
}

/// The first gate: the BIC drops by at least [`MIN_DELTA_BIC`] (with the
/// look-elsewhere term already in `delta`); records why not.
fn strong_evidence(rejected: &mut Vec<RejectedEffect>, kind: Kind, delta: f64) -> bool {
    let strong = delta <= -MIN_DELTA_BIC;
    if !strong {
        let change = if delta < 0.0 {
            format!("the BIC drops by {:.1}", -delta)
        } else {
            format!("the BIC rises by {delta:.1}")
        };
        set_rejection(
            rejected,
            kind,
            format!("not enough evidence: {change}, a drop of {MIN_DELTA_BIC} is needed"),
        );
    }
    strong
}

/// The second gate: the runs left out of the fit are predicted better with
/// the effect than without (leave-one-run-out RMSE, µm); records why not.
fn predicts_better(
    rejected: &mut Vec<RejectedEffect>,
    kind: Kind,
    cv_with: f64,
    cv_without: f64,
) -> bool {
    let better = cv_with < cv_without;
    if !better {
        set_rejection(
            rejected,
            kind,
            format!(
                "improves the fit but not the prediction of runs it was not fitted on ({cv_with:.3} µm vs {cv_without:.3} µm)"
            ),
        );
    }
    better
}

fn set_rejection(rejected: &mut Vec<RejectedEffect>, kind: Kind, why: String) {
    match rejected.iter_mut().find(|r| r.kind == kind) {
        Some(existing) => existing.why = why,
        None => rejected.push(RejectedEffect { kind, why }),
    }
}

/// The mean reversal B̄ of the first test, µm, when it measured both directions.
fn first_test_reversal_um(input: &DiagnoseInput<'_>) -> Option<f64> {
    let before = input.before?;
    let known = KnownError::from_evaluation(&evaluate(before))?;
    known
        .is_bidirectional()
        .then(|| crate::units::mm_to_um(known.mean_reversal_mm()))
}

fn context(input: &DiagnoseInput<'_>, time_assumed: bool) -> Context {
    let material = |m: &Measurement| m.environment.material_temperature_c[0].start;
    let material_change_k = match (input.before, material(input.after)) {
        (Some(before), Some(after)) => material(before).map(|b| after - b),
        _ => None,
    };
    Context {
        table_step_mm: input.table.and_then(CompensationTable::regular_step_mm),
        target_spacing_mm: crate::compensate::regular_step(input.after.targets_mm()),
        expansion_coefficient_ppm_per_k: input.after.environment.expansion_coefficient_ppm_per_k,
        material_change_k,
        time_assumed,
        first_test_reversal_um: first_test_reversal_um(input),
    }
}

fn accepted_effect(
    chosen: Chosen,
    coefficients: &[f64],
    errors: &[f64],
    problem: &Problem,
    context: &Context,
    n: usize,
) -> AcceptedEffect {
    let width = match chosen.shape {
        Shape::Period(_) => 2,
        _ => 1,
    };
    let coefficients = &coefficients[chosen.first_column..chosen.first_column + width];
    let errors = &errors[chosen.first_column..chosen.first_column + width];
    let effect = Effect::from_fit(chosen.shape, coefficients, &problem.line());
    let (uncertainty, mut warnings) = effect.uncertainty(&FitSummary {
        coefficients,
        errors,
        span_mm: problem.targets_mm[problem.targets_mm.len() - 1] - problem.targets_mm[0],
        n,
        target_spacing_mm: context.target_spacing_mm,
    });
    if context.time_assumed && effect.kind() == Kind::Drift {
        warnings.push("the file records no test duration: times assume a typical cycle (3 s dwell, 2000 mm/min)".to_string());
    }
    AcceptedEffect {
        explanation: effect.explanation(context),
        effect,
        uncertainty,
        evidence: chosen.evidence,
        warnings,
    }
}

fn stats(values: &[f64]) -> ResidualStats {
    let n = values.len().max(1) as f64;
    ResidualStats {
        rms_um: (values.iter().map(|v| v * v).sum::<f64>() / n).sqrt(),
        max_abs_um: values.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
    }
}

/// The structure left: along the axis (the levels against the model, with a
/// prediction) and between the directions (reversals that are not one B).
#[allow(clippy::too_many_arguments)]
fn unexplained(
    problem: &Problem,
    levels: &[Level],
    along_fit: &WeightedFit,
    cells: &[Cell],
    reversal_b: f64,
    along_p: f64,
    reversal_p: f64,
    with_prediction: bool,
) -> Unexplained {
    let along_significant = with_prediction && along_p < LACK_OF_FIT_P;
    let reversal_significant = reversal_p < LACK_OF_FIT_P;
    let mut flagged: Vec<(f64, f64)> = Vec::new();
    if along_significant {
        for (l, f) in levels.iter().zip(&along_fit.fitted) {
            let z = (l.value_um - f) / l.variance_um2.max(1e-300).sqrt();
            if z.abs() > 3.0 {
                flagged.push((l.target_mm, z.abs()));
            }
        }
    }
    if reversal_significant {
        for (t, d, v) in reversals(cells) {
            let z = (d - reversal_b) / v.max(1e-300).sqrt();
            if z.abs() > 3.0 {
                flagged.push((problem.targets_mm[t], z.abs()));
            }
        }
    }
    flagged.sort_by(|a, b| b.1.total_cmp(&a.1));
    flagged.dedup_by(|a, b| a.0 == b.0);
    flagged.truncate(10);
    let mut where_mm: Vec<f64> = flagged.into_iter().map(|(x, _)| x).collect();
    where_mm.sort_by(f64::total_cmp);
    where_mm.dedup();
    let rms_um = if with_prediction {
        let squares: f64 = levels
            .iter()
            .zip(&along_fit.fitted)
            .map(|(l, f)| (l.value_um - f).powi(2))
            .sum();
        (squares / levels.len().max(1) as f64).sqrt()
    } else {
        let differences = reversals(cells);
        let squares: f64 = differences
            .iter()
            .map(|(_, d, _)| (d - reversal_b).powi(2) / 4.0)
            .sum();
        (squares / differences.len().max(1) as f64).sqrt()
    };
    Unexplained {
        significant: along_significant || reversal_significant,
        p_value: if with_prediction {
            along_p.min(reversal_p)
        } else {
            reversal_p
        },
        where_mm,
        rms_um,
    }
}

/// ISO figures of the re-test as measured, as predicted and as predicted with
/// the effects; `value(i, with_effects)` gives reading i of the model (µm,
/// with the measured scatter, so A and R stay comparable).
fn figures(
    after: &Measurement,
    problem: &Problem,
    value: impl Fn(usize, bool) -> f64,
) -> Result<FigureSet, DiagnoseError> {
    let build = |with_effects: bool| -> Result<Measurement, DiagnoseError> {
        let mut runs: Vec<Run> = after
            .runs()
            .iter()
            .map(|run| Run {
                deviations_mm: vec![None; after.targets_mm().len()],
                ..run.clone()
            })
            .collect();
        for (i, reading) in problem.readings.iter().enumerate() {
            runs[reading.run_index].deviations_mm[reading.target_index] =
                Some(value(i, with_effects) / 1000.0);
        }
        Measurement::new(
            after.axis(),
            after.targets_mm().to_vec(),
            runs,
            after.environment.clone(),
            after.metadata.clone(),
        )
        .map_err(|e| DiagnoseError::Internal(e.to_string()))
    };
    let predicted = match &problem.first_test_prediction {
        Some(prediction) => evaluate(prediction).figures,
        None => evaluate(&build(false)?).figures,
    };
    Ok(FigureSet {
        measured: evaluate(after).figures,
        predicted,
        predicted_with_effects: evaluate(&build(true)?).figures,
    })
}
