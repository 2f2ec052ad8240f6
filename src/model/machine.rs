//! The machine description: kinematic chain, strokes, offsets, functional
//! points and guideways, as data (TOML).
//!
//! A [`Machine`] is built from a TOML text by [`Machine::from_toml_str`] (the
//! CLI reads the file and adds its path to errors) or is the bundled
//! [`Machine::bundled`], the seed's Kovosvit MAS MCV 754 Quick
//! (`fixtures/machines/mcv754-quick.toml`, which documents every assumed
//! dimension). It is validated once, when built: every number finite,
//! strokes increasing, the reference position inside them, stiffnesses
//! positive, the chain code a permutation of X, Y, Z around one F.
//!
//! # Format
//!
//! One TOML file per machine, shared with other commands: `axcomp convert`
//! reads its `[controller]` table, the model reads `[kinematics]` (and the
//! optional top-level `name`). Unknown keys under `[kinematics]` are errors,
//! so a typo cannot silently fall back to a default; other top-level tables
//! are left to their own readers.
//!
//! ```toml
//! name = "MCV 754 Quick"
//!
//! [kinematics]
//! chain = "ZFYX"                    # tool side … F … workpiece side
//! branch_deviations = "sum"         # optional: "sum" (eq. 67, default) or "difference"
//! reference_mm = [0.0, 0.0, 0.0]    # optional: where E = 0 (eq. 68), default the origin
//!
//! [kinematics.tool]
//! offset_mm = [0.0, -280.0, -250.0] # last tool-side error frame → tool tip
//!
//! [kinematics.workpiece]
//! offset_mm = [0.0, 0.0, 80.0]      # last workpiece-side error frame → workpiece reference
//! point_mm = [0.0, 250.0, 550.0]    # point under the tool at X = Y = Z = 0, from that reference
//!
//! [kinematics.axes.X]               # and [kinematics.axes.Y], [kinematics.axes.Z]
//! stroke_mm = [0.0, 750.0]
//! offset_mm = [0.0, 0.0, 200.0]     # previous error frame (or frame origin) → this axis's
//! motion = -1                       # optional, ±1 (default 1): which way the body moves
//! error_frame = "fixed"             # optional: "moving" (default) or "fixed"
//! normal = "Z"                      # direction normal to the rail mounting face
//! rail_spacing_mm = 350.0           # a
//! carriage_pitch_mm = 640.0         # b
//! # optional: stiffness_normal_n_per_mm = [1e5, 1e5, 1e5, 1e5], stiffness_lateral_n_per_mm,
//! # load_normal_n = 0.0, load_lateral_n = 0.0,
//! # mapping_signs = { normal = 1, lateral = 1, roll = 1, pitch = 1, yaw = 1 }
//! ```
//!
//! The chain code is read as Valášek (2021) writes ZFYX for its C-frame mill with
//! a cross table: the letters left of `F` carry the tool, listed from the
//! tool towards the frame; the letters right of `F` carry the workpiece,
//! listed from the frame towards the workpiece. So ZFYX is tool ← Z ← frame
//! → Y → X → workpiece, FXYZ puts all three axes under the workpiece, and
//! YFXZ has Y on the tool side and X carrying Z on the workpiece side. (ISO
//! 10791-style codes are often read the other way round; this follows the
//! thesis.) How the chain is evaluated is in [`super::volumetric`].
//!
//! The guideway of each axis turns four rail profiles into its six errors
//! (Valášek (2021) Tab. 3.2): the normal straightness feeds the translation along
//! `normal`, the lateral straightness the translation along the remaining
//! direction, roll the rotation about the axis itself, pitch the rotation
//! about the lateral direction and yaw the rotation about the normal. The
//! thesis gives no signs for this mapping; `mapping_signs` defaults to +1
//! throughout, as the NumPy reference `mc_peer.py` does.

use serde::Deserialize;

use super::ModelError;
use super::components::Axis;
use super::components::GeometricErrors;
use super::description::{
    AxisDescription, BranchDeviations, ChainCode, Description, ErrorFrame, MappingSigns, Optics,
    OpticsBody,
};
use super::guideway::{Guideway, GuidewayMap, THESIS_STIFFNESS_N_PER_MM};
use super::volumetric::{ErrorMap, Grid, Kinematics, Method, VolumetricError};
use crate::error::{ParseError, check_machine_profile_keys};

/// The bundled description of Valášek's (2021) machine.
const BUNDLED_TOML: &str = include_str!("../../fixtures/machines/mcv754-quick.toml");

/// A validated machine description with its compiled chain.
#[derive(Clone, Debug, PartialEq)]
pub struct Machine {
    description: Description,
    guideways: [GuidewayMap; 3],
    kinematics: Kinematics,
}

impl Machine {
    /// Valášek's (2021) MCV 754 Quick with the documented assumed dimensions
    /// (`fixtures/machines/mcv754-quick.toml`).
    pub fn bundled() -> Machine {
        // The bundled text is part of the program, not user input, and a test parses it.
        Machine::from_toml_str(BUNDLED_TOML)
            .unwrap_or_else(|error| panic!("the bundled machine description is invalid: {error}"))
    }

    /// The text of the bundled description (to show or copy it).
    pub fn bundled_toml() -> &'static str {
        BUNDLED_TOML
    }

    /// Parses and validates a machine description.
    ///
    /// # Example
    ///
    /// ```
    /// use axcomp::model::{Axis, Machine};
    ///
    /// let text = Machine::bundled_toml().replace("[0.0, 750.0]", "[0.0, 1000.0]");
    /// let machine = Machine::from_toml_str(&text)?;
    /// assert_eq!(machine.axis(Axis::X).stroke_mm, [0.0, 1000.0]);
    /// assert_eq!(machine.chain().as_str(), "ZFYX");
    /// # Ok::<(), axcomp::model::ModelError>(())
    /// ```
    pub fn from_toml_str(text: &str) -> Result<Machine, ModelError> {
        check_machine_profile_keys(text).map_err(ModelError::Toml)?;
        let raw: RawFile = toml::from_str(text).map_err(|error| toml_error(text, &error))?;
        let Some(kinematics) = raw.kinematics else {
            return Err(ModelError::invalid(
                "machine description",
                "a [kinematics] table (chain, strokes, offsets; see fixtures/machines/mcv754-quick.toml)",
                "none",
            ));
        };
        let name = raw.name.unwrap_or_else(|| "unnamed machine".to_string());
        Machine::build(kinematics.into_description(name)?)
    }

    fn build(description: Description) -> Result<Machine, ModelError> {
        let mut guideways = Vec::with_capacity(3);
        for axis in Axis::ALL {
            let map = description.axes[axis.index()]
                .guideway
                .linear_map()
                .map_err(|error| error.within(&format!("kinematics.axes.{axis}")))?;
            guideways.push(map);
        }
        let guideways = [guideways[0], guideways[1], guideways[2]];
        let kinematics = Kinematics::compile(&description);
        Ok(Machine {
            description,
            guideways,
            kinematics,
        })
    }

    /// The machine's name.
    pub fn name(&self) -> &str {
        &self.description.name
    }

    /// The kinematic chain.
    pub fn chain(&self) -> &ChainCode {
        &self.description.chain
    }

    /// One axis.
    pub fn axis(&self, axis: Axis) -> &AxisDescription {
        &self.description.axes[axis.index()]
    }

    /// The solved guideway of one axis.
    pub fn guideway_map(&self, axis: Axis) -> &GuidewayMap {
        &self.guideways[axis.index()]
    }

    /// Last tool-side error frame → tool tip, mm.
    pub fn tool_offset_mm(&self) -> [f64; 3] {
        self.description.tool_offset_mm
    }

    /// Last workpiece-side error frame → workpiece reference, mm.
    pub fn workpiece_offset_mm(&self) -> [f64; 3] {
        self.description.workpiece_offset_mm
    }

    /// The workpiece point under the tool at X = Y = Z = 0, from the workpiece reference, mm.
    pub fn workpiece_point_mm(&self) -> [f64; 3] {
        self.description.workpiece_point_mm
    }

    /// The position where the volumetric error is zero by definition (eq. 68), mm.
    pub fn reference_mm(&self) -> [f64; 3] {
        self.description.reference_mm
    }

    /// Sum (Valášek (2021)) or difference of the branch deviations.
    pub fn branch_deviations(&self) -> BranchDeviations {
        self.description.branch_deviations
    }

    /// The same machine with another tool: Abbe offsets change with it.
    pub fn with_tool_offset(&self, offset_mm: [f64; 3]) -> Result<Machine, ModelError> {
        check_finite("tool.offset_mm", &offset_mm)?;
        let mut description = self.description.clone();
        description.tool_offset_mm = offset_mm;
        Machine::build(description)
    }

    /// The same machine with another workpiece point (e.g. a laser line away from the table centre).
    pub fn with_workpiece_point(&self, point_mm: [f64; 3]) -> Result<Machine, ModelError> {
        check_finite("workpiece.point_mm", &point_mm)?;
        let mut description = self.description.clone();
        description.workpiece_point_mm = point_mm;
        Machine::build(description)
    }

    /// The same machine with the branch deviations combined another way.
    pub fn with_branch_deviations(&self, combination: BranchDeviations) -> Machine {
        let mut machine = self.clone();
        machine.description.branch_deviations = combination;
        machine.kinematics = Kinematics::compile(&machine.description);
        machine
    }

    /// The compiled chain.
    pub(crate) fn kinematics(&self) -> &Kinematics {
        &self.kinematics
    }
}

impl Machine {
    /// The volumetric error at `position_mm` (X, Y, Z), zeroed at the
    /// machine's reference position (eq. 68).
    ///
    /// # Example
    ///
    /// A constant pitch of X of 10 µrad on the bundled machine: the
    /// workpiece point is z4 + 550 + Z mm above the X error frame (notes
    /// §2.5, `EBX·(Z + z4 + 550)`), so 500 mm below the reference (Z = 0)
    /// E_X is 10 µrad × (−500 mm) = −5 µm.
    ///
    /// ```
    /// use axcomp::model::{ErrorFunction, ErrorName, GeometricErrors, Machine, Method};
    ///
    /// let machine = Machine::bundled();
    /// let mut errors = GeometricErrors::default();
    /// errors.set(ErrorName::EBX, ErrorFunction::Constant(10e-6))?;
    /// let error = machine.volumetric_error(&errors, [0.0, 0.0, -500.0], Method::FirstOrder);
    /// assert!((error.translation_mm.x - 10e-6 * -500.0).abs() < 1e-15);
    /// assert!((error.rotation_rad.y - 10e-6).abs() < 1e-18);
    /// # Ok::<(), axcomp::model::ModelError>(())
    /// ```
    pub fn volumetric_error(
        &self,
        errors: &GeometricErrors,
        position_mm: [f64; 3],
        method: Method,
    ) -> VolumetricError {
        self.kinematics
            .volumetric_error(errors, position_mm, method)
    }

    /// The machine as a test's moving optic sees it: the point of the body
    /// that carries the optic moved by the optic's offset, so the angles of
    /// the axes under that body (and only those) take the offset into their
    /// Abbe arms. Its volumetric error is what the optic reads, zero at the
    /// reference position.
    ///
    /// The other optic (the laser head, the interferometer or the
    /// straightness reference) stands on the other body, which the measured
    /// axis does not move; so the reading is the error of the moving body's
    /// point at the optic, and the other body's angles stay constant along
    /// the test. On the tool's side that point is the tool tip (the tool
    /// offset, eq. 59); on the workpiece's, the workpiece point under it
    /// (eq. 60): Valášek (2021) §2.5's EBX·(Z + z4 + 550) in E_x becomes
    /// EBX·(Z + z4 + 550 + d_z) for an optic d_z from the tool tip on the
    /// table (`../shared/notes/seed000-volumetric-model.md` §2.3–2.5). The
    /// offset is held along the line, as the workpiece point is: the reading
    /// is taken where the beam meets the optic across the axis.
    pub fn with_optics(&self, optics: &Optics) -> Result<Machine, ModelError> {
        let d = optics.offset_mm;
        if d == [0.0; 3] {
            return Ok(self.clone());
        }
        match optics.body {
            OpticsBody::Tool => {
                let tool = self.tool_offset_mm();
                self.with_tool_offset([0, 1, 2].map(|i| tool[i] + d[i]))
            }
            OpticsBody::Workpiece => {
                let point = self.workpiece_point_mm();
                self.with_workpiece_point([0, 1, 2].map(|i| point[i] + d[i]))
            }
        }
    }

    /// The volumetric error at every point of `grid`.
    pub fn error_map(&self, errors: &GeometricErrors, grid: &Grid, method: Method) -> ErrorMap {
        self.kinematics.error_map(errors, grid, method)
    }
}

impl Grid {
    /// A grid over the machine's strokes with `step_mm` between points,
    /// starting at each stroke's lower end. The upper end is always included
    /// (as an extra, closer point when the stroke is not a multiple of the
    /// step), so the maximum is taken over the whole volume.
    pub fn over_strokes(machine: &Machine, step_mm: f64) -> Result<Grid, ModelError> {
        if !(step_mm.is_finite() && step_mm > 0.0) {
            return Err(ModelError::invalid(
                "grid step",
                "a positive length in mm",
                step_mm.to_string(),
            ));
        }
        let axes_mm = Axis::ALL.map(|axis| {
            let [low, high] = machine.axis(axis).stroke_mm;
            let mut points = Vec::new();
            let mut index = 0.0;
            loop {
                let point = low + index * step_mm;
                // Points closer than a millionth of a step to the end are the end.
                if point >= high - 1e-6 * step_mm {
                    break;
                }
                points.push(point);
                index += 1.0;
            }
            points.push(high);
            points
        });
        Ok(Grid::of_points(axes_mm))
    }
}

fn check_finite(what: &str, values: &[f64]) -> Result<(), ModelError> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(bad) => Err(ModelError::invalid(what, "finite numbers", bad.to_string())),
        None => Ok(()),
    }
}

/// A TOML error at its line and column (both from 1).
fn toml_error(text: &str, error: &toml::de::Error) -> ModelError {
    ModelError::Toml(ParseError::from_toml(text, error))
}

/// The whole file: only what the model reads. Other top-level tables
/// (`[controller]` for `axcomp convert`, …) belong to other readers; one
/// that no reader knows is refused first (`check_machine_profile_keys`).
#[derive(Deserialize)]
struct RawFile {
    name: Option<String>,
    kinematics: Option<RawMachine>,
}

/// The `[kinematics]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMachine {
    chain: String,
    branch_deviations: Option<BranchDeviations>,
    reference_mm: Option<[f64; 3]>,
    tool: RawTool,
    workpiece: RawWorkpiece,
    axes: RawAxes,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTool {
    offset_mm: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWorkpiece {
    offset_mm: [f64; 3],
    point_mm: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxes {
    #[serde(rename = "X")]
    x: RawAxis,
    #[serde(rename = "Y")]
    y: RawAxis,
    #[serde(rename = "Z")]
    z: RawAxis,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxis {
    stroke_mm: [f64; 2],
    offset_mm: [f64; 3],
    motion: Option<i64>,
    error_frame: Option<ErrorFrame>,
    normal: String,
    rail_spacing_mm: f64,
    carriage_pitch_mm: f64,
    stiffness_normal_n_per_mm: Option<[f64; 4]>,
    stiffness_lateral_n_per_mm: Option<[f64; 4]>,
    load_normal_n: Option<f64>,
    load_lateral_n: Option<f64>,
    mapping_signs: Option<RawSigns>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSigns {
    normal: Option<i64>,
    lateral: Option<i64>,
    roll: Option<i64>,
    pitch: Option<i64>,
    yaw: Option<i64>,
}

impl RawMachine {
    fn into_description(self, name: String) -> Result<Description, ModelError> {
        let chain = ChainCode::parse(&self.chain).map_err(|e| e.within("kinematics"))?;
        check_finite("kinematics.tool.offset_mm", &self.tool.offset_mm)?;
        check_finite("kinematics.workpiece.offset_mm", &self.workpiece.offset_mm)?;
        check_finite("kinematics.workpiece.point_mm", &self.workpiece.point_mm)?;
        let axes = [
            self.axes.x.into_axis(Axis::X)?,
            self.axes.y.into_axis(Axis::Y)?,
            self.axes.z.into_axis(Axis::Z)?,
        ];
        let reference_mm = self.reference_mm.unwrap_or([0.0; 3]);
        check_finite("kinematics.reference_mm", &reference_mm)?;
        for axis in Axis::ALL {
            let [low, high] = axes[axis.index()].stroke_mm;
            let reference = reference_mm[axis.index()];
            if !(low..=high).contains(&reference) {
                return Err(ModelError::invalid(
                    "kinematics.reference_mm",
                    format!("a position inside the {axis} stroke {low} … {high} mm"),
                    format!("{reference} mm"),
                ));
            }
        }
        Ok(Description {
            name,
            chain,
            axes,
            tool_offset_mm: self.tool.offset_mm,
            workpiece_offset_mm: self.workpiece.offset_mm,
            workpiece_point_mm: self.workpiece.point_mm,
            reference_mm,
            branch_deviations: self.branch_deviations.unwrap_or(BranchDeviations::Sum),
        })
    }
}

impl RawAxis {
    fn into_axis(self, axis: Axis) -> Result<AxisDescription, ModelError> {
        let key = |field: &str| format!("kinematics.axes.{axis}.{field}");
        let [low, high] = self.stroke_mm;
        if !(low.is_finite() && high.is_finite() && low < high) {
            return Err(ModelError::invalid(
                key("stroke_mm"),
                "[lowest, highest] with lowest < highest",
                format!("[{low}, {high}]"),
            ));
        }
        check_finite(&key("offset_mm"), &self.offset_mm)?;
        let normal = self
            .normal
            .trim()
            .chars()
            .next()
            .filter(|_| self.normal.trim().chars().count() == 1)
            .and_then(Axis::from_letter)
            .filter(|normal| *normal != axis)
            .ok_or_else(|| {
                ModelError::invalid(
                    key("normal"),
                    format!("one of X, Y, Z other than {axis}"),
                    format!("{:?}", self.normal),
                )
            })?;
        let sign = |field: &str, value: Option<i64>| -> Result<f64, ModelError> {
            match value {
                None | Some(1) => Ok(1.0),
                Some(-1) => Ok(-1.0),
                Some(other) => Err(ModelError::invalid(
                    key(field),
                    "1 or -1",
                    other.to_string(),
                )),
            }
        };
        let signs = match self.mapping_signs {
            None => MappingSigns::POSITIVE,
            Some(raw) => MappingSigns {
                normal: sign("mapping_signs.normal", raw.normal)?,
                lateral: sign("mapping_signs.lateral", raw.lateral)?,
                roll: sign("mapping_signs.roll", raw.roll)?,
                pitch: sign("mapping_signs.pitch", raw.pitch)?,
                yaw: sign("mapping_signs.yaw", raw.yaw)?,
            },
        };
        let guideway = Guideway {
            rail_spacing_mm: self.rail_spacing_mm,
            carriage_pitch_mm: self.carriage_pitch_mm,
            stiffness_normal_n_per_mm: self
                .stiffness_normal_n_per_mm
                .unwrap_or([THESIS_STIFFNESS_N_PER_MM; 4]),
            stiffness_lateral_n_per_mm: self
                .stiffness_lateral_n_per_mm
                .unwrap_or([THESIS_STIFFNESS_N_PER_MM; 4]),
            load_normal_n: self.load_normal_n.unwrap_or(0.0),
            load_lateral_n: self.load_lateral_n.unwrap_or(0.0),
        };
        Ok(AxisDescription {
            stroke_mm: self.stroke_mm,
            offset_mm: self.offset_mm,
            motion: sign("motion", self.motion)?,
            error_frame: self.error_frame.unwrap_or(ErrorFrame::Moving),
            normal,
            guideway,
            signs,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::components::SquarenessPair;

    #[test]
    fn chain_codes() {
        let zfyx = ChainCode::parse("ZFYX").unwrap();
        assert_eq!(zfyx.tool_axes(), [Axis::Z]);
        assert_eq!(zfyx.workpiece_axes(), [Axis::Y, Axis::X]);
        // Eqs 63/64: EXOY sits at X, EXOZ and EYOZ at Z.
        assert_eq!(zfyx.squareness_axis(SquarenessPair::XY), Axis::X);
        assert_eq!(zfyx.squareness_axis(SquarenessPair::XZ), Axis::Z);
        assert_eq!(zfyx.squareness_axis(SquarenessPair::YZ), Axis::Z);
        let fxyz = ChainCode::parse("FXYZ").unwrap();
        assert!(fxyz.tool_axes().is_empty());
        assert_eq!(fxyz.squareness_axis(SquarenessPair::XY), Axis::Y);
        assert_eq!(fxyz.squareness_axis(SquarenessPair::XZ), Axis::Z);
        let yzfx = ChainCode::parse("YZFX").unwrap();
        assert_eq!(yzfx.tool_axes(), [Axis::Z, Axis::Y]);
        assert_eq!(yzfx.squareness_axis(SquarenessPair::YZ), Axis::Y);
        for bad in ["ZYX", "ZFYXF", "ZFYY", "zfyx", "ZFY", "ZFYXA", ""] {
            let error = ChainCode::parse(bad).unwrap_err();
            assert!(
                error.to_string().starts_with("chain: expected X, Y and Z"),
                "{error}"
            );
        }
    }

    #[test]
    fn bundled_machine_is_the_thesis_machine() {
        // Strokes and a/b from Valášek (2021) (notes §2.1, Tab. 3.1); the assumed
        // dimensions z3 = 200, z4 = 80, y2 = 0, yt = 280, zt = 250 mm as `Machine::bundled` documents them.
        let machine = Machine::bundled();
        assert_eq!(machine.chain().as_str(), "ZFYX");
        let expected = [
            (Axis::X, [0.0, 750.0], 350.0, 640.0),
            (Axis::Y, [0.0, 500.0], 604.0, 480.0),
            (Axis::Z, [-550.0, 0.0], 316.0, 356.0),
        ];
        for (axis, stroke, a, b) in expected {
            let description = machine.axis(axis);
            assert_eq!(description.stroke_mm, stroke);
            assert_eq!(description.guideway.rail_spacing_mm, a);
            assert_eq!(description.guideway.carriage_pitch_mm, b);
        }
        assert_eq!(machine.axis(Axis::X).offset_mm, [0.0, 0.0, 200.0]);
        assert_eq!(machine.workpiece_offset_mm(), [0.0, 0.0, 80.0]);
        assert_eq!(machine.tool_offset_mm(), [0.0, -280.0, -250.0]);
        assert_eq!(machine.workpiece_point_mm(), [0.0, 250.0, 550.0]);
        assert_eq!(machine.branch_deviations(), BranchDeviations::Sum);
        assert_eq!(machine.axis(Axis::Z).normal, Axis::Y);
        assert_eq!(machine.axis(Axis::Z).lateral(Axis::Z), Axis::X);
    }

    #[test]
    fn an_optic_reads_the_error_at_its_own_point() {
        // By hand from the notes' §2.5 expansion of the ZFYX chain (z4 = 80,
        // z3 = 200, zt = 250 on the bundled machine), with each angle a line
        // k·q through zero at the reference, k = 1e-8 rad/mm.
        use crate::model::components::{ErrorFunction, ErrorName, ErrorTable, Interpolation};
        const K: f64 = 1e-8;
        let machine = Machine::bundled();
        let line = |name: ErrorName, axis: Axis| {
            let [low, high] = machine.axis(axis).stroke_mm;
            let mut errors = GeometricErrors::default();
            let table = ErrorTable::new(
                vec![low, high],
                vec![K * low, K * high],
                Interpolation::Linear,
            );
            errors
                .set(name, ErrorFunction::Table(table.unwrap()))
                .unwrap();
            errors
        };
        let table = |offset_mm| Optics {
            body: OpticsBody::Workpiece,
            offset_mm,
        };
        let head = |offset_mm| Optics {
            body: OpticsBody::Tool,
            offset_mm,
        };
        let cases = [
            // X's pitch on the X line z = −120: E_x = EBX·(Z + z4 + 550), and an
            // optic 150 mm below the point on the table shortens the arm.
            (
                ErrorName::EBX,
                Axis::X,
                [600.0, 100.0, -120.0],
                table([0.0, 120.0, -150.0]),
                0,
                K * 600.0 * 360.0,
            ),
            (
                ErrorName::EBX,
                Axis::X,
                [600.0, 100.0, -120.0],
                Optics::AT_TOOL_TIP,
                0,
                K * 600.0 * 510.0,
            ),
            // On the spindle head, which X does not move, the offset reaches
            // only Z's angles: X's pitch keeps the tool tip's arm.
            (
                ErrorName::EBX,
                Axis::X,
                [600.0, 100.0, -120.0],
                head([0.0, 120.0, -150.0]),
                0,
                K * 600.0 * 510.0,
            ),
            // X's yaw has no arm in E_y at the tool (x = 0 from its frame);
            // an optic 50 mm along X on the table gives it ECX·50.
            (
                ErrorName::ECX,
                Axis::X,
                [600.0, 100.0, -120.0],
                table([50.0, 120.0, -150.0]),
                1,
                K * 600.0 * 50.0,
            ),
            (
                ErrorName::ECX,
                Axis::X,
                [600.0, 100.0, -120.0],
                head([50.0, 120.0, -150.0]),
                1,
                0.0,
            ),
            // Y's pitch: E_y = −EAY·(Z + z3 + z4 + 550), the optic on the table
            // 150 mm lower: −k·y·(−400 + 830 − 150).
            (
                ErrorName::EAY,
                Axis::Y,
                [600.0, 300.0, -400.0],
                table([100.0, 0.0, -150.0]),
                1,
                -K * 300.0 * 280.0,
            ),
            // Z's pitch on the head: E_y = EAZ·zt, the optic 50 mm further down.
            (
                ErrorName::EAZ,
                Axis::Z,
                [200.0, 400.0, -300.0],
                head([0.0, 0.0, -50.0]),
                1,
                K * -300.0 * 300.0,
            ),
        ];
        for (name, axis, p, optics, direction, expected) in cases {
            let errors = line(name, axis);
            let seen = machine.with_optics(&optics).unwrap();
            for method in [Method::FirstOrder, Method::Full] {
                let reading = seen.volumetric_error(&errors, p, method).translation_mm;
                assert!(
                    (reading[direction] - expected).abs() < 1e-12,
                    "{name} {optics:?} {method:?}: {} against {expected}",
                    reading[direction]
                );
            }
        }
    }

    fn with(replace: &str, by: &str) -> Result<Machine, ModelError> {
        let text = Machine::bundled_toml();
        assert!(
            text.contains(replace),
            "the bundled file has no {replace:?}"
        );
        Machine::from_toml_str(&text.replacen(replace, by, 1))
    }

    #[test]
    fn bad_descriptions_name_the_key_or_the_position() {
        let cases = [
            (
                "chain = \"ZFYX\"",
                "chain = \"ZFY\"",
                "kinematics: chain: expected X, Y and Z",
            ),
            (
                "stroke_mm = [0.0, 750.0]",
                "stroke_mm = [750.0, 0.0]",
                "kinematics.axes.X.stroke_mm: expected [lowest, highest]",
            ),
            (
                "normal = \"Z\"",
                "normal = \"X\"",
                "kinematics.axes.X.normal: expected one of X, Y, Z other than X",
            ),
            (
                "rail_spacing_mm = 350.0",
                "rail_spacing_mm = -350.0",
                "kinematics.axes.X: rail spacing a: expected a positive length",
            ),
            (
                "motion = -1",
                "motion = 2",
                "kinematics.axes.X.motion: expected 1 or -1, found 2",
            ),
            (
                "reference_mm = [0.0, 0.0, 0.0]",
                "reference_mm = [0.0, 0.0, 10.0]",
                "kinematics.reference_mm: expected a position inside the Z stroke",
            ),
            (
                "branch_deviations = \"sum\"",
                "branch_deviations = \"total\"",
                "unknown variant `total`",
            ),
            (
                "rail_spacing_mm = 350.0",
                "rail_spacing_mm = 350.0\nrail_spcing_mm = 1.0",
                "unknown field `rail_spcing_mm`",
            ),
            (
                "rail_spacing_mm = 350.0",
                "rail_spacing_mm = \"wide\"",
                "invalid type",
            ),
            (
                "rail_spacing_mm = 350.0",
                "rail_spacing_mm = nan",
                "kinematics.axes.X: rail spacing a: expected a positive length in mm, found NaN",
            ),
            (
                "offset_mm = [0.0, -280.0, -250.0]",
                "offset_mm = [0.0, -280.0, inf]",
                "kinematics.tool.offset_mm: expected finite numbers, found inf",
            ),
            (
                "[kinematics]\n",
                "[kinematic]\n",
                "a machine profile has no table or key \"kinematic\"",
            ),
        ];
        for (replace, by, message) in cases {
            let error = with(replace, by).unwrap_err();
            assert!(
                error.to_string().contains(message),
                "{replace} → {by}: {error}"
            );
        }
    }

    #[test]
    fn other_tables_are_left_to_their_readers() {
        // A profile with only `axcomp convert`'s table has no model…
        let controller_only = "name = \"M\"\n[controller]\nunits = \"mm\"\n";
        let error = Machine::from_toml_str(controller_only).unwrap_err();
        assert!(
            error
                .to_string()
                .contains("machine description: expected a [kinematics] table"),
            "{error}"
        );
        // … and the bundled file, which has both, is read without complaint.
        assert!(Machine::bundled_toml().contains("\n[controller]\n"));
        assert_eq!(Machine::bundled().name(), "MCV 754 Quick");
    }

    #[test]
    fn toml_errors_carry_line_and_column() {
        let error = with("rail_spacing_mm = 350.0", "rail_spacing_mm = \"wide\"").unwrap_err();
        let ModelError::Toml(parse) = &error else {
            panic!("expected a TOML error, found {error}");
        };
        let line = Machine::bundled_toml()
            .lines()
            .position(|l| l.starts_with("rail_spacing_mm = 350.0"))
            .unwrap()
            + 1;
        assert_eq!((parse.position.line, parse.position.column), (line, 19));
    }
}
