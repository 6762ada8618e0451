//! `hybrid`: a solver for piecewise-smooth (hybrid) ordinary differential equations.
//!
//! It knows nothing about cantilevers: a system states its vector fields, switching surfaces,
//! reset maps and exact flows through [`HybridSystem`]; the solver integrates it, stops exactly
//! at every switching surface, finds every local extremum of every switching function (so that a
//! grazing contact is never missed), and carries the state-transition (monodromy) matrix and the
//! parameter sensitivity through events with saltation matrices.
//!
//! * [`Solver::step`] is the primitive: one DOP853 step (Hairer's Dormand-Prince 8(5,3) with
//!   7th-order dense output) or one exact-flow step, truncated at the earliest event.
//! * [`flow_map()`] integrates over an interval on top of it.
//!
//! The rules that make events unique and the exact-grazing convention are documented in
//! [`solver`].
//!
//! Tuning ([`Settings`]): the cost of a step is its right-hand-side evaluations (15 per
//! accepted DOP853 step, 11 per rejected one) plus `samples_per_step + 1` evaluations of the
//! interpolant and of every `h_k`, `dh_k/dt`, and a few more per extremum and event (a step
//! proven to hold no extremum is sampled at its ends only: see
//! [`HybridSystem::switching_is_affine`] and [`Settings::extremum_height`]). With
//! sensitivities, `sensitivity_tolerance` trades accuracy of the transition matrix against
//! steps where the Jacobian is not smooth (Hertz contact), and `sensitivity_method` chooses
//! between the variational equations carried in the state's Runge-Kutta system (the exact
//! derivative of the numerical flow) and a cheaper integration apart from the state's steps
//! (enough for Newton); see their documentation.
#![warn(missing_docs)]

mod bernstein;
pub mod clock;
mod decoupled_tangents;
mod dop853;
pub mod error;
pub mod event;
mod event_location;
mod extrema;
pub mod flow_map;
mod saltation;
pub mod sensitivity;
mod series_step;
pub mod settings;
pub mod solver;
pub mod system;
mod tableau;
pub mod taylor;
mod variational_field;
pub mod workspace;

pub use clock::Clock;
pub use error::HybridError;
pub use event::{Event, Extremum, ExtremumKind};
pub use flow_map::{flow_map, flow_map_in, flow_map_observed, FlowMap};
pub use sensitivity::{LinearisationBuffers, Sensitivity};
pub use settings::{SensitivityMethod, Settings};
pub use solver::{Solver, Statistics, StepOutcome};
pub use system::{Direction, HybridSystem, Mode, SwitchingPartials, MAX_SURFACES};
pub use taylor::{ClockPolynomial, TaylorSeries};
pub use workspace::SolverWorkspace;
