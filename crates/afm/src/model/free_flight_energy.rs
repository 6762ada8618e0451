//! The energy integrals of each mode over a free-flight interval, in closed form (MODEL.md
//! section 10 restricted to `F_ts = 0`): the drive's work and the velocity's square,
//!
//! ```text
//! W_i = F_i int_a^b cos(w t) q_i' dt,   S_i = int_a^b q_i'^2 dt,
//! ```
//!
//! from which the observables take the drive work and the damping loss
//! `(k_i / (w_i Q_i)) S_i` per mode. Over free flight `q_i' = p_i' + y_i'` is a sum of four
//! complex exponentials `sum_j g_j e^{z_j s}` (`s = t - a`): the steady part
//! `p_i' = Re(w (beta + i alpha) e^{i w t})` (two terms, `z = +-i w`) and the homogeneous part
//! `y_i' = c_1 lambda_1 e^{lambda_1 s} + c_2 lambda_2 e^{lambda_2 s}`
//! ([`crate::model::free_flight_fourier`]'s split). Then
//!
//! ```text
//! S_i = Re sum_{j,l} g_j g_l E(z_j + z_l),
//! W_i = F_i Re sum_j g_j [e^{iwa} E(z_j + i w) + e^{-iwa} E(z_j - i w)] / 2,
//! E(z) = int_0^L e^{z s} ds = (e^{z L} - 1) / z,
//! ```
//!
//! with `E` by its series where `|z L| < 1` (no cancellation for short intervals).

use nalgebra::Complex;

use crate::model::free_flight_fourier::{FreeFlightMode, SecondFlight};
use crate::model::TappingModel;

/// One mode's constants for the closed form.
#[derive(Debug, Clone)]
struct ModeEnergy {
    /// The drive amplitude `F_i = r_i F_1`, nN.
    drive_force_nn: f64,
    /// The steady part and the roots.
    flight: FreeFlightMode,
}

/// The closed-form energy integrals of every mode over free flight of a [`TappingModel`].
#[derive(Debug, Clone)]
pub struct FreeFlightEnergy {
    /// Drive angular frequency `w`, rad/us.
    angular_frequency: f64,
    modes: Vec<ModeEnergy>,
    /// A bimodal drive's second response.
    second: Option<SecondFlight>,
}

/// One mode's energy integrals over an interval.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ModeIntegrals {
    /// The drive's work `F_i int cos(w t) q_i' dt`, nN nm.
    pub drive_work: f64,
    /// `int q_i'^2 dt`, nm^2/us.
    pub velocity_square: f64,
}

impl FreeFlightEnergy {
    /// The closed form for `model`'s free flight (under a bimodal drive with the second drive's
    /// steady response and work, MODEL.md section 14); `None` when a mode is within 0.1% of
    /// critical damping (as [`crate::model::free_flight_fourier::FreeFlightFourier::new`]),
    /// where the caller integrates numerically instead.
    pub fn new(model: &TappingModel) -> Option<Self> {
        let drive = model.drive();
        let modes = model
            .cantilever()
            .modes
            .iter()
            .map(|mode| {
                FreeFlightMode::new(mode, drive).map(|flight| ModeEnergy {
                    drive_force_nn: mode.force_ratio * drive.force_nn,
                    flight,
                })
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Self {
            angular_frequency: drive.angular_frequency,
            modes,
            second: SecondFlight::of(model),
        })
    }

    /// Add each mode's integrals over free flight from state `x_a = [q_1, q_1', ..., q_N,
    /// q_N']` at time `a` (us) to time `b >= a` to `totals` (one entry per mode).
    pub fn accumulate(&self, a: f64, x_a: &[f64], b: f64, totals: &mut [ModeIntegrals]) {
        if let Some(second) = &self.second {
            self.accumulate_bimodal(second, a, x_a, b, totals);
            return;
        }
        let w = self.angular_frequency;
        let (sin_a, cos_a) = (w * a).sin_cos();
        let rotation = Complex::new(cos_a, sin_a);
        let iw = Complex::new(0.0, w);
        for ((i, mode), total) in self.modes.iter().enumerate().zip(totals.iter_mut()) {
            let [alpha, beta] = mode.flight.steady;
            // p' = (X e^{iws} + conj(X) e^{-iws}) / 2 with X = w (beta + i alpha) e^{iwa}.
            let x = Complex::new(w * beta, w * alpha) * rotation;
            let [c1, c2] = mode.flight.homogeneous(w, a, x_a[2 * i], x_a[2 * i + 1]);
            let [l1, l2] = mode.flight.roots;
            let terms = [
                (x * 0.5, iw),
                (x.conj() * 0.5, -iw),
                (c1 * l1, l1),
                (c2 * l2, l2),
            ];
            total.add_flight(mode.drive_force_nn, &terms, &[(1.0, rotation, iw)], b - a);
        }
    }
}

impl FreeFlightEnergy {
    /// [`FreeFlightEnergy::accumulate`] under a bimodal drive: `q_i'` has the second steady
    /// part's two exponentials `s_i' = (X_b e^{i w_b s} + conj(X_b) e^{-i w_b s}) / 2`,
    /// `X_b = w_b (beta_bi + i alpha_bi) e^{i w_b a}`, besides the first's and the homogeneous
    /// part's (from `q_i - p_i - s_i` at `a`), and the drive's work is
    /// `F_i int (cos(w t) + (F_1b / F_1) cos(w_b t)) q_i' dt` (MODEL.md section 14).
    fn accumulate_bimodal(
        &self,
        second: &SecondFlight,
        a: f64,
        x_a: &[f64],
        b: f64,
        totals: &mut [ModeIntegrals],
    ) {
        let w = self.angular_frequency;
        let wb = second.angular_frequency;
        let (sin_a, cos_a) = (w * a).sin_cos();
        let rotation = Complex::new(cos_a, sin_a);
        let (sin_b, cos_b) = (wb * a).sin_cos();
        let rotation_b = Complex::new(cos_b, sin_b);
        let (iw, iwb) = (Complex::new(0.0, w), Complex::new(0.0, wb));
        let drives = [
            (1.0, rotation, iw),
            (second.relative_force, rotation_b, iwb),
        ];
        for ((i, mode), total) in self.modes.iter().enumerate().zip(totals.iter_mut()) {
            let [alpha, beta] = mode.flight.steady;
            let x = Complex::new(w * beta, w * alpha) * rotation;
            let [alpha_b, beta_b] = second.steady[i];
            let x_b = Complex::new(wb * beta_b, wb * alpha_b) * rotation_b;
            let [c1, c2] = second.homogeneous(&mode.flight, i, w, a, x_a[2 * i], x_a[2 * i + 1]);
            let [l1, l2] = mode.flight.roots;
            let terms = [
                (x * 0.5, iw),
                (x.conj() * 0.5, -iw),
                (x_b * 0.5, iwb),
                (x_b.conj() * 0.5, -iwb),
                (c1 * l1, l1),
                (c2 * l2, l2),
            ];
            total.add_flight(mode.drive_force_nn, &terms, &drives, b - a);
        }
    }
}

impl ModeIntegrals {
    /// Add the integrals over a free flight of length `L` (us) whose velocity is
    /// `q' = sum_j g_j e^{z_j s}` (`terms` the pairs `(g_j, z_j)`): `S += Re sum_{j,l} g_j g_l
    /// E(z_j + z_l)`, the diagonal once and each pair twice, and for each drive `(r, e^{i nu
    /// a}, i nu)` of `drives` (relative force `r`, the first's 1) `W += F_i Re sum_j r g_j
    /// [e^{i nu a} E(z_j + i nu) + e^{-i nu a} E(z_j - i nu)] / 2`, `F_i` = `drive_force_nn`.
    fn add_flight(
        &mut self,
        drive_force_nn: f64,
        terms: &[(Complex<f64>, Complex<f64>)],
        drives: &[(f64, Complex<f64>, Complex<f64>)],
        length: f64,
    ) {
        let mut integrals = ExponentialIntegrals::new(length, terms.len(), drives.len());
        let mut square = Complex::new(0.0, 0.0);
        let mut drive = Complex::new(0.0, 0.0);
        for (j, &(g, z)) in terms.iter().enumerate() {
            square += g * g * integrals.at(z + z);
            for &(h, y) in &terms[j + 1..] {
                square += 2.0 * g * h * integrals.at(z + y);
            }
            for &(relative_force, rotation, i_nu) in drives {
                drive += relative_force
                    * g
                    * (rotation * integrals.at(z + i_nu)
                        + rotation.conj() * integrals.at(z - i_nu));
            }
        }
        self.velocity_square += square.re;
        self.drive_work += drive_force_nn * 0.5 * drive.re;
    }
}

/// The values of [`exponential_integral`] over one interval of length `L`, each computed once
/// per argument: the drive's exponents `z_j +- i nu` are mostly the velocity's own pair sums
/// `z_j + z_l` (`+-i w` is a velocity exponent), so an interval needs about half the
/// evaluations. Arguments are matched by their bits, so every value is the one
/// [`exponential_integral`] gives.
struct ExponentialIntegrals {
    length: f64,
    /// `(z, E(z))` for every argument so far.
    known: Vec<(Complex<f64>, Complex<f64>)>,
}

impl ExponentialIntegrals {
    /// No values yet, for an interval of `length` us with `terms` exponentials and `drives`
    /// drives (the table's capacity: every pair sum and every drive term).
    fn new(length: f64, terms: usize, drives: usize) -> Self {
        Self {
            length,
            known: Vec::with_capacity(terms * (terms + 1) / 2 + 2 * terms * drives),
        }
    }

    /// `E(z)` (us) over the interval.
    fn at(&mut self, z: Complex<f64>) -> Complex<f64> {
        let bits = (z.re.to_bits(), z.im.to_bits());
        if let Some(&(_, value)) = self
            .known
            .iter()
            .find(|(known, _)| (known.re.to_bits(), known.im.to_bits()) == bits)
        {
            return value;
        }
        let value = exponential_integral(z, self.length);
        self.known.push((z, value));
        value
    }
}

/// `E(z) = int_0^L e^{z s} ds = (e^{z L} - 1) / z` (`L` at `z = 0`), by its Taylor series
/// `L sum_n (z L)^n / (n + 1)!` where `|z L| < 1`, so that short intervals lose no digits.
fn exponential_integral(z: Complex<f64>, length: f64) -> Complex<f64> {
    let zl = z * length;
    // Squared moduli (no square roots): `|zL| < 1` and `|term| < 1e-17 |sum|`.
    if zl.norm_sqr() < 1.0 {
        let mut term = Complex::new(1.0, 0.0);
        let mut sum = term;
        for n in 1..25 {
            term = term * zl / (n + 1) as f64;
            sum += term;
            if term.norm_sqr() < 1e-34 * sum.norm_sqr() {
                break;
            }
        }
        sum * length
    } else {
        (zl.exp() - 1.0) / z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::builtin_case;
    use crate::model::free_flight::DrivenOscillator;

    /// Under the bimodal drive of `biolever-mica-bimodal` (second drive at 8 `w`): the closed
    /// forms (energy, Fourier integrals at the harmonics 1 to 3 of `w` and at `w_b`) against a
    /// composite Simpson rule on a fixed-step RK4 of each mode's equation with both drives,
    /// `q'' = (w_i^2 / k_i) F_i (cos(w t) + (F_1b / F_1) cos(w_b t)) - w_i^2 q - (w_i/Q_i) q'`,
    /// written here (step 0.001 us: RK4's error below 1e-12 relative, Simpson's likewise),
    /// from a state off the steady orbit over intervals from a hundredth of a period to two
    /// periods; they agree to 1e-9 of each integral's scale.
    #[test]
    fn bimodal_closed_forms_match_simpson_on_a_brute_force_flight() {
        use crate::model::free_flight_fourier::FreeFlightFourier;
        let model = TappingModel::from_case(&builtin_case("biolever-mica-bimodal").expect("case"))
            .expect("model");
        let second = model.second_drive().expect("bimodal").clone();
        let energy = FreeFlightEnergy::new(&model).expect("not critically damped");
        let fourier = FreeFlightFourier::new(&model).expect("not critically damped");
        let (w, wb, r) = (
            model.drive_angular_frequency(),
            second.angular_frequency,
            second.relative_force,
        );
        let period = model.period_us();
        let x_a = [3.0, -0.2, -0.4, 1.5];
        for (a, length) in [
            (0.13, 0.01 * period),
            (5.0, 0.37 * period),
            (1.0, 2.0 * period),
        ] {
            let panels = ((length / 1e-3).ceil() as usize).next_multiple_of(2);
            let h = length / panels as f64;
            let mut closed = vec![ModeIntegrals::default(); 2];
            energy.accumulate(a, &x_a, a + length, &mut closed);
            // Simpson sums of u e^{-i nu t} for nu = w, 2w, 3w, w_b.
            let frequencies = [w, 2.0 * w, 3.0 * w, wb];
            let mut lock_in = [[0.0; 2]; 4];
            for (i, mode) in model.cantilever().modes.iter().enumerate() {
                let omega = mode.angular_frequency();
                let (gain, damping) = (
                    omega * omega / mode.stiffness_n_per_m,
                    omega / mode.quality_factor,
                );
                let force = mode.force_ratio * model.drive_force_nn();
                let field = |t: f64, [q, v]: [f64; 2]| {
                    [
                        v,
                        gain * force * ((w * t).cos() + r * (wb * t).cos())
                            - omega * omega * q
                            - damping * v,
                    ]
                };
                let (mut work, mut square) = (0.0, 0.0);
                let mut y = [x_a[2 * i], x_a[2 * i + 1]];
                for n in 0..=panels {
                    let t = a + n as f64 * h;
                    let simpson = if n == 0 || n == panels {
                        1.0
                    } else if n % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    work += simpson * force * ((w * t).cos() + r * (wb * t).cos()) * y[1];
                    square += simpson * y[1] * y[1];
                    for (sums, nu) in lock_in.iter_mut().zip(frequencies) {
                        let u = mode.optical_sensitivity * y[0];
                        sums[0] += simpson * u * (nu * t).cos();
                        sums[1] += simpson * u * (nu * t).sin();
                    }
                    // One RK4 step to t + h.
                    let k1 = field(t, y);
                    let k2 = field(
                        t + 0.5 * h,
                        [y[0] + 0.5 * h * k1[0], y[1] + 0.5 * h * k1[1]],
                    );
                    let k3 = field(
                        t + 0.5 * h,
                        [y[0] + 0.5 * h * k2[0], y[1] + 0.5 * h * k2[1]],
                    );
                    let k4 = field(t + h, [y[0] + h * k3[0], y[1] + h * k3[1]]);
                    for c in 0..2 {
                        y[c] += h / 6.0 * (k1[c] + 2.0 * k2[c] + 2.0 * k3[c] + k4[c]);
                    }
                }
                work *= h / 3.0;
                square *= h / 3.0;
                let scale = square.abs().max(1e-300);
                assert!(
                    (closed[i].velocity_square - square).abs() < 1e-9 * scale,
                    "mode {i}, L = {length}: {} vs {square}",
                    closed[i].velocity_square
                );
                let work_scale = force.abs() * (1.0 + r.abs()) * square.sqrt() * length.sqrt();
                assert!(
                    (closed[i].drive_work - work).abs() < 1e-9 * work_scale,
                    "mode {i}, L = {length}: {} vs {work}",
                    closed[i].drive_work
                );
            }
            let amplitude = x_a.iter().map(|v| v.abs()).fold(0.0, f64::max) + 10.0;
            for (harmonic, sums) in lock_in.iter().enumerate() {
                let closed = if harmonic < 3 {
                    fourier.integrate_harmonic(harmonic + 1, a, &x_a, a + length)
                } else {
                    fourier
                        .integrate_second(a, &x_a, a + length)
                        .expect("bimodal")
                };
                for c in 0..2 {
                    let quadrature = sums[c] * h / 3.0;
                    assert!(
                        (closed[c] - quadrature).abs() < 1e-9 * amplitude * length,
                        "frequency {harmonic}, part {c}, L = {length}: {} vs {quadrature}",
                        closed[c]
                    );
                }
            }
        }
    }

    /// The closed form against a 20000-panel composite Simpson rule on the exact free flight of
    /// each mode (`DrivenOscillator::flow`), for the two modes of the Biolever, from a state
    /// off the steady orbit over intervals from a hundredth of a period to two periods: Simpson's
    /// error there is below 1e-12 relative, and the closed form agrees to 1e-10.
    #[test]
    fn closed_form_matches_simpson_on_the_exact_flow() {
        let model =
            TappingModel::from_case(&builtin_case("biolever-mica").expect("case")).expect("model");
        let energy = FreeFlightEnergy::new(&model).expect("not critically damped");
        let w = model.drive_angular_frequency();
        let period = model.period_us();
        let x_a = [3.0, -0.2, -0.4, 1.5];
        for (a, length) in [
            (0.13, 0.01 * period),
            (5.0, 0.37 * period),
            (1.0, 2.0 * period),
        ] {
            let mut closed = vec![ModeIntegrals::default(); 2];
            energy.accumulate(a, &x_a, a + length, &mut closed);
            for (i, mode) in model.cantilever().modes.iter().enumerate() {
                let static_deflection =
                    mode.force_ratio * model.drive_force_nn() / mode.stiffness_n_per_m;
                let oscillator = DrivenOscillator::new(
                    mode.angular_frequency(),
                    mode.quality_factor,
                    static_deflection,
                    w,
                );
                let force = mode.force_ratio * model.drive_force_nn();
                let panels = 20_000;
                let h = length / panels as f64;
                let (mut work, mut square) = (0.0, 0.0);
                for n in 0..=panels {
                    let t = a + n as f64 * h;
                    let ([_, v], _) = oscillator.flow(a, [x_a[2 * i], x_a[2 * i + 1]], t - a);
                    let simpson = if n == 0 || n == panels {
                        1.0
                    } else if n % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    work += simpson * force * (w * t).cos() * v;
                    square += simpson * v * v;
                }
                work *= h / 3.0;
                square *= h / 3.0;
                let scale = square.abs().max(1e-300);
                assert!(
                    (closed[i].velocity_square - square).abs() < 1e-10 * scale,
                    "mode {i}, L = {length}: {} vs {square}",
                    closed[i].velocity_square
                );
                let work_scale = force.abs() * square.sqrt() * length.sqrt();
                assert!(
                    (closed[i].drive_work - work).abs() < 1e-10 * work_scale,
                    "mode {i}, L = {length}: {} vs {work}",
                    closed[i].drive_work
                );
            }
        }
    }
}
