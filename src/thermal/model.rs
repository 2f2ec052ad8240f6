//! The compensation model: the drift as a sum of sensors through first-order
//! lags, `d(t) = Σ cᵢ·(Lτᵢ[Tᵢ](t) − Tᵢ,ref)`, with no constant term (at the
//! reference temperatures the drift is zero, as it is at the log's start).
//!
//! Fitting ([`fit`]) chooses the sensors and their time constants by forward
//! selection on time-blocked cross-validation: the rows given are cut into
//! contiguous blocks, each block is predicted by the fit on the others, and a
//! sensor (with the time constant from the grid that predicts best) is added
//! only while it lowers the cross-validated rms by a set fraction. Blocks,
//! not a random split: neighbouring rows of a thermal log are nearly equal,
//! and a random split would score interpolation, not prediction (Arlot and
//! Celisse 2010, §8.1). Only the rows given are used; rows after them are
//! never seen. The cross-validated rms is the prediction's uncertainty.
//!
//! With a reference sensor (the other end of the measuring loop: the table,
//! the air) each chosen sensor enters as its rise over the reference,
//! `cᵢ·(Lτᵢ[Tᵢ] − Lτr[Tr])`: a uniform change of the whole loop's
//! temperature moves both ends alike. One time constant of the reference
//! is chosen for all; the file stores the reference as one more term whose
//! coefficient is minus the sum of the others, so a control runs one sum.
//!
//! Applying ([`apply`]) starts every lag at the log's first row.

use nalgebra::{DMatrix, DVector};
use serde::Deserialize;

use crate::error::ParseError;

use super::{ThermalError, ThermalLog, lag};

/// One term of the model: a sensor through a lag, times a coefficient.
#[derive(Clone, Debug, PartialEq)]
pub struct Term {
    /// The sensor (the log's column name).
    pub sensor: String,
    /// The lag's time constant, s (0: no lag).
    pub tau_s: f64,
    /// µm of drift per K of the lagged temperature.
    pub coefficient_um_per_k: f64,
    /// The temperature at which the term is zero, °C.
    pub reference_c: f64,
}

/// What the fit was made from, and how well it predicts.
#[derive(Clone, Debug, PartialEq)]
pub struct FitSummary {
    /// The drift column fitted.
    pub drift: String,
    /// The rows fitted on, 1-based data rows, first and last (inclusive).
    pub first_row: usize,
    /// The last row fitted on (inclusive).
    pub last_row: usize,
    /// Time of the first and last row fitted on, s from the log's start.
    pub from_s: f64,
    /// Time of the last row fitted on.
    pub to_s: f64,
    /// The sensors the selection could choose from.
    pub candidates: Vec<String>,
    /// The reference sensor, when each term is a rise over it.
    pub reference: Option<String>,
    /// The number of contiguous blocks of the cross-validation.
    pub blocks: usize,
    /// How the blocks were predicted.
    pub validation: Validation,
    /// The cross-validated rms (each block predicted from the others), µm:
    /// the prediction's standard uncertainty. With [`Validation::Late`] it
    /// covers the last third of the rows only, where a warm-up's drift is
    /// nearly flat: it understates the error of a prediction beyond them
    /// (0.15 µm against 0.66 µm held out on the real spindle log).
    pub cv_rms_um: f64,
    /// The rms of the fit on all rows fitted on, µm.
    pub fit_rms_um: f64,
}

/// A fitted model.
#[derive(Clone, Debug, PartialEq)]
pub struct ThermalModel {
    /// The terms, summed.
    pub terms: Vec<Term>,
    /// How it was fitted.
    pub fit: FitSummary,
}

/// How to fit.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// The rows to fit on, 0-based, end exclusive.
    pub rows: std::ops::Range<usize>,
    /// The sensors to choose from (empty: every sensor of the log).
    pub sensors: Vec<String>,
    /// Sensors never to use.
    pub exclude: Vec<String>,
    /// The reference sensor (each term a rise over it).
    pub reference: Option<String>,
    /// The time constants to try, s (0: no lag).
    pub taus_s: Vec<f64>,
    /// Contiguous blocks of the cross-validation.
    pub blocks: usize,
    /// At most this many sensors (the reference aside).
    pub max_sensors: usize,
    /// A sensor is added only if it lowers the cross-validated rms by this fraction.
    pub min_gain: f64,
    /// How the blocks are predicted.
    pub validation: Validation,
    /// Without a reference: try the coldest candidate over the fit rows as
    /// the reference (and none) and keep the choice that predicts best
    /// ([`coldest`]), with [`FitOptions::same_sign`].
    pub auto_reference: bool,
    /// With a reference: every coefficient of a rise over it has the sign
    /// of the drift over the fit rows (nonnegative least squares, Lawson
    /// and Hanson 1974, ch. 23): each chosen part, warmer than the loop's
    /// other end, grows the loop the way the drift goes. Without it, a
    /// sensor that barely moves in the warm-up (a regulated coolant) can
    /// take tens of µm/K of the opposite sign, which cancels inside the
    /// warm-up and not after it.
    pub same_sign: bool,
}

/// How the cross-validation predicts its blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Validation {
    /// Each block from all the others (k-fold over contiguous blocks).
    Blocked,
    /// Each block from the blocks before it only (a rolling forecast
    /// origin, Bergmeir and Benítez 2012): what a model does on a machine,
    /// predicting the hours after the ones it was fitted on. The first
    /// block is never predicted.
    Forward,
    /// Forward over the last third of the rows only: the first two thirds
    /// are one block that is never predicted, the last third is cut into the
    /// blocks, and each is predicted from every row before it (a rolling
    /// origin whose first origin is two thirds in, Tashman 2000, §3). In a
    /// warm-up every heated sensor rises with the drift, and the early
    /// blocks reward whichever tracks that common rise; the late ones, the
    /// nearest the rows come to the steady state the model will run in,
    /// reward the sensor that stays right when the rise ends.
    Late,
}

impl Validation {
    /// The name the model file and `--validation` use.
    pub fn name(self) -> &'static str {
        match self {
            Validation::Blocked => "blocked",
            Validation::Forward => "forward",
            Validation::Late => "late",
        }
    }

    /// The contiguous blocks `rows` is cut into, 0-based ranges in order
    /// (see the variants).
    fn blocks(self, rows: &std::ops::Range<usize>, blocks: usize) -> Vec<std::ops::Range<usize>> {
        let cut = |range: std::ops::Range<usize>| {
            let count = range.len();
            (0..blocks).map(move |b| {
                range.start + b * count / blocks..range.start + (b + 1) * count / blocks
            })
        };
        match self {
            Validation::Blocked | Validation::Forward => cut(rows.clone()).collect(),
            Validation::Late => {
                let last_third = rows.start + 2 * rows.len() / 3;
                std::iter::once(rows.start..last_third)
                    .chain(cut(last_third..rows.end))
                    .collect()
            }
        }
    }
}

impl FitOptions {
    /// The defaults over `rows`: the time-constant grid of [`tau_grid_s`],
    /// five blocks, up to four sensors, each gaining 5 %.
    pub fn over(rows: std::ops::Range<usize>) -> FitOptions {
        FitOptions {
            rows,
            sensors: Vec::new(),
            exclude: Vec::new(),
            reference: None,
            taus_s: tau_grid_s(),
            blocks: 5,
            max_sensors: 4,
            min_gain: 0.05,
            validation: Validation::Blocked,
            auto_reference: false,
            same_sign: false,
        }
    }
}

/// The time constants tried: none, and 5 min doubling to 640 min (a
/// spindle's bearings take minutes, its housing and a machine's structure
/// hours).
pub fn tau_grid_s() -> Vec<f64> {
    let mut taus = vec![0.0];
    taus.extend((0..8).map(|k| 300.0 * f64::from(1u32 << k)));
    taus
}

/// The lagged temperatures' Gram matrices, one per block, over every
/// candidate feature (sensor × time constant) and the reference's.
struct Problem {
    /// Per block: X'X, X'y, y'y, rows.
    blocks: Vec<(DMatrix<f64>, DVector<f64>, f64, usize)>,
    /// Feature index of (candidate k, tau j) is k·taus + j; the reference's
    /// features follow the candidates'.
    taus: usize,
    candidates: usize,
    validation: Validation,
    /// The sign every coefficient must have ([`FitOptions::same_sign`]).
    sign: Option<f64>,
}

/// A choice: candidate features and, with a reference, its feature.
#[derive(Clone, Debug, PartialEq)]
struct Choice {
    features: Vec<usize>,
    reference: Option<usize>,
}

impl Problem {
    fn build(
        log: &ThermalLog,
        drift: &[f64],
        columns: &[&[f64]],
        taus_s: &[f64],
        options: &FitOptions,
    ) -> Problem {
        let end = options.rows.end;
        let times = &log.times_s[..end];
        let mut features: Vec<Vec<f64>> = Vec::new();
        let mut lagged = Vec::new();
        for column in columns {
            for &tau in taus_s {
                lag(&column[..end], times, tau, &mut lagged);
                let start = column[0];
                features.push(lagged.iter().map(|v| v - start).collect());
            }
        }
        let blocks = options
            .validation
            .blocks(&options.rows, options.blocks)
            .into_iter()
            .map(|range| {
                let (lo, hi) = (range.start, range.end);
                let x = DMatrix::from_fn(hi - lo, features.len(), |r, f| features[f][lo + r]);
                let y = DVector::from_fn(hi - lo, |r, _| drift[lo + r] - drift[0]);
                (x.transpose() * &x, x.transpose() * &y, y.dot(&y), hi - lo)
            })
            .collect();
        let rise: f64 = drift[options.rows.clone()]
            .iter()
            .map(|d| d - drift[0])
            .sum();
        Problem {
            blocks,
            taus: taus_s.len(),
            candidates: columns.len() - usize::from(options.reference.is_some()),
            validation: options.validation,
            sign: (options.same_sign && options.reference.is_some()).then_some(if rise < 0.0 {
                -1.0
            } else {
                1.0
            }),
        }
    }

    /// The normal equations of a choice over the blocks `use_block` keeps.
    fn normal(
        &self,
        choice: &Choice,
        use_block: impl Fn(usize) -> bool,
    ) -> (DMatrix<f64>, DVector<f64>) {
        let k = choice.features.len();
        let mut a = DMatrix::zeros(k, k);
        let mut v = DVector::zeros(k);
        for (b, (g, h, _, _)) in self.blocks.iter().enumerate() {
            if !use_block(b) {
                continue;
            }
            let (ga, ha) = self.restricted(choice, g, h);
            a += ga;
            v += ha;
        }
        (a, v)
    }

    /// One block's Gram matrix and X'y for a choice (the rises over the reference, with one).
    fn restricted(
        &self,
        choice: &Choice,
        g: &DMatrix<f64>,
        h: &DVector<f64>,
    ) -> (DMatrix<f64>, DVector<f64>) {
        let f = &choice.features;
        let k = f.len();
        let mut a = DMatrix::from_fn(k, k, |i, j| g[(f[i], f[j])]);
        let mut v = DVector::from_fn(k, |i, _| h[f[i]]);
        if let Some(r) = choice.reference {
            for i in 0..k {
                for j in 0..k {
                    a[(i, j)] += -g[(f[i], r)] - g[(r, f[j])] + g[(r, r)];
                }
                v[i] -= h[r];
            }
        }
        (a, v)
    }

    /// The sum of squared residuals of coefficients `c` on block `b`.
    fn sse(&self, choice: &Choice, c: &DVector<f64>, b: usize) -> f64 {
        let (g, h, yy, _) = &self.blocks[b];
        let (a, v) = self.restricted(choice, g, h);
        (yy - 2.0 * c.dot(&v) + (a * c).dot(c)).max(0.0)
    }

    /// Each block predicted by the fit on the others: the rms, µm
    /// (infinite when a fit is singular).
    fn cv_rms(&self, choice: &Choice) -> f64 {
        if choice.features.is_empty() {
            let first = usize::from(self.validation != Validation::Blocked);
            let scored = &self.blocks[first.min(self.blocks.len())..];
            let total: f64 = scored.iter().map(|b| b.2).sum();
            let rows: usize = scored.iter().map(|b| b.3).sum();
            return (total / rows.max(1) as f64).sqrt();
        }
        let mut total = 0.0;
        let mut rows = 0;
        let first = usize::from(self.validation != Validation::Blocked);
        for held in first..self.blocks.len() {
            let (a, v) = match self.validation {
                Validation::Blocked => self.normal(choice, |b| b != held),
                Validation::Forward | Validation::Late => self.normal(choice, |b| b < held),
            };
            let Some(c) = self.solve(a, v) else {
                return f64::INFINITY;
            };
            total += self.sse(choice, &c, held);
            rows += self.blocks[held].3;
        }
        (total / rows as f64).sqrt()
    }

    /// The coefficients of normal equations `a·c = v`: least squares, or
    /// with [`FitOptions::same_sign`] nonnegative least squares on `sign·c`.
    fn solve(&self, a: DMatrix<f64>, v: DVector<f64>) -> Option<DVector<f64>> {
        match self.sign {
            None => solve(a, v),
            Some(sign) => nonnegative(&a, &(v * sign)).map(|c| c * sign),
        }
    }

    /// Forward selection for one reference feature (or none).
    fn forward(&self, reference: Option<usize>, options: &FitOptions) -> (Choice, f64) {
        let mut choice = Choice {
            features: Vec::new(),
            reference,
        };
        let mut score = self.cv_rms(&choice);
        while choice.features.len() < options.max_sensors {
            let mut best: Option<(f64, usize)> = None;
            for candidate in 0..self.candidates {
                if choice.features.iter().any(|f| f / self.taus == candidate) {
                    continue;
                }
                for t in 0..self.taus {
                    let feature = candidate * self.taus + t;
                    let mut trial = choice.clone();
                    trial.features.push(feature);
                    let trial_score = self.cv_rms(&trial);
                    if best.is_none_or(|(s, _)| trial_score < s) {
                        best = Some((trial_score, feature));
                    }
                }
            }
            match best {
                Some((s, feature)) if s < score * (1.0 - options.min_gain) => {
                    choice.features.push(feature);
                    score = s;
                }
                _ => break,
            }
        }
        (choice, score)
    }
}

fn solve(a: DMatrix<f64>, v: DVector<f64>) -> Option<DVector<f64>> {
    let c = a.cholesky()?.solve(&v);
    c.iter().all(|x| x.is_finite()).then_some(c)
}

/// The `c ≥ 0` minimising `c'·a·c − 2·c'·v` (least squares from its
/// normal equations): Lawson and Hanson's active-set NNLS (1974, ch. 23,
/// algorithm NNLS), on the Gram matrix. `None` when a subsystem is singular.
pub(super) fn nonnegative(a: &DMatrix<f64>, v: &DVector<f64>) -> Option<DVector<f64>> {
    let k = v.len();
    let mut c = DVector::zeros(k);
    let mut passive = vec![false; k];
    let tolerance = 1e-12 * v.amax().max(f64::MIN_POSITIVE);
    // Each outer step frees one coefficient; the bound only guards rounding.
    for _ in 0..3 * k + 3 {
        let w = v - a * &c;
        let Some(j) = (0..k)
            .filter(|&j| !passive[j] && w[j] > tolerance)
            .max_by(|&i, &j| w[i].total_cmp(&w[j]))
        else {
            break;
        };
        passive[j] = true;
        // At most k steps: each drops a coefficient that reached zero.
        loop {
            let p: Vec<usize> = (0..k).filter(|&i| passive[i]).collect();
            let ap = DMatrix::from_fn(p.len(), p.len(), |r, s| a[(p[r], p[s])]);
            let vp = DVector::from_fn(p.len(), |r, _| v[p[r]]);
            let s = solve(ap, vp)?;
            if s.iter().all(|&x| x > 0.0) {
                for (r, &i) in p.iter().enumerate() {
                    c[i] = s[r];
                }
                break;
            }
            // Step from c towards s until the first coefficient reaches zero.
            let (alpha, limit) = p
                .iter()
                .enumerate()
                .filter(|&(r, _)| s[r] <= 0.0)
                .map(|(r, &i)| (c[i] / (c[i] - s[r]), i))
                .fold((f64::INFINITY, k), |m, x| if x.0 < m.0 { x } else { m });
            for (r, &i) in p.iter().enumerate() {
                c[i] += alpha * (s[r] - c[i]);
                if i == limit || c[i] <= 0.0 {
                    c[i] = 0.0;
                    passive[i] = false;
                }
            }
        }
    }
    Some(c)
}

/// Fits a model of `log`'s drift on `options.rows`; with
/// `auto_reference` (and no reference named), the better of the coldest
/// candidate as the reference ([`coldest`]) and none, by the same
/// cross-validation.
pub fn fit(log: &ThermalLog, options: &FitOptions) -> Result<ThermalModel, ThermalError> {
    if !options.auto_reference || options.reference.is_some() {
        return fit_one(log, options);
    }
    let plain = FitOptions {
        auto_reference: false,
        ..options.clone()
    };
    let none = fit_one(log, &plain)?;
    let Some(reference) = coldest(log, &none.fit.candidates, &options.rows) else {
        return Ok(none);
    };
    let trial = FitOptions {
        reference: Some(reference),
        same_sign: true,
        ..plain
    };
    Ok(match fit_one(log, &trial) {
        Ok(model) if model.fit.cv_rms_um < none.fit.cv_rms_um => model,
        _ => none,
    })
}

/// The reference a fit takes when the user names none: of `candidates`,
/// the sensor with the lowest mean temperature over `rows` (the first on a
/// tie). The machine's heat sources only warm it, so the coldest sensor is
/// the one they reach least: the room or the table, the measuring loop's
/// other end, whose own changes (the room's day) move both ends of the loop
/// (Bryan 1990, "International status of thermal error research", CIRP
/// Annals 39/2: a machine's errors follow the differences of its
/// temperatures, not their level). A rule, not a choice by the
/// cross-validation: tried as references, every sensor fits a warm-up alike,
/// and the one chosen is the one that fits its noise.
pub fn coldest(
    log: &ThermalLog,
    candidates: &[String],
    rows: &std::ops::Range<usize>,
) -> Option<String> {
    let mean = |name: &str| {
        let values = &log.sensor(name)?.celsius.get(rows.clone())?;
        Some(values.iter().sum::<f64>() / values.len().max(1) as f64)
    };
    candidates
        .iter()
        .filter_map(|name| Some((mean(name)?, name)))
        .fold(None, |best: Option<(f64, &String)>, (m, name)| match best {
            Some((b, _)) if b <= m => best,
            _ => Some((m, name)),
        })
        .map(|(_, name)| name.clone())
}

fn fit_one(log: &ThermalLog, options: &FitOptions) -> Result<ThermalModel, ThermalError> {
    let drift = log.drift.as_ref().ok_or_else(|| {
        ThermalError::Request("the log has no drift column to fit (--drift)".to_string())
    })?;
    let rows = options.rows.clone();
    let short_block = options.blocks == 0
        || options
            .validation
            .blocks(&rows, options.blocks)
            .iter()
            .any(|b| b.len() < 2);
    if rows.end > log.len() || short_block {
        return Err(ThermalError::Request(format!(
            "cannot fit on rows {}–{}: the log has {} rows, and each of the {} blocks{} needs at least two",
            rows.start + 1,
            rows.end,
            log.len(),
            options.blocks,
            if options.validation == Validation::Late {
                " of the last third"
            } else {
                ""
            }
        )));
    }
    for name in options
        .sensors
        .iter()
        .chain(&options.exclude)
        .chain(&options.reference)
    {
        if log.sensor(name).is_none() {
            return Err(ThermalError::Request(format!(
                "the log has no temperature column {name:?}"
            )));
        }
    }
    let candidates: Vec<&str> = log
        .sensors
        .iter()
        .map(|s| s.name.as_str())
        .filter(|name| options.sensors.is_empty() || options.sensors.iter().any(|s| s == name))
        .filter(|name| !options.exclude.iter().any(|s| s == name))
        .filter(|name| options.reference.as_deref() != Some(*name))
        .collect();
    if candidates.is_empty() {
        return Err(ThermalError::Request(
            "no sensor is left to choose from".to_string(),
        ));
    }
    let mut columns: Vec<&[f64]> = candidates
        .iter()
        .filter_map(|name| log.sensor(name))
        .map(|s| s.celsius.as_slice())
        .collect();
    let reference_sensor = options
        .reference
        .as_deref()
        .and_then(|name| log.sensor(name));
    if let Some(sensor) = reference_sensor {
        columns.push(&sensor.celsius);
    }
    let taus = &options.taus_s;
    let problem = Problem::build(log, &drift.um, &columns, taus, options);
    let references: Vec<Option<usize>> = match reference_sensor {
        None => vec![None],
        Some(_) => (0..taus.len())
            .map(|t| Some(candidates.len() * taus.len() + t))
            .collect(),
    };
    let mut best: Option<(Choice, f64)> = None;
    for reference in references {
        let (choice, score) = problem.forward(reference, options);
        if best.as_ref().is_none_or(|(_, s)| score < *s) {
            best = Some((choice, score));
        }
    }
    let (choice, cv_rms_um) = best.expect("at least one reference choice");
    let (a, v) = problem.normal(&choice, |_| true);
    let coefficients = if choice.features.is_empty() {
        DVector::zeros(0)
    } else {
        problem
            .solve(a, v)
            .ok_or_else(|| ThermalError::Request("the chosen sensors are collinear".to_string()))?
    };
    let sse: f64 = (0..problem.blocks.len())
        .map(|b| problem.sse(&choice, &coefficients, b))
        .sum();
    let fit_rms_um = (sse / rows.len() as f64).sqrt();
    let mut terms: Vec<Term> = choice
        .features
        .iter()
        .zip(coefficients.iter())
        // Nonnegative least squares may leave a chosen sensor at zero.
        .filter(|&(_, &c)| c != 0.0)
        .map(|(&feature, &c)| {
            let name = candidates[feature / taus.len()];
            Term {
                sensor: name.to_string(),
                tau_s: taus[feature % taus.len()],
                coefficient_um_per_k: c,
                reference_c: log.sensor(name).map_or(0.0, |s| s.celsius[0]),
            }
        })
        .collect();
    if let (Some(r), Some(sensor)) = (choice.reference, reference_sensor)
        && !terms.is_empty()
    {
        terms.push(Term {
            sensor: sensor.name.clone(),
            tau_s: taus[r % taus.len()],
            coefficient_um_per_k: -coefficients.sum(),
            reference_c: sensor.celsius[0],
        });
    }
    Ok(ThermalModel {
        terms,
        fit: FitSummary {
            drift: drift.name.clone(),
            first_row: rows.start + 1,
            last_row: rows.end,
            from_s: log.times_s[rows.start],
            to_s: log.times_s[rows.end - 1],
            candidates: candidates.iter().map(|s| s.to_string()).collect(),
            reference: reference_sensor.map(|s| s.name.clone()),
            blocks: options.blocks,
            validation: options.validation,
            cv_rms_um,
            fit_rms_um,
        },
    })
}

/// A model run over a log.
#[derive(Clone, Debug, PartialEq)]
pub struct Application {
    /// The predicted drift at each row, µm.
    pub predicted_um: Vec<f64>,
    /// The measured drift from the first row (where the log has the model's
    /// drift column), µm.
    pub measured_um: Option<Vec<f64>>,
}

impl Application {
    /// Measured minus predicted at each row, µm (where the log has the drift).
    pub fn residual_um(&self) -> Option<Vec<f64>> {
        let measured = self.measured_um.as_ref()?;
        Some(
            measured
                .iter()
                .zip(&self.predicted_um)
                .map(|(m, p)| m - p)
                .collect(),
        )
    }
}

/// Runs `model` over `log`, every lag starting at the log's first row.
pub fn apply(model: &ThermalModel, log: &ThermalLog) -> Result<Application, ThermalError> {
    let mut predicted_um = vec![0.0; log.len()];
    let mut lagged = Vec::with_capacity(log.len());
    for term in &model.terms {
        let sensor = log.sensor(&term.sensor).ok_or_else(|| {
            ThermalError::Request(format!(
                "the log has no temperature column {:?}, which the model uses",
                term.sensor
            ))
        })?;
        lag(&sensor.celsius, &log.times_s, term.tau_s, &mut lagged);
        for (p, l) in predicted_um.iter_mut().zip(&lagged) {
            *p += term.coefficient_um_per_k * (l - term.reference_c);
        }
    }
    let measured_um = log
        .drift
        .as_ref()
        .filter(|d| d.name == model.fit.drift)
        .map(|d| d.um.iter().map(|v| v - d.um[0]).collect());
    Ok(Application {
        predicted_um,
        measured_um,
    })
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelFile {
    fit: FitFile,
    #[serde(default)]
    term: Vec<TermFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FitFile {
    drift: String,
    first_row: usize,
    last_row: usize,
    from_s: f64,
    to_s: f64,
    candidates: Vec<String>,
    reference: Option<String>,
    blocks: usize,
    #[serde(default)]
    validation: Option<String>,
    cv_rms_um: f64,
    fit_rms_um: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TermFile {
    sensor: String,
    tau_s: f64,
    coefficient_um_per_k: f64,
    reference_c: f64,
}

impl ThermalModel {
    /// Reads a model file (`report::thermal::model_toml` writes it).
    pub fn from_toml(text: &str) -> Result<ThermalModel, ParseError> {
        let file: ModelFile = toml::from_str(text).map_err(|e| ParseError::from_toml(text, &e))?;
        let mut terms = Vec::new();
        for term in file.term {
            let finite = [term.tau_s, term.coefficient_um_per_k, term.reference_c]
                .iter()
                .all(|v| v.is_finite());
            if !finite || term.tau_s < 0.0 {
                let at = text.find(&format!("\"{}\"", term.sensor)).unwrap_or(0);
                let line = text[..at].matches('\n').count() + 1;
                return Err(ParseError::new(
                    line,
                    1,
                    format!(
                        "term {:?}: expected finite values and tau_s ≥ 0",
                        term.sensor
                    ),
                ));
            }
            terms.push(Term {
                sensor: term.sensor,
                tau_s: term.tau_s,
                coefficient_um_per_k: term.coefficient_um_per_k,
                reference_c: term.reference_c,
            });
        }
        let f = file.fit;
        let validation = match f.validation.as_deref() {
            None | Some("blocked") => Validation::Blocked,
            Some("forward") => Validation::Forward,
            Some("late") => Validation::Late,
            Some(other) => {
                let at = text.find("validation").unwrap_or(0);
                let line = text[..at].matches('\n').count() + 1;
                return Err(ParseError::new(
                    line,
                    1,
                    format!(
                        "expected validation \"blocked\", \"forward\" or \"late\", found {other:?}"
                    ),
                ));
            }
        };
        Ok(ThermalModel {
            terms,
            fit: FitSummary {
                drift: f.drift,
                first_row: f.first_row,
                last_row: f.last_row,
                from_s: f.from_s,
                to_s: f.to_s,
                candidates: f.candidates,
                reference: f.reference,
                blocks: f.blocks,
                validation,
                cv_rms_um: f.cv_rms_um,
                fit_rms_um: f.fit_rms_um,
            },
        })
    }
}
