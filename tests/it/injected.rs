//! Issue 16: real measurements with one known effect put in.
//!
//! The real ESS/PSI tests of `../shared/data/ecmc` (their own noise, outlier
//! runs, drift and reversal) are each given one effect in a copy in memory,
//! through `Effect::added_to` (the effect's one definition, `src/effects/`),
//! at the reading times `diagnose` uses (`cycle::reading_times_h`). The copy
//! is diagnosed against the file itself as the first test (its own first
//! evaluation is the prediction, as `diagnose --before FILE` takes it), and
//! must show the effect within 10 % (or 0.2 µm in its unit) of what was put
//! in, on top of what the file already contains of that kind, and no kind
//! the file does not contain.
//!
//! What the files contain is what `diagnose` finds in each untouched file
//! alone (no first test: structure between runs), listed in `CONTAINS` and
//! checked here too; the sizes put in are multiples of each file's own
//! scatter s (the RMS of its s_i↑, s_i↓), since the files' scatter ranges
//! from 0.01 µm to 130 µm.
//!
//! The API XD `.pos` files of `../shared/data/api-xd` hold one run in one
//! direction: no effect can pass the leave-one-run-out gate there, so they
//! are checked for exactly that (nothing found, in the untouched and the
//! injected copy), not for detection.

use axcomp::cycle::{CycleTiming, reading_times_h};
use axcomp::diagnose::{DiagnoseError, DiagnoseInput, Diagnosis, diagnose};
use axcomp::effects::{Drift, Effect, OutlierRun, Periodic, Reversal, Scale};
use axcomp::evaluate::{ISO_230_2, evaluate};
use axcomp::measurement::{Direction, Measurement};
use axcomp::read::read_path;

use crate::util::{shared_data, shared_files};

/// What `diagnose` finds in each untouched file alone: the kinds and, for a
/// reversal, a drift or an outlier run, the value the injected one adds to.
/// Found by running it (`untouched_files_contain_what_is_stated` checks the
/// list); the start-up run 1↑ of mcu1025 is anchors-and-standards.md §3.1.
const CONTAINS: [(&str, &[&str]); 17] = [
    (
        "examples__ESS__mcu1025_fat_sat__report.md_ISO230.dat",
        &["outlier-run"],
    ),
    (
        "examples__mcu1025_fat_sat__report.md_ISO230.dat",
        &["outlier-run"],
    ),
    ("examples__test__fat_sat__report.md_ISO230.dat", &[]),
    ("qualityControl__data__sampleData.dat", &[]),
    ("b02__x__target_x.md_ISO230.dat", &["drift"]),
    ("b02__y__report_target_y.md_ISO230.dat", &["drift"]),
    ("b02__z__report_z.md_ISO230.dat", &["reversal"]),
    (
        "muts__data__week42_22__xyz__back__target_x_report.md_ISO230.dat",
        &["reversal", "drift", "outlier-run"],
    ),
    (
        "muts__data__week42_22__xyz__back__target_x_report_2.md_ISO230.dat",
        &["drift", "outlier-run"],
    ),
    (
        "muts__data__week42_22__xyz__back__target_x_report_8A.md_ISO230.dat",
        &["reversal", "drift", "outlier-run"],
    ),
    (
        "muts__data__week42_22__xyz__back__target_y_report.md_ISO230.dat",
        &["drift"],
    ),
    (
        "muts__data__week42_22__xyz__back__target_z_report.md_ISO230.dat",
        &["drift", "outlier-run"],
    ),
    (
        "muts__data__week42_22__xyz__target_x_report_ILD50.md_ISO230.dat",
        &[],
    ),
    (
        "muts__data__week42_22__xyz__target_y_report_ILD50.md_ISO230.dat",
        &["reversal", "drift", "outlier-run"],
    ),
    (
        "muts__data__week42_22__xyz__target_z_report_ILD2300_below.md_ISO230.dat",
        &[],
    ),
    ("tools__iso230-2__example_data_ISO230_2.dat", &[]),
    ("tools__iso230-2_testdata.dat", &[]),
];

fn ecmc_files() -> Vec<std::path::PathBuf> {
    let mut files = shared_files("ecmc/ecmccfg", ".dat");
    files.extend(shared_files("ecmc/ecmc_target_muts_logger", ".dat"));
    files.extend(shared_files("ecmc/ecmccomgui", ".dat"));
    files
}

fn name_of(path: &std::path::Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

fn try_run(after: &Measurement, before: Option<&Measurement>) -> Result<Diagnosis, DiagnoseError> {
    let input = DiagnoseInput {
        angle: Default::default(),
        after,
        before,
        table: None,
        backlash_set: false,
        angular: None,
        timing: CycleTiming::ASSUMED,
        standard: &ISO_230_2,
        known_periods: &[],
    };
    diagnose(&input)
}

fn run(after: &Measurement, before: Option<&Measurement>) -> Diagnosis {
    try_run(after, before).unwrap()
}

fn kinds(d: &Diagnosis) -> Vec<&'static str> {
    let mut kinds: Vec<&'static str> = d.accepted.iter().map(|a| a.effect.kind().name()).collect();
    kinds.dedup();
    kinds
}

/// The file's own scatter: RMS of its s_i↑ and s_i↓, µm.
fn scatter_um(m: &Measurement) -> f64 {
    let s: Vec<f64> = evaluate(m)
        .per_target
        .iter()
        .flat_map(|t| [t.up.s, t.down.s])
        .flatten()
        .collect();
    1000.0 * (s.iter().map(|x| x * x).sum::<f64>() / s.len() as f64).sqrt()
}

/// The one number of an effect that is compared: B, rate, offset, scale, amplitude.
fn value(effect: &Effect) -> f64 {
    match effect {
        Effect::Reversal(e) => e.b,
        Effect::Drift(Drift::PerHour { rate_um_per_h }) => *rate_um_per_h,
        Effect::Drift(Drift::PerRun { rate_um_per_run }) => *rate_um_per_run,
        Effect::OutlierRun(e) => e.offset,
        Effect::Scale(e) => e.scale_um_per_m,
        Effect::Periodic(e) => e.amplitude,
        Effect::Abbe(e) => e.offset_mm,
    }
}

/// The found effect of the kind of `put_in` (the same run for an outlier
/// run, the same period within 2 % for a periodic error).
fn found_like(d: &Diagnosis, put_in: &Effect) -> Option<Effect> {
    d.accepted
        .iter()
        .map(|a| a.effect.clone())
        .find(|e| match (e, put_in) {
            (Effect::OutlierRun(a), Effect::OutlierRun(b)) => {
                a.run == b.run && a.direction == b.direction
            }
            // A period is found only within 2 % of the one put in.
            (Effect::Periodic(a), Effect::Periodic(b)) => {
                (a.period - b.period).abs() <= 0.02 * b.period
            }
            _ => e.kind() == put_in.kind(),
        })
}

/// The effects put in, sized to the file: a reversal and an outlier run of
/// 10 s, a drift of 20 s over the test (per hour, or per run when the file records no times), a scale of 10 s over the span, and
/// (with at least 9 targets) a periodic error of 5 s and a period of span/2.2 or 12 mm.
fn effects_for(m: &Measurement, s_um: f64, duration_h: f64) -> Vec<Effect> {
    let targets = m.targets();
    let span_mm = targets[targets.len() - 1] - targets[0];
    let mut effects = vec![
        Effect::Reversal(Reversal { b: -10.0 * s_um }),
        // The ecmc files record no times: the drift is per run (as diagnose gives it).
        if m.metadata.duration_s().is_some() {
            Effect::Drift(Drift::PerHour {
                rate_um_per_h: 20.0 * s_um / duration_h,
            })
        } else {
            Effect::Drift(Drift::PerRun {
                rate_um_per_run: 20.0 * s_um / m.runs().len() as f64,
            })
        },
        Effect::OutlierRun(OutlierRun {
            run: 3,
            direction: Direction::Down,
            offset: 10.0 * s_um,
        }),
        Effect::Scale(Scale {
            scale_um_per_m: 10.0 * s_um / (span_mm / 1000.0),
        }),
    ];
    if targets.len() >= 9 {
        // One period a whole number of 5 mm steps does not divide (span/2.2
        // = 18.2 mm) and a screw's 12 mm lead.
        for period_mm in [span_mm / 2.2, 12.0] {
            effects.push(Effect::Periodic(Periodic {
                period: period_mm,
                amplitude: 5.0 * s_um,
                phase_rad: 0.5,
            }));
        }
    }
    effects
}

/// One row of the detection table.
struct Row {
    file: String,
    kind: &'static str,
    put_in: f64,
    already: f64,
    found: Option<f64>,
    others: Vec<&'static str>,
}

impl Row {
    fn passes(&self) -> bool {
        let Some(found) = self.found else {
            return false;
        };
        let tolerance = (0.1 * self.put_in.abs()).max(0.2);
        (found - self.already - self.put_in).abs() <= tolerance && self.others.is_empty()
    }
}

fn detection_table() -> Vec<Row> {
    let mut rows = Vec::new();
    for path in ecmc_files() {
        let file = name_of(&path);
        let m = read_path(&path, None).unwrap().measurement;
        let (times, _) = reading_times_h(&m, CycleTiming::ASSUMED);
        let duration_h = times.iter().flatten().fold(0.0_f64, |a, &b| a.max(b));
        let s_um = scatter_um(&m);
        let untouched = run(&m, None);
        let contained = kinds(&untouched);
        for effect in effects_for(&m, s_um, duration_h) {
            let mut copy = effect.added_to(&m, &times).unwrap();
            // A copy in memory, not the file: `diagnose` refuses a file given twice.
            copy.metadata.source_file = None;
            let d = run(&copy, Some(&m));
            // The prediction carries the file's own reversal (per target and
            // direction); its drift and outlier runs stay in the residual.
            let already = match effect {
                Effect::Reversal(_) => 0.0,
                _ => found_like(&untouched, &effect).map_or(0.0, |e| value(&e)),
            };
            rows.push(Row {
                file: file.clone(),
                kind: effect.kind().name(),
                put_in: value(&effect),
                already,
                found: found_like(&d, &effect).map(|e| value(&e)),
                others: kinds(&d)
                    .into_iter()
                    .filter(|k| *k != effect.kind().name() && !contained.contains(k))
                    .collect(),
            });
        }
    }
    rows
}

/// Rows that fail, and why (each checked to fail as stated, so a fix shows up).
/// FIXME(issue 16): the outlier run of the ILD50 X file comes out 16 % high:
/// its run 3↓ is already 62 µm (1.6 s) off, below what the untouched file
/// alone shows as an outlier run, and it adds to the one put in.
const KNOWN_MISSES: [(&str, &str); 1] = [(
    "muts__data__week42_22__xyz__target_x_report_ILD50.md_ISO230.dat",
    "outlier-run",
)];

#[test]
fn untouched_files_contain_what_is_stated() {
    let files = ecmc_files();
    assert_eq!(files.len(), CONTAINS.len() + 1, "{files:?}");
    for path in files {
        let file = name_of(&path);
        let m = read_path(&path, None).unwrap().measurement;
        let found = kinds(&run(&m, None));
        // testdata_ISO230_2.dat holds the readings of example_data_ISO230_2.dat.
        let key = if file == "tools__iso230-2__testdata_ISO230_2.dat" {
            "tools__iso230-2__example_data_ISO230_2.dat"
        } else {
            file.as_str()
        };
        let stated = CONTAINS
            .iter()
            .find(|(name, _)| *name == key)
            .unwrap_or_else(|| panic!("{file}: not in CONTAINS"))
            .1;
        let mut found_sorted = found.clone();
        found_sorted.sort();
        let mut stated_sorted = stated.to_vec();
        stated_sorted.sort();
        assert_eq!(found_sorted, stated_sorted, "{file}");
    }
}

#[test]
fn an_effect_put_into_a_real_file_is_found() {
    let rows = detection_table();
    println!("file | kind | put in | already in the file | found | pass");
    for row in &rows {
        println!(
            "{} | {} | {:.4} | {:.4} | {} | {}{}",
            row.file,
            row.kind,
            row.put_in,
            row.already,
            row.found.map_or("not found".into(), |f| format!("{f:.4}")),
            if row.passes() { "pass" } else { "FAIL" },
            if row.others.is_empty() {
                String::new()
            } else {
                format!(" (also {:?})", row.others)
            }
        );
    }
    let failing: Vec<(&str, &str)> = rows
        .iter()
        .filter(|r| !r.passes())
        .map(|r| (r.file.as_str(), r.kind))
        .collect();
    // Periodic errors are put into the 9-target b02 files only: on 5
    // targets the search would start at twice the spacing, half the span,
    // and `diagnose` says the targets are too coarse (README).
    assert_eq!(rows.iter().filter(|r| r.kind == "periodic").count(), 4);
    assert_eq!(failing, KNOWN_MISSES, "rows that fail");
}

#[test]
fn one_run_in_one_direction_is_refused() {
    for name in [
        "example__8055__X Axis Forward.pos",
        "example__8055__Y Axis Forward.pos",
    ] {
        let path = shared_data(&format!("api-xd/{name}"));
        let m = read_path(&path, None).unwrap().measurement;
        assert_eq!(m.runs().len(), 1);
        let (times, _) = reading_times_h(&m, CycleTiming::ASSUMED);
        let mut copy = Effect::Scale(Scale {
            scale_um_per_m: 20.0,
        })
        .added_to(&m, &times)
        .unwrap();
        copy.metadata.source_file = None;
        for before in [None, Some(&m)] {
            let error = try_run(&copy, before).unwrap_err();
            assert!(
                matches!(error, DiagnoseError::TooFewReadings(_)),
                "{name}: {error}"
            );
        }
    }
}

/// A screw period of exactly twice the b02 files' even 5 mm spacing: the
/// targets see sin(πk + φ) = ±sin φ only, so the amplitude found is
/// A·sin φ (by hand: 5 s · sin 0.5 = 0.479 of what was put in) and the
/// phase π/2, and the diagnosis warns that the spacing aliases periods.
#[test]
fn a_period_of_twice_the_even_spacing_is_seen_aliased() {
    for name in [
        "b02__x__target_x.md_ISO230.dat",
        "b02__y__report_target_y.md_ISO230.dat",
    ] {
        let path = shared_data(&format!("ecmc/ecmc_target_muts_logger/{name}"));
        let m = read_path(&path, None).unwrap().measurement;
        let (times, _) = reading_times_h(&m, CycleTiming::ASSUMED);
        let amplitude_um = 5.0 * scatter_um(&m);
        let effect = Effect::Periodic(Periodic {
            period: 10.0,
            amplitude: amplitude_um,
            phase_rad: 0.5,
        });
        let mut copy = effect.added_to(&m, &times).unwrap();
        copy.metadata.source_file = None;
        let d = run(&copy, Some(&m));
        let accepted = d
            .accepted
            .iter()
            .find(|a| matches!(a.effect, Effect::Periodic(_)))
            .unwrap_or_else(|| panic!("{name}: {:?}", d.accepted));
        let Effect::Periodic(found) = accepted.effect else {
            unreachable!()
        };
        let seen = amplitude_um * 0.5_f64.sin();
        assert!(
            (found.amplitude - seen).abs() <= 0.1 * seen,
            "{name}: {found:?}"
        );
        assert!((found.period - 10.0).abs() <= 0.2, "{name}: {found:?}");
        assert!(
            accepted.warnings.iter().any(|w| w.contains("alias")),
            "{name}: {:?}",
            accepted.warnings
        );
    }
}
