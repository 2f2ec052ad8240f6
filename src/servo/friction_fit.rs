//! `servo-sim --identify`: the friction parameters of Mendřický (2006) ch. 5
//! (F_C, μ_v and the LuGre stiffness k_s) fitted to two records of an axis.
//!
//! 1. **Constant-velocity record** (Mendřický's Tab. 5.1, §5.2): the mean
//!    motor current at several constant feeds. At constant speed the loops
//!    hold the friction force, F = K_F3·I (the PI velocity loop's integrator
//!    takes it all, so the following error there carries no friction and is
//!    not used); F_C and μ_v are the least-squares line F = F_C + μ_v·|v|
//!    ([`identify::coulomb_viscous_fit`], the linear fit of Fig. 5.1).
//! 2. **A measured reversal** (§6.3, Fig. 6.13): the following error of the
//!    axis on Mendřický's circle, sampled at the position loop, through its
//!    quadrant reversals. The spike at each reversal is the pre-sliding of
//!    the friction contact, set by k_s (Mendřický (2006) tuned k_s to this very
//!    record, §6.3.4). With F_C and μ_v from step 1, k_s is the value whose
//!    simulated circle ([`circle::run_circle`], LuGre with the axis's ζ_s
//!    and b_s by eq. 4.15) matches the record best in least squares: a
//!    search over log k_s from 10⁵ to 10⁹ N/m, a quarter decade apart, then
//!    golden section around the best.
//!
//! The record layouts (CSV, `#` comments, a header naming the columns with
//! their units):
//!
//! ```text
//! feed_m_per_min,current_a          constant-velocity record: one row per feed
//! 0.5,1.05                          (signed: a run in −x has a negative feed
//! -0.5,-1.04                         and, on the same axis, a negative current)
//!
//! time_s,following_error_um         the circle: time from the start of the
//! 0.001,0.0000                      circle (φ = π/2, as servo-sim --test
//!                                   circle starts it), following error x_z − x;
//!                                   servo-sim's own --csv trace has these
//!                                   columns among others, and reads as is
//! ```
//!
//! Pure: values in, values out; progress through a callback.

use std::f64::consts::PI;

use crate::error::{ParseError, describe_found};
use crate::servo::ServoError;
use crate::servo::axis::Axis;
use crate::servo::circle::run_circle;
use crate::servo::friction::FrictionKind;
use crate::servo::identify::{coulomb_viscous_fit, m_per_min_to_m_per_s};
use crate::servo::simulate::Stepping;
use crate::servo::trajectory::Circle;
use crate::units::{mm_to_m, um_to_mm};

/// One row of the constant-velocity record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantVelocityRow {
    /// The constant feed, m/min (negative: moving in −x).
    pub feed_m_per_min: f64,
    /// The mean motor current at it, A.
    pub current_a: f64,
}

/// One sample of the circle's following error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FollowingErrorSample {
    /// Time from the start of the circle, s.
    pub time_s: f64,
    /// Following error x_z − x, m.
    pub following_error_m: f64,
}

/// What the identification gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Identified {
    /// Coulomb friction F_C, N.
    pub coulomb_n: f64,
    /// Viscous coefficient μ_v, N·s/m.
    pub viscous_n_s_per_m: f64,
    /// RMS of the constant-velocity forces about the fitted line, N.
    pub force_rms_residual_n: f64,
    /// Rows of the constant-velocity record used.
    pub rows: usize,
    /// The LuGre stiffness k_s, N/m, when a reversal record was given.
    pub stiffness: Option<StiffnessFit>,
}

/// k_s fitted to the circle's following error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StiffnessFit {
    /// LuGre stiffness k_s, N/m.
    pub stiffness_n_per_m: f64,
    /// RMS of the record about the simulated following error, m.
    pub rms_residual_m: f64,
    /// Samples of the record compared (after the run-up).
    pub samples: usize,
    /// Circle simulations run.
    pub simulations: usize,
}

/// Reads the constant-velocity record (`feed_m_per_min,current_a`).
pub fn parse_constant_velocity(text: &str) -> Result<Vec<ConstantVelocityRow>, ServoError> {
    let rows = columns(text, &["feed_m_per_min", "current_a"])?;
    Ok(rows
        .into_iter()
        .map(|values| ConstantVelocityRow {
            feed_m_per_min: values[0],
            current_a: values[1],
        })
        .collect())
}

/// Reads the circle record (`time_s` and `following_error_um` among its columns).
pub fn parse_following_error(text: &str) -> Result<Vec<FollowingErrorSample>, ServoError> {
    let rows = columns(text, &["time_s", "following_error_um"])?;
    Ok(rows
        .into_iter()
        .map(|values| FollowingErrorSample {
            time_s: values[0],
            following_error_m: mm_to_m(um_to_mm(values[1])),
        })
        .collect())
}

/// The axis with these friction parameters: F_C (and F_Ts in the file's
/// ratio F_Ts/F_C), μ_v and, if given, k_s (b_s follows by eq. 4.15 with
/// the file's ζ_s). What `servo-sim` starts from after an identification
/// or a diagnosis.
pub fn axis_with_friction(
    axis: &Axis,
    coulomb_n: Option<f64>,
    viscous_n_s_per_m: Option<f64>,
    stiffness_n_per_m: Option<f64>,
) -> Axis {
    let mut axis = axis.clone();
    let friction = &mut axis.friction;
    if let Some(coulomb) = coulomb_n {
        let static_ratio = if friction.coulomb_n > 0.0 {
            friction.static_n / friction.coulomb_n
        } else {
            1.0
        };
        friction.coulomb_n = coulomb;
        friction.static_n = coulomb * static_ratio;
    }
    if let Some(viscous) = viscous_n_s_per_m {
        friction.viscous_n_s_per_m = viscous;
    }
    if let Some(stiffness) = stiffness_n_per_m {
        friction.lugre_stiffness_n_per_m = stiffness;
    }
    axis
}

/// Fits F_C and μ_v to the constant-velocity record and, given the circle
/// that was run and its record, k_s. `progress` gets the fraction done.
pub fn identify(
    axis: &Axis,
    rows: &[ConstantVelocityRow],
    reversal: Option<(&Circle, &[FollowingErrorSample])>,
    progress: &mut dyn FnMut(f64),
) -> Result<Identified, ServoError> {
    let force_constant = axis.motor.force_constant_n_per_a;
    let speeds: Vec<f64> = rows
        .iter()
        .map(|r| m_per_min_to_m_per_s(r.feed_m_per_min.abs()))
        .collect();
    // The force against the motion: a run in −x draws a negative current.
    let forces: Vec<f64> = rows
        .iter()
        .map(|r| r.feed_m_per_min.signum() * force_constant * r.current_a)
        .collect();
    if rows.iter().any(|r| r.feed_m_per_min == 0.0) {
        return Err(ServoError::Invalid(
            "constant-velocity record: a feed of 0 has no direction; give only moving rows",
        ));
    }
    let (coulomb_n, viscous_n_s_per_m) = coulomb_viscous_fit(&speeds, &forces).ok_or(
        ServoError::Invalid("constant-velocity record: at least two different feeds are needed"),
    )?;
    let force_rms_residual_n = (speeds
        .iter()
        .zip(&forces)
        .map(|(v, f)| (f - coulomb_n - viscous_n_s_per_m * v).powi(2))
        .sum::<f64>()
        / rows.len() as f64)
        .sqrt();
    let stiffness = match reversal {
        Some((circle, record)) => Some(fit_stiffness(
            &axis_with_friction(axis, Some(coulomb_n), Some(viscous_n_s_per_m), None),
            circle,
            record,
            progress,
        )?),
        None => None,
    };
    Ok(Identified {
        coulomb_n,
        viscous_n_s_per_m,
        force_rms_residual_n,
        rows: rows.len(),
        stiffness,
    })
}

/// Lowest and highest log10 k_s searched, N/m (Tab. 4.2's pre-sliding
/// distances of 1–50 µm at F_C ≈ 100 N are 2·10⁶–10⁸; Tab. 6.3 tuned 8·10⁵).
const LOG_STIFFNESS_RANGE: (f64, f64) = (5.0, 9.0);
/// Grid step of the first search, decades.
const GRID_STEP: f64 = 0.25;
/// Golden-section steps after the grid (the bracket shrinks to ≈ 10⁻⁴ decade).
const GOLDEN_STEPS: usize = 18;

fn fit_stiffness(
    axis: &Axis,
    circle: &Circle,
    record: &[FollowingErrorSample],
    progress: &mut dyn FnMut(f64),
) -> Result<StiffnessFit, ServoError> {
    let omega = circle.angular_speed_rad_per_s();
    let end_s = circle.ramp_time_s + 2.0 * 2.0 * PI / omega;
    // After the run-up, as the circle's own reversal figures are taken.
    let samples: Vec<FollowingErrorSample> = record
        .iter()
        .copied()
        .filter(|s| s.time_s >= circle.ramp_time_s && s.time_s <= end_s)
        .collect();
    if samples.len() < 10 {
        return Err(ServoError::Invalid(
            "reversal record: fewer than 10 samples after the circle's 0.3 s run-up (time_s counts from the start of the circle)",
        ));
    }
    let grid_points =
        ((LOG_STIFFNESS_RANGE.1 - LOG_STIFFNESS_RANGE.0) / GRID_STEP).round() as usize + 1;
    let total = (grid_points + GOLDEN_STEPS + 2) as f64;
    let mut simulations = 0usize;
    let mut cost = |log_k: f64| -> f64 {
        let trial = axis_with_friction(axis, None, None, Some(10f64.powf(log_k)));
        let result = run_circle(
            &trial,
            trial.friction(FrictionKind::LuGre),
            circle,
            Stepping::DEFAULT,
            &mut |_| {},
        );
        simulations += 1;
        progress(simulations as f64 / total);
        mean_square_difference(&samples, &result.trace)
    };
    let grid: Vec<(f64, f64)> = (0..grid_points)
        .map(|i| {
            let log_k = LOG_STIFFNESS_RANGE.0 + GRID_STEP * i as f64;
            (log_k, cost(log_k))
        })
        .collect();
    let best = (0..grid.len())
        .min_by(|&a, &b| grid[a].1.total_cmp(&grid[b].1))
        .unwrap_or(0);
    let (mut low, mut high) = (
        grid[best.saturating_sub(1)].0,
        grid[(best + 1).min(grid.len() - 1)].0,
    );
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut a = high - ratio * (high - low);
    let mut b = low + ratio * (high - low);
    let (mut cost_a, mut cost_b) = (cost(a), cost(b));
    for _ in 0..GOLDEN_STEPS {
        if cost_a <= cost_b {
            high = b;
            b = a;
            cost_b = cost_a;
            a = high - ratio * (high - low);
            cost_a = cost(a);
        } else {
            low = a;
            a = b;
            cost_a = cost_b;
            b = low + ratio * (high - low);
            cost_b = cost(b);
        }
    }
    let (log_k, best_cost) = if cost_a <= cost_b {
        (a, cost_a)
    } else {
        (b, cost_b)
    };
    let (log_k, best_cost) = if grid[best].1 < best_cost {
        grid[best]
    } else {
        (log_k, best_cost)
    };
    progress(1.0);
    Ok(StiffnessFit {
        stiffness_n_per_m: 10f64.powf(log_k),
        rms_residual_m: best_cost.sqrt(),
        samples: samples.len(),
        simulations,
    })
}

/// Mean square of record − simulation at the record's times (the
/// simulation's 1 ms position samples, the nearest within half a sample).
fn mean_square_difference(
    samples: &[FollowingErrorSample],
    trace: &[crate::servo::simulate::Snapshot],
) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for sample in samples {
        let index = trace.partition_point(|s| s.time_s < sample.time_s);
        let nearest = [index.wrapping_sub(1), index]
            .into_iter()
            .filter_map(|i| trace.get(i))
            .min_by(|a, b| {
                (a.time_s - sample.time_s)
                    .abs()
                    .total_cmp(&(b.time_s - sample.time_s).abs())
            });
        if let Some(snapshot) = nearest
            && (snapshot.time_s - sample.time_s).abs() <= 0.5e-3
        {
            let difference = sample.following_error_m - snapshot.following_error_m();
            sum += difference * difference;
            count += 1;
        }
    }
    if count == 0 {
        return f64::INFINITY;
    }
    sum / count as f64
}

/// The named columns of a CSV record, row by row, in the order asked for.
fn columns(text: &str, wanted: &[&str]) -> Result<Vec<Vec<f64>>, ServoError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, line)| (i + 1, line.split('#').next().unwrap_or("").trim()))
        .filter(|(_, line)| !line.is_empty());
    let expected = format!("a header with the columns {}", wanted.join(","));
    let Some((header_line, header)) = lines.next() else {
        return Err(ServoError::Parse(ParseError::expected(
            1,
            1,
            &expected,
            "an empty file",
        )));
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let mut indices = Vec::with_capacity(wanted.len());
    for name in wanted {
        let Some(index) = names.iter().position(|n| n == name) else {
            return Err(ServoError::Parse(ParseError::expected(
                header_line,
                1,
                &expected,
                header,
            )));
        };
        indices.push(index);
    }
    let mut rows = Vec::new();
    for (number, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != names.len() {
            return Err(ServoError::Parse(ParseError::expected(
                number,
                1,
                &format!("{} fields as in the header", names.len()),
                &format!("{} fields", fields.len()),
            )));
        }
        let mut values = Vec::with_capacity(wanted.len());
        for &index in &indices {
            let field = fields[index];
            // The column in characters where the field starts, for the message.
            let column = fields[..index]
                .iter()
                .map(|f| f.chars().count() + 1)
                .sum::<usize>()
                + 1;
            let value = field
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    ServoError::Parse(ParseError::expected(
                        number,
                        column,
                        &format!("a number for {}", names[index]),
                        &describe_found(field),
                    ))
                })?;
            values.push(value);
        }
        rows.push(values);
    }
    if rows.is_empty() {
        return Err(ServoError::Parse(ParseError::expected(
            header_line + 1,
            1,
            "at least one row after the header",
            "end of file",
        )));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_read_with_positions_in_errors() {
        let rows =
            parse_constant_velocity("# Tab. 5.1\nfeed_m_per_min,current_a\n1,1.25\n-3.2,-1.51\n")
                .unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[1].feed_m_per_min, -3.2);
        let error = parse_constant_velocity("feed_m_per_min,current_a\n1,x\n").unwrap_err();
        assert_eq!(
            error.to_string(),
            "2:3: expected a number for current_a, found \"x\""
        );
        let error = parse_constant_velocity("feed,current\n1,2\n").unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("1:1: expected a header with the columns feed_m_per_min,current_a"),
            "{error}"
        );
        // servo-sim's trace reads as the reversal record.
        let samples = parse_following_error(
            "time_s,command_mm,position_mm,following_error_um,current_a,friction_n\n0.001,90,90,1.5,0.2,3\n",
        )
        .unwrap();
        assert!((samples[0].following_error_m - 1.5e-6).abs() < 1e-18);
    }
}
