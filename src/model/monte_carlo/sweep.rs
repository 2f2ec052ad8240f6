//! The sensitivity sweep: the maximum volumetric error as one tolerance, or
//! all six straightness tolerances together, is varied over a list of values.

use super::{CarriageFace, RailDirection, StudyOptions, Tolerances, tolerance_study};
use crate::model::ModelError;
use crate::model::components::Axis;
use crate::model::machine::Machine;
use crate::model::stats::linear_slope;

/// A tolerance varied in the sensitivity sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweptTolerance {
    /// One of the six straightness tolerances; the others stay at the base value.
    Straightness(Axis, RailDirection),
    /// All six straightness tolerances together (Tab. 4.12).
    AllStraightness,
    /// One of the six carriage-side tolerances; the others stay at the base value.
    Carriage(Axis, CarriageFace),
}

/// Which side of a guideway a swept tolerance is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The rail mounting surfaces (Valášek's six).
    Rail,
    /// The saddle's carriage mounting faces.
    Carriage,
    /// All six rail surfaces together.
    All,
}

impl Side {
    /// `rail`, `carriage` or `all`.
    pub fn as_str(self) -> &'static str {
        match self {
            Side::Rail => "rail",
            Side::Carriage => "carriage",
            Side::All => "all",
        }
    }
}

impl SweptTolerance {
    /// The six rail tolerances in Valášek's order (X↑, X→, Y↑, Y→, Z↑, Z→),
    /// all six together, then the six carriage-side tolerances (X
    /// parallelism, X flatness, Y …, Z …).
    pub fn all() -> Vec<SweptTolerance> {
        let mut list: Vec<SweptTolerance> = Axis::ALL
            .into_iter()
            .flat_map(|axis| {
                RailDirection::BOTH.map(|direction| SweptTolerance::Straightness(axis, direction))
            })
            .collect();
        list.push(SweptTolerance::AllStraightness);
        list.extend(
            Axis::ALL.into_iter().flat_map(|axis| {
                CarriageFace::BOTH.map(|face| SweptTolerance::Carriage(axis, face))
            }),
        );
        list
    }

    /// `X.normal`, …, `Z.lateral`, `all`, or `X.carriage_parallelism`, …, `Z.carriage_flatness`.
    pub fn name(self) -> String {
        match self {
            SweptTolerance::Straightness(axis, direction) => {
                format!("{axis}.{}", direction.as_str())
            }
            SweptTolerance::AllStraightness => "all".to_string(),
            SweptTolerance::Carriage(axis, face) => format!("{axis}.carriage_{}", face.as_str()),
        }
    }

    /// The side of the guideway it is on.
    pub fn side(self) -> Side {
        match self {
            SweptTolerance::Straightness(..) => Side::Rail,
            SweptTolerance::AllStraightness => Side::All,
            SweptTolerance::Carriage(..) => Side::Carriage,
        }
    }

    pub(super) fn apply(self, tolerances: &mut Tolerances, value_mm: f64) {
        match self {
            SweptTolerance::Straightness(axis, direction) => {
                tolerances.set_straightness(axis, direction, value_mm);
            }
            SweptTolerance::AllStraightness => tolerances.straightness_mm = [[value_mm; 2]; 3],
            SweptTolerance::Carriage(axis, face) => tolerances.set_carriage(axis, face, value_mm),
        }
    }
}

/// One row of the sensitivity table (Tabs 4.6–4.12, 4.14).
#[derive(Clone, Debug, PartialEq)]
pub struct Sensitivity {
    /// What was varied.
    pub tolerance: SweptTolerance,
    /// The values it took, mm.
    pub values_mm: Vec<f64>,
    /// P90 of the maximum volumetric error at each value, mm.
    pub p90_mm: Vec<f64>,
    /// Least-squares slope of P90 over the tolerance (mm per mm; the
    /// Valášek's "linear trend slope" in µm/mm is 1000 times this).
    pub slope: Option<f64>,
}

/// Runs the study once per tolerance and value (the base options with that
/// tolerance changed, same seed) and fits the slopes. `base_p90_mm` is the
/// P90 of the base study, already run; a run whose tolerances equal the base
/// or an earlier run is not repeated (with the same seed its result would
/// be identical). `progress` counts the samples of the runs made, which are
/// [`sweep_runs`] of them.
pub fn sensitivity_sweep(
    machine: &Machine,
    base: &StudyOptions,
    base_p90_mm: f64,
    swept: &[SweptTolerance],
    values_mm: &[f64],
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<Sensitivity>, ModelError> {
    let mut done: Vec<(Tolerances, f64)> = vec![(base.tolerances, base_p90_mm)];
    let mut rows = Vec::with_capacity(swept.len());
    for tolerance in swept {
        let mut p90_mm = Vec::with_capacity(values_mm.len());
        for value in values_mm {
            let mut options = *base;
            tolerance.apply(&mut options.tolerances, *value);
            let known = done.iter().find(|(t, _)| *t == options.tolerances);
            let p90 = match known {
                Some((_, p90)) => *p90,
                None => {
                    let p90 = tolerance_study(machine, &options, progress)?.summary.p90;
                    done.push((options.tolerances, p90));
                    p90
                }
            };
            p90_mm.push(p90);
        }
        rows.push(Sensitivity {
            tolerance: *tolerance,
            values_mm: values_mm.to_vec(),
            slope: linear_slope(values_mm, &p90_mm),
            p90_mm,
        });
    }
    Ok(rows)
}

/// How many studies [`sensitivity_sweep`] runs besides the base (for a progress bar).
pub fn sweep_runs(base: &Tolerances, swept: &[SweptTolerance], values_mm: &[f64]) -> usize {
    let mut seen: Vec<Tolerances> = vec![*base];
    for tolerance in swept {
        for value in values_mm {
            let mut tolerances = *base;
            tolerance.apply(&mut tolerances, *value);
            if !seen.contains(&tolerances) {
                seen.push(tolerances);
            }
        }
    }
    seen.len() - 1
}
