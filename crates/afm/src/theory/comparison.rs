//! The paper's predictions (Eqs. 3 and 4) beside the same quantities measured on a simulated
//! steady orbit, with relative errors: where the single-harmonic, short-contact theory holds.

use hybrid::Settings;
use serde::Serialize;

use super::{measure_impacts, ImpactMeasurement, ImpactPrediction, ImpactTheory};
use crate::{AfmError, SteadyOrbit, TappingModel};

/// Predictions and measurements side by side for one orbit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TheoryComparison {
    /// The theory's constants for the model.
    pub theory: ImpactTheory,
    /// The predictions with `phi` = the phase of the simulated orbit's first harmonic of `q_1`
    /// (the paper's `phi`): the comparison proper.
    pub prediction: ImpactPrediction,
    /// The predictions with `phi` = the phase `Phi` of `u` (what an instrument measures; it
    /// differs from `q_1`'s by `chi_2 q_2`'s share of the first harmonic).
    pub prediction_from_u_phase: ImpactPrediction,
    /// What the simulated orbit shows.
    pub measurement: ImpactMeasurement,
    /// `(Eq. 3 - simulated impulse per period) / simulated impulse`; NaN without contact.
    pub impulse_relative_error: f64,
    /// Eq. 4's initial amplitude with the simulated main impact's impulse instead of Eq. 3's,
    /// `w_2^2 / (k_2 w_2d) * impulse`, nm: separates the impulse-response idealisation (an
    /// instantaneous kick on a free mode) from the error of Eq. 3.
    pub q2_initial_amplitude_from_simulated_impulse_nm: f64,
    /// `(Eq. 4 initial amplitude - measured ringing amplitude) / measured`; NaN without a
    /// measured ringing.
    pub q2_initial_amplitude_relative_error: f64,
    /// `(Eq. 4 decay over a period - measured) / measured`; NaN without a measured ringing.
    pub q2_decay_over_period_relative_error: f64,
}

/// Compare the theory with `orbit`, a converged period-1 steady orbit of `model`.
pub fn compare_theory(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    settings: &Settings,
) -> Result<TheoryComparison, AfmError> {
    let theory = ImpactTheory::new(model)?;
    let measurement = measure_impacts(model, orbit, settings)?;
    let prediction = theory.predict(measurement.q1_phase_deg);
    let prediction_from_u_phase = theory.predict(measurement.u_phase_deg);
    let relative = |predicted: f64, measured: f64| {
        if measured != 0.0 && measured.is_finite() {
            (predicted - measured) / measured
        } else {
            f64::NAN
        }
    };
    let main_impulse = measurement
        .main_impact
        .map_or(0.0, |index| measurement.impacts[index].impulse_nn_us);
    let ringing = measurement.ringing;
    Ok(TheoryComparison {
        impulse_relative_error: relative(prediction.impulse_nn_us, measurement.impulse_nn_us),
        q2_initial_amplitude_from_simulated_impulse_nm: main_impulse
            * theory.q2_amplitude_per_impulse,
        q2_initial_amplitude_relative_error: ringing.map_or(f64::NAN, |r| {
            relative(prediction.q2_initial_amplitude_nm, r.initial_amplitude_nm)
        }),
        q2_decay_over_period_relative_error: ringing.map_or(f64::NAN, |r| {
            relative(prediction.q2_decay_over_period, r.decay_over_period)
        }),
        theory,
        prediction,
        prediction_from_u_phase,
        measurement,
    })
}
