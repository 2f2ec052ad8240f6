//! Diagnosing a re-test of 100, 1 000 and 10 000 targets × 5 runs each way:
//! the demo's truth (its axis error, reversal and a warm-up drift in the
//! re-test) with `count = n`, a periodic error of 47 mm new in the re-test,
//! the first test, a mean table at its targets and the re-test with it
//! applied, as `axcomp synth` and `axcomp convert` make them. Measured: the
//! diagnosis alone (`diagnose::diagnose`), from the two measurements and the
//! table to the `Diagnosis`. Two groups: the re-test at the first test's
//! targets (`diagnose`), and between them (`diagnose_between`: n − 1 targets
//! at the midpoints, whose levels share the prediction's uncertainty).
//!
//! The whole process (`axcomp diagnose` and `axcomp report --diagnose` on
//! files made with `synth` and `convert --controller linuxcnc`) is in README,
//! Speed.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;

use axcomp::compensate::{Extrapolate, GridSpec, TableMode, TableOptions, build_table};
use axcomp::cycle::CycleTiming;
use axcomp::diagnose::{DiagnoseInput, diagnose};
use axcomp::evaluate::{ISO_230_2, evaluate};
use axcomp::synth::{self, Truth};

// The binary's allocator (`src/main.rs`), so that the times are the binary's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn truth(count: usize, between: bool) -> Truth {
    let demo = include_str!("../fixtures/demo/truth.toml")
        .replace("count = 16", &format!("count = {count}"));
    let mut text = format!(
        "{demo}\n[[effect]]\nkind = \"periodic\"\nperiod_mm = 47.0\namplitude_um = 1.2\nphase_rad = 1.0\ntests = [\"after\"]\n"
    );
    if between {
        // The demo's axis is 0 … 750 mm: the midpoints of its targets.
        let half = 750.0 / (2.0 * (count - 1) as f64);
        text += &format!(
            "\n[cycle.after]\nstart_mm = {half:?}\nend_mm = {:?}\ncount = {}\n",
            750.0 - half,
            count - 1
        );
    }
    Truth::from_toml_str(&text).expect("the demo's truth")
}

fn bench(c: &mut Criterion) {
    for (name, between) in [("diagnose", false), ("diagnose_between", true)] {
        bench_group(c, name, between);
    }
}

fn bench_group(c: &mut Criterion, name: &str, between: bool) {
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    for count in [100, 1_000, 10_000] {
        let truth = truth(count, between);
        let before = synth::before(&truth, 2026).unwrap();
        let options = TableOptions {
            mode: TableMode::Mean,
            grid: GridSpec::Targets,
            reference: None,
            extrapolate: Extrapolate::Hold,
        };
        let table = build_table(&before, &evaluate(&before), &options).unwrap();
        let after = synth::after(&truth, &table, 2026).unwrap();
        let input = DiagnoseInput {
            angle: Default::default(),
            after: &after,
            before: Some(&before),
            table: Some(&table),
            backlash_set: false,
            angular: None,
            timing: CycleTiming::ASSUMED,
            standard: &ISO_230_2,
            known_periods: &[],
        };
        let found = diagnose(&input).unwrap();
        assert!(!found.accepted.is_empty(), "{count} targets: nothing found");
        group.bench_with_input(BenchmarkId::from_parameter(count), &input, |b, input| {
            b.iter(|| diagnose(black_box(input)).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
