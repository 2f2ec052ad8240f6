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
//! A rotary axis adds `"axis_kind": "rotary"` (after `table`) and carries
//! its units in the same keys: every `_um` key is `_arcsec` (″), every `_mm`
//! key `_deg` (`residual_before_arcsec`, `figures_arcsec`, `noise_arcsec`,
//! `unexplained.where_deg`, `evidence.cv_rmse_with_arcsec`, a periodic
//! effect's `period_deg` and `amplitude_arcsec`, a reversal's `B_arcsec`,
//! an outlier run's `offset_arcsec`), and a periodic effect's `params` add
//! `per_revolution`, its whole order (2: twice per revolution, period
//! 180°). The terminal says ″ and °. With `--angle-unit urad` the same
//! values are µrad and every such key ends in `_urad`
//! (`residual_before_urad`, `amplitude_urad`) instead. A rotary axis is
//! diagnosed for per-revolution harmonics, its reversal and outlier runs
//! only; it has no `friction`.
//!
//! Each key's unit is the type of the value under it, and each value comes
//! typed from the diagnosis (`Diagnosis::typed`: `Um` and `Mm`, or `Deg`
//! converted by `Deg::to_arcsec` or `Deg::to_urad`), an effect's
//! parameters and their uncertainties too (`Effect::typed`). The object, its
//! evidence and its unexplained structure are one struct per pair of units
//! (`LinearDiagnoseJson` with `residual_before_um: ResidualJson<Um>` and
//! `unexplained.where_mm: Vec<Mm>`, `ArcsecDiagnoseJson`,
//! `UradDiagnoseJson`), and so are a rotary axis' effect parameters
//! (`ArcsecParameters`, `UradParameters`); a linear axis' `params` are the
//! effect's own parameter definitions (`effects::Parameter`), keyed as they
//! name themselves. No key is renamed at run time; every object's keys are
//! in the order declared (`params` and `uncertainty` by key).

use serde::Serialize;
use serde_json::{Map, Value};

use crate::diagnose::friction::ReversalFriction;
use crate::diagnose::{Diagnosis, DiagnosisIn, ResidualStats};
use crate::evaluate::{StandardFigure, standard};
use crate::measurement::{AxisKind, ByKind};
use crate::report::json::{FiguresByUnit, FiguresJson};
use crate::units::{AngleUnit, Arcsec, Deg, DeviationUnit, Mm, Um, Urad};

mod parameters;
mod terminal;

pub use parameters::{
    ArcsecParameters, ArcsecUncertainty, Cell, Cells, EffectParameters, UradParameters,
    UradUncertainty,
};
pub use terminal::render;

/// A deviation as a diagnosis reports it: µm ([`Um`]) on a linear axis, ″
/// ([`Arcsec`]) or µrad ([`Urad`]) on a rotary one, each converted from the
/// diagnosis' typed numbers ([`Diagnosis::typed`]).
pub trait ReportedDeviation: Serialize + Copy {
    /// The unit, for the terminal.
    const UNIT: DeviationUnit;

    /// The number, in this unit.
    fn number(self) -> f64;
}

/// [`ReportedDeviation`] for `$quantity`, reported in `$unit`.
macro_rules! reported_deviation {
    ($quantity:ty, $unit:expr) => {
        impl ReportedDeviation for $quantity {
            const UNIT: DeviationUnit = $unit;

            fn number(self) -> f64 {
                self.0
            }
        }
    };
}

reported_deviation!(Um, DeviationUnit::Micrometre);
reported_deviation!(Arcsec, DeviationUnit::Angle(AngleUnit::Arcsec));
reported_deviation!(Urad, DeviationUnit::Angle(AngleUnit::Urad));

/// A position as a diagnosis reports it: mm ([`Mm`]) on a linear axis, °
/// ([`Deg`]) on a rotary one.
pub trait ReportedPosition: Serialize + Copy {
    /// What follows the number in the terminal: ` mm` or `°`.
    const SUFFIX: &'static str;

    /// The number, in this unit.
    fn number(self) -> f64;
}

impl ReportedPosition for Mm {
    const SUFFIX: &'static str = " mm";

    fn number(self) -> f64 {
        self.0
    }
}

impl ReportedPosition for Deg {
    const SUFFIX: &'static str = "°";

    fn number(self) -> f64 {
        self.0
    }
}

/// RMS and largest |value| of a residual, in the unit its key names.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ResidualJson<D> {
    /// Root mean square.
    pub rms: D,
    /// Largest |value|.
    pub max_abs: D,
}

impl<D: ReportedDeviation> ResidualJson<D> {
    fn new(s: ResidualStats<D>) -> ResidualJson<D> {
        ResidualJson {
            rms: s.rms,
            max_abs: s.max_abs,
        }
    }

    fn numbers(&self) -> (f64, f64) {
        (self.rms.number(), self.max_abs.number())
    }
}

/// An accepted effect: its parameters `P` and their uncertainties `U` under
/// keys with their units, and the evidence `E` for it.
#[derive(Clone, Debug, Serialize)]
pub struct EffectJson<P, U, E> {
    /// `reversal`, `scale`, `drift`, `periodic`, `outlier-run` or `abbe`.
    pub kind: &'static str,
    /// Its parameters, keys with units.
    pub params: P,
    /// Standard uncertainty of the parameters, same keys.
    pub uncertainty: U,
    /// Why it was accepted.
    pub evidence: E,
    /// What it is and what to do, one sentence.
    pub explanation: String,
    /// Caveats (aliasing, assumed times).
    pub warnings: Vec<String>,
}

/// An effect as the terminal shows it, whatever its units.
struct EffectShown<'a> {
    kind: &'static str,
    /// (key, value, its uncertainty), in the order written.
    params: Vec<(String, Cell, Option<f64>)>,
    delta_bic: f64,
    cv_rmse_without: f64,
    cv_rmse_with: f64,
    explanation: &'a str,
    warnings: &'a [String],
}

/// A kind looked for and not accepted.
#[derive(Clone, Debug, Serialize)]
pub struct RejectedJson {
    /// The kind.
    pub kind: &'static str,
    /// Why, in words.
    pub why: String,
}

/// The figures of the re-test three ways, in the unit of the key that holds them.
#[derive(Clone, Debug, Serialize)]
pub struct FigureSetJson {
    /// As measured.
    pub measured: FiguresJson,
    /// As the model predicted it.
    pub predicted: FiguresJson,
    /// Predicted with the accepted effects.
    pub predicted_with_effects: FiguresJson,
}

impl FigureSetJson {
    /// The diagnosis' figures typed by its axis' kind: µm on a linear axis,
    /// `angle` on a rotary one.
    fn new(diagnosis: &Diagnosis, angle: AngleUnit) -> FigureSetJson {
        let figures = &diagnosis.standard_figures;
        let shown = |figures: &[StandardFigure]| {
            FiguresByUnit::of(&standard::typed(figures, diagnosis.kind), angle).into_values()
        };
        FigureSetJson {
            measured: shown(&figures.measured),
            predicted: shown(&figures.predicted),
            predicted_with_effects: shown(&figures.predicted_with_effects),
        }
    }
}

/// What no effect explains, whatever its units.
struct UnexplainedShown {
    significant: bool,
    places: Vec<f64>,
    rms: f64,
    p_value: f64,
}

/// The files a diagnosis is of, as given.
struct Files {
    after: String,
    before: Option<String>,
    table: Option<String>,
}

/// A whole diagnosis as the terminal shows it, whatever its units.
struct Shown<'a> {
    after: &'a str,
    before: Option<&'a str>,
    table: Option<&'a str>,
    standard_name: &'static str,
    definitions_reconstructed: bool,
    residual_before: (f64, f64),
    residual_after: (f64, f64),
    noise: f64,
    effects: Vec<EffectShown<'a>>,
    rejected: &'a [RejectedJson],
    unexplained: UnexplainedShown,
    figures: &'a FigureSetJson,
    friction: Option<&'a FrictionJson>,
    deviation: DeviationUnit,
    position_suffix: &'static str,
}

/// Declares the `diagnose --json` object in one pair of units with its
/// evidence and unexplained-structure objects: each field's name is its
/// JSON key, its type the unit the key names. `head` fields follow the
/// files, `tail` fields end the object.
macro_rules! diagnose_json {
    (
        $(#[$doc:meta])*
        $name:ident, $evidence:ident, $unexplained:ident
            <$position:ty, $deviation:ty, $params:ty> {
            $residual_before:ident, $residual_after:ident, $figures:ident, $noise:ident,
            $cv_without:ident, $cv_with:ident, $where_:ident, $rms:ident $(,)?
        }
        head { $($(#[$head_meta:meta])* $head:ident: $head_ty:ty = $head_value:expr),* $(,)? }
        tail { $($(#[$tail_meta:meta])* $tail:ident: $tail_ty:ty = $tail_value:expr),* $(,)? }
    ) => {
        /// Why an effect was accepted.
        #[derive(Clone, Copy, Debug, Serialize)]
        pub struct $evidence {
            /// Change of the BIC when it was added (negative is better).
            pub delta_bic: f64,
            /// Shapes tried (periods, runs).
            pub trials: usize,
            /// p-value of adding it.
            pub p_value: f64,
            /// Leave-one-run-out prediction error without it.
            pub $cv_without: $deviation,
            /// The same with it.
            pub $cv_with: $deviation,
        }

        /// What no effect explains.
        #[derive(Clone, Debug, Serialize)]
        pub struct $unexplained {
            /// Significant (lack-of-fit p < 0.001).
            pub significant: bool,
            /// Where it is largest.
            pub $where_: Vec<$position>,
            /// RMS of the per-target mean residual.
            pub $rms: $deviation,
            /// p-value of the lack-of-fit test.
            pub p_value: f64,
        }

        $(#[$doc])*
        #[derive(Clone, Debug, Serialize)]
        pub struct $name {
            /// The re-test file.
            pub after: String,
            /// The first test file, if given.
            pub before: Option<String>,
            /// The table file, if given.
            pub table: Option<String>,
            $($(#[$head_meta])* pub $head: $head_ty,)*
            /// The `--standard` the figures follow (`iso230-2:2014`, `vdi3441`).
            pub standard: &'static str,
            /// Its name and edition.
            pub standard_name: &'static str,
            /// Whether its definitions are reconstructed from public sources.
            pub definitions_reconstructed: bool,
            /// Whether the prediction came from a first test.
            pub predicted_from_first_test: bool,
            /// The model's error before adding effects.
            pub $residual_before: ResidualJson<$deviation>,
            /// Effects found.
            pub effects: Vec<EffectJson<
                $params,
                <$params as EffectParameters<$position, $deviation>>::Uncertainty,
                $evidence,
            >>,
            /// Effects looked for and not found.
            pub rejected: Vec<RejectedJson>,
            /// The model's error with the effects.
            pub $residual_after: ResidualJson<$deviation>,
            /// Figures.
            pub $figures: FigureSetJson,
            /// What none of the effects explains.
            pub unexplained: $unexplained,
            /// Scatter of one reading left at the end.
            pub $noise: $deviation,
            /// Whether the reading times were assumed from a typical cycle.
            pub time_assumed: bool,
            $($(#[$tail_meta])* pub $tail: $tail_ty,)*
        }

        impl $name {
            fn new(
                diagnosis: &Diagnosis,
                typed: DiagnosisIn<$position, $deviation>,
                files: Files,
                angle: AngleUnit,
            ) -> $name {
                $name {
                    after: files.after,
                    before: files.before,
                    table: files.table,
                    $($head: $head_value,)*
                    standard: diagnosis.standard.key,
                    standard_name: diagnosis.standard.name,
                    definitions_reconstructed: diagnosis.standard.reconstructed,
                    predicted_from_first_test: diagnosis.predicted_from_first_test,
                    $residual_before: ResidualJson::new(typed.residual_before),
                    effects: diagnosis
                        .accepted
                        .iter()
                        .zip(&typed.evidence)
                        .zip(typed.effects)
                        .map(|((accepted, evidence), effect)| {
                            let (params, uncertainty) = <$params>::of(accepted, effect);
                            EffectJson {
                                kind: accepted.effect.kind().name(),
                                params,
                                uncertainty,
                                evidence: $evidence {
                                    delta_bic: evidence.delta_bic,
                                    trials: evidence.trials,
                                    p_value: evidence.p_value,
                                    $cv_without: evidence.cv_rmse_without,
                                    $cv_with: evidence.cv_rmse_with,
                                },
                                explanation: accepted.explanation.clone(),
                                warnings: accepted.warnings.clone(),
                            }
                        })
                        .collect(),
                    rejected: rejected(diagnosis),
                    $residual_after: ResidualJson::new(typed.residual_after),
                    $figures: FigureSetJson::new(diagnosis, angle),
                    unexplained: $unexplained {
                        significant: typed.unexplained.significant,
                        $where_: typed.unexplained.targets,
                        $rms: typed.unexplained.rms,
                        p_value: typed.unexplained.p_value,
                    },
                    $noise: typed.noise,
                    time_assumed: diagnosis.time_assumed,
                    $($tail: $tail_value,)*
                }
            }

            fn shown<'a>(&'a self, friction: Option<&'a FrictionJson>) -> Shown<'a> {
                Shown {
                    after: &self.after,
                    before: self.before.as_deref(),
                    table: self.table.as_deref(),
                    standard_name: self.standard_name,
                    definitions_reconstructed: self.definitions_reconstructed,
                    residual_before: self.$residual_before.numbers(),
                    residual_after: self.$residual_after.numbers(),
                    noise: self.$noise.number(),
                    effects: self
                        .effects
                        .iter()
                        .map(|effect| EffectShown {
                            kind: effect.kind,
                            params: with_uncertainty(
                                effect.params.cells(),
                                effect.uncertainty.cells(),
                            ),
                            delta_bic: effect.evidence.delta_bic,
                            cv_rmse_without: effect.evidence.$cv_without.number(),
                            cv_rmse_with: effect.evidence.$cv_with.number(),
                            explanation: &effect.explanation,
                            warnings: &effect.warnings,
                        })
                        .collect(),
                    rejected: &self.rejected,
                    unexplained: UnexplainedShown {
                        significant: self.unexplained.significant,
                        places: self
                            .unexplained
                            .$where_
                            .iter()
                            .map(|place| place.number())
                            .collect(),
                        rms: self.unexplained.$rms.number(),
                        p_value: self.unexplained.p_value,
                    },
                    figures: &self.$figures,
                    friction,
                    deviation: <$deviation as ReportedDeviation>::UNIT,
                    position_suffix: <$position as ReportedPosition>::SUFFIX,
                }
            }
        }
    };
}

diagnose_json!(
    /// `diagnose --json` of a linear axis: positions in mm, deviations in µm.
    LinearDiagnoseJson, LinearEvidenceJson, LinearUnexplainedJson
        <Mm, Um, Map<String, Value>> {
        residual_before_um, residual_after_um, figures_um, noise_um,
        cv_rmse_without_um, cv_rmse_with_um, where_mm, rms_um,
    }
    head {}
    tail {
        /// The friction behind the reversal found (with a servo description).
        #[serde(skip_serializing_if = "Option::is_none")]
        friction: Option<FrictionJson> = None,
    }
);

diagnose_json!(
    /// `diagnose --json` of a rotary axis: positions in °, deviations in ″.
    ArcsecDiagnoseJson, ArcsecEvidenceJson, ArcsecUnexplainedJson
        <Deg, Arcsec, ArcsecParameters> {
        residual_before_arcsec, residual_after_arcsec, figures_arcsec, noise_arcsec,
        cv_rmse_without_arcsec, cv_rmse_with_arcsec, where_deg, rms_arcsec,
    }
    head {
        /// `rotary`.
        axis_kind: &'static str = AxisKind::Rotary.as_str(),
    }
    tail {}
);

diagnose_json!(
    /// `diagnose --json` of a rotary axis: positions in °, deviations in µrad.
    UradDiagnoseJson, UradEvidenceJson, UradUnexplainedJson
        <Deg, Urad, UradParameters> {
        residual_before_urad, residual_after_urad, figures_urad, noise_urad,
        cv_rmse_without_urad, cv_rmse_with_urad, where_deg, rms_urad,
    }
    head {
        /// `rotary`.
        axis_kind: &'static str = AxisKind::Rotary.as_str(),
    }
    tail {}
);

/// The kinds looked for and not accepted.
fn rejected(diagnosis: &Diagnosis) -> Vec<RejectedJson> {
    diagnosis
        .rejected
        .iter()
        .map(|r| RejectedJson {
            kind: r.kind.name(),
            why: r.why.clone(),
        })
        .collect()
}

/// Each parameter with the uncertainty under its key, if any.
fn with_uncertainty(
    params: Vec<(String, Cell)>,
    uncertainty: Vec<(String, Cell)>,
) -> Vec<(String, Cell, Option<f64>)> {
    params
        .into_iter()
        .map(|(key, cell)| {
            let sigma = uncertainty.iter().find_map(|(k, u)| match u {
                Cell::Number(u) if *k == key => Some(*u),
                _ => None,
            });
            (key, cell, sigma)
        })
        .collect()
}

/// The whole `diagnose --json` object in the units of its axis and of
/// `--angle-unit`; each form's keys name its units (module doc).
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum DiagnoseJson {
    /// A linear axis: mm and µm.
    Linear(LinearDiagnoseJson),
    /// A rotary axis: ° and ″.
    Arcsec(ArcsecDiagnoseJson),
    /// A rotary axis: ° and µrad.
    Urad(UradDiagnoseJson),
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
        let files = Files {
            after,
            before,
            table,
        };
        match (diagnosis.typed(), angle) {
            (ByKind::Linear(typed), _) => {
                DiagnoseJson::Linear(LinearDiagnoseJson::new(diagnosis, typed, files, angle))
            }
            (ByKind::Rotary(typed), AngleUnit::Arcsec) => {
                DiagnoseJson::Arcsec(ArcsecDiagnoseJson::new(
                    diagnosis,
                    typed.map_deviations(Deg::to_arcsec),
                    files,
                    angle,
                ))
            }
            (ByKind::Rotary(typed), AngleUnit::Urad) => DiagnoseJson::Urad(UradDiagnoseJson::new(
                diagnosis,
                typed.map_deviations(Deg::to_urad),
                files,
                angle,
            )),
        }
    }

    /// The friction behind the reversal found (`--servo-axis`; a linear
    /// axis' only: its keys are µm and N).
    pub fn set_friction(&mut self, friction: Option<FrictionJson>) {
        match self {
            DiagnoseJson::Linear(linear) => linear.friction = friction,
            DiagnoseJson::Arcsec(_) | DiagnoseJson::Urad(_) => debug_assert!(friction.is_none()),
        }
    }

    fn shown(&self) -> Shown<'_> {
        match self {
            DiagnoseJson::Linear(linear) => linear.shown(linear.friction.as_ref()),
            DiagnoseJson::Arcsec(arcsec) => arcsec.shown(None),
            DiagnoseJson::Urad(urad) => urad.shown(None),
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    /// Run 1↓ 10 m° (0.01°) off the others, σ 1 m°.
    use crate::diagnose::tests::outlier_run;

    #[test]
    fn a_rotary_outlier_run_is_in_its_angle_unit_under_its_key() {
        // 0.01° = 36″ = 174.532 925 µrad; 0.001° = 3.6″.
        let run = outlier_run();
        let typed = |kind| run.effect.typed(kind, &run.uncertainty).unwrap();
        let rotary = typed(AxisKind::Rotary).rotary();
        let (params, uncertainty) =
            ArcsecParameters::of(&run, rotary.map(|r| r.map_deviations(Deg::to_arcsec)));
        assert_eq!(
            serde_json::to_string(&params).unwrap(),
            r#"{"direction":"down","offset_arcsec":36.0,"run":1}"#
        );
        assert_eq!(
            serde_json::to_string(&uncertainty).unwrap(),
            r#"{"offset_arcsec":3.6}"#
        );
        let (params, _) = UradParameters::of(&run, rotary.map(|r| r.map_deviations(Deg::to_urad)));
        let UradParameters::OutlierRun { offset_urad, .. } = params else {
            panic!("{params:?}")
        };
        assert!((offset_urad.0 - 174.532_925_199_432_95).abs() < 1e-9);
        // The same effect on a linear axis: the effect's own keys, µm.
        let (params, uncertainty) =
            Map::<String, Value>::of(&run, typed(AxisKind::Linear).linear());
        assert_eq!(
            serde_json::to_string(&params).unwrap(),
            r#"{"direction":"down","offset_um":10.0,"run":1}"#
        );
        assert_eq!(
            with_uncertainty(params.cells(), uncertainty.cells()),
            [
                ("direction".to_string(), Cell::Text("\"down\"".into()), None),
                ("offset_um".to_string(), Cell::Number(10.0), Some(1.0)),
                ("run".to_string(), Cell::Text("1".into()), None),
            ]
        );
    }
}
