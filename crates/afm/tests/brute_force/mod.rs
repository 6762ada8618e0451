// Each test file uses a subset of this shared reference.
#![allow(dead_code)]

//! A brute-force reference for the laws with a state or a force outside contact (MODEL.md
//! section 9): fixed-step RK4 on the model's vector field (its sample state included), each
//! crossing of a switching surface located by bisection of the step and the step split there,
//! a step 64 times finer in contact, and the integrals by the trapezoidal rule on the uniform
//! grid. It shares with drumroll only the field `f_m(t, x)` and the switching functions, not
//! the solver, its event location, Newton or continuation.

use afm::{Separation, TappingModel};
use hybrid::{HybridSystem, Mode};

/// Grid steps per drive period outside contact.
pub const STEPS_PER_PERIOD: usize = 40_000;

fn rk4_step(model: &TappingModel, mode: Mode, t: f64, x: &[f64], h: f64, out: &mut [f64]) {
    let n = x.len();
    let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut y = vec![0.0; n];
    model.vector_field(mode, t, x, &mut k1);
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k1[i];
    }
    model.vector_field(mode, t + 0.5 * h, &y, &mut k2);
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k2[i];
    }
    model.vector_field(mode, t + 0.5 * h, &y, &mut k3);
    for i in 0..n {
        y[i] = x[i] + h * k3[i];
    }
    model.vector_field(mode, t + h, &y, &mut k4);
    for i in 0..n {
        out[i] = x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// Advance `(t, x, mode)` by `h` in RK4 substeps (64 of them in contact), splitting a substep
/// at every switching-surface crossing found by bisection on its length (to 1e-15 periods).
fn advance(model: &TappingModel, mode: &mut Mode, t: &mut f64, x: &mut [f64], h: f64, period: f64) {
    let end = *t + h;
    let mut next = vec![0.0; x.len()];
    while *t < end - 1e-12 * period {
        let sub = if *mode & 1 != 0 { h / 64.0 } else { h };
        let step = sub.min(end - *t);
        rk4_step(model, *mode, *t, x, step, &mut next);
        if model.mode_of(*t + step, &next) == *mode {
            x.copy_from_slice(&next);
            *t += step;
            continue;
        }
        let (mut lo, mut hi) = (0.0, step);
        while hi - lo > 1e-15 * period {
            let mid = 0.5 * (lo + hi);
            rk4_step(model, *mode, *t, x, mid, &mut next);
            if model.mode_of(*t + mid, &next) == *mode {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        rk4_step(model, *mode, *t, x, hi, &mut next);
        x.copy_from_slice(&next);
        *t += hi;
        *mode = model.mode_of(*t, x);
    }
    *t = end;
}

/// The last period of a brute-force run.
pub struct LastPeriod {
    /// A/A0 of u.
    pub amplitude_ratio: f64,
    /// Phase of u, degrees.
    pub phase_deg: f64,
    /// The local minima of `h_0` (parabola through the three grid points around each).
    pub minima: Vec<f64>,
    /// The grid states over the period (`STEPS_PER_PERIOD + 1` of them).
    pub states: Vec<Vec<f64>>,
    /// The grid step, us.
    pub step: f64,
}

/// Integrate `periods` drive periods from `x0` at t = 0 and return the last one.
pub fn brute_force(model: &TappingModel, x0: &[f64], periods: usize) -> LastPeriod {
    let period = model.period_us();
    let w = model.drive_angular_frequency();
    let h = period / STEPS_PER_PERIOD as f64;
    let mut x = x0.to_vec();
    let mut t = 0.0;
    let mut mode = model.mode_of(0.0, &x);
    let (mut a, mut b) = (0.0, 0.0);
    let mut heights = Vec::with_capacity(STEPS_PER_PERIOD + 1);
    let mut states = Vec::with_capacity(STEPS_PER_PERIOD + 1);
    for p in 0..periods {
        let last = p + 1 == periods;
        for i in 0..STEPS_PER_PERIOD {
            if last {
                let u = model.photodiode(&x);
                let tk = i as f64 * h;
                a += u * (w * tk).cos();
                b += u * (w * tk).sin();
                heights.push(model.switching(0, t, &x));
                states.push(x.clone());
            }
            advance(model, &mut mode, &mut t, &mut x, h, period);
        }
    }
    heights.push(model.switching(0, t, &x));
    states.push(x.clone());
    let scale = 2.0 / STEPS_PER_PERIOD as f64;
    let minima = heights
        .windows(3)
        .filter(|w| w[1] < w[0] && w[1] <= w[2])
        .map(|w| w[1] - (w[2] - w[0]).powi(2) / (8.0 * (w[0] - 2.0 * w[1] + w[2])))
        .collect();
    LastPeriod {
        amplitude_ratio: scale * a.hypot(b) / model.free_amplitude_nm(),
        phase_deg: b.atan2(a).to_degrees(),
        minima,
        states,
        step: h,
    }
}

/// The separation (nm) at which the brute-force orbit's gap minimum nearest the surface
/// crosses zero, by bisection in Z within `z_nm +- 2e-4` to 2e-8 nm, each orbit 6 periods
/// from `state` (the orbit at `z_nm`): its largest Floquet multiplier is about 0.1 on the
/// cases tested, so the transient from a `Z` change of at most 2e-4 nm decays below 1e-9 nm.
pub fn grazing_by_bisection(model: &TappingModel, state: &[f64], z_nm: f64) -> f64 {
    grazing_by_bisection_within(model, state, z_nm, 2e-4, 6)
}

/// The separation (nm) at which the brute-force orbit's gap minimum nearest the surface
/// crosses zero, by bisection in Z within `z_nm +- half_width_nm` to 2e-8 nm, each orbit
/// `periods` periods from `state` (the orbit at `z_nm`); the ends must bracket the grazing.
pub fn grazing_by_bisection_within(
    model: &TappingModel,
    state: &[f64],
    z_nm: f64,
    half_width_nm: f64,
    periods: usize,
) -> f64 {
    let nearest = |z: f64| {
        let mut at = model.clone();
        at.set_separation(Separation::Constant(z)).unwrap();
        brute_force(&at, state, periods)
            .minima
            .into_iter()
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap()
    };
    let (mut below, mut above) = (z_nm - half_width_nm, z_nm + half_width_nm);
    assert!(nearest(below) < 0.0 && nearest(above) > 0.0);
    while above - below > 2e-8 {
        let mid = 0.5 * (below + above);
        if nearest(mid) < 0.0 {
            below = mid;
        } else {
            above = mid;
        }
    }
    0.5 * (below + above)
}
