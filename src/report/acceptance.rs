//! The acceptance report's content: what it is made from ([`ReportInput`])
//! and its charts ([`charts`]), which the HTML shows as SVG and
//! `axcomp report --png` writes as PNG: the same [`Chart`] values either way.
//!
//! Every number comes from the values the other commands print: the
//! `Evaluation` of each test (as `evaluate`), the table as read back from its
//! file (as `convert --existing` reads it), the workflow's prediction of
//! the re-test with it (`compensate::retest`) and the `Diagnosis` (as `diagnose`). Deviations are
//! drawn in µm through `crate::units`. The diagnosis' charts are a linear
//! axis' (mm and µm): they read the diagnosis as `Diagnosis::typed` gives a
//! linear axis', and a rotary one has none (the report refuses it before,
//! `workflow::rotary`).

use crate::compensate::CompensationTable;
use crate::compensate::retest::KnownError;
use crate::diagnose::{Diagnosis, DiagnosisIn, ReadingResidual};
use crate::effects::{Context, Effect, Line};
use crate::emit::Controller;
use crate::error::Warning;
use crate::evaluate::{DirectionStats, Evaluation, Standard, StandardFigure, TargetStats};
use crate::measurement::{AxisKind, ByKind};
use crate::measurement::{Direction, Measurement};
use crate::report::chart::{Chart, Mark, Polar, Rgb, Series};
use crate::units::{AngleUnit, DeviationUnit, Mm, Um, mm_to_um};

/// One test (the first, or the re-test) as the report shows it.
#[derive(Clone, Copy, Debug)]
pub struct TestRecord<'a> {
    /// The measurement as read.
    pub measurement: &'a Measurement,
    /// Its ISO 230-2 evaluation (`evaluate::evaluate` of it).
    pub evaluation: &'a Evaluation,
    /// Reader and evaluator warnings.
    pub warnings: &'a [Warning],
    /// Its measurement uncertainty (`evaluate::uncertainty::budget`); `None`: not evaluated.
    pub budget: Option<&'a crate::evaluate::uncertainty::Budget>,
}

/// The compensation table active in the re-test, as read from its file.
#[derive(Clone, Copy, Debug)]
pub struct TableRecord<'a> {
    /// The table, in axcomp's convention (axis error, zero at the reference).
    pub table: &'a CompensationTable,
    /// The file it was read from, as the report names it.
    pub file: &'a str,
    /// The controller format the file is in.
    pub controller: Controller,
}

/// Everything the report is made from.
#[derive(Clone, Copy, Debug)]
pub struct ReportInput<'a> {
    /// The test being reported (the first test when there is a re-test).
    pub before: TestRecord<'a>,
    /// The re-test, for the before/after comparison.
    pub after: Option<TestRecord<'a>>,
    /// The table, for its plot and the predicted re-test.
    pub table: Option<TableRecord<'a>>,
    /// The predicted re-test of the first test with the table (the
    /// workflow's, `workflow::report`); drawn and tabled with the table.
    pub prediction: Option<&'a Prediction>,
    /// The diagnosis of the re-test (`before` = the first test, `after` = the re-test).
    pub diagnosis: Option<&'a Diagnosis>,
    /// The acceptance limits for the verdict box (`report::verdict`);
    /// empty: no limits, no verdict.
    pub limits: &'a [crate::evaluate::verdict::Limit],
    /// The decision rule of the verdict (`--decision`).
    pub decision: crate::evaluate::verdict::Decision,
    /// The standard the tests were evaluated to (`--standard`), whose
    /// figures the predicted re-test reports too.
    pub standard: &'a dyn Standard,
    /// The unit of a rotary axis' deviations (`--angle-unit`; unused on a linear axis).
    pub angle: AngleUnit,
    /// What made the report, e.g. `axcomp 0.1.0 on 2026-11-22 15:04`
    /// (the library reads no clock: the caller says when).
    pub generator: &'a str,
}

/// A chart with the name its PNG file gets (`deviation` → `deviation.png`).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedChart {
    /// File stem and HTML id.
    pub name: &'static str,
    /// The chart.
    pub chart: Chart,
}

/// What a re-test with the table should read, sampled along the axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// Positions, mm.
    pub positions_mm: Vec<f64>,
    /// Predicted deviation moving ↑, µm.
    pub up_um: Vec<f64>,
    /// Predicted deviation moving ↓, µm.
    pub down_um: Vec<f64>,
    /// The first test's mean deviation there (what the axis does without the table), µm.
    pub uncompensated_um: Vec<f64>,
    /// The predicted re-test's figures under the report's standard, as
    /// `predict` gives them on the measured line (the first test's scatter
    /// about the predicted means).
    pub figures: Vec<StandardFigure>,
}

impl Prediction {
    /// Largest minus smallest predicted deviation, both directions, µm.
    pub fn range_um(&self) -> f64 {
        let all = self.up_um.iter().chain(&self.down_um);
        let high = all.clone().fold(f64::NEG_INFINITY, |m, v| m.max(*v));
        let low = all.fold(f64::INFINITY, |m, v| m.min(*v));
        high - low
    }

    /// The same for the uncompensated axis, µm.
    pub fn uncompensated_range_um(&self) -> f64 {
        let values = &self.uncompensated_um;
        let high = values.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v));
        let low = values.iter().fold(f64::INFINITY, |m, v| m.min(*v));
        high - low
    }
}

/// Colours: ↑ blue, ↓ orange (distinguishable in greyscale print by the
/// marker shape, ▲ and ▼, too).
const UP: Rgb = Rgb(31, 95, 170);
const UP_LIGHT: Rgb = Rgb(160, 188, 225);
const DOWN: Rgb = Rgb(200, 82, 0);
const DOWN_LIGHT: Rgb = Rgb(238, 190, 150);
const BLACK: Rgb = Rgb(30, 30, 30);
const GREY: Rgb = Rgb(130, 130, 130);
const MODEL: Rgb = Rgb(120, 40, 140);
const ALERT: Rgb = Rgb(200, 20, 20);
/// Colours of the fitted effects, in the order they are listed.
const EFFECT_COLOURS: [Rgb; 6] = [
    Rgb(31, 95, 170),
    Rgb(200, 82, 0),
    Rgb(40, 140, 60),
    Rgb(120, 40, 140),
    Rgb(160, 120, 0),
    Rgb(0, 140, 150),
];

const POSITION_LABEL: &str = "target position [mm]";
const DEVIATION_LABEL: &str = "positional deviation [µm]";
/// The same on a rotary axis, whose targets are in °.
const ANGLE_LABEL: &str = "target position [°]";

/// How a test's deviations are drawn: in µm (the `_mm` fields), or in
/// `angle` (″, µrad) on a rotary axis (the same fields hold °).
fn shown(test: &TestRecord<'_>, angle: AngleUnit) -> DeviationUnit {
    test.measurement.kind().deviation_unit(angle)
}

/// The deviation axis' label, in the unit drawn.
fn deviation_label(shown: DeviationUnit) -> String {
    match shown {
        DeviationUnit::Micrometre => DEVIATION_LABEL.into(),
        angle => format!("positional deviation [{}]", angle.symbol()),
    }
}

/// All charts of the report, in the order the HTML shows them.
pub fn charts(input: &ReportInput<'_>) -> Vec<NamedChart> {
    let mut charts = Vec::new();
    let angle = input.angle;
    let mut before = deviation_chart(&input.before, "first test", angle);
    match &input.after {
        None => {
            before.title = format!("Positional deviation{}", axis_suffix(&input.before));
            charts.push(NamedChart {
                name: "deviation",
                chart: before,
            });
            if let Some(polar) = polar_chart(&input.before, "", None, angle) {
                charts.push(NamedChart {
                    name: "polar",
                    chart: polar,
                });
            }
        }
        Some(after_record) => {
            let mut after = deviation_chart(after_record, "re-test", angle);
            // One scale for both, so the eye compares them truly.
            let range = [before.y_extent(), after.y_extent()]
                .into_iter()
                .flatten()
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
                .map(|range| pad(range, 0.06));
            before.y_range = range;
            after.y_range = range;
            charts.push(NamedChart {
                name: "deviation-before",
                chart: before,
            });
            charts.push(NamedChart {
                name: "deviation-after",
                chart: after,
            });
            // A rotary axis' polar plots, on one scale too.
            let largest = [&input.before, after_record]
                .into_iter()
                .filter_map(|test| largest_mean(test, angle))
                .reduce(f64::max);
            for (test, name, which) in [
                (&input.before, "polar-before", ", first test"),
                (after_record, "polar-after", ", re-test"),
            ] {
                if let Some(polar) = polar_chart(test, which, largest, angle) {
                    charts.push(NamedChart { name, chart: polar });
                }
            }
        }
    }
    if let Some(table) = &input.table {
        charts.push(NamedChart {
            name: "table",
            chart: table_chart(table.table, input.before.evaluation),
        });
        if let Some(prediction) = input.prediction {
            charts.push(NamedChart {
                name: "predicted",
                chart: prediction_chart(prediction, input.after.map(|a| a.evaluation)),
            });
        }
    }
    if let (Some(diagnosis), Some(after)) = (input.diagnosis, &input.after) {
        charts.extend(diagnosis_charts(diagnosis, after.measurement));
    }
    charts
}

/// The diagnosis' charts, in mm and µm: a linear axis' only. A rotary
/// axis' diagnosis has none (`workflow::rotary` refuses `report --diagnose`
/// on a rotary axis; given one anyway, no chart is drawn in the wrong unit).
fn diagnosis_charts(diagnosis: &Diagnosis, after: &Measurement) -> Vec<NamedChart> {
    let ByKind::Linear(typed) = diagnosis.typed() else {
        return Vec::new();
    };
    let mut charts = vec![
        NamedChart {
            name: "residual",
            chart: residual_chart(&typed),
        },
        NamedChart {
            name: "residual-along-axis",
            chart: residual_along_axis_chart(&typed),
        },
    ];
    if !diagnosis.accepted.is_empty() {
        charts.push(NamedChart {
            name: "effects",
            chart: effects_chart(diagnosis, &typed, after),
        });
    }
    charts
}

/// A linear axis' diagnosis: positions in mm, deviations in µm.
type LinearDiagnosis = DiagnosisIn<Mm, Um>;

/// ` of axis X` when the axis name is plain ASCII (plots draw only the
/// characters of the embedded font; file text is shown in the HTML).
fn axis_suffix(test: &TestRecord<'_>) -> String {
    let axis = test.measurement.axis();
    let plain = test.measurement.axis_recorded()
        && !axis.is_empty()
        && axis.len() <= 12
        && axis
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if plain {
        format!(", axis {axis}")
    } else {
        String::new()
    }
}

fn pad((low, high): (f64, f64), fraction: f64) -> (f64, f64) {
    let span = (high - low).max(1e-9);
    (low - span * fraction, high + span * fraction)
}

fn series(label: Option<String>, color: Rgb, mark: Mark, points: Vec<(f64, f64)>) -> Series {
    Series {
        label,
        color,
        mark,
        points,
    }
}

/// Every run (▲ moving ↑, ▼ moving ↓, a thin line joining each run's
/// readings), the means per direction, the bidirectional mean and the
/// x̄ ± 2s band of each direction.
fn deviation_chart(test: &TestRecord<'_>, which: &str, angle: AngleUnit) -> Chart {
    let measurement = test.measurement;
    let targets = measurement.targets();
    let per_target = &test.evaluation.per_target;
    let shown = shown(test, angle);
    let mut all = Vec::new();
    for (direction, color) in [(Direction::Up, UP), (Direction::Down, DOWN)] {
        let (lower, upper): (Vec<(f64, f64)>, Vec<f64>) = per_target
            .iter()
            .filter_map(|t| band(t.target, t.direction(direction), shown))
            .map(|(x, low, high)| ((x, low), high))
            .unzip();
        if !lower.is_empty() {
            all.push(series(
                Some(format!("mean {direction} ± 2s")),
                color,
                Mark::Band { upper },
                lower,
            ));
        }
    }
    let mut lines = Vec::new();
    let mut markers = Vec::new();
    for direction in Direction::BOTH {
        let (color, light, mark) = match direction {
            Direction::Up => (UP, UP_LIGHT, Mark::Up),
            Direction::Down => (DOWN, DOWN_LIGHT, Mark::Down),
        };
        let count = measurement.run_count(direction);
        for (index, run) in measurement.runs_in(direction).enumerate() {
            let points: Vec<(f64, f64)> = targets
                .iter()
                .zip(&run.deviations)
                .filter_map(|(x, value)| value.map(|v| (*x, shown.from_internal(v))))
                .collect();
            lines.push(series(None, light, Mark::Line(1), points.clone()));
            let runs = if count == 1 { "run" } else { "runs" };
            let label = (index == 0).then(|| format!("{count} {runs} {direction}"));
            markers.push(series(label, color, mark.clone(), points));
        }
    }
    all.extend(lines);
    all.extend(markers);
    all.extend(mean_lines(per_target, shown));
    Chart {
        title: format!("Positional deviation, {which}{}", axis_suffix(test)),
        x_label: match test.measurement.kind() {
            AxisKind::Linear => POSITION_LABEL,
            AxisKind::Rotary => ANGLE_LABEL,
        }
        .into(),
        y_label: deviation_label(shown),
        series: all,
        y_range: None,
        polar: None,
    }
}

/// The mean lines of a test: x̄↑ and x̄↓ (solid, in their colours) and the
/// bidirectional mean x̄ (dashed), converted by `shown`; the deviation plot
/// and the polar plot draw the same three.
fn mean_lines(per_target: &[TargetStats], shown: DeviationUnit) -> Vec<Series> {
    let mut lines = Vec::new();
    for (direction, color) in [(Direction::Up, UP), (Direction::Down, DOWN)] {
        let means = means_in(per_target, direction, shown);
        if !means.is_empty() {
            lines.push(series(
                Some(format!("mean {direction}")),
                color,
                Mark::Line(2),
                means,
            ));
        }
    }
    let bidirectional: Vec<(f64, f64)> = per_target
        .iter()
        .filter_map(|t| t.mean.map(|m| (t.target, shown.from_internal(m))))
        .collect();
    if !bidirectional.is_empty() {
        lines.push(series(
            Some("bidirectional mean".into()),
            BLACK,
            Mark::Dashed(2),
            bidirectional,
        ));
    }
    lines
}

/// (target, x̄) for one direction, where the mean is defined, the mean
/// converted by `shown` (to µm, or ″ or µrad).
fn means_in(
    per_target: &[TargetStats],
    direction: Direction,
    shown: DeviationUnit,
) -> Vec<(f64, f64)> {
    per_target
        .iter()
        .filter_map(|t| {
            let mean = t.direction(direction).mean?;
            Some((t.target, shown.from_internal(mean)))
        })
        .collect()
}

/// (target, x̄ − 2s, x̄ + 2s) converted by `shown`, where both are defined.
fn band(target_mm: f64, stats: &DirectionStats, shown: DeviationUnit) -> Option<(f64, f64, f64)> {
    let (low, high) = stats.band(crate::evaluate::ISO_230_2.k)?;
    Some((
        target_mm,
        shown.from_internal(low),
        shown.from_internal(high),
    ))
}

/// The largest |x̄↑|, |x̄↓|, |x̄| of a rotary test, in `angle`; `None` for a linear one.
fn largest_mean(test: &TestRecord<'_>, angle: AngleUnit) -> Option<f64> {
    if test.measurement.kind() != AxisKind::Rotary {
        return None;
    }
    let per_target = &test.evaluation.per_target;
    per_target
        .iter()
        .flat_map(|t| [t.up.mean, t.down.mean, t.mean])
        .flatten()
        .map(|mean| angle.from_deg(mean).abs())
        .reduce(f64::max)
}

/// A rotary test's polar plot: x̄↑, x̄↓ and x̄ around the circle, each a
/// radial offset in `angle` (″, µrad) from the reference circle ([`Polar`],
/// scaled to `largest` or the test's own largest mean); `None` for a linear axis.
fn polar_chart(
    test: &TestRecord<'_>,
    which: &str,
    largest: Option<f64>,
    angle: AngleUnit,
) -> Option<Chart> {
    let largest = largest.or_else(|| largest_mean(test, angle))?;
    let shown = DeviationUnit::Angle(angle);
    let all = mean_lines(&test.evaluation.per_target, shown);
    Some(Chart {
        title: format!(
            "Mean deviation around the circle{which}{}",
            axis_suffix(test)
        ),
        x_label: ANGLE_LABEL.into(),
        y_label: deviation_label(shown),
        series: all,
        y_range: None,
        polar: Some(Polar::fitting(largest, shown.suffix())),
    })
}

/// The table as the controller applies it (linear between points, the end
/// values held to the measured span) with its points, and the first test's
/// mean shifted to zero at the reference (what the table should follow).
fn table_chart(table: &CompensationTable, before: &Evaluation) -> Chart {
    let mut all = Vec::new();
    let first_target = before.per_target.first().map(|t| t.target);
    let last_target = before.per_target.last().map(|t| t.target);
    if let Some(known) = KnownError::from_evaluation(before) {
        let at_reference = known.mean_at(table.reference);
        let points = known
            .positions()
            .iter()
            .zip(known.mean_values())
            .map(|(x, v)| (*x, mm_to_um(v - at_reference)))
            .collect();
        all.push(series(
            Some(format!(
                "first test's mean, zero at {} mm",
                crate::report::chart::tick_label(table.reference)
            )),
            GREY,
            Mark::Dashed(2),
            points,
        ));
    }
    let directions: &[(Direction, Rgb, &str)] = match table.values.mode() {
        crate::compensate::TableMode::Mean => &[(Direction::Up, BLACK, "table")],
        crate::compensate::TableMode::Bidirectional => &[
            (Direction::Up, UP, "table ↑"),
            (Direction::Down, DOWN, "table ↓"),
        ],
    };
    for (direction, color, label) in directions {
        let values = table.values.for_direction(*direction);
        let mut line: Vec<(f64, f64)> = table
            .positions
            .iter()
            .zip(values)
            .map(|(x, v)| (*x, mm_to_um(*v)))
            .collect();
        // Held outside the table, as controllers do, over the measured span.
        if let (Some(first), Some(&(x0, y0))) = (first_target, line.first())
            && first < x0
        {
            line.insert(0, (first, y0));
        }
        if let (Some(last), Some(&(x1, y1))) = (last_target, line.last())
            && last > x1
        {
            line.push((last, y1));
        }
        all.push(series(Some(label.to_string()), *color, Mark::Line(2), line));
        let points = table
            .positions
            .iter()
            .zip(values)
            .map(|(x, v)| (*x, mm_to_um(*v)))
            .collect();
        all.push(series(None, *color, Mark::Dot, points));
    }
    Chart {
        title: format!(
            "Compensation table, axis {}: {} points",
            plain_or_blank(&table.axis),
            table.positions.len()
        ),
        x_label: "position [mm]".into(),
        y_label: "axis error the table compensates [µm]".into(),
        series: all,
        y_range: None,
        polar: None,
    }
}

fn plain_or_blank(axis: &str) -> &str {
    if axis.chars().all(|c| c.is_ascii_alphanumeric()) {
        axis
    } else {
        "?"
    }
}

/// The predicted re-test, the uncompensated axis for comparison, and the
/// re-test's measured means when there is one.
fn prediction_chart(prediction: &Prediction, after: Option<&Evaluation>) -> Chart {
    let along = |values: &[f64]| -> Vec<(f64, f64)> {
        prediction
            .positions_mm
            .iter()
            .copied()
            .zip(values.iter().copied())
            .collect()
    };
    let mut all = vec![series(
        Some("without the table (first test's mean)".into()),
        GREY,
        Mark::Dashed(2),
        along(&prediction.uncompensated_um),
    )];
    // Both directions whenever they differ: a mean table leaves the reversal
    // the first test measured, and one line would show ↓ as mispredicted.
    let directional = prediction
        .up_um
        .iter()
        .zip(&prediction.down_um)
        .any(|(up, down)| up != down);
    if directional {
        all.push(series(
            Some("predicted re-test ↑".into()),
            UP,
            Mark::Line(2),
            along(&prediction.up_um),
        ));
        all.push(series(
            Some("predicted re-test ↓".into()),
            DOWN,
            Mark::Line(2),
            along(&prediction.down_um),
        ));
    } else {
        all.push(series(
            Some("predicted re-test".into()),
            MODEL,
            Mark::Line(2),
            along(&prediction.up_um),
        ));
    }
    if let Some(after) = after {
        for (direction, mark) in [(Direction::Up, Mark::Up), (Direction::Down, Mark::Down)] {
            let color = if direction == Direction::Up { UP } else { DOWN };
            let means = means_in(&after.per_target, direction, DeviationUnit::Micrometre);
            if !means.is_empty() {
                all.push(series(
                    Some(format!("re-test mean {direction}, measured")),
                    color,
                    mark,
                    means,
                ));
            }
        }
    }
    Chart {
        title: "Predicted re-test with the table applied".into(),
        x_label: POSITION_LABEL.into(),
        y_label: DEVIATION_LABEL.into(),
        series: all,
        y_range: None,
        polar: None,
    }
}

/// The residual of every reading (measured − predicted) in the order
/// measured, and the fitted model through them.
fn residual_chart(diagnosis: &LinearDiagnosis) -> Chart {
    let ordered = in_measured_order(diagnosis);
    let numbered = ordered
        .iter()
        .enumerate()
        .map(|(i, r)| ((i + 1) as f64, *r));
    let by_direction = |direction: Direction| -> Vec<(f64, f64)> {
        numbered
            .clone()
            .filter(|(_, r)| r.reading.direction == direction)
            .map(|(x, r)| (x, r.residual.0))
            .collect()
    };
    let count = diagnosis.readings.len() as f64;
    Chart {
        title: "Residual of each reading of the re-test".into(),
        x_label: "reading, in the order measured".into(),
        y_label: "measured − predicted [µm]".into(),
        series: vec![
            series(None, GREY, Mark::Line(1), vec![(1.0, 0.0), (count, 0.0)]),
            series(
                Some("fitted model".into()),
                MODEL,
                Mark::Line(2),
                numbered.clone().map(|(x, r)| (x, r.fitted.0)).collect(),
            ),
            series(
                Some("residual ↑".into()),
                UP,
                Mark::Up,
                by_direction(Direction::Up),
            ),
            series(
                Some("residual ↓".into()),
                DOWN,
                Mark::Down,
                by_direction(Direction::Down),
            ),
        ],
        y_range: None,
        polar: None,
    }
}

/// The readings in the order measured: by run, then by time within the run
/// (a run moving ↓ visits the targets from the last to the first).
fn in_measured_order(diagnosis: &LinearDiagnosis) -> Vec<&ReadingResidual<Um>> {
    let mut ordered: Vec<&ReadingResidual<Um>> = diagnosis.readings.iter().collect();
    ordered.sort_by(|a, b| {
        (a.reading.run_index, a.reading.time_h)
            .partial_cmp(&(b.reading.run_index, b.reading.time_h))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    ordered
}

/// The residual along the axis: every reading, the fitted model per
/// direction, and the targets where structure is left unexplained.
fn residual_along_axis_chart(diagnosis: &LinearDiagnosis) -> Chart {
    let mut all = Vec::new();
    for (direction, color, mark) in [
        (Direction::Up, UP, Mark::Up),
        (Direction::Down, DOWN, Mark::Down),
    ] {
        let points: Vec<(f64, f64)> = diagnosis
            .readings
            .iter()
            .filter(|r| r.reading.direction == direction)
            .map(|r| (r.reading.target, r.residual.0))
            .collect();
        all.push(series(
            Some(format!("residual {direction}")),
            color,
            mark,
            points,
        ));
    }
    for (direction, color) in [(Direction::Up, UP), (Direction::Down, DOWN)] {
        let fitted = mean_per_target(diagnosis, direction, |r| r.fitted.0);
        if !fitted.is_empty() {
            all.push(series(
                Some(format!("fitted model {direction} (mean per target)")),
                color,
                Mark::Line(2),
                fitted,
            ));
        }
    }
    if diagnosis.unexplained.significant && !diagnosis.unexplained.targets.is_empty() {
        let (low, _) = extent(diagnosis.readings.iter().map(|r| r.residual.0));
        let marks = diagnosis
            .unexplained
            .targets
            .iter()
            .map(|&Mm(x)| (x, low))
            .collect();
        all.push(series(
            Some("unexplained structure".into()),
            ALERT,
            Mark::Dot,
            marks,
        ));
    }
    Chart {
        title: "Residual along the axis".into(),
        x_label: POSITION_LABEL.into(),
        y_label: "measured − predicted [µm]".into(),
        series: all,
        y_range: None,
        polar: None,
    }
}

/// Mean over the readings of each target in one direction, (target, value).
fn mean_per_target(
    diagnosis: &LinearDiagnosis,
    direction: Direction,
    value: impl Fn(&ReadingResidual<Um>) -> f64,
) -> Vec<(f64, f64)> {
    let mut sums: Vec<(f64, f64, usize)> = Vec::new();
    for r in diagnosis
        .readings
        .iter()
        .filter(|r| r.reading.direction == direction)
    {
        match sums.iter_mut().find(|(x, _, _)| *x == r.reading.target) {
            Some(entry) => {
                entry.1 += value(r);
                entry.2 += 1;
            }
            None => sums.push((r.reading.target, value(r), 1)),
        }
    }
    sums.sort_by(|a, b| a.0.total_cmp(&b.0));
    sums.into_iter()
        .map(|(x, sum, n)| (x, sum / n as f64))
        .collect()
}

fn extent(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((0.0, 0.0), |(low, high), v| (low.min(v), high.max(v)))
}

/// Each accepted effect's contribution to every reading (µm: a linear
/// axis' effects), in the order measured.
fn effects_chart(diagnosis: &Diagnosis, typed: &LinearDiagnosis, after: &Measurement) -> Chart {
    let first_target_mm = after.targets().first().copied().unwrap_or(0.0);
    let mut all = Vec::new();
    for (index, accepted) in diagnosis.accepted.iter().enumerate() {
        // The Abbe effect needs the angular profile, which the report is not
        // given: its contribution is drawn as 0 (the report never has one).
        let points = in_measured_order(typed)
            .into_iter()
            .enumerate()
            .map(|(i, r)| {
                (
                    (i + 1) as f64,
                    accepted.effect.value(
                        &r.reading,
                        &Line {
                            first_target_mm,
                            angle_urad: None,
                            times_recorded: !diagnosis.time_assumed,
                            run_h: diagnosis.run_h,
                        },
                    ),
                )
            })
            .collect();
        all.push(series(
            Some(effect_label(&accepted.effect)),
            EFFECT_COLOURS[index % EFFECT_COLOURS.len()],
            Mark::Line(2),
            points,
        ));
    }
    Chart {
        title: "Effects found in the residual".into(),
        x_label: "reading, in the order measured".into(),
        y_label: "contribution [µm]".into(),
        series: all,
        y_range: None,
        polar: None,
    }
}

/// A short legend label with the fitted parameters of a linear axis' effect
/// (mm and µm), in the plot font's characters.
pub fn effect_label(effect: &Effect) -> String {
    let signed = |v: f64| crate::report::chart::tick_label((v * 100.0).round() / 100.0);
    let linear = Context {
        kind: AxisKind::Linear,
        ..Context::default()
    };
    effect.model().label(&linear, &signed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycle::CycleTiming;
    use crate::diagnose::{DiagnoseInput, diagnose};
    use crate::evaluate::ISO_230_2;
    use crate::read::read_path;

    /// A rotary diagnosis (° and m°) draws no chart in mm and µm; the same
    /// numbers said to be a linear axis' draw the residual, the residual
    /// along the axis and the effect found (its reversal).
    #[test]
    fn only_a_linear_diagnosis_is_charted() {
        let path = std::path::Path::new("tests/data/rotary/c-outlier-run.csv");
        let rotary = read_path(path, None).unwrap().measurement;
        let mut diagnosis = diagnose(&DiagnoseInput {
            after: &rotary,
            before: None,
            table: None,
            backlash_set: false,
            angular: None,
            known_periods: &[],
            timing: CycleTiming::ASSUMED,
            standard: &ISO_230_2,
            angle: AngleUnit::Arcsec,
        })
        .unwrap();
        assert_eq!(diagnosis.kind, AxisKind::Rotary);
        assert!(diagnosis_charts(&diagnosis, &rotary).is_empty());
        diagnosis.kind = AxisKind::Linear;
        let names: Vec<&str> = diagnosis_charts(&diagnosis, &rotary)
            .iter()
            .map(|chart| chart.name)
            .collect();
        assert_eq!(names, ["residual", "residual-along-axis", "effects"]);
    }
}
