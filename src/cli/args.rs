//! Command-line flags (clap derive). Each flag's doc comment is its help: the
//! first paragraph for `-h`, all of it for `--help`.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

use axcomp::measurement::{Direction, RunSelector, SourceFormat};

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
    /// Read a laser measurement and evaluate it per ISO 230-2.
    ///
    /// Prints the per-target table and the axis figures A, E, M, R, B in µm.
    /// Give two files to join the forward and reverse files of one axis (API
    /// XD .pos) into one bidirectional measurement.
    Evaluate(EvaluateArgs),
}

/// Flags of `axcomp evaluate`.
#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// Measurement file(s): .rtl, ecmc .dat, API .pos or axcomp CSV.
    ///
    /// The format is detected from the content. Two files of one axis (e.g.
    /// forward and reverse .pos) are joined into one measurement.
    #[arg(required = true, num_args = 1..=2, value_name = "FILE")]
    pub files: Vec<PathBuf>,

    /// Input format, instead of detecting it: rtl, ecmc, api-pos, csv.
    #[arg(long, value_name = "FORMAT", value_parser = parse_format, help_heading = "Input")]
    pub format: Option<SourceFormat>,

    /// Name of the axis, instead of the one in the file.
    ///
    /// Some files name no axis (ecmc) or the wrong one (API files copied
    /// from another axis).
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

    /// Print one JSON object (units in the keys) instead of the report.
    #[arg(long, help_heading = "Output")]
    pub json: bool,

    /// Do not print warnings.
    #[arg(long, short = 'q', help_heading = "Output")]
    pub quiet: bool,
}

fn parse_format(name: &str) -> Result<SourceFormat, String> {
    SourceFormat::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = SourceFormat::ALL.iter().map(|f| f.name()).collect();
        format!("unknown format {name:?}; supported: {}", names.join(", "))
    })
}

/// `3`, `3:up`, `3:down` (also `3up`, `3↑`, `3↓`).
pub fn parse_run_selector(text: &str) -> Result<RunSelector, String> {
    let text = text.trim();
    let digits_end = text
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(text.len());
    let (number, rest) = text.split_at(digits_end);
    let number: u32 =
        number.parse().ok().filter(|n| *n > 0).ok_or_else(|| {
            format!("expected a run number from 1, like 3 or 3:down, found {text:?}")
        })?;
    let direction = match rest.trim_start_matches(':').to_ascii_lowercase().as_str() {
        "" => None,
        "up" | "↑" => Some(Direction::Up),
        "down" | "↓" => Some(Direction::Down),
        other => {
            return Err(format!(
                "expected up or down after the run number, found {other:?}"
            ));
        }
    };
    Ok(RunSelector { number, direction })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn flag_definitions_are_consistent() {
        Args::command().debug_assert();
    }

    #[test]
    fn exclude_run_accepts_run_and_direction() {
        let both = parse_run_selector("3").unwrap();
        assert_eq!((both.number, both.direction), (3, None));
        assert_eq!(
            parse_run_selector("2:down").unwrap().direction,
            Some(Direction::Down)
        );
        assert_eq!(
            parse_run_selector("2up").unwrap().direction,
            Some(Direction::Up)
        );
        assert_eq!(
            parse_run_selector("1↓").unwrap().direction,
            Some(Direction::Down)
        );
        assert!(parse_run_selector("0").is_err());
        assert!(parse_run_selector("x").is_err());
        assert!(parse_run_selector("2:sideways").is_err());
    }

    #[test]
    fn format_names() {
        assert_eq!(parse_format("API-POS").unwrap(), SourceFormat::ApiPos);
        assert!(
            parse_format("xls")
                .unwrap_err()
                .contains("rtl, ecmc, api-pos, csv")
        );
    }

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
        let Command::Evaluate(evaluate) = args.command;
        assert_eq!(evaluate.files.len(), 2);
        assert!(evaluate.json);
        assert_eq!(evaluate.exclude_runs.len(), 1);
    }
}
