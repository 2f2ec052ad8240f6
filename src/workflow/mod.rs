//! One command's work on inputs already in memory, every step of it:
//! `evaluate`, `convert` (and the next table), the table that was active
//! ([`table`]), the diagnosis of a re-test with the profile's known periods
//! ([`retest`]), the acceptance report with its predicted re-test
//! ([`report`]), the cross-axis table of a straightness test
//! ([`cross_axis`]), and what a rotary axis supports ([`rotary`]). The CLI
//! (`src/cli/`), the local web app (`serve`) and the demo all call these, so
//! the page shows the very JSON that `--json` prints and downloads the very
//! bytes `convert` writes.
//!
//! Reading files, the flags and printing stay with the caller; what is here
//! takes a measurement that is read and named (and runs left out) and the
//! settings already parsed.

pub mod cross_axis;
pub mod report;
pub mod retest;
pub mod rotary;
pub mod table;
pub mod thermal;

use crate::compensate::effects::build_table_with_effects;
use crate::compensate::plan::{PlanContext, Request, plan};
use crate::compensate::{CompensateError, CompensationTable};
use crate::diagnose::KnownPeriod;
use crate::effects::Effect;
use crate::emit::{self, Controller, EmitError, EmitOptions, MachineProfile};
use crate::error::{ParseError, Warning};
use crate::evaluate::uncertainty::{Budget, Equipment, UncertaintyError, budget};
use crate::evaluate::verdict::{
    AcceptanceProfile, Decision, Figure, Limit, LimitError, check_standard, command_line_limits,
    with_overrides,
};
use crate::evaluate::{Evaluation, Standard, evaluate, evaluate_with};
use crate::measurement::{AxisKind, Direction, Measurement, RunSelector};
use crate::report::acceptance::TestRecord;
use crate::report::convert::ConvertJson;
use crate::report::json::EvaluationJson;
use crate::report::uncertainty::UncertaintyJson;
use crate::report::update::UpdateJson;
use crate::report::verdict;
use crate::units::{AngleUnit, LengthUnit};

/// Why a command's work stopped. Each wraps its stage's error, so it reads
/// as that error does.
#[derive(Debug, thiserror::Error)]
pub enum WorkflowError {
    /// What a rotary axis does not support ([`rotary::ROTARY`]).
    #[error(transparent)]
    Rotary(#[from] rotary::RotaryRefusal),
    /// A table for a test that does not record its axis.
    #[error(
        "{file}: the file does not record which axis was measured; {how} to say which axis the table is for"
    )]
    AxisNotRecorded {
        /// The test's file.
        file: String,
        /// How the front end names the axis.
        how: String,
    },
    /// A table file that does not read.
    #[error("{file}:{error}")]
    TableFile {
        /// The table's file.
        file: String,
        /// Where and why.
        error: ParseError,
    },
    /// A cross-axis table's model.
    #[error(transparent)]
    Predict(#[from] crate::predict::PredictError),
    /// Input refused, with what was expected (the message names the file).
    #[error("{0}")]
    Refused(String),
    /// Inputs that do not belong together.
    #[error(transparent)]
    NotTogether(#[from] crate::together::NotTogether),
    /// The uncertainty budget.
    #[error(transparent)]
    Uncertainty(#[from] UncertaintyError),
    /// The grid, the mode or the table.
    #[error(transparent)]
    Compensate(#[from] CompensateError),
    /// The controller's file.
    #[error(transparent)]
    Emit(#[from] EmitError),
}

/// What `evaluate`'s object is judged against and shown in.
#[derive(Clone, Copy, Debug)]
pub struct EvaluationReportOptions<'a> {
    /// The runs left out (`--exclude-run`), named in the object.
    pub exclude_runs: &'a [RunSelector],
    /// The acceptance limits; empty: no verdict.
    pub limits: &'a [Limit],
    /// The equipment of the uncertainty budget (`--equipment`); without it
    /// the bundled laser where the file records one ([`budget_of`]).
    pub equipment: Option<&'a Equipment>,
    /// The verdict's decision rule.
    pub decision: Decision,
    /// The unit of a rotary axis' deviations (`--angle-unit`).
    pub angle: AngleUnit,
}

/// `evaluate --json`'s object for `measurement` (named, runs left out) and
/// its `evaluation`: the uncertainty budget (linear axes), the verdict when
/// there are limits, and every warning. The evaluation's warnings are
/// added to `warnings`, for the caller to print.
pub fn evaluation_report(
    measurement: &Measurement,
    evaluation: Evaluation,
    warnings: &mut Vec<Warning>,
    options: EvaluationReportOptions<'_>,
) -> Result<EvaluationJson, WorkflowError> {
    let EvaluationReportOptions {
        exclude_runs,
        limits,
        equipment,
        decision,
        angle,
    } = options;
    warnings.extend(evaluation.warnings.iter().cloned());
    // The budget is the laser's, for lengths, and limits are µm: a rotary
    // axis has neither yet, and asking for either is refused, as `report`
    // refuses it.
    rotary::check(
        measurement,
        &[
            (rotary::Use::Limits, !limits.is_empty()),
            (
                rotary::Use::Uncertainty,
                equipment.is_some() || decision != Default::default(),
            ),
        ],
    )?;
    let budget = match rotary::allows(measurement, rotary::Use::Uncertainty) {
        true => budget_of(measurement, equipment, warnings)?,
        false => None,
    };
    let verdict = rotary::allows(measurement, rotary::Use::Limits)
        .then(|| verdict::judge(&evaluation, limits, decision, budget.as_ref()))
        .flatten();
    let mut report =
        EvaluationJson::from_evaluation(measurement, evaluation, exclude_runs, warnings, angle);
    report.uncertainty_um = budget.as_ref().map(UncertaintyJson::from_budget);
    report.verdict = verdict;
    Ok(report)
}

/// The uncertainty budget of a linear test: with `given` equipment
/// (`--equipment`), else with the bundled laser where the file records a
/// laser interferometer; otherwise none, and a warning says why (a sensor or
/// an encoder is not the bundled laser).
pub fn budget_of(
    measurement: &Measurement,
    given: Option<&Equipment>,
    warnings: &mut Vec<Warning>,
) -> Result<Option<Budget>, UncertaintyError> {
    match given {
        Some(equipment) => Ok(Some(budget(measurement, equipment)?)),
        None if measurement.metadata.records_laser_interferometer() => {
            Ok(Some(budget(measurement, &Equipment::bundled())?))
        }
        None => {
            warnings.push(Warning::InstrumentUnknown {
                instrument: measurement.metadata.setup.instrument.clone(),
            });
            Ok(None)
        }
    }
}

/// The acceptance limits for `axis`: the profile's `[acceptance]` (the
/// profile and its file name, when one is given) with the `given` ones
/// (`--limit`, the page's fields) on top, each on a figure of the
/// evaluation's standard. Empty: no verdict.
pub fn limits(
    profile: Option<(&AcceptanceProfile, &str)>,
    axis: &str,
    evaluation: &Evaluation,
    given: &[(Figure, f64)],
) -> Result<Vec<Limit>, LimitError> {
    let from_profile =
        profile.map_or_else(Vec::new, |(profile, file)| profile.limits_for(axis, file));
    let limits = with_overrides(from_profile, command_line_limits(given)?);
    check_standard(&limits, evaluation)?;
    Ok(limits)
}

/// The periods the diagnosis searches first: the profile's screw lead and
/// scale period of the axis the re-test states (never of a guessed axis).
pub fn known_periods(profile: &MachineProfile, after: &Measurement) -> Vec<KnownPeriod> {
    if !after.axis_recorded() {
        return Vec::new();
    }
    let periods = profile.axis_periods(after.axis());
    [
        periods.screw_lead_mm.map(KnownPeriod::screw_lead),
        periods.scale_period_mm.map(KnownPeriod::scale_period),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// What a table is made for and written as (`convert`'s flags, parsed).
pub struct TableRequest<'a> {
    /// The controller.
    pub controller: Controller,
    /// Axis names, units, limits of the controller's file.
    pub options: &'a EmitOptions,
    /// Mode, grid, reference, extrapolation.
    pub request: &'a Request,
    /// Effects a diagnosis found (`--effects`).
    pub effects: &'a [Effect],
    /// The file that was active, when the new table goes back into it (a Fagor 8065 `.mp`).
    pub existing: Option<&'a [u8]>,
    /// The table that was active during the test (already added to the
    /// measurement): the new table is its update.
    pub active: Option<&'a CompensationTable>,
    /// The output as the user named it (`-o`), shown in the JSON.
    pub output: String,
    /// Its file name, which the activation text names.
    pub file_name: String,
    /// Coupled axes written the same table (`--also`).
    pub also: Vec<String>,
    /// Fanuc: also the table at a finer magnification (`--fanuc-rescaled`).
    pub fanuc_rescaled: bool,
}

/// A table: the file's bytes and `convert --json`'s object.
pub struct Converted {
    /// What the controller loads, byte for byte.
    pub bytes: Vec<u8>,
    /// What `convert --json` prints.
    pub report: ConvertJson,
    /// The table, for its chart.
    pub table: CompensationTable,
    /// Fanuc, when asked: the file at a finer magnification (3623) and the
    /// parameter change that goes with it.
    pub rescaled: Option<emit::fanuc::Rescaled>,
}

/// `convert`: the table of `measurement` (named, runs left out, an active
/// table already added) for `table.controller`. The evaluation's warnings
/// are added to `warnings`, which the JSON lists.
pub fn convert(
    measurement: &Measurement,
    warnings: &mut Vec<Warning>,
    table: &TableRequest<'_>,
) -> Result<Converted, WorkflowError> {
    emit::check_request(table.controller, table.existing, table.fanuc_rescaled)?;
    let evaluation = evaluate(measurement);
    warnings.extend(evaluation.warnings.iter().cloned());
    // The file records its source where the format has comments.
    let mut options = table.options.clone();
    options
        .provenance
        .get_or_insert_with(|| emit::Provenance::of(measurement));
    let options = &options;
    let only_direction = match Direction::BOTH.map(|d| measurement.run_count(d) > 0) {
        [true, false] => Some(Direction::Up),
        [false, true] => Some(Direction::Down),
        _ => None,
    };
    let request = emit::grid(
        table.controller,
        table.request,
        options,
        measurement.targets(),
    )?;
    let plan = plan(
        measurement.kind(),
        measurement.targets(),
        table.effects,
        &table.controller.capabilities(options.machine_unit),
        &request,
        &PlanContext {
            only_direction,
            existing: table.active,
        },
    )?;
    let compensation =
        build_table_with_effects(measurement, &evaluation, &plan.options, table.effects)?;
    let written = emit::write_updated(
        table.controller,
        compensation,
        options,
        table.existing,
        plan.update.as_ref(),
    )?;
    let compensation = written.table;
    let rescaled = match table.fanuc_rescaled {
        true => Some(emit::fanuc_rescaled(
            table.existing,
            &compensation,
            options,
        )?),
        false => None,
    };
    let activation = emit::activation(table.controller, &compensation, &table.file_name, options);
    if written.notes_say_how_read {
        warnings.retain(|w| !matches!(w, Warning::TableReadAs { .. }));
    }
    let warning_texts: Vec<String> = warnings.iter().map(ToString::to_string).collect();
    let mut report = ConvertJson::new(
        table.controller.name(),
        table.output.clone(),
        &compensation,
        table.also.clone(),
        activation,
        warning_texts,
    );
    report.effects = plan.notes;
    report.notes = plan.table_notes;
    report.notes.extend(written.notes);
    if measurement.kind() == AxisKind::Linear {
        let file_unit = table.controller.file_unit(options.machine_unit);
        report.file_unit = file_unit.as_str();
        let resolution =
            file_unit.from_mm(emit::resolution_mm(table.controller, options.machine_unit));
        report.file_decimals = (-resolution.log10()).round().max(0.0) as usize;
    }
    report.update = written
        .update
        .map(|summary| UpdateJson::new(&summary, report.file_unit));
    if let Some(backlash_mm) = compensation.suggested_backlash {
        report.set_backlash(table.controller.backlash_parameter(backlash_mm, options));
    }
    Ok(Converted {
        bytes: written.bytes,
        report,
        table: compensation,
        rescaled,
    })
}

/// A test of the acceptance report: read, named, evaluated, with every
/// warning (as `evaluate` has them) and its uncertainty budget.
pub struct Test {
    /// The measurement.
    pub measurement: Measurement,
    /// Its figures.
    pub evaluation: Evaluation,
    /// The reader's and the evaluation's warnings.
    pub warnings: Vec<Warning>,
    /// `None` on a rotary axis (the budget is the laser's, for lengths) and
    /// where the instrument is unknown (`budget_of`).
    pub budget: Option<Budget>,
}

impl Test {
    /// Evaluates `measurement` (read with `warnings`) to `standard`.
    pub fn new(
        measurement: Measurement,
        mut warnings: Vec<Warning>,
        standard: &dyn Standard,
        equipment: Option<&Equipment>,
    ) -> Result<Test, WorkflowError> {
        let evaluation = evaluate_with(&measurement, standard);
        warnings.extend(evaluation.warnings.iter().cloned());
        let budget = match rotary::allows(&measurement, rotary::Use::Uncertainty) {
            true => budget_of(&measurement, equipment, &mut warnings)?,
            false => None,
        };
        Ok(Test {
            measurement,
            evaluation,
            warnings,
            budget,
        })
    }

    /// What the report is made from.
    pub fn record(&self) -> TestRecord<'_> {
        TestRecord {
            measurement: &self.measurement,
            evaluation: &self.evaluation,
            warnings: &self.warnings,
            budget: self.budget.as_ref(),
        }
    }
}

/// A compensation table's file `bytes` (UTF-8, Latin-1 or UTF-16 with a
/// byte-order mark), in any format `convert` writes, for
/// the axis of `options`. A Fagor 8055 table is read in the profile's unit,
/// else in `test_unit` (`MachineProfile::table_unit`); a LinuxCNC table's
/// type is told from its numbers, `linuxcnc_type` deciding when they do not.
pub fn read_table(
    bytes: &[u8],
    mut options: EmitOptions,
    profile: &MachineProfile,
    test_unit: LengthUnit,
    linuxcnc_type: Option<u8>,
) -> Result<(Controller, CompensationTable), ParseError> {
    let (text, _) = emit::decode_table(bytes)?;
    if emit::fagor8055::looks_like(&text) {
        options.machine_unit = profile.table_unit(Controller::Fagor8055, test_unit);
    }
    emit::read_any(&text, &options, None).or_else(|error| match linuxcnc_type {
        Some(kind) => emit::read_any(&text, &options, Some(kind)),
        None => Err(error),
    })
}
