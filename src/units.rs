//! Units: every conversion factor axcomp uses, in one tested place.
//!
//! Inside axcomp every length is a millimetre `f64` (`target_mm`,
//! `deviation_mm`); file units are converted in `read` and display units in
//! `report`, and both go through the functions here. The aliases below
//! document a unit; they do not check it, which is why each name also carries
//! the unit (see `../shared/spec/style.md` §5).
//!
//! This module does not format numbers for people; `report` does.

/// A length in millimetres.
pub type Mm = f64;
/// A length in micrometres.
pub type Um = f64;

/// Micrometres in one millimetre.
pub const UM_PER_MM: f64 = 1000.0;
/// Millimetres in one inch (exact by definition since 1959).
pub const MM_PER_INCH: f64 = 25.4;
/// Millimetres in one metre (the servo model works in SI units).
pub const MM_PER_M: f64 = 1000.0;
/// Kilopascal in one inch of mercury at 0 °C (NIST SP 811, B.8: 3.386 389 kPa).
pub const KPA_PER_INHG: f64 = 3.386_389;

/// The length unit a source file was written in, kept for reporting.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LengthUnit {
    /// Millimetres.
    #[default]
    Millimetre,
    /// Inches.
    Inch,
}

impl LengthUnit {
    /// The short name used in files and reports: `mm` or `inch`.
    pub fn as_str(self) -> &'static str {
        match self {
            LengthUnit::Millimetre => "mm",
            LengthUnit::Inch => "inch",
        }
    }

    /// Converts a length in this unit to millimetres.
    pub fn to_mm(self, value: f64) -> Mm {
        match self {
            LengthUnit::Millimetre => value,
            LengthUnit::Inch => inch_to_mm(value),
        }
    }

    /// Converts a length in millimetres to this unit.
    pub fn from_mm(self, value_mm: Mm) -> f64 {
        match self {
            LengthUnit::Millimetre => value_mm,
            LengthUnit::Inch => value_mm / MM_PER_INCH,
        }
    }
}

/// Millimetres to micrometres.
pub fn mm_to_um(value_mm: Mm) -> Um {
    value_mm * UM_PER_MM
}

/// Micrometres to millimetres.
pub fn um_to_mm(value_um: Um) -> Mm {
    value_um / UM_PER_MM
}

/// Metres to millimetres.
pub fn m_to_mm(value_m: f64) -> Mm {
    value_m * MM_PER_M
}

/// Metres to micrometres.
pub fn m_to_um(value_m: f64) -> Um {
    mm_to_um(m_to_mm(value_m))
}

/// Millimetres to metres.
pub fn mm_to_m(value_mm: Mm) -> f64 {
    value_mm / MM_PER_M
}

/// An optional length in millimetres to micrometres; `None` stays `None`.
pub fn opt_mm_to_um(value_mm: Option<Mm>) -> Option<Um> {
    value_mm.map(mm_to_um)
}

/// Inches to millimetres.
pub fn inch_to_mm(value_inch: f64) -> Mm {
    value_inch * MM_PER_INCH
}

/// Degrees Fahrenheit to degrees Celsius.
pub fn fahrenheit_to_celsius(value_f: f64) -> f64 {
    (value_f - 32.0) * 5.0 / 9.0
}

/// Inches of mercury to kilopascal.
pub fn inhg_to_kpa(value_inhg: f64) -> f64 {
    value_inhg * KPA_PER_INHG
}

/// An expansion coefficient per °F to the same per °C (a kelvin is 1.8 °F).
pub fn per_fahrenheit_to_per_celsius(value_per_f: f64) -> f64 {
    value_per_f * 1.8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn length_conversions_by_hand() {
        assert_eq!(mm_to_um(0.0123), 12.3);
        assert_eq!(um_to_mm(12.5), 0.0125);
        assert_eq!(inch_to_mm(0.000055), 0.001397);
        assert_eq!(LengthUnit::Inch.to_mm(130.0), 3302.0);
        assert!((LengthUnit::Inch.from_mm(25.4) - 1.0).abs() < 1e-15);
        assert_eq!(LengthUnit::Millimetre.to_mm(7.5), 7.5);
        assert_eq!(opt_mm_to_um(None), None);
        assert_eq!(m_to_mm(0.09), 90.0);
        assert!((m_to_um(1.8e-6) - 1.8).abs() < 1e-12);
        assert_eq!(mm_to_m(500.0), 0.5);
    }

    #[test]
    fn environment_conversions_by_hand() {
        // 68 °F is 20 °C; 29.92 inHg is the standard atmosphere, 101.32 kPa.
        assert!((fahrenheit_to_celsius(68.0) - 20.0).abs() < 1e-12);
        assert!((inhg_to_kpa(29.92) - 101.320_759).abs() < 1e-6);
        // 6.7 ppm/°F (API file, steel) is 12.06 ppm/°C.
        assert!((per_fahrenheit_to_per_celsius(6.7) - 12.06).abs() < 1e-12);
    }
}
