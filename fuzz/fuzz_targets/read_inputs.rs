//! Fuzz target: the small input files the CLI hands to the library as text
//! (effects file, error description, angular profile, truth and machine
//! descriptions) must never panic, whatever the bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;

use axcomp::diagnose::AngularProfile;
use axcomp::effects::read_effects;
use axcomp::model::{Machine, read_error_description};
use axcomp::read::decode;
use axcomp::synth::Truth;

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = decode(bytes) else { return };
    let _ = read_effects(&text);
    let _ = read_error_description(&text);
    let _ = AngularProfile::from_csv_str(&text);
    let _ = Truth::from_toml_str(&text);
    let _ = Machine::from_toml_str(&text);
});
