//! Reading and evaluating a large test: 10,000 targets × 10 runs (5 each way).
//!
//! The parts (parse, evaluate), the two together, and the whole of what
//! `axcomp evaluate` does between reading the file and printing (parse,
//! evaluate, the JSON object, the terminal report), without process start-up.
//! The readings have three decimals in µm, as laser software writes them.
//!
//! The whole process must be at least 10 times faster than
//! `benches/reference/evaluate_rtl.py` (a plain-Python read+evaluate of the
//! same file): write the file with
//! `axcomp synth`
//!
//! ```sh
//! sed -e 's/^count = 16/count = 10000/' -e 's/^end_mm = 750.0/end_mm = 999.9/' \
//!     fixtures/demo/truth.toml > /tmp/big-truth.toml
//! axcomp synth --truth /tmp/big-truth.toml -o /tmp/big.rtl --seed 1
//! ```
//!
//! and time both commands as whole processes, paired, in turn (for example
//! `/usr/bin/time -f '%e s %U+%S s'` on `axcomp evaluate /tmp/big.rtl -q` and
//! on `/usr/bin/python3 benches/reference/evaluate_rtl.py /tmp/big.rtl`,
//! several runs each, medians). Time the interpreter itself: a version
//! manager's `python3` shim adds its own start (0.3 s on one machine) and
//! flatters the ratio. docs/src/speed.md gives the last figures.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

use axcomp::evaluate::evaluate;
use axcomp::evaluate::uncertainty::Equipment;
use axcomp::evaluate::verdict::Decision;
use axcomp::measurement::{Direction, Environment, Measurement, Metadata, Run, SourceFormat};
use axcomp::read::{self, rtl};
use axcomp::report::terminal;
use axcomp::units::AngleUnit;
use axcomp::workflow::{self, EvaluationReportOptions};

// The binary's allocator (`src/main.rs`), so that the times are the binary's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// A deterministic 10,000-target measurement (no RNG: a sine plus a
/// run-dependent wobble is enough to exercise every code path).
fn large_measurement() -> Measurement {
    // i / 10 rather than i · 0.1: targets as a file lists them, 0.3 not 0.30000000000000004.
    let targets: Vec<f64> = (0..10_000).map(|i| f64::from(i) / 10.0).collect();
    let runs = (0..10u32)
        .map(|k| Run {
            direction: if k % 2 == 0 {
                Direction::Up
            } else {
                Direction::Down
            },
            number: k / 2 + 1,
            start_time_s: None,
            deviations: targets
                .iter()
                .map(|x| {
                    let mm = 0.005 * (x / 50.0).sin() + 1e-4 * f64::from(k) * (x * 7.0).cos();
                    // Whole nm: three decimals in µm, as a laser file has them.
                    Some((mm * 1e6).round() / 1e6)
                })
                .collect(),
        })
        .collect();
    Measurement::new(
        "X",
        targets,
        runs,
        Environment::default(),
        Metadata::default(),
    )
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let measurement = large_measurement();
    let text = rtl::write(&measurement);
    let mut group = c.benchmark_group("evaluate_10k_targets_10_runs");
    group.sample_size(20);
    group.bench_function("parse_rtl", |b| {
        b.iter(|| read::parse_str(black_box(&text), SourceFormat::Rtl).unwrap())
    });
    group.bench_function("evaluate", |b| b.iter(|| evaluate(black_box(&measurement))));
    group.bench_function("parse_and_evaluate", |b| {
        b.iter(|| {
            let (measurement, _) = read::parse_str(black_box(&text), SourceFormat::Rtl).unwrap();
            evaluate(&measurement)
        })
    });
    group.bench_function("parse_evaluate_report", |b| {
        let equipment = Equipment::bundled();
        b.iter(|| {
            let (measurement, mut warnings) =
                read::parse_str(black_box(&text), SourceFormat::Rtl).unwrap();
            let evaluation = evaluate(&measurement);
            let report = workflow::evaluation_report(
                &measurement,
                evaluation,
                &mut warnings,
                EvaluationReportOptions {
                    exclude_runs: &[],
                    limits: &[],
                    equipment: Some(&equipment),
                    decision: Decision::default(),
                    angle: AngleUnit::default(),
                },
            )
            .unwrap();
            terminal::evaluation_report(&report)
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
