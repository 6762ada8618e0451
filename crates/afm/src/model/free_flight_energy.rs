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

use crate::model::free_flight_fourier::FreeFlightMode;
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
    /// The closed form for `model`'s free flight; `None` when a mode is within 0.1% of critical
    /// damping or under a bimodal drive (as
    /// [`crate::model::free_flight_fourier::FreeFlightFourier::new`]), where the caller
    /// integrates numerically instead.
    pub fn new(model: &TappingModel) -> Option<Self> {
        if model.second_drive().is_some() {
            return None;
        }
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
        })
    }

    /// Add each mode's integrals over free flight from state `x_a = [q_1, q_1', ..., q_N,
    /// q_N']` at time `a` (us) to time `b >= a` to `totals` (one entry per mode).
    pub fn accumulate(&self, a: f64, x_a: &[f64], b: f64, totals: &mut [ModeIntegrals]) {
        let w = self.angular_frequency;
        let length = b - a;
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
            let mut square = Complex::new(0.0, 0.0);
            let mut drive = Complex::new(0.0, 0.0);
            for (j, &(g, z)) in terms.iter().enumerate() {
                // The symmetric double sum: the diagonal once, each pair twice.
                square += g * g * exponential_integral(z + z, length);
                for &(h, y) in &terms[j + 1..] {
                    square += 2.0 * g * h * exponential_integral(z + y, length);
                }
                drive += g
                    * (rotation * exponential_integral(z + iw, length)
                        + rotation.conj() * exponential_integral(z - iw, length));
            }
            total.velocity_square += square.re;
            total.drive_work += mode.drive_force_nn * 0.5 * drive.re;
        }
    }
}

/// `E(z) = int_0^L e^{z s} ds = (e^{z L} - 1) / z` (`L` at `z = 0`), by its Taylor series
/// `L sum_n (z L)^n / (n + 1)!` where `|z L| < 1`, so that short intervals lose no digits.
fn exponential_integral(z: Complex<f64>, length: f64) -> Complex<f64> {
    let zl = z * length;
    if zl.norm() < 1.0 {
        let mut term = Complex::new(1.0, 0.0);
        let mut sum = term;
        for n in 1..25 {
            term = term * zl / (n + 1) as f64;
            sum += term;
            if term.norm() < 1e-17 * sum.norm() {
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
