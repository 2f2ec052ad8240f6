//! Fuzz target: the controller table readers (`emit::read_any`, which
//! detects the format) must never panic; a table they accept must write back
//! in its own format and read back again.
#![no_main]

use libfuzzer_sys::fuzz_target;

use axcomp::emit::{self, EmitOptions, MachineProfile};
use axcomp::read::decode;
use axcomp::units::LengthUnit;

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = decode(bytes) else { return };
    let options = EmitOptions {
        axes: vec![MachineProfile::default().axis("X").expect("X has defaults")],
        table_name: "X.COM".into(),
        machine_unit: LengthUnit::Millimetre,
        linuxcnc_type: 0,
        max_points: None,
        max_value_mm: None,
        cec_first_table: 0,
        cec_values_are_corrections: true,
        tnc640_columns: Vec::new(),
    };
    let Ok((controller, table)) = emit::read_any(&text, &options, Some(0)) else { return };
    // What was read may still break a controller rule (e.g. a non-zero iTNC
    // datum); if it passes the checks, it must survive its own round trip.
    if emit::check_table(controller, &table, &options).is_ok() {
        emit::write(controller, &table, &options).expect("a checked table writes and reads back");
    }
});
