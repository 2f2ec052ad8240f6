//! What the tests reach over a socket: chromedriver (WebDriver is JSON over
//! HTTP, `browser::WebDriver`, the `system` target) and the one test of
//! `axcomp serve` started as a process, through ureq; the web app's API is
//! tested in process (`server::App`). And the `multipart/form-data` body a
//! browser's `FormData` sends (axum-test's).

use std::time::Duration;

use axum_test::multipart::{MultipartForm, Part};

/// A response: status, headers (names lower case), body.
pub struct Response {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

impl Response {
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == &name.to_ascii_lowercase())
            .map(|(_, v)| v.as_str())
    }

    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }

    pub fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.text()))
    }
}

/// Sends one request to `host` (`127.0.0.1:PORT`) and reads the whole
/// answer, whatever its status (a refusal is an answer to check, not an error).
pub fn request(
    host: &str,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: Vec<u8>,
) -> Response {
    let url = format!("http://{host}{path}");
    let agent: ureq::Agent = ureq::Agent::config_builder()
        .http_status_as_error(false)
        .timeout_global(Some(Duration::from_secs(120)))
        .build()
        .into();
    let mut builder = ureq::http::Request::builder().method(method).uri(&url);
    for (name, value) in headers {
        builder = builder.header(*name, *value);
    }
    let request = builder.body(body).expect("a well-formed request");
    let mut response = agent
        .run(request)
        .unwrap_or_else(|e| panic!("{method} {url}: {e}"));
    let headers = response
        .headers()
        .iter()
        .map(|(name, value)| {
            let value = String::from_utf8_lossy(value.as_bytes()).into_owned();
            (name.as_str().to_string(), value)
        })
        .collect();
    let body = response
        .body_mut()
        .with_config()
        .read_to_vec()
        .unwrap_or_else(|e| panic!("{method} {url}: reading the answer: {e}"));
    Response {
        status: response.status().as_u16(),
        headers,
        body,
    }
}

/// A `multipart/form-data` body, as a browser's `FormData` sends it: a
/// file part is `application/octet-stream` with its file name, a text part
/// plain. Built by axum-test's form builder, for the app in process
/// (`server::App::post`).
pub struct Form(MultipartForm);

impl Form {
    pub fn new() -> Form {
        Form(MultipartForm::new())
    }

    pub fn text(self, name: &str, value: &str) -> Form {
        Form(self.0.add_text(name, value))
    }

    pub fn file(self, name: &str, file_name: &str, bytes: &[u8]) -> Form {
        Form(
            self.0
                .add_part(name, Part::bytes(bytes.to_vec()).file_name(file_name)),
        )
    }

    /// The content type (with the boundary) and the body.
    pub fn finish(self) -> (String, axum::body::Body) {
        (self.0.content_type(), self.0.into())
    }
}
