//! A machine as its description file states it, validated: the chain (which
//! axes carry the tool and which the workpiece), each axis with its stroke,
//! error frame and mapping signs, the offsets, the functional points and the
//! reference position. [`super::volumetric`] compiles it into the chain it
//! evaluates; [`super::machine`] reads and holds it.

use serde::Deserialize;

use super::ModelError;
use super::components::{Axis, SquarenessPair};
use super::guideway::Guideway;

/// How the deviations of the tool and workpiece branches combine (eq. 67).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BranchDeviations {
    /// E = Δtool + Δworkpiece, as Valášek (2021) writes eq. 67 ("superposition").
    Sum,
    /// E = Δtool − Δworkpiece: the tool relative to the workpiece.
    Difference,
}

/// Where an axis's error motion is referred to (see [`super::volumetric`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ErrorFrame {
    /// A point on the moving body (the centre of its carriages): Y and Z in eqs 63/64.
    Moving,
    /// A point on the carrying body under the functional point: X in eq. 64.
    Fixed,
}

/// Signs of the mapping from guideway outputs to ISO 230-1 errors (±1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MappingSigns {
    /// z5 → translation along the normal direction.
    pub normal: f64,
    /// y5 → translation along the lateral direction.
    pub lateral: f64,
    /// roll → rotation about the axis itself.
    pub roll: f64,
    /// pitch → rotation about the lateral direction.
    pub pitch: f64,
    /// yaw → rotation about the normal direction.
    pub yaw: f64,
}

impl MappingSigns {
    /// All +1, as the peer applies Tab. 3.2.
    pub const POSITIVE: MappingSigns = MappingSigns {
        normal: 1.0,
        lateral: 1.0,
        roll: 1.0,
        pitch: 1.0,
        yaw: 1.0,
    };
}

/// One linear axis of the machine.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisDescription {
    /// Lowest and highest position, mm.
    pub stroke_mm: [f64; 2],
    /// From the previous joint's error frame (or the frame origin) to this axis's, mm.
    pub offset_mm: [f64; 3],
    /// +1 or −1: the direction the body moves when the coordinate grows.
    pub motion: f64,
    /// Where the error motion is referred to.
    pub error_frame: ErrorFrame,
    /// The direction normal to the rail mounting face ("vertical" straightness).
    pub normal: Axis,
    /// The guideway: rail spacing, carriage pitch, stiffness, load.
    pub guideway: Guideway,
    /// Signs of the mapping of its outputs to the ISO errors.
    pub signs: MappingSigns,
}

impl AxisDescription {
    /// The lateral ("horizontal") direction: neither the axis nor the normal.
    pub fn lateral(&self, axis: Axis) -> Axis {
        Axis::ALL
            .into_iter()
            .find(|other| *other != axis && *other != self.normal)
            .unwrap_or(axis)
    }
}

/// A validated chain code such as `ZFYX`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChainCode {
    code: String,
    tool: Vec<Axis>,
    workpiece: Vec<Axis>,
}

impl ChainCode {
    /// Parses a code: X, Y and Z once each and one F, nothing else.
    pub fn parse(code: &str) -> Result<ChainCode, ModelError> {
        let expected = "X, Y and Z once each around one F, like ZFYX, FXYZ or YFXZ";
        let invalid = || ModelError::invalid("chain", expected, format!("{code:?}"));
        let letters: Vec<char> = code.trim().chars().collect();
        let frame = letters.iter().position(|c| *c == 'F').ok_or_else(invalid)?;
        let to_axes = |part: &[char]| -> Option<Vec<Axis>> {
            part.iter().map(|c| Axis::from_letter(*c)).collect()
        };
        let mut tool = to_axes(&letters[..frame]).ok_or_else(invalid)?;
        tool.reverse();
        let workpiece = to_axes(&letters[frame + 1..]).ok_or_else(invalid)?;
        let mut all: Vec<Axis> = tool.iter().chain(&workpiece).copied().collect();
        all.sort();
        if all != Axis::ALL {
            return Err(invalid());
        }
        Ok(ChainCode {
            code: letters.iter().collect(),
            tool,
            workpiece,
        })
    }

    /// The code as written.
    pub fn as_str(&self) -> &str {
        &self.code
    }

    /// The tool-side axes, from the frame outwards.
    pub fn tool_axes(&self) -> &[Axis] {
        &self.tool
    }

    /// The workpiece-side axes, from the frame outwards.
    pub fn workpiece_axes(&self) -> &[Axis] {
        &self.workpiece
    }

    /// The body an axis moves, as far as an optic on it goes: the tool's for
    /// a tool-side axis, the workpiece's for a workpiece-side one (an optic
    /// on a saddle moves with the table it carries while the saddle's axis
    /// is measured).
    pub fn body_moved_by(&self, axis: Axis) -> OpticsBody {
        if self.tool.contains(&axis) {
            OpticsBody::Tool
        } else {
            OpticsBody::Workpiece
        }
    }

    /// The axis whose joint carries a squareness error: the outer of the two
    /// when both are on one side, otherwise the tool-side one (eqs 63/64).
    pub fn squareness_axis(&self, pair: SquarenessPair) -> Axis {
        let (first, second) = pair.axes();
        let tool_position = |axis: Axis| self.tool.iter().position(|a| *a == axis);
        let workpiece_position = |axis: Axis| self.workpiece.iter().position(|a| *a == axis);
        match (tool_position(first), tool_position(second)) {
            (Some(a), Some(b)) => return if a > b { first } else { second },
            (Some(_), None) => return first,
            (None, Some(_)) => return second,
            (None, None) => {}
        }
        if workpiece_position(first) > workpiece_position(second) {
            first
        } else {
            second
        }
    }
}

/// The body that carries a laser's moving optic: the last body of one side
/// of the chain, the one holding the tool (the spindle head) or the one
/// holding the workpiece (the table).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpticsBody {
    /// The body that holds the tool: the tool-side chain's last body.
    Tool,
    /// The body that holds the workpiece: the workpiece-side chain's last body.
    Workpiece,
}

impl OpticsBody {
    /// Both, as a survey names them.
    pub const ALL: [OpticsBody; 2] = [OpticsBody::Tool, OpticsBody::Workpiece];

    /// The name a survey writes: `tool` or `workpiece`.
    pub fn name(self) -> &'static str {
        match self {
            OpticsBody::Tool => "tool",
            OpticsBody::Workpiece => "workpiece",
        }
    }

    /// The body a survey names.
    pub fn from_name(name: &str) -> Option<OpticsBody> {
        OpticsBody::ALL.into_iter().find(|b| b.name() == name)
    }
}

/// Where a test's moving optic sits: on which body, and where on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Optics {
    /// The body that carries it.
    pub body: OpticsBody,
    /// From the tool tip to the optic, mm: where across the axis the beam
    /// meets it (held along the line, as the tool tip is).
    pub offset_mm: [f64; 3],
}

impl Optics {
    /// At the tool tip: the volumetric error itself.
    pub const AT_TOOL_TIP: Optics = Optics {
        body: OpticsBody::Tool,
        offset_mm: [0.0; 3],
    };
}

/// What a description file says, validated.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Description {
    pub name: String,
    pub chain: ChainCode,
    pub axes: [AxisDescription; 3],
    pub tool_offset_mm: [f64; 3],
    pub workpiece_offset_mm: [f64; 3],
    pub workpiece_point_mm: [f64; 3],
    pub reference_mm: [f64; 3],
    pub branch_deviations: BranchDeviations,
}
