//! A standard: what derives the axis figures from the statistics of each
//! target. [`evaluate`](super::evaluate) applies [`ISO_230_2`] (the 2014
//! edition, `../shared/spec/iso230-2.md`); `--standard` picks another from
//! [`SUPPORTED`] by [`by_name`]. Another edition of ISO 230-2 is another value
//! of [`Iso230_2`] (the 1988 edition is the same formulas with k = 3), VDI/DGQ
//! 3441 is [`Vdi3441`] beside it: data, not a fork of
//! [`evaluate`](super::evaluate). Evidence levels are those of
//! `../shared/spec/standards.md`: a standard whose definitions are
//! reconstructed there says so ([`Standard::reconstructed`]).
//!
//! ISO 230-2 (1997, 2006, 2014): per target x̄_i = (x̄_i↑ + x̄_i↓)/2, the
//! reversal value B_i = x̄_i↑ − x̄_i↓, the repeatabilities R_i↑ = 2k·s_i↑,
//! R_i↓ = 2k·s_i↓, R_i = max(k·s_i↑ + k·s_i↓ + |B_i|; R_i↑; R_i↓); per axis A,
//! A↑, A↓ (the span of x̄ ± k·s), E, E↑, E↓, M, R, R↑, R↓, B = max |B_i| and
//! the signed mean reversal B̄ (Kadlečík (2019) eq. (22) swaps two signs in A; the
//! spec's form is used), with k = 2. An axis figure is evaluated only when
//! what it needs is defined at every target.
//!
//! VDI/DGQ 3441 (standards.md §3, reconstructed): per target U_i = |B_i|
//! and Ps_i = 6·(s_i↑ + s_i↓)/2; per axis U max, U mean, Ps max, Ps mean,
//! Pa = max x̄_i − min x̄_i and P = max(x̄_i + (U_i + Ps_i)/2) −
//! min(x̄_i − (U_i + Ps_i)/2).

use super::AxisFigures;
use super::targets::{DirectionStats, TargetStats};
use crate::measurement::{AxisKind, ByKind, Direction};
use crate::units::{Deg, Mm};

/// What derives a test's figures from the statistics of each target.
pub trait Standard: Sync + std::fmt::Debug {
    /// Its name and edition, as a report cites it.
    fn name(&self) -> &'static str;

    /// Its `--standard` name (`iso230-2:2014`), also `standard` in the JSON.
    fn key(&self) -> &'static str;

    /// Whether `../shared/spec/standards.md` reconstructs its definitions
    /// from public traces rather than reading them in the standard: the
    /// report then says so.
    fn reconstructed(&self) -> bool;

    /// The multiple of s in ISO 230-2's bands (A) and half the one in its
    /// repeatabilities (R), as [`Standard::axis_figures`] uses it.
    fn k(&self) -> f64;

    /// What it defines at one target from the statistics of each direction.
    fn target_stats(&self, target: f64, up: DirectionStats, down: DirectionStats) -> TargetStats;

    /// The ISO 230-2 axis figures from every target's (±k·s; VDI 3441 gives
    /// ISO 230-2:2014's beside its own).
    fn axis_figures(&self, per_target: &[TargetStats]) -> AxisFigures;

    /// The figures this standard reports, in its order, with its keys.
    fn figures(&self, per_target: &[TargetStats], axis: &AxisFigures) -> Vec<StandardFigure>;
}

/// One figure as a standard names it: its value a bare number in the axis'
/// unit (`V = f64`: mm, or ° on a rotary axis; no name here says which), or
/// typed by the axis' kind ([`typed`]: `StandardFigure<Mm>` or
/// `StandardFigure<Deg>`) for whatever reports it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StandardFigure<V = f64> {
    /// Its key in `figures_um` and in `--limit` (`A`, `Ps_max`).
    pub key: &'static str,
    /// The value; `None` where not evaluated.
    pub value: Option<V>,
}

impl<V> StandardFigure<V> {
    /// The same figure with its value converted by `convert` (`Mm`,
    /// `Mm::to_um`, `Deg::to_arcsec`): the function's type decides which
    /// unit it accepts.
    pub fn map<E>(self, convert: impl FnOnce(V) -> E) -> StandardFigure<E> {
        StandardFigure {
            key: self.key,
            value: self.value.map(convert),
        }
    }
}

/// A standard's figures typed by their axis' kind: in [`Mm`] on a linear
/// axis, in [`Deg`] on a rotary one.
pub type FiguresByKind = ByKind<Vec<StandardFigure<Mm>>, Vec<StandardFigure<Deg>>>;

/// `figures` (in the axis' unit) typed by the axis' `kind`: with
/// [`crate::evaluate::TargetStats::typed`], where a standard's figure gets its
/// unit ([`crate::evaluate::Evaluation::standard_figures_typed`] asks the
/// evaluation's own kind).
pub fn typed(figures: &[StandardFigure], kind: AxisKind) -> FiguresByKind {
    match kind {
        AxisKind::Linear => ByKind::Linear(figures.iter().map(|f| f.map(Mm)).collect()),
        AxisKind::Rotary => ByKind::Rotary(figures.iter().map(|f| f.map(Deg)).collect()),
    }
}

/// A `--standard` name that is not one of [`SUPPORTED`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "standard {name:?} is not supported: its definitions are not established from public sources; supported: {}",
    supported_names()
)]
pub struct UnknownStandard {
    /// What was asked for.
    pub name: String,
}

fn supported_names() -> String {
    SUPPORTED
        .iter()
        .map(|s| s.key())
        .collect::<Vec<_>>()
        .join(", ")
}

/// ISO 230-2, one edition: the figures with the band x̄ ± k·s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iso230_2 {
    /// The `--standard` name.
    pub key: &'static str,
    /// The name and edition, as the report cites it.
    pub name: &'static str,
    /// The multiple of s in a band (A) and half the one in a repeatability (R).
    pub k: f64,
    /// Whether the spec reconstructs this edition's forms (the ±3s ones).
    pub reconstructed: bool,
}

/// ISO 230-2:2014 (the same figures as 1997 and 2006): k = 2.
pub const ISO_230_2: Iso230_2 = Iso230_2 {
    key: "iso230-2:2014",
    name: "ISO 230-2:2014",
    k: 2.0,
    reconstructed: false,
};

/// VDI/DGQ 3441 (1977): P, Pa, Ps, U (standards.md §3, reconstructed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vdi3441;

/// Every standard `--standard` takes, in the order `--help` lists them.
///
/// The 1997, 2006 and 2014 editions and GB/T 17421.2-2000 (an identical
/// adoption of the 1997 edition) define the same figures (standards.md §1);
/// the 1988 edition and JIS B 6192 use ±3s (§2).
pub static SUPPORTED: [&dyn Standard; 7] = [
    &ISO_230_2,
    &Iso230_2 {
        key: "iso230-2:2006",
        name: "ISO 230-2:2006",
        ..ISO_230_2
    },
    &Iso230_2 {
        key: "iso230-2:1997",
        name: "ISO 230-2:1997",
        ..ISO_230_2
    },
    &Iso230_2 {
        key: "gb/t17421.2",
        name: "GB/T 17421.2-2000 (identical adoption of ISO 230-2:1997)",
        ..ISO_230_2
    },
    &Iso230_2 {
        key: "iso230-2:1988",
        name: "ISO 230-2:1988 (±3s)",
        k: 3.0,
        reconstructed: true,
    },
    &Iso230_2 {
        key: "jis-b6192",
        name: "JIS B 6192 (±3s)",
        k: 3.0,
        reconstructed: true,
    },
    &Vdi3441,
];

/// The standard of a `--standard` name (case-insensitive), or why not.
pub fn by_name(name: &str) -> Result<&'static dyn Standard, UnknownStandard> {
    SUPPORTED
        .iter()
        .copied()
        .find(|s| s.key().eq_ignore_ascii_case(name.trim()))
        .ok_or_else(|| UnknownStandard {
            name: name.to_string(),
        })
}

impl Standard for Iso230_2 {
    fn name(&self) -> &'static str {
        self.name
    }

    fn key(&self) -> &'static str {
        self.key
    }

    fn reconstructed(&self) -> bool {
        self.reconstructed
    }

    fn k(&self) -> f64 {
        self.k
    }

    fn target_stats(&self, target: f64, up: DirectionStats, down: DirectionStats) -> TargetStats {
        target_stats(self.k, target, up, down)
    }

    fn axis_figures(&self, per_target: &[TargetStats]) -> AxisFigures {
        axis_figures(self.k, per_target)
    }

    fn figures(&self, _: &[TargetStats], axis: &AxisFigures) -> Vec<StandardFigure> {
        axis.keyed()
            .into_iter()
            .map(|(key, value)| StandardFigure { key, value })
            .collect()
    }
}

impl Standard for Vdi3441 {
    fn name(&self) -> &'static str {
        "VDI/DGQ 3441 (1977)"
    }

    fn key(&self) -> &'static str {
        "vdi3441"
    }

    fn reconstructed(&self) -> bool {
        true
    }

    fn k(&self) -> f64 {
        ISO_230_2.k
    }

    /// The per-target table stays ISO 230-2:2014's (x̄, s, B_i: what VDI's
    /// figures are made of).
    fn target_stats(&self, target: f64, up: DirectionStats, down: DirectionStats) -> TargetStats {
        ISO_230_2.target_stats(target, up, down)
    }

    fn axis_figures(&self, per_target: &[TargetStats]) -> AxisFigures {
        ISO_230_2.axis_figures(per_target)
    }

    fn figures(&self, per_target: &[TargetStats], _: &AxisFigures) -> Vec<StandardFigure> {
        let figures = vdi_figures(per_target);
        let keyed = [
            ("P", figures.map(|f| f.p)),
            ("Pa", figures.map(|f| f.pa)),
            ("Ps_max", figures.map(|f| f.ps_max)),
            ("Ps_mean", figures.map(|f| f.ps_mean)),
            ("U_max", figures.map(|f| f.u_max)),
            ("U_mean", figures.map(|f| f.u_mean)),
        ];
        keyed
            .into_iter()
            .map(|(key, value)| StandardFigure { key, value })
            .collect()
    }
}

/// What a VDI/DGQ 3441 figure is, by its key (standards.md §3), for the
/// terminal and the report; empty for a key that is not VDI's.
pub fn vdi_figure_name(key: &str) -> &'static str {
    match key {
        "P" => "positional uncertainty",
        "Pa" => "positional deviation (span of x̄_i)",
        "Ps_max" => "largest positional scatter 6·(s↑ + s↓)/2",
        "Ps_mean" => "mean positional scatter",
        "U_max" => "largest reversal span |x̄↑ − x̄↓|",
        "U_mean" => "mean reversal span",
        _ => "",
    }
}

/// VDI 3441's axis figures, in the axis' unit.
#[derive(Clone, Copy, Debug)]
struct VdiFigures {
    p: f64,
    pa: f64,
    ps_max: f64,
    ps_mean: f64,
    u_max: f64,
    u_mean: f64,
}

/// VDI 3441's figures, or `None` unless every target has x̄, B_i and s both
/// ways (VDI defines no unidirectional or single-run form).
fn vdi_figures(per_target: &[TargetStats]) -> Option<VdiFigures> {
    // (x̄_i, U_i, Ps_i) per target.
    let cells = every_target(per_target, |t| {
        Some((
            t.mean?,
            t.reversal?.abs(),
            6.0 * (t.up.s? + t.down.s?) / 2.0,
        ))
    })?;
    let count = cells.len() as f64;
    let max = |values: &mut dyn Iterator<Item = f64>| values.fold(f64::NEG_INFINITY, f64::max);
    let min = |values: &mut dyn Iterator<Item = f64>| values.fold(f64::INFINITY, f64::min);
    Some(VdiFigures {
        p: max(&mut cells.iter().map(|(x, u, ps)| x + (u + ps) / 2.0))
            - min(&mut cells.iter().map(|(x, u, ps)| x - (u + ps) / 2.0)),
        pa: span(cells.iter().map(|(x, _, _)| (*x, *x)))?,
        ps_max: max(&mut cells.iter().map(|(_, _, ps)| *ps)),
        ps_mean: cells.iter().map(|(_, _, ps)| ps).sum::<f64>() / count,
        u_max: max(&mut cells.iter().map(|(_, u, _)| *u)),
        u_mean: cells.iter().map(|(_, u, _)| u).sum::<f64>() / count,
    })
}

fn target_stats(k: f64, target: f64, up: DirectionStats, down: DirectionStats) -> TargetStats {
    let both_means = up.mean.zip(down.mean);
    let reversal = both_means.map(|(u, d)| u - d);
    let repeatability = match (up.s, down.s, reversal) {
        (Some(s_up), Some(s_down), Some(b)) => Some(
            (k * s_up + k * s_down + b.abs())
                .max(2.0 * k * s_up)
                .max(2.0 * k * s_down),
        ),
        _ => None,
    };
    TargetStats {
        target,
        mean: both_means.map(|(u, d)| (u + d) / 2.0),
        reversal,
        repeatability_up: up.repeatability(k),
        repeatability_down: down.repeatability(k),
        repeatability,
        up,
        down,
    }
}

/// Collects one value per target, or `None` if any target lacks it.
fn every_target<T>(
    per_target: &[TargetStats],
    value: impl Fn(&TargetStats) -> Option<T>,
) -> Option<Vec<T>> {
    per_target.iter().map(value).collect()
}

/// max(high) − min(low) over a set of (low, high) intervals.
fn span(intervals: impl IntoIterator<Item = (f64, f64)>) -> Option<f64> {
    let mut bounds: Option<(f64, f64)> = None;
    for (low, high) in intervals {
        bounds = Some(match bounds {
            None => (low, high),
            Some((lo, hi)) => (lo.min(low), hi.max(high)),
        });
    }
    bounds.map(|(lo, hi)| hi - lo)
}

fn axis_figures(k: f64, per_target: &[TargetStats]) -> AxisFigures {
    let points = |d: Direction| bounds_every(per_target, |t| t.direction(d).mean.map(|m| (m, m)));
    let bands = |d: Direction| bounds_every(per_target, |t| t.direction(d).band(k));
    let max_every = |value: fn(&TargetStats) -> Option<f64>| {
        bounds_every(per_target, |t| value(t).map(|v| (v, v))).map(|(_, high)| high)
    };
    // Each found once (a pass over every target) and used twice.
    let (bands_up, bands_down) = (bands(Direction::Up), bands(Direction::Down));
    let (points_up, points_down) = (points(Direction::Up), points(Direction::Down));
    AxisFigures {
        a: union(bands_up, bands_down).map(width),
        a_up: bands_up.map(width),
        a_down: bands_down.map(width),
        e: union(points_up, points_down).map(width),
        e_up: points_up.map(width),
        e_down: points_down.map(width),
        m: bounds_every(per_target, |t| t.mean.map(|m| (m, m))).map(width),
        r: max_every(|t| t.repeatability),
        r_up: max_every(|t| t.repeatability_up),
        r_down: max_every(|t| t.repeatability_down),
        b: max_every(|t| t.reversal.map(f64::abs)),
        b_mean: per_target
            .iter()
            .map(|t| t.reversal)
            .sum::<Option<f64>>()
            .map(|sum| sum / per_target.len() as f64),
    }
}

/// The lowest low and the highest high of one (low, high) interval per
/// target, or `None` if any target lacks it (or there is none). It folds
/// rather than collects: thirteen vectors of 10 000 targets each were a
/// measurable part of evaluating a large test.
fn bounds_every(
    per_target: &[TargetStats],
    interval: impl Fn(&TargetStats) -> Option<(f64, f64)>,
) -> Option<(f64, f64)> {
    let mut bounds: Option<(f64, f64)> = None;
    for target in per_target {
        let (low, high) = interval(target)?;
        bounds = Some(match bounds {
            None => (low, high),
            Some((lo, hi)) => (lo.min(low), hi.max(high)),
        });
    }
    bounds
}

/// The bounds of both, when both are evaluated.
fn union(a: Option<(f64, f64)>, b: Option<(f64, f64)>) -> Option<(f64, f64)> {
    let ((a_low, a_high), (b_low, b_high)) = (a?, b?);
    Some((a_low.min(b_low), a_high.max(b_high)))
}

fn width((low, high): (f64, f64)) -> f64 {
    high - low
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluate::evaluate_with;
    use crate::measurement::{Measurement, Run};

    /// Two runs each way at 0 and 100 mm: ↑ 0, 4 and 2, 6 µm; ↓ −2, 2 and 0, 4 µm.
    fn two_by_two() -> Measurement {
        let run = |direction, number, values: [f64; 2]| Run {
            direction,
            number,
            start_time_s: None,
            deviations: values.iter().map(|v| Some(v / 1000.0)).collect(),
        };
        Measurement::new(
            "X",
            vec![0.0, 100.0],
            vec![
                run(Direction::Up, 1, [0.0, 4.0]),
                run(Direction::Down, 1, [-2.0, 2.0]),
                run(Direction::Up, 2, [2.0, 6.0]),
                run(Direction::Down, 2, [0.0, 4.0]),
            ],
            Default::default(),
            Default::default(),
        )
        .unwrap()
    }

    #[test]
    fn figures_are_typed_by_the_axis_kind() {
        use crate::measurement::AxisKind;
        use approx::assert_abs_diff_eq;
        // x̄↑ = 1, 5; x̄↓ = −1, 3 (thousandths of the axis' unit): E = 5 − (−1) = 6.
        let e_of = |figures: &[StandardFigure<f64>]| {
            figures
                .iter()
                .find(|f| f.key == "E")
                .unwrap()
                .value
                .unwrap()
        };
        let linear = evaluate_with(&two_by_two(), &ISO_230_2);
        let ByKind::Linear(in_mm) = linear.standard_figures_typed() else {
            panic!("a linear axis' figures are mm")
        };
        let e_mm = in_mm.iter().find(|f| f.key == "E").unwrap().value.unwrap();
        assert_abs_diff_eq!(e_mm.0, 0.006, epsilon = 1e-15);
        let rotary = evaluate_with(&two_by_two().with_kind(AxisKind::Rotary), &ISO_230_2);
        let ByKind::Rotary(in_deg) = rotary.standard_figures_typed() else {
            panic!("a rotary axis' figures are degrees")
        };
        assert_eq!(in_deg[3].key, "E");
        assert_eq!(in_deg[3].value, Some(Deg(e_of(&rotary.standard_figures))));
        assert_abs_diff_eq!(e_of(&rotary.standard_figures), 0.006, epsilon = 1e-15);
        // 0.006° = 21.6″.
        let in_arcsec = in_deg[3].map(Deg::to_arcsec);
        assert_abs_diff_eq!(in_arcsec.value.unwrap().0, 21.6, epsilon = 1e-12);
        // The ISO 230-2 figures are typed the same way.
        assert_eq!(rotary.figures_typed().kind(), AxisKind::Rotary);
        assert_eq!(linear.figures_typed().kind(), AxisKind::Linear);
    }

    #[test]
    fn an_edition_is_a_value_not_a_fork() {
        // s = √2 µm in every cell (two readings 2 µm apart); B_i = 2 µm.
        let s = 2f64.sqrt();
        let edition_1988 = Iso230_2 {
            key: "iso230-2:1988",
            name: "ISO 230-2:1988",
            k: 3.0,
            reconstructed: true,
        };
        for (standard, k) in [(ISO_230_2, 2.0), (edition_1988, 3.0)] {
            let f = evaluate_with(&two_by_two(), &standard).figures;
            let um = |v: Option<f64>| v.unwrap() * 1000.0;
            // R_i↑ = 2k·s; R_i = max(k·s + k·s + |B_i|, 2k·s) = 2k·s + 2.
            assert!((um(f.r_up) - 2.0 * k * s).abs() < 1e-9, "{}", standard.name);
            assert!((um(f.r) - (2.0 * k * s + 2.0)).abs() < 1e-9);
            // A: from x̄↓ − k·s at 0 mm (−1 µm) to x̄↑ + k·s at 100 mm (5 µm).
            assert!((um(f.a) - (6.0 + 2.0 * k * s)).abs() < 1e-9);
            // E and B do not depend on k.
            assert!((um(f.e) - 6.0).abs() < 1e-9);
            assert!((um(f.b) - 2.0).abs() < 1e-9);
        }
    }
}
