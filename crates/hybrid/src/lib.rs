//! `hybrid`: a solver for piecewise-smooth (hybrid) ordinary differential equations.
//!
//! It knows nothing about cantilevers: a system states its vector fields, switching surfaces and
//! reset maps through [`HybridSystem`]; the solver integrates it, stops exactly
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
//! [`crate::SwitchingStructure::switching_is_affine`] and [`Settings::extremum_height`]). With
//! sensitivities, `sensitivity_tolerance` trades accuracy of the transition matrix against
//! steps where the Jacobian is not smooth (Hertz contact), and `sensitivity_method` chooses
//! between the variational equations carried in the state's Runge-Kutta system (the exact
//! derivative of the numerical flow) and a cheaper integration apart from the state's steps
//! (enough for Newton); see their documentation.
//!
//! # A system: the core, and optional accelerations
//!
//! A model implements [`HybridSystem`]: its dimension, the vector field of each mode and its
//! Jacobian, its switching functions with their rates and gradients, and (for hard impacts)
//! its reset maps. That is all the solver needs for every event guarantee (each crossing
//! located and fired once, every extremum of every switching function reported, the
//! monodromy matrix carried through each event by its saltation matrix). What a model may add
//! to be integrated faster is apart, in [`accelerations`]: closed-form flows ([`ExactFlow`]),
//! Taylor series ([`TaylorExpansion`]), and what is known of the shape of its switching
//! functions ([`SwitchingStructure`]), listed by [`HybridSystem::accelerations`] (none by
//! default).
//!
//! A ball `x'' = -g` dropped from rest at height 1 onto the floor `h = x` with restitution
//! `e` (reset `v+ = -e v-`) implements only the core. Its impacts are at `t_1 = sqrt(2 / g)`
//! and `t_1 + 2 e t_1`, and each multiplies the determinant of the transition matrix by `e^2`
//! (the saltation matrix `[[-e, 0], [-(1 + e) g / v-, -e]]`; the free flight preserves area).
//! DOP853 is exact on the parabolas, so the numbers agree to the event location's tolerance:
//!
//! ```
//! use hybrid::{flow_map, Direction, HybridSystem, Mode, Sensitivity, Settings, SwitchingPartials};
//! use nalgebra::DMatrix;
//!
//! /// A ball `x'' = -g` (state `(x, v)`) bouncing on the floor `x = 0` with restitution `e`.
//! struct BouncingBall {
//!     g: f64,
//!     e: f64,
//! }
//!
//! impl HybridSystem for BouncingBall {
//!     fn dim(&self) -> usize {
//!         2
//!     }
//!     fn surface_count(&self) -> usize {
//!         1
//!     }
//!     fn vector_field(&self, _mode: Mode, _t: f64, x: &[f64], dxdt: &mut [f64]) {
//!         dxdt[0] = x[1];
//!         dxdt[1] = -self.g;
//!     }
//!     fn jacobian(&self, _mode: Mode, _t: f64, _x: &[f64], jacobian: &mut DMatrix<f64>) {
//!         jacobian.fill(0.0);
//!         jacobian[(0, 1)] = 1.0;
//!     }
//!     fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
//!         x[0]
//!     }
//!     fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
//!         x[1]
//!     }
//!     fn switching_gradient(
//!         &self,
//!         _k: usize,
//!         _t: f64,
//!         _x: &[f64],
//!         g: &mut [f64],
//!     ) -> SwitchingPartials {
//!         g.copy_from_slice(&[1.0, 0.0]);
//!         SwitchingPartials::default()
//!     }
//!     fn has_reset(&self, _k: usize, direction: Direction) -> bool {
//!         direction == Direction::Down
//!     }
//!     fn reset(
//!         &self,
//!         _k: usize,
//!         _direction: Direction,
//!         _t: f64,
//!         x: &mut [f64],
//!         jacobian: &mut DMatrix<f64>,
//!         dxdp: &mut [f64],
//!     ) {
//!         x[1] *= -self.e;
//!         jacobian.fill_with_identity();
//!         jacobian[(1, 1)] = -self.e;
//!         dxdp.fill(0.0);
//!     }
//! }
//!
//! let ball = BouncingBall { g: 9.81, e: 0.5 };
//! let settings = Settings::default();
//! let map = flow_map(&ball, 0.0, &[1.0, 0.0], 1.0, Sensitivity::Transition, &settings)?;
//! let t1 = (2.0 / ball.g).sqrt();
//! assert_eq!(map.events.len(), 2);
//! assert!((map.events[0].t - t1).abs() < 1e-9);
//! assert!((map.events[1].t - (t1 + 2.0 * ball.e * t1)).abs() < 1e-9);
//! assert!((map.transition.determinant() - ball.e.powi(4)).abs() < 1e-9);
//! # Ok::<(), hybrid::HybridError>(())
//! ```
#![warn(missing_docs)]

pub mod accelerations;
mod bernstein;
pub mod clock;
mod decoupled_tangents;
mod dop853;
pub mod error;
pub mod event;
mod event_location;
mod extrema;
pub mod flow_map;
mod mode;
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

pub use accelerations::{Accelerations, ExactFlow, SwitchingStructure, TaylorExpansion};
pub use clock::Clock;
pub use error::HybridError;
pub use event::{Event, Extremum, ExtremumKind};
pub use flow_map::{flow_map, flow_map_from_mode, flow_map_in, flow_map_observed, FlowMap};
pub use sensitivity::{LinearisationBuffers, Sensitivity};
pub use series_step::SHARED_SERIES_CAPACITY;
pub use settings::{SensitivityMethod, Settings};
pub use solver::{Solver, Statistics, StepOutcome};
pub use system::{Direction, HybridSystem, Mode, SwitchingPartials, MAX_SURFACES};
pub use taylor::{ClockPolynomial, TaylorSeries};
pub use workspace::SolverWorkspace;
