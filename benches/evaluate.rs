//! Reading and evaluating a large test: 10,000 targets × 10 runs (5 each way).
//!
//! The parts (parse, evaluate) and the two together, without process start-up.
//! The whole process is measured against `benches/reference/evaluate_rtl.py`
//! (a plain-Python read+evaluate of the same file): write the file with
//! `rtl::write` of this measurement, or with `axcomp synth`
//!
//! ```sh
//! sed -e 's/^count = 16/count = 10000/' -e 's/^end_mm = 750.0/end_mm = 999.9/' \
//!     fixtures/demo/truth.toml > /tmp/big-truth.toml
//! axcomp synth --truth /tmp/big-truth.toml -o /tmp/big.rtl --seed 1
//! ```
//!
//! and time both commands, paired (`farm-bench -n 10 --vs 'python3
//! benches/reference/evaluate_rtl.py /tmp/big.rtl' -- target/release/axcomp
//! evaluate /tmp/big.rtl -q`). Last measured (medians, 2-core machine shared
//! with other builds): axcomp 13 ms CPU, 13 ms wall; Python 185 ms CPU, 185 ms
//! wall; ratio 0.068 CPU, 0.071 wall (it was 0.117 and 0.120, 22 ms, before the
//! reader filled each run's readings as it read them). The aim is 1/20.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

use axcomp::evaluate::evaluate;
use axcomp::measurement::{Direction, Environment, Measurement, Metadata, Run, SourceFormat};
use axcomp::read::{self, rtl};

/// A deterministic 10,000-target measurement (no RNG: a sine plus a
/// run-dependent wobble is enough to exercise every code path).
fn large_measurement() -> Measurement {
    let targets: Vec<f64> = (0..10_000).map(|i| f64::from(i) * 0.1).collect();
    let runs = (0..10u32)
        .map(|k| Run {
            direction: if k % 2 == 0 {
                Direction::Up
            } else {
                Direction::Down
            },
            number: k / 2 + 1,
            start_time_s: None,
            deviations_mm: targets
                .iter()
                .map(|x| Some(0.005 * (x / 50.0).sin() + 1e-4 * f64::from(k) * (x * 7.0).cos()))
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
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
