//! `axcomp demo`: the whole workflow on the bundled demo data (a synthetic X
//! axis whose truth, in `fixtures/demo/truth.toml`, has a reversal that both
//! tests measure and a warm-up drift that only the re-test has, which the
//! model cannot declare): evaluate the first test, write
//! the table for every controller, predict the re-test, read the bundled
//! re-test, diagnose it, write the next table and the acceptance report.
//!
//! The data is compiled into the binary, so the demo runs anywhere. Every
//! step is a library call the other subcommands make too; nothing here
//! computes a figure of its own.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use axcomp::compensate::plan::Request;
use axcomp::compensate::{self, CompensationTable, Extrapolate, GridSpec, TableMode, TableOptions};
use axcomp::diagnose::Diagnosis;
use axcomp::effects::{Effect, Parameter, ParameterValue};
use axcomp::emit::{self, Controller, EmitOptions, MachineProfile};
use axcomp::evaluate::{Evaluation, ISO_230_2};
use axcomp::measurement::{Measurement, SourceFormat};
use axcomp::model::{GeometricErrors, Machine, Optics};
use axcomp::output::{create_folder, write_all_new};
use axcomp::predict::{MeasuredAxis, PredictInput, Prediction, predict};
use axcomp::read;
use axcomp::report::acceptance::{TableRecord, charts};
use axcomp::report::chart::chart;
use axcomp::report::diagnose::DiagnoseJson;
use axcomp::report::html;
use axcomp::report::json::EvaluationJson;
use axcomp::report::plot::PlotFormat;
use axcomp::report::predict::PredictJson;
use axcomp::synth::{EffectSpec, Truth};
use axcomp::units::mm_to_um;
use axcomp::workflow::report::{Report, ReportParts};
use axcomp::workflow::retest::{DiagnoseSettings, diagnosis, effects_file};
use axcomp::workflow::table::{WriteAs, write_options};
use axcomp::workflow::{self, Converted, TableRequest, Test};

use super::common::{Verbosity, print_text};
use super::progress;

const TRUTH: &str = include_str!("../../fixtures/demo/truth.toml");
const BEFORE: &str = include_str!("../../fixtures/demo/before.rtl");
const AFTER: &str = include_str!("../../fixtures/demo/after.rtl");

/// Flags of `axcomp demo`.
#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    /// Where to write everything (created if missing).
    #[arg(long, value_name = "DIR", default_value = "axcomp-demo")]
    pub out: PathBuf,

    /// Replace files of an earlier demo in DIR.
    #[arg(long)]
    pub force: bool,

    /// -q/--quiet (the same in every command).
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// One file to write: path relative to the output folder, contents.
type Output = (String, Vec<u8>);

/// Runs `axcomp demo`.
pub fn run(args: &DemoArgs) -> Result<()> {
    let steps = progress::bar(6, "demo", args.verbosity.quiet);
    let truth = Truth::from_toml_str(TRUTH).map_err(|e| anyhow::anyhow!("bundled truth: {e}"))?;
    let before = bundled(BEFORE, "before.rtl")?;
    let after = bundled(AFTER, "after.rtl")?;
    let mut files: Vec<Output> = vec![
        ("truth.toml".into(), TRUTH.into()),
        ("before.rtl".into(), BEFORE.into()),
        ("after.rtl".into(), AFTER.into()),
    ];

    // 1. The first test per ISO 230-2, with the measurement uncertainty of
    // the bundled equipment, as `axcomp report` computes it without --equipment.
    let before_test = Test::new(before, Vec::new(), &ISO_230_2, None)?;
    let (before, evaluation) = (&before_test.measurement, &before_test.evaluation);
    let json = EvaluationJson::new(
        before,
        evaluation,
        &[],
        &evaluation.warnings,
        Default::default(),
    );
    files.push(("evaluate.json".into(), serde_json::to_vec_pretty(&json)?));
    steps.inc(1);

    // 2. A mean table at the targets for every controller, read back as the controller applies it.
    let options = TableOptions {
        mode: TableMode::Mean,
        grid: GridSpec::Targets,
        reference: None,
        extrapolate: Extrapolate::Refuse,
    };
    let table = compensate::build_table(before, evaluation, &options)?;
    let mut active = None;
    let mut active_bytes = Vec::new();
    for controller in Controller::ALL
        .into_iter()
        .filter(|c| !c.needs_the_controls_file())
    {
        let emit_options = emit_options(&table.axis)?;
        let bytes = emit::write_bytes(controller, &table, &emit_options, None)?;
        let (text, _) = emit::decode_table(&bytes)
            .map_err(|e| anyhow::anyhow!("{}: {e}", controller.name()))?;
        let (_, read_back) = emit::read_any(&text, &emit_options, Some(0))
            .map_err(|e| anyhow::anyhow!("{}: {e}", controller.name()))?;
        if controller == Controller::Tnc640 {
            active = Some(read_back);
            active_bytes = bytes.clone();
        }
        files.push((table_path(controller, &table.axis), bytes));
    }
    let active = active.context("no TNC 640 table")?;
    steps.inc(1);

    // 3. The prediction of the re-test with the TNC 640 table (the one the bundled re-test ran with).
    let machine = Machine::bundled();
    let measured = [MeasuredAxis {
        measurement: before,
        line_mm: machine.reference_mm(),
        optics: Optics::AT_TOOL_TIP,
    }];
    let prediction = predict(&PredictInput {
        machine: &machine,
        errors: &GeometricErrors::default(),
        measured: &measured,
        tables: std::slice::from_ref(&active),
        cross_tables: &[],
        line_mm: machine.reference_mm(),
        retest_tool_offset_mm: None,
        grid_step_mm: 50.0,
        effects: &[],
        backlash_set: false,
        standard: &ISO_230_2,
    })?;
    let predict_json = PredictJson::new(
        machine.name(),
        machine.chain().as_str(),
        &prediction,
        50.0,
        Vec::new(),
        Vec::new(),
    );
    files.push((
        "predict.json".into(),
        serde_json::to_vec_pretty(&predict_json)?,
    ));
    steps.inc(1);

    // 4. The re-test, diagnosed against the prediction.
    let profile = MachineProfile::default();
    let diagnosis = diagnosis(
        &after,
        Some(before),
        Some(&active),
        &profile,
        DiagnoseSettings::plain(&ISO_230_2),
    )?;
    let diagnose_json = DiagnoseJson::new(
        &diagnosis,
        "after.rtl".into(),
        Some("before.rtl".into()),
        Some(table_path(Controller::Tnc640, &table.axis)),
        Default::default(),
    );
    files.push((
        "diagnose.json".into(),
        serde_json::to_vec_pretty(&diagnose_json)?,
    ));
    let (effects_text, effects) = effects_file(&diagnosis, "after.rtl")
        .map_err(|e| anyhow::anyhow!("the effects file:{e}"))?;
    files.push(("effects.toml".into(), effects_text.into_bytes()));
    steps.inc(1);

    // 5. The next table, as `convert after.rtl --existing X.COM --effects
    // effects.toml --controller tnc640 -o tables/next/X.COM` writes it.
    let next = next_table(&after, &active, &active_bytes, &effects, &profile)?;
    files.push((format!("tables/next/{}.COM", next.table.axis), next.bytes));
    let next = next.table;
    steps.inc(1);

    // 6. The acceptance report with its plots.
    let after = Test::new(after, Vec::new(), &ISO_230_2, None)?;
    let after_evaluation = &after.evaluation;
    let tnc640_file = table_path(Controller::Tnc640, &table.axis);
    let generator = format!("axcomp {} demo", env!("CARGO_PKG_VERSION"));
    let report = Report::new(ReportParts {
        after: Some(&after),
        table: Some(TableRecord {
            table: &active,
            file: &tnc640_file,
            controller: Controller::Tnc640,
        }),
        diagnosis: Some(&diagnosis),
        generator: &generator,
        ..ReportParts::of(&before_test, &ISO_230_2)
    });
    let input = report.input();
    files.push(("report.html".into(), html::render(&input)?.into_bytes()));
    for named in charts(&input) {
        files.push((
            format!("png/{}.png", named.name),
            chart(&named.chart, PlotFormat::Png)?,
        ));
    }
    steps.finish_and_clear();

    write_all(&args.out, &files, args.force)?;
    print_text(&summary(&Summary {
        out: &args.out,
        truth: &truth,
        evaluation,
        after: after_evaluation,
        prediction: &prediction,
        diagnosis: &diagnosis,
        table: &table,
        next: &next,
        files: files.len(),
    }))
}

/// A bundled test, named as the demo writes it.
fn bundled(text: &str, name: &str) -> Result<Measurement> {
    let (mut measurement, _) = read::parse_str(text, SourceFormat::Rtl)
        .map_err(|e| anyhow::anyhow!("bundled {name}:{e}"))?;
    measurement.metadata.source_file = Some(PathBuf::from(name));
    Ok(measurement)
}

fn emit_options(axis: &str) -> Result<EmitOptions> {
    Ok(EmitOptions::for_axis(
        &MachineProfile::default(),
        axis,
        &format!("{axis}.COM"),
    )?)
}

/// Where a controller's table goes: one folder per controller, its usual extension.
fn table_path(controller: Controller, axis: &str) -> String {
    format!(
        "tables/{}/{}",
        controller.name(),
        controller.file_name(axis)
    )
}

/// The table after the re-test: the active table plus the residual the
/// re-test shows, with the diagnosis's effects, for the TNC 640: what
/// `convert --existing --effects` writes.
fn next_table(
    after: &Measurement,
    active: &CompensationTable,
    active_bytes: &[u8],
    effects: &[Effect],
    profile: &MachineProfile,
) -> Result<Converted> {
    let without = compensate::add_existing_table(after, active)?;
    let file_name = Controller::Tnc640.file_name(&active.axis);
    let options = write_options(
        profile,
        &active.axis,
        &file_name.to_uppercase(),
        &WriteAs {
            controller: Controller::Tnc640,
            test_unit: after.metadata.length_unit,
            kind: after.kind(),
            linuxcnc_type: 0,
            max_points: None,
            also: &[],
        },
    )?;
    Ok(workflow::convert(
        &without,
        &mut Vec::new(),
        &TableRequest {
            controller: Controller::Tnc640,
            options: &options,
            request: &Request::default(),
            effects,
            existing: Some(active_bytes),
            active: Some(active),
            output: format!("tables/next/{file_name}"),
            file_name,
            also: Vec::new(),
            fanuc_rescaled: false,
        },
    )?)
}

/// Writes every file under `out`, refusing to replace any without `force`
/// (checked for all before the first is written).
fn write_all(out: &Path, files: &[Output], force: bool) -> Result<()> {
    if !force && let Some((name, _)) = files.iter().find(|(name, _)| out.join(name).exists()) {
        bail!(
            "{} exists (from an earlier demo?); give --force to replace it, or --out another folder",
            out.join(name).display()
        );
    }
    let files: Vec<(PathBuf, &[u8])> = files
        .iter()
        .map(|(name, bytes)| (out.join(name), bytes.as_slice()))
        .collect();
    // The folder itself only where its parent exists (a mistyped path must
    // not become a tree of new folders); the demo's own subfolders inside it.
    create_folder(out)?;
    for (path, _) in &files {
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).with_context(|| parent.display().to_string())?;
        }
    }
    // All or none, also when the file system refuses one of them. The demo
    // reads only its compiled-in files: no input to protect.
    write_all_new(&files, &[], force)?;
    Ok(())
}

struct Summary<'a> {
    out: &'a Path,
    truth: &'a Truth,
    evaluation: &'a Evaluation,
    after: &'a Evaluation,
    prediction: &'a Prediction,
    diagnosis: &'a Diagnosis,
    table: &'a CompensationTable,
    next: &'a CompensationTable,
    files: usize,
}

/// Where everything is and what happened, in ten lines.
fn summary(s: &Summary<'_>) -> String {
    let um = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{:.2}", mm_to_um(v)));
    let f = &s.evaluation.figures;
    let retest = &s.prediction.retests[0].figures;
    let a = &s.after.figures;
    let found: Vec<String> = s
        .diagnosis
        .accepted
        .iter()
        .map(|accepted| {
            let Parameter { key, value, .. } = accepted.effect.parameters()[0];
            let truth = truth_value(s.truth, &accepted.effect)
                .map_or(String::new(), |t| format!(" (truth {})", text(t)));
            let value = match value {
                ParameterValue::Number(v) => format!("{v:.2}"),
                ParameterValue::Run(run) => run.to_string(),
            };
            format!("{} {key} = {value}{truth}", accepted.effect.kind().name())
        })
        .collect();
    let unexplained = if s.diagnosis.unexplained.significant {
        "structure left unexplained (see the report)"
    } else {
        "nothing left unexplained"
    };
    let mut out = String::new();
    let _ = writeln!(out, "axcomp demo: {} files in {}", s.files, s.out.display());
    let _ = writeln!(
        out,
        " 1 first test    before.rtl: A {} µm, E {} µm, R {} µm, B {} µm (evaluate.json)",
        um(f.a),
        um(f.e),
        um(f.r),
        um(f.b)
    );
    let _ = writeln!(
        out,
        " 2 tables        {} tables for iTNC 530, TNC 640, Sinumerik 840D, LinuxCNC, Fagor 8055: {} points (tables/; Fagor 8065 and Fanuc: convert --existing updates the control's own file)",
        s.table.values.mode().as_str(),
        s.table.positions.len()
    );
    let _ = writeln!(
        out,
        " 3 prediction    re-test A {} µm, E {} µm, B {} µm (the measured reversal stays with a mean table); volumetric max {:.2} → {:.2} µm (predict.json)",
        um(retest.a),
        um(retest.e),
        um(retest.b),
        mm_to_um(s.prediction.volumetric_before.max_mm),
        mm_to_um(s.prediction.volumetric_after.max_mm)
    );
    let _ = writeln!(
        out,
        " 4 re-test       after.rtl: A {} µm, E {} µm, R {} µm, B {} µm: not what was predicted",
        um(a.a),
        um(a.e),
        um(a.r),
        um(a.b)
    );
    let _ = writeln!(
        out,
        " 5 diagnosis     {} (diagnose.json, effects.toml)",
        found.join("; ")
    );
    let _ = writeln!(
        out,
        " 6 residual      rms {:.2} µm → {:.2} µm with the effects; {unexplained}",
        s.diagnosis.residual_before.rms, s.diagnosis.residual_after.rms
    );
    let next_reason = match s.next.values.mode() {
        TableMode::Bidirectional => format!(
            "the reversal B̄ {} µm the re-test measured, the residual and the effects",
            um(s.after.figures.b_mean)
        ),
        TableMode::Mean => "the residual and the effects".to_string(),
    };
    let _ = writeln!(
        out,
        " 7 next table    tables/next/{}.COM: {} ({next_reason})",
        s.next.axis,
        s.next.values.mode().as_str()
    );
    let _ = writeln!(
        out,
        " 8 report        {} (open in a browser; plots in png/)",
        s.out.join("report.html").display()
    );
    let _ = writeln!(
        out,
        " 9 the truth     truth.toml: what the synthetic axis really has"
    );
    out
}

/// A parameter's value as the summary prints the truth's.
fn text(value: ParameterValue) -> String {
    match value {
        ParameterValue::Number(v) => v.to_string(),
        ParameterValue::Run(run) => run.to_string(),
    }
}

/// The truth's value of the parameter the summary shows (the first), when
/// the truth has an effect of that kind.
fn truth_value(truth: &Truth, effect: &Effect) -> Option<ParameterValue> {
    truth
        .effects
        .iter()
        .filter_map(EffectSpec::as_effect)
        .find(|planted| planted.kind() == effect.kind())
        .map(|planted| planted.parameters()[0].value)
}
