//! Cross-axis (straightness) tables: Heidenhain TNC 640 `.COM` with a
//! dependent column and Sinumerik CEC with INPUT ≠ OUTPUT axis, written
//! against golden files and read back (issue 15).

use axcomp::compensate::cross_axis::CrossAxisTable;
use axcomp::emit::{EmitOptions, MachineProfile, sinumerik840d, tnc640};

use crate::util::{assert_golden, root};

/// The golden files these tests write (controller folder, file name);
/// `convert::every_golden_file_has_a_case` counts them as produced here.
pub const GOLDENS: [(&str, &str); 2] = [
    ("tnc640", "cross-Y-of-X.COM"),
    ("sinumerik840d", "cross-Y-of-X-cec.MPF"),
];

fn golden(index: usize) -> std::path::PathBuf {
    let (controller, name) = GOLDENS[index];
    root()
        .join("formats")
        .join(controller)
        .join("golden")
        .join(name)
}

/// EYX by hand: X's straightness in Y, a 3 µm bow over 0 … 750 mm at 150 mm.
fn eyx() -> CrossAxisTable {
    CrossAxisTable::new(
        "X",
        "Y",
        vec![0.0, 150.0, 300.0, 450.0, 600.0, 750.0],
        vec![0.0, 0.0017, 0.0028, 0.003, 0.0021, 0.0004],
        0.0,
    )
}

#[test]
fn tnc640_dependent_column_round_trips() {
    let profile = MachineProfile::default();
    let options = EmitOptions::for_axis(&profile, "Y", "X.COM").unwrap();
    let text = tnc640::write_cross_axis(&eyx(), &options).unwrap();
    // The values sit in column Y of X.COM: Y = F(X), not negated.
    assert!(text.starts_with("BEGIN X.COM MM\r\n"), "{text}");
    assert!(
        text.contains("2    +300                        +0.0028\r\n"),
        "{text}"
    );
    assert_golden(&text, &golden(0));
    let back = tnc640::read_cross_axis(&text, "X", "Y").unwrap();
    assert_eq!(back, eyx());
    // A direction in BACKLASH is refused: a straightness has none.
    let with_backlash = text.replace(
        "2    +300                        +0.0028",
        "2    +300          +0.0001       +0.0028",
    );
    let error = tnc640::read_cross_axis(&with_backlash, "X", "Y").unwrap_err();
    assert!(error.message.contains("BACKLASH"), "{error}");
}

#[test]
fn sinumerik_cec_with_another_output_axis_round_trips() {
    let profile = MachineProfile::default();
    let options = EmitOptions::for_axis(&profile, "Y", "CEC").unwrap();
    let input = profile.axis("X").unwrap().sinumerik_axis;
    let output = options.axes[0].sinumerik_axis.clone();
    let text = sinumerik840d::write_cross_axis(&eyx(), &input, &options).unwrap();
    assert!(
        text.contains(&format!("$AN_CEC_INPUT_AXIS[0]=({input})\n")),
        "{text}"
    );
    assert!(
        text.contains(&format!("$AN_CEC_OUTPUT_AXIS[0]=({output})\n")),
        "{text}"
    );
    // Corrections (the profile's default): −error.
    assert!(text.contains("$AN_CEC[0,2]=-0.0028\n"), "{text}");
    assert_golden(&text, &golden(1));
    let back = sinumerik840d::read_cross_axis(&text, (&input, &output), ("X", "Y"), true).unwrap();
    assert_eq!(back, eyx());
    // The cross table is not Y's own table.
    let own = sinumerik840d::read(&text, &output, true).unwrap_err();
    assert!(own.message.contains("no $AA_ENC_COMP table"), "{own}");
    let missing =
        sinumerik840d::read_cross_axis(&text, (&output, &input), ("Y", "X"), true).unwrap_err();
    assert!(missing.message.contains("found none"), "{missing}");
}
