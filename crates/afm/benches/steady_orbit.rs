//! Benchmark of the steady orbit at the paper's Fig. 1 points (Biolever on mica, A0 = 10 nm,
//! A/A0 = 0.95, 0.90, 0.50): the time to converge it from the orbit at a neighbouring point of
//! the approach branch (Z + 0.01 nm), as a branch would (`steady_orbit_in`, one workspace for
//! the repetitions; also without it, `steady_orbit`, whose period maps each build a new
//! solver), and from a cold start (the free orbit plus transients),
//! and the work of one period map with the monodromy: right-hand-side evaluations (DOP853
//! stages), steps (exact-flow, DOP853 and Taylor-series steps) and, of those, series steps.
//!
//! Run with `cargo bench -p afm --bench steady_orbit`. Timings are medians over repetitions in
//! one process, so the ratios between rows are meaningful on a noisy machine; the neighbour
//! start is also timed on the thread's CPU clock (Linux `/proc/thread-self/schedstat`, best of
//! 5 batches), which does not count the time other processes hold the core.
//!
//! The same orbits by a plain scipy transient integration, for the speed ratio: the example
//! `transient_reference` and `benches/scipy_transient.py` (see that script).

use afm::{
    builtin_case, find_amplitude_ratio, steady_orbit, steady_orbit_in, AmplitudeRatioSearch,
    Separation, SteadyOrbitSettings, SteadyOrbitWorkspace, TappingModel,
};
use hybrid::{flow_map, Sensitivity};
use std::time::Instant;

/// The calling thread's CPU time so far, seconds (Linux); `None` elsewhere.
fn thread_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let nanoseconds: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(nanoseconds * 1e-9)
}

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
        "{:>6} {:>12} {:>8} {:>12} {:>12} {:>14} {:>10} {:>14} {:>14} {:>12} {:>12}",
        "A/A0",
        "Z (nm)",
        "impacts",
        "neighbour us",
        "(CPU us)",
        "no workspace",
        "cold us",
        "Newton iters",
        "RHS evals/T",
        "steps/T",
        "series/T"
    );
    for ratio in [0.95, 0.90, 0.50] {
        let search = AmplitudeRatioSearch::new(ratio).expect("ratio");
        let target = find_amplitude_ratio(&model, &search, &settings).expect("reached");
        let z = target.z_nm;
        // The neighbouring point on the approach branch, 0.01 nm above.
        let neighbour =
            steady_orbit(&model, z + 0.01, Some(&target.state), &settings).expect("neighbour");
        let warm = steady_orbit(&model, z, Some(&neighbour.state), &settings).expect("warm");
        assert!(warm.converged, "warm start converges");
        let mut workspace = SteadyOrbitWorkspace::default();
        let mut from_neighbour = || {
            let orbit =
                steady_orbit_in(&model, z, Some(&neighbour.state), &settings, &mut workspace)
                    .expect("warm");
            std::hint::black_box(orbit);
        };
        let neighbour_us = median_us(201, &mut from_neighbour);
        let neighbour_cpu_us = cpu_us(400, &mut from_neighbour);
        let fresh_us = median_us(201, || {
            let orbit = steady_orbit(&model, z, Some(&neighbour.state), &settings).expect("warm");
            std::hint::black_box(orbit);
        });
        let cold_us = median_us(51, || {
            let orbit = steady_orbit(&model, z, None, &settings).expect("cold");
            std::hint::black_box(orbit);
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
            "{:>6.2} {:>12.6} {:>8} {:>12.1} {:>12.1} {:>14.1} {:>10.1} {:>14} {:>14} {:>12} {:>12}",
            ratio,
            z,
            target.observables().impacts.len(),
            neighbour_us,
            neighbour_cpu_us,
            fresh_us,
            cold_us,
            warm.iterations,
            period.statistics.rhs_evaluations,
            // `steps` counts the exact-flow steps too.
            period.statistics.steps,
            period.statistics.series_steps,
        );
    }
}
