//! The error description file (`axcomp predict --errors E.toml`): any of the
//! 21 errors, each a constant or a table along its own axis, in the units
//! the field quotes them in (µm for translations, µrad = µm/m for angles).
//!
//! ```toml
//! # One table per error, named as in ISO 230-1 (EXX … ECZ, EXOY, EXOZ, EYOZ).
//! [EBX]                                   # pitch of X
//! positions_mm = [0.0, 250.0, 500.0, 750.0]
//! values_urad = [0.0, 4.0, 6.5, 5.0]
//! interpolation = "spline"                # or "linear" (the default)
//!
//! [EYX]                                   # straightness of X in Y
//! positions_mm = [0.0, 375.0, 750.0]
//! values_um = [0.0, 3.0, 0.0]
//!
//! [EXOY]                                  # squareness: a constant
//! value_urad = 30.0
//! ```
//!
//! Translations take `value_um` / `values_um`, angles `value_urad` /
//! `values_urad`; the other unit is an error, so a µrad value is never read as
//! µm. Errors not named are zero. Unknown names and keys are errors.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::components::{ErrorComponent, ErrorFunction, ErrorName, ErrorTable, GeometricErrors};
use super::{Interpolation, ModelError};
use crate::error::ParseError;
use crate::units::{um_per_m_to_rad, um_to_mm};

/// One error as written in the file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawError {
    positions_mm: Option<Vec<f64>>,
    values_um: Option<Vec<f64>>,
    values_urad: Option<Vec<f64>>,
    value_um: Option<f64>,
    value_urad: Option<f64>,
    interpolation: Option<String>,
}

/// Reads an error description.
///
/// # Example
///
/// ```
/// use axcomp::model::{ErrorName, read_error_description};
///
/// let text = "[EXX]\npositions_mm = [0.0, 100.0]\nvalues_um = [0.0, 5.0]\n\n[EXOY]\nvalue_urad = 30.0\n";
/// let errors = read_error_description(text)?;
/// let exx = errors.function(ErrorName::EXX).unwrap();
/// assert!((exx.value_at(50.0) - 0.0025).abs() < 1e-15);
/// assert_eq!(errors.squareness.xy_rad, 30e-6);
/// # Ok::<(), axcomp::model::ModelError>(())
/// ```
pub fn read_error_description(text: &str) -> Result<GeometricErrors, ModelError> {
    let raw: BTreeMap<String, RawError> = toml::from_str(text)
        .map_err(|error| ModelError::Toml(ParseError::from_toml(text, &error)))?;
    let mut errors = GeometricErrors::default();
    for (key, error) in raw {
        let name = ErrorName::from_name(&key).ok_or_else(|| {
            ModelError::invalid(
                format!("[{key}]"),
                "one of the 21 ISO 230-1 names (EXX, EYX, EZX, EAX, EBX, ECX, … EXOY, EXOZ, EYOZ)",
                key.clone(),
            )
        })?;
        let function = function(name, &error).map_err(|e| e.within(&format!("[{key}]")))?;
        errors.set(name, function)?;
    }
    Ok(errors)
}

/// The error's function in model units (mm, rad).
fn function(name: ErrorName, raw: &RawError) -> Result<ErrorFunction, ModelError> {
    let angular = !matches!(name.component(), ErrorComponent::Translation { .. });
    let (value, values, wrong) = if angular {
        (
            raw.value_urad.map(um_per_m_to_rad),
            raw.values_urad
                .as_ref()
                .map(|v| v.iter().map(|x| um_per_m_to_rad(*x)).collect::<Vec<_>>()),
            raw.value_um.is_some() || raw.values_um.is_some(),
        )
    } else {
        (
            raw.value_um.map(um_to_mm),
            raw.values_um
                .as_ref()
                .map(|v| v.iter().map(|x| um_to_mm(*x)).collect::<Vec<_>>()),
            raw.value_urad.is_some() || raw.values_urad.is_some(),
        )
    };
    let unit = if angular { "urad" } else { "um" };
    if wrong {
        let kind = if angular { "an angle" } else { "a translation" };
        return Err(ModelError::invalid(
            "unit",
            format!(
                "value_{unit} or values_{unit} ({} is {kind})",
                name.as_str()
            ),
            "the other unit",
        ));
    }
    let interpolation = match raw.interpolation.as_deref() {
        None | Some("linear") => Interpolation::Linear,
        Some("spline") => Interpolation::Spline,
        Some(other) => {
            return Err(ModelError::invalid(
                "interpolation",
                "\"linear\" or \"spline\"",
                format!("{other:?}"),
            ));
        }
    };
    match (value, values, &raw.positions_mm) {
        (Some(value), None, None) if value.is_finite() => Ok(ErrorFunction::Constant(value)),
        (None, Some(values), Some(positions)) => Ok(ErrorFunction::Table(ErrorTable::new(
            positions.clone(),
            values,
            interpolation,
        )?)),
        _ => Err(ModelError::invalid(
            "error",
            format!(
                "either value_{unit} (a constant) or positions_mm with values_{unit} (a table)"
            ),
            "neither, or both",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_converted_and_checked() {
        let errors = read_error_description(
            "[ebx]\npositions_mm = [0.0, 100.0]\nvalues_urad = [2.0, 4.0]\n\n[EYX]\nvalue_um = -1.5\n",
        )
        .unwrap();
        let ebx = errors.function(ErrorName::EBX).unwrap();
        assert!((ebx.value_at(50.0) - 3e-6).abs() < 1e-18);
        assert_eq!(
            errors.function(ErrorName::EYX).unwrap().value_at(7.0),
            -0.0015
        );

        let wrong_unit = read_error_description("[EBX]\nvalue_um = 3.0\n").unwrap_err();
        assert!(
            wrong_unit.to_string().contains("value_urad"),
            "{wrong_unit}"
        );
        let unknown = read_error_description("[EQX]\nvalue_um = 3.0\n").unwrap_err();
        assert!(unknown.to_string().contains("[EQX]"), "{unknown}");
        let both = read_error_description(
            "[EXX]\nvalue_um = 3.0\npositions_mm = [0.0]\nvalues_um = [1.0]\n",
        )
        .unwrap_err();
        assert!(both.to_string().contains("either"), "{both}");
        let table_squareness =
            read_error_description("[EXOY]\npositions_mm = [0.0]\nvalues_urad = [1.0]\n")
                .unwrap_err();
        assert!(
            table_squareness.to_string().contains("constant"),
            "{table_squareness}"
        );
        let ModelError::Toml(syntax) =
            read_error_description("[EXX]\nvalue_um = \"x\"\n").unwrap_err()
        else {
            panic!("a TOML error")
        };
        assert_eq!(syntax.position.line, 2);
    }
}
