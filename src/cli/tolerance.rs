//! `axcomp tolerance`: the Monte Carlo tolerance study of Valášek (2021).
//!
//! Random machines from straightness, positioning, squareness and
//! carriage-side (saddle mounting face) tolerances, the distribution of their
//! largest volumetric error, the sensitivity of its 90th percentile to each
//! rail and carriage-side tolerance (`--sweep`), and the
//! single-axis study of the guideway model (`--single-axis`). The work is in
//! `axcomp::model::monte_carlo`; this file turns flags into its options,
//! shows progress and prints.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

use axcomp::model::monte_carlo::{
    AxisStudyOptions, CarriageFace, RailDirection, StudyOptions, SweptTolerance, THESIS_SWEEP_MM,
    Tolerances, sensitivity_sweep, single_axis_study, sweep_runs, tolerance_study,
};
use axcomp::model::{Axis, Grid, Guideway, ProfileShape};
use axcomp::output::write_new;
use axcomp::report::plot::{self, PlotFormat};
use axcomp::report::tolerance::{
    AxisStudyJson, ToleranceJson, axis_study_report, tolerance_report,
};
use axcomp::units::um_per_m_to_rad;

use super::common::{
    JsonOutput, MachineFile, Overwrite, Verbosity, load_machine, print_json, print_text,
};
use super::progress;

/// Flags of `axcomp tolerance`.
#[derive(Debug, clap::Args)]
pub struct ToleranceArgs {
    /// `--machine` (one profile; each command reads its part).
    #[command(flatten)]
    pub machine_file: MachineFile,

    /// Number of random machines (or axes with --single-axis).
    ///
    /// Valášek (2021) used 50,000: the smallest count at which P90 no longer
    /// changed in its fourth decimal (mm) between runs.
    #[arg(long, value_name = "N", default_value_t = 50_000, value_parser = parse_samples, help_heading = "Study")]
    pub samples: usize,

    /// Seed of the random streams.
    ///
    /// The same seed gives the same result, bit for bit, on any number of threads.
    #[arg(long, value_name = "S", default_value_t = 1, help_heading = "Study")]
    pub seed: u64,

    /// Straightness tolerance of all six rail mounting surfaces, mm.
    ///
    /// The peak-to-peak band of the generated surface profiles (Valášek 2021,
    /// §3.2.2); its baseline is 0.03 mm.
    #[arg(long, value_name = "MM", default_value_t = 0.03, value_parser = parse_length, help_heading = "Tolerances")]
    pub straightness: f64,

    /// One surface's straightness instead: AXIS.normal=MM or AXIS.lateral=MM (repeatable).
    ///
    /// normal is Valášek's (2021) "vertical" straightness (normal to the rail
    /// mounting face), lateral its "horizontal"; e.g. X.normal=0.02.
    #[arg(long = "surface", value_name = "AXIS.DIR=MM", value_parser = parse_surface, help_heading = "Tolerances")]
    pub surfaces: Vec<(Axis, RailDirection, f64)>,

    /// Positioning tolerance of X, Y and Z, mm (0: no positioning errors).
    ///
    /// Positioning errors come from the same generator as the surfaces; the
    /// full machine of Valášek (2021) uses 0.01 mm, its sensitivity study none.
    #[arg(long, value_name = "MM", default_value_t = 0.0, value_parser = parse_length, help_heading = "Tolerances")]
    pub positioning: f64,

    /// Largest squareness error of each axis pair, µm/m (uniform in ±; 0: none).
    ///
    /// The full machine of Valášek (2021) uses 30 µm/m, its sensitivity study none.
    #[arg(long, value_name = "UM_PER_M", default_value_t = 0.0, value_parser = parse_length, help_heading = "Tolerances")]
    pub squareness: f64,

    /// Parallelism of each saddle's carriage mounting faces to its datum face, mm (0: none).
    ///
    /// The carriage side (docs/src/references.md, carriage side): the plane of the four pads the
    /// carriages are bolted to, tilted across and along the rails within a
    /// zone of this width; a constant roll and pitch of the moving body.
    #[arg(long, value_name = "MM", default_value_t = 0.0, value_parser = parse_length, help_heading = "Tolerances")]
    pub carriage_parallelism: f64,

    /// Flatness of each saddle's four carriage mounting faces, mm (0: none).
    ///
    /// Their twist, which the carriages take up: it loads them, and moves the
    /// saddle only where their stiffnesses differ.
    #[arg(long, value_name = "MM", default_value_t = 0.0, value_parser = parse_length, help_heading = "Tolerances")]
    pub carriage_flatness: f64,

    /// One saddle's carriage-side tolerance instead: AXIS.parallelism=MM or AXIS.flatness=MM (repeatable).
    #[arg(long = "carriage", value_name = "AXIS.FACE=MM", value_parser = parse_carriage, help_heading = "Tolerances")]
    pub carriages: Vec<(Axis, CarriageFace, f64)>,

    /// Grid step over the work volume, mm.
    #[arg(long = "grid", value_name = "MM", default_value_t = 50.0, value_parser = parse_positive, help_heading = "Study")]
    pub grid_mm: f64,

    /// Error period of the generated profiles (knot spacing), mm.
    #[arg(long, value_name = "MM", default_value_t = 100.0, value_parser = parse_positive, help_heading = "Profiles")]
    pub period: f64,

    /// Step factor m of the random walk (eq. 39: steps m · U(−tol, tol)).
    #[arg(long, value_name = "M", default_value_t = 0.5, value_parser = parse_positive, help_heading = "Profiles")]
    pub step_factor: f64,

    /// Width of the band the walk stays in, as a multiple of the tolerance.
    ///
    /// 1 is the band ±tol/2 (a tolerance as a full band).
    #[arg(long, value_name = "FACTOR", default_value_t = 1.0, value_parser = parse_positive, help_heading = "Profiles")]
    pub band_width: f64,

    /// Also vary each tolerance in turn and fit the slopes of P90.
    ///
    /// One study per tolerance and value (Valášek 2021, Tabs 4.6–4.12: X, Y, Z
    /// normal and lateral, then all six together; then each saddle's
    /// carriage parallelism and flatness), the other tolerances as set.
    #[arg(long, help_heading = "Study")]
    pub sweep: bool,

    /// Tolerance values of the sweep, mm.
    #[arg(long, value_name = "MM,…", value_delimiter = ',', value_parser = parse_positive, default_values_t = THESIS_SWEEP_MM, help_heading = "Study")]
    pub sweep_values: Vec<f64>,

    /// Run the single-axis study instead: one axis, two rails, four carriages.
    ///
    /// Reports how much straighter the assembled axis is than its mounting
    /// surfaces (Valášek 2021, §3.5.1); uses --straightness, --stroke,
    /// --rail-spacing, --carriage-pitch and the profile flags.
    #[arg(long, help_heading = "Single axis")]
    pub single_axis: bool,

    /// Stroke of the single axis, mm.
    #[arg(long, value_name = "MM", default_value_t = 1000.0, value_parser = parse_positive, help_heading = "Single axis")]
    pub stroke: f64,

    /// Rail spacing a of the single axis, mm.
    #[arg(long, value_name = "MM", default_value_t = 400.0, value_parser = parse_positive, help_heading = "Single axis")]
    pub rail_spacing: f64,

    /// Carriage pitch b of the single axis, mm.
    #[arg(long, value_name = "MM", default_value_t = 500.0, value_parser = parse_positive, help_heading = "Single axis")]
    pub carriage_pitch: f64,

    /// Write the histogram of the machine study to FILE (.svg or .png).
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub histogram: Option<PathBuf>,

    /// `--force` (the same in every command).
    #[command(flatten)]
    pub overwrite: Overwrite,

    /// Worker threads (default: one per core). The result does not depend on it.
    #[arg(long, value_name = "N", value_parser = parse_samples, help_heading = "Study")]
    pub threads: Option<usize>,

    /// `--json` (the same in every command).
    #[command(flatten)]
    pub json_output: JsonOutput,

    /// -q/--quiet (the same in every command).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Runs `axcomp tolerance`.
pub fn run(args: &ToleranceArgs) -> Result<()> {
    if let Some(threads) = args.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .context("cannot start the worker threads")?;
    }
    let shape = ProfileShape {
        period_mm: args.period,
        step_factor: args.step_factor,
        band_width_factor: args.band_width,
    };
    if args.single_axis {
        return run_single_axis(args, shape);
    }
    let histogram_format = match &args.histogram {
        Some(path) => Some(PlotFormat::from_path(path).with_context(|| {
            format!(
                "--histogram {}: expected a file name ending in .svg or .png",
                path.display()
            )
        })?),
        None => None,
    };
    let machine = load_machine(args.machine_file.machine.as_deref())?;
    let mut tolerances = Tolerances::uniform(
        args.straightness,
        args.positioning,
        um_per_m_to_rad(args.squareness),
    );
    for (axis, direction, value) in &args.surfaces {
        tolerances.set_straightness(*axis, *direction, *value);
    }
    for axis in Axis::ALL {
        tolerances.set_carriage(axis, CarriageFace::Parallelism, args.carriage_parallelism);
        tolerances.set_carriage(axis, CarriageFace::Flatness, args.carriage_flatness);
    }
    for (axis, face, value) in &args.carriages {
        tolerances.set_carriage(*axis, *face, *value);
    }
    let options = StudyOptions {
        samples: args.samples,
        seed: args.seed,
        tolerances,
        shape,
        grid_step_mm: args.grid_mm,
    };
    let grid = Grid::over_strokes(&machine, args.grid_mm)?;
    let swept = SweptTolerance::all();
    let runs = if args.sweep {
        1 + sweep_runs(&tolerances, &swept, &args.sweep_values)
    } else {
        1
    };
    let bar = progress::bar(
        (args.samples * runs) as u64,
        "tolerance study",
        args.verbosity.quiet,
    );
    let advance = |done: u64| bar.inc(done);
    let result = tolerance_study(&machine, &options, &advance)?;
    let sensitivity = if args.sweep {
        Some(sensitivity_sweep(
            &machine,
            &options,
            result.summary.p90,
            &swept,
            &args.sweep_values,
            &advance,
        )?)
    } else {
        None
    };
    bar.finish_and_clear();
    let report = ToleranceJson::new(&machine, &grid, &options, &result, sensitivity.as_deref());
    if let (Some(path), Some(format)) = (&args.histogram, histogram_format) {
        let title = format!(
            "{} ({}): {} random machines, seed {}",
            report.machine, report.chain, report.samples, report.seed
        );
        let bytes = plot::histogram(
            &report.histogram,
            report.max_volumetric_um.p90,
            &title,
            format,
        )?;
        let inputs: Vec<&std::path::Path> =
            args.machine_file.machine.as_deref().into_iter().collect();
        write_new(path, &bytes, &inputs, args.overwrite.force)?;
    }
    if args.json_output.json {
        print_json(&report)
    } else {
        print_text(&tolerance_report(&report))
    }
}

fn run_single_axis(args: &ToleranceArgs, shape: ProfileShape) -> Result<()> {
    for (flag, given) in [
        ("--sweep", args.sweep),
        ("--histogram", args.histogram.is_some()),
        ("--machine", args.machine_file.machine.is_some()),
        ("--surface", !args.surfaces.is_empty()),
        ("--carriage", !args.carriages.is_empty()),
        ("--carriage-parallelism", args.carriage_parallelism != 0.0),
        ("--carriage-flatness", args.carriage_flatness != 0.0),
    ] {
        if given {
            bail!("{flag} applies to the machine study, not to --single-axis");
        }
    }
    let options = AxisStudyOptions {
        samples: args.samples,
        seed: args.seed,
        stroke_mm: args.stroke,
        guideway: Guideway::unloaded(args.rail_spacing, args.carriage_pitch),
        tolerance_mm: args.straightness,
        shape,
        step_mm: 5.0,
    };
    let bar = progress::bar(
        args.samples as u64,
        "single-axis study",
        args.verbosity.quiet,
    );
    let result = single_axis_study(&options, &|done| bar.inc(done))?;
    bar.finish_and_clear();
    let report = AxisStudyJson::new(&options, &result);
    if args.json_output.json {
        print_json(&report)
    } else {
        print_text(&axis_study_report(&report))
    }
}

/// A count of at least 1.
fn parse_samples(text: &str) -> Result<usize, String> {
    match text.trim().replace('_', "").parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("expected a whole number ≥ 1, found {text:?}")),
    }
}

/// A finite number ≥ 0 (a tolerance may be zero: that error is left out).
fn parse_length(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("expected a finite number ≥ 0, found {text:?}")),
    }
}

/// A finite number > 0.
fn parse_positive(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("expected a finite number > 0, found {text:?}")),
    }
}

/// `X.normal=0.02`, `z.lateral=0.06`.
fn parse_surface(text: &str) -> Result<(Axis, RailDirection, f64), String> {
    let expected = || {
        format!("expected AXIS.normal=MM or AXIS.lateral=MM (e.g. X.normal=0.02), found {text:?}")
    };
    let (axis, direction, value) = split_axis_setting(text).ok_or_else(expected)?;
    let direction = match direction.as_str() {
        "normal" | "vertical" => RailDirection::Normal,
        "lateral" | "horizontal" => RailDirection::Lateral,
        _ => return Err(expected()),
    };
    Ok((axis, direction, parse_length(value)?))
}

/// `X.parallelism=0.02`, `y.flatness=0.01`.
fn parse_carriage(text: &str) -> Result<(Axis, CarriageFace, f64), String> {
    let expected = || {
        format!(
            "expected AXIS.parallelism=MM or AXIS.flatness=MM (e.g. X.parallelism=0.02), found {text:?}"
        )
    };
    let (axis, face, value) = split_axis_setting(text).ok_or_else(expected)?;
    let face = match face.as_str() {
        "parallelism" => CarriageFace::Parallelism,
        "flatness" => CarriageFace::Flatness,
        _ => return Err(expected()),
    };
    Ok((axis, face, parse_length(value)?))
}

/// `AXIS.what=value` as the axis, `what` in lower case and the value's text.
fn split_axis_setting(text: &str) -> Option<(Axis, String, &str)> {
    let (setting, value) = text.split_once('=')?;
    let (axis, what) = setting.trim().split_once('.')?;
    let axis = match axis.trim().to_ascii_uppercase().as_str() {
        "X" => Axis::X,
        "Y" => Axis::Y,
        "Z" => Axis::Z,
        _ => return None,
    };
    Some((axis, what.trim().to_ascii_lowercase(), value))
}

#[cfg(test)]
mod tests {
    use super::super::{Args, Command};
    use super::*;
    use clap::Parser;

    fn parse(extra: &[&str]) -> Result<ToleranceArgs, clap::Error> {
        let mut argv = vec!["axcomp", "tolerance"];
        argv.extend_from_slice(extra);
        match Args::try_parse_from(argv)?.command {
            Command::Tolerance(args) => Ok(*args),
            _ => panic!("expected the tolerance subcommand"),
        }
    }

    #[test]
    fn defaults_are_the_thesis_baseline() {
        let args = parse(&[]).unwrap();
        assert_eq!(args.samples, 50_000);
        assert_eq!(args.seed, 1);
        assert_eq!(args.straightness, 0.03);
        assert_eq!((args.positioning, args.squareness), (0.0, 0.0));
        assert_eq!(
            (args.carriage_parallelism, args.carriage_flatness),
            (0.0, 0.0)
        );
        assert!(args.carriages.is_empty());
        assert_eq!(
            (args.grid_mm, args.period, args.step_factor, args.band_width),
            (50.0, 100.0, 0.5, 1.0)
        );
        assert_eq!(args.sweep_values, THESIS_SWEEP_MM);
        assert!(!args.sweep && !args.single_axis && !args.json_output.json);
    }

    #[test]
    fn surfaces_and_numbers() {
        let args = parse(&[
            "--surface",
            "X.normal=0.02",
            "--surface",
            "z.horizontal=0.06",
        ])
        .unwrap();
        assert_eq!(
            args.surfaces,
            vec![
                (Axis::X, RailDirection::Normal, 0.02),
                (Axis::Z, RailDirection::Lateral, 0.06)
            ]
        );
        for bad in [
            &["--surface", "X=0.02"][..],
            &["--surface", "W.normal=0.02"],
            &["--surface", "X.up=0.02"],
            &["--straightness", "nan"],
            &["--straightness", "-0.01"],
            &["--samples", "0"],
            &["--grid", "0"],
            &["--sweep-values", "0.01,inf"],
            &["--carriage", "X=0.02"],
            &["--carriage", "X.normal=0.02"],
            &["--carriage", "Q.flatness=0.02"],
            &["--carriage", "X.flatness=-0.01"],
            &["--carriage-parallelism", "nan"],
        ] {
            assert!(parse(bad).is_err(), "{bad:?} must be refused");
        }
        let args = parse(&[
            "--carriage",
            "x.Parallelism=0.02",
            "--carriage",
            "Z.flatness=0.005",
            "--carriage-parallelism",
            "0.01",
        ])
        .unwrap();
        assert_eq!(
            args.carriages,
            vec![
                (Axis::X, CarriageFace::Parallelism, 0.02),
                (Axis::Z, CarriageFace::Flatness, 0.005)
            ]
        );
        assert_eq!(args.carriage_parallelism, 0.01);
        let args = parse(&["--samples", "2_000", "--sweep-values", "0.01,0.02"]).unwrap();
        assert_eq!((args.samples, args.sweep_values), (2000, vec![0.01, 0.02]));
    }
}
