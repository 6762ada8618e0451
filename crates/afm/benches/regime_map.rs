//! Benchmark of a regime map (issue 23): the Biolever on mica over the free amplitude
//! `A0 = 5 .. 20 nm`, every `G_n`, fold and period-doubling curve of its approach diagram with
//! at least 100 points each, against one approach diagram (what `drumroll continue` computes),
//! both timed in the same run on the calling thread's CPU clock.
//!
//! Target: the map in under 1 s on one core and at most 5 times one diagram.
//!
//! Run with `cargo bench -p afm --bench regime_map`; `-- --repetitions N` (default 3) sets the
//! repetitions, whose median is reported.

use afm::{
    approach_diagram, builtin_case, regime_map, DiagramSettings, ParameterAxis, RegimeMapSettings,
    TappingModel,
};

/// The calling thread's CPU time so far, seconds (Linux `/proc/thread-self/schedstat`).
fn thread_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|text| text.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

/// Median CPU time of `repetitions` calls of `f`, seconds.
fn median_seconds<F: FnMut()>(repetitions: usize, mut f: F) -> f64 {
    let mut times: Vec<f64> = (0..repetitions)
        .map(|_| {
            let start = thread_cpu_seconds();
            f();
            thread_cpu_seconds() - start
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[repetitions / 2]
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
    let diagram_s = median_seconds(repetitions, || {
        approach_diagram(&model, &diagram_settings).expect("diagram");
    });
    let map_s = median_seconds(repetitions, || {
        regime_map(&case, ParameterAxis::FreeAmplitude, &settings).expect("map");
    });
    println!(
        "one approach diagram: {:.1} ms; regime map A0 = 5..20 nm ({} curves, {} points): {:.1} ms; ratio {:.2} (CPU time of this thread, median of {repetitions})",
        diagram_s * 1e3,
        map.curves.len(),
        map.curves.iter().map(|c| c.points.len()).sum::<usize>(),
        map_s * 1e3,
        map_s / diagram_s
    );
}
