//! The paper's predictions (Eqs. 3 and 4) beside the same quantities measured on a simulated
//! steady orbit, with relative errors: where the single-harmonic, short-contact theory holds,
//! and, where it does not, which assumption fails ([`AssumptionFailure`]) with the
//! predictions it would make meaningless withheld (`None`).

use hybrid::Settings;
use serde::Serialize;

use super::validity::{AssumptionFailure, THEORY_MAX_CONTACT_PERIODS, THEORY_MIN_SEPARATION_NM};
use super::{measure_impacts, ImpactMeasurement, ImpactPrediction, ImpactTheory};
use crate::error::AfmError;
use crate::model::TappingModel;
use crate::orbit::steady_orbit::SteadyOrbit;

/// Predictions and measurements side by side for one orbit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TheoryComparison {
    /// The theory's constants for the model (properties of the cantilever and drive, valid for
    /// every orbit).
    pub theory: ImpactTheory,
    /// The predictions with `phi` = the phase of the simulated orbit's first harmonic of `q_1`
    /// (the paper's `phi`): the comparison proper. `None` where an assumption failure
    /// withholds the predictions, or where `cos(phi) <= 0`.
    pub prediction: Option<ImpactPrediction>,
    /// The predictions with `phi` = the phase `Phi` of `u` (what an instrument measures; it
    /// differs from `q_1`'s by `chi_2 q_2`'s share of the first harmonic); `None` as for
    /// `prediction`.
    pub prediction_from_u_phase: Option<ImpactPrediction>,
    /// What the simulated orbit shows.
    pub measurement: ImpactMeasurement,
    /// Every assumption of the theory that this orbit violates, in the order checked (empty:
    /// the theory applies).
    pub assumption_failures: Vec<AssumptionFailure>,
    /// `(Eq. 3 - simulated impulse per period) / simulated impulse`; `None` without a
    /// prediction or without contact.
    pub impulse_relative_error: Option<f64>,
    /// Eq. 4's initial amplitude with the simulated main impact's impulse instead of Eq. 3's,
    /// `w_2^2 / (k_2 w_2d) * impulse`, nm: separates the impulse-response idealisation (an
    /// instantaneous kick on a free mode) from the error of Eq. 3. `None` without an impact.
    pub q2_initial_amplitude_from_simulated_impulse_nm: Option<f64>,
    /// `(Eq. 4 initial amplitude - measured ringing amplitude) / measured`; `None` without a
    /// prediction or a measured ringing.
    pub q2_initial_amplitude_relative_error: Option<f64>,
    /// `(Eq. 4 decay over a period - measured) / measured`; `None` without a prediction or a
    /// measured ringing that decays.
    pub q2_decay_over_period_relative_error: Option<f64>,
}

impl TheoryComparison {
    /// Whether the theory applies to this orbit without any assumption failure.
    pub fn assumptions_hold(&self) -> bool {
        self.assumption_failures.is_empty()
    }
}

/// The assumptions of Eqs. 3-4 that `measurement` (on `model`) violates, in a fixed order:
/// first those that withhold the predictions, then those that flag them.
fn assumption_failures(
    model: &TappingModel,
    theory: &ImpactTheory,
    measurement: &ImpactMeasurement,
) -> Vec<AssumptionFailure> {
    let mut failures = Vec::new();
    let z_nm = measurement.z_nm;
    if z_nm <= THEORY_MIN_SEPARATION_NM {
        failures.push(AssumptionFailure::SeparationBelowSurface { z_nm });
    }
    if measurement.impacts.is_empty() {
        failures.push(AssumptionFailure::NoContact {
            z_nm,
            first_contact_z_nm: model.grazing_separation_nm(),
        });
    }
    let withheld = failures
        .iter()
        .any(AssumptionFailure::withholds_predictions);
    for (phase, phase_deg) in [
        ("q1", measurement.q1_phase_deg),
        ("u", measurement.u_phase_deg),
    ] {
        if !withheld && phase_deg.to_radians().cos() <= 0.0 {
            failures.push(AssumptionFailure::NonPositiveImpulse { phase, phase_deg });
        }
    }
    if let Some(ringing) = measurement.ringing {
        if ringing.effective_decay_time_us.is_none() {
            failures.push(AssumptionFailure::RingingDoesNotDecay {
                amplitude_ratio_over_period: ringing.decay_over_period,
            });
        }
    }
    if !theory.drive_at_fundamental {
        failures.push(AssumptionFailure::DriveOffFundamental {
            drive_frequency_khz: model.drive_frequency_khz(),
            fundamental_frequency_khz: model.cantilever().fundamental_frequency_khz(),
            harmonic_balance_impulse_nn_us: measurement.harmonic_balance_impulse_nn_us,
        });
    }
    if measurement.impacts.len() > 1 {
        failures.push(AssumptionFailure::MultipleImpacts {
            impacts: measurement.impacts.len(),
        });
    }
    if measurement.contact_time_periods > THEORY_MAX_CONTACT_PERIODS {
        failures.push(AssumptionFailure::LongContact {
            contact_time_periods: measurement.contact_time_periods,
        });
    }
    failures
}

/// `(predicted - measured) / measured`, `None` when the measured value is zero or not finite.
fn relative(predicted: f64, measured: f64) -> Option<f64> {
    (measured != 0.0 && measured.is_finite() && predicted.is_finite())
        .then(|| (predicted - measured) / measured)
}

/// Compare the theory with `orbit`, a converged period-1 steady orbit of `model`.
pub fn compare_theory(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    settings: &Settings,
) -> Result<TheoryComparison, AfmError> {
    let theory = ImpactTheory::new(model)?;
    let measurement = measure_impacts(model, orbit, settings)?;
    let assumption_failures = assumption_failures(model, &theory, &measurement);
    let withheld = assumption_failures
        .iter()
        .any(AssumptionFailure::withholds_predictions);
    let predict = |phase_deg: f64| {
        let prediction = theory.predict(phase_deg);
        (!withheld && prediction.impulse_nn_us > 0.0).then_some(prediction)
    };
    let prediction = predict(measurement.q1_phase_deg);
    let prediction_from_u_phase = predict(measurement.u_phase_deg);
    let main_impulse = measurement
        .main_impact
        .map(|index| measurement.impacts[index].impulse_nn_us);
    let ringing = measurement.ringing;
    Ok(TheoryComparison {
        impulse_relative_error: prediction
            .and_then(|p| relative(p.impulse_nn_us, measurement.impulse_nn_us)),
        q2_initial_amplitude_from_simulated_impulse_nm: main_impulse
            .map(|impulse| impulse * theory.q2_amplitude_per_impulse),
        q2_initial_amplitude_relative_error: prediction
            .zip(ringing)
            .and_then(|(p, r)| relative(p.q2_initial_amplitude_nm, r.initial_amplitude_nm)),
        q2_decay_over_period_relative_error: prediction
            .zip(ringing.filter(|r| r.effective_decay_time_us.is_some()))
            .and_then(|(p, r)| relative(p.q2_decay_over_period, r.decay_over_period)),
        theory,
        prediction,
        prediction_from_u_phase,
        measurement,
        assumption_failures,
    })
}
