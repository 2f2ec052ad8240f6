//! `axcomp serve`: the local web app for the engineer at the machine who
//! has a laptop and a browser but no shell.
//!
//! One page (`assets/serve/`: plain HTML, CSS and JavaScript, compiled into
//! the binary; no CDN, so it works offline) and a small JSON API over the
//! library, on axum and tokio:
//!
//! - `POST /api/evaluate`: `evaluate --json`'s object (with the form's
//!   `limits`, `decision` and machine profile, as `--limit`, `--decision`,
//!   `--machine`) and the deviation plot;
//! - `POST /api/convert`: `convert --json`'s object, the file's text and the
//!   table's plot; `POST /api/table` the file itself, byte for byte what
//!   `convert -o NAME` writes, under the controller's usual name
//!   (`Controller::file_name`);
//! - `POST /api/retest`: the diagnosis of a re-test (`diagnose --json`) and
//!   the next table;
//! - `POST /api/report`: the acceptance report, the HTML `axcomp report` writes.
//!
//! Every route takes the machine profile (`machine`, the `--machine` TOML):
//! its axis settings for the tables, its `[acceptance]` for the verdict, its
//! screw lead and scale period for the diagnosis.
//!
//! The work is the CLI's own ([`crate::workflow`]); this module only reads
//! the form and answers. Its limits: uploads of at most [`UPLOAD_LIMIT`]
//! bytes, kept in memory and named by their base name (no path a client
//! names is ever opened, no file is written), and only requests addressed to
//! the app from its own page ([`origin`]). Bad input is a 400 whose `error`
//! is the CLI's message (`file:line:col: …`).
//!
//! Unlike the stages below, this one does I/O: the network is its job.

mod form;
pub mod origin;
mod thermal;

use std::net::{SocketAddr, TcpListener};
use std::sync::Arc;

use axum::Router;
use axum::extract::{DefaultBodyLimit, Multipart, Request, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use serde::Serialize;

use crate::compensate::plan::Request as TableGrid;
use crate::compensate::{self, Extrapolate, TableMode};
use crate::cycle::CycleTiming;
use crate::diagnose::{DiagnoseInput, Diagnosis, diagnose};
use crate::effects::{Effect, read_effects};
use crate::emit::{self, Controller, EmitOptions, MachineProfile};
use crate::error::Warning;
use crate::evaluate::verdict::{AcceptanceProfile, Decision, Figure, Limit, parse_limit};
use crate::evaluate::{self, Standard, evaluate_with};
use crate::measurement::{AxisKind, Measurement, SourceFormat};
use crate::read;
use crate::report::acceptance::{ReportInput, TableRecord, charts};
use crate::report::chart::chart;
use crate::report::convert::ConvertJson;
use crate::report::diagnose::DiagnoseJson;
use crate::report::html;
use crate::report::json::EvaluationJson;
use crate::report::plot::PlotFormat;
use crate::together::{Input, Pairing, check_together};
use crate::units::AngleUnit;
use crate::workflow::{self, Converted, TableRequest, Test};

use form::{Form, Upload};

/// The largest request the app reads, bytes: a 10 000-target × 10-run
/// `.rtl` is 1.9 MB, so 50 MB is far above any real test and still far
/// below what would strain the laptop.
pub const UPLOAD_LIMIT: usize = 50 * 1024 * 1024;

/// The port `axcomp serve` listens on unless told otherwise.
pub const DEFAULT_PORT: u16 = 8230;

const INDEX_HTML: &str = include_str!("../../assets/serve/index.html");
const APP_JS: &str = include_str!("../../assets/serve/app.js");
const APP_CSS: &str = include_str!("../../assets/serve/app.css");

/// Answers on `listener` until the process ends.
pub fn serve(listener: TcpListener) -> std::io::Result<()> {
    let addr = listener.local_addr()?;
    listener.set_nonblocking(true)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_io()
        .build()?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::from_std(listener)?;
        axum::serve(listener, app(addr)).await
    })
}

/// The routes, for a listener bound to `addr` (whose names the requests must use).
pub fn app(addr: SocketAddr) -> Router {
    let allowed: Arc<Vec<String>> = Arc::new(origin::allowed_hosts(addr));
    Router::new()
        .route(
            "/",
            get(|| async { page(INDEX_HTML, "text/html; charset=utf-8") }),
        )
        .route(
            "/app.js",
            get(|| async { page(APP_JS, "text/javascript; charset=utf-8") }),
        )
        .route(
            "/app.css",
            get(|| async { page(APP_CSS, "text/css; charset=utf-8") }),
        )
        .route("/api/options", get(options))
        .route("/api/evaluate", post(api_evaluate))
        .route("/api/convert", post(api_convert))
        .route("/api/table", post(api_table))
        .route("/api/retest", post(api_retest))
        .route("/api/report", post(api_report))
        .route("/thermal", get(thermal::form).post(thermal::submit))
        .layer(DefaultBodyLimit::max(UPLOAD_LIMIT))
        .layer(middleware::from_fn_with_state(allowed, guard))
}

/// Refuses requests by another name or from another origin ([`origin`]).
async fn guard(State(allowed): State<Arc<Vec<String>>>, request: Request, next: Next) -> Response {
    let (host, origin) = {
        let headers = request.headers();
        let text = |name: header::HeaderName| {
            headers
                .get(name)
                .and_then(|value| value.to_str().ok())
                .map(str::to_string)
        };
        (text(header::HOST), text(header::ORIGIN))
    };
    let host = host.or_else(|| request.uri().authority().map(|a| a.to_string()));
    let refusal = origin::refusal(&allowed, host.as_deref(), origin.as_deref());
    match refusal {
        Some(why) => ApiError::new(StatusCode::FORBIDDEN, why).into_response(),
        None => next.run(request).await,
    }
}

fn page(body: &'static str, content_type: &'static str) -> Response {
    (
        [
            (header::CONTENT_TYPE, content_type),
            (header::CACHE_CONTROL, "no-store"),
        ],
        body,
    )
        .into_response()
}

/// A refused request: its status and the message the page shows.
#[derive(Debug)]
struct ApiError {
    status: StatusCode,
    message: String,
}

impl ApiError {
    fn new(status: StatusCode, message: impl Into<String>) -> ApiError {
        ApiError {
            status,
            message: message.into(),
        }
    }

    /// Bad input: 400 with the message.
    fn bad(message: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::BAD_REQUEST, message)
    }

    /// Bad input, said as the CLI says it: the error and its causes, `: ` between.
    fn from_error(error: &dyn std::error::Error) -> ApiError {
        let mut message = error.to_string();
        let mut source = error.source();
        while let Some(cause) = source {
            let text = cause.to_string();
            if !message.ends_with(&text) {
                message.push_str(": ");
                message.push_str(&text);
            }
            source = cause.source();
        }
        ApiError::bad(message)
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        #[derive(Serialize)]
        struct Body {
            error: String,
        }
        (
            self.status,
            axum::Json(Body {
                error: self.message,
            }),
        )
            .into_response()
    }
}

macro_rules! bad_input {
    ($($error:ty),*) => {$(
        impl From<$error> for ApiError {
            fn from(error: $error) -> ApiError {
                ApiError::from_error(&error)
            }
        }
    )*};
}

bad_input!(
    read::ReadError,
    workflow::WorkflowError,
    emit::EmitError,
    crate::measurement::MeasurementError,
    crate::together::NotTogether,
    crate::evaluate::UnknownStandard,
    crate::diagnose::DiagnoseError,
    crate::report::plot::PlotError
);

impl From<String> for ApiError {
    fn from(message: String) -> ApiError {
        ApiError::bad(message)
    }
}

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

/// What the page offers to choose from.
#[derive(Serialize)]
struct OptionsJson {
    controllers: Vec<&'static str>,
    standards: Vec<StandardJson>,
    upload_limit_bytes: usize,
    version: &'static str,
}

#[derive(Serialize)]
struct StandardJson {
    key: &'static str,
    name: &'static str,
}

async fn options() -> axum::Json<OptionsJson> {
    axum::Json(OptionsJson {
        controllers: Controller::ALL.iter().map(|c| c.name()).collect(),
        standards: evaluate::SUPPORTED
            .iter()
            .map(|s| StandardJson {
                key: s.key(),
                name: s.name(),
            })
            .collect(),
        upload_limit_bytes: UPLOAD_LIMIT,
        version: env!("CARGO_PKG_VERSION"),
    })
}

/// The measurement of the form's `file` field(s), named by `axis` when given.
fn measurement(form: &Form, field: &str) -> Result<(Measurement, Vec<Warning>), ApiError> {
    let files = form.files(field);
    if files.is_empty() {
        return Err(ApiError::bad(format!(
            "no {field} file: drop or pick a measurement file"
        )));
    }
    let format = match form.text("format") {
        Some(name) => {
            Some(SourceFormat::from_name(name).ok_or_else(|| format!("unknown format {name:?}"))?)
        }
        None => None,
    };
    let read::ReadResult {
        mut measurement,
        warnings,
    } = read::read_all_bytes(files, format)?;
    if let Some(axis) = form.text("axis") {
        measurement.set_axis(axis);
    }
    Ok((measurement, warnings))
}

fn standard(form: &Form) -> Result<&'static dyn Standard, ApiError> {
    Ok(evaluate::by_name(
        form.text("standard").unwrap_or("iso230-2:2014"),
    )?)
}

/// The machine profile of the form's `machine` field (as `--machine`):
/// its `[controller]` part and its `[acceptance]` part; the defaults and no
/// limits when none is sent. A bad profile is refused as the CLI refuses
/// it: `NAME:LINE:COL: …`.
struct Profile {
    /// The file's name, which the limits' source names.
    file: String,
    machine: MachineProfile,
    acceptance: Option<AcceptanceProfile>,
}

fn profile(form: &Form) -> Result<Profile, ApiError> {
    let Some((name, bytes)) = form.one_file("machine")? else {
        return Ok(Profile {
            file: String::new(),
            machine: MachineProfile::default(),
            acceptance: None,
        });
    };
    let file = name.display().to_string();
    let text = std::str::from_utf8(bytes)
        .map_err(|_| ApiError::bad(format!("{file}: a machine profile is UTF-8 text (TOML)")))?;
    let at = |error: crate::error::ParseError| ApiError::bad(format!("{file}:{error}"));
    Ok(Profile {
        machine: MachineProfile::from_toml_str(text).map_err(at)?,
        acceptance: Some(AcceptanceProfile::from_toml_str(text).map_err(at)?),
        file,
    })
}

/// The form's `limits` (`A=12, E_up=6`: `--limit` each) on top of the
/// profile's `[acceptance]`, for `evaluation`'s axis and standard.
fn limits(
    form: &Form,
    profile: &Profile,
    axis: &str,
    evaluation: &evaluate::Evaluation,
) -> Result<Vec<Limit>, ApiError> {
    let given = form
        .text("limits")
        .unwrap_or_default()
        .split([',', ';', '\n'])
        .map(str::trim)
        .filter(|item| !item.is_empty())
        .map(|item| parse_limit(item).map_err(|error| format!("limits: {error}")))
        .collect::<Result<Vec<(Figure, f64)>, String>>()?;
    let acceptance = profile
        .acceptance
        .as_ref()
        .map(|acceptance| (acceptance, profile.file.as_str()));
    workflow::limits(acceptance, axis, evaluation, &given)
        .map_err(|error| ApiError::bad(error.to_string()))
}

/// The form's decision rule (`--decision`), simple acceptance unless sent.
fn decision(form: &Form) -> Result<Decision, ApiError> {
    match form.text("decision") {
        None => Ok(Decision::default()),
        Some(name) => Decision::from_name(name).ok_or_else(|| {
            ApiError::bad(format!(
                "decision: expected simple or iso14253-1, found {name:?}"
            ))
        }),
    }
}

fn file_label(files: &[Upload]) -> String {
    files
        .iter()
        .map(|(name, _)| name.display().to_string())
        .collect::<Vec<_>>()
        .join(" + ")
}

/// The SVG of the chart named `name` that the report draws for `input`, if it draws one.
fn svg_of(input: &ReportInput<'_>, name: &str) -> Result<Option<String>, ApiError> {
    let Some(named) = charts(input).into_iter().find(|c| c.name == name) else {
        return Ok(None);
    };
    let bytes = chart(&named.chart, PlotFormat::Svg)?;
    Ok(Some(String::from_utf8_lossy(&bytes).into_owned()))
}

fn report_input<'a>(
    before: &'a Test,
    after: Option<&'a Test>,
    table: Option<TableRecord<'a>>,
    diagnosis: Option<&'a Diagnosis>,
    standard: &'a dyn Standard,
    generator: &'a str,
) -> ReportInput<'a> {
    ReportInput {
        before: before.record(),
        after: after.map(Test::record),
        table,
        diagnosis,
        limits: &[],
        decision: Decision::default(),
        standard,
        angle: AngleUnit::default(),
        generator,
    }
}

#[derive(Serialize)]
struct EvaluateAnswer {
    /// `evaluate --json`'s object.
    evaluation: EvaluationJson,
    /// The report's deviation plot.
    deviation_svg: Option<String>,
}

async fn api_evaluate(multipart: Multipart) -> Result<axum::Json<EvaluateAnswer>, ApiError> {
    answer(multipart, |form| {
        let (measurement, mut warnings) = measurement(&form, "file")?;
        let standard = standard(&form)?;
        let profile = profile(&form)?;
        let evaluation = evaluate_with(&measurement, standard);
        let limits = limits(&form, &profile, measurement.axis(), &evaluation)?;
        let test = Test::new(measurement.clone(), warnings.clone(), standard, None)?;
        let evaluation = workflow::evaluation_report(
            &measurement,
            evaluation,
            &mut warnings,
            workflow::EvaluationReportOptions {
                exclude_runs: &[],
                limits: &limits,
                equipment: None,
                decision: decision(&form)?,
                angle: AngleUnit::default(),
            },
        )?;
        let input = report_input(&test, None, None, None, standard, "");
        Ok(EvaluateAnswer {
            evaluation,
            deviation_svg: svg_of(&input, "deviation")?,
        })
    })
    .await
    .map(axum::Json)
}

/// The table the page asks for: its bytes, its name, the JSON.
struct Table {
    converted: Converted,
    file_name: String,
    before: Test,
    controller: Controller,
}

/// A table that was active: the upload, its controller, the table, the
/// doubts about it and the test together.
type ActiveTable = (
    Upload,
    Controller,
    compensate::CompensationTable,
    Vec<Warning>,
);

/// The active table of the form's `table` field, read for `test`'s axis,
/// and the doubts about the two together (as `convert --existing` and
/// `report --table` read it).
fn active_table(
    form: &Form,
    test: &Measurement,
    test_label: String,
    profile: &MachineProfile,
    linuxcnc_type: Option<u8>,
) -> Result<Option<ActiveTable>, ApiError> {
    let Some((name, bytes)) = form.one_file("table")? else {
        return Ok(None);
    };
    let axis = recorded_axis(test)?;
    let mut options = EmitOptions::for_axis(profile, axis, "")?;
    options.linuxcnc_type = linuxcnc_type.unwrap_or(0);
    options.kind = test.kind();
    let (controller, table) = workflow::read_table(
        bytes,
        options,
        profile,
        test.metadata.length_unit,
        linuxcnc_type,
    )
    .map_err(|error| ApiError::bad(format!("{}:{error}", name.display())))?;
    let doubts = check_together(
        Pairing::TableOnTest,
        &Input::measurement(test, test_label),
        &Input::table(&table.axis, &table.positions_mm, name.display().to_string()),
    )?;
    Ok(Some((
        (name.clone(), bytes.clone()),
        controller,
        table,
        doubts,
    )))
}

fn recorded_axis(measurement: &Measurement) -> Result<&str, ApiError> {
    if measurement.axis_recorded() {
        return Ok(measurement.axis());
    }
    let file = measurement.metadata.source_file.as_ref().map_or_else(
        || "the measurement".to_string(),
        |p| p.display().to_string(),
    );
    Err(ApiError::bad(format!(
        "{file}: the file does not record which axis was measured; name it in the Axis field to say which axis the table is for"
    )))
}

/// `convert` for the form: the measurement of `field`, the table that was
/// active during it (`table`), the controller and grid.
fn table_of(form: &Form, field: &str, effects: &[Effect]) -> Result<Table, ApiError> {
    let profile = profile(form)?.machine;
    let (measurement, mut warnings) = measurement(form, field)?;
    let before = Test::new(measurement.clone(), warnings.clone(), standard(form)?, None)?;
    let axis = recorded_axis(&measurement)?.to_string();
    let controller_name = form.text("controller").unwrap_or("tnc640");
    let controller = Controller::from_name(controller_name)
        .ok_or_else(|| format!("unknown controller {controller_name:?}"))?;
    let file_name = controller.file_name(&axis);
    // The name inside Heidenhain files is the file name, upper case (as `convert -o`).
    let mut options = EmitOptions::for_axis(&profile, &axis, &file_name.to_uppercase())?;
    let linuxcnc_type: Option<u8> = form.number("linuxcnc_type", "0 or 1")?;
    if linuxcnc_type.is_some_and(|t| t > 1) {
        return Err(ApiError::bad("linuxcnc_type: expected 0 or 1"));
    }
    options.linuxcnc_type = linuxcnc_type.unwrap_or(0);
    options.machine_unit = profile.table_unit(controller, measurement.metadata.length_unit);
    options.kind = measurement.kind();
    let mut measurement = measurement;
    let label = file_label(form.files(field));
    let (existing, active) = match active_table(form, &measurement, label, &profile, linuxcnc_type)?
    {
        Some(((_, bytes), _, active, doubts)) => {
            warnings.extend(doubts);
            measurement = compensate::add_existing_table(&measurement, &active)?;
            (Some(bytes), Some(active))
        }
        None => (None, None),
    };
    let converted = workflow::convert(
        &measurement,
        &mut warnings,
        &TableRequest {
            controller,
            options: &options,
            request: &TableGrid {
                mode: form
                    .text("mode")
                    .map(TableMode::from_name)
                    .transpose()
                    .map_err(|e| format!("mode: {e}"))?,
                step_mm: form.number("step", "a number of mm")?,
                start_mm: form.number("start", "a number of mm")?,
                count: form.number("count", "a whole number of points")?,
                reference_mm: form.number("reference", "a number of mm")?,
                extrapolate: form
                    .text("extrapolate")
                    .map(Extrapolate::from_name)
                    .transpose()
                    .map_err(|e| format!("extrapolate: {e}"))?,
            },
            effects,
            existing: existing.as_deref(),
            active: active.as_ref(),
            output: file_name.clone(),
            file_name: file_name.clone(),
            also: Vec::new(),
        },
    )?;
    Ok(Table {
        converted,
        file_name,
        before,
        controller,
    })
}

#[derive(Serialize)]
struct ConvertAnswer {
    /// `convert --json`'s object.
    convert: ConvertJson,
    /// The name the download gets.
    file_name: String,
    /// The file as text, for the preview.
    text: String,
    /// The report's plot of the table.
    table_svg: Option<String>,
}

fn convert_answer(table: &Table) -> Result<ConvertAnswer, ApiError> {
    let text = match emit::decode_table(&table.converted.bytes) {
        Ok((text, _)) => text,
        Err(_) => String::from_utf8_lossy(&table.converted.bytes).into_owned(),
    };
    let record = TableRecord {
        table: &table.converted.table,
        file: &table.file_name,
        controller: table.controller,
    };
    let input = report_input(
        &table.before,
        None,
        Some(record),
        None,
        &evaluate::ISO_230_2,
        "",
    );
    Ok(ConvertAnswer {
        convert: table.converted.report.clone(),
        file_name: table.file_name.clone(),
        text,
        table_svg: svg_of(&input, "table")?,
    })
}

async fn api_convert(multipart: Multipart) -> Result<axum::Json<ConvertAnswer>, ApiError> {
    answer(multipart, |form| {
        convert_answer(&table_of(&form, "file", &[])?)
    })
    .await
    .map(axum::Json)
}

/// A download: the bytes under `name`.
fn attachment(name: &str, content_type: &'static str, bytes: Vec<u8>) -> Response {
    let mut headers = HeaderMap::new();
    headers.insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    // The names are ASCII (`X.COM`, `ALX`, `report.html`) but an axis
    // name comes from a file: anything else is given percent-encoded too.
    let ascii: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() && c != '"' && c != '\\' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let encoded: String = name
        .bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'.' | b'-' | b'_' => (b as char).to_string(),
            _ => format!("%{b:02X}"),
        })
        .collect();
    let disposition = format!("attachment; filename=\"{ascii}\"; filename*=UTF-8''{encoded}");
    if let Ok(value) = HeaderValue::from_str(&disposition) {
        headers.insert(header::CONTENT_DISPOSITION, value);
    }
    (headers, bytes).into_response()
}

async fn api_table(multipart: Multipart) -> Result<Response, ApiError> {
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
/// (read back, so the numbers are the file's), with the diagnosis.
fn next_table(form: &Form) -> Result<(Retest, Table), ApiError> {
    let retest = retest(form)?;
    let effects = read_effects(&retest.effects_toml)
        .map_err(|error| ApiError::bad(format!("the effects file:{error}")))?;
    let table = table_of(form, "after", &effects)?;
    Ok((retest, table))
}

/// The re-test (`after`) against the first test (`file`) and the table
/// that was active (`table`), as `diagnose --after AFTER --before FILE
/// --table TABLE` sees them.
struct Retest {
    before: Test,
    after: Test,
    diagnosis: Diagnosis,
    /// `diagnose --json`'s object.
    report: DiagnoseJson,
    /// What `diagnose --write-effects` writes.
    effects_toml: String,
}

fn retest(form: &Form) -> Result<Retest, ApiError> {
    let standard = standard(form)?;
    let (before, before_warnings) = measurement(form, "file")?;
    let (after, mut after_warnings) = measurement(form, "after")?;
    for test in [&before, &after] {
        if test.kind() == AxisKind::Rotary {
            return Err(ApiError::bad(format!(
                "axis {} is a rotary axis: the diagnosis is for linear axes only so far",
                test.axis()
            )));
        }
    }
    let before_label = file_label(form.files("file"));
    let after_label = file_label(form.files("after"));
    after_warnings.extend(check_together(
        Pairing::BeforeAfter,
        &Input::measurement(&before, before_label.clone()),
        &Input::measurement(&after, after_label.clone()),
    )?);
    let linuxcnc_type = form.number("linuxcnc_type", "0 or 1")?;
    let profile = profile(form)?.machine;
    let known_periods = workflow::known_periods(&profile, &after);
    // The table was active during the re-test.
    let table = active_table(form, &after, after_label.clone(), &profile, linuxcnc_type)?;
    if let Some((_, _, _, doubts)) = &table {
        after_warnings.extend(doubts.iter().cloned());
    }
    let diagnosis = diagnose(&DiagnoseInput {
        angle: Default::default(),
        after: &after,
        before: Some(&before),
        table: table.as_ref().map(|(_, _, t, _)| t),
        backlash_set: false,
        angular: None,
        timing: CycleTiming::ASSUMED,
        standard,
        known_periods: &known_periods,
    })?;
    let report = DiagnoseJson::new(
        &diagnosis,
        after_label.clone(),
        Some(before_label),
        table
            .as_ref()
            .map(|((name, _), ..)| name.display().to_string()),
        AngleUnit::default(),
    );
    Ok(Retest {
        effects_toml: diagnosis.effects_file(&after_label),
        report,
        diagnosis,
        before: Test::new(before, before_warnings, standard, None)?,
        after: Test::new(after, after_warnings, standard, None)?,
    })
}

#[derive(Serialize)]
struct RetestAnswer {
    /// `diagnose --json`'s object.
    diagnosis: DiagnoseJson,
    /// What `diagnose --write-effects` writes.
    effects_toml: String,
    /// The report's plot of the residual.
    residual_svg: Option<String>,
    /// The next table (`convert AFTER --existing TABLE --effects E.toml`), when a table was given.
    next: Option<ConvertAnswer>,
    /// Every warning of the two tests, as `diagnose` prints them: the
    /// readers', the evaluations' and the doubts of the pair, each naming its file.
    warnings: Vec<String>,
}

async fn api_retest(multipart: Multipart) -> Result<axum::Json<RetestAnswer>, ApiError> {
    answer(multipart, |form| {
        let (retest, next) = match form.one_file("table")? {
            Some(_) => {
                let (retest, table) = next_table(&form)?;
                (retest, Some(table))
            }
            None => (retest(&form)?, None),
        };
        let standard = standard(&form)?;
        let input = report_input(
            &retest.before,
            Some(&retest.after),
            None,
            Some(&retest.diagnosis),
            standard,
            "",
        );
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
            residual_svg: svg_of(&input, "residual")?,
            next: next.as_ref().map(convert_answer).transpose()?,
            diagnosis: retest.report,
            effects_toml: retest.effects_toml,
        })
    })
    .await
    .map(axum::Json)
}

/// `axcomp report FILE [--after AFTER] [--table TABLE] [--diagnose]`.
async fn api_report(multipart: Multipart) -> Result<Response, ApiError> {
    answer(multipart, |form| {
        let standard = standard(&form)?;
        let (measurement, warnings) = measurement(&form, "file")?;
        let mut before = Test::new(measurement, warnings, standard, None)?;
        let label = file_label(form.files("file"));
        let after = match form.files("after") {
            [] => None,
            files => {
                let (measurement, warnings) = self::measurement(&form, "after")?;
                let mut after = Test::new(measurement, warnings, standard, None)?;
                after.warnings.extend(check_together(
                    Pairing::BeforeAfter,
                    &Input::measurement(&before.measurement, label.clone()),
                    &Input::measurement(&after.measurement, file_label(files)),
                )?);
                Some(after)
            }
        };
        let profile = self::profile(&form)?;
        let limits = limits(
            &form,
            &profile,
            before.measurement.axis(),
            &before.evaluation,
        )?;
        if before.measurement.kind() == AxisKind::Rotary && !limits.is_empty() {
            return Err(workflow::WorkflowError::RotaryLimits {
                axis: before.measurement.axis().to_string(),
            }
            .into());
        }
        let table = active_table(&form, &before.measurement, label, &profile.machine, None)?;
        if let Some((_, _, _, doubts)) = &table {
            before.warnings.extend(doubts.iter().cloned());
        }
        let diagnosis = match (&after, form.text("diagnose")) {
            (Some(after), Some(_)) => Some(diagnose(&DiagnoseInput {
                angle: Default::default(),
                after: &after.measurement,
                before: Some(&before.measurement),
                table: table.as_ref().map(|(_, _, t, _)| t),
                backlash_set: false,
                angular: None,
                timing: CycleTiming::ASSUMED,
                standard,
                known_periods: &[],
            })?),
            _ => None,
        };
        let names: Vec<String> = table
            .iter()
            .map(|((name, _), ..)| name.display().to_string())
            .collect();
        let record = table
            .as_ref()
            .zip(names.first())
            .map(|((_, controller, table, _), file)| TableRecord {
                table,
                file,
                controller: *controller,
            });
        let generator = format!(
            "axcomp {} on {}",
            env!("CARGO_PKG_VERSION"),
            chrono::Local::now().format("%Y-%m-%d %H:%M")
        );
        let mut input = report_input(
            &before,
            after.as_ref(),
            record,
            diagnosis.as_ref(),
            standard,
            &generator,
        );
        input.limits = &limits;
        input.decision = decision(&form)?;
        let page = html::render(&input)?;
        Ok(attachment(
            "report.html",
            "text/html; charset=utf-8",
            page.into_bytes(),
        ))
    })
    .await
}

/// Where the app is, for the message and the browser.
pub fn url(addr: SocketAddr) -> String {
    let host = match addr.ip() {
        ip if ip.is_unspecified() => "127.0.0.1".to_string(),
        std::net::IpAddr::V6(ip) => format!("[{ip}]"),
        ip => ip.to_string(),
    };
    format!("http://{host}:{}/", addr.port())
}
