//! The separation at which a slow approach reaches a given amplitude ratio `A/A0`: `Z` decreases
//! from first contact in steps, each steady orbit started from the previous one (as the
//! paper's slow approach does, so that a fold is jumped over the way an instrument jumps), and
//! the crossing of `A/A0 = R` is then bracketed and refined by the secant/bisection hybrid
//! (Illinois) on `Z`.

use crate::error::AfmError;
use crate::model::TappingModel;
use crate::steady_orbit::{steady_orbit, SteadyOrbit, SteadyOrbitSettings};

/// What [`find_amplitude_ratio`] looks for, and how. Built by [`AmplitudeRatioSearch::new`],
/// which checks the ranges.
#[derive(Debug, Clone, PartialEq)]
pub struct AmplitudeRatioSearch {
    /// The target `R = A/A0`, in (0, 1).
    pub ratio: f64,
    /// The approach step in `Z` as a fraction of `A0` (default 0.005, i.e. 0.05 nm for the
    /// Biolever's A0 = 10 nm); halved down to 1/1024 of itself where Newton from the previous
    /// orbit fails.
    pub step_fraction: f64,
    /// The lowest separation the approach goes to, as a fraction of `A0` (default -1: the
    /// cantilever's base a full free amplitude below the undeformed sample surface).
    pub floor_fraction: f64,
    /// Tolerance on `Z` of the refined crossing, nm (default 1e-9).
    pub z_tolerance_nm: f64,
}

impl AmplitudeRatioSearch {
    /// A search for `A/A0 = ratio` with the default step, floor and tolerance.
    pub fn new(ratio: f64) -> Result<Self, AfmError> {
        if !(ratio > 0.0 && ratio < 1.0) {
            return Err(AfmError::InvalidField {
                file: String::from("amplitude-ratio search"),
                field: String::from("amplitude_ratio"),
                value: ratio.to_string(),
                allowed: String::from(
                    "0 < R < 1 (A/A0 is 1 at first contact and falls as Z decreases)",
                ),
            });
        }
        Ok(Self {
            ratio,
            step_fraction: 0.005,
            floor_fraction: -1.0,
            z_tolerance_nm: 1e-9,
        })
    }
}

/// The steady orbit on the approach branch where `A/A0` first falls to `search.ratio`.
///
/// Errors when the approach reaches its floor first, when a step cannot be converged even at
/// the smallest step, or when the ratio lies inside a jump of the approach curve (a fold: the
/// branch jumps from above `R` to below it, and no steady orbit on it has `A/A0 = R`).
pub fn find_amplitude_ratio(
    model: &TappingModel,
    search: &AmplitudeRatioSearch,
    settings: &SteadyOrbitSettings,
) -> Result<SteadyOrbit, AfmError> {
    let a0 = model.free_amplitude_nm();
    let ratio_of = |orbit: &SteadyOrbit| orbit.lockin(a0).0;
    let step = search.step_fraction * a0;
    let floor = search.floor_fraction * a0;
    let mut above = steady_orbit(
        model,
        model.grazing_separation_nm(),
        Some(&model.free_state()),
        settings,
    )?;
    let mut h = step;
    loop {
        if above.z_nm - h < floor {
            return Err(AfmError::NotReached {
                what: format!("A/A0 = {}", search.ratio),
                reason: format!(
                    "the approach reached its floor Z = {floor} nm with A/A0 = {:.6}",
                    ratio_of(&above)
                ),
            });
        }
        let next = steady_orbit(model, above.z_nm - h, Some(&above.state), settings)?;
        if !next.converged || next.multiplicity != above.multiplicity {
            if h > step / 1024.0 {
                h *= 0.5;
                continue;
            }
            if !next.converged {
                return Err(AfmError::NotReached {
                    what: format!("A/A0 = {}", search.ratio),
                    reason: format!("no converged steady orbit at Z = {} nm", next.z_nm),
                });
            }
        }
        if ratio_of(&next) <= search.ratio {
            return refine(model, search, settings, above, next);
        }
        above = next;
        h = (2.0 * h).min(step);
    }
}

/// Refine the bracket `above` (A/A0 > R) / `below` (A/A0 <= R) by the Illinois method on Z,
/// each orbit started from the bracket end nearer in Z.
fn refine(
    model: &TappingModel,
    search: &AmplitudeRatioSearch,
    settings: &SteadyOrbitSettings,
    mut above: SteadyOrbit,
    mut below: SteadyOrbit,
) -> Result<SteadyOrbit, AfmError> {
    let a0 = model.free_amplitude_nm();
    let f = |orbit: &SteadyOrbit| orbit.lockin(a0).0 - search.ratio;
    let (mut fa, mut fb) = (f(&above), f(&below));
    let mut side = 0i8;
    for _ in 0..200 {
        if (above.z_nm - below.z_nm).abs() <= search.z_tolerance_nm || fb == 0.0 {
            break;
        }
        let mut z = (below.z_nm * fa - above.z_nm * fb) / (fa - fb);
        if !(z < above.z_nm && z > below.z_nm) {
            z = 0.5 * (above.z_nm + below.z_nm);
        }
        let start = if above.z_nm - z < z - below.z_nm {
            &above.state
        } else {
            &below.state
        };
        let trial = steady_orbit(model, z, Some(start), settings)?;
        let ft = f(&trial);
        if ft > 0.0 {
            above = trial;
            fa = ft;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            below = trial;
            fb = ft;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    let jump = (f(&above) - f(&below)).abs();
    if jump > 1e-6 {
        return Err(AfmError::NotReached {
            what: format!("A/A0 = {}", search.ratio),
            reason: format!(
                "the approach curve jumps over it at Z = {:.9} nm (from A/A0 = {:.6} to {:.6}): a fold",
                below.z_nm,
                f(&above) + search.ratio,
                f(&below) + search.ratio
            ),
        });
    }
    Ok(if fa.abs() < fb.abs() { above } else { below })
}
