//! The measurement uncertainty of a laser positioning test: the equipment
//! that measured it ([`Equipment`], from TOML) and the budget of
//! `../shared/spec/standards.md` §4 ([`budget`]).
//!
//! Each contributor is a standard uncertainty of the measured length
//! L = largest − smallest target:
//!
//! | contributor | formula (µm, L in m) |
//! |---|---|
//! | u_DEVICE | (U_laser / k) · L |
//! | u_AIR (only when the laser figure excludes its air compensation) | L · √((0.93 u_T)² + (0.27 u_P)² + (0.0085 u_RH)²), u in °C, hPa, %RH (Edlén's sensitivities) |
//! | u_MISALIGNMENT | L · 10⁶ · (1 − cos θ) / √3 |
//! | u_M,MACHINE | L · α · u_Tmat |
//! | u_E,MACHINE | L · \|T_mat − 20 °C\| · u_α, u_α = (limit of α) / √3 |
//! | u_EVE | E_VE / (2√3) |
//!
//! combined u_c = √Σu², and U(E) = U(M) = U(A) = 2 · u_c (k = 2). The spec's
//! definition is reconstructed [R] (ISO 230-2:2014 Annex A style; the
//! standard's text is not public). U(R) and U(B) are not evaluated: no
//! public form was found, and the report says so.
//!
//! α and the material temperature come from the measurement's environment
//! when the file records them, otherwise from the equipment's assumed
//! values; each contributor's `source` says which.
//!
//! # The equipment file
//!
//! ```toml
//! [laser]
//! U_um_per_m = 0.5                 # expanded uncertainty, µm/m
//! k = 2                            # its coverage factor
//! u_includes_air_compensation = true
//! [air]                            # standard uncertainties (u_AIR only when the above is false)
//! temperature_u_c = 0.1
//! pressure_u_kpa = 0.1
//! humidity_u_pct = 6
//! [material]
//! temperature_u_c = 0.1            # u_Tmat
//! expansion_coefficient_limit_ppm_per_k = 1   # ± limit of α, µm/(m·°C)
//! assumed_expansion_coefficient_ppm_per_k = 11.5  # α when the file records none
//! assumed_temperature_c = 22       # T_mat when the file records none
//! [alignment]
//! misalignment_mrad = 0.1          # θ
//! [environmental_variation]
//! eve_um = 0                       # or drift_test = "drift.rtl" (not both)
//! ```
//!
//! Every key is required (the bundled `fixtures/equipment/hene-default.toml`
//! is a complete example, every value with its source); unknown keys and
//! negative or non-finite numbers are errors at their line and column. A
//! drift test is a measurement file: the CLI reads it (this module does no
//! I/O) and gives it to [`Equipment::with_drift_test`]; E_VE is then the
//! range of its deviations.
//!
//! Pure: no I/O. Lengths in mm inside; µm, hPa and mrad through `crate::units`.

use std::fmt;

use serde::Deserialize;

use crate::error::ParseError;
use crate::evaluate::environment::{REFERENCE_TEMPERATURE_C, material_temperature_c};
use crate::measurement::Measurement;
use crate::units::{kpa_to_hpa, mm_to_um, mrad_to_rad, per_m_over_mm, um_to_mm};

/// The bundled profile: a typical HeNe laser with air and material sensors.
pub const DEFAULT_EQUIPMENT_TOML: &str = include_str!("../../fixtures/equipment/hene-default.toml");

/// What the bundled profile is called in budgets and reports.
pub const DEFAULT_EQUIPMENT_NAME: &str =
    "bundled typical HeNe laser (fixtures/equipment/hene-default.toml)";

/// The coverage factor of U(E), U(M), U(A) (standards.md §4).
pub const COVERAGE_FACTOR: f64 = 2.0;

/// Edlén's sensitivities near 20 °C and 1013 hPa, µm/m per °C, hPa and %RH
/// (standards.md §4: dn/dT ≈ −0.93·10⁻⁶/K, dn/dP ≈ +0.27·10⁻⁶/hPa,
/// dn/dRH ≈ −0.0085·10⁻⁶/%; the signs vanish in the squares).
const EDLEN_PER_C: f64 = 0.93;
const EDLEN_PER_HPA: f64 = 0.27;
const EDLEN_PER_PCT_RH: f64 = 0.0085;

/// The measuring equipment, as its certificate or data sheet states it.
#[derive(Clone, Debug, PartialEq)]
pub struct Equipment {
    /// What the profile is (its file, or the bundled one), for the report.
    pub name: String,
    /// The laser's expanded uncertainty, µm/m.
    pub laser_expanded_um_per_m: f64,
    /// Its coverage factor k.
    pub laser_k: f64,
    /// Whether the laser figure includes the air compensation (no u_AIR then).
    pub laser_includes_air: bool,
    /// Standard uncertainty of the air temperature, °C.
    pub air_temperature_u_c: f64,
    /// Standard uncertainty of the air pressure, kPa.
    pub air_pressure_u_kpa: f64,
    /// Standard uncertainty of the relative humidity, %RH.
    pub air_humidity_u_pct: f64,
    /// Standard uncertainty of the material temperature u_Tmat, °C.
    pub material_temperature_u_c: f64,
    /// The ± limit of the expansion coefficient, µm/(m·°C).
    pub expansion_coefficient_limit_ppm_per_k: f64,
    /// α when the measurement records none, µm/(m·°C).
    pub assumed_expansion_coefficient_ppm_per_k: f64,
    /// T_mat when the measurement records none, °C.
    pub assumed_material_temperature_c: f64,
    /// The beam-to-axis angle θ, mrad.
    pub misalignment_mrad: f64,
    /// E_VE, or where to get it.
    pub environmental_variation: EnvironmentalVariation,
}

/// Where E_VE, the environmental variation, comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentalVariation {
    /// Given in the profile (`eve_um`), mm.
    Given {
        /// E_VE, mm.
        eve_mm: f64,
    },
    /// A drift-test file (`drift_test`), not read yet: the CLI reads it and
    /// calls [`Equipment::with_drift_test`].
    DriftTest {
        /// The path as the profile gives it.
        path: String,
    },
    /// The range of a drift test's deviations.
    Measured {
        /// E_VE, mm.
        eve_mm: f64,
        /// The drift test, as the user named it.
        file: String,
    },
}

/// Why no budget can be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum UncertaintyError {
    /// The profile names a drift test that was not read.
    #[error("the drift test {path} has not been read (E_VE is its range)")]
    DriftTestNotRead {
        /// The path as the profile gives it.
        path: String,
    },
}

/// One contributor to the budget.
#[derive(Clone, Debug, PartialEq)]
pub struct Contributor {
    /// `u_DEVICE`, `u_AIR`, `u_MISALIGNMENT`, `u_M,MACHINE`, `u_E,MACHINE`, `u_EVE`.
    pub name: &'static str,
    /// Its standard uncertainty over the measured length, mm.
    pub u_mm: f64,
    /// Where its inputs come from and how it follows, one sentence.
    pub source: String,
}

/// The uncertainty budget of one test.
#[derive(Clone, Debug, PartialEq)]
pub struct Budget {
    /// The profile used ([`Equipment::name`]).
    pub equipment: String,
    /// L, the measured length: largest − smallest target, mm.
    pub length_mm: f64,
    /// The contributors, largest first.
    pub contributors: Vec<Contributor>,
    /// u_c = √Σu², mm.
    pub combined_mm: f64,
    /// The coverage factor k of the expanded uncertainty.
    pub coverage_factor: f64,
    /// U = k · u_c, mm: U(E) = U(M) = U(A).
    pub expanded_mm: f64,
}

impl Equipment {
    /// Reads an equipment profile (see the module doc); `name` says what it
    /// is in the budget (the file, as the user named it). Errors carry the
    /// line and column.
    ///
    /// # Example
    /// ```
    /// use axcomp::evaluate::uncertainty::{DEFAULT_EQUIPMENT_TOML, Equipment};
    /// let equipment = Equipment::from_toml_str(DEFAULT_EQUIPMENT_TOML, "default").unwrap();
    /// assert_eq!(equipment.laser_expanded_um_per_m, 0.5);
    /// let bad = DEFAULT_EQUIPMENT_TOML.replacen("\nk = 2", "\nk = 2\nq = 1", 1);
    /// let error = Equipment::from_toml_str(&bad, "bad").unwrap_err();
    /// assert!(error.message.contains("unknown field `q`"), "{error}");
    /// ```
    pub fn from_toml_str(text: &str, name: &str) -> Result<Equipment, ParseError> {
        let raw: RawEquipment =
            toml::from_str(text).map_err(|e| ParseError::from_toml(text, &e))?;
        Ok(Equipment {
            name: name.to_string(),
            laser_expanded_um_per_m: raw.laser.expanded_um_per_m.0,
            laser_k: raw.laser.k.0,
            laser_includes_air: raw.laser.u_includes_air_compensation,
            air_temperature_u_c: raw.air.temperature_u_c.0,
            air_pressure_u_kpa: raw.air.pressure_u_kpa.0,
            air_humidity_u_pct: raw.air.humidity_u_pct.0,
            material_temperature_u_c: raw.material.temperature_u_c.0,
            expansion_coefficient_limit_ppm_per_k: raw
                .material
                .expansion_coefficient_limit_ppm_per_k
                .0,
            assumed_expansion_coefficient_ppm_per_k: raw
                .material
                .assumed_expansion_coefficient_ppm_per_k
                .0,
            assumed_material_temperature_c: raw.material.assumed_temperature_c.0,
            misalignment_mrad: raw.alignment.misalignment_mrad.0,
            environmental_variation: raw.environmental_variation,
        })
    }

    /// The bundled profile ([`DEFAULT_EQUIPMENT_TOML`]).
    pub fn bundled() -> Equipment {
        // The bundled text is not user input; a test parses it.
        Equipment::from_toml_str(DEFAULT_EQUIPMENT_TOML, DEFAULT_EQUIPMENT_NAME)
            .expect("the bundled equipment profile parses")
    }

    /// The drift test the profile names and that is still to be read.
    pub fn drift_test_path(&self) -> Option<&str> {
        match &self.environmental_variation {
            EnvironmentalVariation::DriftTest { path } => Some(path),
            _ => None,
        }
    }

    /// The profile with E_VE from a drift test: the range of all its
    /// deviations (`file` names it in the budget).
    pub fn with_drift_test(mut self, drift_test: &Measurement, file: &str) -> Equipment {
        let readings = drift_test
            .runs()
            .iter()
            .flat_map(|run| run.deviations.iter().flatten().copied());
        let (low, high) = readings.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
        let eve_mm = if high >= low { high - low } else { 0.0 };
        self.environmental_variation = EnvironmentalVariation::Measured {
            eve_mm,
            file: file.to_string(),
        };
        self
    }
}

/// The budget of `measurement` measured with `equipment` (standards.md §4).
///
/// # Example
/// ```
/// use axcomp::evaluate::uncertainty::{Equipment, budget};
/// use axcomp::measurement::{Direction, Measurement, Run};
/// let run = |direction| Run { direction, number: 1, start_time_s: None,
///     deviations: vec![Some(0.0), Some(0.001)] };
/// let m = Measurement::new("X", vec![0.0, 1000.0], vec![run(Direction::Up), run(Direction::Down)],
///     Default::default(), Default::default()).unwrap();
/// let b = budget(&m, &Equipment::bundled()).unwrap();
/// // u_DEVICE = 0.5 µm/m / 2 · 1 m = 0.25 µm.
/// let device = b.contributors.iter().find(|c| c.name == "u_DEVICE").unwrap();
/// assert!((device.u_mm - 0.000_25).abs() < 1e-12);
/// assert!((b.expanded_mm - 2.0 * b.combined_mm).abs() < 1e-15);
/// ```
pub fn budget(
    measurement: &Measurement,
    equipment: &Equipment,
) -> Result<Budget, UncertaintyError> {
    let targets = measurement.targets();
    let length_mm = match (targets.first(), targets.last()) {
        (Some(first), Some(last)) => last - first,
        _ => 0.0,
    };
    let over_length = |per_m: f64| per_m_over_mm(per_m, length_mm);
    let length = format!("L = {length_mm} mm");
    let mut contributors = Vec::new();

    let includes = if equipment.laser_includes_air {
        "including the air compensation"
    } else {
        "excluding the air compensation"
    };
    contributors.push(Contributor {
        name: "u_DEVICE",
        u_mm: um_to_mm(over_length(
            equipment.laser_expanded_um_per_m / equipment.laser_k,
        )),
        source: format!(
            "laser {} µm/m at k = {} ({includes}) / k · {length}",
            equipment.laser_expanded_um_per_m, equipment.laser_k
        ),
    });

    if !equipment.laser_includes_air {
        let pressure_u_hpa = kpa_to_hpa(equipment.air_pressure_u_kpa);
        let per_m = ((EDLEN_PER_C * equipment.air_temperature_u_c).powi(2)
            + (EDLEN_PER_HPA * pressure_u_hpa).powi(2)
            + (EDLEN_PER_PCT_RH * equipment.air_humidity_u_pct).powi(2))
        .sqrt();
        contributors.push(Contributor {
            name: "u_AIR",
            u_mm: um_to_mm(over_length(per_m)),
            source: format!(
                "air sensors u = {} °C, {:.2} hPa, {} %RH through Edlén's sensitivities \
                 0.93, 0.27, 0.0085 µm/m per unit · {length}",
                equipment.air_temperature_u_c, pressure_u_hpa, equipment.air_humidity_u_pct
            ),
        });
    }

    // 1 − cos θ = 2 sin²(θ/2), without the cancellation of 1 − cos at 10⁻⁴ rad.
    let theta_rad = mrad_to_rad(equipment.misalignment_mrad);
    let cosine_error_per_m = 1e6 * 2.0 * (theta_rad / 2.0).sin().powi(2);
    contributors.push(Contributor {
        name: "u_MISALIGNMENT",
        u_mm: um_to_mm(over_length(cosine_error_per_m / 3f64.sqrt())),
        source: format!(
            "beam-to-axis angle θ = {} mrad: 10⁶ (1 − cos θ) / √3 · {length}",
            equipment.misalignment_mrad
        ),
    });

    let environment = &measurement.environment;
    let (alpha, alpha_from) = match environment.expansion_coefficient_ppm_per_k {
        Some(alpha) => (alpha, "from the file"),
        None => (
            equipment.assumed_expansion_coefficient_ppm_per_k,
            "assumed: the file records none",
        ),
    };
    contributors.push(Contributor {
        name: "u_M,MACHINE",
        u_mm: um_to_mm(over_length(alpha * equipment.material_temperature_u_c)),
        source: format!(
            "α = {} µm/(m·°C) ({alpha_from}) · u_Tmat {} °C · {length}",
            alpha, equipment.material_temperature_u_c
        ),
    });

    let recorded: Vec<f64> = [
        material_temperature_c(environment, |s| s.start),
        material_temperature_c(environment, |s| s.end),
    ]
    .into_iter()
    .flatten()
    .collect();
    let (material_c, material_from) = if recorded.is_empty() {
        (
            equipment.assumed_material_temperature_c,
            "assumed: the file records no material temperature",
        )
    } else {
        (
            recorded.iter().sum::<f64>() / recorded.len() as f64,
            "the file's material sensors, mean of start and end",
        )
    };
    let alpha_u = equipment.expansion_coefficient_limit_ppm_per_k / 3f64.sqrt();
    let difference_c = (material_c - REFERENCE_TEMPERATURE_C).abs();
    contributors.push(Contributor {
        name: "u_E,MACHINE",
        u_mm: um_to_mm(over_length(difference_c * alpha_u)),
        source: format!(
            "T_mat = {:.2} °C ({material_from}): |T_mat − 20 °C| · u_α ({} µm/(m·°C) / √3) · {length}",
            material_c,
            equipment.expansion_coefficient_limit_ppm_per_k
        ),
    });

    let (eve_mm, eve_from) = match &equipment.environmental_variation {
        // A zero E_VE is not a measured stability: say that U leaves it out.
        EnvironmentalVariation::Given { eve_mm } if *eve_mm == 0.0 => (
            *eve_mm,
            "equipment profile: not measured, so U leaves the environment's drift out; give eve_um or drift_test".to_string(),
        ),
        EnvironmentalVariation::Given { eve_mm } => (*eve_mm, "equipment profile".to_string()),
        EnvironmentalVariation::Measured { eve_mm, file } => {
            (*eve_mm, format!("range of the drift test {file}"))
        }
        EnvironmentalVariation::DriftTest { path } => {
            return Err(UncertaintyError::DriftTestNotRead { path: path.clone() });
        }
    };
    contributors.push(Contributor {
        name: "u_EVE",
        u_mm: eve_mm / (2.0 * 3f64.sqrt()),
        source: format!("E_VE = {:.2} µm ({eve_from}) / (2√3)", mm_to_um(eve_mm)),
    });

    contributors.sort_by(|a, b| b.u_mm.total_cmp(&a.u_mm));
    let combined_mm = contributors
        .iter()
        .map(|c| c.u_mm * c.u_mm)
        .sum::<f64>()
        .sqrt();
    Ok(Budget {
        equipment: equipment.name.clone(),
        length_mm,
        contributors,
        combined_mm,
        coverage_factor: COVERAGE_FACTOR,
        expanded_mm: COVERAGE_FACTOR * combined_mm,
    })
}

// --- TOML -------------------------------------------------------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEquipment {
    laser: RawLaser,
    air: RawAir,
    material: RawMaterial,
    alignment: RawAlignment,
    environmental_variation: EnvironmentalVariation,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLaser {
    #[serde(rename = "U_um_per_m")]
    expanded_um_per_m: NonNegative,
    k: Positive,
    u_includes_air_compensation: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAir {
    temperature_u_c: NonNegative,
    pressure_u_kpa: NonNegative,
    humidity_u_pct: NonNegative,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    temperature_u_c: NonNegative,
    expansion_coefficient_limit_ppm_per_k: NonNegative,
    assumed_expansion_coefficient_ppm_per_k: NonNegative,
    assumed_temperature_c: NonNegative,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAlignment {
    misalignment_mrad: NonNegative,
}

/// `[environmental_variation]`: `eve_um` or `drift_test`, exactly one.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVariation {
    eve_um: Option<NonNegative>,
    drift_test: Option<String>,
}

impl<'de> Deserialize<'de> for EnvironmentalVariation {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        // An error raised here carries the span of the table (toml adds it).
        let raw = RawVariation::deserialize(deserializer)?;
        match (raw.eve_um, raw.drift_test) {
            (Some(Bounded(eve_um)), None) => Ok(EnvironmentalVariation::Given {
                eve_mm: um_to_mm(eve_um),
            }),
            (None, Some(path)) => Ok(EnvironmentalVariation::DriftTest { path }),
            (Some(_), Some(_)) => Err(serde::de::Error::custom(
                "give eve_um or drift_test, not both",
            )),
            (None, None) => Err(serde::de::Error::custom(
                "expected eve_um = … (µm) or drift_test = \"FILE\"",
            )),
        }
    }
}

/// A finite number ≥ 0 (an uncertainty, a limit, an angle, a workshop's °C).
type NonNegative = Bounded<true>;
/// A finite number > 0 (a coverage factor).
type Positive = Bounded<false>;

/// A finite number ≥ 0 (`ZERO`) or > 0; refused at its line and column.
#[derive(Clone, Copy, Deserialize)]
#[serde(try_from = "f64")]
struct Bounded<const ZERO: bool>(f64);

impl<const ZERO: bool> TryFrom<f64> for Bounded<ZERO> {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        let lowest_ok = if ZERO { value >= 0.0 } else { value > 0.0 };
        if value.is_finite() && lowest_ok {
            return Ok(Bounded(value));
        }
        let bound = if ZERO { "≥ 0" } else { "above 0" };
        Err(format!("expected a number {bound}, found {value}"))
    }
}

impl fmt::Display for Contributor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {:.3} µm ({})",
            self.name,
            mm_to_um(self.u_mm),
            self.source
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::{Direction, Environment, Run, StartEnd};

    fn one_metre(environment: Environment) -> Measurement {
        let run = |direction, number| Run {
            direction,
            number,
            start_time_s: None,
            deviations: vec![Some(0.0), Some(0.002), Some(0.001)],
        };
        Measurement::new(
            "X",
            vec![0.0, 500.0, 1000.0],
            vec![
                run(Direction::Up, 1),
                run(Direction::Down, 1),
                run(Direction::Up, 2),
                run(Direction::Down, 2),
            ],
            environment,
            Default::default(),
        )
        .unwrap()
    }

    /// The inputs of the worked example of standards.md §4.
    const WORKED_EXAMPLE: &str = "\
[laser]\nU_um_per_m = 0.5\nk = 2\nu_includes_air_compensation = true\n\
[air]\ntemperature_u_c = 0.1\npressure_u_kpa = 0.1\nhumidity_u_pct = 6\n\
[material]\ntemperature_u_c = 0.1\nexpansion_coefficient_limit_ppm_per_k = 2\n\
assumed_expansion_coefficient_ppm_per_k = 11.5\nassumed_temperature_c = 22\n\
[alignment]\nmisalignment_mrad = 0.1\n\
[environmental_variation]\neve_um = 2.0\n";

    fn u_um(budget: &Budget, name: &str) -> f64 {
        let contributor = budget.contributors.iter().find(|c| c.name == name);
        mm_to_um(contributor.unwrap_or_else(|| panic!("{name} missing")).u_mm)
    }

    #[test]
    fn the_worked_example_of_the_spec() {
        // standards.md §4: L = 1 m; laser 0.5 µm/m at k = 2 including air;
        // α = 11.5 µm/(m·°C), u_Tmat = 0.1 °C; T_mat = 21 °C; α to ±2;
        // θ = 0.1 mrad; E_VE = 2.0 µm. T_mat and α recorded in the file.
        let environment = Environment {
            material_temperature_c: [
                StartEnd::new(Some(21.0), Some(21.0)),
                StartEnd::default(),
                StartEnd::default(),
            ],
            expansion_coefficient_ppm_per_k: Some(11.5),
            ..Default::default()
        };
        let equipment = Equipment::from_toml_str(WORKED_EXAMPLE, "example").unwrap();
        let b = budget(&one_metre(environment), &equipment).unwrap();
        assert_eq!(b.length_mm, 1000.0);
        // The spec's table, each checked by hand:
        // u_DEVICE = 0.5 / 2 · 1 = 0.250 µm
        // u_M,MACHINE = 11.5 · 1 · 0.1 = 1.150 µm
        // u_E,MACHINE = 1 · |21 − 20| · 2/√3 = 2/1.7320508 = 1.1547 µm → 1.155
        // u_MISALIGNMENT = 10⁶ (1 − cos 10⁻⁴)/√3 = 10⁶ · 5·10⁻⁹ / 1.7320508 = 0.00289 → 0.003
        // u_EVE = 2.0/(2√3) = 0.57735 → 0.577
        let table = [
            ("u_DEVICE", 0.250),
            ("u_M,MACHINE", 1.150),
            ("u_E,MACHINE", 1.155),
            ("u_MISALIGNMENT", 0.003),
            ("u_EVE", 0.577),
        ];
        for (name, expected) in table {
            let found = u_um(&b, name);
            assert!(
                (found - expected).abs() <= 0.0005,
                "{name}: {found} vs {expected}"
            );
        }
        // No u_AIR: the laser figure includes the air compensation.
        assert_eq!(b.contributors.len(), 5);
        // u_c = √(0.0625 + 1.3225 + 1.33333 + 0.0000083 + 0.33333) = √3.051675 = 1.74690;
        // U(E) = 2 u_c = 3.49381 → the spec's 3.494.
        assert!((mm_to_um(b.combined_mm) - 1.747).abs() <= 0.0005);
        assert!((mm_to_um(b.expanded_mm) - 3.494).abs() <= 0.01);
        assert_eq!(b.coverage_factor, 2.0);
        // Largest first: u_E,MACHINE (1.1547) just above u_M,MACHINE (1.150).
        let order: Vec<&str> = b.contributors.iter().map(|c| c.name).collect();
        assert_eq!(
            order,
            [
                "u_E,MACHINE",
                "u_M,MACHINE",
                "u_EVE",
                "u_DEVICE",
                "u_MISALIGNMENT"
            ]
        );
        assert!(
            b.contributors[0]
                .source
                .contains("the file's material sensors")
        );
        assert!(b.contributors[1].source.contains("from the file"));
    }

    #[test]
    fn assumed_values_and_air_when_the_laser_excludes_it() {
        // Nothing recorded: α = 11.5 and T_mat = 22 °C assumed (bundled).
        let bundled = Equipment::bundled();
        let b = budget(&one_metre(Environment::default()), &bundled).unwrap();
        // u_E,MACHINE = 1 m · |22 − 20| · 1/√3 = 1.1547 µm.
        assert!((u_um(&b, "u_E,MACHINE") - 2.0 / 3f64.sqrt()).abs() < 1e-9);
        assert!(b.contributors[0].source.contains("assumed"));
        // u_AIR by hand: 0.1 °C, 1 hPa, 6 %RH:
        // √((0.093)² + (0.27)² + (0.051)²) = √(0.008649 + 0.0729 + 0.002601) = √0.08415 = 0.290086 µm/m.
        let excluded = Equipment {
            laser_includes_air: false,
            ..bundled
        };
        let b = budget(&one_metre(Environment::default()), &excluded).unwrap();
        assert!((u_um(&b, "u_AIR") - 0.290_086).abs() < 1e-6);
    }

    #[test]
    fn a_drift_test_gives_e_ve() {
        let drift = one_metre(Environment::default());
        let equipment = Equipment::from_toml_str(
            &WORKED_EXAMPLE.replace("eve_um = 2.0", "drift_test = \"drift.rtl\""),
            "e.toml",
        )
        .unwrap();
        assert_eq!(equipment.drift_test_path(), Some("drift.rtl"));
        assert_eq!(
            budget(&drift, &equipment),
            Err(UncertaintyError::DriftTestNotRead {
                path: "drift.rtl".into()
            })
        );
        // Deviations 0, 2, 1 µm: E_VE = 2 µm, u_EVE = 2/(2√3) = 0.57735 µm.
        let equipment = equipment.with_drift_test(&drift, "drift.rtl");
        let b = budget(&drift, &equipment).unwrap();
        assert!((u_um(&b, "u_EVE") - 0.577_350).abs() < 1e-6);
        assert!(
            b.contributors
                .iter()
                .any(|c| c.source.contains("drift test drift.rtl"))
        );
    }

    #[test]
    fn equipment_errors_name_line_and_column() {
        let check = |from: &str, to: &str, line: usize, column: usize, needle: &str| {
            let text = WORKED_EXAMPLE.replace(from, to);
            let error = Equipment::from_toml_str(&text, "e.toml").unwrap_err();
            assert_eq!(
                (error.position.line, error.position.column),
                (line, column),
                "{to:?}: {error}"
            );
            assert!(error.message.contains(needle), "{to:?}: {error}");
        };
        check("k = 2", "k = 2\nkk = 1", 4, 1, "unknown field `kk`");
        check("k = 2", "k = 0", 3, 5, "above 0, found 0");
        check(
            "humidity_u_pct = 6",
            "humidity_u_pct = -6",
            8,
            18,
            "≥ 0, found -6",
        );
        check(
            "misalignment_mrad = 0.1",
            "misalignment_mrad = nan",
            15,
            21,
            "≥ 0, found NaN",
        );
        check(
            "eve_um = 2.0",
            "eve_um = 2.0\ndrift_test = \"d.rtl\"",
            16,
            1,
            "not both",
        );
        check(
            "U_um_per_m",
            "u_um_per_m",
            2,
            1,
            "unknown field `u_um_per_m`",
        );
    }

    #[test]
    fn the_bundled_profile_parses() {
        let bundled = Equipment::bundled();
        assert_eq!(bundled.laser_k, 2.0);
        assert!(bundled.laser_includes_air);
        assert_eq!(
            bundled.environmental_variation,
            EnvironmentalVariation::Given { eve_mm: 0.0 }
        );
    }
}
