//! `drumroll grid`: the file does not depend on the thread count or the sharding, shards
//! resume after a kill, `grid merge` refuses parts of different grids and names missing rows,
//! bad options are refused by name, and the regime boundaries agree with `continue`.

mod common;
use common::{drumroll, grid_words, json_of, number, reseal, SLOW_GRID, SMALL_GRID};

use serde_json::Value;
use std::path::{Path, PathBuf};

/// Run `drumroll grid ARGS --retract --output FILE EXTRA...` and require success.
fn grid(output: &Path, extra: &[&str]) {
    let result = drumroll()
        .arg("grid")
        .args(SMALL_GRID)
        .arg("--retract")
        .arg("--output")
        .arg(output)
        .args(extra)
        .output()
        .expect("runs");
    assert!(
        result.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&result.stderr)
    );
}

/// Run `drumroll ARGS`, require failure, and return its standard error.
fn failure(args: &[&str]) -> String {
    let result = drumroll().args(args).output().expect("runs");
    assert!(!result.status.success(), "{args:?} succeeded");
    String::from_utf8(result.stderr).expect("utf-8")
}

/// `drumroll grid merge PARTS --output FILE`; its status and standard error.
fn merge(parts: &[PathBuf], output: &Path) -> (bool, String) {
    let result = drumroll()
        .args(["grid", "merge"])
        .args(parts)
        .arg("--output")
        .arg(output)
        .output()
        .expect("runs");
    (
        result.status.success(),
        String::from_utf8_lossy(&result.stderr).into_owned(),
    )
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_map_does_not_depend_on_threads_or_shards() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let at = |name: &str| directory.path().join(name);
    grid(&at("one.jsonl"), &["--threads", "1"]);
    grid(&at("two.jsonl"), &["--threads", "2"]);
    let single = read(&at("one.jsonl"));
    assert_eq!(single, read(&at("two.jsonl")), "1 and 2 threads differ");
    assert!(!at("one.jsonl.part").exists(), "the work file is removed");

    // The header, then rows 0..3 in order, each with 13 cells.
    let text = String::from_utf8(single.clone()).expect("utf-8");
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON"))
        .collect();
    assert_eq!(lines.len(), 5);
    assert_eq!(lines[0]["inputs"]["command"], "grid");
    for (row, line) in lines[1..].iter().enumerate() {
        assert_eq!(line["row"], row);
        assert_eq!(line["cells"].as_array().expect("cells").len(), 13);
    }

    // Three shards, one of them on two threads, merged in a scrambled order.
    let parts: Vec<PathBuf> = (0..3).map(|i| at(&format!("part-{i}.jsonl"))).collect();
    for (i, part) in parts.iter().enumerate() {
        let shard = format!("{i}/3");
        grid(
            part,
            &[
                "--shard",
                &shard,
                "--threads",
                if i == 1 { "2" } else { "1" },
            ],
        );
    }
    let scrambled = [parts[2].clone(), parts[0].clone(), parts[1].clone()];
    let (ok, stderr) = merge(&scrambled, &at("merged.jsonl"));
    assert!(ok, "{stderr}");
    assert_eq!(
        read(&at("merged.jsonl")),
        single,
        "shards + merge != one run"
    );
}

#[test]
fn a_killed_shard_resumes_where_it_stopped() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let at = |name: &str| directory.path().join(name);
    grid(&at("single.jsonl"), &[]);
    let part = at("part.jsonl");
    grid(&part, &["--shard", "0/1"]);
    let complete = String::from_utf8(read(&part)).expect("utf-8");
    let lines: Vec<&str> = complete.split_inclusive('\n').collect();
    assert_eq!(lines.len(), 5);

    // A kill: the last row line cut in half, and a row (row 0 of the kept ones) marked so that
    // its recomputation would show.
    let kept_row = reseal(&lines[1].replacen("\"cells\"", "\"kept\":true,\"cells\"", 1));
    let cut = &lines[4][..lines[4].len() / 2];
    let killed = format!("{}{}{}{}{}", lines[0], kept_row, lines[2], lines[3], cut);
    std::fs::write(&part, &killed).expect("truncate");
    grid(&part, &["--shard", "0/1"]);
    let resumed = String::from_utf8(read(&part)).expect("utf-8");
    assert!(
        resumed.starts_with(&format!("{}{}{}{}", lines[0], kept_row, lines[2], lines[3])),
        "the rows done were kept, not recomputed"
    );
    assert_eq!(
        resumed.lines().count(),
        5,
        "the cut row was computed again, once"
    );
    assert!(
        resumed.ends_with(lines[4]),
        "the cut row, recomputed, is the same line"
    );

    // The resumed part without the marked row merges into the single run's file.
    std::fs::write(&part, resumed.replacen(&kept_row, lines[1], 1).as_bytes()).expect("unmark");
    let (ok, stderr) = merge(std::slice::from_ref(&part), &at("merged.jsonl"));
    assert!(ok, "{stderr}");
    assert_eq!(read(&at("merged.jsonl")), read(&at("single.jsonl")));

    // Killed while writing its header: the part holds a beginning of the header, and the
    // rerun starts it afresh into the same part.
    std::fs::write(&part, &lines[0][..lines[0].len() / 3]).expect("cut header");
    grid(&part, &["--shard", "0/1"]);
    let rerun = String::from_utf8(read(&part)).expect("utf-8");
    let mut rerun_lines: Vec<&str> = rerun.split_inclusive('\n').collect();
    let mut complete_lines = lines.clone();
    // The rows in the order their threads finished them: the same lines.
    rerun_lines.sort_unstable();
    complete_lines.sort_unstable();
    assert!(
        rerun_lines == complete_lines,
        "the part rewritten from a cut header differs from the complete one"
    );

    // A file with no header line that is not the beginning of one (a mistyped --output) is
    // refused and left as it was.
    let notes = at("notes.json");
    std::fs::write(&notes, "{\"my\": \"notes\"}").expect("notes");
    let words = grid_words(&SMALL_GRID, &["--retract", "--shard", "0/1", "--output"]);
    let mut args: Vec<&str> = words;
    let notes_arg = notes.to_str().expect("utf-8 path");
    args.push(notes_arg);
    let stderr = failure(&args);
    assert!(
        stderr.contains("not a drumroll grid file") && stderr.contains("notes.json"),
        "{stderr}"
    );
    assert_eq!(read(&notes), b"{\"my\": \"notes\"}");
}

#[test]
fn merge_refuses_other_grids_and_names_missing_rows() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let at = |name: &str| directory.path().join(name);
    let parts: Vec<PathBuf> = (0..3).map(|i| at(&format!("part-{i}.jsonl"))).collect();
    grid(&parts[0], &["--shard", "0/3"]);
    grid(&parts[2], &["--shard", "2/3"]);

    // Rows 1 is missing (shard 1/3 never ran).
    let output = at("map.jsonl");
    let (ok, stderr) = merge(&[parts[0].clone(), parts[2].clone()], &output);
    assert!(!ok);
    assert!(
        stderr.contains("rows missing from the parts: 1 "),
        "{stderr}"
    );
    assert!(!output.exists(), "no output on a refused merge");

    // A part of a grid with another Z resolution.
    let other = drumroll()
        .arg("grid")
        .args(&SMALL_GRID[..15])
        .args(["14", "--retract", "--shard", "1/3", "--output"])
        .arg(&parts[1])
        .output()
        .expect("runs");
    assert!(other.status.success());
    let (ok, stderr) = merge(&parts, &output);
    assert!(!ok);
    assert!(
        stderr.contains("other inputs") && stderr.contains("inputs.options.z_steps"),
        "{stderr}"
    );
    assert!(!output.exists());

    // Resuming into a part file of another grid is refused too, naming the option.
    let stderr = failure(&grid_words(
        &SMALL_GRID,
        &[
            "--shard",
            "1/3",
            "--output",
            parts[1].to_str().expect("utf-8"),
        ],
    ));
    assert!(
        stderr.contains("--output") && stderr.contains("other inputs"),
        "{stderr}"
    );
}

/// A bad-input case: options replaced in [`SMALL_GRID`] (option, new value), options added, and
/// the texts the error must contain.
type BadCase<'a> = (&'a [(&'a str, &'a str)], &'a [&'a str], &'a [&'a str]);

#[test]
fn bad_options_are_refused_by_name() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = directory.path().join("map.jsonl");
    let out = output.to_str().expect("utf-8");
    let with = |replace: &[(&str, &str)], extra: &[&str]| {
        let mut args: Vec<String> = ["grid".to_string()]
            .into_iter()
            .chain(SMALL_GRID.iter().map(|s| s.to_string()))
            .collect();
        for (option, value) in replace {
            let at = args.iter().position(|a| a == option).expect("option") + 1;
            args[at] = value.to_string();
        }
        args.extend(["--output".to_string(), out.to_string()]);
        args.extend(extra.iter().map(|s| s.to_string()));
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        failure(&refs)
    };
    let cases: [BadCase; 10] = [
        (
            &[("--vary", "amplitude")],
            &[],
            &[
                "--vary amplitude",
                "a0, drive-frequency, sample-modulus, tip-radius, quality-factor-N, stiffness-N",
            ],
        ),
        (&[("--from", "-1")], &[], &["--from", "[0.001, 100000] nm"]),
        (
            &[("--vary", "sample-modulus"), ("--to", "2e4")],
            &[],
            &["--to", "[1e-7, 10000] GPa"],
        ),
        (
            &[
                ("--vary", "quality-factor-3"),
                ("--from", "1"),
                ("--to", "2"),
            ],
            &[],
            &["--vary quality-factor-3", "a mode from 1 to 2"],
        ),
        (
            &[
                ("--vary", "drive-frequency"),
                ("--from", "9"),
                ("--to", "9000"),
            ],
            &[],
            &["--to: no valid model", "drive_frequency_khz", "7200"],
        ),
        (&[("--steps", "1")], &[], &["--steps 1", "--from = --to"]),
        (&[("--z-to", "12")], &[], &["--z-to 12", "below --z-from"]),
        (&[("--z-to", "-10")], &[], &["--z-to -10", "-A0"]),
        (
            &[],
            &["--shard", "3/2"],
            &["--shard 3/2", "below the shard count"],
        ),
        (&[], &["--threads", "0"], &["--threads 0"]),
    ];
    for (replace, extra, expected) in cases {
        let stderr = with(replace, extra);
        for text in expected {
            assert!(stderr.contains(text), "{replace:?} {extra:?}: {stderr}");
        }
        assert!(!output.exists(), "{replace:?}: no output file on an error");
    }
    let stderr = failure(&["grid", "merge", "--output", out]);
    assert!(stderr.contains("PARTS"), "{stderr}");
}

/// The Z at which row `cells` first shows `impacts` or more per period in `direction`, as the
/// interval `[z of that cell, z of the cell before]`.
fn onset(cells: &[Value], direction: &str, impacts: f64) -> [f64; 2] {
    let j = cells
        .iter()
        .position(|c| number(&c[direction], "impacts_per_period") >= impacts)
        .unwrap_or_else(|| panic!("no cell with {impacts} impacts in {direction}"));
    assert!(j > 0, "the first cell already has {impacts} impacts");
    [number(&cells[j], "z_nm"), number(&cells[j - 1], "z_nm")]
}

#[test]
fn the_impact_count_changes_within_one_cell_of_continue_s_grazing_points() {
    // Rows at A0 = 8, 10 and 12 nm; Z from 12.5 down to 2 nm in 0.05 nm cells (G1, G2 and,
    // in the lower rows, G3).
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = directory.path().join("map.jsonl");
    let result = drumroll()
        .args([
            "grid",
            "--case",
            "biolever-mica",
            "--vary",
            "a0",
            "--from",
            "8",
            "--to",
            "12",
            "--steps",
            "3",
            "--z-from",
            "12.5",
            "--z-to",
            "2",
            "--z-steps",
            "211",
            "--retract",
            "--output",
        ])
        .arg(&output)
        .output()
        .expect("runs");
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let text = std::fs::read_to_string(&output).expect("map");
    let cell = 0.05;
    for line in text.lines().skip(1) {
        let row: Value = serde_json::from_str(line).expect("row");
        let a0 = number(&row, "parameter_value");
        let cells = row["cells"].as_array().expect("cells");
        let a0_text = a0.to_string();
        let diagram = json_of(&["continue", "--case", "biolever-mica", "--a0", &a0_text]);
        let mut checked = 0;
        for special in diagram["special_points"]
            .as_array()
            .expect("special points")
        {
            let label = special["label"].as_str().expect("label");
            let Some(n) = label.strip_prefix('G').and_then(|n| n.parse::<f64>().ok()) else {
                continue;
            };
            let z = number(special, "z_nm");
            if z < 2.0 + cell {
                continue;
            }
            for direction in ["approach", "retract"] {
                let [low, high] = onset(cells, direction, n);
                assert!(
                    low - cell <= z && z <= high + cell,
                    "A0 = {a0}, {label} at {z} nm: the grid's {direction} changes to {n} \
                     impacts in [{low}, {high}]"
                );
            }
            checked += 1;
        }
        assert!(checked >= 2, "A0 = {a0}: G1 and G2 at least ({checked})");
        assert!(
            cells.iter().all(|c| c["bistable"] == false),
            "the Biolever on mica has no bistable range"
        );
    }
}

#[test]
fn bistable_cells_lie_in_continue_s_bistable_range() {
    // The MAClever on mica at its own A0 = 20 nm: the fold pair just below first contact,
    // Z from 20 down to 19.99 nm in 2.5e-4 nm cells.
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = directory.path().join("map.jsonl");
    let result = drumroll()
        .args([
            "grid",
            "--case",
            "maclever-mica",
            "--vary",
            "a0",
            "--from",
            "20",
            "--to",
            "20",
            "--steps",
            "1",
            "--z-from",
            "20",
            "--z-to",
            "19.99",
            "--z-steps",
            "41",
            "--retract",
            "--output",
        ])
        .arg(&output)
        .output()
        .expect("runs");
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let text = std::fs::read_to_string(&output).expect("map");
    let row: Value = serde_json::from_str(text.lines().nth(1).expect("row")).expect("JSON");
    let diagram = json_of(&["continue", "--case", "maclever-mica", "--retract"]);
    let ranges = diagram["bistable_ranges_nm"].as_array().expect("ranges");
    assert_eq!(ranges.len(), 1, "{ranges:?}");
    let bound = |i: usize| ranges[0][i].as_f64().expect("a number");
    let [low, high] = [bound(0), bound(1)];
    let cell = 2.5e-4;
    let mut bistable = 0;
    for c in row["cells"].as_array().expect("cells") {
        let z = number(c, "z_nm");
        let flagged = c["bistable"] == true;
        if flagged {
            bistable += 1;
            assert!(
                low - cell <= z && z <= high + cell,
                "bistable at {z}, outside [{low}, {high}]"
            );
        } else {
            assert!(
                !(low + cell <= z && z <= high - cell),
                "not bistable at {z}, inside [{low}, {high}]"
            );
        }
    }
    assert!(bistable >= 5, "{bistable} bistable cells");
}

#[test]
fn a_run_killed_mid_row_resumes_into_the_same_map() {
    // 12 rows of 200 cells (about 70 ms each on one thread), killed (SIGKILL) once 3 rows
    // are in its work file, then run again to the end.
    let directory = tempfile::tempdir().expect("temporary directory");
    let at = |name: &str| directory.path().join(name);
    let options = grid_words(&SLOW_GRID, &["--output"]);
    let killed = at("killed.jsonl");
    let work = at("killed.jsonl.part");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_drumroll"))
        .args(&options)
        .arg(&killed)
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("starts");
    let start = std::time::Instant::now();
    while std::fs::read(&work).map_or(0, |b| b.iter().filter(|&&c| c == b'\n').count()) < 4 {
        assert!(start.elapsed().as_secs() < 60, "no rows written");
        assert!(
            child.try_wait().expect("status").is_none(),
            "finished before the kill"
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().expect("kill");
    child.wait().expect("reaped");
    assert!(!killed.exists(), "no map file from a killed run");
    let rows_done = String::from_utf8(read(&work))
        .expect("utf-8")
        .matches('\n')
        .count()
        - 1;
    assert!((3..12).contains(&rows_done), "{rows_done} rows at the kill");

    let rerun = drumroll()
        .args(&options)
        .arg(&killed)
        .output()
        .expect("runs");
    assert!(
        rerun.status.success(),
        "{}",
        String::from_utf8_lossy(&rerun.stderr)
    );
    assert!(
        !work.exists(),
        "the work file is removed once the map is written"
    );
    let fresh = drumroll()
        .args(&options)
        .arg(at("fresh.jsonl"))
        .output()
        .expect("runs");
    assert!(fresh.status.success());
    assert_eq!(
        read(&killed),
        read(&at("fresh.jsonl")),
        "resumed != uninterrupted"
    );
}
