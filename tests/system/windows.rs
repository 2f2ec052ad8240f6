//! The Windows build: `scripts/dist`'s `axcomp.exe` runs under Wine and
//! writes, byte for byte, what the Linux binary writes for `evaluate`,
//! `convert` and `report` of the sample (README "Windows": the same bytes on
//! every platform, LF in axcomp's own output, each controller file with its
//! controller's line ends). Paths with backslashes and a drive letter
//! (Wine's `Z:\` is `/`), a file with CRLF line ends and a file name with
//! Latin-1 letters work.
//!
//! One test, run in order: Wine's prefix (its `C:` drive and registry) is
//! made on first use, and two Wine processes making it at once break it.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::browser::wait_with_timeout;
use crate::util::{root, without_time};

/// What a run printed.
struct Output {
    stdout: Vec<u8>,
    stderr: String,
}

/// The Windows binary `scripts/dist` builds (`scripts/test` runs it first).
fn windows_exe() -> PathBuf {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().unwrap();
    let exe = target.join("x86_64-pc-windows-gnu/release/axcomp.exe");
    assert!(
        exe.is_file(),
        "{} not found: build it with scripts/dist (scripts/test does, before the tests)",
        exe.display()
    );
    exe
}

fn wine() -> PathBuf {
    crate::program_on_path(
        &["wine"],
        "the Windows build is checked under Wine; install Debian's wine and wine64, or run the \
         tests with scripts/test, which installs them",
    )
}

/// Runs `command` in `dir`, output into files (no pipe to fill), at most five minutes.
fn run(mut command: Command, dir: &Path, what: &str) -> Output {
    let out = tempfile::tempdir().unwrap();
    let (stdout, stderr) = (out.path().join("stdout"), out.path().join("stderr"));
    let child = command
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&stdout).unwrap())
        .stderr(std::fs::File::create(&stderr).unwrap())
        .spawn()
        .unwrap_or_else(|e| panic!("start {what}: {e}"));
    let status = wait_with_timeout(child, Duration::from_secs(300), what);
    let output = Output {
        stdout: std::fs::read(&stdout).unwrap(),
        stderr: std::fs::read_to_string(&stderr).unwrap_or_default(),
    };
    assert!(status.success(), "{what}: {status}: {}", output.stderr);
    output
}

fn linux(dir: &Path, args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_axcomp"));
    command.args(args);
    run(command, dir, &format!("axcomp {args:?}"))
}

/// Wine's environment: its own prefix, quiet, no installer dialogs, no display.
fn wine_command(prefix: &Path) -> Command {
    let mut command = Command::new(wine());
    command
        .env("WINEPREFIX", prefix)
        .env("WINEDEBUG", "-all")
        // No Mono or Gecko installer when the prefix is made: a console program needs neither.
        .env("WINEDLLOVERRIDES", "mscoree,mshtml=")
        .env_remove("DISPLAY");
    command
}

/// The test's Wine prefix, made on first use, with the stand-in for the
/// bcryptprimitives.dll Wine 8 lacks (`tests/data/wine/bcryptprimitives.c`).
fn prefix() -> PathBuf {
    let prefix = Path::new(env!("CARGO_TARGET_TMPDIR")).join("wine-prefix");
    let system32 = prefix.join("drive_c/windows/system32");
    let dll = system32.join("bcryptprimitives.dll");
    if !system32.is_dir() {
        let mut boot = wine_command(&prefix);
        boot.args(["wineboot", "--init"]);
        run(
            boot,
            Path::new(env!("CARGO_TARGET_TMPDIR")),
            "wineboot --init",
        );
    }
    if !dll.is_file() {
        let gcc = crate::program_on_path(
            &["x86_64-w64-mingw32-gcc"],
            "install Debian's gcc-mingw-w64-x86-64 (scripts/test does)",
        );
        let mut build = Command::new(gcc);
        build
            .args(["-shared", "-O2", "-o"])
            .arg(&dll)
            .arg(root().join("tests/data/wine/bcryptprimitives.c"))
            .arg("-ladvapi32");
        run(build, &root(), "x86_64-w64-mingw32-gcc bcryptprimitives.c");
    }
    prefix
}

fn windows(dir: &Path, args: &[&str]) -> Output {
    let mut command = wine_command(&prefix());
    command.arg(windows_exe()).args(args);
    run(command, dir, &format!("wine axcomp.exe {args:?}"))
}

/// Two folders with the same inputs: one for each binary, so that the same
/// relative names give the same output.
fn folders() -> (tempfile::TempDir, tempfile::TempDir) {
    let sample = std::fs::read(root().join("fixtures/sample-x.rtl")).unwrap();
    // The Fagor 8065 table is an update of the axis' exported .mp (UTF-16).
    let parameters = std::fs::read(root().join("fixtures/fagor8065/X.mp")).unwrap();
    let crlf = String::from_utf8(sample.clone())
        .unwrap()
        .replace("\r\n", "\n")
        .replace('\n', "\r\n");
    let folders = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for dir in [folders.0.path(), folders.1.path()] {
        std::fs::write(dir.join("sample-x.rtl"), &sample).unwrap();
        std::fs::write(dir.join("sample-crlf.rtl"), &crlf).unwrap();
        std::fs::write(dir.join("Maß-prüfung-é.rtl"), &sample).unwrap();
        std::fs::write(dir.join("exported-X.mp"), &parameters).unwrap();
        std::fs::create_dir(dir.join("tables")).unwrap();
    }
    folders
}

#[test]
fn the_windows_binary_under_wine_writes_what_the_linux_binary_writes() {
    let exe = windows_exe();
    let (on_linux, on_windows) = folders();
    let (l, w) = (on_linux.path(), on_windows.path());

    // evaluate: the report and the JSON, of the LF, the CRLF and the Latin-1 named file.
    for file in ["sample-x.rtl", "sample-crlf.rtl", "Maß-prüfung-é.rtl"] {
        for json in [false, true] {
            let mut args = vec!["evaluate", file];
            if json {
                args.push("--json");
            }
            let (a, b) = (linux(l, &args), windows(w, &args));
            assert_eq!(
                String::from_utf8_lossy(&b.stdout),
                String::from_utf8_lossy(&a.stdout),
                "{args:?}"
            );
            assert!(!b.stdout.contains(&b'\r'), "{args:?}: CR in the output");
        }
    }
    // The CRLF file is the same test: the same figures.
    let figures = |dir: &Path, file: &str| {
        let json: serde_json::Value =
            serde_json::from_slice(&linux(dir, &["evaluate", file, "--json"]).stdout).unwrap();
        json["figures_um"].clone()
    };
    assert_eq!(figures(l, "sample-crlf.rtl"), figures(l, "sample-x.rtl"));

    // convert: the files and what is printed, for formats with LF and CRLF line ends.
    for (controller, name) in [
        ("tnc640", "X.COM"),
        ("sinumerik840d", "X.MPF"),
        ("linuxcnc", "x.comp"),
        ("fagor8055", "ALX"),
        ("fagor8065", "X.mp"),
    ] {
        let output = format!("tables/{name}");
        let mut args = vec![
            "convert",
            "sample-x.rtl",
            "--controller",
            controller,
            "--step",
            "50",
            "-o",
            &output,
        ];
        if controller == "fagor8065" {
            args.extend(["--existing", "exported-X.mp"]);
        }
        let (a, b) = (linux(l, &args), windows(w, &args));
        assert_eq!(b.stdout, a.stdout, "{args:?}");
        let (file_l, file_w) = (
            std::fs::read(l.join(&output)).unwrap(),
            std::fs::read(w.join(&output)).unwrap(),
        );
        assert!(file_l.len() > 100);
        assert_eq!(file_w, file_l, "{controller}: {name}");
    }

    // report: the same page.
    let args = ["report", "sample-x.rtl", "-o", "report.html"];
    let (a, b) = (linux(l, &args), windows(w, &args));
    assert_eq!(b.stdout, a.stdout);
    let page_l = std::fs::read(l.join("report.html")).unwrap();
    let page_w = std::fs::read(w.join("report.html")).unwrap();
    assert!(page_l.len() > 10_000);
    assert_eq!(
        without_time(&String::from_utf8(page_w).unwrap()),
        without_time(&String::from_utf8(page_l).unwrap())
    );

    // A Windows path: drive letter, backslashes (Wine's Z: is the Unix root).
    let windows_path = |path: &Path| format!("Z:{}", path.display()).replace('/', "\\");
    let sample = windows_path(&w.join("sample-x.rtl"));
    let out = windows_path(&w.join("tables").join("by-path.COM"));
    let b = windows(
        w,
        &[
            "convert",
            &sample,
            "--controller",
            "tnc640",
            "--step",
            "50",
            "-o",
            &out,
        ],
    );
    assert!(
        String::from_utf8_lossy(&b.stdout).contains(&out),
        "{}",
        String::from_utf8_lossy(&b.stdout)
    );
    // The same table (the name inside a .COM is the file's, so compare with a Linux one of that name).
    linux(
        l,
        &[
            "convert",
            "sample-x.rtl",
            "--controller",
            "tnc640",
            "--step",
            "50",
            "-o",
            "tables/by-path.COM",
        ],
    );
    assert_eq!(
        std::fs::read(w.join("tables/by-path.COM")).unwrap(),
        std::fs::read(l.join("tables/by-path.COM")).unwrap()
    );
    let json: serde_json::Value =
        serde_json::from_slice(&windows(w, &["evaluate", &sample, "--json"]).stdout).unwrap();
    assert_eq!(json["source_file"], sample.as_str());
    assert!(exe.is_file());
}
