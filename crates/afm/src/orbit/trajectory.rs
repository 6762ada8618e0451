//! A sampled trajectory of the cantilever for figures and for reading the response between
//! impacts: the state on a uniform time grid, taken from the solver's dense output (or exact
//! flow) inside each step, so that sampling never changes the integration.

use hybrid::{flow_map_observed, Sensitivity, Settings, Solver, StepOutcome};
use serde::Serialize;

use crate::error::AfmError;
use crate::model::TappingModel;

/// The cantilever at one instant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrajectorySample {
    /// Time since the start of the trajectory, us.
    pub t_us: f64,
    /// The modal coordinates `q_i`, nm.
    pub q_nm: Vec<f64>,
    /// The photodiode signal `u = sum_i chi_i q_i`, nm (MODEL.md section 1).
    pub u_nm: f64,
    /// The gap `d = Z + sum_i q_i`, nm.
    pub gap_nm: f64,
    /// The Hertz tip-sample force `F_ts(d)`, nN.
    pub force_nn: f64,
}

/// The trajectory of `model` from state `x0` at `t = 0` over `periods` drive periods, sampled at
/// `samples_per_period` uniform instants per period (both ends included).
pub fn sample_trajectory(
    model: &TappingModel,
    x0: &[f64],
    periods: usize,
    samples_per_period: usize,
    settings: &Settings,
) -> Result<Vec<TrajectorySample>, AfmError> {
    if periods == 0
        || samples_per_period == 0
        || periods.saturating_mul(samples_per_period) > 10_000_000
    {
        return Err(AfmError::InvalidField {
            file: String::from("trajectory sampling"),
            field: String::from("periods x samples_per_period"),
            value: format!("{periods} x {samples_per_period}"),
            allowed: String::from("both >= 1, product <= 1e7"),
        });
    }
    let duration = periods as f64 * model.period_us();
    let count = periods * samples_per_period + 1;
    let dt = duration / (count - 1) as f64;
    let mut samples = Vec::with_capacity(count);
    let mut x = vec![0.0; x0.len()];
    let mut next = 0usize;
    let record = |t: f64, x: &[f64], samples: &mut Vec<TrajectorySample>| {
        let modes = x.len() / 2;
        samples.push(TrajectorySample {
            t_us: t,
            q_nm: (0..modes).map(|i| x[2 * i]).collect(),
            u_nm: model.photodiode(x),
            gap_nm: model.gap(t, x),
            force_nn: model.tip_sample_force(t, x),
        });
    };
    record(0.0, x0, &mut samples);
    next += 1;
    flow_map_observed(
        model,
        0.0,
        x0,
        duration,
        Sensitivity::None,
        settings,
        &mut |solver: &Solver<TappingModel>, _: &StepOutcome| {
            let (_, end) = solver.last_step();
            // The last grid time equals the end up to rounding: allow for it.
            while next < count && next as f64 * dt <= end + 1e-9 * dt {
                let t = (next as f64 * dt).min(end);
                solver.interpolate(t, &mut x);
                record(t, &x, &mut samples);
                next += 1;
            }
        },
    )?;
    Ok(samples)
}
