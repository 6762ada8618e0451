//! The solver's Taylor-series steps against DOP853 everywhere (`Settings::taylor_series =
//! false`), shared by the series tests (`taylor_steps.rs`, `jkr_series.rs`,
//! `relaxing_series.rs`): both at a tight tolerance over whole drive periods, and the comparison
//! of the two flows (the same events, the largest relative differences of the state, the
//! transition matrix and `dx/dZ`).
#![allow(dead_code)]

use afm::TappingModel;
use hybrid::{flow_map, FlowMap, Sensitivity, Settings};

/// Tolerance 1e-13 (relative and absolute), contact by Taylor series when `series`, else by
/// DOP853 everywhere.
pub fn tight(series: bool) -> Settings {
    Settings {
        relative_tolerance: 1e-13,
        absolute_tolerance: 1e-13,
        taylor_series: series,
        ..Settings::default()
    }
}

/// The flow of `model` from `x0` at `t = 0` over `count` drive periods.
pub fn periods(
    model: &TappingModel,
    x0: &[f64],
    count: f64,
    sensitivity: Sensitivity,
    settings: &Settings,
) -> FlowMap {
    flow_map(
        model,
        0.0,
        x0,
        count * model.period_us(),
        sensitivity,
        settings,
    )
    .expect("flow")
}

/// Largest entry of `a - b` relative to the largest entry of `b`.
pub fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// The largest differences of a series flow from its DOP853 reference, each relative to the
/// reference's largest entry ([`relative_difference`]; `parameter` is NaN for flows without
/// `dx/dZ`).
pub struct FlowDifference {
    pub state: f64,
    pub transition: f64,
    pub parameter: f64,
}

/// Assert that `series` has `reference`'s events (surface, direction, and time within
/// `event_tolerance` drive periods of `model`), and return the flows' differences.
pub fn compare(
    model: &TappingModel,
    series: &FlowMap,
    reference: &FlowMap,
    event_tolerance: f64,
) -> FlowDifference {
    assert_eq!(series.events.len(), reference.events.len());
    for (a, b) in series.events.iter().zip(&reference.events) {
        assert_eq!((a.surface, a.direction), (b.surface, b.direction));
        assert!(
            (a.t - b.t).abs() < event_tolerance * model.period_us(),
            "{} vs {}",
            a.t,
            b.t
        );
    }
    FlowDifference {
        state: relative_difference(&series.state, &reference.state),
        transition: relative_difference(
            series.transition.as_slice(),
            reference.transition.as_slice(),
        ),
        parameter: relative_difference(
            &series.parameter_sensitivity,
            &reference.parameter_sensitivity,
        ),
    }
}
