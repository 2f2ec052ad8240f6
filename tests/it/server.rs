//! A running `axcomp serve` for the tests of the web app, and the CLI run
//! beside it. Shared by both test targets.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use crate::http::{Form, Response, request};
use crate::util::root;

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

    /// A POST of `form` to `path` with extra `headers`.
    pub fn post(&self, path: &str, form: Form, headers: &[(&str, &str)]) -> Response {
        let (content_type, body) = form.finish();
        let mut all = vec![("Content-Type", content_type.as_str())];
        all.extend_from_slice(headers);
        request(&self.host, "POST", path, &all, body)
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
