//! Periodic orbits of parametrised (hybrid) systems: shooting, Floquet stability and
//! pseudo-arclength continuation with labelled special points.
//!
//! The crate knows nothing about cantilevers. It works on a [`PeriodicProblem`], a period map
//! `P(x; p)` with its monodromy `dP/dx`, its parameter derivative `dP/dp` and the structure of
//! the orbit (the extrema of a contact switching function and the impacts per period,
//! MODEL.md Sec. 5):
//!
//! * [`shoot`]: Newton's method on `P(x; p) - x = 0` with the exact monodromy;
//! * [`floquet_multipliers`], [`is_stable`]: stability from the monodromy's eigenvalues;
//! * [`Continuation`]: pseudo-arclength continuation in `(x, p)` through folds, an iterator of
//!   [`BranchPoint`]s, which detects and locates [`SpecialPoint`]s: folds, period doubling,
//!   Neimark-Sacker, grazing `G<n>` (a minimum of the gap through zero), merging and
//!   splitting of impacts, and impact-count changes that are not grazing;
//! * [`continue_curve`]: two-parameter continuation of a grazing, fold or period-doubling
//!   point of a [`TwoParametrised`] hybrid system in `(p, q)`, with located
//!   codimension-two points ([`Codim2Point`]) and the reason each end stopped.
//!
//! ```
//! use continuation::{
//!     Continuation, ContinuationError, ContinuationSettings, OrbitStructure, PeriodMap,
//!     PeriodicProblem,
//! };
//! use nalgebra::{DMatrix, DVector};
//!
//! /// `P(x; p) = x + p - x^2`: fixed points `x = +-sqrt(p)`, a fold at `p = 0`.
//! struct Quadratic;
//!
//! impl PeriodicProblem for Quadratic {
//!     fn dim(&self) -> usize {
//!         1
//!     }
//!     fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
//!         Ok(PeriodMap {
//!             image: DVector::from_element(1, x[0] + p - x[0] * x[0]),
//!             monodromy: DMatrix::from_element(1, 1, 1.0 - 2.0 * x[0]),
//!             parameter_derivative: DVector::from_element(1, 1.0),
//!             structure: OrbitStructure::default(),
//!         })
//!     }
//! }
//!
//! let settings = ContinuationSettings {
//!     direction: continuation::ParameterDirection::Decreasing,
//!     parameter_max: 0.5,
//!     ..ContinuationSettings::default()
//! };
//! let branch = Continuation::new(&Quadratic, &[-0.5], 0.25, settings)?.run();
//! let fold = &branch.special_points[0];
//! assert_eq!(fold.label, "fold");
//! assert!(fold.parameter.abs() < 1e-9 && fold.converged);
//! # Ok::<(), ContinuationError>(())
//! ```
#![warn(missing_docs)]

pub mod branch;
pub mod codim_one;
pub mod codim_two;
mod corrector;
pub mod curve;
mod curve_corrector;
pub mod curve_settings;
pub mod error;
mod extrapolated_zero;
pub mod floquet;
pub mod hermite;
pub mod hybrid_problem;
mod location;
pub mod problem;
pub mod settings;
pub mod shooting;
pub mod special_point;
pub mod test_function;
pub mod two_parameter;

pub use branch::{Branch, BranchPoint, Continuation, StopReason};
pub use codim_one::CodimOneKind;
pub use codim_two::{Codim2Kind, Codim2Point};
pub use curve::{
    continue_curve, continue_curve_until, Curve, CurveEnd, CurvePoint, CurveStart, CurveStop,
};
pub use curve_settings::CurveSettings;
pub use error::ContinuationError;
pub use floquet::{floquet_multipliers, is_stable, spectral_radius};
pub use hermite::hermite_basis;
pub use hybrid_problem::{HybridPeriodicProblem, Parametrised};
pub use problem::{OrbitStructure, PeriodMap, PeriodicProblem};
pub use settings::{ContinuationSettings, ParameterDirection};
pub use shooting::{newton_update, shoot, NewtonSettings, ShootingResult};
pub use special_point::{SpecialPoint, SpecialPointKind};
pub use test_function::{neimark_sacker_test, period_doubling_test, TestValues};
pub use two_parameter::{SystemFamily, TwoParameterProblem, TwoParametrised};
