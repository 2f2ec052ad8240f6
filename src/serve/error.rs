//! A refused request: its status and the message the page shows, the CLI's
//! own message for bad input.

use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};

use crate::report::web::ErrorJson;
use crate::{emit, read, workflow};

/// A refused request: its status and the message the page shows.
#[derive(Debug)]
pub struct ApiError {
    status: StatusCode,
    message: String,
}

impl ApiError {
    /// A refusal with `status`.
    pub fn new(status: StatusCode, message: impl Into<String>) -> ApiError {
        ApiError {
            status,
            message: message.into(),
        }
    }

    /// Bad input: 400 with the message.
    pub fn bad(message: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::BAD_REQUEST, message)
    }

    /// Bad input, said as the CLI says it: the error and its causes, `: ` between.
    pub fn from_error(error: &dyn std::error::Error) -> ApiError {
        let mut message = error.to_string();
        let mut source = error.source();
        while let Some(cause) = source {
            let text = cause.to_string();
            if !message.ends_with(&text) {
                message.push_str(": ");
                message.push_str(&text);
            }
            source = cause.source();
        }
        ApiError::bad(message)
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (
            self.status,
            axum::Json(ErrorJson {
                error: self.message,
            }),
        )
            .into_response()
    }
}

macro_rules! bad_input {
    ($($error:ty),*) => {$(
        impl From<$error> for ApiError {
            fn from(error: $error) -> ApiError {
                ApiError::from_error(&error)
            }
        }
    )*};
}

bad_input!(
    read::ReadError,
    workflow::WorkflowError,
    workflow::rotary::RotaryRefusal,
    emit::EmitError,
    crate::measurement::MeasurementError,
    crate::together::NotTogether,
    crate::evaluate::UnknownStandard,
    crate::diagnose::DiagnoseError,
    crate::report::plot::PlotError
);

impl From<String> for ApiError {
    fn from(message: String) -> ApiError {
        ApiError::bad(message)
    }
}
