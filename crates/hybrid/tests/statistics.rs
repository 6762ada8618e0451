//! Regression guards: solver statistics on reference problems with events.
//!
//! The pinned numbers were recorded from the current implementation so that a silent change of
//! the algorithm (step-size control, event handling, sampling) shows; they are not accuracy
//! claims. The accuracy of the same runs is checked independently: against the closed form for
//! the bouncing ball (`bouncing_ball.rs`) and, here, against a run at a 100 times tighter
//! tolerance for the Hertz contact.

mod common;

use common::{BouncingBall, HertzOscillator};
use hybrid::{flow_map, Sensitivity, Settings, Statistics};

/// Hertz contact from rest over 3 drive periods, default settings: 5 crossings. The steps next
/// to onset and release run on the square-root clock (the contact mode declares its
/// half-power surface); stepping in time there instead, the same run took 210 steps, 29
/// rejected, 3476 evaluations (and with the clock kept for up to 4 proposed steps after onset
/// instead of 1, 182 steps, 19 rejected, 2954 evaluations).
#[test]
fn hertz_contact_statistics_are_pinned() {
    let system = HertzOscillator::reference();
    let duration = 3.0 * 2.0 * std::f64::consts::PI / 1.2;
    let result = flow_map(
        &system,
        0.0,
        &[0.0, 0.0],
        duration,
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("integration succeeds");
    eprintln!("{:?}", result.statistics);
    assert_eq!(
        result.statistics,
        Statistics {
            steps: 180,
            rejected_steps: 20,
            exact_steps: 0,
            rhs_evaluations: 2935,
            events: 5,
            series_steps: 0,
            redone_steps: 0,
            sampled_steps: 180,
        }
    );
    // Accuracy: within 1e-9 of a run at tolerance 1e-14 (the global error of a default run
    // through five contacts, each with a non-smooth force, is measured at 1.2e-10).
    let fine = flow_map(
        &system,
        0.0,
        &[0.0, 0.0],
        duration,
        Sensitivity::None,
        &Settings {
            relative_tolerance: 1e-14,
            absolute_tolerance: 1e-14,
            ..Settings::default()
        },
    )
    .expect("integration succeeds");
    for i in 0..2 {
        let e = (result.state[i] - fine.state[i]).abs();
        eprintln!("state error {e:e}");
        assert!(e < 1e-9);
    }
    for (a, b) in result.events.iter().zip(&fine.events) {
        assert!((a.t - b.t).abs() < 1e-9);
    }
}

/// Bouncing ball, 20 impacts (the run of `impact_times_match_geometric_series`). The flight is
/// a quadratic, so the local error estimates are at rounding level and the step count is
/// sensitive to the order of floating-point sums (it changed from 24 to 25 when the stage
/// sums became dot products, and from 25 to 24 when steps started landing just past the
/// predicted impact). RHS evaluations: 15 per step, 1 to restart after each impact, 2 for the
/// starting step: 24 * 15 + 20 + 2 = 382.
#[test]
fn bouncing_ball_statistics_are_pinned() {
    let ball = BouncingBall {
        gravity: 9.81,
        restitution: 0.8,
    };
    let exact = ball.impact_times(1.0, 21);
    let t_end = 0.5 * (exact[19] + exact[20]);
    let result = flow_map(
        &ball,
        0.0,
        &[1.0, 0.0],
        t_end,
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("integration succeeds");
    assert_eq!(
        result.statistics,
        Statistics {
            steps: 24,
            rejected_steps: 0,
            exact_steps: 0,
            rhs_evaluations: 382,
            events: 20,
            series_steps: 0,
            redone_steps: 0,
            sampled_steps: 24,
        }
    );
}
