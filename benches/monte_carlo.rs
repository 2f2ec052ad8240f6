//! The Monte Carlo tolerance study: 50,000 random machines of the bundled
//! MCV 754 Quick (the thesis's baseline: all six straightness tolerances
//! 0.03 mm, no positioning or squareness errors, 50 mm grid), on all cores
//! and on one; the same with the carriage side (parallelism and flatness
//! 0.03 mm on every saddle); and the single-axis study.
//!
//! Criterion reports the throughput in samples per second ("elem/s"). The
//! whole-process comparison with the NumPy peer (`../shared/tools/mc_peer.py`)
//! is in the README ("Speed"), because the peer runs as its own process.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

use axcomp::model::monte_carlo::{
    AxisStudyOptions, StudyOptions, Tolerances, single_axis_study, tolerance_study,
};
use axcomp::model::{Machine, ProfileShape};

const SAMPLES: usize = 50_000;

fn baseline(samples: usize) -> StudyOptions {
    StudyOptions {
        samples,
        seed: 1,
        tolerances: Tolerances::uniform(0.03, 0.0, 0.0),
        shape: ProfileShape::THESIS,
        grid_step_mm: 50.0,
    }
}

fn bench(c: &mut Criterion) {
    let machine = Machine::bundled();
    let mut group = c.benchmark_group("monte_carlo_50k");
    group.sample_size(10);
    group.throughput(Throughput::Elements(SAMPLES as u64));
    let options = baseline(SAMPLES);
    group.bench_function("tolerance_study_all_cores", |b| {
        b.iter(|| tolerance_study(&machine, black_box(&options), &|_| {}).unwrap())
    });
    let mut carriage_side = options;
    carriage_side.tolerances.carriage_mm = [[0.03, 0.03]; 3];
    group.bench_function("tolerance_study_with_carriage_side_all_cores", |b| {
        b.iter(|| tolerance_study(&machine, black_box(&carriage_side), &|_| {}).unwrap())
    });
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    group.bench_function("tolerance_study_one_thread", |b| {
        b.iter(|| {
            one_thread.install(|| tolerance_study(&machine, black_box(&options), &|_| {}).unwrap())
        })
    });
    let axis = AxisStudyOptions::thesis(SAMPLES, 1);
    group.bench_function("single_axis_study_all_cores", |b| {
        b.iter(|| single_axis_study(black_box(&axis), &|_| {}).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
