//! Random straightness and positioning profiles (Valášek (2021) §3.2.2, eq. 39).
//!
//! Valášek (2021) observed that measured mounting surfaces are not random point
//! clouds but "evolve", and generates them as follows
//! (`../shared/notes/seed000-volumetric-model.md` §3.7):
//!
//! 1. knots one error period apart over the rail ([−b/2, stroke + b/2] for a
//!    rail, the stroke for a positioning error);
//! 2. a random start inside the tolerance band;
//! 3. dy(j+1) = dy(j) + m · U(−tol, tol) (eq. 39), clipped to the band;
//! 4. a cubic spline through the knots.
//!
//! What the text leaves open is settled as the NumPy reference `mc_peer.py`
//! (`../shared/tools/mc_peer.py`) settles it: ⌈length / period⌉ + 1 evenly
//! spaced knots from end to end, a band ±tol/2 centred on zero (its width is
//! configurable; its position does not matter for peak-to-peak straightness
//! or for an error map zeroed at a reference point), and the not-a-knot
//! spline (MATLAB's `spline`). The spline may overshoot the band slightly,
//! as Valášek (2021) notes.
//!
//! Randomness comes from the caller's [`ChaCha8Rng`]; uniform numbers are
//! built here from the generator's raw 64-bit output (53 random bits), so the
//! values depend only on ChaCha8, not on a `rand` distribution's version.
//! The walk is generated in units of the tolerance and scaled afterwards, so
//! two studies with the same seed and different tolerances see the same
//! shapes (common random numbers: the sensitivity curves are smooth).

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::Rng;

use super::components::{ErrorTable, Interpolation};
use super::{ModelError, check_positive};

/// The shape parameters of the generator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileShape {
    /// Distance between knots ("error period"), mm.
    pub period_mm: f64,
    /// m: the step multiplier of eq. 39 ("usually 0–1").
    pub step_factor: f64,
    /// Width of the band as a multiple of the tolerance (1: ±tol/2).
    pub band_width_factor: f64,
}

impl ProfileShape {
    /// Valášek's (2021) choice for all its studies: period 100 mm, m = 0.5, band ±tol/2.
    pub const THESIS: ProfileShape = ProfileShape {
        period_mm: 100.0,
        step_factor: 0.5,
        band_width_factor: 1.0,
    };

    /// Checks that every parameter is positive and finite.
    pub fn check(&self) -> Result<(), ModelError> {
        check_positive("profile period", self.period_mm, "a positive length in mm")?;
        check_positive("profile step factor", self.step_factor, "a positive number")?;
        check_positive(
            "profile band width factor",
            self.band_width_factor,
            "a positive number",
        )
    }

    /// The knots over [start, end]: ⌈(end − start)/period⌉ + 1 evenly spaced
    /// points including both ends (as `numpy.linspace` in the peer).
    pub fn knots(&self, start_mm: f64, end_mm: f64) -> Vec<f64> {
        let intervals = ((end_mm - start_mm) / self.period_mm).ceil().max(1.0) as usize;
        let spacing = (end_mm - start_mm) / intervals as f64;
        let mut knots: Vec<f64> = (0..intervals)
            .map(|i| start_mm + i as f64 * spacing)
            .collect();
        knots.push(end_mm);
        knots
    }

    /// Fills `walk` with a bounded random walk in units of the tolerance:
    /// a uniform start in the band, then steps m · U(−1, 1), each clipped to
    /// the band (eq. 39). Draws exactly `walk.len()` numbers from `rng`.
    pub fn unit_walk(&self, rng: &mut ChaCha8Rng, walk: &mut [f64]) {
        let half_band = self.band_width_factor / 2.0;
        let mut value = 0.0;
        for (j, knot_value) in walk.iter_mut().enumerate() {
            value = if j == 0 {
                uniform(rng, -half_band, half_band)
            } else {
                (value + self.step_factor * uniform(rng, -1.0, 1.0)).clamp(-half_band, half_band)
            };
            *knot_value = value;
        }
    }

    /// A random profile over [start, end] with straightness tolerance
    /// `tolerance_mm`: the spline through a scaled [`ProfileShape::unit_walk`].
    ///
    /// # Example
    ///
    /// ```
    /// use axcomp::model::ProfileShape;
    /// use rand_chacha::ChaCha8Rng;
    /// use rand_chacha::rand_core::SeedableRng;
    ///
    /// let mut rng = ChaCha8Rng::seed_from_u64(7);
    /// let rail = ProfileShape::THESIS.random_profile(&mut rng, 0.03, -320.0, 1070.0)?;
    /// assert_eq!(rail.positions_mm().len(), 15); // ⌈1390/100⌉ + 1 knots
    /// assert!(rail.values().iter().all(|v| v.abs() <= 0.015)); // the knots stay in ±tol/2
    /// # Ok::<(), axcomp::model::ModelError>(())
    /// ```
    pub fn random_profile(
        &self,
        rng: &mut ChaCha8Rng,
        tolerance_mm: f64,
        start_mm: f64,
        end_mm: f64,
    ) -> Result<ErrorTable, ModelError> {
        self.check()?;
        if !(tolerance_mm.is_finite() && tolerance_mm >= 0.0) {
            return Err(ModelError::invalid(
                "tolerance",
                "a length ≥ 0 mm",
                tolerance_mm.to_string(),
            ));
        }
        if !(start_mm.is_finite() && end_mm.is_finite() && start_mm < end_mm) {
            return Err(ModelError::invalid(
                "profile range",
                "a finite start below the end",
                format!("{start_mm} … {end_mm} mm"),
            ));
        }
        let knots = self.knots(start_mm, end_mm);
        let mut walk = vec![0.0; knots.len()];
        self.unit_walk(rng, &mut walk);
        let values = walk.iter().map(|unit| unit * tolerance_mm).collect();
        ErrorTable::new(knots, values, Interpolation::Spline)
    }
}

/// A uniform number in [low, high) from the generator's next 64 bits (the
/// top 53 bits make the fraction, the standard construction of a double).
pub fn uniform(rng: &mut ChaCha8Rng, low: f64, high: f64) -> f64 {
    let fraction = (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
    low + (high - low) * fraction
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::rand_core::SeedableRng;

    #[test]
    fn knots_as_the_peer_places_them() {
        // mc_peer.py knots_for: ceil((hi - lo)/100) + 1 points of np.linspace.
        let shape = ProfileShape::THESIS;
        let x_rail = shape.knots(-320.0, 1070.0);
        assert_eq!(x_rail.len(), 15);
        assert!((x_rail[1] - (-320.0 + 1390.0 / 14.0)).abs() < 1e-12);
        assert_eq!(
            shape.knots(0.0, 500.0),
            vec![0.0, 100.0, 200.0, 300.0, 400.0, 500.0]
        );
        assert_eq!(shape.knots(-728.0, 178.0).len(), 11);
        assert_eq!(shape.knots(0.0, 750.0).len(), 9);
        assert_eq!(shape.knots(0.0, 10.0), vec![0.0, 10.0]);
    }

    #[test]
    fn walk_stays_in_the_band_and_moves_by_at_most_m() {
        let shape = ProfileShape {
            period_mm: 50.0,
            step_factor: 0.8,
            band_width_factor: 1.0,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut walk = vec![0.0; 2000];
        shape.unit_walk(&mut rng, &mut walk);
        assert!(walk.iter().all(|v| v.abs() <= 0.5));
        assert!(walk.windows(2).all(|pair| (pair[1] - pair[0]).abs() <= 0.8));
        // A long walk reaches both band limits (it is clipped, not reflected).
        assert!(walk.contains(&0.5) && walk.contains(&-0.5));
    }

    #[test]
    fn uniform_numbers_fill_the_interval() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let draws: Vec<f64> = (0..10_000).map(|_| uniform(&mut rng, -2.0, 3.0)).collect();
        assert!(draws.iter().all(|u| (-2.0..3.0).contains(u)));
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        // Mean 0.5, standard error 5/√12/√10000 ≈ 0.0144: 4 σ.
        assert!((mean - 0.5).abs() < 0.06, "{mean}");
    }

    #[test]
    fn profiles_scale_with_the_tolerance() {
        let shape = ProfileShape::THESIS;
        let small = shape
            .random_profile(&mut ChaCha8Rng::seed_from_u64(5), 0.01, 0.0, 1000.0)
            .unwrap();
        let large = shape
            .random_profile(&mut ChaCha8Rng::seed_from_u64(5), 0.05, 0.0, 1000.0)
            .unwrap();
        for x in [0.0, 123.0, 555.5, 1000.0] {
            assert!((large.value_at(x) - 5.0 * small.value_at(x)).abs() < 1e-15);
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let shape = ProfileShape {
            period_mm: 0.0,
            ..ProfileShape::THESIS
        };
        assert!(shape.random_profile(&mut rng, 0.03, 0.0, 1.0).is_err());
        let shape = ProfileShape::THESIS;
        assert!(shape.random_profile(&mut rng, -0.03, 0.0, 1.0).is_err());
        assert!(shape.random_profile(&mut rng, 0.03, 1.0, 1.0).is_err());
    }
}
