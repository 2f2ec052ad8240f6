//! A thermal log studied as a front end asks for it: `thermal fit`'s flags,
//! `report --thermal…` and the web app's thermal form say the same things
//! (the rows to fit on as typed, the sensors, the reference or `auto`, the
//! validation, the ISO 230-3 test type) and all become the fit's options
//! and the study here, so the page fits the very model the CLI writes.

use crate::thermal::{
    self, FitOptions, LogOptions, ModelSource, Study, TestType, ThermalError, ThermalModel,
    Validation,
};

/// `--reference auto`: each sensor tried as the reference (and none).
pub const AUTO_REFERENCE: &str = "auto";

/// What the user says about a fit: `thermal fit`'s flags, the web form's fields.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FitRequest {
    /// The rows to fit on, `FIRST-LAST` ([`thermal::parse_rows`]; default: all).
    pub rows: Option<String>,
    /// The sensors to choose from (empty: all).
    pub sensors: Vec<String>,
    /// Sensors never to use.
    pub exclude: Vec<String>,
    /// The reference sensor, or [`AUTO_REFERENCE`].
    pub reference: Option<String>,
    /// At most this many sensors (default: the fit's).
    pub max_sensors: Option<usize>,
    /// How the cross-validation predicts its blocks (default: blocked).
    pub validation: Option<Validation>,
}

impl FitRequest {
    /// The fit's options over a log of `rows` rows.
    pub fn options(&self, rows: usize) -> Result<FitOptions, ThermalError> {
        let range = match &self.rows {
            Some(text) => thermal::parse_rows(text, rows).map_err(ThermalError::Request)?,
            None => 0..rows,
        };
        let mut options = FitOptions::over(range);
        options.sensors = self.sensors.clone();
        options.exclude = self.exclude.clone();
        options.auto_reference = self.reference.as_deref() == Some(AUTO_REFERENCE);
        options.reference = self.reference.clone().filter(|r| r != AUTO_REFERENCE);
        if let Some(max) = self.max_sensors {
            options.max_sensors = max;
        }
        if let Some(validation) = self.validation {
            options.validation = validation;
        }
        Ok(options)
    }
}

/// The validation `name` says (`blocked`, `forward`, `late`, as the model
/// file, `--validation` and the web form name them), or what was expected.
pub fn validation(name: &str) -> Result<Validation, String> {
    Validation::ALL
        .into_iter()
        .find(|v| v.name() == name)
        .ok_or_else(|| {
            let names: Vec<&str> = Validation::ALL.iter().map(|v| v.name()).collect();
            format!("expected one of {}, found {name:?}", names.join(", "))
        })
}

/// The ISO 230-3 test type `name` says (`etve`, `spindle`, `linear-axis`:
/// `thermal evaluate --test`, `report --thermal-test`, the web form's
/// `test`), or what was expected.
pub fn test_type(name: &str) -> Result<TestType, String> {
    TestType::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = TestType::ALL.iter().map(|t| t.name()).collect();
        format!("expected one of {}, found {name:?}", names.join(", "))
    })
}

/// What the user says about a log to study: the CLI's `--thermal…` flags,
/// the web form's fields.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StudyRequest {
    /// The drift column (default: the model's).
    pub drift: Option<String>,
    /// Seconds between rows, for a log without a time column.
    pub sample_interval_s: Option<f64>,
    /// The ISO 230-3 test the log records.
    pub test_type: Option<TestType>,
    /// The model to run; without one, a model is fitted when the drift
    /// column is named.
    pub model: Option<ThermalModel>,
    /// How to fit one (when there is no model).
    pub fit: FitRequest,
}

/// Reads the log `text` and studies it as `request` says: with the model
/// given (a log without its drift column is run for the prediction alone),
/// or one fitted when the drift column is named, or none.
pub fn study_text(text: &str, request: StudyRequest) -> Result<Study, ThermalError> {
    let drift = request
        .drift
        .clone()
        .or_else(|| request.model.as_ref().map(|m| m.fit.drift.clone()));
    let options = LogOptions {
        drift: drift.clone(),
        sample_interval_s: request.sample_interval_s,
        drift_optional: request.model.is_some() && request.drift.is_none(),
    };
    let log = thermal::parse_log(text, &options)?;
    let source = match (request.model, drift) {
        (Some(model), _) => ModelSource::Given(model),
        (None, Some(_)) => ModelSource::Fit(request.fit.options(log.len())?),
        (None, None) => ModelSource::None,
    };
    thermal::study(log, request.test_type, source)
}
