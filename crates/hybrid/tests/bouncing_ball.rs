//! Bouncing ball `x'' = -g`, impact at `x = 0` with `v+ = -e v-`: impact times against the
//! geometric series, each impact fired once, and the Zeno accumulation ending in an error.

mod common;

use common::BouncingBall;
use hybrid::{flow_map, Direction, HybridError, Sensitivity, Settings};

const BALL: BouncingBall = BouncingBall {
    gravity: 9.81,
    restitution: 0.8,
};
const HEIGHT: f64 = 1.0;

/// Before the Zeno time the run reaches `t_end` cleanly. Every impact time matches the closed
/// form `t_n = t_1 (1 + 2 e (1 - e^(n-1)) / (1 - e))` to 1e-12 relative: the flight is a
/// quadratic, which DOP853 integrates exactly up to rounding, and events are located to
/// `1e-13 max(|t|, |step|)`. Each impact fires exactly once: the count equals the number of
/// closed-form impacts before `t_end`, all `Down`, all with a reset, none grazing.
#[test]
fn impact_times_match_geometric_series() {
    let zeno = BALL.zeno_time(HEIGHT);
    // 20 impacts happen before t_end; the 21st is later.
    let exact = BALL.impact_times(HEIGHT, 21);
    let t_end = 0.5 * (exact[19] + exact[20]);
    assert!(t_end < zeno);
    let result = flow_map(
        &BALL,
        0.0,
        &[HEIGHT, 0.0],
        t_end,
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("reaches t_end before the Zeno time");
    assert_eq!(result.events.len(), 20, "{:?}", result.events);
    let mut worst: f64 = 0.0;
    for (event, t) in result.events.iter().zip(&exact) {
        assert_eq!(event.direction, Direction::Down);
        assert!(event.reset && !event.grazing);
        assert!(event.rate < 0.0);
        let relative = (event.t - t).abs() / t;
        worst = worst.max(relative);
        // After the bounce the ball moves up, with speed e times the impact speed
        // (impact speed g t_1 e^(n-1) in closed form), to 1e-10 relative.
        assert!(event.state[1] > 0.0);
        assert!(
            event.state[0] >= 0.0,
            "state on the free side: {:?}",
            event.state
        );
    }
    eprintln!("worst relative impact-time error {worst:e}");
    assert!(worst < 1e-12, "worst relative error {worst:e}");
    let t1 = exact[0];
    for (n, event) in result.events.iter().enumerate() {
        let speed = BALL.gravity * t1 * BALL.restitution.powi(n as i32 + 1);
        let e = (event.state[1] - speed).abs() / speed;
        assert!(e < 1e-10, "impact {n}: speed error {e:e}");
    }
    eprintln!("{:?}", result.statistics);
}

/// Past the Zeno time the impacts accumulate: the solver must stop with `TooManyEvents`
/// (rather than loop, or step across the floor) once `max_events` impacts have fired.
#[test]
fn zeno_accumulation_ends_in_too_many_events() {
    let zeno = BALL.zeno_time(HEIGHT);
    let settings = Settings {
        max_events: 500,
        ..Settings::default()
    };
    let result = flow_map(
        &BALL,
        0.0,
        &[HEIGHT, 0.0],
        2.0 * zeno,
        Sensitivity::None,
        &settings,
    );
    match result {
        Err(HybridError::TooManyEvents { t, events }) => {
            assert_eq!(events, 500);
            // The accumulation happens at the Zeno time. Once the bounce apex v^2 / 2g falls
            // below `event_value_tolerance` (1e-14), events are only located to that height,
            // i.e. at speeds v = sqrt(2 g 1e-14) = 4.4e-7, whose remaining flight time is
            // 2 v / (g (1 - e)) = 4.5e-7: the stop time lies within 1e-6 of the Zeno time.
            eprintln!("stopped at {t} (Zeno time {zeno})");
            assert!((t - zeno).abs() < 1e-6, "t = {t} vs Zeno {zeno}");
        }
        other => panic!("expected TooManyEvents, got {other:?}"),
    }
}
