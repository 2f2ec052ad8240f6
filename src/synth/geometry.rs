//! A synthetic machine with known 21 errors, "measured" into geometry test
//! files and a survey, for the tests of `predict::survey`.
//!
//! The truth ([`random_truth`]) is in the survey's own form, because a line
//! measurement can tell nothing else: each straightness has no
//! least-squares slope over its test's targets (a slope is squareness or
//! alignment, ISO 230-1), each angle is zero at the machine's reference
//! position (an angular interferometer reads relative angles), squareness
//! and positioning are free. Each error is a sum of a few smooth waves
//! (periods 400 … 1600 mm), tabulated every 5 mm.
//!
//! The tests ([`measure`]) read what the instruments would: on each axis's
//! line, the model's volumetric error at the moving optic (full
//! transforms, so every Abbe arm and squareness of the chain is in; the
//! optic on the body the plan puts it on, by default the one the axis
//! moves: [`Machine::with_optics`]), the
//! straightness optics turned by one common small rotation of the laser's
//! reference (the optical square keeps the pairs' reference common), an
//! arbitrary zero for each straightness and angle, and Gaussian noise on
//! every reading. Pure: ChaCha8 seeded by the caller.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Normal, Uniform};

use super::SynthError;
use crate::evaluate::straightness::{ReferenceLine, straightness};
use crate::measurement::Direction;
use crate::model::{
    Axis, ErrorComponent, ErrorFunction, ErrorName, ErrorTable, GeometricErrors, Interpolation,
    Machine, Method, ModelError, Optics, OpticsBody,
};
use crate::read::geometry::{ColumnUnit, GeometryColumn, GeometryRun, GeometryTest, Quantity};

/// How the synthetic survey is measured.
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryPlan {
    /// Target spacing of every test, mm (from the stroke's low end).
    pub step_mm: f64,
    /// Runs per direction.
    pub runs: u32,
    /// Noise of a translation reading, mm (1 σ).
    pub noise_mm: f64,
    /// Noise of an angle reading, rad (1 σ).
    pub noise_rad: f64,
    /// The laser reference's rotation about X, Y, Z against the machine, rad.
    pub laser_rotation_rad: [f64; 3],
    /// The line of each axis's test (X, Y, Z), machine position, mm.
    pub lines_mm: [[f64; 3]; 3],
    /// The moving optics from the tool tip, mm, per axis's test.
    pub optics_offset_mm: [[f64; 3]; 3],
    /// The body carrying each axis's moving optic; `None`: the body the
    /// axis moves (the survey states the one taken).
    pub optics_on: [Option<OpticsBody>; 3],
}

impl GeometryPlan {
    /// The plan of the survey tests on the bundled MCV 754 Quick:
    /// 25 mm targets, 2 runs each way, 0.1 µm and 0.1 µrad of noise a
    /// reading, the laser's reference turned by tens of µrad, each axis on
    /// a line away from the reference with optics 120–150 mm from the tool.
    pub fn example() -> GeometryPlan {
        GeometryPlan {
            step_mm: 25.0,
            runs: 2,
            noise_mm: 0.0001,
            noise_rad: 0.1e-6,
            laser_rotation_rad: [30e-6, -45e-6, 25e-6],
            lines_mm: [
                [0.0, 100.0, -120.0],
                [600.0, 0.0, -400.0],
                [200.0, 400.0, 0.0],
            ],
            optics_offset_mm: [
                [0.0, 120.0, -150.0],
                [100.0, 0.0, -150.0],
                [-80.0, -120.0, 0.0],
            ],
            optics_on: [None; 3],
        }
    }
}

/// The files of a synthetic survey: (file name, text), the survey last.
#[derive(Clone, Debug, PartialEq)]
pub struct SyntheticSurvey {
    /// One geometry CSV per axis: `X.csv`, `Y.csv`, `Z.csv`.
    pub tests: Vec<(String, String)>,
    /// The survey TOML naming them.
    pub survey: String,
}

/// The targets of an axis's test.
pub fn targets(machine: &Machine, axis: Axis, step_mm: f64) -> Vec<f64> {
    let [low, high] = machine.axis(axis).stroke_mm;
    let mut targets = Vec::new();
    let mut x = low;
    while x < high - 1e-9 {
        targets.push(x);
        x += step_mm;
    }
    targets.push(high);
    targets
}

/// A random truth in the survey's form (module doc).
pub fn random_truth(
    machine: &Machine,
    plan: &GeometryPlan,
    seed: u64,
) -> Result<GeometricErrors, ModelError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let unit = Uniform::new(-1.0, 1.0)
        .map_err(|e| ModelError::invalid("rng", "a range", e.to_string()))?;
    let reference = machine.reference_mm();
    let mut errors = GeometricErrors::default();
    for name in ErrorName::ALL {
        let (axis, amplitude) = match name.component() {
            ErrorComponent::Squareness(pair) => {
                errors.squareness.set(pair, 20e-6 * unit.sample(&mut rng));
                continue;
            }
            ErrorComponent::Translation { axis, direction } if axis == direction => (axis, 0.008),
            ErrorComponent::Translation { axis, .. } => (axis, 0.004),
            ErrorComponent::Rotation { axis, .. } => (axis, 8e-6),
        };
        let [low, high] = machine.axis(axis).stroke_mm;
        let waves: Vec<(f64, f64, f64)> = (0..3)
            .map(|_| {
                let period = 400.0 + 1200.0 * (unit.sample(&mut rng) + 1.0) / 2.0;
                (
                    period,
                    amplitude / 2.0 * unit.sample(&mut rng),
                    3.0 * unit.sample(&mut rng),
                )
            })
            .collect();
        let f = |x: f64| -> f64 {
            waves
                .iter()
                .map(|(period, a, phase)| a * (std::f64::consts::TAU * x / period + phase).sin())
                .sum()
        };
        let count = ((high - low) / 5.0).ceil() as usize;
        let positions: Vec<f64> = (0..=count)
            .map(|i| low + (high - low) * i as f64 / count as f64)
            .collect();
        let mut values: Vec<f64> = positions.iter().map(|&x| f(x)).collect();
        match name.component() {
            ErrorComponent::Translation { axis, direction } if axis != direction => {
                // No least-squares slope over the test's targets.
                let t = targets(machine, axis, plan.step_mm);
                let at: Vec<f64> = t.iter().map(|&x| f(x)).collect();
                let line = straightness(&t, &at, ReferenceLine::LeastSquares);
                for (v, x) in values.iter_mut().zip(&positions) {
                    *v -= line.intercept_mm + line.slope * x;
                }
            }
            ErrorComponent::Rotation { axis, .. } => {
                let zero = f(reference[axis.index()]);
                for v in &mut values {
                    *v -= zero;
                }
            }
            _ => {}
        }
        let table = ErrorTable::new(positions, values, Interpolation::Linear)?;
        errors.set(name, ErrorFunction::Table(table))?;
    }
    Ok(errors)
}

/// The geometry tests of every axis and the survey naming them (module doc).
pub fn measure(
    machine: &Machine,
    truth: &GeometricErrors,
    plan: &GeometryPlan,
    seed: u64,
) -> Result<SyntheticSurvey, SynthError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(1);
    let translation_noise = Normal::new(0.0, plan.noise_mm)?;
    let angle_noise = Normal::new(0.0, plan.noise_rad)?;
    let reference = machine.reference_mm();
    let mut tests = Vec::new();
    let mut survey = String::from(
        "# A synthetic survey (axcomp synth): one 6-DOF test per axis.\n\
         reference_line = \"least-squares\"\n\n[squareness]\nconvention = \"right-handed\"\n\
         from_straightness = [\"XY\", \"XZ\", \"YZ\"]\n",
    );
    for axis in Axis::ALL {
        let k = axis.index();
        let offset = plan.optics_offset_mm[k];
        let optics = Optics {
            body: plan.optics_on[k].unwrap_or_else(|| machine.chain().body_moved_by(axis)),
            offset_mm: offset,
        };
        let test_machine = machine
            .with_optics(&optics)
            .map_err(|e| SynthError::Truth(e.to_string()))?;
        let targets = targets(machine, axis, plan.step_mm);
        let own_at_reference = truth
            .function(ErrorName::of(ErrorComponent::Translation {
                axis,
                direction: axis,
            }))
            .map_or(0.0, |f| f.value_at(reference[k]));
        // Columns: the three translations, then the three rotations.
        let mut columns: Vec<GeometryColumn> = Vec::new();
        for (quantity, other) in Axis::ALL
            .iter()
            .map(|d| (Quantity::Translation(d.letter()), *d))
            .chain(
                Axis::ALL
                    .iter()
                    .map(|d| (Quantity::Rotation(d.letter()), *d)),
            )
        {
            let component = match quantity {
                Quantity::Translation(_) => ErrorComponent::Translation {
                    axis,
                    direction: other,
                },
                Quantity::Rotation(_) => ErrorComponent::Rotation { axis, about: other },
            };
            columns.push(GeometryColumn {
                name: ErrorName::of(component).as_str().to_string(),
                quantity,
                unit: match quantity {
                    Quantity::Translation(_) => ColumnUnit::Micrometre,
                    Quantity::Rotation(_) => ColumnUnit::Microradian,
                },
                runs: Vec::new(),
            });
        }
        for number in 1..=plan.runs {
            for direction in Direction::BOTH {
                let mut values: Vec<Vec<Option<f64>>> = vec![Vec::new(); 6];
                for &x in &targets {
                    let mut p = plan.lines_mm[k];
                    p[k] = x;
                    let e = test_machine.volumetric_error(truth, p, Method::Full);
                    // The laser's reference turned by φ: φ × e_axis · x.
                    let phi = nalgebra::Vector3::from(plan.laser_rotation_rad);
                    let mut unit_axis = nalgebra::Vector3::zeros();
                    unit_axis[k] = 1.0;
                    let tilt = phi.cross(&unit_axis) * x;
                    for d in 0..3 {
                        let reading = if d == k {
                            e.translation_mm[d] + own_at_reference
                        } else {
                            // An arbitrary zero of the optics: 1 µm.
                            e.translation_mm[d] + tilt[d] + 0.001
                        };
                        values[d].push(Some(reading + translation_noise.sample(&mut rng)));
                    }
                    for about in 0..3 {
                        // An arbitrary zero of the angular optics: 3 µrad.
                        let reading = e.rotation_rad[about] + 3e-6;
                        values[3 + about].push(Some(reading + angle_noise.sample(&mut rng)));
                    }
                }
                for (column, values) in columns.iter_mut().zip(values) {
                    column.runs.push(GeometryRun {
                        number: u64::from(number),
                        direction,
                        values,
                    });
                }
            }
        }
        let test = GeometryTest {
            axis: axis.letter(),
            targets_mm: targets,
            columns,
            machine: Some(machine.name().to_string()),
        };
        let file = format!("{axis}.csv");
        let [lx, ly, lz] = plan.lines_mm[k];
        let [ox, oy, oz] = offset;
        survey.push_str(&format!(
            "\n[[test]]\nfile = \"{file}\"\nline_mm = {{ x = {lx:?}, y = {ly:?}, z = {lz:?} }}\n\
             optics_offset_mm = {{ x = {ox:?}, y = {oy:?}, z = {oz:?} }}\noptics_on = \"{}\"\n",
            optics.body.name()
        ));
        tests.push((file, crate::read::geometry::write(&test)));
    }
    Ok(SyntheticSurvey { tests, survey })
}
