//! Support for the workspace's acceptance tests in `tests/`: independent checks that use no
//! Newton iteration and no continuation, only plain time-domain integration, so that they can
//! confirm what the shooting and continuation machinery reports.

use afm::{Separation, TappingModel};
use hybrid::{flow_map, Direction, ExtremumKind, Sensitivity, Settings};

/// What a plain time-domain run of `periods` drive periods ended on (MODEL.md section 5).
#[derive(Debug, Clone, PartialEq)]
pub struct TimeDomainRun {
    /// Impacts (onsets of contact: the gap `d` going negative) in the last period. On a
    /// periodic orbit every impact has exactly one onset per period, so this is `n`.
    pub impacts_last_period: usize,
    /// The lowest local minimum of the gap in the last period, nm (`+inf` if none): negative
    /// for an impact, positive for a near impact, zero at grazing.
    pub lowest_gap_nm: f64,
    /// Every local minimum of the gap in the last period, in time order, nm.
    pub gap_minima_nm: Vec<f64>,
    /// The state at the start of the last period, `[q_1, q_1', ...]` (nm, nm/us).
    pub state_before_last: Vec<f64>,
    /// The state at the end of the run.
    pub final_state: Vec<f64>,
}

impl TimeDomainRun {
    /// `|x(n T) - x((n - 1) T)|` (Euclidean, state units): how far the run is from a period-1
    /// orbit. Zero (to the integration tolerance) once the transients have decayed onto one.
    pub fn period_drift(&self) -> f64 {
        state_distance(&self.final_state, &self.state_before_last)
    }
}

/// `model` with its separation set to the constant `z_nm`, nm.
pub fn at_separation(model: &TappingModel, z_nm: f64) -> TappingModel {
    let mut model = model.clone();
    model
        .set_separation(Separation::Constant(z_nm))
        .expect("finite separation");
    model
}

/// The state after `periods` drive periods of a plain time-domain run of `model` at separation
/// `z_nm` from state `x0` at `t = 0` (default solver settings, tolerances 1e-12; no Newton).
pub fn time_domain_state(model: &TappingModel, z_nm: f64, x0: &[f64], periods: usize) -> Vec<f64> {
    let model = at_separation(model, z_nm);
    flow_map(
        &model,
        0.0,
        x0,
        periods as f64 * model.period_us(),
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("time-domain run")
    .state
}

/// A plain time-domain run of `periods` drive periods of `model` at separation `z_nm` from
/// state `x0` at `t = 0`: the transients decay over the first `periods - 1` periods, and the
/// impacts and gap minima of the last one are counted. No Newton is involved.
pub fn time_domain_run(
    model: &TappingModel,
    z_nm: f64,
    x0: &[f64],
    periods: usize,
) -> TimeDomainRun {
    assert!(periods >= 1, "at least one period");
    let model = at_separation(model, z_nm);
    let settings = Settings::default();
    let period = model.period_us();
    let settled = flow_map(
        &model,
        0.0,
        x0,
        (periods - 1) as f64 * period,
        Sensitivity::None,
        &settings,
    )
    .expect("transient run")
    .state;
    let last =
        flow_map(&model, 0.0, &settled, period, Sensitivity::None, &settings).expect("last period");
    let gap_minima_nm: Vec<f64> = last
        .extrema
        .iter()
        .filter(|e| e.surface == 0 && e.kind == ExtremumKind::Minimum)
        .map(|e| e.value)
        .collect();
    TimeDomainRun {
        impacts_last_period: last
            .events
            .iter()
            .filter(|event| event.surface == 0 && event.direction == Direction::Down)
            .count(),
        lowest_gap_nm: gap_minima_nm.iter().copied().fold(f64::INFINITY, f64::min),
        gap_minima_nm,
        state_before_last: settled,
        final_state: last.state,
    }
}

/// The number of impacts (onsets of contact, `d` going negative) in the last of `periods`
/// drive periods of a plain time-domain run of `model` at separation `z_nm` from state `x0` at
/// `t = 0`: the transients decay over the first `periods - 1` periods, no Newton is involved.
pub fn time_domain_impacts(model: &TappingModel, z_nm: f64, x0: &[f64], periods: usize) -> usize {
    time_domain_run(model, z_nm, x0, periods).impacts_last_period
}

/// Euclidean distance between two states (state units: nm and nm/us mixed): `afm`'s, with the
/// states' lengths checked.
pub fn state_distance(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "states of one model");
    afm::state_distance(a, b)
}
