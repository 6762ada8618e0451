// Each test file uses a subset of this shared reference.
#![allow(dead_code)]

//! Independent references for the hysteretic laws' brute forces (MODEL.md section 9, "JKR" and
//! "Capillary meniscus"): the JKR law written out with its contact radius by bisection, and a
//! fixed-step RK4 on the cantilever's free field plus a tip-sample force given by the test.
//! They share with drumroll only the free field (its mode 0, no contact force).

use std::f64::consts::PI;

use afm::TappingModel;
use hybrid::HybridSystem;

/// The JKR law written out independently: `E*` from the model's Hertz coefficient
/// `c = (4/3) E* sqrt(R)`, `R = 30 nm` (the Biolever's tip), `W` in nN/nm.
pub struct Jkr {
    /// `E*`, GPa.
    pub e: f64,
    /// `R`, nm.
    pub r: f64,
    /// `W`, nN/nm.
    pub w: f64,
}

impl Jkr {
    /// The law of `model`'s tip and modulus with the work of adhesion `W` (mJ/m^2).
    pub fn of(model: &TappingModel, work_of_adhesion_mj_per_m2: f64) -> Self {
        let r: f64 = 30.0;
        Self {
            e: model.hertz().coefficient / (4.0 / 3.0 * r.sqrt()),
            r,
            w: work_of_adhesion_mj_per_m2 * 1e-3,
        }
    }

    /// `delta(a) = a^2 / R - sqrt(2 pi W a / E*)`, nm.
    pub fn indentation(&self, a: f64) -> f64 {
        a * a / self.r - (2.0 * PI * self.w * a / self.e).sqrt()
    }

    /// The radius where `d delta / da = 0`: `a_c = (pi W R^2 / (8 E*))^{1/3}`.
    pub fn critical_radius(&self) -> f64 {
        (PI * self.w * self.r * self.r / (8.0 * self.e)).cbrt()
    }

    /// The pull-off gap `d_po = -delta(a_c)`, nm.
    pub fn pull_off_gap(&self) -> f64 {
        -self.indentation(self.critical_radius())
    }

    /// `F(a(delta))` (nN) with `a` by bisection on `[a_c, 1e3 nm]` to 1e-15 relative.
    pub fn force(&self, gap: f64) -> f64 {
        let delta = -gap;
        let (mut lo, mut hi) = (self.critical_radius(), 1e3);
        if delta <= self.indentation(lo) {
            hi = lo;
        }
        while hi - lo > 1e-15 * hi.max(1.0) {
            let mid = 0.5 * (lo + hi);
            if self.indentation(mid) < delta {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let a = 0.5 * (lo + hi);
        4.0 * self.e * a * a * a / (3.0 * self.r) - (8.0 * PI * self.w * self.e * a * a * a).sqrt()
    }
}

/// The brute force's field: the cantilever's free field (drumroll's mode 0, no contact force)
/// plus `(w_i^2 / k_i) F(d)` on every acceleration, `F` the test's force at the gap `d`.
pub fn field<F: Fn(f64) -> f64>(
    model: &TappingModel,
    force: &F,
    t: f64,
    x: &[f64],
    out: &mut [f64],
) {
    model.vector_field(0, t, x, out);
    let force = force(model.gap(t, x));
    for (i, mode) in model.cantilever().modes.iter().enumerate() {
        let omega = mode.angular_frequency();
        out[2 * i + 1] += omega * omega / mode.stiffness_n_per_m * force;
    }
}

/// One classical RK4 step of length `h` (us) from `x` at `t` on [`field`] with the force
/// `force(d)` (nN).
pub fn rk4<F: Fn(f64) -> f64>(
    model: &TappingModel,
    force: F,
    t: f64,
    x: &[f64],
    h: f64,
) -> Vec<f64> {
    let n = x.len();
    let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    field(model, &force, t, x, &mut k1);
    let y: Vec<f64> = (0..n).map(|i| x[i] + 0.5 * h * k1[i]).collect();
    field(model, &force, t + 0.5 * h, &y, &mut k2);
    let y: Vec<f64> = (0..n).map(|i| x[i] + 0.5 * h * k2[i]).collect();
    field(model, &force, t + 0.5 * h, &y, &mut k3);
    let y: Vec<f64> = (0..n).map(|i| x[i] + h * k3[i]).collect();
    field(model, &force, t + h, &y, &mut k4);
    (0..n)
        .map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
        .collect()
}

/// JKR's force at the gap while `attached`, none otherwise (the brute force's own attachment
/// flag decides), nN.
pub fn attached_force(jkr: &Jkr, attached: bool) -> impl Fn(f64) -> f64 + '_ {
    move |gap| if attached { jkr.force(gap) } else { 0.0 }
}
