//! The free (`F_ts = 0`) steady orbit in closed form, its first harmonic of `u` (which equals
//! `A0` by construction of `F_1`), its phase, and the separation of first contact `Z_G1`; with
//! an acoustic drive's base motion in the gap and a bimodal drive's second response (MODEL.md
//! section 14).

use crate::model::cantilever::Cantilever;
use crate::model::drive::Drive;
use crate::model::free_flight::DrivenOscillator;
use crate::model::second_drive::SecondDrive;
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
    /// The base amplitude `Y` of an acoustic drive (0 otherwise), nm: the gap holds
    /// `Y cos(w t)`.
    base_amplitude_nm: f64,
    /// A bimodal drive's second response: `w_b`, the ratio `(p, q)`, and `[a_i, b_i]` per
    /// mode with `q_i += a_i cos(w_b t) + b_i sin(w_b t)`.
    second: Option<SecondResponse>,
}

/// The free response to a bimodal drive's second drive.
#[derive(Debug, Clone, PartialEq)]
struct SecondResponse {
    angular_frequency: f64,
    numerator: u32,
    denominator: u32,
    coefficients: Vec<[f64; 2]>,
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
            base_amplitude_nm: 0.0,
            second: None,
        }
    }

    /// The same response with an acoustic drive's base motion `Y cos(w t)` (nm) in the gap
    /// (MODEL.md section 14; `q_i` and `u` are unchanged).
    pub fn with_base_amplitude(mut self, base_amplitude_nm: f64) -> Self {
        self.base_amplitude_nm = base_amplitude_nm;
        self
    }

    /// The same response with a bimodal drive's second response added to every `q_i`
    /// (`None`: unchanged).
    pub fn with_second_drive(mut self, second: Option<&SecondDrive>) -> Self {
        self.second = second.map(|second| SecondResponse {
            angular_frequency: second.angular_frequency,
            numerator: second.ratio.numerator,
            denominator: second.ratio.denominator,
            coefficients: second
                .oscillators
                .iter()
                .map(DrivenOscillator::steady_coefficients)
                .collect(),
        });
        self
    }

    /// A bimodal drive's first harmonic `[a, b]` of `u` at `w_b` (nm):
    /// `u ~ a cos(w_b t) + b sin(w_b t)`; its amplitude is `A0_b`. `None` for another drive.
    pub fn second_photodiode_harmonic(&self) -> Option<[f64; 2]> {
        self.second.as_ref().map(|second| {
            second
                .coefficients
                .iter()
                .zip(&self.optical_sensitivities)
                .fold([0.0, 0.0], |[sa, sb], ([a, b], chi)| {
                    [sa + chi * a, sb + chi * b]
                })
        })
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
        if let Some(second) = &self.second {
            let (sin, cos) = (second.angular_frequency * t).sin_cos();
            for (i, [a, b]) in second.coefficients.iter().enumerate() {
                x[2 * i] += a * cos + b * sin;
                x[2 * i + 1] += second.angular_frequency * (b * cos - a * sin);
            }
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

    /// The gap minus `Z`, `y_base(t) + sum_i q_i(t)`, as a trigonometric polynomial in
    /// `theta = w t / q` (`q = 1` but for a bimodal drive of ratio `p / q`, whose drives are
    /// its harmonics `q` and `p`).
    pub fn deflection_sum(&self) -> TrigonometricPolynomial {
        let sum = |coefficients: &[[f64; 2]]| {
            coefficients
                .iter()
                .fold([0.0, 0.0], |[sa, sb], [a, b]| [sa + a, sb + b])
        };
        let [a, b] = sum(&self.coefficients);
        let first = [a + self.base_amplitude_nm, b];
        let Some(second) = &self.second else {
            return TrigonometricPolynomial {
                constant: 0.0,
                harmonics: vec![first],
            };
        };
        let (p, q) = (second.numerator as usize, second.denominator as usize);
        let mut harmonics = vec![[0.0, 0.0]; p.max(q)];
        harmonics[q - 1] = first;
        let [a, b] = sum(&second.coefficients);
        harmonics[p - 1][0] += a;
        harmonics[p - 1][1] += b;
        TrigonometricPolynomial {
            constant: 0.0,
            harmonics,
        }
    }

    /// The angular frequency of [`FreeResponse::deflection_sum`]'s variable, `w / q`, rad/us.
    fn base_angular_frequency(&self) -> f64 {
        self.angular_frequency / f64::from(self.second.as_ref().map_or(1, |s| s.denominator))
    }

    /// The separation of first contact `Z_G1 = -min_t (y_base(t) + sum_i q_i(t))`, nm: the free
    /// orbit's lowest gap `d = Z + y_base + sum_i q_i` is zero at `Z = Z_G1` (MODEL.md sections
    /// 5 and 14).
    pub fn grazing_separation_nm(&self) -> f64 {
        -self.deflection_sum().minimum().1
    }

    /// The time in `[0, T)` (us; `T` the model's period, `q` drive periods for a bimodal drive)
    /// at which the free orbit's gap is lowest.
    pub fn lowest_gap_time_us(&self) -> f64 {
        self.deflection_sum().minimum().0 / self.base_angular_frequency()
    }
}
