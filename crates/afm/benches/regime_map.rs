//! Benchmark of a regime map (issue 23): the Biolever on mica over the free amplitude
//! `A0 = 5 .. 20 nm`, every `G_n`, fold and period-doubling curve of its approach diagram with
//! at least 100 points each, against one approach diagram (what `drumroll continue` computes),
//! both timed in the same run: wall time, and the CPU time of all the process's threads (the
//! map's curves run in parallel on rayon's; `RAYON_NUM_THREADS=1` runs them on one).
//!
//! Target: the map in under 1 s on one core and at most 5 times one diagram.
//!
//! Run with `cargo bench -p afm --bench regime_map`; `-- --repetitions N` (default 3) sets the
//! repetitions, whose median is reported.

use std::time::Instant;

use afm::{
    approach_diagram, builtin_case, regime_map, DiagramSettings, ParameterAxis, RegimeMapSettings,
    TappingModel,
};

mod cpu_time;
use cpu_time::process_cpu_seconds;

/// Median (wall, CPU) seconds of `repetitions` calls of `f` (CPU NaN where `/proc` cannot
/// be read).
fn median_seconds<F: FnMut()>(repetitions: usize, mut f: F) -> (f64, f64) {
    let mut wall = Vec::new();
    let mut cpu = Vec::new();
    for _ in 0..repetitions {
        let (start, start_cpu) = (Instant::now(), process_cpu_seconds());
        f();
        wall.push(start.elapsed().as_secs_f64());
        cpu.push(match (start_cpu, process_cpu_seconds()) {
            (Some(a), Some(b)) => b - a,
            _ => f64::NAN,
        });
    }
    wall.sort_by(f64::total_cmp);
    cpu.sort_by(f64::total_cmp);
    (wall[repetitions / 2], cpu[repetitions / 2])
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let repetitions = args
        .iter()
        .position(|a| a == "--repetitions")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(3usize)
        .max(1);
    let case = builtin_case("biolever-mica").expect("built-in case");
    let model = TappingModel::from_case(&case).expect("model");
    let diagram_settings = DiagramSettings::approach(&model);
    let settings = RegimeMapSettings::new(&model, 5.0, 20.0);
    let map = regime_map(&case, ParameterAxis::FreeAmplitude, &settings).expect("map");
    for curve in &map.curves {
        let ends: Vec<String> = curve
            .ends
            .iter()
            .map(|e| {
                format!(
                    "{} at A0 = {:.4} nm, Z = {:.4} nm",
                    e.reason, e.parameter, e.z_nm
                )
            })
            .collect();
        println!(
            "{:<16} {:>4} points; ends: {}",
            curve.label,
            curve.points.len(),
            ends.join("; ")
        );
    }
    for point in &map.codim2_points {
        println!(
            "codim-2 {:<24} on {:<6} A0 = {:.6} nm, Z = {:.6} nm (precision {:.1e})",
            point.label, point.curve, point.parameter, point.z_nm, point.precision
        );
    }
    let (diagram_wall, diagram_s) = median_seconds(repetitions, || {
        approach_diagram(&model, &diagram_settings).expect("diagram");
    });
    let (map_wall, map_s) = median_seconds(repetitions, || {
        regime_map(&case, ParameterAxis::FreeAmplitude, &settings).expect("map");
    });
    println!(
        "one approach diagram: {:.1} ms; regime map A0 = 5..20 nm ({} curves, {} points): {:.1} ms; ratio {:.2} (CPU time of the process's threads, median of {repetitions}); wall {:.1} ms and {:.1} ms on {} threads",
        diagram_s * 1e3,
        map.curves.len(),
        map.curves.iter().map(|c| c.points.len()).sum::<usize>(),
        map_s * 1e3,
        map_s / diagram_s,
        diagram_wall * 1e3,
        map_wall * 1e3,
        rayon::current_num_threads()
    );
}
