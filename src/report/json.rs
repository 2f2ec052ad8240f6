//! The `--json` wire format of `axcomp evaluate`.
//!
//! # Wire format
//!
//! One object; keys may be added, never renamed or removed. Lengths carry
//! their unit in the key; not-evaluated figures are `null`, never 0.
//!
//! ```text
//! { "format": "ecmc", "axis": "Z", "axis_source": {"kind": "file", "field": "TGT_SET_PV"},
//!   "source_file": "…", "length_unit": "mm",
//!   "targets_mm": [15.0, …],
//!   "runs": {"up": 5, "down": 5}, "excluded_runs": ["1:down"],
//!   "standard": "iso230-2:2014", "standard_name": "ISO 230-2:2014",
//!   "definitions_reconstructed": false,
//!   "figures_um": {"A": …, "A_up": …, "A_down": …, "E": …, "E_up": …, "E_down": …,
//!                  "M": …, "R": …, "R_up": …, "R_down": …, "B": …, "B_mean": …}
//!               | {"P": …, "Pa": …, "Ps_max": …, "Ps_mean": …, "U_max": …, "U_mean": …} (vdi3441),
//!   "figures_iso230_2_um": {"A": …, …} (only with vdi3441: the ISO 230-2:2014 figures beside),
//!   "per_target": [{"target_mm": …, "n_up": 5, "n_down": 5,
//!                   "mean_up_um": …, "mean_down_um": …, "mean_um": …,
//!                   "s_up_um": …, "s_down_um": …, "B_um": …,
//!                   "R_up_um": …, "R_down_um": …, "R_um": …}, …],
//!   "outliers": [{"run": 1, "direction": "down", "score": 48.2,
//!                 "worst_target_mm": 15.0, "offset_um": 101.4}],
//!   "environment": {…}, "metadata": {…}, "warnings": ["…"],
//!   "refractive_index": {"vacuum_wavelength_um": 0.632991, "wavelength_assumed": true,
//!                        "agreement_ppm": 1.0,
//!                        "start": {"factor_um": …, "implied_n": …, "edlen_n": …,
//!                                  "difference_ppm": …, "material_correction_ppm": null,
//!                                  "agrees": true, "missing": []}, "end": {…}},
//!   "test_conformance": {"title": "bidirectional test, 5 runs, 16 targets over 750 mm to ISO 230-2:2014",
//!                        "meets_iso230_2": true, "length_mm": 750.0,
//!                        "checks": [{"check": "runs", "recommendation": false, "met": true,
//!                                    "found": 5.0, "required": 5.0}, …]},
//!   "test_setup": {"instrument": "API X-D Laser", "instrument_serial": "4848",
//!                  "feed_mm_per_min": null, "dwell_s": 3.0,
//!                  "other_axes_mm": [{"axis": "Y", "position_mm": 0.0}, …]},
//!   "notes": ["…"],
//!   "uncertainty_um": {"E": 3.49, "M": 3.49, "A": 3.49, "R": null, "B": null, "budget": […], …},
//!   "verdict": {"pass": …, "checks": […], …} }
//! ```
//!
//! `test_conformance.checks[].check` is `runs`, `both_directions`, `targets`,
//! `targets_per_m` or `irregular_spacing` (`evaluate::conformance`); `found`
//! and `required` are runs, directions, targets, targets per metre, or for
//! spacing the constant step in mm (`null` when irregular). `test_setup`
//! holds what the file records, `null` or `[]` where it does not. `notes`
//! says where another program's report of the same file will differ.
//!
//! `uncertainty_um` is the expanded measurement uncertainty of the figures
//! and its budget (`report::uncertainty`); absent where none was evaluated.
//!
//! `verdict` is there only when acceptance limits are given (`--limit`, a
//! profile's `[acceptance]`): no limits, no verdict. Its format is in
//! `report::verdict`.
//!
//! `B` is max |B_i| (unsigned); `B_mean` (B̄) and `B_um` are signed, ↑ minus ↓.
//!
//! A rotary axis (`"axis_kind": "rotary"`, a key only rotary axes have)
//! carries its unit in the same keys: `targets_deg` for `targets_mm`,
//! `figures_arcsec` for `figures_um` (same figure keys), per target
//! `target_deg`, `mean_up_arcsec`, …, `R_arcsec`, outliers
//! `worst_target_deg` and `offset_arcsec`, `test_conformance.length_deg`;
//! `length_unit` is `deg`, and there is no `uncertainty_um` (the budget is
//! the laser's, for lengths). A linear axis' object is unchanged.
//!
//! With `--angle-unit urad` every rotary deviation is in µrad instead, and
//! every key that would end in `_arcsec` ends in `_urad` (`figures_urad`,
//! `mean_up_urad`, `offset_urad`); no `_arcsec` key is written then.
//!
//! `axis_source` says where `axis` came from: `{"kind": "file", "field": …}`
//! (the field of the file that states it), `{"kind": "given"}` (`--axis`) or
//! `{"kind": "not_recorded"}`, when `axis` is `null`.
//!
//! Each key's unit is the type of the value under it: a linear and a rotary
//! axis' per-target rows and outliers are different structs
//! (`LinearTargetJson` with `target_mm: Mm` and `mean_up_um: Option<Um>`,
//! `ArcsecTargetJson`, `UradTargetJson`), and the keys that differ in the
//! top-level object are serde-flattened enums (`TargetsJson`,
//! `FiguresByUnit`, `LengthJson`); no key is renamed at run time.

use serde::Serialize;

mod outlier;
mod per_target;

pub use outlier::{
    ArcsecOutlierJson, LinearOutlierJson, OutlierJson, OutlierShown, UradOutlierJson,
};
pub use per_target::{ArcsecTargetJson, LinearTargetJson, PerTargetJson, UradTargetJson};

use crate::error::Warning;
use crate::evaluate::environment::{AGREEMENT_PPM, IndexComparison, RefractiveIndexCheck};
use crate::evaluate::{Evaluation, FiguresByKind, StandardFigure, TestConformance};
use crate::measurement::{
    AxisKind, AxisSource, ByKind, Environment, Measurement, RunSelector, SourceFormat, StartEnd,
    TestSetup,
};
use crate::units::{AngleUnit, Deg, DeviationUnit, Mm};

/// The whole `evaluate --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct EvaluationJson {
    /// Input format name (`rtl`, `ecmc`, `api-pos`, `csv`).
    pub format: Option<&'static str>,
    /// Axis name; `null` when `axis_source` is `not_recorded` (no name is guessed).
    pub axis: Option<String>,
    /// Where the axis name came from.
    pub axis_source: AxisSourceJson,
    /// The file read (the first, when two were joined).
    pub source_file: Option<String>,
    /// `rotary` for a rotary axis; absent for a linear one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_kind: Option<&'static str>,
    /// Length unit of the source file (`mm` or `inch`; `deg` on a rotary
    /// axis); all values here are mm or µm (° or ″).
    pub length_unit: &'static str,
    /// Targets: `targets_mm`, or `targets_deg` on a rotary axis.
    #[serde(flatten)]
    pub targets: TargetsJson,
    /// Runs per direction, after exclusions.
    pub runs: RunCountsJson,
    /// Runs left out by `--exclude-run`, as `3`, `3:up` or `3:down`.
    pub excluded_runs: Vec<String>,
    /// The standard evaluated to (`--standard`: `iso230-2:2014`, `vdi3441`, …).
    pub standard: &'static str,
    /// Its name and edition.
    pub standard_name: &'static str,
    /// Whether its definitions are reconstructed from public sources
    /// (`../shared/spec/standards.md`), not read in the standard.
    pub definitions_reconstructed: bool,
    /// That standard's axis figures under its keys: `figures_um`, or
    /// `figures_arcsec` (`figures_urad`) on a rotary axis.
    #[serde(flatten)]
    pub figures: FiguresByUnit,
    /// The ISO 230-2:2014 figures too, µm, when the standard's keys are
    /// others (VDI 3441) on a linear axis: the report shows both; absent
    /// otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub figures_iso230_2_um: Option<FiguresJson>,
    /// The unit of every deviation here (µm, ″ or µrad); the keys say it.
    #[serde(skip)]
    pub deviation: DeviationUnit,
    /// Per-target statistics.
    pub per_target: Vec<PerTargetJson>,
    /// Suspected outlier runs (included in the figures).
    pub outliers: Vec<OutlierJson>,
    /// Test conditions.
    pub environment: EnvironmentJson,
    /// The recorded environmental factor checked against Edlén's air index
    /// (eq. 36), at the start and the end, as the report shows it.
    pub refractive_index: RefractiveIndexJson,
    /// Who, what, where, when.
    pub metadata: MetadataJson,
    /// Reader and evaluator warnings, as sentences.
    pub warnings: Vec<String>,
    /// The test against ISO 230-2's conditions.
    pub test_conformance: ConformanceJson,
    /// The instrument and set-up, where the file records them.
    pub test_setup: TestSetupJson,
    /// Where another program's report of the same file differs, and why.
    pub notes: Vec<&'static str>,
    /// The measurement uncertainty and its budget (see `report::uncertainty`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uncertainty_um: Option<crate::report::uncertainty::UncertaintyJson>,
    /// The acceptance verdict; absent without limits (see `report::verdict`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<crate::report::verdict::VerdictJson>,
}

/// Where the axis name came from ([`AxisSource`]), tagged by `kind`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum AxisSourceJson {
    /// The file states it in `field`.
    File {
        /// The field, as the file spells it (`TGT_SET_PV`, `Axis`, …).
        field: String,
    },
    /// Given by the user (`--axis`) or the program that made the measurement.
    Given,
    /// Nothing states it.
    NotRecorded,
}

impl AxisSourceJson {
    /// The wire form of an [`AxisSource`].
    pub fn from_source(source: &AxisSource) -> AxisSourceJson {
        match source {
            AxisSource::File { field } => AxisSourceJson::File {
                field: field.clone(),
            },
            AxisSource::Given => AxisSourceJson::Given,
            AxisSource::NotRecorded => AxisSourceJson::NotRecorded,
        }
    }

    /// The axis as a user reads it: `Z (from TGT_SET_PV)`, `X (--axis)`, or
    /// `not recorded (give --axis)`.
    pub fn describe(&self, axis: &str) -> String {
        match self {
            AxisSourceJson::File { field } => format!("{axis} (from {field})"),
            AxisSourceJson::Given => format!("{axis} (--axis)"),
            AxisSourceJson::NotRecorded => "not recorded (give --axis)".to_string(),
        }
    }
}

/// The test against ISO 230-2's conditions (`evaluate::conformance`).
#[derive(Clone, Debug, Serialize)]
pub struct ConformanceJson {
    /// What the test is, as the report's title says it.
    pub title: String,
    /// Whether every requirement (not the recommendations) is met.
    pub meets_iso230_2: bool,
    /// Travel: `length_mm`, or the range `length_deg` on a rotary axis.
    #[serde(flatten)]
    pub length: LengthJson,
    /// Every check.
    pub checks: Vec<CheckJson>,
}

/// A travel in its unit, the key saying which.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum LengthJson {
    /// A linear axis' travel, mm.
    #[serde(rename = "length_mm")]
    Mm(Mm),
    /// A rotary axis' range, °.
    #[serde(rename = "length_deg")]
    Deg(Deg),
}

/// The targets in their unit, the key saying which.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum TargetsJson {
    /// A linear axis' targets, mm.
    #[serde(rename = "targets_mm")]
    Mm(Vec<Mm>),
    /// A rotary axis' targets, °.
    #[serde(rename = "targets_deg")]
    Deg(Vec<Deg>),
}

impl TargetsJson {
    /// The targets of `measurement`, typed by its axis' kind.
    pub fn of(measurement: &Measurement) -> TargetsJson {
        let positions = measurement.positions();
        match measurement.kind() {
            AxisKind::Linear => TargetsJson::Mm(positions.filter_map(ByKind::linear).collect()),
            AxisKind::Rotary => TargetsJson::Deg(positions.filter_map(ByKind::rotary).collect()),
        }
    }
}

/// A standard's figures in the unit they are reported in, the key saying
/// which: `figures_um` on a linear axis, `figures_arcsec` or `figures_urad`
/// on a rotary one.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum FiguresByUnit {
    /// µm.
    #[serde(rename = "figures_um")]
    Um(FiguresJson),
    /// ″.
    #[serde(rename = "figures_arcsec")]
    Arcsec(FiguresJson),
    /// µrad.
    #[serde(rename = "figures_urad")]
    Urad(FiguresJson),
}

impl FiguresByUnit {
    /// A standard's figures typed by their axis' kind
    /// ([`Evaluation::standard_figures_typed`]), a rotary axis' in `angle`.
    pub fn of(figures: &FiguresByKind, angle: AngleUnit) -> FiguresByUnit {
        match (figures, angle) {
            (ByKind::Linear(figures), _) => FiguresByUnit::Um(FiguresJson::from_standard(figures)),
            (ByKind::Rotary(figures), AngleUnit::Arcsec) => {
                FiguresByUnit::Arcsec(FiguresJson::from_standard_deg(figures, angle))
            }
            (ByKind::Rotary(figures), AngleUnit::Urad) => {
                FiguresByUnit::Urad(FiguresJson::from_standard_deg(figures, angle))
            }
        }
    }

    /// The figures, in their unit.
    pub fn values(&self) -> &FiguresJson {
        match self {
            FiguresByUnit::Um(figures)
            | FiguresByUnit::Arcsec(figures)
            | FiguresByUnit::Urad(figures) => figures,
        }
    }

    /// The figures, in their unit, without the key that names it.
    pub fn into_values(self) -> FiguresJson {
        match self {
            FiguresByUnit::Um(figures)
            | FiguresByUnit::Arcsec(figures)
            | FiguresByUnit::Urad(figures) => figures,
        }
    }
}

/// One check of the test.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct CheckJson {
    /// `runs`, `both_directions`, `targets`, `targets_per_m`, `irregular_spacing`.
    pub check: &'static str,
    /// Whether ISO 230-2 only recommends it.
    pub recommendation: bool,
    /// Whether the test meets it.
    pub met: bool,
    /// What the test has.
    pub found: Option<f64>,
    /// What the standard asks.
    pub required: Option<f64>,
}

impl ConformanceJson {
    /// Copies the checks.
    pub fn from_conformance(c: &TestConformance) -> ConformanceJson {
        ConformanceJson {
            title: c.title(),
            meets_iso230_2: c.meets_iso230_2(),
            length: match c.length {
                ByKind::Linear(length_mm) => LengthJson::Mm(length_mm),
                ByKind::Rotary(range_deg) => LengthJson::Deg(range_deg),
            },
            checks: c
                .checks
                .iter()
                .map(|check| CheckJson {
                    check: check.requirement.name(),
                    recommendation: check.requirement.is_recommendation(),
                    met: check.met,
                    found: check.found,
                    required: check.required,
                })
                .collect(),
        }
    }
}

/// The instrument and set-up, mm, s.
#[derive(Clone, Debug, Serialize)]
pub struct TestSetupJson {
    /// The instrument as the file names it.
    pub instrument: Option<String>,
    /// Its serial number.
    pub instrument_serial: Option<String>,
    /// Feed between targets, mm/min.
    pub feed_mm_per_min: Option<f64>,
    /// Dwell at each target, s.
    pub dwell_s: Option<f64>,
    /// The other axes' positions during the test.
    pub other_axes_mm: Vec<AxisPositionJson>,
}

/// One other axis' position.
#[derive(Clone, Debug, Serialize)]
pub struct AxisPositionJson {
    /// Axis name.
    pub axis: String,
    /// Position, mm.
    pub position_mm: f64,
}

impl TestSetupJson {
    /// Copies the set-up.
    pub fn from_setup(s: &TestSetup) -> TestSetupJson {
        TestSetupJson {
            instrument: s.instrument.clone(),
            instrument_serial: s.instrument_serial.clone(),
            feed_mm_per_min: s.feed_mm_per_min,
            dwell_s: s.dwell_s,
            other_axes_mm: s
                .other_axes_mm
                .iter()
                .map(|(axis, position_mm)| AxisPositionJson {
                    axis: axis.clone(),
                    position_mm: *position_mm,
                })
                .collect(),
        }
    }
}

/// Where another program's report of a file in this format will differ.
pub fn source_notes(format: Option<SourceFormat>) -> Vec<&'static str> {
    match format {
        Some(SourceFormat::Ecmc) => vec![crate::read::ecmc::VENDOR_REPORT_NOTE],
        _ => Vec::new(),
    }
}

/// Run counts.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RunCountsJson {
    /// ↑ runs.
    pub up: usize,
    /// ↓ runs.
    pub down: usize,
}

/// A standard's axis figures as reported (µm; ″ or µrad on a rotary axis:
/// [`FiguresByUnit`] names which), under its own keys and in its order
/// (ISO 230-2: `A`, `A_up`, …, `B_mean`; VDI 3441: `P`, `Pa`, `Ps_max`,
/// `Ps_mean`, `U_max`, `U_mean`); serialised as one JSON object.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FiguresJson {
    /// (key, value as reported), in the standard's order.
    pub values: Vec<(&'static str, Option<f64>)>,
}

impl FiguresJson {
    /// A linear axis' figures (mm), in µm.
    ///
    /// A rotary axis' figures are degrees ([`Evaluation::standard_figures_typed`]
    /// gives them as `StandardFigure<Deg>`), which this does not take: they
    /// cannot come out as µm.
    /// ```compile_fail
    /// use axcomp::evaluate::Evaluation;
    /// use axcomp::measurement::ByKind;
    /// use axcomp::report::json::FiguresJson;
    /// fn wire(evaluation: &Evaluation) -> Option<FiguresJson> {
    ///     let rotary = evaluation.standard_figures_typed().rotary()?;
    ///     Some(FiguresJson::from_standard(&rotary))
    /// }
    /// ```
    /// They go through [`FiguresJson::from_standard_deg`] (or [`FiguresByUnit::of`]):
    /// ```
    /// use axcomp::evaluate::Evaluation;
    /// use axcomp::report::json::FiguresJson;
    /// use axcomp::units::AngleUnit;
    /// fn wire(evaluation: &Evaluation) -> Option<FiguresJson> {
    ///     let rotary = evaluation.standard_figures_typed().rotary()?;
    ///     Some(FiguresJson::from_standard_deg(&rotary, AngleUnit::Arcsec))
    /// }
    /// ```
    pub fn from_standard(figures: &[StandardFigure<Mm>]) -> FiguresJson {
        FiguresJson::converted(figures, Mm::to_um, |um| um.0)
    }

    /// A linear axis' figures in µm, for what is written in µm only (a
    /// diagnosis in the report, a predicted re-test, a servo cycle: linear
    /// axes only, `workflow::rotary`); none for a rotary axis, whose
    /// figures are degrees, rather than degrees written as µm.
    pub fn of_linear(figures: &FiguresByKind) -> FiguresJson {
        match figures {
            ByKind::Linear(figures) => FiguresJson::from_standard(figures),
            ByKind::Rotary(_) => FiguresJson::default(),
        }
    }

    /// A rotary axis' figures (°), in `angle` (″ or µrad).
    pub fn from_standard_deg(figures: &[StandardFigure<Deg>], angle: AngleUnit) -> FiguresJson {
        match angle {
            AngleUnit::Arcsec => FiguresJson::converted(figures, Deg::to_arcsec, |arcsec| arcsec.0),
            AngleUnit::Urad => FiguresJson::converted(figures, Deg::to_urad, |urad| urad.0),
        }
    }

    /// Each figure converted by `convert` (whose type says which unit it
    /// takes), written as the bare number `number` gives.
    fn converted<U, R>(
        figures: &[StandardFigure<U>],
        convert: fn(U) -> R,
        number: fn(R) -> f64,
    ) -> FiguresJson
    where
        U: Copy,
    {
        FiguresJson {
            values: figures
                .iter()
                .map(|f| (f.key, f.value.map(|value| number(convert(value)))))
                .collect(),
        }
    }

    /// Whether these are the ISO 230-2 family's figures (keyed `A`, `E`, …).
    pub fn is_iso230_2(&self) -> bool {
        self.values.iter().any(|(key, _)| *key == "A")
    }

    /// The rows a terminal table shows, (name, key): the ISO 230-2 family's
    /// bidirectional figures, or every figure of another standard (VDI 3441).
    pub fn terminal_rows(&self) -> Vec<(&'static str, &'static str)> {
        if self.is_iso230_2() {
            vec![
                ("A", "A"),
                ("E", "E"),
                ("M", "M"),
                ("R", "R"),
                ("B", "B"),
                ("B̄", "B_mean"),
            ]
        } else {
            self.values.iter().map(|(key, _)| (*key, *key)).collect()
        }
    }

    /// No figures: the other unit's field of a rotary or linear axis.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The value under `key`, as reported (`None` when not evaluated or not this standard's).
    pub fn get(&self, key: &str) -> Option<f64> {
        self.values
            .iter()
            .find(|(k, _)| *k == key)
            .and_then(|(_, value)| *value)
    }
}

/// Whether a standard's figures are ISO 230-2's (any edition): keyed `A`, `E`, ….
pub fn iso_keys(figures: &[StandardFigure]) -> bool {
    figures.iter().any(|f| f.key == "A")
}

impl Serialize for FiguresJson {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(self.values.len()))?;
        for (key, value) in &self.values {
            map.serialize_entry(key, value)?;
        }
        map.end()
    }
}

/// A start/end pair.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct StartEndJson {
    /// At the start.
    pub start: Option<f64>,
    /// At the end.
    pub end: Option<f64>,
}

impl From<StartEnd> for StartEndJson {
    fn from(value: StartEnd) -> StartEndJson {
        StartEndJson {
            start: value.start,
            end: value.end,
        }
    }
}

/// Test conditions in °C, kPa, %, ppm/K and µm.
#[derive(Clone, Debug, Serialize)]
pub struct EnvironmentJson {
    /// Air temperature, °C.
    pub air_temperature_c: StartEndJson,
    /// Air pressure, kPa.
    pub air_pressure_kpa: StartEndJson,
    /// Relative humidity, %.
    pub air_humidity_pct: StartEndJson,
    /// Material sensors 1–3, °C (`null` where none is fitted).
    pub material_temperature_c: Vec<StartEndJson>,
    /// Expansion coefficient, µm/(m·K).
    pub expansion_coefficient_ppm_per_k: Option<f64>,
    /// λ_vac / (2·n_air) as the laser used it, µm.
    pub environmental_factor_um: StartEndJson,
    /// The laser's vacuum wavelength, µm.
    pub vacuum_wavelength_um: Option<f64>,
}

impl EnvironmentJson {
    /// Copies the environment record.
    pub fn from_environment(e: &Environment) -> EnvironmentJson {
        EnvironmentJson {
            air_temperature_c: e.air_temperature_c.into(),
            air_pressure_kpa: e.air_pressure_kpa.into(),
            air_humidity_pct: e.air_humidity_pct.into(),
            material_temperature_c: e
                .material_temperature_c
                .iter()
                .map(|s| (*s).into())
                .collect(),
            expansion_coefficient_ppm_per_k: e.expansion_coefficient_ppm_per_k,
            environmental_factor_um: e.environmental_factor_um.into(),
            vacuum_wavelength_um: e.vacuum_wavelength_um,
        }
    }
}

/// The Edlén check (`evaluate::environment::check_refractive_index`).
#[derive(Clone, Debug, Serialize)]
pub struct RefractiveIndexJson {
    /// The vacuum wavelength used, µm.
    pub vacuum_wavelength_um: f64,
    /// Whether it was assumed (the file records none).
    pub wavelength_assumed: bool,
    /// How far the implied index may be from Edlén's and agree, ppm.
    pub agreement_ppm: f64,
    /// At the start of the test.
    pub start: IndexAtJson,
    /// At the end of the test.
    pub end: IndexAtJson,
}

/// The check at one moment: made, or what the file lacks for it.
#[derive(Clone, Debug, Serialize)]
pub struct IndexAtJson {
    /// The recorded factor, µm (`null` when the check could not be made).
    pub factor_um: Option<f64>,
    /// n_air implied by the factor.
    pub implied_n: Option<f64>,
    /// n_air by Edlén's eq. (36) from the recorded air.
    pub edlen_n: Option<f64>,
    /// (implied − Edlén) · 10⁶: µm per metre.
    pub difference_ppm: Option<f64>,
    /// The material correction taken out of the factor, ppm.
    pub material_correction_ppm: Option<f64>,
    /// Whether the difference is within `agreement_ppm`.
    pub agrees: Option<bool>,
    /// What the file lacks for the check (empty when made).
    pub missing: Vec<&'static str>,
}

impl RefractiveIndexJson {
    /// Copies the check.
    pub fn from_check(check: &RefractiveIndexCheck) -> RefractiveIndexJson {
        let at = |comparison: &IndexComparison| match comparison {
            IndexComparison::Made(at) => IndexAtJson {
                factor_um: Some(at.factor_um),
                implied_n: Some(at.implied_n),
                edlen_n: Some(at.edlen_n),
                difference_ppm: Some(at.difference_ppm),
                material_correction_ppm: at.material_correction_ppm,
                agrees: Some(at.agrees()),
                missing: Vec::new(),
            },
            IndexComparison::Missing(missing) => IndexAtJson {
                factor_um: None,
                implied_n: None,
                edlen_n: None,
                difference_ppm: None,
                material_correction_ppm: None,
                agrees: None,
                missing: missing.clone(),
            },
        };
        RefractiveIndexJson {
            vacuum_wavelength_um: check.vacuum_wavelength_um,
            wavelength_assumed: check.wavelength_assumed,
            agreement_ppm: AGREEMENT_PPM,
            start: at(&check.start),
            end: at(&check.end),
        }
    }
}

/// Metadata as text.
#[derive(Clone, Debug, Serialize)]
pub struct MetadataJson {
    /// Machine.
    pub machine: Option<String>,
    /// Serial number.
    pub serial_number: Option<String>,
    /// Operator.
    pub operator: Option<String>,
    /// The date as written in the file.
    pub date: Option<String>,
    /// The date parsed, ISO 8601, when the pattern is known.
    pub date_iso: Option<String>,
    /// Location.
    pub location: Option<String>,
    /// Title or description.
    pub description: Option<String>,
}

impl EvaluationJson {
    /// The targets, in their unit (mm, or ° on a rotary axis).
    pub fn targets(&self) -> Vec<f64> {
        match &self.targets {
            TargetsJson::Mm(targets) => targets.iter().map(|target| target.0).collect(),
            TargetsJson::Deg(targets) => targets.iter().map(|target| target.0).collect(),
        }
    }

    /// The figures, in their unit (µm, or ″ or µrad on a rotary axis).
    pub fn figures(&self) -> &FiguresJson {
        self.figures.values()
    }

    /// How a deviation's unit is printed: `µm`, or `″` or `µrad` on a rotary axis.
    pub fn deviation_unit(&self) -> &'static str {
        self.deviation.symbol()
    }

    /// How a target's unit is printed after a number: ` mm`, or `°` on a rotary axis.
    pub fn position_unit(&self) -> &'static str {
        if self.axis_kind.is_some() {
            "°"
        } else {
            " mm"
        }
    }

    /// Builds the wire object from a measurement, its evaluation and all
    /// warnings, a rotary axis' deviations in `angle`.
    pub fn new(
        measurement: &Measurement,
        evaluation: &Evaluation,
        excluded: &[RunSelector],
        warnings: &[Warning],
        angle: AngleUnit,
    ) -> EvaluationJson {
        let per_target = evaluation
            .per_target
            .iter()
            .map(|stats| PerTargetJson::from_stats_of(stats, measurement.kind(), angle))
            .collect();
        EvaluationJson::with_per_target(
            measurement,
            evaluation,
            per_target,
            (excluded, warnings),
            angle,
        )
    }

    /// [`EvaluationJson::new`], taking the evaluation: its per-target
    /// table is freed once converted (the wire form is another size, so
    /// the conversion allocates anew).
    pub fn from_evaluation(
        measurement: &Measurement,
        mut evaluation: Evaluation,
        excluded: &[RunSelector],
        warnings: &[Warning],
        angle: AngleUnit,
    ) -> EvaluationJson {
        let per_target = std::mem::take(&mut evaluation.per_target)
            .into_iter()
            .map(|stats| PerTargetJson::from_stats_of(&stats, measurement.kind(), angle))
            .collect();
        EvaluationJson::with_per_target(
            measurement,
            &evaluation,
            per_target,
            (excluded, warnings),
            angle,
        )
    }

    fn with_per_target(
        measurement: &Measurement,
        evaluation: &Evaluation,
        per_target: Vec<PerTargetJson>,
        (excluded, warnings): (&[RunSelector], &[Warning]),
        angle: AngleUnit,
    ) -> EvaluationJson {
        let metadata = &measurement.metadata;
        let kind = measurement.kind();
        let deviation = kind.deviation_unit(angle);
        let rotary = kind == AxisKind::Rotary;
        EvaluationJson {
            format: metadata.source_format.map(|f| f.name()),
            axis: measurement
                .axis_recorded()
                .then(|| measurement.axis().to_string()),
            axis_source: AxisSourceJson::from_source(measurement.axis_source()),
            source_file: metadata
                .source_file
                .as_ref()
                .map(|p| p.display().to_string()),
            axis_kind: rotary.then_some(kind.as_str()),
            length_unit: if rotary {
                "deg"
            } else {
                metadata.length_unit.as_str()
            },
            targets: TargetsJson::of(measurement),
            runs: RunCountsJson {
                up: evaluation.runs_up,
                down: evaluation.runs_down,
            },
            excluded_runs: excluded.iter().map(ToString::to_string).collect(),
            standard: evaluation.standard.key,
            standard_name: evaluation.standard.name,
            definitions_reconstructed: evaluation.standard.reconstructed,
            figures_iso230_2_um: evaluation
                .figures_typed()
                .linear()
                .filter(|_| !iso_keys(&evaluation.standard_figures))
                .map(|figures| FiguresJson::from_standard(&figures)),
            figures: FiguresByUnit::of(&evaluation.standard_figures_typed(), angle),
            deviation,
            per_target,
            outliers: evaluation
                .outliers
                .iter()
                .map(|o| OutlierJson::from_outlier(o, kind, angle))
                .collect(),
            environment: EnvironmentJson::from_environment(&measurement.environment),
            refractive_index: RefractiveIndexJson::from_check(&evaluation.refractive_index),
            metadata: MetadataJson {
                machine: metadata.machine.clone(),
                serial_number: metadata.serial_number.clone(),
                operator: metadata.operator.clone(),
                date: metadata.date.as_ref().map(|d| d.raw.clone()),
                date_iso: metadata
                    .date
                    .as_ref()
                    .and_then(|d| d.parsed)
                    .map(|d| d.format("%Y-%m-%dT%H:%M:%S").to_string()),
                location: metadata.location.clone(),
                description: metadata.description.clone(),
            },
            warnings: warnings.iter().map(|w| w.text_in(angle)).collect(),
            uncertainty_um: None,
            verdict: None,
            test_conformance: ConformanceJson::from_conformance(&evaluation.conformance),
            test_setup: TestSetupJson::from_setup(&metadata.setup),
            notes: source_notes(metadata.source_format),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluate::standard::typed;
    use crate::evaluate::{DirectionStats, SuspectedOutlier, TargetStats};
    use crate::measurement::Direction;

    /// A target with x̄↑ = 0.001 and x̄↓ = −0.001 in the axis' unit (two
    /// readings each way, s = 0.0005), computed by hand below.
    fn target(at: f64) -> TargetStats {
        let up = DirectionStats::of(&[0.0005, 0.0015]);
        let down = DirectionStats::of(&[-0.0005, -0.0015]);
        TargetStats {
            target: at,
            up,
            down,
            mean: Some(0.0),
            reversal: Some(0.002),
            repeatability_up: up.s.map(|s| 4.0 * s),
            repeatability_down: down.s.map(|s| 4.0 * s),
            repeatability: Some(0.004),
        }
    }

    /// The keys of a flat JSON object, in the order written.
    fn keys(text: &str) -> Vec<&str> {
        text.trim_matches(|c| c == '{' || c == '}')
            .split(',')
            .map(|entry| entry.split(':').next().unwrap().trim_matches('"'))
            .collect()
    }

    #[test]
    fn a_linear_target_is_in_mm_and_um() {
        let json = PerTargetJson::from_stats(&target(100.0));
        let text = serde_json::to_string(&json).unwrap();
        assert!(text.starts_with(r#"{"target_mm":100.0,"n_up":2,"n_down":2,"mean_up_um":1.0,"#));
        assert_eq!(
            keys(&text),
            [
                "target_mm",
                "n_up",
                "n_down",
                "mean_up_um",
                "mean_down_um",
                "mean_um",
                "s_up_um",
                "s_down_um",
                "B_um",
                "R_up_um",
                "R_down_um",
                "R_um"
            ]
        );
        // B = 0.002 mm = 2 µm, R = 0.004 mm = 4 µm.
        assert!(
            text.contains(r#""B_um":2.0,"#) && text.ends_with(r#""R_um":4.0}"#),
            "{text}"
        );
    }

    #[test]
    fn a_rotary_target_is_in_degrees_and_arcsec_or_urad() {
        // 0.001° = 3.6″ = 17.453 292 5 µrad; B = 0.002° = 7.2″.
        let arcsec =
            PerTargetJson::from_stats_of(&target(90.0), AxisKind::Rotary, AngleUnit::Arcsec);
        let text = serde_json::to_string(&arcsec).unwrap();
        assert!(
            text.starts_with(r#"{"target_deg":90.0,"n_up":2,"n_down":2,"mean_up_arcsec":3.6,"#),
            "{text}"
        );
        assert!(text.contains(r#""B_arcsec":7.2,"#), "{text}");
        assert_eq!(
            keys(&text),
            [
                "target_deg",
                "n_up",
                "n_down",
                "mean_up_arcsec",
                "mean_down_arcsec",
                "mean_arcsec",
                "s_up_arcsec",
                "s_down_arcsec",
                "B_arcsec",
                "R_up_arcsec",
                "R_down_arcsec",
                "R_arcsec"
            ]
        );
        assert_eq!(arcsec.target(), 90.0);
        assert_eq!(arcsec.cells()[0], ("mean_up_arcsec", Some(3.6)));
        let urad = PerTargetJson::from_stats_of(&target(90.0), AxisKind::Rotary, AngleUnit::Urad);
        let (key, value) = urad.cells()[0];
        assert_eq!(key, "mean_up_urad");
        assert!((value.unwrap() - 17.453_292_519_943_3).abs() < 1e-9);
    }

    #[test]
    fn outliers_carry_the_unit_in_their_keys() {
        let outlier = SuspectedOutlier {
            direction: Direction::Down,
            run: 1,
            score: 6.5,
            worst_target: 90.0,
            offset: 0.01,
        };
        // 0.01° = 36″; 0.01 mm = 10 µm.
        let rotary = OutlierJson::from_outlier(&outlier, AxisKind::Rotary, AngleUnit::Arcsec);
        assert_eq!(
            serde_json::to_string(&rotary).unwrap(),
            r#"{"run":1,"direction":"down","score":6.5,"worst_target_deg":90.0,"offset_arcsec":36.0}"#
        );
        let linear = OutlierJson::from_outlier(&outlier, AxisKind::Linear, AngleUnit::Arcsec);
        assert_eq!(
            serde_json::to_string(&linear).unwrap(),
            r#"{"run":1,"direction":"down","score":6.5,"worst_target_mm":90.0,"offset_um":10.0}"#
        );
        assert_eq!(linear.shown().offset, 10.0);
    }

    #[test]
    fn the_travel_and_the_figures_carry_their_unit_in_their_key() {
        let length = |kind: AxisKind| {
            let c = TestConformance {
                length: kind.position(360.0),
                targets: 25,
                runs_up: 5,
                runs_down: 5,
                checks: Vec::new(),
            };
            let json = serde_json::to_value(ConformanceJson::from_conformance(&c)).unwrap();
            (
                json.get("length_mm").cloned(),
                json.get("length_deg").cloned(),
            )
        };
        assert_eq!(length(AxisKind::Linear), (Some(360.0.into()), None));
        assert_eq!(length(AxisKind::Rotary), (None, Some(360.0.into())));
        let figures = [StandardFigure {
            key: "E",
            value: Some(0.002),
        }];
        // 0.002 mm = 2 µm; 0.002° = 7.2″.
        let key = |kind, angle| {
            serde_json::to_value(FiguresByUnit::of(&typed(&figures, kind), angle))
                .unwrap()
                .to_string()
        };
        assert_eq!(
            key(AxisKind::Linear, AngleUnit::Urad),
            r#"{"figures_um":{"E":2.0}}"#
        );
        assert_eq!(
            key(AxisKind::Rotary, AngleUnit::Arcsec),
            r#"{"figures_arcsec":{"E":7.2}}"#
        );
        assert!(key(AxisKind::Rotary, AngleUnit::Urad).starts_with(r#"{"figures_urad":{"E":34.9"#));
    }

    #[test]
    fn what_is_written_in_um_only_leaves_a_rotary_axis_figures_out() {
        let figures = [StandardFigure {
            key: "E",
            value: Some(0.002),
        }];
        // 0.002 mm = 2 µm; 0.002° is not written as 2 µm.
        let um = |kind| FiguresJson::of_linear(&typed(&figures, kind));
        assert_eq!(um(AxisKind::Linear).get("E"), Some(2.0));
        assert!(um(AxisKind::Rotary).is_empty());
    }
}
