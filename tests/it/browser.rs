//! Opening pages in a real browser (Debian's chromium, headless) and reading
//! PNGs: shared by the report and demo tests.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus};
use std::time::{Duration, Instant};

/// Where screenshots and PDFs are kept for a person to look at.
pub fn artefacts() -> PathBuf {
    let directory = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("report");
    std::fs::create_dir_all(&directory).unwrap();
    directory
}

/// A decoded PNG: width, height, and its pixels as RGB(A) rows.
pub struct Pixels {
    pub size: (u32, u32),
    channels: usize,
    data: Vec<u8>,
}

impl Pixels {
    pub fn read(path: &Path) -> Pixels {
        let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .unwrap();
        let mut data = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut data).unwrap();
        data.truncate(info.buffer_size());
        Pixels {
            size: (info.width, info.height),
            channels: info.color_type.samples(),
            data,
        }
    }

    /// The fraction of pixels for which `test(r, g, b)` holds.
    pub fn fraction(&self, test: impl Fn(u8, u8, u8) -> bool) -> f64 {
        let total = self.data.len() / self.channels;
        let hits = self
            .data
            .chunks(self.channels)
            .filter(|p| match p {
                [r, g, b, ..] => test(*r, *g, *b),
                [grey, ..] => test(*grey, *grey, *grey),
                [] => false,
            })
            .count();
        hits as f64 / total as f64
    }

    /// The fraction that is not (nearly) white.
    pub fn inked(&self) -> f64 {
        self.fraction(|r, g, b| r.min(g).min(b) < 235)
    }

    /// The fraction in the plots' blues (↑ runs, bands): a plot is drawn, not only text.
    pub fn blue(&self) -> f64 {
        self.fraction(|r, _, b| i32::from(b) > i32::from(r) + 60)
    }
}

/// Debian's chromium; `scripts/test` installs it. Missing is a failure, not a skip.
pub fn chromium() -> PathBuf {
    let path = std::env::var_os("PATH").unwrap_or_default();
    for directory in std::env::split_paths(&path) {
        for name in ["chromium", "chromium-browser"] {
            let candidate = directory.join(name);
            if candidate.is_file() {
                return candidate;
            }
        }
    }
    panic!(
        "chromium not found on PATH: the report is tested in a real browser; install Debian's \
         chromium (apt-get install chromium), or run the tests with scripts/test, which installs it"
    );
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
    let status = wait_with_timeout(child, Duration::from_secs(120));
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

/// Waits for a child, killing it after `limit` (a hung browser must not hang the tests).
fn wait_with_timeout(mut child: std::process::Child, limit: Duration) -> ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("chromium did not finish within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}
