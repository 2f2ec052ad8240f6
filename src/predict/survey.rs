//! A machine's measured state (`axcomp predict --survey S.toml`): the
//! measurement files of one machine, and the 21-error description built
//! from them.
//!
//! ```toml
//! errors = "declared.toml"          # optional: the errors not measured (else zero)
//! reference_line = "least-squares"  # or "end-points" (ISO 230-1), for every straightness
//!
//! [squareness]
//! convention = "right-handed"       # or "larger-than-90": how values are signed
//! from_straightness = ["XY", "XZ"]  # pairs whose two straightness tests share a reference
//! given_urad = { YZ = 12.0 }        # measured otherwise (ballbar, square), signed as above
//!
//! [[test]]
//! file = "x-6dof.csv"               # geometry CSV (EYX_um, EBX_urad, …) or any positioning test
//! axis = "X"                        # optional: the file's own axis otherwise
//! errors = ["EYX", "EBX"]           # optional: the columns to take (default: all)
//! line_mm = { y = 250.0, z = -275.0 }        # machine position of the line (default: reference)
//! optics_offset_mm = { x = 0.0, y = 0.0, z = -60.0 }  # moving optics from the tool tip
//! optics_on = "workpiece"           # optional: "tool" or "workpiece" (default: the body the axis moves)
//! ```
//!
//! **Where the moving optic is.** It sits on the body `optics_on` names,
//! by default the one the measured axis moves as the machine's chain says
//! (on ZFYX: X and Y move the table, Z the tool), `optics_offset_mm` from
//! the tool tip; the laser stands on the other body. The angles of the axes
//! under that body take the offset into their Abbe arms
//! ([`Machine::with_optics`]). [`MeasuredState::optics`] says where each
//! test's optic was taken to be.
//!
//! **How each error is taken** (model units: mm, rad):
//!
//! 1. An angle (roll, pitch, yaw) is the test's mean reading per target
//!    (both directions), less its value at the machine's reference
//!    position: an angular interferometer reads relative angles, and the
//!    model's volumetric error is zero at the reference (eq. 68). A constant
//!    angle offset is not observable from a line (it is one with the other
//!    axes' angles in eq. 69), so it is taken as zero.
//! 2. A straightness EDA reads the model's E_D along the test's line, which
//!    holds the Abbe terms of A's angles at the line and the optics (the
//!    same arithmetic as a positioning test, `calibrated_errors`): EDA is the
//!    reading minus the model's contribution of the other errors (squareness
//!    left out), then its ISO 230-1 reference line is taken out
//!    (`evaluate::straightness`) and the slope kept apart.
//! 3. A squareness from the slopes of the pair's two straightness tests
//!    ([`crate::evaluate::straightness::angle_excess`]), turned into the
//!    model's EXOY, EXOZ or EYOZ by the model's own response to a unit
//!    squareness on the same two lines (the chain decides how a squareness
//!    tilts each axis); or given.
//! 4. A positioning error (a positioning test, or an `EXX_um` column) goes
//!    to `predict`'s calibration on its line (`MeasuredAxis`), after all the
//!    above are known.
//!
//! What no test measured stays as the `errors` file declares it, or zero;
//! [`MeasuredState::sources`] says which is which.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::{PredictError, axis_named, positioning_error};
use crate::error::ParseError;
use crate::evaluate::straightness::{
    ReferenceLine, SquarenessConvention, Straightness, angle_excess, straightness,
};
use crate::measurement::{AxisSource, Measurement, Metadata, Run};
use crate::model::{
    Axis, ErrorComponent, ErrorFunction, ErrorName, ErrorTable, GeometricErrors, Interpolation,
    Machine, Method, ModelError, Optics, OpticsBody, SquarenessPair,
};

/// Why a survey file is not valid: the model's error (TOML at a position, or
/// a value it cannot use, named by its key).
pub type SurveyError = ModelError;
use crate::read::geometry::{GeometryColumn, GeometryTest, Quantity};
use crate::units::um_per_m_to_rad;

/// A survey file, validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Survey {
    /// The declared errors' file, as written (relative to the survey).
    pub errors_file: Option<String>,
    /// The reference line of every straightness.
    pub reference_line: ReferenceLine,
    /// How squareness values are signed (given and reported).
    pub convention: SquarenessConvention,
    /// Pairs whose squareness comes from their two straightness tests.
    pub squareness_from_straightness: Vec<SquarenessPair>,
    /// Squareness measured otherwise: pair and value, rad, signed in `convention`.
    pub squareness_given: Vec<(SquarenessPair, f64)>,
    /// The tests.
    pub tests: Vec<SurveyTest>,
}

/// One `[[test]]` of a survey.
#[derive(Clone, Debug, PartialEq)]
pub struct SurveyTest {
    /// The file, as written (relative to the survey).
    pub file: String,
    /// The axis, if the survey names it.
    pub axis: Option<Axis>,
    /// The errors to take from it (all its columns if `None`).
    pub errors: Option<Vec<ErrorName>>,
    /// Machine position of the line; `None` coordinates: the reference.
    pub line_mm: [Option<f64>; 3],
    /// Moving optics from the tool tip, mm.
    pub optics_offset_mm: [f64; 3],
    /// The body that carries the moving optic, if the survey says
    /// (otherwise the body the test's axis moves).
    pub optics_on: Option<OpticsBody>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSurvey {
    errors: Option<String>,
    reference_line: Option<String>,
    squareness: Option<RawSquareness>,
    #[serde(default)]
    test: Vec<RawTest>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSquareness {
    convention: Option<String>,
    #[serde(default)]
    from_straightness: Vec<String>,
    #[serde(default)]
    given_urad: BTreeMap<String, f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTest {
    file: String,
    axis: Option<String>,
    errors: Option<Vec<String>>,
    line_mm: Option<RawPosition>,
    optics_offset_mm: Option<RawPosition>,
    optics_on: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawPosition {
    x: Option<f64>,
    y: Option<f64>,
    z: Option<f64>,
}

fn invalid(what: impl Into<String>, expected: &str, found: impl Into<String>) -> SurveyError {
    ModelError::invalid(what, expected, found)
}

fn pair_named(name: &str) -> Option<SquarenessPair> {
    match name.to_ascii_uppercase().as_str() {
        "XY" | "YX" => Some(SquarenessPair::XY),
        "XZ" | "ZX" => Some(SquarenessPair::XZ),
        "YZ" | "ZY" => Some(SquarenessPair::YZ),
        _ => None,
    }
}

/// The pair's name as the survey writes it.
pub fn pair_name(pair: SquarenessPair) -> &'static str {
    match pair {
        SquarenessPair::XY => "XY",
        SquarenessPair::XZ => "XZ",
        SquarenessPair::YZ => "YZ",
    }
}

impl Survey {
    /// Parses a survey file.
    ///
    /// # Example
    ///
    /// ```
    /// use axcomp::predict::survey::Survey;
    ///
    /// let survey = Survey::from_toml_str(
    ///     "[squareness]\nconvention = \"larger-than-90\"\nfrom_straightness = [\"XY\"]\n\n\
    ///      [[test]]\nfile = \"x.csv\"\nline_mm = { y = 250.0 }\n",
    /// )?;
    /// assert_eq!(survey.tests[0].line_mm, [None, Some(250.0), None]);
    /// # Ok::<(), axcomp::model::ModelError>(())
    /// ```
    pub fn from_toml_str(text: &str) -> Result<Survey, SurveyError> {
        let raw: RawSurvey = toml::from_str(text)
            .map_err(|error| ModelError::Toml(ParseError::from_toml(text, &error)))?;
        let reference_line = match raw.reference_line.as_deref() {
            None => ReferenceLine::default(),
            Some(name) => ReferenceLine::from_name(name).ok_or_else(|| {
                invalid(
                    "reference_line",
                    "\"least-squares\" or \"end-points\"",
                    name,
                )
            })?,
        };
        let squareness = raw.squareness.unwrap_or(RawSquareness {
            convention: None,
            from_straightness: Vec::new(),
            given_urad: BTreeMap::new(),
        });
        let convention = match squareness.convention.as_deref() {
            None => SquarenessConvention::default(),
            Some(name) => SquarenessConvention::from_name(name).ok_or_else(|| {
                invalid(
                    "squareness.convention",
                    "\"right-handed\" or \"larger-than-90\"",
                    name,
                )
            })?,
        };
        let pair = |what: &str, name: &str| {
            pair_named(name).ok_or_else(|| invalid(what, "a pair XY, XZ or YZ", name))
        };
        let mut from_straightness = Vec::new();
        for name in &squareness.from_straightness {
            from_straightness.push(pair("squareness.from_straightness", name)?);
        }
        let mut given = Vec::new();
        for (name, value) in &squareness.given_urad {
            let p = pair("squareness.given_urad", name)?;
            if from_straightness.contains(&p) || !value.is_finite() {
                return Err(invalid(
                    format!("squareness.given_urad.{name}"),
                    "a finite value for a pair not also taken from straightness",
                    value.to_string(),
                ));
            }
            given.push((p, um_per_m_to_rad(*value)));
        }
        let mut tests = Vec::new();
        for (index, test) in raw.test.into_iter().enumerate() {
            let what = |key: &str| format!("test {} ({}): {key}", index + 1, test.file);
            let axis = match &test.axis {
                None => None,
                Some(name) => Some(
                    axis_named("a test", name)
                        .map_err(|_| invalid(what("axis"), "X, Y or Z", name))?,
                ),
            };
            let errors = match &test.errors {
                None => None,
                Some(names) => Some(
                    names
                        .iter()
                        .map(|n| {
                            ErrorName::from_name(n)
                                .ok_or_else(|| invalid(what("errors"), "ISO 230-1 names", n))
                        })
                        .collect::<Result<Vec<_>, _>>()?,
                ),
            };
            let position = |p: Option<RawPosition>| {
                let p = p.unwrap_or_default();
                [p.x, p.y, p.z]
            };
            let optics_on = match &test.optics_on {
                None => None,
                Some(name) => Some(OpticsBody::from_name(name).ok_or_else(|| {
                    invalid(what("optics_on"), "\"tool\" or \"workpiece\"", name)
                })?),
            };
            let line_mm = position(test.line_mm);
            let optics = position(test.optics_offset_mm);
            if let Some(bad) = line_mm
                .iter()
                .chain(&optics)
                .flatten()
                .find(|v| !v.is_finite())
            {
                return Err(invalid(what("position"), "finite mm", bad.to_string()));
            }
            tests.push(SurveyTest {
                file: test.file,
                axis,
                errors,
                line_mm,
                optics_offset_mm: optics.map(|v| v.unwrap_or(0.0)),
                optics_on,
            });
        }
        Ok(Survey {
            errors_file: raw.errors,
            reference_line,
            convention,
            squareness_from_straightness: from_straightness,
            squareness_given: given,
            tests,
        })
    }
}

/// A survey test's content, as `read` gave it.
#[derive(Clone, Debug)]
pub enum SurveyFile {
    /// A geometry test (CSV with error columns).
    Geometry(GeometryTest),
    /// A positioning test in any format `read` takes.
    Positioning(Box<Measurement>),
}

/// Where the value of one of the 21 errors came from.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// Measured by this file.
    Measured(String),
    /// From the straightness tests in these two files.
    Squareness([String; 2]),
    /// Given in the survey's `[squareness]`.
    GivenSquareness,
    /// As the errors file declares it.
    Declared,
    /// Not measured, not declared: zero.
    AssumedZero,
}

impl Source {
    /// Whether it was measured (by a test, through straightness, or given as measured).
    pub fn is_measured(&self) -> bool {
        matches!(
            self,
            Source::Measured(_) | Source::Squareness(_) | Source::GivenSquareness
        )
    }
}

/// A straightness as evaluated.
#[derive(Clone, Debug, PartialEq)]
pub struct StraightnessResult {
    /// The error.
    pub name: ErrorName,
    /// The file.
    pub file: String,
    /// Against its reference line, after the Abbe terms are taken out.
    pub straightness: Straightness,
}

/// A squareness as found.
#[derive(Clone, Debug, PartialEq)]
pub struct SquarenessResult {
    /// The pair.
    pub pair: SquarenessPair,
    /// The angle between the positive directions minus 90°, rad.
    pub excess_rad: f64,
    /// The value in the survey's convention, rad.
    pub signed_rad: f64,
    /// The model's EXOY, EXOZ or EYOZ, rad.
    pub model_rad: f64,
}

/// A positioning test and where it was measured.
#[derive(Clone, Debug)]
pub struct PositioningTest {
    /// The test.
    pub measurement: Measurement,
    /// The file.
    pub file: String,
    /// Machine position of the line, mm.
    pub line_mm: [f64; 3],
    /// Its moving optic, as taken.
    pub optics: Optics,
}

/// Where a test's moving optic was taken to be.
#[derive(Clone, Debug, PartialEq)]
pub struct TestOptics {
    /// The file.
    pub file: String,
    /// The axis it measured.
    pub axis: Axis,
    /// The body and the offset.
    pub optics: Optics,
    /// Whether the survey named the body (else it is the one the axis moves).
    pub body_stated: bool,
}

/// The machine's measured state: the 21 errors (positioning still to be
/// calibrated by `predict` from [`MeasuredState::positioning`]).
#[derive(Clone, Debug)]
pub struct MeasuredState {
    /// The errors: declared, with the measured angles, straightness and squareness.
    pub errors: GeometricErrors,
    /// The positioning tests for `predict` (`MeasuredAxis`).
    pub positioning: Vec<PositioningTest>,
    /// Every one of the 21 errors and where its value came from, in ISO order.
    pub sources: Vec<(ErrorName, Source)>,
    /// The straightness tests as evaluated.
    pub straightness: Vec<StraightnessResult>,
    /// The squareness errors found or given.
    pub squareness: Vec<SquarenessResult>,
    /// The survey's convention.
    pub convention: SquarenessConvention,
    /// Each test's moving optic as taken, in the survey's order.
    pub optics: Vec<TestOptics>,
}

/// One column of a test, taken.
struct Taken<'a> {
    name: ErrorName,
    file: &'a str,
    test: &'a GeometryTest,
    column: &'a GeometryColumn,
    line_mm: [f64; 3],
    optics: Optics,
}

/// Builds the measured state from a survey, the declared errors and each
/// test's content (in the survey's order).
pub fn assemble(
    machine: &Machine,
    survey: &Survey,
    declared: &GeometricErrors,
    files: &[SurveyFile],
) -> Result<MeasuredState, PredictError> {
    let reference = machine.reference_mm();
    let mut errors = declared.clone();
    let mut sources: BTreeMap<usize, Source> = BTreeMap::new();
    let index_of = |name: ErrorName| ErrorName::ALL.iter().position(|n| *n == name).unwrap_or(0);
    let declared_nonzero = |name: ErrorName| match declared.function(name) {
        Some(f) => *f != ErrorFunction::Constant(0.0),
        None => {
            let ErrorComponent::Squareness(pair) = name.component() else {
                return false;
            };
            declared.squareness.get(pair) != 0.0
        }
    };
    let mut claim = |name: ErrorName, source: Source| -> Result<(), PredictError> {
        if declared_nonzero(name) || sources.contains_key(&index_of(name)) {
            return Err(PredictError::GivenTwice(name));
        }
        sources.insert(index_of(name), source);
        Ok(())
    };
    let mut angles = Vec::new();
    let mut lines = Vec::new();
    let mut positioning = Vec::new();
    let mut optics_taken = Vec::new();
    let mut taken_optics = |axis: Axis, test: &SurveyTest| {
        let optics = Optics {
            body: test
                .optics_on
                .unwrap_or_else(|| machine.chain().body_moved_by(axis)),
            offset_mm: test.optics_offset_mm,
        };
        optics_taken.push(TestOptics {
            file: test.file.clone(),
            axis,
            optics,
            body_stated: test.optics_on.is_some(),
        });
        optics
    };
    for (test, file) in survey.tests.iter().zip(files) {
        let line_of = |axis: Axis| -> [f64; 3] {
            let mut line = [0, 1, 2].map(|i| test.line_mm[i].unwrap_or(reference[i]));
            line[axis.index()] = reference[axis.index()];
            line
        };
        match file {
            SurveyFile::Positioning(measurement) => {
                let axis = match test.axis {
                    Some(axis) => axis,
                    None => axis_named("a positioning test", measurement.axis())?,
                };
                claim(positioning_error(axis), Source::Measured(test.file.clone()))?;
                let optics = taken_optics(axis, test);
                positioning.push(PositioningTest {
                    measurement: (**measurement).clone(),
                    file: test.file.clone(),
                    line_mm: line_of(axis),
                    optics,
                });
            }
            SurveyFile::Geometry(geometry) => {
                let axis = axis_named("a geometry test", &geometry.axis.to_string())?;
                if test.axis.is_some_and(|a| a != axis) {
                    return Err(survey_error(
                        &test.file,
                        format!(
                            "the survey says axis {:?}, the file's columns are of axis {axis}",
                            test.axis
                        ),
                    ));
                }
                if let Some(wanted) = &test.errors
                    && let Some(missing) = wanted
                        .iter()
                        .find(|n| geometry.column(n.as_str()).is_none())
                {
                    return Err(survey_error(
                        &test.file,
                        format!("the survey takes {missing}, the file has no {missing} column"),
                    ));
                }
                let optics = taken_optics(axis, test);
                for column in &geometry.columns {
                    let name = ErrorName::from_name(&column.name).ok_or_else(|| {
                        PredictError::Internal(format!("column {} is no error name", column.name))
                    })?;
                    if test.errors.as_ref().is_some_and(|w| !w.contains(&name)) {
                        continue;
                    }
                    claim(name, Source::Measured(test.file.clone()))?;
                    if name == positioning_error(axis) {
                        positioning.push(PositioningTest {
                            measurement: positioning_measurement(geometry, column, &test.file)?,
                            file: test.file.clone(),
                            line_mm: line_of(axis),
                            optics,
                        });
                        continue;
                    }
                    let taken = Taken {
                        name,
                        file: &test.file,
                        test: geometry,
                        column,
                        line_mm: line_of(axis),
                        optics,
                    };
                    match column.quantity {
                        Quantity::Rotation(_) => angles.push(taken),
                        Quantity::Translation(_) => lines.push(taken),
                    }
                }
            }
        }
    }
    // 1. Angles: relative readings, zero at the reference position.
    for taken in &angles {
        let axis = axis_of(taken.name);
        let (positions, values) = present_means(taken)?;
        let at_reference =
            ErrorTable::new(positions.clone(), values.clone(), Interpolation::Linear)?
                .value_at(reference[axis.index()]);
        let values = values.iter().map(|v| v - at_reference).collect();
        let table = ErrorTable::new(positions, values, Interpolation::Linear)?;
        errors.set(taken.name, ErrorFunction::Table(table))?;
    }
    // 2. Straightness: the reading less the others' Abbe terms, its line out.
    let mut without_squareness = errors.clone();
    without_squareness.squareness = Default::default();
    let mut straightness_results = Vec::new();
    let mut slopes: Vec<(ErrorName, f64, &Taken<'_>)> = Vec::new();
    for taken in &lines {
        let ErrorComponent::Translation { direction, .. } = taken.name.component() else {
            continue;
        };
        let test_machine = machine.with_optics(&taken.optics)?;
        let (positions, readings) = present_means(taken)?;
        let mut others = without_squareness.clone();
        others.set(taken.name, ErrorFunction::Constant(0.0))?;
        let corrected: Vec<f64> = positions
            .iter()
            .zip(&readings)
            .map(|(&x, reading)| reading - along_line(&test_machine, &others, taken, direction, x))
            .collect();
        let fit = straightness(&positions, &corrected, survey.reference_line);
        let table = ErrorTable::new(
            positions.clone(),
            fit.residuals_mm.clone(),
            Interpolation::Linear,
        )?;
        errors.set(taken.name, ErrorFunction::Table(table))?;
        slopes.push((taken.name, fit.slope, taken));
        straightness_results.push(StraightnessResult {
            name: taken.name,
            file: taken.file.to_string(),
            straightness: fit,
        });
    }
    // 3. Squareness: from the pair's two slopes, through the model's response.
    let mut squareness = Vec::new();
    for pair in &survey.squareness_from_straightness {
        let (a, b) = pair.axes();
        let find = |axis: Axis, direction: Axis| {
            let name = ErrorName::of(ErrorComponent::Translation { axis, direction });
            slopes
                .iter()
                .find(|(n, _, _)| *n == name)
                .ok_or_else(|| {
                    survey_error(
                        "[squareness]",
                        format!(
                            "squareness {} from straightness needs a test of {name}, and the survey has none",
                            pair_name(*pair)
                        ),
                    )
                })
        };
        let (_, slope_ab, taken_ab) = find(a, b)?;
        let (_, slope_ba, taken_ba) = find(b, a)?;
        let excess = angle_excess(*slope_ab, *slope_ba);
        let gain = squareness_gain(machine, *pair, taken_ab, taken_ba, survey.reference_line)?;
        let model_rad = excess / gain;
        let name = ErrorName::of(ErrorComponent::Squareness(*pair));
        claim(
            name,
            Source::Squareness([taken_ab.file.to_string(), taken_ba.file.to_string()]),
        )?;
        errors.squareness.set(*pair, model_rad);
        squareness.push(SquarenessResult {
            pair: *pair,
            excess_rad: excess,
            signed_rad: survey.convention.signed(excess),
            model_rad,
        });
    }
    for (pair, signed) in &survey.squareness_given {
        let excess = survey.convention.excess(*signed);
        let gain = squareness_gain_nominal(machine, *pair)?;
        let model_rad = excess / gain;
        claim(
            ErrorName::of(ErrorComponent::Squareness(*pair)),
            Source::GivenSquareness,
        )?;
        errors.squareness.set(*pair, model_rad);
        squareness.push(SquarenessResult {
            pair: *pair,
            excess_rad: excess,
            signed_rad: *signed,
            model_rad,
        });
    }
    let sources = ErrorName::ALL
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let source = sources
                .get(&i)
                .cloned()
                .unwrap_or(if declared_nonzero(*name) {
                    Source::Declared
                } else {
                    Source::AssumedZero
                });
            (*name, source)
        })
        .collect();
    Ok(MeasuredState {
        errors,
        positioning,
        sources,
        straightness: straightness_results,
        squareness,
        convention: survey.convention,
        optics: optics_taken,
    })
}

fn survey_error(what: &str, why: String) -> PredictError {
    PredictError::Survey {
        what: what.to_string(),
        why,
    }
}

/// The moving axis of a motion error.
fn axis_of(name: ErrorName) -> Axis {
    match name.component() {
        ErrorComponent::Translation { axis, .. } | ErrorComponent::Rotation { axis, .. } => axis,
        ErrorComponent::Squareness(pair) => pair.axes().0,
    }
}

/// The targets with a mean reading, and the means (mm or rad).
fn present_means(taken: &Taken<'_>) -> Result<(Vec<f64>, Vec<f64>), PredictError> {
    let (positions, values): (Vec<f64>, Vec<f64>) = taken
        .test
        .targets_mm
        .iter()
        .zip(taken.column.means())
        .filter_map(|(t, m)| m.map(|m| (*t, m)))
        .unzip();
    if positions.len() < 2 {
        return Err(survey_error(
            taken.file,
            format!("{} has fewer than two targets with a reading", taken.name),
        ));
    }
    Ok((positions, values))
}

/// The model's E_`direction` on the line of `taken` with its axis at
/// `x_mm`, mm (`machine`: as its optic sees it).
fn along_line(
    machine: &Machine,
    errors: &GeometricErrors,
    taken: &Taken<'_>,
    direction: Axis,
    x_mm: f64,
) -> f64 {
    let axis = axis_of(taken.name);
    let mut p = taken.line_mm;
    p[axis.index()] = x_mm;
    machine
        .volumetric_error(errors, p, Method::Full)
        .translation_mm[direction.index()]
}

/// The angle excess over 90° (rad) that a unit model squareness of `pair`
/// gives on the two tests' lines, against the same reference line as the
/// measurement: measured excess / gain = the model's value.
fn squareness_gain(
    machine: &Machine,
    pair: SquarenessPair,
    taken_ab: &Taken<'_>,
    taken_ba: &Taken<'_>,
    reference_line: ReferenceLine,
) -> Result<f64, PredictError> {
    const UNIT: f64 = 1e-6;
    let mut errors = GeometricErrors::default();
    errors.squareness.set(pair, UNIT);
    let (a, b) = pair.axes();
    let slope = |taken: &Taken<'_>, direction: Axis| -> Result<f64, PredictError> {
        let test_machine = machine.with_optics(&taken.optics)?;
        let (positions, _) = present_means(taken)?;
        let values: Vec<f64> = positions
            .iter()
            .map(|&x| along_line(&test_machine, &errors, taken, direction, x))
            .collect();
        Ok(straightness(&positions, &values, reference_line).slope)
    };
    let gain = angle_excess(slope(taken_ab, b)?, slope(taken_ba, a)?) / UNIT;
    check_gain(pair, gain)
}

/// The same gain at the reference position over the strokes (a squareness
/// given without its tests).
fn squareness_gain_nominal(machine: &Machine, pair: SquarenessPair) -> Result<f64, PredictError> {
    const UNIT: f64 = 1e-6;
    let mut errors = GeometricErrors::default();
    errors.squareness.set(pair, UNIT);
    let (a, b) = pair.axes();
    let reference = machine.reference_mm();
    let slope = |axis: Axis, direction: Axis| {
        let [low, high] = machine.axis(axis).stroke_mm;
        let at = |x: f64| {
            let mut p = reference;
            p[axis.index()] = x;
            machine
                .volumetric_error(&errors, p, Method::Full)
                .translation_mm[direction.index()]
        };
        (at(high) - at(low)) / (high - low)
    };
    let gain = angle_excess(slope(a, b), slope(b, a)) / UNIT;
    check_gain(pair, gain)
}

fn check_gain(pair: SquarenessPair, gain: f64) -> Result<f64, PredictError> {
    if !(gain.abs() > 1e-3 && gain.is_finite()) {
        return Err(PredictError::Internal(format!(
            "the model's squareness {} does not change the angle between its axes (gain {gain})",
            pair_name(pair)
        )));
    }
    Ok(gain)
}

/// A positioning column of a geometry test as a positioning `Measurement`.
fn positioning_measurement(
    test: &GeometryTest,
    column: &GeometryColumn,
    file: &str,
) -> Result<Measurement, PredictError> {
    let runs = column
        .runs
        .iter()
        .map(|run| Run {
            direction: run.direction,
            number: u32::try_from(run.number).unwrap_or(u32::MAX),
            start_time_s: None,
            deviations: run.values.clone(),
        })
        .collect();
    let metadata = Metadata {
        axis_source: AxisSource::file(format!("{} column", column.name)),
        machine: test.machine.clone(),
        source_file: Some(file.into()),
        ..Default::default()
    };
    Ok(Measurement::new(
        test.axis.to_string(),
        test.targets_mm.clone(),
        runs,
        Default::default(),
        metadata,
    )?)
}

/// The survey's squareness pair as the model names the error.
pub fn squareness_name(pair: SquarenessPair) -> ErrorName {
    ErrorName::of(ErrorComponent::Squareness(pair))
}

/// The errors the survey measured, and those it assumed (declared or zero).
pub fn measured_and_assumed(state: &MeasuredState) -> (Vec<ErrorName>, Vec<ErrorName>) {
    let measured = state
        .sources
        .iter()
        .filter(|(_, s)| s.is_measured())
        .map(|(n, _)| *n)
        .collect();
    let assumed = state
        .sources
        .iter()
        .filter(|(_, s)| !s.is_measured())
        .map(|(n, _)| *n)
        .collect();
    (measured, assumed)
}

#[cfg(test)]
mod tests;
