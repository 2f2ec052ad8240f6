//! The Monte Carlo tolerance study (Valášek (2021) §3.4–3.5, §4): random machines
//! built from straightness tolerances, and the distribution of their maximum
//! volumetric error; the sensitivity sweep over the six straightness
//! tolerances; and the single-axis study of the guideway model.
//!
//! # One random machine (notes §4.1)
//!
//! For each axis X, Y, Z in turn, the generator ([`ProfileShape`]) draws four
//! rail profiles over [−b/2, stroke + b/2] (rail 1 normal, rail 1 lateral,
//! rail 2 normal, rail 2 lateral, with the axis's normal and lateral
//! straightness tolerances) and one positioning profile over the stroke
//! (the positioning tolerance); then the squareness errors EXOY, EXOZ, EYOZ
//! are drawn uniform in ±their tolerance (eq. 80). The guideway model turns
//! the rails into straightness, roll, pitch and yaw along the stroke, mapped
//! to the ISO errors as the machine description says (Tab. 3.2). The
//! machine's measure is the largest ‖E‖ over the grid (eq. 71), with E from
//! the first-order chain and zeroed at the reference position.
//!
//! The carriage side (the carriage-side thesis (references.md) Obr. 8; [`super::guideway::SaddleFaces`]):
//! each saddle's four pads get a tilt across and along the rails, Δ_a and
//! Δ_b each uniform in ±half the axis's parallelism tolerance t (so the
//! pads' plane stays in a zone of width t: |Δ_a| + |Δ_b| ≤ t), and a twist c
//! uniform in ±half its flatness tolerance (flatness 2|c| ≤ t). They
//! add to the rail deviations under the carriages through the same guideway
//! weights, the same at every position: constant roll, pitch and
//! straightness offsets of the moving body.
//!
//! Every number is drawn even when its tolerance is zero, and profiles are
//! drawn in units of their tolerance, so studies that differ only in
//! tolerances see the same random shapes (common random numbers): the
//! sensitivity curves are smooth and Valášek's Tab. 4.12 linearity
//! (all tolerances scaled together) holds exactly.
//!
//! # Speed and determinism
//!
//! What does not change between samples is computed once (the plan): the
//! spline basis rows at the carriage positions of every grid coordinate (as
//! the NumPy reference `mc_peer.py` does), the guideway weights, and the lever arms of the
//! linearised chain. A sample then costs a few small matrix-vector products
//! and one pass over the grid, which uses that the first-order error is a
//! sum of functions of one coordinate and products of one coordinate's
//! function with another coordinate. Nothing is allocated per sample.
//!
//! Samples are grouped in batches of [`BATCH_SIZE`], a constant independent
//! of the thread count. Batch `i` draws from `ChaCha8Rng::seed_from_u64(seed)`
//! with `set_stream(i)`; results are written by sample index and reduced in
//! index order, so a seed gives bit-identical results on any number of
//! threads (the rand book's "deterministic multi-threaded" recipe). The
//! carriage-side numbers come from a second stream of the same seed,
//! `set_stream(CARRIAGE_STREAM + i)`, so the rail, positioning and
//! squareness draws are those of a study without carriage-side tolerances:
//! with them zero a seed gives the results it gave before they existed.

mod kernel;
mod single_axis;
mod sweep;

pub use single_axis::{AxisStudyOptions, AxisStudyResult, single_axis_study};
pub use sweep::{Sensitivity, Side, SweptTolerance, sensitivity_sweep, sweep_runs};

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rayon::prelude::*;

use crate::model::ModelError;
use crate::model::components::Axis;
use crate::model::machine::Machine;
use crate::model::profile::ProfileShape;
use crate::model::stats::Summary;
use kernel::{Plan, Workspace};

/// Samples per batch: each batch has its own random stream. Changing it
/// changes every result for a given seed (the value-stability tests pin it).
pub const BATCH_SIZE: usize = 256;

/// The first stream number of the carriage-side draws (batch `i` uses
/// `CARRIAGE_STREAM + i`); far above any batch number of the rail streams.
const CARRIAGE_STREAM: u64 = 1 << 62;

/// The tolerance values of Valášek's (2021) sensitivity study (Tab. 4.4), mm.
pub const THESIS_SWEEP_MM: [f64; 5] = [0.005, 0.015, 0.03, 0.045, 0.06];

/// Which straightness of a guideway.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RailDirection {
    /// Normal to the mounting face (Valášek's "vertical").
    Normal,
    /// Across the rail (Valášek's "horizontal").
    Lateral,
}

impl RailDirection {
    /// Normal, then lateral.
    pub const BOTH: [RailDirection; 2] = [RailDirection::Normal, RailDirection::Lateral];

    /// `normal` or `lateral`.
    pub fn as_str(self) -> &'static str {
        match self {
            RailDirection::Normal => "normal",
            RailDirection::Lateral => "lateral",
        }
    }

    fn index(self) -> usize {
        match self {
            RailDirection::Normal => 0,
            RailDirection::Lateral => 1,
        }
    }
}

/// A tolerance of the saddle's carriage mounting faces (the carriage side,
/// the carriage-side thesis (references.md) Obr. 8; see [`super::guideway::SaddleFaces`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CarriageFace {
    /// The pads' plane against the saddle's datum face: constant roll and pitch.
    Parallelism,
    /// The four pads about their plane (their twist): carriage loads, and
    /// motion only where the carriages' stiffnesses differ.
    Flatness,
}

impl CarriageFace {
    /// Parallelism, then flatness.
    pub const BOTH: [CarriageFace; 2] = [CarriageFace::Parallelism, CarriageFace::Flatness];

    /// `parallelism` or `flatness`.
    pub fn as_str(self) -> &'static str {
        match self {
            CarriageFace::Parallelism => "parallelism",
            CarriageFace::Flatness => "flatness",
        }
    }

    fn index(self) -> usize {
        match self {
            CarriageFace::Parallelism => 0,
            CarriageFace::Flatness => 1,
        }
    }
}

/// The tolerances that make a random machine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Straightness of the rail mounting surfaces, `[axis][normal, lateral]`, mm.
    pub straightness_mm: [[f64; 2]; 3],
    /// Positioning tolerance of X, Y, Z (the band of the generated profile), mm.
    pub positioning_mm: [f64; 3],
    /// Largest squareness error XY, XZ, YZ (uniform in ±), rad.
    pub squareness_rad: [f64; 3],
    /// The carriage side: each axis's saddle pads, `[axis][parallelism, flatness]`, mm.
    pub carriage_mm: [[f64; 2]; 3],
}

impl Tolerances {
    /// One straightness tolerance for all six surfaces, one positioning
    /// tolerance and one squareness for all axes (Valášek (2021) Tab. 3.3 is
    /// `uniform(0.03, 0.01, 30e-6)`; its sensitivity baseline `uniform(0.03, 0.0, 0.0)`).
    pub fn uniform(straightness_mm: f64, positioning_mm: f64, squareness_rad: f64) -> Tolerances {
        Tolerances {
            straightness_mm: [[straightness_mm; 2]; 3],
            positioning_mm: [positioning_mm; 3],
            squareness_rad: [squareness_rad; 3],
            carriage_mm: [[0.0; 2]; 3],
        }
    }

    /// One carriage-side tolerance.
    pub fn carriage(&self, axis: Axis, face: CarriageFace) -> f64 {
        self.carriage_mm[axis.index()][face.index()]
    }

    /// Sets one carriage-side tolerance.
    pub fn set_carriage(&mut self, axis: Axis, face: CarriageFace, value_mm: f64) {
        self.carriage_mm[axis.index()][face.index()] = value_mm;
    }

    /// One straightness tolerance.
    pub fn straightness(&self, axis: Axis, direction: RailDirection) -> f64 {
        self.straightness_mm[axis.index()][direction.index()]
    }

    /// Sets one straightness tolerance.
    pub fn set_straightness(&mut self, axis: Axis, direction: RailDirection, value_mm: f64) {
        self.straightness_mm[axis.index()][direction.index()] = value_mm;
    }

    fn check(&self) -> Result<(), ModelError> {
        let all = self
            .straightness_mm
            .iter()
            .flatten()
            .chain(&self.positioning_mm)
            .chain(&self.squareness_rad)
            .chain(self.carriage_mm.iter().flatten());
        if let Some(bad) = all.into_iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
            return Err(ModelError::invalid(
                "tolerance",
                "a finite value ≥ 0",
                bad.to_string(),
            ));
        }
        Ok(())
    }
}

/// What to run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StudyOptions {
    /// Number of random machines (at least 1).
    pub samples: usize,
    /// Master seed of the random streams.
    pub seed: u64,
    /// The tolerances.
    pub tolerances: Tolerances,
    /// The profile generator's shape.
    pub shape: ProfileShape,
    /// Grid step over the work volume, mm (Valášek's measured data used 50).
    pub grid_step_mm: f64,
}

/// The outcome of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyResult {
    /// The largest ‖E‖ over the grid of each sample, mm, in sample order.
    pub max_volumetric_mm: Vec<f64>,
    /// Its summary.
    pub summary: Summary,
}

/// Runs the study. `progress` is called with the number of samples just
/// finished (increments that add up to `samples`), from worker threads.
///
/// # Example
///
/// ```
/// use axcomp::model::monte_carlo::{StudyOptions, Tolerances, tolerance_study};
/// use axcomp::model::{Machine, ProfileShape};
///
/// let options = StudyOptions {
///     samples: 200,
///     seed: 1,
///     tolerances: Tolerances::uniform(0.03, 0.0, 0.0),
///     shape: ProfileShape::THESIS,
///     grid_step_mm: 50.0,
/// };
/// let result = tolerance_study(&Machine::bundled(), &options, &|_done| {})?;
/// assert_eq!(result.max_volumetric_mm.len(), 200);
/// assert!(result.summary.p90 > result.summary.median);
/// # Ok::<(), axcomp::model::ModelError>(())
/// ```
pub fn tolerance_study(
    machine: &Machine,
    options: &StudyOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<StudyResult, ModelError> {
    if options.samples == 0 {
        return Err(ModelError::invalid("samples", "at least 1", "0"));
    }
    let plan = Plan::new(machine, options)?;
    let mut max_volumetric_mm = vec![0.0; options.samples];
    max_volumetric_mm
        .par_chunks_mut(BATCH_SIZE)
        .enumerate()
        .for_each_init(
            || Workspace::new(&plan),
            |workspace, (batch, out)| {
                let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
                rng.set_stream(batch as u64);
                let mut carriage_rng = ChaCha8Rng::seed_from_u64(options.seed);
                carriage_rng.set_stream(CARRIAGE_STREAM + batch as u64);
                for max in out.iter_mut() {
                    *max = plan.sample(&mut rng, &mut carriage_rng, workspace);
                }
                progress(out.len() as u64);
            },
        );
    let summary = Summary::of(&max_volumetric_mm)
        .ok_or_else(|| ModelError::invalid("samples", "at least 1", "0"))?;
    Ok(StudyResult {
        max_volumetric_mm,
        summary,
    })
}

#[cfg(test)]
mod tests;
