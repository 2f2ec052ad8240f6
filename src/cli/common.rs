//! Flag parsers and printing helpers shared by several subcommands.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;

use axcomp::compensate::CompensationTable;
use axcomp::effects::{Effect, read_effects};
use axcomp::emit::{Controller, EmitError, MachineProfile};
use axcomp::error::{ParseError, Warning};
use axcomp::evaluate::Standard;
use axcomp::evaluate::uncertainty::Equipment;
use axcomp::evaluate::verdict::{AcceptanceProfile, Decision};
use axcomp::measurement::{AxisKind, Direction, Measurement, RunSelector, SourceFormat};
use axcomp::model::{Machine, ModelError};
use axcomp::servo::ServoError;
use axcomp::synth::SynthError;
use axcomp::units::{AngleUnit, LengthUnit};
use axcomp::workflow;
use axcomp::workflow::table::{ActiveTable, ActiveTableFile, active_table, read_options};

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

/// `x=0,y=250,z=-275` (any of the three, any order): a machine position, mm.
pub fn parse_position(text: &str) -> Result<[Option<f64>; 3], String> {
    let mut position = [None; 3];
    for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (name, value) = part
            .split_once('=')
            .ok_or_else(|| format!("expected axis=value like y=250, found {part:?}"))?;
        let index = match name.trim().to_ascii_lowercase().as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            other => return Err(format!("expected the axis x, y or z, found {other:?}")),
        };
        let value: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| format!("expected a number of mm after {name}=, found {value:?}"))?;
        if position[index].replace(value).is_some() {
            return Err(format!("{name} is given twice in {text:?}"));
        }
    }
    Ok(position)
}

/// What went wrong in a file the user named: at a position, or in the file
/// as a whole.
pub enum FileError {
    /// At a line and column.
    At(ParseError),
    /// In the file as a whole.
    Whole(String),
}

impl From<ParseError> for FileError {
    fn from(error: ParseError) -> FileError {
        FileError::At(error)
    }
}

/// A stage's error whose one variant carries a position (`ParseError`).
macro_rules! positioned {
    ($($error:ident::$variant:ident),*) => {$(
        impl From<$error> for FileError {
            fn from(error: $error) -> FileError {
                match error {
                    $error::$variant(parse) => FileError::At(parse),
                    other => FileError::Whole(other.to_string()),
                }
            }
        }
    )*};
}

positioned!(ModelError::Toml, ServoError::Parse, SynthError::Toml);

impl From<EmitError> for FileError {
    fn from(error: EmitError) -> FileError {
        FileError::Whole(error.to_string())
    }
}

/// An error in a file the user named, said the same way by every command:
/// `PATH:LINE:COL: message` at a position, `PATH: message` otherwise.
pub fn in_file(path: &Path, error: impl Into<FileError>) -> anyhow::Error {
    match error.into() {
        FileError::At(parse) => anyhow::anyhow!("{}:{parse}", path.display()),
        FileError::Whole(message) => anyhow::anyhow!("{}: {message}", path.display()),
    }
}

/// Reads the text file `path` and parses it with `parse`; an error names the file ([`in_file`]).
pub fn load<T, E: Into<FileError>>(
    path: &Path,
    parse: impl FnOnce(&str) -> Result<T, E>,
) -> Result<T> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    parse(&text).map_err(|error| in_file(path, error))
}

/// The machine's kinematics from `path`, or the bundled MCV 754 Quick. The
/// path goes in front of the error, with the line and column for TOML errors.
pub fn load_machine(path: Option<&Path>) -> Result<Machine> {
    let Some(path) = path else {
        return Ok(Machine::bundled());
    };
    load_part(path, Machine::from_toml_str)
}

/// The machine profile's `[controller]` part from `path`, or the defaults.
pub fn load_profile(path: Option<&Path>) -> Result<MachineProfile> {
    let Some(path) = path else {
        return Ok(MachineProfile::default());
    };
    let mut profile = load_part(path, MachineProfile::from_toml_str)?;
    // A Fanuc control: its parameter backup, named relative to the profile.
    if let Some(name) = &profile.controller.fanuc_parameters {
        let backup = path.parent().unwrap_or(Path::new(".")).join(name);
        profile.fanuc = Some(load_fanuc_parameters(&backup)?);
    }
    Ok(profile)
}

/// One part of the machine profile `path`, read by `part`, after the whole
/// profile is checked: whichever part a command uses, an error in another
/// (`units = "furlong"` under `evaluate`, which reads `[acceptance]`) is
/// refused, not passed over as someone else's.
pub fn load_part<T, E: Into<FileError>>(
    path: &Path,
    part: impl FnOnce(&str) -> Result<T, E>,
) -> Result<T> {
    load(path, |text| {
        check_machine_profile(text)?;
        part(text).map_err(Into::into)
    })
}

/// Every part of a machine profile's text, each by its reader.
fn check_machine_profile(text: &str) -> Result<(), FileError> {
    MachineProfile::from_toml_str(text)?;
    AcceptanceProfile::from_toml_str(text)?;
    let has_kinematics =
        toml::from_str::<toml::Table>(text).is_ok_and(|table| table.contains_key("kinematics"));
    if has_kinematics {
        Machine::from_toml_str(text)?;
    }
    Ok(())
}

/// The effects a diagnosis wrote (`diagnose --write-effects`), for
/// `convert --effects` and `predict --effects`.
pub fn load_effects(path: &Path) -> Result<Vec<Effect>> {
    load(path, read_effects)
}

/// A compensation table for `axis` in any format `convert` writes; the
/// machine profile names the axis's columns. A LinuxCNC table's type is told
/// from its numbers; `linuxcnc_type` decides when they do not.
///
/// The file may be UTF-8, Latin-1 or UTF-16 with a byte-order mark (a Fagor
/// 8065 `.mp`). A Fagor 8055 table is read in the profile's unit, else in
/// `test_unit`, the unit of the test it belongs to
/// (`MachineProfile::table_unit`).
pub fn read_table(
    path: &Path,
    axis: &str,
    profile: &MachineProfile,
    linuxcnc_type: Option<u8>,
    test_unit: LengthUnit,
) -> Result<(Controller, CompensationTable)> {
    read_table_of(
        path,
        axis,
        profile,
        linuxcnc_type,
        test_unit,
        AxisKind::Linear,
    )
}

/// [`read_table`] for an axis of `kind`: a rotary axis' table is in degrees,
/// whatever the machine's length unit.
pub fn read_table_of(
    path: &Path,
    axis: &str,
    profile: &MachineProfile,
    linuxcnc_type: Option<u8>,
    test_unit: LengthUnit,
    kind: AxisKind,
) -> Result<(Controller, CompensationTable)> {
    let options = read_options(profile, axis, kind, linuxcnc_type)?;
    let bytes = std::fs::read(path).with_context(|| path.display().to_string())?;
    workflow::read_table(&bytes, options, profile, test_unit, linuxcnc_type)
        .map_err(|error| in_file(path, error))
}

/// The table that was active during `test` (named `test_label` in messages),
/// read for the test's axis, and the doubts about the two together: refused
/// when the test records no axis, or when the table cannot belong to it
/// (`workflow::table::active_table`).
pub fn read_active_table(
    path: &Path,
    test: &Measurement,
    test_label: &str,
    profile: &MachineProfile,
    linuxcnc_type: Option<u8>,
) -> Result<ActiveTable> {
    let bytes = std::fs::read(path).with_context(|| path.display().to_string())?;
    Ok(active_table(
        ActiveTableFile {
            bytes: &bytes,
            file: &path.display().to_string(),
            test_label,
            how_to_name_the_axis: "give --axis NAME (e.g. --axis X)",
            linuxcnc_type,
        },
        test,
        profile,
    )?)
}

/// Names the measured axis with `--axis`, when given (its source is then "given").
pub fn name_axis(measurement: &mut Measurement, axis: Option<&String>) {
    if let Some(axis) = axis {
        measurement.set_axis(axis.clone());
    }
}

/// The measured axis, to write or read a table for: refused when the file
/// does not record it and `--axis` did not name it (a table for the wrong
/// axis compensates one axis with another's error).
pub fn recorded_axis<'a>(measurement: &'a Measurement, purpose: &str) -> Result<&'a str> {
    if measurement.axis_recorded() {
        return Ok(measurement.axis());
    }
    let file = measurement.metadata.source_file.as_ref().map_or_else(
        || "the measurement".to_string(),
        |p| p.display().to_string(),
    );
    anyhow::bail!(
        "{file}: the file does not record which axis was measured; give --axis NAME (e.g. --axis X) {purpose}"
    )
}

/// `-q/--quiet`, one meaning in every command: stderr carries no warnings
/// and no progress bars. Results are never silenced: what goes to stdout
/// (the report, the JSON) and the files written are the same with or
/// without it, and errors are still printed.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct Verbosity {
    /// No warnings and no progress bars on stderr (results and errors are unchanged).
    #[arg(long, short = 'q', help_heading = "Output")]
    pub quiet: bool,
}

/// `--json`, the same in every command that has it.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct JsonOutput {
    /// Print one JSON object (units in the keys) instead of the report.
    #[arg(long, help_heading = "Output")]
    pub json: bool,
}

/// `--standard`, the same in every command that evaluates a test to one.
#[derive(Clone, Copy, clap::Args)]
pub struct StandardArg {
    /// The standard the figures follow (default iso230-2:2014).
    ///
    /// iso230-2:2014, iso230-2:2006, iso230-2:1997 (the same figures; the
    /// edition is named), gb/t17421.2 (an identical adoption of the 1997
    /// edition), iso230-2:1988 and jis-b6192 (±3s in A and R), vdi3441 (P,
    /// Pa, Ps, U). Definitions the project reconstructs from public sources
    /// (1988, JIS, VDI) are said to be so. A standard whose definitions are
    /// not established (ASME B5.54, NMTBA) is refused.
    #[arg(
        long,
        value_name = "NAME",
        default_value = "iso230-2:2014",
        value_parser = parse_standard,
        help_heading = "Evaluation"
    )]
    pub standard: &'static dyn Standard,
}

impl std::fmt::Debug for StandardArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.standard.key())
    }
}

fn parse_standard(name: &str) -> Result<&'static dyn Standard, String> {
    axcomp::evaluate::by_name(name).map_err(|error| error.to_string())
}

/// `--angle-unit`, the same in every command that reports a rotary axis'
/// deviations (`evaluate`, `report`, `diagnose`).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct AngleUnitArg {
    /// A rotary axis' deviations in arcsec (″, the default) or urad (µrad).
    ///
    /// Every deviation figure of a rotary axis (per target, the axis
    /// figures, outliers, the plots, a diagnosis) is printed in this unit,
    /// and its JSON keys end in `_arcsec` or `_urad` (never both).
    /// 1″ = π/648000 rad ≈ 4.848 µrad. Refused on a linear axis, whose
    /// deviations are µm.
    #[arg(long = "angle-unit", value_name = "UNIT", value_parser = parse_angle_unit, help_heading = "Output")]
    pub angle_unit: Option<AngleUnit>,
}

impl AngleUnitArg {
    /// The unit for `measurement`'s deviations: refused when it is given
    /// for a linear axis (it cannot apply to µm), the default ″ otherwise.
    pub fn for_axis(&self, measurement: &Measurement) -> Result<AngleUnit> {
        let Some(unit) = self.angle_unit else {
            return Ok(AngleUnit::default());
        };
        if measurement.kind() == AxisKind::Linear {
            anyhow::bail!(
                "--angle-unit {}: axis {} is a linear axis, whose deviations are µm; \
                 the flag is for rotary axes only",
                unit.name(),
                measurement.axis()
            );
        }
        Ok(unit)
    }
}

/// `arcsec` or `urad`.
fn parse_angle_unit(name: &str) -> Result<AngleUnit, String> {
    AngleUnit::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = AngleUnit::ALL.map(AngleUnit::name).to_vec();
        format!("expected one of {}, found {name:?}", names.join(", "))
    })
}

/// `--force`, the same in every command that writes files.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct Overwrite {
    /// Replace existing output files (without it an existing file is refused).
    #[arg(long, help_heading = "Output")]
    pub force: bool,
}

/// `--format`, the same in every command that reads measurements.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct InputFormat {
    /// Input format, instead of detecting it: rtl, ecmc, api-pos, csv.
    #[arg(long, value_name = "FORMAT", value_parser = parse_format, help_heading = "Input")]
    pub format: Option<SourceFormat>,
}

/// `--machine`: one machine profile, of which each command reads its part.
#[derive(Debug, Clone, clap::Args)]
pub struct MachineFile {
    /// Machine profile (TOML): [controller] the tables' axis names and units,
    /// [kinematics] the model (default: the bundled MCV 754 Quick),
    /// [acceptance] the permissible values (docs/src/evaluate.md).
    #[arg(long, value_name = "M.toml", help_heading = "Machine")]
    pub machine: Option<PathBuf>,

    /// Fanuc parameter backup (CNC-PARA.TXT): the axes' pitch error
    /// compensation parameters (3620–3624) and detection unit (1013, 1820),
    /// which a Fanuc PITCH.TXT is read and updated with (default: the
    /// profile's controller.fanuc_parameters).
    #[arg(
        long = "fanuc-parameters",
        value_name = "CNC-PARA.TXT",
        help_heading = "Machine"
    )]
    pub fanuc_parameters: Option<PathBuf>,
}

impl MachineFile {
    /// The profile's `[controller]` part ([`load_profile`]) with the Fanuc
    /// parameter backup of `--fanuc-parameters`, when given.
    pub fn profile(&self) -> Result<MachineProfile> {
        let mut profile = load_profile(self.machine.as_deref())?;
        if let Some(path) = &self.fanuc_parameters {
            profile.fanuc = Some(load_fanuc_parameters(path)?);
        }
        Ok(profile)
    }
}

/// A Fanuc parameter backup; errors name the file, line and column.
pub fn load_fanuc_parameters(path: &Path) -> Result<axcomp::emit::fanuc::ParameterBackup> {
    let bytes = std::fs::read(path).with_context(|| path.display().to_string())?;
    let text = axcomp::read::decode(&bytes).map_err(|e| in_file(path, e))?;
    let name = path.display().to_string();
    axcomp::emit::fanuc::ParameterBackup::parse(&text, &name).map_err(|e| in_file(path, e))
}

/// `--equipment` and `--decision`: the measurement uncertainty and the rule
/// that decides the verdict with it, the same in `evaluate` and `report`.
#[derive(Debug, Clone, clap::Args)]
pub struct UncertaintyArgs {
    /// Equipment profile (TOML) for the measurement uncertainty.
    ///
    /// Without it the uncertainty is evaluated only for a file that records a
    /// laser interferometer (.rtl, an API laser's .pos), with a typical HeNe
    /// laser; for any other (an ecmc test's sensor or encoder, a CSV) it is
    /// "not evaluated: instrument unknown".
    ///
    /// The laser's expanded uncertainty and k, whether it includes the air
    /// compensation, the air and material sensors' standard uncertainties,
    /// the expansion coefficient's ± limit, the misalignment (mrad) and the
    /// environmental variation E_VE (eve_um, or drift_test = "FILE", a
    /// measurement file relative to the profile; E_VE is its range). The
    /// bundled default is fixtures/equipment/hene-default.toml (docs/src/evaluate.md).
    #[arg(long, value_name = "E.toml", help_heading = "Uncertainty")]
    pub equipment: Option<PathBuf>,

    /// Decision rule of the verdict: simple or iso14253-1.
    ///
    /// simple: a figure passes when value ≤ limit (the uncertainty is not
    /// considered). iso14253-1: conformance is proven when value + U ≤ limit,
    /// non-conformance when value − U > limit, and otherwise the check is
    /// "not proven"; figures without an evaluated U (R, B, ↑, ↓) are compared
    /// by their value.
    #[arg(long, value_name = "RULE", default_value = "simple", value_parser = parse_decision, help_heading = "Acceptance")]
    pub decision: Decision,
}

/// `simple` or `iso14253-1`.
pub fn parse_decision(name: &str) -> Result<Decision, String> {
    Decision::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = Decision::ALL.map(Decision::name).to_vec();
        format!("expected one of {}, found {name:?}", names.join(", "))
    })
}

/// The equipment of `--equipment`, with its drift test read (relative to
/// the profile) when it names one; `None` without the flag (the workflow
/// then takes the bundled laser only for a file that records a laser).
pub fn load_equipment(args: &UncertaintyArgs) -> Result<Option<Equipment>> {
    let Some(path) = &args.equipment else {
        return Ok(None);
    };
    let name = path.display().to_string();
    let equipment = load(path, |text| Equipment::from_toml_str(text, &name))?;
    let Some(drift) = equipment.drift_test_path() else {
        return Ok(Some(equipment));
    };
    let drift_path = path.parent().unwrap_or(Path::new("")).join(drift);
    let read = axcomp::read::read_paths(std::slice::from_ref(&drift_path), None)
        .with_context(|| format!("{name}: the drift test"))?;
    Ok(Some(equipment.with_drift_test(
        &read.measurement,
        &drift_path.display().to_string(),
    )))
}

/// `--linuxcnc-type` for reading a LinuxCNC table (`convert` has its own: the
/// type it writes).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct LinuxCncType {
    /// LinuxCNC table type (COMP_FILE_TYPE 0 or 1), when a table's numbers do not tell it.
    #[arg(long = "linuxcnc-type", value_name = "0|1", value_parser = clap::value_parser!(u8).range(0..=1), help_heading = "Machine")]
    pub linuxcnc_type: Option<u8>,
}

/// Prints the warnings `evaluate` gives a test (conformance, spacing,
/// outliers…) that another command reads, each naming the file, unless
/// `quiet`: a test diagnosed or predicted from says what evaluating it says.
pub fn print_test_warnings(path: &Path, measurement: &Measurement, quiet: bool, angle: AngleUnit) {
    if quiet {
        return;
    }
    let warnings = axcomp::evaluate::evaluate(measurement).warnings;
    print_file_warnings(path, &warnings, quiet, angle);
}

/// Prints a file's warnings to stderr, each naming the file, unless `quiet`.
pub fn print_file_warnings(path: &Path, warnings: &[Warning], quiet: bool, angle: AngleUnit) {
    if quiet {
        return;
    }
    for warning in warnings {
        eprintln!(
            "axcomp: warning: {}: {}",
            path.display(),
            warning.text_in(angle)
        );
    }
}

/// Prints warnings to stderr unless `quiet`.
pub fn print_warnings(warnings: &[Warning], quiet: bool) {
    print_warnings_in(warnings, quiet, AngleUnit::default());
}

/// [`print_warnings`], a rotary axis' deviations in `angle` (`--angle-unit`).
pub fn print_warnings_in(warnings: &[Warning], quiet: bool, angle: AngleUnit) {
    if quiet {
        return;
    }
    for warning in warnings {
        eprintln!("axcomp: warning: {}", warning.text_in(angle));
    }
}

/// Prints one JSON object, pretty, to stdout.
pub fn print_json(value: &impl Serialize) -> Result<()> {
    // Buffered: stdout flushes at every line end, and pretty JSON is a line
    // per value (a 10 000-target test's object took 150 000 writes, 70 ms).
    let mut stdout = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions() {
        assert_eq!(
            parse_position("y=250, Z=-275").unwrap(),
            [None, Some(250.0), Some(-275.0)]
        );
        assert!(parse_position("y=250,y=3").unwrap_err().contains("twice"));
        assert!(parse_position("w=1").unwrap_err().contains("x, y or z"));
        assert!(parse_position("y=abc").unwrap_err().contains("number"));
        assert!(parse_position("y250").unwrap_err().contains("axis=value"));
    }

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
