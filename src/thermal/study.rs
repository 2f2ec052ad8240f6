//! A thermal log studied as a whole: its ISO 230-3 view and, when there is
//! a model (given, or fitted on the log), the model run over it. The one
//! piece of work behind the report's thermal section, the web app's thermal
//! page and `diagnose --thermal` (`workflow::thermal` says what to study).

use super::{
    Application, FitOptions, Iso230_3, TestType, ThermalError, ThermalLog, ThermalModel, apply,
    evaluate, fit,
};

/// Where the model comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelSource {
    /// No model: the ISO 230-3 view and the plots only.
    None,
    /// A model file read before.
    Given(ThermalModel),
    /// Fitted on the log itself, with these options.
    Fit(FitOptions),
}

/// A log, its ISO 230-3 view, and the model run over it.
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    /// The log.
    pub log: ThermalLog,
    /// Its ISO 230-3 view.
    pub iso: Iso230_3,
    /// The model, when there is one.
    pub model: Option<ThermalModel>,
    /// The model run over the log from its first row.
    pub applied: Option<Application>,
}

/// Studies `log`: the ISO 230-3 view, the model from `source` and its run.
pub fn study(
    log: ThermalLog,
    test_type: Option<TestType>,
    source: ModelSource,
) -> Result<Study, ThermalError> {
    let iso = evaluate(&log, test_type);
    let model = match source {
        ModelSource::None => None,
        ModelSource::Given(model) => Some(model),
        ModelSource::Fit(options) => Some(fit(&log, &options)?),
    };
    let applied = model.as_ref().map(|m| apply(m, &log)).transpose()?;
    Ok(Study {
        log,
        iso,
        model,
        applied,
    })
}

/// `FIRST-LAST` (1-based data rows, inclusive, as `thermal fit --rows` and
/// the web form take them) as a 0-based range over a log of `rows` rows.
pub fn parse_rows(text: &str, rows: usize) -> Result<std::ops::Range<usize>, String> {
    let parsed = text.split_once('-').and_then(|(a, b)| {
        Some((
            a.trim().parse::<usize>().ok()?,
            b.trim().parse::<usize>().ok()?,
        ))
    });
    match parsed {
        Some((first, last)) if first >= 1 && first < last && last <= rows => Ok(first - 1..last),
        _ => Err(format!(
            "rows {text}: expected FIRST-LAST, 1 ≤ FIRST < LAST ≤ {rows} (the log's rows)"
        )),
    }
}
