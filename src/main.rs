//! The `axcomp` binary: parse the command line, run, map the result to an exit code.
//!
//! Exit status: 0 on success, 2 on any error (bad input, refused table, I/O).
//! 1 is kept for a negative verdict, should one ever be added.

mod cli;

// mimalloc rather than the system allocator: a large test (10 000 targets,
// 1.9 MB) spent a third of its time in the kernel faulting in fresh pages
// for the file, the runs, the statistics and the printed table; mimalloc
// reuses freed pages and asks for transparent huge pages, and evaluate of
// that file took a fifth less CPU time on a quiet machine, less when huge
// pages are scarce (docs/src/speed.md). ripgrep likewise replaces the allocator
// where the system's is slow (jemalloc, in its musl builds). Its 2.x series
// (feature `v2`): evaluate of that file peaks at 19 MB rather than 27 MB
// with 3.x, five fresh huge pages to zero rather than nine, and takes
// 6–14 % less CPU time (paired runs, loaded machine).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    cli::main()
}
