//! The continued regime boundaries (`drumroll map`) against the brute-force grid
//! (`drumroll grid`), two independent computations: on the Biolever on mica and on the soft
//! sample, at five free amplitudes, every change of impacts per period along a grid row, on the
//! approach and on the retract, lies within one grid cell of a continued `G_n` curve at that
//! row's `A0`, and every continued `G_n` inside the row's `Z` range has such a change within one
//! cell. The map's points at the rows' values are located exactly there (`--at` and the range
//! ends), so no interpolation enters the comparison.

mod common;
use common::{drumroll, json_of, number};

use serde_json::Value;

/// The rows' free amplitudes, nm: both range ends and the `--at` values of the map.
const ROWS: [f64; 5] = [8.0, 9.0, 10.0, 11.0, 12.0];
/// The grid's separations: from above every row's first contact down to 1 nm.
const Z_FROM: f64 = 13.0;
const Z_TO: f64 = 1.0;
const Z_STEPS: usize = 241;

/// The continued `G_n` separations of `case` at each row's `A0`: `(row index, label, Z)`
/// (`json_of` adds `--json`).
fn continued(case: &str) -> Vec<(usize, String, f64)> {
    let map = json_of(&[
        "map", "--case", case, "--vary", "a0", "--from", "8", "--to", "12", "--at", "9,10,11",
    ]);
    let mut grazings = Vec::new();
    for curve in map["curves"].as_array().expect("curves") {
        let label = curve["label"].as_str().expect("label").to_string();
        if !label.starts_with('G') {
            continue;
        }
        for point in curve["points"].as_array().expect("points") {
            let p = number(point, "parameter");
            if let Some(row) = ROWS.iter().position(|&a0| a0 == p) {
                grazings.push((row, label.clone(), number(point, "z_nm")));
            }
        }
    }
    grazings
}

/// The grid of `case`: per row, the separations of the cells and the impacts per period on the
/// approach and on the retract.
fn grid(case: &str) -> Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = directory.path().join("map.jsonl");
    let (z_from, z_to, z_steps) = (Z_FROM.to_string(), Z_TO.to_string(), Z_STEPS.to_string());
    let status = drumroll()
        .args([
            "grid",
            "--case",
            case,
            "--vary",
            "a0",
            "--from",
            "8",
            "--to",
            "12",
            "--steps",
            "5",
            "--z-from",
            &z_from,
            "--z-to",
            &z_to,
            "--z-steps",
            &z_steps,
            "--retract",
        ])
        .arg("--output")
        .arg(&output)
        .output()
        .expect("runs");
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let text = std::fs::read_to_string(&output).expect("grid file");
    text.lines()
        .skip(1)
        .map(|line| {
            let row: Value = serde_json::from_str(line).expect("a row");
            let cells = row["cells"].as_array().expect("cells");
            let z = cells.iter().map(|c| number(c, "z_nm")).collect();
            let approach = cells
                .iter()
                .map(|c| number(&c["approach"], "impacts_per_period"))
                .collect();
            let retract = cells
                .iter()
                .map(|c| number(&c["retract"], "impacts_per_period"))
                .collect();
            (z, approach, retract)
        })
        .collect()
}

/// The midpoints of the cell pairs where `impacts` changes along `z`.
fn changes(z: &[f64], impacts: &[f64]) -> Vec<f64> {
    (1..z.len())
        .filter(|&i| impacts[i] != impacts[i - 1])
        .map(|i| 0.5 * (z[i] + z[i - 1]))
        .collect()
}

fn check(case: &str) {
    let grazings = continued(case);
    let rows = grid(case);
    assert_eq!(rows.len(), ROWS.len());
    let cell = (Z_FROM - Z_TO) / (Z_STEPS - 1) as f64;
    for (row, (z, approach, retract)) in rows.iter().enumerate() {
        let at_row: Vec<&(usize, String, f64)> = grazings.iter().filter(|g| g.0 == row).collect();
        assert!(at_row.len() >= 2, "{case} row {row}: {at_row:?}");
        for (sweep, impacts) in [("approach", approach), ("retract", retract)] {
            let found = changes(z, impacts);
            for change in &found {
                assert!(
                    at_row.iter().any(|g| (g.2 - change).abs() <= cell),
                    "{case} A0 = {} nm {sweep}: impacts change at {change} nm, no continued G_n within {cell} nm: {at_row:?}",
                    ROWS[row]
                );
            }
            for g in &at_row {
                if g.2 > Z_TO + cell && g.2 < Z_FROM - cell {
                    assert!(
                        found.iter().any(|change| (g.2 - change).abs() <= cell),
                        "{case} A0 = {} nm {sweep}: {} at {} nm has no change within {cell} nm: {found:?}",
                        ROWS[row],
                        g.1,
                        g.2
                    );
                }
            }
        }
    }
}

#[test]
fn grid_boundaries_lie_within_one_cell_of_the_continued_curves_on_mica() {
    check("biolever-mica");
}

#[test]
fn grid_boundaries_lie_within_one_cell_of_the_continued_curves_on_the_soft_sample() {
    check("biolever-soft");
}
