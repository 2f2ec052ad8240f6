//! ISO 230-2 evaluation of a linear positioning test.
//!
//! In two parts, so that another standard is data beside the first rather
//! than a fork: [`targets`] the statistics of each target (n, x̄, s per
//! direction), [`standard`] what a standard derives from them (ISO 230-2:2014,
//! `../shared/spec/iso230-2.md`: B_i, R_i, and the axis figures A, E, M, R, B
//! and B̄). [`evaluate`] applies ISO 230-2; [`evaluate_with`] any [`Standard`].
//!
//! Undefined is `None`, never 0: a unidirectional test has no bidirectional
//! figures; with n = 1 run in a direction s, R and A are undefined there. An
//! axis figure is evaluated only when what it needs is defined at every
//! target; otherwise it is `None` and a warning names the target. Suspected
//! outlier runs are flagged ([`outliers`]) but stay in the figures.
//! [`environment`] checks the test conditions: the refractive index the laser
//! used against Edlén's equation. [`conformance`] checks the test itself
//! against ISO 230-2 (targets, runs, directions, spacing); its warnings come
//! first in [`Evaluation::warnings`]. A rotary axis is evaluated the same
//! way in degrees; [`rotary`] adds what ISO 230-2 asks of one (the n = 1
//! rule over 360°, the principal angles, the two ends of a full turn).
//!
//! Pure: no I/O, no printing. All lengths in mm, angles in degrees: the
//! statistics are bare numbers in the axis' unit, under names that say no
//! unit (`target`, `mean`, `a`, …: the unit is the axis'), and leave typed
//! by the axis' kind ([`TargetStats::typed`],
//! [`SuspectedOutlier::typed`], [`Evaluation::standard_figures_typed`],
//! [`crate::measurement::AxisKind::position`]).

pub mod conformance;
pub mod environment;
pub mod outliers;
pub mod rotary;
pub mod standard;
pub mod straightness;
pub mod targets;
pub mod uncertainty;
pub mod verdict;

use crate::error::Warning;
use crate::measurement::{AxisKind, Direction, Measurement};
pub use conformance::TestConformance;
use environment::{RefractiveIndexCheck, check_refractive_index};
pub use outliers::{OutlierIn, SuspectedOutlier};
pub use standard::{
    FiguresByKind, ISO_230_2, SUPPORTED, Standard, StandardFigure, UnknownStandard, by_name,
};
use targets::per_target_stats;
pub use targets::{DirectionStats, TargetIn, TargetStats};

/// The axis figures of ISO 230-2, in the axis' unit (mm, or ° on a rotary
/// axis); `None` where not evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisFigures {
    /// Bidirectional accuracy of positioning A.
    pub a: Option<f64>,
    /// Unidirectional accuracy A↑.
    pub a_up: Option<f64>,
    /// Unidirectional accuracy A↓.
    pub a_down: Option<f64>,
    /// Bidirectional systematic positional deviation E.
    pub e: Option<f64>,
    /// Unidirectional systematic positional deviation E↑.
    pub e_up: Option<f64>,
    /// Unidirectional systematic positional deviation E↓.
    pub e_down: Option<f64>,
    /// Mean bidirectional positional deviation M.
    pub m: Option<f64>,
    /// Bidirectional repeatability R = max R_i.
    pub r: Option<f64>,
    /// Unidirectional repeatability R↑ = max R_i↑.
    pub r_up: Option<f64>,
    /// Unidirectional repeatability R↓ = max R_i↓.
    pub r_down: Option<f64>,
    /// Reversal value B = max |B_i|.
    pub b: Option<f64>,
    /// Mean reversal value B̄ = mean of B_i (signed).
    pub b_mean: Option<f64>,
}

impl AxisFigures {
    /// The figures with their keys in `figures_um` and `--limit`, in order.
    pub fn keyed(&self) -> [(&'static str, Option<f64>); 12] {
        [
            ("A", self.a),
            ("A_up", self.a_up),
            ("A_down", self.a_down),
            ("E", self.e),
            ("E_up", self.e_up),
            ("E_down", self.e_down),
            ("M", self.m),
            ("R", self.r),
            ("R_up", self.r_up),
            ("R_down", self.r_down),
            ("B", self.b),
            ("B_mean", self.b_mean),
        ]
    }

    /// The figures under their keys, typed by the axis' kind: in
    /// [`crate::units::Mm`] on a linear axis, in [`crate::units::Deg`] on a
    /// rotary one ([`Evaluation::figures_typed`] asks the evaluation's kind).
    pub fn typed(&self, kind: AxisKind) -> FiguresByKind {
        standard::typed(
            &self
                .keyed()
                .map(|(key, value)| StandardFigure { key, value }),
            kind,
        )
    }
}

/// Which standard a test was evaluated to, as the reports name it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StandardUsed {
    /// The `--standard` name (`iso230-2:2014`, `vdi3441`).
    pub key: &'static str,
    /// Its name and edition.
    pub name: &'static str,
    /// Whether its definitions are reconstructed from public sources.
    pub reconstructed: bool,
    /// The multiple of s in the ISO 230-2 figures' bands (2; 3 for ±3s).
    pub k: f64,
}

impl StandardUsed {
    /// How the reports name `standard`.
    pub fn of(standard: &dyn Standard) -> StandardUsed {
        StandardUsed {
            key: standard.key(),
            name: standard.name(),
            reconstructed: standard.reconstructed(),
            k: standard.k(),
        }
    }
}

/// The result of evaluating a measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// Per-target statistics, in target order.
    pub per_target: Vec<TargetStats>,
    /// Axis figures (ISO 230-2; of the 1988 edition's ±3s when that is the standard).
    pub figures: AxisFigures,
    /// The standard the test was evaluated to.
    pub standard: StandardUsed,
    /// The figures that standard reports, with its keys, in its order.
    pub standard_figures: Vec<StandardFigure>,
    /// Number of ↑ runs.
    pub runs_up: usize,
    /// Number of ↓ runs.
    pub runs_down: usize,
    /// Runs that deviate from the others far more than the scatter; included in the figures.
    pub outliers: Vec<SuspectedOutlier>,
    /// The test against ISO 230-2's conditions (targets, runs, directions, spacing).
    pub conformance: TestConformance,
    /// The laser's refractive index against Edlén's equation, at the start
    /// and the end of the test ([`environment`]).
    pub refractive_index: RefractiveIndexCheck,
    /// Where the test falls short of ISO 230-2 ([`conformance`]), then what
    /// could not be evaluated, and why.
    pub warnings: Vec<Warning>,
}

impl Evaluation {
    /// Linear or rotary: the unit of every value here (mm, or °).
    pub fn kind(&self) -> AxisKind {
        self.conformance.kind()
    }

    /// The ISO 230-2 figures typed by the axis' kind ([`AxisFigures::typed`]).
    pub fn figures_typed(&self) -> FiguresByKind {
        self.figures.typed(self.kind())
    }

    /// The standard's figures typed by the axis' kind: `StandardFigure<Mm>`
    /// on a linear axis, `StandardFigure<Deg>` on a rotary one. A rotary
    /// axis' figures are degrees, which nothing that takes millimetres accepts
    /// (`report::json::FiguresJson::from_standard`).
    pub fn standard_figures_typed(&self) -> FiguresByKind {
        standard::typed(&self.standard_figures, self.kind())
    }

    /// The variance of one reading about its target's mean, pooled over
    /// every target and direction, s² = Σ (n − 1)·s_i² / Σ (n − 1), in the
    /// axis' unit squared (mm², or deg²);
    /// `None` without repeated runs. (Each target's own s rests on a handful
    /// of readings; where one σ serves the whole test, this is it.)
    pub fn pooled_variance(&self) -> Option<f64> {
        let (mut sum_sq, mut degrees) = (0.0, 0usize);
        for t in &self.per_target {
            for stats in [&t.up, &t.down] {
                if let Some(s) = stats.s {
                    sum_sq += s * s * (stats.n - 1) as f64;
                    degrees += stats.n - 1;
                }
            }
        }
        (degrees > 0).then(|| sum_sq / degrees as f64)
    }
}

impl Evaluation {
    /// An evaluation with only `figures` (ISO 230-2:2014), `runs` each way,
    /// the given per-target statistics and nothing else, for the tests of
    /// what is judged and shown from the figures.
    #[cfg(test)]
    pub(crate) fn of_figures(
        figures: AxisFigures,
        per_target: Vec<TargetStats>,
        runs: usize,
        length_mm: f64,
    ) -> Evaluation {
        Evaluation {
            standard: StandardUsed::of(&ISO_230_2),
            standard_figures: ISO_230_2.figures(&per_target, &figures),
            conformance: TestConformance {
                length: crate::measurement::ByKind::Linear(crate::units::Mm(length_mm)),
                targets: per_target.len(),
                runs_up: runs,
                runs_down: runs,
                checks: Vec::new(),
            },
            per_target,
            figures,
            runs_up: runs,
            runs_down: runs,
            outliers: Vec::new(),
            refractive_index: check_refractive_index(&Default::default()),
            warnings: Vec::new(),
        }
    }
}

/// Evaluates a measurement per ISO 230-2.
///
/// # Example
/// ```
/// use axcomp::evaluate::evaluate;
/// use axcomp::measurement::{Direction, Measurement, Run};
/// let run = |direction, number, values: [f64; 2]| Run {
///     direction, number, start_time_s: None,
///     deviations: values.iter().map(|v| Some(*v)).collect() };
/// let m = Measurement::new("X", vec![0.0, 100.0], vec![
///     run(Direction::Up, 1, [0.000, 0.004]), run(Direction::Down, 1, [-0.002, 0.002]),
///     run(Direction::Up, 2, [0.002, 0.006]), run(Direction::Down, 2, [0.000, 0.004]),
/// ], Default::default(), Default::default()).unwrap();
/// let e = evaluate(&m);
/// // x̄↑ = 1, 5 µm; x̄↓ = −1, 3 µm: B_i = 2 µm at both targets, E = 5 − (−1) = 6 µm.
/// assert!((e.figures.b.unwrap() - 0.002).abs() < 1e-12);
/// assert!((e.figures.e.unwrap() - 0.006).abs() < 1e-12);
/// ```
pub fn evaluate(measurement: &Measurement) -> Evaluation {
    evaluate_with(measurement, &ISO_230_2)
}

/// Evaluates a measurement per `standard`.
pub fn evaluate_with(measurement: &Measurement, standard: &dyn Standard) -> Evaluation {
    let per_target = per_target_stats(measurement, |target, up, down| {
        standard.target_stats(target, up, down)
    });
    let runs_up = measurement.run_count(Direction::Up);
    let runs_down = measurement.run_count(Direction::Down);
    let conformance = conformance::check_test(measurement);
    let mut warnings = conformance.warnings();
    let kind = measurement.kind();
    warnings.extend(coverage_warnings(&per_target, runs_up, runs_down, kind));
    let mut figures = standard.axis_figures(&per_target);
    let mut standard_figures = standard.figures(&per_target, &figures);
    if kind == AxisKind::Rotary {
        warnings.extend(rotary::warnings(&per_target));
        if rotary::over_full_turn(measurement.targets()) {
            // ISO 230-2's n = 1 rule: the scatter figures are not evaluated.
            for figure in [
                &mut figures.a,
                &mut figures.a_up,
                &mut figures.a_down,
                &mut figures.r,
                &mut figures.r_up,
                &mut figures.r_down,
            ] {
                *figure = None;
            }
            for figure in &mut standard_figures {
                if rotary::FIGURES_NEEDING_REPEATS.contains(&figure.key) {
                    figure.value = None;
                }
            }
        }
    }
    Evaluation {
        conformance,
        refractive_index: check_refractive_index(&measurement.environment),
        standard: StandardUsed::of(standard),
        standard_figures,
        figures,
        outliers: outliers::suspected_outliers(measurement),
        per_target,
        runs_up,
        runs_down,
        warnings,
    }
}

/// Says what is not evaluated and why: n = 1, or a target without enough
/// readings (one direction only is said by [`conformance`]).
fn coverage_warnings(
    per_target: &[TargetStats],
    runs_up: usize,
    runs_down: usize,
    kind: AxisKind,
) -> Vec<Warning> {
    let mut warnings = Vec::new();
    let measured: Vec<Direction> = Direction::BOTH
        .into_iter()
        .filter(|d| match d {
            Direction::Up => runs_up > 0,
            Direction::Down => runs_down > 0,
        })
        .collect();
    for direction in measured {
        let most_readings = per_target
            .iter()
            .map(|t| t.direction(direction).n)
            .max()
            .unwrap_or(0);
        if most_readings == 1 {
            warnings.push(Warning::SingleRun { direction });
            continue;
        }
        for target in per_target {
            let missing = match target.direction(direction).n {
                0 => format!("{direction} reading"),
                1 => format!("second {direction} reading (s{direction} needs n ≥ 2)"),
                _ => continue,
            };
            warnings.push(Warning::TargetNotEvaluated {
                kind,
                target: target.target,
                missing,
            });
        }
    }
    warnings
}

#[cfg(test)]
mod tests;
