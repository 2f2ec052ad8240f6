//! One linear axis on two rails and four carriages: from the straightness of
//! the rail mounting surfaces to the error motions of the saddle.
//!
//! Valášek (2021) §3.1–3.2 (`../shared/notes/seed000-volumetric-model.md` §3): a
//! rigid saddle rests on four carriages, linear springs of stiffness k_i
//! (N/mm) in the direction normal to the rail mounting face ("vertical", z)
//! and across it ("horizontal", y). The rails copy their mounting surfaces,
//! so carriage i sits on a rail deviation d_zi, d_yi and deforms by
//! Δ_i = F_i / k_i; the saddle corner moves by z_i = d_zi + Δ_zi.
//!
//! Carriage indexing (derived from eqs 40–47, the figure is missing): with
//! rail spacing a and carriage pitch b, at axis position x carriage 1 is on
//! rail 1 at x − b/2, carriage 2 on rail 1 at x + b/2, carriage 3 on rail 2
//! at x + b/2 and carriage 4 on rail 2 at x − b/2 (1→2→3→4 goes round the
//! rectangle).
//!
//! - Normal direction: force balance (9), moments (10), (11) and the
//!   coplanarity of the four corners (12), solved as K_z F_z = Q_z (14). The
//!   printed matrix (13) is garbled (5 × 4); the consistent 4 × 4 form of the
//!   notes is used. Outputs z5 = mean z_i (17), roll = (z4 − z1)/a (18),
//!   pitch = (z2 − z1)/b (19).
//! - Lateral direction: force balance (29), moment (30) and equal lateral
//!   displacement across the rails (31), (32) as K_y F_y = Q_y (33); eq. 25
//!   prints Δ_y4 where eq. 28 (and sense) has Δ_y3. Outputs y5 = mean y_i
//!   (37), yaw = (y1 − y2)/b (38).
//!
//! The loads act at the saddle centre: F_zz downwards (Valášek's sign,
//! −F_zz in eq. 9) and F_zy sideways (+F_zy in eq. 29). Both problems are
//! linear, so [`Guideway::linear_map`] solves them once for unit inputs and
//! the Monte Carlo study applies the resulting weights to every sample. With
//! equal stiffness and no load, z5 and y5 are the means of the four rail
//! deviations (the notes' closed forms, §3.5), which the tests check.
//!
//! Tilting stiffness of the carriages is neglected, as in Valášek (2021).
//!
//! # The carriage side: the saddle's mounting faces
//!
//! Valášek's (2021) assignment asks for errors "on the rail side and on the
//! carriage side"; Valášek (2021) models only the rails (notes §3.6). The carriage-side thesis (references.md)
//! (the paper of the same work, §4) names the carriage-side input, "the
//! prescribed parallelism tolerance of the faces for the carriages on the
//! saddle", and draws it in Obr. 8, which the text lacks. [`SaddleFaces`]
//! models it: the four pads on the saddle that the carriages are bolted to
//! are not exactly in the plane of the saddle's datum face (the face that
//! carries the next member of the chain). Pad i sits e_i further from the
//! rails than it should, so the datum face above carriage i moves by
//! d_zi + e_i + Δ_zi: a pad error adds to the rail deviation under its
//! carriage, and the equilibrium above applies unchanged. What differs from
//! a rail error is that the pads travel with the saddle: e_i is the same at
//! every position of the stroke. Split into the three shapes four points can
//! have about a plane (ISO 1101 terms):
//!
//! - **parallelism** of the pads' plane to the datum face: a tilt across the
//!   rails (height difference between the rail-2 and the rail-1 pads, Δ_a)
//!   and along them (ahead minus behind, Δ_b). With equal stiffness it gives a
//!   constant roll Δ_a/a (eq. 18 with z4 − z1 = Δ_a) and a constant pitch
//!   Δ_b/b (eq. 19), for the whole stroke. A constant angle is not removed by
//!   the reference position: it acts through the Abbe arms, which change
//!   with the other axes' positions, as a squareness error does.
//! - **flatness** of the four pads: their twist c·(+1, −1, +1, −1), which
//!   no plane takes out (the sum of the signed residuals is 4c for any
//!   plane, so the minimum zone is 2|c|). The coplanarity condition (12)
//!   makes the carriages take it up: with equal stiffness z_i = e_i ∓ τ/4 =
//!   0 (notes §3.5, τ = 4c), so the saddle does not move and each carriage
//!   is loaded by ∓k·c. With unequal stiffness part of the twist turns into
//!   roll and pitch, which [`GuidewayMap`] computes.
//!
//! A lateral counterpart (the carriages' locating edges on the saddle) would
//! enter the lateral system the same way; the carriage-side thesis (references.md) names only the mounting
//! faces, and it is not modelled.

use nalgebra::{Matrix4, Vector4};

use super::components::ErrorFunction;
use super::{ModelError, check_positive};

/// The geometry, stiffness and load of one axis's guideway (Valášek (2021) Tab. 3.1, 3.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Guideway {
    /// a: distance between the two rails, mm.
    pub rail_spacing_mm: f64,
    /// b: distance between the two carriages on one rail, mm.
    pub carriage_pitch_mm: f64,
    /// k_z1 … k_z4: carriage stiffness normal to the mounting face, N/mm.
    pub stiffness_normal_n_per_mm: [f64; 4],
    /// k_y1 … k_y4: carriage stiffness across the rail, N/mm.
    pub stiffness_lateral_n_per_mm: [f64; 4],
    /// F_zz: load normal to the mounting face at the saddle centre, N
    /// (positive pushes the saddle towards the rails, eq. 9).
    pub load_normal_n: f64,
    /// F_zy: lateral load at the saddle centre, N (eq. 29).
    pub load_lateral_n: f64,
}

/// The stiffness of every carriage in Valášek (2021) (Tab. 3.3, 3.4), N/mm.
pub const THESIS_STIFFNESS_N_PER_MM: f64 = 100_000.0;

impl Guideway {
    /// Four equal carriages of Valášek's stiffness, no load.
    pub fn unloaded(rail_spacing_mm: f64, carriage_pitch_mm: f64) -> Guideway {
        Guideway {
            rail_spacing_mm,
            carriage_pitch_mm,
            stiffness_normal_n_per_mm: [THESIS_STIFFNESS_N_PER_MM; 4],
            stiffness_lateral_n_per_mm: [THESIS_STIFFNESS_N_PER_MM; 4],
            load_normal_n: 0.0,
            load_lateral_n: 0.0,
        }
    }

    /// Solves the equilibrium for the rail deviations under the four carriages.
    ///
    /// # Example
    ///
    /// Valášek's Obr. 3.8 example; the check values are the notes' §3.3:
    ///
    /// ```
    /// use axcomp::model::{CarriageDeviations, Guideway};
    ///
    /// let guideway = Guideway::unloaded(150.0, 200.0);
    /// let deviations = CarriageDeviations {
    ///     normal_mm: [0.006, 0.001, 0.0, -0.004],
    ///     lateral_mm: [0.0; 4],
    /// };
    /// let response = guideway.solve(&deviations)?;
    /// assert!((response.normal_mm - 0.00075).abs() < 1e-15);
    /// assert!((response.pitch_rad - -2.5e-6).abs() < 1e-15);
    /// # Ok::<(), axcomp::model::ModelError>(())
    /// ```
    pub fn solve(&self, deviations: &CarriageDeviations) -> Result<GuidewayResponse, ModelError> {
        Ok(self.linear_map()?.response(deviations))
    }

    /// Checks the parameters and solves both systems once, for reuse.
    pub fn linear_map(&self) -> Result<GuidewayMap, ModelError> {
        self.check()?;
        let k_z = self.stiffness_normal_n_per_mm;
        let k_y = self.stiffness_lateral_n_per_mm;
        // K_z F_z = Q_z, the consistent form of eq. 13 (rows: eqs 9, 10, 11, 12).
        #[rustfmt::skip]
        let matrix_z = Matrix4::new(
            1.0, 1.0, 1.0, 1.0,
            1.0, 1.0, 0.0, 0.0,
            0.0, 1.0, 1.0, 0.0,
            1.0 / k_z[0], -1.0 / k_z[1], 1.0 / k_z[2], -1.0 / k_z[3],
        );
        // K_y F_y = Q_y, eq. 33 (rows: eqs 29, 30, 31, 32).
        #[rustfmt::skip]
        let matrix_y = Matrix4::new(
            1.0, 1.0, 1.0, 1.0,
            0.0, 1.0, 1.0, 0.0,
            1.0 / k_y[0], 0.0, 0.0, -1.0 / k_y[3],
            0.0, 1.0 / k_y[1], -1.0 / k_y[2], 0.0,
        );
        let singular = || {
            ModelError::invalid(
                "guideway",
                "carriage stiffnesses that give a solvable equilibrium",
                format!("{:?} and {:?} N/mm", k_z, k_y),
            )
        };
        let inverse_z = matrix_z.try_inverse().ok_or_else(singular)?;
        let inverse_y = matrix_y.try_inverse().ok_or_else(singular)?;
        let f_zz = self.load_normal_n;
        let f_zy = self.load_lateral_n;
        // Corner displacement z = d + diag(1/k) K⁻¹ Q(d): affine in d. The
        // d-part of Q_z is (0, 0, 0, −d1 + d2 − d3 + d4), of Q_y
        // (0, 0, −d1 + d4, −d2 + d3).
        let twist = Vector4::new(-1.0, 1.0, -1.0, 1.0);
        let mut normal = Matrix4::identity();
        let mut lateral = Matrix4::identity();
        for input in 0..4 {
            let force_z = inverse_z.column(3) * twist[input];
            let q_y = match input {
                0 => Vector4::new(0.0, 0.0, -1.0, 0.0),
                1 => Vector4::new(0.0, 0.0, 0.0, -1.0),
                2 => Vector4::new(0.0, 0.0, 0.0, 1.0),
                _ => Vector4::new(0.0, 0.0, 1.0, 0.0),
            };
            let force_y = inverse_y * q_y;
            for corner in 0..4 {
                normal[(corner, input)] += force_z[corner] / k_z[corner];
                lateral[(corner, input)] += force_y[corner] / k_y[corner];
            }
        }
        let load_force_z = inverse_z * Vector4::new(-f_zz, -f_zz / 2.0, -f_zz / 2.0, 0.0);
        let load_force_y = inverse_y * Vector4::new(f_zy, f_zy / 2.0, 0.0, 0.0);
        let inverse_stiffness_z = Vector4::from_fn(|i, _| 1.0 / k_z[i]);
        let inverse_stiffness_y = Vector4::from_fn(|i, _| 1.0 / k_y[i]);
        Ok(GuidewayMap {
            rail_spacing_mm: self.rail_spacing_mm,
            carriage_pitch_mm: self.carriage_pitch_mm,
            inverse_z,
            inverse_y,
            normal,
            lateral,
            load_normal_mm: load_force_z.component_mul(&inverse_stiffness_z),
            load_lateral_mm: load_force_y.component_mul(&inverse_stiffness_y),
            load_force_normal_n: load_force_z,
            load_force_lateral_n: load_force_y,
        })
    }

    fn check(&self) -> Result<(), ModelError> {
        check_positive(
            "rail spacing a",
            self.rail_spacing_mm,
            "a positive length in mm",
        )?;
        check_positive(
            "carriage pitch b",
            self.carriage_pitch_mm,
            "a positive length in mm",
        )?;
        let stiffnesses = self
            .stiffness_normal_n_per_mm
            .iter()
            .chain(&self.stiffness_lateral_n_per_mm);
        if let Some(bad) = stiffnesses
            .into_iter()
            .find(|k| !(k.is_finite() && **k > 0.0))
        {
            return Err(ModelError::invalid(
                "carriage stiffness",
                "a positive number of N/mm",
                bad.to_string(),
            ));
        }
        for (what, value) in [
            ("normal load", self.load_normal_n),
            ("lateral load", self.load_lateral_n),
        ] {
            if !value.is_finite() {
                return Err(ModelError::invalid(
                    what,
                    "a finite force in N",
                    value.to_string(),
                ));
            }
        }
        Ok(())
    }
}

/// The rail deviations under the four carriages (d_z1 … d_z4, d_y1 … d_y4), mm.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CarriageDeviations {
    /// Normal to the mounting face ("vertical"), carriages 1–4.
    pub normal_mm: [f64; 4],
    /// Across the rail ("horizontal"), carriages 1–4.
    pub lateral_mm: [f64; 4],
}

impl CarriageDeviations {
    /// The deviations under the carriages with the saddle's pad errors added
    /// to the normal ones (a pad error adds to the rail deviation under its
    /// carriage; see the module's "carriage side").
    pub fn with_saddle_faces(mut self, faces: &SaddleFaces) -> CarriageDeviations {
        for (deviation, pad) in self.normal_mm.iter_mut().zip(faces.pad_heights_mm()) {
            *deviation += pad;
        }
        self
    }
}

/// The errors of the saddle's four carriage mounting faces (pads), normal to
/// them, relative to the saddle's datum face, mm (the carriage side; the carriage-side thesis (references.md)
/// Obr. 8). Constant along the stroke: the pads travel with the saddle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SaddleFaces {
    /// Δ_a: pads on rail 2 (carriages 3, 4) minus pads on rail 1 (1, 2), mm.
    /// Its largest value is the parallelism tolerance across the rails.
    pub tilt_across_mm: f64,
    /// Δ_b: pads ahead (2, 3) minus pads behind (1, 4), mm.
    pub tilt_along_mm: f64,
    /// c: the twist, pads 1 and 3 up by c and 2 and 4 down by c, mm;
    /// the flatness of the four pads is 2|c|.
    pub twist_mm: f64,
}

impl SaddleFaces {
    /// e_1 … e_4: how much further from the rails the datum face sits above
    /// each carriage (carriage 1 rail 1 behind, 2 rail 1 ahead, 3 rail 2
    /// ahead, 4 rail 2 behind), mm. The plane part has zero mean, so the
    /// pads' mean height (a constant offset, removed by the reference
    /// position) is not part of the description.
    pub fn pad_heights_mm(&self) -> [f64; 4] {
        let (a, b, c) = (
            self.tilt_across_mm / 2.0,
            self.tilt_along_mm / 2.0,
            self.twist_mm,
        );
        [-a - b + c, -a + b - c, a + b + c, a - b - c]
    }
}

/// What the saddle does on given rail deviations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuidewayResponse {
    /// z_1 … z_4: normal displacement of the saddle corners, mm (eq. 16).
    pub corner_normal_mm: [f64; 4],
    /// y_1 … y_4: lateral displacement of the saddle corners, mm (eq. 36).
    pub corner_lateral_mm: [f64; 4],
    /// F_z1 … F_z4: normal carriage forces, N (eq. 15).
    pub force_normal_n: [f64; 4],
    /// F_y1 … F_y4: lateral carriage forces, N (eq. 35).
    pub force_lateral_n: [f64; 4],
    /// z5: normal straightness at the saddle centre, mm (eq. 17).
    pub normal_mm: f64,
    /// y5: lateral straightness at the saddle centre, mm (eq. 37).
    pub lateral_mm: f64,
    /// (z4 − z1)/a, rad (eq. 18).
    pub roll_rad: f64,
    /// (z2 − z1)/b, rad (eq. 19).
    pub pitch_rad: f64,
    /// (y1 − y2)/b, rad (eq. 38).
    pub yaw_rad: f64,
}

/// A guideway with both systems solved: the response is affine in the rail deviations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuidewayMap {
    rail_spacing_mm: f64,
    carriage_pitch_mm: f64,
    inverse_z: Matrix4<f64>,
    inverse_y: Matrix4<f64>,
    /// Corner normal displacement per unit normal rail deviation.
    normal: Matrix4<f64>,
    /// Corner lateral displacement per unit lateral rail deviation.
    lateral: Matrix4<f64>,
    /// Corner displacements and carriage forces due to the loads alone.
    load_normal_mm: Vector4<f64>,
    load_lateral_mm: Vector4<f64>,
    load_force_normal_n: Vector4<f64>,
    load_force_lateral_n: Vector4<f64>,
}

/// The five outputs as weights on the rail deviations plus a constant (the load's share):
/// `output = Σ_i weights[i] · d_i + constant`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutputWeights {
    /// Weights on d_1 … d_4 (normal deviations for z5, roll and pitch; lateral for y5 and yaw).
    pub weights: [f64; 4],
    /// The part that does not depend on the rail deviations.
    pub constant: f64,
}

impl GuidewayMap {
    /// The full response to given rail deviations.
    pub fn response(&self, deviations: &CarriageDeviations) -> GuidewayResponse {
        let d_z = Vector4::from(deviations.normal_mm);
        let d_y = Vector4::from(deviations.lateral_mm);
        let z = self.normal * d_z + self.load_normal_mm;
        let y = self.lateral * d_y + self.load_lateral_mm;
        // Forces from F = K⁻¹ Q (eqs 15, 35) rather than k_i (z_i − d_i),
        // which would cancel digits.
        let q_z = Vector4::new(0.0, 0.0, 0.0, -d_z[0] + d_z[1] - d_z[2] + d_z[3]);
        let q_y = Vector4::new(0.0, 0.0, -d_y[0] + d_y[3], -d_y[1] + d_y[2]);
        let force_z = self.inverse_z * q_z + self.load_force_normal_n;
        let force_y = self.inverse_y * q_y + self.load_force_lateral_n;
        GuidewayResponse {
            corner_normal_mm: z.into(),
            corner_lateral_mm: y.into(),
            force_normal_n: force_z.into(),
            force_lateral_n: force_y.into(),
            normal_mm: z.mean(),
            lateral_mm: y.mean(),
            roll_rad: (z[3] - z[0]) / self.rail_spacing_mm,
            pitch_rad: (z[1] - z[0]) / self.carriage_pitch_mm,
            yaw_rad: (y[0] - y[1]) / self.carriage_pitch_mm,
        }
    }

    /// z5, roll and pitch (normal) as weights on d_z1 … d_z4.
    pub fn normal_outputs(&self) -> [OutputWeights; 3] {
        let (a, b) = (self.rail_spacing_mm, self.carriage_pitch_mm);
        let of = |combination| combine(&self.normal, &self.load_normal_mm, combination);
        [
            of([0.25; 4]),                     // z5 = mean z_i (17)
            of([-1.0 / a, 0.0, 0.0, 1.0 / a]), // roll = (z4 − z1)/a (18)
            of([-1.0 / b, 1.0 / b, 0.0, 0.0]), // pitch = (z2 − z1)/b (19)
        ]
    }

    /// y5 and yaw (lateral) as weights on d_y1 … d_y4.
    pub fn lateral_outputs(&self) -> [OutputWeights; 2] {
        let b = self.carriage_pitch_mm;
        let of = |combination| combine(&self.lateral, &self.load_lateral_mm, combination);
        [
            of([0.25; 4]),                     // y5 = mean y_i (37)
            of([1.0 / b, -1.0 / b, 0.0, 0.0]), // yaw = (y1 − y2)/b (38)
        ]
    }
}

/// The weights of Σ_corner combination[corner] · (corner displacement), where
/// the corner displacements are `corners · d + load`.
fn combine(corners: &Matrix4<f64>, load: &Vector4<f64>, combination: [f64; 4]) -> OutputWeights {
    let combination = Vector4::from(combination);
    OutputWeights {
        weights: (corners.transpose() * combination).into(),
        constant: combination.dot(load),
    }
}

/// The four rail profiles of one axis, as functions of the position along the
/// rail (the axis coordinate), mm: the straightness of the mounting surfaces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RailProfiles {
    /// Rail 1 and rail 2, normal to the mounting face ("vertical").
    pub normal: [ErrorFunction; 2],
    /// Rail 1 and rail 2, across the rail ("horizontal").
    pub lateral: [ErrorFunction; 2],
}

impl GuidewayMap {
    /// The rail deviations under the four carriages at axis position `position_mm`
    /// (eqs 40–47: carriages 1 and 4 at x − b/2, 2 and 3 at x + b/2; 1, 2 on rail 1).
    pub fn deviations_at(&self, rails: &RailProfiles, position_mm: f64) -> CarriageDeviations {
        let behind = position_mm - self.carriage_pitch_mm / 2.0;
        let ahead = position_mm + self.carriage_pitch_mm / 2.0;
        let under = |profiles: &[ErrorFunction; 2]| {
            [
                profiles[0].value_at(behind),
                profiles[0].value_at(ahead),
                profiles[1].value_at(ahead),
                profiles[1].value_at(behind),
            ]
        };
        CarriageDeviations {
            normal_mm: under(&rails.normal),
            lateral_mm: under(&rails.lateral),
        }
    }

    /// The response at every axis position: straightness in both
    /// directions, roll, pitch and yaw along the stroke.
    pub fn along_stroke(
        &self,
        rails: &RailProfiles,
        positions_mm: &[f64],
    ) -> Vec<GuidewayResponse> {
        positions_mm
            .iter()
            .map(|position| self.response(&self.deviations_at(rails, *position)))
            .collect()
    }

    /// b, mm.
    pub fn carriage_pitch_mm(&self) -> f64 {
        self.carriage_pitch_mm
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use proptest::prelude::*;

    #[test]
    fn thesis_example_obr_3_8() {
        // Check values of the notes §3.3 (a = 150, b = 200, k = 100 000 N/mm, no load).
        let guideway = Guideway::unloaded(150.0, 200.0);
        let response = guideway
            .solve(&CarriageDeviations {
                normal_mm: [0.006, 0.001, 0.0, -0.004],
                lateral_mm: [0.0; 4],
            })
            .unwrap();
        let expected_z = [0.00375, 0.00325, -0.00225, -0.00175];
        for (actual, expected) in response.corner_normal_mm.iter().zip(expected_z) {
            assert_abs_diff_eq!(*actual, expected, epsilon = 1e-15);
        }
        assert_abs_diff_eq!(response.normal_mm, 0.00075, epsilon = 1e-15);
        assert_abs_diff_eq!(response.roll_rad, -0.0055 / 150.0, epsilon = 1e-17);
        assert_abs_diff_eq!(response.pitch_rad, -2.5e-6, epsilon = 1e-17);
        for (actual, expected) in response
            .force_normal_n
            .iter()
            .zip([-225.0, 225.0, -225.0, 225.0])
        {
            assert_abs_diff_eq!(*actual, expected, epsilon = 1e-9);
        }
        // The plane condition (5): z1 − z2 = z4 − z3 = 0.0005.
        let z = response.corner_normal_mm;
        assert_abs_diff_eq!(z[0] - z[1], 0.0005, epsilon = 1e-15);
        assert_abs_diff_eq!(z[3] - z[2], 0.0005, epsilon = 1e-15);
    }

    #[test]
    fn equal_stiffness_closed_forms_with_load() {
        // Notes §3.5: z_i = d_zi ∓ τ/4 − F_zz/(4k), y1 = y4 = (d_y1 + d_y4)/2 + F_zy/(4k), …
        let k = 50_000.0;
        let guideway = Guideway {
            rail_spacing_mm: 400.0,
            carriage_pitch_mm: 500.0,
            stiffness_normal_n_per_mm: [k; 4],
            stiffness_lateral_n_per_mm: [k; 4],
            load_normal_n: 2000.0,
            load_lateral_n: -800.0,
        };
        let d_z = [0.004, -0.002, 0.001, 0.003];
        let d_y = [-0.001, 0.002, 0.005, 0.0];
        let response = guideway
            .solve(&CarriageDeviations {
                normal_mm: d_z,
                lateral_mm: d_y,
            })
            .unwrap();
        let twist = d_z[0] - d_z[1] + d_z[2] - d_z[3];
        let sink = 2000.0 / (4.0 * k);
        let expected_z = [
            d_z[0] - twist / 4.0 - sink,
            d_z[1] + twist / 4.0 - sink,
            d_z[2] - twist / 4.0 - sink,
            d_z[3] + twist / 4.0 - sink,
        ];
        for (actual, expected) in response.corner_normal_mm.iter().zip(expected_z) {
            assert_abs_diff_eq!(*actual, expected, epsilon = 1e-15);
        }
        assert_abs_diff_eq!(
            response.normal_mm,
            d_z.iter().sum::<f64>() / 4.0 - sink,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            response.roll_rad,
            ((d_z[2] + d_z[3]) - (d_z[0] + d_z[1])) / (2.0 * 400.0),
            epsilon = 1e-17
        );
        assert_abs_diff_eq!(
            response.pitch_rad,
            ((d_z[1] + d_z[2]) - (d_z[0] + d_z[3])) / (2.0 * 500.0),
            epsilon = 1e-17
        );
        let shift = -800.0 / (4.0 * k);
        assert_abs_diff_eq!(
            response.corner_lateral_mm[0],
            (d_y[0] + d_y[3]) / 2.0 + shift,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            response.corner_lateral_mm[3],
            (d_y[0] + d_y[3]) / 2.0 + shift,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            response.corner_lateral_mm[1],
            (d_y[1] + d_y[2]) / 2.0 + shift,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            response.lateral_mm,
            d_y.iter().sum::<f64>() / 4.0 + shift,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            response.yaw_rad,
            ((d_y[0] + d_y[3]) - (d_y[1] + d_y[2])) / (2.0 * 500.0),
            epsilon = 1e-17
        );
    }

    #[test]
    fn output_weights_agree_with_the_response() {
        let guideway = Guideway {
            stiffness_normal_n_per_mm: [80_000.0, 120_000.0, 95_000.0, 60_000.0],
            stiffness_lateral_n_per_mm: [70_000.0, 110_000.0, 100_000.0, 90_000.0],
            load_normal_n: 1500.0,
            load_lateral_n: 300.0,
            ..Guideway::unloaded(350.0, 640.0)
        };
        let map = guideway.linear_map().unwrap();
        let deviations = CarriageDeviations {
            normal_mm: [0.01, -0.004, 0.002, 0.007],
            lateral_mm: [-0.003, 0.001, 0.006, -0.002],
        };
        let response = map.response(&deviations);
        let apply = |output: &OutputWeights, d: &[f64; 4]| -> f64 {
            output.constant + (0..4).map(|i| output.weights[i] * d[i]).sum::<f64>()
        };
        let [z5, roll, pitch] = map.normal_outputs();
        let [y5, yaw] = map.lateral_outputs();
        assert_abs_diff_eq!(
            apply(&z5, &deviations.normal_mm),
            response.normal_mm,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            apply(&roll, &deviations.normal_mm),
            response.roll_rad,
            epsilon = 1e-17
        );
        assert_abs_diff_eq!(
            apply(&pitch, &deviations.normal_mm),
            response.pitch_rad,
            epsilon = 1e-17
        );
        assert_abs_diff_eq!(
            apply(&y5, &deviations.lateral_mm),
            response.lateral_mm,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            apply(&yaw, &deviations.lateral_mm),
            response.yaw_rad,
            epsilon = 1e-17
        );
    }

    #[test]
    fn carriages_sit_where_eqs_40_to_47_put_them() {
        use super::super::components::{ErrorTable, Interpolation};
        // Rail 1 normal is the line d = x/1000; rail 2 normal d = 2x/1000.
        let line = |slope: f64| {
            ErrorFunction::Table(
                ErrorTable::new(
                    vec![-1000.0, 1000.0],
                    vec![-slope, slope],
                    Interpolation::Linear,
                )
                .unwrap(),
            )
        };
        let rails = RailProfiles {
            normal: [line(1.0), line(2.0)],
            lateral: Default::default(),
        };
        let map = Guideway::unloaded(300.0, 200.0).linear_map().unwrap();
        let deviations = map.deviations_at(&rails, 100.0);
        // x − b/2 = 0, x + b/2 = 200.
        let expected = [0.0, 0.2, 0.4, 0.0];
        for (actual, expected) in deviations.normal_mm.iter().zip(expected) {
            assert_abs_diff_eq!(*actual, expected, epsilon = 1e-15);
        }
    }

    #[test]
    fn sloped_rails_give_pitch_and_an_offset_rail_gives_roll() {
        use super::super::components::{ErrorTable, Interpolation};
        // By hand, equal stiffness: rails d = k·x (rail 1) and d = k·x + c
        // (rail 2) give z5 = k·x + c/2, pitch = k, roll = c/a; lateral rails
        // d = −k·x on both give y5 = −k·x and yaw = k (eq. 38: (y1 − y2)/b).
        let (k, c, a) = (2e-5, 0.004, 300.0);
        let line = |slope: f64, offset: f64| {
            ErrorFunction::Table(
                ErrorTable::new(
                    vec![-1000.0, 2000.0],
                    vec![offset - 1000.0 * slope, offset + 2000.0 * slope],
                    Interpolation::Linear,
                )
                .unwrap(),
            )
        };
        let rails = RailProfiles {
            normal: [line(k, 0.0), line(k, c)],
            lateral: [line(-k, 0.0), line(-k, 0.0)],
        };
        let map = Guideway::unloaded(a, 400.0).linear_map().unwrap();
        let positions = [0.0, 250.0, 700.0];
        for (x, response) in positions.iter().zip(map.along_stroke(&rails, &positions)) {
            assert_abs_diff_eq!(response.normal_mm, k * x + c / 2.0, epsilon = 1e-15);
            assert_abs_diff_eq!(response.pitch_rad, k, epsilon = 1e-15);
            assert_abs_diff_eq!(response.roll_rad, c / a, epsilon = 1e-15);
            assert_abs_diff_eq!(response.lateral_mm, -k * x, epsilon = 1e-15);
            assert_abs_diff_eq!(response.yaw_rad, k, epsilon = 1e-15);
        }
    }

    #[test]
    fn saddle_pads_alone_tilt_the_saddle_for_the_whole_stroke() {
        // By hand, equal stiffness (a = 350, b = 640, the MCV 754 Quick's X):
        // a parallelism of 0.02 mm across the rails (rail-2 pads higher) and
        // 0.01 mm along them (pads ahead higher), on straight rails, give
        // roll = 0.02/350 rad and pitch = 0.01/640 rad at every position, no
        // straightness (the pads' mean is zero) and no carriage forces.
        let faces = SaddleFaces {
            tilt_across_mm: 0.02,
            tilt_along_mm: 0.01,
            twist_mm: 0.0,
        };
        assert_eq!(
            faces.pad_heights_mm(),
            [-0.015, -0.005, 0.015, 0.005],
            "e_i of carriages 1–4"
        );
        let map = Guideway::unloaded(350.0, 640.0).linear_map().unwrap();
        for rail in [0.0, 0.003] {
            let on_rails = CarriageDeviations {
                normal_mm: [rail; 4],
                lateral_mm: [0.0; 4],
            };
            let response = map.response(&on_rails.with_saddle_faces(&faces));
            assert_abs_diff_eq!(response.roll_rad, 0.02 / 350.0, epsilon = 1e-18);
            assert_abs_diff_eq!(response.pitch_rad, 0.01 / 640.0, epsilon = 1e-18);
            assert_abs_diff_eq!(response.normal_mm, rail, epsilon = 1e-17);
            for force in response.force_normal_n {
                assert_abs_diff_eq!(force, 0.0, epsilon = 1e-9);
            }
        }
    }

    #[test]
    fn a_twisted_saddle_loads_equal_carriages_and_does_not_move() {
        // Notes §3.5 with d = c·(1, −1, 1, −1): τ = 4c, z_i = d_i ∓ τ/4 = 0,
        // F_i = k·Δ_i = ∓k·c. Flatness 0.02 mm (c = 0.01) on 100 000 N/mm
        // carriages: ∓1000 N each, and the saddle stays where it was.
        let faces = SaddleFaces {
            twist_mm: 0.01,
            ..SaddleFaces::default()
        };
        let guideway = Guideway::unloaded(350.0, 640.0);
        let response = guideway
            .solve(&CarriageDeviations::default().with_saddle_faces(&faces))
            .unwrap();
        for (corner, force) in response
            .corner_normal_mm
            .iter()
            .zip(response.force_normal_n)
        {
            assert_abs_diff_eq!(*corner, 0.0, epsilon = 1e-17);
            assert_abs_diff_eq!(force.abs(), 1000.0, epsilon = 1e-9);
        }
        assert_abs_diff_eq!(response.force_normal_n[0], -1000.0, epsilon = 1e-9);
        assert_abs_diff_eq!(response.force_normal_n[1], 1000.0, epsilon = 1e-9);
        // Unequal carriages turn part of the twist into motion. Carriage 1 at
        // k/2, the others k: eq. 12 with Δ_i = F_i/k_i and the balances
        // (9)–(11) give F = (f, −f, f, −f) with f(2 + 1 + 1 + 1)/k = −4c, so
        // f = −4kc/5 and corner 1 keeps e_1 + 2f/k = c − 8c/5 = −3c/5.
        let mut soft = guideway;
        soft.stiffness_normal_n_per_mm[0] /= 2.0;
        let response = soft
            .solve(&CarriageDeviations::default().with_saddle_faces(&faces))
            .unwrap();
        let c = 0.01;
        assert_abs_diff_eq!(
            response.force_normal_n[0],
            -4.0 * 1e5 * c / 5.0,
            epsilon = 1e-9
        );
        assert_abs_diff_eq!(
            response.corner_normal_mm[0],
            -3.0 * c / 5.0,
            epsilon = 1e-15
        );
        assert_abs_diff_eq!(
            response.corner_normal_mm[1],
            -c + 4.0 * c / 5.0,
            epsilon = 1e-15
        );
        assert!(response.pitch_rad.abs() > 1e-7);
    }

    #[test]
    fn bad_parameters_are_errors() {
        let mut guideway = Guideway::unloaded(0.0, 200.0);
        let error = guideway.linear_map().unwrap_err();
        assert!(
            error
                .to_string()
                .contains("rail spacing a: expected a positive length"),
            "{error}"
        );
        guideway = Guideway::unloaded(100.0, 200.0);
        guideway.stiffness_lateral_n_per_mm[2] = -1.0;
        assert!(
            guideway
                .linear_map()
                .unwrap_err()
                .to_string()
                .contains("stiffness")
        );
        guideway = Guideway::unloaded(100.0, 200.0);
        guideway.load_normal_n = f64::NAN;
        assert!(
            guideway
                .linear_map()
                .unwrap_err()
                .to_string()
                .contains("normal load")
        );
    }

    proptest! {
        // The solution satisfies Valášek's own equations, whatever the
        // stiffnesses and loads: force and moment balance (9)–(11), (29), (30),
        // the plane condition (5), equal lateral displacement (22), (23) and
        // Hooke's law (7), (26).
        #[test]
        fn solution_satisfies_the_equilibrium_equations(
            k_z in proptest::array::uniform4(1e3f64..1e6),
            k_y in proptest::array::uniform4(1e3f64..1e6),
            d_z in proptest::array::uniform4(-0.05f64..0.05),
            d_y in proptest::array::uniform4(-0.05f64..0.05),
            f_zz in -5e3f64..5e3,
            f_zy in -5e3f64..5e3,
        ) {
            let guideway = Guideway {
                rail_spacing_mm: 300.0,
                carriage_pitch_mm: 450.0,
                stiffness_normal_n_per_mm: k_z,
                stiffness_lateral_n_per_mm: k_y,
                load_normal_n: f_zz,
                load_lateral_n: f_zy,
            };
            let r = guideway.solve(&CarriageDeviations { normal_mm: d_z, lateral_mm: d_y }).unwrap();
            let f = r.force_normal_n;
            let g = r.force_lateral_n;
            let force_tolerance = 1e-6 * (1.0 + f_zz.abs() + f_zy.abs());
            prop_assert!((f.iter().sum::<f64>() + f_zz).abs() < force_tolerance);
            prop_assert!((f[0] + f[1] + f_zz / 2.0).abs() < force_tolerance);
            prop_assert!((f[1] + f[2] + f_zz / 2.0).abs() < force_tolerance);
            prop_assert!((g.iter().sum::<f64>() - f_zy).abs() < force_tolerance);
            prop_assert!((g[1] + g[2] - f_zy / 2.0).abs() < force_tolerance);
            let z = r.corner_normal_mm;
            let y = r.corner_lateral_mm;
            prop_assert!(((z[0] - z[1]) - (z[3] - z[2])).abs() < 1e-12);
            prop_assert!((y[0] - y[3]).abs() < 1e-12);
            prop_assert!((y[1] - y[2]).abs() < 1e-12);
            for i in 0..4 {
                prop_assert!((z[i] - d_z[i] - f[i] / k_z[i]).abs() < 1e-12);
                prop_assert!((y[i] - d_y[i] - g[i] / k_y[i]).abs() < 1e-12);
            }
        }
    }
}
