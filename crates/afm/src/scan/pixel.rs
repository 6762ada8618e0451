//! One pixel of a scan: where it is, what the feedback put `Z` at, the apparent height, and
//! the contrast observables of the orbit there (MODEL.md sections 10 and 12).

use serde::Serialize;

use crate::orbit::observables::Harmonic;
use crate::orbit::steady_orbit::SteadyOrbit;

/// Which way the tip moves along the line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ScanDirection {
    /// Increasing `x`.
    Trace,
    /// Decreasing `x`.
    Retrace,
}

impl ScanDirection {
    /// `trace` or `retrace`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Trace => "trace",
            Self::Retrace => "retrace",
        }
    }
}

/// Where the ideal feedback had to leave the branch it was on: the stable part of the branch
/// it followed ended (a fold) before `A/A0` reached the setpoint, and the cantilever fell onto
/// another attractor (MODEL.md section 12).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BranchJump {
    /// `Z` at the end of the stable part left (the fold), nm.
    pub from_z_nm: f64,
    /// `A/A0` there.
    pub from_amplitude_ratio: f64,
    /// Impacts per period there.
    pub from_impacts_per_period: f64,
}

/// One pixel of a scan line, in scan order (MODEL.md section 12).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScanPixel {
    /// Pixel index along `x` (0 at the line's start, whatever the direction).
    pub index: usize,
    /// The pixel's centre along the line, nm.
    pub x_nm: f64,
    /// Trace or retrace.
    pub direction: ScanDirection,
    /// The sample under the tip (its name).
    pub sample: String,
    /// The true surface height `h(x)`, nm.
    pub height_true_nm: f64,
    /// The measured height `h(x) + Z(x) - Z(x_0)` (the base's height relative to the first
    /// pixel scanned, plus that pixel's true height), nm.
    pub height_nm: f64,
    /// `height_nm - height_true_nm`, nm.
    pub height_error_nm: f64,
    /// The separation `Z` from the base's rest position to the sample surface under the tip,
    /// nm (for a time-domain scan, the mean over the pixel's cycles).
    pub z_nm: f64,
    /// `A/A0` (for a time-domain scan, the lock-in over the pixel's cycles).
    pub amplitude_ratio: f64,
    /// Phase lag of the first harmonic of `u`, degrees.
    pub phase_deg: f64,
    /// Impacts per drive period (for a time-domain scan, averaged over the pixel's cycles).
    pub impacts_per_period: f64,
    /// The largest tip-sample force, nN.
    pub peak_force_nn: f64,
    /// The mean tip-sample force, nN (`None` for a time-domain scan).
    pub mean_force_nn: Option<f64>,
    /// Energy dissipated in the sample per drive period, eV (MODEL.md section 10).
    pub dissipated_ev: f64,
    /// The virial, eV (`None` for a time-domain scan).
    pub virial_ev: Option<f64>,
    /// The largest indentation, nm (`None` for a time-domain scan).
    pub max_indentation_nm: Option<f64>,
    /// The mean indentation over the time in contact, nm (`None` for a time-domain scan).
    pub mean_indentation_nm: Option<f64>,
    /// Harmonics `1..=N` of `u`.
    pub harmonics: Vec<Harmonic>,
    /// The orbit's period in drive periods (1 for a time-domain scan, which reads cycles).
    pub multiplicity: usize,
    /// Whether the orbit attracts (`None` for a time-domain scan).
    pub stable: Option<bool>,
    /// The jump the feedback made on the way to this pixel, if any (not serialised: the
    /// command line writes `jumped` and `jump_from_z_nm`).
    #[serde(skip)]
    pub jump: Option<BranchJump>,
}

impl ScanPixel {
    /// The pixel of the steady `orbit` found by the ideal feedback at `x_nm` (true height
    /// `height_true_nm`, sample `sample`), its measured height still to be set by
    /// [`set_measured_heights`].
    #[allow(clippy::too_many_arguments)]
    pub fn of_orbit(
        index: usize,
        x_nm: f64,
        direction: ScanDirection,
        sample: &str,
        height_true_nm: f64,
        orbit: &SteadyOrbit,
        free_amplitude_nm: f64,
        jump: Option<BranchJump>,
    ) -> Self {
        let o = orbit.observables();
        Self {
            index,
            x_nm,
            direction,
            sample: sample.to_string(),
            height_true_nm,
            height_nm: f64::NAN,
            height_error_nm: f64::NAN,
            z_nm: orbit.z_nm,
            amplitude_ratio: o.amplitude_nm / free_amplitude_nm,
            phase_deg: o.phase_deg,
            impacts_per_period: o.impacts_per_period,
            peak_force_nn: o.peak_force_nn,
            mean_force_nn: Some(o.mean_force_nn),
            dissipated_ev: o.dissipated_ev,
            virial_ev: Some(o.virial_ev),
            max_indentation_nm: Some(o.max_indentation_nm),
            mean_indentation_nm: Some(o.mean_indentation_nm),
            harmonics: o.harmonics.clone(),
            multiplicity: orbit.multiplicity,
            stable: Some(orbit.stable),
            jump,
        }
    }
}

/// Set `height_nm = b(x) - b(x_0) + h(x_0)` and its error on every pixel of one pass of the
/// PI feedback, `b` the base's height averaged over the pixel's cycles (`bases[i]` that of
/// `pass[i]`, nm), `x_0` the pixel of index 0 of the same pass (MODEL.md section 12): over a
/// pixel where `h` is constant, `h(x) + Z(x) - Z(x_0)` as [`set_measured_heights`]; over one
/// straddling a step, the base's mean height, as a recorded image has it.
pub fn set_heights_from_bases(pass: &mut [ScanPixel], bases: &[f64]) {
    let Some(reference) = pass
        .iter()
        .zip(bases)
        .find(|(p, _)| p.index == 0)
        .map(|(p, &b)| b - p.height_true_nm)
    else {
        return;
    };
    for (pixel, &base) in pass.iter_mut().zip(bases) {
        pixel.height_nm = base - reference;
        pixel.height_error_nm = pixel.height_nm - pixel.height_true_nm;
    }
}

/// Set `height_nm = h(x) + Z(x) - Z(x_0)` and its error on every pixel of one pass, `x_0`
/// being the pixel of index 0 (the line's start) of the same pass (MODEL.md section 12).
pub fn set_measured_heights(pass: &mut [ScanPixel]) {
    let Some(reference) = pass.iter().find(|p| p.index == 0).map(|p| p.z_nm) else {
        return;
    };
    for pixel in pass {
        pixel.height_nm = pixel.height_true_nm + pixel.z_nm - reference;
        pixel.height_error_nm = pixel.height_nm - pixel.height_true_nm;
    }
}
