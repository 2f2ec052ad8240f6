//! The web app's thermal page, `/thermal`: a thermal log (and a model, or
//! the rows and sensors to fit one on) uploaded, the ISO 230-3 view, the
//! fit and the plots shown, as `report --thermal` shows them.
//!
//! `GET` is the form; `POST` (multipart: `log`, optional `model`, `drift`,
//! `sample_interval`, `rows`, `sensors`, `reference` (a sensor or `auto`),
//! `validation` (`blocked` or `forward`), `test` (the ISO 230-3 test type:
//! `etve`, `spindle`, `linear-axis`), the names `thermal fit` and `report
//! --thermal-test` take) answers the same page with the thermal section
//! below the form and, when it fitted one, the model file `thermal fit`
//! writes; or a 400 whose message is the CLI's (`LOG.csv:line:col: …`).
//! Plain HTML, no script: the work is `workflow::thermal::study_text`, this
//! file only reads the form and answers.

use axum::extract::Multipart;
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};

use crate::report::format::esc;
use crate::report::thermal::{model_file_html, page_html, section_html};
use crate::thermal::{self, ThermalModel};
use crate::workflow::thermal::{self as workflow, FitRequest, StudyRequest, study_text};

/// The fields the form sends.
#[derive(Debug, Default)]
struct ThermalForm {
    log: Option<(String, Vec<u8>)>,
    model: Option<(String, Vec<u8>)>,
    drift: Option<String>,
    sample_interval: Option<String>,
    rows: Option<String>,
    sensors: Option<String>,
    reference: Option<String>,
    validation: Option<String>,
    test: Option<String>,
}

fn generator() -> String {
    format!("axcomp {}", env!("CARGO_PKG_VERSION"))
}

fn html(status: StatusCode, body: &str) -> Response {
    (
        status,
        [
            (header::CONTENT_TYPE, "text/html; charset=utf-8"),
            (header::CACHE_CONTROL, "no-store"),
        ],
        page_html(body, &generator()),
    )
        .into_response()
}

fn refused(message: &str) -> Response {
    html(
        StatusCode::BAD_REQUEST,
        &format!("<p class=\"error\" id=\"error\">{}</p>\n", esc(message)),
    )
}

/// `GET /thermal`: the form.
pub async fn form() -> Response {
    html(StatusCode::OK, "")
}

/// `POST /thermal`: the log studied.
pub async fn submit(multipart: Multipart) -> Response {
    let form = match read_form(multipart).await {
        Ok(form) => form,
        Err(message) => return refused(&message),
    };
    let answer = tokio::task::spawn_blocking(move || work(&form)).await;
    match answer {
        Ok(Ok(section)) => html(StatusCode::OK, &section),
        Ok(Err(message)) => refused(&message),
        Err(error) => html(
            StatusCode::INTERNAL_SERVER_ERROR,
            &format!("<p class=\"error\">{}</p>", esc(&error.to_string())),
        ),
    }
}

async fn read_form(mut multipart: Multipart) -> Result<ThermalForm, String> {
    let mut form = ThermalForm::default();
    while let Some(field) = multipart.next_field().await.map_err(|e| e.body_text())? {
        let name = field.name().unwrap_or_default().to_string();
        // A file is named by its base name only: no path a client names is opened.
        let file_name = field
            .file_name()
            .map(|n| n.rsplit(['/', '\\']).next().unwrap_or_default().to_string());
        let bytes = field.bytes().await.map_err(|e| e.body_text())?.to_vec();
        let text = || String::from_utf8_lossy(&bytes).trim().to_string();
        let slot = match name.as_str() {
            "log" | "model" => {
                if bytes.is_empty() {
                    continue;
                }
                let file = Some((file_name.unwrap_or_else(|| name.clone()), bytes.clone()));
                if name == "log" {
                    form.log = file;
                } else {
                    form.model = file;
                }
                continue;
            }
            "drift" => &mut form.drift,
            "sample_interval" => &mut form.sample_interval,
            "rows" => &mut form.rows,
            "sensors" => &mut form.sensors,
            "reference" => &mut form.reference,
            "validation" => &mut form.validation,
            "test" => &mut form.test,
            other => return Err(format!("unknown form field {other:?}")),
        };
        let value = text();
        if !value.is_empty() {
            *slot = Some(value);
        }
    }
    Ok(form)
}

fn utf8<'a>(name: &str, bytes: &'a [u8]) -> Result<&'a str, String> {
    std::str::from_utf8(bytes).map_err(|e| format!("{name}: expected UTF-8 text ({e})"))
}

fn work(form: &ThermalForm) -> Result<String, String> {
    let (log_name, log_bytes) = form
        .log
        .as_ref()
        .ok_or("no thermal log: choose the log's CSV file")?;
    let model = match &form.model {
        Some((name, bytes)) => {
            Some(ThermalModel::from_toml(utf8(name, bytes)?).map_err(|e| format!("{name}:{e}"))?)
        }
        None => None,
    };
    let sample_interval_s = form
        .sample_interval
        .as_deref()
        .map(|s| {
            s.parse::<f64>()
                .map_err(|_| format!("seconds between rows: expected a number, found {s:?}"))
        })
        .transpose()?;
    let list = |text: &Option<String>| -> Vec<String> {
        text.iter()
            .flat_map(|t| t.split(','))
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect()
    };
    let validation = form
        .validation
        .as_deref()
        .map(|name| workflow::validation(name).map_err(|e| format!("cross-validation: {e}")))
        .transpose()?;
    let test_type = form
        .test
        .as_deref()
        .map(|name| workflow::test_type(name).map_err(|e| format!("ISO 230-3 test: {e}")))
        .transpose()?;
    let given = model.is_some();
    let request = StudyRequest {
        drift: form.drift.clone(),
        sample_interval_s,
        test_type,
        model,
        fit: FitRequest {
            rows: form.rows.clone(),
            sensors: list(&form.sensors),
            reference: form.reference.clone(),
            validation,
            ..Default::default()
        },
    };
    let study = study_text(utf8(log_name, log_bytes)?, request).map_err(|e| match e {
        thermal::ThermalError::Parse(p) => format!("{log_name}:{p}"),
        other => format!("{log_name}: {other}"),
    })?;
    let mut html = section_html(&study, None).map_err(|e| e.to_string())?;
    if let Some(fitted) = study.model.as_ref().filter(|_| !given) {
        html.push_str(&model_file_html(fitted));
    }
    Ok(html)
}
