//! Shared by the CLI tests: running the real `drumroll` binary and reading its JSON.
// Each test binary uses its own subset of these helpers.
#![allow(dead_code)]

use assert_cmd::Command;
use serde_json::Value;

/// The `drumroll` binary built by cargo for this test run.
pub fn drumroll() -> Command {
    Command::cargo_bin("drumroll").expect("binary built")
}

/// Run `drumroll ARGS --json`, require success, and parse its one JSON object.
pub fn json_of(args: &[&str]) -> Value {
    let output = drumroll().args(args).arg("--json").output().expect("runs");
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("one JSON object")
}

/// Run `drumroll ARGS` with rayon's pool of `threads` threads (`RAYON_NUM_THREADS`), require
/// success, and return its standard output.
pub fn stdout_on_threads(threads: &str, args: &[&str]) -> Vec<u8> {
    let output = drumroll()
        .env("RAYON_NUM_THREADS", threads)
        .args(args)
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "{args:?} on {threads} threads: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output.stdout
}

/// The number at `key` of a JSON object.
pub fn number(value: &Value, key: &str) -> f64 {
    value[key]
        .as_f64()
        .unwrap_or_else(|| panic!("`{key}` is not a number in {value}"))
}

/// A row line (newline included) with its `crc32` recomputed as docs/output-schema.md
/// defines it: the CRC-32 of the bytes before `,"crc32"` followed by `}` (a line without one,
/// as before checksums, unchanged).
pub fn reseal(line: &str) -> String {
    let Some(at) = line.rfind(",\"crc32\"") else {
        return line.to_string();
    };
    let body = format!("{}}}", &line[..at]);
    format!(
        "{},\"crc32\":\"{:08x}\"}}\n",
        &line[..at],
        crc32fast::hash(body.as_bytes())
    )
}

/// The options after `drumroll grid` of a small grid on the Biolever on mica: 4 free
/// amplitudes (9.5 to 11 nm), Z from 11 down to 8 nm in 13 steps (through first contact and
/// G2 in every row).
pub const SMALL_GRID: [&str; 16] = [
    "--case",
    "biolever-mica",
    "--vary",
    "a0",
    "--from",
    "9.5",
    "--to",
    "11",
    "--steps",
    "4",
    "--z-from",
    "11",
    "--z-to",
    "8",
    "--z-steps",
    "13",
];

/// The options after `drumroll grid` of a grid that runs for seconds: 12 rows (tip radius 10
/// to 40 nm) of 200 cells (Z from 12 down to 1 nm) on one thread (about 70 ms a row).
pub const SLOW_GRID: [&str; 18] = [
    "--case",
    "biolever-mica",
    "--vary",
    "tip-radius",
    "--from",
    "10",
    "--to",
    "40",
    "--steps",
    "12",
    "--z-from",
    "12",
    "--z-to",
    "1",
    "--z-steps",
    "200",
    "--threads",
    "1",
];

/// The words `grid OPTIONS MORE...` of a `drumroll grid` command.
pub fn grid_words<'a>(options: &[&'a str], more: &[&'a str]) -> Vec<&'a str> {
    std::iter::once("grid")
        .chain(options.iter().copied())
        .chain(more.iter().copied())
        .collect()
}
