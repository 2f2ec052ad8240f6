//! Fuzz target: the csv reader must never panic, whatever the bytes; what it
//! accepts must be a valid measurement that the evaluator handles.
#![no_main]

use libfuzzer_sys::fuzz_target;

use axcomp::evaluate::evaluate;
use axcomp::measurement::SourceFormat;
use axcomp::read::{decode, parse_str};

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = decode(bytes) else { return };
    if let Ok((measurement, _warnings)) = parse_str(&text, SourceFormat::Csv) {
        let evaluation = evaluate(&measurement);
        assert_eq!(evaluation.per_target.len(), measurement.targets().len());
    }
});
