//! The free (`F_ts = 0`) steady orbit in closed form, its first harmonic of `u` (which equals
//! `A0` by construction of `F_1`), its phase, and the separation of first contact `Z_G1`.

use crate::model::cantilever::Cantilever;
use crate::model::drive::Drive;
use crate::model::free_flight::DrivenOscillator;
use crate::model::trigonometric::TrigonometricPolynomial;

/// The free steady orbit: every `q_i(t) = a_i cos(w t) + b_i sin(w t)` (nm, t in us).
#[derive(Debug, Clone, PartialEq)]
pub struct FreeResponse {
    /// Drive angular frequency `w`, rad/us.
    angular_frequency: f64,
    /// `[a_i, b_i]` per mode, nm.
    coefficients: Vec<[f64; 2]>,
    /// `chi_i` per mode.
    optical_sensitivities: Vec<f64>,
}

impl FreeResponse {
    /// The free steady orbit of `cantilever` under `drive`: `q_i = Re[r_i F_1 H_i(w) e^{iwt}]`.
    pub fn new(cantilever: &Cantilever, drive: &Drive) -> Self {
        let coefficients = cantilever
            .modes
            .iter()
            .map(|mode| {
                DrivenOscillator::new(
                    mode.angular_frequency(),
                    mode.quality_factor,
                    mode.force_ratio * drive.force_nn / mode.stiffness_n_per_m,
                    drive.angular_frequency,
                )
                .steady_coefficients()
            })
            .collect();
        Self {
            angular_frequency: drive.angular_frequency,
            coefficients,
            optical_sensitivities: cantilever
                .modes
                .iter()
                .map(|mode| mode.optical_sensitivity)
                .collect(),
        }
    }

    /// `[a_i, b_i]` of every mode (nm): `q_i(t) = a_i cos(w t) + b_i sin(w t)`.
    pub fn modal_coefficients(&self) -> &[[f64; 2]] {
        &self.coefficients
    }

    /// The state `[q_1, q_1', ..., q_N, q_N']` (nm, nm/us) of the free orbit at time `t` (us)
    /// into `x` (length 2N).
    pub fn state_at(&self, t: f64, x: &mut [f64]) {
        let (sin, cos) = (self.angular_frequency * t).sin_cos();
        for (i, [a, b]) in self.coefficients.iter().enumerate() {
            x[2 * i] = a * cos + b * sin;
            x[2 * i + 1] = self.angular_frequency * (b * cos - a * sin);
        }
    }

    /// The first harmonic `[a, b]` of `u = sum_i chi_i q_i` (nm): `u = a cos(wt) + b sin(wt)`
    /// (MODEL.md section 4).
    pub fn photodiode_harmonic(&self) -> [f64; 2] {
        self.coefficients
            .iter()
            .zip(&self.optical_sensitivities)
            .fold([0.0, 0.0], |[sa, sb], ([a, b], chi)| {
                [sa + chi * a, sb + chi * b]
            })
    }

    /// The first-harmonic amplitude `A = hypot(a, b)` of `u`, nm (equals `A0`).
    pub fn amplitude_nm(&self) -> f64 {
        let [a, b] = self.photodiode_harmonic();
        a.hypot(b)
    }

    /// The phase lag `Phi = atan2(b, a)` of `u`, degrees (MODEL.md section 4).
    pub fn phase_deg(&self) -> f64 {
        let [a, b] = self.photodiode_harmonic();
        b.atan2(a).to_degrees()
    }

    /// `sum_i q_i(t)` as a trigonometric polynomial in `theta = w t` (the gap minus `Z`).
    pub fn deflection_sum(&self) -> TrigonometricPolynomial {
        let sum = self
            .coefficients
            .iter()
            .fold([0.0, 0.0], |[sa, sb], [a, b]| [sa + a, sb + b]);
        TrigonometricPolynomial {
            constant: 0.0,
            harmonics: vec![sum],
        }
    }

    /// The separation of first contact `Z_G1 = -min_t sum_i q_i(t)`, nm: the free orbit's
    /// lowest gap `d = Z + sum_i q_i` is zero at `Z = Z_G1` (MODEL.md section 5).
    pub fn grazing_separation_nm(&self) -> f64 {
        -self.deflection_sum().minimum().1
    }

    /// The time in `[0, T)` (us) at which the free orbit's gap is lowest.
    pub fn lowest_gap_time_us(&self) -> f64 {
        self.deflection_sum().minimum().0 / self.angular_frequency
    }
}
