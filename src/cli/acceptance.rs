//! `--limit FIGURE=UM` and the machine profile's `[acceptance]` table, shared
//! by `evaluate` and `report`: flags to the library's limits
//! (`axcomp::evaluate::verdict`), which decide the verdict.

use std::path::Path;

use super::common::load_part;
use anyhow::Result;

use axcomp::evaluate::Evaluation;
use axcomp::evaluate::verdict::{AcceptanceProfile, Figure, Limit, parse_limit};
use axcomp::workflow;

/// The acceptance flags.
#[derive(Debug, Clone, clap::Args)]
pub struct LimitArgs {
    /// Permissible value of a figure, µm: FIGURE=UM, e.g. A=12 (repeat for several).
    ///
    /// FIGURE is a key of figures_um in evaluate --json under the --standard:
    /// A, A_up, A_down, E, E_up, E_down, M, R, R_up, R_down, B, B_mean
    /// (B_mean compares |B̄|) for ISO 230-2 and its ±3s forms; P, Pa,
    /// Ps_max, Ps_mean, U_max, U_mean for vdi3441.
    /// Replaces the machine profile's [acceptance] limit for that figure. With
    /// limits the output gets a verdict under --decision (default simple:
    /// value ≤ limit); a figure that is not evaluated fails. The exit status stays 0:
    /// a FAIL is a result, not an error.
    #[arg(long = "limit", value_name = "FIGURE=UM", value_parser = parse_limit, help_heading = "Acceptance")]
    pub limits: Vec<(Figure, f64)>,
}

/// The limits for `axis`: the profile's `[acceptance]` (if a profile is
/// given), with the command line's on top, each on a figure of the
/// evaluation's standard. Empty: no verdict.
pub fn load_limits(
    profile: Option<&Path>,
    axis: &str,
    evaluation: &Evaluation,
    args: &LimitArgs,
) -> Result<Vec<Limit>> {
    let profile = match profile {
        Some(path) => Some((
            load_part(path, AcceptanceProfile::from_toml_str)?,
            path.display().to_string(),
        )),
        None => None,
    };
    let profile = profile.as_ref().map(|(p, name)| (p, name.as_str()));
    Ok(workflow::limits(profile, axis, evaluation, &args.limits)?)
}
