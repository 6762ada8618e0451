//! `hybrid`: a solver for piecewise-smooth (hybrid) ordinary differential equations.
//!
//! It knows nothing about cantilevers: a system states its vector fields, switching surfaces,
//! reset maps and exact flows through [`HybridSystem`]; the solver integrates it, stops exactly
//! at every switching surface, finds every local extremum of every switching function (so that a
//! grazing contact is never missed), and carries the state-transition (monodromy) matrix and the
//! parameter sensitivity through events with saltation matrices.
#![warn(missing_docs)]

pub mod system;

pub use system::{Direction, HybridSystem, Mode, SwitchingPartials, MAX_SURFACES};
