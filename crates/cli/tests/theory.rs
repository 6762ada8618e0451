//! `drumroll theory` run as a user runs it: its JSON against closed forms typed in here, against
//! `drumroll simulate` (an independent path to the simulated impulse), and its refusals.

mod common;
use common::{drumroll, json_of, number};

use std::f64::consts::PI;

#[test]
fn json_has_the_documented_keys_and_the_papers_closed_forms() {
    // Default: A/A0 = 0.95, the paper's single-impact example.
    let theory = json_of(&["theory", "--case", "biolever-mica"]);
    for key in [
        "lambda_1",
        "lambda_2",
        "lambda_3",
        "impulse_eq3_nn_us",
        "q2_initial_amplitude_nm",
        "q2_decay_time_us",
        "q2_decay_over_period",
        "q1_phase_deg",
        "simulated",
        "relative_error",
    ] {
        assert!(theory.get(key).is_some(), "missing `{key}`");
    }
    assert!((number(&theory, "amplitude_ratio") - 0.95).abs() < 1e-8);
    assert_eq!(theory["phase_used"], "q1_first_harmonic");
    assert_eq!(theory["drive_at_fundamental"], true);
    assert_eq!(theory["warnings"], serde_json::json!([]));
    assert_eq!(theory["assumption_failures"], serde_json::json!([]));
    assert_eq!(theory["inputs"]["command"], "theory");
    // The paper's formulas typed in for the Biolever (k_1 = 0.036 N/m, Q_1 = 1.2, f_1 = 9.3
    // kHz; k_2 = 1.4 N/m, Q_2 = 2, f_2 = 72 kHz), with a_0 and phi as the command reports them.
    let (w1, w2) = (2.0 * PI * 9.3e-3, 2.0 * PI * 72e-3);
    let w2d = w2 * (1.0f64 - 1.0 / 16.0).sqrt();
    let lambda_1 = w2 * w2 * 0.036 / (w1 * w2d * 1.4 * 1.2);
    assert!((number(&theory, "lambda_1") - lambda_1).abs() <= 1e-12 * lambda_1);
    assert!((number(&theory, "lambda_2") - w2d / w1).abs() <= 1e-12 * w2d / w1);
    assert!((number(&theory, "lambda_3") - 2.0 * w1 / w2).abs() <= 1e-14);
    let a0 = number(&theory, "free_q1_amplitude_nm");
    let phi = number(&theory, "q1_phase_deg").to_radians();
    let impulse = PI * 0.036 * a0 * phi.cos() / (1.2 * w1);
    assert!((number(&theory, "impulse_eq3_nn_us") - impulse).abs() <= 1e-12 * impulse);
    let amplitude = a0 * PI * w2 * w2 * 0.036 * phi.cos() / (1.2 * w1 * w2d * 1.4);
    assert!((number(&theory, "q2_initial_amplitude_nm") - amplitude).abs() <= 1e-12 * amplitude);
    let tau = 2.0 * 2.0 / w2;
    assert!((number(&theory, "q2_decay_time_us") - tau).abs() <= 1e-12 * tau);
    let decay = (-2.0 * PI / w1 / tau).exp();
    assert!((number(&theory, "q2_decay_over_period") - decay).abs() <= 1e-12 * decay);
    assert_eq!(theory["ring_down_criterion"]["holds"], true);

    // The simulated impulse is the one `drumroll simulate` reports at the same A/A0.
    let orbit = json_of(&[
        "simulate",
        "--case",
        "biolever-mica",
        "--amplitude-ratio",
        "0.95",
    ]);
    let simulated = number(&theory["simulated"], "impulse_nn_us");
    let observed = number(&orbit, "impulse_nn_us");
    assert!((simulated - observed).abs() <= 1e-9 * observed);
    // Eq. 3 neglects int F (1 + cos theta) >= 0, at most 1 - cos(theta_bar_max) of the impulse
    // (see crates/afm/tests/theory.rs).
    let impact = &theory["simulated"]["impacts"][0];
    let bound = 1.0 - number(impact, "largest_theta_bar_deg").to_radians().cos();
    let error = number(&theory["relative_error"], "impulse");
    assert!(
        error <= 1e-8 && error >= -bound - 1e-8,
        "{error} vs {bound}"
    );
}

#[test]
fn lambda_1_of_biolever_over_maclever_is_the_papers_3_4() {
    let bio = json_of(&["theory", "--case", "biolever-mica", "--z", "9.5"]);
    let mac = json_of(&["theory", "--case", "maclever-mica", "--z", "19.5"]);
    // The paper: 3.4, two significant digits.
    let ratio = number(&bio, "lambda_1") / number(&mac, "lambda_1");
    assert!((ratio - 3.4).abs() <= 0.05, "{ratio}");
}

#[test]
fn eq3_brackets_the_simulated_impulse_in_the_single_impact_regime() {
    for z in ["9.9", "9.7", "9.4"] {
        let theory = json_of(&["theory", "--case", "biolever-mica", "--z", z]);
        let simulated = &theory["simulated"];
        assert_eq!(
            simulated["impacts_per_period"].as_f64(),
            Some(1.0),
            "Z = {z}"
        );
        assert!(
            simulated["impacts_per_period"].is_f64(),
            "a float like simulate's"
        );
        let impact = &theory["simulated"]["impacts"][0];
        let bound = 1.0 - number(impact, "largest_theta_bar_deg").to_radians().cos();
        let error = number(&theory["relative_error"], "impulse");
        assert!(
            error <= 1e-8 && error >= -bound - 1e-8,
            "Z = {z}: {error} vs {bound}"
        );
    }
}

#[test]
fn off_resonance_drive_is_flagged() {
    let theory = json_of(&[
        "theory",
        "--case",
        "maclever-mica-experiment",
        "--z",
        "19.5",
    ]);
    assert_eq!(theory["drive_at_fundamental"], false);
    assert_eq!(theory["assumption_failures"][0], "drive_off_fundamental");
    let warning = theory["warnings"][0].as_str().expect("a warning");
    assert!(warning.contains("assume w = w_1"), "{warning}");
    let text = drumroll()
        .args([
            "theory",
            "--case",
            "maclever-mica-experiment",
            "--z",
            "19.5",
        ])
        .output()
        .expect("runs");
    assert!(text.status.success());
    assert!(String::from_utf8_lossy(&text.stdout).contains("WARNING: the drive (3.3000 kHz)"));
}

#[test]
fn bad_input_is_refused_with_a_message_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let single = dir.path().join("single.json");
    std::fs::write(
        &single,
        r#"{"name": "single", "tip_radius_nm": 30, "tip_mass_ratio": 0,
            "modes": [{"stiffness_n_per_m": 0.036, "frequency_khz": 9.3, "quality_factor": 1.2,
                       "optical_sensitivity": 1, "force_ratio": 1}]}"#,
    )
    .expect("write");
    let single = single.display().to_string();
    let cases: [(&[&str], &str); 4] = [
        (
            &[
                "theory",
                "--case",
                "biolever-mica",
                "--amplitude-ratio",
                "1.5",
            ],
            "--amplitude-ratio 1.5: allowed (0, 1)",
        ),
        (
            &["theory", "--case", "biolever-mica", "--z", "NaN"],
            "--z NaN: allowed [-100000, 100000] nm",
        ),
        (
            &[
                "theory",
                "--case",
                "biolever-mica",
                "--z",
                "9",
                "--amplitude-ratio",
                "0.9",
            ],
            "cannot be used with",
        ),
        (
            &[
                "theory",
                "--cantilever",
                &single,
                "--sample",
                "mica",
                "--a0",
                "10",
                "--z",
                "9",
            ],
            "at least two eigenmodes",
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

/// Issue 21, defect 2: below the sample surface (`--z -5`, the tip resting 5 nm inside the
/// sample) and above first contact the theory's assumptions fail: every prediction and
/// relative error is `null`, no negative decay time appears anywhere, and the reasons are in
/// `warnings`, on stderr and in the table.
#[test]
fn where_the_assumptions_fail_no_number_looks_valid() {
    for (z, kind) in [("-5", "separation_below_surface"), ("11", "no_contact")] {
        let output = drumroll()
            .args(["theory", "--case", "biolever-mica", "--z", z, "--json"])
            .output()
            .expect("runs");
        assert!(output.status.success(), "Z = {z}");
        let theory: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
        let kinds = theory["assumption_failures"].as_array().expect("an array");
        assert!(kinds.iter().any(|k| k == kind), "Z = {z}: {kinds:?}");
        for key in [
            "impulse_eq3_nn_us",
            "q2_initial_amplitude_nm",
            "q2_decay_time_us",
            "q2_decay_over_period",
            "impulse_eq3_from_u_phase_nn_us",
        ] {
            assert!(theory[key].is_null(), "Z = {z}: `{key}` = {}", theory[key]);
        }
        for error in theory["relative_error"]
            .as_object()
            .expect("object")
            .values()
        {
            assert!(error.is_null(), "Z = {z}: a relative error {error}");
        }
        if let Some(time) = theory["simulated"]["ringing"]["effective_decay_time_us"].as_f64() {
            assert!(time > 0.0, "Z = {z}: decay time {time}");
        }
        let warnings = theory["warnings"].as_array().expect("warnings");
        assert_eq!(warnings.len(), kinds.len());
        let stderr = String::from_utf8_lossy(&output.stderr);
        for warning in warnings {
            let warning = warning.as_str().expect("text");
            assert!(
                stderr.contains(warning),
                "Z = {z}: not on stderr: {warning}"
            );
        }
        let table = drumroll()
            .args(["theory", "--case", "biolever-mica", "--z", z])
            .output()
            .expect("runs");
        let text = String::from_utf8_lossy(&table.stdout);
        assert!(text.contains("WARNING: "), "Z = {z}: {text}");
        assert!(
            !text.contains("-243"),
            "Z = {z}: the negative decay time is printed"
        );
    }
    // Z = -5: the ringing grows between main impacts, so it has no decay time at all.
    let deep = json_of(&["theory", "--case", "biolever-mica", "--z", "-5"]);
    assert!(deep["simulated"]["ringing"]["effective_decay_time_us"].is_null());
}

/// Eqs. 3-4 assume force-free flight between impacts: the theory warns where the sample pulls
/// beyond `d = 0`, whether by a force outside contact (the hydration force) or by a contact
/// that stays attached up to its release gap (JKR's pull-off gap, named in nm), and not for
/// Hertz.
#[test]
fn forces_beyond_contact_are_warned_of() {
    let warnings = |case: &str| -> Vec<String> {
        let theory = json_of(&["theory", "--case", case, "--amplitude-ratio", "0.9"]);
        theory["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .map(|w| w.as_str().expect("text").to_string())
            .collect()
    };
    let outside = warnings("biolever-mica-hydration");
    assert!(
        outside
            .iter()
            .any(|w| w.contains("acts outside contact") && w.contains("hydration")),
        "{outside:?}"
    );
    // JKR's pull-off gap `d_po = (3/4) (pi^2 W^2 R / E*^2)^{1/3}` (MODEL.md section 9) for
    // `adhesive-soft` (W = 0.5 mJ/m^2 = 5e-4 nN/nm, E = 1 GPa, nu = 0.3) under the Biolever's tip
    // (R = 30 nm, 130 GPa, nu = 0.3): `1/E* = 0.91/1 + 0.91/130` per GPa.
    let reduced: f64 = 1.0 / (0.91 / 1.0 + 0.91 / 130.0);
    let pull_off =
        0.75 * (std::f64::consts::PI.powi(2) * 5e-4f64.powi(2) * 30.0 / reduced.powi(2)).cbrt();
    let attached = warnings("biolever-adhesive");
    let gap: f64 = attached
        .iter()
        .find(|w| w.contains("stays attached"))
        .and_then(|w| w.split("release gap ").nth(1))
        .and_then(|rest| rest.split(' ').next())
        .and_then(|number| number.parse().ok())
        .unwrap_or_else(|| panic!("no release gap in {attached:?}"));
    assert!((gap - pull_off).abs() < 1e-9, "{gap} vs {pull_off}");
    let hertz = warnings("biolever-mica");
    assert!(
        hertz
            .iter()
            .all(|w| !w.contains("outside contact") && !w.contains("attached")),
        "{hertz:?}"
    );
}
