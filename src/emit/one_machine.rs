//! Tables of one machine that would overwrite each other in the control,
//! told from their files: two Sinumerik programs writing the same CEC table
//! number, or two TNC 640 tables of one table axis, which has one active
//! table (MANUALplus 620 technical manual p.718).

use super::{Controller, detect, sinumerik840d};

/// A table file given for one machine.
#[derive(Clone, Copy, Debug)]
pub struct MachineTable<'a> {
    /// The file, as the user named it.
    pub name: &'a str,
    /// The axis the table is a function of.
    pub axis: &'a str,
    /// Its text.
    pub text: &'a str,
}

/// Why `second`, loaded after `first`, would overwrite it in the control;
/// `None` when it would not (or when either is not a table axcomp reads).
pub fn overwrites(first: &MachineTable<'_>, second: &MachineTable<'_>) -> Option<String> {
    let controller = detect(second.text)?;
    if detect(first.text)? != controller {
        return None;
    }
    let (other, path, axis) = (first.name, second.name, second.axis);
    match controller {
        Controller::Sinumerik840d => {
            let numbers = sinumerik840d::cec_tables(second.text).unwrap_or_default();
            let other_numbers = sinumerik840d::cec_tables(first.text).unwrap_or_default();
            let t = numbers.iter().find(|t| other_numbers.contains(t))?;
            Some(format!(
                "{other} and {path} both write Sinumerik CEC table {t}: loaded one after the other, the second overwrites the first in the control; write them again with convert, which numbers the tables of one machine from its profile (formats/sinumerik840d/README.md)"
            ))
        }
        Controller::Tnc640 if first.axis == axis => Some(format!(
            "{other} and {path} are both tables of axis {axis}, and the TNC 640 has one active compensation table per axis (MANUALplus 620 technical manual p.718): put the columns into one table (convert STRAIGHTNESS --controller tnc640 --existing {other})"
        )),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn golden(path: &str) -> String {
        let path = format!("{}/formats/{path}", env!("CARGO_MANIFEST_DIR"));
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
    }

    fn table<'a>(name: &'a str, axis: &'a str, text: &'a str) -> MachineTable<'a> {
        MachineTable { name, axis, text }
    }

    #[test]
    fn two_sinumerik_programs_of_one_cec_table_number_overwrite() {
        // The grid program writes CEC tables 0 and 1, the cross-axis one table 6.
        let own = golden("sinumerik840d/golden/sample-grid50-cec.MPF");
        let cross = golden("sinumerik840d/golden/cross-Y-of-X-cec.MPF");
        let why = overwrites(&table("a.MPF", "X", &own), &table("b.MPF", "X", &own))
            .expect("tables 0 and 1 twice");
        assert!(
            why.starts_with("a.MPF and b.MPF both write Sinumerik CEC table 0:"),
            "{why}"
        );
        assert_eq!(
            overwrites(&table("a.MPF", "X", &own), &table("b.MPF", "X", &cross)),
            None
        );
        // A LEC program writes no CEC table.
        let lec = golden("sinumerik840d/golden/sample-grid50-lec.MPF");
        assert_eq!(
            overwrites(&table("a.MPF", "X", &lec), &table("b.MPF", "X", &lec)),
            None
        );
    }

    #[test]
    fn two_tnc640_tables_of_one_axis_overwrite_and_of_two_axes_do_not() {
        let cross = golden("tnc640/golden/cross-Y-of-X.COM");
        let mean = golden("tnc640/golden/sample-mean.COM");
        let why = overwrites(
            &table("X.COM", "X", &mean),
            &table("Y-of-X.COM", "X", &cross),
        )
        .expect("one table per axis");
        assert!(why.contains("both tables of axis X"), "{why}");
        assert_eq!(
            overwrites(&table("X.COM", "X", &mean), &table("Y.COM", "Y", &cross)),
            None
        );
    }

    #[test]
    fn tables_of_two_controllers_do_not_overwrite() {
        let tnc = golden("tnc640/golden/sample-mean.COM");
        let sinumerik = golden("sinumerik840d/golden/sample-grid50-cec.MPF");
        assert_eq!(
            overwrites(&table("a", "X", &tnc), &table("b", "X", &sinumerik)),
            None
        );
    }
}
