//! One handler per step: read the form ([`super::inputs`]), call the
//! workflow, answer ([`super::present`]). The work off the async threads.

use axum::extract::Multipart;
use axum::http::StatusCode;
use axum::response::Response;

use crate::compensate;
use crate::diagnose::Diagnosis;
use crate::effects::Effect;
use crate::report::acceptance::TableRecord;
use crate::report::diagnose::DiagnoseJson;
use crate::report::html;
use crate::report::web::{ConvertAnswer, EvaluateAnswer, OptionsJson, RetestAnswer};
use crate::together::{Input, Pairing, check_together};
use crate::units::AngleUnit;
use crate::workflow::report::{Report, ReportParts, generator};
use crate::workflow::retest::{DiagnoseSettings, diagnosis, effects_file};
use crate::workflow::rotary::{self, ReportAsks, Use};
use crate::workflow::table::{WriteAs, recorded_axis, write_options};
use crate::workflow::{self, TableRequest, Test};

use super::UPLOAD_LIMIT;
use super::error::ApiError;
use super::form::Form;
use super::inputs::{
    active_table, controller, decision, fanuc_rescaled, file_label, grid, limits, linuxcnc_type,
    measurement, profile, standard, test,
};
use super::present::{Table, attachment, convert_answer, svg_of};

/// Runs the blocking work off the async threads (a large test takes a
/// while) and reads the form first.
async fn answer<T: Send + 'static>(
    multipart: Multipart,
    work: impl FnOnce(Form) -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    let form = Form::read(multipart)
        .await
        .map_err(|(status, message)| ApiError::new(status, message))?;
    tokio::task::spawn_blocking(move || work(form))
        .await
        .map_err(|error| ApiError::new(StatusCode::INTERNAL_SERVER_ERROR, error.to_string()))?
}

/// `GET /api/options`.
pub async fn options() -> axum::Json<OptionsJson> {
    axum::Json(OptionsJson::new(UPLOAD_LIMIT))
}

/// `POST /api/evaluate`: `evaluate --json` and the deviation plot, the test evaluated once.
pub async fn api_evaluate(multipart: Multipart) -> Result<axum::Json<EvaluateAnswer>, ApiError> {
    answer(multipart, |form| {
        let standard = standard(&form)?;
        let (measurement, mut warnings) = measurement(&form, "file")?;
        let profile = profile(&form)?;
        let test = Test::new(measurement, warnings.clone(), standard, None)?;
        let limits = limits(&form, &profile, test.measurement.axis(), &test.evaluation)?;
        let evaluation = workflow::evaluation_report(
            &test.measurement,
            test.evaluation.clone(),
            &mut warnings,
            workflow::EvaluationReportOptions {
                exclude_runs: &[],
                limits: &limits,
                equipment: None,
                decision: decision(&form)?,
                angle: AngleUnit::default(),
            },
        )?;
        let report = Report::new(ReportParts::of(&test, standard));
        Ok(EvaluateAnswer {
            evaluation,
            deviation_svg: svg_of(&report.input(), "deviation")?,
        })
    })
    .await
    .map(axum::Json)
}

/// `convert` for the form: the measurement of `field`, the table that was
/// active during it (`table`), the controller and grid, the `effects`.
fn table_of(form: &Form, field: &str, effects: &[Effect]) -> Result<Table, ApiError> {
    let profile = profile(form)?.machine;
    let (measurement, mut warnings) = measurement(form, field)?;
    let before = Test::new(measurement.clone(), warnings.clone(), standard(form)?, None)?;
    let axis = recorded_axis(&measurement, "name it in the Axis field")?.to_string();
    let controller = controller(form)?;
    let file_name = controller.file_name(&axis);
    let linuxcnc_type = linuxcnc_type(form)?;
    // The name inside Heidenhain files is the file name, upper case (as `convert -o`).
    let options = write_options(
        &profile,
        &axis,
        &file_name.to_uppercase(),
        &WriteAs {
            controller,
            test_unit: measurement.metadata.length_unit,
            kind: measurement.kind(),
            linuxcnc_type: linuxcnc_type.unwrap_or(0),
            max_points: None,
            also: &[],
        },
    )?;
    let mut measurement = measurement;
    let label = file_label(form.files(field));
    let (existing, active) =
        match active_table(form, &measurement, &label, &profile, linuxcnc_type)? {
            Some(((_, bytes), active)) => {
                warnings.extend(active.doubts);
                measurement = compensate::add_existing_table(&measurement, &active.table)?;
                (Some(bytes.as_slice()), Some(active.table))
            }
            None => (None, None),
        };
    let converted = workflow::convert(
        &measurement,
        &mut warnings,
        &TableRequest {
            controller,
            options: &options,
            request: &grid(form)?,
            effects,
            existing,
            active: active.as_ref(),
            output: file_name.clone(),
            file_name: file_name.clone(),
            also: Vec::new(),
            fanuc_rescaled: fanuc_rescaled(form)?,
        },
    )?;
    Ok(Table {
        converted,
        file_name,
        before,
        controller,
    })
}

/// `POST /api/convert`: `convert --json`, the file's text and the table's plot.
pub async fn api_convert(multipart: Multipart) -> Result<axum::Json<ConvertAnswer>, ApiError> {
    answer(multipart, |form| {
        convert_answer(&table_of(&form, "file", &[])?)
    })
    .await
    .map(axum::Json)
}

/// `POST /api/table`: the table's file (the next table with a re-test).
pub async fn api_table(multipart: Multipart) -> Result<Response, ApiError> {
    answer(multipart, |form| {
        let table = match form.files("after") {
            [] => table_of(&form, "file", &[])?,
            _ => next_table(&form)?.1,
        };
        Ok(attachment(
            &table.file_name,
            "application/octet-stream",
            table.converted.bytes,
        ))
    })
    .await
}

/// The table after the re-test, as `convert AFTER --existing TABLE
/// --effects E.toml` makes it from the effects file the diagnosis writes
/// (read back, so the numbers are the file's; none on a rotary axis, which
/// has no effects file), with the diagnosis.
fn next_table(form: &Form) -> Result<(Retest, Table), ApiError> {
    let retest = retest(form)?;
    let effects = retest.effects.as_ref().map_or(&[][..], |(_, e)| e);
    let table = table_of(form, "after", effects)?;
    Ok((retest, table))
}

/// The re-test (`after`) against the first test (`file`) and the table
/// that was active (`table`), as `diagnose --after AFTER --before FILE
/// --table TABLE --machine PROFILE` sees them.
struct Retest {
    before: Test,
    after: Test,
    diagnosis: Diagnosis,
    /// `diagnose --json`'s object.
    report: DiagnoseJson,
    /// What `diagnose --write-effects` writes and its effects read back;
    /// `None` on a rotary axis.
    effects: Option<(String, Vec<Effect>)>,
}

fn retest(form: &Form) -> Result<Retest, ApiError> {
    let standard = standard(form)?;
    let (before, before_warnings) = measurement(form, "file")?;
    let (after, mut after_warnings) = measurement(form, "after")?;
    let before_label = file_label(form.files("file"));
    let after_label = file_label(form.files("after"));
    after_warnings.extend(check_together(
        Pairing::BeforeAfter,
        &Input::measurement(&before, before_label.clone()),
        &Input::measurement(&after, after_label.clone()),
    )?);
    let linuxcnc_type = linuxcnc_type(form)?;
    let profile = profile(form)?.machine;
    // The table was active during the re-test.
    let table = active_table(form, &after, &after_label, &profile, linuxcnc_type)?;
    if let Some((_, active)) = &table {
        after_warnings.extend(active.doubts.iter().cloned());
    }
    let diagnosis = diagnosis(
        &after,
        Some(&before),
        table.as_ref().map(|(_, active)| &active.table),
        &profile,
        DiagnoseSettings::plain(standard),
    )?;
    let report = DiagnoseJson::new(
        &diagnosis,
        after_label.clone(),
        Some(before_label),
        table
            .as_ref()
            .map(|((name, _), _)| name.display().to_string()),
        AngleUnit::default(),
    );
    let effects = match rotary::check(&after, &[(Use::EffectsFile, true)]) {
        Ok(()) => Some(
            effects_file(&diagnosis, &after_label)
                .map_err(|error| ApiError::bad(format!("the effects file:{error}")))?,
        ),
        Err(_) => None,
    };
    Ok(Retest {
        effects,
        report,
        diagnosis,
        before: Test::new(before, before_warnings, standard, None)?,
        after: Test::new(after, after_warnings, standard, None)?,
    })
}

/// `POST /api/retest`: the diagnosis (`diagnose --json`), the residual's
/// plot, the effects file and, with a table, the next table.
pub async fn api_retest(multipart: Multipart) -> Result<axum::Json<RetestAnswer>, ApiError> {
    answer(multipart, |form| {
        let (retest, next) = match form.one_file("table")? {
            Some(_) => {
                let (retest, table) = next_table(&form)?;
                (retest, Some(table))
            }
            None => (retest(&form)?, None),
        };
        let standard = standard(&form)?;
        // The report's diagnosis charts are lengths: none on a rotary axis.
        let residual_svg =
            match rotary::check(&retest.after.measurement, &[(Use::ReportDiagnosis, true)]) {
                Ok(()) => {
                    let report = Report::new(ReportParts {
                        after: Some(&retest.after),
                        diagnosis: Some(&retest.diagnosis),
                        ..ReportParts::of(&retest.before, standard)
                    });
                    svg_of(&report.input(), "residual")?
                }
                Err(_) => None,
            };
        let warnings = [&retest.before, &retest.after]
            .into_iter()
            .zip([form.files("file"), form.files("after")])
            .flat_map(|(test, files)| {
                let label = file_label(files);
                test.warnings.iter().map(move |w| format!("{label}: {w}"))
            })
            .collect();
        Ok(RetestAnswer {
            warnings,
            residual_svg,
            next: next.as_ref().map(convert_answer).transpose()?,
            diagnosis: retest.report,
            effects_toml: retest.effects.map(|(text, _)| text),
        })
    })
    .await
    .map(axum::Json)
}

/// `POST /api/report`: `axcomp report FILE [--after AFTER] [--table TABLE]
/// [--diagnose] [--machine PROFILE]`, refused for a rotary axis where the
/// CLI refuses it.
pub async fn api_report(multipart: Multipart) -> Result<Response, ApiError> {
    answer(multipart, |form| {
        let standard = standard(&form)?;
        let mut before = test(&form, "file", standard)?;
        let label = file_label(form.files("file"));
        let after = match form.files("after") {
            [] => None,
            files => {
                let mut after = test(&form, "after", standard)?;
                after.warnings.extend(check_together(
                    Pairing::BeforeAfter,
                    &Input::measurement(&before.measurement, label.clone()),
                    &Input::measurement(&after.measurement, file_label(files)),
                )?);
                Some(after)
            }
        };
        let profile = profile(&form)?;
        let limits = limits(
            &form,
            &profile,
            before.measurement.axis(),
            &before.evaluation,
        )?;
        let decision = decision(&form)?;
        let diagnose = form.text("diagnose").is_some();
        rotary::check_report(
            &before.measurement,
            ReportAsks {
                limits: !limits.is_empty(),
                uncertainty: decision != Default::default(),
                table: form.one_file("table")?.is_some(),
                diagnose,
                standard,
            },
        )?;
        let table = active_table(&form, &before.measurement, &label, &profile.machine, None)?;
        if let Some((_, active)) = &table {
            before.warnings.extend(active.doubts.iter().cloned());
        }
        let diagnosis = match (&after, diagnose) {
            (Some(after), true) => Some(diagnosis(
                &after.measurement,
                Some(&before.measurement),
                table.as_ref().map(|(_, active)| &active.table),
                &profile.machine,
                DiagnoseSettings::plain(standard),
            )?),
            _ => None,
        };
        let file = table
            .as_ref()
            .map(|((name, _), _)| name.display().to_string());
        let generator = generator(chrono::Local::now());
        let report = Report::new(ReportParts {
            after: after.as_ref(),
            table: table
                .as_ref()
                .zip(file.as_deref())
                .map(|((_, active), file)| TableRecord {
                    table: &active.table,
                    file,
                    controller: active.controller,
                }),
            diagnosis: diagnosis.as_ref(),
            limits: &limits,
            decision,
            generator: &generator,
            ..ReportParts::of(&before, standard)
        });
        let page = html::render(&report.input())?;
        Ok(attachment(
            "report.html",
            "text/html; charset=utf-8",
            page.into_bytes(),
        ))
    })
    .await
}
