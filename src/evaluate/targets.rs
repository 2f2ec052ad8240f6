//! The statistics of each target (ISO 230-2 §2, `../shared/spec/iso230-2.md`):
//! per direction the number of readings n, the mean positional deviation x̄
//! and the estimator of the standard uncertainty s (n − 1 in the
//! denominator, inside the square root: Kadlečík (2019) eq. (8)/(9) has a typo
//! there). What a standard derives from them (reversal, repeatability, the
//! axis figures) is the [`Standard`](super::standard::Standard)'s.
//!
//! The statistics are bare numbers in the axis' unit (mm, or ° on a rotary
//! axis: the arithmetic is the same); [`TargetStats::typed`] gives them their
//! unit as a type ([`TargetIn`]) for whatever reports them.

use crate::measurement::{AxisKind, ByKind, Direction, Measurement};
use crate::units::{Deg, Mm};

/// Statistics of one target in one direction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DirectionStats {
    /// Number of readings n.
    pub n: usize,
    /// Mean positional deviation x̄, in the axis' unit (`None` when n = 0).
    pub mean: Option<f64>,
    /// Estimator of the standard uncertainty s (`None` when n < 2).
    pub s: Option<f64>,
}

impl DirectionStats {
    /// Mean and s of the readings (two-pass, for accuracy with offsets much larger than the scatter).
    pub fn of(values: &[f64]) -> DirectionStats {
        let n = values.len();
        if n == 0 {
            return DirectionStats::default();
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let s = (n >= 2).then(|| {
            let sum_sq: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
            (sum_sq / (n - 1) as f64).sqrt()
        });
        DirectionStats {
            n,
            mean: Some(mean),
            s,
        }
    }

    /// The band x̄ ± k·s, as (low, high): A spans it (k = 2 in ISO
    /// 230-2 since 1997, 3 in 1988: [`super::standard::Iso230_2::k`]).
    pub fn band(&self, k: f64) -> Option<(f64, f64)> {
        let (mean, s) = (self.mean?, self.s?);
        Some((mean - k * s, mean + k * s))
    }

    /// The unidirectional repeatability R_i = 2k·s_i (4 s_i for k = 2).
    pub(super) fn repeatability(&self, k: f64) -> Option<f64> {
        self.s.map(|s| 2.0 * k * s)
    }
}

/// Everything ISO 230-2 defines at one target (with the standard's k), in
/// the axis' unit (mm, or ° on a rotary axis; no name here says which):
/// [`TargetStats::typed`] gives them their unit as a type.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetStats {
    /// Target P_i.
    pub target: f64,
    /// ↑ statistics.
    pub up: DirectionStats,
    /// ↓ statistics.
    pub down: DirectionStats,
    /// Mean bidirectional positional deviation x̄_i = (x̄_i↑ + x̄_i↓)/2.
    pub mean: Option<f64>,
    /// Reversal value B_i = x̄_i↑ − x̄_i↓ (signed).
    pub reversal: Option<f64>,
    /// R_i↑ = 4 s_i↑.
    pub repeatability_up: Option<f64>,
    /// R_i↓ = 4 s_i↓.
    pub repeatability_down: Option<f64>,
    /// R_i = max(2 s_i↑ + 2 s_i↓ + |B_i|; R_i↑; R_i↓).
    pub repeatability: Option<f64>,
}

impl TargetStats {
    /// Statistics of one direction.
    pub fn direction(&self, direction: Direction) -> &DirectionStats {
        match direction {
            Direction::Up => &self.up,
            Direction::Down => &self.down,
        }
    }

    /// The statistics typed by the axis' kind: in [`Mm`] on a linear axis,
    /// in [`Deg`] on a rotary one.
    pub fn typed(&self, kind: AxisKind) -> ByKind<TargetIn<Mm>, TargetIn<Deg>> {
        match kind {
            AxisKind::Linear => ByKind::Linear(self.in_unit(Mm)),
            AxisKind::Rotary => ByKind::Rotary(self.in_unit(Deg)),
        }
    }

    fn in_unit<U>(&self, unit: fn(f64) -> U) -> TargetIn<U> {
        let typed = |value: Option<f64>| value.map(unit);
        TargetIn {
            target: unit(self.target),
            n_up: self.up.n,
            n_down: self.down.n,
            mean_up: typed(self.up.mean),
            mean_down: typed(self.down.mean),
            mean: typed(self.mean),
            s_up: typed(self.up.s),
            s_down: typed(self.down.s),
            reversal: typed(self.reversal),
            repeatability_up: typed(self.repeatability_up),
            repeatability_down: typed(self.repeatability_down),
            repeatability: typed(self.repeatability),
        }
    }
}

/// One target's statistics with their unit as a type: the target in `P`
/// (`Mm` or `Deg`), the deviations and the quantities made of them in `D`
/// (the axis' unit, or the one they are reported in, see
/// [`TargetIn::map_deviations`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetIn<P, D = P> {
    /// Target P_i.
    pub target: P,
    /// Readings ↑.
    pub n_up: usize,
    /// Readings ↓.
    pub n_down: usize,
    /// x̄_i↑.
    pub mean_up: Option<D>,
    /// x̄_i↓.
    pub mean_down: Option<D>,
    /// x̄_i.
    pub mean: Option<D>,
    /// s_i↑.
    pub s_up: Option<D>,
    /// s_i↓.
    pub s_down: Option<D>,
    /// B_i (signed).
    pub reversal: Option<D>,
    /// R_i↑.
    pub repeatability_up: Option<D>,
    /// R_i↓.
    pub repeatability_down: Option<D>,
    /// R_i.
    pub repeatability: Option<D>,
}

impl<P, D> TargetIn<P, D> {
    /// The same with every deviation converted by `convert` (`Mm::to_um`,
    /// `Deg::to_arcsec`, `Deg::to_urad`): the function's type decides which
    /// unit it accepts.
    pub fn map_deviations<E>(self, convert: fn(D) -> E) -> TargetIn<P, E> {
        let shown = |value: Option<D>| value.map(convert);
        TargetIn {
            target: self.target,
            n_up: self.n_up,
            n_down: self.n_down,
            mean_up: shown(self.mean_up),
            mean_down: shown(self.mean_down),
            mean: shown(self.mean),
            s_up: shown(self.s_up),
            s_down: shown(self.s_down),
            reversal: shown(self.reversal),
            repeatability_up: shown(self.repeatability_up),
            repeatability_down: shown(self.repeatability_down),
            repeatability: shown(self.repeatability),
        }
    }
}

/// The statistics of every target, in target order, handed to `at_target`
/// with the target (a standard derives its quantities there).
pub(super) fn per_target_stats<T>(
    measurement: &Measurement,
    mut at_target: impl FnMut(f64, DirectionStats, DirectionStats) -> T,
) -> Vec<T> {
    // Each direction's runs, found once rather than once per target.
    let runs_of = |direction: Direction| -> Vec<&[Option<f64>]> {
        measurement
            .runs_in(direction)
            .map(|run| run.deviations.as_slice())
            .collect()
    };
    let runs_by_direction = [runs_of(Direction::Up), runs_of(Direction::Down)];
    let mut readings: Vec<f64> = Vec::with_capacity(measurement.runs().len());
    let mut stats_of = |target_index: usize, direction: Direction| {
        readings.clear();
        readings.extend(
            runs_by_direction[usize::from(direction == Direction::Down)]
                .iter()
                .filter_map(|deviations| deviations[target_index]),
        );
        DirectionStats::of(&readings)
    };
    let mut per_target = Vec::with_capacity(measurement.targets().len());
    for (index, &target) in measurement.targets().iter().enumerate() {
        let up = stats_of(index, Direction::Up);
        let down = stats_of(index, Direction::Down);
        per_target.push(at_target(target, up, down));
    }
    per_target
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_are_typed_by_the_axis_kind() {
        let up = DirectionStats::of(&[0.001, 0.003]);
        let stats = TargetStats {
            target: 90.0,
            up,
            down: DirectionStats::default(),
            mean: None,
            reversal: None,
            repeatability_up: Some(0.004),
            repeatability_down: None,
            repeatability: None,
        };
        let ByKind::Rotary(rotary) = stats.typed(AxisKind::Rotary) else {
            panic!("a rotary axis' statistics are in degrees")
        };
        // x̄↑ = 0.002°; 0.002° = 7.2″.
        assert_eq!(
            (rotary.target, rotary.mean_up),
            (Deg(90.0), Some(Deg(0.002)))
        );
        let shown = rotary.map_deviations(Deg::to_arcsec);
        assert_eq!(shown.mean_up, Some(crate::units::Arcsec(7.2)));
        assert_eq!((shown.n_up, shown.n_down, shown.mean_down), (2, 0, None));
        let ByKind::Linear(linear) = stats.typed(AxisKind::Linear) else {
            panic!("a linear axis' statistics are in mm")
        };
        assert_eq!(
            linear.map_deviations(Mm::to_um).repeatability_up,
            Some(crate::units::Um(4.0))
        );
    }
}
