//! The stroboscopic period maps of a steady-orbit search on reused solver buffers: one map with
//! a chosen sensitivity, and iterates of the map (transients).

use hybrid::{flow_map_in, FlowMap, Sensitivity, Settings, SolverWorkspace};

use crate::error::AfmError;
use crate::model::TappingModel;

/// The solver buffers of the period maps of [`steady_orbit_in`], kept from one orbit to the
/// next: the maps with the monodromy only (Newton's loose first map), those with the
/// monodromy and `dP/dZ` (Newton's full-tolerance maps) and those of the state only
/// (transients, the observed last map, the recurrence search) each reuse their own (a
/// solver's buffers fit one kind of sensitivity), so that a branch of orbits (an approach in
/// `Z`) allocates only results. Empty at first ([`Default`]); a clone is empty.
#[derive(Debug, Default, Clone)]
pub struct SteadyOrbitWorkspace {
    transition: SolverWorkspace,
    transition_and_parameter: SolverWorkspace,
    state_only: SolverWorkspace,
}

impl SteadyOrbitWorkspace {
    /// The buffers for maps with `sensitivity`.
    pub(crate) fn for_maps(&mut self, sensitivity: Sensitivity) -> &mut SolverWorkspace {
        match sensitivity {
            Sensitivity::None => &mut self.state_only,
            Sensitivity::Transition => &mut self.transition,
            Sensitivity::TransitionAndParameter => &mut self.transition_and_parameter,
        }
    }
}

/// `settings` for a period map whose extrema nobody reads (a Newton iterate not expected to
/// be the last, a transient period): `extremum_height` 0, so that free flight the model proves
/// clear of the sample is neither sampled nor cut into short steps. Contacts are found all the
/// same; the state differs from a fully sampled map by rounding only.
fn crossings_only(settings: &Settings) -> Settings {
    Settings {
        extremum_height: 0.0,
        ..settings.clone()
    }
}

/// One period map from `x` with `sensitivity`, crossings only ([`crossings_only`]), on the
/// workspace's buffers for it.
pub(crate) fn period_map(
    model: &TappingModel,
    x: &[f64],
    sensitivity: Sensitivity,
    settings: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<FlowMap, AfmError> {
    Ok(flow_map_in(
        model,
        0.0,
        x,
        model.period_us(),
        sensitivity,
        &crossings_only(settings),
        &mut |_: &_, _: &_| {},
        workspace.for_maps(sensitivity),
    )?)
}

/// Iterate the stroboscopic map `periods` times from `x0` (state only, no extrema).
pub(crate) fn iterate(
    model: &TappingModel,
    x0: &[f64],
    periods: usize,
    settings: &Settings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<Vec<f64>, AfmError> {
    let mut x = x0.to_vec();
    for _ in 0..periods {
        x = period_map(model, &x, Sensitivity::None, settings, workspace)?.state;
    }
    Ok(x)
}
