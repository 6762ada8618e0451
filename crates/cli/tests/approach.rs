//! `drumroll approach` run as a user runs it: the real binary on short windows of the Biolever
//! on mica, its CSV and JSON Lines checked against `drumroll simulate` (the steady orbit by
//! shooting, an independent computation) and against the closed-form free orbit, and bad
//! options refused with a message naming the option.

mod common;
use common::{drumroll, stdout_on_threads};
use serde_json::Value;

fn stdout_of(args: &[&str]) -> String {
    let output = drumroll().args(args).output().expect("runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).expect("UTF-8")
}

/// One CSV row: (cycle, z, A/A0, phase, impacts, peak force, direction); the dissipated
/// energy and the four harmonics' eight columns are checked to be numbers.
fn parse_row(line: &str) -> (u64, f64, f64, f64, f64, f64, String) {
    let fields: Vec<&str> = line.split(',').collect();
    assert_eq!(fields.len(), 16, "{line}");
    for i in [6].into_iter().chain(8..16) {
        fields[i].parse::<f64>().expect("a number");
    }
    let number = |i: usize| fields[i].parse::<f64>().expect("a number");
    (
        fields[0].parse().expect("cycle"),
        number(1),
        number(2),
        number(3),
        number(4),
        number(5),
        fields[7].to_string(),
    )
}

fn simulate(z: f64) -> Value {
    let text = stdout_of(&[
        "simulate",
        "--case",
        "biolever-mica",
        "--z",
        &z.to_string(),
        "--json",
    ]);
    serde_json::from_str(&text).expect("JSON")
}

/// At 10 nm/s through 9.01 -> 8.99 nm (single impacts, 18 cycles): the CSV header, one row per
/// cycle with Z falling by one cycle's travel, and the last row on the steady orbit at its Z
/// to the tolerances (1e-3 in A/A0, 0.1 deg; the quasi-static lag at 10 nm/s is
/// ~1e-3 nm, worth ~1e-4 in A/A0 and ~0.02 deg).
#[test]
fn csv_rows_follow_the_steady_orbit() {
    let text = stdout_of(&[
        "approach",
        "--case",
        "biolever-mica",
        "--from",
        "9.01",
        "--to",
        "8.99",
        "--rate",
        "10",
    ]);
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(concat!(
            "cycle,z_nm,amplitude_ratio,phase_deg,impacts_per_period,peak_force_nn,dissipated_ev,",
            "direction,harmonic_1_amplitude_nm,harmonic_1_phase_deg,harmonic_2_amplitude_nm,",
            "harmonic_2_phase_deg,harmonic_3_amplitude_nm,harmonic_3_phase_deg,",
            "harmonic_4_amplitude_nm,harmonic_4_phase_deg"
        ))
    );
    let rows: Vec<_> = lines.map(parse_row).collect();
    let free = simulate(12.0);
    let period_us = free["period_us"].as_f64().expect("period");
    let z_step = 10.0e-6 * period_us;
    assert_eq!(rows.len(), (0.02 / z_step).floor() as usize);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row.0, k as u64);
        assert!((row.1 - (9.01 - (k as f64 + 0.5) * z_step)).abs() < 1e-9);
        assert_eq!(row.4, 1.0, "one impact per cycle at 9 nm");
        assert!(row.5 > 0.0);
        assert_eq!(row.6, "approach");
    }
    let last = rows.last().expect("rows");
    let orbit = simulate(last.1);
    assert!((last.2 - orbit["amplitude_ratio"].as_f64().unwrap()).abs() < 1e-3);
    assert!((last.3 - orbit["phase_deg"].as_f64().unwrap()).abs() < 0.1);
    assert_eq!(last.4, orbit["impacts_per_period"].as_f64().unwrap());
    // Peak force: the orbit's, to 1% (the per-cycle maximum samples the same contact).
    let peak = orbit["peak_force_nn"].as_f64().unwrap();
    assert!((last.5 - peak).abs() < 1e-2 * peak, "{} vs {peak}", last.5);
}

/// JSON Lines into a file with a retract and a figure: every line a complete object, the
/// approach above first contact reading the free orbit (A/A0 = 1, the free phase), the retract
/// as long as the approach and labelled, and an SVG written.
#[test]
fn jsonl_file_with_retract_and_plot() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let out = directory.path().join("sweep.jsonl");
    let plot = directory.path().join("sweep.svg");
    let free = simulate(12.0);
    let z_g1 = free["first_contact_z_nm"].as_f64().unwrap();
    let from = z_g1 + 0.05;
    let to = z_g1 - 0.05;
    let output = drumroll()
        .args([
            "approach",
            "--from",
            &from.to_string(),
            "--to",
            &to.to_string(),
            "--rate",
            "20",
            "--retract",
            "--jsonl",
            "--out",
            out.to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
        ])
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(output.stdout.is_empty(), "records go to the file");
    let text = std::fs::read_to_string(&out).expect("records file");
    assert!(text.ends_with('\n'));
    let mut lines: Vec<Value> = text
        .lines()
        .map(|line| serde_json::from_str(line).expect("one complete object per line"))
        .collect();
    // The first line holds the inputs: enough to run the sweep again.
    let header = lines.remove(0);
    let inputs = &header["inputs"];
    assert_eq!(inputs["command"], "approach");
    assert_eq!(inputs["case"], "biolever-mica");
    assert_eq!(inputs["options"]["from_nm"].as_f64(), Some(from));
    assert_eq!(inputs["options"]["retract"], true);
    assert_eq!(inputs["cantilever"]["name"], "biolever");
    let records = lines;
    let approach: Vec<&Value> = records
        .iter()
        .filter(|r| r["direction"] == "approach")
        .collect();
    let retract: Vec<&Value> = records
        .iter()
        .filter(|r| r["direction"] == "retract")
        .collect();
    assert_eq!(approach.len(), retract.len());
    assert_eq!(approach.len() + retract.len(), records.len());
    let free_phase = free["free_phase_deg"].as_f64().unwrap();
    for record in &approach {
        let z = record["z_nm"].as_f64().unwrap();
        if z > z_g1 + 1e-3 {
            // Free flight: exact flow from the exact free state.
            assert!((record["amplitude_ratio"].as_f64().unwrap() - 1.0).abs() < 1e-9);
            assert!((record["phase_deg"].as_f64().unwrap() - free_phase).abs() < 1e-6);
            assert_eq!(record["impacts_per_period"], 0.0);
        }
        if z < z_g1 - 1e-2 {
            assert_eq!(
                record["impacts_per_period"], 1.0,
                "in contact below Z_G1: {record}"
            );
        }
    }
    let z: Vec<f64> = retract
        .iter()
        .map(|r| r["z_nm"].as_f64().unwrap())
        .collect();
    assert!(z.windows(2).all(|w| w[1] > w[0]), "the retract rises");
    let svg = std::fs::read_to_string(&plot).expect("figure");
    assert!(svg.starts_with("<svg") || svg.contains("<svg"));
}

/// `--lockin-cycles` and `--every` set the number of rows.
#[test]
fn lockin_blocks_and_decimation_set_the_row_count() {
    let all = stdout_of(&["approach", "--from", "9.01", "--to", "9.0", "--rate", "10"]);
    let cycles = all.lines().count() - 1;
    let blocks = stdout_of(&[
        "approach",
        "--from",
        "9.01",
        "--to",
        "9.0",
        "--rate",
        "10",
        "--lockin-cycles",
        "3",
        "--every",
        "2",
    ]);
    assert_eq!(blocks.lines().count() - 1, (cycles / 3).div_ceil(2));
}

#[test]
fn bad_options_are_refused_with_the_option_named() {
    for (args, expected) in [
        (vec!["--rate", "0"], "--rate"),
        (vec!["--rate", "inf"], "--rate"),
        (vec!["--to", "-1"], "--to"),
        (vec!["--from", "1", "--to", "2"], "--from"),
        (vec!["--lockin-cycles", "0"], "--lockin-cycles"),
        (vec!["--every", "0"], "--every"),
        (vec!["--tolerance", "1"], "--tolerance"),
        (vec!["--from", "10", "--to", "9.9999"], "drive cycle"),
        (vec!["--from", "9", "--to", "8", "--rate", "1e-9"], "--rate"),
        (vec!["--plot", "figure.jpg"], ".svg, .png or .pdf"),
        (
            vec!["--from", "9", "--to", "8.99", "--lockin-cycles", "1000"],
            "lockin_cycles",
        ),
    ] {
        let output = drumroll()
            .arg("approach")
            .args(&args)
            .output()
            .expect("runs");
        assert!(!output.status.success(), "{args:?} accepted");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
}

/// A run killed mid-sweep leaves no `--out` file, and its records so far in `--out` + `.part`
/// (docs/guide/concurrency.md): every line whole (one write per record), the header first,
/// rows in order.
#[test]
fn a_killed_run_leaves_only_complete_records() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let out = directory.path().join("killed.csv");
    let streamed = directory.path().join("killed.csv.part");
    // 11 nm -> 0 at 1 nm/s: ~100,000 cycles, far more than runs before the kill.
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("drumroll"))
        .args(["approach", "--from", "11", "--to", "0", "--out"])
        .arg(&out)
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("starts");
    // Wait until some records are there, then kill the process (SIGKILL: no clean-up).
    let start = std::time::Instant::now();
    // (Rows of about 250 bytes with the four harmonics.)
    while std::fs::metadata(&streamed).map(|m| m.len()).unwrap_or(0) < 60_000 {
        assert!(start.elapsed().as_secs() < 60, "no records within a minute");
        assert!(
            child.try_wait().expect("status").is_none(),
            "finished before the kill"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().expect("killed");
    child.wait().expect("reaped");
    assert!(!out.exists(), "a killed sweep writes no --out file");
    let text = std::fs::read_to_string(&streamed).expect("records file");
    assert!(text.ends_with('\n'), "the last record is complete");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(concat!(
            "cycle,z_nm,amplitude_ratio,phase_deg,impacts_per_period,peak_force_nn,dissipated_ev,",
            "direction,harmonic_1_amplitude_nm,harmonic_1_phase_deg,harmonic_2_amplitude_nm,",
            "harmonic_2_phase_deg,harmonic_3_amplitude_nm,harmonic_3_phase_deg,",
            "harmonic_4_amplitude_nm,harmonic_4_phase_deg"
        ))
    );
    let rows: Vec<_> = lines.map(parse_row).collect();
    assert!(rows.len() > 100);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row.0, k as u64);
    }
}

/// On several threads the cycles ahead run in speculative segments; the records are one
/// trajectory's all the same: the CSV of an approach and retract across G2 (4650 cycles each
/// way, blocks of 2 cycles, every 3rd kept) and the JSON Lines of a 9,300-cycle approach are
/// the same bytes on 1, 2 and 3 threads.
#[test]
fn records_are_the_same_bytes_on_any_number_of_threads() {
    let runs = [
        "approach --case biolever-mica --from 9 --to 8.5 --rate 1 --retract --lockin-cycles 2 \
         --every 3",
        "approach --case biolever-mica --from 9 --to 8 --rate 1 --jsonl",
    ];
    for command in runs {
        let args: Vec<&str> = command.split_whitespace().collect();
        let args = args.as_slice();
        let one = stdout_on_threads("1", args);
        assert!(one.split(|&b| b == b'\n').count() > 1000, "{args:?}");
        for threads in ["2", "3"] {
            assert!(
                stdout_on_threads(threads, args) == one,
                "{args:?} on {threads} threads"
            );
        }
    }
}
