//! axcomp system tests: what needs a program besides Rust, each of them real
//! and never skipped (a missing program is a failure that says what to
//! install; `scripts/test` installs them all):
//! - LinuxCNC 2.9: the LinuxCNC table applied by the real controller
//!   (`linuxcnc.rs`);
//! - Chromium (headless) and chromedriver: the report, the demo's report and
//!   the web app's page in a real browser (`pages.rs`, `web_page.rs`);
//! - Wine and the Windows build (`scripts/dist`): `axcomp.exe` against the
//!   Linux binary (`windows.rs`).
//!
//! Plain `cargo test` leaves this target out (Cargo.toml: `test = false`);
//! `scripts/test` installs what it needs and runs it as `cargo test --test
//! system`. The helpers shared with the `it` target are its files, included
//! by path.

// Shared with the `it` target: each target uses only part of them.
#[allow(dead_code)]
#[path = "../it/http.rs"]
mod http;
#[allow(dead_code)]
#[path = "../it/page.rs"]
mod page;
#[allow(dead_code)]
#[path = "../it/pixels.rs"]
mod pixels;
#[allow(dead_code)]
#[path = "../it/retest_case.rs"]
mod retest_case;
#[allow(dead_code)]
#[path = "../it/server.rs"]
mod server;
#[allow(dead_code)]
#[path = "../it/util.rs"]
mod util;

mod browser;
mod linuxcnc;
mod linuxcnc_thermal;
mod pages;
mod web_page;
mod windows;

use std::path::PathBuf;

/// The first of `names` on PATH: a program the tests need (Debian's
/// chromium, chromedriver, wine; `scripts/test` installs them). Missing is a
/// failure that says `how` to get it, never a skip.
fn program_on_path(names: &[&str], how: &str) -> PathBuf {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .flat_map(|directory| names.iter().map(move |name| directory.join(name)))
        .find(|candidate| candidate.is_file())
        .unwrap_or_else(|| panic!("{} not found on PATH: {how}", names.join(" or ")))
}
