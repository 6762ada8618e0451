//! Issue 21, defect 5: every bad input is an error naming the option (or the file and field)
//! and its allowed range, with the likely unit mistake; valid but implausible values are
//! warned about; runs that stop early say so and exit with status 3; unwritable outputs are
//! found before computing; `--help` states the ranges and the exit statuses.

mod common;
use common::drumroll;

use std::path::Path;

/// Run `drumroll ARGS`; (exit code, stdout, stderr).
fn run(args: &[&str]) -> (i32, String, String) {
    let output = drumroll().args(args).output().expect("runs");
    (
        output.status.code().expect("an exit code"),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// Require `args` to fail with status 1 and every one of `messages` on stderr.
fn refused(args: &[&str], messages: &[&str]) -> String {
    let (code, _, stderr) = run(args);
    assert_eq!(code, 1, "{args:?}: {stderr}");
    for message in messages {
        assert!(stderr.contains(message), "{args:?}: stderr was {stderr}");
    }
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    stderr
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    path.display().to_string()
}

#[test]
fn values_in_the_wrong_unit_are_refused_naming_the_unit_mistake() {
    // A0 in metres: refused for A0 itself, no longer an error about max_step.
    let stderr = refused(
        &["simulate", "--a0", "1e-8", "--z", "5"],
        &[
            "--a0 1e-8: allowed [0.001, 100000] nm",
            "looks like a value in m: 1e-8 m = 10 nm",
        ],
    );
    assert!(!stderr.contains("max_step"), "{stderr}");
    // A tip radius of 20e-9 nm in a cantilever file: the file, the field, the range, metres.
    let dir = tempfile::tempdir().expect("temp dir");
    let lever = write(
        dir.path(),
        "lever.json",
        r#"{"name": "lever", "tip_radius_nm": 20e-9, "tip_mass_ratio": 0,
            "modes": [{"stiffness_n_per_m": 0.036, "frequency_khz": 9.3, "quality_factor": 1.2,
                       "optical_sensitivity": 1, "force_ratio": 1}]}"#,
    );
    refused(
        &[
            "simulate",
            "--cantilever",
            &lever,
            "--sample",
            "mica",
            "--a0",
            "10",
            "--z",
            "5",
        ],
        &[
            "lever.json",
            "`tip_radius_nm` = 2e-8",
            "[0.1, 100000] nm",
            "2e-8 m = 20 nm",
        ],
    );
    // A sample modulus in Pa.
    let sample = write(
        dir.path(),
        "hard.json",
        r#"{"name": "hard", "youngs_modulus_gpa": 60e9}"#,
    );
    refused(
        &[
            "simulate",
            "--cantilever",
            "biolever",
            "--sample",
            &sample,
            "--a0",
            "10",
            "--z",
            "5",
        ],
        &[
            "hard.json",
            "`youngs_modulus_gpa` = 6e10",
            "6e10 Pa = 60 GPa",
        ],
    );
}

#[test]
fn the_drive_frequency_range_is_the_same_in_every_command() {
    // 3500 kHz on the MAClever (f_1 = 3.5 kHz, f_2 = 28 kHz): above 100 f_2, and 3500 Hz is f_1.
    let expected = "--drive-frequency 3500: allowed [0.035, 2800] kHz";
    let mut messages = Vec::new();
    for command in [
        &["simulate", "--z", "19"][..],
        &["continue"][..],
        &["approach"][..],
        &["theory", "--z", "19"][..],
    ] {
        let mut args = command.to_vec();
        args.extend(["--case", "maclever-mica", "--drive-frequency", "3500"]);
        let stderr = refused(&args, &[expected, "3500 Hz = 3.5 kHz"]);
        messages.push(stderr);
    }
    assert!(
        messages.windows(2).all(|pair| pair[0] == pair[1]),
        "{messages:?}"
    );
    // Allowed but over ten times away from every mode: a warning that names it.
    let (code, _, stderr) = run(&[
        "simulate",
        "--case",
        "biolever-mica",
        "--drive-frequency",
        "3500",
        "--z",
        "9",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("warning: --drive-frequency 3500 kHz is more than ten times away"),
        "{stderr}"
    );
}

/// A case file whose own drive lies outside its cantilever's range (the MAClever: f_1/100 to
/// 100 f_2 = [0.035, 2800] kHz) is refused naming the file and the field, not the command line;
/// a `--drive-frequency` inside the range replaces it.
#[test]
fn a_case_files_drive_beyond_its_cantilever_is_blamed_on_the_file() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let case = write(
        directory.path(),
        "fast.json",
        r#"{"name": "fast", "cantilever": "maclever", "sample": "mica",
            "free_amplitude_nm": 20, "drive_frequency_khz": 5789}"#,
    );
    let stderr = refused(
        &["simulate", "--case", &case, "--z", "19"],
        &[
            &format!("{case}: field `drive_frequency_khz` = 5789"),
            "allowed: [0.035000, 2800.000000] kHz",
        ],
    );
    assert!(!stderr.contains("the command line"), "{stderr}");
    let (code, _, stderr) = run(&[
        "simulate",
        "--case",
        &case,
        "--drive-frequency",
        "3.5",
        "--z",
        "19",
    ]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn an_implausible_value_is_warned_about_with_its_likely_unit() {
    // 0.01 nm is allowed, but 0.01 um = 10 nm is the usual amplitude.
    let (code, _, stderr) = run(&["simulate", "--a0", "0.01", "--z", "0.005"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("warning: --a0 0.01 is unusual for AFM")
            && stderr.contains("0.01 um = 10 nm"),
        "{stderr}"
    );
    // The same for a file's field: a sample of 500 Pa is allowed, softer than AFM samples are.
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = write(
        dir.path(),
        "gel.json",
        r#"{"name": "gel", "youngs_modulus_gpa": 5e-7}"#,
    );
    let (code, _, stderr) = run(&[
        "simulate",
        "--cantilever",
        "biolever",
        "--sample",
        &sample,
        "--a0",
        "10",
        "--z",
        "9.5",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("gel.json: field `youngs_modulus_gpa` = 5e-7 is unusual for AFM")
            && stderr.contains("typical 1e-6 to 1500 GPa"),
        "{stderr}"
    );
}

#[test]
fn every_option_is_checked_in_one_style() {
    // clap used to refuse `-1` as an unknown flag while `--floor -19` reached the model.
    refused(
        &["continue", "--min-amplitude-ratio", "-1"],
        &["--min-amplitude-ratio -1: allowed [0, 1)"],
    );
    refused(
        &["continue", "--floor", "-19"],
        &["--floor -19: allowed [-10, 10.01"],
    );
    refused(
        &["approach", "--every", "-1"],
        &["--every -1: allowed [1, 100000000]"],
    );
    refused(
        &["continue", "--max-points", "1"],
        &["--max-points 1: allowed [2, 10000000]"],
    );
    refused(
        &["simulate", "--z", "-11"],
        &["--z -11: allowed [-10, 100000] nm"],
    );
}

#[test]
fn the_cantilever_builder_names_only_the_missing_option() {
    let stderr = refused(
        &[
            "cantilever",
            "--tip-mass-ratio",
            "0",
            "--k1",
            "0.036",
            "--f1",
            "9.3",
            "--q1",
            "1.2",
            "--q2",
            "2",
        ],
        &["missing: --radius (nm) ("],
    );
    for given in ["--k1", "--f1", "--q1", "--q2"] {
        assert!(!stderr.contains(given), "{given} is given: {stderr}");
    }
}

#[test]
fn a_branch_cut_short_by_the_point_cap_says_so_and_exits_3() {
    let (code, stdout, stderr) = run(&[
        "continue",
        "--max-step",
        "1e-6",
        "--max-points",
        "30",
        "--json",
    ]);
    assert_eq!(code, 3, "{stderr}");
    assert!(
        stderr.contains("stopped before its requested end")
            && stderr.contains("maximum number of points")
            && stderr.contains("--max-points (now 30)"),
        "{stderr}"
    );
    let json: serde_json::Value = serde_json::from_str(&stdout).expect("the JSON is printed");
    assert_eq!(json["completed"], false);
    assert_eq!(json["points"].as_array().expect("points").len(), 30);
    assert!(json["stop"]
        .as_str()
        .expect("stop")
        .contains("maximum number of points"));
    assert_eq!(json["inputs"]["options"]["max_points"], 30);
    // A branch that reaches its floor completes with status 0.
    let (code, stdout, _) = run(&["continue", "--floor", "9.9", "--json"]);
    assert_eq!(code, 0);
    let json: serde_json::Value = serde_json::from_str(&stdout).expect("JSON");
    assert_eq!(json["completed"], true);
}

#[test]
fn unwritable_outputs_are_found_before_computing_and_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let missing = dir.path().join("no-such-directory");
    let plot = missing.join("figure.svg").display().to_string();
    let csv = missing.join("branch.csv").display().to_string();
    let out = missing.join("records.csv").display().to_string();
    for (args, path) in [
        (vec!["simulate", "--z", "9", "--plot", &plot], &plot),
        (vec!["continue", "--floor", "9.5", "--csv", &csv], &csv),
        (vec!["continue", "--floor", "9.5", "--plot", &plot], &plot),
        (
            vec![
                "approach", "--from", "9.9", "--to", "9.89", "--rate", "10", "--out", &out,
            ],
            &out,
        ),
    ] {
        let (code, stdout, stderr) = run(&args);
        assert_eq!(code, 1, "{args:?}");
        assert!(
            stderr.contains(&format!("{path}: cannot write there")),
            "{args:?}: {stderr}"
        );
        assert!(!stderr.contains(".partial"), "{args:?}: {stderr}");
        // Nothing was computed: no table, no record.
        assert!(stdout.is_empty(), "{args:?} computed first: {stdout}");
    }
    assert!(!missing.exists());
}

#[test]
fn causes_are_printed_once() {
    let dir = tempfile::tempdir().expect("temp dir");
    let case = write(
        dir.path(),
        "broken.json",
        r#"{"name": "broken", "cantilever": 3}"#,
    );
    let (code, _, stderr) = run(&["simulate", "--case", &case, "--z", "5"]);
    assert_eq!(code, 1);
    let lines: Vec<&str> = stderr.lines().collect();
    for pair in lines.windows(2) {
        let cause = pair[1].trim_start().trim_start_matches("caused by: ");
        assert!(!pair[0].contains(cause), "repeated: {stderr}");
    }
}

#[test]
fn help_states_every_range_and_the_exit_statuses() {
    let (_, help, _) = run(&["--help"]);
    assert!(help.contains("Exit status: 0 success; 1 error"), "{help}");
    assert!(
        help.contains("3 the run stopped before its requested end"),
        "{help}"
    );
    let squash = |text: &str| text.split_whitespace().collect::<Vec<_>>().join(" ");
    let helps: Vec<String> = ["simulate", "continue", "approach", "theory", "cantilever"]
        .iter()
        .map(|command| squash(&run(&[command, "--help"]).1))
        .collect();
    // An option may have one range per command (--harmonics: [1, 1000] for orbits and
    // diagrams, [1, 20] for the lock-in's readings): every help showing the option states one
    // of its ranges, and every range is stated by some help.
    let table = drumroll::option_ranges::TABLE;
    for range in table {
        if range.option == "--z" {
            continue; // stated per model, [-A0, 100000] nm
        }
        let with_option: Vec<&String> = helps
            .iter()
            .filter(|help| help.contains(&format!("{} <", range.option)))
            .collect();
        assert!(!with_option.is_empty(), "{} is in no command", range.option);
        let stated = |help: &String, interval: &str| help.contains(interval);
        assert!(
            with_option
                .iter()
                .any(|help| stated(help, &range.interval.describe())),
            "{}: no help states {}",
            range.option,
            range.interval.describe()
        );
        for help in with_option {
            assert!(
                table
                    .iter()
                    .filter(|other| other.option == range.option)
                    .any(|other| stated(help, &other.interval.describe())),
                "{}: a help states none of its ranges",
                range.option
            );
        }
    }
}

/// `drumroll theory --json | head -1` closes the pipe before the output is written: the
/// command ends quietly, never with a panic about a broken pipe.
#[test]
fn a_closed_pipe_ends_the_output_without_a_panic() {
    for args in [
        &["theory", "--z", "9.5", "--json"][..],
        &["simulate", "--z", "9.5"][..],
        &["continue", "--floor", "9.9", "--json"][..],
        &[
            "map", "--vary", "a0", "--from", "9.5", "--to", "10.5", "--json",
        ][..],
        &["map", "--vary", "a0", "--from", "9.5", "--to", "10.5"][..],
        &["cases"][..],
        &["cases", "show", "biolever-mica"][..],
    ] {
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("drumroll"))
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("starts");
        // The reader goes away before the orbit is computed and printed.
        drop(child.stdout.take());
        let output = child.wait_with_output().expect("ends");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_eq!(output.status.code(), Some(0), "{args:?}: {stderr}");
    }
}
