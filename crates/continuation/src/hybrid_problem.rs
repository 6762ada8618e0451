//! The periodic-orbit problem of a parametrised hybrid system: its period map is the hybrid
//! solver's flow map over a whole number of forcing periods from `t0 = 0` (or another section
//! time), with the monodromy
//! and `dx/dp` carried through every event by saltation matrices.
//!
//! The orbit structure is read from the flow map: the local minima and maxima of the contact
//! switching function that the solver locates inside its steps, and the `Down` events on it
//! (impacts, MODEL.md Sec. 5). At a hard impact (a reset map) `h` has a corner at zero instead
//! of a smooth minimum; there the structure records the *virtual minimum* of the free flight
//! continued through the surface, `h_min = -v^2 / (2 a)` with `v = dh/dt` before the impact
//! and `a = d^2h/dt^2` (the parabola of the flight near the contact), so that the grazing test
//! function is continuous through the grazing of a hard impact as well: `v^2` grows linearly
//! with the distance past grazing (Nordmark's square-root law for `v`).

use std::cell::RefCell;

use hybrid::{
    flow_map_in, Direction, ExtremumKind, FlowMap, HybridSystem, Sensitivity, Settings, Solver,
    SolverWorkspace, StepOutcome,
};
use nalgebra::{DMatrix, DVector};

use crate::error::ContinuationError;
use crate::problem::{OrbitStructure, PeriodMap, PeriodicProblem};

/// A hybrid system with one scalar parameter and a periodic forcing, as continuation needs it.
pub trait Parametrised: HybridSystem + Clone {
    /// The current parameter value (for the AFM model, the separation `Z` in nm).
    fn parameter(&self) -> f64;
    /// Set the parameter (the derivatives `parameter_derivative`, `switching_gradient().p`
    /// and `reset`'s `dxdp` of [`HybridSystem`] are with respect to it).
    fn set_parameter(&mut self, p: f64);
    /// The forcing period `T` (system time units).
    fn period(&self) -> f64;
    /// The index of the switching function whose impacts and extrema define the orbit
    /// structure (the contact surface). Default 0.
    fn contact_surface(&self) -> usize {
        0
    }
    /// A release surface `r` and the mode bits `held` of a contact that forms on the contact
    /// surface and ends only at the `Up` crossing of `r` (a hysteretic contact: for the AFM,
    /// JKR's pull-off gap, MODEL.md section 9): the maxima of `h_r` in modes with a bit of
    /// `held` set, and the releases, make the orbit structure's
    /// [`OrbitStructure::release_maxima`]. Default `None`: no release surface.
    fn release_surface(&self) -> Option<(usize, hybrid::Mode)> {
        None
    }
}

/// The period map `x -> x(periods * T)` from `t0 = 0` of a [`Parametrised`] hybrid system.
pub struct HybridPeriodicProblem<S: Parametrised> {
    system: RefCell<S>,
    periods: usize,
    start_time: f64,
    settings: Settings,
    buffers: RefCell<Buffers>,
    /// The solver's buffers, reused by every period map (`hybrid::flow_map_in`: the same run
    /// without a new solver's allocations).
    workspace: RefCell<SolverWorkspace>,
}

/// Scratch vectors for the virtual-minimum estimate.
struct Buffers {
    field: Vec<f64>,
    shifted: Vec<f64>,
}

impl<S: Parametrised> HybridPeriodicProblem<S> {
    /// The problem of the orbits of period `periods * system.period()` (`periods >= 1`),
    /// integrated with `settings`.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidSettings`] for `periods == 0`, a non-positive or
    /// non-finite period, or a contact surface beyond the system's surfaces;
    /// [`ContinuationError::Hybrid`] for invalid solver settings.
    pub fn new(system: S, periods: usize, settings: Settings) -> Result<Self, ContinuationError> {
        if periods == 0 {
            return Err(ContinuationError::InvalidSettings {
                field: "periods",
                value: 0.0,
                allowed: ">= 1",
            });
        }
        let period = system.period();
        if !(period.is_finite() && period > 0.0) {
            return Err(ContinuationError::InvalidSettings {
                field: "period",
                value: period,
                allowed: "> 0, finite",
            });
        }
        if system.contact_surface() >= system.surface_count() {
            return Err(ContinuationError::InvalidSettings {
                field: "contact_surface",
                value: system.contact_surface() as f64,
                allowed: "< surface_count",
            });
        }
        settings
            .validate()
            .map_err(|source| ContinuationError::Hybrid {
                parameter: system.parameter(),
                source,
            })?;
        let n = system.dim();
        Ok(Self {
            system: RefCell::new(system),
            periods,
            start_time: 0.0,
            settings,
            buffers: RefCell::new(Buffers {
                field: vec![0.0; n],
                shifted: vec![0.0; n],
            }),
            workspace: RefCell::new(SolverWorkspace::default()),
        })
    }

    /// The same problem with the Poincare section at time `t0` instead of 0 (the period map
    /// is then `x(t0) -> x(t0 + periods T)` and extremum times are measured from `t0`).
    ///
    /// With a reset map the period map is discontinuous where an impact happens exactly at
    /// the section time, so a branch of a hard-impact system stops where its impact time
    /// crosses `t0`; another section moves that point. Continuous contact (Hertz) has no such
    /// discontinuity.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidSettings`] for a non-finite `t0`.
    pub fn with_start_time(mut self, t0: f64) -> Result<Self, ContinuationError> {
        if !t0.is_finite() {
            return Err(ContinuationError::InvalidSettings {
                field: "start_time",
                value: t0,
                allowed: "finite",
            });
        }
        self.start_time = t0;
        Ok(self)
    }

    /// The time `t0` of the Poincare section (0 unless set by
    /// [`HybridPeriodicProblem::with_start_time`]).
    pub fn start_time(&self) -> f64 {
        self.start_time
    }

    /// A copy of the system with its parameter set to `p` (to integrate observables on a
    /// branch point, for example with `hybrid::flow_map_observed`).
    pub fn system_at(&self, p: f64) -> S {
        let mut system = self.system.borrow().clone();
        system.set_parameter(p);
        system
    }

    /// Number of forcing periods in one period map.
    pub fn periods(&self) -> usize {
        self.periods
    }

    /// Duration of one period map, `periods * T` (system time units).
    pub fn duration(&self) -> f64 {
        self.periods as f64 * self.system.borrow().period()
    }

    /// The solver settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The flow map over one period map at `(x, p)` from the section time, with the requested
    /// sensitivities (event and extremum times are absolute).
    ///
    /// # Errors
    /// [`ContinuationError::Hybrid`] if the integration fails.
    pub fn flow(
        &self,
        x: &[f64],
        p: f64,
        sensitivity: Sensitivity,
    ) -> Result<FlowMap, ContinuationError> {
        self.flow_observed(x, p, sensitivity, &mut |_: &Solver<S>, _: &StepOutcome| {})
    }

    /// As [`HybridPeriodicProblem::flow`], calling `observer` after every step of the solver
    /// (as `hybrid::flow_map_observed` does): the same flow map, with whatever the observer
    /// records along it.
    ///
    /// # Errors
    /// [`ContinuationError::Hybrid`] if the integration fails.
    pub fn flow_observed(
        &self,
        x: &[f64],
        p: f64,
        sensitivity: Sensitivity,
        observer: &mut dyn FnMut(&Solver<S>, &StepOutcome),
    ) -> Result<FlowMap, ContinuationError> {
        self.system.borrow_mut().set_parameter(p);
        let system = self.system.borrow();
        let duration = self.periods as f64 * system.period();
        flow_map_in(
            &*system,
            self.start_time,
            x,
            duration,
            sensitivity,
            &self.settings,
            &mut |solver: &Solver<S>, outcome: &StepOutcome| observer(solver, outcome),
            &mut self.workspace.borrow_mut(),
        )
        .map_err(|source| ContinuationError::Hybrid {
            parameter: p,
            source,
        })
    }

    /// `-v^2 / (2 a)` for a hard impact at time `t` with pre-impact rate `v` and post-impact
    /// state `x`: `a = d^2h/dt^2` by a forward difference of `dh/dt` along the flow
    /// (continuous through the reset up to `O(v)`, which vanishes at grazing).
    fn virtual_minimum(&self, system: &S, k: usize, t: f64, v: f64, x: &[f64]) -> f64 {
        self.virtual_extremum(system, k, system.mode_of(t, x), t, v, x)
    }

    /// `-v^2 / (2 |a|)` for surface `k` crossed at time `t` with rate `v` from state `x`, with
    /// `a = d^2h/dt^2` of mode `mode`'s flow by a forward difference of `dh/dt`: minus the
    /// height of the parabola's extremum beyond the surface.
    fn virtual_extremum(
        &self,
        system: &S,
        k: usize,
        mode: hybrid::Mode,
        t: f64,
        v: f64,
        x: &[f64],
    ) -> f64 {
        let mut buffers = self.buffers.borrow_mut();
        let Buffers { field, shifted } = &mut *buffers;
        system.vector_field(mode, t, x, field);
        let scale = system.period();
        let delta = 1e-7 * scale;
        for ((s, xi), fi) in shifted.iter_mut().zip(x).zip(field.iter()) {
            *s = xi + delta * fi;
        }
        let r0 = system.switching_rate(k, mode, t, x);
        let r1 = system.switching_rate(k, mode, t + delta, shifted);
        let a = (r1 - r0) / delta;
        -v * v / (2.0 * a.abs().max(f64::MIN_POSITIVE))
    }
}

impl<S: Parametrised> PeriodicProblem for HybridPeriodicProblem<S> {
    fn dim(&self) -> usize {
        self.system.borrow().dim()
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        self.period_map_observed(x, p, &mut |_: &Solver<S>, _: &StepOutcome| {})
    }
}

impl<S: Parametrised> HybridPeriodicProblem<S> {
    /// The period map at `(x, p)` ([`PeriodicProblem::period_map`]), calling `observer` after
    /// every step of the integration (as [`HybridPeriodicProblem::flow_observed`]): the same
    /// map, and what the observer records along the orbit it integrates (the AFM diagram's
    /// observables of an accepted point, without integrating the point once more).
    ///
    /// # Errors
    /// As [`PeriodicProblem::period_map`].
    pub fn period_map_observed(
        &self,
        x: &[f64],
        p: f64,
        observer: &mut dyn FnMut(&Solver<S>, &StepOutcome),
    ) -> Result<PeriodMap, ContinuationError> {
        let n = self.dim();
        if x.len() != n {
            return Err(ContinuationError::DimensionMismatch {
                what: "state of the period map",
                expected: n,
                found: x.len(),
            });
        }
        let flow = self.flow_observed(x, p, Sensitivity::TransitionAndParameter, observer)?;
        let system = self.system.borrow();
        let k = system.contact_surface();
        let duration = self.periods as f64 * system.period();
        // The contact surface's extrema, and its impacts with a virtual minimum: the sizes of
        // the structure's lists (allocated once each instead of grown).
        let on_contact = |kind| {
            flow.extrema
                .iter()
                .filter(|e| e.surface == k && e.kind == kind)
                .count()
        };
        let virtual_minima = flow
            .events
            .iter()
            .filter(|e| e.surface == k && e.direction == Direction::Down && e.reset)
            .count();
        let mut structure = OrbitStructure {
            minima: Vec::with_capacity(on_contact(ExtremumKind::Minimum) + virtual_minima),
            maxima: Vec::with_capacity(on_contact(ExtremumKind::Maximum)),
            impacts: 0,
            permanent_contact: false,
            duration,
            release_maxima: Vec::new(),
        };
        if let Some((r, held)) = system.release_surface() {
            for extremum in flow
                .extrema
                .iter()
                .filter(|e| e.surface == r && e.kind == ExtremumKind::Maximum && e.mode & held != 0)
            {
                structure
                    .release_maxima
                    .push((extremum.t - self.start_time, extremum.value));
            }
            for event in flow
                .events
                .iter()
                .filter(|e| e.surface == r && e.direction == Direction::Up && e.mode & held != 0)
            {
                let value = -self.virtual_extremum(
                    &system,
                    r,
                    event.mode,
                    event.t,
                    event.rate,
                    &event.state,
                );
                structure
                    .release_maxima
                    .push((event.t - self.start_time, value));
            }
            structure.release_maxima.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        for extremum in flow.extrema.iter().filter(|e| e.surface == k) {
            let entry = (extremum.t - self.start_time, extremum.value);
            match extremum.kind {
                ExtremumKind::Minimum => structure.minima.push(entry),
                ExtremumKind::Maximum => structure.maxima.push(entry),
            }
        }
        for event in flow
            .events
            .iter()
            .filter(|e| e.surface == k && e.direction == Direction::Down)
        {
            structure.impacts += 1;
            if event.reset {
                let value = self.virtual_minimum(&system, k, event.t, event.rate, &event.state);
                structure.minima.push((event.t - self.start_time, value));
            }
        }
        // No crossing of the surface at all from a start inside it: in contact throughout, one
        // impact (a maximal interval with h < 0 that is the whole period).
        if !flow.events.iter().any(|e| e.surface == k)
            && system.switching(k, self.start_time, x) < 0.0
        {
            structure.permanent_contact = true;
            structure.impacts = 1;
        }
        structure.minima.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(PeriodMap {
            image: DVector::from_vec(flow.state),
            monodromy: DMatrix::from(flow.transition),
            parameter_derivative: DVector::from_vec(flow.parameter_sensitivity),
            structure,
        })
    }
}
