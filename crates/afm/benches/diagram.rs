//! Benchmark of the full four-case bifurcation-diagram computation (the target): the
//! approach diagrams of the paper's four cases (Biolever and MAClever on mica and on the soft
//! sample; MODEL.md section 6) with `DiagramSettings::approach`, every special point located.
//!
//! Target: all four diagrams, each with at least 300 points and every special point to
//! 1e-9 nm, in under 1 s in total (release build, one core). The reference is a brute-force
//! scipy sweep of one case at about 250 separations, which takes about a minute.
//!
//! Run with `cargo bench -p afm --bench diagram`; `-- --repetitions N` (default 5) sets the
//! repetitions of each diagram, whose median is reported.

use afm::{approach_diagram, builtin_case, BifurcationDiagram, DiagramSettings, TappingModel};
use std::time::Instant;

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
        "{:<15} {:>8} {:>8} {:>10} {:>11} {:>10} {:>9} {:>22}",
        "case",
        "points",
        "special",
        "median ms",
        "us/point",
        "min ms",
        "max ms",
        "worst precision (nm)"
    );
    let mut total = 0.0;
    let mut all_ok = true;
    let mut total_points = 0;
    for name in CASES {
        let model =
            TappingModel::from_case(&builtin_case(name).expect("built-in case")).expect("model");
        let settings = DiagramSettings::approach(&model);
        let mut times = Vec::with_capacity(repetitions);
        let mut last: Option<BifurcationDiagram> = None;
        for _ in 0..repetitions {
            let start = Instant::now();
            let diagram = approach_diagram(&model, &settings).expect("diagram");
            times.push(start.elapsed().as_secs_f64());
            last = Some(std::hint::black_box(diagram));
        }
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
            "{:<15} {:>8} {:>8} {:>10.1} {:>11.1} {:>10.1} {:>9.1} {:>22.1e}{}",
            name,
            diagram.points.len(),
            diagram.special_points.len(),
            median * 1e3,
            median * 1e6 / diagram.points.len() as f64,
            times[0] * 1e3,
            times[times.len() - 1] * 1e3,
            worst_precision,
            if ok { "" } else { "  (target missed)" }
        );
        let labels: Vec<String> = diagram
            .special_points
            .iter()
            .map(|s| format!("{} {:.9} nm", s.label, s.z_nm))
            .collect();
        println!("{:<15} {}", "", labels.join(", "));
    }
    println!(
        "total: {:.1} ms for {total_points} points in 4 diagrams (target < 1000 ms; {})",
        total * 1e3,
        if total < 1.0 && all_ok {
            "met"
        } else {
            "NOT met"
        }
    );
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
