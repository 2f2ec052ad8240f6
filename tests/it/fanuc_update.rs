//! What `convert --existing PITCH.TXT` says of a Fanuc update, checked
//! against the file it wrote: X of the real backup (`../shared/data/fanuc/`)
//! updated from the synthetic test (seed 30) over −1000 … 0 mm. The
//! expected numbers come from the two files with plain text handling (the
//! data lines `N1nnnnQ0P<value>`, `fanuc::increments`) and from the backup's
//! parameters by hand: 1240 = 0 mm at 3620 = 40, 3621 = 1, 3622 = 41,
//! 3624 = 40 mm, so X's points 0 … 41 lie at (n − 40) × 40 mm, −1600 … 40 mm,
//! and one unit is 0.0001 mm × 3623 = 10 = 1 µm.

use axcomp::emit::fanuc::ParameterBackup;

use crate::fanuc::{absolute, data, increments, update_x};

#[test]
fn a_fanuc_update_says_which_points_it_updated_and_how_it_kept_the_others() {
    let directory = tempfile::tempdir().unwrap();
    let new_file = directory.path().join("NEW.TXT").display().to_string();
    let parameters = data("CNC-PARA.TXT");
    let (_, run) = update_x(
        directory.path(),
        &parameters,
        "30",
        &["-o", &new_file, "--json", "-q"],
    );
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let update = &json["update"];
    assert!(update.is_object(), "{json:#}");

    // X's points as the backup has them, and by hand.
    let backup = std::fs::read_to_string(&parameters).unwrap();
    let x = ParameterBackup::parse(&backup, "CNC-PARA.TXT")
        .unwrap()
        .axis("X")
        .unwrap();
    let points: Vec<(i64, f64)> = (x.first_point()..=x.most_positive)
        .map(|n| (n, x.position(n)))
        .collect();
    let by_hand: Vec<(i64, f64)> = (0..=41).map(|n| (n, (n - 40) as f64 * 40.0)).collect();
    assert_eq!(points, by_hand);
    let inside = |x: f64| (-1000.0..=0.0).contains(&x);

    // Updated: the points inside the measured range, 15 … 40 (26).
    let updated = points.iter().filter(|(_, x)| inside(*x)).count();
    assert_eq!(updated, 26);
    assert_eq!(update["updated"], updated);
    assert_eq!(update["measured_mm"], serde_json::json!([-1000.0, 0.0]));
    assert_eq!(update["reference_mm"], 0.0);
    assert_eq!(update["reference"], "existing zero");
    assert_eq!(update["kept_as"], "increments");
    assert_eq!(update["dropped_mm"], serde_json::json!([]));
    assert_eq!(update["added_mm"], serde_json::json!([]));

    // The data lines: the sections ending at points 16 … 40 are written
    // (25); those that differ are the lines that differ between the files.
    let old_text = std::fs::read_to_string(data("PITCH.TXT")).unwrap();
    let new_text = std::fs::read_to_string(&new_file).unwrap();
    let differing = old_text
        .lines()
        .zip(new_text.lines())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(old_text.lines().count(), new_text.lines().count());
    assert!(differing > 0 && differing <= 25, "{differing}");
    assert_eq!(update["data_lines"]["sections"], 25);
    assert_eq!(update["data_lines"]["changed"], differing);

    // Kept: −1600 … −1040 mm (points 0 … 14) and 40 mm (point 41), with
    // their increments: each point's value moved by the change at the end of
    // the measured range next to it (−1000 mm, point 15; 0 mm, point 40).
    let (old, new) = (increments(&old_text), increments(&new_text));
    for n in (1..=15).chain([41]) {
        assert_eq!(old[&n], new[&n], "the increment of point {n}");
    }
    // The table's value is −(absolute compensation) × 1 µm; in mm.
    let change_mm = |n: i64| -((absolute(&new, n) - absolute(&old, n)) as f64) / 1000.0;
    let kept = update["kept_mm"].as_array().unwrap();
    assert_eq!(kept.len(), 2, "{kept:?}");
    for (run, (first, last, count, end)) in kept
        .iter()
        .zip([(-1600.0, -1040.0, 15, 15), (40.0, 40.0, 1, 40)])
    {
        assert_eq!(run["first"], first);
        assert_eq!(run["last"], last);
        assert_eq!(run["count"], count);
        assert_eq!(
            count,
            points
                .iter()
                .filter(|(_, x)| *x >= first && *x <= last)
                .count()
        );
        let with = (end - 40) as f64 * 40.0;
        assert_eq!(run["moved"]["with"], with);
        let by = run["moved"]["by"][0].as_f64().unwrap();
        assert_eq!(run["moved"]["by"][1].as_f64().unwrap(), by, "a mean table");
        for (n, x) in &points {
            if *x >= first && *x <= last {
                assert!(
                    (change_mm(*n) - by).abs() < 1e-12,
                    "point {n} at {x} mm moved by {} mm, said {by}",
                    change_mm(*n)
                );
            }
        }
    }
    // At the reference point 40 (0 mm) the update adds nothing: 40 mm is as it was.
    assert_eq!(change_mm(41), 0.0);
    let below = kept[0]["moved"]["by"][0].as_f64().unwrap();
    assert!(
        below != 0.0,
        "the new value at −1000 mm differs from the old"
    );

    // The terminal says it, in the file's unit (mm) and in µm.
    let lines: Vec<&str> = update["lines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    let below_um = format!("{:+}", (below * 1e5).round() / 100.0);
    assert_eq!(
        lines,
        [
            format!(
                "-1600…-1040 mm (15 points): kept their increments, not their values (outside the measured -1000…0 mm; the file's data are increments per section): the old curve continues from the new value at -1000 mm: their values moved by {below_um} µm"
            )
            .as_str(),
            "40 mm (1 point): kept its increment, not its value (outside the measured -1000…0 mm; the file's data are increments per section): the old curve continues from the new value at 0 mm, which is the old one: its value is as it was",
            "-1000…0 mm (26 points): the existing table plus the measured residual, referred to 0 mm (the existing table's zero), where the update adds nothing",
            format!(
                "pitch file: {differing} of the 25 data lines of those points' sections changed (the others already held their new value); every other line of the file as it was"
            )
            .as_str(),
        ]
    );
    let terminal = crate::fanuc::ok(&[
        "convert",
        &directory.path().join("after.rtl").display().to_string(),
        "--controller",
        "fanuc",
        "--existing",
        &data("PITCH.TXT"),
        "--fanuc-parameters",
        &parameters,
        "--axis",
        "X",
        "-o",
        &new_file,
        "--force",
    ]);
    for line in &lines {
        assert!(
            terminal.stdout.contains(&format!("Update: {line}\n")),
            "{line}\n{}",
            terminal.stdout
        );
    }
    // The printed table has X's 26 updated points only: no row is marked kept.
    assert!(!terminal.stdout.contains("kept: the old value"));
    assert_eq!(std::fs::read_to_string(&new_file).unwrap(), new_text);
}
