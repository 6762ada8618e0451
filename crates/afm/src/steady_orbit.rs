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
use hybrid::{
    flow_map_in, FlowMap, HybridSystem, Sensitivity, SensitivityMethod, Settings, SolverWorkspace,
};
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use crate::error::AfmError;
use crate::model::TappingModel;
use crate::observables::{observe_orbit_in, observe_period_in, OrbitObservables};
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
    /// (default 4000: 5e-8 nm below the MAClever-on-mica fold, the transients pass the ghost
    /// of the orbit that vanished there within them and converge, in 0.07 s in all; with 400
    /// they did not even 1e-6 nm below it). Range 1..=1000000.
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
            recurrence_periods: 4000,
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
    /// `dx/dZ`: how the orbit's state at `t = 0` moves with the separation along its branch
    /// (nm per nm and nm/us per nm), `-(M - I)^{-1} dP/dZ` from the monodromy `M` and the
    /// parameter derivative `dP/dZ` of the same period map (of `P^k`; the implicit-function
    /// theorem on `P(x; Z) = x`), the map being Newton's last one with sensitivities (as for
    /// the multipliers). The branch's slope, for predicting a neighbouring orbit
    /// ([`OrbitStart::Predicted`]). `None` where `M - I` is singular (a fold of the branch,
    /// where `Z` cannot parametrise it) or the solve gives a non-finite vector.
    pub tangent: Option<Vec<f64>>,
    /// The observables of the whole orbit: one window of its `k` drive periods, so that every
    /// impact, gap minimum and force of every period is in it (times in drive periods from
    /// `t = 0`, in `[0, k)`), integrals per drive period, and the first harmonic the lock-in
    /// reading over `k T`.
    pub whole_orbit: OrbitObservables,
    /// The observables of each of the `k` drive periods of the orbit in order, each over its
    /// own window `[j T, (j + 1) T]` (times from that period's start): its first harmonic,
    /// force integrals, gap minima and peak force. Its impact list treats the one period as
    /// periodic (an impact running across the window's end joins one running across its
    /// start), so per-period impact counts come from [`SteadyOrbit::period_breakdown`].
    pub periods: Vec<OrbitObservables>,
}

/// One drive period of a period-`k` orbit: the per-period breakdown of its observables.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeriodBreakdown {
    /// The period's index `j` in the orbit, from 0 (the window `[j T, (j + 1) T]`).
    pub period: usize,
    /// `A / A0` of the first harmonic of `u` over this period alone.
    pub amplitude_ratio: f64,
    /// Phase lag `Phi` of that harmonic over this period alone, degrees.
    pub phase_deg: f64,
    /// The orbit's impacts whose onset lies in this period (an impact belongs to the period
    /// it starts in; one in contact throughout the orbit belongs to period 0).
    pub impacts: usize,
    /// The largest tip-sample force in this period, nN.
    pub peak_force_nn: f64,
    /// The mean tip-sample force over this period, nN.
    pub mean_force_nn: f64,
    /// The impulse `int F_ts dt` over this period, nN us.
    pub impulse_nn_us: f64,
    /// The time in contact within this period, in periods.
    pub contact_time_periods: f64,
    /// The lowest local minimum of the gap in this period, nm (`null` in JSON if none).
    pub min_gap_nm: Option<f64>,
}

impl SteadyOrbit {
    /// The observables of the whole orbit (all `k` periods; see [`SteadyOrbit::whole_orbit`]).
    pub fn observables(&self) -> &OrbitObservables {
        &self.whole_orbit
    }

    /// The lock-in reading over the whole orbit (`k` periods): `(A / A0, Phi in degrees)` of
    /// the first harmonic of `u` over `k T` (MODEL.md section 4), with `A0 =
    /// free_amplitude_nm`.
    pub fn lockin(&self, free_amplitude_nm: f64) -> (f64, f64) {
        (
            self.whole_orbit.amplitude_nm / free_amplitude_nm,
            self.whole_orbit.phase_deg,
        )
    }

    /// Impacts per drive period: the impacts over the orbit's `k` periods divided by `k`.
    pub fn impacts_per_period(&self) -> f64 {
        self.whole_orbit.impacts_per_period
    }

    /// The impacts over the whole orbit (`k` periods), an integer.
    pub fn impacts_per_orbit(&self) -> usize {
        self.whole_orbit.impacts.len()
    }

    /// The per-period breakdown of the orbit's observables, one entry per drive period.
    pub fn period_breakdown(&self, free_amplitude_nm: f64) -> Vec<PeriodBreakdown> {
        self.periods
            .iter()
            .enumerate()
            .map(|(j, period)| {
                let onsets = j as f64..(j + 1) as f64;
                let min_gap = period.min_gap_nm();
                PeriodBreakdown {
                    period: j,
                    amplitude_ratio: period.amplitude_nm / free_amplitude_nm,
                    phase_deg: period.phase_deg,
                    impacts: self
                        .whole_orbit
                        .impacts
                        .iter()
                        .filter(|impact| onsets.contains(&impact.start_periods))
                        .count(),
                    peak_force_nn: period.peak_force_nn,
                    mean_force_nn: period.mean_force_nn,
                    impulse_nn_us: period.impulse_nn_us,
                    contact_time_periods: period.contact_time_periods,
                    min_gap_nm: min_gap.is_finite().then_some(min_gap),
                }
            })
            .collect()
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
/// next: the maps with the monodromy only (Newton's loose first map), those with the
/// monodromy and `dP/dZ` (Newton's full-tolerance maps) and those of the state only
/// (transients, the observed last map, the recurrence search) each reuse their own (a
/// solver's buffers fit one kind of sensitivity), so that a branch of orbits (an approach in
/// `Z`) allocates only results. Empty at first ([`Default`]); a clone is empty.
#[derive(Debug, Default, Clone)]
pub struct SteadyOrbitWorkspace {
    transition: SolverWorkspace,
    transition_and_parameter: SolverWorkspace,
    state_only: SolverWorkspace,
}

impl SteadyOrbitWorkspace {
    /// The buffers for maps with `sensitivity`.
    fn for_maps(&mut self, sensitivity: Sensitivity) -> &mut SolverWorkspace {
        match sensitivity {
            Sensitivity::None => &mut self.state_only,
            Sensitivity::Transition => &mut self.transition,
            Sensitivity::TransitionAndParameter => &mut self.transition_and_parameter,
        }
    }
}

/// Where Newton on the stroboscopic map starts, and so how its first period map is
/// integrated (see [`steady_orbit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrbitStart<'a> {
    /// The free steady state after `transient_periods` periods.
    Cold,
    /// A state near the orbit, such as a neighbouring orbit's on the branch. From an orbit
    /// 0.01 nm away in `Z` at the paper's Fig. 1 points the state is 3e-4 to 2e-2 nm off,
    /// so the first Newton map, whose only use is the first update, is integrated at a loose
    /// tolerance (inexact Newton, see `shoot_observed`).
    Near(&'a [f64]),
    /// A state predicted to within about 1e-6 nm of the orbit, such as the cubic Hermite
    /// extrapolation from two orbits along the branch ([`crate::orbit_prediction`]): the
    /// first map is integrated at full tolerance, and when its residual is small enough for
    /// one Newton update to converge, the next map is the last (two period maps in all
    /// instead of three: at the Fig. 1 points 0.52M, 0.84M and 1.16M instructions per orbit
    /// at A/A0 = 0.95, 0.90 and 0.50, against 0.71M, 1.13M and 1.60M from the nearer
    /// orbit's state; callgrind). A worse prediction costs a map, never accuracy:
    /// convergence is decided by measured residuals only.
    Predicted(&'a [f64]),
    /// `transient_periods` periods integrated from this state before Newton, as [`Self::Cold`]
    /// does from the free state: the attractor whose basin holds the state rather than the
    /// orbit nearest to it, as a quasi-static sweep of `Z` follows it (a neighbouring cell's
    /// orbit, [`crate::quasi_static`]).
    AfterTransients(&'a [f64]),
}

impl<'a> OrbitStart<'a> {
    /// `Near(x)` for `Some(x)`, `Cold` for `None`.
    pub fn near_or_cold(state: Option<&'a [f64]>) -> Self {
        state.map_or(Self::Cold, Self::Near)
    }
}

/// The steady orbit of `model` at separation `z_nm`.
///
/// Newton starts from `start` (see [`OrbitStart`]); a cold start first integrates
/// `transient_periods` periods from the free steady state. If Newton does not converge, or
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
/// to it: the same orbit, without a new solver's allocations per map (about 3% of an orbit
/// from its neighbour at A/A0 = 0.5: 1.604M against 1.661M instructions). For a sequence of
/// orbits, as along a branch.
pub fn steady_orbit_in(
    model: &TappingModel,
    z_nm: f64,
    start: OrbitStart<'_>,
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

    let free_state = model.free_state();
    let (given, transients, predicted) = match start {
        OrbitStart::Near(x) => (x, false, false),
        OrbitStart::Predicted(x) => (x, false, true),
        OrbitStart::AfterTransients(x) => (x, true, false),
        OrbitStart::Cold => (free_state.as_slice(), true, false),
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
            given,
            settings.transient_periods,
            &settings.integration,
            workspace,
        )?
    } else {
        given.to_vec()
    };

    let first = shoot_observed(
        &model,
        &initial,
        predicted,
        &settings.newton,
        &settings.integration,
        workspace,
    )?;
    let first_multipliers = floquet_multipliers(&first.sensitivities.monodromy);
    let first_tangent = first.sensitivities.tangent(z_nm);
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
            tangent: first_tangent,
            whole_orbit: first.observables.clone(),
            periods: vec![first.observables],
        });
    }

    // Period-1 Newton failed or found a repelling orbit: look for the attractor by iteration.
    // Each period, the smallest multiplicity whose state recurs is shot, leaving out those at
    // which an earlier shot failed from a recurrence less than [`RETRY_FACTOR`] times farther
    // (a transient nearing an attractor comes closer by factors; the ghost of a vanished orbit
    // does not).
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
    let mut failed_at = vec![f64::INFINITY; settings.max_multiplicity + 1];
    // The best non-converged attempt.
    let mut best: Option<Attempt> = None;
    for _ in 0..settings.recurrence_periods {
        x = iterate(&model, &x, 1, &settings.integration, workspace)?;
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
        let problem = HybridPeriodicProblem::new(model.clone(), k, settings.integration.clone())?;
        let shot = shoot(&problem, &states[last], z_nm, &settings.newton)?;
        let multipliers = floquet_multipliers(&shot.period_map.monodromy);
        let tangent = branch_tangent(
            &shot.period_map.monodromy,
            shot.period_map.parameter_derivative.as_slice(),
            z_nm,
        );
        let attempt = Attempt {
            multiplicity: k,
            state: shot.state.as_slice().to_vec(),
            iterations: shot.iterations,
            residual: shot.residual,
            multipliers,
            tangent,
        };
        if shot.converged {
            return finish(&model, attempt, settings, workspace);
        }
        failed_at[k] = distance;
        if best.as_ref().is_none_or(|b| attempt.residual < b.residual) {
            best = Some(attempt);
        }
    }
    // No recurrence converged: report honestly, with the best attempt (or the period-1 one).
    let attempt = match best {
        Some(best) if best.residual < first.residual => best,
        _ => Attempt {
            multiplicity: 1,
            state: first.state.clone(),
            iterations: first.iterations,
            residual: first.residual,
            multipliers: first_multipliers,
            tangent: first_tangent,
        },
    };
    let mut orbit = finish(&model, attempt, settings, workspace)?;
    orbit.converged = false;
    Ok(orbit)
}

/// A state recurs after `k` periods when it comes within this fraction of `A0` of the state `k`
/// periods before; Newton on the `k`-th iterate is then tried from it.
const RECURRENCE_DISTANCE: f64 = 1e-4;

/// After a failed shot at multiplicity `k` from a recurrence `d` apart, the next shot at `k`
/// waits for a recurrence closer than this factor times `d`. Shooting at every period had
/// taken 9.6 s at the ghost of the MAClever-on-mica orbit that vanishes at its fold (1e-8 nm
/// below it: every state recurs within 2e-3 nm, and every multiplicity was shot each period).
const RETRY_FACTOR: f64 = 0.1;

/// A shooting's outcome on the `multiplicity`-th iterate of the map, before its observables.
struct Attempt {
    multiplicity: usize,
    state: Vec<f64>,
    iterations: usize,
    residual: f64,
    multipliers: Vec<Complex<f64>>,
    tangent: Option<Vec<f64>>,
}

/// The outcome of [`shoot_observed`]: Newton's last iterate with the residual and observables
/// of the period map evaluated there, and the sensitivities (see [`shoot_observed`] for
/// where).
struct ObservedShot {
    state: Vec<f64>,
    iterations: usize,
    residual: f64,
    converged: bool,
    sensitivities: MapSensitivities,
    observables: OrbitObservables,
}

/// The derivatives of one period map: the monodromy `dP/dx` and, if tracked, `dP/dZ`.
struct MapSensitivities {
    monodromy: DMatrix<f64>,
    parameter_derivative: Option<DVector<f64>>,
}

impl MapSensitivities {
    /// The branch's slope `dx/dZ = -(M - I)^{-1} dP/dZ` (see [`SteadyOrbit::tangent`]).
    fn tangent(&self, z_nm: f64) -> Option<Vec<f64>> {
        branch_tangent(
            &self.monodromy,
            self.parameter_derivative.as_ref()?.as_slice(),
            z_nm,
        )
    }
}

/// `dx/dZ = -(M - I)^{-1} dP/dZ` from the monodromy `M` and `dP/dZ` of one map; `None` if
/// `M - I` is singular or the result is not finite.
fn branch_tangent(
    monodromy: &DMatrix<f64>,
    parameter_derivative: &[f64],
    z_nm: f64,
) -> Option<Vec<f64>> {
    let rhs = DVector::from_column_slice(parameter_derivative);
    let tangent = newton_update(monodromy, &rhs, z_nm).ok()?;
    tangent
        .iter()
        .all(|v| v.is_finite())
        .then(|| tangent.iter().map(|v| -v).collect())
}

/// A period map's image, sensitivities (if asked for) and observables (if asked for).
type ObservedMap = (Vec<f64>, Option<MapSensitivities>, Option<OrbitObservables>);

/// One period map from `x` with `sensitivity`; with `observe`, also the observables (the
/// sampling for the gap's extrema and the quadratures add about half of a state-only map,
/// 0.53M against 0.36M instructions at A/A0 = 0.5: done only where the evaluation is expected
/// to be the last).
fn observed_map(
    model: &TappingModel,
    x: &[f64],
    sensitivity: Sensitivity,
    observe: bool,
    integration: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<ObservedMap, AfmError> {
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
    let finite = |values: &[f64]| values.iter().all(|v| v.is_finite());
    if !(finite(&flow.state)
        && finite(flow.transition.as_slice())
        && finite(&flow.parameter_sensitivity))
    {
        return Err(ContinuationError::NonFinite {
            what: "period map",
            parameter: model.parameter(),
        }
        .into());
    }
    let sensitivities = (sensitivity != Sensitivity::None).then(|| MapSensitivities {
        monodromy: flow.transition,
        parameter_derivative: sensitivity
            .parameter()
            .then(|| DVector::from_vec(flow.parameter_sensitivity)),
    });
    Ok((flow.state, sensitivities, observables))
}

/// Newton on the period-1 stroboscopic map `P(x) - x = 0` with the exact monodromy (the same
/// iteration, convergence test and divergence guard as `continuation::shoot`), each period
/// map integrated with its observables, so that the evaluation at the returned state gives
/// its residual (always measured there) and observables at once. The maps with the
/// monodromy at full tolerance also carry `dP/dZ` (one more tangent column: 0.63M
/// instructions for such a map at A/A0 = 0.5 against 0.58M without it), for the orbit's
/// [`SteadyOrbit::tangent`].
///
/// The last evaluation skips the sensitivities when Newton's quadratic convergence predicts
/// it final (`C r_k^2 <= tolerance / 10`, `C = r_k / r_{k-1}^2` from the last two residuals,
/// or [`ASSUMED_NEWTON_CONSTANT`] after a first map at full tolerance) and the update leading
/// to it is below `0.1 * sensitivity_tolerance.unwrap_or(1e-5) * (1 + |x|)`: the
/// sensitivities returned are then the ones at the previous iterate, that close to the
/// orbit, so they differ from those at the returned state by about that relative amount
/// (1e-6), less than their integration error (below), far less than matters for the
/// Floquet multipliers' use here, the orbit's stability, or for the tangent's, a prediction.
/// If the prediction fails (residual above the tolerance), the point is evaluated again with
/// the sensitivities and Newton goes on.
///
/// From a [`OrbitStart::Near`] start (`predicted = false`), the first evaluation, whose only
/// use is the first Newton update, is integrated at the tolerances of [`first_iterate`]
/// (inexact Newton): its error, a few 1e-7 nm, adds about that much to the first iterate,
/// which the next, full-tolerance iteration removes with the rest (the iteration counts of
/// the Fig. 1 benchmark stay 2). Every residual that decides convergence comes from a
/// full-tolerance map: a start whose loose residual is below [`LOOSE_RESIDUAL_FLOOR`] is
/// evaluated again at full tolerance before anything is decided. From a
/// [`OrbitStart::Predicted`] start the first map is at full tolerance.
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
    predicted: bool,
    newton: &NewtonSettings,
    integration: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<ObservedShot, AfmError> {
    let n = x0.len();
    let shift_scale = 0.1 * integration.sensitivity_tolerance.unwrap_or(1e-5);
    let integration = &newton_maps(integration);
    let full = Sensitivity::TransitionAndParameter;
    let mut x = x0.to_vec();
    let (mut image, mut first_sensitivities, mut observables) = if predicted {
        observed_map(model, &x, full, false, integration, workspace)?
    } else {
        observed_map(
            model,
            &x,
            Sensitivity::Transition,
            false,
            &first_iterate(integration),
            workspace,
        )?
    };
    let mut full_tolerance = predicted;
    if !predicted && state_distance(&image, &x) <= LOOSE_RESIDUAL_FLOOR {
        (image, first_sensitivities, observables) =
            observed_map(model, &x, full, false, integration, workspace)?;
        full_tolerance = true;
    }
    let mut sensitivities = first_sensitivities.unwrap_or_else(|| MapSensitivities {
        monodromy: DMatrix::identity(n, n),
        parameter_derivative: None,
    });
    // The Newton constant `C` of the quadratic prediction: from the last two residuals once
    // there are two, assumed before that only if the first residual is a full-tolerance one.
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
                sensitivities,
                observables,
            });
        }
        let update = newton_update(
            &sensitivities.monodromy,
            &residual_vector,
            model.parameter(),
        )?;
        let candidate: Vec<f64> = x.iter().zip(update.iter()).map(|(x, u)| x - u).collect();
        iterations += 1;
        if !candidate.iter().all(|v| v.is_finite()) {
            return Err(ContinuationError::NonFinite {
                what: "Newton iterate",
                parameter: model.parameter(),
            }
            .into());
        }
        let constant = match previous_residual {
            Some(r_prev) => Some(residual / (r_prev * r_prev)),
            None => full_tolerance.then_some(ASSUMED_NEWTON_CONSTANT),
        };
        let predicted_final = constant
            .is_some_and(|constant| constant * residual * residual <= 0.1 * newton.tolerance)
            && update.norm() <= shift_scale * (1.0 + DVector::from_column_slice(&x).norm());
        let next_sensitivity = if predicted_final {
            Sensitivity::None
        } else {
            full
        };
        let (mut next_image, mut next_sensitivities, mut next_observables) = observed_map(
            model,
            &candidate,
            next_sensitivity,
            predicted_final,
            integration,
            workspace,
        )?;
        let next_residual = state_distance(&next_image, &candidate);
        if next_residual > newton.divergence_factor * residual {
            let observables = observables_at(model, &x, observables, integration, workspace)?;
            return Ok(ObservedShot {
                state: x,
                iterations,
                residual,
                converged: false,
                sensitivities,
                observables,
            });
        }
        if next_sensitivities.is_none() && next_residual > newton.tolerance {
            // The prediction failed: Newton goes on and needs the monodromy there.
            (next_image, next_sensitivities, next_observables) =
                observed_map(model, &candidate, full, false, integration, workspace)?;
        }
        previous_residual = Some(residual);
        x = candidate;
        image = next_image;
        observables = next_observables;
        if let Some(next) = next_sensitivities {
            sensitivities = next;
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

/// The Newton constant `C` (1/nm) assumed for the quadratic prediction `C r^2` of the next
/// residual after a first map at full tolerance, before two residuals measure it: the largest
/// `C = e_1 / e_0^2` measured at the Fig. 1 points over starting errors `e_0` from 2e-8 to
/// 2e-2 nm was 0.78 (A/A0 = 0.5, from the neighbouring orbit 0.01 nm away). A constant too
/// small costs one more map when the prediction fails, never accuracy.
const ASSUMED_NEWTON_CONSTANT: f64 = 1.0;

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

/// Assemble the orbit: the observables of the whole orbit and of each of its `k` periods from
/// the converged state.
fn finish(
    model: &TappingModel,
    attempt: Attempt,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<SteadyOrbit, AfmError> {
    let mut periods = Vec::with_capacity(attempt.multiplicity);
    let mut x = attempt.state.clone();
    for _ in 0..attempt.multiplicity {
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
    let whole_orbit = if attempt.multiplicity == 1 {
        periods[0].clone()
    } else {
        observe_orbit_in(
            model,
            &attempt.state,
            attempt.multiplicity,
            &settings.integration,
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
        tangent: attempt.tangent,
        whole_orbit,
        periods,
    })
}
