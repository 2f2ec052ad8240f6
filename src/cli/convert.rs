//! `axcomp convert`: a measurement to a compensation file the controller loads as is.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use axcomp::compensate::plan::Request;
use axcomp::compensate::{self, Extrapolate, TableMode};
use axcomp::emit::Controller;
use axcomp::evaluate::straightness::ReferenceLine;
use axcomp::measurement::RunSelector;
use axcomp::output::write_new;
use axcomp::read;
use axcomp::workflow::table::{WriteAs, write_options};
use axcomp::workflow::{self, Converted, TableRequest};

use super::common::{
    InputFormat, JsonOutput, MachineFile, Overwrite, Verbosity, load_effects, name_axis,
    parse_position, parse_run_selector, print_json, print_text, print_warnings, read_active_table,
    recorded_axis,
};
use super::evaluate::check_selectors;

mod cross_axis;

/// Flags of `axcomp convert`.
#[derive(Debug, clap::Args)]
pub struct ConvertArgs {
    /// Measurement file(s): .rtl, ecmc .dat, API .pos or axcomp CSV.
    #[arg(required = true, num_args = 1..=2, value_name = "FILE")]
    pub files: Vec<PathBuf>,

    /// The controller: itnc530, tnc640, sinumerik840d, linuxcnc, fagor8055, fagor8065 or fanuc (with --fanuc-parameters: the control's points; --existing PITCH.TXT is updated in place).
    #[arg(long, value_name = "CONTROLLER", value_parser = parse_controller, help_heading = "Table")]
    pub controller: Controller,

    /// Output file (refused if it exists, unless --force).
    #[arg(
        short = 'o',
        long = "output",
        value_name = "OUT",
        help_heading = "Output"
    )]
    pub output: PathBuf,

    /// `--force` (the same in every command).
    #[command(flatten)]
    pub overwrite: Overwrite,

    /// The compensated axis, instead of the one the file names.
    ///
    /// Required when the file does not record its axis (an ecmc file whose
    /// PV names and file name state no axis letter, an .rtl without Axis:,
    /// a CSV without # axis:): no table is written for a guessed axis.
    #[arg(long, value_name = "NAME", help_heading = "Table")]
    pub axis: Option<String>,

    /// mean: one table from the bidirectional mean (plus a suggested backlash);
    /// bidirectional: separate ↑ and ↓ tables.
    ///
    /// Bidirectional tables go into the TNC 640 BACKLASH column, two Sinumerik
    /// CEC tables ($AN_CEC_DIRECTION 1 and -1) and the LinuxCNC forward and
    /// reverse columns; the iTNC 530 has no place for them.
    ///
    /// Default: mean, or bidirectional when --effects has a reversal and the
    /// controller takes bidirectional tables.
    #[arg(long, value_name = "MODE", value_parser = TableMode::from_name, help_heading = "Table")]
    pub mode: Option<TableMode>,

    /// First compensation point, in the axis' unit: mm, or ° on a rotary
    /// axis (default: the first target).
    #[arg(
        long,
        value_name = "POS",
        requires = "step",
        allow_negative_numbers = true,
        help_heading = "Grid"
    )]
    pub start: Option<f64>,

    /// Spacing of the compensation points, in the axis' unit: mm, or ° on a
    /// rotary axis.
    ///
    /// Without it the points are the measured targets, which iTNC 530 and
    /// Sinumerik accept only when they are evenly spaced.
    #[arg(long, value_name = "STEP", help_heading = "Grid")]
    pub step: Option<f64>,

    /// Number of compensation points (default: as many as fit in the measured range).
    #[arg(long, value_name = "N", requires = "step", help_heading = "Grid")]
    pub count: Option<usize>,

    /// Position where the table is zero, in the axis' unit: mm, or ° on a
    /// rotary axis (default: the first point; with --existing, the existing
    /// table's zero).
    ///
    /// Controllers reference the axis there. With --existing it is where the
    /// update adds nothing (inside the measured range); the old table's zero
    /// is its machine reference point, so the default keeps it.
    #[arg(
        long,
        value_name = "POS",
        allow_negative_numbers = true,
        help_heading = "Table"
    )]
    pub reference: Option<f64>,

    /// Points outside the measured range: hold the end value, or zero.
    /// Without it such points are refused.
    #[arg(long, value_name = "RULE", value_parser = Extrapolate::from_name, help_heading = "Grid")]
    pub extrapolate: Option<Extrapolate>,

    /// The table that was active during the measurement (any format convert writes).
    ///
    /// The measurement then shows the residual; the new table is the old one
    /// plus that residual, referred to the old table's zero, on the new grid
    /// inside the measured range; every old point outside it is kept as it
    /// was. A Fagor 8065 .mp file is updated in place: only its leadscrew
    /// lines change. A Fanuc PITCH.TXT is updated in place too, but its data
    /// are increments: the points outside keep their increments, so their
    /// values move with the new value at the range's end (said by how much).
    #[arg(long, value_name = "TABLE", help_heading = "Table")]
    pub existing: Option<PathBuf>,

    /// Effects found by diagnose (--write-effects): a reversal makes the table
    /// bidirectional, a periodic error a finer step (≤ period / 10) with the
    /// periodic error at the points, a scale is taken out (the table stays
    /// referred to the first test's conditions).
    #[arg(long, value_name = "E.toml", help_heading = "Table")]
    pub effects: Option<PathBuf>,

    /// Write the same table for a coupled axis too (gantry slave); repeatable.
    #[arg(long = "also", value_name = "AXIS", help_heading = "Table")]
    pub also: Vec<String>,

    /// Fanuc: also write the table with a finer magnification (3623) to
    /// this file: every point of the axis rescaled, with the parameter
    /// change to make (for a 3623 too coarse for the error).
    #[arg(long = "fanuc-rescaled", value_name = "OUT", help_heading = "Output")]
    pub fanuc_rescaled: Option<PathBuf>,

    /// `--machine` (one profile; each command reads its part).
    #[command(flatten)]
    pub machine_file: MachineFile,

    /// Most compensation points the machine takes (Sinumerik MD38000 / MD18342).
    #[arg(long = "max-points", value_name = "N", help_heading = "Machine")]
    pub max_points: Option<usize>,

    /// LinuxCNC COMP_FILE_TYPE: 0 (actual positions) or 1 (offsets).
    #[arg(long = "linuxcnc-type", value_name = "0|1", default_value_t = 0, value_parser = clap::value_parser!(u8).range(0..=1), help_heading = "Machine")]
    pub linuxcnc_type: u8,

    /// A straightness test: the straightness to write when the file has
    /// several (EYX: X's straightness in Y, the table Y = F(X)).
    #[arg(long, value_name = "EYX", help_heading = "Cross-axis table")]
    pub straightness: Option<String>,

    /// A straightness test: the machine position of its line, mm, as in a
    /// survey's `line_mm` (default: the machine's reference position).
    #[arg(long, value_name = "y=…,z=…", value_parser = parse_position, help_heading = "Cross-axis table")]
    pub line: Option<[Option<f64>; 3]>,

    /// A straightness test: the moving optics from the tool tip, mm, as in a
    /// survey's `optics_offset_mm` (default: at the tool tip).
    #[arg(long = "optics-offset", value_name = "x=…,y=…,z=…", value_parser = parse_position, help_heading = "Cross-axis table")]
    pub optics_offset: Option<[Option<f64>; 3]>,

    /// A straightness test: its ISO 230-1 reference line, least-squares
    /// (default) or end-points.
    #[arg(long = "reference-line", value_name = "LINE", value_parser = parse_reference_line, help_heading = "Cross-axis table")]
    pub reference_line: Option<ReferenceLine>,

    /// `--format` (the same in every command).
    #[command(flatten)]
    pub input_format: InputFormat,

    /// Leave a run out: RUN, RUN:up or RUN:down (as in evaluate).
    #[arg(long = "exclude-run", value_name = "RUN[:DIR]", value_parser = parse_run_selector, help_heading = "Input")]
    pub exclude_runs: Vec<RunSelector>,

    /// `--json` (the same in every command).
    #[command(flatten)]
    pub json_output: JsonOutput,

    /// -q/--quiet (the same in every command).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

impl ConvertArgs {
    /// Every file the command reads: never an output (`output::write_new`).
    pub fn inputs(&self) -> Vec<&Path> {
        let named = [
            self.existing.as_deref(),
            self.effects.as_deref(),
            self.machine_file.machine.as_deref(),
            self.machine_file.fanuc_parameters.as_deref(),
        ];
        let files = self.files.iter().map(PathBuf::as_path);
        files.chain(named.into_iter().flatten()).collect()
    }
}

fn parse_controller(name: &str) -> Result<Controller, String> {
    Controller::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = Controller::ALL.iter().map(|c| c.name()).collect();
        format!(
            "unknown controller {name:?}; supported: {}",
            names.join(", ")
        )
    })
}

fn parse_reference_line(name: &str) -> Result<ReferenceLine, String> {
    ReferenceLine::from_name(name)
        .ok_or_else(|| format!("expected least-squares or end-points, found {name:?}"))
}

/// Runs `axcomp convert`.
pub fn run(args: &ConvertArgs) -> Result<()> {
    // A straightness test gives a cross-axis table (`cross_axis`), not the axis's own.
    if let [file] = args.files.as_slice()
        && read::is_geometry_path(file)?
    {
        return cross_axis::run(args, file);
    }
    if args.straightness.is_some()
        || args.line.is_some()
        || args.optics_offset.is_some()
        || args.reference_line.is_some()
    {
        bail!(
            "--straightness, --line, --optics-offset and --reference-line are for a straightness test (a geometry CSV with EYX_um, …); {} is a positioning test",
            args.files
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(" + ")
        );
    }
    let profile = args.machine_file.profile()?;
    let read::ReadResult {
        mut measurement,
        mut warnings,
    } = read::read_paths(&args.files, args.input_format.format)?;
    name_axis(&mut measurement, args.axis.as_ref());
    let axis = recorded_axis(
        &measurement,
        "to say which axis the table is for; nothing was written",
    )?
    .to_string();
    check_selectors(&measurement, &args.exclude_runs)?;
    let mut measurement = measurement.without_runs(&args.exclude_runs)?;
    let options = write_options(
        &profile,
        &axis,
        &table_name(&args.output),
        &WriteAs {
            controller: args.controller,
            test_unit: measurement.metadata.length_unit,
            kind: measurement.kind(),
            linuxcnc_type: args.linuxcnc_type,
            max_points: args.max_points,
            also: &args.also,
        },
    )?;
    let mut active = None;
    if let Some(existing) = &args.existing {
        // The table was active during the test: its axis, over the test's range.
        let test_name = args
            .files
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(" + ");
        let table = read_active_table(
            existing,
            &measurement,
            &test_name,
            &profile,
            Some(args.linuxcnc_type),
        )?;
        warnings.extend(table.doubts);
        measurement = compensate::add_existing_table(&measurement, &table.table)?;
        active = Some(table.table);
    }
    let effects = match &args.effects {
        Some(path) => load_effects(path)?,
        None => Vec::new(),
    };
    // A Fagor 8065 table goes back into the .mp file that was active.
    let existing_bytes = match &args.existing {
        Some(path) => Some(std::fs::read(path).with_context(|| path.display().to_string())?),
        None => None,
    };
    let file_name = args.output.file_name().map_or_else(
        || args.output.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let request = Request {
        mode: args.mode,
        step: args.step,
        start: args.start,
        count: args.count,
        reference: args.reference,
        extrapolate: args.extrapolate,
    };
    let Converted {
        bytes,
        report,
        rescaled,
        ..
    } = workflow::convert(
        &measurement,
        &mut warnings,
        &TableRequest {
            controller: args.controller,
            options: &options,
            request: &request,
            effects: &effects,
            existing: existing_bytes.as_deref(),
            active: active.as_ref(),
            output: args.output.display().to_string(),
            file_name,
            also: args.also.clone(),
            fanuc_rescaled: args.fanuc_rescaled.is_some(),
        },
    )?;
    write_new(&args.output, &bytes, &args.inputs(), args.overwrite.force)?;
    if let (Some(path), Some(fine)) = (&args.fanuc_rescaled, rescaled) {
        write_new(
            path,
            fine.text.as_bytes(),
            &args.inputs(),
            args.overwrite.force,
        )?;
        let line = format!("{}: {}", path.display(), fine.instruction);
        if args.json_output.json {
            eprintln!("{line}")
        } else {
            println!("{line}")
        }
    }
    print_warnings(&warnings, args.verbosity.quiet);
    if args.json_output.json {
        print_json(&report)
    } else {
        print_text(&report.summary())
    }
}

/// The name inside Heidenhain files: the output file name, upper case.
fn table_name(output: &Path) -> String {
    output
        .file_name()
        .map(|name| name.to_string_lossy().to_uppercase())
        .unwrap_or_else(|| "AXIS.COM".to_string())
}
