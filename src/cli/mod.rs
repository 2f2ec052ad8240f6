//! The command line: a thin layer over the library (binary only).
//!
//! [`args`] mirrors the flags with clap and validates them; [`run`] turns them
//! into library calls and prints. Errors are printed once, with their chain,
//! and give exit code 2. A closed pipe (`axcomp evaluate x | head`) is success.

mod args;
mod run;

use std::io::IsTerminal;
use std::process::ExitCode;

use clap::Parser;

/// Parses, runs, and maps the outcome to an exit code.
pub fn main() -> ExitCode {
    let args = match args::Args::try_parse() {
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
    match run::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) if is_broken_pipe(&error) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("axcomp: error: {error:#}");
            ExitCode::from(2)
        }
    }
}

fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Whether progress bars and colour may be shown: stdout is a terminal and not `--quiet`.
#[allow(dead_code)]
pub fn interactive(quiet: bool) -> bool {
    !quiet && std::io::stdout().is_terminal()
}
