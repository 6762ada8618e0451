//! A steady orbit as found: its state, multiplicity, stability and Floquet multipliers, its
//! slope along the branch, and its observables over the whole orbit and per drive period
//! (MODEL.md sections 4 and 5).

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

use super::state_distance;
use crate::orbit::observables::OrbitObservables;

/// A steady periodic orbit at one separation, with how it was found and what it looks like.
#[derive(Debug, Clone, Serialize)]
pub struct SteadyOrbit {
    /// The separation `Z`, nm.
    pub z_nm: f64,
    /// The orbit's period in drive periods (`k` for an orbit of period `k T`).
    pub multiplicity: usize,
    /// Whether Newton reached the tolerance on the `k`-th iterate of the stroboscopic map.
    pub converged: bool,
    /// Newton iterations of the last (successful or final) shooting.
    pub iterations: usize,
    /// The final residual `|P^k(x) - x|`, nm and nm/us mixed (the state's units).
    pub residual: f64,
    /// The state at `t = 0` (drive phase zero): `[q_1, q_1', ..., q_N, q_N']`, nm and nm/us.
    pub state: Vec<f64>,
    /// Floquet multipliers: eigenvalues of the monodromy matrix of `P^k`. For a period-1 orbit,
    /// the monodromy of Newton's last map with it (decoupled sensitivities, see
    /// `shoot_observed`): the monodromy within 1.3e-6 and 2.3e-6 relative at the Fig. 1 points
    /// A/A0 = 0.95 and 0.5 of the Biolever on mica (`cargo run --release -p afm --example
    /// monodromy_error`), enough for the orbit's stability; continuation
    /// (`bifurcation_diagram`) computes its own.
    #[serde(serialize_with = "serialize_multipliers")]
    pub multipliers: Vec<Complex<f64>>,
    /// Whether every multiplier lies inside the unit circle (the orbit attracts).
    pub stable: bool,
    /// The monodromy matrix `dP/dx` (dimensionless, `2N x 2N` in the state's order) whose
    /// eigenvalues are [`SteadyOrbit::multipliers`], for a period-1 orbit found by Newton
    /// (MODEL.md section 8); `None` for an orbit of period `k T`, `k > 1`. The coexistence
    /// check ([`crate::orbit::steady_orbit::coexisting_orbit`]) compares transients with it.
    #[serde(skip)]
    pub monodromy: Option<DMatrix<f64>>,
    /// `dx/dZ`: how the orbit's state at `t = 0` moves with the separation along its branch
    /// (nm per nm and nm/us per nm), `-(M - I)^{-1} dP/dZ` from the monodromy `M` and the
    /// parameter derivative `dP/dZ` of the same period map (of `P^k`; the implicit-function
    /// theorem on `P(x; Z) = x`), the map being Newton's last one with sensitivities (as for
    /// the multipliers). The branch's slope, for predicting a neighbouring orbit
    /// ([`OrbitStart::Predicted`]). `None` where `M - I` is singular (a fold of the branch,
    /// where `Z` cannot parametrise it) or the solve gives a non-finite vector.
    pub tangent: Option<Vec<f64>>,
    /// The observables of the whole orbit: one window of its `k` drive periods, so that every
    /// impact, gap minimum and force of every period is in it (times in drive periods from
    /// `t = 0`, in `[0, k)`), integrals per drive period, and the first harmonic the lock-in
    /// reading over `k T`.
    pub whole_orbit: OrbitObservables,
    /// The observables of each of the `k` drive periods of the orbit in order, each over its
    /// own window `[j T, (j + 1) T]` (times from that period's start): its first harmonic,
    /// force integrals, gap minima and peak force. Its impact list treats the one period as
    /// periodic (an impact running across the window's end joins one running across its
    /// start), so per-period impact counts come from [`SteadyOrbit::period_breakdown`].
    pub periods: Vec<OrbitObservables>,
    /// The state at the start of each of the `k` drive periods (`x(j T)`, `j = 0..k`), the
    /// first being [`SteadyOrbit::state`] (nm, nm/us): the same orbit started a period later
    /// has the state `x(T)` at `t = 0`.
    #[serde(skip)]
    pub period_states: Vec<Vec<f64>>,
}

/// One drive period of a period-`k` orbit: the per-period breakdown of its observables.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeriodBreakdown {
    /// The period's index `j` in the orbit, from 0 (the window `[j T, (j + 1) T]`).
    pub period: usize,
    /// `A / A0` of the first harmonic of `u` over this period alone.
    pub amplitude_ratio: f64,
    /// Phase lag `Phi` of that harmonic over this period alone, degrees.
    pub phase_deg: f64,
    /// The orbit's impacts whose onset lies in this period (an impact belongs to the period
    /// it starts in; one in contact throughout the orbit belongs to period 0).
    pub impacts: usize,
    /// The largest tip-sample force in this period, nN.
    pub peak_force_nn: f64,
    /// The mean tip-sample force over this period, nN.
    pub mean_force_nn: f64,
    /// The impulse `int F_ts dt` over this period, nN us.
    pub impulse_nn_us: f64,
    /// The time in contact within this period, in periods.
    pub contact_time_periods: f64,
    /// The lowest local minimum of the gap in this period, nm (`null` in JSON if none).
    pub min_gap_nm: Option<f64>,
    /// The energy dissipated in the sample in this period, eV (MODEL.md section 10).
    pub dissipated_ev: f64,
    /// The virial over this period, eV.
    pub virial_ev: f64,
    /// The largest indentation in this period, nm.
    pub max_indentation_nm: f64,
    /// The mean indentation over this period's time in contact, nm.
    pub mean_indentation_nm: f64,
    /// The relative residual of this period's energy balance.
    pub energy_balance_residual: f64,
}

impl SteadyOrbit {
    /// Whether `other` is the same orbit as this one: the same multiplicity `k`, and the state
    /// of `other` within `tolerance` (nm, nm/us; [`state_distance`]) of this orbit's state at
    /// the start of one of its `k` periods (a period-`k` orbit found from another start may be
    /// the same cycle entered `j` periods later).
    pub fn is_same_orbit(&self, other: &SteadyOrbit, tolerance: f64) -> bool {
        self.multiplicity == other.multiplicity
            && self
                .period_states
                .iter()
                .any(|x| state_distance(x, &other.state) <= tolerance)
    }

    /// The observables of the whole orbit (all `k` periods; see [`SteadyOrbit::whole_orbit`]).
    pub fn observables(&self) -> &OrbitObservables {
        &self.whole_orbit
    }

    /// The lock-in reading over the whole orbit (`k` periods): `(A / A0, Phi in degrees)` of
    /// the first harmonic of `u` over `k T` (MODEL.md section 4), with `A0 =
    /// free_amplitude_nm`.
    pub fn lockin(&self, free_amplitude_nm: f64) -> (f64, f64) {
        (
            self.whole_orbit.amplitude_nm / free_amplitude_nm,
            self.whole_orbit.phase_deg,
        )
    }

    /// Impacts per drive period: the impacts over the orbit's `k` periods divided by `k`.
    pub fn impacts_per_period(&self) -> f64 {
        self.whole_orbit.impacts_per_period
    }

    /// The impacts over the whole orbit (`k` periods), an integer.
    pub fn impacts_per_orbit(&self) -> usize {
        self.whole_orbit.impacts.len()
    }

    /// The per-period breakdown of the orbit's observables, one entry per drive period.
    pub fn period_breakdown(&self, free_amplitude_nm: f64) -> Vec<PeriodBreakdown> {
        self.periods
            .iter()
            .enumerate()
            .map(|(j, period)| {
                let onsets = j as f64..(j + 1) as f64;
                let min_gap = period.min_gap_nm();
                PeriodBreakdown {
                    period: j,
                    amplitude_ratio: period.amplitude_nm / free_amplitude_nm,
                    phase_deg: period.phase_deg,
                    impacts: self
                        .whole_orbit
                        .impacts
                        .iter()
                        .filter(|impact| onsets.contains(&impact.start_periods))
                        .count(),
                    peak_force_nn: period.peak_force_nn,
                    mean_force_nn: period.mean_force_nn,
                    impulse_nn_us: period.impulse_nn_us,
                    contact_time_periods: period.contact_time_periods,
                    min_gap_nm: min_gap.is_finite().then_some(min_gap),
                    dissipated_ev: period.dissipated_ev,
                    virial_ev: period.virial_ev,
                    max_indentation_nm: period.max_indentation_nm,
                    mean_indentation_nm: period.mean_indentation_nm,
                    energy_balance_residual: period.energy_balance_residual,
                }
            })
            .collect()
    }
}

fn serialize_multipliers<S: serde::Serializer>(
    multipliers: &[Complex<f64>],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = serializer.serialize_seq(Some(multipliers.len()))?;
    for m in multipliers {
        seq.serialize_element(&[m.re, m.im])?;
    }
    seq.end()
}
