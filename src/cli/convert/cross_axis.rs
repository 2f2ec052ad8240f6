//! `axcomp convert STRAIGHTNESS.csv`: a straightness test to the cross-axis
//! table the controller loads ("Y = F(X)": the values move Y as a function
//! of X's position). The straightness is taken as `predict --survey` takes
//! it (a survey of this one file): the Abbe terms of the file's own angles
//! at `--line` and `--optics-offset` out, then the ISO 230-1 reference line;
//! the slope is reported, never compensated.

use std::path::Path;

use anyhow::{Result, bail};
use serde::Serialize;

use axcomp::compensate::cross_axis::CrossAxisTable;
use axcomp::compensate::plan::{PlanContext, Request, plan};
use axcomp::compensate::{CompensateError, grid_positions};
use axcomp::emit::{self, Controller, EmitOptions, MachineProfile, Provenance, tnc640};
use axcomp::model::{ErrorComponent, ErrorName, GeometricErrors, Machine};
use axcomp::output::write_new;
use axcomp::predict::cross_axis_table_at;
use axcomp::predict::survey::{Survey, SurveyFile, SurveyTest, assemble};
use axcomp::read::{self, geometry::Quantity};
use axcomp::units::{LengthUnit, mm_to_um, rad_to_um_per_m};

use super::{ConvertArgs, table_name};
use crate::cli::common::{load_machine, load_profile, print_json, print_text};

/// The controllers with a cross-axis table in axcomp.
const CONTROLLERS: &str = "tnc640 (a .COM with a dependent column) and sinumerik840d (a CEC table with another output axis)";

/// What `convert --json` prints for a cross-axis table.
#[derive(Serialize)]
struct CrossAxisJson {
    /// `"Y = F(X)"`.
    table: String,
    /// The straightness, `EYX`.
    error: String,
    controller: &'static str,
    output: String,
    /// Unit of the positions and values in the file.
    file_unit: &'static str,
    reference_line: &'static str,
    straightness_um: f64,
    /// The reference line's slope, taken out and not compensated.
    slope_urad: f64,
    reference_mm: f64,
    /// Each point: the table axis's position and the value as in the file.
    points: Vec<CrossAxisPoint>,
    activation: String,
}

#[derive(Serialize)]
struct CrossAxisPoint {
    position_mm: f64,
    value_mm: f64,
}

/// Runs `axcomp convert` on a straightness test.
pub fn run(args: &ConvertArgs, file: &Path) -> Result<()> {
    refuse_positioning_flags(args)?;
    if !matches!(
        args.controller,
        Controller::Tnc640 | Controller::Sinumerik840d
    ) {
        bail!(
            "{}: a straightness test gives a cross-axis table, which axcomp writes for {CONTROLLERS}; {} has none here",
            file.display(),
            args.controller.name()
        );
    }
    let machine = load_machine(args.machine_file.machine.as_deref())?;
    let profile = load_profile(args.machine_file.machine.as_deref())?;
    if profile.machine_unit() != LengthUnit::Millimetre {
        bail!(
            "{}: cross-axis tables are written in mm only, and the machine profile's unit is {}",
            file.display(),
            profile.machine_unit().as_str()
        );
    }
    let geometry = read::read_geometry_path(file)?;
    let name = chosen_straightness(file, &geometry, args.straightness.as_deref())?;
    let ErrorComponent::Translation { axis, direction } = name.component() else {
        bail!("{name} is no straightness");
    };
    let name_text = file.display().to_string();
    let survey = Survey {
        errors_file: None,
        reference_line: args.reference_line.unwrap_or_default(),
        convention: Default::default(),
        squareness_from_straightness: Vec::new(),
        squareness_given: Vec::new(),
        tests: vec![SurveyTest {
            file: name_text.clone(),
            axis: None,
            errors: None,
            line_mm: args.line.unwrap_or([None; 3]),
            optics_offset_mm: args
                .optics_offset
                .unwrap_or([None; 3])
                .map(|v| v.unwrap_or(0.0)),
            optics_on: None,
        }],
    };
    let state = assemble(
        &machine,
        &survey,
        &GeometricErrors::default(),
        &[SurveyFile::Geometry(geometry.clone())],
    )
    .map_err(|e| anyhow::anyhow!("{name_text}: {e}"))?;
    let Some(result) = state.straightness.iter().find(|s| s.name == name) else {
        bail!("{name_text}: {name} has no straightness result");
    };
    let fit = &result.straightness;
    // The targets with a reading: the measured range of the straightness.
    let column = geometry
        .column(name.as_str())
        .ok_or_else(|| anyhow::anyhow!("{name_text}: no {name} column"))?;
    let targets: Vec<f64> = geometry
        .targets_mm
        .iter()
        .zip(column.means())
        .filter_map(|(t, m)| m.map(|_| *t))
        .collect();
    // The TNC 640's one table per axis: the existing .COM's points and columns.
    let existing = match &args.existing {
        Some(path) => Some(
            std::fs::read_to_string(path)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?,
        ),
        None => None,
    };
    let existing_points = match &existing {
        Some(text) => Some(tnc640::read_positions(text).map_err(|e| {
            anyhow::anyhow!(
                "{}:{e}",
                args.existing
                    .as_ref()
                    .map_or_else(String::new, |p| p.display().to_string())
            )
        })?),
        None => None,
    };
    let table = build(
        args,
        &machine,
        &state.errors,
        name,
        &targets,
        existing_points,
    )?;
    let mut options = emit_options(&profile, &direction.to_string(), &args.output)?;
    options.max_points = args.max_points.or(options.max_points);
    options.provenance = Some(Provenance {
        source: file
            .file_name()
            .map_or_else(|| name_text.clone(), |n| n.to_string_lossy().into_owned()),
        recorded: None,
    });
    let text = emit::write_cross_axis(
        args.controller,
        &table,
        &profile,
        &options,
        existing.as_deref(),
    )?;
    write_new(
        &args.output,
        text.as_bytes(),
        &args.inputs(),
        args.overwrite.force,
    )?;
    let file_name = args.output.file_name().map_or_else(
        || args.output.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    // The value as in the file: the CEC holds −error when it holds corrections.
    let sign = emit::cross_axis_file_sign(args.controller, &options);
    let activation = emit::cross_axis_activation(
        args.controller,
        &table,
        &profile,
        (&file_name, existing.is_some()),
        &options,
    )?;
    let report = CrossAxisJson {
        table: format!("{direction} = F({axis})"),
        error: name.as_str().to_string(),
        controller: args.controller.name(),
        output: args.output.display().to_string(),
        file_unit: LengthUnit::Millimetre.as_str(),
        reference_line: fit.reference.as_str(),
        straightness_um: mm_to_um(fit.deviation_mm()),
        slope_urad: rad_to_um_per_m(fit.slope),
        reference_mm: table.table.reference_mm,
        points: table
            .table
            .positions_mm
            .iter()
            .map(|&p| CrossAxisPoint {
                position_mm: p,
                value_mm: sign * table.value_at(p),
            })
            .collect(),
        activation,
    };
    if args.json_output.json {
        return print_json(&report);
    }
    let what = if sign < 0.0 {
        "correction (−error)"
    } else {
        "error"
    };
    let mut out = format!(
        "Cross-axis table {} ({name}: the straightness of {axis} in {direction}) from {name_text} for {} → {}\n",
        report.table, report.controller, report.output
    );
    out.push_str(&format!(
        "  straightness {:.2} µm ({} reference line); its slope {:.2} µrad is taken out and not compensated: it is the optics' alignment and, with the other test of the pair, squareness (predict --survey, which also takes the other axes' angles out of the slope)\n",
        report.straightness_um, report.reference_line, report.slope_urad
    ));
    if let Some(taken) = state.optics.first() {
        let [x, y, z] = taken.optics.offset_mm;
        out.push_str(&format!(
            "  moving optic on the {} (the body {axis} moves), x {x} y {y} z {z} mm from the tool tip: its offset is in the Abbe arms of the angles under that body\n",
            taken.optics.body.name()
        ));
    }
    out.push_str(&format!(
        "  zero at {axis} = {} mm (the machine's reference position unless --reference)\n\n",
        report.reference_mm
    ));
    out.push_str(&format!(
        "  {:>10}  {:>12}\n",
        format!("{axis} mm"),
        format!("{direction} mm")
    ));
    for point in &report.points {
        // To 0.1 µm as the .COM holds it; + 0.0 makes a rounded −0 print as +0.
        let shown = (point.value_mm * 1e4).round() / 1e4 + 0.0;
        out.push_str(&format!(
            "  {:>10.3}  {:>+12.4}\n",
            point.position_mm, shown
        ));
    }
    out.push_str(&format!(
        "  ({direction} values: the {what} in mm, as in the file)\n\n{}\n",
        report.activation
    ));
    print_text(&out)
}

/// Flags of a positioning table that a straightness has no use for.
fn refuse_positioning_flags(args: &ConvertArgs) -> Result<()> {
    let given: Vec<&str> = [
        ("--mode", args.mode.is_some()),
        (
            "--existing (a cross-axis table goes into an existing table only on the tnc640)",
            args.existing.is_some() && args.controller != Controller::Tnc640,
        ),
        ("--effects", args.effects.is_some()),
        ("--also", !args.also.is_empty()),
        ("--axis", args.axis.is_some()),
        ("--exclude-run", !args.exclude_runs.is_empty()),
        ("--extrapolate", args.extrapolate.is_some()),
    ]
    .into_iter()
    .filter_map(|(flag, set)| set.then_some(flag))
    .collect();
    if !given.is_empty() {
        bail!(
            "{} belong to a positioning table; a straightness test gives a cross-axis table (one mean table over the measured range, its axis from the file's columns)",
            given.join(", ")
        );
    }
    Ok(())
}

/// The straightness column to write: `--straightness`, or the file's only one.
fn chosen_straightness(
    file: &Path,
    geometry: &read::geometry::GeometryTest,
    wanted: Option<&str>,
) -> Result<ErrorName> {
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
        (_, []) => bail!(
            "{}: a cross-axis table is written from a straightness (EYX, EZX, …), and this test of {} has none (its columns: {}); angles and positioning go into a survey (predict --survey)",
            file.display(),
            geometry.axis,
            columns.join(", ")
        ),
        (None, [only]) => Ok(*only),
        (None, _) => bail!(
            "{}: the test has {} straightness columns ({}); say which with --straightness",
            file.display(),
            present.len(),
            names(&present)
        ),
        (Some(text), _) => ErrorName::from_name(&text.to_ascii_uppercase())
            .filter(|n| present.contains(n))
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: --straightness {text}: the test's straightness columns are {}",
                    file.display(),
                    names(&present)
                )
            }),
    }
}

/// The table on the grid of `--start`/`--step`/`--count` (default: the
/// measured targets) or on the points of the existing table, inside the
/// measured range, zero at `--reference` or the machine's reference position.
fn build(
    args: &ConvertArgs,
    machine: &Machine,
    errors: &GeometricErrors,
    name: ErrorName,
    targets: &[f64],
    existing_points: Option<Vec<f64>>,
) -> Result<CrossAxisTable> {
    let capabilities = args.controller.capabilities(LengthUnit::Millimetre);
    let request = Request {
        mode: None,
        step_mm: args.step,
        start_mm: args.start,
        count: args.count,
        reference_mm: args.reference,
        extrapolate: None,
    };
    let positions = match existing_points {
        Some(points) => {
            if args.step.is_some() {
                bail!(
                    "--step: the table goes into the existing table, on its points (the TNC 640 has one table per axis)"
                );
            }
            points
        }
        None => grid_positions(
            targets,
            plan(
                targets,
                &[],
                &capabilities,
                &request,
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
            position_mm,
            first_mm,
            last_mm,
        }
        .into());
    }
    let ErrorComponent::Translation { axis, .. } = name.component() else {
        bail!("{name} is no straightness");
    };
    let reference = args
        .reference
        .unwrap_or(machine.reference_mm()[axis.index()]);
    Ok(cross_axis_table_at(errors, name, positions, reference)?)
}

/// The options of the column axis's table, in mm.
fn emit_options(profile: &MachineProfile, column: &str, output: &Path) -> Result<EmitOptions> {
    let mut options = EmitOptions::for_axis(profile, column, &table_name(output))?;
    options.machine_unit = LengthUnit::Millimetre;
    Ok(options)
}
