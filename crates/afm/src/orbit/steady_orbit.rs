//! The steady periodic orbit of the tapping cantilever at a fixed separation `Z`: transient
//! periods from a sensible start, then Newton (shooting) on the stroboscopic map
//! `x -> x(T)` with the exact monodromy matrix from the hybrid solver, and the orbit's
//! observables (MODEL.md sections 4 and 5).
//!
//! An orbit that is not period-1 (period doubling, a period-k window) is found by iterating the
//! map until a state recurs after `k` periods, then shooting on the `k`-th iterate; an orbit that
//! settles on none within the budget is reported as not converged, never dressed up as one.

mod approach_walk;
mod coexistence;
mod newton;
mod orbit;
mod period_maps;
mod recurrence;

use continuation::{floquet_multipliers, is_stable, NewtonSettings, Parametrised};
use hybrid::{HybridSystem, Mode, Settings};

pub use coexistence::{coexisting_orbit, COEXISTING_DISTANCE};
pub use orbit::{PeriodBreakdown, SteadyOrbit};
pub use period_maps::SteadyOrbitWorkspace;

use crate::contact::law::ContactLaw;
use crate::error::AfmError;
use crate::model::separation::Separation;
use crate::model::{TappingModel, ATTACHED, PULL_OFF_SURFACE};
use crate::validation::invalid;
use approach_walk::{walk_approach, WalkEnd};
use newton::shoot_observed;
use period_maps::iterate;
use recurrence::{recurrence_search, Attempt};

/// `TappingModel` as a parametrised periodic system for shooting and continuation: the
/// parameter is the separation `Z` (nm), the period is the drive period `T` (us), and the
/// contact surface is the gap `d = Z + sum_i q_i` (surface 0).
impl Parametrised for TappingModel {
    fn parameter(&self) -> f64 {
        self.separation().at(0.0)
    }

    fn set_parameter(&mut self, p: f64) {
        // A finite p always gives a valid constant separation; a non-finite one is rejected by
        // the solver's non-finite state check on the first step.
        let _ = self.set_separation(Separation::Constant(p));
    }

    fn period(&self) -> f64 {
        self.period_us()
    }

    /// JKR's pull-off surface while attached (MODEL.md section 9, JKR): its maxima make the
    /// `pull-off` grazing (section 8). `None` for every other law.
    fn release_surface(&self) -> Option<(usize, Mode)> {
        matches!(self.contact_force().law, ContactLaw::Jkr(_))
            .then_some((PULL_OFF_SURFACE, ATTACHED))
    }
}

/// The largest separation a steady orbit is computed at, nm (far above first contact the orbit is
/// the free one; the bound keeps the gap's rounding meaningful).
pub const MAX_SEPARATION_NM: f64 = 1e6;

/// How the steady orbit is searched for. Every field is checked by
/// [`SteadyOrbitSettings::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyOrbitSettings {
    /// Settings of the hybrid solver (tolerances 1e-12 by default, so that the period map is
    /// accurate well below the Newton tolerance).
    pub integration: Settings,
    /// Newton on the stroboscopic map; the tolerance is on the state residual
    /// `|P(x) - x|` in nm and nm/us (default 1e-10, the brief's target).
    pub newton: NewtonSettings,
    /// Periods integrated from the free orbit's state before Newton for [`OrbitStart::Transient`] (default 20; the slowest free decay,
    /// `exp(-w_1 t / (2 Q_1))`, loses a factor `exp(-pi / Q_1)` per period, about 1e-36 over 20
    /// periods for the paper's cantilevers). Range 0..=100000.
    pub transient_periods: usize,
    /// Periods iterated to find a recurrence when the period-1 orbit is not the attractor
    /// (default 4000: 5e-8 nm below the MAClever-on-mica fold, the transients pass the ghost
    /// of the orbit that vanished there within them and converge, in 0.07 s in all; with 400
    /// they did not even 1e-6 nm below it). Range 1..=1000000.
    pub recurrence_periods: usize,
    /// The largest multiplicity `k` (orbit period `k T`) searched for (default 8). Range 1..=64.
    pub max_multiplicity: usize,
    /// The harmonics `1..=harmonics` of `u` in the orbit's observables (default 4, as
    /// `drumroll simulate --harmonics`). Range 1..=1000.
    pub harmonics: usize,
}

impl Default for SteadyOrbitSettings {
    fn default() -> Self {
        Self {
            integration: Settings::default(),
            newton: NewtonSettings::default(),
            transient_periods: 20,
            recurrence_periods: 4000,
            max_multiplicity: 8,
            harmonics: 4,
        }
    }
}

impl SteadyOrbitSettings {
    /// Check every field against its documented range.
    pub fn validate(&self) -> Result<(), AfmError> {
        self.integration.validate()?;
        self.newton.validate()?;
        let checks = [
            ("transient_periods", self.transient_periods, 0, 100_000),
            ("recurrence_periods", self.recurrence_periods, 1, 1_000_000),
            ("max_multiplicity", self.max_multiplicity, 1, 64),
            ("harmonics", self.harmonics, 1, 1000),
        ];
        for (field, value, low, high) in checks {
            if !(low..=high).contains(&value) {
                return Err(AfmError::InvalidField {
                    file: String::from("steady-orbit settings"),
                    field: field.to_string(),
                    value: value.to_string(),
                    allowed: format!("an integer in {low}..={high}"),
                });
            }
        }
        Ok(())
    }
}

/// Where Newton on the stroboscopic map starts, and so how its first period map is
/// integrated (see [`steady_orbit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrbitStart<'a> {
    /// The orbit of the quasi-static approach, without a previous orbit: the free orbit above
    /// first contact, else the approach branch walked down from it in steps of `Z`, each a
    /// loose Newton from the tangent-line prediction of the last orbit, jumping by transients
    /// where the branch ends (a fold), as the quasi-static approach does.
    Approach,
    /// The attractor a transient from the free steady state reaches: `transient_periods`
    /// periods from the free orbit's state at `Z`, then Newton. Where orbits coexist, it may
    /// be another than the approach's.
    Transient,
    /// A state near the orbit, such as a neighbouring orbit's on the branch. From an orbit
    /// 0.01 nm away in `Z` at the paper's Fig. 1 points the state is 3e-4 to 2e-2 nm off,
    /// so the first Newton map, whose only use is the first update, is integrated at a loose
    /// tolerance (inexact Newton, see `shoot_observed`).
    Near(&'a [f64]),
    /// A state predicted to within about 1e-6 nm of the orbit, such as the cubic Hermite
    /// extrapolation from two orbits along the branch ([`crate::orbit::prediction`]): the
    /// first map is integrated at full tolerance, and when its residual is small enough for
    /// one Newton update to converge, the next map is the last (two period maps in all
    /// instead of three). A worse prediction costs a map, never accuracy: convergence is
    /// decided by measured residuals only.
    Predicted(&'a [f64]),
    /// `transient_periods` periods integrated from this state before Newton, as [`Self::Transient`]
    /// does from the free state: the attractor whose basin holds the state rather than the
    /// orbit nearest to it, as a quasi-static sweep of `Z` follows it (a neighbouring cell's
    /// orbit, [`crate::diagram::quasi_static`]).
    AfterTransients(&'a [f64]),
}

impl<'a> OrbitStart<'a> {
    /// `Near(x)` for `Some(x)`, `Transient` for `None`.
    pub fn near_or_transient(state: Option<&'a [f64]>) -> Self {
        state.map_or(Self::Transient, Self::Near)
    }

    /// The name of the start in outputs: `approach`, `transient`, `near` or `predicted`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Approach => "approach",
            Self::Transient => "transient",
            Self::Near(_) => "near",
            Self::Predicted(_) => "predicted",
            Self::AfterTransients(_) => "after-transients",
        }
    }
}

/// The steady orbit of `model` at separation `z_nm`.
///
/// Newton starts from `start` (see [`OrbitStart`]): without a previous orbit,
/// [`OrbitStart::Approach`] gives the orbit of the quasi-static approach and
/// [`OrbitStart::Transient`] the attractor after `transient_periods` periods from the free
/// steady state. If Newton does not converge, or
/// converges to an orbit that repels (so that it is not what a cantilever would settle on),
/// the map is iterated until a state recurs after `k <= max_multiplicity` periods and Newton
/// is applied to the `k`-th iterate.
pub fn steady_orbit(
    model: &TappingModel,
    z_nm: f64,
    start: OrbitStart<'_>,
    settings: &SteadyOrbitSettings,
) -> Result<SteadyOrbit, AfmError> {
    steady_orbit_in(
        model,
        z_nm,
        start,
        settings,
        &mut SteadyOrbitWorkspace::default(),
    )
}

/// As [`steady_orbit`], the period maps' solver buffers taken from `workspace` and handed back
/// to it: the same orbit, without a new solver's allocations per map. For a sequence of
/// orbits, as along a branch.
pub fn steady_orbit_in(
    model: &TappingModel,
    z_nm: f64,
    start: OrbitStart<'_>,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<SteadyOrbit, AfmError> {
    let (model, initial, predicted) = prepared_start(model, z_nm, start, settings, workspace)?;
    match shoot_period_one(&model, &initial, predicted, settings, workspace)? {
        Ok(orbit) => Ok(orbit),
        // Period-1 Newton failed or found a repelling orbit: look for the attractor by
        // iteration.
        Err(fallback) => recurrence_search(&model, &initial, fallback, settings, workspace),
    }
}

/// [`steady_orbit`] from [`OrbitStart::AfterTransients`]`(state)` without its search for
/// another attractor by recurrence: `transient_periods` periods from `state`, then Newton on
/// the period-1 map. Returns the orbit when Newton converges on a stable one (the orbit
/// [`steady_orbit`] returns then, to the bit), and the state the transients reached (the
/// cantilever's state after them, to go on from). For a walk in `Z` that only stops at a
/// stable period-1 orbit, where the energy budget rules one out beyond Newton's reach
/// (MODEL.md section 9, "Capillary meniscus").
pub fn period_one_after_transients(
    model: &TappingModel,
    z_nm: f64,
    state: &[f64],
    settings: &SteadyOrbitSettings,
) -> Result<(Option<SteadyOrbit>, Vec<f64>), AfmError> {
    let mut workspace = SteadyOrbitWorkspace::default();
    let start = OrbitStart::AfterTransients(state);
    let (model, initial, predicted) = prepared_start(model, z_nm, start, settings, &mut workspace)?;
    let orbit = shoot_period_one(&model, &initial, predicted, settings, &mut workspace)?.ok();
    Ok((orbit, initial))
}

/// The model at `z_nm` and the state Newton starts from (after the transients of `start`, if
/// it has any), with whether that state is a prediction ([`OrbitStart::Predicted`]); every
/// input checked.
fn prepared_start(
    model: &TappingModel,
    z_nm: f64,
    start: OrbitStart<'_>,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<(TappingModel, Vec<f64>, bool), AfmError> {
    settings.validate()?;
    let lowest = -model.free_amplitude_nm();
    if !(lowest..=MAX_SEPARATION_NM).contains(&z_nm) {
        return Err(invalid(
            "steady orbit",
            "z_nm",
            z_nm,
            format!(
                "[{lowest}, {MAX_SEPARATION_NM}] nm (from -A0, a rest position one free amplitude inside the sample where Hertz contact is long past its validity, up to far above first contact)"
            ),
        ));
    }
    let mut model = model.clone();
    model.set_separation(Separation::Constant(z_nm))?;

    let (given, transients, predicted) = match start {
        OrbitStart::Near(x) => (x.to_vec(), false, false),
        OrbitStart::Predicted(x) => (x.to_vec(), false, true),
        OrbitStart::AfterTransients(x) => (x.to_vec(), true, false),
        OrbitStart::Transient => (model.free_state(), true, false),
        OrbitStart::Approach => match walk_approach(&model, z_nm, settings, workspace)? {
            WalkEnd::Predicted(x) => (x, false, true),
            WalkEnd::Near(x) => (x, false, false),
        },
    };
    if given.len() != model.dim() || given.iter().any(|v| !v.is_finite()) {
        return Err(AfmError::InvalidField {
            file: String::from("steady orbit"),
            field: String::from("start"),
            value: format!("{given:?}"),
            allowed: format!(
                "a finite state of the model's dimension {} ([q_1, q_1', ..., q_N, q_N'])",
                model.dim()
            ),
        });
    }
    let initial = if transients {
        iterate(
            &model,
            &given,
            settings.transient_periods,
            &settings.integration,
            workspace,
        )?
    } else {
        given
    };
    Ok((model, initial, predicted))
}

/// Newton on the period-1 map of `model` from `initial`: the orbit when it converges on a
/// stable one, else the attempt (the fallback of the recurrence search).
fn shoot_period_one(
    model: &TappingModel,
    initial: &[f64],
    predicted: bool,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<Result<SteadyOrbit, Attempt>, AfmError> {
    let z_nm = model.parameter();
    let first = shoot_observed(
        model,
        initial,
        predicted,
        &settings.newton,
        &settings.integration,
        settings.harmonics,
        workspace,
    )?;
    let first_multipliers = floquet_multipliers(&first.sensitivities.monodromy);
    let first_tangent = first.sensitivities.tangent(z_nm);
    if first.converged && is_stable(&first_multipliers) {
        return Ok(Ok(SteadyOrbit {
            z_nm,
            multiplicity: 1,
            converged: true,
            iterations: first.iterations,
            residual: first.residual,
            state: first.state.clone(),
            stable: true,
            multipliers: first_multipliers,
            monodromy: Some(first.sensitivities.monodromy),
            tangent: first_tangent,
            whole_orbit: first.observables.clone(),
            periods: vec![first.observables],
            period_states: vec![first.state],
        }));
    }
    Ok(Err(Attempt {
        multiplicity: 1,
        state: first.state,
        iterations: first.iterations,
        residual: first.residual,
        multipliers: first_multipliers,
        tangent: first_tangent,
    }))
}

/// The Euclidean distance between two states of the model, `[q_1, q_1', ..., q_N, q_N']` (nm
/// and nm/us mixed, as Newton's residual and the 1e-10 nm convergence test measure it).
pub fn state_distance(a: &[f64], b: &[f64]) -> f64 {
    debug_assert_eq!(a.len(), b.len(), "states of one model");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}
