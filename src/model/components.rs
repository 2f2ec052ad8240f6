//! The 21 geometric errors of a three-axis machine (ISO 230-1 names), each as
//! a function of its own axis.
//!
//! Valášek (2021) §2.1 and §3.3.1 (`../shared/notes/seed000-volumetric-model.md`
//! §1): a linear axis has six error motions, one per rigid-body degree of
//! freedom, and a three-axis machine adds three squareness errors, 21 in all.
//! The name `E<direction><axis>` gives the direction of a translation (X, Y, Z)
//! or the axis of a rotation (A, B, C about X, Y, Z) and then the moving axis:
//! EYX is the straightness of X in Y, EBX the rotation of X about Y.
//! Translations are mm, rotations rad (small, right-handed, as in the error
//! matrices of eqs 48–50). The 18 motion errors depend only on their own
//! axis's position (Valášek (2021) neglects the influence of the other axes,
//! §2.1.1); the squareness errors EXOY, EXOZ, EYOZ are constants (eqs 51–53:
//! rotations about Z, Y and X). Valášek (2021) spells them with a letter O in the
//! glossary and a zero in eqs 63/64; they are the same quantities.
//!
//! A position-dependent error is an [`ErrorFunction`]: a constant or an
//! [`ErrorTable`] (positions and values with linear or not-a-knot spline
//! interpolation, end values held outside). A generated random profile is a
//! spline table through its knots. This module only holds values; the
//! kinematics are in [`super::volumetric`].

use std::fmt;

use super::ModelError;
use crate::spline::CubicSpline;

/// A linear axis of the machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Axis {
    /// X.
    X,
    /// Y.
    Y,
    /// Z.
    Z,
}

impl Axis {
    /// X, Y, Z in this order (the order of every per-axis array).
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// 0, 1, 2 for X, Y, Z: the index into per-axis arrays and vectors.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// `X`, `Y` or `Z`.
    pub fn letter(self) -> char {
        ['X', 'Y', 'Z'][self.index()]
    }

    /// The axis named by `X`, `Y` or `Z` (upper case only, as in ISO names).
    pub fn from_letter(letter: char) -> Option<Axis> {
        match letter {
            'X' => Some(Axis::X),
            'Y' => Some(Axis::Y),
            'Z' => Some(Axis::Z),
            _ => None,
        }
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.letter())
    }
}

/// One of the three squareness errors (constant, rad).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SquarenessPair {
    /// EXOY, between X and Y: a rotation about Z (eq. 51).
    XY,
    /// EXOZ, between X and Z: a rotation about Y (eq. 52).
    XZ,
    /// EYOZ, between Y and Z: a rotation about X (eq. 53).
    YZ,
}

impl SquarenessPair {
    /// The three pairs, in the order of [`Squareness`]'s fields.
    pub const ALL: [SquarenessPair; 3] =
        [SquarenessPair::XY, SquarenessPair::XZ, SquarenessPair::YZ];

    /// The two axes of the pair.
    pub fn axes(self) -> (Axis, Axis) {
        match self {
            SquarenessPair::XY => (Axis::X, Axis::Y),
            SquarenessPair::XZ => (Axis::X, Axis::Z),
            SquarenessPair::YZ => (Axis::Y, Axis::Z),
        }
    }

    /// The axis the error rotates about: the one not in the pair (eqs 51–53).
    pub fn rotation_axis(self) -> Axis {
        match self {
            SquarenessPair::XY => Axis::Z,
            SquarenessPair::XZ => Axis::Y,
            SquarenessPair::YZ => Axis::X,
        }
    }
}

/// The ISO 230-1 name of one of the 21 errors, as Valášek (2021) writes it.
#[allow(clippy::upper_case_acronyms)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorName {
    /// Positioning error of X, mm.
    EXX,
    /// Straightness of X in Y, mm.
    EYX,
    /// Straightness of X in Z, mm.
    EZX,
    /// Roll of X, rad.
    EAX,
    /// Pitch of X, rad.
    EBX,
    /// Yaw of X, rad.
    ECX,
    /// Straightness of Y in X, mm.
    EXY,
    /// Positioning error of Y, mm.
    EYY,
    /// Straightness of Y in Z, mm.
    EZY,
    /// Pitch of Y, rad.
    EAY,
    /// Roll of Y, rad.
    EBY,
    /// Yaw of Y, rad.
    ECY,
    /// Straightness of Z in X, mm.
    EXZ,
    /// Straightness of Z in Y, mm.
    EYZ,
    /// Positioning error of Z, mm.
    EZZ,
    /// Pitch of Z, rad.
    EAZ,
    /// Yaw of Z, rad.
    EBZ,
    /// Roll of Z, rad.
    ECZ,
    /// Squareness X–Y, rad.
    EXOY,
    /// Squareness X–Z, rad.
    EXOZ,
    /// Squareness Y–Z, rad.
    EYOZ,
}

/// What an error name refers to: a motion error of an axis, or a squareness.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorComponent {
    /// A translation of `axis` in direction `direction` (mm).
    Translation {
        /// The moving axis.
        axis: Axis,
        /// The direction of the error.
        direction: Axis,
    },
    /// A rotation of `axis` about `about` (rad).
    Rotation {
        /// The moving axis.
        axis: Axis,
        /// The axis the rotation is about.
        about: Axis,
    },
    /// A squareness error (rad, constant).
    Squareness(SquarenessPair),
}

impl ErrorName {
    /// All 21, in the order of Valášek's glossary.
    pub const ALL: [ErrorName; 21] = [
        ErrorName::EXX,
        ErrorName::EYX,
        ErrorName::EZX,
        ErrorName::EAX,
        ErrorName::EBX,
        ErrorName::ECX,
        ErrorName::EXY,
        ErrorName::EYY,
        ErrorName::EZY,
        ErrorName::EAY,
        ErrorName::EBY,
        ErrorName::ECY,
        ErrorName::EXZ,
        ErrorName::EYZ,
        ErrorName::EZZ,
        ErrorName::EAZ,
        ErrorName::EBZ,
        ErrorName::ECZ,
        ErrorName::EXOY,
        ErrorName::EXOZ,
        ErrorName::EYOZ,
    ];

    /// The name as written: `EXX`, …, `EXOY`.
    pub fn as_str(self) -> &'static str {
        match self {
            ErrorName::EXX => "EXX",
            ErrorName::EYX => "EYX",
            ErrorName::EZX => "EZX",
            ErrorName::EAX => "EAX",
            ErrorName::EBX => "EBX",
            ErrorName::ECX => "ECX",
            ErrorName::EXY => "EXY",
            ErrorName::EYY => "EYY",
            ErrorName::EZY => "EZY",
            ErrorName::EAY => "EAY",
            ErrorName::EBY => "EBY",
            ErrorName::ECY => "ECY",
            ErrorName::EXZ => "EXZ",
            ErrorName::EYZ => "EYZ",
            ErrorName::EZZ => "EZZ",
            ErrorName::EAZ => "EAZ",
            ErrorName::EBZ => "EBZ",
            ErrorName::ECZ => "ECZ",
            ErrorName::EXOY => "EXOY",
            ErrorName::EXOZ => "EXOZ",
            ErrorName::EYOZ => "EYOZ",
        }
    }

    /// The error named `name` (case-insensitive; `EX0Y` with a zero, as in
    /// eqs 63/64, is accepted for `EXOY`).
    pub fn from_name(name: &str) -> Option<ErrorName> {
        let upper = name.trim().to_ascii_uppercase().replace('0', "O");
        ErrorName::ALL
            .into_iter()
            .find(|candidate| candidate.as_str() == upper)
    }

    /// The error named by a component.
    pub fn of(component: ErrorComponent) -> ErrorName {
        ErrorName::ALL
            .into_iter()
            .find(|name| name.component() == component)
            .unwrap_or(ErrorName::EXX)
    }

    /// What the name refers to.
    pub fn component(self) -> ErrorComponent {
        let text = self.as_str().as_bytes();
        if text.len() == 4 {
            return ErrorComponent::Squareness(match self {
                ErrorName::EXOY => SquarenessPair::XY,
                ErrorName::EXOZ => SquarenessPair::XZ,
                _ => SquarenessPair::YZ,
            });
        }
        let axis = letter_axis(text[2]);
        match text[1] {
            b'A' => ErrorComponent::Rotation {
                axis,
                about: Axis::X,
            },
            b'B' => ErrorComponent::Rotation {
                axis,
                about: Axis::Y,
            },
            b'C' => ErrorComponent::Rotation {
                axis,
                about: Axis::Z,
            },
            direction => ErrorComponent::Translation {
                axis,
                direction: letter_axis(direction),
            },
        }
    }

    /// `mm` for translations, `rad` for rotations and squareness.
    pub fn unit(self) -> &'static str {
        match self.component() {
            ErrorComponent::Translation { .. } => "mm",
            _ => "rad",
        }
    }
}

fn letter_axis(letter: u8) -> Axis {
    match letter {
        b'X' => Axis::X,
        b'Y' => Axis::Y,
        _ => Axis::Z,
    }
}

impl fmt::Display for ErrorName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How an [`ErrorTable`] interpolates between its points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// Straight lines between points (how controllers apply compensation tables).
    Linear,
    /// The not-a-knot cubic spline through the points (MATLAB's `spline`).
    Spline,
}

/// An error as a table over its axis: strictly increasing positions (mm) and
/// one value per position (mm or rad), interpolated in between, the end
/// values held outside.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorTable {
    positions_mm: Vec<f64>,
    values: Vec<f64>,
    interpolation: Interpolation,
    spline: Option<CubicSpline>,
}

impl ErrorTable {
    /// A table; positions finite and strictly increasing, values finite, at
    /// least one point, as many values as positions.
    ///
    /// # Example
    ///
    /// EXX from a positioning test (targets and mean deviations in mm):
    ///
    /// ```
    /// use axcomp::model::{ErrorTable, Interpolation};
    ///
    /// let exx = ErrorTable::new(vec![0.0, 100.0, 200.0], vec![0.0, 0.004, 0.002], Interpolation::Linear)?;
    /// assert!((exx.value_at(150.0) - 0.003).abs() < 1e-15);
    /// assert_eq!(exx.value_at(250.0), 0.002); // end value held outside
    /// # Ok::<(), axcomp::model::ModelError>(())
    /// ```
    pub fn new(
        positions_mm: Vec<f64>,
        values: Vec<f64>,
        interpolation: Interpolation,
    ) -> Result<ErrorTable, ModelError> {
        if positions_mm.is_empty() || positions_mm.len() != values.len() {
            return Err(ModelError::invalid(
                "error table",
                "as many values as positions, at least one",
                format!(
                    "{} positions and {} values",
                    positions_mm.len(),
                    values.len()
                ),
            ));
        }
        if let Some(bad) = positions_mm.iter().chain(&values).find(|v| !v.is_finite()) {
            return Err(ModelError::invalid(
                "error table",
                "finite numbers",
                bad.to_string(),
            ));
        }
        if let Some(pair) = positions_mm.windows(2).find(|pair| pair[0] >= pair[1]) {
            return Err(ModelError::invalid(
                "error table",
                "strictly increasing positions",
                format!("{} mm followed by {} mm", pair[0], pair[1]),
            ));
        }
        let spline = (interpolation == Interpolation::Spline)
            .then(|| CubicSpline::new(&positions_mm, &values));
        Ok(ErrorTable {
            positions_mm,
            values,
            interpolation,
            spline,
        })
    }

    /// The positions, mm.
    pub fn positions_mm(&self) -> &[f64] {
        &self.positions_mm
    }

    /// The values at the positions (mm or rad).
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The interpolation.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// The value at `position_mm`; the end values outside the table.
    pub fn value_at(&self, position_mm: f64) -> f64 {
        if let Some(spline) = &self.spline {
            return spline.value_at(position_mm);
        }
        linear_at(&self.positions_mm, &self.values, position_mm)
    }
}

/// Linear interpolation in a table with strictly increasing positions, end
/// values held outside.
fn linear_at(positions: &[f64], values: &[f64], x: f64) -> f64 {
    let n = positions.len();
    if x <= positions[0] {
        return values[0];
    }
    if x >= positions[n - 1] {
        return values[n - 1];
    }
    let i = positions.partition_point(|p| *p <= x) - 1;
    let fraction = (x - positions[i]) / (positions[i + 1] - positions[i]);
    values[i] + fraction * (values[i + 1] - values[i])
}

/// One position-dependent error along its axis.
#[derive(Clone, Debug, PartialEq)]
pub enum ErrorFunction {
    /// The same value everywhere (0 for an error that is not modelled).
    Constant(f64),
    /// A table (measured, or a generated profile).
    Table(ErrorTable),
}

impl ErrorFunction {
    /// The value at `position_mm` of the error's own axis.
    pub fn value_at(&self, position_mm: f64) -> f64 {
        match self {
            ErrorFunction::Constant(value) => *value,
            ErrorFunction::Table(table) => table.value_at(position_mm),
        }
    }
}

impl Default for ErrorFunction {
    fn default() -> ErrorFunction {
        ErrorFunction::Constant(0.0)
    }
}

/// The six motion errors of one axis, functions of that axis's position.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisErrors {
    /// Translations in X, Y, Z (e.g. EXX, EYX, EZX for the X axis), mm.
    pub translation_mm: [ErrorFunction; 3],
    /// Rotations about X, Y, Z (e.g. EAX, EBX, ECX for the X axis), rad.
    pub rotation_rad: [ErrorFunction; 3],
}

/// The three squareness errors, rad (eqs 51–53).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Squareness {
    /// EXOY, a rotation about Z.
    pub xy_rad: f64,
    /// EXOZ, a rotation about Y.
    pub xz_rad: f64,
    /// EYOZ, a rotation about X.
    pub yz_rad: f64,
}

impl Squareness {
    /// The value of one pair.
    pub fn get(&self, pair: SquarenessPair) -> f64 {
        match pair {
            SquarenessPair::XY => self.xy_rad,
            SquarenessPair::XZ => self.xz_rad,
            SquarenessPair::YZ => self.yz_rad,
        }
    }

    /// Sets one pair.
    pub fn set(&mut self, pair: SquarenessPair, value_rad: f64) {
        match pair {
            SquarenessPair::XY => self.xy_rad = value_rad,
            SquarenessPair::XZ => self.xz_rad = value_rad,
            SquarenessPair::YZ => self.yz_rad = value_rad,
        }
    }
}

/// All 21 errors of a machine. `Default` is the perfect machine (all zero).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GeometricErrors {
    /// The motion errors of X, Y and Z, indexed by [`Axis::index`].
    pub axes: [AxisErrors; 3],
    /// The squareness errors.
    pub squareness: Squareness,
}

impl GeometricErrors {
    /// Sets one error. A squareness error is a constant: giving it a table is an error.
    ///
    /// # Example
    ///
    /// ```
    /// use axcomp::model::{ErrorFunction, ErrorName, GeometricErrors};
    ///
    /// let mut errors = GeometricErrors::default();
    /// errors.set(ErrorName::EBX, ErrorFunction::Constant(20e-6))?;
    /// errors.set(ErrorName::EXOY, ErrorFunction::Constant(30e-6))?;
    /// let values = errors.values_at([100.0, 0.0, 0.0]);
    /// assert_eq!(values.rotation_rad[0][1], 20e-6);
    /// assert_eq!(values.squareness.xy_rad, 30e-6);
    /// # Ok::<(), axcomp::model::ModelError>(())
    /// ```
    pub fn set(&mut self, name: ErrorName, function: ErrorFunction) -> Result<(), ModelError> {
        match name.component() {
            ErrorComponent::Translation { axis, direction } => {
                self.axes[axis.index()].translation_mm[direction.index()] = function;
            }
            ErrorComponent::Rotation { axis, about } => {
                self.axes[axis.index()].rotation_rad[about.index()] = function;
            }
            ErrorComponent::Squareness(pair) => match function {
                ErrorFunction::Constant(value) if value.is_finite() => {
                    self.squareness.set(pair, value);
                }
                ErrorFunction::Constant(value) => {
                    return Err(ModelError::invalid(
                        name.as_str(),
                        "a finite angle",
                        value.to_string(),
                    ));
                }
                ErrorFunction::Table(_) => {
                    return Err(ModelError::invalid(
                        name.as_str(),
                        "a constant (squareness does not depend on position)",
                        "a table",
                    ));
                }
            },
        }
        Ok(())
    }

    /// The function of one motion error, or `None` for a squareness name.
    pub fn function(&self, name: ErrorName) -> Option<&ErrorFunction> {
        match name.component() {
            ErrorComponent::Translation { axis, direction } => {
                Some(&self.axes[axis.index()].translation_mm[direction.index()])
            }
            ErrorComponent::Rotation { axis, about } => {
                Some(&self.axes[axis.index()].rotation_rad[about.index()])
            }
            ErrorComponent::Squareness(_) => None,
        }
    }

    /// Every error's value at the axis positions `position_mm` (X, Y, Z):
    /// each axis's errors at its own coordinate.
    pub fn values_at(&self, position_mm: [f64; 3]) -> ErrorValues {
        let mut values = ErrorValues {
            squareness: self.squareness,
            ..ErrorValues::default()
        };
        for axis in Axis::ALL {
            let k = axis.index();
            for direction in 0..3 {
                values.translation_mm[k][direction] =
                    self.axes[k].translation_mm[direction].value_at(position_mm[k]);
                values.rotation_rad[k][direction] =
                    self.axes[k].rotation_rad[direction].value_at(position_mm[k]);
            }
        }
        values
    }
}

/// The values of all 21 errors at one machine position.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorValues {
    /// `translation_mm[axis][direction]`: e.g. `[0][1]` is EYX, mm.
    pub translation_mm: [[f64; 3]; 3],
    /// `rotation_rad[axis][about]`: e.g. `[0][1]` is EBX, rad.
    pub rotation_rad: [[f64; 3]; 3],
    /// The squareness errors, rad.
    pub squareness: Squareness,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_refer_to_their_component() {
        for name in ErrorName::ALL {
            assert_eq!(ErrorName::from_name(name.as_str()), Some(name));
            assert_eq!(ErrorName::of(name.component()), name);
        }
        assert_eq!(ErrorName::from_name("ex0y"), Some(ErrorName::EXOY));
        assert_eq!(ErrorName::from_name("EQX"), None);
        assert_eq!(
            ErrorName::EBX.component(),
            ErrorComponent::Rotation {
                axis: Axis::X,
                about: Axis::Y
            }
        );
        assert_eq!(
            ErrorName::EYZ.component(),
            ErrorComponent::Translation {
                axis: Axis::Z,
                direction: Axis::Y
            }
        );
        assert_eq!(ErrorName::EYZ.unit(), "mm");
        assert_eq!(ErrorName::EYOZ.unit(), "rad");
    }

    #[test]
    fn linear_table_interpolates_and_holds_the_ends() {
        let table = ErrorTable::new(
            vec![0.0, 100.0, 300.0],
            vec![0.0, 0.010, -0.010],
            Interpolation::Linear,
        )
        .unwrap();
        // By hand: halfway between 100 and 300 mm is 0; a quarter is 0.005.
        assert_eq!(table.value_at(200.0), 0.0);
        assert!((table.value_at(150.0) - 0.005).abs() < 1e-15);
        assert_eq!(table.value_at(-5.0), 0.0);
        assert_eq!(table.value_at(1000.0), -0.010);
        let single = ErrorTable::new(vec![50.0], vec![0.003], Interpolation::Spline).unwrap();
        assert_eq!(single.value_at(0.0), 0.003);
    }

    #[test]
    fn bad_tables_are_errors_not_panics() {
        let cases = [
            (vec![], vec![], "at least one"),
            (vec![0.0, 1.0], vec![0.0], "2 positions and 1 values"),
            (vec![0.0, 0.0], vec![0.0, 1.0], "0 mm followed by 0 mm"),
            (vec![0.0, f64::NAN], vec![0.0, 1.0], "finite"),
            (vec![0.0, 1.0], vec![0.0, f64::INFINITY], "finite"),
        ];
        for (positions, values, message) in cases {
            let error = ErrorTable::new(positions, values, Interpolation::Linear).unwrap_err();
            assert!(error.to_string().contains(message), "{error}");
        }
    }

    #[test]
    fn squareness_takes_only_constants() {
        let mut errors = GeometricErrors::default();
        let table = ErrorTable::new(vec![0.0], vec![1.0], Interpolation::Linear).unwrap();
        let error = errors
            .set(ErrorName::EXOZ, ErrorFunction::Table(table.clone()))
            .unwrap_err();
        assert!(
            error.to_string().contains("EXOZ: expected a constant"),
            "{error}"
        );
        errors
            .set(ErrorName::EYOZ, ErrorFunction::Constant(1e-5))
            .unwrap();
        assert_eq!(errors.squareness.yz_rad, 1e-5);
        errors
            .set(ErrorName::EZY, ErrorFunction::Table(table))
            .unwrap();
        assert_eq!(errors.values_at([0.0, 7.0, 0.0]).translation_mm[1][2], 1.0);
        assert!(errors.function(ErrorName::EXOY).is_none());
    }
}
