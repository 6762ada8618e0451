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
//! The transient periods are first integrated at [`SCOUT_TOLERANCE`] (about 2.4 times fewer
//! steps of the order-8 methods than at 1e-12): the iterate's distance to the orbit is then
//! known to about that tolerance, far below [`COEXISTING_DISTANCE`], so it enters the basin
//! exactly when the full-tolerance iterate does (up to iterates within that tolerance of the
//! threshold, which enter it a period later either way). Only when this scout finds no entry
//! are the periods integrated again at the settings' tolerance, as above, so that the orbit
//! found, a coexisting one, is the same bits as before.

use hybrid::Settings;

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
    let mut workspace = SteadyOrbitWorkspace::default();
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
