//! Detection of regime boundaries in synthetic measured curves made by drumroll itself
//! (MODEL.md sections 13.2 and 13.5): the truth is the model's own `G_n` shifted by the
//! instrument's piezo offset.
//!
//! The full studies (20 seeds on both cases, 200 smooth curves) are
//! `cargo test --release -p afm --test fit_detection -- --ignored --nocapture`.
use afm::fit::followed_branch::FollowedBranch;
use afm::fit::measurement::MeasuredPoint;
use afm::fit::synthetic::{model_branch, synthetic_approach, SyntheticInstrument};
use afm::fit::transitions::{
    detect_transitions, DetectionSettings, TransitionKind, LONG_WINDOW_FACTOR,
};
use afm::fit::window_models::KINK_ROUNDING;
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

/// A straight approach curve (1000 rows, Z from 20 to 0 nm every 0.02 nm; A/A0 = 0.5 + 0.02 Z
/// and the phase 60 + 1.5 Z deg) with a jump between two rows at Z = 10.01 nm, and white
/// Gaussian noise of 0.3% of A0 and 0.2 deg (a seeded Box-Muller): for jumps of A/A0 by 0.01 to
/// 0.2 (3 to 67 noise levels; the strongest have T far beyond 1489, where `exp(-T/2)` underflows
/// to zero for both alternatives) and of the phase by as many tenths of the noise, exactly one
/// transition, a jump, between the two rows (its Z the gap's middle, its sigma the gap over
/// sqrt(12)).
#[test]
fn jumps_are_found_as_jumps_at_their_gap_however_strong() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut gaussian = move || {
        let (u, v) = (uniform(), uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    };
    let a0 = 10.0;
    for jump in [0.01, 0.03, 0.1, 0.2] {
        let points: Vec<MeasuredPoint> = (0..1000)
            .map(|row| {
                let z = 20.0 - 0.02 * row as f64;
                let below = if z < 10.01 { 1.0 } else { 0.0 };
                MeasuredPoint {
                    line: row + 1,
                    z_nm: z,
                    amplitude_nm: a0 * (0.5 + 0.02 * z - jump * below + 0.003 * gaussian()),
                    phase_deg: 60.0 + 1.5 * z + 20.0 * jump * below + 0.2 * gaussian(),
                }
            })
            .collect();
        let detection = detect_transitions(&points, a0, &DetectionSettings::default()).unwrap();
        let found: Vec<(f64, TransitionKind)> = detection
            .transitions
            .iter()
            .map(|t| (t.z_nm, t.kind))
            .collect();
        assert_eq!(found.len(), 1, "jump {jump}: {found:?}");
        let transition = &detection.transitions[0];
        assert_eq!(
            transition.kind,
            TransitionKind::Jump,
            "jump {jump}: {found:?}"
        );
        assert!(
            (transition.z_nm - 10.01).abs() < 1e-9,
            "jump {jump}: {found:?}"
        );
        assert!((transition.z_uncertainty_nm - 0.02 / 12f64.sqrt()).abs() < 1e-12);
    }
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

/// Smooth noisy curves: a case's branch between two grazings, 1 nm from each (no transition
/// there), sampled at twice the density (2000 rows over the full curve, so that the
/// stretch holds enough rows for the long window of MODEL.md 13.2 to be scanned too), 15 seeds
/// per case: at most 1 of 15 per case (7%; the level is 1%) may show a spurious transition.
#[test]
fn smooth_curves_give_few_spurious_transitions() {
    for (case, low, high) in [
        ("maclever-mica-experiment", "G2", "G1"),
        ("biolever-soft", "G3", "G2"),
    ] {
        let (spurious, long_scanned) = spurious_count(case, (low, high), 0..15);
        assert!(long_scanned, "{case}: the long window was not scanned");
        assert!(spurious <= 1, "{case}: {spurious} of 15 smooth curves");
    }
}

/// How many of the smooth stretches of `case` between grazings `labels` (1 nm from each)
/// give a spurious transition, over `seeds`, and whether the long window was scanned.
fn spurious_count(case: &str, labels: (&str, &str), seeds: std::ops::Range<u64>) -> (usize, bool) {
    let (branch, a0) = branch_of(case);
    let z_of = |label: &str| {
        branch
            .diagram
            .special_points
            .iter()
            .find(|s| s.label == label)
            .unwrap()
            .z_nm
    };
    let (low, high) = (z_of(labels.0) + 1.0, z_of(labels.1) - 1.0);
    let mut spurious = 0;
    let mut long_scanned = true;
    for seed in seeds {
        let instrument = SyntheticInstrument {
            seed: 1000 + seed,
            rows: 2000,
            ..SyntheticInstrument::default()
        };
        let points: Vec<MeasuredPoint> = synthetic_approach(&branch, a0, &instrument)
            .into_iter()
            .filter(|p| (low..high).contains(&(p.z_nm - instrument.z_offset_nm)))
            .collect();
        let detection = detect_transitions(&points, a0, &DetectionSettings::default()).unwrap();
        long_scanned &= points.len() / 4 >= LONG_WINDOW_FACTOR * detection.half_window;
        if !detection.transitions.is_empty() {
            println!("{case} seed {seed}: spurious {:?}", detection.transitions);
            spurious += 1;
        }
    }
    (spurious, long_scanned)
}

/// The information a kink carries against each scan window's smooth null (MODEL.md 13.5): on
/// the noise-free curve (the 1000 rows, statistics in units of the noise),
/// the drop of `chi^2` from the null polynomial to the null plus the detector's kink family
/// (rounded hinge, free curvature below the onset), maximised over the rounding, is the
/// noncentrality of the detector's statistic: printed at each `G_n` (n >= 2) and its largest
/// value on the smooth stretches (0.3 nm or more from every grazing). Computed here by plain
/// least squares, independently of the detector's code.
#[test]
#[ignore = "information study; run with --ignored --nocapture"]
fn kink_information() {
    use nalgebra::{DMatrix, DVector};
    let rss = |z: &[f64], y: &[f64], c: f64, degree: usize, epsilon: Option<f64>| {
        let span = (z[0] - z[z.len() - 1]).abs();
        let columns = degree + 1 + if epsilon.is_some() { 2 } else { 0 };
        let m = DMatrix::from_fn(z.len(), columns, |i, j| {
            let u = (z[i] - c) / span;
            if j <= degree {
                u.powi(j as i32)
            } else if j == degree + 1 {
                u.min(0.0).powi(2)
            } else {
                let (e, s) = (epsilon.unwrap(), -u);
                if s <= 0.0 {
                    0.0
                } else if s < e {
                    s * s / (2.0 * e)
                } else {
                    s - 0.5 * e
                }
            }
        });
        let y = DVector::from_column_slice(y);
        let solution = m.clone().svd(true, true).solve(&y, 1e-12).unwrap();
        (m * solution - y).norm_squared()
    };
    for case in ["biolever-soft", "maclever-mica-experiment"] {
        let (branch, a0) = branch_of(case);
        let instrument = SyntheticInstrument {
            amplitude_noise_fraction: 0.0,
            phase_noise_deg: 0.0,
            ..SyntheticInstrument::default()
        };
        let points = synthetic_approach(&branch, a0, &instrument);
        let z: Vec<f64> = points
            .iter()
            .map(|p| p.z_nm - instrument.z_offset_nm)
            .collect();
        let signals = [
            points
                .iter()
                .map(|p| p.amplitude_nm / (a0 * instrument.amplitude_calibration) / 0.003)
                .collect::<Vec<_>>(),
            points
                .iter()
                .map(|p| (p.phase_deg - instrument.phase_offset_deg) / 0.15)
                .collect::<Vec<_>>(),
        ];
        let grazings: Vec<(String, f64)> = branch
            .diagram
            .special_points
            .iter()
            .filter(|s| s.label.starts_with('G'))
            .map(|s| (s.label.clone(), s.z_nm))
            .collect();
        for (w, degree) in [(40usize, 2usize), (80, 2), (80, 4), (120, 2), (120, 4)] {
            let statistic = |g: usize| {
                let range = g + 1 - w..g + w + 1;
                let zs = &z[range.clone()];
                let c = 0.5 * (z[g] + z[g + 1]);
                KINK_ROUNDING
                    .iter()
                    .map(|&e| {
                        (0..2)
                            .map(|k| {
                                rss(zs, &signals[k][range.clone()], c, degree, None)
                                    - rss(zs, &signals[k][range.clone()], c, degree, Some(e))
                            })
                            .sum::<f64>()
                    })
                    .fold(0.0, f64::max)
            };
            let at_grazings: Vec<String> = grazings
                .iter()
                .filter(|(label, _)| label != "G1")
                .filter_map(|(label, zg)| {
                    let g = z.iter().position(|&zi| zi < *zg)? - 1;
                    (g + 1 >= w && g + w < z.len()).then(|| format!("{label} {:.0}", statistic(g)))
                })
                .collect();
            let smooth = (w..z.len() - w - 1)
                .step_by(3)
                .filter(|&g| {
                    grazings
                        .iter()
                        .all(|(_, zg)| *zg > z[g + 1 - w] + 0.3 || *zg < z[g + w] - 0.3)
                })
                .map(statistic)
                .fold(0.0, f64::max);
            println!(
                "{case}, window {w} rows per side, degree {degree}: at {}; smooth stretches at most {smooth:.1}",
                at_grazings.join(", ")
            );
        }
    }
}

/// The full studies whose results MODEL.md section 13.5 and the guide quote.
#[test]
#[ignore = "studies over 20 seeds and 200 smooth curves, several minutes"]
fn detection_studies() {
    for case in ["maclever-mica-experiment", "biolever-soft"] {
        println!("{case}: {:?} of 20", detection_counts(case, 0..20));
    }
    for (case, low, high) in [
        ("maclever-mica-experiment", "G2", "G1"),
        ("biolever-soft", "G3", "G2"),
    ] {
        let (spurious, _) = spurious_count(case, (low, high), 0..100);
        println!("{case}: spurious on {spurious} of 100 smooth curves");
    }
}
