//! The `--json` wire format and the terminal report of `axcomp predict`.
//!
//! # Wire format
//!
//! One object; keys may be added, never renamed or removed. The re-test of the
//! first `--table`'s axis is at the top level; further tables' re-tests are
//! in `also`, with the same keys.
//!
//! ```text
//! { "machine": "MCV 754 Quick", "chain": "ZFYX",
//!   "standard": "iso230-2:2014", "standard_name": "ISO 230-2:2014",
//!   "definitions_reconstructed": false,      (as in evaluate: --standard)
//!   "axis": "X", "line_mm": {"x": 0.0, "y": 250.0, "z": -275.0},
//!   "with_measured_scatter": true, "table_mode": "mean",
//!   "measured_B_mean_um": -3.18,              (the first test's B̄, which the prediction carries; null if unknown)
//!   "backlash_set": false,                    (--backlash-set: the backlash parameter takes B̄ out)
//!   "predicted_figures_um": {"A": …, … as in evaluate: the standard's keys},
//!   "figures_before_um": {…},                 (the same line without the table)
//!   "per_target": [{"target_mm": …, "predicted_up_um": …, "predicted_down_um": …,
//!                   "before_up_um": …, "before_down_um": …}, …],
//!   "also": [{"axis": "Y", …}],
//!   "volumetric_max_um": …, "volumetric_max_at_mm": {"x", "y", "z"},
//!   "volumetric_max_before_um": …, "volumetric_max_before_at_mm": {…},
//!   "volumetric_max_positioning_only_um": …, "volumetric_max_positioning_only_at_mm": {…},
//!                                             (the positioning tables only, without --cross-table)
//!   "shares": [{"error": "EYX", "share": 0.41, "contribution_um": …}, …],
//!                                             (at volumetric_max_at_mm, largest first; add up to 1)
//!   "grid_step_mm": 50.0, "grid_points": 2112,
//!   "effects": ["reversal"], "notes": ["…"],
//!   "survey": {                               (only with --survey)
//!     "measured": ["EXX", "EYX", …], "assumed": [{"error": "EAX", "as": "declared" | "zero"}],
//!     "sources": [{"error": "EYX", "source": "measured", "files": ["X.csv"]}, …],
//!     "straightness": [{"error": "EYX", "file": "X.csv", "reference_line": "least-squares",
//!                       "straightness_um": …, "slope_urad": …}],
//!     "squareness": [{"pair": "XY", "error": "EXOY", "convention": "right-handed",
//!                     "value_urad": …, "angle_minus_90_urad": …, "model_urad": …}],
//!     "optics": [{"file": "X.csv", "axis": "X", "on": "workpiece" | "tool",
//!                 "on_stated": true, "offset_mm": {"x", "y", "z"}}] } }
//!                                             (each test's moving optic as taken; on_stated
//!                                              false: the body the axis moves, by the chain)
//! ```
//!
//! A straightness's `slope_urad` is its reference line's slope, kept apart
//! (alignment, or squareness against the pair's other test); `value_urad`
//! of a squareness is signed in the survey's convention (`right-handed`:
//! positive when the angle is below 90°; `larger-than-90`: above).
//!
//! Deviations are actual − target as the laser reads them on the line, µm.

use std::fmt::Write;

use serde::Serialize;

use crate::evaluate::{StandardFigure, standard};
use crate::predict::survey::{MeasuredState, Source, pair_name, squareness_name};
use crate::predict::{PredictedRetest, Prediction};
use crate::report::format::{pad_name, um};
use crate::report::json::FiguresJson;
use crate::units::{mm_to_um, rad_to_um_per_m};

/// A machine position, mm.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct PositionJson {
    /// X, mm.
    pub x: f64,
    /// Y, mm.
    pub y: f64,
    /// Z, mm.
    pub z: f64,
}

impl From<[f64; 3]> for PositionJson {
    fn from(p: [f64; 3]) -> PositionJson {
        PositionJson {
            x: p[0],
            y: p[1],
            z: p[2],
        }
    }
}

/// One target of a predicted re-test, µm.
#[derive(Clone, Debug, Serialize)]
pub struct PredictedTargetJson {
    /// Target, mm.
    pub target_mm: f64,
    /// With the table, moving ↑.
    pub predicted_up_um: f64,
    /// With the table, moving ↓.
    pub predicted_down_um: f64,
    /// Without the table, moving ↑.
    pub before_up_um: f64,
    /// Without the table, moving ↓.
    pub before_down_um: f64,
}

/// The re-test of one axis.
#[derive(Clone, Debug, Serialize)]
pub struct RetestJson {
    /// The axis.
    pub axis: String,
    /// The line, mm.
    pub line_mm: PositionJson,
    /// Whether the readings carry the measured test's scatter.
    pub with_measured_scatter: bool,
    /// `mean` or `bidirectional`.
    pub table_mode: &'static str,
    /// The mean reversal B̄ the first test measured, which the prediction
    /// carries, µm; `null` without a bidirectional first test.
    #[serde(rename = "measured_B_mean_um")]
    pub measured_b_mean_um: Option<f64>,
    /// Whether the controller's backlash parameter takes B̄ out (`--backlash-set`).
    pub backlash_set: bool,
    /// Figures of the predicted re-test under the standard's keys, µm.
    pub predicted_figures_um: FiguresJson,
    /// The same line without the table, under the standard's keys, µm.
    pub figures_before_um: FiguresJson,
    /// Per target.
    pub per_target: Vec<PredictedTargetJson>,
}

impl RetestJson {
    /// From a predicted re-test.
    pub fn new(retest: &PredictedRetest) -> RetestJson {
        RetestJson {
            axis: retest.axis.letter().to_string(),
            line_mm: retest.line_mm.into(),
            with_measured_scatter: retest.with_measured_scatter,
            table_mode: retest.table_mode.as_str(),
            measured_b_mean_um: retest.measured_mean_reversal_mm.map(mm_to_um),
            backlash_set: retest.backlash_reversal_mm != 0.0,
            predicted_figures_um: in_um(&retest.standard_figures, retest),
            figures_before_um: in_um(&retest.standard_figures_before, retest),
            per_target: retest
                .per_target
                .iter()
                .map(|t| PredictedTargetJson {
                    target_mm: t.target_mm,
                    predicted_up_um: mm_to_um(t.up_mm),
                    predicted_down_um: mm_to_um(t.down_mm),
                    before_up_um: mm_to_um(t.before_up_mm),
                    before_down_um: mm_to_um(t.before_down_mm),
                })
                .collect(),
        }
    }
}

/// A re-test's figures in µm (the volumetric model predicts linear axes only).
fn in_um(figures: &[StandardFigure], retest: &PredictedRetest) -> FiguresJson {
    FiguresJson::of_linear(&standard::typed(figures, retest.retest.kind()))
}

/// One error's share of the largest residual volumetric error.
#[derive(Clone, Debug, Serialize)]
pub struct ShareJson {
    /// ISO 230-1 name.
    pub error: &'static str,
    /// Its contribution along ‖E‖'s direction over ‖E‖ (the shares add up to 1).
    pub share: f64,
    /// Its contribution's size there, µm.
    pub contribution_um: f64,
}

/// The whole `predict --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct PredictJson {
    /// Machine name.
    pub machine: String,
    /// Chain code.
    pub chain: String,
    /// The `--standard` the figures follow (`iso230-2:2014`, `vdi3441`).
    pub standard: &'static str,
    /// Its name and edition.
    pub standard_name: &'static str,
    /// Whether its definitions are reconstructed from public sources.
    pub definitions_reconstructed: bool,
    /// The first table's re-test; none when only cross-axis tables are given.
    #[serde(flatten)]
    pub retest: Option<RetestJson>,
    /// The other tables' re-tests.
    pub also: Vec<RetestJson>,
    /// Largest volumetric error with the tables, µm.
    pub volumetric_max_um: f64,
    /// Where, mm.
    pub volumetric_max_at_mm: PositionJson,
    /// Largest volumetric error without the tables, µm.
    pub volumetric_max_before_um: f64,
    /// Where, mm.
    pub volumetric_max_before_at_mm: PositionJson,
    /// Largest volumetric error with the positioning tables only, µm.
    pub volumetric_max_positioning_only_um: f64,
    /// Where, mm.
    pub volumetric_max_positioning_only_at_mm: PositionJson,
    /// Each error's share of the largest residual, largest first.
    pub shares: Vec<ShareJson>,
    /// Step of the map, mm.
    pub grid_step_mm: f64,
    /// Points of the map.
    pub grid_points: usize,
    /// Kinds of the effects added from `--effects`.
    pub effects: Vec<&'static str>,
    /// What the reader should know, as sentences.
    pub notes: Vec<String>,
    /// The measured state, with `--survey`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub survey: Option<SurveyJson>,
}

/// Where one error's value came from.
#[derive(Clone, Debug, Serialize)]
pub struct SourceJson {
    /// ISO 230-1 name.
    pub error: &'static str,
    /// `measured`, `squareness from straightness`, `given`, `declared` or `zero`.
    pub source: &'static str,
    /// The files it was measured in.
    pub files: Vec<String>,
}

/// An error not measured.
#[derive(Clone, Debug, Serialize)]
pub struct AssumedJson {
    /// ISO 230-1 name.
    pub error: &'static str,
    /// `declared` (the errors file) or `zero`.
    #[serde(rename = "as")]
    pub taken_as: &'static str,
}

/// A straightness test as evaluated.
#[derive(Clone, Debug, Serialize)]
pub struct StraightnessJson {
    /// ISO 230-1 name.
    pub error: &'static str,
    /// The file.
    pub file: String,
    /// `least-squares` or `end-points`.
    pub reference_line: &'static str,
    /// Range of the residuals about the line, µm.
    pub straightness_um: f64,
    /// The line's slope, µrad (µm/m): alignment or squareness.
    pub slope_urad: f64,
}

/// A squareness found or given.
#[derive(Clone, Debug, Serialize)]
pub struct SquarenessJson {
    /// `XY`, `XZ` or `YZ`.
    pub pair: &'static str,
    /// The model's name: `EXOY`, `EXOZ`, `EYOZ`.
    pub error: &'static str,
    /// `right-handed` or `larger-than-90`.
    pub convention: &'static str,
    /// Signed in the convention, µrad.
    pub value_urad: f64,
    /// The angle between the positive directions minus 90°, µrad.
    pub angle_minus_90_urad: f64,
    /// The model's value, µrad (its chain's own sign and scale).
    pub model_urad: f64,
}

/// The measured state of `predict --survey`.
#[derive(Clone, Debug, Serialize)]
pub struct SurveyJson {
    /// Errors a test measured (or the survey gives as measured), ISO order.
    pub measured: Vec<&'static str>,
    /// Errors not measured, and how they were taken.
    pub assumed: Vec<AssumedJson>,
    /// Every error's source.
    pub sources: Vec<SourceJson>,
    /// The straightness tests.
    pub straightness: Vec<StraightnessJson>,
    /// The squareness errors.
    pub squareness: Vec<SquarenessJson>,
    /// Each test's moving optic as it was taken.
    pub optics: Vec<OpticsJson>,
}

/// Where a survey test's moving optic was taken to be.
#[derive(Clone, Debug, Serialize)]
pub struct OpticsJson {
    /// The test's file.
    pub file: String,
    /// The axis it measured.
    pub axis: String,
    /// The body that carries the optic: `tool` or `workpiece`.
    pub on: &'static str,
    /// Whether the survey named the body (else the one the axis moves).
    pub on_stated: bool,
    /// From the tool tip, mm.
    pub offset_mm: PositionJson,
}

impl SurveyJson {
    /// From the measured state.
    pub fn new(state: &MeasuredState) -> SurveyJson {
        let source = |s: &Source| -> (&'static str, Vec<String>) {
            match s {
                Source::Measured(file) => ("measured", vec![file.clone()]),
                Source::Squareness(files) => ("squareness from straightness", files.to_vec()),
                Source::GivenSquareness => ("given", Vec::new()),
                Source::Declared => ("declared", Vec::new()),
                Source::AssumedZero => ("zero", Vec::new()),
            }
        };
        SurveyJson {
            measured: state
                .sources
                .iter()
                .filter(|(_, s)| s.is_measured())
                .map(|(n, _)| n.as_str())
                .collect(),
            assumed: state
                .sources
                .iter()
                .filter(|(_, s)| !s.is_measured())
                .map(|(n, s)| AssumedJson {
                    error: n.as_str(),
                    taken_as: source(s).0,
                })
                .collect(),
            sources: state
                .sources
                .iter()
                .map(|(n, s)| {
                    let (source, files) = source(s);
                    SourceJson {
                        error: n.as_str(),
                        source,
                        files,
                    }
                })
                .collect(),
            straightness: state
                .straightness
                .iter()
                .map(|s| StraightnessJson {
                    error: s.name.as_str(),
                    file: s.file.clone(),
                    reference_line: s.straightness.reference.as_str(),
                    straightness_um: mm_to_um(s.straightness.deviation_mm()),
                    slope_urad: rad_to_um_per_m(s.straightness.slope),
                })
                .collect(),
            squareness: state
                .squareness
                .iter()
                .map(|s| SquarenessJson {
                    pair: pair_name(s.pair),
                    error: squareness_name(s.pair).as_str(),
                    convention: state.convention.as_str(),
                    value_urad: rad_to_um_per_m(s.signed_rad),
                    angle_minus_90_urad: rad_to_um_per_m(s.excess_rad),
                    model_urad: rad_to_um_per_m(s.model_rad),
                })
                .collect(),
            optics: state
                .optics
                .iter()
                .map(|o| OpticsJson {
                    file: o.file.clone(),
                    axis: o.axis.to_string(),
                    on: o.optics.body.name(),
                    on_stated: o.body_stated,
                    offset_mm: o.optics.offset_mm.into(),
                })
                .collect(),
        }
    }
}

impl PredictJson {
    /// Builds the wire object (a re-test per positioning table).
    pub fn new(
        machine: &str,
        chain: &str,
        prediction: &Prediction,
        grid_step_mm: f64,
        effects: Vec<&'static str>,
        notes: Vec<String>,
    ) -> PredictJson {
        let mut retests = prediction.retests.iter().map(RetestJson::new);
        let first = retests.next();
        PredictJson {
            machine: machine.to_string(),
            chain: chain.to_string(),
            standard: prediction.standard.key,
            standard_name: prediction.standard.name,
            definitions_reconstructed: prediction.standard.reconstructed,
            retest: first,
            also: retests.collect(),
            volumetric_max_um: mm_to_um(prediction.volumetric_after.max_mm),
            volumetric_max_at_mm: prediction.volumetric_after.at_mm.into(),
            volumetric_max_before_um: mm_to_um(prediction.volumetric_before.max_mm),
            volumetric_max_before_at_mm: prediction.volumetric_before.at_mm.into(),
            volumetric_max_positioning_only_um: mm_to_um(
                prediction.volumetric_positioning_only.max_mm,
            ),
            volumetric_max_positioning_only_at_mm: prediction
                .volumetric_positioning_only
                .at_mm
                .into(),
            shares: prediction
                .shares
                .iter()
                .map(|s| ShareJson {
                    error: s.name.as_str(),
                    share: s.share,
                    contribution_um: mm_to_um(s.contribution_mm),
                })
                .collect(),
            grid_step_mm,
            grid_points: prediction.grid_points,
            effects,
            notes,
            survey: None,
        }
    }

    /// The same report with the survey's measured state.
    pub fn with_survey(self, survey: Option<SurveyJson>) -> PredictJson {
        PredictJson { survey, ..self }
    }
}

/// The terminal report.
pub fn render(report: &PredictJson) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "Machine      {} ({})", report.machine, report.chain);
    let _ = writeln!(out, "Figures      {}", report.standard_name);
    if report.definitions_reconstructed {
        let _ = writeln!(
            out,
            "             definitions reconstructed from public sources, not read in the standard (docs/src/evaluate.md, Standards)"
        );
    }
    for retest in report.retest.iter().chain(&report.also) {
        render_retest(&mut out, retest);
    }
    let at = |p: &PositionJson| format!("X {} Y {} Z {} mm", p.x, p.y, p.z);
    let _ = writeln!(
        out,
        "\nVolumetric error, max ‖E‖ over a {} mm grid ({} points)\n  without the tables {} µm at {}\n  with the tables    {} µm at {}",
        report.grid_step_mm,
        report.grid_points,
        um(Some(report.volumetric_max_before_um)),
        at(&report.volumetric_max_before_at_mm),
        um(Some(report.volumetric_max_um)),
        at(&report.volumetric_max_at_mm),
    );
    // The map of each direction carries the reversal its first test measured.
    let reversals: Vec<String> = report
        .retest
        .iter()
        .chain(&report.also)
        .filter_map(|r| {
            r.measured_b_mean_um
                .map(|b| format!("{} B̄ = {} µm", r.axis, um(Some(b))))
        })
        .collect();
    if !reversals.is_empty() {
        let _ = writeln!(
            out,
            "  (the worse of ↑ and ↓: each direction keeps what the tables leave of the reversal the first test measured, {})",
            reversals.join(", ")
        );
    }
    // Without a positioning table that line would repeat "without the tables".
    if report.retest.is_some()
        && report.volumetric_max_positioning_only_um != report.volumetric_max_um
    {
        let _ = writeln!(
            out,
            "  positioning tables only {} µm at {} (the cross-axis tables take the rest)",
            um(Some(report.volumetric_max_positioning_only_um)),
            at(&report.volumetric_max_positioning_only_at_mm),
        );
    }
    if !report.shares.is_empty() {
        let top: Vec<String> = report
            .shares
            .iter()
            .take(5)
            .map(|s| format!("{} {:.0} %", s.error, 100.0 * s.share))
            .collect();
        let _ = writeln!(
            out,
            "  where it is largest, by error (compensate the first next): {}",
            top.join(", ")
        );
    }
    if let Some(survey) = &report.survey {
        render_survey(&mut out, survey);
    }
    if !report.effects.is_empty() {
        let _ = writeln!(out, "Effects      {}", report.effects.join(", "));
    }
    for note in &report.notes {
        let _ = writeln!(out, "Note: {note}");
    }
    out
}

fn render_retest(out: &mut String, retest: &RetestJson) {
    let line = &retest.line_mm;
    let _ = writeln!(
        out,
        "\nRe-test of {} on the line X {} Y {} Z {} mm{}",
        retest.axis,
        line.x,
        line.y,
        line.z,
        if retest.with_measured_scatter {
            " (with the first test's scatter)"
        } else {
            " (systematic only: one run each way, no R)"
        }
    );
    let _ = writeln!(out, " figure [µm] | no table | with the table");
    let _ = writeln!(out, "-------------+----------+---------------");
    let (b, p) = (&retest.figures_before_um, &retest.predicted_figures_um);
    for (name, key) in p.terminal_rows() {
        let _ = writeln!(
            out,
            " {} | {:>8} | {:>14}",
            pad_name(name, 11),
            um(b.get(key)),
            um(p.get(key))
        );
    }
}

fn render_survey(out: &mut String, survey: &SurveyJson) {
    let _ = writeln!(
        out,
        "\nSurvey: {} of the 21 errors measured, {} assumed",
        survey.measured.len(),
        survey.assumed.len()
    );
    let _ = writeln!(out, "  measured  {}", survey.measured.join(" "));
    for (label, taken_as) in [("declared", "declared"), ("zero", "zero")] {
        let names: Vec<&str> = survey
            .assumed
            .iter()
            .filter(|a| a.taken_as == taken_as)
            .map(|a| a.error)
            .collect();
        if !names.is_empty() {
            let _ = writeln!(out, "  {label:<9} {}", names.join(" "));
        }
    }
    for s in &survey.straightness {
        let _ = writeln!(
            out,
            "  {} straightness {:.2} µm ({} line; slope {:.2} µrad kept apart) from {}",
            s.error, s.straightness_um, s.reference_line, s.slope_urad, s.file
        );
    }
    for s in &survey.squareness {
        let _ = writeln!(
            out,
            "  squareness {} {:.2} µrad ({}; the angle is 90° {} {:.2} µrad; model {} = {:.2} µrad)",
            s.pair,
            s.value_urad,
            s.convention,
            if s.angle_minus_90_urad < 0.0 {
                "−"
            } else {
                "+"
            },
            s.angle_minus_90_urad.abs(),
            s.error,
            s.model_urad
        );
    }
    for o in &survey.optics {
        let PositionJson { x, y, z } = o.offset_mm;
        let why = if o.on_stated {
            "as the survey says".to_string()
        } else {
            format!("the body {} moves", o.axis)
        };
        let _ = writeln!(
            out,
            "  optics of {} ({}): on the {} ({why}), x {x} y {y} z {z} mm from the tool tip; the laser on the other body",
            o.file, o.axis, o.on
        );
    }
}
