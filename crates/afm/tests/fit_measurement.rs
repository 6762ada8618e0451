//! Fitting the model to synthetic measurements made by drumroll itself (MODEL.md section
//! 13.3-13.5): the truth is the instrument's offset, calibration and phase offset and the case's
//! sample modulus, which the fit starts away from.
//!
//! The suite runs one seed; the coverage study over 20 seeds is
//! `cargo test --release -p afm --test fit_measurement -- --ignored --nocapture`.
use afm::diagram::bifurcation_diagram::{approach_diagram, DiagramSettings};
use afm::fit::followed_branch::FollowedBranch;
use afm::fit::least_squares::{fit_measurement, FitParameter, FitResult, FitSettings};
use afm::fit::measurement::{Measurement, MeasurementOptions};
use afm::fit::synthetic::{model_branch, synthetic_approach, to_csv, SyntheticInstrument};
use afm::map::parameter_axis::ParameterAxis;
use afm::{builtin_case, Case, TappingModel};

/// The truth: the instrument on the experiment's case (mica, E = 60 GPa).
const CASE: &str = "maclever-mica-experiment";

fn fit_seed(case: &Case, seed: u64) -> (FitResult, [f64; 4]) {
    let instrument = SyntheticInstrument {
        seed,
        ..SyntheticInstrument::default()
    };
    let result = fit_with(case, &instrument, 1);
    let truth = [
        instrument.z_offset_nm,
        instrument.amplitude_calibration,
        instrument.phase_offset_deg,
        case.sample.youngs_modulus_gpa,
    ];
    (result, truth)
}

/// Fit the four parameters to `case`'s curve seen through `instrument`, the curve sampled from a
/// diagram with `refine` times the fit's density of points.
fn fit_with(case: &Case, instrument: &SyntheticInstrument, refine: u32) -> FitResult {
    let model = TappingModel::from_case(case).unwrap();
    let mut diagram_settings = DiagramSettings::approach(&model);
    diagram_settings.max_step /= f64::from(refine);
    let branch = FollowedBranch::new(approach_diagram(&model, &diagram_settings).unwrap());
    let points = synthetic_approach(&branch, model.free_amplitude_nm(), instrument);
    let measurement = Measurement::parse(
        &to_csv(&points, &[]),
        "synthetic.csv",
        &MeasurementOptions::default(),
    )
    .unwrap();
    // The fit starts from a modulus 1.6 times too high.
    let mut start = case.clone();
    start.sample.youngs_modulus_gpa *= 1.6;
    let settings = FitSettings::new(vec![
        FitParameter::ZOffset,
        FitParameter::AmplitudeCalibration,
        FitParameter::PhaseOffset,
        FitParameter::Case(ParameterAxis::SampleModulus),
    ]);
    fit_measurement(&start, &measurement, &settings).unwrap()
}

/// How many of the four parameters lie within `k` of their standard errors of the truth.
fn within(result: &FitResult, truth: &[f64; 4], k: f64) -> [bool; 4] {
    let mut out = [false; 4];
    for (i, p) in result.parameters.iter().enumerate() {
        out[i] = p
            .stderr
            .is_some_and(|s| (p.value - truth[i]).abs() <= k * s);
    }
    out
}

/// One seed: every parameter within 3 of its reported sigmas (a 0.3% chance each if the
/// errors are right), the residuals at the noise (reduced chi^2 within 0.8..1.25 for 2000
/// residuals), and the fitted G2 where the true one is shifted by the offset.
#[test]
fn one_seed_recovers_the_truth_within_three_sigma() {
    let case = builtin_case(CASE).unwrap();
    let model = TappingModel::from_case(&case).unwrap();
    let true_g2 = model_branch(&model)
        .unwrap()
        .diagram
        .special_points
        .iter()
        .find(|s| s.label == "G2")
        .unwrap()
        .z_nm;
    for seed in [11] {
        let (result, truth) = fit_seed(&case, seed);
        assert!(result.converged, "{}", result.termination);
        for (i, ok) in within(&result, &truth, 3.0).iter().enumerate() {
            assert!(
                ok,
                "seed {seed}: {:?} vs truth {}",
                result.parameters[i], truth[i]
            );
        }
        assert!(
            (0.8..1.25).contains(&result.reduced_chi2),
            "reduced chi2 {}",
            result.reduced_chi2
        );
        let g2 = result.grazing.iter().find(|g| g.label == "G2").unwrap();
        let z_offset = &result.parameters[0];
        assert!(
            (g2.z_nm - (true_g2 + truth[0])).abs() < 0.2,
            "G2 at {} vs {}",
            g2.z_nm,
            true_g2 + truth[0]
        );
        assert!(z_offset.stderr.unwrap() < 0.2);
    }
}

/// The coverage study: 20 seeds (100..119; `DRUMROLL_COVERAGE_SEEDS=N` for N), each parameter
/// within its 2-sigma interval (expected 95%); prints the RMS and mean of
/// `(value - truth) / stderr` (1 and 0 if the errors are honest).
#[test]
#[ignore = "coverage study over 20 seeds, several minutes; run with --ignored --nocapture"]
fn coverage_over_twenty_seeds() {
    let case = builtin_case(CASE).unwrap();
    let mut inside = [0usize; 4];
    let mut sum = [0.0f64; 4];
    let mut sum2 = [0.0f64; 4];
    let seeds: u64 = std::env::var("DRUMROLL_COVERAGE_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    for seed in 100..100 + seeds {
        let (result, truth) = fit_seed(&case, seed);
        let hits = within(&result, &truth, 2.0);
        for i in 0..4 {
            inside[i] += usize::from(hits[i]);
            let p = &result.parameters[i];
            let score = (p.value - truth[i]) / p.stderr.unwrap_or(f64::NAN);
            sum[i] += score;
            sum2[i] += score * score;
        }
        println!(
            "seed {seed}: {} chi2 {:.3} evals {}",
            result
                .parameters
                .iter()
                .zip(truth.iter())
                .map(|(p, t)| format!(
                    "{} = {:.4} +- {:.4} (z {:.2})",
                    p.name,
                    p.value,
                    p.stderr.unwrap_or(f64::NAN),
                    (p.value - t) / p.stderr.unwrap_or(f64::NAN)
                ))
                .collect::<Vec<_>>()
                .join(", "),
            result.reduced_chi2,
            result.evaluations
        );
    }
    let n = seeds as f64;
    println!("within 2 sigma of the truth (of {seeds}): z_offset {}, calibration {}, phase offset {}, modulus {}", inside[0], inside[1], inside[2], inside[3]);
    println!(
        "RMS of (value - truth)/stderr: {:.2?}; mean: {:.2?}",
        sum2.map(|s| (s / n).sqrt()),
        sum.map(|s| s / n)
    );
    for count in inside {
        assert!(count as f64 >= 0.8 * n, "coverage {count} of {seeds}");
    }
}

/// The fit's bias: a curve with the noise 1000 times smaller than the (same ratio of
/// amplitude to phase noise, so the same weights), sampled from a diagram 8 times denser than
/// the fit's (so that the fit's interpolation between its points is tested against a finer
/// reference), must return the truth within half the standard errors of the noise
/// (seed 11); printed as deviation over that standard error.
#[test]
#[ignore = "bias study, two fits; run with --ignored --nocapture"]
fn quiet_curve_returns_the_truth() {
    let case = builtin_case(CASE).unwrap();
    let (noisy, truth) = fit_seed(&case, 11);
    let quiet_instrument = SyntheticInstrument {
        seed: 11,
        amplitude_noise_fraction: 0.003e-3,
        phase_noise_deg: 0.15e-3,
        ..SyntheticInstrument::default()
    };
    let quiet = fit_with(&case, &quiet_instrument, 8);
    for ((noisy, quiet), truth) in noisy.parameters.iter().zip(&quiet.parameters).zip(truth) {
        let stderr = noisy.stderr.unwrap();
        let deviation = quiet.value - truth;
        println!(
            "{}: quiet deviation {:.3e}, noisy stderr {:.3e}, ratio {:.3}",
            quiet.name,
            deviation,
            stderr,
            deviation / stderr
        );
        assert!(
            deviation.abs() < 0.5 * stderr,
            "{}: bias {deviation} vs stderr {stderr}",
            quiet.name
        );
    }
}

/// Seven parameters on the MAClever's synthetic curve (`fixtures/measurements`), fitted with the
/// built-in `maclever-mica` case: the data cannot separate the sample modulus, tip radius and
/// first mode, and Levenberg-Marquardt's early steps push the modulus past its range (to an
/// overflow of its logarithm). Such trial steps are rejected and the fit goes on: it returns a
/// result whose values all lie in their ranges and which says how many steps were rejected.
/// Before the rejection this fit failed with "field `sample-modulus` = inf is invalid".
#[test]
fn trial_steps_out_of_the_models_range_are_rejected_and_the_fit_goes_on() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/measurements/maclever-mica-synthetic.csv"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let measurement = Measurement::parse(&text, path, &MeasurementOptions::default()).unwrap();
    let case = builtin_case("maclever-mica").unwrap();
    let mut parameters = vec![
        FitParameter::ZOffset,
        FitParameter::AmplitudeCalibration,
        FitParameter::PhaseOffset,
    ];
    parameters.extend(
        [
            ParameterAxis::SampleModulus,
            ParameterAxis::TipRadius,
            ParameterAxis::QualityFactor(1),
            ParameterAxis::Stiffness(1),
        ]
        .map(FitParameter::Case),
    );
    let axes: Vec<Option<ParameterAxis>> = parameters
        .iter()
        .map(|p| match p {
            FitParameter::Case(axis) => Some(*axis),
            _ => None,
        })
        .collect();
    let mut settings = FitSettings::new(parameters);
    settings.max_evaluations = 8;
    let result = fit_measurement(&case, &measurement, &settings).unwrap();
    assert!(
        result.warnings.iter().any(
            |w| w.contains("trial steps could not be evaluated") && w.contains("were rejected")
        ),
        "{:?}",
        result.warnings
    );
    for (value, axis) in result.parameters.iter().zip(&axes) {
        assert!(value.value.is_finite(), "{value:?}");
        if let Some(axis) = axis {
            assert!(axis.allows(&case, value.value), "{value:?}");
        }
    }
    // Levenberg-Marquardt's count includes the rejected steps, within its budget: MINPACK's
    // patience ceil(8 / 9) = 1 times the varied quantities plus one, 8 + 1 (seven parameters,
    // the calibration varying two).
    assert!(result.evaluations <= 9, "{}", result.evaluations);
}
