//! `axcomp serve`: the local web app for the engineer at the machine who
//! has a laptop and a browser but no shell.
//!
//! One page (`assets/serve/`: plain HTML, CSS and JavaScript, compiled into
//! the binary; no CDN, so it works offline) and a small JSON API over the
//! library, on axum and tokio:
//!
//! - `POST /api/evaluate`: `evaluate --json`'s object (with the form's
//!   `limits`, `decision` and machine profile, as `--limit`, `--decision`,
//!   `--machine`) and the deviation plot;
//! - `POST /api/convert`: `convert --json`'s object, the file's text and the
//!   table's plot; `POST /api/table` the file itself, byte for byte what
//!   `convert -o NAME` writes, under the controller's usual name
//!   (`Controller::file_name`);
//! - `POST /api/retest`: the diagnosis of a re-test (`diagnose --json`) and
//!   the next table;
//! - `POST /api/report`: the acceptance report, the HTML `axcomp report` writes.
//!
//! Every route takes the machine profile (`machine`, the `--machine` TOML):
//! its axis settings for the tables, its `[acceptance]` for the verdict, its
//! screw lead and scale period for the diagnosis.
//!
//! A rotary axis gets what the CLI gives it (`workflow::rotary`): its
//! re-test is diagnosed (in ″; no effects file, so its next table has no
//! effects, and no residual plot, which is in µm), and the report refuses
//! what `axcomp report` refuses.
//!
//! The work is the CLI's own ([`crate::workflow`]); this module only reads
//! the form (`form.rs`, `inputs.rs`), calls the workflow (`steps.rs`, one
//! handler per step) and answers (`present.rs`, `error.rs`). Its limits:
//! uploads of at most [`UPLOAD_LIMIT`] bytes, kept in memory and named by their base name (no path a client
//! names is ever opened, no file is written), and only requests addressed to
//! the app from its own page ([`origin`]). Bad input is a 400 whose `error`
//! is the CLI's message (`file:line:col: …`).
//!
//! Unlike the stages below, this one does I/O: the network is its job.

mod error;
mod form;
mod inputs;
pub mod origin;
mod present;
mod steps;
mod thermal;

use std::net::{SocketAddr, TcpListener};
use std::sync::Arc;

use axum::Router;
use axum::extract::{DefaultBodyLimit, Request, State};
use axum::http::{StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};

use error::ApiError;

/// The largest request the app reads, bytes: a 10 000-target × 10-run
/// `.rtl` is 1.9 MB, so 50 MB is far above any real test and still far
/// below what would strain the laptop.
pub const UPLOAD_LIMIT: usize = 50 * 1024 * 1024;

/// The port `axcomp serve` listens on unless told otherwise.
pub const DEFAULT_PORT: u16 = 8230;

const INDEX_HTML: &str = include_str!("../../assets/serve/index.html");
const APP_JS: &str = include_str!("../../assets/serve/app.js");
const APP_CSS: &str = include_str!("../../assets/serve/app.css");

/// Answers on `listener` until the process ends.
pub fn serve(listener: TcpListener) -> std::io::Result<()> {
    let addr = listener.local_addr()?;
    listener.set_nonblocking(true)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_io()
        .build()?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::from_std(listener)?;
        axum::serve(listener, app(addr)).await
    })
}

/// The routes, for a listener bound to `addr` (whose names the requests must use).
pub fn app(addr: SocketAddr) -> Router {
    let allowed: Arc<Vec<String>> = Arc::new(origin::allowed_hosts(addr));
    Router::new()
        .route(
            "/",
            get(|| async { page(INDEX_HTML, "text/html; charset=utf-8") }),
        )
        .route(
            "/app.js",
            get(|| async { page(APP_JS, "text/javascript; charset=utf-8") }),
        )
        .route(
            "/app.css",
            get(|| async { page(APP_CSS, "text/css; charset=utf-8") }),
        )
        .route("/api/options", get(steps::options))
        .route("/api/evaluate", post(steps::api_evaluate))
        .route("/api/convert", post(steps::api_convert))
        .route("/api/table", post(steps::api_table))
        .route("/api/retest", post(steps::api_retest))
        .route("/api/report", post(steps::api_report))
        .route("/thermal", get(thermal::form).post(thermal::submit))
        .layer(DefaultBodyLimit::max(UPLOAD_LIMIT))
        .layer(middleware::from_fn_with_state(allowed, guard))
}

/// Refuses requests by another name or from another origin ([`origin`]).
async fn guard(State(allowed): State<Arc<Vec<String>>>, request: Request, next: Next) -> Response {
    let (host, origin) = {
        let headers = request.headers();
        let text = |name: header::HeaderName| {
            headers
                .get(name)
                .and_then(|value| value.to_str().ok())
                .map(str::to_string)
        };
        (text(header::HOST), text(header::ORIGIN))
    };
    let host = host.or_else(|| request.uri().authority().map(|a| a.to_string()));
    let refusal = origin::refusal(&allowed, host.as_deref(), origin.as_deref());
    match refusal {
        Some(why) => ApiError::new(StatusCode::FORBIDDEN, why).into_response(),
        None => next.run(request).await,
    }
}

fn page(body: &'static str, content_type: &'static str) -> Response {
    (
        [
            (header::CONTENT_TYPE, content_type),
            (header::CACHE_CONTROL, "no-store"),
        ],
        body,
    )
        .into_response()
}

/// Where the app is, for the message and the browser.
pub fn url(addr: SocketAddr) -> String {
    let host = match addr.ip() {
        ip if ip.is_unspecified() => "127.0.0.1".to_string(),
        std::net::IpAddr::V6(ip) => format!("[{ip}]"),
        ip => ip.to_string(),
    };
    format!("http://{host}:{}/", addr.port())
}
