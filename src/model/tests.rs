//! Tests of the volumetric model against outside references: the notes'
//! first-order expansion of eqs 63–67 (§2.5, derived with sympy), hand
//! derivations for other chains, and the agreement of the two evaluations.

use nalgebra::Vector3;
use proptest::prelude::*;

use super::*;

/// A small deterministic pseudo-random sequence for test values (no RNG
/// crate, so the test does not depend on the code under test).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// All 21 errors: the 18 motion errors as linear tables over their axis
/// (7 points over the stroke) with values up to `translation_mm` and
/// `rotation_rad`, squareness constants up to `rotation_rad`.
fn random_errors(
    machine: &Machine,
    seed: u64,
    translation_mm: f64,
    rotation_rad: f64,
) -> GeometricErrors {
    let mut lcg = Lcg(seed);
    let mut errors = GeometricErrors::default();
    for name in ErrorName::ALL {
        let scale = if name.unit() == "mm" {
            translation_mm
        } else {
            rotation_rad
        };
        let function = match name.component() {
            ErrorComponent::Squareness(_) => ErrorFunction::Constant(scale * lcg.next()),
            ErrorComponent::Translation { axis, .. } | ErrorComponent::Rotation { axis, .. } => {
                let [low, high] = machine.axis(axis).stroke_mm;
                let positions: Vec<f64> = (0..7)
                    .map(|i| low + (high - low) * f64::from(i) / 6.0)
                    .collect();
                let values = positions.iter().map(|_| scale * lcg.next()).collect();
                ErrorFunction::Table(
                    ErrorTable::new(positions, values, Interpolation::Linear).unwrap(),
                )
            }
        };
        errors.set(name, function).unwrap();
    }
    errors
}

/// The notes' §2.5 first-order expansion for ZFYX with z3 = 200, z4 = 80,
/// y2 = 0, yt = 280, zt = 250 (before subtracting E⁰), typed in from the notes.
fn notes_expansion(values: &ErrorValues, [x, y, z]: [f64; 3]) -> Vector3<f64> {
    let (z3, z4, y2, yt, zt) = (200.0, 80.0, 0.0, 280.0, 250.0);
    let t = |axis: usize, direction: usize| values.translation_mm[axis][direction];
    let r = |axis: usize, about: usize| values.rotation_rad[axis][about];
    let (exx, eyx, ezx, eax, ebx, ecx) = (t(0, 0), t(0, 1), t(0, 2), r(0, 0), r(0, 1), r(0, 2));
    let (exy, eyy, ezy, eay, eby, ecy) = (t(1, 0), t(1, 1), t(1, 2), r(1, 0), r(1, 1), r(1, 2));
    let (exz, eyz, ezz, eaz, ebz, ecz) = (t(2, 0), t(2, 1), t(2, 2), r(2, 0), r(2, 1), r(2, 2));
    let exoy = values.squareness.xy_rad;
    let exoz = values.squareness.xz_rad;
    let eyoz = values.squareness.yz_rad;
    let e_x = exx + exy + exz + ebx * (z + z4 + 550.0) + eby * (z + z3 + z4 + 550.0) - ebz * zt
        + ecx * (y - 250.0)
        + ecy * (y - y2 - 250.0)
        + ecz * yt
        + exoy * (y - 250.0)
        + exoz * (z - zt);
    let e_y = eyx + eyy + eyz - eax * (z + z4 + 550.0) - eay * (z + z3 + z4 + 550.0)
        + eaz * zt
        + exoy * x
        + eyoz * (zt - z);
    let e_z = ezx + ezy + ezz + eax * (250.0 - y) + eay * (y2 + 250.0 - y) - eaz * yt - eyoz * yt;
    Vector3::new(e_x, e_y, e_z)
}

fn positions() -> Vec<[f64; 3]> {
    vec![
        [0.0, 0.0, 0.0],
        [750.0, 500.0, -550.0],
        [375.0, 250.0, -275.0],
        [123.4, 456.7, -89.0],
        [700.0, 10.0, -500.0],
    ]
}

#[test]
fn first_order_is_the_notes_expansion_for_zfyx() {
    let machine = Machine::bundled();
    let errors = random_errors(&machine, 1, 0.02, 1e-4);
    let at_origin = notes_expansion(&errors.values_at([0.0; 3]), [0.0; 3]);
    for position in positions() {
        let expected = notes_expansion(&errors.values_at(position), position) - at_origin;
        let actual = machine.volumetric_error(&errors, position, Method::FirstOrder);
        assert!(
            (actual.translation_mm - expected).norm() < 1e-15,
            "at {position:?}: {actual:?} vs {expected}"
        );
    }
}

#[test]
fn rotation_is_the_sum_of_the_angles() {
    // Eq. 69: E_A = EAX + EAY + EAZ + EYOZ, E_B = … + EXOZ, E_C = … + EXOY; not zeroed.
    let machine = Machine::bundled();
    let errors = random_errors(&machine, 2, 0.01, 1e-4);
    let position = [200.0, 300.0, -100.0];
    let v = errors.values_at(position);
    let expected = Vector3::new(
        v.rotation_rad[0][0] + v.rotation_rad[1][0] + v.rotation_rad[2][0] + v.squareness.yz_rad,
        v.rotation_rad[0][1] + v.rotation_rad[1][1] + v.rotation_rad[2][1] + v.squareness.xz_rad,
        v.rotation_rad[0][2] + v.rotation_rad[1][2] + v.rotation_rad[2][2] + v.squareness.xy_rad,
    );
    // First order exactly; the full product adds products of two angles
    // (≤ about 3 · (4e-4)² here).
    for (method, tolerance) in [(Method::FirstOrder, 1e-18), (Method::Full, 5e-7)] {
        let actual = machine
            .volumetric_error(&errors, position, method)
            .rotation_rad;
        assert!(
            (actual - expected).norm() < tolerance,
            "{method:?}: {actual} vs {expected}"
        );
    }
}

#[test]
fn full_transforms_agree_with_first_order_for_micrometre_errors() {
    // Agreement to 1e-9 mm for µm-level errors. The two differ by
    // products of two errors; with every pair of errors at 1 µm or 1 µrad
    // (constant, so at full size everywhere) each product stays below 1e-9 mm
    // on the whole grid (largest found: 9.0e-10 mm, ECY with EXOY on ZFYX).
    for machine in [Machine::bundled(), yfxz_machine(), fxyz_machine()] {
        let grid = Grid::over_strokes(&machine, 125.0).unwrap();
        for (i, first) in ErrorName::ALL.iter().enumerate() {
            for second in &ErrorName::ALL[i + 1..] {
                let mut errors = GeometricErrors::default();
                for name in [*first, *second] {
                    let value = if name.unit() == "mm" { 0.001 } else { 1e-6 };
                    errors.set(name, ErrorFunction::Constant(value)).unwrap();
                }
                let worst = largest_difference(&machine, &errors, &grid);
                assert!(
                    worst < 1e-9,
                    "{}: {first} with {second}: {worst:e} mm",
                    machine.chain().as_str()
                );
            }
        }
    }
}

#[test]
fn all_21_errors_at_once_differ_by_second_order_terms_only() {
    // With all 21 errors at up to 1 µm / 1 µrad at once, the ~200 products
    // add up to a few 1e-9 mm (4.3e-9 mm at worst for ZFYX with these
    // tables), and ten times larger errors give a hundred times more.
    for machine in [Machine::bundled(), yfxz_machine(), fxyz_machine()] {
        let grid = Grid::over_strokes(&machine, 125.0).unwrap();
        let small = largest_difference(&machine, &random_errors(&machine, 1, 0.001, 1e-6), &grid);
        let large = largest_difference(&machine, &random_errors(&machine, 1, 0.01, 1e-5), &grid);
        assert!(small < 1e-8, "{}: {small:e}", machine.chain().as_str());
        let ratio = large / small;
        assert!(
            (99.0..101.0).contains(&ratio),
            "{}: ratio {ratio}",
            machine.chain().as_str()
        );
    }
}

fn largest_difference(machine: &Machine, errors: &GeometricErrors, grid: &Grid) -> f64 {
    let full = machine.error_map(errors, grid, Method::Full);
    let linear = machine.error_map(errors, grid, Method::FirstOrder);
    full.errors
        .iter()
        .zip(&linear.errors)
        .map(|(f, l)| (f.translation_mm - l.translation_mm).norm())
        .fold(0.0, f64::max)
}

#[test]
fn translations_alone_add_exactly() {
    // Pure translations commute: the full product is the first-order sum.
    let machine = Machine::bundled();
    let mut errors = GeometricErrors::default();
    for (k, name) in [
        ErrorName::EXX,
        ErrorName::EYY,
        ErrorName::EZZ,
        ErrorName::EZX,
        ErrorName::EXZ,
    ]
    .into_iter()
    .enumerate()
    {
        let value = 0.01 * (k as f64 + 1.0);
        let table = ErrorTable::new(
            vec![-600.0, 800.0],
            vec![-value, value],
            Interpolation::Linear,
        )
        .unwrap();
        errors.set(name, ErrorFunction::Table(table)).unwrap();
    }
    let position = [300.0, 100.0, -200.0];
    let full = machine.volumetric_error(&errors, position, Method::Full);
    let linear = machine.volumetric_error(&errors, position, Method::FirstOrder);
    // Only rounding differs (positions of ~1000 mm carry ~1e-13 mm).
    assert!((full.translation_mm - linear.translation_mm).norm() < 1e-12);
}

#[test]
fn difference_flips_the_workpiece_branch() {
    // Workpiece-side EYY only: the sum gives +ΔEYY, the difference −ΔEYY;
    // the tool-side EZZ keeps its sign.
    let machine = Machine::bundled();
    let mut errors = GeometricErrors::default();
    let ramp = ErrorTable::new(
        vec![-1000.0, 1000.0],
        vec![-0.001, 0.001],
        Interpolation::Linear,
    )
    .unwrap();
    errors
        .set(ErrorName::EYY, ErrorFunction::Table(ramp.clone()))
        .unwrap();
    errors
        .set(ErrorName::EZZ, ErrorFunction::Table(ramp))
        .unwrap();
    let position = [0.0, 400.0, -300.0];
    let sum = machine.volumetric_error(&errors, position, Method::Full);
    let difference = machine
        .with_branch_deviations(BranchDeviations::Difference)
        .volumetric_error(&errors, position, Method::Full);
    assert!((sum.translation_mm.y - 0.0004).abs() < 1e-12);
    assert!((difference.translation_mm.y + 0.0004).abs() < 1e-12);
    assert!((sum.translation_mm.z - difference.translation_mm.z).abs() < 1e-12);
    assert!((sum.translation_mm.z + 0.0003).abs() < 1e-12);
}

#[test]
fn a_longer_tool_lengthens_the_tool_side_abbe_arm() {
    // Notes §2.5: E_X has −EBZ·zt. A yaw EBZ that grows along Z by 1 µrad
    // per 100 mm, read between Z = 0 and Z = −500: ΔEBZ = −5 µrad.
    let machine = Machine::bundled();
    let mut errors = GeometricErrors::default();
    let ramp =
        ErrorTable::new(vec![-550.0, 0.0], vec![-5.5e-6, 0.0], Interpolation::Linear).unwrap();
    errors
        .set(ErrorName::EBZ, ErrorFunction::Table(ramp))
        .unwrap();
    for zt in [250.0, 400.0] {
        let tool = machine.with_tool_offset([0.0, -280.0, -zt]).unwrap();
        let error = tool.volumetric_error(&errors, [0.0, 0.0, -500.0], Method::FirstOrder);
        assert!(
            (error.translation_mm.x - 5e-6 * zt).abs() < 1e-15,
            "zt = {zt}"
        );
    }
}

/// A YFXZ machine for hand checks: Y carries the tool 100 mm below its error
/// frame; X carries Z carries the workpiece; every frame moves with its body.
pub(super) fn yfxz_machine() -> Machine {
    let text = Machine::bundled_toml()
        .replace("chain = \"ZFYX\"", "chain = \"YFXZ\"")
        .replace(
            "offset_mm = [0.0, -280.0, -250.0]",
            "offset_mm = [0.0, 0.0, -100.0]",
        )
        .replace(
            "offset_mm = [0.0, 0.0, 80.0]",
            "offset_mm = [0.0, 0.0, 0.0]",
        )
        .replace(
            "point_mm = [0.0, 250.0, 550.0]",
            "point_mm = [0.0, 0.0, -100.0]",
        )
        .replace(
            "offset_mm = [0.0, 0.0, 200.0]",
            "offset_mm = [0.0, 0.0, 0.0]",
        )
        .replace("motion = -1", "motion = 1")
        .replace("error_frame = \"fixed\"", "error_frame = \"moving\"");
    Machine::from_toml_str(&text).unwrap()
}

pub(super) fn fxyz_machine() -> Machine {
    let text = Machine::bundled_toml().replace("chain = \"ZFYX\"", "chain = \"FXYZ\"");
    Machine::from_toml_str(&text).unwrap()
}

#[test]
fn yfxz_arms_by_hand() {
    // Tool side: the tool tip is 100 mm below the Y error frame, so a roll
    // of Y about X, EAY = k·Y, moves it by ε × (0, 0, −100) = (0, 100·EAY, 0).
    // Workpiece side: X carries Z; the point under the tool is at
    // (−X, Y, −100) from the X error frame (X moved +X, the tool moved +Y),
    // so a yaw of X, ECX = c, gives (0, 0, c) × (−X, Y, −100) = (−cY, −cX, 0).
    let machine = yfxz_machine();
    let k = 1e-8;
    let c = 3e-6;
    let mut errors = GeometricErrors::default();
    let roll = ErrorTable::new(
        vec![0.0, 500.0],
        vec![0.0, 500.0 * k],
        Interpolation::Linear,
    )
    .unwrap();
    errors
        .set(ErrorName::EAY, ErrorFunction::Table(roll))
        .unwrap();
    errors
        .set(ErrorName::ECX, ErrorFunction::Constant(c))
        .unwrap();
    let (x, y, z) = (600.0, 300.0, -200.0);
    for method in [Method::FirstOrder, Method::Full] {
        let error = machine
            .volumetric_error(&errors, [x, y, z], method)
            .translation_mm;
        let expected = Vector3::new(-c * y, 100.0 * k * y - c * x, 0.0);
        assert!(
            (error - expected).norm() < 1e-12,
            "{method:?}: {error} vs {expected}"
        );
    }
}

#[test]
fn squareness_xy_tilts_x_motion_in_the_thesis_chain() {
    // Notes §2.5: EXOY enters E_Y as EXOY·X and E_X as EXOY·(Y − 250).
    let machine = Machine::bundled();
    let mut errors = GeometricErrors::default();
    errors
        .set(ErrorName::EXOY, ErrorFunction::Constant(30e-6))
        .unwrap();
    let error = machine.volumetric_error(&errors, [500.0, 200.0, -100.0], Method::Full);
    assert!(
        (error.translation_mm - Vector3::new(30e-6 * 200.0, 30e-6 * 500.0, 0.0)).norm() < 1e-12
    );
}

#[test]
fn grids() {
    let machine = Machine::bundled();
    let grid = Grid::over_strokes(&machine, 50.0).unwrap();
    // The peer's grid: 16 × 11 × 12 = 2112 points.
    assert_eq!(grid.counts(), [16, 11, 12]);
    assert_eq!(grid.len(), 2112);
    assert_eq!(grid.position_mm(0), [0.0, 0.0, -550.0]);
    assert_eq!(grid.position_mm(11), [0.0, 0.0, 0.0]);
    assert_eq!(grid.position_mm(12), [0.0, 50.0, -550.0]);
    assert_eq!(grid.position_mm(2111), [750.0, 500.0, 0.0]);
    // 70 mm steps: 0, 70, …, 700 and the stroke's end 750.
    let coarse = Grid::over_strokes(&machine, 70.0).unwrap();
    assert_eq!(coarse.axis_mm(Axis::X).len(), 12);
    assert_eq!(coarse.axis_mm(Axis::X)[11], 750.0);
    assert!(Grid::over_strokes(&machine, 0.0).is_err());
    assert!(Grid::from_axes([vec![0.0], vec![], vec![1.0]]).is_err());
    assert!(Grid::from_axes([vec![0.0, 0.0], vec![1.0], vec![1.0]]).is_err());
}

#[test]
fn error_map_holds_the_pointwise_errors_and_the_maximum() {
    let machine = Machine::bundled();
    let errors = random_errors(&machine, 4, 0.01, 2e-5);
    let grid = Grid::over_strokes(&machine, 125.0).unwrap();
    let map = machine.error_map(&errors, &grid, Method::Full);
    assert_eq!(map.errors.len(), grid.len());
    let probe = 37;
    let position = grid.position_mm(probe);
    assert_eq!(
        map.errors[probe],
        machine.volumetric_error(&errors, position, Method::Full)
    );
    let (max_mm, at) = map.max_translation();
    let brute = map
        .errors
        .iter()
        .map(|e| e.translation_mm.norm())
        .fold(0.0, f64::max);
    assert_eq!(max_mm, brute);
    assert_eq!(
        machine
            .volumetric_error(&errors, at, Method::Full)
            .translation_mm
            .norm(),
        max_mm
    );
    // The reference position itself has no error (eq. 68).
    assert_eq!(
        machine
            .volumetric_error(&errors, [0.0; 3], Method::Full)
            .translation_mm
            .norm(),
        0.0
    );
}

proptest! {
    // The first-order model is linear in the errors: E(a + b) = E(a) + E(b).
    #[test]
    fn first_order_superposes(seed_a in 0u64..1000, seed_b in 1000u64..2000, x in 0.0f64..750.0, y in 0.0f64..500.0, z in -550.0f64..0.0) {
        let machine = Machine::bundled();
        let a = random_errors(&machine, seed_a, 0.01, 1e-4);
        let b = random_errors(&machine, seed_b, 0.01, 1e-4);
        let mut sum = GeometricErrors::default();
        for name in ErrorName::ALL {
            let combined = match (a.function(name), b.function(name)) {
                (Some(ErrorFunction::Table(ta)), Some(ErrorFunction::Table(tb))) => {
                    let values = ta.values().iter().zip(tb.values()).map(|(p, q)| p + q).collect();
                    ErrorFunction::Table(ErrorTable::new(ta.positions_mm().to_vec(), values, Interpolation::Linear).unwrap())
                }
                _ => ErrorFunction::Constant(match name.component() {
                    ErrorComponent::Squareness(pair) => a.squareness.get(pair) + b.squareness.get(pair),
                    _ => 0.0,
                }),
            };
            sum.set(name, combined).unwrap();
        }
        let position = [x, y, z];
        let e = |errors: &GeometricErrors| machine.volumetric_error(errors, position, Method::FirstOrder).translation_mm;
        prop_assert!((e(&sum) - e(&a) - e(&b)).norm() < 1e-13);
    }
}

/// Valášek's (2021) simplified model, eqs 72–79, typed in from the notes (§2.6):
/// no kinematic dimensions, each axis's error matrix applied at its own
/// frame's origin (so angles do not enter), squareness matrices in front of
/// Y (EXOY) and Z (EXOZ, EYOZ). `delta(axis, q)` gives the axis's three
/// translation errors at its coordinate; the squareness values in rad.
fn simplified_model(
    delta: impl Fn(Axis, f64) -> Vector3<f64>,
    squareness: Squareness,
    [x, y, z]: [f64; 3],
) -> Vector3<f64> {
    use nalgebra::{Matrix4, Vector4};
    let translation = |v: Vector3<f64>| Matrix4::new_translation(&v);
    // Eqs 51–53: rotations about Z (EXOY), Y (EXOZ), X (EYOZ), linearised.
    let rotation = |about: usize, angle: f64| {
        let mut m = Matrix4::identity();
        let (i, j) = [(1, 2), (2, 0), (0, 1)][about];
        m[(i, j)] = -angle;
        m[(j, i)] = angle;
        m
    };
    let r1 = Vector4::new(0.0, 0.0, 0.0, 1.0);
    let rx = translation(Vector3::new(x, 0.0, 0.0)) * translation(delta(Axis::X, x)) * r1;
    let ry = rotation(2, squareness.xy_rad)
        * translation(Vector3::new(0.0, y, 0.0))
        * translation(delta(Axis::Y, y))
        * r1;
    let rz = rotation(1, squareness.xz_rad)
        * rotation(0, squareness.yz_rad)
        * translation(Vector3::new(0.0, 0.0, z))
        * translation(delta(Axis::Z, z))
        * r1;
    // Eq. 79: the sum of each axis's deviation from its ideal point.
    (rx.xyz() - Vector3::new(x, 0.0, 0.0))
        + (ry.xyz() - Vector3::new(0.0, y, 0.0))
        + (rz.xyz() - Vector3::new(0.0, 0.0, z))
}

#[test]
fn the_simplified_model_agrees_with_the_full_chain_along_lines_through_the_origin() {
    // Valášek (2021) §3.3.5 (notes §5): with errors identified from volumetric
    // measurements without the machine's dimensions (Trac-cal), the
    // simplified model (eqs 72–79) matched the measured error along lines
    // through the origin [0, 0, 0] and deviated away from it. Here the
    // "measurement" is the full chain (ZFYX, all 21 errors at µm/µrad
    // scale), and the dimensionless identification takes each axis's
    // translation errors as the full chain's error along that axis's line
    // through the origin (squareness and Abbe terms included, so the
    // simplified model's own squareness is zero).
    let machine = Machine::bundled();
    let errors = random_errors(&machine, 72, 0.005, 10e-6);
    let full = |p: [f64; 3]| {
        machine
            .volumetric_error(&errors, p, Method::Full)
            .translation_mm
    };
    let on_axis = |axis: Axis, q: f64| {
        let mut p = [0.0; 3];
        p[axis.index()] = q;
        full(p)
    };
    let simplified = |p| simplified_model(on_axis, Squareness::default(), p);
    let mut along_origin_lines: f64 = 0.0;
    for axis in Axis::ALL {
        let [low, high] = machine.axis(axis).stroke_mm;
        for i in 0..=20 {
            let mut p = [0.0; 3];
            p[axis.index()] = low + (high - low) * f64::from(i) / 20.0;
            along_origin_lines = along_origin_lines.max((full(p) - simplified(p)).norm());
        }
    }
    assert!(along_origin_lines < 1e-12, "{along_origin_lines}");
    // Away from the origin the two part: the full chain has each angle
    // times the other axes' positions (notes §2.5: EBX·Z, ECX·Y, EAX·Z, …),
    // which no dimensionless model holds. X's line at Y = 500, Z = −550:
    let mut off_origin: f64 = 0.0;
    for i in 0..=20 {
        let p = [750.0 * f64::from(i) / 20.0, 500.0, -550.0];
        off_origin = off_origin.max((full(p) - simplified(p)).norm());
    }
    assert!(off_origin > 0.002, "{off_origin}");
    // Without angles the errors add, so the two agree on every line (only
    // products of two errors differ, ≤ 1e-9 mm).
    let mut flat = errors.clone();
    for name in ErrorName::ALL {
        if matches!(name.component(), ErrorComponent::Rotation { .. }) {
            flat.set(name, ErrorFunction::Constant(0.0)).unwrap();
        }
    }
    let full_flat = |p: [f64; 3]| {
        machine
            .volumetric_error(&flat, p, Method::Full)
            .translation_mm
    };
    let on_axis_flat = |axis: Axis, q: f64| {
        let mut p = [0.0; 3];
        p[axis.index()] = q;
        full_flat(p)
    };
    let p = [600.0, 350.0, -420.0];
    let gap = (full_flat(p) - simplified_model(on_axis_flat, Squareness::default(), p)).norm();
    assert!(gap < 1e-9, "{gap}");
    // The typed-in squareness terms against the notes' first order (§2.6):
    // E_x = −EXOY·Y + EXOZ·Z, E_y = −EYOZ·Z.
    let none = |_: Axis, _: f64| Vector3::zeros();
    let s = Squareness {
        xy_rad: 1e-5,
        xz_rad: 2e-5,
        yz_rad: 3e-5,
    };
    let e = simplified_model(none, s, [0.0, 100.0, -200.0]);
    assert!((e.x - (-1e-5 * 100.0 + 2e-5 * -200.0)).abs() < 1e-15, "{e}");
    assert!((e.y - (-3e-5 * -200.0)).abs() < 1e-15, "{e}");
    assert_eq!(e.z, 0.0);
}
