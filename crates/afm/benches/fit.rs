//! Benchmark of a measured-curve fit (MODEL.md section 13.3): four parameters (piezo offset,
//! amplitude calibration, phase offset, sample modulus) fitted to a synthetic 1000-point
//! approach of `maclever-mica-experiment`, starting from a modulus 1.6 times too high; and one
//! detection of its transitions. Target (issue 32): the fit under 10 s.
//!
//! Run with `cargo bench -p afm --bench fit`; `-- --repetitions N` (default 3) sets the
//! repetitions, whose median is reported (wall time and the CPU time of all the process's threads;
//! `RAYON_NUM_THREADS=1` runs the Jacobian's columns on one).

use afm::fit::least_squares::{fit_measurement, FitParameter, FitSettings};
use afm::fit::measurement::{Measurement, MeasurementOptions};
use afm::fit::synthetic::{model_branch, synthetic_approach, to_csv, SyntheticInstrument};
use afm::fit::transitions::{detect_transitions, DetectionSettings};
use afm::map::parameter_axis::ParameterAxis;
use afm::{builtin_case, TappingModel};
use std::time::Instant;

mod cpu_time;
use cpu_time::process_cpu_seconds;

/// Median (wall, CPU) seconds of `repetitions` calls of `f`.
fn median<F: FnMut()>(repetitions: usize, mut f: F) -> (f64, f64) {
    let mut wall = Vec::new();
    let mut cpu = Vec::new();
    for _ in 0..repetitions {
        let (start, start_cpu) = (Instant::now(), process_cpu_seconds().unwrap_or(0.0));
        f();
        wall.push(start.elapsed().as_secs_f64());
        cpu.push(process_cpu_seconds().unwrap_or(0.0) - start_cpu);
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
        .and_then(|i| args.get(i + 1))
        .and_then(|n| n.parse().ok())
        .unwrap_or(3usize)
        .max(1);
    let case = builtin_case("maclever-mica-experiment").expect("built-in case");
    let model = TappingModel::from_case(&case).expect("valid case");
    let branch = model_branch(&model).expect("diagram");
    let points = synthetic_approach(
        &branch,
        model.free_amplitude_nm(),
        &SyntheticInstrument::default(),
    );
    let measurement = Measurement::parse(
        &to_csv(&points, &[]),
        "bench",
        &MeasurementOptions::default(),
    )
    .expect("synthetic curve reads");
    let mut start = case.clone();
    start.sample.youngs_modulus_gpa *= 1.6;
    let settings = FitSettings::new(vec![
        FitParameter::ZOffset,
        FitParameter::AmplitudeCalibration,
        FitParameter::PhaseOffset,
        FitParameter::Case(ParameterAxis::SampleModulus),
    ]);
    let mut evaluations = 0;
    let (wall, cpu) = median(repetitions, || {
        let result = fit_measurement(&start, &measurement, &settings).expect("fit");
        evaluations = result.evaluations;
    });
    println!(
        "fit, 4 parameters, {} points: {wall:.2} s wall, {cpu:.2} s CPU (median of {repetitions}; {evaluations} residual evaluations)",
        measurement.approach.len()
    );
    let (wall, cpu) = median(repetitions, || {
        detect_transitions(
            &measurement.approach,
            measurement.a0_nm,
            &DetectionSettings::default(),
        )
        .expect("detection");
    });
    println!(
        "detection, {} points: {wall:.3} s wall, {cpu:.3} s CPU",
        measurement.approach.len()
    );
}
