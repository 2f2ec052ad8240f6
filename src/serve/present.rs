//! What the app answers: the JSON objects the page shows
//! (`report::web`, each the CLI's own object with the plots beside it)
//! filled in, and the downloads.

use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::{IntoResponse, Response};
use percent_encoding::{AsciiSet, NON_ALPHANUMERIC, utf8_percent_encode};

use crate::emit::{self, Controller};
use crate::evaluate;
use crate::report::acceptance::{ReportInput, TableRecord, charts};
use crate::report::chart::chart;
use crate::report::plot::PlotFormat;
use crate::report::web::{ConvertAnswer, RescaledAnswer};
use crate::workflow::report::{Report, ReportParts};
use crate::workflow::{Converted, Test};

use super::error::ApiError;

/// The SVG of the chart named `name` that the report draws for `input`, if it draws one.
pub fn svg_of(input: &ReportInput<'_>, name: &str) -> Result<Option<String>, ApiError> {
    let Some(named) = charts(input).into_iter().find(|c| c.name == name) else {
        return Ok(None);
    };
    let bytes = chart(&named.chart, PlotFormat::Svg)?;
    Ok(Some(String::from_utf8_lossy(&bytes).into_owned()))
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

/// The answer for `table`: `convert --json`, the file's text, the table's plot.
pub fn convert_answer(table: &Table) -> Result<ConvertAnswer, ApiError> {
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
        fanuc_rescaled: table
            .converted
            .rescaled
            .as_ref()
            .map(|fine| RescaledAnswer::new(&table.file_name, fine)),
    })
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
