//! A hybrid system with a second scalar parameter `q` besides the continuation parameter `p`,
//! and its period map over a whole number of forcing periods from a section time `t0`, as the
//! two-parameter continuation of codimension-one points needs it (MODEL.md Sec. 5).
//!
//! The solver's sensitivities are with respect to `p` only; derivatives with respect to `q`
//! are taken by forward finite differences of whole flows (the residuals stay exact, so
//! Newton's method still converges to the exact root, only no longer quadratically).

use std::cell::RefCell;

use hybrid::{flow_map, Direction, ExtremumKind, FlowMap, HybridSystem, Sensitivity, Settings};

use crate::error::ContinuationError;
use crate::hybrid_problem::Parametrised;
use crate::problem::OrbitStructure;

/// A [`Parametrised`] hybrid system with a second parameter `q` that it sets on itself (the
/// impact oscillator's drive frequency, say). Setting `q` may change the forcing period:
/// [`Parametrised::period`] is read after every [`TwoParametrised::set_second_parameter`].
/// Every such system is a [`SystemFamily`] of its clones.
pub trait TwoParametrised: Parametrised {
    /// The current value of the second parameter (its own units).
    fn second_parameter(&self) -> f64;
    /// Set the second parameter, keeping the first.
    ///
    /// # Errors
    /// A message saying why `q` is not allowed (outside the system's physical range).
    fn set_second_parameter(&mut self, q: f64) -> Result<(), String>;
}

/// A one-parameter family of [`Parametrised`] systems, indexed by the second parameter `q`:
/// for systems that are rebuilt rather than adjusted when `q` changes (the AFM model, whose
/// drive, modal constants and contact law follow from its inputs).
pub trait SystemFamily {
    /// The member systems.
    type System: Parametrised;
    /// The member at `q` (its first parameter is then set by the caller).
    ///
    /// # Errors
    /// A message saying why `q` is not allowed (outside the family's physical range).
    fn system_at(&self, q: f64) -> Result<Self::System, String>;
}

impl<S: TwoParametrised> SystemFamily for S {
    type System = S;
    fn system_at(&self, q: f64) -> Result<S, String> {
        let mut system = self.clone();
        system.set_second_parameter(q)?;
        Ok(system)
    }
}

/// Members kept built (the value, its neighbours of the finite differences in `q`).
const CACHED_MEMBERS: usize = 4;

/// The periodic-orbit problem of a [`SystemFamily`]: flows from a section time over `periods`
/// forcing periods at `(p, q)`. The last few members built are kept.
pub struct TwoParameterProblem<F: SystemFamily> {
    family: F,
    members: RefCell<Vec<(f64, F::System)>>,
    periods: usize,
    settings: Settings,
}

impl<F: SystemFamily> TwoParameterProblem<F> {
    /// The problem of orbits of `periods` forcing periods (`>= 1`) integrated with `settings`.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidSettings`] for `periods == 0` or a contact surface beyond
    /// the system's surfaces; [`ContinuationError::Hybrid`] for invalid solver settings.
    /// The member at `q0` must exist (it fixes the dimension and the contact surface).
    pub fn new(
        family: F,
        q0: f64,
        periods: usize,
        settings: Settings,
    ) -> Result<Self, ContinuationError> {
        let system = family
            .system_at(q0)
            .map_err(|message| ContinuationError::SecondParameter { value: q0, message })?;
        if periods == 0 {
            return Err(ContinuationError::InvalidSettings {
                field: "periods",
                value: 0.0,
                allowed: ">= 1",
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
        Ok(Self {
            family,
            members: RefCell::new(vec![(q0, system)]),
            periods,
            settings,
        })
    }

    /// Dimension `n` of the state.
    pub fn dim(&self) -> usize {
        self.members.borrow()[0].1.dim()
    }

    /// Forcing periods per period map.
    pub fn periods(&self) -> usize {
        self.periods
    }

    /// The solver settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// A copy of the system at `(p, q)`.
    ///
    /// # Errors
    /// [`ContinuationError::SecondParameter`] if the system refuses `q`.
    pub fn system_at(&self, p: f64, q: f64) -> Result<F::System, ContinuationError>
    where
        F::System: Clone,
    {
        self.with_system(p, q, |system| system.clone())
    }

    /// Duration `periods * T(q)` of one period map at `q` (system time units).
    ///
    /// # Errors
    /// [`ContinuationError::SecondParameter`] if the system refuses `q`.
    pub fn duration(&self, q: f64) -> Result<f64, ContinuationError> {
        let index = self.member(q)?;
        Ok(self.periods as f64 * self.members.borrow()[index].1.period())
    }

    /// Index of the member at `q` in the cache, building it if needed (beyond
    /// [`CACHED_MEMBERS`] the oldest member is dropped).
    fn member(&self, q: f64) -> Result<usize, ContinuationError> {
        if let Some(i) = self.members.borrow().iter().position(|(v, _)| *v == q) {
            return Ok(i);
        }
        let system = self
            .family
            .system_at(q)
            .map_err(|message| ContinuationError::SecondParameter { value: q, message })?;
        let mut members = self.members.borrow_mut();
        if members.len() >= CACHED_MEMBERS {
            members.remove(0);
        }
        members.push((q, system));
        Ok(members.len() - 1)
    }

    /// Run `f` on the member at `q` with its first parameter set to `p`.
    fn on_member<R>(
        &self,
        p: f64,
        q: f64,
        f: impl FnOnce(&F::System) -> R,
    ) -> Result<R, ContinuationError> {
        let index = self.member(q)?;
        let mut members = self.members.borrow_mut();
        let system = &mut members[index].1;
        system.set_parameter(p);
        Ok(f(system))
    }

    /// The flow from `(t_from, x)` over `duration` at `(p, q)` with the requested
    /// sensitivities (event and extremum times absolute).
    ///
    /// # Errors
    /// [`ContinuationError::SecondParameter`] or [`ContinuationError::Hybrid`].
    pub fn flow(
        &self,
        x: &[f64],
        p: f64,
        q: f64,
        t_from: f64,
        duration: f64,
        sensitivity: Sensitivity,
    ) -> Result<FlowMap, ContinuationError> {
        self.flow_in(x, None, p, q, t_from, duration, sensitivity)
    }

    /// As [`Self::flow`], started in `mode` if given (the mode an earlier flow ended in, its
    /// [`FlowMap::mode`]: a period map split at a grazing continues in it, as the state alone
    /// does not tell a hysteretic system's mode there), else in the system's `mode_of`.
    ///
    /// # Errors
    /// As [`Self::flow`].
    #[allow(clippy::too_many_arguments)]
    pub fn flow_in(
        &self,
        x: &[f64],
        mode: Option<hybrid::Mode>,
        p: f64,
        q: f64,
        t_from: f64,
        duration: f64,
        sensitivity: Sensitivity,
    ) -> Result<FlowMap, ContinuationError> {
        self.on_member(p, q, |system| match mode {
            Some(mode) => hybrid::flow_map_from_mode(
                system,
                t_from,
                x,
                mode,
                duration,
                sensitivity,
                &self.settings,
            ),
            None => flow_map(system, t_from, x, duration, sensitivity, &self.settings),
        })?
        .map_err(|source| ContinuationError::Hybrid {
            parameter: p,
            source,
        })
    }

    /// Run `f` on the system set to `(p, q)` (switching functions, vector field, ...).
    ///
    /// # Errors
    /// [`ContinuationError::SecondParameter`] if the system refuses `q`.
    pub fn with_system<R>(
        &self,
        p: f64,
        q: f64,
        f: impl FnOnce(&F::System) -> R,
    ) -> Result<R, ContinuationError> {
        self.on_member(p, q, f)
    }

    /// The structure of the contact switching function over flows that together cover one
    /// period map from `t0` (extremum times measured from `t0`; hard impacts are counted but,
    /// unlike [`crate::HybridPeriodicProblem`], not given virtual minima). `x0` is the state
    /// at `t0`, used for the in-contact-throughout case.
    ///
    /// # Errors
    /// [`ContinuationError::SecondParameter`] if the system refuses `q`.
    pub fn structure(
        &self,
        flows: &[&FlowMap],
        t0: f64,
        duration: f64,
        x0: &[f64],
        p: f64,
        q: f64,
    ) -> Result<OrbitStructure, ContinuationError> {
        self.on_member(p, q, |system| structure_of(system, flows, t0, duration, x0))
    }
}

/// The orbit structure over `flows` (see [`TwoParameterProblem::structure`]).
fn structure_of<S: Parametrised>(
    system: &S,
    flows: &[&FlowMap],
    t0: f64,
    duration: f64,
    x0: &[f64],
) -> OrbitStructure {
    let k = system.contact_surface();
    let mut structure = OrbitStructure {
        duration,
        ..OrbitStructure::default()
    };
    let mut crossings = 0;
    for flow in flows {
        for extremum in flow.extrema.iter().filter(|e| e.surface == k) {
            let entry = (extremum.t - t0, extremum.value);
            match extremum.kind {
                ExtremumKind::Minimum => structure.minima.push(entry),
                ExtremumKind::Maximum => structure.maxima.push(entry),
            }
        }
        for event in flow.events.iter().filter(|e| e.surface == k) {
            crossings += 1;
            if event.direction == Direction::Down {
                structure.impacts += 1;
            }
        }
    }
    if crossings == 0 && system.switching(k, t0, x0) < 0.0 {
        structure.permanent_contact = true;
        structure.impacts = 1;
    }
    structure.minima.sort_by(|a, b| a.0.total_cmp(&b.0));
    structure.maxima.sort_by(|a, b| a.0.total_cmp(&b.0));
    structure
}
