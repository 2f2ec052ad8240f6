//! The single-axis study of the guideway model: how much straighter an
//! assembled axis is than the rails it is mounted on.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rayon::prelude::*;

use super::BATCH_SIZE;
use super::kernel::{basis_product, transposed};
use crate::model::guideway::{Guideway, OutputWeights};
use crate::model::profile::ProfileShape;
use crate::model::stats::Summary;
use crate::model::{ModelError, check_positive};
use crate::spline::basis_matrix;

/// The single-axis study (Valášek (2021) §3.5.1, §4.1, Tab. 3.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisStudyOptions {
    /// Number of random axes (at least 1).
    pub samples: usize,
    /// Master seed.
    pub seed: u64,
    /// Stroke, mm (the axis runs from 0 to it).
    pub stroke_mm: f64,
    /// The guideway.
    pub guideway: Guideway,
    /// Straightness tolerance of the mounting surfaces (normal and lateral), mm.
    pub tolerance_mm: f64,
    /// The profile generator's shape.
    pub shape: ProfileShape,
    /// Step at which profiles and the axis are evaluated, mm.
    pub step_mm: f64,
}

impl AxisStudyOptions {
    /// Tab. 3.4: a = 400, b = 500, stroke 1000, tolerance 0.05 mm, 100 000 N/mm, no load;
    /// evaluated every 5 mm (the step is not in the text).
    pub fn thesis(samples: usize, seed: u64) -> AxisStudyOptions {
        AxisStudyOptions {
            samples,
            seed,
            stroke_mm: 1000.0,
            guideway: Guideway::unloaded(400.0, 500.0),
            tolerance_mm: 0.05,
            shape: ProfileShape::THESIS,
            step_mm: 5.0,
        }
    }
}

/// The improvement of straightness from the mounting surfaces to the
/// assembled axis: 1 − p-p(axis) / max(p-p(rail 1), p-p(rail 2)), as a fraction.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisStudyResult {
    /// Normal ("vertical") direction, per sample.
    pub improvement_normal: Vec<f64>,
    /// Lateral ("horizontal") direction, per sample.
    pub improvement_lateral: Vec<f64>,
    /// Summary of the normal improvement; its `p10` is Valášek's "P90"
    /// (9 of 10 axes improve at least this much).
    pub summary_normal: Summary,
    /// Summary of the lateral improvement.
    pub summary_lateral: Summary,
}

/// Runs the single-axis study: four random rails per sample through the
/// guideway model. The input straightness of the two rails is the larger of
/// their peak-to-peak values over the rail ([−b/2, stroke + b/2]); the
/// thesis does not say how it combines the two, and the maximum is the
/// conservative reading. The output is the peak-to-peak of z5 (y5) over
/// the stroke, with no reference line removed ("peak to peak", §3.2.3).
pub fn single_axis_study(
    options: &AxisStudyOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<AxisStudyResult, ModelError> {
    if options.samples == 0 {
        return Err(ModelError::invalid("samples", "at least 1", "0"));
    }
    check_positive("stroke", options.stroke_mm, "a positive length in mm")?;
    check_positive("tolerance", options.tolerance_mm, "a positive length in mm")?;
    check_positive(
        "evaluation step",
        options.step_mm,
        "a positive length in mm",
    )?;
    options.shape.check()?;
    let map = options.guideway.linear_map()?;
    let half_pitch = options.guideway.carriage_pitch_mm / 2.0;
    let knots = options
        .shape
        .knots(-half_pitch, options.stroke_mm + half_pitch);
    let rail_points = steps(-half_pitch, options.stroke_mm + half_pitch, options.step_mm);
    let axis_points = steps(0.0, options.stroke_mm, options.step_mm);
    let shifted = |shift: f64| -> Vec<f64> { axis_points.iter().map(|x| x + shift).collect() };
    let plan = AxisStudyPlan {
        n_knots: knots.len(),
        rail: transposed(&basis_matrix(&knots, &rail_points), knots.len()),
        behind: transposed(&basis_matrix(&knots, &shifted(-half_pitch)), knots.len()),
        ahead: transposed(&basis_matrix(&knots, &shifted(half_pitch)), knots.len()),
        normal: map.normal_outputs()[0],
        lateral: map.lateral_outputs()[0],
        shape: options.shape,
        tolerance_mm: options.tolerance_mm,
    };
    let mut improvements = vec![[0.0; 2]; options.samples];
    improvements
        .par_chunks_mut(BATCH_SIZE)
        .enumerate()
        .for_each_init(
            || plan.workspace(),
            |workspace, (batch, out)| {
                let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
                rng.set_stream(batch as u64);
                for improvement in out.iter_mut() {
                    *improvement = plan.sample(&mut rng, workspace);
                }
                progress(out.len() as u64);
            },
        );
    let improvement_normal: Vec<f64> = improvements.iter().map(|pair| pair[0]).collect();
    let improvement_lateral: Vec<f64> = improvements.iter().map(|pair| pair[1]).collect();
    let none = || ModelError::invalid("samples", "at least 1", "0");
    Ok(AxisStudyResult {
        summary_normal: Summary::of(&improvement_normal).ok_or_else(none)?,
        summary_lateral: Summary::of(&improvement_lateral).ok_or_else(none)?,
        improvement_normal,
        improvement_lateral,
    })
}

/// Points from `start` to `end` every `step`, the end always included.
pub(super) fn steps(start: f64, end: f64, step: f64) -> Vec<f64> {
    let mut points: Vec<f64> = (0u32..)
        .map(|i| start + f64::from(i) * step)
        .take_while(|x| *x < end - 1e-6 * step)
        .collect();
    points.push(end);
    points
}

pub(super) struct AxisStudyPlan {
    n_knots: usize,
    /// Spline weights over the rail, and at the carriages behind and ahead
    /// of each axis position, knot-major (see [`basis_product`]).
    rail: Vec<f64>,
    behind: Vec<f64>,
    ahead: Vec<f64>,
    normal: OutputWeights,
    lateral: OutputWeights,
    shape: ProfileShape,
    tolerance_mm: f64,
}

/// Per-thread buffers of the single-axis study.
pub(super) struct AxisStudyWorkspace {
    /// Rails 1 normal, 1 lateral, 2 normal, 2 lateral: knot values, mm.
    walks: [Vec<f64>; 4],
    /// One rail over its length.
    rail: Vec<f64>,
    /// Rail 1 and rail 2 behind and ahead of each axis position.
    behind: [Vec<f64>; 2],
    ahead: [Vec<f64>; 2],
}

impl AxisStudyPlan {
    pub(super) fn workspace(&self) -> AxisStudyWorkspace {
        let rail_points = self.rail.len() / self.n_knots;
        let axis_points = self.behind.len() / self.n_knots;
        AxisStudyWorkspace {
            walks: std::array::from_fn(|_| vec![0.0; self.n_knots]),
            rail: vec![0.0; rail_points],
            behind: std::array::from_fn(|_| vec![0.0; axis_points]),
            ahead: std::array::from_fn(|_| vec![0.0; axis_points]),
        }
    }

    /// One axis: rails 1 normal, 1 lateral, 2 normal, 2 lateral (the machine study's order).
    pub(super) fn sample(
        &self,
        rng: &mut ChaCha8Rng,
        workspace: &mut AxisStudyWorkspace,
    ) -> [f64; 2] {
        for walk in workspace.walks.iter_mut() {
            self.shape.unit_walk(rng, walk);
            walk.iter_mut().for_each(|v| *v *= self.tolerance_mm);
        }
        let mut improvement = [0.0; 2];
        for (direction, weights) in [(0, &self.normal), (1, &self.lateral)] {
            let mut input: f64 = 0.0;
            for (rail, walk) in [&workspace.walks[direction], &workspace.walks[direction + 2]]
                .into_iter()
                .enumerate()
            {
                basis_product(&self.rail, walk, &mut workspace.rail);
                input = input.max(peak_to_peak(&workspace.rail));
                basis_product(&self.behind, walk, &mut workspace.behind[rail]);
                basis_product(&self.ahead, walk, &mut workspace.ahead[rail]);
            }
            let (behind, ahead) = (&workspace.behind, &workspace.ahead);
            // Carriages 1, 2 on rail 1 behind and ahead; 3, 4 on rail 2 ahead and behind.
            let [w1, w2, w3, w4] = weights.weights;
            let (low, high) = (0..behind[0].len())
                .map(|p| {
                    weights.constant
                        + w1 * behind[0][p]
                        + w2 * ahead[0][p]
                        + w3 * ahead[1][p]
                        + w4 * behind[1][p]
                })
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(low, high), v| {
                    (low.min(v), high.max(v))
                });
            improvement[direction] = 1.0 - (high - low) / input;
        }
        improvement
    }
}

pub(super) fn peak_to_peak(values: &[f64]) -> f64 {
    let (low, high) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(low, high), v| {
            (low.min(*v), high.max(*v))
        });
    high - low
}
