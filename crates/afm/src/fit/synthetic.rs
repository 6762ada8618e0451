//! Synthetic measurements made by drumroll itself (MODEL.md section 13.5): the model's
//! followed approach branch sampled at equally spaced piezo positions, seen through an
//! instrument with a piezo offset, an amplitude calibration error, a phase offset and white
//! Gaussian noise, for tests, fixtures and examples. Never real data.

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use crate::diagram::bifurcation_diagram::{approach_diagram, DiagramSettings};
use crate::error::AfmError;
use crate::fit::followed_branch::FollowedBranch;
use crate::fit::measurement::MeasuredPoint;
use crate::model::TappingModel;

/// What the synthetic instrument adds to the model's curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyntheticInstrument {
    /// Data `Z` minus drumroll's `Z`, nm.
    pub z_offset_nm: f64,
    /// Amplitude calibration `c`: the instrument reports `c A` (and `c A0`).
    pub amplitude_calibration: f64,
    /// Added to the model's phase, degrees.
    pub phase_offset_deg: f64,
    /// Standard deviation of the amplitude noise as a fraction of the reported `A0`.
    pub amplitude_noise_fraction: f64,
    /// Standard deviation of the phase noise, degrees.
    pub phase_noise_deg: f64,
    /// Rows on the approach.
    pub rows: usize,
    /// Piezo range above first contact, as a fraction of `A0` (the free rows).
    pub free_range_fraction: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for SyntheticInstrument {
    /// The test instrument: offsets 12.5 nm and 90 deg, calibration 1.08, noise 0.3%
    /// of `A0` and 0.15 deg, 1000 rows, 25% of `A0` of free range, seed 1.
    fn default() -> Self {
        Self {
            z_offset_nm: 12.5,
            amplitude_calibration: 1.08,
            phase_offset_deg: 90.0,
            amplitude_noise_fraction: 0.003,
            phase_noise_deg: 0.15,
            rows: 1000,
            free_range_fraction: 0.25,
            seed: 1,
        }
    }
}

/// A standard normal deviate (mean 0, deviation 1) by Box-Muller from two uniform deviates of
/// `rng`.
pub fn gaussian(rng: &mut StdRng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// The followed approach branch of `model` down to `A/A0 = 0.3` (or `Z = 0.05 A0`).
///
/// # Errors
/// As [`approach_diagram`].
pub fn model_branch(model: &TappingModel) -> Result<FollowedBranch, AfmError> {
    let settings = DiagramSettings::approach(model);
    Ok(FollowedBranch::new(approach_diagram(model, &settings)?))
}

/// Sample `branch` (of a model with free amplitude `a0_nm`) through `instrument`: rows from
/// `Z_top + free_range_fraction A0` down to the branch's lowest `Z`, equally spaced, with
/// `line` numbers from 2 (after a header). The reported amplitude is
/// `c A0 (A/A0)(Z) + noise`, the phase `phase(Z) + offset + noise`, at data `Z + z_offset`.
pub fn synthetic_approach(
    branch: &FollowedBranch,
    a0_nm: f64,
    instrument: &SyntheticInstrument,
) -> Vec<MeasuredPoint> {
    let mut rng = StdRng::seed_from_u64(instrument.seed);
    let top = branch.z_top() + instrument.free_range_fraction * a0_nm;
    let bottom = branch.z_bottom();
    let n = instrument.rows.max(2);
    (0..n)
        .map(|i| {
            let z = top + (bottom - top) * i as f64 / (n - 1) as f64;
            let ratio = branch.value(z, |p| p.amplitude_ratio).value;
            let phase = branch.value(z, |p| p.phase_deg).value;
            let reported_a0 = instrument.amplitude_calibration * a0_nm;
            MeasuredPoint {
                line: i + 2,
                z_nm: z + instrument.z_offset_nm,
                amplitude_nm: reported_a0
                    * (ratio + instrument.amplitude_noise_fraction * gaussian(&mut rng)),
                phase_deg: phase
                    + instrument.phase_offset_deg
                    + instrument.phase_noise_deg * gaussian(&mut rng),
            }
        })
        .collect()
}

/// `points` as the text of a CSV file with the default header `z_nm,amplitude_nm,phase_deg`,
/// after `comments` (each line prefixed by `# `).
pub fn to_csv(points: &[MeasuredPoint], comments: &[String]) -> String {
    let mut text = String::new();
    for comment in comments {
        text.push_str(&format!("# {comment}\n"));
    }
    text.push_str("z_nm,amplitude_nm,phase_deg\n");
    for p in points {
        text.push_str(&format!(
            "{:.5},{:.5},{:.4}\n",
            p.z_nm, p.amplitude_nm, p.phase_deg
        ));
    }
    text
}
