//! The `.rtl` writer: a measurement as Renishaw's software writes a linear test.

use super::NO_SENSOR_C;
use crate::measurement::{Direction, Environment, Measurement, Metadata, StartEnd};
use crate::units::um_text;

/// Writes a measurement as an `.rtl` file (CRLF line ends, as Renishaw's software writes).
///
/// Runs are written in the order measured, one file run per direction pass;
/// rows go in the order the run visited the targets. Numbers use the shortest
/// text that reads back to the same value, so `parse(write(m))` gives `m` back.
pub fn write(measurement: &Measurement) -> String {
    let mut out = String::new();
    let mut line = |text: &str| {
        out.push_str(text);
        out.push_str("\r\n");
    };
    let metadata = &measurement.metadata;
    let field = |value: &Option<String>| value.clone().unwrap_or_default();
    let unidirectional =
        measurement.run_count(Direction::Up) == 0 || measurement.run_count(Direction::Down) == 0;

    line("HEADER::");
    line("File type  : rtl");
    line("Owner      : Linear");
    line("Version no : axcomp");
    line("");
    line("TARGET DATA::");
    line("Filetype  : ISO");
    line(&format!("Target-count: {}", measurement.targets().len()));
    line("Targets :");
    for chunk in measurement.targets().chunks(5) {
        let texts: Vec<String> = chunk.iter().map(|t| format!("{t}")).collect();
        line(&texts.join("  "));
    }
    line(if unidirectional {
        "Flags: 0 1 2 0"
    } else {
        "Flags: 0 0 2 0"
    });
    line("");
    line("USER-TEXT::");
    line(&format!("Machine: {}", field(&metadata.machine)));
    line(&format!("Serial No: {}", field(&metadata.serial_number)));
    let date = metadata
        .date
        .as_ref()
        .map(|d| d.raw.clone())
        .unwrap_or_default();
    line(&format!("Date: {date}"));
    line(&format!("By: {}", field(&metadata.operator)));
    // A placeholder name stays unrecorded: the file must not claim an axis.
    let axis = if measurement.axis_recorded() {
        measurement.axis()
    } else {
        ""
    };
    line(&format!("Axis: {axis}"));
    line(&format!("Location: {}", field(&metadata.location)));
    line(&format!("TITLE: {}", field(&metadata.description)));
    line("");
    line("RUNS::");
    line(&format!("Run-count:{}", measurement.runs().len()));
    line("");
    line("DEVIATIONS::");
    line("Run Target Data:");
    for (run_index, run) in measurement.runs().iter().enumerate() {
        let order: Vec<usize> = match run.direction {
            Direction::Up => (0..measurement.targets().len()).collect(),
            Direction::Down => (0..measurement.targets().len()).rev().collect(),
        };
        for target_index in order {
            if let Some(deviation_mm) = run.deviations[target_index] {
                line(&format!(
                    "{:<3} {:<6} {}",
                    run_index + 1,
                    target_index + 1,
                    um_text(deviation_mm)
                ));
            }
        }
    }
    line("");
    line("ENVIRONMENT::");
    write_environment(&measurement.environment, &mut line);
    if let Some(times) = capture_times(metadata) {
        line(&times);
    }
    line("");
    line("EOF::");
    out
}

pub(super) fn write_environment(environment: &Environment, line: &mut impl FnMut(&str)) {
    let pair = |value: StartEnd, missing: f64| {
        format!(
            "{:.6} {:.6}",
            value.start.unwrap_or(missing),
            value.end.unwrap_or(missing)
        )
    };
    if !environment.air_temperature_c.is_empty() {
        line(&format!(
            "Air temp   : {}",
            pair(environment.air_temperature_c, 0.0)
        ));
    }
    if !environment.air_pressure_kpa.is_empty() {
        line(&format!(
            "Air press  : {}",
            pair(environment.air_pressure_kpa, 0.0)
        ));
    }
    if !environment.air_humidity_pct.is_empty() {
        line(&format!(
            "Air humid  : {}",
            pair(environment.air_humidity_pct, 0.0)
        ));
    }
    for (index, sensor) in environment.material_temperature_c.iter().enumerate() {
        line(&format!(
            "Mat temp {} : {}",
            index + 1,
            pair(*sensor, NO_SENSOR_C)
        ));
    }
    if !environment.environmental_factor_um.is_empty() {
        let factor = environment.environmental_factor_um;
        line(&format!(
            "Env factor : {:.8} {:.8}",
            factor.start.unwrap_or(0.0),
            factor.end.unwrap_or(0.0)
        ));
    }
    if let Some(coefficient) = environment.expansion_coefficient_ppm_per_k {
        line(&format!("Exp coeff  : {coefficient:.6} {coefficient:.6}"));
    }
}

/// The `Date Time` line in the format of real files (`"10:46 Dec 12 2016"`),
/// when the start and end of the test are known.
pub(super) fn capture_times(metadata: &Metadata) -> Option<String> {
    let start = metadata.date.as_ref()?.parsed?;
    let end = metadata.end_date.as_ref()?.parsed?;
    let format = |at: chrono::NaiveDateTime| at.format("%H:%M %b %d %Y").to_string();
    Some(format!(
        "Date Time  : \"{}\" \"{}\"",
        format(start),
        format(end)
    ))
}
