//! `axcomp serve`: the local web app (`axcomp::serve`) on a port of this
//! machine, and the browser opened on it.

use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpListener};

use anyhow::{Context, Result};

use axcomp::serve::{DEFAULT_PORT, serve, url};

use super::common::Verbosity;

/// Flags of `axcomp serve`.
#[derive(Debug, clap::Args)]
pub struct ServeArgs {
    /// The port (0: any free one; the address is printed).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_PORT)]
    pub port: u16,

    /// Listen on ADDR instead of 127.0.0.1 (e.g. 0.0.0.0 for every
    /// network): anyone who reaches the port can then use the app.
    #[arg(long, value_name = "ADDR")]
    pub listen: Option<IpAddr>,

    /// Do not open the browser.
    #[arg(long)]
    pub no_open: bool,

    /// -q/--quiet (the same in every command): no warning about --listen.
    #[command(flatten)]
    pub verbosity: Verbosity,
}

/// Runs `axcomp serve` until interrupted.
pub fn run(args: &ServeArgs) -> Result<()> {
    let ip = args.listen.unwrap_or(IpAddr::V4(Ipv4Addr::LOCALHOST));
    if !ip.is_loopback() && !args.verbosity.quiet {
        eprintln!(
            "axcomp: warning: listening on {ip}, not only this machine: anyone who reaches port {} can upload files and read what the app computes",
            args.port
        );
    }
    let listener = TcpListener::bind(SocketAddr::new(ip, args.port))
        .with_context(|| format!("cannot listen on {ip} port {}", args.port))?;
    let addr = listener.local_addr()?;
    let url = url(addr);
    // Printed before anything else, and flushed: a script (or a test) reads the address here.
    println!("axcomp serve: {url} (Ctrl-C stops it)");
    std::io::Write::flush(&mut std::io::stdout())?;
    if !args.no_open {
        open_browser(&url, args.verbosity.quiet);
    }
    serve(listener).context("the web app stopped")
}

/// Opens `url` in the desktop's browser; when that fails the printed address is enough.
fn open_browser(url: &str, quiet: bool) {
    let mut command = if cfg!(windows) {
        let mut command = std::process::Command::new("cmd");
        command.args(["/C", "start", ""]);
        command
    } else if cfg!(target_os = "macos") {
        std::process::Command::new("open")
    } else {
        std::process::Command::new("xdg-open")
    };
    let opened = command
        .arg(url)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    if opened.is_err() && !quiet {
        eprintln!("axcomp: could not open a browser; open {url} yourself");
    }
}
