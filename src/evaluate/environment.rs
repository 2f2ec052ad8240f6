//! The test conditions checked: is the refractive index of air the laser used
//! the one the recorded air conditions give?
//!
//! A Renishaw XL-80 with its XC-80 compensator corrects the laser wavelength
//! for the air with the simplified empirical Edlén equation of Kadlečík (2019),
//! eq. (36):
//!
//! ```text
//! n_air = 1 + 7.86·10⁻⁵ · P / (273 + T) − 1.5·10⁻¹¹ · H · (T² + 160)
//! ```
//!
//! with T the air temperature in °C, P the pressure in mbar (hPa: with P in
//! mbar, n − 1 ≈ 2.7·10⁻⁴ as it must be) and H the relative humidity in %.
//! At 20 °C it agrees with the full modified Edlén equation of NIST (Stone &
//! Zimmerman) to 0.03 ppm (see the tests); at 60 °C it is 0.7 ppm off, so it
//! is a workshop-temperature formula.
//!
//! The `.rtl` file records the factor the laser applied ("Env factor", µm).
//! `../shared/spec/renishaw-rtl.md` reads it as λ_vac / (2·n_air). The only
//! real file we have (Kadlečík's (2019) X axis, Table 9; its ENVIRONMENT lines are in
//! the spec) says it also holds the normal-temperature correction of the
//! material: between start and end the factor falls by 0.917 ppm, while
//! eq. (36) changes n_air by only −0.016 ppm and the material sensor rose by
//! 0.118 K at 8 ppm/K, i.e. 0.944 ppm; −0.944 + 0.016 = −0.928 ppm, within the
//! factor's eight digits (0.03 ppm). So the factor is taken as
//!
//! ```text
//! factor = λ_vac / (2 · n_air · (1 + α · (T_material − 20 °C)))
//! ```
//!
//! and the index it implies is compared with eq. (36). Where the file has no
//! material temperature or expansion coefficient, the correction is left out
//! and the comparison says so. The laser's vacuum wavelength is taken from the
//! file when recorded (API `.pos`), else [`ASSUMED_VACUUM_WAVELENGTH_UM`].
//!
//! Pure: values in, values out.

use crate::measurement::{Environment, StartEnd};

/// The HeNe vacuum wavelength assumed when the file does not record one, µm
/// (`../shared/spec/renishaw-rtl.md`: "λ_vac ≈ 0.632991 µm for HeNe"). A
/// stabilised HeNe tube's wavelength is known to better than 0.1 ppm, but
/// which one a file's laser had is not: 632.990 nm to 632.991 nm spans
/// 1.6 ppm, which is why [`AGREEMENT_PPM`] is not smaller.
pub const ASSUMED_VACUUM_WAVELENGTH_UM: f64 = 0.632991;

/// Largest |difference| between the implied index and eq. (36) that counts
/// as agreement, ppm: the spread of HeNe vacuum wavelengths when the file does
/// not give it (about ±0.8 ppm around the assumed one), eq. (36) against the
/// full Edlén equation (0.03 ppm at 20 °C) and the factor's eight digits
/// (0.03 ppm).
pub const AGREEMENT_PPM: f64 = 1.0;

/// The reference temperature of ISO 1 to which lengths are referred, °C.
pub const REFERENCE_TEMPERATURE_C: f64 = 20.0;

/// The refractive index of air by Kadlečík (2019) eq. (36): air temperature °C,
/// pressure kPa (as `Environment` keeps it), relative humidity %.
///
/// # Example
/// ```
/// use axcomp::evaluate::environment::edlen_seed001;
/// // Standard air, 20 °C, 1013.25 mbar, 50 %RH, by hand:
/// // 7.86e-5 · 1013.25 / 293 − 1.5e-11 · 50 · 560 = 2.718138e-4 − 4.2e-7.
/// let n = edlen_seed001(20.0, 101.325, 50.0);
/// assert!((n - 1.000_271_393_8).abs() < 1e-10);
/// ```
pub fn edlen_seed001(air_temperature_c: f64, air_pressure_kpa: f64, humidity_pct: f64) -> f64 {
    let pressure_mbar = air_pressure_kpa * 10.0;
    let t = air_temperature_c;
    1.0 + 7.86e-5 * pressure_mbar / (273.0 + t) - 1.5e-11 * humidity_pct * (t * t + 160.0)
}

/// The environmental factor a laser records for these conditions, µm: the
/// half wavelength in air with the material correction,
/// λ_vac / (2 · n_air · (1 + α·(T_material − 20 °C))), n_air by eq. (36) —
/// the relation [`check_refractive_index`] inverts. `axcomp synth` writes it
/// so that its files pass the check.
pub fn environmental_factor_um(
    air_temperature_c: f64,
    air_pressure_kpa: f64,
    humidity_pct: f64,
    material_correction_ppm: f64,
    vacuum_wavelength_um: f64,
) -> f64 {
    let n = edlen_seed001(air_temperature_c, air_pressure_kpa, humidity_pct);
    vacuum_wavelength_um / (2.0 * n * (1.0 + material_correction_ppm * 1e-6))
}

/// The comparison at the start or the end of the test.
#[derive(Clone, Debug, PartialEq)]
pub enum IndexComparison {
    /// Everything needed was recorded.
    Made(IndexAt),
    /// What the file lacks for it (`"environmental factor"`, `"air temperature"`, …).
    Missing(Vec<&'static str>),
}

/// The index the factor implies and the one eq. (36) gives, at one moment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IndexAt {
    /// The factor recorded, µm.
    pub factor_um: f64,
    /// n_air implied by the factor (with the material correction, if known).
    pub implied_n: f64,
    /// n_air by eq. (36) from the recorded air temperature, pressure, humidity.
    pub edlen_n: f64,
    /// (implied − Edlén) · 10⁶: a length error of this many µm per metre.
    pub difference_ppm: f64,
    /// The material correction α·(T_material − 20 °C) taken out of the factor,
    /// ppm; `None` when the file has no material temperature or coefficient.
    pub material_correction_ppm: Option<f64>,
}

impl IndexAt {
    /// Whether the difference is within [`AGREEMENT_PPM`].
    pub fn agrees(&self) -> bool {
        self.difference_ppm.abs() <= AGREEMENT_PPM
    }
}

/// The check at the start and the end of the test.
#[derive(Clone, Debug, PartialEq)]
pub struct RefractiveIndexCheck {
    /// The vacuum wavelength used, µm.
    pub vacuum_wavelength_um: f64,
    /// Whether it was assumed ([`ASSUMED_VACUUM_WAVELENGTH_UM`]) rather than recorded.
    pub wavelength_assumed: bool,
    /// At the start of the test.
    pub start: IndexComparison,
    /// At the end of the test.
    pub end: IndexComparison,
}

/// Checks the recorded environmental factor against eq. (36).
///
/// # Example
/// ```
/// use axcomp::evaluate::environment::{IndexComparison, check_refractive_index};
/// use axcomp::measurement::Environment;
/// // A file without an environmental factor cannot be checked, and says why.
/// let check = check_refractive_index(&Environment::default());
/// let IndexComparison::Missing(missing) = &check.start else { panic!() };
/// assert_eq!(missing[0], "environmental factor");
/// ```
pub fn check_refractive_index(environment: &Environment) -> RefractiveIndexCheck {
    let (vacuum_wavelength_um, wavelength_assumed) = match environment.vacuum_wavelength_um {
        Some(recorded) => (recorded, false),
        None => (ASSUMED_VACUUM_WAVELENGTH_UM, true),
    };
    let at = |pick: fn(&StartEnd) -> Option<f64>| compare(environment, vacuum_wavelength_um, pick);
    RefractiveIndexCheck {
        vacuum_wavelength_um,
        wavelength_assumed,
        start: at(|s| s.start),
        end: at(|s| s.end),
    }
}

fn compare(
    environment: &Environment,
    vacuum_wavelength_um: f64,
    pick: fn(&StartEnd) -> Option<f64>,
) -> IndexComparison {
    let factor = pick(&environment.environmental_factor_um).filter(|f| *f > 0.0);
    let temperature = pick(&environment.air_temperature_c);
    let pressure = pick(&environment.air_pressure_kpa);
    let humidity = pick(&environment.air_humidity_pct);
    let (Some(factor_um), Some(t), Some(p), Some(h)) = (factor, temperature, pressure, humidity)
    else {
        let named = [
            (factor.is_none(), "environmental factor"),
            (temperature.is_none(), "air temperature"),
            (pressure.is_none(), "air pressure"),
            (humidity.is_none(), "air humidity"),
        ];
        let missing = named
            .iter()
            .filter(|(absent, _)| *absent)
            .map(|(_, name)| *name)
            .collect();
        return IndexComparison::Missing(missing);
    };
    let material_correction_ppm = material_temperature_c(environment, pick)
        .zip(environment.expansion_coefficient_ppm_per_k)
        .map(|(material_c, alpha)| alpha * (material_c - REFERENCE_TEMPERATURE_C));
    let material_factor = 1.0 + material_correction_ppm.unwrap_or(0.0) * 1e-6;
    let implied_n = vacuum_wavelength_um / (2.0 * factor_um * material_factor);
    let edlen_n = edlen_seed001(t, p, h);
    IndexComparison::Made(IndexAt {
        factor_um,
        implied_n,
        edlen_n,
        difference_ppm: (implied_n - edlen_n) * 1e6,
        material_correction_ppm,
    })
}

/// The mean of the fitted material sensors, °C (the laser software averages
/// them), at the start or the end of the test as `pick` says.
pub fn material_temperature_c(
    environment: &Environment,
    pick: fn(&StartEnd) -> Option<f64>,
) -> Option<f64> {
    let fitted: Vec<f64> = environment
        .material_temperature_c
        .iter()
        .filter_map(pick)
        .collect();
    (!fitted.is_empty()).then(|| fitted.iter().sum::<f64>() / fitted.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// NIST's modified Edlén equation (Stone & Zimmerman, NIST Engineering
    /// Metrology Toolbox) as implemented by the PyPI package `ref_index`,
    /// whose README gives these outputs for λ = 633.0 nm, 101 325 Pa
    /// (`../shared/notes/anchors-and-standards.md` §3.5), digits as published.
    #[allow(clippy::excessive_precision)]
    const NIST_EDLEN: [(f64, f64, f64); 3] = [
        (20.0, 20.0, 1.000_271_629_169_164_9),
        (20.0, 80.0, 1.000_271_119_763_522_6),
        (60.0, 80.0, 1.000_233_974_854_282_3),
    ];

    #[test]
    fn eq36_agrees_with_nist_edlen_at_workshop_temperature() {
        for (t, h, nist) in NIST_EDLEN {
            let difference_ppm = (edlen_seed001(t, 101.325, h) - nist) * 1e6;
            if t < 30.0 {
                assert!(
                    difference_ppm.abs() < 0.03,
                    "{t} °C {h} %: {difference_ppm} ppm"
                );
            } else {
                // The simplified equation is for the workshop: at 60 °C it is 0.68 ppm high.
                assert!((difference_ppm - 0.677).abs() < 0.01, "{difference_ppm}");
            }
        }
    }

    /// The ENVIRONMENT lines of Kadlečík's (2019) own X-axis file (Table 9), as the
    /// `.rtl` spec quotes them.
    fn seed001_table9() -> Environment {
        let pair = |start, end| StartEnd::new(Some(start), Some(end));
        Environment {
            air_temperature_c: pair(20.337280, 20.384956),
            air_pressure_kpa: pair(99.039005, 99.049346),
            air_humidity_pct: pair(46.954897, 46.893887),
            material_temperature_c: [
                pair(20.203292, 20.321342),
                StartEnd::default(),
                StartEnd::default(),
            ],
            expansion_coefficient_ppm_per_k: Some(8.0),
            environmental_factor_um: pair(0.31641096, 0.31641067),
            vacuum_wavelength_um: None,
        }
    }

    #[test]
    fn the_real_file_agrees_once_the_material_correction_is_taken_out() {
        let check = check_refractive_index(&seed001_table9());
        assert!(check.wavelength_assumed);
        let (IndexComparison::Made(start), IndexComparison::Made(end)) = (&check.start, &check.end)
        else {
            panic!("{check:?}")
        };
        // By hand at the start: eq. (36) gives n − 1 = 7.86e-5·990.39005/293.33728
        // − 1.5e-11·46.954897·(20.33728² + 160) = 264.972 ppm; the factor gives
        // 0.632991 / (2·0.31641096·(1 + 8·0.203292e-6)) − 1 = 265.557 ppm.
        assert!(
            (start.edlen_n - 1.000_264_972).abs() < 1e-9,
            "{}",
            start.edlen_n
        );
        assert!(
            (start.implied_n - 1.000_265_557).abs() < 2e-9,
            "{}",
            start.implied_n
        );
        assert!((start.material_correction_ppm.unwrap() - 1.626_336).abs() < 1e-6);
        assert!(start.agrees() && end.agrees(), "{start:?} {end:?}");
        // The material correction makes start and end agree with each other to
        // the factor's eight digits; without it they would be 0.93 ppm apart.
        assert!((start.difference_ppm - end.difference_ppm).abs() < 0.05);
    }

    #[test]
    fn without_material_sensors_the_factor_is_read_as_the_spec_says() {
        let mut environment = seed001_table9();
        environment.material_temperature_c[0] = StartEnd::default();
        let check = check_refractive_index(&environment);
        let IndexComparison::Made(start) = check.start else {
            panic!()
        };
        assert_eq!(start.material_correction_ppm, None);
        // 0.632991 / (2·0.31641096) − 1 = 267.184 ppm, 2.21 ppm above eq. (36).
        assert!(
            (start.difference_ppm - 2.212).abs() < 0.002,
            "{}",
            start.difference_ppm
        );
        assert!(!start.agrees());
    }

    #[test]
    fn a_recorded_wavelength_is_used_and_missing_values_are_named() {
        let mut environment = seed001_table9();
        environment.vacuum_wavelength_um = Some(0.632_990_35);
        environment.air_humidity_pct = StartEnd::new(Some(46.9), None);
        environment.environmental_factor_um = StartEnd::new(Some(0.31641096), None);
        environment.air_temperature_c.end = None;
        let check = check_refractive_index(&environment);
        assert!(!check.wavelength_assumed);
        assert_eq!(check.vacuum_wavelength_um, 0.632_990_35);
        assert!(matches!(check.start, IndexComparison::Made(_)));
        assert_eq!(
            check.end,
            IndexComparison::Missing(vec![
                "environmental factor",
                "air temperature",
                "air humidity"
            ])
        );
    }
}
