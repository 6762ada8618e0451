//! The ideal feedback (MODEL.md section 12): at every pixel the steady orbit whose `A/A0` is
//! the setpoint, reached from the previous pixel's orbit as a slow feedback reaches it
//! ([`SetpointBranch::follow`]): over one material nothing changes from pixel to pixel; where
//! the material changes, the cantilever settles on the new material at the old `Z`, and the
//! feedback walks the new material's branch to the setpoint, jumping where its stable part
//! ends. The first pass engages by a slow approach at its first pixel; a retrace after a
//! trace goes on from where the trace ended.

use rayon::prelude::*;

use crate::error::AfmError;
use crate::model::case::Case;
use crate::orbit::steady_orbit::{SteadyOrbit, SteadyOrbitWorkspace};
use crate::scan::line::ScanLine;
use crate::scan::materials::line_models;
use crate::scan::pixel::{set_measured_heights, ScanDirection, ScanPixel};
use crate::scan::setpoint_branch::{on_sample, SetpointBranch};
use crate::scan::settings::ScanSettings;
use crate::sweep::amplitude_ratio::AmplitudeRatioSearch;

/// The ideal-feedback scan of `line` with the cantilever, drive and free amplitude of `case`
/// (its sample is replaced by the line's): the pixels of each pass in scan order, trace
/// first.
pub fn ideal_scan(
    case: &Case,
    line: &ScanLine,
    settings: &ScanSettings,
) -> Result<Vec<ScanPixel>, AfmError> {
    ideal_scan_until(case, line, settings, &mut |_| false)
}

/// As [`ideal_scan`], telling `progress` the number of pixels done after each pixel; when it
/// answers `true` the scan ends with [`AfmError::Interrupted`].
pub fn ideal_scan_until(
    case: &Case,
    line: &ScanLine,
    settings: &ScanSettings,
    progress: &mut dyn FnMut(usize) -> bool,
) -> Result<Vec<ScanPixel>, AfmError> {
    settings.validate()?;
    let models = line_models(case, line)?;
    let search = AmplitudeRatioSearch::new(settings.setpoint)?;
    let centres = line.pixel_centres(settings.pixels);
    // Each material under a pixel needs its branch (a diagram of its own): they are computed
    // in parallel, and a material's error is returned where the scan first reaches it, as if
    // its branch were computed there.
    let mut branches: Vec<Option<SetpointBranch>> = Vec::with_capacity(models.len());
    let mut errors: Vec<Option<AfmError>> = Vec::with_capacity(models.len());
    for result in (0..models.len())
        .into_par_iter()
        .map(|material| {
            centres
                .iter()
                .any(|&x| line.material_at(x) == material)
                .then(|| {
                    SetpointBranch::new(&models[material], &search, &settings.orbit).map_err(
                        |error| on_sample(error, settings.setpoint, &line.materials[material].name),
                    )
                })
        })
        .collect::<Vec<_>>()
    {
        let (branch, error) = match result {
            Some(Ok(branch)) => (Some(branch), None),
            Some(Err(error)) => (None, Some(error)),
            None => (None, None),
        };
        branches.push(branch);
        errors.push(error);
    }
    let workspace = &mut SteadyOrbitWorkspace::default();
    let a0 = case.free_amplitude_nm;
    let mut pixels = Vec::with_capacity(centres.len() * settings.directions.passes().len());
    // The material and orbit the cantilever is on, and where (nm).
    let mut current: Option<(usize, SteadyOrbit, f64)> = None;
    for &direction in settings.directions.passes() {
        let order: Vec<usize> = match direction {
            ScanDirection::Trace => (0..centres.len()).collect(),
            ScanDirection::Retrace => (0..centres.len()).rev().collect(),
        };
        let pass_start = pixels.len();
        for index in order {
            let x = centres[index];
            let material = line.material_at(x);
            if let Some(error) = errors[material].take() {
                return Err(error);
            }
            let Some(branch) = branches[material].as_ref() else {
                unreachable!("every material under a pixel has its branch or its error");
            };
            let (orbit, jump) = match &current {
                None => branch
                    .engage(workspace)
                    .map_err(|error| branch.named(error))?,
                Some((on, orbit, _)) if *on == material => (orbit.clone(), None),
                // A new material: the base is held across the boundary, so the tip arrives
                // at the old Z less the height's step there (0 across a ramp).
                Some((_, orbit, from)) => branch
                    .follow(
                        orbit.z_nm - line.height_step_between(*from, x),
                        &orbit.state,
                        workspace,
                    )
                    .map_err(|error| branch.named(error))?,
            };
            pixels.push(ScanPixel::of_orbit(
                index,
                x,
                direction,
                &line.materials[material].name,
                line.height_at(x),
                &orbit,
                a0,
                jump,
            ));
            current = Some((material, orbit, x));
            if progress(pixels.len()) {
                return Err(AfmError::Interrupted);
            }
        }
        set_measured_heights(&mut pixels[pass_start..]);
    }
    Ok(pixels)
}
