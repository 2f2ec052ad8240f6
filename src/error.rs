//! Errors and warnings shared by every stage.
//!
//! A parser knows lines and columns but not the file it reads: it returns a
//! [`ParseError`] (`line:col: message`), and the `read` front end adds the path
//! ([`ReadError`]), so a user sees `X.rtl:31:9: expected …, found …`.
//! Lines and columns start at 1; a column counts characters, not bytes.
//!
//! Oddities that are not fatal are [`Warning`]s, returned next to the value;
//! their `Display` says what to do about them.

use std::fmt;

use crate::measurement::{AxisKind, Direction};
use crate::units::LengthUnit;
use crate::units::{AngleUnit, DeviationUnit};

/// A position in a text file. Both fields start at 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Position {
    /// Line number, starting at 1.
    pub line: usize,
    /// Column in characters, starting at 1.
    pub column: usize,
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// A fatal error found while parsing text, at a position.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{position}: {message}")]
pub struct ParseError {
    /// Where the problem is.
    pub position: Position,
    /// What was expected and what was found, lowercase, no trailing period.
    pub message: String,
}

impl ParseError {
    /// An error with a free-form message.
    pub fn new(line: usize, column: usize, message: impl Into<String>) -> ParseError {
        ParseError {
            position: Position { line, column },
            message: message.into(),
        }
    }

    /// A TOML syntax or type error, at the line and column of its span; the
    /// first line of toml's message (the rest is a source excerpt).
    pub fn from_toml(text: &str, error: &toml::de::Error) -> ParseError {
        let mut offset = error.span().map_or(0, |span| span.start).min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &text[..offset];
        let line = before.matches('\n').count() + 1;
        let column = before
            .rsplit('\n')
            .next()
            .map_or(0, |rest| rest.chars().count())
            + 1;
        let message = error
            .message()
            .lines()
            .next()
            .unwrap_or("invalid TOML")
            .trim();
        ParseError::new(line, column, message.to_string())
    }

    /// The usual shape: `expected X, found Y`.
    pub fn expected(line: usize, column: usize, expected: &str, found: &str) -> ParseError {
        ParseError::new(line, column, format!("expected {expected}, found {found}"))
    }
}

/// The top-level keys of a machine profile (`--machine`): `name`, and the
/// tables each reader takes its part from (`[controller]` the tables' axis
/// names and units, `[kinematics]` the model, `[acceptance]` the limits).
/// The one list of them, so that a misspelt table (`[controler]`,
/// `[acceptence]`) is refused by every reader instead of being skipped by
/// each as another reader's.
pub const MACHINE_PROFILE_KEYS: [&str; 4] = ["name", "controller", "kinematics", "acceptance"];

/// Refuses a machine profile with a top-level key or table not in
/// [`MACHINE_PROFILE_KEYS`], at its line and column.
pub fn check_machine_profile_keys(text: &str) -> Result<(), ParseError> {
    use serde::de::IgnoredAny;
    /// The profile's top level; the parts are their readers' to check.
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct TopLevel {
        name: Option<IgnoredAny>,
        controller: Option<IgnoredAny>,
        kinematics: Option<IgnoredAny>,
        acceptance: Option<IgnoredAny>,
    }
    match toml::from_str::<TopLevel>(text) {
        Ok(_) => Ok(()),
        Err(error) => {
            let mut parsed = ParseError::from_toml(text, &error);
            if let Some(key) = parsed.message.strip_prefix("unknown field `") {
                let key = key.split('`').next().unwrap_or_default();
                parsed.message = format!(
                    "a machine profile has no table or key {key:?}; expected {}",
                    MACHINE_PROFILE_KEYS.join(", ")
                );
            }
            Err(parsed)
        }
    }
}

/// Describes a token for an error message: quoted and shortened, or "end of line".
pub fn describe_found(token: &str) -> String {
    if token.is_empty() {
        return "end of line".to_string();
    }
    let mut shown: String = token.chars().take(24).collect();
    if token.chars().count() > 24 {
        shown.push('…');
    }
    format!("{shown:?}")
}

/// Something odd that is not fatal. `Display` says what it means and what to do.
#[derive(Clone, Debug, PartialEq)]
pub enum Warning {
    /// A section the reader does not know was skipped.
    UnknownSection {
        /// Line of the section header.
        line: usize,
        /// Its name.
        name: String,
    },
    /// A key the reader does not know was ignored.
    UnknownKey {
        /// Line of the key.
        line: usize,
        /// The key.
        key: String,
    },
    /// Readings that the file lists as missing or does not list at all.
    MissingReadings {
        /// How many (run, target) readings are missing.
        count: usize,
        /// The first few, as "run 2↑ at 45.6 mm".
        examples: Vec<String>,
    },
    /// A laser status other than "normal" on a data row.
    LaserStatus {
        /// Line of the row.
        line: usize,
        /// The status code.
        status: i64,
        /// What the file's legend says it means.
        meaning: &'static str,
    },
    /// Metadata fields that contradict each other; the reader says which it used.
    InconsistentMetadata {
        /// What disagrees and what was used.
        message: String,
    },
    /// Only one run in a direction: scatter is undefined.
    SingleRun {
        /// The direction with one run.
        direction: Direction,
    },
    /// Only one direction was measured.
    Unidirectional {
        /// The direction that was measured.
        measured: Direction,
    },
    /// Fewer runs per direction than ISO 230-2's standard test (a long axis needs one).
    TooFewRuns {
        /// Linear or rotary: which axes need fewer.
        kind: AxisKind,
        /// Runs ↑.
        runs_up: usize,
        /// Runs ↓.
        runs_down: usize,
        /// Runs the standard test has per direction.
        required: usize,
    },
    /// Fewer targets than ISO 230-2 asks: 5 in all and 5 per metre of travel.
    TooFewTargets {
        /// Targets measured.
        targets: usize,
        /// Travel, typed by the axis' kind (mm, or ° on a rotary axis).
        length: crate::measurement::Position,
        /// Targets the standard asks for this travel.
        required: usize,
    },
    /// A travel over 2000 mm measured with more than one run: allowed, noted.
    LongAxis {
        /// Travel, mm.
        length_mm: f64,
        /// Runs per direction.
        runs: usize,
    },
    /// Targets at one constant step, where a periodic error can alias.
    EvenSpacing {
        /// The step, mm.
        step_mm: f64,
    },
    /// A target lacks what a figure needs, so that figure is not evaluated.
    TargetNotEvaluated {
        /// Linear or rotary.
        kind: AxisKind,
        /// The target, in the axis' unit (mm, or ° on a rotary axis).
        target: f64,
        /// Which quantity is missing there.
        missing: String,
    },
    /// A rotary axis over 360°: ISO 230-2 takes one approach per direction
    /// and target there, so the repeatabilities and A are not evaluated.
    RotaryOverFullTurn {
        /// The span of the targets, °.
        range_deg: f64,
    },
    /// Principal angles (multiples of 90°) within a rotary axis' range that
    /// are not among its targets.
    PrincipalAnglesMissing {
        /// The angles missing, °.
        missing_deg: Vec<f64>,
    },
    /// A full-turn test with both ends of one turn (0° and 360°), whose mean
    /// deviations differ by more than the repeatability there.
    FullTurnEndsDisagree {
        /// The first end, °.
        first_deg: f64,
        /// The end one turn later, °.
        last_deg: f64,
        /// Mean bidirectional deviation x̄_i at the first, °.
        mean_first_deg: f64,
        /// At the last, °.
        mean_last_deg: f64,
        /// The larger bidirectional repeatability R_i of the two, °.
        repeatability_deg: f64,
    },
    /// Two inputs joined or compared may not belong together
    /// (`together`).
    Doubtful(Doubt),
    /// No uncertainty budget: no equipment was given and the file records
    /// no laser interferometer, so the bundled laser's data would describe
    /// another instrument.
    InstrumentUnknown {
        /// The instrument as the file names it, if it does.
        instrument: Option<String>,
    },
    /// A compensation table read as its file and parameters describe it,
    /// where the control has a setting axcomp does not know: the sentence
    /// says which and what to check.
    TableReadAs {
        /// The sentence.
        note: String,
    },
}

/// Something that makes two inputs doubtful together; the user decides.
#[derive(Clone, Debug, PartialEq)]
pub enum Doubt {
    /// The files name different machines.
    DifferentMachines {
        /// The first input.
        first: String,
        /// Its machine.
        first_machine: String,
        /// The second input.
        second: String,
        /// Its machine.
        second_machine: String,
    },
    /// The original files were written in different length units.
    DifferentUnits {
        /// The first input.
        first: String,
        /// Its unit.
        first_unit: LengthUnit,
        /// The second input.
        second: String,
        /// Its unit.
        second_unit: LengthUnit,
    },
    /// The ranges overlap only in part.
    PartialOverlap {
        /// After a position: ` mm`, or `°` on a rotary axis.
        unit: &'static str,
        /// The first input.
        first: String,
        /// Its range, mm.
        first_mm: (f64, f64),
        /// The second input.
        second: String,
        /// Its range, mm.
        second_mm: (f64, f64),
        /// What happens outside the common part.
        consequence: &'static str,
    },
}

impl fmt::Display for Doubt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Doubt::DifferentMachines {
                first,
                first_machine,
                second,
                second_machine,
            } => write!(
                f,
                "{first} names machine {first_machine:?}, {second} {second_machine:?}: check that both are of the same machine"
            ),
            Doubt::DifferentUnits {
                first,
                first_unit,
                second,
                second_unit,
            } => write!(
                f,
                "{first} was written in {}, {second} in {}: both are converted to mm, but check that they come from the same set-up",
                first_unit.as_str(),
                second_unit.as_str()
            ),
            Doubt::PartialOverlap {
                unit,
                first,
                first_mm,
                second,
                second_mm,
                consequence,
            } => write!(
                f,
                "{first} covers {} … {}{unit}, {second} {} … {}{unit}: they overlap only in part; {consequence}",
                first_mm.0, first_mm.1, second_mm.0, second_mm.1
            ),
        }
    }
}

impl Warning {
    /// The sentence, a rotary axis' deviations in `angle` (″ or µrad,
    /// `--angle-unit`); `Display` says them in ″.
    pub fn text_in(&self, angle: AngleUnit) -> String {
        let Warning::FullTurnEndsDisagree {
            first_deg,
            last_deg,
            mean_first_deg,
            mean_last_deg,
            repeatability_deg,
        } = self
        else {
            return self.to_string();
        };
        let unit = DeviationUnit::Angle(angle).suffix();
        format!(
            "{} and {} are one physical position, but their mean deviations differ by {:.2}{unit} \
             ({:+.2}{unit} and {:+.2}{unit}), more than the repeatability there ({:.2}{unit}): \
             check for drift or a reference that moved during the turn",
            degree_text(*first_deg),
            degree_text(*last_deg),
            angle.from_deg((mean_last_deg - mean_first_deg).abs()),
            angle.from_deg(*mean_first_deg),
            angle.from_deg(*mean_last_deg),
            angle.from_deg(*repeatability_deg),
        )
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::UnknownSection { line, name } => write!(
                f,
                "line {line}: unknown section {name:?} skipped; check the result if the file comes from newer software"
            ),
            Warning::UnknownKey { line, key } => {
                write!(f, "line {line}: unknown key {key:?} ignored")
            }
            Warning::MissingReadings { count, examples } => write!(
                f,
                "{count} reading(s) missing ({}); they are left out, never counted as 0; re-measure those points if they matter",
                examples.join(", ")
            ),
            Warning::LaserStatus {
                line,
                status,
                meaning,
            } => write!(
                f,
                "line {line}: laser status {status} ({meaning}); the reading is used, but check the beam path and re-measure if in doubt"
            ),
            Warning::InconsistentMetadata { message } => write!(f, "{message}"),
            Warning::TableReadAs { note } => write!(f, "{note}"),
            Warning::SingleRun { direction } => {
                write!(f, "n = 1 run {direction}: s, R and A are not evaluated")
            }
            Warning::Unidirectional { measured } => write!(
                f,
                "unidirectional test ({measured} only): bidirectional figures A, E, M, R, B and B̄ are not evaluated; \
                 ISO 230-2's test approaches every target from both directions: measure both to get them"
            ),
            Warning::TooFewRuns {
                kind,
                runs_up,
                runs_down,
                required,
            } => {
                let fewer = match kind {
                    AxisKind::Linear => "axes over 2000 mm",
                    AxisKind::Rotary => "rotary axes over 360°",
                };
                let runs = match (runs_up, runs_down) {
                    (n, 0) | (0, n) => format!("{n}"),
                    (up, down) if up == down => format!("{up}"),
                    (up, down) => format!("{up}↑ {down}↓"),
                };
                write!(
                    f,
                    "{runs} run(s) per direction: ISO 230-2's test has {required} each way (fewer only on {fewer}), \
                     and A and R from fewer runs are rough estimates; measure {required} runs each way"
                )
            }
            Warning::TooFewTargets {
                targets,
                length,
                required,
            } => {
                let over = position_text(*length);
                match length.kind() {
                    AxisKind::Rotary => write!(
                        f,
                        "{targets} target(s) over {over}: ISO 230-2 asks for at least {required}; measure at least {required}, \
                         with 0°, 90°, 180° and 270° among them where in range"
                    ),
                    AxisKind::Linear => write!(
                        f,
                        "{targets} target(s) over {over}: ISO 230-2 asks for at least 5 targets and at least 5 per metre of travel, \
                         {required} here; measure at least {required}, with a random part in the spacing"
                    ),
                }
            }
            Warning::LongAxis { length_mm, runs } => write!(
                f,
                "note: travel {} mm is over 2000 mm, where ISO 230-2 needs only one run per direction \
                 (then R and A are not evaluated); the {runs} runs of this test are more than it asks, and all are evaluated",
                mm_text(*length_mm)
            ),
            Warning::InstrumentUnknown { instrument } => {
                let named = instrument.as_ref().map_or_else(
                    || "names no instrument".to_string(),
                    |name| format!("names {name}, not a laser interferometer"),
                );
                write!(
                    f,
                    "measurement uncertainty not evaluated: instrument unknown (give --equipment); the file {named}, \
                     and the bundled laser's data would describe another instrument"
                )
            }
            Warning::EvenSpacing { step_mm } => write!(
                f,
                "targets evenly spaced every {} mm: a periodic error (screw lead, scale period) whose period divides the step \
                 is read at the same phase at every target and hides in the figures, and shorter periods alias into slow waves; \
                 ISO 230-2 recommends irregular spacing: give each target a different random offset",
                mm_text(*step_mm)
            ),
            Warning::TargetNotEvaluated {
                kind,
                target,
                missing,
            } => write!(
                f,
                "target {target} {} has no {missing}; the axis figures that need it are not evaluated",
                kind.position_unit()
            ),
            Warning::RotaryOverFullTurn { range_deg } => write!(
                f,
                "rotary axis over 360° ({}): ISO 230-2 takes one approach per direction and target there (n = 1), \
                 so the repeatabilities and A are not evaluated",
                degree_text(*range_deg)
            ),
            Warning::PrincipalAnglesMissing { missing_deg } => {
                let angles: Vec<String> = missing_deg
                    .iter()
                    .map(|angle| degree_text(*angle))
                    .collect();
                write!(
                    f,
                    "principal angle(s) {} within the range are not among the targets: ISO 230-2 asks a rotary test \
                     to include 0°, 90°, 180° and 270° where in range; add them",
                    angles.join(", ")
                )
            }
            Warning::FullTurnEndsDisagree { .. } => {
                f.write_str(&self.text_in(AngleUnit::default()))
            }
            Warning::Doubtful(doubt) => write!(f, "{doubt}"),
        }
    }
}

/// A length in mm for a sentence: at most three decimals, no trailing zeros.
pub(crate) fn mm_text(value_mm: f64) -> String {
    three_decimals(value_mm)
}

/// A number for a sentence: at most three decimals, no trailing zeros
/// (µm for a length in mm, thousandths of a degree for an angle).
fn three_decimals(value: f64) -> String {
    format!("{}", (value * 1000.0).round() / 1000.0 + 0.0)
}

/// An angle in degrees for a sentence, as [`position_text`] writes it.
fn degree_text(value_deg: f64) -> String {
    position_text(crate::measurement::ByKind::Rotary(crate::units::Deg(
        value_deg,
    )))
}

/// A position or length in its axis' unit for a sentence: at most three
/// decimals of that unit, no trailing zeros, then ` mm` or `°`.
pub(crate) fn position_text(position: crate::measurement::Position) -> String {
    format!(
        "{}{}",
        three_decimals(position.in_axis_unit()),
        position.unit_after_number()
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::ReadError;
    use std::path::PathBuf;

    #[test]
    fn parse_error_reads_as_path_line_column() {
        let error = ReadError::Parse {
            path: PathBuf::from("X.rtl"),
            error: ParseError::expected(31, 9, "a deviation value", "end of line"),
        };
        assert_eq!(
            error.to_string(),
            "X.rtl:31:9: expected a deviation value, found end of line"
        );
    }

    #[test]
    fn too_few_targets_are_said_in_the_axis_unit() {
        use crate::measurement::ByKind;
        use crate::units::{Deg, Mm};
        // 3 targets over 90.0004°: at most three decimals of a degree, 90°.
        let rotary = Warning::TooFewTargets {
            targets: 3,
            length: ByKind::Rotary(Deg(90.0004)),
            required: 5,
        };
        assert_eq!(
            rotary.to_string(),
            "3 target(s) over 90°: ISO 230-2 asks for at least 5; measure at least 5, \
             with 0°, 90°, 180° and 270° among them where in range"
        );
        // 6 targets over 1500.0625 mm: 1500.063 mm; ⌈5 × 1.5⌉ = 8 needed.
        let linear = Warning::TooFewTargets {
            targets: 6,
            length: ByKind::Linear(Mm(1500.0625)),
            required: 8,
        };
        assert_eq!(
            linear.to_string(),
            "6 target(s) over 1500.063 mm: ISO 230-2 asks for at least 5 targets and at least 5 per metre of travel, \
             8 here; measure at least 8, with a random part in the spacing"
        );
    }

    #[test]
    fn found_tokens_are_quoted_and_shortened() {
        assert_eq!(describe_found(""), "end of line");
        assert_eq!(describe_found("1,5"), "\"1,5\"");
        assert_eq!(
            describe_found("abcdefghijklmnopqrstuvwxyz"),
            "\"abcdefghijklmnopqrstuvwx…\""
        );
    }
}
