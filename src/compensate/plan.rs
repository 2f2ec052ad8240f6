//! The plan of a table: what a measurement, the effects a diagnosis found, the
//! controller's capabilities and the user's request make of the next table
//! (its mode, its points, its reference) and what the user must be told. One
//! function, [`plan`], used by `convert` and the demo alike.
//!
//! The rules, each from the effect's own [`TableRole`]:
//! - a **reversal** makes the table bidirectional where the controller takes
//!   one; elsewhere it stays a mean table and the backlash parameter takes the
//!   reversal (the caller prints the controller's own line);
//! - a **periodic** error asks for points at most a tenth of its period apart
//!   (linear interpolation then leaves < 5 % of its amplitude), rounded down
//!   to a step the controller's format writes exactly;
//! - what an effect takes out of the table or leaves to another remedy is a
//!   note.
//!
//! The user's `--mode` and `--step` win, except that a step coarser than a
//! periodic error allows is refined.

use super::{CompensateError, Extrapolate, GridSpec, TableMode, TableOptions, regular_step};
use crate::effects::{Effect, TableRole};

/// What the controller can take, as far as a table's plan is concerned
/// (filled by the caller from `emit::Controller`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capabilities {
    /// The controller's name, for the notes.
    pub name: &'static str,
    /// Whether it takes one column per direction.
    pub bidirectional: bool,
    /// Whether its table may have unevenly spaced points.
    pub free_positions: bool,
    /// The smallest step its format writes exactly, mm.
    pub resolution_mm: f64,
}

/// What the user asked for (`None`: let the plan decide).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Request {
    /// `--mode`.
    pub mode: Option<TableMode>,
    /// `--step`, mm.
    pub step_mm: Option<f64>,
    /// `--start`, mm.
    pub start_mm: Option<f64>,
    /// `--count`.
    pub count: Option<usize>,
    /// `--reference`, mm.
    pub reference_mm: Option<f64>,
    /// `--extrapolate`.
    pub extrapolate: Option<Extrapolate>,
}

/// The table to build and what to say about it.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The options for [`super::effects::build_table_with_effects`].
    pub options: TableOptions,
    /// One line per decision an effect made (empty without effects).
    pub notes: Vec<String>,
}

/// The plan for a table over `targets_mm` (the measured targets, ascending).
pub fn plan(
    targets_mm: &[f64],
    effects: &[Effect],
    controller: &Capabilities,
    request: &Request,
) -> Result<Plan, CompensateError> {
    let mut notes = Vec::new();
    let mode = mode(effects, controller, request, &mut notes);
    let step_mm = effects_step(effects, controller, request, &mut notes);
    for effect in effects {
        if let TableRole::TakenOut { note } | TableRole::NotATable { note } = effect.in_table() {
            notes.push(note);
        }
    }
    Ok(Plan {
        options: TableOptions {
            mode,
            grid: grid(targets_mm, controller, request, step_mm)?,
            reference_mm: request.reference_mm,
            extrapolate: request.extrapolate.unwrap_or(Extrapolate::Refuse),
        },
        notes,
    })
}

fn mode(
    effects: &[Effect],
    controller: &Capabilities,
    request: &Request,
    notes: &mut Vec<String>,
) -> TableMode {
    let reversal = effects.iter().find_map(|e| match e.in_table() {
        TableRole::Bidirectional { b_um } => Some(b_um),
        _ => None,
    });
    match (request.mode, reversal) {
        (Some(mode), _) => mode,
        (None, Some(_)) if controller.bidirectional => {
            notes.push("reversal: a bidirectional table (one column per direction)".to_string());
            TableMode::Bidirectional
        }
        (None, Some(b)) => {
            notes.push(format!(
                "reversal: {} takes no bidirectional table; set the backlash parameter (the suggested value below; the diagnosis found B = {b:.2} µm)",
                controller.name
            ));
            TableMode::Mean
        }
        (None, None) => TableMode::Mean,
    }
}

/// The step the periodic effects ask for: a step the format writes exactly,
/// at most the finest they allow (and at most the user's).
fn effects_step(
    effects: &[Effect],
    controller: &Capabilities,
    request: &Request,
    notes: &mut Vec<String>,
) -> Option<f64> {
    let finest = effects
        .iter()
        .filter_map(|e| match e.in_table() {
            TableRole::AtPoints { finest_step_mm } => Some(finest_step_mm),
            _ => None,
        })
        .min_by(f64::total_cmp)?;
    let resolution = controller.resolution_mm;
    let step = ((finest / resolution).floor() * resolution).max(resolution);
    let chosen = request.step_mm.map_or(step, |given| given.min(step));
    notes.push(format!(
        "periodic: points every {chosen} mm (at most a tenth of the period), the periodic error at each point"
    ));
    Some(chosen)
}

/// The grid: the effects' finer step or `--step` (with `--start`, `--count`),
/// else the measured targets when the controller takes them.
fn grid(
    targets_mm: &[f64],
    controller: &Capabilities,
    request: &Request,
    effects_step: Option<f64>,
) -> Result<GridSpec, CompensateError> {
    let (first, last) = (targets_mm[0], targets_mm[targets_mm.len() - 1]);
    let Some(step_mm) = effects_step.or(request.step_mm) else {
        if controller.free_positions || regular_step(targets_mm).is_some() {
            return Ok(GridSpec::Targets);
        }
        return Err(CompensateError::UnevenTargets {
            count: targets_mm.len(),
            first_mm: first,
            last_mm: last,
            controller: controller.name,
        });
    };
    let start_mm = request.start_mm.unwrap_or(first);
    // A --count belongs to the --step it was given with, not to a finer step of the effects.
    let count = match request.count.filter(|_| Some(step_mm) == request.step_mm) {
        Some(count) => count,
        None => ((last - start_mm) / step_mm + 1e-9).floor().max(0.0) as usize + 1,
    };
    Ok(GridSpec::Regular {
        start_mm,
        step_mm,
        count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::{Drift, Periodic, Reversal};

    const ITNC: Capabilities = Capabilities {
        name: "iTNC 530",
        bidirectional: true,
        free_positions: false,
        resolution_mm: 0.0001,
    };

    fn targets() -> Vec<f64> {
        (0..=10).map(|i| f64::from(i) * 50.0).collect()
    }

    #[test]
    fn without_effects_a_mean_table_at_the_targets() {
        let plan = plan(&targets(), &[], &ITNC, &Request::default()).unwrap();
        assert_eq!(plan.options.mode, TableMode::Mean);
        assert_eq!(plan.options.grid, GridSpec::Targets);
        assert!(plan.notes.is_empty());
    }

    #[test]
    fn a_reversal_makes_it_bidirectional_where_the_controller_takes_it() {
        let effects = [Effect::Reversal(Reversal { b_um: -3.0 })];
        let bidirectional = plan(&targets(), &effects, &ITNC, &Request::default()).unwrap();
        assert_eq!(bidirectional.options.mode, TableMode::Bidirectional);
        let mean_only = Capabilities {
            bidirectional: false,
            name: "LinuxCNC",
            ..ITNC
        };
        let mean = plan(&targets(), &effects, &mean_only, &Request::default()).unwrap();
        assert_eq!(mean.options.mode, TableMode::Mean);
        assert!(
            mean.notes[0].contains("LinuxCNC takes no bidirectional table"),
            "{:?}",
            mean.notes
        );
        assert!(mean.notes[0].contains("B = -3.00 µm"), "{:?}", mean.notes);
        let asked = Request {
            mode: Some(TableMode::Mean),
            ..Request::default()
        };
        assert_eq!(
            plan(&targets(), &effects, &ITNC, &asked)
                .unwrap()
                .options
                .mode,
            TableMode::Mean
        );
    }

    #[test]
    fn a_periodic_error_asks_for_a_tenth_of_its_period() {
        // Period 5.3 mm: a tenth is 0.53 mm, a step the iTNC writes exactly.
        let effects = [
            Effect::Periodic(Periodic {
                period_mm: 5.3,
                amplitude_um: 1.0,
                phase_rad: 0.0,
            }),
            Effect::Drift(Drift::PerHour { rate_um_per_h: 2.0 }),
        ];
        let plan = plan(&targets(), &effects, &ITNC, &Request::default()).unwrap();
        let GridSpec::Regular {
            start_mm,
            step_mm,
            count,
        } = plan.options.grid
        else {
            panic!("{:?}", plan.options.grid)
        };
        assert_eq!(start_mm, 0.0);
        assert!((step_mm - 0.53).abs() < 1e-12, "{step_mm}");
        // floor(500 / 0.53) + 1 points: 943 + 1.
        assert_eq!(count, 944);
        assert_eq!(plan.notes.len(), 2, "{:?}", plan.notes);
        assert!(
            plan.notes[1].starts_with("drift of 2.00 µm/h"),
            "{:?}",
            plan.notes
        );
    }

    #[test]
    fn uneven_targets_need_a_step_where_the_controller_takes_only_one() {
        let uneven = [0.0, 10.0, 25.0, 40.0];
        let error = plan(&uneven, &[], &ITNC, &Request::default()).unwrap_err();
        assert!(
            error.to_string().contains("iTNC 530 needs one step"),
            "{error}"
        );
        let free = Capabilities {
            free_positions: true,
            ..ITNC
        };
        assert_eq!(
            plan(&uneven, &[], &free, &Request::default())
                .unwrap()
                .options
                .grid,
            GridSpec::Targets
        );
    }
}
