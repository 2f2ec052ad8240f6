//! `axcomp thermal`: ISO 230-3 thermal tests and a compensation model from temperatures.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use axcomp::output::write_new;
use axcomp::report::chart::chart;
use axcomp::report::plot::PlotFormat;
use axcomp::report::thermal as report;
use axcomp::thermal::{self, FitOptions, LogOptions, TestType, ThermalLog, ThermalModel};

use super::common::{JsonOutput, Overwrite, Verbosity, in_file, load, print_json, print_text};

/// Flags of `axcomp thermal`.
#[derive(Debug, clap::Args)]
pub struct ThermalArgs {
    /// What to do with a thermal log.
    #[command(subcommand)]
    pub command: ThermalCommand,
}

/// The thermal subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum ThermalCommand {
    /// The ISO 230-3 view of a thermal log: duration, largest drift and when, each sensor's rise.
    Evaluate(EvaluateArgs),
    /// Fit a model of the drift from the temperatures (sensors through first-order lags).
    ///
    /// Sensors and time constants are chosen by time-blocked cross-validation
    /// inside the rows fitted on (--rows); the cross-validated rms is the
    /// prediction's uncertainty. Writes the model file (TOML).
    Fit(FitArgs),
    /// Run a model over a thermal log: the predicted drift at each row and,
    /// where the log has the drift, the residual before and after.
    Apply(ApplyArgs),
    /// Write a model as a LinuxCNC HAL file: lowpass, scale and sum2
    /// components computing the model every servo period, feeding the axis'
    /// external offset (eoffset-counts at 1 nm).
    Hal(HalArgs),
}

/// Flags of `axcomp thermal hal`.
#[derive(Debug, clap::Args)]
pub struct HalArgs {
    /// The model file (from `axcomp thermal fit`).
    #[arg(value_name = "MODEL.toml")]
    pub model: PathBuf,
    /// The axis whose external offset takes the drift out (x, y, z, …).
    #[arg(long, value_name = "AXIS")]
    pub axis: String,
    /// The period of the thread the components run in, s (the servo thread's, 0.001 by default).
    #[arg(long, value_name = "S", default_value_t = 0.001)]
    pub period: f64,
    /// The thread the components are added to.
    #[arg(long, value_name = "NAME", default_value = "servo-thread")]
    pub thread: String,
    /// The HAL file to write.
    #[arg(short = 'o', long = "output", value_name = "FILE.hal")]
    pub output: PathBuf,
    /// `--force`.
    #[command(flatten)]
    pub overwrite: Overwrite,
    /// `-q` (the same in every command; hal prints no warnings).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// How to read a thermal log (the same in every thermal command).
#[derive(Debug, Clone, clap::Args)]
pub struct LogArgs {
    /// The drift column's name (µm unless its header says mm or nm).
    #[arg(long, value_name = "COLUMN", help_heading = "Input")]
    pub drift: Option<String>,
    /// Seconds between rows, for a log without a time column.
    #[arg(long = "sample-interval", value_name = "S", help_heading = "Input")]
    pub sample_interval: Option<f64>,
}

impl LogArgs {
    fn read(&self, path: &Path) -> Result<ThermalLog> {
        let options = LogOptions {
            drift: self.drift.clone(),
            sample_interval_s: self.sample_interval,
            drift_optional: false,
        };
        load(path, |text| thermal::parse_log(text, &options))
    }
}

/// Flags of `axcomp thermal evaluate`.
#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// The thermal log (CSV).
    #[arg(value_name = "LOG.csv")]
    pub log: PathBuf,
    /// How to read it.
    #[command(flatten)]
    pub log_args: LogArgs,
    /// The ISO 230-3 test the log records: etve, spindle or linear-axis.
    #[arg(long = "test", value_name = "TYPE", value_parser = parse_test)]
    pub test_type: Option<TestType>,
    /// Write the drift against time (.svg or .png).
    #[arg(long = "drift-plot", value_name = "FILE", help_heading = "Output")]
    pub drift_plot: Option<PathBuf>,
    /// Write the temperatures against time (.svg or .png).
    #[arg(
        long = "temperature-plot",
        value_name = "FILE",
        help_heading = "Output"
    )]
    pub temperature_plot: Option<PathBuf>,
    /// `--json`.
    #[command(flatten)]
    pub json: JsonOutput,
    /// `--force`.
    #[command(flatten)]
    pub overwrite: Overwrite,
    /// `-q`.
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Flags of `axcomp thermal fit`.
#[derive(Debug, clap::Args)]
pub struct FitArgs {
    /// The thermal log (CSV).
    #[arg(value_name = "LOG.csv")]
    pub log: PathBuf,
    /// How to read it (--drift is required).
    #[command(flatten)]
    pub log_args: LogArgs,
    /// The model file to write (TOML).
    #[arg(short = 'o', long = "output", value_name = "MODEL.toml")]
    pub output: PathBuf,
    /// The rows to fit on, 1-based data rows FIRST-LAST (default: all); the
    /// cross-validation never looks outside them.
    #[arg(long, value_name = "FIRST-LAST")]
    pub rows: Option<String>,
    /// Choose only from these sensors (comma-separated; default: every temperature column).
    #[arg(long, value_name = "T1,T2,…", value_delimiter = ',')]
    pub sensors: Vec<String>,
    /// Never use these sensors.
    #[arg(long, value_name = "T1,T2,…", value_delimiter = ',')]
    pub exclude: Vec<String>,
    /// The reference sensor: each term is a sensor's rise over it (the
    /// measuring loop's other end, e.g. the table), so a uniform change of
    /// the loop's temperature moves nothing. `auto`: the coldest sensor
    /// over the fit rows (the room or the table) or none, whichever
    /// predicts better.
    #[arg(long, value_name = "SENSOR")]
    pub reference: Option<String>,
    /// At most this many sensors (the reference aside).
    #[arg(long = "max-sensors", value_name = "N", default_value_t = 4)]
    pub max_sensors: usize,
    /// How the cross-validation predicts its blocks: blocked (each from all
    /// the others), forward (each from the blocks before it only: what
    /// the model does on the machine, predicting the hours after its fit)
    /// or late (forward over the last third of the rows: the blocks nearest
    /// the steady state).
    #[arg(long, value_name = "HOW", default_value = "blocked", value_parser = ["blocked", "forward", "late"])]
    pub validation: String,
    /// Write the drift, the model and the residual against time (.svg or .png).
    #[arg(long = "plot", value_name = "FILE", help_heading = "Output")]
    pub plot: Option<PathBuf>,
    /// `--force`.
    #[command(flatten)]
    pub overwrite: Overwrite,
    /// `-q`.
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Flags of `axcomp thermal apply`.
#[derive(Debug, clap::Args)]
pub struct ApplyArgs {
    /// The model file (from `axcomp thermal fit`).
    #[arg(value_name = "MODEL.toml")]
    pub model: PathBuf,
    /// The thermal log (CSV) to run it over.
    #[arg(value_name = "LOG.csv")]
    pub log: PathBuf,
    /// Seconds between rows, for a log without a time column.
    #[arg(long = "sample-interval", value_name = "S", help_heading = "Input")]
    pub sample_interval: Option<f64>,
    /// Write the drift, the model and the residual against time (.svg or .png).
    #[arg(long = "plot", value_name = "FILE", help_heading = "Output")]
    pub plot: Option<PathBuf>,
    /// `--json`.
    #[command(flatten)]
    pub json: JsonOutput,
    /// `--force`.
    #[command(flatten)]
    pub overwrite: Overwrite,
    /// `-q`.
    #[command(flatten)]
    pub verbosity: Verbosity,
}

fn parse_test(name: &str) -> Result<TestType, String> {
    TestType::from_name(name)
        .ok_or_else(|| format!("expected etve, spindle or linear-axis, found {name:?}"))
}

/// Runs `axcomp thermal`.
pub fn run(args: &ThermalArgs) -> Result<()> {
    match &args.command {
        ThermalCommand::Evaluate(a) => evaluate(a),
        ThermalCommand::Fit(a) => fit(a),
        ThermalCommand::Apply(a) => apply(a),
        ThermalCommand::Hal(a) => hal(a),
    }
}

fn evaluate(args: &EvaluateArgs) -> Result<()> {
    let log = args.log_args.read(&args.log)?;
    let iso = thermal::evaluate(&log, args.test_type);
    write_plot(
        args.drift_plot.as_deref(),
        || report::drift_chart(&log, None),
        &[&args.log],
        args.overwrite.force,
    )?;
    write_plot(
        args.temperature_plot.as_deref(),
        || report::temperature_chart(&log),
        &[&args.log],
        args.overwrite.force,
    )?;
    let json = report::evaluate_json(&iso);
    if args.json.json {
        print_json(&json)
    } else {
        print_text(&report::evaluate_text(&json))
    }
}

fn fit(args: &FitArgs) -> Result<()> {
    if args.log_args.drift.is_none() {
        bail!("thermal fit needs the drift column: --drift COLUMN");
    }
    let log = args.log_args.read(&args.log)?;
    let rows = match &args.rows {
        None => 0..log.len(),
        Some(text) => parse_rows(text, log.len())?,
    };
    let mut options = FitOptions::over(rows);
    options.sensors = args.sensors.clone();
    options.exclude = args.exclude.clone();
    options.auto_reference = args.reference.as_deref() == Some("auto");
    options.reference = args.reference.clone().filter(|r| r != "auto");
    options.max_sensors = args.max_sensors;
    options.validation = match args.validation.as_str() {
        "forward" => thermal::Validation::Forward,
        "late" => thermal::Validation::Late,
        _ => thermal::Validation::Blocked,
    };
    let model = thermal::fit(&log, &options).map_err(|e| in_file_thermal(&args.log, e))?;
    write_new(
        &args.output,
        report::model_toml(&model).as_bytes(),
        &[&args.log],
        args.overwrite.force,
    )?;
    if let Some(path) = &args.plot {
        let applied = thermal::apply(&model, &log).map_err(|e| in_file_thermal(&args.log, e))?;
        write_plot(
            Some(path),
            || report::drift_chart(&log, Some(&applied)),
            &[&args.log],
            args.overwrite.force,
        )?;
    }
    print_text(&report::fit_text(&model))
}

fn apply(args: &ApplyArgs) -> Result<()> {
    let model = load(&args.model, ThermalModel::from_toml)?;
    // A log without the model's drift column is run for the prediction alone.
    let options = LogOptions {
        drift: Some(model.fit.drift.clone()),
        sample_interval_s: args.sample_interval,
        drift_optional: true,
    };
    let log = load(&args.log, |text| thermal::parse_log(text, &options))?;
    let applied = thermal::apply(&model, &log).map_err(|e| in_file_thermal(&args.log, e))?;
    write_plot(
        args.plot.as_deref(),
        || report::drift_chart(&log, Some(&applied)),
        &[&args.log, &args.model],
        args.overwrite.force,
    )?;
    let json = report::apply_json(&model, &log, &applied);
    if args.json.json {
        print_json(&json)
    } else {
        print_text(&report::apply_text(&model, &json))
    }
}

fn in_file_thermal(path: &Path, error: thermal::ThermalError) -> anyhow::Error {
    match error {
        thermal::ThermalError::Parse(parse) => in_file(path, parse),
        other => anyhow::anyhow!("{}: {other}", path.display()),
    }
}

/// `FIRST-LAST`, 1-based inclusive data rows, as a 0-based range.
fn parse_rows(text: &str, rows: usize) -> Result<std::ops::Range<usize>> {
    thermal::parse_rows(text, rows).map_err(|message| anyhow::anyhow!("--{message}"))
}

fn write_plot(
    path: Option<&Path>,
    make: impl FnOnce() -> axcomp::report::chart::Chart,
    inputs: &[&Path],
    force: bool,
) -> Result<()> {
    let Some(path) = path else {
        return Ok(());
    };
    let Some(format) = PlotFormat::from_path(path) else {
        bail!(
            "{}: expected a plot file ending in .svg or .png",
            path.display()
        );
    };
    write_new(path, &chart(&make(), format)?, inputs, force)?;
    Ok(())
}

fn hal(args: &HalArgs) -> Result<()> {
    let model = load(&args.model, ThermalModel::from_toml)?;
    if !(args.period.is_finite() && args.period > 0.0) {
        bail!("--period {}: expected a period above 0 s", args.period);
    }
    if args.axis.len() != 1 || !"xyzabcuvw".contains(args.axis.to_ascii_lowercase().as_str()) {
        bail!(
            "--axis {}: expected one of x, y, z, a, b, c, u, v, w",
            args.axis
        );
    }
    let text =
        axcomp::emit::linuxcnc_thermal::write_hal(&model, &args.axis, args.period, &args.thread);
    write_new(
        &args.output,
        text.as_bytes(),
        &[&args.model],
        args.overwrite.force,
    )?;
    Ok(())
}

/// A thermal log given with a test (`report --thermal`, `diagnose --thermal`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ThermalInputArgs {
    /// A thermal log (CSV, as `thermal evaluate` reads it): the report adds
    /// its ISO 230-3 view, plots and model; diagnose says how much of a
    /// drift found its temperatures explain (the log's first row at the
    /// re-test's start).
    #[arg(long = "thermal", value_name = "LOG.csv", help_heading = "Thermal")]
    pub log: Option<PathBuf>,
    /// The thermal model to run over it (from `axcomp thermal fit`); without
    /// one, the report fits a model on the whole log when its drift column
    /// is named (--thermal-drift).
    #[arg(
        long = "thermal-model",
        value_name = "MODEL.toml",
        requires = "log",
        help_heading = "Thermal"
    )]
    pub model: Option<PathBuf>,
    /// The log's drift column (default: the model's).
    #[arg(
        long = "thermal-drift",
        value_name = "COLUMN",
        requires = "log",
        help_heading = "Thermal"
    )]
    pub drift: Option<String>,
    /// Seconds between the log's rows, for a log without a time column.
    #[arg(
        long = "thermal-sample-interval",
        value_name = "S",
        requires = "log",
        help_heading = "Thermal"
    )]
    pub sample_interval: Option<f64>,
}

impl ThermalInputArgs {
    /// The log studied (`None` without --thermal): with the model given,
    /// or one fitted on every row when the drift column is named.
    pub fn study(&self) -> Result<Option<thermal::Study>> {
        let Some(path) = &self.log else {
            return Ok(None);
        };
        let model = self
            .model
            .as_deref()
            .map(|p| load(p, ThermalModel::from_toml))
            .transpose()?;
        let request = thermal::StudyRequest {
            drift: self.drift.clone(),
            sample_interval_s: self.sample_interval,
            model,
            ..Default::default()
        };
        let text = load(path, |text| {
            Ok::<_, axcomp::error::ParseError>(text.to_string())
        })?;
        let study = thermal::study_text(&text, request).map_err(|e| in_file_thermal(path, e))?;
        Ok(Some(study))
    }

    /// The files read, for `write_new`'s check that no output is an input.
    pub fn inputs(&self) -> Vec<&Path> {
        [self.log.as_deref(), self.model.as_deref()]
            .into_iter()
            .flatten()
            .collect()
    }
}

/// The share of the found drift the logged temperatures explain, for
/// `diagnose --thermal` and `report --diagnose --thermal`.
pub fn drift_share(
    diagnosis: &axcomp::diagnose::Diagnosis,
    environment: &axcomp::measurement::Environment,
    study: Option<&thermal::Study>,
) -> Option<report::ShareView> {
    use axcomp::diagnose::thermal::{recorded_changes, thermal_share};
    let drift = diagnosis.accepted.iter().find_map(|a| match &a.effect {
        axcomp::effects::Effect::Drift(d) => Some(*d),
        _ => None,
    })?;
    let recorded = recorded_changes(environment);
    let Some(study) = study else {
        return Some(report::ShareView::not_computed(
            "not computed: no thermal log of the re-test (--thermal LOG.csv --thermal-model MODEL.toml)",
            &recorded,
        ));
    };
    let Some(applied) = &study.applied else {
        return Some(report::ShareView::not_computed(
            "not computed: the thermal log has no model (--thermal-model, or --thermal-drift to fit one)",
            &recorded,
        ));
    };
    let readings: Vec<_> = diagnosis.readings.iter().map(|r| r.reading).collect();
    Some(
        match thermal_share(&drift, &readings, &study.log, applied) {
            Ok(share) => report::ShareView::of(&share),
            Err(why) => report::ShareView::not_computed(&format!("not computed: {why}"), &recorded),
        },
    )
}

/// Prints a report (`--json` or text) with the thermal share added: as
/// `"thermal"` in the JSON, as a paragraph after the text.
pub fn print_with_share<T: serde::Serialize>(
    report: &T,
    render: impl Fn(&T) -> String,
    share: Option<report::ShareView>,
    json: bool,
) -> Result<()> {
    if json {
        let Some(share) = share else {
            return print_json(report);
        };
        print_json(&report::WithShare {
            report,
            thermal: share,
        })
    } else {
        let mut text = render(report);
        if let Some(share) = share {
            text.push_str(&format!("\nThermal: {}\n", share.text));
        }
        print_text(&text)
    }
}

/// The report's `page` with the thermal section when --thermal is given
/// (and, with a diagnosis, the share of its drift the log explains).
pub fn with_thermal_section(
    page: String,
    args: &ThermalInputArgs,
    diagnosis: Option<&axcomp::diagnose::Diagnosis>,
    environment: Option<&axcomp::measurement::Environment>,
) -> Result<String> {
    let Some(study) = args.study()? else {
        return Ok(page);
    };
    let share = match (diagnosis, environment) {
        (Some(d), Some(e)) => drift_share(d, e, Some(&study)),
        _ => None,
    };
    let section = report::section_html(&study, share.as_ref())?;
    Ok(report::insert_section(&page, &section))
}
