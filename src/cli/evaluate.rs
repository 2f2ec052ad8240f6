//! `axcomp evaluate`: read a measurement and print its ISO 230-2 figures.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

use axcomp::evaluate::evaluate_with;
use axcomp::measurement::{Direction, Measurement, RunSelector};
use axcomp::read;
use axcomp::report::terminal;
use axcomp::workflow::{EvaluationReportOptions, evaluation_report};

use super::acceptance::{LimitArgs, load_limits};
use super::common::{
    AngleUnitArg, InputFormat, JsonOutput, MachineFile, StandardArg, UncertaintyArgs, Verbosity,
    load_equipment, name_axis, parse_run_selector, print_json, print_text, print_warnings_in,
};

/// Flags of `axcomp evaluate`.
#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// Measurement file(s): .rtl, ecmc .dat, API .pos or axcomp CSV.
    ///
    /// The format is detected from the content. Two files of one axis (e.g.
    /// forward and reverse .pos) are joined into one measurement.
    #[arg(required = true, num_args = 1..=2, value_name = "FILE")]
    pub files: Vec<PathBuf>,

    /// `--format` (the same in every command).
    #[command(flatten)]
    pub input_format: InputFormat,

    /// Name of the axis, instead of the one in the file.
    ///
    /// Some files name no axis (an ecmc file whose PV names and file name
    /// state no axis letter; the report then says "not recorded") or the
    /// wrong one (API files copied from another axis).
    #[arg(long, value_name = "NAME", help_heading = "Input")]
    pub axis: Option<String>,

    /// Leave a run out of the evaluation: RUN (both directions), RUN:up or RUN:down.
    ///
    /// Runs are numbered 1, 2, 3, … per direction in the order measured, as the
    /// report names them. Repeat the flag to leave out several. Only do this
    /// for a run you know is faulty (e.g. flagged as a suspected outlier and
    /// explained).
    #[arg(long = "exclude-run", value_name = "RUN[:DIR]", value_parser = parse_run_selector, help_heading = "Evaluation")]
    pub exclude_runs: Vec<RunSelector>,

    /// `--machine` (one profile; each command reads its part).
    #[command(flatten)]
    pub machine_file: MachineFile,

    /// `--standard` (the same in every command).
    #[command(flatten)]
    pub standard: StandardArg,

    #[command(flatten)]
    pub acceptance: LimitArgs,

    /// `--equipment`, `--decision` (the same in `report`).
    #[command(flatten)]
    pub uncertainty: UncertaintyArgs,

    /// `--json` (the same in every command).
    #[command(flatten)]
    pub json_output: JsonOutput,

    /// `--angle-unit` (the same in `report` and `diagnose`).
    #[command(flatten)]
    pub angle_unit: AngleUnitArg,

    /// -q/--quiet (the same in every command).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Runs `axcomp evaluate`.
pub fn run(args: &EvaluateArgs) -> Result<()> {
    let read::ReadResult {
        mut measurement,
        mut warnings,
    } = read::read_paths(&args.files, args.input_format.format)?;
    name_axis(&mut measurement, args.axis.as_ref());
    let angle = args.angle_unit.for_axis(&measurement)?;
    check_selectors(&measurement, &args.exclude_runs)?;
    let measurement = measurement
        .without_runs(&args.exclude_runs)
        .context("after excluding runs")?;
    let evaluation = evaluate_with(&measurement, args.standard.standard);
    let limits = load_limits(
        args.machine_file.machine.as_deref(),
        measurement.axis(),
        &evaluation,
        &args.acceptance,
    )?;
    let equipment = load_equipment(&args.uncertainty)?;
    let report = evaluation_report(
        &measurement,
        evaluation,
        &mut warnings,
        EvaluationReportOptions {
            exclude_runs: &args.exclude_runs,
            limits: &limits,
            equipment: equipment.as_ref(),
            decision: args.uncertainty.decision,
            angle,
        },
    )?;
    // The report holds all it prints. The readings go first, so that the
    // text rendered from a large test (megabytes) takes memory already in
    // use rather than new pages.
    drop(measurement);
    print_warnings_in(&warnings, args.verbosity.quiet, angle);
    if args.json_output.json {
        print_json(&report)
    } else {
        print_text(&terminal::evaluation_report(&report))
    }
}

/// Refuses selectors that pick no run: a typo must not pass silently.
pub fn check_selectors(measurement: &Measurement, selectors: &[RunSelector]) -> Result<()> {
    for selector in selectors {
        if measurement.runs().iter().any(|run| selector.selects(run)) {
            continue;
        }
        let up = measurement.run_count(Direction::Up);
        let down = measurement.run_count(Direction::Down);
        bail!("--exclude-run {selector}: no such run (the file has runs 1–{up} ↑ and 1–{down} ↓)");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{Args, Command};
    use clap::Parser;

    #[test]
    fn evaluate_takes_one_or_two_files() {
        assert!(Args::try_parse_from(["axcomp", "evaluate"]).is_err());
        assert!(Args::try_parse_from(["axcomp", "evaluate", "a", "b", "c"]).is_err());
        let args = Args::try_parse_from([
            "axcomp",
            "evaluate",
            "a.pos",
            "b.pos",
            "--exclude-run",
            "1:down",
            "--json",
        ])
        .unwrap();
        let Command::Evaluate(evaluate) = args.command else {
            panic!("parsed as evaluate")
        };
        assert_eq!(evaluate.files.len(), 2);
        assert!(evaluate.json_output.json);
        assert_eq!(evaluate.exclude_runs.len(), 1);
    }
}
