//! An effect's parameters with their units as types, as they leave the
//! effects for a report: the parameters that are positions or deviations
//! of the axis (a periodic error's period and amplitude, a reversal's B, an
//! outlier run's offset), `Mm` and `Um` on a linear axis, `Deg` and `Deg` on
//! a rotary one ([`super::Effect::typed`]).
//!
//! Inside, an effect holds bare numbers in the axis' units: positions in mm
//! or °, deviations in µm or m° (1/1000 °). The other kinds' parameters
//! (scale µm/m, drift µm/h or µm/run, Abbe's lever in mm) are not positions
//! or deviations of the axis, and those kinds are looked for on a linear
//! axis only (`diagnose::gates`): they have no typed form here.

use super::{Effect, Uncertainty};
use crate::measurement::{AxisKind, ByKind, Direction};
use crate::units::{Deg, Mm, Um, millideg_to_deg};

/// A deviation held in the effects' rotary unit, m° (1/1000 °), as degrees.
pub fn held_angle(value_millideg: f64) -> Deg {
    Deg(millideg_to_deg(value_millideg))
}

/// An effect's parameters that have a unit of the axis, each with its
/// standard uncertainty (NaN where the fit gave none): positions in `P`,
/// deviations in `D`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EffectIn<P, D> {
    /// A [`super::Reversal`].
    Reversal {
        /// B = ↑ − ↓.
        b: D,
        /// Its standard uncertainty.
        b_uncertainty: D,
    },
    /// A [`super::Periodic`] error.
    Periodic {
        /// Its period.
        period: P,
        /// The period's standard uncertainty, when it was estimated (a
        /// rotary axis' whole order per revolution is chosen, not estimated).
        period_uncertainty: Option<P>,
        /// Its amplitude.
        amplitude: D,
        /// The amplitude's standard uncertainty.
        amplitude_uncertainty: D,
        /// Its phase, rad.
        phase_rad: f64,
    },
    /// An [`super::OutlierRun`].
    OutlierRun {
        /// Its number within its direction.
        run: u32,
        /// ↑ or ↓.
        direction: Direction,
        /// How far it sits off the others.
        offset: D,
        /// The offset's standard uncertainty.
        offset_uncertainty: D,
    },
}

impl<D> EffectIn<Deg, D> {
    /// A rotary periodic error's whole number of periods per revolution
    /// (360°/period), when its period is one; `None` for other kinds.
    pub fn per_revolution(&self) -> Option<u32> {
        match *self {
            EffectIn::Periodic { period, .. } => super::periodic::per_revolution(period.0),
            EffectIn::Reversal { .. } | EffectIn::OutlierRun { .. } => None,
        }
    }
}

impl<P, D> EffectIn<P, D> {
    /// The same with every deviation converted by `convert` (`Deg::to_arcsec`,
    /// `Deg::to_urad`): the function's type decides which unit it accepts.
    pub fn map_deviations<E>(self, convert: fn(D) -> E) -> EffectIn<P, E> {
        match self {
            EffectIn::Reversal { b, b_uncertainty } => EffectIn::Reversal {
                b: convert(b),
                b_uncertainty: convert(b_uncertainty),
            },
            EffectIn::Periodic {
                period,
                period_uncertainty,
                amplitude,
                amplitude_uncertainty,
                phase_rad,
            } => EffectIn::Periodic {
                period,
                period_uncertainty,
                amplitude: convert(amplitude),
                amplitude_uncertainty: convert(amplitude_uncertainty),
                phase_rad,
            },
            EffectIn::OutlierRun {
                run,
                direction,
                offset,
                offset_uncertainty,
            } => EffectIn::OutlierRun {
                run,
                direction,
                offset: convert(offset),
                offset_uncertainty: convert(offset_uncertainty),
            },
        }
    }
}

impl Effect {
    /// Its parameters that are positions or deviations of the axis, with
    /// their standard uncertainties (`uncertainty`, by the parameters'
    /// keys, as [`super::Fit::uncertainty`] gives them), their units as
    /// types by the axis' `kind`: on a linear axis positions in [`Mm`] and
    /// deviations in [`Um`], on a rotary one both in [`Deg`] (the
    /// deviations held in m°). `None` for a kind whose parameters are none
    /// of these (scale, drift, Abbe: module doc).
    ///
    /// ```
    /// use axcomp::effects::{Effect, EffectIn, Reversal};
    /// use axcomp::measurement::AxisKind;
    /// use axcomp::units::Deg;
    ///
    /// // 10 m° is 0.01°.
    /// let effect = Effect::Reversal(Reversal { b: 10.0 });
    /// let typed = effect.typed(AxisKind::Rotary, &[("B_um", 1.0)]);
    /// let Some(EffectIn::Reversal { b, b_uncertainty }) = typed.and_then(|t| t.rotary()) else {
    ///     unreachable!()
    /// };
    /// let b: Deg = b;
    /// assert_eq!((b, b_uncertainty), (Deg(0.01), Deg(0.001)));
    /// ```
    /// A rotary axis' B is no `Um`:
    /// ```compile_fail
    /// use axcomp::effects::{Effect, EffectIn, Reversal};
    /// use axcomp::measurement::AxisKind;
    /// use axcomp::units::Um;
    ///
    /// let effect = Effect::Reversal(Reversal { b: 10.0 });
    /// let typed = effect.typed(AxisKind::Rotary, &[]);
    /// let Some(EffectIn::Reversal { b, .. }) = typed.and_then(|t| t.rotary()) else {
    ///     unreachable!()
    /// };
    /// let b: Um = b;
    /// ```
    pub fn typed(
        &self,
        kind: AxisKind,
        uncertainty: &[Uncertainty],
    ) -> Option<ByKind<EffectIn<Mm, Um>, EffectIn<Deg, Deg>>> {
        Some(match kind {
            AxisKind::Linear => ByKind::Linear(self.in_units(uncertainty, Mm, Um)?),
            AxisKind::Rotary => ByKind::Rotary(self.in_units(uncertainty, Deg, held_angle)?),
        })
    }

    fn in_units<P, D>(
        &self,
        uncertainty: &[Uncertainty],
        position: fn(f64) -> P,
        deviation: fn(f64) -> D,
    ) -> Option<EffectIn<P, D>> {
        let sigma = |key: &str| {
            uncertainty
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, sigma)| *sigma)
        };
        let deviation_sigma = |key: &str| deviation(sigma(key).unwrap_or(f64::NAN));
        Some(match self {
            Effect::Reversal(reversal) => EffectIn::Reversal {
                b: deviation(reversal.b),
                b_uncertainty: deviation_sigma(super::reversal::B_KEY),
            },
            Effect::Periodic(periodic) => EffectIn::Periodic {
                period: position(periodic.period),
                period_uncertainty: sigma(super::periodic::PERIOD_KEY).map(position),
                amplitude: deviation(periodic.amplitude),
                amplitude_uncertainty: deviation_sigma(super::periodic::AMPLITUDE_KEY),
                phase_rad: periodic.phase_rad,
            },
            Effect::OutlierRun(run) => EffectIn::OutlierRun {
                run: run.run,
                direction: run.direction,
                offset: deviation(run.offset),
                offset_uncertainty: deviation_sigma(super::outlier_run::OFFSET_KEY),
            },
            Effect::Scale(_) | Effect::Drift(_) | Effect::Abbe(_) => return None,
        })
    }
}
