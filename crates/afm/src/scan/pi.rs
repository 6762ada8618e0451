//! The time-domain closed loop (MODEL.md section 12): the tip moves along the line at the scan
//! rate while Eq. 1 is integrated cycle by cycle without interruption, the sweep's lock-in
//! ([`crate::orbit::lockin`]) reads the amplitude of every drive cycle, a first-order low-pass
//! of time constant `tau` smooths it, and a PI controller sets the base height:
//!
//! ```text
//! e_k = A_f,k - R A0,   I_k = I_{k-1} + e_k T,   b_{k+2} = b_0 - K_p e_k - K_i I_k,
//! Z(t) = b(t) - h(x(t)),
//! ```
//!
//! the base `b` running linearly over each cycle to the controller's output of the cycle
//! before (a one-cycle delay, as a digital loop updating once per period has), and the surface
//! `h` linear over each cycle between its values at the cycle's ends. The sample under the tip
//! is that at the cycle's middle. Engaged at the first pixel on the setpoint orbit of the
//! ideal feedback, so that a slow scan over uniform ground reads exactly what the ideal one
//! reads; a step down leaves the tip parachuting (free, `A = A0`) until the integral brings
//! the base down.

use hybrid::{Settings, SolverWorkspace};

use crate::error::AfmError;
use crate::model::case::Case;
use crate::model::separation::Separation;
use crate::orbit::lockin::{BlockAverage, CycleLockIn};
use crate::orbit::observables::Harmonic;
use crate::orbit::steady_orbit::SteadyOrbitWorkspace;
use crate::scan::line::ScanLine;
use crate::scan::materials::line_models;
use crate::scan::pixel::{set_heights_from_bases, ScanDirection, ScanPixel};
use crate::scan::setpoint_branch::{on_sample, SetpointBranch};
use crate::scan::settings::ScanSettings;
use crate::sweep::amplitude_ratio::AmplitudeRatioSearch;
use crate::sweep::{integrate_cycle, SweepSettings, MAX_CYCLE_COUNT};
use crate::validation::{check, invalid, Interval};

/// Microseconds per millisecond.
const US_PER_MS: f64 = 1e3;

/// The PI loop's gains, the scan rate and the lock-in. Checked by [`PiSettings::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct PiSettings {
    /// `K_p`: base displacement per amplitude error, nm/nm, in [0, 100]. Default 0.2.
    pub gain_p: f64,
    /// `K_i`: base speed per amplitude error, nm/(nm ms) = 1/ms, in [0, 1e4]. Default 0.5.
    pub gain_i_per_ms: f64,
    /// The tip's speed along the line, nm/s, in (0, 1e9]. Default 100.
    pub scan_rate_nm_per_s: f64,
    /// The lock-in's output time constant `tau`, ms, in [0, 1e4] (0: each cycle's reading
    /// unfiltered). Default 0.
    pub lockin_time_constant_ms: f64,
    /// Settings of the hybrid solver (the sweep's: tolerances 1e-8).
    pub integration: Settings,
}

impl PiSettings {
    /// The defaults for `case`'s cantilever (the sweep's integration settings).
    pub fn for_case(case: &Case) -> Result<Self, AfmError> {
        let model = crate::model::TappingModel::from_case(case)?;
        Ok(Self {
            gain_p: 0.2,
            gain_i_per_ms: 0.5,
            scan_rate_nm_per_s: 100.0,
            lockin_time_constant_ms: 0.0,
            integration: SweepSettings::for_model(&model).integration,
        })
    }

    /// Check every field (errors name the field and its allowed range).
    pub fn validate(&self) -> Result<(), AfmError> {
        const FILE: &str = "PI settings";
        check(
            FILE,
            "gain_p",
            self.gain_p,
            Interval::closed(0.0, 100.0, "nm/nm"),
        )?;
        check(
            FILE,
            "gain_i_per_ms",
            self.gain_i_per_ms,
            Interval::closed(0.0, 1e4, "1/ms"),
        )?;
        check(
            FILE,
            "scan_rate_nm_per_s",
            self.scan_rate_nm_per_s,
            Interval::positive(1e9, "nm/s"),
        )?;
        check(
            FILE,
            "lockin_time_constant_ms",
            self.lockin_time_constant_ms,
            Interval::closed(0.0, 1e4, "ms"),
        )?;
        self.integration.validate()?;
        Ok(())
    }
}

/// The time-domain PI scan of `line` (see the module's text), the pixels of each pass in scan
/// order, trace first; a retrace after a trace goes on from the trace's end, loop engaged.
pub fn pi_scan(
    case: &Case,
    line: &ScanLine,
    settings: &ScanSettings,
    pi: &PiSettings,
) -> Result<Vec<ScanPixel>, AfmError> {
    pi_scan_until(case, line, settings, pi, &mut |_| false)
}

/// As [`pi_scan`], telling `progress` the number of pixels done after each pixel; when it
/// answers `true` the scan ends with [`AfmError::Interrupted`].
pub fn pi_scan_until(
    case: &Case,
    line: &ScanLine,
    settings: &ScanSettings,
    pi: &PiSettings,
    progress: &mut dyn FnMut(usize) -> bool,
) -> Result<Vec<ScanPixel>, AfmError> {
    settings.validate()?;
    pi.validate()?;
    let mut models = line_models(case, line)?;
    let a0 = case.free_amplitude_nm;
    let period_us = models[0].period_us();
    let (start, end) = (line.start_nm(), line.end_nm());
    let length = end - start;
    let travel_per_cycle = pi.scan_rate_nm_per_s * 1e-6 * period_us;
    let cycles = (length / travel_per_cycle).round();
    if cycles < settings.pixels as f64 || cycles > MAX_CYCLE_COUNT as f64 {
        return Err(invalid(
            "PI settings",
            "scan_rate_nm_per_s",
            pi.scan_rate_nm_per_s,
            format!(
                "a rate giving at least one drive cycle per pixel and at most \
                 {MAX_CYCLE_COUNT:e} cycles per pass: here {cycles} cycles of {period_us:.3} us \
                 over {length} nm and {} pixels",
                settings.pixels
            ),
        ));
    }
    let cycles = cycles as usize;
    // The exact travel per cycle, so that the last cycle ends at the line's end.
    let travel = length / cycles as f64;
    // The pixel holding the middle of the `j`-th cycle counted from the line's start,
    // `floor((j + 1/2) N / K)`, in integers: a middle on a pixel boundary goes to the same
    // pixel in the count and in both passes.
    let pixel_of =
        |j: usize| ((2 * j + 1) * settings.pixels / (2 * cycles)).min(settings.pixels - 1);
    let mut cycles_in_pixel = vec![0usize; settings.pixels];
    for j in 0..cycles {
        cycles_in_pixel[pixel_of(j)] += 1;
    }
    let centres = line.pixel_centres(settings.pixels);
    let harmonics = settings
        .orbit
        .harmonics
        .min(crate::orbit::lockin::MAX_LOCKIN_HARMONICS);
    let mut lockins: Vec<CycleLockIn> = models
        .iter()
        .map(|m| CycleLockIn::with_harmonics(m, harmonics))
        .collect();

    // Engage on the ideal feedback's setpoint orbit where the first pass starts.
    let passes = settings.directions.passes();
    let x_first = match passes[0] {
        ScanDirection::Trace => start,
        ScanDirection::Retrace => end,
    };
    let material = line.material_at(x_first);
    let search = AmplitudeRatioSearch::new(settings.setpoint)?;
    // Errors name the sample, as the ideal feedback's do.
    let (orbit, _) = SetpointBranch::new(&models[material], &search, &settings.orbit)
        .and_then(|branch| branch.engage(&mut SteadyOrbitWorkspace::default()))
        .map_err(|error| on_sample(error, settings.setpoint, &line.materials[material].name))?;
    let mut state = orbit.state.clone();
    let hold = line.height_at(x_first) + orbit.z_nm;
    let (mut base_start, mut base_end) = (hold, hold);
    let mut filtered = settings.setpoint * a0;
    let mut integral = 0.0;
    let alpha = if pi.lockin_time_constant_ms > 0.0 {
        1.0 - (-period_us / (pi.lockin_time_constant_ms * US_PER_MS)).exp()
    } else {
        1.0
    };
    let period_ms = period_us / US_PER_MS;
    let mut workspace = SolverWorkspace::default();
    let mut pixels = Vec::with_capacity(settings.pixels * passes.len());
    for &direction in passes {
        let x_at = |k: usize| match direction {
            ScanDirection::Trace => start + k as f64 * travel,
            ScanDirection::Retrace => end - k as f64 * travel,
        };
        let pass_start = pixels.len();
        // The pixel's block of cycles and the sum of their mean base heights (nm).
        let mut average: Option<(usize, BlockAverage, f64)> = None;
        let mut bases = Vec::with_capacity(settings.pixels);
        for k in 0..cycles {
            let (x0, x1) = (x_at(k), x_at(k + 1));
            let x_mid = 0.5 * (x0 + x1);
            let material = line.material_at(x_mid);
            let z_start = base_start - line.height_at(x0);
            let z_end = base_end - line.height_at(x1);
            if !(z_end >= -a0 && z_end.is_finite()) {
                return Err(AfmError::NotReached {
                    what: format!("a stable PI loop at x = {x1:.3} nm"),
                    reason: format!(
                        "the controller drove Z to {z_end:.3} nm, below -A0 (the gains are too \
                         high for the loop to be stable: lower gain_p or gain_i_per_ms)"
                    ),
                });
            }
            let model = &mut models[material];
            model.set_separation(Separation::Ramp {
                z0_nm: z_start,
                rate_nm_per_us: (z_start - z_end) / period_us,
            })?;
            let reading = integrate_cycle(
                model,
                &pi.integration,
                &mut state,
                &mut workspace,
                &mut lockins[material],
            )?;
            let pixel = pixel_of(match direction {
                ScanDirection::Trace => k,
                ScanDirection::Retrace => cycles - 1 - k,
            });
            let (block, base_sum) = match &mut average {
                Some((p, block, base_sum)) if *p == pixel => (block, base_sum),
                _ => {
                    average = Some((pixel, BlockAverage::new(cycles_in_pixel[pixel], a0), 0.0));
                    let (_, block, base_sum) = average.as_mut().expect("just set");
                    (block, base_sum)
                }
            };
            *base_sum += 0.5 * (base_start + base_end);
            if let Some(done) = block.push(k as u64, 0.5 * (z_start + z_end), &reading) {
                let x = centres[pixel];
                bases.push(*base_sum / cycles_in_pixel[pixel] as f64);
                pixels.push(ScanPixel {
                    index: pixel,
                    x_nm: x,
                    direction,
                    sample: line.materials[line.material_at(x)].name.clone(),
                    height_true_nm: line.height_at(x),
                    height_nm: f64::NAN,
                    height_error_nm: f64::NAN,
                    z_nm: done.z_nm,
                    amplitude_ratio: done.amplitude_ratio,
                    phase_deg: done.phase_deg,
                    impacts_per_period: done.impacts_per_cycle,
                    peak_force_nn: done.peak_force_nn,
                    mean_force_nn: None,
                    dissipated_ev: done.dissipated_ev,
                    virial_ev: None,
                    max_indentation_nm: None,
                    mean_indentation_nm: None,
                    harmonics: done.harmonics[..done.harmonic_count]
                        .iter()
                        .enumerate()
                        .map(|(i, &[a, b])| Harmonic {
                            n: i + 1,
                            amplitude_nm: a.hypot(b),
                            phase_deg: b.atan2(a).to_degrees(),
                        })
                        .collect(),
                    multiplicity: 1,
                    stable: None,
                    jump: None,
                });
                if progress(pixels.len()) {
                    return Err(AfmError::Interrupted);
                }
            }
            // The lock-in's output, the error and the controller's next base.
            let amplitude = reading.cosine_nm.hypot(reading.sine_nm);
            filtered += alpha * (amplitude - filtered);
            let error = filtered - settings.setpoint * a0;
            integral += error * period_ms;
            base_start = base_end;
            base_end = hold - pi.gain_p * error - pi.gain_i_per_ms * integral;
        }
        if pixels.len() - pass_start != settings.pixels {
            return Err(AfmError::NotReached {
                what: format!("{} pixels in the PI pass", settings.pixels),
                reason: format!(
                    "{} were read: the cycles were not shared out among the pixels",
                    pixels.len() - pass_start
                ),
            });
        }
        set_heights_from_bases(&mut pixels[pass_start..], &bases);
    }
    Ok(pixels)
}
