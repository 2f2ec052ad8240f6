//! `axcomp servo-sim`: simulate a feed axis with a friction model (Mendřický (2006))
//! in the circle test, a force step, a constant-velocity run or an ISO 230-2
//! cycle, and print what Mendřický (2006) reports (or the ISO figures).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use axcomp::output::write_new;
use axcomp::report::servo::{
    CircleJson, ConstantVelocityJson, ForceStepJson, IdentifyJson, IsoJson, MacroStepsJson,
    ServoSimJson, identify_text, iso_csv, text, trace_csv,
};
use axcomp::servo::axis::Axis;
use axcomp::servo::circle::run_circle;
use axcomp::servo::force_step::{run_constant_velocity, run_force_step};
use axcomp::servo::friction::FrictionKind;
use axcomp::servo::friction_fit::{
    axis_with_friction, identify, parse_constant_velocity, parse_following_error,
};
use axcomp::servo::iso_cycle::{DEFAULT_STIFFNESS_N_PER_UM, IsoCycle, IsoOptions, run_iso_cycle};
use axcomp::servo::simulate::{ForceStep, Stepping};
use axcomp::servo::trajectory::{Circle, CircleAxis, MoveLimits};
use axcomp::units::{mm_to_m, um_to_mm};

use super::common::{JsonOutput, Overwrite, Verbosity, in_file, load, print_json, print_text};
use super::progress;

/// Which test to simulate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TestKind {
    /// Circular test (Mendřický 2006, §6.3, Tab. 6.4).
    Circle,
    /// External force step at standstill (Mendřický 2006, §6.2).
    Step,
    /// One long move at constant feed (Mendřický 2006, §6.1).
    ConstantVelocity,
    /// ISO 230-2 bidirectional linear positioning cycle.
    #[value(name = "iso230-2")]
    Iso230_2,
}

impl TestKind {
    fn name(self) -> &'static str {
        match self {
            TestKind::Circle => "circle",
            TestKind::Step => "step",
            TestKind::ConstantVelocity => "constant-velocity",
            TestKind::Iso230_2 => "iso230-2",
        }
    }
}

/// Flags of `axcomp servo-sim`.
#[derive(Debug, clap::Args)]
pub struct ServoSimArgs {
    /// Axis: mcfv5050-x, mcfv5050-y (bundled) or a .toml axis file.
    ///
    /// The bundled axes are the MCFV 5050 LN cross table of Mendřický (2006)
    /// (fixtures/axes/*.toml, each value commented with its source).
    #[arg(long, value_name = "AXIS", help_heading = "Model")]
    pub axis: String,

    /// Friction model: classic (A), ramp (B1), power (B2) or lugre (C).
    #[arg(long, value_name = "MODEL", value_parser = parse_friction, help_heading = "Model",
          required_unless_present = "identify")]
    pub friction: Option<FrictionKind>,

    /// Test: circle, step, constant-velocity or iso230-2.
    #[arg(
        long,
        value_enum,
        value_name = "TEST",
        help_heading = "Model",
        required_unless_present = "identify"
    )]
    pub test: Option<TestKind>,

    /// The axis's friction instead of the file's: `--coulomb-n` and the others.
    #[command(flatten, next_help_heading = "Friction")]
    pub friction_values: FrictionValues,

    /// Fit F_C and μ_v to this constant-velocity record (CSV feed_m_per_min,current_a).
    ///
    /// One row per constant feed (signed: a run in −x has a negative feed
    /// and current), the mean motor current there; F = K_F3·I of the axis
    /// file. With --reversal also k_s. Prints the values and the servo-sim
    /// flags that start from them. See docs/src/servo.md, "Identifying the friction".
    #[arg(long, value_name = "CSV", help_heading = "Identification")]
    pub identify: Option<PathBuf>,

    /// The measured reversal for k_s: the circle's following error (CSV time_s,following_error_um).
    ///
    /// Time from the start of the circle (φ = π/2, with the 0.3 s run-up of
    /// servo-sim --test circle), the following error x_z − x at the position
    /// samples; --feed-m-min and --radius-mm say which circle it is
    /// (servo-sim --test circle --csv writes this layout, among other columns).
    #[arg(
        long,
        value_name = "CSV",
        requires = "identify",
        help_heading = "Identification"
    )]
    pub reversal: Option<PathBuf>,

    /// `--radius-mm`, `--circle-axis`.
    #[command(flatten, next_help_heading = "Circle")]
    pub circle: CircleFlags,

    /// `--feed-m-min`, `--acceleration-m-s2`, `--jerk-m-s3`.
    #[command(flatten, next_help_heading = "Motion")]
    pub motion: MotionFlags,

    /// `--force-n`, `--duration-s`.
    #[command(flatten, next_help_heading = "Step")]
    pub step: StepFlags,

    /// The ISO cycle's targets, runs, dwell, overrun and compliance.
    #[command(flatten, next_help_heading = "ISO 230-2")]
    pub iso: IsoFlags,

    /// Step uniformly at 1 µs (the reference) instead of adaptively.
    ///
    /// About 100–1000 times slower; the adaptive scheme agrees with it
    /// within 0.05 µm (docs/src/servo.md).
    #[arg(long, help_heading = "Numerics")]
    pub reference: bool,

    /// `--json` (the same in every command).
    #[command(flatten)]
    pub json_output: JsonOutput,

    /// Also write a CSV: the 1 ms trace, or the ISO readings (axcomp CSV layout).
    #[arg(long, value_name = "OUT", help_heading = "Output")]
    pub csv: Option<PathBuf>,

    /// `--force` (the same in every command).
    #[command(flatten)]
    pub overwrite: Overwrite,

    /// -q/--quiet (the same in every command).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Friction values that replace the axis file's (heading "Friction"):
/// what `--identify` or a diagnosis (`diagnose --servo-axis`) found.
#[derive(Debug, clap::Args)]
pub struct FrictionValues {
    /// Coulomb friction F_C, N (F_Ts keeps the file's ratio F_Ts/F_C).
    #[arg(long = "coulomb-n", value_name = "N")]
    pub coulomb_n: Option<f64>,

    /// Viscous coefficient μ_v, N·s/m.
    #[arg(long = "viscous-n-s-m", value_name = "N_S_PER_M")]
    pub viscous_n_s_m: Option<f64>,

    /// LuGre stiffness k_s, N/m (b_s follows by eq. 4.15 with the file's ζ_s).
    #[arg(long = "lugre-stiffness-n-m", value_name = "N_PER_M")]
    pub lugre_stiffness_n_m: Option<f64>,
}

/// The circle test's flags (heading "Circle").
#[derive(Debug, clap::Args)]
pub struct CircleFlags {
    /// Circle radius, mm.
    #[arg(long = "radius-mm", value_name = "MM", default_value_t = 90.0)]
    pub radius_mm: f64,

    /// Which circle coordinate the axis follows: x (R cos φ) or y (R sin φ).
    ///
    /// Defaults from the axis name in the file (X or Y).
    #[arg(long = "circle-axis", value_name = "x|y", value_parser = parse_circle_axis)]
    pub circle_axis: Option<CircleAxis>,
}

/// The moves' feed, acceleration and jerk (heading "Motion").
#[derive(Debug, clap::Args)]
pub struct MotionFlags {
    /// Feed, m/min [circle 16, constant-velocity 5, iso230-2 2].
    ///
    /// The path feed of the circle (Mendřický 2006 ran 3.2, 8, 16, 24 and
    /// 48 m/min), the cruise feed of the constant-velocity run, or the feed of
    /// every move of the ISO cycle.
    #[arg(long = "feed-m-min", value_name = "M_PER_MIN")]
    pub feed_m_min: Option<f64>,

    /// Acceleration of the moves, m/s² (constant-velocity and iso230-2).
    #[arg(
        long = "acceleration-m-s2",
        value_name = "M_PER_S2",
        default_value_t = 1.0
    )]
    pub acceleration_m_s2: f64,

    /// Jerk of the moves, m/s³ (constant-velocity and iso230-2).
    #[arg(long = "jerk-m-s3", value_name = "M_PER_S3", default_value_t = 20.0)]
    pub jerk_m_s3: f64,
}

/// The force step test's flags (heading "Step").
#[derive(Debug, clap::Args)]
pub struct StepFlags {
    /// Force of the step test, N [1500: half the continuous force, §6.2].
    #[arg(long = "force-n", value_name = "N", default_value_t = 1500.0)]
    pub force_n: f64,

    /// Simulated time of the step test, s (the step comes at 0.01 s).
    #[arg(long = "duration-s", value_name = "S", default_value_t = 0.3)]
    pub duration_s: f64,
}

/// The ISO 230-2 cycle's flags (heading "ISO 230-2"); `--first-mm` and
/// `--last-mm` also set the constant-velocity run's length.
#[derive(Debug, clap::Args)]
pub struct IsoFlags {
    /// Number of ISO targets, evenly spaced from --first-mm to --last-mm.
    #[arg(long, value_name = "N", default_value_t = 21)]
    pub targets: usize,

    /// First ISO target, mm.
    #[arg(long = "first-mm", value_name = "MM", default_value_t = 0.0)]
    pub first_mm: f64,

    /// Last ISO target, mm [400: fits both bundled axes].
    #[arg(long = "last-mm", value_name = "MM", default_value_t = 400.0)]
    pub last_mm: f64,

    /// Bidirectional runs (ISO 230-2 asks for 5).
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub runs: u32,

    /// Dwell at each target before the reading, s.
    #[arg(long = "dwell-s", value_name = "S", default_value_t = 1.0)]
    pub dwell_s: f64,

    /// Overrun past the first and last target, mm.
    #[arg(long = "overrun-mm", value_name = "MM", default_value_t = 5.0)]
    pub overrun_mm: f64,

    /// Structural stiffness between the drive's force line and the laser, N/µm.
    ///
    /// The drive holds its residual friction force through this stiffness,
    /// so the measured point lags the scale by F/k_c. The default (100 N/µm)
    /// is illustrative, not from Mendřický (2006). 0 means rigid: the laser reads
    /// the scale.
    // `alias`: the name it had before 0.2 (CHANGELOG.md).
    #[arg(
        long = "stiffness-n-per-um",
        alias = "compliance-n-um",
        value_name = "N_PER_UM",
        default_value_t = DEFAULT_STIFFNESS_N_PER_UM
    )]
    pub stiffness_n_per_um: f64,
}

fn parse_friction(name: &str) -> Result<FrictionKind, String> {
    FrictionKind::from_name(name).ok_or_else(|| {
        format!("unknown friction model {name:?}; expected classic, ramp, power or lugre")
    })
}

fn parse_circle_axis(name: &str) -> Result<CircleAxis, String> {
    match name.to_ascii_lowercase().as_str() {
        "x" => Ok(CircleAxis::X),
        "y" => Ok(CircleAxis::Y),
        _ => Err(format!("expected x or y, found {name:?}")),
    }
}

/// Reads `--axis` (and diagnose's `--servo-axis`): a bundled name, else a TOML file.
pub(super) fn load_axis(source: &str) -> Result<Axis> {
    if let Ok(axis) = Axis::bundled(source) {
        return Ok(axis);
    }
    let path = Path::new(source);
    if !path.exists() {
        bail!("--axis {source:?}: not a bundled axis (mcfv5050-x, mcfv5050-y) and no such file");
    }
    let bytes = std::fs::read(path).with_context(|| format!("{}", path.display()))?;
    let text = axcomp::read::decode(&bytes).map_err(|e| in_file(path, e))?;
    Axis::from_toml_str(&text).map_err(|e| in_file(path, e))
}

fn positive(flag: &str, value: f64) -> Result<f64> {
    if !(value.is_finite() && value > 0.0) {
        bail!("{flag}: expected a number > 0, found {value}");
    }
    Ok(value)
}

/// Runs `axcomp servo-sim`.
pub fn run(args: &ServoSimArgs) -> Result<()> {
    let values = &args.friction_values;
    for (flag, value) in [
        ("--coulomb-n", values.coulomb_n),
        ("--viscous-n-s-m", values.viscous_n_s_m),
        ("--lugre-stiffness-n-m", values.lugre_stiffness_n_m),
    ] {
        if let Some(value) = value {
            positive(flag, value)?;
        }
    }
    let axis = axis_with_friction(
        &load_axis(&args.axis)?,
        values.coulomb_n,
        values.viscous_n_s_m,
        values.lugre_stiffness_n_m,
    );
    if let Some(record) = &args.identify {
        return run_identify(args, &axis, record);
    }
    let (Some(friction_kind), Some(test)) = (args.friction, args.test) else {
        bail!("--friction and --test are needed to simulate (or give --identify)");
    };
    let friction = axis.friction(friction_kind);
    let stepping = if args.reference {
        Stepping::Uniform
    } else {
        Stepping::DEFAULT
    };
    let bar = progress::bar(1000, test.name(), args.verbosity.quiet);
    let mut report_progress = |fraction: f64| bar.set_position((fraction * 1000.0) as u64);
    let mut report = ServoSimJson {
        axis: axis.name.clone(),
        axis_source: args.axis.clone(),
        friction: friction_kind.name(),
        friction_label: friction_kind.thesis_label(),
        test: test.name(),
        stepping: if args.reference {
            "uniform-1us"
        } else {
            "adaptive"
        },
        simulated_s: 0.0,
        macro_steps: MacroStepsJson::new(Default::default()),
        circle: None,
        force_step: None,
        constant_velocity: None,
        iso230_2: None,
    };
    let csv: Vec<u8> = match test {
        TestKind::Circle => {
            let circle = circle_of(args, &axis, 16.0)?;
            let result = run_circle(&axis, friction, &circle, stepping, &mut report_progress);
            report.simulated_s = result.simulated_s;
            report.macro_steps = MacroStepsJson::new(result.counts);
            report.circle = Some(CircleJson::new(
                circle.radius_m,
                circle.feed_m_per_s,
                &result,
            ));
            trace_csv(&result.trace)
        }
        TestKind::Step => {
            let step = ForceStep {
                at_s: 0.01,
                force_n: args.step.force_n,
            };
            let duration = positive("--duration-s", args.step.duration_s)?;
            let result = run_force_step(&axis, friction, step, duration + step.at_s, stepping);
            report.simulated_s = result.simulated_s;
            report.macro_steps = MacroStepsJson::new(result.counts);
            report.force_step = Some(ForceStepJson::new(step.force_n, step.at_s, &result));
            trace_csv(&result.trace)
        }
        TestKind::ConstantVelocity => {
            let limits = move_limits(&args.motion, 5.0)?;
            let distance_m = mm_to_m(args.iso.last_mm - args.iso.first_mm)
                .abs()
                .max(um_to_mm(1.0));
            let result = run_constant_velocity(&axis, friction, distance_m, limits, stepping);
            report.simulated_s = result.simulated_s;
            report.macro_steps = MacroStepsJson::new(result.counts);
            report.constant_velocity =
                Some(ConstantVelocityJson::new(limits.feed_m_per_s, &result));
            Vec::new()
        }
        TestKind::Iso230_2 => {
            let cycle = IsoCycle {
                targets_m: IsoCycle::evenly_spaced(
                    mm_to_m(args.iso.first_mm),
                    mm_to_m(args.iso.last_mm),
                    args.iso.targets,
                ),
                runs: args.iso.runs,
                dwell_s: args.iso.dwell_s,
                overrun_m: mm_to_m(args.iso.overrun_mm),
                limits: move_limits(&args.motion, 2.0)?,
            };
            let compliance =
                (args.iso.stiffness_n_per_um != 0.0).then_some(args.iso.stiffness_n_per_um);
            let options = IsoOptions {
                stiffness_n_per_um: compliance,
                stepping,
            };
            let result = run_iso_cycle(&axis, friction, &cycle, options, &mut report_progress)
                .context("iso230-2")?;
            report.simulated_s = result.simulated_s;
            report.macro_steps = MacroStepsJson::new(result.counts);
            let iso = IsoJson::new(&cycle, compliance, &result);
            let csv = iso_csv(&axis.name, &iso);
            report.iso230_2 = Some(iso);
            csv
        }
    };
    bar.finish_and_clear();
    if let Some(path) = &args.csv {
        if csv.is_empty() {
            bail!("--csv: the {} test has no trace to write", test.name());
        }
        let inputs = [
            Some(Path::new(&args.axis)),
            args.identify.as_deref(),
            args.reversal.as_deref(),
        ];
        let inputs: Vec<&Path> = inputs.into_iter().flatten().collect();
        write_new(path, &csv, &inputs, args.overwrite.force)?;
    }
    if args.json_output.json {
        print_json(&report)
    } else {
        print_text(&text(&report))
    }
}

/// `--identify`: the fit, printed with the flags that start a simulation from it.
fn run_identify(args: &ServoSimArgs, axis: &Axis, record: &Path) -> Result<()> {
    let rows = load(record, parse_constant_velocity)?;
    let samples = match &args.reversal {
        Some(path) => Some(load(path, parse_following_error)?),
        None => None,
    };
    let circle = circle_of(args, axis, 3.2)?;
    let bar = progress::bar(1000, "identify", args.verbosity.quiet);
    let mut report_progress = |fraction: f64| bar.set_position((fraction * 1000.0) as u64);
    let found = identify(
        axis,
        &rows,
        samples.as_deref().map(|s| (&circle, s)),
        &mut report_progress,
    )
    .with_context(|| format!("{}", record.display()))?;
    bar.finish_and_clear();
    let json = IdentifyJson::new(
        &args.axis,
        found,
        args.reversal
            .as_ref()
            .map(|_| (&circle, circle.feed_m_per_s * 60.0)),
    );
    if args.json_output.json {
        print_json(&json)
    } else {
        print_text(&identify_text(&json))
    }
}

/// The circle of `--feed-m-min` (default `default_feed`), `--radius-mm`
/// and `--circle-axis` (or the axis name).
fn circle_of(args: &ServoSimArgs, axis: &Axis, default_feed: f64) -> Result<Circle> {
    let feed = positive(
        "--feed-m-min",
        args.motion.feed_m_min.unwrap_or(default_feed),
    )?;
    let circle_axis = match (
        args.circle.circle_axis,
        axis.name.to_ascii_uppercase().as_str(),
    ) {
        (Some(chosen), _) => chosen,
        (None, "X") => CircleAxis::X,
        (None, "Y") => CircleAxis::Y,
        (None, other) => {
            bail!("axis {other:?}: say which circle coordinate it follows with --circle-axis x|y")
        }
    };
    Ok(Circle {
        radius_m: mm_to_m(positive("--radius-mm", args.circle.radius_mm)?),
        ..Circle::thesis(feed, circle_axis)
    })
}

fn move_limits(motion: &MotionFlags, default_feed_m_min: f64) -> Result<MoveLimits> {
    Ok(MoveLimits {
        feed_m_per_s: positive(
            "--feed-m-min",
            motion.feed_m_min.unwrap_or(default_feed_m_min),
        )? / 60.0,
        acceleration_m_per_s2: positive("--acceleration-m-s2", motion.acceleration_m_s2)?,
        jerk_m_per_s3: positive("--jerk-m-s3", motion.jerk_m_s3)?,
    })
}

#[cfg(test)]
mod tests {
    use super::super::{Args, Command};
    use super::*;
    use clap::Parser;

    fn parse(extra: &[&str]) -> Result<ServoSimArgs, clap::Error> {
        let mut argv = vec!["axcomp", "servo-sim"];
        argv.extend_from_slice(extra);
        match Args::try_parse_from(argv)?.command {
            Command::ServoSim(args) => Ok(args),
            other => panic!("parsed as {other:?}"),
        }
    }

    #[test]
    fn axis_friction_and_test_are_required() {
        assert!(parse(&["--friction", "lugre", "--test", "circle"]).is_err());
        assert!(parse(&["--axis", "mcfv5050-x", "--test", "circle"]).is_err());
        assert!(parse(&["--axis", "mcfv5050-x", "--friction", "lugre"]).is_err());
        let args = parse(&[
            "--axis",
            "mcfv5050-x",
            "--friction",
            "LuGre",
            "--test",
            "iso230-2",
        ])
        .unwrap();
        assert_eq!(args.friction, Some(FrictionKind::LuGre));
        assert_eq!(args.test, Some(TestKind::Iso230_2));
    }

    #[test]
    fn identify_needs_no_model_or_test() {
        let args = parse(&[
            "--axis",
            "mcfv5050-x",
            "--identify",
            "cv.csv",
            "--reversal",
            "c.csv",
        ])
        .unwrap();
        assert_eq!(args.identify, Some(PathBuf::from("cv.csv")));
        assert_eq!((args.friction, args.test), (None, None));
        // --reversal only with --identify.
        assert!(
            parse(&[
                "--axis",
                "x",
                "--friction",
                "lugre",
                "--test",
                "circle",
                "--reversal",
                "c.csv"
            ])
            .is_err()
        );
        let args = parse(&[
            "--axis",
            "x",
            "--friction",
            "lugre",
            "--test",
            "circle",
            "--coulomb-n",
            "165",
        ])
        .unwrap();
        assert_eq!(args.friction_values.coulomb_n, Some(165.0));
    }

    #[test]
    fn friction_names_are_checked() {
        let error = parse(&["--axis", "x", "--friction", "dahl", "--test", "circle"]).unwrap_err();
        assert!(
            error.to_string().contains("classic, ramp, power or lugre"),
            "{error}"
        );
    }

    #[test]
    fn defaults_are_the_documented_ones() {
        let args = parse(&[
            "--axis",
            "mcfv5050-y",
            "--friction",
            "power",
            "--test",
            "circle",
        ])
        .unwrap();
        assert_eq!(args.circle.radius_mm, 90.0);
        assert_eq!(args.motion.feed_m_min, None);
        assert_eq!(
            (args.iso.targets, args.iso.runs, args.iso.dwell_s),
            (21, 5, 1.0)
        );
        assert_eq!(args.iso.stiffness_n_per_um, 100.0);
        assert!(!args.reference);
    }

    #[test]
    fn circle_axis_and_numbers() {
        let args = parse(&[
            "--axis",
            "a.toml",
            "--friction",
            "ramp",
            "--test",
            "circle",
            "--circle-axis",
            "Y",
            "--radius-mm",
            "50",
            "--feed-m-min",
            "8",
        ])
        .unwrap();
        assert_eq!(args.circle.circle_axis, Some(CircleAxis::Y));
        assert_eq!(
            (args.circle.radius_mm, args.motion.feed_m_min),
            (50.0, Some(8.0))
        );
        assert!(
            parse(&[
                "--axis",
                "x",
                "--friction",
                "ramp",
                "--test",
                "circle",
                "--circle-axis",
                "z"
            ])
            .is_err()
        );
    }
}
