//! The search for the attractor when period-1 Newton fails or finds a repelling orbit: the
//! stroboscopic map is iterated until a state recurs after `k` periods, then Newton is applied
//! to the `k`-th iterate; the orbit is reported at its least period.

use continuation::{floquet_multipliers, is_stable, shoot, HybridPeriodicProblem, Parametrised};
use hybrid::Sensitivity;
use nalgebra::Complex;

use super::newton::branch_tangent;
use super::period_maps::iterate;
use super::{state_distance, SteadyOrbit, SteadyOrbitSettings, SteadyOrbitWorkspace};
use crate::error::AfmError;
use crate::model::TappingModel;
use crate::orbit::observables::{observe_orbit_in, observe_period_in};

/// Iterate the map of `model` from `initial` until a state recurs after `k <=
/// max_multiplicity` periods and Newton on the `k`-th iterate converges from it; the orbit at
/// its least period. If none converges within `recurrence_periods`, the best attempt (or
/// `fallback`, the period-1 one, if it is better), reported as not converged.
pub(crate) fn recurrence_search(
    model: &TappingModel,
    initial: &[f64],
    fallback: Attempt,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<SteadyOrbit, AfmError> {
    // Each period, the smallest multiplicity whose state recurs is shot, leaving out those at
    // which an earlier shot failed from a recurrence less than [`RETRY_FACTOR`] times farther
    // (a transient nearing an attractor comes closer by factors; the ghost of a vanished orbit
    // does not).
    let mut states = Vec::with_capacity(settings.recurrence_periods + 1);
    let mut x = iterate(
        model,
        initial,
        settings.transient_periods,
        &settings.integration,
        workspace,
    )?;
    states.push(x.clone());
    let scale = model.free_amplitude_nm();
    let mut failed_at = vec![f64::INFINITY; settings.max_multiplicity + 1];
    // The best non-converged attempt.
    let mut best: Option<Attempt> = None;
    for _ in 0..settings.recurrence_periods {
        x = iterate(model, &x, 1, &settings.integration, workspace)?;
        states.push(x.clone());
        let last = states.len() - 1;
        let recurrence = (1..=settings.max_multiplicity.min(last))
            .map(|k| (k, state_distance(&states[last], &states[last - k])))
            .find(|&(k, distance)| {
                distance <= RECURRENCE_DISTANCE * scale && distance <= RETRY_FACTOR * failed_at[k]
            });
        let Some((k, distance)) = recurrence else {
            continue;
        };
        let (attempt, converged) = shoot_period(model, k, &states[last], settings)?;
        if converged {
            let attempt = minimal_period(model, attempt, settings, workspace)?;
            return finish(model, attempt, settings, workspace);
        }
        failed_at[k] = distance;
        if best.as_ref().is_none_or(|b| attempt.residual < b.residual) {
            best = Some(attempt);
        }
    }
    // No recurrence converged: report honestly, with the best attempt (or the period-1 one).
    let attempt = match best {
        Some(best) if best.residual < fallback.residual => best,
        _ => fallback,
    };
    let mut orbit = finish(model, attempt, settings, workspace)?;
    orbit.converged = false;
    Ok(orbit)
}

/// A state recurs after `k` periods when it comes within this fraction of `A0` of the state `k`
/// periods before; Newton on the `k`-th iterate is then tried from it.
const RECURRENCE_DISTANCE: f64 = 1e-4;

/// After a failed shot at multiplicity `k` from a recurrence `d` apart, the next shot at `k`
/// waits for a recurrence closer than this factor times `d`: a transient nearing an attractor
/// comes closer by factors, while at the ghost of an orbit that vanished at a fold every state
/// recurs loosely for thousands of periods, and shooting at each of them would cost seconds.
const RETRY_FACTOR: f64 = 0.1;

/// Newton on the `k`-th iterate of the stroboscopic map from `x`: the attempt and whether it
/// converged.
fn shoot_period(
    model: &TappingModel,
    k: usize,
    x: &[f64],
    settings: &SteadyOrbitSettings,
) -> Result<(Attempt, bool), AfmError> {
    let z_nm = model.parameter();
    let problem = HybridPeriodicProblem::new(model.clone(), k, settings.integration.clone())?;
    let shot = shoot(&problem, x, z_nm, &settings.newton)?;
    let attempt = Attempt {
        multiplicity: k,
        state: shot.state.as_slice().to_vec(),
        iterations: shot.iterations,
        residual: shot.residual,
        multipliers: floquet_multipliers(&shot.period_map.monodromy),
        tangent: branch_tangent(
            &shot.period_map.monodromy,
            shot.period_map.parameter_derivative.as_slice(),
            z_nm,
        ),
    };
    Ok((attempt, shot.converged))
}

/// A converged fixed point of the `k`-th iterate may be one of a shorter period `d` (a divisor
/// of `k`), found at `k` because Newton at `d` had failed from an earlier, farther state: the
/// orbit is then shot again at the least such `d` whose state recurs within
/// [`MINIMAL_PERIOD_DISTANCE`] times the Newton tolerance, so that its multiplicity is its
/// least period and its multipliers those of `P^d`.
fn minimal_period(
    model: &TappingModel,
    attempt: Attempt,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<Attempt, AfmError> {
    let k = attempt.multiplicity;
    let mut x = attempt.state.clone();
    for d in 1..k {
        x = iterate(model, &x, 1, &settings.integration, workspace)?;
        let recurs = state_distance(&x, &attempt.state)
            <= MINIMAL_PERIOD_DISTANCE * settings.newton.tolerance;
        if k.is_multiple_of(d) && recurs {
            let (shorter, converged) = shoot_period(model, d, &attempt.state, settings)?;
            if converged {
                return Ok(shorter);
            }
        }
    }
    Ok(attempt)
}

/// A converged period-`k` state that recurs after `d < k` periods within this many Newton
/// tolerances is an orbit of period `d`: the states of a true period-`k` orbit `d` periods
/// apart are distinct orbit points, far farther apart.
const MINIMAL_PERIOD_DISTANCE: f64 = 100.0;

/// A shooting's outcome on the `multiplicity`-th iterate of the map, before its observables.
pub(crate) struct Attempt {
    pub(crate) multiplicity: usize,
    pub(crate) state: Vec<f64>,
    pub(crate) iterations: usize,
    pub(crate) residual: f64,
    pub(crate) multipliers: Vec<Complex<f64>>,
    pub(crate) tangent: Option<Vec<f64>>,
}

/// Assemble the orbit: the observables of the whole orbit and of each of its `k` periods from
/// the converged state.
fn finish(
    model: &TappingModel,
    attempt: Attempt,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<SteadyOrbit, AfmError> {
    let mut periods = Vec::with_capacity(attempt.multiplicity);
    let mut period_states = Vec::with_capacity(attempt.multiplicity);
    let mut x = attempt.state.clone();
    for _ in 0..attempt.multiplicity {
        period_states.push(x.clone());
        let (flow, observables) = observe_period_in(
            model,
            0.0,
            &x,
            Sensitivity::None,
            &settings.integration,
            settings.harmonics,
            workspace.for_maps(Sensitivity::None),
        )?;
        periods.push(observables);
        x = flow.state;
    }
    let whole_orbit = if attempt.multiplicity == 1 {
        periods[0].clone()
    } else {
        observe_orbit_in(
            model,
            &attempt.state,
            attempt.multiplicity,
            &settings.integration,
            settings.harmonics,
            workspace.for_maps(Sensitivity::None),
        )?
        .1
    };
    Ok(SteadyOrbit {
        z_nm: model.parameter(),
        multiplicity: attempt.multiplicity,
        converged: attempt.residual <= settings.newton.tolerance,
        iterations: attempt.iterations,
        residual: attempt.residual,
        state: attempt.state,
        stable: is_stable(&attempt.multipliers),
        multipliers: attempt.multipliers,
        monodromy: None,
        tangent: attempt.tangent,
        whole_orbit,
        periods,
        period_states,
    })
}
