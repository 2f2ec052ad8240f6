//! The command line: a thin layer over the library (binary only).
//!
//! Each subcommand lives in its own file with its flags (clap derive, each
//! flag documented where it is defined) and its `run` function, which turns
//! the flags into library calls and prints. Errors are printed once, with
//! their chain, and give exit code 2. A closed pipe (`axcomp … | head`) is
//! success.

mod acceptance;
mod common;
mod convert;
mod demo;
mod diagnose;
mod evaluate;
mod generate;
mod predict;
mod progress;
mod report;
mod serve;
mod servo_sim;
mod synth;
mod thermal;
mod tolerance;

use std::any::TypeId;
use std::process::ExitCode;

use anyhow::Result;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

/// axcomp: laser measurements to ISO 230-2 figures and compensation tables.
#[derive(Debug, Parser)]
#[command(name = "axcomp", version, about, long_about = None, propagate_version = true)]
pub struct Args {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the whole workflow on bundled sample data and say where everything is.
    ///
    /// Evaluates a first test, writes the table for every controller, predicts
    /// the re-test, diagnoses the bundled re-test (an axis with effects the
    /// model does not declare), writes the next table and the acceptance report.
    Demo(demo::DemoArgs),
    /// Read a laser measurement and evaluate it per ISO 230-2.
    ///
    /// Prints the per-target table and the axis figures A, E, M, R, B in µm.
    /// Give two files to join the forward and reverse files of one axis (API
    /// XD .pos) into one bidirectional measurement.
    Evaluate(evaluate::EvaluateArgs),
    /// Write a compensation table a controller loads as is.
    ///
    /// Heidenhain iTNC 530 and TNC 640 .COM, Siemens Sinumerik 840D .MPF (LEC,
    /// or CEC for bidirectional tables) and LinuxCNC COMP_FILE, from the
    /// per-target mean deviations of a measurement.
    Convert(convert::ConvertArgs),
    /// Write measurement files from a known truth (tests, demos, training).
    ///
    /// The truth (TOML) holds the axis error, effects the model does not
    /// declare (reversal, scale, drift, periodic, outlier run, Abbe), noise,
    /// the ISO 230-2 cycle with its timing and the conditions. With --table the
    /// re-test of the compensated axis is written too, the table applied as the
    /// controller applies it.
    Synth(synth::SynthArgs),
    /// Predict the re-test of a compensated axis and the residual volumetric error.
    ///
    /// From the volumetric model (21 errors): measured files give the
    /// positioning errors along their lines, an error description the others;
    /// each table is applied as its controller applies it. Prints the predicted
    /// ISO 230-2 figures of the re-test on the line and the largest volumetric
    /// error over the work volume with and without the tables.
    Predict(predict::PredictArgs),
    /// Trace the residual of a re-test to the physical effect the model lacks.
    ///
    /// Compares the re-test with the prediction from the first test and the
    /// table, fits the known effects (reversal, scale, drift, periodic,
    /// outlier run, Abbe), accepts one only if it predicts the runs it was not
    /// fitted on and passes an information criterion, and reports what no
    /// effect explains as unexplained structure.
    Diagnose(diagnose::DiagnoseArgs),
    /// Monte Carlo tolerance study: random machines from straightness tolerances.
    ///
    /// Draws random rail mounting surfaces within the tolerances, turns them
    /// into the 21 geometric errors through the guideway model, and reports
    /// the distribution of the largest volumetric error over the work volume
    /// (Valášek 2021). --sweep adds the sensitivity to each tolerance;
    /// --single-axis runs the one-axis study instead.
    Tolerance(Box<tolerance::ToleranceArgs>),
    /// Simulate a feed axis with a friction model (Mendřický 2006).
    ///
    /// The circle test prints the quadrant (reversal) error and current
    /// Mendřický (2006) tabulates; the ISO 230-2 cycle prints the simulated readings
    /// after each dwell and their ISO 230-2 figures, including the reversal
    /// B that friction leaves through the structure's compliance.
    ServoSim(servo_sim::ServoSimArgs),
    /// Write the acceptance report: one self-contained HTML file.
    ///
    /// Header, test conditions with the refractive index check, the ISO
    /// 230-2 figures and per-target table, the deviation plot; with --after
    /// the before/after comparison, with --table the table and the predicted
    /// re-test, with --diagnose the diagnosis. --png writes the plots as PNG.
    Report(Box<report::ReportArgs>),
    /// Start the local web app: evaluate, convert and report in the browser.
    ///
    /// Serves one page on http://127.0.0.1:8230/ (this machine only, unless
    /// --listen) and opens it: drop a measurement file, pick the controller
    /// and grid, download the table and the acceptance report. The same
    /// numbers and files as the commands; everything stays in memory.
    Serve(serve::ServeArgs),
    /// ISO 230-3 thermal tests and a drift model from temperatures (evaluate, fit, apply).
    ///
    /// Reads thermal logs (CSV: time, drift, temperatures), gives the ISO
    /// 230-3 view, fits a model of the drift from sensors through first-order
    /// lags that a control can run, and runs a model over a log.
    Thermal(thermal::ThermalArgs),
    /// Print the shell completion script (bash, zsh, fish, PowerShell, elvish).
    Completions(generate::CompletionsArgs),
    /// Print the manual page (roff) of axcomp or of one of its commands.
    Man(generate::ManArgs),
}

/// Parses, runs, and maps the outcome to an exit code.
pub fn main() -> ExitCode {
    let parsed = command()
        .try_get_matches()
        .and_then(|mut matches| Args::from_arg_matches_mut(&mut matches));
    let args = match parsed {
        Ok(args) => args,
        Err(error) => {
            // clap prints help and version to stdout with exit 0, usage errors to stderr.
            let _ = error.print();
            return if error.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    match run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) if is_broken_pipe(&error) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("axcomp: error: {error:#}");
            ExitCode::from(2)
        }
    }
}

/// The command line as clap parses it: the derived flags, with every number
/// allowed to be negative.
///
/// Without this clap reads `--step -50` or `--reference -10` as the flag
/// `-5…`, and says "unexpected argument" instead of letting axcomp say what
/// is wrong with the value (or use it: a reference below zero is fine). Set
/// here for every flag whose value is a number, so a new flag cannot forget it.
pub fn command() -> clap::Command {
    numbers_may_be_negative(Args::command())
}

fn numbers_may_be_negative(mut command: clap::Command) -> clap::Command {
    let numeric: Vec<(clap::Id, bool)> = command
        .get_arguments()
        .filter(|arg| takes_a_number(arg))
        .map(|arg| (arg.get_id().clone(), arg.get_value_delimiter().is_some()))
        .collect();
    for (id, delimited) in numeric {
        command = command.mut_arg(id, |arg| {
            if delimited {
                // `-0.1,0.2` is not one number, so clap would still take it for a flag.
                arg.allow_hyphen_values(true)
            } else {
                arg.allow_negative_numbers(true)
            }
        });
    }
    let subcommands: Vec<String> = command
        .get_subcommands()
        .map(|sub| sub.get_name().to_string())
        .collect();
    for name in subcommands {
        command = command.mut_subcommand(name, numbers_may_be_negative);
    }
    command
}

/// The value of `arg` is a number (whatever its sign may be).
fn takes_a_number(arg: &clap::Arg) -> bool {
    let value = arg.get_value_parser().type_id();
    [
        TypeId::of::<f64>(),
        TypeId::of::<f32>(),
        TypeId::of::<i64>(),
        TypeId::of::<i32>(),
        TypeId::of::<u64>(),
        TypeId::of::<u32>(),
        TypeId::of::<u8>(),
        TypeId::of::<usize>(),
    ]
    .into_iter()
    .any(|number| value == number)
}

fn run(args: Args) -> Result<()> {
    match args.command {
        Command::Demo(demo_args) => demo::run(&demo_args),
        Command::Evaluate(evaluate_args) => evaluate::run(&evaluate_args),
        Command::Convert(convert_args) => convert::run(&convert_args),
        Command::Synth(synth_args) => synth::run(&synth_args),
        Command::Predict(predict_args) => predict::run(&predict_args),
        Command::Diagnose(diagnose_args) => diagnose::run(&diagnose_args),
        Command::Tolerance(tolerance_args) => tolerance::run(&tolerance_args),
        Command::ServoSim(servo_args) => servo_sim::run(&servo_args),
        Command::Report(report_args) => report::run(&report_args),
        Command::Serve(serve_args) => serve::run(&serve_args),
        Command::Thermal(thermal_args) => thermal::run(&thermal_args),
        Command::Completions(completions_args) => generate::completions(&completions_args),
        Command::Man(man_args) => generate::man(&man_args),
    }
}

fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        let io = cause
            .downcast_ref::<std::io::Error>()
            .map(std::io::Error::kind);
        // serde_json wraps the writer's error without exposing it as a source.
        let json = cause
            .downcast_ref::<serde_json::Error>()
            .and_then(serde_json::Error::io_error_kind);
        io.or(json) == Some(std::io::ErrorKind::BrokenPipe)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flag_definitions_are_consistent() {
        command().debug_assert();
    }

    /// Every flag with a numeric value takes a negative one (otherwise
    /// `convert --step -50` is parsed as a flag).
    #[test]
    fn every_numeric_flag_takes_a_negative_value() {
        let command = command();
        let mut numeric = Vec::new();
        for sub in command.get_subcommands() {
            for arg in sub.get_arguments().filter(|a| takes_a_number(a)) {
                numeric.push(format!("{} --{}", sub.get_name(), arg.get_id()));
                assert!(
                    arg.is_allow_negative_numbers_set() || arg.is_allow_hyphen_values_set(),
                    "{} --{}",
                    sub.get_name(),
                    arg.get_id()
                );
            }
        }
        // The walk sees the flags that take negative numbers (and so cannot pass by seeing none).
        for flag in [
            "convert --step",
            "convert --start",
            "convert --reference",
            "servo-sim --first_mm",
        ] {
            assert!(numeric.contains(&flag.to_string()), "{flag} in {numeric:?}");
        }
        let parsed = Args::from_arg_matches(
            &command
                .clone()
                .try_get_matches_from([
                    "axcomp",
                    "convert",
                    "a.rtl",
                    "--controller",
                    "tnc640",
                    "-o",
                    "X.COM",
                    "--start",
                    "750",
                    "--step",
                    "-50",
                    "--reference",
                    "-10",
                ])
                .unwrap(),
        )
        .unwrap();
        let Command::Convert(convert) = parsed.command else {
            panic!("parsed as convert")
        };
        assert_eq!(
            (convert.start, convert.step, convert.reference),
            (Some(750.0), Some(-50.0), Some(-10.0))
        );
    }
}
