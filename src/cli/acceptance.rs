//! `--limit FIGURE=UM` and the machine profile's `[acceptance]` table, shared
//! by `evaluate` and `report`: flags to the library's limits
//! (`axcomp::evaluate::verdict`), which decide the verdict.

use std::path::Path;

use super::common::load;
use anyhow::Result;

use axcomp::evaluate::Evaluation;
use axcomp::evaluate::verdict::{
    AcceptanceProfile, Figure, Limit, check_standard, command_line_limits, with_overrides,
};

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

/// `A=12`: a figure and a number of µm above 0.
pub fn parse_limit(text: &str) -> Result<(Figure, f64), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("expected FIGURE=UM like A=12, found {text:?}"))?;
    let name = name.trim();
    let figure = Figure::from_name(name).ok_or_else(|| {
        format!(
            "unknown figure {name:?}; the figures are {}",
            Figure::names()
        )
    })?;
    let value: f64 = value
        .trim()
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("expected a number of µm above 0 after {name}=, found {value:?}"))?;
    Ok((figure, value))
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
    let from_profile = match profile {
        Some(path) => load(path, AcceptanceProfile::from_toml_str)?
            .limits_for(axis, &path.display().to_string()),
        None => Vec::new(),
    };
    let from_command_line = command_line_limits(&args.limits)?;
    let limits = with_overrides(from_profile, from_command_line);
    check_standard(&limits, evaluation)?;
    Ok(limits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_parse_and_bad_ones_say_what_is_valid() {
        assert_eq!(parse_limit("A=12").unwrap(), (Figure::A, 12.0));
        assert_eq!(parse_limit("B_mean = 2.5").unwrap(), (Figure::BMean, 2.5));
        let unknown = parse_limit("Q=3").unwrap_err();
        assert!(unknown.contains("unknown figure \"Q\""), "{unknown}");
        assert!(
            unknown.contains("A, A_up, A_down, E, E_up, E_down, M, R, R_up, R_down, B, B_mean")
        );
        for bad in ["A=0", "A=-3", "A=inf", "A=NaN", "A=12um", "A="] {
            assert!(parse_limit(bad).unwrap_err().contains("above 0"), "{bad}");
        }
        assert!(parse_limit("A12").unwrap_err().contains("FIGURE=UM"));
    }
}
