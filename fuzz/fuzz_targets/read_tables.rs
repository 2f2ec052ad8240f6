//! Fuzz target: the controller table readers (`emit::read_any`, which
//! detects the format) must never panic; a table they accept must write back
//! in its own format and read back again.
#![no_main]

use libfuzzer_sys::fuzz_target;

use axcomp::emit::{self, EmitOptions, MachineProfile};
use axcomp::emit::decode_table;

fuzz_target!(|bytes: &[u8]| {
    let Ok((text, _)) = decode_table(bytes) else { return };
    let options = EmitOptions::for_axis(&MachineProfile::default(), "X", "X.COM").expect("X has defaults");
    let Ok((controller, table)) = emit::read_any(&text, &options, Some(0)) else { return };
    // What was read may still break a controller rule (e.g. a non-zero iTNC
    // datum); if it passes the checks, it must survive its own round trip.
    if emit::check_table(controller, &table, &options).is_ok() {
        emit::write(controller, &table, &options).expect("a checked table writes and reads back");
    }
});
