//! `axcomp synth`: measurement files from a known truth.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use axcomp::measurement::{AxisKind, Measurement};
use axcomp::model::{Axis, OpticsBody};
use axcomp::output::{create_folder, write_all_new};
use axcomp::read::{csv, rtl};
use axcomp::synth::geometry::{self, GeometryPlan};
use axcomp::synth::{self, RotaryTruth, Truth};
use axcomp::units::{LengthUnit, mm_to_um, rad_to_um_per_m};

use super::common::{
    LinuxCncType, MachineFile, Overwrite, Verbosity, load, load_machine, print_text, read_table,
};

/// Flags of `axcomp synth`.
#[derive(Debug, clap::Args)]
pub struct SynthArgs {
    /// The ground truth (TOML): axis error, effects, noise, test cycle, conditions.
    #[arg(long, value_name = "T.toml", required_unless_present_any = ["geometry", "thermal"])]
    pub truth: Option<PathBuf>,

    /// The first test: .rtl (Renishaw) or .csv (axcomp CSV), by extension.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "BEFORE",
        required_unless_present_any = ["geometry", "thermal"]
    )]
    pub output: Option<PathBuf>,

    /// Instead of a positioning test: the geometry tests of a synthetic
    /// machine with random 21 errors (`synth::geometry`: one 6-DOF CSV per axis on a line away from the
    /// reference, optics off the tool), X.csv, Y.csv, Z.csv, and the
    /// survey.toml naming them, written into the folder DIR.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["truth", "output", "table", "output2"])]
    pub geometry: Option<PathBuf>,

    /// With --geometry: the body that carries every test's moving optic,
    /// `tool` or `workpiece` (the laser on the other); default: the body
    /// each test's axis moves, from the machine's chain (survey.toml states
    /// the one taken).
    #[arg(long = "optics-on", value_name = "BODY", requires = "geometry", value_parser = parse_optics_body)]
    pub optics_on: Option<OpticsBody>,

    /// Instead of a positioning test: a thermal log (CSV) from the built-in
    /// thermal truth: five sensors (bearing, housing, coolant, base, air)
    /// driven by a spindle's and a coolant's duty cycles and the room's daily
    /// cycle; the drift 1.2 µm/K of the bearing lagged 40 min and −3 µm/K of
    /// the air lagged 320 min, noise 0.3 µm; three days, a row a minute.
    #[arg(long, value_name = "LOG.csv", conflicts_with_all = ["truth", "output", "table", "output2", "geometry"])]
    pub thermal: Option<PathBuf>,

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

impl SynthArgs {
    /// Every file the command reads: never an output (`output::write_new`).
    fn inputs(&self) -> Vec<&Path> {
        let named = [
            self.truth.as_deref(),
            self.table.as_deref(),
            self.machine_file.machine.as_deref(),
        ];
        named.into_iter().flatten().collect()
    }
}

/// Runs `axcomp synth`.
pub fn run(args: &SynthArgs) -> Result<()> {
    if let Some(path) = &args.thermal {
        let log = axcomp::synth::thermal::thermal_log(&Default::default(), args.seed);
        let text = axcomp::thermal::write_log(&log);
        axcomp::output::write_new(path, text.as_bytes(), &[], args.overwrite.force)?;
        return Ok(());
    }
    let (Some(truth_path), Some(output)) = (&args.truth, &args.output) else {
        return run_geometry(args);
    };
    if load(truth_path, |text| {
        Ok::<bool, axcomp::synth::SynthError>(RotaryTruth::is_rotary(text))
    })? {
        return run_rotary(args, truth_path, output);
    }
    let truth = load(truth_path, Truth::from_toml_str)?;
    // Render everything before writing anything, so a bad table leaves no half result.
    let first = synth::before(&truth, args.seed)?;
    let first_text = render(&first, output)?;
    let second = match (&args.table, &args.output2) {
        (Some(table_path), Some(output2)) => {
            let profile = args.machine_file.profile()?;
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
    let mut files = vec![(output.as_path(), first_text.as_bytes())];
    if let Some((path, text)) = &second {
        files.push((path.as_path(), text.as_bytes()));
    }
    write_all_new(&files, &args.inputs(), args.overwrite.force)?;
    let mut summary = format!(
        "Wrote {} ({} targets, {} runs)\n",
        output.display(),
        first.targets().len(),
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
fn run_rotary(args: &SynthArgs, truth_path: &Path, output: &Path) -> Result<()> {
    if args.table.is_some() {
        bail!(
            "{}: a rotary truth has no re-test with a table yet; leave out --table and --o2",
            truth_path.display()
        );
    }
    let truth = load(truth_path, RotaryTruth::from_toml_str)?;
    let test = synth::rotary_test(&truth, args.seed)?;
    let text = render(&test, output)?;
    write_all_new(
        &[(output, text.as_bytes())],
        &args.inputs(),
        args.overwrite.force,
    )?;
    print_text(&format!(
        "Wrote {} (rotary axis, {} targets, {} runs)\n",
        output.display(),
        test.targets().len(),
        test.runs().len()
    ))
}

/// `--geometry DIR`: a synthetic machine's geometry tests and their survey.
fn run_geometry(args: &SynthArgs) -> Result<()> {
    let Some(dir) = &args.geometry else {
        bail!("give --truth T.toml -o FILE, or --geometry DIR");
    };
    let machine = load_machine(args.machine_file.machine.as_deref())?;
    let plan = GeometryPlan {
        optics_on: [args.optics_on; 3],
        ..GeometryPlan::example()
    };
    let truth = geometry::random_truth(&machine, &plan, args.seed)?;
    let synthetic = geometry::measure(&machine, &truth, &plan, args.seed)?;
    create_folder(dir)?;
    let mut files: Vec<(PathBuf, &[u8])> = synthetic
        .tests
        .iter()
        .map(|(name, text)| (dir.join(name), text.as_bytes()))
        .collect();
    files.push((dir.join("survey.toml"), synthetic.survey.as_bytes()));
    write_all_new(&files, &args.inputs(), args.overwrite.force)?;
    let mut summary = String::new();
    for (path, _) in &files {
        summary.push_str(&format!("Wrote {}\n", path.display()));
    }
    let bodies: Vec<String> = Axis::ALL
        .iter()
        .map(|axis| {
            let on = args
                .optics_on
                .unwrap_or_else(|| machine.chain().body_moved_by(*axis));
            format!("{axis} on the {}", on.name())
        })
        .collect();
    summary.push_str(&format!(
        "  {} with 21 random errors (seed {}); one 6-DOF test per axis ({} mm targets, {} runs each way, noise {:.1} µm and {:.1} µrad a reading), on a line away from the reference with the moving optic off the tool tip ({}), as survey.toml states\n",
        machine.name(),
        args.seed,
        plan.step_mm,
        plan.runs,
        mm_to_um(plan.noise_mm),
        rad_to_um_per_m(plan.noise_rad),
        bodies.join(", "),
    ));
    print_text(&summary)
}

/// `--optics-on`'s value.
fn parse_optics_body(text: &str) -> Result<OpticsBody, String> {
    OpticsBody::from_name(text).ok_or_else(|| format!("expected tool or workpiece, found {text:?}"))
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
