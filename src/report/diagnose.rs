//! The `--json` wire format and the terminal report of `axcomp diagnose`.
//!
//! # Wire format
//!
//! One object; keys may be added, never renamed or removed. Residuals are
//! measured − predicted, µm, over every reading of the re-test.
//!
//! ```text
//! { "after": "after.rtl", "before": "before.rtl" | null, "table": "X.COM" | null,
//!   "standard": "iso230-2:2014", "standard_name": "ISO 230-2:2014",
//!   "definitions_reconstructed": false,      (as in evaluate: --standard)
//!   "predicted_from_first_test": true,
//!   "residual_before_um": {"rms": …, "max_abs": …},
//!   "effects": [{"kind": "periodic", "params": {"period_mm": …, "amplitude_um": …, "phase_rad": …},
//!                "uncertainty": {"period_mm": …, "amplitude_um": …},
//!                "evidence": {"delta_bic": …, "trials": …, "p_value": …,
//!                             "cv_rmse_without_um": …, "cv_rmse_with_um": …},
//!                "explanation": "…", "warnings": ["…"]}],
//!   "rejected": [{"kind": "scale", "why": "…"}],
//!   "residual_after_um": {"rms": …, "max_abs": …},
//!   "figures_um": {"measured": {"A": …, …}, "predicted": {…}, "predicted_with_effects": {…}},
//!                                            (each under the standard's keys, as in evaluate)
//!   "unexplained": {"significant": false, "where_mm": [], "rms_um": …, "p_value": …},
//!   "noise_um": …, "time_assumed": false,
//!   "friction": {"servo_axis": "mcfv5050-x", "B_um": -3.3, "B_uncertainty_um": 0.1,
//!                "change_since_first_test": false, "friction_n": 165.0,
//!                "friction_uncertainty_n": 5.0, "scale_part_n": 50.0,
//!                "stiffness_n_per_um": 100.0, "axis_coulomb_n": 90.0, "expected_reversal_um": -1.8,
//!                "start_coulomb_n": 165.0, "servo_sim": "axcomp servo-sim …"} }
//!                                            (only with --servo-axis and a reversal found)
//! ```
//!
//! `friction` is the force held against friction that the reversal means
//! through B̄ = B̄_scale − 2·F_res/k_c (`diagnose::friction`), with
//! B̄_scale = 0 and `scale_part_n` what one position increment of B̄_scale
//! would be worth (±); with a first test both are changes since then.
//!
//! `params` of an `outlier-run` are `run` (a number), `direction` (`up` or
//! `down`) and `offset_um`. `residual_before_um` is the model's error before
//! the effects are added, `residual_after_um` with them.
//!
//! A rotary axis adds `"axis_kind": "rotary"` and carries its
//! units in the same keys: every `_um` key is `_arcsec` (″), every `_mm` key
//! `_deg` (`residual_before_arcsec`, `figures_arcsec`, `noise_arcsec`,
//! `unexplained.where_deg`, `evidence.cv_rmse_with_arcsec`, a periodic
//! effect's `period_deg` and `amplitude_arcsec`, a reversal's `B_arcsec`),
//! and a periodic effect's `params` add `per_revolution`, its whole order
//! (2: twice per revolution, period 180°). The terminal says ″ and °.
//! With `--angle-unit urad` the same values are µrad and every such key
//! ends in `_urad` (`residual_before_urad`, `amplitude_urad`) instead.

use std::fmt::Write;

use serde::Serialize;
use serde_json::{Map, Value};

use crate::diagnose::friction::ReversalFriction;
use crate::diagnose::{AcceptedEffect, Diagnosis, ResidualStats};
use crate::effects::{Effect, ParameterValue};
use crate::measurement::AxisKind;
use crate::report::format::{pad_name, um};
use crate::report::json::FiguresJson;
use crate::units::{AngleUnit, DeviationUnit, um_to_mm};

/// How a diagnosis' values are reported: µm and mm on a linear axis, ″ (or
/// µrad, the [`AngleUnit`]) and ° on a rotary one (held inside as m°,
/// 1/1000 °, and °).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Units(AxisKind, AngleUnit);

impl Units {
    /// The unit a deviation is reported in.
    fn shown(self) -> DeviationUnit {
        self.0.deviation_unit(self.1)
    }

    /// A deviation held in µm (m° on a rotary axis) in its reported unit.
    fn deviation(self, value_um: f64) -> f64 {
        match self.shown() {
            DeviationUnit::Micrometre => value_um,
            DeviationUnit::Angle(angle) => angle.from_deg(um_to_mm(value_um)),
        }
    }

    /// A parameter by the unit its key carries: `_um` (and `_um_per_h`) a
    /// deviation, anything else (mm: ° on a rotary axis, rad, a run) as it is.
    fn parameter(self, key: &str, value: f64) -> f64 {
        if key.ends_with("_um") || key.ends_with("_um_per_h") {
            self.deviation(value)
        } else {
            value
        }
    }

    /// A key with the unit it reports: `_um` → `_arcsec` (`_urad`), `_mm`
    /// → `_deg` on a rotary axis; unchanged on a linear one.
    fn key(self, key: &str) -> String {
        if self.0 == AxisKind::Linear {
            return key.to_string();
        }
        let angle = self.shown().key();
        for (linear, rotary) in [
            ("_um", angle),
            ("_um_per_h", &format!("{angle}_per_h")),
            ("_mm", "deg"),
        ] {
            if let Some(stem) = key.strip_suffix(linear) {
                return format!("{stem}_{rotary}");
            }
        }
        key.to_string()
    }

    /// The keys of a serialised object, renamed by [`Units::key`] at every depth.
    fn keys(self, value: Value) -> Value {
        match value {
            Value::Object(map) => Value::Object(
                map.into_iter()
                    .map(|(k, v)| (self.key(&k), self.keys(v)))
                    .collect(),
            ),
            Value::Array(items) => Value::Array(items.into_iter().map(|v| self.keys(v)).collect()),
            other => other,
        }
    }

    /// After a deviation in the terminal: ` µm`, `″` or ` µrad`.
    fn deviation_suffix(self) -> &'static str {
        self.shown().suffix()
    }

    /// After a position in the terminal: ` mm` or `°`.
    fn position_suffix(self) -> &'static str {
        match self.0 {
            AxisKind::Linear => " mm",
            AxisKind::Rotary => "°",
        }
    }
}

/// RMS and largest |value|, µm.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ResidualJson {
    /// Root mean square, µm.
    pub rms: f64,
    /// Largest |value|, µm.
    pub max_abs: f64,
}

impl ResidualJson {
    fn new(s: ResidualStats, units: Units) -> ResidualJson {
        ResidualJson {
            rms: units.deviation(s.rms_um),
            max_abs: units.deviation(s.max_abs_um),
        }
    }
}

/// Why an effect was accepted.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct EvidenceJson {
    /// Change of the BIC when it was added (negative is better).
    pub delta_bic: f64,
    /// Shapes tried (periods, runs).
    pub trials: usize,
    /// p-value of adding it.
    pub p_value: f64,
    /// Leave-one-run-out prediction error without it, µm.
    pub cv_rmse_without_um: f64,
    /// The same with it, µm.
    pub cv_rmse_with_um: f64,
}

/// An accepted effect.
#[derive(Clone, Debug, Serialize)]
pub struct EffectJson {
    /// `reversal`, `scale`, `drift`, `periodic`, `outlier-run` or `abbe`.
    pub kind: &'static str,
    /// Its parameters, keys with units.
    pub params: Map<String, Value>,
    /// Standard uncertainty of the parameters, same keys.
    pub uncertainty: Map<String, Value>,
    /// Why it was accepted.
    pub evidence: EvidenceJson,
    /// What it is and what to do, one sentence.
    pub explanation: String,
    /// Caveats (aliasing, assumed times).
    pub warnings: Vec<String>,
}

impl EffectJson {
    /// From an accepted effect, in `units`.
    fn new(a: &AcceptedEffect, units: Units) -> EffectJson {
        let mut params = Map::new();
        for parameter in a.effect.parameters() {
            let value = match parameter.value {
                ParameterValue::Run(run) => Value::from(run),
                ParameterValue::Number(value) => Value::from(units.parameter(parameter.key, value)),
            };
            params.insert(parameter.key.to_string(), value);
        }
        match &a.effect {
            Effect::OutlierRun(run) => {
                params.insert("direction".into(), Value::from(run.direction.as_str()));
            }
            Effect::Periodic(periodic) if units.0 == AxisKind::Rotary => {
                if let Some(order) = periodic.per_revolution() {
                    params.insert("per_revolution".into(), Value::from(order));
                }
            }
            _ => {}
        }
        let uncertainty = a
            .uncertainty
            .iter()
            .map(|(k, v)| (k.to_string(), Value::from(units.parameter(k, *v))))
            .collect();
        EffectJson {
            kind: a.effect.kind().name(),
            params,
            uncertainty,
            evidence: EvidenceJson {
                delta_bic: a.evidence.delta_bic,
                trials: a.evidence.trials,
                p_value: a.evidence.p_value,
                cv_rmse_without_um: units.deviation(a.evidence.cv_rmse_without_um),
                cv_rmse_with_um: units.deviation(a.evidence.cv_rmse_with_um),
            },
            explanation: a.explanation.clone(),
            warnings: a.warnings.clone(),
        }
    }
}

/// A kind looked for and not accepted.
#[derive(Clone, Debug, Serialize)]
pub struct RejectedJson {
    /// The kind.
    pub kind: &'static str,
    /// Why, in words.
    pub why: String,
}

/// The figures of the re-test three ways, µm.
#[derive(Clone, Debug, Serialize)]
pub struct FigureSetJson {
    /// As measured.
    pub measured: FiguresJson,
    /// As the model predicted it.
    pub predicted: FiguresJson,
    /// Predicted with the accepted effects.
    pub predicted_with_effects: FiguresJson,
}

/// What no effect explains.
#[derive(Clone, Debug, Serialize)]
pub struct UnexplainedJson {
    /// Significant (lack-of-fit p < 0.001).
    pub significant: bool,
    /// Where it is largest, mm.
    pub where_mm: Vec<f64>,
    /// RMS of the per-target mean residual, µm.
    pub rms_um: f64,
    /// p-value of the lack-of-fit test.
    pub p_value: f64,
}

/// The whole `diagnose --json` object: the fields as a linear axis' keys
/// name them, with a rotary axis' values already in ″ and ° (module doc),
/// serialised under the keys of its unit.
#[derive(Clone, Debug)]
pub struct DiagnoseJson {
    fields: DiagnoseFields,
    units: Units,
}

impl Serialize for DiagnoseJson {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        if self.units.0 == AxisKind::Linear {
            return self.fields.serialize(serializer);
        }
        let Value::Object(fields) =
            serde_json::to_value(&self.fields).map_err(serde::ser::Error::custom)?
        else {
            unreachable!("a struct serialises as an object")
        };
        let mut object = Map::new();
        object.insert("axis_kind".into(), Value::from(AxisKind::Rotary.as_str()));
        object.extend(fields);
        self.units.keys(Value::Object(object)).serialize(serializer)
    }
}

/// [`DiagnoseJson`]'s fields.
#[derive(Clone, Debug, Serialize)]
struct DiagnoseFields {
    /// The re-test file.
    pub after: String,
    /// The first test file, if given.
    pub before: Option<String>,
    /// The table file, if given.
    pub table: Option<String>,
    /// The `--standard` the figures follow (`iso230-2:2014`, `vdi3441`).
    pub standard: &'static str,
    /// Its name and edition.
    pub standard_name: &'static str,
    /// Whether its definitions are reconstructed from public sources.
    pub definitions_reconstructed: bool,
    /// Whether the prediction came from a first test.
    pub predicted_from_first_test: bool,
    /// The model's error before adding effects, µm.
    pub residual_before_um: ResidualJson,
    /// Effects found.
    pub effects: Vec<EffectJson>,
    /// Effects looked for and not found.
    pub rejected: Vec<RejectedJson>,
    /// The model's error with the effects, µm.
    pub residual_after_um: ResidualJson,
    /// Figures.
    pub figures_um: FigureSetJson,
    /// What none of the effects explains.
    pub unexplained: UnexplainedJson,
    /// Scatter of one reading left at the end, µm.
    pub noise_um: f64,
    /// Whether the reading times were assumed from a typical cycle.
    pub time_assumed: bool,
    /// The friction behind the reversal found (with a servo description).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionJson>,
}

/// The friction force a found reversal means (module doc).
#[derive(Clone, Debug, Serialize)]
pub struct FrictionJson {
    /// The servo description (`--servo-axis`) as given.
    pub servo_axis: String,
    /// The reversal found, µm.
    #[serde(rename = "B_um")]
    pub b_um: f64,
    /// Its standard uncertainty, µm.
    #[serde(rename = "B_uncertainty_um")]
    pub b_uncertainty_um: f64,
    /// Whether B and the force are changes since the first test.
    pub change_since_first_test: bool,
    /// F_res, N.
    pub friction_n: f64,
    /// Its standard uncertainty, N.
    pub friction_uncertainty_n: f64,
    /// ± N that one position increment of the scale's own reversal is worth.
    pub scale_part_n: f64,
    /// k_c, N/µm.
    pub stiffness_n_per_um: f64,
    /// The same k_c under the key it had before 0.2 (a stiffness, misnamed;
    /// CHANGELOG.md), kept for scripts that read it.
    pub compliance_n_per_um: f64,
    /// The description's F_C, N.
    pub axis_coulomb_n: f64,
    /// −2·F_C/k_c with the description's F_C, µm.
    pub expected_reversal_um: f64,
    /// The F_C servo-sim starts from, N.
    pub start_coulomb_n: f64,
    /// The command that simulates the ISO test with it.
    pub servo_sim: String,
}

impl FrictionJson {
    /// Builds the wire object for the servo description `servo_axis`.
    pub fn new(servo_axis: &str, f: &ReversalFriction) -> FrictionJson {
        FrictionJson {
            servo_axis: servo_axis.to_string(),
            b_um: f.reversal_um,
            b_uncertainty_um: f.reversal_uncertainty_um,
            change_since_first_test: f.change_since_first_test,
            friction_n: f.friction_n,
            friction_uncertainty_n: f.friction_uncertainty_n,
            scale_part_n: f.scale_part_n,
            stiffness_n_per_um: f.stiffness_n_per_um,
            compliance_n_per_um: f.stiffness_n_per_um,
            axis_coulomb_n: f.axis_coulomb_n,
            expected_reversal_um: f.expected_reversal_um,
            start_coulomb_n: f.start_coulomb_n,
            servo_sim: format!(
                "axcomp servo-sim --axis {servo_axis} --friction lugre --test iso230-2 --coulomb-n {:.1} --stiffness-n-per-um {}",
                f.start_coulomb_n, f.stiffness_n_per_um
            ),
        }
    }

    /// The terminal lines under the reversal.
    fn lines(&self) -> Vec<String> {
        let what = if self.change_since_first_test {
            format!(
                "the friction force held after each approach changed by {:.1} ± {:.1} N since the first test",
                self.friction_n, self.friction_uncertainty_n
            )
        } else {
            format!(
                "F_res = {:.1} ± {:.1} N held against friction after each approach",
                self.friction_n, self.friction_uncertainty_n
            )
        };
        vec![
            format!(
                "friction: B̄ = B̄_scale − 2·F_res/k_c with k_c = {} N/µm ({}): {what}, ±{:.1} N more from the scale's own part (one position increment); the F_C of {} ({:.1} N) would give B = {:.2} µm",
                self.stiffness_n_per_um,
                self.servo_axis,
                self.scale_part_n,
                self.servo_axis,
                self.axis_coulomb_n,
                self.expected_reversal_um
            ),
            format!("servo-sim starts from it: {}", self.servo_sim),
        ]
    }
}

impl DiagnoseJson {
    /// Builds the wire object.
    /// A rotary axis' deviations are in `angle`.
    pub fn new(
        diagnosis: &Diagnosis,
        after: String,
        before: Option<String>,
        table: Option<String>,
        angle: AngleUnit,
    ) -> DiagnoseJson {
        let units = Units(diagnosis.kind, angle);
        let figures = |figures: &[crate::evaluate::StandardFigure]| match units.0 {
            AxisKind::Linear => FiguresJson::from_standard(figures),
            AxisKind::Rotary => FiguresJson::from_standard_deg(figures, angle),
        };
        let fields = DiagnoseFields {
            after,
            before,
            table,
            standard: diagnosis.standard.key,
            standard_name: diagnosis.standard.name,
            definitions_reconstructed: diagnosis.standard.reconstructed,
            predicted_from_first_test: diagnosis.predicted_from_first_test,
            residual_before_um: ResidualJson::new(diagnosis.residual_before, units),
            effects: diagnosis
                .accepted
                .iter()
                .map(|a| EffectJson::new(a, units))
                .collect(),
            rejected: diagnosis
                .rejected
                .iter()
                .map(|r| RejectedJson {
                    kind: r.kind.name(),
                    why: r.why.clone(),
                })
                .collect(),
            residual_after_um: ResidualJson::new(diagnosis.residual_after, units),
            figures_um: FigureSetJson {
                measured: figures(&diagnosis.standard_figures.measured),
                predicted: figures(&diagnosis.standard_figures.predicted),
                predicted_with_effects: figures(&diagnosis.standard_figures.predicted_with_effects),
            },
            unexplained: UnexplainedJson {
                significant: diagnosis.unexplained.significant,
                where_mm: diagnosis.unexplained.where_mm.clone(),
                rms_um: units.deviation(diagnosis.unexplained.rms_um),
                p_value: diagnosis.unexplained.p_value,
            },
            noise_um: units.deviation(diagnosis.noise_um),
            time_assumed: diagnosis.time_assumed,
            friction: None,
        };
        DiagnoseJson { fields, units }
    }

    /// The friction behind the reversal found (`--servo-axis`; a linear
    /// axis' only: its keys are µm and N).
    pub fn set_friction(&mut self, friction: Option<FrictionJson>) {
        debug_assert!(friction.is_none() || self.units.0 == AxisKind::Linear);
        self.fields.friction = friction;
    }
}

/// The terminal report.
pub fn render(report: &DiagnoseJson) -> String {
    let units = report.units;
    let (dev, pos) = (units.deviation_suffix(), units.position_suffix());
    let report = &report.fields;
    let mut out = String::new();
    let source = match (&report.before, &report.table) {
        (Some(before), Some(table)) => format!("predicted from {before} with {table}"),
        (Some(before), None) => format!("predicted from {before} (no table)"),
        _ => "no first test: structure between runs only".to_string(),
    };
    let _ = writeln!(out, "Re-test      {} ({source})", report.after);
    let (b, a) = (&report.residual_before_um, &report.residual_after_um);
    let _ = writeln!(
        out,
        "Residual     rms {}{dev}, max {}{dev}; with the effects rms {}{dev}, max {}{dev}; noise {}{dev}",
        um(Some(b.rms)),
        um(Some(b.max_abs)),
        um(Some(a.rms)),
        um(Some(a.max_abs)),
        um(Some(report.noise_um)),
    );
    let _ = writeln!(out, "\nFound");
    if report.effects.is_empty() {
        let _ = writeln!(out, "  nothing beyond noise");
    }
    for effect in &report.effects {
        let params: Vec<String> = effect
            .params
            .iter()
            .map(
                |(key, value)| match (value.as_f64(), effect.uncertainty.get(key)) {
                    // A run has no uncertainty: it is shown as it is.
                    (Some(v), Some(u)) => format!(
                        "{} = {v:.2} ± {:.2}",
                        units.key(key),
                        u.as_f64().unwrap_or(f64::NAN)
                    ),
                    // A number without an uncertainty (a phase): 4 decimals, as the effects file.
                    (Some(v), None) if value.is_f64() => format!("{} = {v:.4}", units.key(key)),
                    _ => format!("{} = {value}", units.key(key)),
                },
            )
            .collect();
        let _ = writeln!(
            out,
            "  {:<12} {}   (ΔBIC {:.1}; runs left out predicted {:.2} → {:.2}{dev})",
            effect.kind,
            params.join(", "),
            effect.evidence.delta_bic,
            effect.evidence.cv_rmse_without_um,
            effect.evidence.cv_rmse_with_um,
        );
        let _ = writeln!(out, "  {:<12} {}", "", effect.explanation);
        if effect.kind == "reversal"
            && let Some(friction) = &report.friction
        {
            for line in friction.lines() {
                let _ = writeln!(out, "  {:<12} {line}", "");
            }
        }
        for warning in &effect.warnings {
            let _ = writeln!(out, "  {:<12} warning: {warning}", "");
        }
    }
    let _ = writeln!(out, "\nNot found");
    for rejected in &report.rejected {
        let _ = writeln!(out, "  {:<12} {}", rejected.kind, rejected.why);
    }
    let u = &report.unexplained;
    let _ = writeln!(out);
    if u.significant {
        let places: Vec<String> = u.where_mm.iter().map(|x| format!("{x}")).collect();
        let _ = writeln!(
            out,
            "Unexplained  significant structure (p = {:.1e}), rms {}{dev}, largest at {}{pos}: no known effect describes it",
            u.p_value,
            um(Some(u.rms_um)),
            places.join(", ")
        );
    } else {
        let _ = writeln!(
            out,
            "Unexplained  nothing significant (p = {:.2}), rms {}{dev}",
            u.p_value,
            um(Some(u.rms_um))
        );
    }
    // The first column fits its heading: `Figures [µrad]` is wider than `Figures [µm]`.
    let heading = format!("Figures [{}]", dev.trim());
    let width = heading.chars().count().max(12);
    let _ = writeln!(
        out,
        "\n{heading:<width$} |  measured | predicted | predicted with effects   ({}{})",
        report.standard_name,
        if report.definitions_reconstructed {
            "; definitions reconstructed from public sources (docs/src/evaluate.md, Standards)"
        } else {
            ""
        }
    );
    let _ = writeln!(
        out,
        "{}+-----------+-----------+-----------------------",
        "-".repeat(width + 1)
    );
    let f = &report.figures_um;
    for (name, key) in f.measured.terminal_rows() {
        let _ = writeln!(
            out,
            " {} | {:>9} | {:>9} | {:>22}",
            pad_name(name, width - 1),
            um(f.measured.get(key)),
            um(f.predicted.get(key)),
            um(f.predicted_with_effects.get(key))
        );
    }
    out
}
