//! Runs a parsed command: turns flags into library calls and prints the result.

use std::io::Write;

use anyhow::{Context, Result, bail};

use axcomp::evaluate::evaluate;
use axcomp::measurement::{Direction, Measurement, RunSelector};
use axcomp::read;
use axcomp::report::{json::EvaluationJson, terminal};

use super::args::{Args, Command, EvaluateArgs};

/// Runs one command.
pub fn run(args: Args) -> Result<()> {
    match args.command {
        Command::Evaluate(evaluate_args) => run_evaluate(&evaluate_args),
    }
}

fn run_evaluate(args: &EvaluateArgs) -> Result<()> {
    let read::ReadResult {
        mut measurement,
        mut warnings,
    } = read::read_paths(&args.files, args.format)?;
    if let Some(axis) = &args.axis {
        measurement.set_axis(axis.clone());
    }
    check_selectors(&measurement, &args.exclude_runs)?;
    let measurement = measurement
        .without_runs(&args.exclude_runs)
        .context("after excluding runs")?;
    let evaluation = evaluate(&measurement);
    warnings.extend(evaluation.warnings.iter().cloned());
    let report = EvaluationJson::new(&measurement, &evaluation, &args.exclude_runs, &warnings);
    if !args.quiet {
        for warning in &warnings {
            eprintln!("axcomp: warning: {warning}");
        }
    }
    let mut stdout = std::io::stdout().lock();
    if args.json {
        serde_json::to_writer_pretty(&mut stdout, &report)?;
        writeln!(stdout)?;
    } else {
        stdout.write_all(terminal::evaluation_report(&report).as_bytes())?;
    }
    stdout.flush()?;
    Ok(())
}

/// Refuses selectors that pick no run: a typo must not pass silently.
fn check_selectors(measurement: &Measurement, selectors: &[RunSelector]) -> Result<()> {
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
