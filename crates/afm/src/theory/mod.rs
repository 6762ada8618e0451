//! The paper's approximate theory of the single-impact regime (its Eqs. 2-4 and the numbers
//! `lambda_1..3`; MODEL.md section 7), and the same quantities measured on a simulated steady
//! orbit, so that the two can be compared:
//!
//! - [`ImpactTheory`]: the constants of Eqs. 3 and 4 for a model, and the predictions
//!   ([`ImpactPrediction`]) for a given phase `phi` of `q_1`;
//! - [`measure_impacts`]: the impulse per period, the impacts, the first harmonic of `q_1` and the
//!   free ringing of `q_2` after the main impact, measured on a period-1 orbit
//!   ([`ImpactMeasurement`], [`Ringing`]);
//! - [`compare_theory`]: both side by side with relative errors ([`TheoryComparison`]), and
//!   where the theory's assumptions fail on the orbit ([`AssumptionFailure`]): there the
//!   predictions it would give are withheld or flagged.

mod comparison;
pub mod impact_numbers;
mod measurement;
mod prediction;
mod validity;

pub use comparison::{compare_theory, TheoryComparison};
pub use measurement::{measure_impacts, ImpactImpulse, ImpactMeasurement, Ringing};
pub use prediction::{ImpactPrediction, ImpactTheory};
pub use validity::{AssumptionFailure, THEORY_MAX_CONTACT_PERIODS, THEORY_MIN_SEPARATION_NM};
