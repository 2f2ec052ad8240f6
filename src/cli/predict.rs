//! `axcomp predict`: what a re-test of the compensated axis will show, and the
//! residual volumetric error, from the volumetric model.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use axcomp::compensate::cross_axis::CrossAxisTable;
use axcomp::compensate::{CompensationTable, TableMode};
use axcomp::effects::Effect;
use axcomp::emit::{MachineTable, fanuc, overwrites, sinumerik840d, tnc640};
use axcomp::error::{ParseError, Warning};
use axcomp::measurement::{AxisKind, Measurement};
use axcomp::model::{GeometricErrors, Optics, read_error_description};
use axcomp::predict::survey::{MeasuredState, Survey, SurveyFile, assemble};
use axcomp::predict::{MeasuredAxis, PredictInput, Prediction, predict};
use axcomp::read;
use axcomp::report::predict::{PredictJson, SurveyJson, render};
use axcomp::together::{Input, Pairing, check_together};
use axcomp::units::{LengthUnit, mm_to_um};
use axcomp::workflow::rotary;
use axcomp::workflow::table::read_options;

use super::common::{
    JsonOutput, LinuxCncType, MachineFile, StandardArg, Verbosity, load, load_effects,
    load_machine, name_axis, parse_position, print_json, print_test_warnings, print_text,
    print_warnings, read_table,
};

/// Flags of `axcomp predict`.
#[derive(Debug, clap::Args)]
pub struct PredictArgs {
    /// `--machine` (one profile; each command reads its part).
    #[command(flatten)]
    pub machine_file: MachineFile,

    /// The errors the model knows besides the measured ones (TOML: EXX … EYOZ,
    /// tables or constants, µm and µrad).
    #[arg(long, value_name = "E.toml", help_heading = "Errors")]
    pub errors: Option<PathBuf>,

    /// A machine's measured state: a TOML listing its measurement files
    /// (geometry and positioning tests, lines, optics offsets, squareness;
    /// docs/src/geometry.md), from which the 21 errors are built. Errors it
    /// does not measure are the survey's `errors` file's, or zero.
    #[arg(long, value_name = "S.toml", help_heading = "Errors")]
    pub survey: Option<PathBuf>,

    /// A linear test of an axis: its positioning error along the line it was
    /// measured on, FILE or FILE@y=250,z=-275 (default: the --line).
    ///
    /// X=FILE names the axis when the file does not record it (or records
    /// another); a file that records no axis is refused without it.
    #[arg(long, value_name = "[AXIS=]FILE[@LINE]", help_heading = "Errors")]
    pub measured: Vec<String>,

    /// A compensation table in any format convert writes, [AXIS=]FILE (the
    /// axis defaults to the one measured axis).
    #[arg(
        long,
        value_name = "[AXIS=]TABLE",
        required_unless_present = "cross_table",
        help_heading = "Tables"
    )]
    pub table: Vec<String>,

    /// A cross-axis (straightness) table, COLUMN=F(AXIS):FILE: a TNC 640
    /// `.COM` whose COLUMN holds the values along AXIS (entered in AXIS's
    /// `.CMA` column), or a Sinumerik CEC program with that input and output
    /// axis. Applied as the controller does: COLUMN moved by −value.
    #[arg(
        long = "cross-table",
        value_name = "Y=F(X):FILE",
        help_heading = "Tables"
    )]
    pub cross_table: Vec<String>,

    /// The re-test line as machine positions, x=…,y=…,z=… mm (missing
    /// coordinates: the machine's reference position).
    #[arg(long, value_name = "x=…,y=…,z=…", value_parser = parse_position, help_heading = "Re-test")]
    pub line: Option<[Option<f64>; 3]>,

    /// The re-test's tool: last tool-side error frame → functional point,
    /// x=…,y=…,z=… mm (default: the machine description's).
    #[arg(long = "tool-offset", value_name = "x=…,y=…,z=…", value_parser = parse_position, help_heading = "Re-test")]
    pub tool_offset: Option<[Option<f64>; 3]>,

    /// Effects found by diagnose (--write-effects) that the model lacks: their
    /// systematic part is added to the re-test.
    #[arg(long, value_name = "E.toml", help_heading = "Errors")]
    pub effects: Option<PathBuf>,

    /// The controller's backlash parameter is set as convert suggests (−B̄ of
    /// the measured first test): it takes out the mean reversal that a mean
    /// table leaves. Not with a bidirectional table.
    #[arg(long = "backlash-set", help_heading = "Tables")]
    pub backlash_set: bool,

    /// Step of the volumetric error map, mm.
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 50.0,
        help_heading = "Re-test"
    )]
    pub grid: f64,

    /// `--linuxcnc-type` for reading a table (the same in every command).
    #[command(flatten)]
    pub table_type: LinuxCncType,

    /// `--standard` (the same in every command).
    #[command(flatten)]
    pub standard: StandardArg,

    /// `--json` (the same in every command).
    #[command(flatten)]
    pub json_output: JsonOutput,

    /// -q/--quiet (the same in every command).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Runs `axcomp predict`.
pub fn run(args: &PredictArgs) -> Result<()> {
    if !(args.grid > 0.0 && args.grid.is_finite()) {
        bail!("--grid must be a step > 0 mm, found {}", args.grid);
    }
    let machine = load_machine(args.machine_file.machine.as_deref())?;
    let profile = args.machine_file.profile()?;
    let mut errors = match &args.errors {
        Some(path) => load_errors(path)?,
        None => GeometricErrors::default(),
    };
    let mut state = None;
    let mut surveyed: Vec<(Measurement, [f64; 3], Optics)> = Vec::new();
    if let Some(path) = &args.survey {
        let measured = load_survey(path, &machine, &errors, args.errors.is_some())?;
        errors = measured.errors.clone();
        surveyed = measured
            .positioning
            .iter()
            .map(|p| (p.measurement.clone(), p.line_mm, p.optics))
            .collect();
        state = Some(measured);
    }
    let effects = match &args.effects {
        Some(path) => load_effects(path)?,
        None => Vec::new(),
    };
    let reference = machine.reference_mm();
    let line_mm = complete(args.line, reference);
    let mut measurements: Vec<(Measurement, [f64; 3])> = Vec::new();
    let mut optics: Vec<Optics> = Vec::new();
    for (measurement, line, offset) in surveyed {
        measurements.push((measurement, line));
        optics.push(offset);
    }
    for spec in &args.measured {
        let (axis, spec) = split_axis(spec);
        let (path, line) = split_measured(spec)?;
        let mut result = read::read_path(&path, None)?;
        print_warnings(&result.warnings, args.verbosity.quiet);
        name_axis(&mut result.measurement, axis.as_ref());
        rotary::check(&result.measurement, &[(rotary::Use::Predict, true)])?;
        if !result.measurement.axis_recorded() {
            bail!(
                "{}: the file does not record which axis was measured; name it as --measured X={spec}",
                path.display()
            );
        }
        print_test_warnings(
            &path,
            &result.measurement,
            args.verbosity.quiet,
            Default::default(),
        );
        let line = line.map_or(line_mm, |l| complete(Some(l), reference));
        measurements.push((result.measurement, line));
        optics.push(Optics::AT_TOOL_TIP);
    }
    let measured: Vec<MeasuredAxis<'_>> = measurements
        .iter()
        .zip(&optics)
        .map(|((measurement, line_mm), optics)| MeasuredAxis {
            measurement,
            line_mm: *line_mm,
            optics: *optics,
        })
        .collect();
    check_one_machine(args, &measurements)?;
    let (tables, read_notes): (Vec<CompensationTable>, Vec<Option<Warning>>) = args
        .table
        .iter()
        .map(|spec| load_table(spec, &measurements, &profile, args.table_type.linuxcnc_type))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .unzip();
    let cross_tables = args
        .cross_table
        .iter()
        .map(|spec| load_cross_table(spec, &profile))
        .collect::<Result<Vec<CrossAxisTable>>>()?;
    // Each table against the test of its axis: the range it is predicted over.
    let mut doubts = Vec::new();
    for (table, spec) in tables.iter().zip(&args.table) {
        let Some((measurement, _)) = measurements
            .iter()
            .find(|(m, _)| m.axis().eq_ignore_ascii_case(&table.axis))
        else {
            continue;
        };
        let test_name = measurement.metadata.source_file.as_ref().map_or_else(
            || format!("the test of {}", table.axis),
            |p| p.display().to_string(),
        );
        doubts.extend(check_together(
            Pairing::TableOnTest,
            &Input::measurement(measurement, test_name),
            &Input::table(&table.axis, &table.positions, format!("--table {spec}")),
        )?);
    }
    doubts.extend(read_notes.into_iter().flatten());
    print_warnings(&doubts, args.verbosity.quiet);
    let tool = args
        .tool_offset
        .map(|offset| complete(Some(offset), machine.tool_offset_mm()));
    let input = PredictInput {
        machine: &machine,
        errors: &errors,
        measured: &measured,
        tables: &tables,
        cross_tables: &cross_tables,
        line_mm,
        retest_tool_offset_mm: tool,
        grid_step_mm: args.grid,
        effects: &effects,
        backlash_set: args.backlash_set,
        standard: args.standard.standard,
    };
    let prediction = predict(&input)?;
    let mut notes = notes(&prediction, &effects);
    notes.extend(doubts.iter().map(ToString::to_string));
    if args.machine_file.machine.is_none() {
        notes.push("machine: the bundled MCV 754 Quick (give --machine for another)".to_string());
    }
    let report = PredictJson::new(
        machine.name(),
        machine.chain().as_str(),
        &prediction,
        args.grid,
        effects.iter().map(|e| e.kind().name()).collect(),
        notes,
    )
    .with_survey(state.as_ref().map(SurveyJson::new));
    if args.json_output.json {
        print_json(&report)
    } else {
        print_text(&render(&report))
    }
}

/// Missing coordinates from `default`.
fn complete(position: Option<[Option<f64>; 3]>, default: [f64; 3]) -> [f64; 3] {
    let given = position.unwrap_or([None; 3]);
    [0, 1, 2].map(|i| given[i].unwrap_or(default[i]))
}

/// `X=REST`: an axis letter in front of a `--measured` file, when there is one.
fn split_axis(spec: &str) -> (Option<String>, &str) {
    match spec.split_once('=') {
        Some((axis, rest)) if axis.len() == 1 && axis.chars().all(|c| c.is_ascii_alphabetic()) => {
            (Some(axis.to_ascii_uppercase()), rest)
        }
        _ => (None, spec),
    }
}

/// `FILE` or `FILE@y=250,z=-275`; the `@` part only when it reads as a position.
fn split_measured(spec: &str) -> Result<(PathBuf, Option<[Option<f64>; 3]>)> {
    if let Some((path, line)) = spec.rsplit_once('@')
        && let Ok(position) = parse_position(line)
    {
        return Ok((PathBuf::from(path), Some(position)));
    }
    Ok((PathBuf::from(spec), None))
}

fn load_errors(path: &Path) -> Result<GeometricErrors> {
    load(path, read_error_description)
}

/// Reads a survey and every file it names (relative to the survey's
/// folder), and assembles the measured state.
fn load_survey(
    path: &Path,
    machine: &axcomp::model::Machine,
    declared: &GeometricErrors,
    errors_given: bool,
) -> Result<MeasuredState> {
    let survey = load(path, Survey::from_toml_str)?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let declared = match &survey.errors_file {
        Some(_) if errors_given => bail!(
            "{}: the survey names an errors file and so does --errors: give the declared errors once",
            path.display()
        ),
        Some(file) => load_errors(&folder.join(file))?,
        None => declared.clone(),
    };
    let mut files = Vec::new();
    for test in &survey.tests {
        let file = folder.join(&test.file);
        if read::is_geometry_path(&file)? {
            files.push(SurveyFile::Geometry(read::read_geometry_path(&file)?));
        } else {
            let mut result = read::read_path(&file, None)?;
            if let Some(axis) = test.axis {
                name_axis(&mut result.measurement, Some(&axis.letter().to_string()));
            }
            rotary::check(&result.measurement, &[(rotary::Use::Predict, true)])?;
            files.push(SurveyFile::Positioning(Box::new(result.measurement)));
        }
    }
    assemble(machine, &survey, &declared, &files)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// `[AXIS=]FILE`: the axis defaults to the one measured axis. With the
/// table, what its reading rests on when the file does not tell all
/// (`emit::fanuc::read_note`).
fn load_table(
    spec: &str,
    measurements: &[(Measurement, [f64; 3])],
    profile: &axcomp::emit::MachineProfile,
    linuxcnc_type: Option<u8>,
) -> Result<(CompensationTable, Option<Warning>)> {
    let (axis, path) = match spec.split_once('=') {
        Some((axis, path)) if axis.len() == 1 => (axis.to_ascii_uppercase(), path),
        _ => match measurements {
            [(only, _)] => (only.axis().to_string(), spec),
            _ => bail!(
                "--table {spec}: say which axis the table is for, as X={spec} (it cannot be taken from {} measured files)",
                measurements.len()
            ),
        },
    };
    // A Fagor 8055 table holds the machine unit: that of the test of its axis.
    let test_unit = measurements
        .iter()
        .map(|(m, _)| m)
        .find(|m| m.axis() == axis)
        .or(measurements.first().map(|(m, _)| m))
        .map_or(LengthUnit::Millimetre, |m| m.metadata.length_unit);
    let (controller, table) =
        read_table(Path::new(path), &axis, profile, linuxcnc_type, test_unit)?;
    let options = read_options(profile, &axis, AxisKind::Linear, linuxcnc_type)?;
    Ok((table, fanuc::read_note(controller, &options)))
}

/// Refuses table files of one machine that would overwrite each other in
/// the control (`emit::overwrites`).
fn check_one_machine(args: &PredictArgs, measurements: &[(Measurement, [f64; 3])]) -> Result<()> {
    // (file, the axis the table is a function of)
    let mut files: Vec<(&str, String)> = Vec::new();
    for spec in &args.table {
        match spec.split_once('=') {
            Some((axis, path)) if axis.len() == 1 => files.push((path, axis.to_ascii_uppercase())),
            _ => {
                if let [(only, _)] = measurements {
                    files.push((spec, only.axis().to_string()));
                }
            }
        }
    }
    for spec in &args.cross_table {
        if let (Some(axis), Some(path)) = (spec.chars().nth(4), spec.get(7..)) {
            files.push((path, axis.to_ascii_uppercase().to_string()));
        }
    }
    let same_file = |a: &str, b: &str| {
        a == b
            || std::fs::canonicalize(a)
                .ok()
                .is_some_and(|a| std::fs::canonicalize(b).ok() == Some(a))
    };
    // Read once each; a file that cannot be read is refused where it is loaded.
    let texts: Vec<Option<String>> = files
        .iter()
        .map(|(path, _)| std::fs::read_to_string(path).ok())
        .collect();
    let tables: Vec<MachineTable<'_>> = files
        .iter()
        .zip(&texts)
        .filter_map(|((name, axis), text)| {
            Some(MachineTable {
                name,
                axis,
                text: text.as_deref()?,
            })
        })
        .collect();
    for (i, second) in tables.iter().enumerate() {
        for first in tables[..i]
            .iter()
            .filter(|f| !same_file(f.name, second.name))
        {
            if let Some(why) = overwrites(first, second) {
                bail!("{why}");
            }
        }
    }
    Ok(())
}

/// `COLUMN=F(AXIS):FILE`: a cross-axis table from a TNC 640 `.COM` or a
/// Sinumerik CEC program.
fn load_cross_table(spec: &str, profile: &axcomp::emit::MachineProfile) -> Result<CrossAxisTable> {
    let chars: Vec<char> = spec.chars().collect();
    let well_formed = chars.len() > 7
        && chars[1] == '='
        && chars[2..4] == ['F', '(']
        && chars[5..7] == [')', ':'];
    if !well_formed {
        bail!("--cross-table {spec}: expected COLUMN=F(AXIS):FILE, e.g. Y=F(X):X.COM");
    }
    let column = chars[0].to_ascii_uppercase().to_string();
    let axis = chars[4].to_ascii_uppercase().to_string();
    let path = Path::new(&spec[7..]);
    let cec = profile.controller.cec_values != Some(axcomp::emit::CecValues::Error);
    load(path, |text| {
        if text.contains("%_N_NC_CEC_INI") {
            let input = profile
                .axis(&axis)
                .map_err(|e| ParseError::new(1, 1, e.to_string()))?;
            let output = profile
                .axis(&column)
                .map_err(|e| ParseError::new(1, 1, e.to_string()))?;
            sinumerik840d::read_cross_axis(
                text,
                (&input.sinumerik_axis, &output.sinumerik_axis),
                (&axis, &column),
                cec,
            )
        } else {
            let output = profile
                .axis(&column)
                .map_err(|e| ParseError::new(1, 1, e.to_string()))?;
            let mut table = tnc640::read_cross_axis(text, &axis, &output.tnc640_column)?;
            table.table.axis = column.clone();
            Ok(table)
        }
    })
}

/// What the reader should know about this prediction.
fn notes(prediction: &Prediction, effects: &[Effect]) -> Vec<String> {
    let mut notes = Vec::new();
    for retest in &prediction.retests {
        let axis = retest.axis;
        let note = match (retest.measured_mean_reversal_mm, retest.table_mode) {
            (Some(b), _) if retest.backlash_reversal_mm != 0.0 => format!(
                "the first test of {axis} measured a mean reversal B̄ = {:.2} µm; the backlash parameter (--backlash-set) takes it out, leaving its variation along the axis",
                mm_to_um(b)
            ),
            (Some(b), TableMode::Mean) => format!(
                "the first test of {axis} measured a mean reversal B̄ = {:.2} µm: the prediction carries it, and a mean table leaves it (take it out with a bidirectional table, or set the backlash parameter convert suggests and give --backlash-set)",
                mm_to_um(b)
            ),
            (Some(b), TableMode::Bidirectional) => format!(
                "the first test of {axis} measured a mean reversal B̄ = {:.2} µm: the bidirectional table takes it out",
                mm_to_um(b)
            ),
            (None, _) if retest.with_measured_scatter => format!(
                "the first test of {axis} is unidirectional: its reversal is not known, and the prediction has none"
            ),
            (None, _) => format!(
                "axis {axis} was not measured: its re-test is systematic only (one run each way, no R, no reversal)"
            ),
        };
        notes.push(note);
    }
    if effects.iter().any(|e| matches!(e, Effect::Reversal(_))) {
        notes.push(
            "the reversal in --effects is added to the one the first test measured (diagnose reports the change)"
                .to_string(),
        );
    }
    for effect in effects {
        if effect
            .systematic(0.0, axcomp::measurement::Direction::Up, 0.0)
            .is_none()
        {
            notes.push(format!(
                "the {} effect is not systematic in position and is not added (Abbe: give the line and the angular errors instead)",
                effect.kind().name()
            ));
        }
    }
    notes
}
