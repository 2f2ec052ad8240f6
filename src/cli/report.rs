//! `axcomp report`: the acceptance report as one self-contained HTML file,
//! and its plots as PNG files with `--png`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use axcomp::evaluate::Standard;
use axcomp::evaluate::uncertainty::Equipment;
use axcomp::evaluate::verdict::Decision;
use axcomp::measurement::SourceFormat;
use axcomp::output::{create_folder, write_all_new};
use axcomp::read;
use axcomp::report::acceptance::{TableRecord, charts};
use axcomp::report::chart::chart;
use axcomp::report::html;
use axcomp::report::plot::PlotFormat;
use axcomp::together::{Input, Pairing, check_together};
use axcomp::workflow::Test;
use axcomp::workflow::report::{Report, ReportParts, generator};
use axcomp::workflow::retest::{DiagnoseSettings, diagnosis};
use axcomp::workflow::rotary::{self, ReportAsks};

use super::acceptance::{LimitArgs, load_limits};
use super::common::{
    AngleUnitArg, InputFormat, LinuxCncType, MachineFile, Overwrite, StandardArg, UncertaintyArgs,
    Verbosity, load_equipment, name_axis, print_file_warnings, print_text, print_warnings_in,
    read_active_table,
};

/// Flags of `axcomp report`.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    /// The measurement to report (.rtl, ecmc .dat, API .pos or axcomp CSV).
    ///
    /// With --after it is the first test, before compensation.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,

    /// The re-test of the same axis: adds the before/after comparison.
    ///
    /// Figures side by side, both deviation plots on one scale, both
    /// per-target tables.
    #[arg(long, value_name = "FILE2", help_heading = "Input")]
    pub after: Option<PathBuf>,

    /// The compensation table (any format convert writes): its plot and the predicted re-test.
    ///
    /// The prediction is the first test's mean deviation with the table
    /// applied as the controller applies it (linear between points, the end
    /// values held), along the laser line.
    #[arg(long, value_name = "T", help_heading = "Input")]
    pub table: Option<PathBuf>,

    /// Diagnose the re-test against the prediction (needs --after; uses --table).
    ///
    /// Adds the residual of every reading, the effects found in it (reversal,
    /// scale, drift, periodic, outlier run) with what to do about each, and
    /// what none of them explains.
    #[arg(long, requires = "after", help_heading = "Input")]
    pub diagnose: bool,

    /// `--format` (the same in every command).
    #[command(flatten)]
    pub input_format: InputFormat,

    /// `--thermal`, `--thermal-model`: a thermal log's section.
    #[command(flatten)]
    pub thermal: super::thermal::ThermalInputArgs,

    /// Name of the axis of FILE and FILE2, instead of the one in the files
    /// (needed with --table when FILE does not record its axis).
    #[arg(long, value_name = "NAME", help_heading = "Input")]
    pub axis: Option<String>,

    /// `--machine` (one profile; each command reads its part).
    #[command(flatten)]
    pub machine_file: MachineFile,

    #[command(flatten)]
    pub acceptance: LimitArgs,

    /// `--equipment`, `--decision` (the same in `evaluate`).
    #[command(flatten)]
    pub uncertainty: UncertaintyArgs,

    /// `--linuxcnc-type` for reading a table (the same in every command).
    #[command(flatten)]
    pub table_type: LinuxCncType,

    /// The HTML file to write (refused if it exists, unless --force).
    #[arg(
        short = 'o',
        long = "output",
        value_name = "OUT",
        default_value = "report.html",
        help_heading = "Output"
    )]
    pub output: PathBuf,

    /// Also write every plot as a PNG file into DIR (created if missing; its parent must exist).
    ///
    /// The same plots as in the HTML, 960 × 600 pixels, text in the embedded
    /// font (no system fonts needed): deviation.png (or deviation-before.png
    /// and deviation-after.png), table.png, predicted.png, residual.png,
    /// residual-along-axis.png, effects.png, as the inputs allow.
    #[arg(long, value_name = "DIR", help_heading = "Output")]
    pub png: Option<PathBuf>,

    /// `--force` (the same in every command).
    #[command(flatten)]
    pub overwrite: Overwrite,

    /// `--angle-unit` (the same in `evaluate` and `diagnose`).
    #[command(flatten)]
    pub angle_unit: AngleUnitArg,

    /// `--standard` (the same in every command).
    #[command(flatten)]
    pub standard: StandardArg,

    /// -q/--quiet (the same in every command).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Reads `path` (named with `--axis`) and evaluates it as a test of the report.
fn read_test(
    path: &Path,
    format: Option<SourceFormat>,
    axis: Option<&String>,
    standard: &dyn Standard,
    equipment: Option<&Equipment>,
) -> Result<Test> {
    let read::ReadResult {
        mut measurement,
        warnings,
    } = read::read_paths(&[path.to_path_buf()], format)?;
    name_axis(&mut measurement, axis);
    Ok(Test::new(measurement, warnings, standard, equipment)?)
}

/// Runs `axcomp report`.
pub fn run(args: &ReportArgs) -> Result<()> {
    let standard = args.standard.standard;
    let equipment = load_equipment(&args.uncertainty)?;
    let mut before = read_test(
        &args.file,
        args.input_format.format,
        args.axis.as_ref(),
        standard,
        equipment.as_ref(),
    )?;
    let angle = args.angle_unit.for_axis(&before.measurement)?;
    let asks = |limits: bool| ReportAsks {
        limits,
        uncertainty: args.uncertainty.equipment.is_some()
            || args.uncertainty.decision != Decision::default(),
        table: args.table.is_some(),
        diagnose: args.diagnose,
        standard,
    };
    rotary::check_report(
        &before.measurement,
        asks(!args.acceptance.limits.is_empty()),
    )?;
    let limits = load_limits(
        args.machine_file.machine.as_deref(),
        before.measurement.axis(),
        &before.evaluation,
        &args.acceptance,
    )?;
    rotary::check_report(&before.measurement, asks(!limits.is_empty()))?;
    let mut after = match &args.after {
        Some(path) => Some(read_test(
            path,
            args.input_format.format,
            args.axis.as_ref(),
            standard,
            equipment.as_ref(),
        )?),
        None => None,
    };
    if let (Some(after), Some(path)) = (&mut after, &args.after) {
        // Refused, or its doubts shown with the re-test's warnings (terminal and report).
        let doubts = check_together(
            Pairing::BeforeAfter,
            &Input::measurement(&before.measurement, args.file.display().to_string()),
            &Input::measurement(&after.measurement, path.display().to_string()),
        )?;
        after.warnings.extend(doubts);
    }
    let profile = args.machine_file.profile()?;
    let table = match &args.table {
        Some(path) => {
            let active = read_active_table(
                path,
                &before.measurement,
                &args.file.display().to_string(),
                &profile,
                args.table_type.linuxcnc_type,
            )?;
            before.warnings.extend(active.doubts.iter().cloned());
            Some((path.display().to_string(), active))
        }
        None => None,
    };
    let diagnosis = match (&after, args.diagnose) {
        (Some(after), true) => Some(
            diagnosis(
                &after.measurement,
                Some(&before.measurement),
                table.as_ref().map(|(_, active)| &active.table),
                &profile,
                DiagnoseSettings {
                    angle,
                    ..DiagnoseSettings::plain(standard)
                },
            )
            .context("cannot diagnose the re-test")?,
        ),
        _ => None,
    };
    let generator = generator(chrono::Local::now());
    let report = Report::new(ReportParts {
        after: after.as_ref(),
        table: table.as_ref().map(|(file, active)| TableRecord {
            table: &active.table,
            file,
            controller: active.controller,
        }),
        diagnosis: diagnosis.as_ref(),
        limits: &limits,
        decision: args.uncertainty.decision,
        angle,
        generator: &generator,
        ..ReportParts::of(&before, standard)
    });
    let input = report.input();
    // Render everything before writing anything: a failure leaves no half report.
    let page = super::thermal::with_thermal_section(
        html::render(&input)?,
        &args.thermal,
        diagnosis.as_ref(),
        after.as_ref().map(|a| &a.measurement.environment),
    )?;
    let mut files: Vec<(PathBuf, Vec<u8>)> = vec![(args.output.clone(), page.into_bytes())];
    if let Some(directory) = &args.png {
        for named in charts(&input) {
            let bytes = chart(&named.chart, PlotFormat::Png)?;
            files.push((directory.join(format!("{}.png", named.name)), bytes));
        }
    }
    // All files or none (output::write_all_new checks every target first);
    // a --png folder this run creates is removed again if nothing is written.
    let created = match &args.png {
        Some(directory) if create_folder(directory)? => Some(directory),
        _ => None,
    };
    let inputs = [
        Some(args.file.as_path()),
        args.after.as_deref(),
        args.table.as_deref(),
        args.machine_file.machine.as_deref(),
        args.uncertainty.equipment.as_deref(),
    ];
    let mut inputs: Vec<&Path> = inputs.into_iter().flatten().collect();
    inputs.extend(args.thermal.inputs());
    if let Err(error) = write_all_new(&files, &inputs, args.overwrite.force) {
        if let Some(directory) = created {
            let _ = std::fs::remove_dir(directory);
        }
        return Err(error.into());
    }
    // With a re-test each test's warnings name its file: the same warning of
    // both is said once for each, not twice alike.
    let paths = std::iter::once(&args.file).chain(&args.after);
    for (test, path) in std::iter::once(&before).chain(&after).zip(paths) {
        match after {
            Some(_) => print_file_warnings(path, &test.warnings, args.verbosity.quiet, angle),
            None => print_warnings_in(&test.warnings, args.verbosity.quiet, angle),
        }
    }
    let mut summary = format!("Wrote {}\n", args.output.display());
    for (path, _) in files.iter().skip(1) {
        summary.push_str(&format!("Wrote {}\n", path.display()));
    }
    print_text(&summary)
}

#[cfg(test)]
mod tests {
    use super::super::{Args, Command};
    use clap::Parser;

    #[test]
    fn diagnose_needs_a_retest_and_output_has_a_default() {
        assert!(Args::try_parse_from(["axcomp", "report", "a.rtl", "--diagnose"]).is_err());
        let args = Args::try_parse_from([
            "axcomp",
            "report",
            "a.rtl",
            "--after",
            "b.rtl",
            "--table",
            "X.COM",
            "--diagnose",
            "--png",
            "plots",
        ])
        .unwrap();
        let Command::Report(report) = args.command else {
            panic!("parsed as report")
        };
        assert!(report.diagnose);
        assert_eq!(report.output.to_str(), Some("report.html"));
        assert_eq!(
            report.png.as_deref().and_then(|p| p.to_str()),
            Some("plots")
        );
    }
}
