//! `conditions.html`: test conditions, the test against ISO 230-2, the
//! environment, and the refractive index check (`evaluate::environment`).

use super::{recorded, signed, signed_plus, tests_of};
use crate::evaluate::TestConformance;
use crate::evaluate::conformance::{Check, Requirement};
use crate::evaluate::environment::{AGREEMENT_PPM, IndexComparison, RefractiveIndexCheck};
use crate::measurement::{AxisKind, Direction, Measurement, StartEnd};
use crate::report::acceptance::{ReportInput, TestRecord};
use crate::report::format::inch_text;
use crate::units::LengthUnit;

/// `conditions.html`: one column pair (start, end) per test.
pub(super) struct Conditions {
    pub(super) test_names: Vec<&'static str>,
    pub(super) rows: Vec<Row>,
    pub(super) refractive_index: Vec<IndexView>,
}

/// A row of the conditions table.
pub(super) struct Row {
    pub(super) label: &'static str,
    pub(super) unit: &'static str,
    pub(super) cells: Vec<Cell>,
}

/// A cell of the conditions table.
pub(super) enum Cell {
    /// Text over `colspan` columns, `None`: not recorded.
    Text {
        colspan: usize,
        text: Option<String>,
    },
    /// What the test has for an ISO 230-2 requirement, and whether it meets it.
    Conformance { finding: String, met: Compliance },
    /// A number, over start and end when `wide`; `None`: not recorded.
    Number { wide: bool, value: Option<String> },
}

/// A requirement of ISO 230-2: met, a recommendation not followed, or not met.
pub(super) enum Compliance {
    Met,
    NotFollowed,
    NotMet,
}

/// The refractive index check of one test.
pub(super) struct IndexView {
    /// The test's name when the report has two.
    pub(super) heading: Option<&'static str>,
    pub(super) agreement_ppm: f64,
    pub(super) made: Vec<IndexRow>,
    pub(super) all_agree: bool,
    pub(super) wavelength_assumed: bool,
    pub(super) vacuum_wavelength_um: f64,
    /// (start or end, what the file does not record).
    pub(super) missing: Vec<(&'static str, String)>,
}

pub(super) struct IndexRow {
    pub(super) when: &'static str,
    pub(super) factor_um: String,
    pub(super) material_correction_ppm: Option<String>,
    pub(super) implied_n: String,
    pub(super) edlen_n: String,
    pub(super) difference_ppm_full: f64,
    pub(super) difference_ppm: String,
    pub(super) agrees: bool,
}

pub(super) fn conditions(input: &ReportInput<'_>) -> Conditions {
    let tests = tests_of(input);
    let mut rows = test_rows(&tests);
    rows.extend(conformance_rows(&tests));
    rows.extend(setup_rows(&tests));
    rows.extend(environment_rows(&tests));
    Conditions {
        test_names: tests.iter().map(|(name, _)| *name).collect(),
        rows,
        refractive_index: tests
            .iter()
            .map(|(name, test)| {
                let heading = if tests.len() > 1 { Some(*name) } else { None };
                refractive_index(heading, &test.evaluation.refractive_index)
            })
            .collect(),
    }
}

/// A row with one cell over start and end per test.
pub(super) fn wide_row(
    tests: &[(&str, &TestRecord<'_>)],
    label: &'static str,
    unit: &'static str,
    cell: &dyn Fn(&TestRecord<'_>) -> Cell,
) -> Row {
    Row {
        label,
        unit,
        cells: tests.iter().map(|(_, test)| cell(test)).collect(),
    }
}

/// Text over start and end.
pub(super) fn text(text: Option<String>) -> Cell {
    Cell::Text { colspan: 2, text }
}

/// The unit of the tests' positions: `mm`, or `°` on a rotary axis.
pub(super) fn position_unit(tests: &[(&str, &TestRecord<'_>)]) -> &'static str {
    match tests.first().map(|(_, t)| t.measurement.kind()) {
        Some(AxisKind::Rotary) => "°",
        _ => "mm",
    }
}

pub(super) fn test_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    vec![
        wide_row(tests, "Runs", "", &|t| {
            let m = t.measurement;
            text(Some(format!(
                "{}↑ {}↓",
                m.run_count(Direction::Up),
                m.run_count(Direction::Down)
            )))
        }),
        wide_row(tests, "Targets", position_unit(tests), &|t| {
            let targets = t.measurement.targets();
            text(Some(format!(
                "{} from {} to {}",
                targets.len(),
                targets.first().copied().unwrap_or_default(),
                targets.last().copied().unwrap_or_default()
            )))
        }),
        wide_row(tests, "Duration", "min", &|t| {
            text(
                t.measurement
                    .metadata
                    .duration_s()
                    .map(|s| format!("{:.0}", s / 60.0)),
            )
        }),
    ]
}

/// The instrument and set-up (`Metadata::setup`), in mm and, for an inch
/// file, in inches beside; "not recorded" where the file does not say.
pub(super) fn setup_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    let mut rows = instrument_rows(tests);
    if position_unit(tests) == "°" {
        // The angle reference a rotary laser test turns against (an indexer
        // such as Renishaw's XR20): no format axcomp reads records it yet.
        rows.insert(0, wide_row(tests, "Rotary reference", "", &|_| text(None)));
    }
    rows
}

pub(super) fn instrument_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    let nothing = tests.iter().all(|(_, t)| {
        t.measurement.metadata.setup.is_empty()
            && t.measurement.environment.vacuum_wavelength_um.is_none()
    });
    if nothing {
        return vec![Row {
            label: "Instrument, set-up",
            unit: "",
            cells: vec![Cell::Text {
                colspan: 2 * tests.len(),
                text: None,
            }],
        }];
    }
    let inch = |m: &Measurement, value_mm: f64| {
        if m.metadata.length_unit == LengthUnit::Inch {
            format!(" ({} in)", inch_text(LengthUnit::Inch.from_mm(value_mm)))
        } else {
            String::new()
        }
    };
    type Pick<'a> = &'a dyn Fn(&Measurement) -> Option<String>;
    let rows: [(&str, &str, Pick<'_>); 6] = [
        ("Instrument", "", &|m| {
            recorded(m.metadata.setup.instrument.as_deref())
        }),
        ("Instrument serial number", "", &|m| {
            recorded(m.metadata.setup.instrument_serial.as_deref())
        }),
        ("Laser wavelength (vacuum)", "µm", &|m| {
            m.environment
                .vacuum_wavelength_um
                .map(|w| format!("{w:.6}"))
        }),
        ("Feed", "mm/min", &|m| {
            m.metadata
                .setup
                .feed_mm_per_min
                .map(|f| format!("{f}{}", inch(m, f).replace(" in)", " in/min)")))
        }),
        ("Dwell", "s", &|m| {
            m.metadata.setup.dwell_s.map(|d| format!("{d}"))
        }),
        ("Measuring line: other axes at", "mm", &|m| {
            let axes = &m.metadata.setup.other_axes_mm;
            if axes.is_empty() {
                return None;
            }
            let list: Vec<String> = axes
                .iter()
                .map(|(axis, at)| format!("{axis} {at}{}", inch(m, *at)))
                .collect();
            Some(list.join(", "))
        }),
    ];
    rows.into_iter()
        .map(|(label, unit, pick)| wide_row(tests, label, unit, &|t| text(pick(t.measurement))))
        .collect()
}

/// The test against ISO 230-2 (`evaluate::conformance`): what the test has
/// and whether it meets each requirement, three rows of the conditions table.
pub(super) fn conformance_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    let met = |checks: &[Option<&Check>]| {
        if checks.iter().all(|c| c.is_some_and(|c| c.met)) {
            Compliance::Met
        } else if checks
            .iter()
            .all(|c| c.is_some_and(|c| c.requirement.is_recommendation()))
        {
            Compliance::NotFollowed
        } else {
            Compliance::NotMet
        }
    };
    type Judge<'a> = &'a dyn Fn(&TestConformance) -> Cell;
    let rows: [(&str, Judge<'_>); 3] = [
        ("Runs for ISO 230-2", &|c| {
            let runs = c.check(Requirement::Runs);
            let both = c.check(Requirement::BothDirections);
            let directions = if both.is_some_and(|b| b.met) {
                "both directions"
            } else {
                "one direction"
            };
            Cell::Conformance {
                finding: format!(
                    "{} per direction, {directions} (5 each way, 1 over {})",
                    runs.and_then(|r| r.found).unwrap_or_default(),
                    if c.kind() == AxisKind::Rotary {
                        "360°"
                    } else {
                        "2000 mm"
                    },
                ),
                met: met(&[runs, both]),
            }
        }),
        ("Targets for ISO 230-2", &|c| {
            let count = c.check(Requirement::Targets);
            let density = c.check(Requirement::TargetsPerMetre);
            let per_metre = density
                .and_then(|d| d.found)
                .map_or_else(String::new, |d| format!(", {d:.1} per metre"));
            // A rotary axis has no per-metre rule (evaluate::conformance).
            if c.kind() == AxisKind::Rotary {
                return Cell::Conformance {
                    finding: format!("{} (at least 5)", c.targets),
                    met: met(&[count]),
                };
            }
            Cell::Conformance {
                finding: format!("{}{per_metre} (at least 5, and 5 per metre)", c.targets),
                met: met(&[count, density]),
            }
        }),
        ("Spacing for ISO 230-2", &|c| {
            let spacing = c.check(Requirement::IrregularSpacing);
            Cell::Conformance {
                finding: spacing.and_then(|s| s.found).map_or_else(
                    || "irregular".to_string(),
                    |step| {
                        let unit = if c.kind() == AxisKind::Rotary {
                            "°"
                        } else {
                            " mm"
                        };
                        format!("constant step {}{unit}", signed(step, 3))
                    },
                ),
                met: met(&[spacing]),
            }
        }),
    ];
    // Nor a spacing rule: a rotary test's even steps are its principal angles.
    let rotary = tests
        .iter()
        .any(|(_, t)| t.evaluation.conformance.kind() == AxisKind::Rotary);
    rows.into_iter()
        .filter(|(label, _)| !(rotary && label.starts_with("Spacing")))
        .map(|(label, judge)| wide_row(tests, label, "", &|t| judge(&t.evaluation.conformance)))
        .collect()
}

pub(super) fn environment_rows(tests: &[(&str, &TestRecord<'_>)]) -> Vec<Row> {
    type Pick = fn(&Measurement) -> StartEnd;
    let rows: [(&str, &str, usize, Pick); 7] = [
        ("Air temperature", "°C", 3, |m| {
            m.environment.air_temperature_c
        }),
        ("Air pressure", "kPa", 3, |m| m.environment.air_pressure_kpa),
        ("Relative humidity", "%", 1, |m| {
            m.environment.air_humidity_pct
        }),
        ("Material temperature 1", "°C", 3, |m| {
            m.environment.material_temperature_c[0]
        }),
        ("Material temperature 2", "°C", 3, |m| {
            m.environment.material_temperature_c[1]
        }),
        ("Material temperature 3", "°C", 3, |m| {
            m.environment.material_temperature_c[2]
        }),
        ("Environmental factor", "µm", 8, |m| {
            m.environment.environmental_factor_um
        }),
    ];
    let number = |wide: bool, value: Option<f64>, decimals: usize| Cell::Number {
        wide,
        value: value.map(|v| signed(v, decimals)),
    };
    let mut shown = Vec::new();
    for (label, unit, decimals, pick) in rows {
        let recorded = tests.iter().any(|(_, t)| !pick(t.measurement).is_empty());
        if !recorded && label.starts_with("Material temperature ") && !label.ends_with('1') {
            continue;
        }
        let cells = tests
            .iter()
            .flat_map(|(_, test)| {
                let value = pick(test.measurement);
                [value.start, value.end].map(|v| number(false, v, decimals))
            })
            .collect();
        shown.push(Row { label, unit, cells });
    }
    shown.push(Row {
        label: "Expansion coefficient",
        unit: "µm/(m·K)",
        cells: tests
            .iter()
            .map(|(_, test)| {
                let value = test.measurement.environment.expansion_coefficient_ppm_per_k;
                number(true, value, 2)
            })
            .collect(),
    });
    shown
}

pub(super) fn refractive_index(
    heading: Option<&'static str>,
    check: &RefractiveIndexCheck,
) -> IndexView {
    let at = [("start", &check.start), ("end", &check.end)];
    let made: Vec<IndexRow> = at
        .iter()
        .filter_map(|(when, comparison)| match comparison {
            IndexComparison::Made(at) => Some(IndexRow {
                when,
                factor_um: format!("{:.8}", at.factor_um),
                material_correction_ppm: at.material_correction_ppm.map(|c| signed(c, 3)),
                implied_n: format!("{:.9}", at.implied_n),
                edlen_n: format!("{:.9}", at.edlen_n),
                difference_ppm_full: at.difference_ppm,
                difference_ppm: signed_plus(at.difference_ppm, 2),
                agrees: at.agrees(),
            }),
            IndexComparison::Missing(_) => None,
        })
        .collect();
    IndexView {
        heading,
        agreement_ppm: AGREEMENT_PPM,
        all_agree: made.iter().all(|row| row.agrees),
        made,
        wavelength_assumed: check.wavelength_assumed,
        vacuum_wavelength_um: check.vacuum_wavelength_um,
        missing: at
            .iter()
            .filter_map(|(when, comparison)| match comparison {
                IndexComparison::Missing(missing) => Some((*when, missing.join(", "))),
                IndexComparison::Made(_) => None,
            })
            .collect(),
    }
}
