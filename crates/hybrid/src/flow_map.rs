//! Solving over an interval, built on [`Solver::step`]: the flow map `x0 -> x(t0 + T)` with its
//! derivatives, events and extrema.

use nalgebra::DMatrix;

use crate::error::HybridError;
use crate::event::{Event, Extremum};
use crate::sensitivity::Sensitivity;
use crate::settings::Settings;
use crate::solver::{Solver, Statistics, StepOutcome};
use crate::system::{HybridSystem, Mode};
use crate::workspace::SolverWorkspace;

/// The result of integrating over `[t0, t0 + duration]`.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowMap {
    /// `x(t0 + duration)`.
    pub state: Vec<f64>,
    /// `dx(t0 + duration)/dx0` through every event (saltation included): the monodromy matrix
    /// when the duration is a period. The identity if not tracked.
    pub transition: DMatrix<f64>,
    /// `dx(t0 + duration)/dp` for fixed `x0`; zeros if not tracked.
    pub parameter_sensitivity: Vec<f64>,
    /// Every event, in time order.
    pub events: Vec<Event>,
    /// Every extremum of every switching function, in time order.
    pub extrema: Vec<Extremum>,
    /// Work counters.
    pub statistics: Statistics,
    /// The mode at `t0 + duration` (for [`flow_map_from_mode`] to continue the flow in it).
    pub mode: Mode,
}

/// Integrate `system` from `(t0, x0)` over `duration` (system time units, `>= 0`).
///
/// # Errors
/// Any [`HybridError`] of [`Solver::new`] or [`Solver::step`];
/// [`HybridError::InvalidEndTime`] for a negative or non-finite duration.
pub fn flow_map<S: HybridSystem + ?Sized>(
    system: &S,
    t0: f64,
    x0: &[f64],
    duration: f64,
    sensitivity: Sensitivity,
    settings: &Settings,
) -> Result<FlowMap, HybridError> {
    flow_map_observed(
        system,
        t0,
        x0,
        duration,
        sensitivity,
        settings,
        &mut |_: &Solver<S>, _: &StepOutcome| {},
    )
}

/// As [`flow_map`], calling `observer(&solver, &outcome)` after every step (for quadratures
/// over the dense output via [`Solver::interpolate`] on [`Solver::last_step`], or plots).
///
/// # Errors
/// As [`flow_map`].
pub fn flow_map_observed<S, O>(
    system: &S,
    t0: f64,
    x0: &[f64],
    duration: f64,
    sensitivity: Sensitivity,
    settings: &Settings,
    observer: &mut O,
) -> Result<FlowMap, HybridError>
where
    S: HybridSystem + ?Sized,
    O: FnMut(&Solver<S>, &StepOutcome),
{
    flow_map_in(
        system,
        t0,
        x0,
        duration,
        sensitivity,
        settings,
        observer,
        &mut SolverWorkspace::default(),
    )
}

/// As [`flow_map_observed`], the solver taking its buffers from `workspace` and handing them
/// back to it when done ([`Solver::with_workspace`], [`Solver::into_workspace`]): repeated
/// maps of one shape (Newton iterations, a branch of orbits) allocate only their results. The
/// run is identical to one on fresh buffers. On an error the buffers are dropped and
/// `workspace` is left empty.
///
/// # Errors
/// As [`flow_map`].
#[allow(clippy::too_many_arguments)]
pub fn flow_map_in<S, O>(
    system: &S,
    t0: f64,
    x0: &[f64],
    duration: f64,
    sensitivity: Sensitivity,
    settings: &Settings,
    observer: &mut O,
    workspace: &mut SolverWorkspace,
) -> Result<FlowMap, HybridError>
where
    S: HybridSystem + ?Sized,
    O: FnMut(&Solver<S>, &StepOutcome),
{
    flow_map_in_mode(
        system,
        t0,
        x0,
        None,
        duration,
        sensitivity,
        settings,
        observer,
        workspace,
    )
}

/// As [`flow_map`], started in `mode` instead of the mode [`HybridSystem::mode_of`] gives at
/// `(t0, x0)` ([`Solver::set_mode`]): the continuation of a flow that ended in `mode` (its
/// [`FlowMap::mode`]), for a hysteretic system whose mode the state alone does not tell.
///
/// # Errors
/// As [`flow_map`].
pub fn flow_map_from_mode<S: HybridSystem + ?Sized>(
    system: &S,
    t0: f64,
    x0: &[f64],
    mode: Mode,
    duration: f64,
    sensitivity: Sensitivity,
    settings: &Settings,
) -> Result<FlowMap, HybridError> {
    flow_map_in_mode(
        system,
        t0,
        x0,
        Some(mode),
        duration,
        sensitivity,
        settings,
        &mut |_: &Solver<S>, _: &StepOutcome| {},
        &mut SolverWorkspace::default(),
    )
}

/// [`flow_map_in`] in `mode` if given, else in [`HybridSystem::mode_of`]'s.
#[allow(clippy::too_many_arguments)]
fn flow_map_in_mode<S, O>(
    system: &S,
    t0: f64,
    x0: &[f64],
    mode: Option<Mode>,
    duration: f64,
    sensitivity: Sensitivity,
    settings: &Settings,
    observer: &mut O,
    workspace: &mut SolverWorkspace,
) -> Result<FlowMap, HybridError>
where
    S: HybridSystem + ?Sized,
    O: FnMut(&Solver<S>, &StepOutcome),
{
    let t_end = t0 + duration;
    if !duration.is_finite() || duration < 0.0 || !t_end.is_finite() {
        return Err(HybridError::InvalidEndTime { t: t0, t_end });
    }
    let (event_count, extremum_count) = workspace
        .buffers
        .as_ref()
        .map_or((0, 0), |buffers| buffers.result_counts);
    let mut solver = Solver::with_workspace(
        system,
        t0,
        x0,
        sensitivity,
        settings.clone(),
        std::mem::take(workspace),
    )?;
    if let Some(mode) = mode {
        solver.set_mode(mode);
    }
    let mut events = Vec::with_capacity(event_count);
    let mut extrema = Vec::with_capacity(extremum_count);
    loop {
        let outcome = solver.step(t_end)?;
        extrema.extend_from_slice(solver.step_extrema());
        observer(&solver, &outcome);
        match outcome {
            StepOutcome::Internal => {}
            StepOutcome::Event(event) => events.push(event),
            StepOutcome::EndTime => break,
        }
    }
    let result_counts = (events.len(), extrema.len());
    let map = FlowMap {
        state: solver.state().to_vec(),
        transition: solver.transition().clone(),
        parameter_sensitivity: solver.parameter_sensitivity().to_vec(),
        events,
        extrema,
        statistics: *solver.statistics(),
        mode: solver.mode(),
    };
    *workspace = solver.into_workspace();
    if let Some(buffers) = workspace.buffers.as_mut() {
        buffers.result_counts = result_counts;
    }
    Ok(map)
}
