//! Benchmark of the acoustic and bimodal drives (MODEL.md section 14): the approach diagram
//! (`DiagramSettings::approach`) of the bimodal Biolever on mica (a second drive at 8 `f_1`,
//! so that the common period is one drive period) against the same case driven at one
//! frequency over that period (`biolever-mica`), and of the acoustic case.
//!
//! Target (issue 33): the bimodal diagram within 3x of the single drive's. The diagrams differ
//! in their number of points (the second drive adds folds and period doublings), so the time
//! per branch point is compared as well as the total.
//!
//! Measured on the shared 2-core machine (three runs, loaded): the bimodal diagram has 575
//! points and 17 special points against the single drive's 351 and 3, and takes 1.6 to 2.6
//! times as long per point (2.6 to 4.2 times in total); the acoustic one 8 to 9 times per point
//! (its Hertz contact by Runge-Kutta, MODEL.md section 14).
//!
//! Run with `cargo bench -p afm --bench drives`; `-- --repetitions N` (default 3) sets the
//! repetitions of each diagram, whose median is reported.

use afm::{approach_diagram, builtin_case, DiagramSettings, TappingModel};
use std::time::Instant;

/// The cases: the reference first.
const CASES: [&str; 3] = [
    "biolever-mica",
    "biolever-mica-bimodal",
    "biolever-mica-acoustic",
];

fn main() {
    let repetitions = std::env::args()
        .skip_while(|a| a != "--repetitions")
        .nth(1)
        .map(|n| {
            n.parse::<usize>()
                .expect("--repetitions N: a positive integer")
        })
        .unwrap_or(3)
        .max(1);
    println!(
        "approach diagrams (DiagramSettings::approach), median of {repetitions} repetitions, \
         one thread"
    );
    println!(
        "{:<24} {:>7} {:>8} {:>10} {:>10} {:>12} {:>14}",
        "case", "points", "special", "median ms", "us/point", "x total", "x per point"
    );
    let mut reference: Option<(f64, f64)> = None;
    for name in CASES {
        let model =
            TappingModel::from_case(&builtin_case(name).expect("built-in case")).expect("model");
        let settings = DiagramSettings::approach(&model);
        let mut times = Vec::with_capacity(repetitions);
        let mut last = None;
        for _ in 0..repetitions {
            let start = Instant::now();
            let diagram = approach_diagram(&model, &settings).expect("diagram");
            times.push(start.elapsed().as_secs_f64());
            last = Some(diagram);
        }
        times.sort_by(f64::total_cmp);
        let median = times[repetitions / 2];
        let diagram = last.expect("one repetition");
        let per_point = median / diagram.points.len().max(1) as f64;
        let (total_ratio, point_ratio) = match reference {
            None => {
                reference = Some((median, per_point));
                (1.0, 1.0)
            }
            Some((total, point)) => (median / total, per_point / point),
        };
        println!(
            "{:<24} {:>7} {:>8} {:>10.1} {:>10.1} {:>12.2} {:>14.2}",
            name,
            diagram.points.len(),
            diagram.special_points.len(),
            1e3 * median,
            1e6 * per_point,
            total_ratio,
            point_ratio
        );
    }
}
