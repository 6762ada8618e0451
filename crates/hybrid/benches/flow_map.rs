//! Timing of `flow_map` on reference problems (a plain bench binary: `cargo bench -p hybrid`).
//!
//! Prints the median wall time of repeated runs and the solver statistics, per drive period,
//! for the forced linear oscillator (DOP853 and exact flow) and the Hertz contact oscillator.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{ForcedOscillator, HertzOscillator};
use hybrid::{flow_map, HybridSystem, Sensitivity, Settings};

/// A benchmark case: runs with the given sensitivity, returns (median us, statistics).
type Case<'a> = &'a dyn Fn(Sensitivity) -> (f64, hybrid::Statistics);

fn median_micros<S: HybridSystem>(
    system: &S,
    x0: &[f64],
    duration: f64,
    sensitivity: Sensitivity,
    settings: &Settings,
) -> (f64, hybrid::Statistics) {
    let mut times = Vec::new();
    let mut statistics = None;
    for _ in 0..201 {
        let start = Instant::now();
        let result = flow_map(system, 0.0, x0, duration, sensitivity, settings);
        times.push(start.elapsed().as_secs_f64() * 1e6);
        match result {
            Ok(r) => statistics = Some(r.statistics),
            Err(e) => {
                eprintln!("benchmark run failed: {e}");
                std::process::exit(1);
            }
        }
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], statistics.unwrap_or_default())
}

fn main() {
    let settings = Settings::default();
    let oscillator = ForcedOscillator::reference();
    let period = 2.0 * std::f64::consts::PI / oscillator.drive;
    let exact = ForcedOscillator {
        exact_flow_limit: Some(period / 8.0),
        ..oscillator
    };
    let hertz = HertzOscillator::reference();
    let hertz_period = 2.0 * std::f64::consts::PI / hertz.drive;
    let cases: [(&str, Case); 3] = [
        ("linear oscillator, DOP853, 1 period", &|s| {
            median_micros(&oscillator, &[0.4, -0.3], period, s, &settings)
        }),
        ("linear oscillator, exact flow, 1 period", &|s| {
            median_micros(&exact, &[0.4, -0.3], period, s, &settings)
        }),
        ("Hertz contact oscillator, 3 periods from rest", &|s| {
            median_micros(&hertz, &[0.0, 0.0], 3.0 * hertz_period, s, &settings)
        }),
    ];
    for (name, run) in cases {
        for s in [Sensitivity::None, Sensitivity::TransitionAndParameter] {
            let (micros, statistics) = run(s);
            println!("{name}, {s:?}: {micros:.1} us  {statistics:?}");
        }
    }
}
