//! The measurement uncertainty as users and scripts read it: its `--json`
//! wire format ([`UncertaintyJson`], the `uncertainty_um` key of
//! `evaluate --json`), its terminal table ([`terminal`]) and the report's
//! budget table (the same rows).
//!
//! # Wire format
//!
//! Keys may be added, never renamed; every value in µm except `k` and
//! `length_mm`:
//!
//! ```text
//! "uncertainty_um": { "E": 3.49, "M": 3.49, "A": 3.49,   // U = k · u_c, k = 2
//!   "R": null, "B": null,                                 // not evaluated (standards.md §4)
//!   "u_c": 1.75, "k": 2.0, "length_mm": 1000.0,
//!   "equipment": "bundled typical HeNe laser (fixtures/equipment/hene-default.toml)",
//!   "budget": [{ "name": "u_E,MACHINE", "u_um": 1.155, "source": "T_mat = 21.00 °C (…)" }, …] }
//! ```
//!
//! `budget` is largest contributor first.

use std::fmt::Write;

use serde::Serialize;

use crate::evaluate::uncertainty::Budget;
use crate::units::mm_to_um;

/// What U(R) and U(B) are, in every output that shows U.
pub const NOT_EVALUATED_NOTE: &str = "U(R) and U(B) are not evaluated: no public form of their \
     uncertainty was found; the budget is reconstructed from ISO 230-2:2014 \
     Annex A as published descriptions give it";

/// The uncertainty of one test's figures, µm.
#[allow(non_snake_case)]
#[derive(Clone, Debug, Serialize)]
pub struct UncertaintyJson {
    /// U(E), µm.
    pub E: f64,
    /// U(M), µm.
    pub M: f64,
    /// U(A), µm.
    pub A: f64,
    /// U(R): not evaluated, always `null`.
    pub R: Option<f64>,
    /// U(B): not evaluated, always `null`.
    pub B: Option<f64>,
    /// The combined standard uncertainty u_c, µm.
    pub u_c: f64,
    /// The coverage factor of U.
    pub k: f64,
    /// L, the measured length, mm.
    pub length_mm: f64,
    /// The equipment profile used.
    pub equipment: String,
    /// The contributors, largest first.
    pub budget: Vec<ContributorJson>,
}

/// One contributor.
#[derive(Clone, Debug, Serialize)]
pub struct ContributorJson {
    /// `u_DEVICE`, `u_AIR`, `u_MISALIGNMENT`, `u_M,MACHINE`, `u_E,MACHINE`, `u_EVE`.
    pub name: &'static str,
    /// Its standard uncertainty, µm.
    pub u_um: f64,
    /// Where it comes from.
    pub source: String,
}

impl UncertaintyJson {
    /// The wire form of a budget.
    pub fn from_budget(budget: &Budget) -> UncertaintyJson {
        let expanded_um = mm_to_um(budget.expanded_mm);
        UncertaintyJson {
            E: expanded_um,
            M: expanded_um,
            A: expanded_um,
            R: None,
            B: None,
            u_c: mm_to_um(budget.combined_mm),
            k: budget.coverage_factor,
            length_mm: budget.length_mm,
            equipment: budget.equipment.clone(),
            budget: budget
                .contributors
                .iter()
                .map(|c| ContributorJson {
                    name: c.name,
                    u_um: mm_to_um(c.u_mm),
                    source: c.source.clone(),
                })
                .collect(),
        }
    }

    /// The title line: `U(E) = U(M) = U(A) = 3.49 µm (k = 2, u_c = 1.75 µm, equipment: …)`,
    /// naming only the figures of `evaluated` (`E`, `M`, `A`) the test has.
    pub fn summary(&self, evaluated: &[&str]) -> String {
        let named: Vec<String> = ["E", "M", "A"]
            .into_iter()
            .filter(|f| evaluated.contains(f))
            .map(|f| format!("U({f}) = "))
            .collect();
        let named = if named.is_empty() {
            "U = ".to_string()
        } else {
            named.concat()
        };
        format!(
            "{named}{:.2} µm (k = {}, u_c = {:.3} µm; equipment: {})",
            self.E, self.k, self.u_c, self.equipment
        )
    }
}

/// The budget table of `evaluate`, largest contributor first.
pub fn terminal(uncertainty: &UncertaintyJson, evaluated: &[&str]) -> String {
    use tabled::builder::Builder;
    use tabled::settings::object::Columns;
    use tabled::settings::{Alignment, Style};

    let mut builder = Builder::default();
    builder.push_record(["contributor", "u [µm]", "source"]);
    for c in &uncertainty.budget {
        builder.push_record([
            c.name.to_string(),
            format!("{:.3}", c.u_um),
            c.source.clone(),
        ]);
    }
    let mut table = builder.build();
    table
        .with(Style::psql())
        .modify(Columns::new(1..2), Alignment::right());
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\nMeasurement uncertainty (ISO 230-2:2014 Annex A, ISO/TR 230-9; docs/src/evaluate.md, Measurement uncertainty)\n{}\n{table}\n{}.",
        uncertainty.summary(evaluated),
        NOT_EVALUATED_NOTE
    );
    out
}
