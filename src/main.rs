//! The `axcomp` binary: parse the command line, run, map the result to an exit code.
//!
//! Exit status: 0 on success, 2 on any error (bad input, refused table, I/O).
//! 1 is kept for a negative verdict, should one ever be added.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
