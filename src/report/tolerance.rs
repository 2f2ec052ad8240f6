//! The `--json` wire format and the terminal report of `axcomp tolerance`.
//!
//! # Wire format
//!
//! One object; keys may be added, never renamed or removed. Lengths carry
//! their unit in the key (µm for results, mm for inputs).
//!
//! The machine study:
//!
//! ```text
//! { "machine": "MCV 754 Quick", "chain": "ZFYX", "samples": 50000, "seed": 1,
//!   "batch_size": 256, "grid_step_mm": 50.0, "grid_points": [16, 11, 12],
//!   "tolerances": {"straightness_mm": {"X.lateral": 0.03, "X.normal": 0.03, …},
//!                  "positioning_mm": {"X": 0.0, "Y": 0.0, "Z": 0.0},
//!                  "squareness_um_per_m": {"XY": 0.0, "XZ": 0.0, "YZ": 0.0},
//!                  "carriage_mm": {"X.flatness": 0.0, "X.parallelism": 0.0, …}},
//!   "profile": {"period_mm": 100.0, "step_factor": 0.5, "band_width_factor": 1.0},
//!   "max_volumetric_um": {"mean": …, "median": …, "min": …, "max": …, "p90": …},
//!   "histogram": {"edges_um": [...], "counts": [...]},
//!   "sensitivity": [{"tolerance": "X.normal", "side": "rail", "values_mm": [0.005, …],
//!                    "p90_um": [...], "slope_um_per_mm": 1171.6, "rank": 2}, …] }
//! ```
//!
//! `carriage_mm` are the carriage-side tolerances of each axis's saddle
//! (`model::guideway::SaddleFaces`): `parallelism` of its carriage mounting
//! faces to its datum face, `flatness` of the four faces.
//! `sensitivity` is present only with `--sweep`: the six rail tolerances,
//! `"all"` (all six straightness tolerances scaled together, Valášek (2021) Tab.
//! 4.12), then the six carriage-side tolerances (`X.carriage_parallelism`,
//! `X.carriage_flatness`, …). `side` is `rail`, `carriage` or `all`; `rank`
//! orders the single tolerances of both sides by slope, 1 the largest
//! (`null` for `all` and for a row without a slope).
//! `normal` is Valášek's (2021) "vertical" straightness (normal to the rail
//! mounting face), `lateral` its "horizontal". `p90` is the 90th percentile
//! (linear interpolation, as NumPy's default). `slope_um_per_mm` is the
//! least-squares slope of `p90_um` over `values_mm` (`null` with fewer than
//! two distinct values).
//!
//! The single-axis study (`--single-axis`):
//!
//! ```text
//! { "samples": 50000, "seed": 1,
//!   "single_axis": {"stroke_mm": 1000.0, "rail_spacing_mm": 400.0, "carriage_pitch_mm": 500.0,
//!                   "tolerance_mm": 0.05, "step_mm": 5.0, "profile": {…},
//!                   "improvement_percent": {"normal": {"mean", "median", "min", "max", "p10"},
//!                                           "lateral": {…}}} }
//! ```
//!
//! `p10` of the improvement is what Valášek (2021) calls its "P90": 9 of 10
//! axes improve at least this much.

use std::collections::BTreeMap;
use std::fmt::Write;

use serde::Serialize;
use tabled::builder::Builder;
use tabled::settings::object::Columns;
use tabled::settings::{Alignment, Style};

use crate::model::monte_carlo::{
    AxisStudyOptions, AxisStudyResult, BATCH_SIZE, CarriageFace, RailDirection, Sensitivity, Side,
    StudyOptions, StudyResult,
};
use crate::model::stats::{Histogram, Summary};
use crate::model::{Axis, Grid, Machine, ProfileShape, SquarenessPair};
use crate::units::{mm_to_um, rad_to_um_per_m};

/// Bins of the histogram in the report and the plot.
pub const HISTOGRAM_BINS: usize = 30;

/// The whole `tolerance --json` object of the machine study.
#[derive(Clone, Debug, Serialize)]
pub struct ToleranceJson {
    /// The machine's name.
    pub machine: String,
    /// Its chain code.
    pub chain: String,
    /// Random machines drawn.
    pub samples: usize,
    /// Master seed.
    pub seed: u64,
    /// Samples per random stream (part of what a seed reproduces).
    pub batch_size: usize,
    /// Grid step over the work volume, mm.
    pub grid_step_mm: f64,
    /// Grid points along X, Y, Z.
    pub grid_points: [usize; 3],
    /// The tolerances that made the machines.
    pub tolerances: TolerancesJson,
    /// The profile generator's shape.
    pub profile: ProfileJson,
    /// Statistics of the largest volumetric error per machine, µm.
    pub max_volumetric_um: MaxVolumetricJson,
    /// Its histogram, µm.
    pub histogram: HistogramJson,
    /// With `--sweep`: the sensitivity table.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensitivity: Option<Vec<SensitivityJson>>,
}

/// Tolerances, keyed by surface (`X.normal`), axis (`X`) or pair (`XY`).
#[derive(Clone, Debug, Serialize)]
pub struct TolerancesJson {
    /// Straightness of each rail mounting surface, mm.
    pub straightness_mm: BTreeMap<String, f64>,
    /// Positioning tolerance per axis, mm.
    pub positioning_mm: BTreeMap<String, f64>,
    /// Largest squareness error per pair, µm/m.
    pub squareness_um_per_m: BTreeMap<String, f64>,
    /// Carriage-side tolerances per saddle (`X.parallelism`, `X.flatness`), mm.
    pub carriage_mm: BTreeMap<String, f64>,
}

/// The generator's shape.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ProfileJson {
    /// Distance between knots, mm.
    pub period_mm: f64,
    /// m of eq. 39.
    pub step_factor: f64,
    /// Band width over the tolerance.
    pub band_width_factor: f64,
}

/// Summary of the largest volumetric error, µm.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MaxVolumetricJson {
    /// Mean.
    pub mean: f64,
    /// Median.
    pub median: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
    /// 90th percentile.
    pub p90: f64,
}

/// Equal bins between the smallest and the largest value, µm.
#[derive(Clone, Debug, Serialize)]
pub struct HistogramJson {
    /// Bin edges (one more than counts), µm.
    pub edges_um: Vec<f64>,
    /// Machines per bin.
    pub counts: Vec<u64>,
}

/// One row of the sensitivity table.
#[derive(Clone, Debug, Serialize)]
pub struct SensitivityJson {
    /// `X.normal` … `Z.lateral`, `all`, or `X.carriage_parallelism` … `Z.carriage_flatness`.
    pub tolerance: String,
    /// `rail`, `carriage` or `all`.
    pub side: &'static str,
    /// The values it took, mm.
    pub values_mm: Vec<f64>,
    /// P90 of the largest volumetric error at each value, µm.
    pub p90_um: Vec<f64>,
    /// Least-squares slope, µm of P90 per mm of tolerance.
    pub slope_um_per_mm: Option<f64>,
    /// Place by slope among the single tolerances of both sides (1 = largest).
    pub rank: Option<usize>,
}

impl ToleranceJson {
    /// The report of a study (and its sweep, if one was run).
    pub fn new(
        machine: &Machine,
        grid: &Grid,
        options: &StudyOptions,
        result: &StudyResult,
        sensitivity: Option<&[Sensitivity]>,
    ) -> ToleranceJson {
        let in_um: Vec<f64> = result
            .max_volumetric_mm
            .iter()
            .map(|v| mm_to_um(*v))
            .collect();
        let summary = &result.summary;
        let tolerances = &options.tolerances;
        let mut straightness_mm = BTreeMap::new();
        let mut positioning_mm = BTreeMap::new();
        let mut carriage_mm = BTreeMap::new();
        for axis in Axis::ALL {
            for face in CarriageFace::BOTH {
                let key = format!("{axis}.{}", face.as_str());
                carriage_mm.insert(key, tolerances.carriage(axis, face));
            }
            for direction in RailDirection::BOTH {
                let key = format!("{axis}.{}", direction.as_str());
                straightness_mm.insert(key, tolerances.straightness(axis, direction));
            }
            positioning_mm.insert(axis.to_string(), tolerances.positioning_mm[axis.index()]);
        }
        let squareness_um_per_m = SquarenessPair::ALL
            .iter()
            .zip(tolerances.squareness_rad)
            .map(|(pair, value)| (format!("{pair:?}"), rad_to_um_per_m(value)))
            .collect();
        ToleranceJson {
            machine: machine.name().to_string(),
            chain: machine.chain().as_str().to_string(),
            samples: options.samples,
            seed: options.seed,
            batch_size: BATCH_SIZE,
            grid_step_mm: options.grid_step_mm,
            grid_points: grid.counts(),
            tolerances: TolerancesJson {
                straightness_mm,
                positioning_mm,
                squareness_um_per_m,
                carriage_mm,
            },
            profile: ProfileJson::from_shape(&options.shape),
            max_volumetric_um: MaxVolumetricJson {
                mean: mm_to_um(summary.mean),
                median: mm_to_um(summary.median),
                min: mm_to_um(summary.min),
                max: mm_to_um(summary.max),
                p90: mm_to_um(summary.p90),
            },
            histogram: HistogramJson::of(&in_um),
            sensitivity: sensitivity.map(SensitivityJson::ranked),
        }
    }
}

impl ProfileJson {
    fn from_shape(shape: &ProfileShape) -> ProfileJson {
        ProfileJson {
            period_mm: shape.period_mm,
            step_factor: shape.step_factor,
            band_width_factor: shape.band_width_factor,
        }
    }
}

impl HistogramJson {
    /// [`HISTOGRAM_BINS`] bins over values already in µm.
    pub fn of(values_um: &[f64]) -> HistogramJson {
        let histogram = Histogram::of(values_um, HISTOGRAM_BINS).unwrap_or(Histogram {
            edges: vec![0.0, 0.0],
            counts: vec![0],
        });
        HistogramJson {
            edges_um: histogram.edges,
            counts: histogram.counts,
        }
    }
}

impl SensitivityJson {
    /// The rows in sweep order, each single tolerance ranked by its slope
    /// as the report shows it (to 0.1 µm/mm): 1 the largest, equal slopes
    /// one rank (several tolerances that change nothing share the last).
    fn ranked(rows: &[Sensitivity]) -> Vec<SensitivityJson> {
        let shown = |row: &Sensitivity| -> Option<i64> {
            let slope = row.slope?;
            (row.tolerance.side() != Side::All).then(|| (mm_to_um(slope) * 10.0).round() as i64)
        };
        let ranked: Vec<i64> = rows.iter().filter_map(shown).collect();
        rows.iter()
            .map(|row| SensitivityJson {
                tolerance: row.tolerance.name(),
                side: row.tolerance.side().as_str(),
                values_mm: row.values_mm.clone(),
                p90_um: row.p90_mm.iter().map(|v| mm_to_um(*v)).collect(),
                slope_um_per_mm: row.slope.map(mm_to_um),
                rank: shown(row).map(|own| 1 + ranked.iter().filter(|s| **s > own).count()),
            })
            .collect()
    }
}

/// The whole `tolerance --single-axis --json` object.
#[derive(Clone, Debug, Serialize)]
pub struct AxisStudyJson {
    /// Random axes drawn.
    pub samples: usize,
    /// Master seed.
    pub seed: u64,
    /// The study.
    pub single_axis: SingleAxisJson,
}

/// Inputs and results of the single-axis study.
#[derive(Clone, Debug, Serialize)]
pub struct SingleAxisJson {
    /// Stroke, mm.
    pub stroke_mm: f64,
    /// a, mm.
    pub rail_spacing_mm: f64,
    /// b, mm.
    pub carriage_pitch_mm: f64,
    /// Straightness tolerance of the mounting surfaces, mm.
    pub tolerance_mm: f64,
    /// Evaluation step, mm.
    pub step_mm: f64,
    /// The generator's shape.
    pub profile: ProfileJson,
    /// Straightness improvement from mounting surface to axis, %.
    pub improvement_percent: ImprovementJson,
}

/// Improvement per direction, %.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ImprovementJson {
    /// Normal ("vertical").
    pub normal: ImprovementSummaryJson,
    /// Lateral ("horizontal").
    pub lateral: ImprovementSummaryJson,
}

/// Summary of an improvement, %.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ImprovementSummaryJson {
    /// Mean.
    pub mean: f64,
    /// Median.
    pub median: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
    /// 10th percentile (Valášek's (2021) "P90").
    pub p10: f64,
}

impl AxisStudyJson {
    /// The report of a single-axis study.
    pub fn new(options: &AxisStudyOptions, result: &AxisStudyResult) -> AxisStudyJson {
        AxisStudyJson {
            samples: options.samples,
            seed: options.seed,
            single_axis: SingleAxisJson {
                stroke_mm: options.stroke_mm,
                rail_spacing_mm: options.guideway.rail_spacing_mm,
                carriage_pitch_mm: options.guideway.carriage_pitch_mm,
                tolerance_mm: options.tolerance_mm,
                step_mm: options.step_mm,
                profile: ProfileJson::from_shape(&options.shape),
                improvement_percent: ImprovementJson {
                    normal: ImprovementSummaryJson::from_fractions(&result.summary_normal),
                    lateral: ImprovementSummaryJson::from_fractions(&result.summary_lateral),
                },
            },
        }
    }
}

impl ImprovementSummaryJson {
    fn from_fractions(summary: &Summary) -> ImprovementSummaryJson {
        let percent = |fraction: f64| 100.0 * fraction;
        ImprovementSummaryJson {
            mean: percent(summary.mean),
            median: percent(summary.median),
            min: percent(summary.min),
            max: percent(summary.max),
            p10: percent(summary.p10),
        }
    }
}

/// The terminal report of the machine study, from the JSON object.
pub fn tolerance_report(report: &ToleranceJson) -> String {
    let mut out = String::new();
    let t = &report.tolerances;
    let [nx, ny, nz] = report.grid_points;
    let _ = writeln!(out, "Machine      {} ({})", report.machine, report.chain);
    let _ = writeln!(
        out,
        "Samples      {} (seed {}), grid {} mm ({nx} × {ny} × {nz} points)",
        report.samples, report.seed, report.grid_step_mm
    );
    let _ = writeln!(
        out,
        "Straightness {}",
        describe(&t.straightness_mm, "mm", "all six rail mounting surfaces")
    );
    let _ = writeln!(
        out,
        "Positioning  {}",
        describe(&t.positioning_mm, "mm", "X, Y and Z")
    );
    let _ = writeln!(
        out,
        "Squareness   {}",
        describe(&t.squareness_um_per_m, "µm/m", "XY, XZ and YZ")
    );
    let faces = |face: CarriageFace| -> BTreeMap<String, f64> {
        t.carriage_mm
            .iter()
            .filter_map(|(key, value)| {
                let (axis, name) = key.split_once('.')?;
                (name == face.as_str()).then(|| (axis.to_string(), *value))
            })
            .collect()
    };
    let _ = writeln!(
        out,
        "Saddle faces parallelism {}; flatness {}",
        describe(
            &faces(CarriageFace::Parallelism),
            "mm",
            "the X, Y and Z saddles"
        ),
        describe(
            &faces(CarriageFace::Flatness),
            "mm",
            "the X, Y and Z saddles"
        )
    );
    let p = &report.profile;
    let band = if p.band_width_factor == 1.0 {
        "±tol/2".to_string()
    } else {
        format!("±{}·tol/2", p.band_width_factor)
    };
    let _ = writeln!(
        out,
        "Profiles     knots every ≤ {} mm, step factor {}, band {band}",
        p.period_mm, p.step_factor
    );
    let m = &report.max_volumetric_um;
    out.push_str("\nLargest volumetric error per machine [µm]\n");
    for (name, value) in [
        ("mean", m.mean),
        ("median", m.median),
        ("min", m.min),
        ("max", m.max),
        ("P90", m.p90),
    ] {
        let _ = writeln!(out, "  {name:<7}{value:>8.1}");
    }
    out.push_str("  (P90: 9 of 10 machines are at least this good)\n");
    out.push_str("\nHistogram [µm]\n");
    out.push_str(&text_histogram(&report.histogram, 40));
    if let Some(rows) = &report.sensitivity {
        out.push_str(
            "\nSensitivity of P90 [µm] to one tolerance (the others at their value); \
             rank by slope, rail and carriage side together\n",
        );
        out.push_str(&sensitivity_table(rows));
        out.push('\n');
    }
    out
}

/// `0.03 mm on all …` when all values are equal, `none` when all are 0,
/// else `key value, …` and the unit.
fn describe(values: &BTreeMap<String, f64>, unit: &str, all: &str) -> String {
    let mut distinct: Vec<f64> = values.values().copied().collect();
    distinct.dedup();
    match distinct[..] {
        [0.0] => "none".to_string(),
        [value] => format!("{value} {unit} on {all}"),
        _ => {
            let listed: Vec<String> = values.iter().map(|(k, v)| format!("{k} {v}")).collect();
            format!("{} {unit}", listed.join(", "))
        }
    }
}

/// A horizontal bar per bin, scaled so the fullest bin is `width` wide.
fn text_histogram(histogram: &HistogramJson, width: usize) -> String {
    let mut out = String::new();
    let fullest = histogram.counts.iter().copied().max().unwrap_or(0).max(1);
    for (index, count) in histogram.counts.iter().enumerate() {
        let (low, high) = (histogram.edges_um[index], histogram.edges_um[index + 1]);
        let eighths = (*count as f64 / fullest as f64 * (width * 8) as f64).round() as usize;
        let mut bar = "█".repeat(eighths / 8);
        if !eighths.is_multiple_of(8) {
            bar.push(['▏', '▎', '▍', '▌', '▋', '▊', '▉'][eighths % 8 - 1]);
        }
        let _ = writeln!(out, "  {low:>6.1} – {high:>6.1} │{bar:<width$} {count}");
    }
    out
}

fn sensitivity_table(rows: &[SensitivityJson]) -> String {
    let mut builder = Builder::default();
    let mut header = vec![
        "rank".to_string(),
        "tolerance".to_string(),
        "side".to_string(),
    ];
    if let Some(first) = rows.first() {
        header.extend(first.values_mm.iter().map(|v| format!("{v} mm")));
    }
    header.push("slope [µm/mm]".to_string());
    builder.push_record(header);
    // Read by rank, the first the most sensitive (the JSON keeps the sweep's
    // order); the unranked `all` row last, ties in the sweep's order.
    let mut by_rank: Vec<&SensitivityJson> = rows.iter().collect();
    by_rank.sort_by_key(|row| row.rank.unwrap_or(usize::MAX));
    for row in by_rank {
        let mut record = vec![
            row.rank.map_or(String::new(), |rank| rank.to_string()),
            row.tolerance.clone(),
            row.side.to_string(),
        ];
        record.extend(row.p90_um.iter().map(|v| format!("{v:.1}")));
        // A slope that rounds to zero is 0.0, not −0.0 (a rounding of 1e-13).
        record.push(row.slope_um_per_mm.map_or("—".to_string(), |s| {
            format!("{s:.1}").replace("-0.0", "0.0")
        }));
        builder.push_record(record);
    }
    let mut table = builder.build();
    table
        .with(Style::markdown())
        .modify(Columns::new(3..), Alignment::right())
        .modify(Columns::first(), Alignment::right());
    table.to_string()
}

/// The terminal report of the single-axis study.
pub fn axis_study_report(report: &AxisStudyJson) -> String {
    let s = &report.single_axis;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Single axis  stroke {} mm, rail spacing a {} mm, carriage pitch b {} mm",
        s.stroke_mm, s.rail_spacing_mm, s.carriage_pitch_mm
    );
    let _ = writeln!(
        out,
        "Samples      {} (seed {}), mounting-surface tolerance {} mm, evaluated every {} mm",
        report.samples, report.seed, s.tolerance_mm, s.step_mm
    );
    out.push_str("\nStraightness improvement, mounting surfaces → assembled axis [%]\n");
    out.push_str("  1 − p-p(axis) / max(p-p(rail 1), p-p(rail 2))\n");
    let mut builder = Builder::default();
    builder.push_record(["direction", "mean", "median", "min", "max", "P10"]);
    for (name, i) in [
        ("normal", &s.improvement_percent.normal),
        ("lateral", &s.improvement_percent.lateral),
    ] {
        builder.push_record(
            [name.to_string()]
                .into_iter()
                .chain([i.mean, i.median, i.min, i.max, i.p10].map(|v| format!("{v:.1}"))),
        );
    }
    let mut table = builder.build();
    table
        .with(Style::markdown())
        .modify(Columns::new(1..), Alignment::right());
    out.push_str(&table.to_string());
    out.push_str(
        "\n  (P10: 9 of 10 axes improve at least this much; Valášek 2021 calls it \"P90\")\n",
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_histogram_scales_to_the_fullest_bin() {
        let histogram = HistogramJson {
            edges_um: vec![0.0, 1.0, 2.0],
            counts: vec![4, 1],
        };
        let text = text_histogram(&histogram, 8);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "     0.0 –    1.0 │████████ 4");
        assert_eq!(lines[1], "     1.0 –    2.0 │██       1");
    }

    #[test]
    fn ranks_both_sides_by_slope_and_ties_share_a_rank() {
        use crate::model::monte_carlo::{CarriageFace, SweptTolerance};
        let row = |tolerance, slope: f64| Sensitivity {
            tolerance,
            values_mm: vec![0.01, 0.02],
            p90_mm: vec![0.08, 0.08 + 0.01 * slope],
            slope: Some(slope),
        };
        let rows = [
            row(
                SweptTolerance::Straightness(Axis::X, RailDirection::Normal),
                1.0,
            ),
            row(
                SweptTolerance::Straightness(Axis::X, RailDirection::Lateral),
                0.1,
            ),
            row(SweptTolerance::AllStraightness, 3.0),
            row(
                SweptTolerance::Carriage(Axis::X, CarriageFace::Parallelism),
                0.25,
            ),
            row(
                SweptTolerance::Carriage(Axis::X, CarriageFace::Flatness),
                -4e-16,
            ),
            row(
                SweptTolerance::Carriage(Axis::Z, CarriageFace::Flatness),
                0.0,
            ),
        ];
        let json = SensitivityJson::ranked(&rows);
        let ranks: Vec<Option<usize>> = json.iter().map(|r| r.rank).collect();
        // 1000 > 250 > 100 > 0 = 0 µm/mm; `all` is not ranked.
        assert_eq!(ranks, [Some(1), Some(3), None, Some(2), Some(4), Some(4)]);
        let sides: Vec<&str> = json.iter().map(|r| r.side).collect();
        assert_eq!(
            sides,
            ["rail", "rail", "all", "carriage", "carriage", "carriage"]
        );
        let table = sensitivity_table(&json);
        let flatness = table
            .lines()
            .find(|line| line.contains("X.carriage_flatness"))
            .unwrap();
        assert!(flatness.ends_with("|           0.0 |"), "{flatness}");
        assert!(
            table.contains("|    2 | X.carriage_parallelism | carriage |"),
            "{table}"
        );
    }

    #[test]
    fn describe_collapses_equal_values() {
        let mut values = BTreeMap::new();
        values.insert("X".to_string(), 0.0);
        values.insert("Y".to_string(), 0.0);
        assert_eq!(describe(&values, "mm", "X and Y"), "none");
        values.insert("X".to_string(), 0.01);
        values.insert("Y".to_string(), 0.01);
        assert_eq!(describe(&values, "mm", "X and Y"), "0.01 mm on X and Y");
        values.insert("Z".to_string(), 0.02);
        assert_eq!(
            describe(&values, "mm", "X, Y, Z"),
            "X 0.01, Y 0.01, Z 0.02 mm"
        );
    }
}
