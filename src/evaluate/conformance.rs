//! Does the test itself meet ISO 230-2? Targets, runs, directions and spacing.
//!
//! The figures of a test are only ISO 230-2 figures when the test was run as
//! the standard asks (`../shared/spec/iso230-2.md`, "Test cycle" and "Edge
//! cases users meet"; `../shared/spec/standards.md` §6):
//!
//! - at least [`MIN_TARGETS`] targets, and at least [`MIN_TARGETS_PER_M`] per
//!   metre of travel (the travel is the span of the targets);
//! - the standard cycle approaches every target from both directions, with
//!   [`STANDARD_RUNS`] runs each way;
//! - a linear axis longer than [`LONG_AXIS_MM`] needs only one run per
//!   direction (n = 1; R and A are then not evaluated: GOST ISO 230-2-2016
//!   §6.2, `standards.md` §6), so more runs there are allowed and only noted;
//! - irregular spacing is *recommended*, so that a periodic error (screw
//!   lead, scale period) is not read at one phase at every target: a constant
//!   step (within [`SAME_STEP_MM`]) is reported, but a recommendation does not
//!   make the test non-conforming.
//!
//! A rotary axis ([`AxisKind::Rotary`], `standards.md` §6): one run per
//! direction suffices over [`FULL_TURN_DEG`] (n = 1; R and A are then not
//! evaluated, `evaluate::rotary`); the per-metre and spacing rules are
//! linear ones and are not applied: a rotary test instead includes the
//! principal angles (`evaluate::rotary` says which are missing).
//!
//! Not applied: the notes give a 250 mm average interval for axes over
//! 2000 mm, unverified (`../shared/notes/anchors-and-standards.md` §4.2,
//! marked \[U\]); the spec's 5 targets per metre is applied at every length.
//!
//! [`check_test`] is the one place these rules live; its [`TestConformance`]
//! gives the checks (for `evaluate --json`), the warnings (each says what to
//! do) and the report's title.

use crate::error::{Warning, mm_text};
use crate::measurement::{AxisKind, ByKind, Direction, Measurement, Position};
use crate::units::{Deg, MM_PER_M, Mm};

/// The fewest targets ISO 230-2 accepts (spec "Test cycle").
pub const MIN_TARGETS: usize = 5;
/// The fewest targets per metre of travel ISO 230-2 accepts (spec "Test cycle").
pub const MIN_TARGETS_PER_M: f64 = 5.0;
/// Runs per direction of the standard test cycle, n (spec "Test cycle").
pub const STANDARD_RUNS: usize = 5;
/// Travel above which one run per direction suffices (spec "Edge cases";
/// `standards.md` §6, GOST ISO 230-2-2016 §6.2), mm.
pub const LONG_AXIS_MM: f64 = 2000.0;
/// A rotary axis' range above which one run per direction suffices (n = 1,
/// `standards.md` §6, GOST ISO 230-2-2016 §6.2), °.
pub const FULL_TURN_DEG: f64 = 360.0;
/// Steps between targets that differ by less than this are one step, mm: a
/// micrometre, finer than any target is programmed.
pub const SAME_STEP_MM: f64 = 0.001;
/// The edition the figures follow.
pub const EDITION: &str = "ISO 230-2:2014";

/// One thing ISO 230-2 asks of the test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Requirement {
    /// At least [`MIN_TARGETS`] targets.
    Targets,
    /// At least [`MIN_TARGETS_PER_M`] targets per metre of travel.
    TargetsPerMetre,
    /// [`STANDARD_RUNS`] runs in each direction (one over [`LONG_AXIS_MM`]).
    Runs,
    /// Both directions measured.
    BothDirections,
    /// Irregular spacing (a recommendation, not a requirement).
    IrregularSpacing,
}

impl Requirement {
    /// The name in `evaluate --json` (`test_conformance.checks[].check`).
    pub fn name(self) -> &'static str {
        match self {
            Requirement::Targets => "targets",
            Requirement::TargetsPerMetre => "targets_per_m",
            Requirement::Runs => "runs",
            Requirement::BothDirections => "both_directions",
            Requirement::IrregularSpacing => "irregular_spacing",
        }
    }

    /// Whether the standard only recommends it.
    pub fn is_recommendation(self) -> bool {
        self == Requirement::IrregularSpacing
    }

    /// What the standard asks, for "does not meet ISO 230-2's …".
    fn asked(self) -> &'static str {
        match self {
            Requirement::Targets => "5 targets",
            Requirement::TargetsPerMetre => "5 targets per metre",
            Requirement::Runs => "5 runs",
            Requirement::BothDirections => "two directions",
            Requirement::IrregularSpacing => "irregular spacing",
        }
    }
}

/// One requirement, checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Check {
    /// What is checked.
    pub requirement: Requirement,
    /// Whether the test meets it.
    pub met: bool,
    /// What the test has: targets; targets per metre (`None` for a single
    /// target); the fewest runs in a measured direction; directions measured;
    /// for spacing, the constant step in mm (`None` when the spacing is irregular).
    pub found: Option<f64>,
    /// What the standard asks, in the same unit (`None` for spacing).
    pub required: Option<f64>,
}

/// The test against ISO 230-2's conditions.
#[derive(Clone, Debug, PartialEq)]
pub struct TestConformance {
    /// Travel: last target minus first, mm on a linear axis, ° on a rotary
    /// one (the type says which, and so the axis' kind).
    pub length: Position,
    /// Number of targets.
    pub targets: usize,
    /// Runs ↑.
    pub runs_up: usize,
    /// Runs ↓.
    pub runs_down: usize,
    /// Every check, requirements first.
    pub checks: Vec<Check>,
}

/// Checks a measurement against ISO 230-2's test conditions.
///
/// # Example
/// ```
/// use axcomp::evaluate::conformance::check_test;
/// use axcomp::measurement::{Direction, Measurement, Run};
/// let run = |direction, number| Run { direction, number, start_time_s: None,
///     deviations: vec![Some(0.0); 2] };
/// let m = Measurement::new("X", vec![0.0, 1000.0], vec![
///     run(Direction::Up, 1), run(Direction::Down, 1),
///     run(Direction::Up, 2), run(Direction::Down, 2),
/// ], Default::default(), Default::default()).unwrap();
/// let c = check_test(&m);
/// assert!(!c.meets_iso230_2());
/// assert_eq!(c.title(), "bidirectional test, 2 runs, 2 targets over 1000 mm: \
///     does not meet ISO 230-2's 5 runs, 5 targets and 5 targets per metre");
/// ```
pub fn check_test(measurement: &Measurement) -> TestConformance {
    let targets = measurement.targets();
    let runs_up = measurement.run_count(Direction::Up);
    let runs_down = measurement.run_count(Direction::Down);
    let length = measurement
        .kind()
        .position(match (targets.first(), targets.last()) {
            (Some(first), Some(last)) => last - first,
            _ => 0.0,
        });
    let target_count = targets.len();
    let fewest_runs = [runs_up, runs_down]
        .into_iter()
        .filter(|n| *n > 0)
        .min()
        .unwrap_or(0);
    let directions = [runs_up, runs_down].iter().filter(|n| **n > 0).count();
    let one_run_is_enough = match length {
        ByKind::Linear(Mm(length_mm)) => length_mm > LONG_AXIS_MM,
        ByKind::Rotary(Deg(range_deg)) => range_deg > FULL_TURN_DEG,
    };
    let runs_required = if one_run_is_enough { 1 } else { STANDARD_RUNS };
    // Targets per metre and even spacing are asked of a linear axis only.
    let per_metre = match length {
        ByKind::Linear(Mm(length_mm)) if length_mm > 0.0 => {
            Some(target_count as f64 / (length_mm / MM_PER_M))
        }
        _ => None,
    };
    let step = constant_step(targets);
    let mut checks = vec![
        Check {
            requirement: Requirement::Runs,
            met: fewest_runs >= runs_required,
            found: Some(fewest_runs as f64),
            required: Some(runs_required as f64),
        },
        Check {
            requirement: Requirement::BothDirections,
            met: directions == 2,
            found: Some(directions as f64),
            required: Some(2.0),
        },
        Check {
            requirement: Requirement::Targets,
            met: target_count >= MIN_TARGETS,
            found: Some(target_count as f64),
            required: Some(MIN_TARGETS as f64),
        },
        Check {
            requirement: Requirement::TargetsPerMetre,
            // A relative tolerance: 5 targets over exactly 1 m are 5 per metre.
            met: per_metre.is_none_or(|d| d >= MIN_TARGETS_PER_M * (1.0 - 1e-9)),
            found: per_metre,
            required: Some(MIN_TARGETS_PER_M),
        },
        Check {
            requirement: Requirement::IrregularSpacing,
            met: step.is_none(),
            found: step,
            required: None,
        },
    ];
    if length.kind() == AxisKind::Rotary {
        checks.retain(|check| {
            !matches!(
                check.requirement,
                Requirement::TargetsPerMetre | Requirement::IrregularSpacing
            )
        });
    }
    TestConformance {
        length,
        targets: target_count,
        runs_up,
        runs_down,
        checks,
    }
}

/// The step between targets when every step is the same (within
/// [`SAME_STEP_MM`]) and there are at least two; `None` otherwise.
fn constant_step(targets: &[f64]) -> Option<f64> {
    if targets.len() < 3 {
        return None;
    }
    let steps: Vec<f64> = targets.windows(2).map(|w| w[1] - w[0]).collect();
    let low = steps.iter().copied().fold(f64::INFINITY, f64::min);
    let high = steps.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (high - low < SAME_STEP_MM)
        .then(|| (targets[targets.len() - 1] - targets[0]) / steps.len() as f64)
}

impl TestConformance {
    /// Linear or rotary.
    pub fn kind(&self) -> AxisKind {
        self.length.kind()
    }

    /// The travel as a bare number in the axis' unit (mm or °), for the
    /// sentences that name the unit by [`TestConformance::kind`].
    fn length_in_axis_unit(&self) -> f64 {
        match self.length {
            ByKind::Linear(Mm(length_mm)) => length_mm,
            ByKind::Rotary(Deg(range_deg)) => range_deg,
        }
    }

    /// Whether every requirement (not the recommendations) is met.
    pub fn meets_iso230_2(&self) -> bool {
        self.checks
            .iter()
            .all(|c| c.met || c.requirement.is_recommendation())
    }

    /// The check of one requirement.
    pub fn check(&self, requirement: Requirement) -> Option<&Check> {
        self.checks.iter().find(|c| c.requirement == requirement)
    }

    /// Whether the travel is over [`LONG_AXIS_MM`].
    pub fn is_long_axis(&self) -> bool {
        matches!(self.length, ByKind::Linear(Mm(length_mm)) if length_mm > LONG_AXIS_MM)
    }

    /// What the test is, for the report's title: `bidirectional test, 5 runs,
    /// 16 targets over 750 mm to ISO 230-2:2014`, or `…: does not meet ISO
    /// 230-2's 5 runs` naming every requirement it misses.
    pub fn title(&self) -> String {
        let kind = match (self.runs_up, self.runs_down) {
            (_, 0) => "unidirectional test (↑ only)",
            (0, _) => "unidirectional test (↓ only)",
            _ => "bidirectional test",
        };
        let runs = match (self.runs_up, self.runs_down) {
            (1, 0) | (0, 1) | (1, 1) => "1 run".to_string(),
            (n, 0) | (0, n) => format!("{n} runs"),
            (up, down) if up == down => format!("{up} runs"),
            (up, down) => format!("{up}↑ {down}↓ runs"),
        };
        let (space, unit) = match self.kind() {
            AxisKind::Linear => (" ", "mm"),
            AxisKind::Rotary => ("", "°"),
        };
        let mut title = format!(
            "{kind}, {runs}, {} target{} over {}{space}{unit}",
            self.targets,
            if self.targets == 1 { "" } else { "s" },
            mm_text(self.length_in_axis_unit())
        );
        if self.kind() == AxisKind::Rotary {
            title.insert_str(0, "rotary axis, ");
        }
        let missed: Vec<&str> = self
            .checks
            .iter()
            .filter(|c| !c.met && !c.requirement.is_recommendation())
            .map(|c| c.requirement.asked())
            .collect();
        match missed.as_slice() {
            [] => {
                title.push_str(" to ");
                title.push_str(EDITION);
                if self.is_long_axis() && self.runs_up.max(self.runs_down) == 1 {
                    title.push_str(" (one run: axis over 2000 mm)");
                }
                if matches!(self.length, ByKind::Rotary(Deg(range_deg)) if range_deg > FULL_TURN_DEG)
                {
                    title.push_str(" (one run: rotary axis over 360°)");
                }
            }
            [only] => title.push_str(&format!(": does not meet ISO 230-2's {only}")),
            [init @ .., last] => title.push_str(&format!(
                ": does not meet ISO 230-2's {} and {last}",
                init.join(", ")
            )),
        }
        title
    }

    /// One warning per requirement missed or recommendation not followed,
    /// and the note on a long axis measured with more than one run.
    pub fn warnings(&self) -> Vec<Warning> {
        let mut warnings = Vec::new();
        let missed = |r: Requirement| self.check(r).is_some_and(|c| !c.met);
        if missed(Requirement::BothDirections) {
            let measured = if self.runs_up > 0 {
                Direction::Up
            } else {
                Direction::Down
            };
            warnings.push(Warning::Unidirectional { measured });
        }
        if missed(Requirement::Runs) {
            warnings.push(Warning::TooFewRuns {
                kind: self.kind(),
                runs_up: self.runs_up,
                runs_down: self.runs_down,
                required: STANDARD_RUNS,
            });
        }
        if missed(Requirement::Targets) || missed(Requirement::TargetsPerMetre) {
            let for_length = match self.length {
                ByKind::Linear(Mm(length_mm)) => {
                    (MIN_TARGETS_PER_M * length_mm / MM_PER_M - 1e-9).ceil()
                }
                ByKind::Rotary(_) => 0.0,
            };
            warnings.push(Warning::TooFewTargets {
                targets: self.targets,
                length: self.length,
                required: MIN_TARGETS.max(for_length as usize),
            });
        }
        // A long axis is a linear one: its travel is taken as mm from the
        // `Mm` it is, not from the axis' bare number.
        if let ByKind::Linear(Mm(length_mm)) = self.length
            && self.is_long_axis()
            && self.runs_up.max(self.runs_down) > 1
        {
            warnings.push(Warning::LongAxis {
                length_mm,
                runs: self.runs_up.max(self.runs_down),
            });
        }
        if let Some(step_mm) = self
            .check(Requirement::IrregularSpacing)
            .and_then(|c| c.found)
        {
            warnings.push(Warning::EvenSpacing { step_mm });
        }
        warnings
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::Run;

    fn test(targets_mm: Vec<f64>, up: u32, down: u32) -> TestConformance {
        let count = targets_mm.len();
        let run = |direction, number| Run {
            direction,
            number,
            start_time_s: None,
            deviations: vec![Some(0.0); count],
        };
        let mut runs: Vec<Run> = (1..=up).map(|n| run(Direction::Up, n)).collect();
        runs.extend((1..=down).map(|n| run(Direction::Down, n)));
        let m = Measurement::new(
            "X",
            targets_mm,
            runs,
            Default::default(),
            Default::default(),
        )
        .unwrap();
        check_test(&m)
    }

    fn irregular(count: usize, length_mm: f64) -> Vec<f64> {
        // Steps alternating ±3 mm around the mean step: irregular.
        let step = length_mm / (count - 1) as f64;
        (0..count)
            .map(|i| {
                let jitter = if i == 0 || i == count - 1 {
                    0.0
                } else if i % 2 == 0 {
                    3.0
                } else {
                    -3.0
                };
                i as f64 * step + jitter
            })
            .collect()
    }

    #[test]
    fn a_standard_test_meets_the_standard() {
        let c = test(irregular(16, 750.0), 5, 5);
        assert!(c.meets_iso230_2());
        assert_eq!(
            c.title(),
            "bidirectional test, 5 runs, 16 targets over 750 mm to ISO 230-2:2014"
        );
        assert!(c.warnings().is_empty());
    }

    #[test]
    fn five_targets_per_metre_and_five_in_all() {
        // 5 over exactly 1 m: 5 per metre, met. 6 over 1.5 m: 4 per metre, missed.
        assert!(test(irregular(5, 1000.0), 5, 5).meets_iso230_2());
        let c = test(irregular(6, 1500.0), 5, 5);
        let density = c.check(Requirement::TargetsPerMetre).unwrap();
        assert_eq!((density.met, density.found), (false, Some(4.0)));
        // ⌈5 × 1.5⌉ = 8 targets are needed.
        assert_eq!(
            c.warnings(),
            vec![Warning::TooFewTargets {
                targets: 6,
                length: ByKind::Linear(Mm(1500.0)),
                required: 8
            }]
        );
        // 4 over 100 mm: 40 per metre, but fewer than 5.
        let c = test(irregular(4, 100.0), 5, 5);
        assert!(!c.check(Requirement::Targets).unwrap().met);
        assert!(c.check(Requirement::TargetsPerMetre).unwrap().met);
        assert!(c.title().ends_with(": does not meet ISO 230-2's 5 targets"));
    }

    #[test]
    fn runs_and_directions() {
        let c = test(irregular(16, 750.0), 2, 2);
        assert_eq!(
            c.title(),
            "bidirectional test, 2 runs, 16 targets over 750 mm: does not meet ISO 230-2's 5 runs"
        );
        let c = test(irregular(16, 750.0), 5, 3);
        assert!(c.title().starts_with("bidirectional test, 5↑ 3↓ runs,"));
        let c = test(irregular(16, 750.0), 5, 0);
        assert_eq!(
            c.title(),
            "unidirectional test (↑ only), 5 runs, 16 targets over 750 mm: does not meet ISO 230-2's two directions"
        );
        assert_eq!(
            c.warnings(),
            vec![Warning::Unidirectional {
                measured: Direction::Up
            }]
        );
    }

    #[test]
    fn a_long_axis_needs_one_run_and_more_are_noted() {
        let one = test(irregular(20, 3000.0), 1, 1);
        assert!(one.meets_iso230_2());
        assert!(
            one.title()
                .ends_with("to ISO 230-2:2014 (one run: axis over 2000 mm)")
        );
        assert!(one.warnings().is_empty());
        let five = test(irregular(20, 3000.0), 5, 5);
        assert!(five.meets_iso230_2());
        assert_eq!(
            five.warnings(),
            vec![Warning::LongAxis {
                length_mm: 3000.0,
                runs: 5
            }]
        );
        // At 2000 mm exactly the standard cycle applies.
        assert!(!test(irregular(20, 2000.0), 1, 1).meets_iso230_2());
    }

    #[test]
    fn a_constant_step_is_reported_but_still_meets_the_standard() {
        let even: Vec<f64> = (0..5).map(|i| 15.0 + 10.2 * f64::from(i)).collect();
        let c = test(even, 5, 5);
        assert!(c.meets_iso230_2());
        let spacing = c.check(Requirement::IrregularSpacing).unwrap();
        assert!(!spacing.met);
        assert!((spacing.found.unwrap() - 10.2).abs() < 1e-12);
        assert!(matches!(
            c.warnings().as_slice(),
            [Warning::EvenSpacing { step_mm }] if (step_mm - 10.2).abs() < 1e-12
        ));
        // Two targets have one step: nothing to say about spacing.
        assert!(
            test(vec![0.0, 1.0], 5, 5)
                .check(Requirement::IrregularSpacing)
                .unwrap()
                .met
        );
    }
}
