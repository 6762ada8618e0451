//! Nothing lost under concurrency, requeue and corruption (issue 35): a second writer on a
//! grid part or an approach `--out` refuses at once, naming the file and the first writer's
//! process, and leaves it untouched; `grid merge` and resume check every row against the
//! header (index, parameter value, cells, required fields, checksum, duplicates) and say how
//! to recover; a resumed run says what it reused; two commands writing one path leave one
//! complete file; the limits on modes and grid cells; gathered warnings; a byte-order mark
//! and a bad cantilever reference in a case file.

mod common;
use common::{drumroll, grid_words, reseal, SLOW_GRID, SMALL_GRID};

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// [`SMALL_GRID`] on one thread (so that row `i` is line `i + 2` of its part), then `more`.
fn small<'a>(more: &[&'a str]) -> Vec<&'a str> {
    let mut words = grid_words(&SMALL_GRID, &["--threads", "1"]);
    words.extend(more);
    words
}

/// Run `drumroll ARGS`; its success and standard error.
fn run(args: &[&str], extra: &[&Path]) -> (bool, String) {
    let output = drumroll().args(args).args(extra).output().expect("runs");
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// The lines of a file, newlines included.
fn lines(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .split_inclusive('\n')
        .map(String::from)
        .collect()
}

/// Start `drumroll ARGS PATH` in the background.
fn start(args: &[&str], path: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_drumroll"))
        .args(args)
        .arg(path)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("starts")
}

/// Wait until `path` exists and is not empty (the first writer holds it), at most 60 s.
fn wait_for_content(path: &Path, child: &mut Child) {
    let started = Instant::now();
    while std::fs::metadata(path).map_or(0, |m| m.len()) == 0 {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "nothing written"
        );
        assert!(
            child.try_wait().expect("status").is_none(),
            "finished early"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_second_writer_on_a_grid_part_refuses_at_once_and_the_first_is_untouched() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let part = directory.path().join("part.jsonl");
    let sharded = grid_words(&SLOW_GRID, &["--shard", "0/1", "--output"]);
    let mut first = start(&sharded, &part);
    wait_for_content(&part, &mut first);
    let (ok, stderr) = run(&sharded, &[&part]);
    let still_running = first.try_wait().expect("status").is_none();
    assert!(!ok, "the second writer ran");
    assert!(
        stderr.contains(&part.display().to_string()) && stderr.contains("being written"),
        "{stderr}"
    );
    if cfg!(target_os = "linux") {
        assert!(
            stderr.contains(&format!("PID {}", first.id())),
            "the first writer's process: {stderr}"
        );
    }
    assert!(
        still_running,
        "the second writer returned only after the first finished"
    );
    // The first writer goes on; stopped now, its part holds valid rows only: merging it
    // names the missing rows, not a damaged line.
    first.kill().expect("kill");
    first.wait().expect("reaped");
    let (ok, stderr) = run(
        &["grid", "merge", "--output"],
        &[&directory.path().join("map.jsonl"), &part],
    );
    assert!(
        !ok && stderr.contains("rows missing from the parts"),
        "{stderr}"
    );

    // The same through a single run's work file `FILE.part`.
    let map = directory.path().join("single.jsonl");
    let whole = grid_words(&SLOW_GRID, &["--output"]);
    let mut first = start(&whole, &map);
    let work = directory.path().join("single.jsonl.part");
    wait_for_content(&work, &mut first);
    let (ok, stderr) = run(&whole, &[&map]);
    assert!(!ok && stderr.contains("single.jsonl.part"), "{stderr}");
    first.kill().expect("kill");
    first.wait().expect("reaped");
    assert!(!map.exists(), "no map from a refused or killed run");
}

#[test]
fn a_second_approach_on_the_same_out_refuses_and_the_first_finishes_complete() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let out = directory.path().join("sweep.csv");
    let args = ["approach", "--case", "biolever-mica", "--to", "6", "--out"];
    let mut first = start(&args, &out);
    let streamed = directory.path().join("sweep.csv.part");
    wait_for_content(&streamed, &mut first);
    let (ok, stderr) = run(&args, &[&out]);
    assert!(!ok, "the second sweep ran");
    assert!(stderr.contains("sweep.csv.part"), "{stderr}");
    if cfg!(target_os = "linux") {
        assert!(stderr.contains(&format!("PID {}", first.id())), "{stderr}");
    }
    assert!(first.wait().expect("finishes").success());
    assert!(!streamed.exists(), "the streamed file became the output");
    // One header, then records each with all the header's columns, the last at the floor.
    let records = lines(&out);
    let columns = records[0].split(',').count();
    assert!(records.len() > 100, "{} records", records.len());
    assert!(records
        .iter()
        .all(|r| r.ends_with('\n') && r.split(',').count() == columns));
    let last_z: f64 = records[records.len() - 1]
        .split(',')
        .nth(1)
        .expect("z")
        .parse()
        .expect("z");
    assert!(last_z <= 6.0 + 0.01, "the sweep ended at {last_z} nm");
}

/// A part of [`SMALL_GRID`] with every row: header, then rows 0 to 3 on lines 2 to 5.
fn small_part(directory: &Path, name: &str) -> PathBuf {
    let part = directory.join(name);
    let args = small(&["--shard", "0/1", "--output"]);
    let (ok, stderr) = run(&args, &[&part]);
    assert!(ok, "{stderr}");
    part
}

/// The value text after `"key":` in a row line, up to the next `,`.
fn value_text<'a>(line: &'a str, key: &str) -> &'a str {
    let start = line.find(&format!("\"{key}\":")).expect("key") + key.len() + 3;
    let end = start + line[start..].find(',').expect("a comma");
    &line[start..end]
}

#[test]
fn merge_and_resume_check_every_row_against_the_header() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let at = |name: &str| directory.path().join(name);
    let part = small_part(directory.path(), "good.jsonl");
    let good = lines(&part);
    assert_eq!(good.len(), 5);
    let (ok, stderr) = run(
        &["grid", "merge", "--output"],
        &[&at("good-map.jsonl"), &part],
    );
    assert!(ok, "{stderr}");
    let good_map = std::fs::read(at("good-map.jsonl")).expect("map");

    // Row 1 (line 3) damaged in each way the issue lists, its checksum made to match again
    // (except where the checksum is what finds it); the texts the error must hold.
    let row = good[2].clone();
    let without_last_cell = {
        let cut = row.rfind(",{\"z_nm\"").expect("cells");
        let close = row.rfind(']').expect("end of cells");
        reseal(&format!("{}{}", &row[..cut], &row[close..]))
    };
    let without_first_contact = reseal(&row.replacen(
        &format!(
            "\"first_contact_z_nm\":{},",
            value_text(&row, "first_contact_z_nm")
        ),
        "",
        1,
    ));
    let other_parameter = reseal(&row.replacen(
        &format!(
            "\"parameter_value\":{}",
            value_text(&row, "parameter_value")
        ),
        &format!(
            "\"parameter_value\":{}",
            value_text(&good[3], "parameter_value")
        ),
        1,
    ));
    let out_of_range = reseal(&row.replacen("\"row\":1,", "\"row\":4,", 1));
    let other_phase = {
        let phase = value_text(&row, "phase_deg");
        reseal(&row.replacen(
            &format!("\"phase_deg\":{phase}"),
            &format!("\"phase_deg\":{}", phase.replace('.', "1.")),
            1,
        ))
    };
    let edited = {
        let phase = value_text(&row, "phase_deg");
        row.replacen(
            &format!("\"phase_deg\":{phase}"),
            &format!("\"phase_deg\":{}", phase.replace('.', "1.")),
            1,
        )
    };
    let cases: Vec<(&str, Vec<String>, Vec<&str>)> = vec![
        (
            "one cell short",
            vec![
                good[0].clone(),
                good[1].clone(),
                without_last_cell,
                good[3].clone(),
                good[4].clone(),
            ],
            vec!["line 3", "12 cells", "13 separations"],
        ),
        (
            "no first_contact_z_nm",
            vec![
                good[0].clone(),
                good[1].clone(),
                without_first_contact,
                good[3].clone(),
                good[4].clone(),
            ],
            vec!["line 3", "first_contact_z_nm"],
        ),
        (
            "another row's parameter value",
            vec![
                good[0].clone(),
                good[1].clone(),
                other_parameter,
                good[3].clone(),
                good[4].clone(),
            ],
            vec!["line 3", "parameter_value", "not the header's value"],
        ),
        (
            "a row index past the grid",
            vec![
                good[0].clone(),
                good[1].clone(),
                out_of_range,
                good[3].clone(),
                good[4].clone(),
            ],
            vec!["line 3", "row 4 is outside the grid's 4 rows"],
        ),
        (
            "row 1 twice with different contents",
            vec![
                good[0].clone(),
                good[1].clone(),
                row.clone(),
                good[3].clone(),
                good[4].clone(),
                other_phase,
            ],
            vec!["lines 3 and 6 both hold row 1"],
        ),
        (
            "an edited number",
            vec![
                good[0].clone(),
                good[1].clone(),
                edited,
                good[3].clone(),
                good[4].clone(),
            ],
            vec!["line 3", "checksum mismatch"],
        ),
    ];
    for (what, content, expected) in cases {
        let damaged = at("damaged.jsonl");
        std::fs::write(&damaged, content.concat()).expect("write");
        let output = at("map.jsonl");
        let (ok, stderr) = run(&["grid", "merge", "--output"], &[&output, &damaged]);
        assert!(!ok, "{what}: merged");
        for text in &expected {
            assert!(stderr.contains(text), "{what}: {stderr}");
        }
        assert!(stderr.contains("damaged.jsonl"), "{what}: {stderr}");
        assert!(!output.exists(), "{what}: no map from a refused merge");
        // Resuming the damaged part is refused the same way, saying how to recover.
        let args = small(&["--shard", "0/1", "--output"]);
        let (ok, stderr) = run(&args, &[&damaged]);
        assert!(!ok, "{what}: resumed");
        assert!(stderr.contains(expected[0]), "{what}: {stderr}");
        assert!(
            stderr.contains("sed -i") || stderr.contains("delete one of them"),
            "{what}: no way to recover in: {stderr}"
        );
        assert_eq!(
            std::fs::read_to_string(&damaged).expect("kept"),
            content.concat(),
            "{what}: a refused resume leaves the part as it was"
        );
    }

    // The same row twice, identical (a requeued task that redid it): kept once.
    let twice = at("twice.jsonl");
    std::fs::write(&twice, format!("{}{}", good.concat(), good[2])).expect("write");
    let (ok, stderr) = run(
        &["grid", "merge", "--output"],
        &[&at("twice-map.jsonl"), &twice],
    );
    assert!(ok, "{stderr}");
    assert_eq!(std::fs::read(at("twice-map.jsonl")).expect("map"), good_map);

    // Resuming says what it reused and what is left; row 2 (line 4) removed is recomputed.
    let resumed = at("resumed.jsonl");
    let mut without_row_2 = good.clone();
    without_row_2.remove(3);
    std::fs::write(&resumed, without_row_2.concat()).expect("write");
    let args = small(&["--shard", "0/1", "--output"]);
    let (ok, stderr) = run(&args, &[&resumed]);
    assert!(ok, "{stderr}");
    assert!(
        stderr.contains("resuming: 3 of 4 rows already in") && stderr.contains("1 left"),
        "{stderr}"
    );
    let after = lines(&resumed);
    assert_eq!(after[..4], without_row_2[..], "the rows done were kept");
    assert_eq!(after[4], good[3], "row 2 computed again is the same line");
}

#[test]
fn two_commands_writing_one_path_leave_one_complete_file() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let at = |name: &str| directory.path().join(name);
    let csv = |a0: &str, path: &Path| {
        Command::new(env!("CARGO_BIN_EXE_drumroll"))
            .args(["continue", "--case", "biolever-mica", "--a0", a0, "--csv"])
            .arg(path)
            .stdout(Stdio::null())
            .spawn()
            .expect("starts")
    };
    let mut references = Vec::new();
    for (a0, name) in [("9", "nine.csv"), ("11", "eleven.csv")] {
        assert!(csv(a0, &at(name)).wait().expect("runs").success());
        references.push(std::fs::read(at(name)).expect("reference"));
    }
    assert_ne!(references[0], references[1]);
    let shared = at("shared.csv");
    let mut both = [csv("9", &shared), csv("11", &shared)];
    for child in &mut both {
        assert!(child.wait().expect("runs").success());
    }
    let written = std::fs::read(&shared).expect("written");
    assert!(references.contains(&written), "not one complete file");
    let names: Vec<String> = std::fs::read_dir(directory.path())
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".partial")), "{names:?}");
}

/// A cantilever file of `count` modes (`f_n = 9.3 n^2` kHz, `k_n = k * n^4` N/m, `Q = 1.2`,
/// ratios 1): mode n's stiffness above the typical 1e3 N/m once `k * n^4` is.
fn cantilever_file(path: &Path, count: usize, k: f64) {
    let modes: Vec<String> = (1..=count)
        .map(|n| {
            let n = n as f64;
            format!(
                "{{\"stiffness_n_per_m\": {}, \"frequency_khz\": {}, \"quality_factor\": 1.2, \
                 \"optical_sensitivity\": 1, \"force_ratio\": 1}}",
                k * n.powi(4),
                9.3 * n * n
            )
        })
        .collect();
    let text = format!(
        "{{\"name\": \"lever\", \"tip_radius_nm\": 30, \"tip_mass_ratio\": 0.1, \
         \"tip_youngs_modulus_gpa\": 130, \"tip_poisson_ratio\": 0.3, \"modes\": [{}]}}",
        modes.join(", ")
    );
    std::fs::write(path, text).expect("write");
}

#[test]
fn more_modes_than_the_limit_are_refused_naming_the_field_and_the_limit() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let lever = directory.path().join("lever.json");
    cantilever_file(&lever, afm::MAX_MODES + 1, 0.036);
    let lever_text = lever.display().to_string();
    let (ok, stderr) = run(
        &[
            "simulate",
            "--cantilever",
            &lever_text,
            "--sample",
            "mica",
            "--a0",
            "10",
            "--z",
            "5",
        ],
        &[],
    );
    assert!(!ok, "{} modes accepted", afm::MAX_MODES + 1);
    assert!(
        stderr.contains("lever.json") && stderr.contains("`modes`") && stderr.contains("1 to 50"),
        "{stderr}"
    );
    // The grid's cells are limited too (10^7: 4000 rows of 2501 separations are one past it).
    let (ok, stderr) = run(
        &[
            "grid",
            "--case",
            "biolever-mica",
            "--vary",
            "a0",
            "--from",
            "9",
            "--to",
            "11",
            "--steps",
            "4000",
            "--z-from",
            "11",
            "--z-to",
            "8",
            "--z-steps",
            "2501",
            "--output",
        ],
        &[&directory.path().join("big.jsonl")],
    );
    assert!(
        !ok && stderr.contains("--steps 4000 x --z-steps 2501") && stderr.contains("10000000"),
        "{stderr}"
    );
}

#[test]
fn warnings_of_one_kind_are_one_line_with_count_and_range() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let lever = directory.path().join("lever.json");
    // k_n = 2 n^4 N/m: modes 5 to 8 (1250 to 8192 N/m) lie above the typical 1e3 N/m.
    cantilever_file(&lever, 8, 2.0);
    let lever_text = lever.display().to_string();
    let (_, stderr) = run(
        &[
            "simulate",
            "--cantilever",
            &lever_text,
            "--sample",
            "mica",
            "--a0",
            "10",
            "--z",
            "-100",
        ],
        &[],
    );
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.contains("unusual for AFM"))
        .collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(
        warnings[0].contains("modes[i].stiffness_n_per_m")
            && warnings[0].contains("4 entries")
            && warnings[0].contains("modes[4].stiffness_n_per_m")
            && warnings[0].contains("modes[7].stiffness_n_per_m")
            && warnings[0].contains("1250 to 8192"),
        "{}",
        warnings[0]
    );
}

#[test]
fn a_byte_order_mark_is_accepted_and_a_bad_cantilever_reference_is_named() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let case = |name: &str, text: &str| {
        let path = directory.path().join(name);
        std::fs::write(&path, text).expect("write");
        path.display().to_string()
    };
    let body = "{\"name\": \"c\", \"cantilever\": \"biolever\", \"sample\": \"mica\", \
                \"free_amplitude_nm\": 10}";
    let with_mark = case("bom.json", &format!("\u{feff}{body}"));
    let plain = case("plain.json", body);
    let simulate = |file: &str| {
        drumroll()
            .args(["simulate", "--case", file, "--z", "5", "--json"])
            .output()
            .expect("runs")
    };
    let (marked, unmarked) = (simulate(&with_mark), simulate(&plain));
    assert!(
        marked.status.success(),
        "{}",
        String::from_utf8_lossy(&marked.stderr)
    );
    assert_eq!(marked.stdout, unmarked.stdout, "the mark changes nothing");

    let dot = case("dot.json", &body.replace("\"biolever\"", "\".\""));
    let (ok, stderr) = run(&["simulate", "--case", &dot, "--z", "5"], &[]);
    assert!(!ok);
    assert!(
        stderr.contains("dot.json") && stderr.contains("`cantilever`") && stderr.contains("\".\""),
        "{stderr}"
    );
}

/// Damage done to a part file's bytes by [`damaged_parts_are_refused_by_line_or_merge_to_the_same_map`].
#[derive(Debug, Clone)]
enum Damage {
    /// Replace the byte at this position (modulo the row lines' length) by another value.
    Replace(usize, u8),
    /// Remove the byte at this position.
    Remove(usize),
    /// Cut the file at this position.
    Cut(usize),
    /// Append a copy of this row line.
    Duplicate(usize),
    /// Swap two row lines.
    Swap(usize, usize),
}

#[test]
fn damaged_parts_are_refused_by_line_or_merge_to_the_same_map() {
    use proptest::prelude::*;
    use proptest::test_runner::{Config, TestRunner};
    let directory = tempfile::tempdir().expect("temporary directory");
    let part = small_part(directory.path(), "good.jsonl");
    let good = std::fs::read(&part).expect("part");
    let header_length = good.iter().position(|&b| b == b'\n').expect("header") + 1;
    let good_map = directory.path().join("good-map.jsonl");
    drumroll::grid_file::assemble(std::slice::from_ref(&part), &good_map).expect("merges");
    let good_map = std::fs::read(&good_map).expect("map");
    let damaged = directory.path().join("damaged.jsonl");
    let output = directory.path().join("map.jsonl");
    let damage = prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(at, by)| Damage::Replace(at, by)),
        any::<usize>().prop_map(Damage::Remove),
        any::<usize>().prop_map(Damage::Cut),
        (0usize..4).prop_map(Damage::Duplicate),
        (0usize..4, 0usize..4).prop_map(|(a, b)| Damage::Swap(a, b)),
    ];
    let cases = std::env::var("DRUMROLL_PART_FUZZ_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(500);
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(&damage, |damage| {
            let rows = good.len() - header_length;
            let mut lines: Vec<Vec<u8>> = good
                .split_inclusive(|&b| b == b'\n')
                .map(<[u8]>::to_vec)
                .collect();
            let mut bytes = good.clone();
            let must_fail = match &damage {
                Damage::Replace(at, by) => {
                    let at = header_length + at % rows;
                    // A different byte value: `by` added modulo 256, never zero.
                    bytes[at] = bytes[at].wrapping_add(*by);
                    true
                }
                Damage::Remove(at) => {
                    bytes.remove(header_length + at % rows);
                    true
                }
                Damage::Cut(at) => {
                    bytes.truncate(header_length + at % rows);
                    true
                }
                Damage::Duplicate(row) => {
                    let copy = lines[1 + row].clone();
                    lines.push(copy);
                    bytes = lines.concat();
                    false
                }
                Damage::Swap(a, b) => {
                    lines.swap(1 + a, 1 + b);
                    bytes = lines.concat();
                    false
                }
            };
            std::fs::write(&damaged, &bytes).expect("write");
            let _ = std::fs::remove_file(&output);
            match drumroll::grid_file::assemble(std::slice::from_ref(&damaged), &output) {
                Ok(()) => {
                    prop_assert!(!must_fail, "{damage:?} was merged");
                    prop_assert!(
                        std::fs::read(&output).expect("map") == good_map,
                        "{damage:?}: merged into another map"
                    );
                }
                Err(error) => {
                    let message = format!("{error:#}");
                    prop_assert!(!output.exists(), "{damage:?}: a map from a refused merge");
                    prop_assert!(message.contains("damaged.jsonl"), "{damage:?}: {message}");
                    prop_assert!(
                        message.contains(" line ")
                            || message.contains("lines ")
                            || message.contains("rows missing"),
                        "{damage:?}: neither a line nor the missing rows named: {message}"
                    );
                }
            }
            Ok(())
        })
        .unwrap_or_else(|error| panic!("{error}"));
}
