//! Fuzz target: the Fanuc readers (parameter backup, pitch file) must never
//! panic; a pitch file they accept must take its own table back with
//! `update` and read back to the same points, for the one-direction and the
//! bidirectional table, and `rescaled` of it must not panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

use axcomp::emit::fanuc::{self, AxisParameters, ParameterBackup};
use axcomp::emit::{EmitOptions, MachineProfile, decode_table};

fuzz_target!(|bytes: &[u8]| {
    let Ok((text, _)) = decode_table(bytes) else { return };
    if let Ok(backup) = ParameterBackup::parse(&text, "fuzz") {
        for (_, name) in backup.axis_names() {
            let _ = backup.axis(&name);
        }
    }
    // The real backup's X: points 0 … 41, reference 40, 40 mm apart; and
    // the same with its negative-direction table at 50 … 90 (3626 = 50).
    let one = AxisParameters {
        most_negative: 1,
        most_positive: 41,
        ..AxisParameters::default_for("X", 42, 40.0, 40, 0.0)
    };
    let both = AxisParameters {
        bidirectional: true,
        negative_first: 50,
        ..one.clone()
    };
    for parameters in [one, both] {
        let Ok(table) = fanuc::read(&text, &parameters) else { continue };
        let mut options = EmitOptions::for_axis(&MachineProfile::default(), "X", "").unwrap();
        options.axes[0].fanuc = Some(parameters.clone());
        if let Ok(updated) = fanuc::update(&text, &table, &options) {
            let back = fanuc::read(&updated, &parameters).expect("an updated file reads back");
            assert_eq!(back.positions_mm, table.positions_mm);
        }
        let _ = fanuc::rescaled(Some(&text), &table, &options, None);
    }
});
