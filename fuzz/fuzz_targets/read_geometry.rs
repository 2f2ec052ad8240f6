//! Fuzz target: the geometry CSV reader must never panic, whatever the
//! bytes; what it accepts has one value per target in every run, and its
//! means and written text read back.
#![no_main]

use libfuzzer_sys::fuzz_target;

use axcomp::read::{decode, geometry};

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = decode(bytes) else { return };
    if let Ok(test) = geometry::parse(&text) {
        for column in &test.columns {
            assert_eq!(column.means().len(), test.targets_mm.len());
            for run in &column.runs {
                assert_eq!(run.values.len(), test.targets_mm.len());
            }
        }
        let again = geometry::parse(&geometry::write(&test)).expect("written text reads back");
        assert_eq!(again.targets_mm, test.targets_mm);
    }
});
