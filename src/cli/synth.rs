//! `axcomp synth`: measurement files from a known truth.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use axcomp::measurement::{AxisKind, Measurement};
use axcomp::output::write_all_new;
use axcomp::read::{csv, rtl};
use axcomp::synth::{self, RotaryTruth, Truth};
use axcomp::units::LengthUnit;

use super::common::{
    LinuxCncType, MachineFile, Overwrite, Verbosity, load, load_profile, print_text, read_table,
};

/// Flags of `axcomp synth`.
#[derive(Debug, clap::Args)]
pub struct SynthArgs {
    /// The ground truth (TOML): axis error, effects, noise, test cycle, conditions.
    #[arg(long, value_name = "T.toml")]
    pub truth: PathBuf,

    /// The first test: .rtl (Renishaw) or .csv (axcomp CSV), by extension.
    #[arg(short = 'o', long = "output", value_name = "BEFORE")]
    pub output: PathBuf,

    /// The compensation table the controller applies in the re-test (any format convert writes).
    #[arg(long, value_name = "TABLE", requires = "output2")]
    pub table: Option<PathBuf>,

    /// The re-test of the compensated axis (.rtl or .csv).
    #[arg(long = "o2", value_name = "AFTER", requires = "table")]
    pub output2: Option<PathBuf>,

    /// Seed of the random numbers (targets, noise); the same seed gives the same files.
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,

    /// `--machine` (one profile; each command reads its part).
    #[command(flatten)]
    pub machine_file: MachineFile,

    /// `--linuxcnc-type` for reading a table (the same in every command).
    #[command(flatten)]
    pub table_type: LinuxCncType,

    /// `--force` (the same in every command).
    #[command(flatten)]
    pub overwrite: Overwrite,

    /// -q/--quiet (the same in every command; synth prints no warnings yet).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Runs `axcomp synth`.
pub fn run(args: &SynthArgs) -> Result<()> {
    if load(&args.truth, |text| {
        Ok::<bool, axcomp::synth::SynthError>(RotaryTruth::is_rotary(text))
    })? {
        return run_rotary(args);
    }
    let truth = load(&args.truth, Truth::from_toml_str)?;
    // Render everything before writing anything, so a bad table leaves no half result.
    let first = synth::before(&truth, args.seed)?;
    let first_text = render(&first, &args.output)?;
    let second = match (&args.table, &args.output2) {
        (Some(table_path), Some(output2)) => {
            let profile = load_profile(args.machine_file.machine.as_deref())?;
            let (_, table) = read_table(
                table_path,
                &truth.axis.name,
                &profile,
                args.table_type.linuxcnc_type,
                // The truth file is in mm.
                LengthUnit::Millimetre,
            )?;
            let retest = synth::after(&truth, &table, args.seed)?;
            let text = render(&retest, output2)?;
            Some((output2, text))
        }
        _ => None,
    };
    // Both files or neither: an existing --o2 must not leave a new first file.
    let mut files = vec![(args.output.as_path(), first_text.as_bytes())];
    if let Some((path, text)) = &second {
        files.push((path.as_path(), text.as_bytes()));
    }
    write_all_new(&files, args.overwrite.force)?;
    let mut summary = format!(
        "Wrote {} ({} targets, {} runs)\n",
        args.output.display(),
        first.targets_mm().len(),
        first.runs().len()
    );
    if let Some((path, _)) = &second {
        summary.push_str(&format!(
            "Wrote {} (re-test with the table applied)\n",
            path.display()
        ));
    }
    print_text(&summary)
}

/// A rotary truth's test (`synth::rotary`): one file, no re-test yet.
fn run_rotary(args: &SynthArgs) -> Result<()> {
    if args.table.is_some() {
        bail!(
            "{}: a rotary truth has no re-test with a table yet (issue 14); leave out --table and --o2",
            args.truth.display()
        );
    }
    let truth = load(&args.truth, RotaryTruth::from_toml_str)?;
    let test = synth::rotary_test(&truth, args.seed)?;
    let text = render(&test, &args.output)?;
    write_all_new(
        &[(args.output.as_path(), text.as_bytes())],
        args.overwrite.force,
    )?;
    print_text(&format!(
        "Wrote {} (rotary axis, {} targets, {} runs)\n",
        args.output.display(),
        test.targets_mm().len(),
        test.runs().len()
    ))
}

/// The file text for an output path, by its extension.
fn render(measurement: &Measurement, path: &Path) -> Result<String> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match extension.as_str() {
        "rtl" if measurement.kind() == AxisKind::Rotary => bail!(
            "{}: Renishaw's rotary .rtl layout is not public; write a rotary test as .csv",
            path.display()
        ),
        "rtl" => Ok(rtl::write(measurement)),
        "csv" => Ok(csv::write(measurement)),
        _ => bail!(
            "{}: write .rtl or .csv (the extension chooses the format)",
            path.display()
        ),
    }
}
