//! What the app answers: the JSON objects the page shows (each the CLI's
//! own object with the plots beside it) and the downloads.

use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::{IntoResponse, Response};
use percent_encoding::{AsciiSet, NON_ALPHANUMERIC, utf8_percent_encode};
use serde::Serialize;

use crate::emit;
use crate::report::acceptance::{ReportInput, TableRecord, charts};
use crate::report::chart::chart;
use crate::report::convert::ConvertJson;
use crate::report::diagnose::DiagnoseJson;
use crate::report::json::EvaluationJson;
use crate::report::plot::PlotFormat;
use crate::workflow::report::{Report, ReportParts};
use crate::workflow::{Converted, Test};
use crate::{emit::Controller, evaluate};

use super::error::ApiError;

/// What the page offers to choose from.
#[derive(Serialize)]
pub struct OptionsJson {
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

impl OptionsJson {
    /// The controllers, the standards, the upload limit and the version.
    pub fn new(upload_limit_bytes: usize) -> OptionsJson {
        OptionsJson {
            controllers: Controller::ALL.iter().map(|c| c.name()).collect(),
            standards: evaluate::SUPPORTED
                .iter()
                .map(|s| StandardJson {
                    key: s.key(),
                    name: s.name(),
                })
                .collect(),
            upload_limit_bytes,
            version: env!("CARGO_PKG_VERSION"),
        }
    }
}

/// The SVG of the chart named `name` that the report draws for `input`, if it draws one.
pub fn svg_of(input: &ReportInput<'_>, name: &str) -> Result<Option<String>, ApiError> {
    let Some(named) = charts(input).into_iter().find(|c| c.name == name) else {
        return Ok(None);
    };
    let bytes = chart(&named.chart, PlotFormat::Svg)?;
    Ok(Some(String::from_utf8_lossy(&bytes).into_owned()))
}

/// `/api/evaluate`'s answer.
#[derive(Serialize)]
pub struct EvaluateAnswer {
    /// `evaluate --json`'s object.
    pub evaluation: EvaluationJson,
    /// The report's deviation plot.
    pub deviation_svg: Option<String>,
}

/// The table the page asks for: its bytes, its name, the JSON.
pub struct Table {
    /// The workflow's table.
    pub converted: Converted,
    /// The name the download gets.
    pub file_name: String,
    /// The test it was made from, for its plot.
    pub before: Test,
    /// The controller.
    pub controller: Controller,
}

/// `/api/convert`'s answer (and the next table of `/api/retest`).
#[derive(Serialize)]
pub struct ConvertAnswer {
    /// `convert --json`'s object.
    convert: ConvertJson,
    /// The name the download gets.
    file_name: String,
    /// The file as text, for the preview.
    text: String,
    /// The report's plot of the table.
    table_svg: Option<String>,
}

impl ConvertAnswer {
    /// The answer for `table`.
    pub fn new(table: &Table) -> Result<ConvertAnswer, ApiError> {
        let text = match emit::decode_table(&table.converted.bytes) {
            Ok((text, _)) => text,
            Err(_) => String::from_utf8_lossy(&table.converted.bytes).into_owned(),
        };
        let report = Report::new(ReportParts {
            table: Some(TableRecord {
                table: &table.converted.table,
                file: &table.file_name,
                controller: table.controller,
            }),
            ..ReportParts::of(&table.before, &evaluate::ISO_230_2)
        });
        Ok(ConvertAnswer {
            convert: table.converted.report.clone(),
            file_name: table.file_name.clone(),
            text,
            table_svg: svg_of(&report.input(), "table")?,
        })
    }
}

/// `/api/retest`'s answer.
#[derive(Serialize)]
pub struct RetestAnswer {
    /// `diagnose --json`'s object.
    pub diagnosis: DiagnoseJson,
    /// What `diagnose --write-effects` writes (`null` where it writes none: a rotary axis).
    pub effects_toml: Option<String>,
    /// The report's plot of the residual (`null` where the report has none: a rotary axis).
    pub residual_svg: Option<String>,
    /// The next table (`convert AFTER --existing TABLE --effects E.toml`), when a table was given.
    pub next: Option<ConvertAnswer>,
    /// Every warning of the two tests, as `diagnose` prints them: the
    /// readers', the evaluations' and the doubts of the pair, each naming its file.
    pub warnings: Vec<String>,
}

/// What a file name keeps in `filename*` (RFC 5987's attr-char less a few):
/// letters, digits and `.-_`; everything else is percent-encoded.
const FILE_NAME: &AsciiSet = &NON_ALPHANUMERIC.remove(b'.').remove(b'-').remove(b'_');

/// A download: the bytes under `name`.
pub fn attachment(name: &str, content_type: &'static str, bytes: Vec<u8>) -> Response {
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
    let encoded = utf8_percent_encode(name, FILE_NAME);
    let disposition = format!("attachment; filename=\"{ascii}\"; filename*=UTF-8''{encoded}");
    if let Ok(value) = HeaderValue::from_str(&disposition) {
        headers.insert(header::CONTENT_DISPOSITION, value);
    }
    (headers, bytes).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_name_is_percent_encoded_in_utf8() {
        let response = attachment("X ä.COM", "application/octet-stream", Vec::new());
        let disposition = response.headers()[header::CONTENT_DISPOSITION]
            .to_str()
            .unwrap()
            .to_string();
        // ä is U+00E4, C3 A4 in UTF-8 (RFC 3629); the space is 20.
        assert_eq!(
            disposition,
            "attachment; filename=\"X__.COM\"; filename*=UTF-8''X%20%C3%A4.COM"
        );
    }
}
