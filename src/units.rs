//! Units: every conversion factor axcomp uses, in one tested place.
//!
//! Inside axcomp every length is a millimetre `f64` and every rotary axis'
//! angle a degree `f64`. The numerical core (ISO 230-2's statistics, which
//! are the same arithmetic in mm and in degrees) works on bare numbers in
//! the axis' unit; a value that leaves it for a report gets its unit as a
//! type here: [`Mm`], [`Deg`] for positions and deviations in the axis' unit,
//! [`Um`], [`Arcsec`], [`Urad`] for deviations as reported. A field named
//! `…_mm` of one of these types cannot be given a degree: `Mm` and `Deg`
//! are different types, and the only conversions between units are the
//! methods and functions here. `measurement::AxisKind` gives a bare number
//! its type ([`crate::measurement::Position`], [`crate::measurement::Deviation`]).
//! File units are converted in `read` and display units in `report`, both
//! through the functions here (`../shared/spec/style.md` §5).
//!
//! This module does not format numbers for people; `report` does.

/// Declares a quantity: an `f64` in one unit (`report` writes it to JSON
/// as the bare number, under a key that names the unit).
macro_rules! quantity {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
        pub struct $name(pub f64);
    };
}

quantity!(
    /// A length in millimetres: a linear axis' position or deviation.
    ///
    /// ```
    /// use axcomp::units::{Deg, Mm, Um, Arcsec};
    /// assert_eq!(Mm(0.0025).to_um(), Um(2.5));
    /// assert_eq!(Deg(0.5).to_arcsec(), Arcsec(1800.0));
    /// ```
    /// A degree is not a millimetre: neither given where one is expected
    /// ```compile_fail
    /// use axcomp::units::{Deg, Mm};
    /// let travel: Mm = Deg(90.0);
    /// ```
    /// nor converted as one:
    /// ```compile_fail
    /// use axcomp::units::{Deg, Um};
    /// let offset: Um = Deg(0.001).to_um();
    /// ```
    Mm
);
quantity!(
    /// A length in micrometres: a linear axis' deviation as reported.
    Um
);
quantity!(
    /// An angle in degrees: a rotary axis' position or deviation.
    Deg
);
quantity!(
    /// An angle in arc-seconds (″): a rotary axis' deviation as reported.
    Arcsec
);
quantity!(
    /// An angle in microradians (µrad): a rotary axis' deviation as reported
    /// with `--angle-unit urad`.
    Urad
);

impl Mm {
    /// In micrometres.
    pub fn to_um(self) -> Um {
        Um(mm_to_um(self.0))
    }
}

impl Deg {
    /// In arc-seconds.
    pub fn to_arcsec(self) -> Arcsec {
        Arcsec(deg_to_arcsec(self.0))
    }

    /// In microradians.
    pub fn to_urad(self) -> Urad {
        Urad(deg_to_urad(self.0))
    }
}

/// Micrometres in one millimetre.
pub const UM_PER_MM: f64 = 1000.0;
/// Millimetres in one inch (exact by definition since 1959).
pub const MM_PER_INCH: f64 = 25.4;
/// Millimetres in one metre (the servo model works in SI units).
pub const MM_PER_M: f64 = 1000.0;
/// Arc-seconds in one degree (60 minutes of 60 seconds).
pub const ARCSEC_PER_DEG: f64 = 3600.0;
/// Microradians in one degree: 10⁶·π/180.
pub const URAD_PER_DEG: f64 = 1e6 * std::f64::consts::PI / 180.0;
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

    /// Looks a unit up by name (`mm`, `inch`, `in`).
    pub fn from_name(name: &str) -> Option<LengthUnit> {
        match name.to_ascii_lowercase().as_str() {
            "mm" => Some(LengthUnit::Millimetre),
            "inch" | "in" => Some(LengthUnit::Inch),
            _ => None,
        }
    }

    /// Converts a length in this unit to millimetres.
    pub fn to_mm(self, value: f64) -> f64 {
        match self {
            LengthUnit::Millimetre => value,
            LengthUnit::Inch => inch_to_mm(value),
        }
    }

    /// Converts a length in millimetres to this unit.
    pub fn from_mm(self, value_mm: f64) -> f64 {
        match self {
            LengthUnit::Millimetre => value_mm,
            LengthUnit::Inch => value_mm / MM_PER_INCH,
        }
    }
}

/// The unit a rotary axis' deviations are reported in: arc-seconds (″, the
/// default, as the rotary laser vendors and ISO 230-2's tables quote them) or
/// microradians (µrad, on request). Inside they stay degrees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AngleUnit {
    /// Arc-seconds, ″.
    #[default]
    Arcsec,
    /// Microradians, µrad.
    Urad,
}

impl AngleUnit {
    /// Every unit, in the order `--angle-unit` lists them.
    pub const ALL: [AngleUnit; 2] = [AngleUnit::Arcsec, AngleUnit::Urad];

    /// The name a user types and JSON keys end in: `arcsec` or `urad`.
    pub fn name(self) -> &'static str {
        match self {
            AngleUnit::Arcsec => "arcsec",
            AngleUnit::Urad => "urad",
        }
    }

    /// Looks a unit up by [`AngleUnit::name`].
    pub fn from_name(name: &str) -> Option<AngleUnit> {
        AngleUnit::ALL
            .into_iter()
            .find(|unit| unit.name().eq_ignore_ascii_case(name))
    }

    /// The sign printed after a number: `″` or `µrad`.
    pub fn symbol(self) -> &'static str {
        match self {
            AngleUnit::Arcsec => "″",
            AngleUnit::Urad => "µrad",
        }
    }

    /// An angle in degrees in this unit.
    pub fn from_deg(self, value_deg: f64) -> f64 {
        match self {
            AngleUnit::Arcsec => deg_to_arcsec(value_deg),
            AngleUnit::Urad => deg_to_urad(value_deg),
        }
    }
}

/// The unit a deviation is reported in: µm on a linear axis, the
/// [`AngleUnit`] on a rotary one (`AxisKind::deviation_unit` picks it). One
/// value that every report (terminal, JSON, HTML, plots, diagnosis) converts
/// and labels with, so that a number and its unit cannot disagree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviationUnit {
    /// Micrometres (held inside in mm).
    Micrometre,
    /// An angle unit (held inside in degrees).
    Angle(AngleUnit),
}

impl DeviationUnit {
    /// A deviation held inside (mm, or ° on a rotary axis) in this unit.
    pub fn from_internal(self, value: f64) -> f64 {
        match self {
            DeviationUnit::Micrometre => mm_to_um(value),
            DeviationUnit::Angle(unit) => unit.from_deg(value),
        }
    }

    /// The suffix of a JSON key: `um`, `arcsec` or `urad`.
    pub fn key(self) -> &'static str {
        match self {
            DeviationUnit::Micrometre => "um",
            DeviationUnit::Angle(unit) => unit.name(),
        }
    }

    /// The unit as a table heading writes it: `µm`, `″` or `µrad`.
    pub fn symbol(self) -> &'static str {
        match self {
            DeviationUnit::Micrometre => "µm",
            DeviationUnit::Angle(unit) => unit.symbol(),
        }
    }

    /// What follows a number in a sentence: ` µm`, `″` (set close, as in
    /// 3.2″) or ` µrad`.
    pub fn suffix(self) -> &'static str {
        match self {
            DeviationUnit::Micrometre => " µm",
            DeviationUnit::Angle(AngleUnit::Arcsec) => "″",
            DeviationUnit::Angle(AngleUnit::Urad) => " µrad",
        }
    }
}

/// Millimetres to micrometres.
pub fn mm_to_um(value_mm: f64) -> f64 {
    value_mm * UM_PER_MM
}

/// Micrometres to millimetres.
pub fn um_to_mm(value_um: f64) -> f64 {
    value_um / UM_PER_MM
}

/// A variance in mm² to µm².
pub fn mm2_to_um2(value_mm2: f64) -> f64 {
    value_mm2 * UM_PER_MM * UM_PER_MM
}

/// The shortest decimal text, in µm, that reads back (µm → mm with
/// [`um_to_mm`]) to exactly `value_mm`. `mm_to_um` and `um_to_mm` are not
/// exact inverses in binary floating point, so the nearest neighbours of
/// `value_mm · 1000` are tried too; writers use this so that a file reads back
/// to the very measurement that was written.
pub fn um_text(value_mm: f64) -> String {
    shortest_text(value_mm, mm_to_um, um_to_mm)
}

/// The shortest decimal text, in arc-seconds, that reads back (″ → ° with
/// [`arcsec_to_deg`]) to exactly `value_deg`: [`um_text`] for angles.
pub fn arcsec_text(value_deg: f64) -> String {
    shortest_text(value_deg, deg_to_arcsec, arcsec_to_deg)
}

/// The shortest text of `to(value)` that `back` turns into exactly `value`,
/// trying the nearest neighbours of `to(value)` too.
fn shortest_text(value: f64, to: fn(f64) -> f64, back: fn(f64) -> f64) -> String {
    let scaled = to(value);
    let step = |x: f64, up: bool| {
        // The adjacent f64 (f64::next_up/next_down, written out for rust-version 1.85).
        if x == 0.0 {
            return if up {
                f64::from_bits(1)
            } else {
                -f64::from_bits(1)
            };
        }
        let bits = x.to_bits();
        let larger_magnitude = (x > 0.0) == up;
        f64::from_bits(if larger_magnitude { bits + 1 } else { bits - 1 })
    };
    let mut candidates = vec![scaled];
    let (mut above, mut below) = (scaled, scaled);
    for _ in 0..4 {
        above = step(above, true);
        below = step(below, false);
        candidates.push(above);
        candidates.push(below);
    }
    candidates
        .into_iter()
        .filter(|candidate| back(*candidate) == value)
        .map(|candidate| candidate.to_string())
        .min_by_key(String::len)
        .unwrap_or_else(|| scaled.to_string())
}

/// Degrees to arc-seconds.
pub fn deg_to_arcsec(value_deg: f64) -> f64 {
    value_deg * ARCSEC_PER_DEG
}

/// Arc-seconds to degrees.
pub fn arcsec_to_deg(value_arcsec: f64) -> f64 {
    value_arcsec / ARCSEC_PER_DEG
}

/// An optional angle in degrees to arc-seconds; `None` stays `None`.
pub fn opt_deg_to_arcsec(value_deg: Option<f64>) -> Option<f64> {
    value_deg.map(deg_to_arcsec)
}

/// Degrees to microradians.
pub fn deg_to_urad(value_deg: f64) -> f64 {
    value_deg * URAD_PER_DEG
}

/// Millidegrees (m°, how a diagnosis holds a rotary axis' deviations where
/// a linear axis' are µm) to degrees.
pub fn millideg_to_deg(value_millideg: f64) -> f64 {
    value_millideg / 1000.0
}

/// Degrees to millidegrees (m°), the inverse of [`millideg_to_deg`].
pub fn deg_to_millideg(value_deg: f64) -> f64 {
    value_deg * 1000.0
}

/// Square degrees (a rotary axis' variance) to square millidegrees.
pub fn deg2_to_millideg2(value_deg2: f64) -> f64 {
    deg_to_millideg(deg_to_millideg(value_deg2))
}

/// Arc-seconds to microradians (1″ ≈ 4.848 µrad).
pub fn arcsec_to_urad(value_arcsec: f64) -> f64 {
    deg_to_urad(arcsec_to_deg(value_arcsec))
}

/// Metres to millimetres.
pub fn m_to_mm(value_m: f64) -> f64 {
    value_m * MM_PER_M
}

/// Metres to micrometres.
pub fn m_to_um(value_m: f64) -> f64 {
    mm_to_um(m_to_mm(value_m))
}

/// Millimetres to metres.
pub fn mm_to_m(value_mm: f64) -> f64 {
    value_mm / MM_PER_M
}

/// What a rate per metre (µm/m, ppm) gives over `length_mm`, in the rate's
/// unit (µm/m over 250 mm: µm).
pub fn per_m_over_mm(rate_per_m: f64, length_mm: f64) -> f64 {
    rate_per_m * length_mm / MM_PER_M
}

/// An angle in µrad times a lever in mm, in µm (µrad · mm = nm).
pub fn urad_times_mm_to_um(value_urad_mm: f64) -> f64 {
    value_urad_mm / UM_PER_MM
}

/// An optional length in millimetres to micrometres; `None` stays `None`.
pub fn opt_mm_to_um(value_mm: Option<f64>) -> Option<f64> {
    value_mm.map(mm_to_um)
}

/// An angle in µm/m (µrad, how squareness and angular errors are quoted) to rad.
pub fn um_per_m_to_rad(value_um_per_m: f64) -> f64 {
    // Dividing by the exact 1e6 (rather than multiplying by the inexact 1e-6)
    // makes the round trip through rad_to_um_per_m give back 30, not 29.999…
    value_um_per_m / 1e6
}

/// An angle in rad to µm/m (µrad).
pub fn rad_to_um_per_m(value_rad: f64) -> f64 {
    value_rad * 1e6
}

/// Inches to millimetres.
pub fn inch_to_mm(value_inch: f64) -> f64 {
    value_inch * MM_PER_INCH
}

/// Milliradians to radians.
pub fn mrad_to_rad(value_mrad: f64) -> f64 {
    value_mrad / 1000.0
}

/// Kilopascal to hectopascal (hPa, the unit of Edlén's sensitivities).
pub fn kpa_to_hpa(value_kpa: f64) -> f64 {
    value_kpa * 10.0
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
    fn um_text_reads_back_exactly() {
        for um in [0.71, -0.385, 1.0, 0.0, 123.456, -0.001, 1e-9, 5.0e3] {
            let mm = um_to_mm(um);
            let text = um_text(mm);
            assert_eq!(um_to_mm(text.parse().unwrap()), mm, "{um}: {text}");
        }
        // 0.00071 mm is written as 0.71 µm, not 0.7100000000000001.
        assert_eq!(um_text(um_to_mm(0.71)), "0.71");
    }

    #[test]
    fn environment_conversions_by_hand() {
        // 68 °F is 20 °C; 29.92 inHg is the standard atmosphere, 101.32 kPa.
        assert!((fahrenheit_to_celsius(68.0) - 20.0).abs() < 1e-12);
        assert!((inhg_to_kpa(29.92) - 101.320_759).abs() < 1e-6);
        // 6.7 ppm/°F (API file, steel) is 12.06 ppm/°C.
        assert!((per_fahrenheit_to_per_celsius(6.7) - 12.06).abs() < 1e-12);
        // 0.1 kPa is 1 hPa; 0.1 mrad is 1e-4 rad.
        assert!((kpa_to_hpa(0.1) - 1.0).abs() < 1e-15);
        assert_eq!(mrad_to_rad(0.1), 1e-4);
    }

    #[test]
    fn angle_conversions_by_hand() {
        // 30 µm/m (Valášek (2021) Tab. 3.3) is 30 µrad.
        assert_eq!(um_per_m_to_rad(30.0), 30e-6);
        assert_eq!(rad_to_um_per_m(um_per_m_to_rad(30.0)), 30.0);
    }

    #[test]
    fn rotary_conversions_by_hand() {
        // 1° = 3600″; 1″ = π/648000 rad = 4.848 136 811 µrad.
        assert_eq!(deg_to_arcsec(0.5), 1800.0);
        assert_eq!(arcsec_to_deg(36.0), 0.01);
        // 10 m° (a diagnosis holds a rotary axis in m°) is 0.01° = 36″.
        assert_eq!(millideg_to_deg(10.0), 0.01);
        assert_eq!(deg_to_millideg(0.25), 250.0);
        // A standard deviation of 0.002° (2 m°) is a variance of 4e-6 °², 4 m°².
        assert!((deg2_to_millideg2(4e-6) - 4.0).abs() < 1e-12);
        assert_eq!(opt_deg_to_arcsec(None), None);
        assert!((arcsec_to_urad(1.0) - 4.848_136_811).abs() < 1e-9);
        assert!((deg_to_urad(180.0) - std::f64::consts::PI * 1e6).abs() < 1e-6);
        for arcsec in [1.3, -0.7, 12.25, 0.0, 3.1] {
            let deg = arcsec_to_deg(arcsec);
            let text = arcsec_text(deg);
            assert_eq!(
                arcsec_to_deg(text.parse().unwrap()),
                deg,
                "{arcsec}: {text}"
            );
        }
        assert_eq!(arcsec_text(arcsec_to_deg(1.3)), "1.3");
    }

    #[test]
    fn quantities_convert_by_hand() {
        // 0.0025 mm = 2.5 µm; 0.5° = 1800″; 1° = π/180 rad = 17 453.292 519 943 3 µrad.
        assert_eq!(Mm(0.0025).to_um(), Um(2.5));
        assert_eq!(Deg(0.5).to_arcsec(), Arcsec(1800.0));
        assert!((Deg(1.0).to_urad().0 - 17_453.292_519_943_3).abs() < 1e-9);
    }

    #[test]
    fn deviation_units_by_hand() {
        // 1° = 3600″ = 17 453.292 5 µrad (π/180 · 10⁶); 0.001 mm = 1 µm.
        assert_eq!(
            DeviationUnit::Angle(AngleUnit::Arcsec).from_internal(1.0),
            3600.0
        );
        assert!(
            (DeviationUnit::Angle(AngleUnit::Urad).from_internal(1.0) - 17_453.292_519_943_3).abs()
                < 1e-9
        );
        assert_eq!(DeviationUnit::Micrometre.from_internal(0.5), 500.0);
        assert_eq!(AngleUnit::from_name("URAD"), Some(AngleUnit::Urad));
        assert_eq!(AngleUnit::from_name("mrad"), None);
        assert_eq!(DeviationUnit::Angle(AngleUnit::Urad).key(), "urad");
        assert_eq!(DeviationUnit::Angle(AngleUnit::Urad).suffix(), " µrad");
    }
}
