//! `diagnosis.html`: the diagnosis's figures, effects and plots.

use super::figures::{FIGURE_ROWS, FigureRow};
use super::{Plot, signed};
use crate::diagnose::{Diagnosis, Evidence, ResidualStats};
use crate::effects::{Parameter, ParameterValue};
use crate::evaluate::standard::{self, vdi_figure_name};
use crate::report::format::{SourcedUm, um};
use crate::report::json::FiguresJson;
use crate::units::Um;

/// `diagnosis.html`.
pub(super) struct DiagnosisView {
    pub(super) predicted_from_first_test: bool,
    pub(super) residual_before: ResidualCells,
    pub(super) residual_after: ResidualCells,
    pub(super) noise: SourcedUm,
    pub(super) time_assumed: bool,
    pub(super) figures: Vec<FigureRow>,
    pub(super) accepted: Vec<EffectRow>,
    /// (effect kind, why it was not accepted).
    pub(super) rejected: Vec<(&'static str, String)>,
    pub(super) unexplained: UnexplainedView,
    pub(super) residual_plot: Option<Plot>,
    pub(super) along_axis_plot: Option<Plot>,
    pub(super) effects_plot: Option<Plot>,
}

pub(super) struct ResidualCells {
    pub(super) rms: SourcedUm,
    pub(super) max_abs: SourcedUm,
}

pub(super) struct EffectRow {
    pub(super) kind: &'static str,
    pub(super) parameters: Vec<ParameterText>,
    pub(super) delta_bic: String,
    pub(super) trials: Option<usize>,
    /// `None`: below 0.0001 (`macros.html`, `p_value`).
    pub(super) p_value: Option<String>,
    pub(super) cv_rmse_without_um: String,
    pub(super) cv_rmse_with_um: String,
    pub(super) explanation: String,
    pub(super) warnings: Vec<String>,
}

/// One parameter with its standard uncertainty; µm values carry their data key.
pub(super) enum ParameterText {
    Run(u32),
    Um {
        name: &'static str,
        value: SourcedUm,
        plus_minus: Option<String>,
    },
    Number {
        name: &'static str,
        value: String,
        plus_minus: Option<String>,
        unit: &'static str,
    },
}

pub(super) struct UnexplainedView {
    pub(super) significant: bool,
    pub(super) p_value: Option<String>,
    pub(super) rms_um: String,
    /// Where it is largest, mm, `, `-separated; empty: spread along the axis.
    pub(super) where_mm: String,
}

/// The page's diagnosis, in mm and µm: `None` for a rotary axis' (the
/// report diagnoses linear axes only, `workflow::rotary`).
pub(super) fn diagnosis_view(
    diagnosis: &Diagnosis,
    plot: &dyn Fn(&str) -> Option<Plot>,
) -> Option<DiagnosisView> {
    let typed = diagnosis.typed().linear()?;
    let u = &typed.unexplained;
    Some(DiagnosisView {
        predicted_from_first_test: diagnosis.predicted_from_first_test,
        residual_before: residual_cells("residual_before", typed.residual_before),
        residual_after: residual_cells("residual_after", typed.residual_after),
        noise: SourcedUm::new("diagnosis.noise_um".to_string(), Some(typed.noise.0)),
        time_assumed: diagnosis.time_assumed,
        figures: diagnosis_figures(diagnosis),
        accepted: accepted_effects(diagnosis, &typed.evidence),
        rejected: diagnosis
            .rejected
            .iter()
            .map(|rejected| (rejected.kind.name(), rejected.why.clone()))
            .collect(),
        unexplained: UnexplainedView {
            significant: u.significant,
            p_value: p_value(u.p_value),
            rms_um: um(Some(u.rms.0)),
            where_mm: u
                .targets
                .iter()
                .map(|x| x.0.to_string())
                .collect::<Vec<_>>()
                .join(", "),
        },
        residual_plot: plot("residual"),
        along_axis_plot: plot("residual-along-axis"),
        effects_plot: plot("effects"),
    })
}

/// The RMS and largest |value| cells of a residual.
pub(super) fn residual_cells(name: &str, stats: ResidualStats<Um>) -> ResidualCells {
    let key = |what: &str| format!("diagnosis.{name}.{what}");
    ResidualCells {
        rms: SourcedUm::new(key("rms_um"), Some(stats.rms.0)),
        max_abs: SourcedUm::new(key("max_abs_um"), Some(stats.max_abs.0)),
    }
}

pub(super) fn diagnosis_figures(diagnosis: &Diagnosis) -> Vec<FigureRow> {
    let figures = &diagnosis.standard_figures;
    let sets = [
        ("measured", &figures.measured),
        ("predicted", &figures.predicted),
        ("predicted_with_effects", &figures.predicted_with_effects),
    ]
    // This page's figures are µm: a rotary axis' (degrees) are left out.
    .map(|(set, figures)| {
        (
            set,
            FiguresJson::of_linear(&standard::typed(figures, diagnosis.kind)),
        )
    });
    // The ISO 230-2 family's bidirectional figures, or every figure of another standard.
    let rows: Vec<(&'static str, &'static str, &'static str)> = if sets[0].1.is_iso230_2() {
        FIGURE_ROWS
            .iter()
            .map(|&(symbol, name, figure)| (symbol, name, figure.name()))
            .collect()
    } else {
        sets[0]
            .1
            .values
            .iter()
            .map(|&(key, _)| (key, vdi_figure_name(key), key))
            .collect()
    };
    rows.into_iter()
        .map(|(symbol, name, key)| FigureRow {
            symbol,
            name,
            cells: sets
                .iter()
                .map(|(set, json)| {
                    Some(SourcedUm::new(
                        format!("diagnosis.figures.{set}.{key}"),
                        json.get(key),
                    ))
                })
                .collect(),
            change: None,
        })
        .collect()
}

/// The accepted effects, each with its evidence in µm (`evidence`, in the
/// same order).
pub(super) fn accepted_effects(diagnosis: &Diagnosis, evidence: &[Evidence<Um>]) -> Vec<EffectRow> {
    diagnosis
        .accepted
        .iter()
        .zip(evidence)
        .enumerate()
        .map(|(index, (accepted, evidence))| EffectRow {
            kind: accepted.effect.kind().name(),
            parameters: accepted
                .effect
                .parameters()
                .into_iter()
                .map(|parameter| parameter_text(index, &parameter, &accepted.uncertainty))
                .collect(),
            delta_bic: signed(evidence.delta_bic, 1),
            trials: (evidence.trials > 1).then_some(evidence.trials),
            p_value: p_value(evidence.p_value),
            cv_rmse_without_um: um(Some(evidence.cv_rmse_without.0)),
            cv_rmse_with_um: um(Some(evidence.cv_rmse_with.0)),
            explanation: accepted.explanation.clone(),
            warnings: accepted.warnings.clone(),
        })
        .collect()
}

/// One parameter with its standard uncertainty; µm values carry their data key.
pub(super) fn parameter_text(
    index: usize,
    parameter: &Parameter,
    uncertainty: &[(&str, f64)],
) -> ParameterText {
    let (key, name, unit) = (parameter.key, parameter.name, parameter.unit);
    let plus_minus = uncertainty
        .iter()
        .find(|(k, _)| *k == key)
        .map(|(_, u)| format!("{u:.2}"));
    match parameter.value {
        ParameterValue::Run(run) => ParameterText::Run(run),
        ParameterValue::Number(value) if unit == "µm" => ParameterText::Um {
            name,
            value: SourcedUm::new(format!("diagnosis.accepted.{index}.{key}"), Some(value)),
            plus_minus,
        },
        ParameterValue::Number(value) => ParameterText::Number {
            name,
            value: format!("{value:.2}"),
            plus_minus,
            unit,
        },
    }
}

/// `= 0.1262` as `Some("0.1262")`; `None` below 0.0001.
pub(super) fn p_value(p: f64) -> Option<String> {
    (p >= 1e-4).then(|| format!("{p:.4}"))
}
