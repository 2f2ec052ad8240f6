//! A plain HTTP/1.1 client over `TcpStream`, for what the tests reach over
//! a socket: chromedriver (WebDriver is JSON over HTTP, `browser::WebDriver`,
//! the `system` target) and the one test of `axcomp serve` started as a
//! process; the web app's API is tested in process (`server::App`). And the
//! `multipart/form-data` body a browser's `FormData` sends (axum-test's).
//!
//! Why not a crate: a WebDriver crate (fantoccini, thirtyfour) or an HTTP
//! client (reqwest) brings an async client stack with TLS into the test
//! build for a handful of requests to 127.0.0.1 with `Connection: close`.

use std::io::{Read, Write};
use std::net::TcpStream;
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

/// Sends one request to `host` (`127.0.0.1:PORT`) and reads the whole answer.
/// `headers` may set `Host` (else it is `host`). The body is written from
/// another thread, so that a server that answers before reading it all
/// (a refused upload) is heard rather than deadlocked.
pub fn request(
    host: &str,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: Vec<u8>,
) -> Response {
    let mut stream = TcpStream::connect(host).unwrap_or_else(|e| panic!("connect {host}: {e}"));
    stream
        .set_read_timeout(Some(Duration::from_secs(120)))
        .unwrap();
    let mut head = format!("{method} {path} HTTP/1.1\r\n");
    if !headers.iter().any(|(n, _)| n.eq_ignore_ascii_case("host")) {
        head.push_str(&format!("Host: {host}\r\n"));
    }
    for (name, value) in headers {
        head.push_str(&format!("{name}: {value}\r\n"));
    }
    head.push_str(&format!(
        "Content-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    ));
    stream.write_all(head.as_bytes()).unwrap();
    let mut writer = stream.try_clone().unwrap();
    // A server that refuses the body closes the connection: the writer's error is expected then.
    let sending = std::thread::spawn(move || writer.write_all(&body).is_ok());
    let raw = read_answer(&mut stream);
    let _ = sending.join();
    if raw.is_empty() {
        panic!("no answer from {host}{path}");
    }
    parse(&raw)
}

/// Reads one answer: up to its `Content-Length`, or its last chunk, or the
/// end of the connection (some servers keep it open despite `Connection: close`).
fn read_answer(stream: &mut TcpStream) -> Vec<u8> {
    let mut raw = Vec::new();
    let mut buffer = [0u8; 64 * 1024];
    loop {
        if let Some(end) = raw.windows(4).position(|w| w == b"\r\n\r\n") {
            let head = String::from_utf8_lossy(&raw[..end]).to_ascii_lowercase();
            let length = head
                .lines()
                .find_map(|l| l.strip_prefix("content-length:"))
                .and_then(|v| v.trim().parse::<usize>().ok());
            let complete = match length {
                Some(length) => raw.len() >= end + 4 + length,
                None if head.contains("transfer-encoding: chunked") => raw.ends_with(b"0\r\n\r\n"),
                None => false,
            };
            if complete {
                return raw;
            }
        }
        match stream.read(&mut buffer) {
            Ok(0) | Err(_) => return raw,
            Ok(n) => raw.extend_from_slice(&buffer[..n]),
        }
    }
}

fn parse(raw: &[u8]) -> Response {
    let end = raw
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("a complete header");
    let head = String::from_utf8_lossy(&raw[..end]).into_owned();
    let mut lines = head.split("\r\n");
    let status = lines
        .next()
        .and_then(|l| l.split(' ').nth(1))
        .and_then(|s| s.parse().ok())
        .expect("a status line");
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(n, v)| (n.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let mut body = raw[end + 4..].to_vec();
    let chunked = headers
        .iter()
        .any(|(n, v)| n == "transfer-encoding" && v.eq_ignore_ascii_case("chunked"));
    if chunked {
        body = dechunk(&body);
    }
    Response {
        status,
        headers,
        body,
    }
}

fn dechunk(mut raw: &[u8]) -> Vec<u8> {
    let mut body = Vec::new();
    loop {
        let line_end = raw
            .windows(2)
            .position(|w| w == b"\r\n")
            .expect("chunk size");
        let size_text = String::from_utf8_lossy(&raw[..line_end]);
        let size = usize::from_str_radix(size_text.split(';').next().unwrap().trim(), 16)
            .expect("hex chunk size");
        raw = &raw[line_end + 2..];
        if size == 0 {
            return body;
        }
        body.extend_from_slice(&raw[..size]);
        raw = &raw[size + 2..];
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
