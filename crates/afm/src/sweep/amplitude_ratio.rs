//! The separation at which a slow approach reaches a given amplitude ratio `A/A0`: the approach
//! branch (pseudo-arclength continuation from first contact, `Z` decreasing) is walked through
//! its stable points in order, as the paper's slow approach meets them (an unstable part
//! between folds is jumped over, the way an instrument jumps), and the crossing of `A/A0 = R`
//! is bracketed and refined by the secant/bisection hybrid (Illinois) on `Z`.

use crate::diagram::bifurcation_diagram::{approach_diagram, DiagramSettings};
use crate::error::AfmError;
use crate::model::TappingModel;
use crate::orbit::prediction::hermite_state;
use crate::orbit::steady_orbit::{
    steady_orbit_in, OrbitStart, SteadyOrbit, SteadyOrbitSettings, SteadyOrbitWorkspace,
};
use crate::validation::invalid;

/// What [`find_amplitude_ratio`] looks for, and how. Built by [`AmplitudeRatioSearch::new`],
/// which checks the ranges.
#[derive(Debug, Clone, PartialEq)]
pub struct AmplitudeRatioSearch {
    /// The target `R = A/A0`, in (0, 1).
    pub ratio: f64,
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
            return Err(invalid(
                "amplitude-ratio search",
                "amplitude_ratio",
                ratio,
                String::from("0 < R < 1 (A/A0 is 1 at first contact and falls as Z decreases)"),
            ));
        }
        Ok(Self {
            ratio,
            floor_fraction: -1.0,
            z_tolerance_nm: 1e-9,
        })
    }

    /// The approach diagram's settings for this search on `model`: from first contact down to
    /// `A/A0 = ratio - 0.05` (at least 0) or `Z = floor_fraction * A0` (nm), whichever comes
    /// first, each orbit with `settings`. The branch that [`find_amplitude_ratio`] and the
    /// scan's setpoint branch (`crate::scan::setpoint_branch`) walk.
    pub fn diagram_settings(
        &self,
        model: &TappingModel,
        settings: &SteadyOrbitSettings,
    ) -> DiagramSettings {
        DiagramSettings {
            orbit: settings.clone(),
            z_limit_nm: self.floor_fraction * model.free_amplitude_nm(),
            min_amplitude_ratio: (self.ratio - 0.05).max(0.0),
            ..DiagramSettings::approach(model)
        }
    }
}

/// The steady orbit on the approach branch where `A/A0` first falls to `search.ratio`.
///
/// The branch is the pseudo-arclength continuation of the periodic orbit from above first
/// contact with `Z` decreasing ([`approach_diagram`]); its stable points are walked in branch
/// order, as a slow approach meets them, and the first pair of consecutive stable points that
/// brackets the ratio is refined on `Z`. Errors when the branch ends first, or when the ratio
/// lies only in a jump of the approach (an unstable part of the branch between folds, which a
/// slow approach jumps over).
pub fn find_amplitude_ratio(
    model: &TappingModel,
    search: &AmplitudeRatioSearch,
    settings: &SteadyOrbitSettings,
) -> Result<SteadyOrbit, AfmError> {
    let branch = approach_diagram(model, &search.diagram_settings(model, settings))?;
    let bracket = branch.points.windows(2).find(|pair| {
        pair[0].stable
            && pair[1].stable
            && pair[0].amplitude_ratio > search.ratio
            && pair[1].amplitude_ratio <= search.ratio
    });
    let Some([above, below]) = bracket else {
        let lowest = branch
            .points
            .iter()
            .map(|p| p.amplitude_ratio)
            .fold(f64::INFINITY, f64::min);
        let reason = if lowest <= search.ratio {
            String::from("the ratio is crossed only on an unstable part of the branch (a jump of the approach between folds)")
        } else {
            format!(
                "the branch ended ({}) with A/A0 >= {lowest:.6}{}",
                branch.stop,
                branch
                    .error
                    .as_deref()
                    .map(|e| format!(": {e}"))
                    .unwrap_or_default()
            )
        };
        return Err(AfmError::NotReached {
            what: format!("A/A0 = {}", search.ratio),
            reason,
        });
    };
    // One workspace for the refinement's sequence of orbits; the bracket's ends as steady
    // orbits (with their slopes dx/dZ, for the refinement's predictions).
    let workspace = &mut SteadyOrbitWorkspace::default();
    let mut orbit_at = |z_nm: f64, state: &[f64]| {
        steady_orbit_in(model, z_nm, OrbitStart::Near(state), settings, workspace)
    };
    let above = orbit_at(above.z_nm, &above.state)?;
    let below = orbit_at(below.z_nm, &below.state)?;
    refine_ratio_bracket(model, search, settings, above, below, workspace)
}

/// Refine the bracket `above` (A/A0 > R) / `below` (A/A0 <= R) by the Illinois method on Z,
/// each orbit started from the cubic Hermite interpolation of the bracket's two orbits
/// ([`hermite_state`]), or from the end nearer in Z if one of them has no tangent. `above`
/// must lie at the larger `Z`; errors when the bracket holds a jump of `A/A0` (a fold). Also
/// the ideal scan's last step onto its setpoint (`crate::scan`).
pub(crate) fn refine_ratio_bracket(
    model: &TappingModel,
    search: &AmplitudeRatioSearch,
    settings: &SteadyOrbitSettings,
    mut above: SteadyOrbit,
    mut below: SteadyOrbit,
    workspace: &mut SteadyOrbitWorkspace,
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
        let prediction = hermite_state(z, &below, &above);
        let start = match &prediction {
            Some(state) => OrbitStart::Predicted(state),
            None if above.z_nm - z < z - below.z_nm => OrbitStart::Near(&above.state),
            None => OrbitStart::Near(&below.state),
        };
        let trial = steady_orbit_in(model, z, start, settings, workspace)?;
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
