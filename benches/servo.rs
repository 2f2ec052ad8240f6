//! Speed of a full ISO 230-2 cycle on the bundled X axis, per friction model.
//!
//! The issue asks that such a cycle (21 targets, 5 bidirectional runs, 1 s
//! dwell, a few minutes of machine time) simulate at least 100× faster than
//! real time on one core, aiming at 1000×. The machine time of the cycle is
//! printed once; divide it by criterion's time per iteration for the factor
//! (README, "Speed").

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

use axcomp::servo::axis::Axis;
use axcomp::servo::friction::FrictionKind;
use axcomp::servo::iso_cycle::{IsoCycle, IsoOptions, run_iso_cycle};
use axcomp::servo::simulate::Stepping;
use axcomp::servo::trajectory::MoveLimits;

/// 21 targets over the X axis's 500 mm travel (Tab. 3.3), 5 runs, 1 s dwell, 2 m/min.
fn full_cycle() -> IsoCycle {
    IsoCycle {
        targets_m: IsoCycle::evenly_spaced(0.0, 0.5, 21),
        runs: 5,
        dwell_s: 1.0,
        overrun_m: 0.005,
        limits: MoveLimits {
            feed_m_per_s: 2.0 / 60.0,
            acceleration_m_per_s2: 1.0,
            jerk_m_per_s3: 20.0,
        },
    }
}

fn bench(c: &mut Criterion) {
    let axis = Axis::bundled("mcfv5050-x").unwrap();
    let cycle = full_cycle();
    let options = IsoOptions {
        stiffness_n_per_um: Some(100.0),
        stepping: Stepping::DEFAULT,
    };
    let mut group = c.benchmark_group("iso230_2_cycle_21_targets_5_runs");
    group.sample_size(10);
    for kind in FrictionKind::ALL {
        let friction = axis.friction(kind);
        let once = run_iso_cycle(&axis, friction, &cycle, options, &mut |_| {}).unwrap();
        eprintln!(
            "{}: machine time {:.1} s, macro steps kept {} / refined {}",
            kind.name(),
            once.simulated_s,
            once.counts.coarse,
            once.counts.refined
        );
        group.bench_function(kind.name(), |b| {
            b.iter(|| {
                run_iso_cycle(&axis, friction, black_box(&cycle), options, &mut |_| {}).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
