//! `uncertainty.html`: the budget of the test being accepted and U of the figures.

use crate::report::acceptance::ReportInput;
use crate::report::format::SourcedUm;
use crate::report::uncertainty::{NOT_EVALUATED_NOTE, UncertaintyJson};

/// `uncertainty.html`: the budget of the test being accepted, largest
/// contributor first, and U of the figures.
pub(super) struct UncertaintyView {
    /// "test FILE" or "re-test FILE".
    pub(super) test_name: String,
    /// U(E) = U(M) = U(A).
    pub(super) expanded: SourcedUm,
    /// u_c, µm, three decimals.
    pub(super) combined_um: String,
    /// k.
    pub(super) k: String,
    /// The equipment profile.
    pub(super) equipment: String,
    /// (name, u, source), largest first.
    pub(super) rows: Vec<(&'static str, SourcedUm, String)>,
    /// U(R), U(B) not evaluated.
    pub(super) note: &'static str,
}

/// The budget of the test being accepted (the re-test when there is one, as
/// the verdict box); `None` when no budget was made.
pub(super) fn uncertainty_view(input: &ReportInput<'_>) -> Option<UncertaintyView> {
    let (prefix, what, test) = match &input.after {
        Some(after) => ("after", "re-test", after),
        None => ("before", "test", &input.before),
    };
    let json = UncertaintyJson::from_budget(test.budget?);
    let test_name = match &test.measurement.metadata.source_file {
        Some(file) => format!("{what} {}", file.display()),
        None => what.to_string(),
    };
    Some(UncertaintyView {
        test_name,
        expanded: SourcedUm::new(format!("{prefix}.uncertainty_um.E"), Some(json.E)),
        combined_um: format!("{:.3}", json.u_c),
        k: json.k.to_string(),
        equipment: json.equipment.clone(),
        rows: json
            .budget
            .iter()
            .enumerate()
            .map(|(index, c)| {
                let key = format!("{prefix}.uncertainty_um.budget.{index}.u_um");
                (c.name, SourcedUm::new(key, Some(c.u_um)), c.source.clone())
            })
            .collect(),
        note: NOT_EVALUATED_NOTE,
    })
}
