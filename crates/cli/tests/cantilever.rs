//! `drumroll cantilever` run as a user runs it: the paper's modal numbers, a written file that
//! the other commands accept, the built-in fixtures reproduced from their tip mass ratios, and
//! refusals of bad input.

mod common;
use common::{drumroll, json_of, number};

use serde_json::Value;

fn second_mode(tip_mass_ratio: &str) -> Value {
    let table = json_of(&[
        "cantilever",
        "--tip-mass-ratio",
        tip_mass_ratio,
        "--modes",
        "2",
    ]);
    assert!(table.get("cantilever").is_none(), "table only");
    let modes = table["modes"].as_array().expect("modes");
    assert_eq!(modes.len(), 2);
    for key in [
        "stiffness_ratio",
        "frequency_ratio",
        "optical_sensitivity",
        "force_ratio_distributed",
        "force_ratio_tip",
    ] {
        assert_eq!(number(&modes[0], key), 1.0, "mode 1 `{key}`");
    }
    modes[1].clone()
}

#[test]
fn table_reproduces_the_papers_numbers() {
    // The paper (and MODEL.md section 7): k_2/k_1 = 39 at 0 and 74 at 0.1 (two digits,
    // +-0.5); chi = 3.47 at 0 and 5.26 at 0.16 (+-0.005); F_2/F_1 = -0.554 at 0 (+-0.0005)
    // and -1.54 at 0.16 (+-0.005).
    let bare = second_mode("0");
    assert!((number(&bare, "stiffness_ratio") - 39.0).abs() <= 0.5);
    assert!((number(&bare, "optical_sensitivity") - 3.47).abs() <= 0.005);
    assert!((number(&bare, "force_ratio_distributed") + 0.554).abs() <= 0.0005);
    assert_eq!(number(&bare, "force_ratio_tip"), 1.0);
    // The classical clamped-free eigenvalues: (b_2/b_1)^2 = (4.694091/1.875104)^2.
    let ratio = (4.694_091_132_974_175_f64 / 1.875_104_068_711_961).powi(2);
    assert!((number(&bare, "frequency_ratio") - ratio).abs() <= 1e-9 * ratio);
    assert!((number(&second_mode("0.1"), "stiffness_ratio") - 74.0).abs() <= 0.5);
    let mac = second_mode("0.16");
    assert!((number(&mac, "optical_sensitivity") - 5.26).abs() <= 0.005);
    assert!((number(&mac, "force_ratio_distributed") + 1.54).abs() <= 0.005);
}

#[test]
fn built_file_loads_and_drives_a_simulation() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("my-lever.json");
    let out = path.display().to_string();
    let report = json_of(&[
        "cantilever",
        "--k1",
        "0.1",
        "--f1",
        "3.5",
        "--f2",
        "28",
        "--q1",
        "1.6",
        "--q2",
        "4.3",
        "--q3",
        "7",
        "--tip-mass-ratio",
        "0.16",
        "--radius",
        "50",
        "--modes",
        "3",
        "--out",
        &out,
    ]);
    let cantilever = afm::fixtures::load_cantilever(&path).expect("loads and validates");
    assert_eq!(cantilever.name, "my-lever");
    assert_eq!(cantilever.modes.len(), 3);
    assert_eq!(cantilever.tip_radius_nm, 50.0);
    assert_eq!(cantilever.tip_mass_ratio, 0.16);
    let modes = report["modes"].as_array().expect("modes");
    for (mode, row) in cantilever.modes.iter().zip(modes) {
        // Stiffness k_1 times the table's ratio; chi and F_n/F_1 from the table.
        let k = 0.1 * number(row, "stiffness_ratio");
        assert!((mode.stiffness_n_per_m - k).abs() <= 1e-15 * k);
        assert_eq!(mode.optical_sensitivity, number(row, "optical_sensitivity"));
        assert_eq!(mode.force_ratio, number(row, "force_ratio_distributed"));
    }
    // Measured frequencies kept; the third from f_1 times the vacuum ratio.
    assert_eq!(cantilever.modes[1].frequency_khz, 28.0);
    assert_eq!(modes[1]["frequency_source"], "measured");
    let f3 = 3.5 * number(&modes[2], "frequency_ratio");
    assert!((cantilever.modes[2].frequency_khz - f3).abs() <= 1e-12 * f3);
    assert_eq!(modes[2]["frequency_source"], "f1 x vacuum ratio");
    assert_eq!(cantilever.modes[2].quality_factor, 7.0);
    // The JSON's cantilever is the file's.
    let printed: afm::Cantilever =
        serde_json::from_value(report["cantilever"].clone()).expect("cantilever");
    assert_eq!(printed, cantilever);
    // Another command accepts it.
    let orbit = json_of(&[
        "simulate",
        "--cantilever",
        &out,
        "--sample",
        "mica",
        "--a0",
        "20",
        "--z",
        "19",
    ]);
    assert_eq!(orbit["converged"], true);
    // Tip forcing puts F_n/F_1 = 1 (unit tip deflection normalisation).
    let tip = json_of(&[
        "cantilever",
        "--k1",
        "0.1",
        "--f1",
        "3.5",
        "--quality-factors",
        "1.6,4.3",
        "--radius",
        "50",
        "--tip-mass-ratio",
        "0.16",
        "--drive",
        "tip",
    ]);
    assert_eq!(tip["cantilever"]["modes"][1]["force_ratio"], 1.0);
}

/// The built-in Biolever and MAClever against the builder fed with their measured values and
/// tip mass ratios. The fixtures hold the paper's rounded values: k_2 to two digits (1.4 and
/// 10 N/m: +-0.05/1.4 = 3.6% and +-0.5/10 = 5%), chi to three (+-0.005), F_2/F_1 to three
/// (+-0.0005 and +-0.005).
#[test]
fn fixtures_agree_with_the_builder() {
    for (name, k2_rounding, force_rounding) in
        [("biolever", 0.05, 0.0005), ("maclever", 0.5, 0.005)]
    {
        let fixture = afm::builtin_cantilever(name).expect("fixture");
        let [first, second] = [&fixture.modes[0], &fixture.modes[1]];
        let args: Vec<String> = vec![
            "cantilever".into(),
            "--k1".into(),
            first.stiffness_n_per_m.to_string(),
            "--f1".into(),
            first.frequency_khz.to_string(),
            "--f2".into(),
            second.frequency_khz.to_string(),
            "--q1".into(),
            first.quality_factor.to_string(),
            "--q2".into(),
            second.quality_factor.to_string(),
            "--radius".into(),
            fixture.tip_radius_nm.to_string(),
            "--tip-mass-ratio".into(),
            fixture.tip_mass_ratio.to_string(),
        ];
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let built: afm::Cantilever =
            serde_json::from_value(json_of(&args)["cantilever"].clone()).expect("cantilever");
        let mode = &built.modes[1];
        assert!(
            (mode.stiffness_n_per_m - second.stiffness_n_per_m).abs() <= k2_rounding,
            "{name}: k_2 {} vs {}",
            mode.stiffness_n_per_m,
            second.stiffness_n_per_m
        );
        assert!((mode.optical_sensitivity - second.optical_sensitivity).abs() <= 0.005);
        assert!((mode.force_ratio - second.force_ratio).abs() <= force_rounding);
        assert_eq!(mode.frequency_khz, second.frequency_khz);
        assert_eq!(mode.quality_factor, second.quality_factor);
        assert_eq!(built.modes[0], *first);
    }
}

#[test]
fn bad_input_is_refused_with_a_message_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text_out = dir.path().join("lever.txt").display().to_string();
    let base = [
        "cantilever",
        "--k1",
        "0.1",
        "--f1",
        "3.5",
        "--radius",
        "50",
        "--tip-mass-ratio",
        "0.16",
    ];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            [&base[..], &["--q1", "1.6"]].concat(),
            "to build a cantilever, missing: --q2 (",
        ),
        (
            [&base[..], &["--q1", "1.6", "--q2", "4", "--q3", "5"]].concat(),
            "--q3 is given but --modes is 2",
        ),
        (
            [&base[..], &["--q1", "1.6", "--q2", "-4"]].concat(),
            "--q2 -4: allowed [0.001, 1000000]",
        ),
        (
            [&base[..], &["--q1", "1.6", "--q2", "4", "--f2", "3"]].concat(),
            "must increase",
        ),
        (
            [&base[..], &["--q1", "1.6", "--q2", "4", "--out", &text_out]].concat(),
            "allowed: a file name ending in .json",
        ),
        (
            vec!["cantilever", "--tip-mass-ratio", "0", "--k1", "-1"],
            "--k1 -1: allowed [1e-6, 1000000] N/m",
        ),
        (
            vec!["cantilever", "--tip-mass-ratio", "0", "--radius", "30"],
            "to build a cantilever, missing: --k1 (N/m), --f1 (kHz), --q1, --q2 (",
        ),
        (
            vec!["cantilever", "--tip-mass-ratio", "-0.1"],
            "--tip-mass-ratio -0.1: allowed [0, 1000]",
        ),
        (
            vec!["cantilever", "--tip-mass-ratio", "0", "--modes", "51"],
            "--modes 51: allowed [1, 50]",
        ),
    ];
    for (args, message) in cases {
        let output = drumroll().args(&args).output().expect("runs");
        assert!(!output.status.success(), "{args:?} should fail");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(message), "{args:?}: stderr was {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    }
    assert!(!dir.path().join("lever.txt").exists());
}
