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
//!    1995), plus 2·ln(trials) when its shape was chosen among many (runs, or
//!    the independent periods of a least-squares periodogram, `periodogram`:
//!    the look-elsewhere effect), and predicts the runs it was not fitted on
//!    better (leave-one-run-out). Several can be accepted.
//! 6. **Never the nearest kind.** A position-dependent effect must be the same
//!    along the whole axis (its parameters on the two halves of the span agree
//!    within their uncertainties and, for a period, the period's, p ≥
//!    [`LACK_OF_FIT_P`]), and after selection the per-target levels must be
//!    explained (χ² lack of fit p ≥ [`LACK_OF_FIT_P`]); otherwise the
//!    position-dependent effects are moved to `rejected` and the structure is
//!    reported as unexplained, with where and how large.
//!
//! Pure: values in, values out.

mod along_axis;
mod angular_profile;
mod between_runs;
mod covariance;
mod findings;
pub mod fit;
pub mod friction;
mod gates;
mod levels;
mod periodogram;
mod problem;
mod selection;
mod stats;
pub mod thermal;
mod trig_sums;
mod unexplained;

pub use angular_profile::AngularProfile;

use crate::compensate::CompensateError;
use crate::compensate::CompensationTable;
use crate::cycle::CycleTiming;
use crate::effects::{
    Context, Effect, EffectIn, FileEntry, Kind, PeriodicIn, Reading, Reversal, Shape, held_angle,
    position_as_deviation, reversal,
};
use crate::evaluate::{AxisFigures, Standard, StandardFigure, StandardUsed};
use crate::measurement::{AxisKind, ByKind, Direction, Measurement};
use crate::together::NotTogether;
use crate::units::{Deg, Mm, Um};
use along_axis::{AlongAxisSelection, Background, select_along_axis};
use between_runs::{select_between_runs, select_reversal};
use findings::{accepted_effect, context, figures, stats};
use gates::applicable_kinds;
use levels::{cell_levels, cross_validation_folds, target_levels};
use problem::problem;
use stats::chi2_p;
use unexplained::unexplained;

/// Minimum drop of the BIC for an effect to be accepted.
pub const MIN_DELTA_BIC: f64 = 6.0;
/// Below this p-value a model lacks fit, or an effect is not the same along the axis.
pub const LACK_OF_FIT_P: f64 = 0.001;
/// A periodic error must fit at least this many periods in the measured span.
pub const MIN_PERIODS_IN_SPAN: f64 = 2.0;
/// On irregular targets, periods down to this are looked for (unless twice
/// the median spacing is shorter): the short screw leads of machine-tool feed
/// drives (5 mm and up); a shorter lead or scale period is looked for when the
/// machine profile gives it ([`KnownPeriod`]).
pub const SHORTEST_PERIOD_MM: f64 = 5.0;
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
    /// Periods the axis is known to have (its screw lead, its scale period:
    /// the machine profile's, mm), looked for before the scan of every
    /// period; a linear axis' only (a rotary axis' are whole orders per
    /// revolution, and these are not used there).
    pub known_periods: &'a [KnownPeriod],
    /// Cycle timing to assume when the file records no duration.
    pub timing: CycleTiming,
    /// The standard whose figures the diagnosis reports
    /// ([`Diagnosis::standard_figures`]); the statistics do not depend on it.
    pub standard: &'a dyn Standard,
    /// The unit the sentences say a rotary axis' deviations in (″ or µrad;
    /// `--angle-unit`); the numbers of the diagnosis stay in m°.
    pub angle: crate::units::AngleUnit,
}

/// A period the machine's axis is known to have, from its drive or its scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnownPeriod {
    /// mm.
    pub period_mm: f64,
    /// What has this period.
    pub source: PeriodSource,
}

/// What a known period belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeriodSource {
    /// The ball screw's lead (one revolution).
    ScrewLead,
    /// The linear scale's or rotary encoder's period on the axis.
    ScalePeriod,
}

impl KnownPeriod {
    /// The screw lead, mm.
    pub fn screw_lead(period_mm: f64) -> KnownPeriod {
        KnownPeriod {
            period_mm,
            source: PeriodSource::ScrewLead,
        }
    }

    /// The scale's (or encoder's) period along the axis, mm.
    pub fn scale_period(period_mm: f64) -> KnownPeriod {
        KnownPeriod {
            period_mm,
            source: PeriodSource::ScalePeriod,
        }
    }

    /// Its name in a sentence.
    pub fn name(self) -> &'static str {
        match self.source {
            PeriodSource::ScrewLead => "the screw lead",
            PeriodSource::ScalePeriod => "the scale period",
        }
    }
}

/// RMS and largest |value| of a residual, in `D`: in a [`Diagnosis`] a bare
/// number in the diagnosis' deviation unit (µm, or m° on a rotary axis),
/// typed by [`Diagnosis::typed`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResidualStats<D = f64> {
    /// Root mean square.
    pub rms: D,
    /// Largest absolute value.
    pub max_abs: D,
}

impl<D> ResidualStats<D> {
    /// The same converted by `convert` (`Deg::to_arcsec`, …).
    pub fn map<E>(self, convert: fn(D) -> E) -> ResidualStats<E> {
        ResidualStats {
            rms: convert(self.rms),
            max_abs: convert(self.max_abs),
        }
    }
}

/// Why an accepted effect was accepted; its prediction errors in `D` (as
/// [`ResidualStats`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evidence<D = f64> {
    /// Change of the BIC when it was added (negative is better).
    pub delta_bic: f64,
    /// How many independent shapes were tried (runs, periods searched), 1 otherwise.
    pub trials: usize,
    /// p-value of adding it (partial F-test, or χ² with known variances), as
    /// the chance that the best of `trials` shapes of noise fits as well.
    pub p_value: f64,
    /// Leave-one-run-out prediction error without it.
    pub cv_rmse_without: D,
    /// The same with it.
    pub cv_rmse_with: D,
}

impl<D> Evidence<D> {
    /// The same with its prediction errors converted by `convert`.
    pub fn map<E>(self, convert: fn(D) -> E) -> Evidence<E> {
        Evidence {
            delta_bic: self.delta_bic,
            trials: self.trials,
            p_value: self.p_value,
            cv_rmse_without: convert(self.cv_rmse_without),
            cv_rmse_with: convert(self.cv_rmse_with),
        }
    }
}

/// An effect found in the residual.
#[derive(Clone, Debug, PartialEq)]
pub struct AcceptedEffect {
    /// The effect and its parameters.
    pub effect: Effect,
    /// Standard uncertainty of each parameter, by its key
    /// (`effects::Parameter::key`), in the parameter's unit; typed with the
    /// parameters by [`Effect::typed`] ([`DiagnosisIn::effects`]).
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

/// Structure left after the accepted effects: targets in `P` (in a
/// [`Diagnosis`] bare, in the axis' unit: mm or °), its size in `D` (as
/// [`ResidualStats`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Unexplained<P = f64, D = f64> {
    /// Whether it is significant (lack-of-fit p < [`LACK_OF_FIT_P`]).
    pub significant: bool,
    /// p-value of the lack-of-fit test.
    pub p_value: f64,
    /// Targets where it is largest (|mean residual| > 3 standard errors).
    pub targets: Vec<P>,
    /// RMS of the per-target mean residual.
    pub rms: D,
}

impl<P, D> Unexplained<P, D> {
    /// The same with its targets converted by `position` and its size by
    /// `deviation`.
    pub fn map<Q, E>(self, position: fn(P) -> Q, deviation: fn(D) -> E) -> Unexplained<Q, E> {
        Unexplained {
            significant: self.significant,
            p_value: self.p_value,
            targets: self.targets.into_iter().map(position).collect(),
            rms: deviation(self.rms),
        }
    }
}

/// The figures of the re-test as measured and as the model predicts it:
/// ISO 230-2:2014's ([`AxisFigures`]) or a standard's, keyed
/// (`Vec<StandardFigure>`).
#[derive(Clone, Debug, PartialEq)]
pub struct FigureSet<F = AxisFigures> {
    /// As measured.
    pub measured: F,
    /// Predicted by the model, as `predict` gives them: the first test's
    /// readings with the predicted systematic error (so the first test's
    /// scatter and R). Without a first test: the re-test's own systematic
    /// curve with its scatter.
    pub predicted: F,
    /// What the prediction with the accepted effects explains of this
    /// re-test: its systematic part with this re-test's scatter.
    pub predicted_with_effects: F,
}

/// The diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnosis {
    /// Linear or rotary. The numbers below are bare, in the diagnosis'
    /// units: deviations (residuals, noise, prediction errors) in µm, or m°
    /// (1/1000 °) on a rotary axis; positions in mm, or °. They leave typed
    /// by this kind through [`Diagnosis::typed`].
    pub kind: AxisKind,
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
    /// ISO 230-2:2014 figures.
    pub figures: FigureSet,
    /// The same re-tests' figures as [`DiagnoseInput::standard`] reports them.
    pub standard_figures: FigureSet<Vec<StandardFigure>>,
    /// That standard.
    pub standard: StandardUsed,
    /// What none of the effects explains.
    pub unexplained: Unexplained,
    /// Scatter of one reading left at the end (µm, or m°).
    pub noise: f64,
    /// Whether reading times were assumed from a typical cycle (a drift is
    /// then per run).
    pub time_assumed: bool,
    /// One run's mean duration on the clock of the readings' `time_h`, h.
    pub run_h: f64,
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

/// One reading of the re-test and what the diagnosis made of it, its
/// deviations in `D` (as [`ResidualStats`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadingResidual<D = f64> {
    /// Where, in which direction and run, and when it was taken.
    pub reading: Reading,
    /// Measured − predicted.
    pub residual: D,
    /// The fitted model of the residual there: the level along the axis, the
    /// reversal and the between-runs effects.
    pub fitted: D,
}

impl<D> ReadingResidual<D> {
    /// The same with its deviations converted by `convert`.
    pub fn map<E>(self, convert: fn(D) -> E) -> ReadingResidual<E> {
        ReadingResidual {
            reading: self.reading,
            residual: convert(self.residual),
            fitted: convert(self.fitted),
        }
    }
}

/// What of a [`Diagnosis`] has a unit, with the unit as a type: positions in
/// `P`, deviations in `D` ([`Diagnosis::typed`]: `Mm` and `Um` on a linear
/// axis, `Deg` and `Deg` on a rotary one).
#[derive(Clone, Debug, PartialEq)]
pub struct DiagnosisIn<P, D> {
    /// The model's error before adding effects.
    pub residual_before: ResidualStats<D>,
    /// The model's error with the effects.
    pub residual_after: ResidualStats<D>,
    /// Scatter of one reading left at the end.
    pub noise: D,
    /// Why each accepted effect was accepted, in the order of
    /// [`Diagnosis::accepted`].
    pub evidence: Vec<Evidence<D>>,
    /// Each accepted effect's parameters that are positions or deviations,
    /// with their uncertainties ([`Effect::typed`]), in the same order;
    /// `None` for a kind that has none (scale, drift, Abbe).
    pub effects: Vec<Option<EffectIn<P, D>>>,
    /// What none of the effects explains.
    pub unexplained: Unexplained<P, D>,
    /// Every reading of the re-test, as [`Diagnosis::readings`].
    pub readings: Vec<ReadingResidual<D>>,
}

impl<P, D> DiagnosisIn<P, D> {
    /// The same with every deviation converted by `convert` (`Deg::to_arcsec`,
    /// `Deg::to_urad`): the function's type decides which unit it accepts.
    pub fn map_deviations<E>(self, convert: fn(D) -> E) -> DiagnosisIn<P, E> {
        DiagnosisIn {
            residual_before: self.residual_before.map(convert),
            residual_after: self.residual_after.map(convert),
            noise: convert(self.noise),
            evidence: self.evidence.into_iter().map(|e| e.map(convert)).collect(),
            effects: self
                .effects
                .into_iter()
                .map(|effect| effect.map(|effect| effect.map_deviations(convert)))
                .collect(),
            unexplained: self.unexplained.map(|place| place, convert),
            readings: self.readings.into_iter().map(|r| r.map(convert)).collect(),
        }
    }
}

impl Diagnosis {
    /// Its numbers with their units as types: on a linear axis positions in
    /// [`Mm`] and deviations in [`Um`], on a rotary one both in [`Deg`] (the
    /// deviations held in m°), and so are the accepted effects' parameters
    /// ([`DiagnosisIn::effects`]). A rotary axis' residual is no `Um`:
    /// ```
    /// # fn f(diagnosis: &axcomp::diagnose::Diagnosis) {
    /// use axcomp::units::Deg;
    /// if let Some(rotary) = diagnosis.typed().rotary() {
    ///     let rms: Deg = rotary.residual_after.rms;
    /// }
    /// # }
    /// ```
    /// ```compile_fail
    /// # fn f(diagnosis: &axcomp::diagnose::Diagnosis) {
    /// use axcomp::units::Um;
    /// if let Some(rotary) = diagnosis.typed().rotary() {
    ///     let rms: Um = rotary.residual_after.rms;
    /// }
    /// # }
    /// ```
    pub fn typed(&self) -> ByKind<DiagnosisIn<Mm, Um>, DiagnosisIn<Deg, Deg>> {
        match self.kind {
            AxisKind::Linear => ByKind::Linear(self.in_units(Mm, Um, ByKind::linear)),
            AxisKind::Rotary => ByKind::Rotary(self.in_units(Deg, held_angle, ByKind::rotary)),
        }
    }

    /// Its numbers with positions by `position`, deviations by `deviation`,
    /// and the effects' parameters in the branch `branch` takes of
    /// [`Effect::typed`] (the same units).
    fn in_units<P, D>(
        &self,
        position: fn(f64) -> P,
        deviation: fn(f64) -> D,
        branch: fn(TypedEffect) -> Option<EffectIn<P, D>>,
    ) -> DiagnosisIn<P, D> {
        DiagnosisIn {
            residual_before: self.residual_before.map(deviation),
            residual_after: self.residual_after.map(deviation),
            noise: deviation(self.noise),
            evidence: self
                .accepted
                .iter()
                .map(|accepted| accepted.evidence.map(deviation))
                .collect(),
            effects: self
                .accepted
                .iter()
                .map(|accepted| {
                    accepted
                        .effect
                        .typed(self.kind, &accepted.uncertainty)
                        .and_then(branch)
                })
                .collect(),
            unexplained: self.unexplained.clone().map(position, deviation),
            readings: self.readings.iter().map(|r| r.map(deviation)).collect(),
        }
    }
}

/// An effect's parameters typed by the axis' kind ([`Effect::typed`]).
type TypedEffect = ByKind<EffectIn<Mm, Um>, EffectIn<Deg, Deg>>;

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
    /// A table cannot be applied as said (the backlash parameter).
    #[error(transparent)]
    Compensate(#[from] CompensateError),
    /// The two tests (or the table) do not belong together: another axis,
    /// ranges without a common stretch, the same readings twice.
    #[error(transparent)]
    NotTogether(#[from] NotTogether),
    /// A measurement could not be rebuilt (a bug).
    #[error("{0}")]
    Internal(String),
}

/// Diagnoses a re-test.
pub fn diagnose(input: &DiagnoseInput<'_>) -> Result<Diagnosis, DiagnoseError> {
    let (problem, time_assumed) = problem(input)?;
    let y: Vec<f64> = problem
        .measured
        .iter()
        .zip(&problem.predicted)
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
    let reversal_b = reversal.map_or(0.0, |r| r.b);
    let context = context(input, time_assumed);

    // 3. Along the axis (scale, periodic, Abbe) on the pooled per-target levels, with a prediction only.
    let levels = target_levels(&problem, &cells);
    // Without a prediction only a periodic error is looked for there, in the test's own curve.
    let background = if with_prediction {
        Background::Constant
    } else {
        Background::Smooth
    };
    let AlongAxisSelection {
        chosen: along,
        fit: along_fit,
        aliases_mm,
    } = select_along_axis(
        &problem,
        &levels,
        &folds,
        reversal_b,
        &kinds,
        known_periods(input),
        background,
        &mut rejected,
    );
    let along_p = chi2_p(along_fit.chi2, levels.len().saturating_sub(along_fit.rank));

    let mut accepted: Vec<AcceptedEffect> = Vec::new();
    if let Some(r) = reversal {
        let effect = Effect::Reversal(Reversal { b: r.b });
        accepted.push(AcceptedEffect {
            explanation: effect.explanation(&context),
            effect,
            uncertainty: vec![(reversal::B_KEY, r.standard_error)],
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
        let mut effect = accepted_effect(
            *c,
            &along_fit.coefficients,
            &along_fit.standard_errors,
            &problem,
            &context,
            levels.len(),
        );
        if let Shape::Period(period, tests) = c.shape {
            effect.warnings.extend(period_notes(
                period,
                tests,
                &aliases_mm,
                known_periods(input),
            ));
        }
        accepted.push(effect);
    }

    // The model: per target, the level along the axis (with a prediction: the constant and the
    // effects along the axis; without: the re-test's own level), ±B/2 by direction, and the
    // between-runs effects of each reading. The scatter is what the cells leave.
    let mut level_at_target = vec![0.0; problem.targets.len()];
    let mut model_at_target = vec![0.0; problem.targets.len()];
    for (level, fitted) in levels.iter().zip(&along_fit.fitted) {
        level_at_target[level.target_index] = level.value;
        model_at_target[level.target_index] = if with_prediction {
            *fitted
        } else {
            level.value
        };
    }
    let half_reversal = |d: Direction| d.reversal_share(reversal_b);
    let between_values = problem.between_runs(&between, &between_fit.coefficients);
    let scatter: Vec<f64> = y
        .iter()
        .zip(&between_fit.fitted)
        .map(|(v, f)| v - f)
        .collect();
    let model: Vec<f64> = problem
        .readings
        .iter()
        .enumerate()
        .map(|(i, r)| {
            model_at_target[r.target_index] + half_reversal(r.direction) + between_values[i]
        })
        .collect();
    let residual_after: Vec<f64> = y.iter().zip(&model).map(|(v, m)| v - m).collect();
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
    let noise_level = (between_fit.rss / n.saturating_sub(between_fit.rank).max(1) as f64).sqrt();
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
    let (figures, standard_figures) = figures(input, &problem, |i, with_effects| {
        let r = &problem.readings[i];
        // Without effects this is only asked without a first test (see `figures`).
        let systematic = if with_effects {
            model_at_target[r.target_index] + half_reversal(r.direction) + between_values[i]
        } else {
            level_at_target[r.target_index]
        };
        problem.predicted[i] + systematic + scatter[i]
    })?;
    // The figures' B̄ (mm, or °) in the effects' unit (µm, or m°).
    let held = |value: f64| position_as_deviation(input.after.kind(), value);
    // The reversal's sentence says the B̄ the figures show; where the fitted
    // B differs from the change they show, it says why.
    if let (Some(predicted_b), Some(measured_b)) =
        (figures.predicted.b_mean, figures.measured.b_mean)
    {
        let context = Context {
            retest_mean_reversal: Some((held(predicted_b), held(measured_b))),
            ..context
        };
        let others: Vec<String> = accepted
            .iter()
            .filter(|a| {
                !matches!(a.effect, Effect::Reversal(_)) && !a.effect.kind().is_positional()
            })
            .map(|a| a.effect.model().label(&context, &|v| format!("{v:.2}")))
            .collect();
        for found in accepted.iter_mut() {
            let Effect::Reversal(reversal) = found.effect else {
                continue;
            };
            let shown = if with_prediction {
                held(measured_b - predicted_b)
            } else {
                held(measured_b)
            };
            found.explanation = found.effect.explanation(&context);
            if context.deviation(reversal.b) != context.deviation(shown) {
                let why = if others.is_empty() {
                    "it weighs each target by its readings, where B̄ is the plain mean of the targets' reversals".to_string()
                } else {
                    format!(
                        "it is fitted with the {} taken out, which the measured B̄ includes",
                        others.join(", ")
                    )
                };
                found.explanation.push_str(&format!(
                    " The fit's B = {} differs from that {}: {why}.",
                    context.deviation(reversal.b),
                    if with_prediction { "change" } else { "B̄" },
                ));
            }
        }
    }
    // With a first test the prediction carries its reversal (what the table
    // leaves of it): a reversal found is a change, and none found is none.
    if reversal.is_none()
        && let Some(first_reversal) = context.first_test_reversal
        && let Some(entry) = rejected.iter_mut().find(|r| r.kind == Kind::Reversal)
    {
        let predicted_reversal = figures.predicted.b_mean.map(held);
        entry.why = no_reversal_change(&context, first_reversal, predicted_reversal, &entry.why);
    }
    // A kind is either found or not: a second outlier run that fails a gate
    // after the first was accepted records a rejection of the same kind.
    rejected.retain(|r| !accepted.iter().any(|a| a.effect.kind() == r.kind));
    Ok(Diagnosis {
        kind: input.after.kind(),
        predicted_from_first_test: with_prediction,
        residual_before: stats(&residual_before),
        accepted,
        rejected,
        residual_after: stats(&residual_after),
        figures,
        standard_figures,
        standard: StandardUsed::of(input.standard),
        unexplained,
        noise: noise_level,
        time_assumed,
        run_h: problem.run_h,
        readings: problem
            .readings
            .iter()
            .zip(y.iter().zip(&model))
            .map(|(reading, (residual, fitted))| ReadingResidual {
                reading: *reading,
                residual: *residual,
                fitted: *fitted,
            })
            .collect(),
    })
}

/// Why no reversal is reported when the re-test's B̄ is the predicted one:
/// the first test's B̄ carried by the prediction, or, where the table took
/// some of it out (a bidirectional table), the B̄ the prediction is left with.
fn no_reversal_change(
    context: &Context,
    first_reversal: f64,
    predicted_reversal: Option<f64>,
    why: &str,
) -> String {
    let first = context.deviation(first_reversal);
    match predicted_reversal.map(|p| context.deviation(p)) {
        Some(predicted) if predicted != first => format!(
            "no change since the first test: its B̄ = {first} less what the table takes out leaves the B̄ = {predicted} the prediction carries ({why})"
        ),
        _ => format!(
            "no change since the first test, whose B̄ = {first} the prediction carries ({why})"
        ),
    }
}

/// The axis' known periods, a linear axis' only: they are lengths (a screw
/// lead, a scale period, mm), and a rotary axis' periods are whole orders
/// per revolution, in degrees.
fn known_periods<'a>(input: &DiagnoseInput<'a>) -> &'a [KnownPeriod] {
    match input.after.kind() {
        AxisKind::Linear => input.known_periods,
        AxisKind::Rotary => &[],
    }
}

/// What a user should know of a periodic error's period: that it is a known
/// period of the axis, and which periods the targets cannot tell from it.
/// `period` is in the axis' unit; a rotary axis' orders have no aliases and
/// no known periods (`known_periods`), so the sentences' mm are a linear axis'.
fn period_notes(
    period: f64,
    tests: PeriodicIn,
    aliases_mm: &[f64],
    known: &[KnownPeriod],
) -> Vec<String> {
    let mut notes = Vec::new();
    if tests == PeriodicIn::BothTests {
        notes.push("it is in both tests: the first test's targets sampled it without resolving it, and the prediction and the table carry those samples; the amplitude is the axis' whole periodic error".to_string());
    }
    let known_here = known.iter().find(|k| k.period_mm == period);
    if let Some(k) = known_here {
        notes.push(format!(
            "the period is {} the machine profile gives ({} mm), looked for first",
            k.name(),
            k.period_mm
        ));
    }
    if !aliases_mm.is_empty() {
        let list: Vec<String> = aliases_mm.iter().map(|p| format!("{p:.2} mm")).collect();
        let advice = if known_here.is_some() {
            "the profile's period was taken; re-measure at other irregular targets to confirm it"
        } else {
            "re-measure at other irregular targets, or give the axis' screw lead in the machine profile, to tell them apart"
        };
        notes.push(format!(
            "these targets cannot tell a period of {period:.2} mm from {} (the fits differ by less than a BIC of {MIN_DELTA_BIC}); {advice}",
            list.join(", ")
        ));
    }
    notes
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::effects::outlier_run::OutlierRun;
    use crate::evaluate::ISO_230_2;
    use crate::units::{Arcsec, Urad};

    /// Run 1↓ 10 µm (or m°, 0.01°) off the others, σ 1; its prediction
    /// error 1000 without it, 500 with it.
    pub(crate) fn outlier_run() -> AcceptedEffect {
        AcceptedEffect {
            effect: Effect::OutlierRun(OutlierRun {
                run: 1,
                direction: Direction::Down,
                offset: 10.0,
            }),
            uncertainty: vec![("offset_um", 1.0)],
            evidence: Evidence {
                delta_bic: -20.0,
                trials: 5,
                p_value: 0.001,
                cv_rmse_without: 1000.0,
                cv_rmse_with: 500.0,
            },
            explanation: String::new(),
            warnings: Vec::new(),
        }
    }

    /// A diagnosis of `kind` holding its deviations bare: 250 and 125 (µm,
    /// or m°) for the residual before, 62.5 and 31.25 after, noise 500, an
    /// outlier run's evidence 1000 → 500, unexplained structure at 90 and
    /// 180 (mm, or °) of rms 62.5, one reading of residual 250 fitted 125.
    fn held(kind: AxisKind) -> Diagnosis {
        let none = FigureSet {
            measured: AxisFigures::default(),
            predicted: AxisFigures::default(),
            predicted_with_effects: AxisFigures::default(),
        };
        Diagnosis {
            kind,
            predicted_from_first_test: true,
            residual_before: ResidualStats {
                rms: 250.0,
                max_abs: 125.0,
            },
            accepted: vec![outlier_run()],
            rejected: Vec::new(),
            residual_after: ResidualStats {
                rms: 62.5,
                max_abs: 31.25,
            },
            figures: none,
            standard_figures: FigureSet {
                measured: Vec::new(),
                predicted: Vec::new(),
                predicted_with_effects: Vec::new(),
            },
            standard: StandardUsed::of(&ISO_230_2),
            unexplained: Unexplained {
                significant: true,
                p_value: 1e-4,
                targets: vec![90.0, 180.0],
                rms: 62.5,
            },
            noise: 500.0,
            time_assumed: false,
            run_h: 0.5,
            readings: vec![ReadingResidual {
                reading: Reading {
                    target_index: 0,
                    target: 90.0,
                    direction: Direction::Up,
                    run: 1,
                    run_index: 0,
                    time_h: 0.0,
                },
                residual: 250.0,
                fitted: 125.0,
            }],
        }
    }

    #[test]
    fn a_linear_diagnosis_is_typed_in_mm_and_um_as_held() {
        let ByKind::Linear(typed) = held(AxisKind::Linear).typed() else {
            panic!("a linear diagnosis typed as rotary")
        };
        assert_eq!(
            typed.residual_before,
            ResidualStats {
                rms: Um(250.0),
                max_abs: Um(125.0)
            }
        );
        assert_eq!(typed.noise, Um(500.0));
        assert_eq!(typed.unexplained.targets, [Mm(90.0), Mm(180.0)]);
        assert_eq!(typed.unexplained.rms, Um(62.5));
        assert_eq!(
            (typed.readings[0].residual, typed.readings[0].fitted),
            (Um(250.0), Um(125.0))
        );
    }

    #[test]
    fn a_rotary_diagnosis_held_in_millidegrees_is_typed_in_degrees() {
        // 250 m° = 0.25° = 900″; 62.5 m° = 0.0625° = 225″; 1000 m° = 1° =
        // 3600″ = 10⁶·π/180 µrad; the places stay degrees.
        let ByKind::Rotary(typed) = held(AxisKind::Rotary).typed() else {
            panic!("a rotary diagnosis typed as linear")
        };
        assert_eq!(typed.residual_before.rms, Deg(0.25));
        assert_eq!(typed.residual_after.max_abs, Deg(0.03125));
        assert_eq!(typed.noise, Deg(0.5));
        assert_eq!(typed.unexplained.targets, [Deg(90.0), Deg(180.0)]);
        assert_eq!(
            (typed.readings[0].residual, typed.readings[0].fitted),
            (Deg(0.25), Deg(0.125))
        );
        let arcsec = typed.clone().map_deviations(Deg::to_arcsec);
        assert_eq!(
            arcsec.residual_before,
            ResidualStats {
                rms: Arcsec(900.0),
                max_abs: Arcsec(450.0)
            }
        );
        assert_eq!(arcsec.unexplained.rms, Arcsec(225.0));
        assert_eq!(
            (
                arcsec.evidence[0].cv_rmse_without,
                arcsec.evidence[0].cv_rmse_with,
                arcsec.evidence[0].trials
            ),
            (Arcsec(3600.0), Arcsec(1800.0), 5)
        );
        let urad = typed.map_deviations(Deg::to_urad);
        approx::assert_relative_eq!(
            urad.evidence[0].cv_rmse_without.0,
            1e6 * std::f64::consts::PI / 180.0,
            max_relative = 1e-15
        );
        let _: Urad = urad.noise;
    }
}
