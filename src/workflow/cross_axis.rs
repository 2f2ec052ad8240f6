//! `convert STRAIGHTNESS.csv`: a straightness test to the cross-axis table
//! the controller loads ("Y = F(X)": the values move Y as a function of X's
//! position). The straightness is taken as `predict --survey` takes it (a
//! survey of this one file): the Abbe terms of the file's own angles at the
//! test's line and optics offset out, then the ISO 230-1 reference line; the
//! slope is reported, never compensated.

use crate::compensate::cross_axis::CrossAxisTable;
use crate::compensate::plan::{PlanContext, Request, plan};
use crate::compensate::{CompensateError, grid_positions};
use crate::emit::{self, Controller, MachineProfile, Provenance, tnc640};
use crate::evaluate::straightness::ReferenceLine;
use crate::measurement::AxisKind;
use crate::model::{ErrorComponent, ErrorName, GeometricErrors, Machine};
use crate::predict::cross_axis_table_at;
use crate::predict::survey::{Survey, SurveyFile, SurveyTest, assemble};
use crate::read::geometry::{GeometryTest, Quantity};
use crate::report::cross_axis::{CrossAxisJson, CrossAxisPoint, CrossAxisText};
use crate::units::{LengthUnit, mm_to_um, rad_to_um_per_m};

use super::WorkflowError;
use super::table::{WriteAs, write_options};

/// The controllers with a cross-axis table in axcomp.
const CONTROLLERS: &str = "tnc640 (a .COM with a dependent column) and sinumerik840d (a CEC table with another output axis)";

/// A straightness test and what its table is made for (`convert`'s flags).
pub struct CrossAxisRequest<'a> {
    /// The controller.
    pub controller: Controller,
    /// The machine (its reference position and chain).
    pub machine: &'a Machine,
    /// The machine profile (axis names, CEC tables).
    pub profile: &'a MachineProfile,
    /// The test.
    pub geometry: &'a GeometryTest,
    /// Its file as messages name it.
    pub file: &'a str,
    /// Its file name, which the table's comment names.
    pub source: String,
    /// The straightness column (`--straightness`), when the test has several.
    pub straightness: Option<&'a str>,
    /// The reference line.
    pub reference_line: ReferenceLine,
    /// The machine position of the test's line, mm.
    pub line_mm: [Option<f64>; 3],
    /// The moving optics from the tool tip, mm.
    pub optics_offset_mm: [f64; 3],
    /// The grid and the reference (`--step`, `--start`, `--count`, `--reference`).
    pub grid: Request,
    /// The TNC 640's existing table of the axis (its text and file name): the
    /// points, and the columns kept.
    pub existing: Option<(&'a str, &'a str)>,
    /// The name inside Heidenhain files.
    pub table_name: String,
    /// The output as the user named it.
    pub output: String,
    /// Its file name, which the activation names.
    pub file_name: String,
    /// `--max-points`.
    pub max_points: Option<usize>,
}

/// The cross-axis table: the file's text, `convert --json`'s object and
/// what the terminal says besides.
pub struct CrossAxis {
    /// What the controller loads.
    pub text: String,
    /// `convert --json`'s object.
    pub report: CrossAxisJson,
    /// The terminal's context.
    pub terminal: CrossAxisText,
}

fn refused(message: String) -> WorkflowError {
    WorkflowError::Refused(message)
}

/// The cross-axis table of `request`'s straightness test.
pub fn cross_axis(request: &CrossAxisRequest<'_>) -> Result<CrossAxis, WorkflowError> {
    let file = request.file;
    if !request.controller.writes_cross_axis() {
        return Err(refused(format!(
            "{file}: a straightness test gives a cross-axis table, which axcomp writes for {CONTROLLERS}; {} has none here",
            request.controller.name()
        )));
    }
    let profile = request.profile;
    if profile.machine_unit() != LengthUnit::Millimetre {
        return Err(refused(format!(
            "{file}: cross-axis tables are written in mm only, and the machine profile's unit is {}",
            profile.machine_unit().as_str()
        )));
    }
    let geometry = request.geometry;
    let name = chosen_straightness(file, geometry, request.straightness)?;
    let ErrorComponent::Translation { axis, direction } = name.component() else {
        return Err(refused(format!("{name} is no straightness")));
    };
    let survey = Survey {
        errors_file: None,
        reference_line: request.reference_line,
        convention: Default::default(),
        squareness_from_straightness: Vec::new(),
        squareness_given: Vec::new(),
        tests: vec![SurveyTest {
            file: file.to_string(),
            axis: None,
            errors: None,
            line_mm: request.line_mm,
            optics_offset_mm: request.optics_offset_mm,
            optics_on: None,
        }],
    };
    let state = assemble(
        request.machine,
        &survey,
        &GeometricErrors::default(),
        &[SurveyFile::Geometry(geometry.clone())],
    )
    .map_err(|e| refused(format!("{file}: {e}")))?;
    let Some(result) = state.straightness.iter().find(|s| s.name == name) else {
        return Err(refused(format!(
            "{file}: {name} has no straightness result"
        )));
    };
    let fit = &result.straightness;
    // The targets with a reading: the measured range of the straightness.
    let column = geometry
        .column(name.as_str())
        .ok_or_else(|| refused(format!("{file}: no {name} column")))?;
    let targets: Vec<f64> = geometry
        .targets_mm
        .iter()
        .zip(column.means())
        .filter_map(|(t, m)| m.map(|_| *t))
        .collect();
    // The TNC 640's one table per axis: the existing .COM's points and columns.
    let existing_points = match request.existing {
        Some((text, existing_file)) => Some(
            tnc640::read_positions(text).map_err(|e| refused(format!("{existing_file}:{e}")))?,
        ),
        None => None,
    };
    let table = build(request, &state.errors, name, &targets, existing_points)?;
    let mut options = write_options(
        profile,
        &direction.to_string(),
        &request.table_name,
        &WriteAs {
            controller: request.controller,
            test_unit: LengthUnit::Millimetre,
            kind: AxisKind::Linear,
            linuxcnc_type: 0,
            max_points: request.max_points,
            also: &[],
        },
    )?;
    options.provenance = Some(Provenance {
        source: request.source.clone(),
        recorded: None,
    });
    let existing = request.existing.map(|(text, _)| text);
    let text = emit::write_cross_axis(request.controller, &table, profile, &options, existing)?;
    // The value as in the file: the CEC holds −error when it holds corrections.
    let values = emit::cross_axis_values(request.controller, &options);
    let activation = emit::cross_axis_activation(
        request.controller,
        &table,
        profile,
        (&request.file_name, existing.is_some()),
        &options,
    )?;
    let report = CrossAxisJson {
        table: format!("{direction} = F({axis})"),
        error: name.as_str().to_string(),
        controller: request.controller.name(),
        output: request.output.clone(),
        file_unit: LengthUnit::Millimetre.as_str(),
        reference_line: fit.reference.as_str(),
        straightness_um: mm_to_um(fit.deviation_mm()),
        slope_urad: rad_to_um_per_m(fit.slope),
        reference_mm: table.table.reference,
        points: table
            .table
            .positions
            .iter()
            .map(|&p| CrossAxisPoint {
                position_mm: p,
                value_mm: values.sign * table.value_at(p),
            })
            .collect(),
        activation,
    };
    let terminal = CrossAxisText {
        file: file.to_string(),
        axis: axis.to_string(),
        direction: direction.to_string(),
        optics: state
            .optics
            .first()
            .map(|taken| (taken.optics.body.name().to_string(), taken.optics.offset_mm)),
        values_are: values.name,
    };
    Ok(CrossAxis {
        text,
        report,
        terminal,
    })
}

/// The straightness column to write: `wanted`, or the file's only one.
fn chosen_straightness(
    file: &str,
    geometry: &GeometryTest,
    wanted: Option<&str>,
) -> Result<ErrorName, WorkflowError> {
    let present: Vec<ErrorName> = geometry
        .columns
        .iter()
        .filter(|c| matches!(c.quantity, Quantity::Translation(d) if d != geometry.axis))
        .filter_map(|c| ErrorName::from_name(&c.name))
        .collect();
    let names = |list: &[ErrorName]| {
        list.iter()
            .map(|n| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let columns: Vec<&str> = geometry.columns.iter().map(|c| c.name.as_str()).collect();
    match (wanted, present.as_slice()) {
        (_, []) => Err(refused(format!(
            "{file}: a cross-axis table is written from a straightness (EYX, EZX, …), and this test of {} has none (its columns: {}); angles and positioning go into a survey (predict --survey)",
            geometry.axis,
            columns.join(", ")
        ))),
        (None, [only]) => Ok(*only),
        (None, _) => Err(refused(format!(
            "{file}: the test has {} straightness columns ({}); say which with --straightness",
            present.len(),
            names(&present)
        ))),
        (Some(text), _) => ErrorName::from_name(&text.to_ascii_uppercase())
            .filter(|n| present.contains(n))
            .ok_or_else(|| {
                refused(format!(
                    "{file}: --straightness {text}: the test's straightness columns are {}",
                    names(&present)
                ))
            }),
    }
}

/// The table on the requested grid (default: the measured targets) or on
/// the points of the existing table, inside the measured range, zero at the
/// requested reference or the machine's reference position.
fn build(
    request: &CrossAxisRequest<'_>,
    errors: &GeometricErrors,
    name: ErrorName,
    targets: &[f64],
    existing_points: Option<Vec<f64>>,
) -> Result<CrossAxisTable, WorkflowError> {
    let capabilities = request.controller.capabilities(LengthUnit::Millimetre);
    let grid = Request {
        mode: None,
        extrapolate: None,
        ..request.grid
    };
    let positions = match existing_points {
        Some(points) => {
            if grid.step.is_some() {
                return Err(refused(
                    "--step: the table goes into the existing table, on its points (the TNC 640 has one table per axis)".to_string(),
                ));
            }
            points
        }
        None => grid_positions(
            targets,
            plan(
                AxisKind::Linear,
                targets,
                &[],
                &capabilities,
                &grid,
                &PlanContext::default(),
            )?
            .options
            .grid,
        )?,
    };
    let (first_mm, last_mm) = (targets[0], targets[targets.len() - 1]);
    if let Some(&position_mm) = positions
        .iter()
        .find(|&&p| p < first_mm - 1e-9 || p > last_mm + 1e-9)
    {
        return Err(CompensateError::OutsideMeasuredRange {
            position: AxisKind::Linear.position(position_mm),
            first: AxisKind::Linear.position(first_mm),
            last: AxisKind::Linear.position(last_mm),
        }
        .into());
    }
    let ErrorComponent::Translation { axis, .. } = name.component() else {
        return Err(refused(format!("{name} is no straightness")));
    };
    let reference = grid
        .reference
        .unwrap_or(request.machine.reference_mm()[axis.index()]);
    Ok(cross_axis_table_at(errors, name, positions, reference)?)
}
