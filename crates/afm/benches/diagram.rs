//! Benchmark of the full four-case bifurcation-diagram computation (the target): the
//! approach diagrams of the paper's four cases (Biolever and MAClever on mica and on the soft
//! sample; MODEL.md section 6) with `DiagramSettings::approach`, every special point located.
//!
//! Target: all four diagrams, each with at least 300 points and every special point to
//! 1e-9 nm, in under 1 s in total (release build, one core). The reference is a brute-force
//! scipy sweep of one case at about 250 separations, which takes about a minute.
//!
//! Run with `cargo bench -p afm --bench diagram`; `-- --repetitions N` (default 5) sets the
//! repetitions of each diagram, whose median is reported. A line after the totals times the
//! four computed at once, one per thread on up to one thread per core, as `drumroll continue`
//! computes several `--case`s (issue 29's target for Fig. 2: under 0.1 s).
//!
//! The last table is the cost of the observables (issue 30): each diagram against the same
//! continuation without them (`HybridPeriodicProblem` alone, no stop predicate, down to the
//! diagram's last `Z`: the same branch points), CPU time of both in one run, and what
//! integrating every accepted point once more for its observables (as before they were
//! recorded during the corrector's accepted period map) would add.

use afm::{
    approach_diagram, builtin_case, orbit_observables, BifurcationDiagram, DiagramSettings,
    Separation, TappingModel,
};
use continuation::{Continuation, ContinuationSettings, HybridPeriodicProblem, ParameterDirection};
use hybrid::{flow_map, Sensitivity};
use std::time::Instant;

mod cpu_time;
use cpu_time::thread_cpu_seconds;

/// Median wall time of `repetitions` calls of `f`, seconds.
fn median_seconds<F: FnMut()>(repetitions: usize, mut f: F) -> f64 {
    let mut times: Vec<f64> = (0..repetitions)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[repetitions / 2]
}

/// Where the time of one diagram goes: the cost of one period map with the monodromy and
/// parameter sensitivity (what the corrector integrates per Newton iteration) and of one
/// period of observables (once per branch point), each the mean over every 10th branch point
/// (median of 5 calls each), and the period maps of the accepted points (one per Newton
/// iteration plus the final residual evaluation: `iterations + 1`).
struct Work {
    map_us: f64,
    observables_us: f64,
    accepted_maps: usize,
}

fn work(model: &TappingModel, settings: &DiagramSettings, diagram: &BifurcationDiagram) -> Work {
    let (mut map_us, mut observables_us, mut samples) = (0.0, 0.0, 0);
    for point in diagram.points.iter().step_by(10) {
        let mut at = model.clone();
        at.set_separation(Separation::Constant(point.z_nm))
            .expect("finite separation");
        map_us += 1e6
            * median_seconds(5, || {
                let map = flow_map(
                    &at,
                    0.0,
                    &point.state,
                    at.period_us(),
                    Sensitivity::TransitionAndParameter,
                    &settings.orbit.integration,
                )
                .expect("period map");
                std::hint::black_box(map);
            });
        observables_us += 1e6
            * median_seconds(5, || {
                let o = orbit_observables(
                    &at,
                    &point.state,
                    &settings.orbit.integration,
                    settings.orbit.harmonics,
                )
                .expect("observables");
                std::hint::black_box(o);
            });
        samples += 1;
    }
    Work {
        map_us: map_us / samples as f64,
        observables_us: observables_us / samples as f64,
        accepted_maps: diagram.points.iter().map(|p| p.iterations + 1).sum(),
    }
}

/// The median CPU time (the thread's, else wall) of `repetitions` calls of `f`, seconds.
fn median_cpu_seconds<F: FnMut()>(repetitions: usize, mut f: F) -> f64 {
    let mut times: Vec<f64> = (0..repetitions)
        .map(|_| {
            let (cpu, wall) = (thread_cpu_seconds(), Instant::now());
            f();
            match (cpu, thread_cpu_seconds()) {
                (Some(a), Some(b)) => b - a,
                _ => wall.elapsed().as_secs_f64(),
            }
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[repetitions / 2]
}

/// The approach diagram's continuation without observables: the period-1 problem alone, the
/// diagram's continuation settings, from the same start down to `z_last` (the diagram's last
/// point, where its `A/A0` stop ended it), no stop predicate. Returns the number of points.
fn bare_continuation(model: &TappingModel, settings: &DiagramSettings, z_last: f64) -> usize {
    let z_start = model.grazing_separation_nm() + 0.02 * model.free_amplitude_nm();
    let mut system = model.clone();
    system
        .set_separation(Separation::Constant(z_start))
        .expect("finite separation");
    let problem =
        HybridPeriodicProblem::new(system, 1, settings.orbit.integration.clone()).expect("problem");
    let continuation_settings = ContinuationSettings {
        initial_step: settings.max_step * 0.1,
        max_step: settings.max_step,
        direction: ParameterDirection::Decreasing,
        parameter_min: z_last,
        parameter_max: f64::INFINITY,
        max_points: settings.max_points,
        corrector: settings.orbit.newton.clone(),
        ..ContinuationSettings::default()
    };
    Continuation::new(
        &problem,
        &model.free_state(),
        z_start,
        continuation_settings,
    )
    .expect("continuation")
    .run()
    .points
    .len()
}

/// The four cases' approach diagrams computed at once on `threads` threads, each taking the
/// next case not yet started (models built inside, as the command line builds them before
/// computing).
fn all_at_once(threads: usize) {
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| loop {
                let index = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(name) = CASES.get(index) else {
                    break;
                };
                let model = TappingModel::from_case(&builtin_case(name).expect("built-in case"))
                    .expect("model");
                let diagram =
                    approach_diagram(&model, &DiagramSettings::approach(&model)).expect("diagram");
                std::hint::black_box(diagram);
            });
        }
    });
}

/// The reference: a brute-force scipy sweep of one case, about 250 separations, about
/// one minute, seconds.
const SCIPY_SECONDS_PER_SWEEP: f64 = 60.0;
/// Separations of that reference sweep.
const SCIPY_SWEEP_POINTS: f64 = 250.0;

const CASES: [&str; 4] = [
    "biolever-mica",
    "biolever-soft",
    "maclever-mica",
    "maclever-soft",
];

fn main() {
    let repetitions = std::env::args()
        .skip_while(|a| a != "--repetitions")
        .nth(1)
        .map(|n| {
            n.parse::<usize>()
                .expect("--repetitions N: a positive integer")
        })
        .unwrap_or(5)
        .max(1);
    println!(
        "approach diagrams of the four paper cases (DiagramSettings::approach), median of \
         {repetitions} repetitions, one thread"
    );
    println!(
        "{:<15} {:>7} {:>8} {:>10} {:>10} {:>9} {:>8} {:>8} {:>21}",
        "case",
        "points",
        "special",
        "median ms",
        "us/point",
        "min ms",
        "max ms",
        "CPU ms",
        "worst precision (nm)"
    );
    let mut total = 0.0;
    let mut all_ok = true;
    let mut total_points = 0;
    let mut total_cpu = Some(0.0);
    let mut breakdown = Vec::new();
    for name in CASES {
        let model =
            TappingModel::from_case(&builtin_case(name).expect("built-in case")).expect("model");
        let settings = DiagramSettings::approach(&model);
        let mut times = Vec::with_capacity(repetitions);
        let mut cpu_times = Vec::with_capacity(repetitions);
        let mut last: Option<BifurcationDiagram> = None;
        for _ in 0..repetitions {
            let cpu_start = thread_cpu_seconds();
            let start = Instant::now();
            let diagram = approach_diagram(&model, &settings).expect("diagram");
            times.push(start.elapsed().as_secs_f64());
            if let (Some(a), Some(b)) = (cpu_start, thread_cpu_seconds()) {
                cpu_times.push(b - a);
            }
            last = Some(std::hint::black_box(diagram));
        }
        cpu_times.sort_by(f64::total_cmp);
        let cpu_median = cpu_times.get(cpu_times.len() / 2).copied();
        total_cpu = total_cpu.zip(cpu_median).map(|(t, c)| t + c);
        let diagram = last.expect("at least one repetition");
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        total += median;
        total_points += diagram.points.len();
        let worst_precision = diagram
            .special_points
            .iter()
            .map(|s| s.precision_nm)
            .fold(0.0, f64::max);
        let ok = diagram.points.len() >= 300
            && diagram
                .special_points
                .iter()
                .all(|s| s.converged && s.precision_nm < 1e-9)
            && diagram.error.is_none();
        all_ok &= ok;
        println!(
            "{:<15} {:>7} {:>8} {:>10.1} {:>10.1} {:>9.1} {:>8.1} {:>8} {:>21.1e}{}",
            name,
            diagram.points.len(),
            diagram.special_points.len(),
            median * 1e3,
            median * 1e6 / diagram.points.len() as f64,
            times[0] * 1e3,
            times[times.len() - 1] * 1e3,
            cpu_median.map_or(String::from("n/a"), |c| format!("{:.1}", c * 1e3)),
            worst_precision,
            if ok { "" } else { "  (target missed)" }
        );
        let labels: Vec<String> = diagram
            .special_points
            .iter()
            .map(|s| format!("{} {:.9} nm", s.label, s.z_nm))
            .collect();
        println!("{:<15} {}", "", labels.join(", "));
        breakdown.push((
            name,
            median,
            work(&model, &settings, &diagram),
            diagram.points.len(),
        ));
    }
    let verdict = |seconds: f64| {
        if seconds < 1.0 && all_ok {
            "met"
        } else {
            "NOT met"
        }
    };
    println!(
        "total: {:.1} ms wall (medians) for {total_points} points in 4 diagrams (target < 1000 \
         ms: {})",
        total * 1e3,
        verdict(total)
    );
    if let Some(cpu) = total_cpu {
        println!(
            "total: {:.1} ms on the CPU (medians of the thread's CPU time; target: {})",
            cpu * 1e3,
            verdict(cpu)
        );
    }
    let threads = std::thread::available_parallelism()
        .map_or(1, usize::from)
        .min(CASES.len());
    let at_once = median_seconds(repetitions, || all_at_once(threads));
    println!(
        "the four at once on {threads} thread(s), one case per thread at a time (as `drumroll \
         continue --case ... --case ...` computes them): {:.1} ms wall (median of \
         {repetitions}; issue 29's target < 100 ms: {})",
        at_once * 1e3,
        if at_once < 0.1 { "met" } else { "NOT met" }
    );
    println!(
        "\nwhere the time goes (per diagram; one period map = one Newton iteration of the \
         corrector, with monodromy and parameter sensitivity)"
    );
    println!(
        "{:<15} {:>10} {:>10} {:>14} {:>11} {:>16} {:>14}",
        "case",
        "map (us)",
        "obs. (us)",
        "accepted maps",
        "maps/point",
        "accepted ms (%)",
        "obs. ms (%)"
    );
    for (name, median, work, points) in &breakdown {
        let accepted = work.accepted_maps as f64 * work.map_us * 1e-3;
        let observables = *points as f64 * work.observables_us * 1e-3;
        println!(
            "{:<15} {:>10.1} {:>10.1} {:>14} {:>11.2} {:>9.1} ({:>3.0}%) {:>7.1} ({:>3.0}%)",
            name,
            work.map_us,
            work.observables_us,
            work.accepted_maps,
            work.accepted_maps as f64 / *points as f64,
            accepted,
            100.0 * accepted / (median * 1e3),
            observables,
            100.0 * observables / (median * 1e3),
        );
    }
    println!(
        "(the rest: rejected corrector attempts, special-point location, linear algebra, \
         allocation)\n"
    );
    println!(
        "the observables' cost: CPU ms (medians of {repetitions}) of the diagram (observables \
         recorded during the corrector's accepted map) and of the same continuation without \
         them; 'again' = one more integration per point for its observables (the way before)"
    );
    println!(
        "{:<15} {:>8} {:>13} {:>14} {:>9} {:>10} {:>12}",
        "case", "points", "with obs. ms", "without ms", "extra %", "again ms", "again extra %"
    );
    for (name, _, work, points) in &breakdown {
        let model =
            TappingModel::from_case(&builtin_case(name).expect("built-in case")).expect("model");
        let settings = DiagramSettings::approach(&model);
        let z_last = approach_diagram(&model, &settings)
            .expect("diagram")
            .points
            .last()
            .expect("a point")
            .z_nm;
        let with = median_cpu_seconds(repetitions, || {
            std::hint::black_box(approach_diagram(&model, &settings).expect("diagram"));
        });
        let mut bare_points = 0;
        let without = median_cpu_seconds(repetitions, || {
            bare_points = std::hint::black_box(bare_continuation(&model, &settings, z_last));
        });
        let again = *points as f64 * work.observables_us * 1e-6;
        println!(
            "{:<15} {:>8} {:>13.1} {:>14.1} {:>9.1} {:>10.1} {:>12.1}",
            name,
            format!("{points}/{bare_points}"),
            with * 1e3,
            without * 1e3,
            100.0 * (with / without - 1.0),
            again * 1e3,
            100.0 * again / without,
        );
    }
    println!();
    let per_case = total / CASES.len() as f64;
    println!(
        "vs a brute-force scipy sweep of one case ({SCIPY_SWEEP_POINTS} Z values in \
         {SCIPY_SECONDS_PER_SWEEP} s): {:.0}x faster per case ({:.1} ms per case, with about \
         {:.1}x the Z values and every special point located), {:.0}x per point",
        SCIPY_SECONDS_PER_SWEEP / per_case,
        per_case * 1e3,
        total_points as f64 / CASES.len() as f64 / SCIPY_SWEEP_POINTS,
        (SCIPY_SECONDS_PER_SWEEP / SCIPY_SWEEP_POINTS) / (total / total_points as f64)
    );
}
