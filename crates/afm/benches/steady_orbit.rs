//! Benchmark of the steady orbit at the paper's Fig. 1 points (Biolever on mica, A0 = 10 nm,
//! A/A0 = 0.95, 0.90, 0.50): the time to converge it along the approach branch,
//!
//! - from the state of the orbit at the neighbouring point (Z + 0.01 nm, `OrbitStart::Near`:
//!   a loose first Newton map, then two at full tolerance),
//! - from the cubic Hermite prediction of the two previous orbits (Z + 0.01 and Z + 0.02 nm,
//!   with their slopes dx/dZ; `OrbitStart::Predicted`, one Newton update: two maps),
//!
//! both as a branch would (`steady_orbit_in`, one workspace for the repetitions); also from
//! the neighbour without the workspace (`steady_orbit`, whose period maps each build a new
//! solver), and without a previous orbit: by transients from the free orbit
//! (`OrbitStart::Transient`) and by walking the approach branch from the free orbit
//! (`OrbitStart::Approach`, the cold start); the cold start with the coexistence check that
//! `simulate --z` and Python's `case.orbit(z=...)` add (`coexisting_orbit`: the transient start
//! stopped once it enters the found orbit's basin), beside the check done in full (the
//! transient start's whole orbit); the Newton iterations
//! (neighbour/predicted) and the work of one period map with the monodromy: right-hand-side
//! evaluations (DOP853 stages), steps (exact-flow, DOP853 and Taylor-series steps) and, of
//! those, series steps.
//!
//! Run with `cargo bench -p afm --bench steady_orbit`. Timings are medians over repetitions in
//! one process, so the ratios between rows are meaningful on a noisy machine; the neighbour
//! and predicted starts are also timed on the thread's CPU clock (Linux
//! `/proc/thread-self/schedstat`, best of 5 batches), which does not count the time other
//! processes hold the core.
//!
//! The same orbits by a plain scipy transient integration, for the speed ratio: the example
//! `transient_reference` and `benches/scipy_transient.py` (see that script).

use afm::orbit::steady_orbit::{coexisting_orbit, COEXISTING_DISTANCE};
use afm::{
    builtin_case, find_amplitude_ratio, hermite_state, steady_orbit, steady_orbit_in,
    AmplitudeRatioSearch, OrbitStart, Separation, SteadyOrbitSettings, SteadyOrbitWorkspace,
    TappingModel,
};
use hybrid::{flow_map, Sensitivity};
use std::time::Instant;

mod cpu_time;
use cpu_time::thread_cpu_seconds;

/// Best over 5 batches of the thread CPU time per call of `f` (`calls` per batch),
/// microseconds; NaN where the thread clock is unavailable.
fn cpu_us<F: FnMut()>(calls: usize, mut f: F) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let Some(start) = thread_cpu_seconds() else {
            return f64::NAN;
        };
        for _ in 0..calls {
            f();
        }
        let Some(end) = thread_cpu_seconds() else {
            return f64::NAN;
        };
        best = best.min((end - start) * 1e6 / calls as f64);
    }
    best
}

/// Median wall time of `repetitions` calls of `f`, microseconds.
fn median_us<F: FnMut()>(repetitions: usize, mut f: F) -> f64 {
    let mut times: Vec<f64> = (0..repetitions)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[repetitions / 2]
}

fn main() {
    let case = builtin_case("biolever-mica").expect("built-in case");
    let model = TappingModel::from_case(&case).expect("model");
    let settings = SteadyOrbitSettings::default();
    println!("steady orbit, Biolever on mica, A0 = 10 nm (median of repetitions)");
    println!(
        "{:>6} {:>10} {:>8} {:>12} {:>9} {:>12} {:>9} {:>13} {:>12} {:>11} {:>9} {:>12} {:>7} {:>12} {:>8} {:>9}",
        "A/A0",
        "Z (nm)",
        "impacts",
        "neighbour us",
        "(CPU us)",
        "predicted us",
        "(CPU us)",
        "no workspace",
        "transient us",
        "approach us",
        "cold us",
        "(full check)",
        "iters",
        "RHS evals/T",
        "steps/T",
        "series/T"
    );
    for ratio in [0.95, 0.90, 0.50] {
        let search = AmplitudeRatioSearch::new(ratio).expect("ratio");
        let target = find_amplitude_ratio(&model, &search, &settings).expect("reached");
        let z = target.z_nm;
        // The two previous points on the approach branch, 0.02 and 0.01 nm above, each
        // converged from the one before it.
        let second = steady_orbit(&model, z + 0.02, OrbitStart::Near(&target.state), &settings)
            .expect("second neighbour");
        let neighbour = steady_orbit(&model, z + 0.01, OrbitStart::Near(&second.state), &settings)
            .expect("neighbour");
        let prediction = hermite_state(z, &second, &neighbour).expect("both have tangents");
        let warm =
            steady_orbit(&model, z, OrbitStart::Near(&neighbour.state), &settings).expect("warm");
        let predicted = steady_orbit(&model, z, OrbitStart::Predicted(&prediction), &settings)
            .expect("predicted");
        assert!(
            warm.converged && predicted.converged,
            "both starts converge"
        );
        let mut workspace = SteadyOrbitWorkspace::default();
        let mut from = |start: OrbitStart<'_>| {
            let orbit =
                steady_orbit_in(&model, z, start, &settings, &mut workspace).expect("orbit");
            std::hint::black_box(orbit);
        };
        let neighbour_us = median_us(201, || from(OrbitStart::Near(&neighbour.state)));
        let neighbour_cpu_us = cpu_us(400, || from(OrbitStart::Near(&neighbour.state)));
        let predicted_us = median_us(201, || from(OrbitStart::Predicted(&prediction)));
        let predicted_cpu_us = cpu_us(400, || from(OrbitStart::Predicted(&prediction)));
        let fresh_us = median_us(201, || {
            let orbit = steady_orbit(&model, z, OrbitStart::Near(&neighbour.state), &settings)
                .expect("warm");
            std::hint::black_box(orbit);
        });
        let transient_us = median_us(51, || {
            let orbit =
                steady_orbit(&model, z, OrbitStart::Transient, &settings).expect("transient");
            std::hint::black_box(orbit);
        });
        let approach_us = median_us(51, || {
            let orbit = steady_orbit(&model, z, OrbitStart::Approach, &settings).expect("approach");
            std::hint::black_box(orbit);
        });
        // What a cold `simulate --z` (and Python's `case.orbit(z=...)`) computes: the approach
        // start's orbit and the coexistence check against the transient start; beside it the
        // check done in full (the transient start's own orbit, then the comparison).
        let cold_us = median_us(51, || {
            let orbit = steady_orbit(&model, z, OrbitStart::Approach, &settings).expect("approach");
            let other = coexisting_orbit(&model, &orbit, OrbitStart::Transient, &settings);
            std::hint::black_box((orbit, other));
        });
        let full_check_us = median_us(51, || {
            let orbit = steady_orbit(&model, z, OrbitStart::Approach, &settings).expect("approach");
            let other =
                steady_orbit(&model, z, OrbitStart::Transient, &settings).expect("transient");
            let same = orbit.is_same_orbit(&other, COEXISTING_DISTANCE);
            std::hint::black_box((orbit, other, same));
        });
        let mut at_z = model.clone();
        at_z.set_separation(Separation::Constant(z))
            .expect("finite");
        let period = flow_map(
            &at_z,
            0.0,
            &target.state,
            at_z.period_us(),
            Sensitivity::TransitionAndParameter,
            &settings.integration,
        )
        .expect("period map");
        println!(
            "{:>6.2} {:>10.6} {:>8} {:>12.1} {:>9.1} {:>12.1} {:>9.1} {:>13.1} {:>12.1} {:>11.1} {:>9.1} {:>12.1} {:>7} {:>12} {:>8} {:>9}",
            ratio,
            z,
            target.observables().impacts.len(),
            neighbour_us,
            neighbour_cpu_us,
            predicted_us,
            predicted_cpu_us,
            fresh_us,
            transient_us,
            approach_us,
            cold_us,
            full_check_us,
            format!("{}/{}", warm.iterations, predicted.iterations),
            period.statistics.rhs_evaluations,
            // `steps` counts the exact-flow steps too.
            period.statistics.steps,
            period.statistics.series_steps,
        );
    }
}
