//! What `convert --existing` says of the update: per range, what the new
//! table kept of the old one and what it changed (`compensate::update`).
//!
//! # Wire format (`"update"` in `convert --json`, null without `--existing`)
//!
//! ```text
//! { "kept_mm": [{"first": -4953.0, "last": -2286.0, "count": 22}, …],
//!   "measured_mm": [-2159.0, 0.0], "updated": 18, "reference_mm": 0.0,
//!   "reference": "existing zero" | "given",
//!   "dropped_mm": [...], "added_mm": [...], "lines": ["…", …],
//!   "kept_as": "values" | "increments" }
//! ```
//! Positions in mm; `lines` are the sentences the terminal prints, with
//! positions in the file's unit (inch files: inch and mm). A Fanuc pitch
//! file keeps the increments of the points outside (`"kept_as":
//! "increments"`): each kept run has `"moved": {"with": -1000.0, "by": [↑,
//! ↓]}` (the new table's point it continues from, and the change of its
//! values, in mm), and `"data_lines": {"sections": 25, "changed": 23}` says
//! how many of the file's lines the update wrote and how many differ. A
//! rotary axis' update has its positions in ° under `kept_deg`,
//! `measured_deg`, `reference_deg`, `dropped_deg` and `added_deg`.

use serde::Serialize;

use crate::compensate::update::{DataLines, KeptAs, KeptRange, Moved, UpdateSummary};
use crate::measurement::AxisKind;
use crate::report::format::inch_text;
use crate::units::{Deg, LengthUnit, Mm};

/// Old points kept as they were, one run, in `P` (mm, or ° on a rotary axis).
#[derive(Clone, Debug, Serialize)]
pub struct KeptJson<P> {
    /// First point.
    pub first: P,
    /// Last point.
    pub last: P,
    /// How many points.
    pub count: usize,
    /// Kept with their increments: how their values moved (Fanuc).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub moved: Option<MovedJson<P>>,
}

/// A kept run's values moved with the new table's point `with`, by `by`
/// (↑, ↓), in `P`.
#[derive(Clone, Debug, Serialize)]
pub struct MovedJson<P> {
    /// The new table's point the run continues from.
    pub with: P,
    /// new − old there, ↑ and ↓.
    pub by: [P; 2],
}

/// The lines of a file updated in place (Fanuc).
#[derive(Clone, Debug, Serialize)]
pub struct DataLinesJson {
    /// The data lines of the updated sections.
    pub sections: usize,
    /// Those that differ from the existing file's.
    pub changed: usize,
}

/// Declares the update's wire struct of one kind of axis: its positions
/// typed in the unit its keys name.
macro_rules! update_json {
    ($(#[$doc:meta])* $name:ident<$position:ty> {
        $kept:ident, $measured:ident, $reference:ident, $dropped:ident, $added:ident $(,)?
    }) => {
        $(#[$doc])*
        #[derive(Clone, Debug, Serialize)]
        pub struct $name {
            /// Old points outside the measured range, kept as they were, by runs.
            pub $kept: Vec<KeptJson<$position>>,
            /// The measured range.
            pub $measured: [$position; 2],
            /// Points inside it that got old + residual.
            pub updated: usize,
            /// Where the update adds nothing.
            pub $reference: $position,
            /// `existing zero` (the existing table's zero, the default) or `given` (`--reference`).
            pub reference: &'static str,
            /// Old points inside the measured range the new grid does not have.
            pub $dropped: Vec<$position>,
            /// New points the old table did not have.
            pub $added: Vec<$position>,
            /// What the terminal prints.
            pub lines: Vec<String>,
            /// What the kept points keep: `values`, or `increments` (Fanuc).
            pub kept_as: &'static str,
            /// A file updated line by line (Fanuc): its lines written and changed.
            #[serde(skip_serializing_if = "Option::is_none")]
            pub data_lines: Option<DataLinesJson>,
        }

        impl $name {
            /// The summary's positions typed by `unit`, with the sentences.
            fn of(
                summary: &UpdateSummary,
                unit: fn(f64) -> $position,
                lines: Vec<String>,
            ) -> $name {
                let all = |positions: &[f64]| positions.iter().map(|&p| unit(p)).collect();
                $name {
                    $kept: summary
                        .kept
                        .iter()
                        .map(|k| KeptJson {
                            first: unit(k.first),
                            last: unit(k.last),
                            count: k.count,
                            moved: k.moved.map(|m: Moved| MovedJson {
                                with: unit(m.with),
                                by: m.by.map(unit),
                            }),
                        })
                        .collect(),
                    $measured: [unit(summary.measured.0), unit(summary.measured.1)],
                    updated: summary.updated,
                    $reference: unit(summary.reference),
                    reference: if summary.at_existing_zero {
                        "existing zero"
                    } else {
                        "given"
                    },
                    $dropped: all(&summary.dropped),
                    $added: all(&summary.added),
                    lines,
                    kept_as: match summary.kept_as {
                        KeptAs::Values => "values",
                        KeptAs::Increments => "increments",
                    },
                    data_lines: summary.data_lines.map(|d: DataLines| DataLinesJson {
                        sections: d.sections,
                        changed: d.changed,
                    }),
                }
            }
        }
    };
}

update_json!(
    /// A linear axis' update: positions in mm.
    LinearUpdateJson<Mm> { kept_mm, measured_mm, reference_mm, dropped_mm, added_mm }
);

update_json!(
    /// A rotary axis' update: positions in °.
    RotaryUpdateJson<Deg> { kept_deg, measured_deg, reference_deg, dropped_deg, added_deg }
);

/// The update's positions in the unit of its axis, the keys naming it: a
/// rotary axis' in ° under `kept_deg`, `measured_deg`, `reference_deg`,
/// `dropped_deg`, `added_deg`.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum UpdateWireJson {
    /// In mm.
    Linear(LinearUpdateJson),
    /// In °.
    Rotary(RotaryUpdateJson),
}

/// The update, for `--json` and the terminal.
#[derive(Clone, Debug, Serialize)]
pub struct UpdateJson {
    /// What `--json` writes.
    #[serde(flatten)]
    pub wire: UpdateWireJson,
    /// Whether the new table is zero at the reference (the existing table is).
    #[serde(skip)]
    pub zero_at_reference: bool,
    /// Every kept point, in the axis' unit (for marking the printed table's rows).
    #[serde(skip)]
    pub kept_points: Vec<f64>,
    /// Every new point, in the axis' unit (for marking the printed table's rows).
    #[serde(skip)]
    pub added_points: Vec<f64>,
    /// What the printed table's marks mean (none where the kept points are not printed).
    #[serde(skip)]
    pub legend: &'static str,
}

impl UpdateJson {
    /// What a row of the printed table is: `kept` (the old value), `new`
    /// (a point the old table did not have) or nothing (old + residual).
    pub fn row_mark(&self, position: f64) -> &'static str {
        let among = |list: &[f64]| list.iter().any(|p| (p - position).abs() < 1e-6);
        if among(&self.kept_points) {
            "  kept"
        } else if among(&self.added_points) {
            "  new"
        } else {
            ""
        }
    }

    /// What the terminal prints.
    pub fn lines(&self) -> &[String] {
        match &self.wire {
            UpdateWireJson::Linear(update) => &update.lines,
            UpdateWireJson::Rotary(update) => &update.lines,
        }
    }
}

impl UpdateJson {
    /// From the summary; positions written in `file_unit` (`mm`, `inch` or
    /// `deg`) in the sentences, in mm or ° under keys naming them.
    pub fn new(summary: &UpdateSummary, file_unit: &str) -> UpdateJson {
        let lines = lines(summary, file_unit);
        let wire = match summary.kind {
            AxisKind::Linear => UpdateWireJson::Linear(LinearUpdateJson::of(summary, Mm, lines)),
            AxisKind::Rotary => UpdateWireJson::Rotary(RotaryUpdateJson::of(summary, Deg, lines)),
        };
        UpdateJson {
            wire,
            zero_at_reference: summary.existing_at_reference.abs() < 1e-12,
            kept_points: summary.kept_points.clone(),
            added_points: summary.added.clone(),
            // A Fanuc update prints the table's points only: none is kept.
            legend: match summary.kept_as {
                KeptAs::Values => {
                    "; kept: the old value, outside the measured range; new: a point the old table did not have"
                }
                KeptAs::Increments => "",
            },
        }
    }
}

/// A position or a range `a…b` in the file's unit (inch files: and mm).
fn range_text(first_mm: f64, last_mm: f64, file_unit: &str) -> String {
    let number = |value: f64| {
        let text = format!("{value:.4}");
        let text = text.trim_end_matches('0').trim_end_matches('.');
        if text == "-0" {
            "0".to_string()
        } else {
            text.to_string()
        }
    };
    let span = |f: &dyn Fn(f64) -> String| {
        if (last_mm - first_mm).abs() < 1e-9 {
            f(first_mm)
        } else {
            format!("{}…{}", f(first_mm), f(last_mm))
        }
    };
    match file_unit {
        "inch" => {
            let inch = |mm: f64| inch_text(LengthUnit::Inch.from_mm(mm));
            format!("{} in ({} mm)", span(&inch), span(&number))
        }
        "deg" => format!("{}°", span(&number)),
        _ => format!("{} mm", span(&number)),
    }
}

fn ranges_text(ranges: &[KeptRange], file_unit: &str) -> String {
    let parts: Vec<String> = ranges
        .iter()
        .map(|k| {
            let points = if k.count == 1 { "point" } else { "points" };
            format!(
                "{} ({} {points})",
                range_text(k.first, k.last, file_unit),
                k.count
            )
        })
        .collect();
    parts.join(" and ")
}

fn list_text(positions_mm: &[f64], file_unit: &str) -> String {
    let parts: Vec<String> = positions_mm
        .iter()
        .map(|p| range_text(*p, *p, file_unit))
        .collect();
    parts.join(", ")
}

/// The sentences: what was kept, what was updated and where it is referred,
/// how the grid changed.
fn lines(summary: &UpdateSummary, file_unit: &str) -> Vec<String> {
    let (first, last) = summary.measured;
    let measured = range_text(first, last, file_unit);
    let mut lines = Vec::new();
    if summary.kept_as == KeptAs::Increments {
        lines.extend(
            summary
                .kept
                .iter()
                .map(|run| kept_increments(run, summary.kind, &measured, file_unit)),
        );
    } else if !summary.kept.is_empty() {
        let kept: usize = summary.kept.iter().map(|k| k.count).sum();
        lines.push(format!(
            "{}: kept as {} (outside the measured {measured})",
            ranges_text(&summary.kept, file_unit),
            if kept == 1 { "it was" } else { "they were" }
        ));
    }
    let reference = range_text(summary.reference, summary.reference, file_unit);
    let why = if summary.at_existing_zero && summary.existing_at_reference.abs() < 1e-12 {
        "the existing table's zero".to_string()
    } else if summary.at_existing_zero {
        "the existing table's first point; it has no zero".to_string()
    } else {
        "--reference".to_string()
    };
    lines.push(format!(
        "{measured} ({} points): the existing table plus the measured residual, referred to {reference} ({why}), where the update adds nothing",
        summary.updated
    ));
    if let Some(DataLines { sections, changed }) = summary.data_lines {
        lines.push(format!(
            "pitch file: {changed} of the {sections} data lines of those points' sections changed (the others already held their new value); every other line of the file as it was"
        ));
    }
    if !summary.dropped.is_empty() {
        lines.push(format!(
            "grid changed: the old points at {} are not on the new grid (the new table follows the old one plus the residual between its points)",
            list_text(&summary.dropped, file_unit)
        ));
    }
    if !summary.added.is_empty() {
        lines.push(format!(
            "grid changed: new points at {} (the old table had none there)",
            list_text(&summary.added, file_unit)
        ));
    }
    lines
}

/// A run kept with its increments (Fanuc): where its values went.
fn kept_increments(run: &KeptRange, kind: AxisKind, measured: &str, file_unit: &str) -> String {
    let points = if run.count == 1 { "point" } else { "points" };
    let (its, they) = if run.count == 1 {
        ("its increment", "its value")
    } else {
        ("their increments", "their values")
    };
    let head = format!(
        "{} ({} {points}): kept {its}, not {they} (outside the measured {measured}; the file's data are increments per section)",
        range_text(run.first, run.last, file_unit),
        run.count
    );
    let Some(moved) = run.moved else {
        return head;
    };
    let (scale, unit) = match kind {
        AxisKind::Linear => (1000.0, "µm"),
        AxisKind::Rotary => (3600.0, "″"),
    };
    let value = |v: f64| {
        let v = (v * scale * 100.0).round() / 100.0 + 0.0;
        if v == 0.0 {
            format!("0 {unit}")
        } else {
            format!("{v:+} {unit}")
        }
    };
    let [up, down] = moved.by;
    let by = if (up - down).abs() * scale < 0.005 {
        value(up)
    } else {
        format!("{} ↑, {} ↓", value(up), value(down))
    };
    let at = range_text(moved.with, moved.with, file_unit);
    if up.abs() * scale < 0.005 && down.abs() * scale < 0.005 {
        let were = if run.count == 1 {
            "its value is as it was"
        } else {
            "their values are as they were"
        };
        return format!(
            "{head}: the old curve continues from the new value at {at}, which is the old one: {were}"
        );
    }
    format!("{head}: the old curve continues from the new value at {at}: {they} moved by {by}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_read_in_the_files_unit() {
        let summary = UpdateSummary {
            kept: vec![
                KeptRange {
                    first: -4953.0,
                    last: -2286.0,
                    count: 22,
                    moved: None,
                },
                KeptRange {
                    first: 127.0,
                    last: 127.0,
                    count: 1,
                    moved: None,
                },
            ],
            measured: (-2159.0, 0.0),
            updated: 18,
            reference: 0.0,
            existing_at_reference: 0.0,
            at_existing_zero: true,
            dropped: vec![],
            added: vec![3302.0],
            kept_points: vec![],
            kept_as: KeptAs::Values,
            data_lines: None,
            kind: AxisKind::Linear,
        };
        let lines = lines(&summary, "mm");
        assert_eq!(
            lines[0],
            "-4953…-2286 mm (22 points) and 127 mm (1 point): kept as they were (outside the measured -2159…0 mm)"
        );
        assert!(lines[1].contains("referred to 0 mm (the existing table's zero)"));
        assert_eq!(
            lines[2],
            "grid changed: new points at 3302 mm (the old table had none there)"
        );
        assert_eq!(range_text(-2159.0, 0.0, "inch"), "-85…0 in (-2159…0 mm)");
    }
}
