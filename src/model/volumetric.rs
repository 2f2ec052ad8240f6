//! The volumetric error of a three-axis machine from its 21 geometric errors:
//! the kinematic chain, evaluated with full homogeneous transforms or to first order.
//!
//! Valášek (2021) §2.4 and §3.3 (`../shared/notes/seed000-volumetric-model.md` §2).
//! Each branch of the machine (frame → tool, frame → workpiece) is a product
//! of 4 × 4 matrices: fixed offsets between joints (eqs 54–56), the axis
//! motions, the error matrices T_E of each axis (eqs 48–50, linearised
//! rotations I + \[ε\]× as in Valášek (2021)) and the squareness matrices (eqs
//! 51–53). The deviation of a branch is where its functional point goes with
//! the errors minus where it goes without (eqs 61–66); the volumetric error
//! combines the two branches (eq. 67) and subtracts its value at the
//! reference position (eq. 68, the machine origin in Valášek (2021)); the
//! rotational error is the sum of the angles (eq. 69), not zeroed.
//!
//! # The chain, generalised from eqs 63 and 64
//!
//! A branch lists its axes from the frame outwards. Each joint contributes
//!
//! - `T(offset)`: from the previous joint's error frame (or the frame origin)
//!   to this one's, at position 0;
//! - with `error_frame = "moving"` (the error motion is referred to a point
//!   on the moving body, such as the centre of its carriages; eq. 63 for Z,
//!   eq. 64 for Y): the squareness matrices attached to this axis, then
//!   `T(σ q e)`, then `T_E(q)`;
//! - with `error_frame = "fixed"` (referred to a point fixed on the carrying
//!   body, which the moving body slides past; eq. 64 for X, whose
//!   `T_x(−X) · T_EX0Y · T_x(X) · T_EX(X)` leaves the X-error frame under the
//!   tool): `T(σ q e)`, the squareness matrices, `T(−σ q e)`, `T_E(q)`.
//!
//! σ = ±1 is the direction the body moves when its coordinate grows. The
//! tool branch ends with `T(tool offset)` at the tool tip (eq. 59); the
//! workpiece branch with `T(workpiece offset)` and the workpiece point: the
//! given point at position 0 (eq. 60 at X = Y = Z = 0), moved with the
//! position so that it stays under the tool tip in the ideal machine (this
//! reproduces eq. 60's `250 − Y(t)` and `550 + Z(t)`). A squareness error
//! is attached to the outer of its two axes when both are in one branch,
//! otherwise to the tool-branch axis (eqs 63/64: EXOY to X, EXOZ and EYOZ
//! to Z), in the order EYOZ, EXOZ, EXOY.
//!
//! Eq. 57 (the ideal tool chain) prints `T_x(X(t))` where eq. 63 and the
//! machine have `T_z(Z(t))`; the ideal chain here is always the error chain
//! with every error zero, which is the corrected form.
//!
//! # Two evaluations
//!
//! [`Method::Full`] multiplies the matrices (second-order products of errors
//! kept); [`Method::FirstOrder`] sums δ + ε × r over the error frames, where
//! r is the ideal lever arm from the frame to the functional point (an affine
//! function of the position, precomputed). For µm-level errors the two agree
//! to about 1e-9 mm (tested). The first-order form for Valášek's ZFYX
//! chain is the notes' §2.5 expansion, which the tests check term by term.

use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

use super::ModelError;
use super::components::{Axis, ErrorValues, GeometricErrors, SquarenessPair};
use super::description::{BranchDeviations, Description, ErrorFrame};

/// How to evaluate the chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Multiply the 4 × 4 matrices (eqs 63–68 as written).
    Full,
    /// Keep only terms linear in the errors (notes §2.5).
    FirstOrder,
}

/// The volumetric error at one machine position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumetricError {
    /// E_X, E_Y, E_Z (eq. 68), mm: zero at the machine's reference position.
    pub translation_mm: Vector3<f64>,
    /// E_A, E_B, E_C (eq. 69), rad: the combined rotation, not zeroed.
    pub rotation_rad: Vector3<f64>,
}

/// The positions of a rectangular grid over the work volume, per axis, mm.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    axes_mm: [Vec<f64>; 3],
}

impl Grid {
    /// A grid with these points along X, Y and Z, mm, as they are (the
    /// caller made them in order).
    pub(crate) fn of_points(axes_mm: [Vec<f64>; 3]) -> Grid {
        Grid { axes_mm }
    }

    /// A grid from explicit positions per axis (finite, strictly increasing, at least one each).
    pub fn from_axes(axes_mm: [Vec<f64>; 3]) -> Result<Grid, ModelError> {
        for (axis, points) in Axis::ALL.iter().zip(&axes_mm) {
            let increasing = points.windows(2).all(|pair| pair[0] < pair[1]);
            if points.is_empty() || !increasing || points.iter().any(|p| !p.is_finite()) {
                return Err(ModelError::invalid(
                    format!("grid {axis}"),
                    "finite, strictly increasing positions",
                    format!("{points:?}"),
                ));
            }
        }
        Ok(Grid { axes_mm })
    }

    /// The positions along one axis, mm.
    pub fn axis_mm(&self, axis: Axis) -> &[f64] {
        &self.axes_mm[axis.index()]
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.axes_mm.iter().map(Vec::len).product()
    }

    /// Never true for a grid built by the constructors; here for completeness.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The position of point `index`, X slowest and Z fastest (the order of [`ErrorMap::errors`]).
    pub fn position_mm(&self, index: usize) -> [f64; 3] {
        let [_, ny, nz] = self.counts();
        let l = index % nz;
        let j = (index / nz) % ny;
        let i = index / (nz * ny);
        [self.axes_mm[0][i], self.axes_mm[1][j], self.axes_mm[2][l]]
    }

    /// Points per axis.
    pub fn counts(&self) -> [usize; 3] {
        [
            self.axes_mm[0].len(),
            self.axes_mm[1].len(),
            self.axes_mm[2].len(),
        ]
    }
}

/// The volumetric error at every point of a grid.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorMap {
    /// The grid.
    pub grid: Grid,
    /// One error per grid point, X slowest and Z fastest ([`Grid::position_mm`]).
    pub errors: Vec<VolumetricError>,
}

impl ErrorMap {
    /// The largest ‖E‖ (eq. 71) and where it occurs: Valášek's measure of a machine.
    pub fn max_translation(&self) -> (f64, [f64; 3]) {
        let mut best = (0.0, self.grid.position_mm(0));
        for (index, error) in self.errors.iter().enumerate() {
            let norm = error.translation_mm.norm();
            if norm > best.0 {
                best = (norm, self.grid.position_mm(index));
            }
        }
        best
    }
}

impl Kinematics {
    /// The volumetric error at `position_mm`, zeroed at the reference (eq. 68).
    pub(crate) fn volumetric_error(
        &self,
        errors: &GeometricErrors,
        position_mm: [f64; 3],
        method: Method,
    ) -> VolumetricError {
        let kinematics = self;
        let at = kinematics.raw_error(&errors.values_at(position_mm), position_mm, method);
        let reference = kinematics.reference_mm;
        let at_reference = kinematics.raw_error(&errors.values_at(reference), reference, method);
        VolumetricError {
            translation_mm: at.translation_mm - at_reference.translation_mm,
            rotation_rad: at.rotation_rad,
        }
    }

    /// The volumetric error at every point of `grid`.
    pub(crate) fn error_map(
        &self,
        errors: &GeometricErrors,
        grid: &Grid,
        method: Method,
    ) -> ErrorMap {
        let kinematics = self;
        let reference = kinematics.reference_mm;
        let at_reference = kinematics.raw_error(&errors.values_at(reference), reference, method);
        let errors = (0..grid.len())
            .map(|index| {
                let position = grid.position_mm(index);
                let at = kinematics.raw_error(&errors.values_at(position), position, method);
                VolumetricError {
                    translation_mm: at.translation_mm - at_reference.translation_mm,
                    rotation_rad: at.rotation_rad,
                }
            })
            .collect();
        ErrorMap {
            grid: grid.clone(),
            errors,
        }
    }
}

/// An affine function of the machine position: `constant + linear · q`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Affine {
    pub constant: Vector3<f64>,
    pub linear: Matrix3<f64>,
}

impl Affine {
    const ZERO: Affine = Affine {
        constant: Vector3::new(0.0, 0.0, 0.0),
        linear: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };

    fn at(&self, position_mm: [f64; 3]) -> Vector3<f64> {
        self.constant + self.linear * Vector3::from(position_mm)
    }

    fn plus(&self, other: &Affine) -> Affine {
        Affine {
            constant: self.constant + other.constant,
            linear: self.linear + other.linear,
        }
    }
}

/// A first-order term: the sign of its branch in eq. 67 and the lever arm
/// from its error frame to the functional point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SignedArm {
    pub sign: f64,
    pub arm: Affine,
}

/// The linearised chain: E = Σ_axes s (δ + ε × r(q)) + Σ_pairs s ψ × r(q).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FirstOrderTerms {
    /// Per axis (X, Y, Z).
    pub axis: [SignedArm; 3],
    /// Per squareness pair (XY, XZ, YZ).
    pub squareness: [SignedArm; 3],
}

/// One factor of a branch's chain.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Element {
    /// A fixed offset, mm.
    Offset(Vector3<f64>),
    /// The body moves by `sign · q` along `axis`.
    Motion { axis: Axis, sign: f64 },
    /// The error matrix T_E of an axis (eqs 48–50).
    Error(Axis),
    /// A squareness matrix (eqs 51–53).
    Squareness(SquarenessPair),
}

impl Element {
    /// The ideal (error-free) translation of this factor, as a function of q.
    fn ideal(&self) -> Affine {
        match *self {
            Element::Offset(offset) => Affine {
                constant: offset,
                linear: Matrix3::zeros(),
            },
            Element::Motion { axis, sign } => {
                let mut linear = Matrix3::zeros();
                linear[(axis.index(), axis.index())] = sign;
                Affine {
                    constant: Vector3::zeros(),
                    linear,
                }
            }
            Element::Error(_) | Element::Squareness(_) => Affine::ZERO,
        }
    }

    /// The factor's matrix with the errors in.
    fn matrix(&self, position_mm: [f64; 3], values: &ErrorValues) -> Matrix4<f64> {
        match *self {
            Element::Offset(_) | Element::Motion { .. } => {
                Matrix4::new_translation(&self.ideal().at(position_mm))
            }
            Element::Error(axis) => {
                let k = axis.index();
                small_motion(
                    Vector3::from(values.rotation_rad[k]),
                    Vector3::from(values.translation_mm[k]),
                )
            }
            Element::Squareness(pair) => {
                small_motion(squareness_rotation(pair, values), Vector3::zeros())
            }
        }
    }
}

/// The rotation vector of a squareness error: its angle about the third axis.
fn squareness_rotation(pair: SquarenessPair, values: &ErrorValues) -> Vector3<f64> {
    let mut rotation = Vector3::zeros();
    rotation[pair.rotation_axis().index()] = values.squareness.get(pair);
    rotation
}

/// The linearised error matrix of eqs 48–53: rotation block I + [ε]×, translation δ.
fn small_motion(rotation: Vector3<f64>, translation: Vector3<f64>) -> Matrix4<f64> {
    let (a, b, c) = (rotation.x, rotation.y, rotation.z);
    #[rustfmt::skip]
    let matrix = Matrix4::new(
        1.0, -c, b, translation.x,
        c, 1.0, -a, translation.y,
        -b, a, 1.0, translation.z,
        0.0, 0.0, 0.0, 1.0,
    );
    matrix
}

/// A machine's chain, compiled from its description.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Kinematics {
    tool: Vec<Element>,
    workpiece: Vec<Element>,
    /// The workpiece functional point in the last workpiece frame.
    workpiece_point: Affine,
    /// +1 (sum, Valášek (2021)) or −1 (difference) for the workpiece branch.
    workpiece_sign: f64,
    pub reference_mm: [f64; 3],
    pub terms: FirstOrderTerms,
}

/// The uncorrected (not yet zeroed) error of eq. 67 and the rotation of eq. 69.
struct RawError {
    translation_mm: Vector3<f64>,
    rotation_rad: Vector3<f64>,
}

impl Kinematics {
    /// Compiles the chain of a machine whose description has been validated.
    pub(crate) fn compile(machine: &Description) -> Kinematics {
        let mut tool = Vec::new();
        for axis in machine.chain.tool_axes() {
            push_joint(&mut tool, machine, *axis);
        }
        tool.push(Element::Offset(Vector3::from(machine.tool_offset_mm)));
        let mut workpiece = Vec::new();
        for axis in machine.chain.workpiece_axes() {
            push_joint(&mut workpiece, machine, *axis);
        }
        workpiece.push(Element::Offset(Vector3::from(machine.workpiece_offset_mm)));

        // The workpiece point follows the tool tip in the ideal machine:
        // r(q) = r(0) + [p_tool(q) − t_workpiece(q)] − [p_tool(0) − t_workpiece(0)].
        let motion_of = |elements: &[Element]| -> Matrix3<f64> {
            elements.iter().map(|e| e.ideal().linear).sum()
        };
        let workpiece_point = Affine {
            constant: Vector3::from(machine.workpiece_point_mm),
            linear: motion_of(&tool) - motion_of(&workpiece),
        };
        let workpiece_sign = match machine.branch_deviations {
            BranchDeviations::Sum => 1.0,
            BranchDeviations::Difference => -1.0,
        };
        let mut terms = FirstOrderTerms {
            axis: [SignedArm {
                sign: 0.0,
                arm: Affine::ZERO,
            }; 3],
            squareness: [SignedArm {
                sign: 0.0,
                arm: Affine::ZERO,
            }; 3],
        };
        for (elements, point, sign) in [
            (&tool, Affine::ZERO, 1.0),
            (&workpiece, workpiece_point, workpiece_sign),
        ] {
            // The arm of a factor is the sum of the ideal translations after it, plus the point.
            let mut arm = point;
            for element in elements.iter().rev() {
                match *element {
                    Element::Error(axis) => terms.axis[axis.index()] = SignedArm { sign, arm },
                    Element::Squareness(pair) => {
                        let index = SquarenessPair::ALL
                            .iter()
                            .position(|p| *p == pair)
                            .unwrap_or(0);
                        terms.squareness[index] = SignedArm { sign, arm };
                    }
                    _ => arm = arm.plus(&element.ideal()),
                }
            }
        }
        Kinematics {
            tool,
            workpiece,
            workpiece_point,
            workpiece_sign,
            reference_mm: machine.reference_mm,
            terms,
        }
    }

    fn raw_error(&self, values: &ErrorValues, position_mm: [f64; 3], method: Method) -> RawError {
        match method {
            Method::Full => {
                let (tool_deviation, tool_rotation) =
                    branch_deviation(&self.tool, Vector3::zeros(), position_mm, values);
                let point = self.workpiece_point.at(position_mm);
                let (workpiece_deviation, workpiece_rotation) =
                    branch_deviation(&self.workpiece, point, position_mm, values);
                RawError {
                    translation_mm: tool_deviation + self.workpiece_sign * workpiece_deviation,
                    rotation_rad: tool_rotation + self.workpiece_sign * workpiece_rotation,
                }
            }
            Method::FirstOrder => {
                let mut translation = Vector3::zeros();
                let mut rotation = Vector3::zeros();
                for axis in Axis::ALL {
                    let k = axis.index();
                    let term = &self.terms.axis[k];
                    let epsilon = Vector3::from(values.rotation_rad[k]);
                    let delta = Vector3::from(values.translation_mm[k]);
                    translation += term.sign * (delta + epsilon.cross(&term.arm.at(position_mm)));
                    rotation += term.sign * epsilon;
                }
                for (index, pair) in SquarenessPair::ALL.iter().enumerate() {
                    let term = &self.terms.squareness[index];
                    let psi = squareness_rotation(*pair, values);
                    translation += term.sign * psi.cross(&term.arm.at(position_mm));
                    rotation += term.sign * psi;
                }
                RawError {
                    translation_mm: translation,
                    rotation_rad: rotation,
                }
            }
        }
    }
}

/// Appends one joint's factors (see the module documentation).
fn push_joint(elements: &mut Vec<Element>, machine: &Description, axis: Axis) {
    let description = &machine.axes[axis.index()];
    let sign = description.motion;
    elements.push(Element::Offset(Vector3::from(description.offset_mm)));
    let attached = [SquarenessPair::YZ, SquarenessPair::XZ, SquarenessPair::XY]
        .into_iter()
        .filter(|pair| machine.chain.squareness_axis(*pair) == axis)
        .map(Element::Squareness);
    match description.error_frame {
        ErrorFrame::Moving => {
            elements.extend(attached);
            elements.push(Element::Motion { axis, sign });
        }
        ErrorFrame::Fixed => {
            elements.push(Element::Motion { axis, sign });
            elements.extend(attached);
            elements.push(Element::Motion { axis, sign: -sign });
        }
    }
    elements.push(Element::Error(axis));
}

/// Deviation of one branch's functional point (with errors minus ideal) and
/// the branch's rotation (the vector of the skew part of its rotation block).
fn branch_deviation(
    elements: &[Element],
    point_mm: Vector3<f64>,
    position_mm: [f64; 3],
    values: &ErrorValues,
) -> (Vector3<f64>, Vector3<f64>) {
    let mut transform = Matrix4::identity();
    let mut ideal = Vector3::zeros();
    for element in elements {
        transform *= element.matrix(position_mm, values);
        ideal += element.ideal().at(position_mm);
    }
    let moved = transform * Vector4::new(point_mm.x, point_mm.y, point_mm.z, 1.0);
    let deviation = moved.xyz() - (ideal + point_mm);
    let rotation = Vector3::new(
        (transform[(2, 1)] - transform[(1, 2)]) / 2.0,
        (transform[(0, 2)] - transform[(2, 0)]) / 2.0,
        (transform[(1, 0)] - transform[(0, 1)]) / 2.0,
    );
    (deviation, rotation)
}
