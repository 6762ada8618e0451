//! A hybrid system with a second scalar parameter `q` besides the continuation parameter `p`,
//! and its period map over a whole number of forcing periods from a section time `t0`, as the
//! two-parameter continuation of codimension-one points needs it (MODEL.md Sec. 5).
//!
//! The solver's sensitivities are with respect to `p` only; derivatives with respect to `q`
//! are taken by forward finite differences of whole flows (the residuals stay exact, so
//! Newton's method still converges to the exact root, only no longer quadratically).

use std::cell::RefCell;

use hybrid::{flow_map, Direction, ExtremumKind, FlowMap, Sensitivity, Settings};

use crate::error::ContinuationError;
use crate::hybrid_problem::Parametrised;
use crate::problem::OrbitStructure;

/// A [`Parametrised`] hybrid system with a second parameter `q` (for the AFM model, the free
/// amplitude, the drive frequency, a sample or cantilever property). Setting `q` may change
/// the forcing period: [`Parametrised::period`] is read after every
/// [`TwoParametrised::set_second_parameter`].
pub trait TwoParametrised: Parametrised {
    /// The current value of the second parameter (its own units).
    fn second_parameter(&self) -> f64;
    /// Set the second parameter, keeping the first.
    ///
    /// # Errors
    /// A message saying why `q` is not allowed (outside the system's physical range).
    fn set_second_parameter(&mut self, q: f64) -> Result<(), String>;
}

/// The periodic-orbit problem of a [`TwoParametrised`] system: flows from a section time over
/// `periods` forcing periods at `(p, q)`.
pub struct TwoParameterProblem<S: TwoParametrised> {
    system: RefCell<S>,
    periods: usize,
    settings: Settings,
}

impl<S: TwoParametrised> TwoParameterProblem<S> {
    /// The problem of orbits of `periods` forcing periods (`>= 1`) integrated with `settings`.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidSettings`] for `periods == 0` or a contact surface beyond
    /// the system's surfaces; [`ContinuationError::Hybrid`] for invalid solver settings.
    pub fn new(system: S, periods: usize, settings: Settings) -> Result<Self, ContinuationError> {
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
            system: RefCell::new(system),
            periods,
            settings,
        })
    }

    /// Dimension `n` of the state.
    pub fn dim(&self) -> usize {
        self.system.borrow().dim()
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
    pub fn system_at(&self, p: f64, q: f64) -> Result<S, ContinuationError> {
        self.set(p, q)?;
        Ok(self.system.borrow().clone())
    }

    /// Duration `periods * T(q)` of one period map at `q` (system time units).
    ///
    /// # Errors
    /// [`ContinuationError::SecondParameter`] if the system refuses `q`.
    pub fn duration(&self, q: f64) -> Result<f64, ContinuationError> {
        let p = self.system.borrow().parameter();
        self.set(p, q)?;
        Ok(self.periods as f64 * self.system.borrow().period())
    }

    /// Set both parameters on the held system (`q` only when it changed).
    fn set(&self, p: f64, q: f64) -> Result<(), ContinuationError> {
        let mut system = self.system.borrow_mut();
        if system.second_parameter() != q {
            system
                .set_second_parameter(q)
                .map_err(|message| ContinuationError::SecondParameter { value: q, message })?;
        }
        system.set_parameter(p);
        Ok(())
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
        self.set(p, q)?;
        let system = self.system.borrow();
        flow_map(&*system, t_from, x, duration, sensitivity, &self.settings).map_err(|source| {
            ContinuationError::Hybrid {
                parameter: p,
                source,
            }
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
        f: impl FnOnce(&S) -> R,
    ) -> Result<R, ContinuationError> {
        self.set(p, q)?;
        Ok(f(&self.system.borrow()))
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
        self.set(p, q)?;
        let system = self.system.borrow();
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
        Ok(structure)
    }
}
