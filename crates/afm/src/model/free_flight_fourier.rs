//! The first-harmonic Fourier integrals of the photodiode signal over a free-flight interval,
//! in closed form (MODEL.md section 4 restricted to `F_ts = 0`):
//!
//! ```text
//! J = int_a^b u(t) e^{-i w t} dt,   int u cos(w t) dt = Re J,   int u sin(w t) dt = -Im J,
//! ```
//!
//! with `u = sum_i chi_i q_i` and each `q_i` the exact free flight of Eq. 1 from its state at
//! `a`: the steady part `p_i(t) = alpha_i cos(w t) + beta_i sin(w t)` plus the homogeneous part
//! `y_i(s) = c_1 e^{lambda_1 s} + c_2 e^{lambda_2 s}` (`s = t - a`; `lambda` the roots of
//! `lambda^2 + (w_i/Q_i) lambda + w_i^2 = 0`, complex conjugate when under-damped, real when
//! over-damped), each of which integrates against `e^{-i w t}` in closed form:
//!
//! ```text
//! int_a^b p e^{-iwt} dt = (alpha - i beta)(b - a)/2
//!                         + (alpha + i beta)(e^{-2iwb} - e^{-2iwa}) / (-4 i w),
//! int_0^L c e^{lambda s} e^{-iw(a+s)} ds = c e^{-iwa} (e^{(lambda - iw) L} - 1) / (lambda - iw).
//! ```
//!
//! A sweep's lock-in uses this over whole free-flight intervals (between a release and the
//! next contact), so its cost per cycle does not grow with the number of exact-flow steps.

use nalgebra::Complex;

use crate::model::drive::Drive;
use crate::model::eigenmode::Eigenmode;
use crate::model::free_flight::DrivenOscillator;
use crate::model::TappingModel;

/// Modes closer to critical damping than this (`|1 - 4 Q^2| <` it) have nearly equal roots, for
/// which the two-exponential form loses accuracy: [`FreeFlightFourier::new`] declines them.
pub(crate) const CRITICAL_DAMPING_MARGIN: f64 = 1e-3;

/// The harmonics [`FreeFlightFourier::add_harmonics`] integrates in one pass (more are taken
/// in further passes): the room of its stack tables.
pub(crate) const HARMONICS_PER_PASS: usize = 20;

/// One mode's free flight split for the closed forms: the steady part
/// `p(t) = alpha cos(w t) + beta sin(w t)` and the characteristic roots of the homogeneous
/// part (shared with [`crate::model::free_flight_energy`]).
#[derive(Debug, Clone)]
pub(crate) struct FreeFlightMode {
    /// `chi_i`.
    pub(crate) optical_sensitivity: f64,
    /// `[alpha_i, beta_i]`, nm: the steady free response `alpha cos(w t) + beta sin(w t)`.
    pub(crate) steady: [f64; 2],
    /// The characteristic roots `lambda_1`, `lambda_2`, 1/us.
    pub(crate) roots: [Complex<f64>; 2],
}

impl FreeFlightMode {
    /// The split of `mode` under `drive`; `None` within [`CRITICAL_DAMPING_MARGIN`] of
    /// critical damping (`|1 - 4 Q^2|` below it), where the two exponentials lose accuracy.
    pub(crate) fn new(mode: &Eigenmode, drive: &Drive) -> Option<Self> {
        let w = drive.angular_frequency;
        let q = mode.quality_factor;
        if (1.0 - 4.0 * q * q).abs() < CRITICAL_DAMPING_MARGIN {
            return None;
        }
        let natural = mode.angular_frequency();
        let static_deflection = mode.force_ratio * drive.force_nn / mode.stiffness_n_per_m;
        let steady = DrivenOscillator::new(natural, q, static_deflection, w).steady_coefficients();
        let mu = -natural / (2.0 * q);
        let roots = if q > 0.5 {
            let delta = natural * (1.0 - 1.0 / (4.0 * q * q)).sqrt();
            [Complex::new(mu, delta), Complex::new(mu, -delta)]
        } else {
            // Over-damped: the fast root directly, the slow one from lambda_1 lambda_2 =
            // w_i^2 (no cancellation).
            let fast = mu - (mu * mu - natural * natural).sqrt();
            [
                Complex::new(fast, 0.0),
                Complex::new(natural * natural / fast, 0.0),
            ]
        };
        Some(Self {
            optical_sensitivity: mode.optical_sensitivity,
            steady,
            roots,
        })
    }

    /// The homogeneous part's coefficients `[c_1, c_2]` (nm) of the flight from `q`, `q'`
    /// (nm, nm/us) at time `a` under the drive `w` (rad/us): `y(s) = c_1 e^{lambda_1 s} +
    /// c_2 e^{lambda_2 s}`, `s = t - a`, with `y = q - p`.
    pub(crate) fn homogeneous(&self, w: f64, a: f64, q: f64, velocity: f64) -> [Complex<f64>; 2] {
        self.homogeneous_at_phase(w, (w * a).sin_cos(), q, velocity)
    }

    /// [`FreeFlightMode::homogeneous`] with the drive phase at `a` given, `(sin w a, cos w a)`
    /// (shared by every mode of a flight).
    pub(crate) fn homogeneous_at_phase(
        &self,
        w: f64,
        (sin_a, cos_a): (f64, f64),
        q: f64,
        velocity: f64,
    ) -> [Complex<f64>; 2] {
        let [alpha, beta] = self.steady;
        let p = alpha * cos_a + beta * sin_a;
        let dp = w * (beta * cos_a - alpha * sin_a);
        let y = q - p;
        let dy = velocity - dp;
        let [l1, l2] = self.roots;
        let c1 = (dy - l2 * y) / (l1 - l2);
        [c1, Complex::new(y, 0.0) - c1]
    }
}

/// A bimodal drive's second steady response in free flight (MODEL.md section 14): each mode's
/// `s_i(t) = alpha_bi cos(w_b t) + beta_bi sin(w_b t)`, a further particular solution added to
/// the first drive's free flight (shared with [`crate::model::free_flight_energy`]).
#[derive(Debug, Clone)]
pub(crate) struct SecondFlight {
    /// `w_b`, rad/us.
    pub(crate) angular_frequency: f64,
    /// `F_1b / F_1`.
    pub(crate) relative_force: f64,
    /// Each mode's `[alpha_bi, beta_bi]`, nm.
    pub(crate) steady: Vec<[f64; 2]>,
}

impl SecondFlight {
    /// The second response of `model`'s bimodal drive; `None` for another drive.
    pub(crate) fn of(model: &TappingModel) -> Option<Self> {
        model.second_drive().map(|second| Self {
            angular_frequency: second.angular_frequency,
            relative_force: second.relative_force,
            steady: second
                .oscillators
                .iter()
                .map(|oscillator| oscillator.steady_coefficients())
                .collect(),
        })
    }

    /// Mode `i`'s `[s_i(t), s_i'(t)]` (nm, nm/us).
    pub(crate) fn state(&self, i: usize, t: f64) -> [f64; 2] {
        let [alpha, beta] = self.steady[i];
        let w = self.angular_frequency;
        let (sin, cos) = (w * t).sin_cos();
        [alpha * cos + beta * sin, w * (beta * cos - alpha * sin)]
    }

    /// Mode `i`'s homogeneous coefficients (as [`FreeFlightMode::homogeneous`]) of the flight
    /// from `q`, `q'` at `a` under both drives: the first drive's from `q - s_i(a)`,
    /// `q' - s_i'(a)`.
    pub(crate) fn homogeneous(
        &self,
        mode: &FreeFlightMode,
        i: usize,
        w: f64,
        a: f64,
        q: f64,
        velocity: f64,
    ) -> [Complex<f64>; 2] {
        let [s, ds] = self.state(i, a);
        mode.homogeneous(w, a, q - s, velocity - ds)
    }
}

/// The closed-form Fourier integrals of `u` over free flight of a [`TappingModel`].
#[derive(Debug, Clone)]
pub struct FreeFlightFourier {
    /// Drive angular frequency `w`, rad/us.
    angular_frequency: f64,
    modes: Vec<FreeFlightMode>,
    /// A bimodal drive's second response.
    second: Option<SecondFlight>,
}

impl FreeFlightFourier {
    /// The closed form for `model`'s free flight (under a bimodal drive with the second drive's
    /// steady response added, MODEL.md section 14); `None` when a mode is within 0.1% of
    /// critical damping (`Q_i` near 1/2), where the caller should integrate numerically
    /// instead.
    pub fn new(model: &TappingModel) -> Option<Self> {
        let drive = model.drive();
        let modes = model
            .cantilever()
            .modes
            .iter()
            .map(|mode| FreeFlightMode::new(mode, drive))
            .collect::<Option<Vec<_>>>()?;
        Some(Self {
            angular_frequency: drive.angular_frequency,
            modes,
            second: SecondFlight::of(model),
        })
    }

    /// `[int_a^b u cos(w t) dt, int_a^b u sin(w t) dt]` (nm us) for free flight from state
    /// `x_a = [q_1, q_1', ..., q_N, q_N']` at time `a` (us) to time `b >= a`.
    pub fn integrate(&self, a: f64, x_a: &[f64], b: f64) -> [f64; 2] {
        self.integrate_harmonic(1, a, x_a, b)
    }

    /// `[int_a^b u cos(k w t) dt, int_a^b u sin(k w t) dt]` (nm us) for harmonic `k >= 1`, for
    /// free flight from state `x_a` at time `a` (us) to time `b >= a`: the closed form of the
    /// module docs with `e^{-i k w t}`, where the steady part `p = Re((alpha - i beta)
    /// e^{iwt})` integrates as `(alpha - i beta)/2 int e^{i(1-k)wt} dt + (alpha + i beta)/2 int
    /// e^{-i(1+k)wt} dt` and the homogeneous part as `c e^{-ikwa} (e^{(lambda - ikw) L} - 1) /
    /// (lambda - ikw)`.
    /// Under a bimodal drive, [`FreeFlightFourier::integrate_frequency`] at `k w`.
    pub fn integrate_harmonic(&self, k: usize, a: f64, x_a: &[f64], b: f64) -> [f64; 2] {
        if self.second.is_some() {
            return self.integrate_frequency(k as f64 * self.angular_frequency, a, x_a, b);
        }
        let mut integral = [Complex::new(0.0, 0.0)];
        self.harmonic_integrals(k, a, x_a, b, &mut integral);
        [integral[0].re, -integral[0].im]
    }

    /// Add [`FreeFlightFourier::integrate_harmonic`] for every harmonic `k = 1..=totals.len()`
    /// to `totals[k - 1]` (nm us), for free flight from state `x_a` at time `a` (us) to time
    /// `b >= a`: the same numbers as harmonic by harmonic, with what does not depend on `k`
    /// computed once for all of them ([`FreeFlightFourier::harmonic_integrals`]).
    pub fn add_harmonics(&self, a: f64, x_a: &[f64], b: f64, totals: &mut [[f64; 2]]) {
        if self.second.is_some() {
            for (k, total) in totals.iter_mut().enumerate() {
                let frequency = (k + 1) as f64 * self.angular_frequency;
                let [cosine, sine] = self.integrate_frequency(frequency, a, x_a, b);
                total[0] += cosine;
                total[1] += sine;
            }
            return;
        }
        let mut integrals = [Complex::new(0.0, 0.0); HARMONICS_PER_PASS];
        for (pass, chunk) in totals.chunks_mut(HARMONICS_PER_PASS).enumerate() {
            let integrals = &mut integrals[..chunk.len()];
            self.harmonic_integrals(pass * HARMONICS_PER_PASS + 1, a, x_a, b, integrals);
            for (total, integral) in chunk.iter_mut().zip(integrals.iter()) {
                total[0] += integral.re;
                total[1] += -integral.im;
            }
        }
    }

    /// `J_k = int_a^b u e^{-ikwt} dt` (nm us; `int u cos = Re J_k`, `int u sin = -Im J_k`) of a
    /// single drive for the harmonics `k = first, first + 1, ...` (one per element of
    /// `integrals`, at most [`HARMONICS_PER_PASS`]), for free flight from `x_a` at `a` to `b`:
    /// the closed form of [`FreeFlightFourier::integrate_harmonic`]. What does not depend on
    /// `k` is computed once: each mode's homogeneous coefficients (with the drive phase at `a`
    /// once for all modes), each root's decay `exp(Re(lambda) L)` (the modulus of
    /// `e^{(lambda - ikw) L}`, num-complex's `exp` being `from_polar(exp(re), im)`), and the
    /// steady part's integrals of `e^{-imwt}`, `m = k - 1` (co-rotating) and `m = k + 1`
    /// (counter-rotating), each shared by two harmonics. Every number is the same operation on
    /// the same operands as harmonic by harmonic, so the integrals are the same bits.
    fn harmonic_integrals(
        &self,
        first: usize,
        a: f64,
        x_a: &[f64],
        b: f64,
        integrals: &mut [Complex<f64>],
    ) {
        let count = integrals.len();
        debug_assert!(first >= 1 && count <= HARMONICS_PER_PASS);
        let w = self.angular_frequency;
        let length = b - a;
        // `int_a^b e^{-imwt} dt` for m = first - 1 ..= first + count: `(1 - k) w` and
        // `-(1 + k) w` are the double `-m w` (exact small integers; at m = 0 a zero).
        let mut steady_integrals = [Complex::new(0.0, 0.0); HARMONICS_PER_PASS + 2];
        for (j, integral) in steady_integrals[..count + 2].iter_mut().enumerate() {
            let m = first - 1 + j;
            *integral = exponential_integral(-(m as f64) * w, a, length);
        }
        // e^{-ikwa}, by which the homogeneous part is rotated (at k = 1 the phase the modes'
        // coefficients need, `k w` being `w` there).
        let phase_a = (w * a).sin_cos();
        let mut rotations = [Complex::new(0.0, 0.0); HARMONICS_PER_PASS];
        for (j, rotation) in rotations[..count].iter_mut().enumerate() {
            let k = first + j;
            let (sin_ka, cos_ka) = if k == 1 {
                phase_a
            } else {
                (k as f64 * w * a).sin_cos()
            };
            *rotation = Complex::new(cos_ka, -sin_ka);
        }
        integrals.fill(Complex::new(0.0, 0.0));
        for (i, mode) in self.modes.iter().enumerate() {
            let coefficients = mode.homogeneous_at_phase(w, phase_a, x_a[2 * i], x_a[2 * i + 1]);
            // `(lambda + 0) L`: the real part of `(lambda - ikw) L`, whatever `k`.
            let decays = mode.roots.map(|l| {
                let exponent = (l.re + 0.0) * length;
                exponent.is_finite().then(|| exponent.exp())
            });
            let [alpha, beta] = mode.steady;
            for (j, integral) in integrals.iter_mut().enumerate() {
                let kw = (first + j) as f64 * w;
                let minus_ikw = Complex::new(0.0, -kw);
                // The steady part.
                let steady = Complex::new(alpha, -beta) * 0.5 * steady_integrals[j]
                    + Complex::new(alpha, beta) * 0.5 * steady_integrals[j + 2];
                let mut homogeneous = Complex::new(0.0, 0.0);
                for ((&c, l), decay) in coefficients.iter().zip(mode.roots).zip(decays) {
                    let z = l + minus_ikw;
                    // `(z L).exp()` (num-complex: `from_polar(exp(re), im)`, its corner cases
                    // of an infinite or NaN real part left to it).
                    let growth = match decay {
                        Some(modulus) => {
                            let (sin, cos) = (z.im * length).sin_cos();
                            Complex::new(modulus * cos, modulus * sin)
                        }
                        None => (z * length).exp(),
                    };
                    homogeneous += c * (growth - 1.0) / z;
                }
                *integral += (steady + rotations[j] * homogeneous) * mode.optical_sensitivity;
            }
        }
    }
}

impl FreeFlightFourier {
    /// A bimodal drive's second lock-in integrals `[int_a^b u cos(w_b t) dt, int_a^b u sin(w_b
    /// t) dt]` (nm us) over free flight from `x_a` at `a` to `b` (MODEL.md section 14); `None`
    /// for another drive.
    pub fn integrate_second(&self, a: f64, x_a: &[f64], b: f64) -> Option<[f64; 2]> {
        let second = self.second.as_ref()?;
        Some(self.integrate_frequency(second.angular_frequency, a, x_a, b))
    }

    /// `[int_a^b u cos(nu t) dt, int_a^b u sin(nu t) dt]` (nm us) under a bimodal drive: `q_i`
    /// is the first drive's steady part `p_i`, the second's `s_i` and the homogeneous part
    /// `y_i` (from `q_i - p_i - s_i` at `a`), each integrated against `e^{-i nu t}` as in
    /// the module docs (`s_i` like `p_i` at `w_b`).
    fn integrate_frequency(&self, nu: f64, a: f64, x_a: &[f64], b: f64) -> [f64; 2] {
        let w = self.angular_frequency;
        let length = b - a;
        let (sin_a, cos_a) = (nu * a).sin_cos();
        let rotation_a = Complex::new(cos_a, -sin_a);
        let co_rotating = exponential_integral(w - nu, a, length);
        let counter_rotating = exponential_integral(-w - nu, a, length);
        let (second_co, second_counter) = self.second.as_ref().map_or(
            (Complex::new(0.0, 0.0), Complex::new(0.0, 0.0)),
            |second| {
                let wb = second.angular_frequency;
                (
                    exponential_integral(wb - nu, a, length),
                    exponential_integral(-wb - nu, a, length),
                )
            },
        );
        let minus_inu = Complex::new(0.0, -nu);
        let mut total = Complex::new(0.0, 0.0);
        for (i, mode) in self.modes.iter().enumerate() {
            let [alpha, beta] = mode.steady;
            let mut steady = Complex::new(alpha, -beta) * 0.5 * co_rotating
                + Complex::new(alpha, beta) * 0.5 * counter_rotating;
            let (q, velocity) = (x_a[2 * i], x_a[2 * i + 1]);
            let coefficients = match &self.second {
                Some(second) => {
                    let [alpha_b, beta_b] = second.steady[i];
                    steady += Complex::new(alpha_b, -beta_b) * 0.5 * second_co
                        + Complex::new(alpha_b, beta_b) * 0.5 * second_counter;
                    second.homogeneous(mode, i, w, a, q, velocity)
                }
                None => mode.homogeneous(w, a, q, velocity),
            };
            let mut homogeneous = Complex::new(0.0, 0.0);
            for (c, l) in coefficients.into_iter().zip(mode.roots) {
                let z = l + minus_inu;
                homogeneous += c * ((z * length).exp() - 1.0) / z;
            }
            total += (steady + rotation_a * homogeneous) * mode.optical_sensitivity;
        }
        [total.re, -total.im]
    }
}

/// `int_a^{a+L} e^{i nu t} dt = e^{i nu a} (e^{i nu L} - 1) / (i nu)` (`L` for `nu = 0`), with
/// `e^{i nu L} - 1 = 2 i sin(nu L / 2) e^{i nu L / 2}`, free of cancellation for short `L`.
fn exponential_integral(nu: f64, a: f64, length: f64) -> Complex<f64> {
    if nu == 0.0 {
        return Complex::new(length, 0.0);
    }
    let half = 0.5 * nu * length;
    let (sin_start, cos_start) = (nu * a + half).sin_cos();
    // e^{i nu (a + L/2)} 2 sin(nu L / 2) / nu.
    Complex::new(cos_start, sin_start) * (2.0 * half.sin() / nu)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::builtin_case;
    use hybrid::HybridSystem;

    /// The harmonic-by-harmonic closed form as first written (module docs): for harmonic `k`,
    /// the modes' homogeneous coefficients, `e^{-ikwa}`, the steady part's two exponential
    /// integrals and num-complex's `exp` of `(lambda - ikw) L`, all computed anew.
    fn harmonic_by_harmonic(
        fourier: &FreeFlightFourier,
        k: usize,
        a: f64,
        x_a: &[f64],
        b: f64,
    ) -> [f64; 2] {
        let w = fourier.angular_frequency;
        let kw = k as f64 * w;
        let length = b - a;
        let (sin_ka, cos_ka) = (kw * a).sin_cos();
        let rotation_a = Complex::new(cos_ka, -sin_ka);
        let co_rotating = exponential_integral((1.0 - k as f64) * w, a, length);
        let counter_rotating = exponential_integral(-(1.0 + k as f64) * w, a, length);
        let minus_ikw = Complex::new(0.0, -kw);
        let mut total = Complex::new(0.0, 0.0);
        for (i, mode) in fourier.modes.iter().enumerate() {
            let coefficients = mode.homogeneous(w, a, x_a[2 * i], x_a[2 * i + 1]);
            let [alpha, beta] = mode.steady;
            let steady = Complex::new(alpha, -beta) * 0.5 * co_rotating
                + Complex::new(alpha, beta) * 0.5 * counter_rotating;
            let mut homogeneous = Complex::new(0.0, 0.0);
            for (&c, l) in coefficients.iter().zip(mode.roots) {
                let z = l + minus_ikw;
                homogeneous += c * ((z * length).exp() - 1.0) / z;
            }
            total += (steady + rotation_a * homogeneous) * mode.optical_sensitivity;
        }
        [total.re, -total.im]
    }

    /// [`FreeFlightFourier::add_harmonics`], which computes what does not depend on `k` once,
    /// gives the harmonic-by-harmonic closed form bit for bit: 1 to 25 harmonics (past one
    /// pass of [`HARMONICS_PER_PASS`]), over intervals from a thousandth of a period to three
    /// periods, on the Biolever and the MAClever in water and a silicon lever in air, added to
    /// totals that start non-zero. (The closed form itself is checked against quadrature in
    /// `tests/sweep.rs` and `free_flight_energy`'s tests.)
    #[test]
    fn all_harmonics_at_once_are_the_harmonic_by_harmonic_bits() {
        for case in [
            "biolever-mica",
            "maclever-mica",
            "rectangular-air-mica-humid",
        ] {
            let model = TappingModel::from_case(&builtin_case(case).expect("case")).expect("model");
            let fourier = FreeFlightFourier::new(&model).expect("not critically damped");
            let period = model.period_us();
            let x_a: Vec<f64> = (0..model.dim()).map(|i| 1.7 - 0.9 * i as f64).collect();
            let x_a = &x_a[..2 * fourier.modes.len()];
            for (a, length) in [
                (0.3, 1e-3 * period),
                (12.5, 0.41 * period),
                (-3.0, 3.0 * period),
            ] {
                for count in [1, 4, 20, 25] {
                    let start = [0.25, -1.5];
                    let mut totals = vec![start; count];
                    fourier.add_harmonics(a, x_a, a + length, &mut totals);
                    for (k, total) in (1..).zip(&totals) {
                        let [c, s] = harmonic_by_harmonic(&fourier, k, a, x_a, a + length);
                        let expected = [start[0] + c, start[1] + s];
                        assert_eq!(
                            total.map(f64::to_bits),
                            expected.map(f64::to_bits),
                            "{case}, harmonic {k} of {count}, a = {a}, L = {length}"
                        );
                        let single = fourier.integrate_harmonic(k, a, x_a, a + length);
                        assert_eq!(single.map(f64::to_bits), [c, s].map(f64::to_bits));
                    }
                }
            }
        }
    }
}
