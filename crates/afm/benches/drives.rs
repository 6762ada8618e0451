//! Benchmark of every model's approach diagram (`DiagramSettings::approach`) against the Hertz
//! diagram of the same case (issue 33: each within 3 times Hertz's): the hydration force
//! (`biolever-mica-hydration`, MODEL.md section 9), the acoustic drive
//! (`biolever-mica-acoustic`, section 14) and the standard linear solid
//! (`biolever-soft-viscoelastic`, against `biolever-soft`), and the bimodal drive
//! (`biolever-mica-bimodal`, a second drive at 8 `f_1`, so that its common period is one drive
//! period) against the same case driven at one frequency over that period (`biolever-mica`).
//! The bimodal diagram has more branch points and special points than the single drive's (the
//! second drive's folds and period doublings near each grazing), so the time per branch point
//! is compared as well as the total; the bimodal case with `A0_b = 0` (the single drive through
//! the bimodal code: the same diagram as `biolever-mica`) shows the cost of the machinery alone.
//!
//! Instruction counts (`valgrind --tool=callgrind`, deterministic on the shared machine) of
//! `drumroll continue --case C --json` are quoted in docs/guide/performance.md.
//!
//! Run with `cargo bench -p afm --bench drives`; `-- --repetitions N` (default 5) sets the
//! repetitions of each diagram, whose least thread CPU time is reported (on a loaded machine
//! other work only ever adds to a run's time, and the median still scattered by a factor 2).

use afm::model::drive_spec::DriveSpec;
use afm::{approach_diagram, builtin_case, DiagramSettings, TappingModel};

/// The calling thread's CPU time so far, seconds (Linux `/proc/thread-self/schedstat`), else
/// the wall clock since an arbitrary instant.
fn cpu_seconds(start: std::time::Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|text| text.split_whitespace().next()?.parse::<f64>().ok())
        .map_or_else(|| start.elapsed().as_secs_f64(), |ns| ns * 1e-9)
}

/// The model of built-in case `name`; with `silent_second`, its bimodal drive's second free
/// amplitude set to 0.
fn model(name: &str, silent_second: bool) -> TappingModel {
    let mut case = builtin_case(name).expect("built-in case");
    if silent_second {
        if let DriveSpec::Bimodal {
            second_free_amplitude_nm,
            ..
        } = &mut case.drive
        {
            *second_free_amplitude_nm = 0.0;
        }
    }
    TappingModel::from_case(&case).expect("model")
}

/// The least CPU seconds of `repetitions` approach diagrams of `model`, its point count and
/// special-point count.
fn time_diagram(model: &TappingModel, repetitions: usize) -> (f64, usize, usize) {
    let settings = DiagramSettings::approach(model);
    let clock = std::time::Instant::now();
    let (mut points, mut special) = (0, 0);
    let mut times: Vec<f64> = (0..repetitions)
        .map(|_| {
            let start = cpu_seconds(clock);
            let diagram = approach_diagram(model, &settings).expect("diagram");
            (points, special) = (diagram.points.len(), diagram.special_points.len());
            cpu_seconds(clock) - start
        })
        .collect();
    times.sort_by(f64::total_cmp);
    (times[0], points, special)
}

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
    // (label, case, second amplitude silenced, reference row).
    let rows: [(&str, &str, bool, usize); 7] = [
        ("biolever-mica (Hertz)", "biolever-mica", false, 0),
        ("hydration", "biolever-mica-hydration", false, 0),
        ("acoustic", "biolever-mica-acoustic", false, 0),
        ("bimodal", "biolever-mica-bimodal", false, 0),
        ("bimodal, A0_b = 0", "biolever-mica-bimodal", true, 0),
        ("biolever-soft (Hertz)", "biolever-soft", false, 5),
        (
            "standard linear solid",
            "biolever-soft-viscoelastic",
            false,
            5,
        ),
    ];
    println!(
        "approach diagrams (DiagramSettings::approach), least CPU time of {repetitions} \
         repetitions, one thread; x: against the reference row's Hertz diagram"
    );
    println!(
        "{:<24} {:>7} {:>8} {:>10} {:>10} {:>9} {:>12}",
        "model", "points", "special", "least ms", "us/point", "x total", "x per point"
    );
    let mut measured: Vec<(f64, f64)> = Vec::with_capacity(rows.len());
    for (label, case, silent_second, reference) in rows {
        let (least, points, special) = time_diagram(&model(case, silent_second), repetitions);
        let per_point = least / points.max(1) as f64;
        measured.push((least, per_point));
        let (total, point) = measured[reference];
        println!(
            "{:<24} {:>7} {:>8} {:>10.1} {:>10.1} {:>9.2} {:>12.2}",
            label,
            points,
            special,
            1e3 * least,
            1e6 * per_point,
            least / total,
            per_point / point
        );
    }
}
