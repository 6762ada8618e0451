//! Acoustic (base) excitation (MODEL.md section 14): the base's motion `y_base(t) = Y cos(w t)`
//! in the gap, the inertial forcing it gives each mode in the base's frame, and the
//! Euler-Bernoulli participation factors `gamma_i` by default.

use crate::error::AfmError;
use crate::model::cantilever::Cantilever;
use crate::model::phase;

/// The base's motion `y_base(t) = Y cos(w t)`, nm (positive away from the sample, as `Z`).
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMotion {
    /// The base amplitude `Y`, nm (solved from `A0`; its sign is `gamma_1`'s).
    pub amplitude_nm: f64,
    /// The drive angular frequency `w`, rad/us.
    pub angular_frequency: f64,
    /// The participation factors `gamma_i`, one per mode.
    pub participation: Vec<f64>,
}

impl BaseMotion {
    /// `y_base(t) = Y cos(w t)`, nm (t in us).
    #[inline]
    pub fn displacement(&self, t: f64) -> f64 {
        self.amplitude_nm * phase::cos(self.angular_frequency * t)
    }

    /// `y_base'(t) = -w Y sin(w t)`, nm/us.
    #[inline]
    pub fn velocity(&self, t: f64) -> f64 {
        -self.angular_frequency * self.amplitude_nm * phase::sin_cos(self.angular_frequency * t).0
    }

    /// `y_base''(t) = -w^2 Y cos(w t)`, nm/us^2.
    #[inline]
    pub fn acceleration(&self, t: f64) -> f64 {
        -self.angular_frequency * self.angular_frequency * self.displacement(t)
    }
}

/// The force amplitude on mode `i` per nm of base amplitude, nN/nm: the inertial force
/// `-m_i gamma_i y_base''` with `m_i = k_i / w_i^2` is `k_i gamma_i (w / w_i)^2 Y cos(w t)`
/// (MODEL.md section 14). `w` in rad/us.
pub fn inertial_force_per_nm(cantilever: &Cantilever, participation: &[f64], w: f64) -> Vec<f64> {
    cantilever
        .modes
        .iter()
        .zip(participation)
        .map(|(mode, gamma)| {
            let ratio = w / mode.angular_frequency();
            mode.stiffness_n_per_m * gamma * ratio * ratio
        })
        .collect()
}

/// The cantilever whose direct drive is the base motion's inertial forcing at `w` (rad/us):
/// the same modes with the forcing ratios `r_i = k_i gamma_i w_1^2 / (k_1 gamma_1 w_i^2)`
/// (MODEL.md section 14), so that `F_1 = k_1 gamma_1 (w / w_1)^2 Y`.
pub fn acoustic_cantilever(cantilever: &Cantilever, participation: &[f64], w: f64) -> Cantilever {
    let forces = inertial_force_per_nm(cantilever, participation, w);
    let mut acoustic = cantilever.clone();
    for (mode, force) in acoustic.modes.iter_mut().zip(&forces) {
        mode.force_ratio = force / forces[0];
    }
    acoustic
}

/// The participation factors of base motion of the Euler-Bernoulli cantilever with the point
/// tip mass ratio `mu` of `cantilever`, modes normalised to unit tip deflection:
/// `gamma_i = (int_0^1 phi_i + mu) / (int_0^1 phi_i^2 + mu)` (MODEL.md sections 11 and 14;
/// 1.566, -0.868, 0.509 for the first three modes at `mu = 0`). Fails with an error naming
/// `file` and the field for a tip mass ratio or mode count the beam model does not cover.
pub fn beam_participation(cantilever: &Cantilever, file: &str) -> Result<Vec<f64>, AfmError> {
    let mu = cantilever.tip_mass_ratio;
    let shapes = beam::cantilever::Beam::new(mu)
        .and_then(|beam| beam.modes(cantilever.mode_count()))
        .map_err(|error| AfmError::InvalidField {
            file: file.to_string(),
            field: "drive.base_participation".to_string(),
            value: "absent".to_string(),
            allowed: format!(
                "one factor per mode (the beam model cannot supply them: {error}); give \
                 `base_participation` in the drive object"
            ),
        })?;
    Ok(shapes
        .iter()
        .map(|shape| (shape.distributed_force_integral() + mu) / (shape.beam_mass_integral() + mu))
        .collect())
}
