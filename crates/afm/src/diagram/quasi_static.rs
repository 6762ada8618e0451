//! A quasi-static sweep of the separation `Z`: at each of a list of separations the cantilever
//! settles by time-domain transients from the orbit it had at the previous one, as in a lab
//! approach slow enough that every orbit settles (MODEL.md section 8), and the attractor it
//! settles on is polished by Newton ([`OrbitStart::AfterTransients`]). An approach follows one
//! attractor down until it ends (a fold, a grazing that destroys it) and then lands on another;
//! the retract back up from the lowest separation can follow another one, and where the two
//! disagree the cantilever is bistable. This is the brute force behind `drumroll grid`,
//! independent of the branch continuation ([`crate::diagram::bifurcation_diagram`]).

use serde::Serialize;

use crate::error::AfmError;
use crate::model::TappingModel;
use crate::orbit::steady_orbit::{
    steady_orbit_in, OrbitStart, SteadyOrbitSettings, SteadyOrbitWorkspace,
};
use crate::validation::invalid;

/// Two cells hold the same attractor when their `A / A0` differ by at most this (and their
/// impacts per period agree). Newton converges each orbit to 1e-10 nm in state, which moves
/// `A / A0` by about 1e-10 / A0; two distinct stable orbits at one `Z` (the MAClever on mica's
/// bistable range) differ by 1e-4 or more, except within a vanishing distance of the fold
/// where they meet.
pub const SAME_ATTRACTOR_AMPLITUDE_RATIO: f64 = 1e-7;

/// The steady orbit one quasi-static sweep settles on at one separation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QuasiStaticCell {
    /// `A / A0`: the first harmonic of `u` over the whole orbit (MODEL.md section 4).
    pub amplitude_ratio: f64,
    /// The phase lag `Phi` of that harmonic, degrees.
    pub phase_deg: f64,
    /// The orbit's period in drive periods `k`.
    pub multiplicity: usize,
    /// Impacts over the orbit's `k` periods (an impact: a maximal interval with gap `d < 0`).
    pub impacts_per_orbit: usize,
    /// `impacts_per_orbit / k`, as `drumroll simulate` and `continue` count it.
    pub impacts_per_period: f64,
    /// Whether every Floquet multiplier lies inside the unit circle.
    pub stable: bool,
    /// Whether Newton reached its tolerance (a cell that did not is reported, not dropped).
    pub converged: bool,
}

impl QuasiStaticCell {
    /// Whether `self` and `other` are the same attractor: equal impacts per period and
    /// `A / A0` within [`SAME_ATTRACTOR_AMPLITUDE_RATIO`]. The period `k` is not compared: the
    /// recurrence search of [`crate::orbit::steady_orbit()`] can report a period-1 orbit as a period-2
    /// one (found on the second iterate of the map: 1e-4 nm below the MAClever on mica's fold),
    /// the same orbit under another `k`.
    pub fn same_attractor(&self, other: &Self) -> bool {
        self.impacts_per_period == other.impacts_per_period
            && (self.amplitude_ratio - other.amplitude_ratio).abs()
                <= SAME_ATTRACTOR_AMPLITUDE_RATIO
    }
}

/// A quasi-static approach over separations, and optionally the retract back.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QuasiStaticRow {
    /// The separations, nm, in approach order (strictly decreasing).
    pub z_nm: Vec<f64>,
    /// The approach's cell at each separation, in the same order.
    pub approach: Vec<QuasiStaticCell>,
    /// The retract's cell at each separation (same order as `z_nm`, computed from the last
    /// back to the first), if asked.
    pub retract: Option<Vec<QuasiStaticCell>>,
}

impl QuasiStaticRow {
    /// Whether approach and retract settle on different attractors at cell `j` (`None` without
    /// a retract or for `j` out of range).
    pub fn bistable(&self, j: usize) -> Option<bool> {
        let retract = self.retract.as_ref()?.get(j)?;
        Some(!self.approach.get(j)?.same_attractor(retract))
    }
}

/// The quasi-static approach of `model` over the separations `z_nm` (nm, strictly
/// decreasing), starting from the free orbit's state at the first one, each cell's transients
/// (`settings.transient_periods` periods) started from the previous cell's orbit; with
/// `retract`, the sweep back up over the same separations from the approach's last orbit.
///
/// # Errors
/// [`AfmError::InvalidField`] for an empty or not strictly decreasing list or a separation out
/// of the steady orbit's range; the solver's errors.
pub fn quasi_static_row(
    model: &TappingModel,
    z_nm: &[f64],
    retract: bool,
    settings: &SteadyOrbitSettings,
) -> Result<QuasiStaticRow, AfmError> {
    if z_nm.is_empty() || z_nm.iter().any(|z| !z.is_finite()) {
        return Err(invalid(
            "quasi-static sweep",
            "z_nm",
            z_nm.len() as f64,
            String::from("at least one finite separation"),
        ));
    }
    if let Some(pair) = z_nm.windows(2).find(|pair| pair[1] >= pair[0]) {
        return Err(invalid(
            "quasi-static sweep",
            "z_nm",
            pair[1],
            format!("below the previous separation {} nm (an approach)", pair[0]),
        ));
    }
    let mut workspace = SteadyOrbitWorkspace::default();
    let mut state = model.free_state();
    let approach = sweep(
        model,
        z_nm.iter().copied(),
        &mut state,
        settings,
        &mut workspace,
    )?;
    let retract = if retract {
        let mut cells = sweep(
            model,
            z_nm.iter().rev().copied(),
            &mut state,
            settings,
            &mut workspace,
        )?;
        cells.reverse();
        Some(cells)
    } else {
        None
    };
    Ok(QuasiStaticRow {
        z_nm: z_nm.to_vec(),
        approach,
        retract,
    })
}

/// Settle at each separation in turn from `state`, which is left at the last cell's orbit.
fn sweep(
    model: &TappingModel,
    separations: impl Iterator<Item = f64>,
    state: &mut Vec<f64>,
    settings: &SteadyOrbitSettings,
    workspace: &mut SteadyOrbitWorkspace,
) -> Result<Vec<QuasiStaticCell>, AfmError> {
    let free_amplitude = model.free_amplitude_nm();
    let mut cells = Vec::with_capacity(separations.size_hint().0);
    for z in separations {
        let orbit = steady_orbit_in(
            model,
            z,
            OrbitStart::AfterTransients(state),
            settings,
            workspace,
        )?;
        let (amplitude_ratio, phase_deg) = orbit.lockin(free_amplitude);
        cells.push(QuasiStaticCell {
            amplitude_ratio,
            phase_deg,
            multiplicity: orbit.multiplicity,
            impacts_per_orbit: orbit.impacts_per_orbit(),
            impacts_per_period: orbit.impacts_per_period(),
            stable: orbit.stable,
            converged: orbit.converged,
        });
        *state = orbit.state;
    }
    Ok(cells)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::builtin_case;

    #[test]
    fn a_row_rejects_separations_that_do_not_decrease() {
        let model = TappingModel::from_case(&builtin_case("biolever-mica").unwrap()).unwrap();
        let settings = SteadyOrbitSettings::default();
        let message = quasi_static_row(&model, &[9.0, 9.5], false, &settings)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("below the previous separation 9 nm"),
            "{message}"
        );
        assert!(quasi_static_row(&model, &[], false, &settings).is_err());
    }
}
