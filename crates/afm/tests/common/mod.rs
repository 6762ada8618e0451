//! Independent reference computations shared by the tests: a classical RK4 integrator and
//! test cantilevers written out by hand.
#![allow(dead_code)]

use afm::{Cantilever, Eigenmode, Sample};

/// Classical fourth-order Runge-Kutta with `steps` equal steps from `t0` over `duration`.
pub fn rk4<F: Fn(f64, &[f64], &mut [f64])>(
    field: F,
    t0: f64,
    x0: &[f64],
    duration: f64,
    steps: usize,
) -> Vec<f64> {
    let n = x0.len();
    let h = duration / steps as f64;
    let mut x = x0.to_vec();
    let (mut k1, mut k2, mut k3, mut k4, mut tmp) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    );
    for step in 0..steps {
        let t = t0 + step as f64 * h;
        field(t, &x, &mut k1);
        for i in 0..n {
            tmp[i] = x[i] + 0.5 * h * k1[i];
        }
        field(t + 0.5 * h, &tmp, &mut k2);
        for i in 0..n {
            tmp[i] = x[i] + 0.5 * h * k2[i];
        }
        field(t + 0.5 * h, &tmp, &mut k3);
        for i in 0..n {
            tmp[i] = x[i] + h * k3[i];
        }
        field(t + h, &tmp, &mut k4);
        for i in 0..n {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    x
}

/// A cantilever written out by hand with the given modes `(k, f, Q, chi, r)`.
pub fn cantilever(modes: &[(f64, f64, f64, f64, f64)]) -> Cantilever {
    Cantilever {
        name: "test".to_string(),
        description: String::new(),
        tip_radius_nm: 30.0,
        tip_mass_ratio: 0.0,
        tip_youngs_modulus_gpa: 130.0,
        tip_poisson_ratio: 0.3,
        modes: modes
            .iter()
            .map(|&(stiffness, frequency, quality, chi, ratio)| Eigenmode {
                stiffness_n_per_m: stiffness,
                frequency_khz: frequency,
                quality_factor: quality,
                optical_sensitivity: chi,
                force_ratio: ratio,
            })
            .collect(),
    }
}

/// The paper's Biolever (MODEL.md section 6), typed in independently of the fixture file.
pub fn biolever() -> Cantilever {
    cantilever(&[(0.036, 9.3, 1.2, 1.0, 1.0), (1.4, 72.0, 2.0, 3.47, -0.554)])
}

/// Mica (MODEL.md section 6).
pub fn mica() -> Sample {
    Sample {
        name: "mica".to_string(),
        description: String::new(),
        youngs_modulus_gpa: 60.0,
        poisson_ratio: 0.3,
        contact: None,
        electrostatic: None,
        hydration: None,
    }
}

/// First harmonic `[a, b]` of a periodic signal by the rectangle rule over `m` points of one
/// period (exact for trigonometric polynomials of degree below `m - 1`).
pub fn first_harmonic<F: Fn(f64) -> f64>(signal: F, period: f64, m: usize) -> [f64; 2] {
    let omega = 2.0 * std::f64::consts::PI / period;
    let (mut a, mut b) = (0.0, 0.0);
    for j in 0..m {
        let t = period * j as f64 / m as f64;
        let u = signal(t);
        a += u * (omega * t).cos();
        b += u * (omega * t).sin();
    }
    [2.0 * a / m as f64, 2.0 * b / m as f64]
}
