//! Benchmark of the contact laws (MODEL.md section 9): the approach diagram
//! (`DiagramSettings::approach`) of the Biolever and the MAClever on the soft sample with a DMT
//! law (H = 5e-22 J, a0 = 0.165 nm), a clipped Kelvin-Voigt law (eta = 100 Pa s), a standard
//! linear solid (E0 = 1 GPa, Einf = 0.4 GPa, tau = 5 us), Hertz with the hydration force
//! (10 MPa, 0.25 nm, 0.3 nm) and JKR (W = 0.5 mJ/m^2, the `adhesive-soft` sample; W = 2 mJ/m^2,
//! `sticky-soft`, whose approach meets the pull-off grazing), against the Hertz diagram of the
//! same case; and the capillary meniscus in air, the built-in `rectangular-air-mica-humid`
//! against the same case on dry `mica`. Target: each within 3 times the Hertz time.
//!
//! Run with `cargo bench -p afm --bench contact_laws`; `-- --repetitions N` (default 5) sets
//! the repetitions of each diagram, whose median thread CPU time is reported.

use afm::{approach_diagram, builtin_cantilever, fixtures::parse_sample, DiagramSettings};
use afm::{builtin_case, builtin_sample};
use afm::{Separation, TappingModel};

/// The calling thread's CPU time so far, seconds (Linux `/proc/thread-self/schedstat`), else
/// the wall clock since an arbitrary instant.
fn cpu_seconds(start: std::time::Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|text| text.split_whitespace().next()?.parse::<f64>().ok())
        .map_or_else(|| start.elapsed().as_secs_f64(), |ns| ns * 1e-9)
}

/// The soft sample (E_s = 1 GPa) with the `contact` object `contact` (`None`: Hertz).
fn model(cantilever: &str, free_amplitude_nm: f64, contact: Option<&str>) -> TappingModel {
    let contact = contact.map_or(String::new(), |c| format!(r#", "contact": {c}"#));
    let text = format!(r#"{{"name": "soft", "youngs_modulus_gpa": 1.0{contact}}}"#);
    let sample = parse_sample("bench sample", &text).expect("sample");
    let cantilever = builtin_cantilever(cantilever).expect("cantilever");
    TappingModel::new(
        cantilever,
        sample,
        free_amplitude_nm,
        None,
        Separation::Constant(0.0),
    )
    .expect("model")
}

/// Median CPU seconds of `repetitions` approach diagrams of `model`, and its point count.
fn time_diagram(model: &TappingModel, repetitions: usize) -> (f64, usize) {
    let settings = DiagramSettings::approach(model);
    let clock = std::time::Instant::now();
    let mut points = 0;
    let mut times: Vec<f64> = (0..repetitions)
        .map(|_| {
            let start = cpu_seconds(clock);
            let diagram = approach_diagram(model, &settings).expect("diagram");
            points = diagram.points.len();
            cpu_seconds(clock) - start
        })
        .collect();
    times.sort_by(f64::total_cmp);
    (times[repetitions / 2], points)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let repetitions = args
        .iter()
        .position(|a| a == "--repetitions")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(5usize)
        .max(1);
    let laws = [
        ("hertz", None),
        (
            "dmt",
            Some(
                r#"{"law": "dmt", "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}"#,
            ),
        ),
        (
            "kelvin-voigt",
            Some(r#"{"law": "kelvin-voigt", "viscosity_pa_s": 100}"#),
        ),
        (
            "sls",
            Some(
                r#"{"law": "standard-linear-solid", "instant_modulus_gpa": 1.0, "relaxed_modulus_gpa": 0.4, "relaxation_time_us": 5.0}"#,
            ),
        ),
        // The hydration object follows the contact object in the sample's text.
        (
            "hydration",
            Some(
                r#"{"law": "hertz"}, "hydration": {"pressure_mpa": 10, "layer_spacing_nm": 0.25, "decay_length_nm": 0.3}"#,
            ),
        ),
        (
            "jkr",
            Some(r#"{"law": "jkr", "work_of_adhesion_mj_per_m2": 0.5}"#),
        ),
        (
            "jkr-sticky",
            Some(r#"{"law": "jkr", "work_of_adhesion_mj_per_m2": 2.0}"#),
        ),
    ];
    for (cantilever, a0) in [("biolever", 10.0), ("maclever", 20.0)] {
        let mut hertz_seconds = f64::NAN;
        for (name, contact) in laws {
            let (seconds, points) = time_diagram(&model(cantilever, a0, contact), repetitions);
            if contact.is_none() {
                hertz_seconds = seconds;
            }
            println!(
                "{cantilever}-soft {name:>13}: {:8.1} ms ({points} points), {:.2} x Hertz",
                1e3 * seconds,
                seconds / hertz_seconds
            );
        }
    }
    // The capillary meniscus needs a cantilever in air: the built-in humid case against the
    // same case on dry mica (Hertz).
    let humid = builtin_case("rectangular-air-mica-humid").expect("case");
    let dry = afm::Case {
        sample: builtin_sample("mica").expect("sample"),
        ..humid.clone()
    };
    let (hertz_seconds, hertz_points) =
        time_diagram(&TappingModel::from_case(&dry).expect("model"), repetitions);
    let (seconds, points) = time_diagram(
        &TappingModel::from_case(&humid).expect("model"),
        repetitions,
    );
    println!(
        "rectangular-air-mica    hertz: {:8.1} ms ({hertz_points} points)",
        1e3 * hertz_seconds
    );
    println!(
        "rectangular-air-mica capillary: {:8.1} ms ({points} points), {:.2} x Hertz",
        1e3 * seconds,
        seconds / hertz_seconds
    );
}
