//! A rotary axis' effects say their values in the axis' units: every
//! sentence of a rotary diagnosis in ″ and °, never in µm or mm, including
//! where one effect names another.

use axcomp::cycle::{CycleTiming, reading_times_h};
use axcomp::diagnose::{DiagnoseInput, Diagnosis, KnownPeriod, diagnose};
use axcomp::effects::{Effect, OutlierRun, Periodic, Reversal};
use axcomp::evaluate::ISO_230_2;
use axcomp::measurement::{Direction, Measurement};
use axcomp::read::read_path;

use crate::util::test_data;

/// The diagnosis of `after` (against `before`), in ″.
fn diagnosed(
    after: &Measurement,
    before: Option<&Measurement>,
    known: &[KnownPeriod],
) -> Diagnosis {
    diagnose(&DiagnoseInput {
        angle: Default::default(),
        after,
        before,
        table: None,
        backlash_set: false,
        angular: None,
        timing: CycleTiming::ASSUMED,
        standard: &ISO_230_2,
        known_periods: known,
    })
    .unwrap()
}

/// The synthetic rotary test with a reversal of 10 m° (36″) and run 1↑ put
/// 5 m° (18″) off the others added: the reversal fitted with that run
/// taken out differs from the B̄ of the figures, which include it, and the
/// reversal's sentence says so, naming the run with the offset its own
/// sentence gives, in ″.
#[test]
fn a_rotary_reversal_names_an_outlier_run_in_arc_seconds() {
    let read = read_path(&test_data("rotary/c-outlier-run.csv"), None).unwrap();
    let (times, _) = reading_times_h(&read.measurement, CycleTiming::ASSUMED);
    let mut after = read.measurement;
    for effect in [
        Effect::Reversal(Reversal { b: 10.0 }),
        Effect::OutlierRun(OutlierRun {
            run: 1,
            direction: Direction::Up,
            offset: 5.0,
        }),
    ] {
        after = effect.added_to(&after, &times).unwrap();
    }
    let diagnosis = diagnosed(&after, None, &[]);
    let sentence = |kind: &str| {
        diagnosis
            .accepted
            .iter()
            .find(|a| a.effect.kind().name() == kind)
            .map(|a| a.explanation.as_str())
            .unwrap_or_else(|| panic!("no {kind}: {:?}", diagnosis.accepted))
    };
    let (reversal, outlier) = (sentence("reversal"), sentence("outlier-run"));
    // "Run 1↑ sits +17.88″ off the others …": the offset as said there.
    let offset = outlier
        .strip_prefix("Run 1↑ sits +")
        .and_then(|rest| rest.split_once('″'))
        .map(|(number, _)| number)
        .unwrap_or_else(|| panic!("{outlier}"));
    assert!(
        reversal.contains(&format!(
            "fitted with the run 1↑ offset {offset}″ taken out"
        )),
        "{reversal}"
    );
    for text in [reversal, outlier] {
        assert!(!text.contains("µm") && !text.contains(" mm"), "{text}");
    }
}

/// A machine profile's periods are lengths (a screw lead, a scale period,
/// mm): a rotary axis' twice-per-revolution error of 180° is not said to be
/// "the screw lead the machine profile gives (180 mm)".
#[test]
fn a_rotary_harmonic_is_no_screw_lead() {
    let read = read_path(&test_data("rotary/c-outlier-run.csv"), None).unwrap();
    let (times, _) = reading_times_h(&read.measurement, CycleTiming::ASSUMED);
    let before = read.measurement;
    // 2 m° = 7.2″, twice per revolution.
    let harmonic = Effect::Periodic(Periodic {
        period: 180.0,
        amplitude: 2.0,
        phase_rad: 0.3,
    });
    let mut after = harmonic.added_to(&before, &times).unwrap();
    // Another test, not the first one again.
    after.metadata.source_file = None;
    let diagnosis = diagnosed(&after, Some(&before), &[KnownPeriod::screw_lead(180.0)]);
    let found = diagnosis
        .accepted
        .iter()
        .find(|a| matches!(a.effect, Effect::Periodic(_)))
        .unwrap_or_else(|| panic!("{:?}", diagnosis.rejected));
    assert!(
        found.explanation.contains("Twice-per-revolution"),
        "{}",
        found.explanation
    );
    let notes = found.warnings.join(" ");
    assert!(
        !notes.contains("screw lead") && !notes.contains(" mm"),
        "{notes}"
    );
}
