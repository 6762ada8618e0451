//! The solver's Taylor-series steps in Hertz contact against DOP853 everywhere
//! (`Settings::taylor_series = false`): the same flow map, events and transition matrix over
//! three drive periods of the Biolever on mica at the paper's Fig. 1 point A/A0 = 0.5 (three
//! impacts per period), from the free orbit (so the first period's contacts are a transient).
//! Measured: 94 series steps for the 9 contacts where DOP853 takes 418 steps in all; event
//! times within 6e-11 us, the state within 1.1e-12, the transition matrix within 4.9e-9
//! (coupled: tangents at the state's order) and 3.1e-6 (decoupled: order 14), relative to
//! their largest entries.

use afm::{builtin_case, Separation, TappingModel};
use hybrid::{flow_map, Direction, FlowMap, Sensitivity, SensitivityMethod, Settings};

/// The separation of the Fig. 1 point A/A0 = 0.5 on the approach branch (nm).
const Z_HALF_AMPLITUDE: f64 = 2.733_156_827_672_611;

fn model() -> TappingModel {
    let case = builtin_case("biolever-mica").expect("built-in case");
    let mut model = TappingModel::from_case(&case).expect("model");
    model
        .set_separation(Separation::Constant(Z_HALF_AMPLITUDE))
        .expect("finite");
    model
}

fn three_periods(model: &TappingModel, settings: &Settings) -> FlowMap {
    flow_map(
        model,
        0.0,
        &model.free_state(),
        3.0 * model.period_us(),
        Sensitivity::Transition,
        settings,
    )
    .expect("three periods")
}

/// Largest entry of `a - b` relative to the largest entry of `b`.
fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

#[test]
fn series_steps_reproduce_the_runge_kutta_flow_events_and_transition() {
    let model = model();
    let tight = Settings {
        relative_tolerance: 1e-13,
        absolute_tolerance: 1e-13,
        ..Settings::default()
    };
    let reference = three_periods(
        &model,
        &Settings {
            taylor_series: false,
            ..tight.clone()
        },
    );
    assert_eq!(reference.statistics.series_steps, 0);
    for (method, transition_tolerance) in [
        (SensitivityMethod::Coupled, 5e-8),
        (SensitivityMethod::Decoupled, 2e-5),
    ] {
        let series = three_periods(
            &model,
            &Settings {
                sensitivity_method: method,
                ..tight.clone()
            },
        );
        // Every contact stepped by series (several steps per contact), none by DOP853.
        let contacts = series
            .events
            .iter()
            .filter(|e| e.direction == Direction::Down)
            .count();
        assert!(contacts >= 9, "{contacts} contacts in three periods");
        assert!(series.statistics.series_steps >= 2 * contacts);
        assert_eq!(series.events.len(), reference.events.len());
        for (a, b) in series.events.iter().zip(&reference.events) {
            assert_eq!(a.direction, b.direction);
            assert!(
                (a.t - b.t).abs() < 1e-12 * model.period_us(),
                "{} vs {}",
                a.t,
                b.t
            );
        }
        let state = relative_difference(&series.state, &reference.state);
        assert!(state < 2e-11, "{method:?}: state {state:.2e}");
        let transition = relative_difference(
            series.transition.as_slice(),
            reference.transition.as_slice(),
        );
        assert!(
            transition < transition_tolerance,
            "{method:?}: transition {transition:.2e}"
        );
    }
}
