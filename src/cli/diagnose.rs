//! `axcomp diagnose`: the residual of a re-test against the prediction,
//! traced to the physical effects the model lacks.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use axcomp::diagnose::AngularProfile;
use axcomp::diagnose::friction::friction_behind_reversal;
use axcomp::output::write_new;
use axcomp::read;
use axcomp::report::diagnose::{DiagnoseJson, FrictionJson, render};
use axcomp::together::{Input, Pairing, check_together};
use axcomp::workflow::retest::{DiagnoseSettings, diagnosis};
use axcomp::workflow::rotary::{self, Use};

use super::common::{
    AngleUnitArg, JsonOutput, LinuxCncType, MachineFile, Overwrite, StandardArg, Verbosity, load,
    name_axis, print_test_warnings, print_warnings, read_active_table,
};
use super::servo_sim::load_axis;

/// Flags of `axcomp diagnose`.
#[derive(Debug, clap::Args)]
pub struct DiagnoseArgs {
    /// The re-test (any format evaluate reads).
    #[arg(long, value_name = "FILE")]
    pub after: PathBuf,

    /// The first test, from which the model predicts the re-test on the same
    /// line; without it, only structure between runs is looked for (drift,
    /// outlier runs, reversal) and periodic errors in the re-test's own curve.
    #[arg(long, value_name = "FILE")]
    pub before: Option<PathBuf>,

    /// The compensation table active during the re-test (any format convert writes).
    #[arg(long, value_name = "TABLE", requires = "before")]
    pub table: Option<PathBuf>,

    /// The controller's backlash parameter was set during the re-test as
    /// convert suggests (−B̄ of the first test). Not with a bidirectional table.
    #[arg(long = "backlash-set", requires = "before")]
    pub backlash_set: bool,

    /// Name of the axis of both tests, instead of the one in the files
    /// (needed with --table when the re-test does not record its axis).
    #[arg(long, value_name = "NAME")]
    pub axis: Option<String>,

    /// `--machine` (one profile; each command reads its part).
    #[command(flatten)]
    pub machine_file: MachineFile,

    /// The axis's pitch or yaw along the stroke (CSV: position_mm,angle_urad),
    /// to tell an Abbe error.
    #[arg(long, value_name = "FILE")]
    pub angular: Option<PathBuf>,

    /// The axis's servo description, to read a reversal found as friction.
    ///
    /// A bundled axis (mcfv5050-x, mcfv5050-y) or an axis TOML file as
    /// servo-sim takes it; with --stiffness-n-per-um the reversal B found is
    /// reported as the force F_res = −B·k_c/2 held against friction
    /// (B̄ = B̄_scale − 2·F_res/k_c), in the terminal and as "friction" in JSON.
    #[arg(
        long = "servo-axis",
        value_name = "AXIS",
        requires = "stiffness_n_per_um"
    )]
    pub servo_axis: Option<String>,

    /// Structural stiffness k_c between the drive's force line and the laser, N/µm.
    #[arg(
        long = "stiffness-n-per-um",
        // The name it had before 0.2 (CHANGELOG.md).
        alias = "compliance-n-um",
        value_name = "N_PER_UM",
        requires = "servo_axis"
    )]
    pub stiffness_n_per_um: Option<f64>,

    /// `--thermal`, `--thermal-model`: the temperatures logged during the re-test.
    #[command(flatten)]
    pub thermal: super::thermal::ThermalInputArgs,

    /// Save the accepted effects (TOML) for predict --effects and convert --effects.
    #[arg(long = "write-effects", value_name = "E.toml")]
    pub write_effects: Option<PathBuf>,

    /// `--force` (the same in every command).
    #[command(flatten)]
    pub overwrite: Overwrite,

    /// `--linuxcnc-type` for reading a table (the same in every command).
    #[command(flatten)]
    pub table_type: LinuxCncType,

    /// `--standard` (the same in every command).
    #[command(flatten)]
    pub standard: StandardArg,

    /// `--json` (the same in every command).
    #[command(flatten)]
    pub json_output: JsonOutput,

    /// `--angle-unit` (the same in `evaluate` and `report`).
    #[command(flatten)]
    pub angle_unit: AngleUnitArg,

    /// -q/--quiet (the same in every command).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Runs `axcomp diagnose`.
pub fn run(args: &DiagnoseArgs) -> Result<()> {
    let mut after = read::read_path(&args.after, None)?;
    print_warnings(&after.warnings, args.verbosity.quiet);
    name_axis(&mut after.measurement, args.axis.as_ref());
    let angle = args.angle_unit.for_axis(&after.measurement)?;
    print_test_warnings(&args.after, &after.measurement, args.verbosity.quiet, angle);
    // A rotary re-test is diagnosed in ″ (per-revolution harmonics,
    // reversal, outlier runs); what is lengths is refused (`rotary`).
    rotary::check(
        &after.measurement,
        &[
            (Use::EffectsFile, args.write_effects.is_some()),
            (Use::AngularProfile, args.angular.is_some()),
            (Use::ServoAxis, args.servo_axis.is_some()),
        ],
    )?;
    let before = match &args.before {
        Some(path) => {
            let mut result = read::read_path(path, None)?;
            print_warnings(&result.warnings, args.verbosity.quiet);
            name_axis(&mut result.measurement, args.axis.as_ref());
            let doubts = check_together(
                Pairing::BeforeAfter,
                &Input::measurement(&result.measurement, path.display().to_string()),
                &Input::measurement(&after.measurement, args.after.display().to_string()),
            )?;
            print_warnings(&doubts, args.verbosity.quiet);
            print_test_warnings(path, &result.measurement, args.verbosity.quiet, angle);
            Some(result.measurement)
        }
        None => None,
    };
    let profile = args.machine_file.profile()?;
    let table = match &args.table {
        Some(path) => {
            // The table was active during the re-test.
            let active = read_active_table(
                path,
                &after.measurement,
                &args.after.display().to_string(),
                &profile,
                args.table_type.linuxcnc_type,
            )?;
            print_warnings(&active.doubts, args.verbosity.quiet);
            Some(active.table)
        }
        None => None,
    };
    let angular = args.angular.as_deref().map(load_angular).transpose()?;
    let diagnosis = diagnosis(
        &after.measurement,
        before.as_ref(),
        table.as_ref(),
        &profile,
        DiagnoseSettings {
            angle,
            backlash_set: args.backlash_set,
            angular: angular.as_ref(),
            standard: args.standard.standard,
        },
    )?;
    let name = |p: &Path| p.display().to_string();
    if let Some(path) = &args.write_effects {
        let text = diagnosis.effects_file(&name(&args.after));
        let inputs = [
            Some(args.after.as_path()),
            args.before.as_deref(),
            args.table.as_deref(),
            args.angular.as_deref(),
            args.machine_file.machine.as_deref(),
        ];
        let inputs: Vec<&Path> = inputs.into_iter().flatten().collect();
        write_new(path, text.as_bytes(), &inputs, args.overwrite.force)?;
    }
    let mut report = DiagnoseJson::new(
        &diagnosis,
        name(&args.after),
        args.before.as_deref().map(name),
        args.table.as_deref().map(name),
        angle,
    );
    if let (Some(servo_axis), Some(compliance)) = (&args.servo_axis, args.stiffness_n_per_um) {
        if !(compliance.is_finite() && compliance > 0.0) {
            bail!("--stiffness-n-per-um: expected a number > 0, found {compliance}");
        }
        let axis = load_axis(servo_axis)?;
        report.set_friction(
            friction_behind_reversal(&diagnosis, &axis, compliance)
                .map(|f| FrictionJson::new(servo_axis, &f)),
        );
    }
    let study = args.thermal.study()?;
    let share = study.as_ref().and_then(|s| {
        super::thermal::drift_share(&diagnosis, &after.measurement.environment, Some(s))
    });
    super::thermal::print_with_share(&report, render, share, args.json_output.json)
}

fn load_angular(path: &Path) -> Result<AngularProfile> {
    load(path, AngularProfile::from_csv_str)
}
