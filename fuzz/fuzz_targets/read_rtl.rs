//! Fuzz target: the `.rtl` reader must never panic, whatever the bytes; what it
//! accepts must be a valid measurement that the evaluator handles, and writing
//! it back as `.rtl` must read back to the same targets and readings.
#![no_main]

use libfuzzer_sys::fuzz_target;

use axcomp::evaluate::evaluate;
use axcomp::measurement::SourceFormat;
use axcomp::read::{decode, parse_str, rtl};

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = decode(bytes) else { return };
    let Ok((measurement, _warnings)) = parse_str(&text, SourceFormat::Rtl) else { return };
    let evaluation = evaluate(&measurement);
    assert_eq!(evaluation.per_target.len(), measurement.targets().len());
    let written = rtl::write(&measurement);
    let (again, _) = parse_str(&written, SourceFormat::Rtl).expect("what axcomp writes, it reads");
    assert_eq!(again.targets(), measurement.targets());
    for (a, b) in again.runs().iter().zip(measurement.runs()) {
        assert_eq!(a.deviations.len(), b.deviations.len());
        for (x, y) in a.deviations.iter().zip(&b.deviations) {
            match (x, y) {
                (Some(x), Some(y)) => assert!((x - y).abs() <= 1e-15 * y.abs().max(1.0)),
                (None, None) => {}
                _ => panic!("a reading appeared or vanished in the round trip"),
            }
        }
    }
});
