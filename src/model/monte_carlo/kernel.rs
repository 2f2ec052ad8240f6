//! One random machine and its maximum volumetric error: the plan computed
//! once per study and the per-sample workspace (the module doc's "Speed and
//! determinism").

use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;

use super::{CarriageFace, RailDirection, StudyOptions, Tolerances};
use crate::model::ModelError;
use crate::model::components::{Axis, SquarenessPair};
use crate::model::guideway::{GuidewayMap, OutputWeights, SaddleFaces};
use crate::model::machine::Machine;
use crate::model::profile::{ProfileShape, uniform};
use crate::model::volumetric::{Affine, FirstOrderTerms, Grid};
use crate::spline::basis_matrix;

pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// What every sample of a study shares: the per-axis evaluation plan and
/// the linearised chain, precomputed once.
pub(super) struct Plan {
    pub(super) axes: [AxisPlan; 3],
    /// Per axis: the constant part of the first-order terms and the
    /// coefficients that multiply each coordinate (see [`Plan::sample`]).
    terms: FirstOrderTerms,
    squareness_rad: [f64; 3],
    shape: ProfileShape,
}

/// One axis: the grid coordinates (the reference position appended last),
/// the basis rows there, the guideway weights, the mapping and the tolerances.
pub(super) struct AxisPlan {
    axis: Axis,
    /// Grid coordinates; the last entry is the reference coordinate.
    pub(super) coordinates_mm: Vec<f64>,
    rail_knots: usize,
    /// Spline weights at coordinate − b/2 and + b/2 (carriages behind and
    /// ahead) and at the coordinate (positioning), knot-major:
    /// `[knot · coordinates + index]`.
    behind: Vec<f64>,
    ahead: Vec<f64>,
    positioning_knots: usize,
    positioning: Vec<f64>,
    /// z5, roll, pitch from the normal deviations; y5, yaw from the lateral ones.
    normal: [OutputWeights; 3],
    lateral: [OutputWeights; 2],
    /// Index of the translation fed by z5 and y5, and the rotation fed by
    /// pitch (lateral direction) and yaw (normal direction).
    normal_direction: usize,
    lateral_direction: usize,
    signs: [f64; 5],
    tolerance_normal_mm: f64,
    tolerance_lateral_mm: f64,
    tolerance_positioning_mm: f64,
    tolerance_parallelism_mm: f64,
    tolerance_flatness_mm: f64,
}

impl Plan {
    pub(super) fn new(machine: &Machine, options: &StudyOptions) -> Result<Plan, ModelError> {
        options.tolerances.check()?;
        options.shape.check()?;
        let grid = Grid::over_strokes(machine, options.grid_step_mm)?;
        let reference = machine.reference_mm();
        let axes = Axis::ALL.map(|axis| {
            let mut coordinates_mm = grid.axis_mm(axis).to_vec();
            coordinates_mm.push(reference[axis.index()]);
            AxisPlan::new(
                machine,
                axis,
                coordinates_mm,
                &options.shape,
                &options.tolerances,
            )
        });
        Ok(Plan {
            axes,
            terms: machine.kinematics().terms,
            squareness_rad: options.tolerances.squareness_rad,
            shape: options.shape,
        })
    }

    /// One random machine: draws its errors into `workspace` and returns
    /// the largest ‖E‖ over the grid, mm.
    ///
    /// The first-order error (see `volumetric`) is
    /// E(q) = Σ_k s_k [δ_k(q_k) + ε_k(q_k) × (c_k + M_k q)] + Σ_p s_p ψ_p × (c_p + M_p q).
    /// Splitting M q by coordinate gives
    /// E(q) = Σ_k g_k(q_k) + Σ_{k ≠ j} m_kj(q_k) q_j with
    /// g_k = s_k [δ_k + ε_k × c_k + q_k ε_k × M_k e_k] + q_k Σ_p s_p ψ_p × M_p e_k
    /// (plus the constant Σ_p s_p ψ_p × c_p, put into g_X) and
    /// m_kj = s_k ε_k × M_k e_j, all tabulated over each axis's coordinates.
    pub(super) fn sample(
        &self,
        rng: &mut ChaCha8Rng,
        carriage_rng: &mut ChaCha8Rng,
        workspace: &mut Workspace,
    ) -> f64 {
        for (axis_plan, walks) in self.axes.iter().zip(workspace.walks.iter_mut()) {
            axis_plan.draw_walks(rng, &self.shape, walks);
        }
        let mut squareness = [0.0; 3];
        for (value, tolerance) in squareness.iter_mut().zip(self.squareness_rad) {
            *value = tolerance * uniform(rng, -1.0, 1.0);
        }
        let faces = self
            .axes
            .each_ref()
            .map(|axis_plan| axis_plan.draw_faces(carriage_rng));
        self.evaluate(&squareness, &faces, workspace)
    }

    /// The largest ‖E‖ of the machine whose walks are in `workspace`, with
    /// the given squareness errors and saddle faces.
    pub(super) fn evaluate(
        &self,
        squareness_rad: &[f64; 3],
        faces: &[SaddleFaces; 3],
        workspace: &mut Workspace,
    ) -> f64 {
        let Workspace {
            walks,
            errors,
            behind,
            ahead,
            positioning,
            ..
        } = workspace;
        for (k, axis_plan) in self.axes.iter().enumerate() {
            axis_plan.fill(
                &walks[k],
                &faces[k],
                behind,
                ahead,
                positioning,
                &mut errors[k],
            );
        }
        self.tabulate(squareness_rad, workspace);
        workspace.max_norm(&self.axes)
    }

    /// Fills the g and m tables of the workspace from its axis errors.
    pub(super) fn tabulate(&self, squareness: &[f64; 3], workspace: &mut Workspace) {
        let Workspace {
            errors, g, cross, ..
        } = workspace;
        // The squareness terms: linear in each coordinate, plus a constant.
        let mut squareness_slope = [Vector3::zeros(); 3];
        let mut squareness_constant = Vector3::zeros();
        for (index, pair) in SquarenessPair::ALL.iter().enumerate() {
            let term = &self.terms.squareness[index];
            let mut psi = Vector3::zeros();
            psi[pair.rotation_axis().index()] = squareness[index] * term.sign;
            squareness_constant += psi.cross(&term.arm.constant);
            for (k, slope) in squareness_slope.iter_mut().enumerate() {
                *slope += psi.cross(&term.arm.linear.column(k).into_owned());
            }
        }
        for (k, axis_plan) in self.axes.iter().enumerate() {
            let term = &self.terms.axis[k];
            let arm: &Affine = &term.arm;
            let own_column: Vector3<f64> = arm.linear.column(k).into_owned();
            let axis_errors = &errors[k];
            for (p, q) in axis_plan.coordinates_mm.iter().enumerate() {
                let delta = Vector3::new(
                    axis_errors.translation[0][p],
                    axis_errors.translation[1][p],
                    axis_errors.translation[2][p],
                );
                let epsilon = Vector3::new(
                    axis_errors.rotation[0][p],
                    axis_errors.rotation[1][p],
                    axis_errors.rotation[2][p],
                );
                let mut value = term.sign
                    * (delta + epsilon.cross(&arm.constant) + *q * epsilon.cross(&own_column))
                    + *q * squareness_slope[k];
                if k == 0 {
                    value += squareness_constant;
                }
                for c in 0..3 {
                    g[k][c][p] = value[c];
                }
                for (slot, j) in other_axes(k).into_iter().enumerate() {
                    let column: Vector3<f64> = arm.linear.column(j).into_owned();
                    let coefficient = term.sign * epsilon.cross(&column);
                    for c in 0..3 {
                        cross[k][slot][c][p] = coefficient[c];
                    }
                }
            }
        }
    }
}

/// The two other axes of `k`, in increasing order (the slots of the cross tables).
pub(super) fn other_axes(k: usize) -> [usize; 2] {
    match k {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    }
}

impl AxisPlan {
    pub(super) fn new(
        machine: &Machine,
        axis: Axis,
        coordinates_mm: Vec<f64>,
        shape: &ProfileShape,
        tolerances: &Tolerances,
    ) -> AxisPlan {
        let description = machine.axis(axis);
        let map: &GuidewayMap = machine.guideway_map(axis);
        let half_pitch = map.carriage_pitch_mm() / 2.0;
        let [low, high] = description.stroke_mm;
        let rail_knots = shape.knots(low - half_pitch, high + half_pitch);
        let positioning_knots = shape.knots(low, high);
        let shifted =
            |shift: f64| -> Vec<f64> { coordinates_mm.iter().map(|x| x + shift).collect() };
        let signs = description.signs;
        AxisPlan {
            axis,
            rail_knots: rail_knots.len(),
            behind: transposed(
                &basis_matrix(&rail_knots, &shifted(-half_pitch)),
                rail_knots.len(),
            ),
            ahead: transposed(
                &basis_matrix(&rail_knots, &shifted(half_pitch)),
                rail_knots.len(),
            ),
            positioning_knots: positioning_knots.len(),
            positioning: transposed(
                &basis_matrix(&positioning_knots, &coordinates_mm),
                positioning_knots.len(),
            ),
            coordinates_mm,
            normal: map.normal_outputs(),
            lateral: map.lateral_outputs(),
            normal_direction: description.normal.index(),
            lateral_direction: description.lateral(axis).index(),
            signs: [
                signs.normal,
                signs.lateral,
                signs.roll,
                signs.pitch,
                signs.yaw,
            ],
            tolerance_normal_mm: tolerances.straightness(axis, RailDirection::Normal),
            tolerance_lateral_mm: tolerances.straightness(axis, RailDirection::Lateral),
            tolerance_positioning_mm: tolerances.positioning_mm[axis.index()],
            tolerance_parallelism_mm: tolerances.carriage(axis, CarriageFace::Parallelism),
            tolerance_flatness_mm: tolerances.carriage(axis, CarriageFace::Flatness),
        }
    }

    /// This axis's saddle faces: the tilts across and along the rails each
    /// uniform in ±t_parallelism/2, the twist in ±t_flatness/2 (see the
    /// module's notes). Three numbers are drawn whatever the tolerances.
    pub(super) fn draw_faces(&self, rng: &mut ChaCha8Rng) -> SaddleFaces {
        let mut draw = |tolerance: f64| tolerance * uniform(rng, -0.5, 0.5);
        SaddleFaces {
            tilt_across_mm: draw(self.tolerance_parallelism_mm),
            tilt_along_mm: draw(self.tolerance_parallelism_mm),
            twist_mm: draw(self.tolerance_flatness_mm),
        }
    }

    /// Draws this axis's walks in units of the tolerance: rail 1 normal,
    /// rail 1 lateral, rail 2 normal, rail 2 lateral, positioning.
    pub(super) fn draw_walks(
        &self,
        rng: &mut ChaCha8Rng,
        shape: &ProfileShape,
        walks: &mut [Vec<f64>; 5],
    ) {
        for walk in walks[..4].iter_mut() {
            shape.unit_walk(rng, walk);
        }
        shape.unit_walk(rng, &mut walks[4]);
    }

    /// This axis's six errors at every coordinate from its walks (Tab. 3.2
    /// mapping); `behind`, `ahead` and `positioning` are scratch buffers.
    pub(super) fn fill(
        &self,
        walks: &[Vec<f64>; 5],
        faces: &SaddleFaces,
        behind: &mut [Vec<f64>; 4],
        ahead: &mut [Vec<f64>; 4],
        positioning: &mut [f64],
        out: &mut AxisGridErrors,
    ) {
        let count = self.coordinates_mm.len();
        for rail in 0..4 {
            basis_product(&self.behind, &walks[rail], &mut behind[rail][..count]);
            basis_product(&self.ahead, &walks[rail], &mut ahead[rail][..count]);
        }
        basis_product(&self.positioning, &walks[4], &mut positioning[..count]);
        let own = self.axis.index();
        let [s_normal, s_lateral, s_roll, s_pitch, s_yaw] = self.signs;
        let [z5, roll, pitch] = &self.normal;
        let [y5, yaw] = &self.lateral;
        let (t_n, t_l) = (self.tolerance_normal_mm, self.tolerance_lateral_mm);
        let apply = |w: &OutputWeights, d: &[f64; 4]| w.constant + dot(&w.weights, d);
        // The saddle's pads add to the deviations under the carriages, the
        // same at every position: their share of z5, roll and pitch is a
        // constant (the weights are linear; the load's constant is counted once).
        let pads = faces.pad_heights_mm();
        let [z5_pads, roll_pads, pitch_pads] = [z5, roll, pitch].map(|w| dot(&w.weights, &pads));
        for p in 0..count {
            // Carriages 1, 2 on rail 1 behind and ahead; 3, 4 on rail 2 ahead
            // and behind (eqs 40–47). Rails: 0, 2 normal; 1, 3 lateral.
            let d_z = [behind[0][p], ahead[0][p], ahead[2][p], behind[2][p]].map(|d| t_n * d);
            let d_y = [behind[1][p], ahead[1][p], ahead[3][p], behind[3][p]].map(|d| t_l * d);
            out.translation[own][p] = self.tolerance_positioning_mm * positioning[p];
            out.translation[self.normal_direction][p] = s_normal * (apply(z5, &d_z) + z5_pads);
            out.translation[self.lateral_direction][p] = s_lateral * apply(y5, &d_y);
            out.rotation[own][p] = s_roll * (apply(roll, &d_z) + roll_pads);
            out.rotation[self.lateral_direction][p] = s_pitch * (apply(pitch, &d_z) + pitch_pads);
            out.rotation[self.normal_direction][p] = s_yaw * apply(yaw, &d_y);
        }
    }
}

/// `out = Bᵀ v` for a knot-major basis (`v.len()` rows of `out.len()`
/// weights): one vectorisable pass per knot instead of a dependent sum per point.
pub(super) fn basis_product(knot_major: &[f64], values: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (row, value) in knot_major.chunks_exact(out.len()).zip(values) {
        for (o, weight) in out.iter_mut().zip(row) {
            *o += weight * value;
        }
    }
}

/// Transposes a row-major `rows × columns` matrix.
pub(super) fn transposed(matrix: &[f64], columns: usize) -> Vec<f64> {
    let rows = matrix.len() / columns;
    (0..columns)
        .flat_map(|column| (0..rows).map(move |row| matrix[row * columns + column]))
        .collect()
}

/// The six errors of one axis at its coordinates: `[direction][index]`.
pub(super) struct AxisGridErrors {
    pub(super) translation: [Vec<f64>; 3],
    pub(super) rotation: [Vec<f64>; 3],
}

/// Per-thread buffers, sized once from the plan and reused for every sample.
pub(super) struct Workspace {
    /// Per axis: the four rail walks and the positioning walk, in units of the tolerance.
    pub(super) walks: [[Vec<f64>; 5]; 3],
    pub(super) errors: [AxisGridErrors; 3],
    /// g_k: `[axis][component][index]`.
    g: [[Vec<f64>; 3]; 3],
    /// m_kj: `[axis k][slot of j][component][index of k]`.
    pub(super) cross: [[[Vec<f64>; 3]; 2]; 3],
    /// A over the Y–Z plane, `[component][j · nz + l]` (see `max_norm`).
    plane: [Vec<f64>; 3],
    /// B_i over Y and C_i over Z for the current X coordinate, `[component][index]`.
    by_y: [Vec<f64>; 3],
    by_z: [Vec<f64>; 3],
    /// The largest squared norm so far at each Y–Z plane point.
    running: Vec<f64>,
    /// Rail values at the carriages behind and ahead of each coordinate, and
    /// the positioning profile: `[rail 1 normal, 1 lateral, 2 normal, 2 lateral][index]`.
    behind: [Vec<f64>; 4],
    ahead: [Vec<f64>; 4],
    positioning: Vec<f64>,
}

impl Workspace {
    pub(super) fn new(plan: &Plan) -> Workspace {
        let lengths = plan.axes.each_ref().map(|axis| axis.coordinates_mm.len());
        let table = |k: usize| -> [Vec<f64>; 3] { std::array::from_fn(|_| vec![0.0; lengths[k]]) };
        let longest = lengths.into_iter().max().unwrap_or(0);
        Workspace {
            walks: plan.axes.each_ref().map(|axis| {
                let rail = || vec![0.0; axis.rail_knots];
                [
                    rail(),
                    rail(),
                    rail(),
                    rail(),
                    vec![0.0; axis.positioning_knots],
                ]
            }),
            errors: std::array::from_fn(|k| AxisGridErrors {
                translation: table(k),
                rotation: table(k),
            }),
            g: std::array::from_fn(table),
            cross: std::array::from_fn(|k| [table(k), table(k)]),
            plane: std::array::from_fn(|_| vec![0.0; lengths[1] * lengths[2]]),
            by_y: table(1),
            by_z: table(2),
            running: vec![0.0; lengths[1] * lengths[2]],
            behind: std::array::from_fn(|_| vec![0.0; longest]),
            ahead: std::array::from_fn(|_| vec![0.0; longest]),
            positioning: vec![0.0; longest],
        }
    }

    /// max ‖E(q) − E(reference)‖ over the grid, from the g and m tables.
    ///
    /// With X coordinate i, Y coordinate j and Z coordinate l,
    /// E = A(j, l) + B_i(j) + C_i(l), where
    /// A = g_Y(j) + g_Z(l) + m_YZ(j) z_l + m_ZY(l) y_j − E(reference) is
    /// tabulated once per sample over the Y–Z plane,
    /// B_i = g_X(i) + m_XY(i) y_j + m_YX(j) x_i and C_i = m_XZ(i) z_l + m_ZX(l) x_i
    /// once per X coordinate. The squared norms are folded into a running
    /// maximum per plane point (independent lanes, no reduction chain) and
    /// reduced once at the end.
    pub(super) fn max_norm(&mut self, axes: &[AxisPlan; 3]) -> f64 {
        let x = &axes[0].coordinates_mm;
        let y = &axes[1].coordinates_mm;
        let z = &axes[2].coordinates_mm;
        let (nx, ny, nz) = (x.len() - 1, y.len() - 1, z.len() - 1);
        let Workspace {
            g,
            cross,
            plane,
            by_y,
            by_z,
            running,
            ..
        } = self;
        // Cross slots: X → [Y, Z], Y → [X, Z], Z → [X, Y].
        let point = |i: usize, j: usize, l: usize, c: usize| -> f64 {
            g[0][c][i]
                + g[1][c][j]
                + g[2][c][l]
                + cross[0][0][c][i] * y[j]
                + cross[0][1][c][i] * z[l]
                + cross[1][0][c][j] * x[i]
                + cross[1][1][c][j] * z[l]
                + cross[2][0][c][l] * x[i]
                + cross[2][1][c][l] * y[j]
        };
        let reference = [0, 1, 2].map(|c| point(nx, ny, nz, c));
        for c in 0..3 {
            for j in 0..ny {
                let row = &mut plane[c][j * nz..(j + 1) * nz];
                let (g_y, m_yz) = (g[1][c][j], cross[1][1][c][j]);
                for (l, value) in row.iter_mut().enumerate() {
                    *value =
                        g_y + g[2][c][l] + m_yz * z[l] + cross[2][1][c][l] * y[j] - reference[c];
                }
            }
        }
        running[..ny * nz].fill(0.0);
        for i in 0..nx {
            for c in 0..3 {
                for (j, value) in by_y[c][..ny].iter_mut().enumerate() {
                    *value = g[0][c][i] + cross[0][0][c][i] * y[j] + cross[1][0][c][j] * x[i];
                }
                for (l, value) in by_z[c][..nz].iter_mut().enumerate() {
                    *value = cross[0][1][c][i] * z[l] + cross[2][0][c][l] * x[i];
                }
            }
            let [c_x, c_y, c_z] = [&by_z[0][..nz], &by_z[1][..nz], &by_z[2][..nz]];
            let by_y_columns = by_y[0][..ny].iter().zip(&by_y[1][..ny]).zip(&by_y[2][..ny]);
            for (j, ((b_x, b_y), b_z)) in by_y_columns.enumerate() {
                let span = j * nz..(j + 1) * nz;
                let (a_x, a_y, a_z) = (
                    &plane[0][span.clone()],
                    &plane[1][span.clone()],
                    &plane[2][span.clone()],
                );
                let largest = &mut running[span];
                for l in 0..nz {
                    let e_x = a_x[l] + b_x + c_x[l];
                    let e_y = a_y[l] + b_y + c_y[l];
                    let e_z = a_z[l] + b_z + c_z[l];
                    let squared = e_x * e_x + e_y * e_y + e_z * e_z;
                    largest[l] = if squared > largest[l] {
                        squared
                    } else {
                        largest[l]
                    };
                }
            }
        }
        running[..ny * nz]
            .iter()
            .fold(0.0, |a: f64, b| a.max(*b))
            .sqrt()
    }
}
