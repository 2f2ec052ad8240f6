//! `axcomp convert STRAIGHTNESS.csv`: a straightness test to the cross-axis
//! table the controller loads ("Y = F(X)": the values move Y as a function
//! of X's position). The straightness is taken as `predict --survey` takes
//! it (a survey of this one file): the Abbe terms of the file's own angles
//! at `--line` and `--optics-offset` out, then the ISO 230-1 reference line;
//! the slope is reported, never compensated.

use std::path::Path;

use anyhow::{Result, bail};

use axcomp::output::write_new;
use axcomp::read;
use axcomp::workflow::cross_axis::{CrossAxis, CrossAxisRequest, cross_axis};

use super::{ConvertArgs, table_name};
use crate::cli::common::{load_machine, load_profile, print_json, print_text};

/// Runs `axcomp convert` on a straightness test.
pub fn run(args: &ConvertArgs, file: &Path) -> Result<()> {
    refuse_positioning_flags(args)?;
    let machine = load_machine(args.machine_file.machine.as_deref())?;
    let profile = load_profile(args.machine_file.machine.as_deref())?;
    let geometry = read::read_geometry_path(file)?;
    let existing = match &args.existing {
        Some(path) => Some((
            std::fs::read_to_string(path)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?,
            path.display().to_string(),
        )),
        None => None,
    };
    let name_text = file.display().to_string();
    let CrossAxis {
        text,
        report,
        terminal,
    } = cross_axis(&CrossAxisRequest {
        controller: args.controller,
        machine: &machine,
        profile: &profile,
        geometry: &geometry,
        file: &name_text,
        source: file
            .file_name()
            .map_or_else(|| name_text.clone(), |n| n.to_string_lossy().into_owned()),
        straightness: args.straightness.as_deref(),
        reference_line: args.reference_line.unwrap_or_default(),
        line_mm: args.line.unwrap_or([None; 3]),
        optics_offset_mm: args
            .optics_offset
            .unwrap_or([None; 3])
            .map(|v| v.unwrap_or(0.0)),
        grid: axcomp::compensate::plan::Request {
            step: args.step,
            start: args.start,
            count: args.count,
            reference: args.reference,
            ..Default::default()
        },
        existing: existing
            .as_ref()
            .map(|(text, name)| (text.as_str(), name.as_str())),
        table_name: table_name(&args.output),
        output: args.output.display().to_string(),
        file_name: args.output.file_name().map_or_else(
            || args.output.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        ),
        max_points: args.max_points,
    })?;
    write_new(
        &args.output,
        text.as_bytes(),
        &args.inputs(),
        args.overwrite.force,
    )?;
    if args.json_output.json {
        return print_json(&report);
    }
    print_text(&report.summary(&terminal))
}

/// Flags of a positioning table that a straightness has no use for.
fn refuse_positioning_flags(args: &ConvertArgs) -> Result<()> {
    let given: Vec<&str> = [
        ("--mode", args.mode.is_some()),
        (
            "--existing (a cross-axis table goes into an existing table only on the tnc640)",
            args.existing.is_some() && !args.controller.cross_axis_into_existing(),
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
