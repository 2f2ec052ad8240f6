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
//!   note;
//! - a **one-direction test** gives a mean table of its one curve: the note
//!   says where the controller puts it and that the reversal (backlash) was
//!   not measured; it cannot update a table with a column per direction;
//! - an **existing table** (`--existing`) makes the table an update
//!   ([`UpdatePlan`]): referred to the existing table's own zero unless
//!   `--reference` says otherwise, every old point outside the measured range
//!   kept.
//!
//! The user's `--mode` and `--step` win, except that a step coarser than a
//! periodic error allows is refined.

use super::update::UpdatePlan;
use super::{
    CompensateError, CompensationTable, Extrapolate, GridSpec, TableMode, TableOptions,
    regular_step,
};
use crate::effects::{Effect, TableRole};
use crate::measurement::{AxisKind, Direction};

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
    /// The smallest step its format writes exactly, mm. Used only to round
    /// the step a periodic effect asks for ([`TableRole::AtPoints`]), and
    /// the effects come from an effects file, which a rotary axis is refused
    /// (`workflow::rotary`): never taken as degrees.
    pub resolution_mm: f64,
    /// Where it keeps a mean table and how it applies it ("the positive
    /// column …, applied in both directions").
    pub mean_table: &'static str,
}

/// What is known of the test and the control beyond the targets.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanContext<'a> {
    /// The one direction the test ran, when it ran only one.
    pub only_direction: Option<Direction>,
    /// The table that was active during the test (`--existing`).
    pub existing: Option<&'a CompensationTable>,
}

/// What the user asked for (`None`: let the plan decide). Positions as
/// typed, in the measured axis' unit (mm, or ° on a rotary axis): [`plan`]
/// gives them the axis' kind.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Request {
    /// `--mode`.
    pub mode: Option<TableMode>,
    /// `--step`, in the axis' unit.
    pub step: Option<f64>,
    /// `--start`, in the axis' unit.
    pub start: Option<f64>,
    /// `--count`.
    pub count: Option<usize>,
    /// `--reference`, in the axis' unit.
    pub reference: Option<f64>,
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
    /// What the table must say of itself: a one-direction test's curve and
    /// where it goes.
    pub table_notes: Vec<String>,
    /// The update of the existing table, when there is one.
    pub update: Option<UpdatePlan>,
}

/// The plan for a table of an axis of `kind` over `targets` (the
/// measured targets, ascending, in the axis' unit).
pub fn plan(
    kind: AxisKind,
    targets: &[f64],
    effects: &[Effect],
    controller: &Capabilities,
    request: &Request,
    context: &PlanContext<'_>,
) -> Result<Plan, CompensateError> {
    let mut notes = Vec::new();
    let mode = mode(effects, controller, request, &mut notes);
    let mut table_notes = one_direction(mode, controller, context)?;
    let update = match context.existing {
        Some(_) if request.extrapolate.is_some() => {
            return Err(CompensateError::ExtrapolateUpdate);
        }
        Some(existing) => Some(UpdatePlan::new(
            existing,
            kind,
            targets,
            request.reference.map(|r| kind.position(r)),
        )?),
        None => None,
    };
    let finer_step = effects_step(kind, effects, controller, request, &mut notes);
    for effect in effects {
        if let TableRole::TakenOut { note } | TableRole::NotATable { note } = effect.in_table() {
            notes.push(note);
        }
    }
    let grid = grid(
        kind,
        targets,
        controller,
        request,
        finer_step,
        &mut table_notes,
    )?;
    if let Some(update) = &update {
        check_update_grid(update, targets, grid, controller)?;
    }
    Ok(Plan {
        options: TableOptions {
            mode,
            grid,
            reference: update
                .as_ref()
                .map_or(request.reference, |u| Some(u.reference))
                .map(|r| kind.position(r)),
            // An update keeps the old values outside the measured range
            // (`UpdatePlan::apply` replaces whatever is built there).
            extrapolate: match update {
                Some(_) => Extrapolate::Hold,
                None => request.extrapolate.unwrap_or(Extrapolate::Refuse),
            },
        },
        notes,
        table_notes,
        update,
    })
}

/// A controller with one step takes an update only when the kept old
/// points lie on the new grid's step.
fn check_update_grid(
    update: &UpdatePlan,
    targets: &[f64],
    grid: GridSpec,
    controller: &Capabilities,
) -> Result<(), CompensateError> {
    if controller.free_positions {
        return Ok(());
    }
    let (first, last) = update.measured;
    let mut positions = super::grid_positions(targets, grid)?;
    positions.extend(
        update
            .existing
            .positions
            .iter()
            .filter(|&&p| p < first - 1e-9 || p > last + 1e-9),
    );
    positions.sort_by(f64::total_cmp);
    positions.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    if regular_step(&positions).is_some() {
        return Ok(());
    }
    let old = &update.existing.positions;
    let unit = update.existing.kind.unit_after_number();
    Err(CompensateError::Grid(format!(
        "the update keeps the existing table's points outside the measured range {first} … {last}{unit}, and with them the points are unevenly spaced, which {} cannot take: put the new points on the existing table's grid ({} points from {} to {}{unit}; --start, --step, --count)",
        controller.name,
        old.len(),
        old[0],
        old[old.len() - 1]
    )))
}

/// What a one-direction test's table must say: its one curve goes where the
/// controller keeps a mean table, and the reversal was not measured. A table
/// with a column per direction is not updated from one direction.
fn one_direction(
    mode: TableMode,
    controller: &Capabilities,
    context: &PlanContext<'_>,
) -> Result<Vec<String>, CompensateError> {
    let Some(direction) = context.only_direction else {
        return Ok(Vec::new());
    };
    if context
        .existing
        .is_some_and(|t| t.values.mode() == TableMode::Bidirectional)
    {
        return Err(CompensateError::OneDirectionUpdate(direction));
    }
    if mode == TableMode::Bidirectional {
        // build_table refuses it, naming the missing direction.
        return Ok(Vec::new());
    }
    Ok(vec![format!(
        "the test ran {direction} only: the table is the {direction} curve, in {}; the reversal (backlash) was not measured, so leave the backlash parameter as it is (measure both directions to check it)",
        controller.mean_table
    )])
}

fn mode(
    effects: &[Effect],
    controller: &Capabilities,
    request: &Request,
    notes: &mut Vec<String>,
) -> TableMode {
    let reversal = effects.iter().find_map(|e| match e.in_table() {
        TableRole::Bidirectional { b } => Some(b),
        _ => None,
    });
    match (request.mode, reversal) {
        (Some(mode), _) => mode,
        (None, Some(_)) if controller.bidirectional => {
            notes.push("reversal: a bidirectional table (one column per direction)".to_string());
            TableMode::Bidirectional
        }
        // B in µm: the effects are a linear axis' (`Capabilities::resolution_mm`).
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
    kind: AxisKind,
    effects: &[Effect],
    controller: &Capabilities,
    request: &Request,
    notes: &mut Vec<String>,
) -> Option<f64> {
    let finest = effects
        .iter()
        .filter_map(|e| match e.in_table() {
            TableRole::AtPoints { finest_step } => Some(finest_step),
            _ => None,
        })
        .min_by(f64::total_cmp)?;
    let resolution = controller.resolution_mm;
    let step = ((finest / resolution).floor() * resolution).max(resolution);
    let chosen = request.step.map_or(step, |given| given.min(step));
    notes.push(format!(
        "periodic: points every {chosen}{} (at most a tenth of the period), the periodic error at each point",
        kind.unit_after_number()
    ));
    Some(chosen)
}

/// The grid: the effects' finer step or `--step` (with `--start`, `--count`),
/// else the measured targets when the controller takes them.
fn grid(
    kind: AxisKind,
    targets: &[f64],
    controller: &Capabilities,
    request: &Request,
    effects_step: Option<f64>,
    notes: &mut Vec<String>,
) -> Result<GridSpec, CompensateError> {
    let (first, last) = (targets[0], targets[targets.len() - 1]);
    let Some(step) = effects_step.or(request.step) else {
        if controller.free_positions || regular_step(targets).is_some() {
            return Ok(GridSpec::Targets);
        }
        return Err(CompensateError::UnevenTargets {
            count: targets.len(),
            first: kind.position(first),
            last: kind.position(last),
            controller: controller.name,
        });
    };
    let unit = kind.unit_after_number();
    let start = request.start.unwrap_or(first);
    if request.count.is_none() && start + step > last + 1e-9 {
        return Err(CompensateError::Grid(format!(
            "the grid starts at {start}{unit} with a step of {step}{unit}, but the test measured \
             {first} … {last}{unit}: no second point lies within it (give a start below {}{unit}, or --count)",
            last - step
        )));
    }
    // A --count belongs to the --step it was given with, not to a finer step of the effects.
    let count = match request.count.filter(|_| Some(step) == request.step) {
        Some(count) => count,
        None => ((last - start) / step + 1e-9).floor().max(0.0) as usize + 1,
    };
    let end = start + (count - 1) as f64 * step;
    // The user's step is said where it falls short; the effects' fine step ends within it.
    if request.count.is_none() && request.step == Some(step) && end < last - 1e-9 {
        notes.push(format!(
            "the table ends at {end}{unit}, its last compensation point, short of the measured end \
             {last}{unit} ({start}{unit} + whole steps of {step}{unit}): to include {last}{unit} give a \
             step that divides {length}{unit}",
            end = super::round_nm(end),
            length = super::round_nm(last - start),
        ));
    }
    Ok(GridSpec::Regular {
        start: kind.position(start),
        step: kind.position(step),
        count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::{Drift, Periodic, Reversal};
    use crate::measurement::ByKind;
    use crate::units::Mm;

    const ITNC: Capabilities = Capabilities {
        name: "iTNC 530",
        bidirectional: true,
        free_positions: false,
        resolution_mm: 0.0001,
        mean_table: "its one column",
    };

    fn targets() -> Vec<f64> {
        (0..=10).map(|i| f64::from(i) * 50.0).collect()
    }

    /// The plan of a linear axis measured at [`targets`].
    fn linear_plan(
        effects: &[Effect],
        controller: &Capabilities,
        request: &Request,
        context: &PlanContext<'_>,
    ) -> Result<Plan, CompensateError> {
        plan(
            AxisKind::Linear,
            &targets(),
            effects,
            controller,
            request,
            context,
        )
    }

    #[test]
    fn without_effects_a_mean_table_at_the_targets() {
        let plan = linear_plan(&[], &ITNC, &Request::default(), &PlanContext::default()).unwrap();
        assert_eq!(plan.options.mode, TableMode::Mean);
        assert_eq!(plan.options.grid, GridSpec::Targets);
        assert!(plan.notes.is_empty());
    }

    #[test]
    fn a_reversal_makes_it_bidirectional_where_the_controller_takes_it() {
        let effects = [Effect::Reversal(Reversal { b: -3.0 })];
        let bidirectional = linear_plan(
            &effects,
            &ITNC,
            &Request::default(),
            &PlanContext::default(),
        )
        .unwrap();
        assert_eq!(bidirectional.options.mode, TableMode::Bidirectional);
        let mean_only = Capabilities {
            bidirectional: false,
            name: "LinuxCNC",
            ..ITNC
        };
        let mean = linear_plan(
            &effects,
            &mean_only,
            &Request::default(),
            &PlanContext::default(),
        )
        .unwrap();
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
            linear_plan(&effects, &ITNC, &asked, &PlanContext::default())
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
                period: 5.3,
                amplitude: 1.0,
                phase_rad: 0.0,
            }),
            Effect::Drift(Drift::PerHour { rate_um_per_h: 2.0 }),
        ];
        let plan = linear_plan(
            &effects,
            &ITNC,
            &Request::default(),
            &PlanContext::default(),
        )
        .unwrap();
        let GridSpec::Regular {
            start: ByKind::Linear(Mm(start_mm)),
            step: ByKind::Linear(Mm(step_mm)),
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

    /// An old table over −100 … 600 mm, zero at 0 mm.
    fn existing() -> CompensationTable {
        CompensationTable {
            axis: "X".into(),
            kind: AxisKind::Linear,
            positions: vec![-100.0, 0.0, 250.0, 600.0],
            values: crate::compensate::TableValues::Mean(vec![0.01, 0.0, 0.002, 0.003]),
            reference: 0.0,
            suggested_backlash: None,
        }
    }

    #[test]
    fn an_update_is_referred_to_the_existing_zero_inside_the_measured_range() {
        let free = Capabilities {
            free_positions: true,
            ..ITNC
        };
        let old = existing();
        let context = PlanContext {
            only_direction: None,
            existing: Some(&old),
        };
        let update = linear_plan(&[], &free, &Request::default(), &context).unwrap();
        assert_eq!(update.options.reference, Some(ByKind::Linear(Mm(0.0))));
        assert_eq!(update.update.unwrap().measured, (0.0, 500.0));
        // A zero the test did not measure cannot refer the update.
        let mut shifted = existing();
        shifted.reference = 600.0;
        let context = PlanContext {
            only_direction: None,
            existing: Some(&shifted),
        };
        let error = linear_plan(&[], &free, &Request::default(), &context).unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("the existing table is zero (its reference) at 600 mm is outside the measured range 0 … 500 mm"),
            "{error}"
        );
        let given = Request {
            reference: Some(250.0),
            ..Request::default()
        };
        assert_eq!(
            linear_plan(&[], &free, &given, &context)
                .unwrap()
                .options
                .reference,
            Some(ByKind::Linear(Mm(250.0)))
        );
        let extrapolate = Request {
            extrapolate: Some(Extrapolate::Hold),
            ..given
        };
        assert_eq!(
            linear_plan(&[], &free, &extrapolate, &context).unwrap_err(),
            CompensateError::ExtrapolateUpdate
        );
        // One step: the kept −100 and 600 mm leave the 50 mm grid 0 … 500 mm
        // uneven (100 mm gaps).
        let context = PlanContext {
            only_direction: None,
            existing: Some(&old),
        };
        let error = linear_plan(&[], &ITNC, &Request::default(), &context).unwrap_err();
        assert!(
            error.to_string().contains("4 points from -100 to 600 mm"),
            "{error}"
        );
    }

    #[test]
    fn a_one_direction_test_says_where_its_curve_goes() {
        let down = PlanContext {
            only_direction: Some(Direction::Down),
            existing: None,
        };
        let plan_down = linear_plan(&[], &ITNC, &Request::default(), &down).unwrap();
        assert_eq!(
            plan_down.table_notes,
            vec!["the test ran ↓ only: the table is the ↓ curve, in its one column; the reversal (backlash) was not measured, so leave the backlash parameter as it is (measure both directions to check it)".to_string()]
        );
        let mut bidirectional = existing();
        bidirectional.values = crate::compensate::TableValues::Bidirectional {
            up: vec![0.0; 4],
            down: vec![0.001; 4],
        };
        let update = PlanContext {
            existing: Some(&bidirectional),
            ..down
        };
        assert_eq!(
            linear_plan(&[], &ITNC, &Request::default(), &update).unwrap_err(),
            CompensateError::OneDirectionUpdate(Direction::Down)
        );
    }

    #[test]
    fn uneven_targets_need_a_step_where_the_controller_takes_only_one() {
        let uneven = |kind, controller: &Capabilities| {
            plan(
                kind,
                &[0.0, 10.0, 25.0, 40.0],
                &[],
                controller,
                &Request::default(),
                &PlanContext::default(),
            )
        };
        let error = uneven(AxisKind::Linear, &ITNC).unwrap_err();
        assert_eq!(
            error.to_string(),
            "the targets are unevenly spaced (4 targets from 0 to 40 mm) and iTNC 530 needs one step: give --step (and optionally --start, --count)"
        );
        // On a rotary axis the same targets are degrees.
        let rotary = uneven(AxisKind::Rotary, &ITNC).unwrap_err();
        assert_eq!(
            rotary.to_string(),
            "the targets are unevenly spaced (4 targets from 0 to 40°) and iTNC 530 needs one step: give --step (and optionally --start, --count)"
        );
        let free = Capabilities {
            free_positions: true,
            ..ITNC
        };
        assert_eq!(
            uneven(AxisKind::Linear, &free).unwrap().options.grid,
            GridSpec::Targets
        );
    }
}
