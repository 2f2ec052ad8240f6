//! Fuzz target: the Fagor readers (8055 `AL<axis>`, 8065 `.mp` after UTF-16
//! decoding) must never panic; an 8065 table they accept must go back into
//! its own file with `update` and read back to the same number of points.
#![no_main]

use libfuzzer_sys::fuzz_target;

use axcomp::emit::{decode_table, fagor8055, fagor8065};
use axcomp::units::LengthUnit;

fuzz_target!(|bytes: &[u8]| {
    let Ok((text, _)) = decode_table(bytes) else { return };
    let _ = fagor8055::read(&text, "X", LengthUnit::Inch);
    let Ok(table) = fagor8065::read(&text, "X") else { return };
    if let Ok(updated) = fagor8065::update(&text, &table) {
        let back = fagor8065::read(&updated, "X").expect("an updated file reads back");
        assert_eq!(back.positions_mm.len(), table.positions_mm.len());
    }
});
