//! The angular error of the axis along its stroke (`--angular`): the pitch or
//! yaw an angular laser measurement gives, for the Abbe effect.

use crate::error::{ParseError, describe_found};

/// An angular error along the axis, µrad at positions, mm.
#[derive(Clone, Debug, PartialEq)]
pub struct AngularProfile {
    /// Positions, mm, increasing.
    pub positions_mm: Vec<f64>,
    /// Angle there, µrad.
    pub angle_urad: Vec<f64>,
}

impl AngularProfile {
    /// Reads `position_mm,angle_urad` lines (that header first; `#` starts a
    /// comment), positions strictly increasing, at least two: the pitch or
    /// yaw of the axis from an angular laser measurement.
    ///
    /// ```
    /// use axcomp::diagnose::AngularProfile;
    ///
    /// let profile = AngularProfile::from_csv_str("position_mm,angle_urad\n0,0\n375,12.5\n750,0\n")?;
    /// assert_eq!(profile.angle_urad, [0.0, 12.5, 0.0]);
    /// # Ok::<(), axcomp::error::ParseError>(())
    /// ```
    pub fn from_csv_str(text: &str) -> Result<AngularProfile, ParseError> {
        let mut rows = text
            .lines()
            .enumerate()
            .map(|(i, line)| (i + 1, line.split('#').next().unwrap_or("").trim()))
            .filter(|(_, line)| !line.is_empty());
        let header: Vec<&str> = rows
            .next()
            .map_or(Vec::new(), |(_, l)| l.split(',').map(str::trim).collect());
        if header != ["position_mm", "angle_urad"] {
            return Err(ParseError::expected(
                1,
                1,
                "the header position_mm,angle_urad",
                &header.join(","),
            ));
        }
        let mut profile = AngularProfile {
            positions_mm: Vec::new(),
            angle_urad: Vec::new(),
        };
        for (number, line) in rows {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            let [position, angle] = fields[..] else {
                return Err(ParseError::expected(
                    number,
                    1,
                    "two fields: position_mm,angle_urad",
                    line,
                ));
            };
            let parse = |field: &str, column: usize| {
                field
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        ParseError::expected(number, column, "a number", &describe_found(field))
                    })
            };
            let x = parse(position, 1)?;
            if profile.positions_mm.last().is_some_and(|last| x <= *last) {
                return Err(ParseError::expected(
                    number,
                    1,
                    "positions strictly increasing",
                    position,
                ));
            }
            profile.positions_mm.push(x);
            profile.angle_urad.push(parse(angle, position.len() + 2)?);
        }
        if profile.positions_mm.len() < 2 {
            return Err(ParseError::new(
                1,
                1,
                "expected at least two positions with an angle",
            ));
        }
        Ok(profile)
    }
}
