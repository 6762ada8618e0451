//! The steady periodic orbit of the tapping cantilever at a fixed separation `Z`: transient
//! periods from a sensible start, then Newton (shooting) on the stroboscopic map
//! `x -> x(T)` with the exact monodromy matrix from the hybrid solver, and the orbit's
//! observables (MODEL.md sections 4 and 5).
//!
//! An orbit that is not period-1 (period doubling, a period-k window) is found by iterating the
//! map until a state recurs after `k` periods, then shooting on the `k`-th iterate; an orbit that
//! settles on none within the budget is reported as not converged, never dressed up as one.

use continuation::{
    floquet_multipliers, is_stable, newton_update, shoot, ContinuationError, HybridPeriodicProblem,
    NewtonSettings, Parametrised,
};
use hybrid::{flow_map_in, FlowMap, Sensitivity, SensitivityMethod, Settings, SolverWorkspace};
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use crate::error::AfmError;
use crate::model::TappingModel;
use crate::observables::{observe_period_in, OrbitObservables};
use crate::separation::Separation;
use crate::validation::invalid;

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
    /// Periods integrated from a cold start before Newton (default 20; the slowest free decay,
    /// `exp(-w_1 t / (2 Q_1))`, loses a factor `exp(-pi / Q_1)` per period, about 1e-36 over 20
    /// periods for the paper's cantilevers). Range 0..=100000.
    pub transient_periods: usize,
    /// Periods iterated to find a recurrence when the period-1 orbit is not the attractor
    /// (default 400). Range 1..=1000000.
    pub recurrence_periods: usize,
    /// The largest multiplicity `k` (orbit period `k T`) searched for (default 8). Range 1..=64.
    pub max_multiplicity: usize,
}

impl Default for SteadyOrbitSettings {
    fn default() -> Self {
        Self {
            integration: Settings::default(),
            newton: NewtonSettings::default(),
            transient_periods: 20,
            recurrence_periods: 400,
            max_multiplicity: 8,
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

/// A steady periodic orbit at one separation, with how it was found and what it looks like.
#[derive(Debug, Clone, Serialize)]
pub struct SteadyOrbit {
    /// The separation `Z`, nm.
    pub z_nm: f64,
    /// The orbit's period in drive periods (`k` for an orbit of period `k T`).
    pub multiplicity: usize,
    /// Whether Newton reached the tolerance on the `k`-th iterate of the stroboscopic map.
    pub converged: bool,
    /// Newton iterations of the last (successful or final) shooting.
    pub iterations: usize,
    /// The final residual `|P^k(x) - x|`, nm and nm/us mixed (the state's units).
    pub residual: f64,
    /// The state at `t = 0` (drive phase zero): `[q_1, q_1', ..., q_N, q_N']`, nm and nm/us.
    pub state: Vec<f64>,
    /// Floquet multipliers: eigenvalues of the monodromy matrix of `P^k`. For a period-1 orbit,
    /// the monodromy of Newton's last map with it (decoupled sensitivities, see
    /// `shoot_observed`): the monodromy within 1.3e-6 and 2.3e-6 relative at the Fig. 1 points
    /// A/A0 = 0.95 and 0.5 of the Biolever on mica (`cargo run --release -p afm --example
    /// monodromy_error`), enough for the orbit's stability; continuation
    /// (`bifurcation_diagram`) computes its own.
    #[serde(serialize_with = "serialize_multipliers")]
    pub multipliers: Vec<Complex<f64>>,
    /// Whether every multiplier lies inside the unit circle (the orbit attracts).
    pub stable: bool,
    /// The observables of each of the `k` drive periods of the orbit, in order.
    pub periods: Vec<OrbitObservables>,
}

impl SteadyOrbit {
    /// The observables of the orbit's first drive period.
    pub fn observables(&self) -> &OrbitObservables {
        &self.periods[0]
    }

    /// The lock-in reading over the whole orbit (`k` periods): the first-harmonic Fourier
    /// coefficients `a`, `b` of `u` averaged over the periods, returned as
    /// `(A / A0, Phi in degrees)` (MODEL.md section 4).
    pub fn lockin(&self, free_amplitude_nm: f64) -> (f64, f64) {
        let (mut a, mut b) = (0.0, 0.0);
        for period in &self.periods {
            let phase = period.phase_deg.to_radians();
            a += period.amplitude_nm * phase.cos();
            b += period.amplitude_nm * phase.sin();
        }
        let k = self.periods.len() as f64;
        (
            (a / k).hypot(b / k) / free_amplitude_nm,
            (b / k).atan2(a / k).to_degrees(),
        )
    }

    /// Impacts per drive period: the total over the orbit's `k` periods divided by `k`.
    pub fn impacts_per_period(&self) -> f64 {
        let total: usize = self.periods.iter().map(|p| p.impacts.len()).sum();
        total as f64 / self.periods.len() as f64
    }
}

fn serialize_multipliers<S: serde::Serializer>(
    multipliers: &[Complex<f64>],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = serializer.serialize_seq(Some(multipliers.len()))?;
    for m in multipliers {
        seq.serialize_element(&[m.re, m.im])?;
    }
    seq.end()
}

/// The solver buffers of the period maps of [`steady_orbit_in`], kept from one orbit to the
/// next: the maps with the monodromy (Newton's) and those of the state only (transients, the
/// observed last map, the recurrence search) each reuse their own, so that a branch of orbits
/// (an approach in `Z`) allocates only results. Empty at first ([`Default`]); a clone is empty.
#[derive(Debug, Default, Clone)]
pub struct SteadyOrbitWorkspace {
    with_monodromy: SolverWorkspace,
    state_only: SolverWorkspace,
}

impl SteadyOrbitWorkspace {
    /// The buffers for maps with `sensitivity`.
    fn for_maps(&mut self, sensitivity: Sensitivity) -> &mut SolverWorkspace {
        if sensitivity == Sensitivity::None {
            &mut self.state_only
        } else {
            &mut self.with_monodromy
        }
    }
}

/// The steady orbit of `model` at separation `z_nm`.
///
/// With `start = Some(x)` (the orbit at a neighbouring `Z`), Newton starts from `x` directly;
/// with `None` (a cold start), from the free steady state after `transient_periods` periods.
/// If Newton does not converge, or converges to an orbit that repels (so that it is not what a
/// cantilever would settle on), the map is iterated until a state recurs after `k <=
/// max_multiplicity` periods and Newton is applied to the `k`-th iterate.
pub fn steady_orbit(
    model: &TappingModel,
    z_nm: f64,
    start: Option<&[f64]>,
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
/// to it: the same orbit, without a new solver's allocations per map (about 2% of an orbit
/// from its neighbour at A/A0 = 0.5: 1.543M against 1.579M instructions). For a sequence of
/// orbits, as along a branch.
pub fn steady_orbit_in(
    model: &TappingModel,
    z_nm: f64,
    start: Option<&[f64]>,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<SteadyOrbit, AfmError> {
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

    let initial = match start {
        Some(x) => x.to_vec(),
        None => iterate(
            &model,
            &model.free_state(),
            settings.transient_periods,
            &settings.integration,
            workspace,
        )?,
    };

    let first = shoot_observed(
        &model,
        &initial,
        &settings.newton,
        &settings.integration,
        workspace,
    )?;
    let first_multipliers = floquet_multipliers(&first.monodromy);
    if first.converged && is_stable(&first_multipliers) {
        return Ok(SteadyOrbit {
            z_nm: model.parameter(),
            multiplicity: 1,
            converged: true,
            iterations: first.iterations,
            residual: first.residual,
            state: first.state,
            stable: true,
            multipliers: first_multipliers,
            periods: vec![first.observables],
        });
    }

    // Period-1 Newton failed or found a repelling orbit: look for the attractor by iteration.
    let mut states = Vec::with_capacity(settings.recurrence_periods + 1);
    let mut x = iterate(
        &model,
        &initial,
        settings.transient_periods,
        &settings.integration,
        workspace,
    )?;
    states.push(x.clone());
    let scale = model.free_amplitude_nm();
    // The best non-converged attempt: (multiplicity, state, iterations, residual, multipliers).
    #[allow(clippy::type_complexity)]
    let mut best: Option<(usize, Vec<f64>, usize, f64, Vec<Complex<f64>>)> = None;
    for _ in 0..settings.recurrence_periods {
        x = iterate(&model, &x, 1, &settings.integration, workspace)?;
        states.push(x.clone());
        let last = states.len() - 1;
        for k in 1..=settings.max_multiplicity.min(last) {
            let distance = distance(&states[last], &states[last - k]);
            if distance > 1e-4 * scale {
                continue;
            }
            let problem =
                HybridPeriodicProblem::new(model.clone(), k, settings.integration.clone())?;
            let shot = shoot(&problem, &states[last], z_nm, &settings.newton)?;
            let multipliers = floquet_multipliers(&shot.period_map.monodromy);
            if shot.converged {
                return finish(
                    &model,
                    k,
                    shot.state.as_slice(),
                    shot.iterations,
                    shot.residual,
                    multipliers,
                    settings,
                    workspace,
                );
            }
            if best.as_ref().is_none_or(|b| shot.residual < b.3) {
                best = Some((
                    k,
                    shot.state.as_slice().to_vec(),
                    shot.iterations,
                    shot.residual,
                    multipliers,
                ));
            }
        }
    }
    // No recurrence converged: report honestly, with the best attempt (or the period-1 one).
    let (k, state, iterations, residual, multipliers) = match best {
        Some(best) if best.3 < first.residual => best,
        _ => (
            1,
            first.state.clone(),
            first.iterations,
            first.residual,
            first_multipliers,
        ),
    };
    let mut orbit = finish(
        &model,
        k,
        &state,
        iterations,
        residual,
        multipliers,
        settings,
        workspace,
    )?;
    orbit.converged = false;
    Ok(orbit)
}

/// The outcome of [`shoot_observed`]: Newton's last iterate with the residual and observables
/// of the period map evaluated there, and the monodromy (see [`shoot_observed`] for where).
struct ObservedShot {
    state: Vec<f64>,
    iterations: usize,
    residual: f64,
    converged: bool,
    monodromy: DMatrix<f64>,
    observables: OrbitObservables,
}

/// A period map's image, monodromy (if asked for) and observables (if asked for).
type ObservedMap = (Vec<f64>, Option<DMatrix<f64>>, Option<OrbitObservables>);

/// One period map from `x`; with `transition`, also the monodromy; with `observe`, also the
/// observables (the quadratures cost about a tenth of a period map: done only where the
/// evaluation is expected to be the last).
fn observed_map(
    model: &TappingModel,
    x: &[f64],
    transition: bool,
    observe: bool,
    integration: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<ObservedMap, AfmError> {
    let sensitivity = if transition {
        Sensitivity::Transition
    } else {
        Sensitivity::None
    };
    let (flow, observables) = if observe {
        let buffers = workspace.for_maps(sensitivity);
        let (flow, observables) =
            observe_period_in(model, 0.0, x, sensitivity, integration, 1, buffers)?;
        (flow, Some(observables))
    } else {
        (
            period_map(model, x, sensitivity, integration, workspace)?,
            None,
        )
    };
    if flow.state.iter().any(|v| !v.is_finite()) || flow.transition.iter().any(|v| !v.is_finite()) {
        return Err(ContinuationError::NonFinite {
            what: "period map",
            parameter: model.parameter(),
        }
        .into());
    }
    let monodromy = transition.then_some(flow.transition);
    Ok((flow.state, monodromy, observables))
}

/// Newton on the period-1 stroboscopic map `P(x) - x = 0` with the exact monodromy (the same
/// iteration, convergence test and divergence guard as `continuation::shoot`), each period
/// map integrated with its observables, so that the evaluation at the returned state gives
/// its residual (always measured there) and observables at once, and without `dx/dZ` (unused
/// here).
///
/// The last evaluation skips the monodromy when Newton's quadratic convergence predicts it
/// final (`C r_k^2 <= tolerance / 10`, `C = r_k / r_{k-1}^2` from the last two residuals) and
/// the update leading to it is below `0.1 * sensitivity_tolerance.unwrap_or(1e-5) * (1 +
/// |x|)`: the monodromy returned is then the one at the previous iterate, that close to the
/// orbit, so it differs from the monodromy at the returned state by about that relative
/// amount (1e-6), less than its integration error (below), far less than matters for the
/// Floquet multipliers' use here, the orbit's stability. If the
/// prediction fails (residual above the tolerance), the point is evaluated again with the
/// monodromy and Newton goes on.
///
/// The first evaluation, whose only use is the first Newton update, is integrated at the
/// tolerances of [`first_iterate`] (inexact Newton): its error, a few 1e-7 nm, adds about that
/// much to the first iterate, which the next, full-tolerance iteration removes with the rest
/// (the iteration counts of the Fig. 1 benchmark stay 2). Every residual that decides
/// convergence comes from a full-tolerance map: a start whose loose residual is below
/// [`LOOSE_RESIDUAL_FLOOR`] is evaluated again at full tolerance before anything is decided.
///
/// The monodromy of every map is carried by [`newton_maps`]: decoupled from the state's
/// steps (order-12 tangent series in contact, the exact flow in free flight), within 1.3e-6
/// to 2.3e-6 relative at the Fig. 1 points (`cargo run --release -p afm --example
/// monodromy_error`), so each Newton iteration also contracts the error by about
/// that much (times the conditioning of `M - I`) besides squaring it: far below what the
/// iterations need (the Fig. 1 benchmark's counts stay 2, and a start after transients
/// converges in as many iterations as with the coupled monodromy).
fn shoot_observed(
    model: &TappingModel,
    x0: &[f64],
    newton: &NewtonSettings,
    integration: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<ObservedShot, AfmError> {
    let n = x0.len();
    let shift_scale = 0.1 * integration.sensitivity_tolerance.unwrap_or(1e-5);
    let integration = &newton_maps(integration);
    let mut x = x0.to_vec();
    let (mut image, mut first_monodromy, mut observables) = observed_map(
        model,
        &x,
        true,
        false,
        &first_iterate(integration),
        workspace,
    )?;
    if distance(&image, &x) <= LOOSE_RESIDUAL_FLOOR {
        (image, first_monodromy, observables) =
            observed_map(model, &x, true, false, integration, workspace)?;
    }
    let mut monodromy = first_monodromy.unwrap_or_else(|| DMatrix::identity(n, n));
    let mut previous_residual: Option<f64> = None;
    let mut iterations = 0;
    loop {
        let residual_vector = DVector::from_iterator(n, image.iter().zip(&x).map(|(p, x)| p - x));
        let residual = residual_vector.norm();
        if residual <= newton.tolerance || iterations >= newton.max_iterations {
            let observables = observables_at(model, &x, observables, integration, workspace)?;
            return Ok(ObservedShot {
                state: x,
                iterations,
                residual,
                converged: residual <= newton.tolerance,
                monodromy,
                observables,
            });
        }
        let update = newton_update(&monodromy, &residual_vector, model.parameter())?;
        let candidate: Vec<f64> = x.iter().zip(update.iter()).map(|(x, u)| x - u).collect();
        iterations += 1;
        if !candidate.iter().all(|v| v.is_finite()) {
            return Err(ContinuationError::NonFinite {
                what: "Newton iterate",
                parameter: model.parameter(),
            }
            .into());
        }
        let predicted_final = previous_residual.is_some_and(|r_prev| {
            let constant = residual / (r_prev * r_prev);
            constant * residual * residual <= 0.1 * newton.tolerance
        }) && update.norm()
            <= shift_scale * (1.0 + DVector::from_column_slice(&x).norm());
        let (mut next_image, mut next_monodromy, mut next_observables) = observed_map(
            model,
            &candidate,
            !predicted_final,
            predicted_final,
            integration,
            workspace,
        )?;
        let next_residual = distance(&next_image, &candidate);
        if next_residual > newton.divergence_factor * residual {
            let observables = observables_at(model, &x, observables, integration, workspace)?;
            return Ok(ObservedShot {
                state: x,
                iterations,
                residual,
                converged: false,
                monodromy,
                observables,
            });
        }
        if next_monodromy.is_none() && next_residual > newton.tolerance {
            // The prediction failed: Newton goes on and needs the monodromy there.
            (next_image, next_monodromy, next_observables) =
                observed_map(model, &candidate, true, false, integration, workspace)?;
        }
        previous_residual = Some(residual);
        x = candidate;
        image = next_image;
        observables = next_observables;
        if let Some(m) = next_monodromy {
            monodromy = m;
        }
    }
}

/// The observables at `x`: `known` if the evaluation there recorded them, else one more
/// (state-only) period.
fn observables_at(
    model: &TappingModel,
    x: &[f64],
    known: Option<OrbitObservables>,
    integration: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<OrbitObservables, AfmError> {
    match known {
        Some(observables) => Ok(observables),
        None => {
            let buffers = workspace.for_maps(Sensitivity::None);
            Ok(observe_period_in(model, 0.0, x, Sensitivity::None, integration, 1, buffers)?.1)
        }
    }
}

/// The loosest tolerance (relative and absolute) of the first Newton map of
/// [`shoot_observed`]. At 1e-8 (the sweep's default) the Taylor-series steps in contact left a
/// state error of ~2e-8 nm at A/A0 = 0.9, enough to fail Newton's quadratic prediction after
/// the next iteration and cost one more period map with the monodromy; at 1e-9 the orbit from
/// its neighbour needs no extra map (2.79M -> 2.07M instructions at A/A0 = 0.9
/// when this was chosen).
const FIRST_ITERATE_TOLERANCE: f64 = 1e-9;

/// A first Newton map at [`FIRST_ITERATE_TOLERANCE`] whose residual is below this (nm) is
/// computed again at full tolerance: the loose map's own error is part of such a residual (its
/// residual at converged Fig. 1 orbits measured 2e-11 to 2e-8 nm), and the start is close
/// enough for full-tolerance Newton (after the transient periods of a cold start, typically).
/// From a neighbouring orbit on the branch 0.01 nm away, the residual is 3e-4 to 2e-2 nm.
const LOOSE_RESIDUAL_FLOOR: f64 = 1e3 * FIRST_ITERATE_TOLERANCE;

/// `settings` for the period maps of [`shoot_observed`]: the monodromy integrated apart from
/// the state's steps ([`SensitivityMethod::Decoupled`]: tangent series of order 12 on the
/// Taylor steps in contact, a sixth-order method on any Runge-Kutta step; the period map with
/// the monodromy at A/A0 = 0.5 costs 0.58M instructions, against 0.67M with the tangents at
/// the state's order and 0.36M without the monodromy), unless `settings` ask for
/// error-controlled sensitivities (`sensitivity_tolerance`), which only the coupled method has.
fn newton_maps(settings: &Settings) -> Settings {
    Settings {
        sensitivity_method: if settings.sensitivity_tolerance.is_none() {
            SensitivityMethod::Decoupled
        } else {
            SensitivityMethod::Coupled
        },
        ..settings.clone()
    }
}

/// `settings` for the first Newton map of [`shoot_observed`]: tolerances no tighter than
/// [`FIRST_ITERATE_TOLERANCE`].
fn first_iterate(settings: &Settings) -> Settings {
    Settings {
        relative_tolerance: settings.relative_tolerance.max(FIRST_ITERATE_TOLERANCE),
        absolute_tolerance: settings.absolute_tolerance.max(FIRST_ITERATE_TOLERANCE),
        ..settings.clone()
    }
}

/// `settings` for a period map whose extrema nobody reads (a Newton iterate not expected to
/// be the last, a transient period): `extremum_height` 0, so that free flight the model proves
/// clear of the sample is neither sampled nor cut into short steps. Contacts are found all the
/// same; the state differs from a fully sampled map by rounding only.
fn crossings_only(settings: &Settings) -> Settings {
    Settings {
        extremum_height: 0.0,
        ..settings.clone()
    }
}

/// One period map from `x` with `sensitivity`, crossings only ([`crossings_only`]), on the
/// workspace's buffers for it.
fn period_map(
    model: &TappingModel,
    x: &[f64],
    sensitivity: Sensitivity,
    settings: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<FlowMap, AfmError> {
    Ok(flow_map_in(
        model,
        0.0,
        x,
        model.period_us(),
        sensitivity,
        &crossings_only(settings),
        &mut |_: &_, _: &_| {},
        workspace.for_maps(sensitivity),
    )?)
}

/// Iterate the stroboscopic map `periods` times from `x0` (state only, no extrema).
fn iterate(
    model: &TappingModel,
    x0: &[f64],
    periods: usize,
    settings: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<Vec<f64>, AfmError> {
    let mut x = x0.to_vec();
    for _ in 0..periods {
        x = period_map(model, &x, Sensitivity::None, settings, workspace)?.state;
    }
    Ok(x)
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Assemble the orbit: the observables of each of its `k` periods from the converged state.
#[allow(clippy::too_many_arguments)]
fn finish(
    model: &TappingModel,
    multiplicity: usize,
    state: &[f64],
    iterations: usize,
    residual: f64,
    multipliers: Vec<Complex<f64>>,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<SteadyOrbit, AfmError> {
    let mut periods = Vec::with_capacity(multiplicity);
    let mut x = state.to_vec();
    for _ in 0..multiplicity {
        let (flow, observables) = observe_period_in(
            model,
            0.0,
            &x,
            Sensitivity::None,
            &settings.integration,
            1,
            workspace.for_maps(Sensitivity::None),
        )?;
        periods.push(observables);
        x = flow.state;
    }
    Ok(SteadyOrbit {
        z_nm: model.parameter(),
        multiplicity,
        converged: residual <= settings.newton.tolerance,
        iterations,
        residual,
        state: state.to_vec(),
        stable: is_stable(&multipliers),
        multipliers,
        periods,
    })
}
