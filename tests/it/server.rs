//! The web app for its tests: in process ([`App`], the axum router called
//! through tower's `oneshot`, no socket), or a running `axcomp serve`
//! ([`Server`], for the browser and the test of the server start itself);
//! and the CLI run beside it. Shared by both test targets.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use tower::ServiceExt;

use crate::http::{Form, Response};
use crate::util::root;

/// The app in process, as `axcomp serve` answers on 127.0.0.1:8230: each
/// request goes through the whole router (the origin guard, the upload
/// limit, the handlers) by `oneshot`, on a runtime of its own.
pub struct App {
    router: axum::Router,
    runtime: tokio::runtime::Runtime,
    /// `127.0.0.1:PORT`, the name requests use unless they set `Host`.
    pub host: String,
}

impl App {
    pub fn new() -> App {
        let addr: std::net::SocketAddr = "127.0.0.1:8230".parse().unwrap();
        App {
            router: axcomp::serve::app(addr),
            runtime: tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .unwrap(),
            host: addr.to_string(),
        }
    }

    pub fn url(&self) -> String {
        format!("http://{}/", self.host)
    }

    /// A POST of `form` to `path` with extra `headers`.
    pub fn post(&self, path: &str, form: Form, headers: &[(&str, &str)]) -> Response {
        let (content_type, body) = form.finish();
        // Whole, as a browser sends a form (its length known).
        let body = self
            .runtime
            .block_on(axum::body::to_bytes(body, usize::MAX))
            .unwrap()
            .to_vec();
        let mut all = vec![("Content-Type", content_type.as_str())];
        all.extend_from_slice(headers);
        self.request("POST", path, &all, body)
    }

    /// A GET of `path` with `headers`.
    pub fn get(&self, path: &str, headers: &[(&str, &str)]) -> Response {
        self.request("GET", path, headers, Vec::new())
    }

    fn request(
        &self,
        method: &str,
        path: &str,
        headers: &[(&str, &str)],
        body: Vec<u8>,
    ) -> Response {
        let mut request = axum::http::Request::builder().method(method).uri(path);
        if !headers.iter().any(|(n, _)| n.eq_ignore_ascii_case("host")) {
            request = request.header("Host", &self.host);
        }
        for (name, value) in headers {
            request = request.header(*name, *value);
        }
        let request = request.body(axum::body::Body::from(body)).unwrap();
        self.runtime.block_on(async {
            let response = self.router.clone().oneshot(request).await.unwrap();
            let status = response.status().as_u16();
            let headers = response
                .headers()
                .iter()
                .map(|(n, v)| (n.as_str().to_string(), v.to_str().unwrap_or("").to_string()))
                .collect();
            let body = axum::body::to_bytes(response.into_body(), usize::MAX)
                .await
                .unwrap()
                .to_vec();
            Response {
                status,
                headers,
                body,
            }
        })
    }
}

/// A running `axcomp serve --port 0 --no-open`, stopped when dropped.
pub struct Server {
    child: Child,
    /// `127.0.0.1:PORT`.
    pub host: String,
}

impl Server {
    pub fn start() -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_axcomp"))
            .args(["serve", "--port", "0", "--no-open"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start axcomp serve");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        // "axcomp serve: http://127.0.0.1:PORT/ (Ctrl-C stops it)"
        let host = line
            .split("http://")
            .nth(1)
            .and_then(|rest| rest.split('/').next())
            .unwrap_or_else(|| panic!("no address in {line:?}"))
            .to_string();
        assert!(host.starts_with("127.0.0.1:"), "{line}");
        Server { child, host }
    }

    pub fn url(&self) -> String {
        format!("http://{}/", self.host)
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub fn sample() -> PathBuf {
    root().join("fixtures/sample-x.rtl")
}

pub fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Runs the CLI in `dir` (so that a file named by its base name is shown
/// as the app shows an upload) and returns its stdout.
pub fn cli_in(dir: &Path, args: &[&str]) -> Vec<u8> {
    let output = Command::new(env!("CARGO_BIN_EXE_axcomp"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "axcomp {args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output.stdout
}
