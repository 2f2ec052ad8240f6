//! Flag parsers and printing helpers shared by several subcommands.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;

use axcomp::compensate::CompensationTable;
use axcomp::emit::{self, Controller, EmitOptions, MachineProfile};
use axcomp::error::Warning;
use axcomp::measurement::{Direction, RunSelector, SourceFormat};

/// `--format NAME`: one of the input formats.
pub fn parse_format(name: &str) -> Result<SourceFormat, String> {
    SourceFormat::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = SourceFormat::ALL.iter().map(|f| f.name()).collect();
        format!("unknown format {name:?}; supported: {}", names.join(", "))
    })
}

/// `3`, `3:up`, `3:down` (also `3up`, `3↑`, `3↓`).
pub fn parse_run_selector(text: &str) -> Result<RunSelector, String> {
    let text = text.trim();
    let digits_end = text
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(text.len());
    let (number, rest) = text.split_at(digits_end);
    let number: u32 =
        number.parse().ok().filter(|n| *n > 0).ok_or_else(|| {
            format!("expected a run number from 1, like 3 or 3:down, found {text:?}")
        })?;
    let direction = match rest.trim_start_matches(':').to_ascii_lowercase().as_str() {
        "" => None,
        "up" | "↑" => Some(Direction::Up),
        "down" | "↓" => Some(Direction::Down),
        other => {
            return Err(format!(
                "expected up or down after the run number, found {other:?}"
            ));
        }
    };
    Ok(RunSelector { number, direction })
}

/// Prints warnings to stderr unless `quiet`.
pub fn print_warnings(warnings: &[Warning], quiet: bool) {
    if quiet {
        return;
    }
    for warning in warnings {
        eprintln!("axcomp: warning: {warning}");
    }
}

/// Prints one JSON object, pretty, to stdout.
pub fn print_json(value: &impl Serialize) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    serde_json::to_writer_pretty(&mut stdout, value)?;
    writeln!(stdout)?;
    stdout.flush()?;
    Ok(())
}

/// Prints text to stdout.
pub fn print_text(text: &str) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    stdout.write_all(text.as_bytes())?;
    stdout.flush()?;
    Ok(())
}

/// The machine profile of `--machine`, or the defaults from the axis letters.
pub fn load_profile(path: Option<&Path>) -> Result<MachineProfile> {
    let Some(path) = path else {
        return Ok(MachineProfile::default());
    };
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    MachineProfile::from_toml_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Reads a compensation table of `axis` in any format `convert` writes; the
/// axis names come from the profile. `linuxcnc_type` decides a LinuxCNC
/// table whose numbers do not tell its type.
pub fn read_table(
    path: &Path,
    axis: &str,
    profile: &MachineProfile,
    linuxcnc_type: Option<u8>,
) -> Result<(Controller, CompensationTable)> {
    let options = EmitOptions {
        axes: vec![profile.axis(axis).map_err(anyhow::Error::msg)?],
        table_name: String::new(),
        machine_unit: profile.machine_unit(),
        linuxcnc_type: linuxcnc_type.unwrap_or(0),
        max_points: None,
        max_value_mm: None,
        cec_first_table: profile.controller.cec_first_table.unwrap_or(0),
        cec_values_are_corrections: profile.controller.cec_values.as_deref() != Some("error"),
        tnc640_columns: Vec::new(),
    };
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    emit::read_any(&text, &options, linuxcnc_type)
        .map_err(|e| anyhow::anyhow!("{}:{e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_selectors() {
        let both = parse_run_selector("3").unwrap();
        assert_eq!((both.number, both.direction), (3, None));
        assert_eq!(
            parse_run_selector("2:down").unwrap().direction,
            Some(Direction::Down)
        );
        assert_eq!(
            parse_run_selector("2up").unwrap().direction,
            Some(Direction::Up)
        );
        assert_eq!(
            parse_run_selector("1↓").unwrap().direction,
            Some(Direction::Down)
        );
        assert!(parse_run_selector("0").is_err());
        assert!(parse_run_selector("x").is_err());
        assert!(parse_run_selector("2:sideways").is_err());
    }

    #[test]
    fn format_names() {
        assert_eq!(parse_format("API-POS").unwrap(), SourceFormat::ApiPos);
        assert!(
            parse_format("xls")
                .unwrap_err()
                .contains("rtl, ecmc, api-pos, csv")
        );
    }
}
