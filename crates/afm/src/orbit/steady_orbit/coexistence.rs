//! Whether another orbit coexists with a found one at the same separation: the orbit the other
//! start of [`steady_orbit`] reaches ([`OrbitStart::Approach`] against
//! [`OrbitStart::Transient`]), when it is a different orbit.
//!
//! From a found stable orbit, the transient start needs no Newton to be told apart: its
//! periods from the free state are iterated one at a time, and once the iterate comes within
//! [`COEXISTING_DISTANCE`] of one of the orbit's period states it is inside the orbit's basin,
//! where every further period brings it closer (the multipliers are inside the unit circle), so
//! the transient start would converge to the same orbit. Only when it does not come that close
//! within the transient periods is the rest of the transient start (Newton from the iterate)
//! run, exactly as [`steady_orbit`] with [`OrbitStart::Transient`] runs it.
//!
//! Most transients enter the basin long before they come that close: a period or two from the
//! free state they already move as the orbit's linearisation moves them, `e_{k+1} = M e_k`
//! (`e_k = x_k - x*` the deviation from the orbit's state `x*` after `k` periods, `M` its
//! monodromy; Floquet theory, MODEL.md section 4), and the linearisation contracts every
//! deviation by the spectral radius `rho < 1` per period, up to transient growth. So the check
//! first follows the transient at [`LINEAR_SCOUT_TOLERANCE`] and stops as soon as two
//! consecutive periods, from deviations within [`LINEAR_REACH`] `A0`, each satisfy
//! `|e_{k+1} - M e_k| <= LINEAR_FRACTION (1 - rho) |e_k|`: the map's nonlinear remainder is
//! then a small fraction of the margin by which the linearisation contracts, at the largest
//! deviation left, so the remaining transient converges to the orbit (a period of another
//! impact sequence than the orbit's, or one heading for another attractor, departs from the
//! linearisation by an amount of the order of the deviation itself, and fails the test). Only
//! for a period-1 orbit with its monodromy ([`SteadyOrbit::monodromy`]). At the paper's Fig. 1
//! point `A/A0 = 0.9` the deviations are 2.7, 0.32, 0.039 nm with remainders 1.2e-2, 1.8e-3,
//! 1.6e-4 of the deviation, against the allowed `0.1 (1 - rho) = 0.089`: with the reach of
//! [`LINEAR_REACH`] `A0` the test passes after 2 periods (the first from the free state
//! itself; at `A/A0 = 0.5` too, whose first deviation is 3.5 nm), with 0.1 `A0` it took 3,
//! and the distance test below takes 7; a transient that fails it runs the distance test
//! from the start.
//!
//! The transient periods are first integrated at [`SCOUT_TOLERANCE`] (about 2.4 times fewer
//! steps of the order-8 methods than at 1e-12): the iterate's distance to the orbit is then
//! known to about that tolerance, far below [`COEXISTING_DISTANCE`], so it enters the basin
//! exactly when the full-tolerance iterate does (up to iterates within that tolerance of the
//! threshold, which enter it a period later either way). Only when this scout finds no entry
//! are the periods integrated again at the settings' tolerance, as above, so that the orbit
//! found, a coexisting one, is the same bits as before.

use hybrid::Settings;
use nalgebra::{DMatrix, DVector};

use super::period_maps::{iterate, SteadyOrbitWorkspace};
use super::{state_distance, steady_orbit, steady_orbit_in, OrbitStart, SteadyOrbit};
use super::{SteadyOrbitSettings, MAX_SEPARATION_NM};
use crate::error::AfmError;
use crate::model::separation::Separation;
use crate::model::TappingModel;

/// Two converged orbits at one `Z` are different orbits when their states at `t = 0` differ by
/// more than this (nm and nm/us): far above the 1e-10 residual of either, far below the
/// distance between coexisting orbits.
pub const COEXISTING_DISTANCE: f64 = 1e-6;

/// The integration tolerance (relative and absolute) of the scouting transient of the
/// coexistence check (module documentation): a thousandth of [`COEXISTING_DISTANCE`].
const SCOUT_TOLERANCE: f64 = 1e-9;

/// The integration tolerance (relative and absolute) of the transient compared with the
/// orbit's linearisation (module documentation): the period map's error, about ten times this
/// in nm, is below 1e-2 of the remainder the test allows (`0.1 (1 - rho) |e_k|`) at
/// deviations above 1e-2 nm for a spectral radius `rho` up to 0.9 (at `A/A0` = 0.9 and 0.5 the
/// test passes on deviations of 0.06 to 3.5 nm). An error can only fail a period that would
/// pass (the check then goes on to the distance test) or pass one whose remainder is within
/// the error of the bound.
const LINEAR_SCOUT_TOLERANCE: f64 = 1e-6;

/// The largest deviation from the orbit, in units of `A0`, at which a period of the transient
/// counts towards the linearisation test (module documentation). Farther out the test is
/// still decided by the measured remainder of two consecutive periods; the reach only keeps
/// deviations of the order of the whole orbit's size out of it. 0.4 lets the first period from
/// the free state count at the Fig. 1 points `A/A0 >= 0.5` (deviations 2.6 and 3.5 nm at
/// `A/A0` = 0.9 and 0.5, remainders 1.4e-2 and 7.4e-2 of them against the allowed 8.9e-2 and
/// 9.6e-2), so that the test passes after 2 periods there (`crates/afm/tests/coexistence.rs`
/// checks the fast check against the full one on every built-in case and inside the MAClever
/// bistable window).
const LINEAR_REACH: f64 = 0.4;

/// The largest nonlinear remainder of a period, `|e_{k+1} - M e_k| / |e_k|`, allowed by the
/// linearisation test, as a fraction of the contraction margin `1 - rho` (module
/// documentation).
const LINEAR_FRACTION: f64 = 0.1;

/// The consecutive periods that must each pass the linearisation test.
const LINEAR_PERIODS: usize = 2;

/// The smallest deviation from the orbit (nm, nm/us) at which the linearisation test is
/// tried: below it the error of a period map at [`LINEAR_SCOUT_TOLERANCE`] is no longer a
/// small part of the allowed remainder, and the distance test takes over.
const LINEAR_FLOOR: f64 = 1e3 * LINEAR_SCOUT_TOLERANCE;

/// The orbit that `other` (the start `orbit` was not found from: [`OrbitStart::Approach`] or
/// [`OrbitStart::Transient`]) reaches at `orbit`'s separation, if it is a converged orbit
/// different from `orbit` (by [`SteadyOrbit::is_same_orbit`] at [`COEXISTING_DISTANCE`]).
/// `None` also when either orbit did not converge or the other start fails.
pub fn coexisting_orbit(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    other: OrbitStart<'_>,
    settings: &SteadyOrbitSettings,
) -> Option<SteadyOrbit> {
    if !orbit.converged {
        return None;
    }
    let found = match other {
        OrbitStart::Transient if orbit.stable => transient_start(model, orbit, settings).ok()?,
        _ => steady_orbit(model, orbit.z_nm, other, settings).ok(),
    }?;
    (found.converged && !orbit.is_same_orbit(&found, COEXISTING_DISTANCE)).then_some(found)
}

/// The transient start's orbit at `orbit`'s separation, or `None` as soon as its transient
/// comes within [`COEXISTING_DISTANCE`] of the stable `orbit` (see the module's documentation).
fn transient_start(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    settings: &SteadyOrbitSettings,
) -> Result<Option<SteadyOrbit>, AfmError> {
    settings.validate()?;
    let z_nm = orbit.z_nm;
    if !(-model.free_amplitude_nm()..=MAX_SEPARATION_NM).contains(&z_nm) {
        return steady_orbit(model, z_nm, OrbitStart::Transient, settings).map(Some);
    }
    let mut at_z = model.clone();
    at_z.set_separation(Separation::Constant(z_nm))?;
    // The transient starts in the orbit's basin (the free orbit above first contact).
    let start = at_z.free_state();
    if orbit
        .period_states
        .iter()
        .any(|state| state_distance(state, &start) <= COEXISTING_DISTANCE)
    {
        return Ok(None);
    }
    let mut workspace = SteadyOrbitWorkspace::default();
    if let Some(monodromy) = orbit.monodromy.as_ref().filter(|_| orbit.multiplicity == 1) {
        let linear_scout = Settings {
            relative_tolerance: settings
                .integration
                .relative_tolerance
                .max(LINEAR_SCOUT_TOLERANCE),
            absolute_tolerance: settings
                .integration
                .absolute_tolerance
                .max(LINEAR_SCOUT_TOLERANCE),
            ..settings.integration.clone()
        };
        if follows_linearisation(
            &at_z,
            orbit,
            monodromy,
            settings.transient_periods,
            &linear_scout,
            &mut workspace,
        ) {
            return Ok(None);
        }
    }
    let scout = Settings {
        relative_tolerance: settings.integration.relative_tolerance.max(SCOUT_TOLERANCE),
        absolute_tolerance: settings.integration.absolute_tolerance.max(SCOUT_TOLERANCE),
        ..settings.integration.clone()
    };
    if enters_basin(
        &at_z,
        orbit,
        settings.transient_periods,
        &scout,
        &mut workspace,
    ) {
        return Ok(None);
    }
    let mut x = at_z.free_state();
    for _ in 0..settings.transient_periods {
        x = iterate(&at_z, &x, 1, &settings.integration, &mut workspace)?;
        let inside = orbit
            .period_states
            .iter()
            .any(|state| state_distance(state, &x) <= COEXISTING_DISTANCE);
        if inside {
            return Ok(None);
        }
    }
    // The transient start's own Newton from the same iterate (the map iterated one period at a
    // time gives the same bits as `transient_periods` periods at once).
    steady_orbit_in(model, z_nm, OrbitStart::Near(&x), settings, &mut workspace).map(Some)
}

/// Whether the transient of `model` from the free state, integrated with `integration` one
/// period at a time for at most `periods` periods, comes within [`COEXISTING_DISTANCE`] of one
/// of the stable `orbit`'s period states. A failed integration answers `false` (the caller
/// then runs the check at full tolerance).
fn enters_basin(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    periods: usize,
    integration: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> bool {
    let mut x = model.free_state();
    for _ in 0..periods {
        let Ok(next) = iterate(model, &x, 1, integration, workspace) else {
            return false;
        };
        x = next;
        if orbit
            .period_states
            .iter()
            .any(|state| state_distance(state, &x) <= COEXISTING_DISTANCE)
        {
            return true;
        }
    }
    false
}

/// Whether the transient of `model` from the free state, integrated with `integration` one
/// period at a time for at most `periods` periods, moves as the period-1 `orbit`'s
/// linearisation `monodromy` does for [`LINEAR_PERIODS`] consecutive periods from deviations
/// within [`LINEAR_REACH`] `A0` (the test of the module documentation). A failed integration,
/// an orbit without a contraction margin, or a deviation below [`LINEAR_FLOOR`] before the
/// test passes answers `false`.
fn follows_linearisation(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    monodromy: &DMatrix<f64>,
    periods: usize,
    integration: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> bool {
    let spectral_radius = orbit
        .multipliers
        .iter()
        .map(|m| m.norm())
        .fold(0.0, f64::max);
    let n = orbit.state.len();
    if spectral_radius.is_nan() || spectral_radius >= 1.0 || monodromy.shape() != (n, n) {
        return false;
    }
    let allowed = LINEAR_FRACTION * (1.0 - spectral_radius);
    let reach = LINEAR_REACH * model.free_amplitude_nm();
    let deviation =
        |x: &[f64]| DVector::from_iterator(n, x.iter().zip(&orbit.state).map(|(x, o)| x - o));
    let mut x = model.free_state();
    let mut e = deviation(&x);
    let mut passed = 0;
    for _ in 0..periods {
        let Ok(next) = iterate(model, &x, 1, integration, workspace) else {
            return false;
        };
        let e_next = deviation(&next);
        let size = e.norm();
        if size < LINEAR_FLOOR {
            return false;
        }
        let remainder = (&e_next - monodromy * &e).norm();
        if size <= reach && remainder <= allowed * size {
            passed += 1;
            if passed == LINEAR_PERIODS {
                return true;
            }
        } else {
            passed = 0;
        }
        x = next;
        e = e_next;
    }
    false
}
