//! The period-1 problem of a bifurcation diagram whose corrector records the observables of
//! the orbits it expects to accept (MODEL.md sections 4, 6 and 10): the integration that
//! checks Newton's convergence at a branch point is the point's period, so its observables
//! are recorded along it instead of integrating the accepted point once more.
//!
//! The period map itself is [`HybridPeriodicProblem`]'s, unchanged: the solver's steps do not
//! depend on the sensitivities it carries (their error is not controlled), so the trajectory
//! and the observables recorded along it are those of a state-only integration from the same
//! state, bit for bit (the output snapshot script checks this on every built-in case).

use std::cell::RefCell;

use continuation::{
    ContinuationError, HybridPeriodicProblem, Parametrised, PeriodMap, PeriodicProblem,
};
use hybrid::{Settings, Solver, StepOutcome};

use crate::error::AfmError;
use crate::model::TappingModel;
use crate::orbit::observables::{orbit_observables, OrbitObservables, PeriodObserver};

/// How many recorded orbits are kept: the corrector's last few likely-accepted evaluations
/// (a trial rejected after convergence, for a turn or a wander, is followed by another).
const KEPT_ORBITS: usize = 4;

/// One recorded orbit: the start state and separation `Z` (nm) of the period map, with the
/// observables of that period.
struct RecordedOrbit {
    state: Vec<f64>,
    z_nm: f64,
    observables: OrbitObservables,
}

/// The period map `x -> x(T)` of the tapping model at separation `Z` (the continuation's
/// parameter), recording harmonics `1..=harmonics` and every other observable of the period
/// whenever the corrector evaluates it at a point it expects to accept
/// ([`PeriodicProblem::period_map_likely_accepted`]).
pub struct ObservedPeriodProblem {
    problem: HybridPeriodicProblem<TappingModel>,
    model: RefCell<TappingModel>,
    integration: Settings,
    harmonics: usize,
    recorded: RefCell<Vec<RecordedOrbit>>,
}

impl ObservedPeriodProblem {
    /// The period-1 problem of `model` (its separation constant; the continuation sets `Z`)
    /// integrated with `integration`, recording harmonics `1..=harmonics` of `u`.
    ///
    /// # Errors
    /// As [`HybridPeriodicProblem::new`] (invalid solver settings).
    pub fn new(
        model: &TappingModel,
        integration: &Settings,
        harmonics: usize,
    ) -> Result<Self, AfmError> {
        Ok(Self {
            problem: HybridPeriodicProblem::new(model.clone(), 1, integration.clone())?,
            model: RefCell::new(model.clone()),
            integration: integration.clone(),
            harmonics,
            recorded: RefCell::new(Vec::with_capacity(KEPT_ORBITS)),
        })
    }

    /// The observables of the period from `state` at separation `z_nm` (MODEL.md sections 4
    /// and 10): the recorded ones when the corrector's last accepted evaluation started from
    /// exactly this state and `Z` (the usual case for a branch point), else integrated now
    /// ([`orbit_observables`]); the same numbers either way.
    ///
    /// # Errors
    /// A failed integration.
    pub fn observables(&self, state: &[f64], z_nm: f64) -> Result<OrbitObservables, AfmError> {
        let mut recorded = self.recorded.borrow_mut();
        if let Some(index) = recorded
            .iter()
            .position(|orbit| orbit.z_nm == z_nm && orbit.state.as_slice() == state)
        {
            return Ok(recorded.swap_remove(index).observables);
        }
        drop(recorded);
        let mut model = self.model.borrow_mut();
        model.set_parameter(z_nm);
        orbit_observables(&model, state, &self.integration, self.harmonics)
    }
}

impl PeriodicProblem for ObservedPeriodProblem {
    fn dim(&self) -> usize {
        self.problem.dim()
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        self.problem.period_map(x, p)
    }

    fn period_map_likely_accepted(
        &self,
        x: &[f64],
        p: f64,
    ) -> Result<PeriodMap, ContinuationError> {
        if x.len() != self.dim() {
            return self.problem.period_map(x, p);
        }
        let mut model = self.model.borrow_mut();
        model.set_parameter(p);
        let mut observer = PeriodObserver::new(&model, 0.0, x, self.harmonics);
        let map = self.problem.period_map_observed(
            x,
            p,
            &mut |solver: &Solver<TappingModel>, outcome: &StepOutcome| {
                observer.observe(solver, outcome)
            },
        )?;
        let observables = observer.finish(&model);
        let mut recorded = self.recorded.borrow_mut();
        if recorded.len() == KEPT_ORBITS {
            recorded.remove(0);
        }
        recorded.push(RecordedOrbit {
            state: x.to_vec(),
            z_nm: p,
            observables,
        });
        Ok(map)
    }
}
