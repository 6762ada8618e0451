//! `drumroll simulate` run as a user runs it: the real binary, its JSON checked against the
//! library's independent numbers, and bad input refused with a message that names the problem.

mod common;
use common::{drumroll, json_of};

#[test]
fn json_has_the_documented_fields_and_a_double_impact_at_z_8_5() {
    let orbit = json_of(&["simulate", "--case", "biolever-mica", "--z", "8.5"]);
    for key in [
        "z_nm",
        "amplitude_ratio",
        "phase_deg",
        "impacts_per_period",
        "multiplicity",
        "converged",
        "gap_minima",
        "impacts",
        "peak_force_nn",
        "mean_force_nn",
        "contact_time_periods",
        "impulse_nn_us",
    ] {
        assert!(orbit.get(key).is_some(), "missing `{key}`");
    }
    assert_eq!(orbit["z_nm"], 8.5);
    assert_eq!(orbit["converged"], true);
    assert_eq!(orbit["multiplicity"], 1);
    // Fig. 1(b): Z = 8.5 nm lies in the double-impact range of the Biolever on mica.
    assert_eq!(orbit["impacts_per_period"], 2.0);
    let impacts = orbit["impacts"].as_array().expect("list");
    assert_eq!(impacts.len(), 2);
    // Each impact's deepest gap is a negative gap minimum, and the peak force is Hertz's force
    // at the deepest one: F = (4/3) E* sqrt(R) (-d)^1.5 with E* of mica and the silicon tip.
    let deepest = orbit["gap_minima"]
        .as_array()
        .expect("list")
        .iter()
        .map(|m| m["gap_nm"].as_f64().expect("number"))
        .fold(f64::INFINITY, f64::min);
    let e_star = 1.0 / ((1.0 - 0.09) / 60.0 + (1.0 - 0.09) / 130.0);
    let hertz = 4.0 / 3.0 * e_star * 30f64.sqrt() * (-deepest).powf(1.5);
    let peak = orbit["peak_force_nn"].as_f64().expect("number");
    assert!(
        (peak - hertz).abs() < 1e-9 * hertz,
        "peak {peak} vs Hertz {hertz}"
    );
}

#[test]
fn amplitude_ratio_mode_lands_on_the_ratio() {
    let orbit = json_of(&[
        "simulate",
        "--case",
        "biolever-mica",
        "--amplitude-ratio",
        "0.9",
    ]);
    let ratio = orbit["amplitude_ratio"].as_f64().expect("number");
    assert!((ratio - 0.9).abs() < 1e-8, "A/A0 = {ratio}");
}

#[test]
fn cantilever_and_sample_files_replace_a_case() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures");
    let by_files = json_of(&[
        "simulate",
        "--cantilever",
        &format!("{root}/cantilevers/biolever.json"),
        "--sample",
        &format!("{root}/samples/mica.json"),
        "--a0",
        "10",
        "--z",
        "9",
    ]);
    let by_case = json_of(&["simulate", "--case", "biolever-mica", "--z", "9"]);
    assert_eq!(by_files["amplitude_ratio"], by_case["amplitude_ratio"]);
    assert_eq!(by_files["phase_deg"], by_case["phase_deg"]);
}

#[test]
fn bad_input_is_refused_with_a_message_naming_it() {
    let cases: [(&[&str], &str); 4] = [
        (
            &["simulate", "--case", "no-such-case", "--z", "5"],
            "unknown case `no-such-case`",
        ),
        (
            &[
                "simulate",
                "--case",
                "biolever-mica",
                "--amplitude-ratio",
                "1.5",
            ],
            "--amplitude-ratio 1.5: allowed (0, 1)",
        ),
        (
            &["simulate", "--case", "biolever-mica", "--z", "NaN"],
            "--z NaN: allowed [-100000, 100000] nm",
        ),
        (
            &[
                "simulate",
                "--case",
                "biolever-mica",
                "--a0",
                "-3",
                "--z",
                "5",
            ],
            "--a0 -3: allowed [0.001, 100000] nm",
        ),
    ];
    for (args, message) in cases {
        let output = drumroll().args(args).output().expect("runs");
        assert!(!output.status.success(), "{args:?} should fail");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(message), "{args:?}: stderr was {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    }
}

#[test]
fn plot_is_written_whole_or_not_at_all() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let svg = dir.path().join("orbit.svg");
    drumroll()
        .args([
            "simulate",
            "--case",
            "biolever-mica",
            "--z",
            "8.5",
            "--plot",
        ])
        .arg(&svg)
        .assert()
        .success();
    let text = std::fs::read_to_string(&svg).expect("written");
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    let bad = dir.path().join("orbit.jpg");
    drumroll()
        .args([
            "simulate",
            "--case",
            "biolever-mica",
            "--z",
            "8.5",
            "--plot",
        ])
        .arg(&bad)
        .assert()
        .failure();
    assert!(!bad.exists());
}

#[test]
fn next_to_a_fold_an_orbit_not_found_is_reported_with_its_fold() {
    // The MAClever on mica has a fold 3e-3 nm below first contact; 1e-8 nm beyond it the
    // orbit of the approach has vanished, and a cold start's transients linger at its ghost
    // for more than the 4000 periods searched (measured: Newton stops with a residual of
    // 1.2e-7, a multiplier at 0.999894, in 0.1 s). The summary must either give a converged
    // orbit or say that Z is next to a fold.
    let diagram = json_of(&["continue", "--case", "maclever-mica"]);
    let fold = diagram["special_points"]
        .as_array()
        .expect("list")
        .iter()
        .find(|s| s["label"] == "fold")
        .expect("a fold on the approach");
    let z = common::number(fold, "z_nm") - 1e-8;
    let output = drumroll()
        .args([
            "simulate",
            "--case",
            "maclever-mica",
            "--z",
            &format!("{z:.12}"),
        ])
        .output()
        .expect("runs");
    assert!(output.status.success());
    let summary = String::from_utf8_lossy(&output.stdout);
    let converged = summary.contains(": converged in ");
    let explained = summary.contains("NOT CONVERGED") && summary.contains("Z is next to a fold");
    assert!(converged || explained, "{summary}");
}
