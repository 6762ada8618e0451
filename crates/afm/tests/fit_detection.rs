//! Detection of regime boundaries in synthetic measured curves made by drumroll itself
//! (MODEL.md sections 13.2 and 13.5): the truth is the model's own `G_n` shifted by the
//! instrument's piezo offset.
//!
//! The full studies (20 seeds on both cases, 200 smooth curves) are
//! `cargo test --release -p afm --test fit_detection -- --ignored --nocapture`.
use afm::fit::followed_branch::FollowedBranch;
use afm::fit::measurement::MeasuredPoint;
use afm::fit::synthetic::{model_branch, synthetic_approach, SyntheticInstrument};
use afm::fit::transitions::{detect_transitions, DetectionSettings};
use afm::{builtin_case, TappingModel};

fn branch_of(case: &str) -> (FollowedBranch, f64) {
    let model = TappingModel::from_case(&builtin_case(case).unwrap()).unwrap();
    let a0 = model.free_amplitude_nm();
    (model_branch(&model).unwrap(), a0)
}

/// For seeds `seeds`, how often each `G_n` (n >= 2, A/A0 > 0.3) is detected within 3 of its
/// reported sigmas, with the labels.
fn detection_counts(case: &str, seeds: std::ops::Range<u64>) -> Vec<(String, usize)> {
    let (branch, a0) = branch_of(case);
    let targets: Vec<(String, f64)> = branch
        .diagram
        .special_points
        .iter()
        .filter(|s| s.label.starts_with('G') && s.label != "G1" && s.amplitude_ratio > 0.3)
        .map(|s| (s.label.clone(), s.z_nm))
        .collect();
    let mut counts: Vec<(String, usize)> = targets.iter().map(|(l, _)| (l.clone(), 0)).collect();
    for seed in seeds {
        let instrument = SyntheticInstrument {
            seed,
            ..SyntheticInstrument::default()
        };
        let points = synthetic_approach(&branch, a0, &instrument);
        let detection = detect_transitions(
            &points,
            a0 * instrument.amplitude_calibration,
            &DetectionSettings::default(),
        )
        .unwrap();
        for (k, (label, z)) in targets.iter().enumerate() {
            let truth = z + instrument.z_offset_nm;
            let hit = detection
                .transitions
                .iter()
                .any(|t| (t.z_nm - truth).abs() <= 3.0 * t.z_uncertainty_nm);
            counts[k].1 += usize::from(hit);
            if !hit {
                println!(
                    "{case} seed {seed}: {label} at {truth:.4} missed: {:?}",
                    detection
                        .transitions
                        .iter()
                        .map(|t| (t.z_nm, t.z_uncertainty_nm))
                        .collect::<Vec<_>>()
                );
            }
        }
    }
    counts
}

/// The criterion on the paper's experiment: G2 (A/A0 = 0.55) found within 3 of its
/// sigmas in at least 18 of 20 seeds.
#[test]
fn maclever_mica_g2_is_found_within_three_sigma_in_18_of_20_seeds() {
    let counts = detection_counts("maclever-mica-experiment", 0..20);
    println!("{counts:?}");
    assert!(!counts.is_empty());
    for (label, count) in counts {
        assert!(count >= 18, "{label}: {count} of 20");
    }
}

/// The Biolever on the soft sample: G2 (A/A0 = 0.93, 1.2 nm below G1) and the weak G3 kink
/// (A/A0 = 0.48, whose slope change builds up over about 0.5 nm and which only the long scan
/// window resolves) each found within 3 of its reported sigmas in at least 4 of 5 seeds (the
/// full study over 20 seeds is the ignored `detection_studies`: 19/20 and 18/20).
#[test]
fn biolever_soft_g2_and_weak_g3_are_found_within_three_sigma() {
    let counts = detection_counts("biolever-soft", 0..5);
    println!("{counts:?}");
    assert_eq!(counts.len(), 2, "{counts:?}");
    for (label, count) in counts {
        assert!(count >= 4, "{label}: {count} of 5");
    }
}

/// Smooth noisy curves: the model's branch between G2 + 1 nm and G1 - 1 nm (no transition
/// there), 30 seeds: at most 1 (3%; the level is 1%) may show a spurious transition at the default level.
#[test]
fn smooth_curves_give_few_spurious_transitions() {
    let spurious = spurious_count(0..30);
    assert!(spurious <= 1, "{spurious} of 30 smooth curves");
}

fn spurious_count(seeds: std::ops::Range<u64>) -> usize {
    let (branch, a0) = branch_of("maclever-mica-experiment");
    let z_of = |label: &str| {
        branch
            .diagram
            .special_points
            .iter()
            .find(|s| s.label == label)
            .unwrap()
            .z_nm
    };
    let (low, high) = (z_of("G2") + 1.0, z_of("G1") - 1.0);
    let mut spurious = 0;
    for seed in seeds {
        let instrument = SyntheticInstrument {
            seed: 1000 + seed,
            ..SyntheticInstrument::default()
        };
        let points: Vec<MeasuredPoint> = synthetic_approach(&branch, a0, &instrument)
            .into_iter()
            .filter(|p| (low..high).contains(&(p.z_nm - instrument.z_offset_nm)))
            .collect();
        let detection = detect_transitions(&points, a0, &DetectionSettings::default()).unwrap();
        if !detection.transitions.is_empty() {
            println!("seed {seed}: spurious {:?}", detection.transitions);
            spurious += 1;
        }
    }
    spurious
}

/// The full studies whose results MODEL.md section 13.5 and the guide quote.
#[test]
#[ignore = "studies over 20 seeds and 200 smooth curves, a few minutes"]
fn detection_studies() {
    for case in ["maclever-mica-experiment", "biolever-soft"] {
        println!("{case}: {:?} of 20", detection_counts(case, 0..20));
    }
    println!("spurious: {} of 200 smooth curves", spurious_count(0..200));
}
