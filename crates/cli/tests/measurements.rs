//! `drumroll detect` and `drumroll fit` on measured curves (MODEL.md section 13): bad files are
//! errors naming the file, line and column; bad rows are reported with their line numbers;
//! the synthetic fixture's transitions lie where the model's grazing points are.

mod common;
use common::drumroll;

use std::path::PathBuf;

/// Run `drumroll ARGS`; (exit code, stdout, stderr).
fn run(args: &[&str]) -> (i32, String, String) {
    let output = drumroll().args(args).output().expect("runs");
    (
        output.status.code().expect("an exit code"),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

fn fixture(name: &str) -> String {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/measurements");
    root.join(name).display().to_string()
}

/// A file in `dir` holding `text`.
fn file(dir: &tempfile::TempDir, name: &str, text: &str) -> String {
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// A smooth synthetic curve: 100 free rows at 10 nm, then A = Z for Z below 10 (a hard
/// sample, A/A0 down to 0.4), phase 90 deg, written with `header` and `separator`.
fn curve(header: &str, separator: &str) -> String {
    let mut text = format!("{header}\n");
    for i in 0..200 {
        let z = 14.0 - 0.05 * i as f64;
        text.push_str(&format!("{z}{separator}{}{separator}90\n", z.min(10.0)));
    }
    text
}

#[test]
fn bad_files_name_the_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let missing = file(&dir, "missing.csv", &curve("z_nm,amp,phase_deg", ","));
    let (code, _, stderr) = run(&["detect", "--data", &missing]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("missing.csv line 1") && stderr.contains("amplitude_nm"),
        "{stderr}"
    );
    let few = file(
        &dir,
        "few.csv",
        "z_nm,amplitude_nm,phase_deg\n1,1,1\n2,1,1\n",
    );
    let (code, _, stderr) = run(&["detect", "--data", &few]);
    assert_eq!(code, 1);
    assert!(stderr.contains("at least 50"), "{stderr}");
    let good = file(
        &dir,
        "good.tsv",
        &curve("z_nm\tamplitude_nm\tphase_deg", "\t"),
    );
    let (code, _, stderr) = run(&["detect", "--data", &good, "--amplitude-unit", "m"]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("A0") && stderr.contains("--amplitude-unit"),
        "{stderr}"
    );
    let (code, _, stderr) = run(&["detect", "--data", &good, "--amplitude-unit", "V"]);
    assert_eq!(code, 1);
    assert!(stderr.contains("--invols"), "{stderr}");
    let (code, _, stderr) = run(&["detect", "--data", &good, "--amplitude-unit", "furlong"]);
    assert_eq!(code, 1);
    assert!(stderr.contains("nm, um, m, V"), "{stderr}");
    // No free part: the amplitude falls from the first row on.
    let mut sloped = String::from("z_nm,amplitude_nm,phase_deg\n");
    for i in 0..200 {
        let z = 10.0 - 0.04 * i as f64;
        sloped.push_str(&format!("{z},{z},90\n"));
    }
    let sloped = file(&dir, "sloped.csv", &sloped);
    let (code, _, stderr) = run(&["detect", "--data", &sloped]);
    assert_eq!(code, 1);
    assert!(stderr.contains("no free part"), "{stderr}");
    let (code, _, stderr) = run(&[
        "detect",
        "--data",
        &dir.path().join("absent.csv").display().to_string(),
    ]);
    assert_eq!(code, 1);
    assert!(stderr.contains("absent.csv"), "{stderr}");
    assert!(!stderr.contains("panicked"));
}

#[test]
fn bad_rows_are_reported_with_line_numbers_and_the_curve_is_split() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = curve("z_nm,amplitude_nm,phase_deg", ",");
    // Line 202 (after the header and 200 rows): NaN; then a retract back up of 150 rows with a
    // duplicate Z at line 205.
    text.push_str("4.0,NaN,90\n");
    for i in 0..150 {
        let z = 4.0 + 0.05 * i as f64;
        text.push_str(&format!("{z},{},91\n", z.min(10.0)));
        if i == 1 {
            text.push_str(&format!("{z},{},91\n", z.min(10.0)));
        }
    }
    let path = file(&dir, "both.csv", &text);
    let (code, stdout, stderr) = run(&["detect", "--data", &path, "--json"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("line 202") && stderr.contains("not a finite number"),
        "{stderr}"
    );
    assert!(
        stderr.contains("line 205") && stderr.contains("duplicate"),
        "{stderr}"
    );
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    // The turning row (Z = 4.0, the lowest) ends the approach.
    assert_eq!(json["rows"], 201);
    assert_eq!(json["bad_rows"].as_array().unwrap().len(), 2);
    // A0 from the 80 free rows at 10 nm: exactly 10.
    assert!((json["a0_nm"].as_f64().unwrap() - 10.0).abs() < 1e-12);
}

/// The synthetic fixture (made by the command in its first lines): its G2 is at data
/// Z = 7.9588 + 12.5 nm (the model's G2 plus the instrument's offset, from
/// `drumroll continue --case maclever-mica-experiment`); `detect` finds a kink there within
/// 3 of its sigmas, and no other transition but G1's.
#[test]
fn the_fixture_shows_g1_and_g2() {
    let (code, stdout, stderr) = run(&[
        "detect",
        "--data",
        &fixture("maclever-mica-synthetic.csv"),
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let transitions = json["transitions"].as_array().unwrap();
    assert_eq!(transitions.len(), 2, "{transitions:?}");
    let g2 = 7.9588 + 12.5;
    let t = &transitions[1];
    let sigma = t["z_uncertainty_nm"].as_f64().unwrap();
    assert!(
        (t["z_nm"].as_f64().unwrap() - g2).abs() <= 3.0 * sigma,
        "{t}"
    );
    assert_eq!(t["kind"], "kink");
}

#[test]
fn fit_refuses_bad_parameter_lists() {
    let data = fixture("maclever-mica-synthetic.csv");
    for (list, message) in [
        ("z-offset,bogus", "bogus"),
        ("a0", "\"a0\""),
        ("z-offset,z-offset", "each once"),
    ] {
        let (code, _, stderr) = run(&[
            "fit",
            "--data",
            &data,
            "--case",
            "maclever-mica-experiment",
            "--fit",
            list,
        ]);
        assert_eq!(code, 1, "{list}");
        assert!(stderr.contains(message), "{list}: {stderr}");
    }
}

/// The fit's Jacobian columns, the detection of the transitions alongside it, and inside the
/// detection the candidates' scores and the kinks' onsets and bootstrap replicates run in
/// parallel (rayon) with the serial result: the soft fixture's detection (three transitions,
/// kinks among them), a short fit (one evaluation's patience; the calibration, fitted as the
/// model's `A0`, whose column is the central difference of two followed branches, and the
/// reported `A0`) print the same bytes on one thread and on two (`RAYON_NUM_THREADS`), and so
/// does a fit whose trial steps leave the tip radius's range (rejected, and counted in the
/// warnings on stderr) and which ends at that range's bound.
#[test]
fn detect_and_fit_are_the_same_on_one_thread_and_on_two() {
    let soft = fixture("biolever-soft-synthetic.csv");
    let maclever = fixture("maclever-mica-synthetic.csv");
    let fits: [&[&str]; 3] = [
        &["detect", "--data", &soft, "--json"],
        &[
            "fit",
            "--data",
            &soft,
            "--case",
            "biolever-soft",
            "--fit",
            "amplitude-calibration",
            "--max-evaluations",
            "1",
            "--json",
        ],
        &[
            "fit",
            "--data",
            &maclever,
            "--case",
            "maclever-mica",
            "--fit",
            "amplitude-calibration,tip-radius",
            "--json",
        ],
    ];
    let bound = drumroll()
        .args(fits[2])
        .env("RAYON_NUM_THREADS", "2")
        .output()
        .expect("runs");
    let warnings = String::from_utf8_lossy(&bound.stderr);
    assert!(
        warnings.contains("tip_radius_nm: stopped at the bound of its range")
            && warnings.contains("were rejected (the first: fit: field `tip-radius`"),
        "{warnings}"
    );
    for args in &fits {
        let on = |threads: &str| {
            let output = drumroll()
                .args(*args)
                .env("RAYON_NUM_THREADS", threads)
                .output()
                .expect("runs");
            (output.status.code(), output.stdout, output.stderr)
        };
        let one = on("1");
        assert_eq!(one.0, Some(0), "{args:?}");
        let two = on("2");
        assert!(one == two, "{args:?}: 1 and 2 threads differ");
    }
}
