//! Support for the workspace's acceptance tests in `tests/`: independent checks that use no
//! Newton iteration and no continuation, only plain time-domain integration, so that they can
//! confirm what the shooting and continuation machinery reports.

use afm::{Separation, TappingModel};
use hybrid::{flow_map, Direction, Sensitivity, Settings};

/// The number of impacts (onsets of contact, `d` going negative) in the last of `periods`
/// drive periods of a plain time-domain run of `model` at separation `z_nm` from state `x0` at
/// `t = 0`: the transients decay over the first `periods - 1` periods, no Newton is involved.
pub fn time_domain_impacts(model: &TappingModel, z_nm: f64, x0: &[f64], periods: usize) -> usize {
    assert!(periods >= 1, "at least one period");
    let mut model = model.clone();
    model
        .set_separation(Separation::Constant(z_nm))
        .expect("finite separation");
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
    flow_map(&model, 0.0, &settled, period, Sensitivity::None, &settings)
        .expect("last period")
        .events
        .iter()
        .filter(|event| event.direction == Direction::Down)
        .count()
}
