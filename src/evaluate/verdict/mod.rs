//! The acceptance verdict: a standard's axis figures (ISO 230-2's, or VDI
//! 3441's keys under `--standard vdi3441`) against permissible values; a
//! limit on a figure the standard does not report is refused
//! ([`check_standard`]).
//!
//! ISO 230-2 defines the figures but sets no limits: the permissible values
//! come from the contract or a machine standard. They are given on the
//! command line (`--limit A=12`, µm) or in a machine profile's `[acceptance]`
//! table ([`AcceptanceProfile`]); command-line limits replace the profile's
//! for the same figure ([`with_overrides`]). A limit is fixed or grows with
//! the measured length ("10 µm per 1000 mm, at least 5 µm", as machine
//! standards state tolerances for a measuring length); the length is the
//! measured travel, last target − first target.
//!
//! The decision rule ([`Decision`], `../shared/spec/standards.md` §5) is
//! simple acceptance by default: a figure passes when its value is at most
//! the limit, compared at full precision, the measurement uncertainty not
//! taken into account. Under ISO 14253-1 the expanded uncertainty U of the
//! figure ([`Figure::expanded_uncertainty_mm`], from the budget of
//! [`crate::evaluate::uncertainty`]) decides: conformance is proven when
//! value + U ≤ limit, non-conformance when value − U > limit, and neither
//! between ([`Conformance::NotProven`]). A figure without an evaluated U
//! (R, B, the unidirectional figures, VDI 3441's: standards.md §4 gives no form) is
//! compared by its value alone, and its check says so. A figure
//! that is not evaluated (`None`, e.g. R of a one-run test) cannot pass: its
//! check fails with [`Outcome::NotEvaluated`], never an implied pass. Without
//! limits there is no verdict at all ([`verdict`] returns `None`).
//!
//! # The `[acceptance]` table
//!
//! ```toml
//! [acceptance]
//! A = { per_1000_mm_um = 10, min_um = 5 }  # 10 µm per 1000 mm of travel, at least 5 µm
//! R = 4                                    # µm (the same as R = { um = 4 })
//! B_mean = 2                               # compares |B̄|
//!
//! [acceptance.axes.X]                      # this axis only: replaces A above
//! A = 12
//! ```
//!
//! Keys are the figure names of `figures_um` in `evaluate --json`: A, A_up,
//! A_down, E, E_up, E_down, M, R, R_up, R_down, B, B_mean. A value is a
//! number of µm, or a table with either `um` (fixed) or `per_1000_mm_um` and
//! optionally `min_um` (per length). Every value must be finite and above 0.
//! Unknown keys are errors, at their line and column; `[acceptance.axes.NAME]`
//! tables for axes other than the measured one are ignored (one profile
//! serves the whole machine). Other top-level tables belong to other readers;
//! one that no reader knows (`[acceptence]`) is an error at its line.
//!
//! Pure: no I/O. Lengths in mm inside; µm only at the TOML boundary, through
//! `crate::units`.

use std::collections::BTreeMap;
use std::fmt;

use crate::evaluate::uncertainty::Budget;
use crate::evaluate::{Evaluation, StandardFigure};
use crate::measurement::Direction;
use crate::units::um_to_mm;
use crate::units::{Mm, per_m_over_mm};

mod acceptance;

pub use acceptance::AcceptanceProfile;

/// An ISO 230-2 axis figure a limit can be set on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Figure {
    /// Bidirectional accuracy of positioning A.
    A,
    /// Unidirectional accuracy A↑.
    AUp,
    /// Unidirectional accuracy A↓.
    ADown,
    /// Bidirectional systematic positional deviation E.
    E,
    /// E↑.
    EUp,
    /// E↓.
    EDown,
    /// Mean bidirectional positional deviation M.
    M,
    /// Bidirectional repeatability R.
    R,
    /// R↑.
    RUp,
    /// R↓.
    RDown,
    /// Reversal value B = max |B_i|.
    B,
    /// Mean reversal value B̄, compared as |B̄|.
    BMean,
    /// VDI/DGQ 3441 positional uncertainty P.
    P,
    /// VDI/DGQ 3441 positional deviation Pa.
    Pa,
    /// VDI/DGQ 3441 largest positional scatter Ps max.
    PsMax,
    /// VDI/DGQ 3441 mean positional scatter Ps mean.
    PsMean,
    /// VDI/DGQ 3441 largest reversal span U max.
    UMax,
    /// VDI/DGQ 3441 mean reversal span U mean.
    UMean,
}

impl Figure {
    /// Every figure, in the order of `figures_um`: ISO 230-2's, then VDI 3441's.
    pub const ALL: [Figure; 18] = [
        Figure::A,
        Figure::AUp,
        Figure::ADown,
        Figure::E,
        Figure::EUp,
        Figure::EDown,
        Figure::M,
        Figure::R,
        Figure::RUp,
        Figure::RDown,
        Figure::B,
        Figure::BMean,
        Figure::P,
        Figure::Pa,
        Figure::PsMax,
        Figure::PsMean,
        Figure::UMax,
        Figure::UMean,
    ];

    /// The name, as the key in `figures_um` of `evaluate --json`.
    pub fn name(self) -> &'static str {
        match self {
            Figure::A => "A",
            Figure::AUp => "A_up",
            Figure::ADown => "A_down",
            Figure::E => "E",
            Figure::EUp => "E_up",
            Figure::EDown => "E_down",
            Figure::M => "M",
            Figure::R => "R",
            Figure::RUp => "R_up",
            Figure::RDown => "R_down",
            Figure::B => "B",
            Figure::BMean => "B_mean",
            Figure::P => "P",
            Figure::Pa => "Pa",
            Figure::PsMax => "Ps_max",
            Figure::PsMean => "Ps_mean",
            Figure::UMax => "U_max",
            Figure::UMean => "U_mean",
        }
    }

    /// The figure of one direction that this bidirectional figure has (A↑ of
    /// A), or `None` for a figure without directions (M, B, B̄) or one that
    /// is already of a direction.
    pub fn directed(self, direction: Direction) -> Option<Figure> {
        match (self, direction) {
            (Figure::A, Direction::Up) => Some(Figure::AUp),
            (Figure::A, Direction::Down) => Some(Figure::ADown),
            (Figure::E, Direction::Up) => Some(Figure::EUp),
            (Figure::E, Direction::Down) => Some(Figure::EDown),
            (Figure::R, Direction::Up) => Some(Figure::RUp),
            (Figure::R, Direction::Down) => Some(Figure::RDown),
            _ => None,
        }
    }

    /// The figure of a name (exactly as [`Figure::name`] writes it).
    pub fn from_name(name: &str) -> Option<Figure> {
        Figure::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Every name, comma-separated, for error messages.
    pub fn names() -> String {
        Figure::ALL.map(Figure::name).join(", ")
    }

    /// The value a limit is compared with, mm, from a standard's figures
    /// ([`Evaluation::standard_figures`]): the figure, except |B̄| for
    /// B_mean (the signed mean reversal is a direction, its size is the
    /// error). `None` when the figure is not evaluated or not the standard's
    /// ([`check_standard`] refuses such a limit first). A linear axis'
    /// figures only ([`Evaluation::standard_figures_typed`]): limits are µm.
    pub fn value_mm(self, figures: &[StandardFigure<Mm>]) -> Option<f64> {
        let Mm(value) = figures.iter().find(|f| f.key == self.name())?.value?;
        Some(match self {
            Figure::BMean => value.abs(),
            _ => value,
        })
    }

    /// The expanded uncertainty of the figure, mm: U(E) = U(M) = U(A) = the
    /// budget's U (standards.md §4), and VDI 3441's Pa, which is M's formula
    /// (the range of the bidirectional mean deviations), has U(M); `None`
    /// for the figures whose U is not evaluated (R and B: no public form;
    /// the unidirectional figures: the spec names only E, M and A; VDI 3441's
    /// P, Ps and U: standards.md gives no form).
    pub fn expanded_uncertainty_mm(self, budget: &Budget) -> Option<f64> {
        match self {
            Figure::A | Figure::E | Figure::M | Figure::Pa => Some(budget.expanded_mm),
            _ => None,
        }
    }
}

/// The decision rule of a verdict (standards.md §5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Decision {
    /// Value ≤ limit; the measurement uncertainty is not considered.
    #[default]
    Simple,
    /// ISO 14253-1: value + U ≤ limit proves conformance, value − U > limit
    /// non-conformance, neither is proven between.
    Iso14253_1,
}

impl Decision {
    /// Both rules, in the order they are listed to users.
    pub const ALL: [Decision; 2] = [Decision::Simple, Decision::Iso14253_1];

    /// The name, as `--decision` and the JSON `rule` write it.
    pub fn name(self) -> &'static str {
        match self {
            Decision::Simple => "simple",
            Decision::Iso14253_1 => "iso14253-1",
        }
    }

    /// The rule of a name (exactly as [`Decision::name`] writes it).
    pub fn from_name(name: &str) -> Option<Decision> {
        Decision::ALL.into_iter().find(|d| d.name() == name)
    }

    /// The rule's short label: `simple acceptance` or `ISO 14253-1`.
    pub fn label(self) -> &'static str {
        match self {
            Decision::Simple => "simple acceptance",
            Decision::Iso14253_1 => "ISO 14253-1",
        }
    }

    /// The rule in words, as the report states it.
    pub fn description(self) -> &'static str {
        match self {
            Decision::Simple => {
                "simple acceptance: value ≤ limit, measurement uncertainty not considered"
            }
            Decision::Iso14253_1 => {
                "ISO 14253-1: conformance proven when value + U ≤ limit, \
                 non-conformance when value − U > limit, otherwise not proven"
            }
        }
    }
}

/// What a check proves under its decision rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Conformance {
    /// Conformance is proven (simple: value ≤ limit).
    Pass,
    /// Non-conformance is proven (simple: value > limit), or the figure is
    /// not evaluated.
    Fail,
    /// ISO 14253-1: the limit lies within value ± U.
    NotProven,
}

impl Conformance {
    /// `pass`, `fail` or `not-proven`, as in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            Conformance::Pass => "pass",
            Conformance::Fail => "fail",
            Conformance::NotProven => "not-proven",
        }
    }
}

impl fmt::Display for Figure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How large a figure may be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Permissible {
    /// A fixed value, mm.
    Fixed {
        /// The permissible value, mm.
        limit_mm: f64,
    },
    /// Proportional to the measured travel, with an optional floor.
    PerLength {
        /// Permissible value per 1000 mm of travel, mm.
        per_1000_mm_mm: f64,
        /// The limit is never below this, mm.
        min_mm: Option<f64>,
    },
}

impl Permissible {
    /// The limit for a measured travel, mm: `per_1000_mm · travel / 1000 mm`,
    /// raised to the minimum.
    pub fn limit_mm(&self, travel_mm: f64) -> f64 {
        match *self {
            Permissible::Fixed { limit_mm } => limit_mm,
            Permissible::PerLength {
                per_1000_mm_mm,
                min_mm,
            } => {
                let proportional = per_m_over_mm(per_1000_mm_mm, travel_mm);
                proportional.max(min_mm.unwrap_or(0.0))
            }
        }
    }

    /// Whether the minimum, not the proportional part, sets the limit.
    pub fn minimum_applies(&self, travel_mm: f64) -> bool {
        match *self {
            Permissible::Fixed { .. } => false,
            Permissible::PerLength {
                per_1000_mm_mm,
                min_mm,
            } => min_mm.is_some_and(|min| min > per_m_over_mm(per_1000_mm_mm, travel_mm)),
        }
    }
}

/// Where a limit was given.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LimitSource {
    /// `--limit` on the command line.
    CommandLine,
    /// A machine profile's `[acceptance]` table, or its
    /// `[acceptance.axes.NAME]` table when `axis` is set.
    Profile {
        /// The profile, as the user named it.
        file: String,
        /// The axis table the limit came from; `None` for `[acceptance]`.
        axis: Option<String>,
    },
}

impl fmt::Display for LimitSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LimitSource::CommandLine => f.write_str("--limit"),
            LimitSource::Profile { file, axis: None } => write!(f, "{file} [acceptance]"),
            LimitSource::Profile {
                file,
                axis: Some(axis),
            } => write!(f, "{file} [acceptance.axes.{axis}]"),
        }
    }
}

/// A permissible value of one figure and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Limit {
    /// The figure it limits.
    pub figure: Figure,
    /// How large the figure may be.
    pub permissible: Permissible,
    /// Where it was given.
    pub source: LimitSource,
}

/// Why a limit is refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LimitError {
    /// A figure the chosen standard does not report.
    #[error(
        "{given}: a limit on {figure}, which {standard} does not report; its figures are {keys} (--standard picks another)"
    )]
    NotOfStandard {
        /// The figure.
        figure: Figure,
        /// Where the limit was given.
        given: LimitSource,
        /// The standard's name.
        standard: &'static str,
        /// Its keys, comma-separated.
        keys: String,
    },
    /// The same figure twice on the command line.
    #[error("--limit {0} is given twice")]
    Twice(Figure),
    /// Zero, negative or not finite.
    #[error("the limit of {figure} must be a number of µm above 0, found {value_um}")]
    NotPositive {
        /// The figure.
        figure: Figure,
        /// The value given, µm.
        value_um: f64,
    },
}

/// `A=12`: a figure and a number of µm above 0, as `--limit` and the web
/// app's limit fields take it.
pub fn parse_limit(text: &str) -> Result<(Figure, f64), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("expected FIGURE=UM like A=12, found {text:?}"))?;
    let name = name.trim();
    let figure = Figure::from_name(name).ok_or_else(|| {
        format!(
            "unknown figure {name:?}; the figures are {}",
            Figure::names()
        )
    })?;
    let value: f64 = value
        .trim()
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("expected a number of µm above 0 after {name}=, found {value:?}"))?;
    Ok((figure, value))
}

/// The limits given on the command line as (figure, µm): fixed values.
/// A figure given twice, or a value that is not above 0, is refused.
pub fn command_line_limits(limits: &[(Figure, f64)]) -> Result<Vec<Limit>, LimitError> {
    let mut out: Vec<Limit> = Vec::with_capacity(limits.len());
    for &(figure, value_um) in limits {
        if !(value_um.is_finite() && value_um > 0.0) {
            return Err(LimitError::NotPositive { figure, value_um });
        }
        if out.iter().any(|l| l.figure == figure) {
            return Err(LimitError::Twice(figure));
        }
        out.push(Limit {
            figure,
            permissible: Permissible::Fixed {
                limit_mm: um_to_mm(value_um),
            },
            source: LimitSource::CommandLine,
        });
    }
    Ok(out)
}

/// Refuses a limit on a figure the evaluation's standard does not report
/// (a VDI 3441 figure under ISO 230-2, A under VDI 3441).
pub fn check_standard(limits: &[Limit], evaluation: &Evaluation) -> Result<(), LimitError> {
    let keys = &evaluation.standard_figures;
    match limits
        .iter()
        .find(|l| !keys.iter().any(|f| f.key == l.figure.name()))
    {
        None => Ok(()),
        Some(limit) => Err(LimitError::NotOfStandard {
            figure: limit.figure,
            given: limit.source.clone(),
            standard: evaluation.standard.name,
            keys: keys.iter().map(|f| f.key).collect::<Vec<_>>().join(", "),
        }),
    }
}

/// `base` with every figure of `overrides` replaced (or added): how
/// command-line limits override a profile's, and an axis table the general one.
/// The result is in [`Figure::ALL`] order.
pub fn with_overrides(base: Vec<Limit>, overrides: Vec<Limit>) -> Vec<Limit> {
    let mut by_figure: BTreeMap<Figure, Limit> = BTreeMap::new();
    for limit in base.into_iter().chain(overrides) {
        by_figure.insert(limit.figure, limit);
    }
    by_figure.into_values().collect()
}

/// How a check came out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The value is at most the limit.
    Pass,
    /// The value is above the limit.
    Exceeds,
    /// The figure is not evaluated for this test: it cannot pass.
    NotEvaluated,
}

/// One figure compared with its limit.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// The limit, as given.
    pub limit: Limit,
    /// The value compared (|B̄| for B_mean), mm; `None` when not evaluated.
    pub value_mm: Option<f64>,
    /// The limit for this test's travel, mm.
    pub limit_mm: f64,
    /// The value against the limit alone.
    pub outcome: Outcome,
    /// The figure's expanded uncertainty U, mm, when the verdict has a
    /// budget and U of this figure is evaluated.
    pub uncertainty_mm: Option<f64>,
    /// What the check proves under the verdict's decision rule.
    pub conformance: Conformance,
}

impl Check {
    /// The figure checked.
    pub fn figure(&self) -> Figure {
        self.limit.figure
    }

    /// Whether conformance is proven.
    pub fn pass(&self) -> bool {
        self.conformance == Conformance::Pass
    }
}

/// The verdict on one test.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// One check per limit, in [`Figure::ALL`] order.
    pub checks: Vec<Check>,
    /// The measured travel per-length limits use: last − first target, mm.
    pub travel_mm: f64,
    /// The decision rule.
    pub decision: Decision,
    /// Whether there was an uncertainty budget (none: the instrument is
    /// unknown, and no figure has a U).
    pub budget: bool,
}

impl Verdict {
    /// Pass: every check passed (and there is at least one).
    pub fn pass(&self) -> bool {
        !self.checks.is_empty() && self.checks.iter().all(Check::pass)
    }

    /// The verdict's conformance: fail when a check fails, else not proven
    /// when a check is not proven, else pass.
    pub fn conformance(&self) -> Conformance {
        let any = |c: Conformance| self.checks.iter().any(|check| check.conformance == c);
        if any(Conformance::Fail) || self.checks.is_empty() {
            Conformance::Fail
        } else if any(Conformance::NotProven) {
            Conformance::NotProven
        } else {
            Conformance::Pass
        }
    }

    /// The checks that did not pass.
    pub fn failed(&self) -> impl Iterator<Item = &Check> {
        self.checks.iter().filter(|c| !c.pass())
    }
}

/// Compares the figures of an evaluation with the limits; `None` without
/// limits (no limits, no verdict).
///
/// # Example
/// ```
/// use axcomp::evaluate::evaluate;
/// use axcomp::evaluate::verdict::{Figure, command_line_limits, verdict};
/// use axcomp::measurement::{Direction, Measurement, Run};
/// let run = |direction, number, values: [f64; 2]| Run {
///     direction, number, start_time_s: None,
///     deviations: values.iter().map(|v| Some(*v)).collect() };
/// let m = Measurement::new("X", vec![0.0, 100.0], vec![
///     run(Direction::Up, 1, [0.000, 0.004]), run(Direction::Down, 1, [-0.002, 0.002]),
///     run(Direction::Up, 2, [0.002, 0.006]), run(Direction::Down, 2, [0.000, 0.004]),
/// ], Default::default(), Default::default()).unwrap();
/// // E = 5 − (−1) = 6 µm, B = 2 µm.
/// let limits = command_line_limits(&[(Figure::E, 5.0), (Figure::B, 2.0)]).unwrap();
/// let v = verdict(&evaluate(&m), &limits).unwrap();
/// assert!(!v.pass());
/// assert_eq!(v.failed().map(|c| c.figure()).collect::<Vec<_>>(), [Figure::E]);
/// assert!(verdict(&evaluate(&m), &[]).is_none());
/// ```
pub fn verdict(evaluation: &Evaluation, limits: &[Limit]) -> Option<Verdict> {
    verdict_with(evaluation, limits, Decision::Simple, None)
}

/// Compares the figures with the limits under `decision`, with the
/// uncertainty of `budget` (none: no figure has a U, and ISO 14253-1 then
/// compares values alone); `None` without limits.
///
/// # Example
/// ```
/// use axcomp::evaluate::evaluate;
/// use axcomp::evaluate::uncertainty::{Equipment, budget};
/// use axcomp::evaluate::verdict::{Conformance, Decision, Figure, command_line_limits, verdict_with};
/// use axcomp::measurement::{Direction, Measurement, Run};
/// let run = |direction, number, values: [f64; 2]| Run {
///     direction, number, start_time_s: None,
///     deviations: values.iter().map(|v| Some(*v)).collect() };
/// let m = Measurement::new("X", vec![0.0, 1000.0], vec![
///     run(Direction::Up, 1, [0.000, 0.004]), run(Direction::Down, 1, [-0.002, 0.002]),
///     run(Direction::Up, 2, [0.002, 0.006]), run(Direction::Down, 2, [0.000, 0.004]),
/// ], Default::default(), Default::default()).unwrap();
/// // E = 6 µm against 6.5 µm: a pass by value, but U(E) of the bundled
/// // equipment over 1 m (about 3.3 µm) reaches over the limit.
/// let limits = command_line_limits(&[(Figure::E, 6.5)]).unwrap();
/// let budget = budget(&m, &Equipment::bundled()).unwrap();
/// let v = verdict_with(&evaluate(&m), &limits, Decision::Iso14253_1, Some(&budget)).unwrap();
/// assert_eq!(v.checks[0].conformance, Conformance::NotProven);
/// ```
pub fn verdict_with(
    evaluation: &Evaluation,
    limits: &[Limit],
    decision: Decision,
    budget: Option<&Budget>,
) -> Option<Verdict> {
    if limits.is_empty() {
        return None;
    }
    let travel_mm = match (evaluation.per_target.first(), evaluation.per_target.last()) {
        (Some(first), Some(last)) => last.target - first.target,
        _ => 0.0,
    };
    // Limits are µm: a rotary axis' figures (degrees; refused before, in
    // `workflow::rotary`) would not be compared, not taken for millimetres.
    let linear_figures = evaluation
        .standard_figures_typed()
        .linear()
        .unwrap_or_default();
    let mut ordered: Vec<&Limit> = limits.iter().collect();
    ordered.sort_by_key(|l| l.figure);
    let checks = ordered
        .into_iter()
        .map(|limit| {
            let value_mm = limit.figure.value_mm(&linear_figures);
            let limit_mm = limit.permissible.limit_mm(travel_mm);
            let outcome = match value_mm {
                None => Outcome::NotEvaluated,
                Some(value) if value <= limit_mm => Outcome::Pass,
                Some(_) => Outcome::Exceeds,
            };
            let uncertainty_mm = budget.and_then(|b| limit.figure.expanded_uncertainty_mm(b));
            let conformance = match (outcome, decision, value_mm, uncertainty_mm) {
                (Outcome::NotEvaluated, ..) => Conformance::Fail,
                (_, Decision::Iso14253_1, Some(value), Some(u)) => {
                    if value + u <= limit_mm {
                        Conformance::Pass
                    } else if value - u > limit_mm {
                        Conformance::Fail
                    } else {
                        Conformance::NotProven
                    }
                }
                (Outcome::Pass, ..) => Conformance::Pass,
                _ => Conformance::Fail,
            };
            Check {
                limit: limit.clone(),
                value_mm,
                limit_mm,
                outcome,
                uncertainty_mm,
                conformance,
            }
        })
        .collect();
    Some(Verdict {
        checks,
        travel_mm,
        decision,
        budget: budget.is_some(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::evaluate::{AxisFigures, TargetStats};
    use crate::units::mm_to_um;

    #[test]
    fn limits_parse_and_bad_ones_say_what_is_valid() {
        assert_eq!(parse_limit("A=12").unwrap(), (Figure::A, 12.0));
        assert_eq!(parse_limit("B_mean = 2.5").unwrap(), (Figure::BMean, 2.5));
        let unknown = parse_limit("Q=3").unwrap_err();
        assert!(unknown.contains("unknown figure \"Q\""), "{unknown}");
        assert!(
            unknown.contains("A, A_up, A_down, E, E_up, E_down, M, R, R_up, R_down, B, B_mean")
        );
        for bad in ["A=0", "A=-3", "A=inf", "A=NaN", "A=12um", "A="] {
            assert!(parse_limit(bad).unwrap_err().contains("above 0"), "{bad}");
        }
        assert!(parse_limit("A12").unwrap_err().contains("FIGURE=UM"));
    }

    fn evaluation(first_mm: f64, last_mm: f64, figures: AxisFigures) -> Evaluation {
        let target = |target_mm| TargetStats {
            target: target_mm,
            up: Default::default(),
            down: Default::default(),
            mean: None,
            reversal: None,
            repeatability_up: None,
            repeatability_down: None,
            repeatability: None,
        };
        Evaluation::of_figures(
            figures,
            vec![target(first_mm), target(last_mm)],
            5,
            last_mm - first_mm,
        )
    }

    fn per_length(per_um: f64, min_um: Option<f64>) -> Permissible {
        Permissible::PerLength {
            per_1000_mm_mm: um_to_mm(per_um),
            min_mm: min_um.map(um_to_mm),
        }
    }

    #[test]
    fn per_length_limits_by_hand() {
        // 10 µm per 1000 mm over 750 mm: 10 · 750 / 1000 = 7.5 µm.
        let rule = per_length(10.0, None);
        assert!((mm_to_um(rule.limit_mm(750.0)) - 7.5).abs() < 1e-12);
        // With a 5 µm minimum over 200 mm: 10 · 0.2 = 2 µm, raised to 5 µm.
        let rule = per_length(10.0, Some(5.0));
        assert!((mm_to_um(rule.limit_mm(200.0)) - 5.0).abs() < 1e-12);
        assert!(rule.minimum_applies(200.0));
        // … and over 750 mm the proportional 7.5 µm is above the minimum.
        assert!((mm_to_um(rule.limit_mm(750.0)) - 7.5).abs() < 1e-12);
        assert!(!rule.minimum_applies(750.0));
        // A fixed limit ignores the travel.
        let fixed = Permissible::Fixed { limit_mm: 0.012 };
        assert_eq!(fixed.limit_mm(10_000.0), 0.012);
    }

    #[test]
    fn a_rotary_axis_figures_are_not_taken_for_millimetres() {
        // E = 0.003 on a rotary axis is 0.003° = 10.8″, not 3 µm: against a
        // 5 µm limit it is not compared (limits are µm), so the check fails
        // as not evaluated rather than passing.
        let figures = AxisFigures {
            e: Some(0.003),
            ..Default::default()
        };
        let mut rotary = evaluation(0.0, 90.0, figures);
        rotary.conformance.length = crate::measurement::ByKind::Rotary(crate::units::Deg(90.0));
        let limit = [Limit {
            figure: Figure::E,
            permissible: Permissible::Fixed { limit_mm: 0.005 },
            source: LimitSource::CommandLine,
        }];
        let v = verdict(&rotary, &limit).unwrap();
        assert_eq!(v.checks[0].outcome, Outcome::NotEvaluated);
        // The same figure of a linear axis, 3 µm, passes.
        let v = verdict(&evaluation(0.0, 90.0, figures), &limit).unwrap();
        assert_eq!(v.checks[0].outcome, Outcome::Pass);
    }

    #[test]
    fn the_verdict_uses_the_travel_and_fails_what_is_not_evaluated() {
        // A = 7 µm over 750 mm against 10 µm/1000 mm (7.5 µm): pass.
        // R not evaluated (one run): a failed check, never an implied pass.
        // B̄ = −3 µm against 2 µm: |B̄| = 3 µm exceeds.
        let figures = AxisFigures {
            a: Some(0.007),
            b_mean: Some(-0.003),
            ..Default::default()
        };
        let evaluation = evaluation(100.0, 850.0, figures);
        let profile = [
            Limit {
                figure: Figure::BMean,
                permissible: Permissible::Fixed { limit_mm: 0.002 },
                source: LimitSource::CommandLine,
            },
            Limit {
                figure: Figure::A,
                permissible: per_length(10.0, Some(5.0)),
                source: LimitSource::CommandLine,
            },
            Limit {
                figure: Figure::R,
                permissible: Permissible::Fixed { limit_mm: 0.004 },
                source: LimitSource::CommandLine,
            },
        ];
        let v = verdict(&evaluation, &profile).unwrap();
        assert_eq!(v.travel_mm, 750.0);
        let outcomes: Vec<(Figure, Outcome)> =
            v.checks.iter().map(|c| (c.figure(), c.outcome)).collect();
        assert_eq!(
            outcomes,
            [
                (Figure::A, Outcome::Pass),
                (Figure::R, Outcome::NotEvaluated),
                (Figure::BMean, Outcome::Exceeds),
            ]
        );
        assert!((mm_to_um(v.checks[0].limit_mm) - 7.5).abs() < 1e-12);
        assert_eq!(v.checks[2].value_mm, Some(0.003));
        assert!(!v.pass());
        // Only A: pass. A value equal to its limit passes (F ≤ T).
        let only_a = verdict(&evaluation, &profile[1..2]).unwrap();
        assert!(only_a.pass());
        let exact = command_line_limits(&[(Figure::A, 7.0)]).unwrap();
        assert!(verdict(&evaluation, &exact).unwrap().pass());
        let below = command_line_limits(&[(Figure::A, 6.99)]).unwrap();
        assert!(!verdict(&evaluation, &below).unwrap().pass());
        // No limits, no verdict.
        assert_eq!(verdict(&evaluation, &[]), None);
    }

    #[test]
    fn iso_14253_1_proves_conformance_non_conformance_or_neither() {
        // E = 11.96 µm, R = 3 µm over 1000 mm; a budget with U = 3.49 µm
        // (standards.md §4's U(E) to two decimals), applying to E, M, A only.
        let figures = AxisFigures {
            e: Some(0.011_96),
            r: Some(0.003),
            ..Default::default()
        };
        let evaluation = evaluation(0.0, 1000.0, figures);
        let budget = Budget {
            equipment: "test".into(),
            length_mm: 1000.0,
            contributors: Vec::new(),
            combined_mm: 0.001_745,
            coverage_factor: 2.0,
            expanded_mm: 0.003_49,
        };
        let check = |e_limit_um: f64, decision| {
            let limits = command_line_limits(&[(Figure::E, e_limit_um), (Figure::R, 3.5)]).unwrap();
            verdict_with(&evaluation, &limits, decision, Some(&budget)).unwrap()
        };
        // Just under the limit 12: simple passes; 11.96 + 3.49 = 15.45 > 12
        // and 11.96 − 3.49 = 8.47 ≤ 12: not proven.
        let simple = check(12.0, Decision::Simple);
        assert_eq!(simple.checks[0].conformance, Conformance::Pass);
        assert_eq!(simple.conformance(), Conformance::Pass);
        let iso = check(12.0, Decision::Iso14253_1);
        assert_eq!(iso.checks[0].conformance, Conformance::NotProven);
        assert_eq!(iso.checks[0].outcome, Outcome::Pass);
        assert_eq!(iso.checks[0].uncertainty_mm, Some(0.003_49));
        assert_eq!(iso.conformance(), Conformance::NotProven);
        assert!(!iso.pass());
        // 15.45 ≤ 16: conformance proven.
        let proven = check(16.0, Decision::Iso14253_1);
        assert_eq!(proven.checks[0].conformance, Conformance::Pass);
        assert!(proven.pass());
        // 8.47 > 8: non-conformance proven; at 8.47 exactly it would not be.
        let failed = check(8.0, Decision::Iso14253_1);
        assert_eq!(failed.checks[0].conformance, Conformance::Fail);
        assert_eq!(failed.conformance(), Conformance::Fail);
        // R has no U: decided by its value (3 ≤ 3.5), with no U.
        assert_eq!(iso.checks[1].figure(), Figure::R);
        assert_eq!(iso.checks[1].uncertainty_mm, None);
        assert_eq!(iso.checks[1].conformance, Conformance::Pass);
        // Without a budget ISO 14253-1 has no U anywhere: values alone.
        let limits = command_line_limits(&[(Figure::E, 12.0)]).unwrap();
        let no_budget = verdict_with(&evaluation, &limits, Decision::Iso14253_1, None).unwrap();
        assert_eq!(no_budget.checks[0].conformance, Conformance::Pass);
        // A figure not evaluated fails under either rule.
        let limits = command_line_limits(&[(Figure::A, 12.0)]).unwrap();
        let missing = verdict_with(&evaluation, &limits, Decision::Iso14253_1, Some(&budget));
        assert_eq!(missing.unwrap().checks[0].conformance, Conformance::Fail);
        // The rule's names.
        for decision in Decision::ALL {
            assert_eq!(Decision::from_name(decision.name()), Some(decision));
        }
        assert_eq!(Decision::default(), Decision::Simple);
    }

    #[test]
    fn command_line_limits_are_checked_and_override_the_profile() {
        assert_eq!(
            command_line_limits(&[(Figure::A, 12.0), (Figure::A, 14.0)]),
            Err(LimitError::Twice(Figure::A))
        );
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(command_line_limits(&[(Figure::R, bad)]).is_err(), "{bad}");
        }
        let profile = AcceptanceProfile::from_toml_str("[acceptance]\nA = 10\nR = 4\n")
            .unwrap()
            .limits_for("X", "p.toml");
        let cli = command_line_limits(&[(Figure::A, 14.0)]).unwrap();
        let merged = with_overrides(profile, cli);
        assert_eq!(merged.len(), 2);
        assert_eq!(merged[0].source, LimitSource::CommandLine);
        assert_eq!(
            merged[0].permissible,
            Permissible::Fixed {
                limit_mm: um_to_mm(14.0)
            }
        );
        assert_eq!(merged[1].source.to_string(), "p.toml [acceptance]");
    }

    #[test]
    fn the_acceptance_table() {
        let text = "name = \"M\"\n[controller]\nunits = \"mm\"\n\n[acceptance]\n\
                    A = { per_1000_mm_um = 10, min_um = 5 }\nR = 4.5\nB_mean = { um = 2 }\n\n\
                    [acceptance.axes.X]\nA = 12\n\n[acceptance.axes.Y]\nE = 3\n";
        let profile = AcceptanceProfile::from_toml_str(text).unwrap();
        assert_eq!(
            profile.general,
            [
                (Figure::A, per_length(10.0, Some(5.0))),
                (Figure::R, Permissible::Fixed { limit_mm: 0.0045 }),
                (Figure::BMean, Permissible::Fixed { limit_mm: 0.002 }),
            ]
        );
        let x = profile.limits_for("X", "m.toml");
        let figures: Vec<Figure> = x.iter().map(|l| l.figure).collect();
        assert_eq!(figures, [Figure::A, Figure::R, Figure::BMean]);
        assert_eq!(x[0].source.to_string(), "m.toml [acceptance.axes.X]");
        assert_eq!(x[1].source.to_string(), "m.toml [acceptance]");
        // Z has no table of its own: the general limits.
        let z = profile.limits_for("Z", "m.toml");
        assert_eq!(z[0].permissible, per_length(10.0, Some(5.0)));
        // No [acceptance]: empty, no error (a profile may have only [controller]).
        assert!(
            AcceptanceProfile::from_toml_str("[controller]\nunits = \"mm\"\n")
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn acceptance_errors_name_line_and_column() {
        let check = |text: &str, line: usize, column: usize, needle: &str| {
            let error = AcceptanceProfile::from_toml_str(text).unwrap_err();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "{text:?}: {error}"
            );
            assert!(error.message.contains(needle), "{text:?}: {error}");
        };
        check(
            "[acceptance]\nA = 3\nQ = 3\n",
            3,
            1,
            "unknown figure `Q`; expected one of A, A_up, A_down",
        );
        check("[acceptance]\nR = -4\n", 2, 5, "above 0, found -4");
        check("[acceptance]\nR = 0\n", 2, 5, "above 0, found 0");
        check("[acceptance]\nR = nan\n", 2, 5, "above 0, found NaN");
        check("[acceptance]\nR = \"4\"\n", 2, 5, "number of µm above 0");
        check(
            "[acceptance]\nA = { per_m_um = 10 }\n",
            2,
            7,
            "unknown field `per_m_um`",
        );
        check(
            "[acceptance]\nA = { um = 3, per_1000_mm_um = 10 }\n",
            2,
            5,
            "not both",
        );
        check("[acceptance]\nA = { min_um = 5 }\n", 2, 5, "per_1000_mm_um");
        check(
            "[acceptance]\nA = { per_1000_mm_um = 10, min_um = -5 }\n",
            2,
            37,
            "above 0",
        );
        check(
            "[acceptance.axes.X]\naxes = 3\n",
            2,
            1,
            "unknown figure `axes`",
        );
        check("[acceptance.axes.X]\nA = 0\n", 2, 5, "above 0");
    }
}
