//! Opening pages in a real browser (Debian's chromium, headless) for the
//! report and demo pages; driving a page over WebDriver (chromedriver) for
//! the web app (`web_page.rs`). Screenshots are read with `crate::pixels`.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus};
use std::time::{Duration, Instant};

use base64::Engine as _;

/// Debian's chromium; `scripts/test` installs it. Missing is a failure, not a skip.
pub fn chromium() -> PathBuf {
    crate::program_on_path(
        &["chromium", "chromium-browser"],
        "the report is tested in a real browser; install Debian's chromium (apt-get install \
         chromium), or run the tests with scripts/test, which installs it",
    )
}

/// What the browser made of a page.
pub struct BrowserRun {
    /// The DOM after loading (`--dump-dom`).
    pub dom: String,
    /// Console messages (`:CONSOLE` log lines): the report has no script, so any is an error.
    pub console: Vec<String>,
}

/// Opens a local page headless, with the network and background services
/// off, and takes a screenshot of `window` pixels (or prints a PDF).
pub fn open_in_browser(page: &Path, window: (u32, u32), output: BrowserOutput<'_>) -> BrowserRun {
    let profile = tempfile::tempdir().unwrap();
    let mut command = Command::new(chromium());
    command.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--enable-logging=stderr",
        "--v=0",
    ]);
    command.arg(format!("--user-data-dir={}", profile.path().display()));
    command.arg(format!("--window-size={},{}", window.0, window.1));
    match output {
        BrowserOutput::Screenshot(path) => {
            command.arg(format!("--screenshot={}", path.display()));
            command.arg("--dump-dom");
        }
        BrowserOutput::Pdf(path) => {
            command.arg("--no-pdf-header-footer");
            command.arg(format!("--print-to-pdf={}", path.display()));
        }
    }
    command.arg(format!("file://{}", page.canonicalize().unwrap().display()));
    // Into files, not pipes: a DOM larger than a pipe's buffer would block
    // chromium until someone reads it.
    let stdout_path = profile.path().join("stdout");
    let stderr_path = profile.path().join("stderr");
    let child = command
        .stdout(std::fs::File::create(&stdout_path).unwrap())
        .stderr(std::fs::File::create(&stderr_path).unwrap())
        .spawn()
        .expect("start chromium");
    let status = wait_with_timeout(child, Duration::from_secs(120), "chromium");
    let stderr = std::fs::read_to_string(&stderr_path).unwrap_or_default();
    assert!(status.success(), "chromium failed: {stderr}");
    BrowserRun {
        dom: std::fs::read_to_string(&stdout_path).unwrap(),
        console: stderr
            .lines()
            .filter(|l| l.contains(":CONSOLE"))
            .map(str::to_string)
            .collect(),
    }
}

#[derive(Clone, Copy)]
pub enum BrowserOutput<'a> {
    Screenshot(&'a Path),
    Pdf(&'a Path),
}

/// Waits for a child (`what`), killing it after `limit` (a hung browser or
/// Wine must not hang the tests).
pub fn wait_with_timeout(
    mut child: std::process::Child,
    limit: Duration,
    what: &str,
) -> ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{what} did not finish within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Debian's chromedriver (package `chromium-driver`; `scripts/test`
/// installs it). Missing is a failure, not a skip.
pub fn chromedriver() -> PathBuf {
    crate::program_on_path(
        &["chromedriver"],
        "the web app is tested in a real browser; install Debian's chromium-driver (apt-get \
         install chromium-driver), or run the tests with scripts/test, which installs it",
    )
}

/// Headless Chromium driven over WebDriver (W3C, JSON over HTTP through
/// `http::request`, ureq): a page that runs scripts, takes uploads and saves
/// downloads, as the engineer's browser does. The `--screenshot` runs of
/// [`open_in_browser`] cannot click; this can.
pub struct WebDriver {
    driver: std::process::Child,
    host: String,
    session: String,
    /// The browser's process: ended with the driver (chromedriver leaves it
    /// running when killed, and ending the session politely can hang).
    browser_pid: Option<u64>,
    /// Where the browser saves downloads.
    pub downloads: tempfile::TempDir,
    _profile: tempfile::TempDir,
}

impl WebDriver {
    /// Starts chromedriver on a free port and a headless browser in it.
    pub fn start(window: (u32, u32)) -> WebDriver {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .unwrap()
            .port();
        let log = tempfile::NamedTempFile::new().unwrap();
        let driver = Command::new(chromedriver())
            .arg(format!("--port={port}"))
            .stdout(std::process::Stdio::null())
            .stderr(log.reopen().unwrap())
            .spawn()
            .expect("start chromedriver");
        let host = format!("127.0.0.1:{port}");
        let start = Instant::now();
        while std::net::TcpStream::connect(&host).is_err() {
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "chromedriver did not listen on {host}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        let downloads = tempfile::tempdir().unwrap();
        let profile = tempfile::tempdir().unwrap();
        let capabilities = serde_json::json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {
                "binary": chromium(),
                "args": [
                    "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                    "--no-first-run", "--disable-background-networking",
                    "--disable-component-update", "--disable-sync",
                    format!("--window-size={},{}", window.0, window.1),
                    format!("--user-data-dir={}", profile.path().display()),
                ],
                "prefs": {
                    "download.default_directory": downloads.path(),
                    "download.prompt_for_download": false,
                },
            },
        }}});
        let mut webdriver = WebDriver {
            driver,
            host,
            session: String::new(),
            browser_pid: None,
            downloads,
            _profile: profile,
        };
        let answer = webdriver.call("POST", "/session", capabilities);
        webdriver.session = answer["value"]["sessionId"]
            .as_str()
            .unwrap_or_else(|| panic!("no WebDriver session: {answer}"))
            .to_string();
        webdriver.browser_pid = answer["value"]["capabilities"]["goog:processID"].as_u64();
        // Headless Chromium saves downloads only when told where (CDP, through chromedriver).
        let downloads = webdriver.downloads.path().display().to_string();
        webdriver.session_call(
            "POST",
            "/goog/cdp/execute",
            serde_json::json!({"cmd": "Browser.setDownloadBehavior",
                "params": {"behavior": "allow", "downloadPath": downloads}}),
        );
        webdriver
    }

    fn call(&self, method: &str, path: &str, body: serde_json::Value) -> serde_json::Value {
        let body = if method == "GET" {
            Vec::new()
        } else {
            body.to_string().into_bytes()
        };
        let response = crate::http::request(
            &self.host,
            method,
            path,
            &[("Content-Type", "application/json")],
            body,
        );
        let json = response.json();
        assert_eq!(response.status, 200, "WebDriver {method} {path}: {json}");
        json
    }

    fn session_call(&self, method: &str, path: &str, body: serde_json::Value) -> serde_json::Value {
        let path = format!("/session/{}{path}", self.session);
        self.call(method, &path, body)["value"].clone()
    }

    pub fn goto(&self, url: &str) {
        self.session_call("POST", "/url", serde_json::json!({ "url": url }));
    }

    /// The element matching `css` (its WebDriver reference).
    pub fn find(&self, css: &str) -> String {
        let found = self.session_call(
            "POST",
            "/element",
            serde_json::json!({"using": "css selector", "value": css}),
        );
        found
            .as_object()
            .and_then(|o| o.values().next())
            .and_then(|v| v.as_str())
            .unwrap_or_else(|| panic!("no element {css}: {found}"))
            .to_string()
    }

    /// Types `text` into the element (for a file input: the file's path, which uploads it).
    pub fn send_keys(&self, element: &str, text: &str) {
        self.session_call(
            "POST",
            &format!("/element/{element}/value"),
            serde_json::json!({ "text": text }),
        );
    }

    pub fn click(&self, element: &str) {
        self.session_call(
            "POST",
            &format!("/element/{element}/click"),
            serde_json::json!({}),
        );
    }

    /// Runs `script` (a function body; `return` gives the value) in the page.
    pub fn execute(&self, script: &str) -> serde_json::Value {
        self.session_call(
            "POST",
            "/execute/sync",
            serde_json::json!({"script": script, "args": []}),
        )
    }

    /// Waits until `script` returns true, or fails saying `what`.
    pub fn wait_for(&self, script: &str, what: &str) {
        let start = Instant::now();
        while self.execute(script) != serde_json::Value::Bool(true) {
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "waited 60 s for {what}"
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// The visible part of the page as a PNG in `path`.
    pub fn screenshot(&self, path: &Path) {
        let encoded = self.session_call("GET", "/screenshot", serde_json::Value::Null);
        // Standard base64 (RFC 4648 §4), as WebDriver sends screenshots.
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(encoded.as_str().expect("a base64 screenshot"))
            .expect("a base64 screenshot");
        std::fs::write(path, bytes).unwrap();
    }

    /// The file `name` in the downloads once it is complete (Chromium
    /// writes `name.crdownload` first).
    pub fn downloaded(&self, name: &str) -> Vec<u8> {
        let path = self.downloads.path().join(name);
        let start = Instant::now();
        loop {
            let partial = self.downloads.path().join(format!("{name}.crdownload"));
            if path.is_file() && !partial.exists() {
                return std::fs::read(&path).unwrap();
            }
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "no download {name} in {}: {:?}",
                self.downloads.path().display(),
                std::fs::read_dir(self.downloads.path())
                    .unwrap()
                    .map(|e| e.unwrap().file_name())
                    .collect::<Vec<_>>()
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

impl Drop for WebDriver {
    fn drop(&mut self) {
        if let Some(pid) = self.browser_pid {
            // Its own process only (by id): the renderers and helpers end with it.
            let _ = Command::new("kill").arg(pid.to_string()).status();
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}
