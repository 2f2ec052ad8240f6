//! `figures.html`: the ISO 230-2 figures (side by side with the re-test's
//! when there is one), or another standard's beside them.

use super::tests_of;
use crate::evaluate::Standard;
use crate::evaluate::standard::{Vdi3441, vdi_figure_name};
use crate::evaluate::verdict::Figure;
use crate::measurement::{AxisKind, ByKind, Direction};
use crate::report::acceptance::{ReportInput, TestRecord};
use crate::report::format::{SourcedUm, inch_text, um};
use crate::report::json::source_notes;
use crate::report::json::{FiguresByUnit, FiguresJson, iso_keys};
use crate::units::{LengthUnit, mm_to_um, um_to_mm};

/// `figures.html`.
pub(super) struct Figures {
    /// With a re-test: both tests side by side, and the change.
    pub(super) compared: bool,
    pub(super) test_names: Vec<&'static str>,
    pub(super) rows: Vec<FigureRow>,
    /// (test name, its figures in inches) for an inch file.
    pub(super) inch: Vec<(&'static str, String)>,
    pub(super) source_notes: Vec<&'static str>,
    /// The ISO 230-2 figures' k (2; 3 for the ±3s editions) and 2k, for the note.
    pub(super) k: f64,
    pub(super) two_k: f64,
    /// A standard other than ISO 230-2 (VDI 3441): its name and its figures,
    /// one row each (symbol and name, a cell per test); empty for ISO 230-2.
    pub(super) standard_name: &'static str,
    pub(super) standard_rows: Vec<(String, Vec<Option<SourcedUm>>)>,
    /// Whether E, M and A show their U (a test has a budget).
    pub(super) with_u: bool,
}

/// A figure's row: per test bidirectional, ↑ and ↓ (`None`: the figure has
/// no directions).
pub(super) struct FigureRow {
    pub(super) symbol: &'static str,
    pub(super) name: &'static str,
    pub(super) cells: Vec<Option<SourcedUm>>,
    pub(super) change: Option<String>,
}

/// (symbol, name, figure); a figure with directions gets a column for each.
pub(super) const FIGURE_ROWS: [(&str, &str, Figure); 6] = [
    ("A", "accuracy of positioning", Figure::A),
    ("E", "systematic positional deviation", Figure::E),
    ("R", "repeatability of positioning", Figure::R),
    ("M", "mean bidirectional positional deviation", Figure::M),
    ("B", "reversal value", Figure::B),
    ("B̄", "mean reversal value", Figure::BMean),
];

/// A figure's value in the unit of the key that holds it (`figures_um`: µm;
/// `figures_arcsec` or `figures_urad` on a rotary axis).
pub(super) fn figure_value(figures: &FiguresJson, figure: Figure) -> Option<f64> {
    figures.get(figure.name())
}

pub(super) fn figures(input: &ReportInput<'_>) -> Figures {
    let tests = tests_of(input);
    let figures: Vec<FiguresJson> = tests
        .iter()
        .map(|(_, test)| {
            // A linear axis' ISO 230-2 figures (beside another standard's),
            // a rotary axis' standard's (ISO 230-2 only), each in its unit.
            let shown = match test.evaluation.figures_typed() {
                ByKind::Linear(iso) => ByKind::Linear(iso),
                ByKind::Rotary(_) => test.evaluation.standard_figures_typed(),
            };
            FiguresByUnit::of(&shown, input.angle).into_values()
        })
        .collect();
    let rows = FIGURE_ROWS
        .into_iter()
        .map(|(symbol, name, figure)| {
            let cells = figures
                .iter()
                .zip(&tests)
                .zip(["before", "after"])
                .flat_map(|((f, (_, test)), prefix)| {
                    // Where these figures are in the test's JSON: its
                    // `figures_um`, or beside another standard's.
                    let object = if test.measurement.kind() == AxisKind::Rotary {
                        format!("figures_{}", input.angle.name())
                    } else if iso_keys(&test.evaluation.standard_figures) {
                        "figures_um".to_string()
                    } else {
                        "figures_iso230_2_um".to_string()
                    };
                    // U beside the figures it is evaluated for (E, M, A).
                    let cell = |shown: Figure| {
                        SourcedUm::new(
                            format!("{prefix}.{object}.{}", shown.name()),
                            figure_value(f, shown),
                        )
                        .with_u(
                            test.budget
                                .and_then(|b| shown.expanded_uncertainty_mm(b))
                                .map(mm_to_um),
                        )
                    };
                    let directed = [Direction::Up, Direction::Down]
                        .map(|direction| figure.directed(direction).map(cell));
                    [Some(cell(figure)), directed[0].clone(), directed[1].clone()]
                })
                .collect();
            let change = match figures.as_slice() {
                [before, after] => Some(um(figure_value(before, figure)
                    .zip(figure_value(after, figure))
                    .map(|(b, a)| a - b))),
                _ => None,
            };
            FigureRow {
                symbol,
                name,
                cells,
                change,
            }
        })
        .collect();
    let standard = input.before.evaluation.standard;
    let standard_rows = if standard.key == Vdi3441.key() {
        // µm: another standard than ISO 230-2 is for linear axes only
        // (`workflow::rotary`); a rotary axis' would be left out, not shown as µm.
        let in_um: Vec<FiguresJson> = tests
            .iter()
            .map(|(_, test)| FiguresJson::of_linear(&test.evaluation.standard_figures_typed()))
            .collect();
        input
            .before
            .evaluation
            .standard_figures
            .iter()
            .map(|figure| {
                let cells = in_um
                    .iter()
                    .zip(["before", "after"])
                    .map(|(figures, prefix)| {
                        Some(SourcedUm::new(
                            format!("{prefix}.figures_um.{}", figure.key),
                            figures.get(figure.key),
                        ))
                    })
                    .collect();
                (
                    format!("{}  {}", figure.key, vdi_figure_name(figure.key)),
                    cells,
                )
            })
            .collect()
    } else {
        Vec::new()
    };
    Figures {
        k: standard.k,
        two_k: 2.0 * standard.k,
        standard_name: standard.name,
        standard_rows,
        with_u: tests.iter().any(|(_, test)| test.budget.is_some()),
        compared: figures.len() > 1,
        test_names: tests.iter().map(|(name, _)| *name).collect(),
        rows,
        inch: inch_figures(&tests),
        source_notes: source_notes(input.before.measurement.metadata.source_format).to_vec(),
    }
}

/// For an inch file, the bidirectional figures in inches too (the file's unit).
pub(super) fn inch_figures(
    tests: &[(&'static str, &TestRecord<'_>)],
) -> Vec<(&'static str, String)> {
    let mut notes = Vec::new();
    for (name, test) in tests {
        let iso = test.evaluation.figures_typed().linear();
        let (Some(iso), LengthUnit::Inch) = (iso, test.measurement.metadata.length_unit) else {
            continue;
        };
        let f = &FiguresJson::from_standard(&iso);
        let parts: Vec<String> = FIGURE_ROWS
            .iter()
            .flat_map(|&(symbol, _, figure)| {
                let directed = [(Direction::Up, "↑"), (Direction::Down, "↓")]
                    .into_iter()
                    .filter_map(move |(d, arrow)| Some((figure.directed(d)?, arrow)));
                let figures = std::iter::once((figure, "")).chain(directed);
                figures.filter_map(move |(shown, arrow)| {
                    let um = figure_value(f, shown)?;
                    Some(format!(
                        "{symbol}{arrow} {} in",
                        inch_text(LengthUnit::Inch.from_mm(um_to_mm(um)))
                    ))
                })
            })
            .collect();
        if !parts.is_empty() {
            notes.push((*name, parts.join(", ")));
        }
    }
    notes
}
