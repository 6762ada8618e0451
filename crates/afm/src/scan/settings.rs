//! What a scan does (MODEL.md section 12): the setpoint, the pixels, the directions, and the
//! orbit settings of the ideal feedback.

use crate::error::AfmError;
use crate::orbit::steady_orbit::SteadyOrbitSettings;
use crate::scan::pixel::ScanDirection;
use crate::validation::invalid;

/// The most pixels a scan line has.
pub const MAX_PIXELS: usize = 100_000;

/// Which passes a scan makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScanDirections {
    /// Left to right only.
    Trace,
    /// Right to left only (engaged at the line's end).
    Retrace,
    /// Trace, then retrace from where the trace ended (the feedback stays engaged).
    Both,
}

impl ScanDirections {
    /// The passes in the order they are made.
    pub fn passes(self) -> &'static [ScanDirection] {
        match self {
            Self::Trace => &[ScanDirection::Trace],
            Self::Retrace => &[ScanDirection::Retrace],
            Self::Both => &[ScanDirection::Trace, ScanDirection::Retrace],
        }
    }
}

/// The settings shared by both feedbacks. Checked by [`ScanSettings::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct ScanSettings {
    /// The setpoint `A/A0`, in (0, 1) (`A0` the free amplitude, far from the sample).
    pub setpoint: f64,
    /// Pixels along the line, `1..=`[`MAX_PIXELS`].
    pub pixels: usize,
    /// Trace, retrace or both.
    pub directions: ScanDirections,
    /// How each orbit of the ideal feedback is computed (its `harmonics` also set the
    /// harmonics a time-domain scan reads).
    pub orbit: SteadyOrbitSettings,
}

impl ScanSettings {
    /// A trace of `pixels` pixels at `setpoint` with the default orbit settings.
    pub fn new(setpoint: f64, pixels: usize) -> Self {
        Self {
            setpoint,
            pixels,
            directions: ScanDirections::Trace,
            orbit: SteadyOrbitSettings::default(),
        }
    }

    /// Check every field (errors name the field and its allowed range).
    pub fn validate(&self) -> Result<(), AfmError> {
        const FILE: &str = "scan settings";
        if !(self.setpoint > 0.0 && self.setpoint < 1.0) {
            return Err(invalid(
                FILE,
                "setpoint",
                self.setpoint,
                String::from("0 < A/A0 < 1"),
            ));
        }
        if !(1..=MAX_PIXELS).contains(&self.pixels) {
            return Err(invalid(
                FILE,
                "pixels",
                self.pixels as f64,
                format!("an integer in [1, {MAX_PIXELS}]"),
            ));
        }
        self.orbit.validate()
    }
}
