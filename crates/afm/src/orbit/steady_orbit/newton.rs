//! Newton on the period-1 stroboscopic map `P(x) - x = 0` with the exact monodromy, each map
//! integrated with its observables where it is expected to be the last.

use continuation::{newton_update, ContinuationError, NewtonSettings, Parametrised};
use hybrid::{Sensitivity, SensitivityMethod, Settings};
use nalgebra::{DMatrix, DVector};

use super::period_maps::period_map;
use super::{state_distance, SteadyOrbitWorkspace};
use crate::error::AfmError;
use crate::model::TappingModel;
use crate::orbit::observables::{observe_period_in, OrbitObservables};

/// The outcome of [`shoot_observed`]: Newton's last iterate with the residual and observables
/// of the period map evaluated there, and the sensitivities (see [`shoot_observed`] for
/// where).
pub(crate) struct ObservedShot {
    pub(crate) state: Vec<f64>,
    pub(crate) iterations: usize,
    pub(crate) residual: f64,
    pub(crate) converged: bool,
    pub(crate) sensitivities: MapSensitivities,
    pub(crate) observables: OrbitObservables,
}

/// The derivatives of one period map: the monodromy `dP/dx` and, if tracked, `dP/dZ`.
pub(crate) struct MapSensitivities {
    pub(crate) monodromy: DMatrix<f64>,
    pub(crate) parameter_derivative: Option<DVector<f64>>,
}

impl MapSensitivities {
    /// The branch's slope `dx/dZ = -(M - I)^{-1} dP/dZ` (see [`SteadyOrbit::tangent`]).
    pub(crate) fn tangent(&self, z_nm: f64) -> Option<Vec<f64>> {
        branch_tangent(
            &self.monodromy,
            self.parameter_derivative.as_ref()?.as_slice(),
            z_nm,
        )
    }
}

/// `dx/dZ = -(M - I)^{-1} dP/dZ` from the monodromy `M` and `dP/dZ` of one map; `None` if
/// `M - I` is singular or the result is not finite.
pub(crate) fn branch_tangent(
    monodromy: &DMatrix<f64>,
    parameter_derivative: &[f64],
    z_nm: f64,
) -> Option<Vec<f64>> {
    let rhs = DVector::from_column_slice(parameter_derivative);
    let tangent = newton_update(monodromy, &rhs, z_nm).ok()?;
    tangent
        .iter()
        .all(|v| v.is_finite())
        .then(|| tangent.iter().map(|v| -v).collect())
}

/// A period map's image, sensitivities (if asked for) and observables (if asked for).
type ObservedMap = (Vec<f64>, Option<MapSensitivities>, Option<OrbitObservables>);

/// One period map from `x` with `sensitivity`; with `observe`, also the observables (the
/// sampling for the gap's extrema and the quadratures add about half of a state-only map, so
/// they are done only where the evaluation is expected to be the last).
fn observed_map(
    model: &TappingModel,
    x: &[f64],
    sensitivity: Sensitivity,
    observe: bool,
    integration: &Settings,
    harmonics: usize,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<ObservedMap, AfmError> {
    let (flow, observables) = if observe {
        let buffers = workspace.for_maps(sensitivity);
        let (flow, observables) =
            observe_period_in(model, 0.0, x, sensitivity, integration, harmonics, buffers)?;
        (flow, Some(observables))
    } else {
        (
            period_map(model, x, sensitivity, integration, workspace)?,
            None,
        )
    };
    let finite = |values: &[f64]| values.iter().all(|v| v.is_finite());
    if !(finite(&flow.state)
        && finite(flow.transition.as_slice())
        && finite(&flow.parameter_sensitivity))
    {
        return Err(ContinuationError::NonFinite {
            what: "period map",
            parameter: model.parameter(),
        }
        .into());
    }
    let sensitivities = (sensitivity != Sensitivity::None).then(|| MapSensitivities {
        monodromy: flow.transition,
        parameter_derivative: sensitivity
            .parameter()
            .then(|| DVector::from_vec(flow.parameter_sensitivity)),
    });
    Ok((flow.state, sensitivities, observables))
}

/// Newton on the period-1 stroboscopic map `P(x) - x = 0` with the exact monodromy (the same
/// iteration, convergence test and divergence guard as `continuation::shoot`), each period
/// map integrated with its observables, so that the evaluation at the returned state gives
/// its residual (always measured there) and observables at once. The maps with the
/// monodromy at full tolerance also carry `dP/dZ` (one more tangent column, a few per cent of
/// a map), for the orbit's [`SteadyOrbit::tangent`].
///
/// The last evaluation skips the sensitivities when Newton's quadratic convergence predicts
/// it final (`C r_k^2 <= tolerance / 10`, `C = r_k / r_{k-1}^2` from the last two residuals,
/// or [`ASSUMED_NEWTON_CONSTANT`] after a first map at full tolerance) and the update leading
/// to it is below `0.1 * sensitivity_tolerance.unwrap_or(1e-5) * (1 + |x|)`: the
/// sensitivities returned are then the ones at the previous iterate, that close to the
/// orbit, so they differ from those at the returned state by about that relative amount
/// (1e-6), less than their integration error (below), far less than matters for the
/// Floquet multipliers' use here, the orbit's stability, or for the tangent's, a prediction.
/// If the prediction fails (residual above the tolerance), the point is evaluated again with
/// the sensitivities and Newton goes on.
///
/// From a [`OrbitStart::Near`] start (`predicted = false`), the first evaluation, whose only
/// use is the first Newton update, is integrated at the tolerances of [`first_iterate`]
/// (inexact Newton): its error, a few 1e-7 nm, adds about that much to the first iterate,
/// which the next, full-tolerance iteration removes with the rest (the iteration counts of
/// the Fig. 1 benchmark stay 2). Every residual that decides convergence comes from a
/// full-tolerance map: a start whose loose residual is below [`LOOSE_RESIDUAL_FLOOR`] is
/// evaluated again at full tolerance before anything is decided. From a
/// [`OrbitStart::Predicted`] start the first map is at full tolerance.
///
/// The monodromy of every map is carried by [`newton_maps`]: decoupled from the state's
/// steps (order-12 tangent series in contact, the exact flow in free flight), within 1.3e-6
/// to 2.3e-6 relative at the Fig. 1 points (`cargo run --release -p afm --example
/// monodromy_error`), so each Newton iteration also contracts the error by about
/// that much (times the conditioning of `M - I`) besides squaring it: far below what the
/// iterations need (the Fig. 1 benchmark's counts stay 2, and a start after transients
/// converges in as many iterations as with the coupled monodromy).
pub(crate) fn shoot_observed(
    model: &TappingModel,
    x0: &[f64],
    predicted: bool,
    newton: &NewtonSettings,
    integration: &Settings,
    harmonics: usize,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<ObservedShot, AfmError> {
    let n = x0.len();
    let shift_scale = 0.1 * integration.sensitivity_tolerance.unwrap_or(1e-5);
    let integration = &newton_maps(integration);
    let full = Sensitivity::TransitionAndParameter;
    let mut x = x0.to_vec();
    let (mut image, mut first_sensitivities, mut observables) = if predicted {
        observed_map(model, &x, full, false, integration, harmonics, workspace)?
    } else {
        observed_map(
            model,
            &x,
            Sensitivity::Transition,
            false,
            &first_iterate(integration),
            harmonics,
            workspace,
        )?
    };
    let mut full_tolerance = predicted;
    if !predicted && state_distance(&image, &x) <= LOOSE_RESIDUAL_FLOOR {
        (image, first_sensitivities, observables) =
            observed_map(model, &x, full, false, integration, harmonics, workspace)?;
        full_tolerance = true;
    }
    let mut sensitivities = first_sensitivities.unwrap_or_else(|| MapSensitivities {
        monodromy: DMatrix::identity(n, n),
        parameter_derivative: None,
    });
    // The Newton constant `C` of the quadratic prediction: from the last two residuals once
    // there are two, assumed before that only if the first residual is a full-tolerance one.
    let mut previous_residual: Option<f64> = None;
    let mut iterations = 0;
    loop {
        let residual_vector = DVector::from_iterator(n, image.iter().zip(&x).map(|(p, x)| p - x));
        let residual = residual_vector.norm();
        if residual <= newton.tolerance || iterations >= newton.max_iterations {
            let observables =
                observables_at(model, &x, observables, integration, harmonics, workspace)?;
            return Ok(ObservedShot {
                state: x,
                iterations,
                residual,
                converged: residual <= newton.tolerance,
                sensitivities,
                observables,
            });
        }
        let update = newton_update(
            &sensitivities.monodromy,
            &residual_vector,
            model.parameter(),
        )?;
        let candidate: Vec<f64> = x.iter().zip(update.iter()).map(|(x, u)| x - u).collect();
        iterations += 1;
        if !candidate.iter().all(|v| v.is_finite()) {
            return Err(ContinuationError::NonFinite {
                what: "Newton iterate",
                parameter: model.parameter(),
            }
            .into());
        }
        let constant = match previous_residual {
            Some(r_prev) => Some(residual / (r_prev * r_prev)),
            None => full_tolerance.then_some(ASSUMED_NEWTON_CONSTANT),
        };
        let predicted_final = constant
            .is_some_and(|constant| constant * residual * residual <= 0.1 * newton.tolerance)
            && update.norm() <= shift_scale * (1.0 + DVector::from_column_slice(&x).norm());
        let next_sensitivity = if predicted_final {
            Sensitivity::None
        } else {
            full
        };
        let (mut next_image, mut next_sensitivities, mut next_observables) = observed_map(
            model,
            &candidate,
            next_sensitivity,
            predicted_final,
            integration,
            harmonics,
            workspace,
        )?;
        let next_residual = state_distance(&next_image, &candidate);
        if next_residual > newton.divergence_factor * residual {
            let observables =
                observables_at(model, &x, observables, integration, harmonics, workspace)?;
            return Ok(ObservedShot {
                state: x,
                iterations,
                residual,
                converged: false,
                sensitivities,
                observables,
            });
        }
        if next_sensitivities.is_none() && next_residual > newton.tolerance {
            // The prediction failed: Newton goes on and needs the monodromy there.
            (next_image, next_sensitivities, next_observables) = observed_map(
                model,
                &candidate,
                full,
                false,
                integration,
                harmonics,
                workspace,
            )?;
        }
        previous_residual = Some(residual);
        x = candidate;
        image = next_image;
        observables = next_observables;
        if let Some(next) = next_sensitivities {
            sensitivities = next;
        }
    }
}

/// The observables at `x`: `known` if the evaluation there recorded them, else one more
/// (state-only) period.
fn observables_at(
    model: &TappingModel,
    x: &[f64],
    known: Option<OrbitObservables>,
    integration: &Settings,
    harmonics: usize,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<OrbitObservables, AfmError> {
    match known {
        Some(observables) => Ok(observables),
        None => {
            let buffers = workspace.for_maps(Sensitivity::None);
            Ok(observe_period_in(
                model,
                0.0,
                x,
                Sensitivity::None,
                integration,
                harmonics,
                buffers,
            )?
            .1)
        }
    }
}

/// The Newton constant `C` (1/nm) assumed for the quadratic prediction `C r^2` of the next
/// residual after a first map at full tolerance, before two residuals measure it: above the
/// constants of the paper's Fig. 1 orbits (below 1 for starting errors up to 2e-2 nm). A
/// constant too small costs one more map when the prediction fails, never accuracy.
const ASSUMED_NEWTON_CONSTANT: f64 = 1.0;

/// The loosest tolerance (relative and absolute) of the first Newton map of
/// [`shoot_observed`]: loose enough to make the first map cheap, tight enough that its state
/// error (the Taylor-series steps in contact leave about 10 times the tolerance) does not fail
/// Newton's quadratic prediction after the next iteration, which would cost one more period
/// map with the monodromy.
const FIRST_ITERATE_TOLERANCE: f64 = 1e-9;

/// A first Newton map at [`FIRST_ITERATE_TOLERANCE`] whose residual is below this (nm) is
/// computed again at full tolerance: the loose map's own error (up to about 10 times its
/// tolerance) is part of such a residual, and the start is close
/// enough for full-tolerance Newton (after transient periods, typically).
/// From a neighbouring orbit on the branch 0.01 nm away, the residual is 3e-4 to 2e-2 nm.
const LOOSE_RESIDUAL_FLOOR: f64 = 1e3 * FIRST_ITERATE_TOLERANCE;

/// `settings` for the period maps of [`shoot_observed`]: the monodromy integrated apart from
/// the state's steps ([`SensitivityMethod::Decoupled`]: tangent series of order 12 on the
/// Taylor steps in contact, a sixth-order method on any Runge-Kutta step: cheaper than the
/// tangents at the state's order, accurate to about 1e-6 relative), unless `settings` ask for
/// error-controlled sensitivities (`sensitivity_tolerance`), which only the coupled method has.
pub(crate) fn newton_maps(settings: &Settings) -> Settings {
    Settings {
        sensitivity_method: if settings.sensitivity_tolerance.is_none() {
            SensitivityMethod::Decoupled
        } else {
            SensitivityMethod::Coupled
        },
        ..settings.clone()
    }
}

/// `settings` for the first Newton map of [`shoot_observed`]: tolerances no tighter than
/// [`FIRST_ITERATE_TOLERANCE`].
pub(crate) fn first_iterate(settings: &Settings) -> Settings {
    Settings {
        relative_tolerance: settings.relative_tolerance.max(FIRST_ITERATE_TOLERANCE),
        absolute_tolerance: settings.absolute_tolerance.max(FIRST_ITERATE_TOLERANCE),
        ..settings.clone()
    }
}
