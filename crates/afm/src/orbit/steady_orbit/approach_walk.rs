//! The start of a steady-orbit search without a previous orbit: the orbit of the quasi-static
//! approach, the one `drumroll continue` and the paper report.
//!
//! Above the separation of first contact `Z_G1` the steady orbit is the free one, known in
//! closed form ([`crate::model::free_response::FreeResponse`]). Below it, the approach branch is walked down from the
//! free orbit at `Z_G1` in steps of `Z`: each step predicts the orbit by the tangent line of
//! the last one, its state plus the step times its slope `dx/dZ` (the free orbit's slope is
//! zero, since it does not depend on `Z`), corrects it by Newton on the stroboscopic map at a
//! loose tolerance, and keeps it if Newton converges within a few iterations to an orbit that
//! attracts. Steps grow to at most [`MAX_WALK_STEP`] `A0`, so that a prediction stays within
//! Newton's reach of its own branch's orbit. A step that fails is halved; where the step
//! falls below
//! [`MIN_WALK_STEP`] `A0`, the branch has ended (a fold, a period doubling) and the walk does
//! what the quasi-static approach does there: it jumps, by transient periods from the last
//! orbit, to the attractor that takes over, and walks on from it.
//!
//! The walk ends with the orbit at the requested `Z` converged at the walk's loose tolerance;
//! [`crate::orbit::steady_orbit`] converges it at full tolerance.

use continuation::{floquet_multipliers, is_stable, newton_update};
use hybrid::{Sensitivity, Settings};
use nalgebra::DVector;

use super::newton::{branch_tangent, newton_maps};
use super::period_maps::period_map;
use super::{steady_orbit_in, OrbitStart, SteadyOrbitSettings, SteadyOrbitWorkspace};
use crate::error::AfmError;
use crate::model::separation::Separation;
use crate::model::TappingModel;

/// The first step of the walk below `Z_G1`, in units of `A0`: the steps grow from it by
/// [`STEP_GROWTH`]. The first one is taken from the free orbit, whatever its length: the orbit
/// departs from the free one like the square root of the depth below the grazing at `Z_G1`,
/// so that no shorter step would give a closer prediction.
const INITIAL_WALK_STEP: f64 = 0.05;

/// The farthest below `Z_G1`, in units of `A0`, that the walk's first step, from the free
/// orbit itself, lands on the requested `Z` (twice [`INITIAL_WALK_STEP`]; the later steps,
/// from an orbit with its slope, land within the step grown by [`STEP_GROWTH`]). Where a
/// long-range force bends the approach branch away from the free orbit above `Z_G1`, Newton
/// from the free state can converge to another orbit that stays near it: on the built-in
/// silicon-air-polymer, 0.105 `A0` below `Z_G1` it finds the near-free orbit (`A/A0 = 0.999`)
/// beside the approach branch's (0.898), which the walk reaches over shorter steps.
const FIRST_LANDING: f64 = 0.1;

/// The longest step of the walk, in units of `A0`: long enough that the walk from its first
/// orbit (0.05 `A0` below `Z_G1`) reaches `A/A0 = 0.5` in one more step (on the paper's
/// Biolever on mica 0.68 `A0` below it, across the grazings of a second and a third impact),
/// short enough that Newton from the tangent line stays on the approach branch (the walk
/// reaches the same period-1 orbits as with steps of at most 0.25 `A0` on every built-in case,
/// docs/guide/performance.md; with 1 `A0` it did not).
const MAX_WALK_STEP: f64 = 0.7;

/// The shortest step, in units of `A0`, before the walk decides its branch has ended and jumps
/// by transients (a fold or a period doubling lies within this distance).
const MIN_WALK_STEP: f64 = 1e-3;

/// The factor by which a step grows after a successful one, up to [`MAX_WALK_STEP`]; a
/// remainder of the walk within the grown step is walked in one step.
const STEP_GROWTH: f64 = 4.0;

/// Newton's tolerance on a walk step's residual `|P(x) - x|`, in units of `A0`: the walk's
/// orbits only predict the next, so they need not be converged to the final tolerance.
const WALK_TOLERANCE: f64 = 1e-6;

/// Newton's tolerance on the residual of the walk's last step, the one that lands on the
/// requested `Z`, in units of `A0`: its orbit is where the full-tolerance Newton starts, which
/// takes one update and the final map only from a residual within about 3e-6 nm
/// ([`super::newton`]'s quadratic prediction with its assumed constant 1/nm), near the error
/// of the walk's maps at [`WALK_INTEGRATION_TOLERANCE`].
const LANDING_TOLERANCE: f64 = 1e-8;

/// The integration tolerance (relative and absolute) of the walk's period maps: well below
/// [`WALK_TOLERANCE`] `A0` for any `A0` above 1 nm.
const WALK_INTEGRATION_TOLERANCE: f64 = 1e-7;

/// Newton iterations per walk step before the step is rejected.
const WALK_ITERATIONS: usize = 4;

/// Where the walk leaves the search for the orbit at the requested `Z`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum WalkEnd {
    /// The approach branch's period-1 orbit at `Z` converged at the walk's loose tolerance (or
    /// the free orbit itself above `Z_G1`): Newton starts from it at full tolerance.
    Predicted(Vec<f64>),
    /// The state of an attractor at a `Z` above the requested one that is not a period-1
    /// orbit (the approach jumped to it at the end of its period-1 branch): the search goes on
    /// from it like from a neighbouring orbit.
    Near(Vec<f64>),
}

/// One orbit of the walk: the separation (nm), the state at `t = 0` and its slope `dx/dZ`
/// (empty for the landing orbit, whose slope predicts nothing).
#[derive(Debug, Clone)]
struct WalkPoint {
    z_nm: f64,
    state: Vec<f64>,
    slope: Vec<f64>,
}

/// Walk the approach branch of `model` from the free orbit at `Z_G1` down to `z_nm` and
/// predict its orbit there (see the module documentation).
pub(crate) fn walk_approach(
    model: &TappingModel,
    z_nm: f64,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<WalkEnd, AfmError> {
    let free = model.free_state();
    let z_g1 = model.grazing_separation_nm();
    if z_nm >= z_g1 {
        return Ok(WalkEnd::Predicted(free));
    }
    let amplitude = model.free_amplitude_nm();
    let mut last = WalkPoint {
        z_nm: z_g1,
        slope: vec![0.0; free.len()],
        state: free,
    };
    let mut step = INITIAL_WALK_STEP * amplitude;
    while last.z_nm > z_nm {
        // A remainder within the step the walk would grow to is taken at once, rather than
        // as this step and a shorter one after it.
        let landing_reach = if last.z_nm == z_g1 {
            FIRST_LANDING * amplitude
        } else {
            (step * STEP_GROWTH).min(MAX_WALK_STEP * amplitude)
        };
        let z_next = if last.z_nm - z_nm <= landing_reach {
            z_nm
        } else {
            last.z_nm - step
        };
        let mut at_next = model.clone();
        at_next.set_separation(Separation::Constant(z_next))?;
        let prediction = predict(z_next, &last);
        let landing = z_next == z_nm;
        let tolerance = if landing {
            LANDING_TOLERANCE
        } else {
            WALK_TOLERANCE
        } * amplitude;
        // The landing orbit predicts nothing: its slope is not computed.
        if let Some(point) = corrected(&at_next, &prediction, tolerance, !landing, workspace)? {
            if landing {
                return Ok(WalkEnd::Predicted(point.state));
            }
            step = (step * STEP_GROWTH).min(MAX_WALK_STEP * amplitude);
            last = point;
        } else if step / 2.0 >= MIN_WALK_STEP * amplitude {
            step /= 2.0;
        } else {
            // The branch ends within the shortest step: jump as the approach does.
            let attractor = steady_orbit_in(
                &at_next,
                z_next,
                OrbitStart::Near(&last.state),
                settings,
                workspace,
            )?;
            match attractor.tangent {
                Some(slope)
                    if attractor.converged && attractor.stable && attractor.multiplicity == 1 =>
                {
                    last = WalkPoint {
                        z_nm: z_next,
                        state: attractor.state,
                        slope,
                    };
                    step = INITIAL_WALK_STEP * amplitude;
                }
                _ => return Ok(WalkEnd::Near(attractor.state)),
            }
        }
    }
    Ok(WalkEnd::Predicted(last.state))
}

/// The state at `z_nm` predicted from the walk's last orbit by its tangent line,
/// `x + (z_nm - Z) dx/dZ`. Over the walk's steps, which grow by [`STEP_GROWTH`], it is closer
/// than the cubic Hermite extrapolation of the last two orbits with their slopes, which
/// reaches `1 + STEP_GROWTH` of their interval beyond them (on the paper's Biolever on mica,
/// walking 10.01 -> 9.51 -> 8.51 -> 6.51 -> 4.01 -> 2.73 nm, Newton's first residuals from the
/// cubic were 11.8, 6.1 and 0.52 nm over the last three steps, from the tangent line 3.0, 0.61
/// and 0.51 nm).
fn predict(z_nm: f64, last: &WalkPoint) -> Vec<f64> {
    last.state
        .iter()
        .zip(&last.slope)
        .map(|(x, s)| x + (z_nm - last.z_nm) * s)
        .collect()
}

/// Newton from `prediction` on the period map of `model` (at its separation) to `tolerance`
/// (nm, nm/us: [`WALK_TOLERANCE`] or [`LANDING_TOLERANCE`] `A0`), the maps integrated at
/// [`WALK_INTEGRATION_TOLERANCE`]. Once two residuals measure Newton's constant `C`
/// (`r_k = C r_{k-1}^2`), an iterate whose predicted residual `C r_k^2` is below the tolerance
/// is taken without a map of its own; its slope and stability are those of the map before,
/// which is as close to the orbit as a walk's prediction needs. The orbit with its slope
/// `dx/dZ` if `with_slope` (the maps then carry `dP/dZ`; else the slope is left empty), or
/// `None` if Newton does not converge within [`WALK_ITERATIONS`] or the orbit repels.
fn corrected(
    model: &TappingModel,
    prediction: &[f64],
    tolerance: f64,
    with_slope: bool,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<Option<WalkPoint>, AfmError> {
    let sensitivity = if with_slope {
        Sensitivity::TransitionAndParameter
    } else {
        Sensitivity::Transition
    };
    let integration = newton_maps(&Settings {
        relative_tolerance: WALK_INTEGRATION_TOLERANCE,
        absolute_tolerance: WALK_INTEGRATION_TOLERANCE,
        ..Settings::default()
    });
    let z_nm = model.separation().at(0.0);
    let mut x = prediction.to_vec();
    let mut previous_residual = f64::INFINITY;
    for _ in 0..=WALK_ITERATIONS {
        let Ok(map) = period_map(model, &x, sensitivity, &integration, workspace) else {
            return Ok(None);
        };
        let residual =
            DVector::from_iterator(x.len(), map.state.iter().zip(&x).map(|(p, x)| p - x));
        let size = residual.norm();
        if !size.is_finite() || size >= previous_residual {
            return Ok(None);
        }
        let converged = size <= tolerance;
        // Newton's constant is measured only once there are two residuals.
        let next_converged = previous_residual.is_finite()
            && size / (previous_residual * previous_residual) * size * size <= tolerance;
        if converged || next_converged {
            if next_converged && !converged {
                let Ok(update) = newton_update(&map.transition, &residual, z_nm) else {
                    return Ok(None);
                };
                x.iter_mut().zip(update.iter()).for_each(|(x, u)| *x -= u);
            }
            if !is_stable(&floquet_multipliers(&map.transition)) {
                return Ok(None);
            }
            let slope = if with_slope {
                branch_tangent(&map.transition, &map.parameter_sensitivity, z_nm)
            } else {
                Some(Vec::new())
            };
            return Ok(slope.map(|slope| WalkPoint {
                z_nm,
                state: x,
                slope,
            }));
        }
        previous_residual = size;
        let Ok(update) = newton_update(&map.transition, &residual, z_nm) else {
            return Ok(None);
        };
        x.iter_mut().zip(update.iter()).for_each(|(x, u)| *x -= u);
    }
    Ok(None)
}
