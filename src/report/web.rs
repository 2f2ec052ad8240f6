//! The web app's answers (`axcomp serve`'s JSON API): each the CLI's own
//! object (`evaluate --json`, `convert --json`, `diagnose --json`) with the
//! report's plots beside it, what the page offers, and a refusal.

use serde::Serialize;

use crate::emit::Controller;
use crate::evaluate;
use crate::report::convert::ConvertJson;
use crate::report::diagnose::DiagnoseJson;
use crate::report::json::EvaluationJson;

/// What the page offers to choose from (`GET /api/options`).
#[derive(Serialize)]
pub struct OptionsJson {
    controllers: Vec<&'static str>,
    standards: Vec<StandardJson>,
    upload_limit_bytes: usize,
    version: &'static str,
}

#[derive(Serialize)]
struct StandardJson {
    key: &'static str,
    name: &'static str,
}

impl OptionsJson {
    /// The controllers, the standards, the upload limit and the version.
    pub fn new(upload_limit_bytes: usize) -> OptionsJson {
        OptionsJson {
            controllers: Controller::ALL.iter().map(|c| c.name()).collect(),
            standards: evaluate::SUPPORTED
                .iter()
                .map(|s| StandardJson {
                    key: s.key(),
                    name: s.name(),
                })
                .collect(),
            upload_limit_bytes,
            version: env!("CARGO_PKG_VERSION"),
        }
    }
}

/// `POST /api/evaluate`'s answer.
#[derive(Serialize)]
pub struct EvaluateAnswer {
    /// `evaluate --json`'s object.
    pub evaluation: EvaluationJson,
    /// The report's deviation plot.
    pub deviation_svg: Option<String>,
}

/// `POST /api/convert`'s answer (and the next table of `/api/retest`).
#[derive(Serialize)]
pub struct ConvertAnswer {
    /// `convert --json`'s object.
    pub convert: ConvertJson,
    /// The name the download gets.
    pub file_name: String,
    /// The file as text, for the preview.
    pub text: String,
    /// The report's plot of the table.
    pub table_svg: Option<String>,
    /// Fanuc, when asked (`--fanuc-rescaled`): the file at a finer magnification.
    pub fanuc_rescaled: Option<RescaledAnswer>,
}

/// `--fanuc-rescaled`'s file: its name, its text and the parameter change.
#[derive(Serialize)]
pub struct RescaledAnswer {
    /// The name the download gets: the table's, with the new 3623.
    pub file_name: String,
    /// The file as text.
    pub text: String,
    /// The new magnification (3623).
    pub magnification: i64,
    /// What to set with it, as `convert` prints it.
    pub instruction: String,
}

impl RescaledAnswer {
    /// The rescaled file of the table `file_name`.
    pub fn new(file_name: &str, fine: &crate::emit::fanuc::Rescaled) -> RescaledAnswer {
        let (stem, extension) = file_name.rsplit_once('.').unwrap_or((file_name, "TXT"));
        RescaledAnswer {
            file_name: format!("{stem}-3623-{}.{extension}", fine.magnification),
            text: fine.text.clone(),
            magnification: fine.magnification,
            instruction: fine.instruction.clone(),
        }
    }
}

/// `POST /api/retest`'s answer.
#[derive(Serialize)]
pub struct RetestAnswer {
    /// `diagnose --json`'s object.
    pub diagnosis: DiagnoseJson,
    /// What `diagnose --write-effects` writes (`null` where it writes none: a rotary axis).
    pub effects_toml: Option<String>,
    /// The report's plot of the residual (`null` where the report has none: a rotary axis).
    pub residual_svg: Option<String>,
    /// The next table (`convert AFTER --existing TABLE --effects E.toml`), when a table was given.
    pub next: Option<ConvertAnswer>,
    /// Every warning of the two tests, as `diagnose` prints them: the
    /// readers', the evaluations' and the doubts of the pair, each naming its file.
    pub warnings: Vec<String>,
}

/// A refused request's body: the message the page shows.
#[derive(Serialize)]
pub struct ErrorJson {
    /// The CLI's message for the same input.
    pub error: String,
}
