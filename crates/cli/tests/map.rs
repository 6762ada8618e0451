//! `drumroll map`: the regime map's curves against independent `drumroll continue` runs, its
//! figure, and its refusal of bad input.

mod common;
use common::{drumroll, json_of, number, stdout_on_threads};

use serde_json::Value;

/// The special point `label` of `continue --a0 A0` (Biolever on mica).
fn continue_point(a0: f64, label: &str) -> Value {
    let diagram = json_of(&[
        "continue",
        "--case",
        "biolever-mica",
        "--a0",
        &a0.to_string(),
    ]);
    diagram["special_points"]
        .as_array()
        .expect("special points")
        .iter()
        .find(|p| p["label"] == label)
        .unwrap_or_else(|| panic!("{label} in continue at A0 = {a0}"))
        .clone()
}

/// Over `A0 = 9 .. 11 nm` every curve (G1, G2, G3) holds a point at each range end, each
/// `--at` value and the case's own `A0 = 10`; at those seven values an independent
/// `continue --a0` locates the same grazing within 1e-9 nm in `Z` (plus the precision the
/// diagram reports for its own location: its bracket). At the case's own value the map's points
/// are `continue`'s special points: `Z` as above, `A/A0` and the phase within 1e-6 (the
/// observables of two orbits 1e-9 nm apart; `dA/dZ ~ 1`), and so are the contrast
/// observables: the harmonics' amplitudes and the indentations within 1e-6 nm, the virial and
/// the dissipation within 1e-6 eV (each moves by less than 1 per nm of `Z` there). The CSV
/// written alongside holds the JSON's numbers, the harmonics in their columns.
#[test]
fn map_points_are_the_special_points_of_independent_continue_runs() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let csv = directory.path().join("map.csv");
    let map = json_of(&[
        "map",
        "--csv",
        csv.to_str().expect("utf-8 path"),
        "--case",
        "biolever-mica",
        "--vary",
        "a0",
        "--from",
        "9",
        "--to",
        "11",
        "--at",
        "9.4,9.7,10.3,10.6",
        "--points",
        "8",
    ]);
    assert_eq!(map["parameter"]["name"], "a0");
    assert_eq!(map["parameter"]["unit"], "nm");
    let curves = map["curves"].as_array().expect("curves");
    let labels: Vec<&str> = curves
        .iter()
        .map(|c| c["label"].as_str().unwrap_or(""))
        .collect();
    assert_eq!(labels, ["G1", "G2", "G3"]);
    for curve in curves {
        let label = curve["label"].as_str().expect("label");
        for end in curve["ends"].as_array().expect("ends") {
            assert_eq!(end["reason"], "range-end", "{label}: {end}");
        }
        for a0 in [9.0, 9.4, 9.7, 10.0, 10.3, 10.6, 11.0] {
            let points: Vec<&Value> = curve["points"]
                .as_array()
                .expect("points")
                .iter()
                .filter(|p| number(p, "parameter") == a0)
                .collect();
            assert_eq!(points.len(), 1, "{label} at A0 = {a0}");
            assert_eq!(points[0]["at_fixed_parameter"], true);
            let special = continue_point(a0, label);
            let error = (number(points[0], "z_nm") - number(&special, "z_nm")).abs();
            assert!(
                error <= 1e-9 + number(&special, "precision_nm"),
                "{label} at A0 = {a0}: Z differs by {error:e}"
            );
            if a0 == 10.0 {
                for key in ["amplitude_ratio", "phase_deg"] {
                    let d = (number(points[0], key) - number(&special, key)).abs();
                    assert!(d <= 1e-6, "{label} {key}: {d:e}");
                }
                assert_eq!(points[0]["impacts_before"], special["impacts_before"]);
                assert_eq!(points[0]["impacts_after"], special["impacts_after"]);
                for key in [
                    "dissipated_ev",
                    "virial_ev",
                    "max_indentation_nm",
                    "mean_indentation_nm",
                ] {
                    let d = (number(points[0], key) - number(&special, key)).abs();
                    assert!(d <= 1e-6, "{label} {key}: {d:e}");
                }
                assert!(number(points[0], "energy_balance_residual") <= 1e-9);
                let harmonics = points[0]["harmonics"].as_array().expect("harmonics");
                assert_eq!(harmonics.len(), 4, "the default --harmonics");
                for (ours, theirs) in harmonics
                    .iter()
                    .zip(special["harmonics"].as_array().expect("harmonics"))
                {
                    let d = (number(ours, "amplitude_nm") - number(theirs, "amplitude_nm")).abs();
                    assert!(d <= 1e-6, "{label} harmonic {}: {d:e}", ours["n"]);
                }
            }
        }
    }
    // The CSV: one row per JSON point, curve after curve, the harmonics' cells the JSON's.
    let text = std::fs::read_to_string(&csv).expect("CSV written");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let points: Vec<&Value> = curves
        .iter()
        .flat_map(|c| c["points"].as_array().expect("points"))
        .collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), points.len());
    for (row, point) in rows.iter().zip(&points) {
        for (column, cell) in header.iter().zip(row) {
            let value = match column.strip_prefix("harmonic_") {
                Some(rest) => {
                    let (n, key) = rest.split_once('_').expect("harmonic_<n>_<key>");
                    let n: usize = n.parse().expect("n");
                    point["harmonics"][n - 1][key].clone()
                }
                None if *column == "label" => continue,
                None => point[*column].clone(),
            };
            // Within 2 ulp: the test's JSON parser (serde_json without `float_roundtrip`)
            // may round the printed shortest digits to a neighbouring float.
            if let Some(expected) = value.as_f64() {
                let written = cell.parse::<f64>().expect("a number");
                assert!(
                    (written - expected).abs() <= 4.0 * f64::EPSILON * expected.abs(),
                    "{column}: {written} vs {expected}"
                );
            }
        }
    }
}

/// The figure holds both planes, the region names, the curves' labels; the closed fold curve
/// of the MAClever on mica over `Q_1` is shaded (bistable) and its two cusps are marked.
#[test]
fn the_plot_names_regions_shades_the_bistable_area_and_marks_cusps() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let plot = directory.path().join("map.svg");
    let map = json_of(&[
        "map",
        "--case",
        "maclever-mica",
        "--vary",
        "quality-factor-1",
        "--from",
        "1",
        "--to",
        "8",
        "--points",
        "10",
        "--plot",
        plot.to_str().expect("utf-8"),
    ]);
    let fold = map["curves"]
        .as_array()
        .expect("curves")
        .iter()
        .find(|c| c["label"] == "fold")
        .expect("fold curve");
    assert_eq!(fold["ends"][0]["reason"], "closed");
    let cusps: Vec<f64> = map["codim2_points"]
        .as_array()
        .expect("codim-2 points")
        .iter()
        .filter(|p| p["label"] == "cusp")
        .map(|p| number(p, "parameter"))
        .collect();
    assert_eq!(cusps.len(), 2, "{cusps:?}");
    // The codimension-two points carry the contrast observables of their orbit (issue 30):
    // Hertz on mica is conservative, so no energy is dissipated (to 1e-12 eV, MODEL.md
    // section 10), the orbit's energy balance closes to 1e-9, and the first harmonic is the
    // point's A/A0 (A0 = 20 nm, the case's) and phase.
    for point in map["codim2_points"].as_array().expect("codim-2 points") {
        assert!(number(point, "dissipated_ev").abs() < 1e-12, "{point}");
        assert!(number(point, "energy_balance_residual") < 1e-9, "{point}");
        assert!(number(point, "virial_ev").is_finite());
        assert!(number(point, "max_indentation_nm") >= number(point, "mean_indentation_nm"));
        let harmonics = point["harmonics"].as_array().expect("harmonics");
        assert_eq!(harmonics.len(), 4);
        let first = &harmonics[0];
        assert!(
            (number(first, "amplitude_nm") / 20.0 - number(point, "amplitude_ratio")).abs() < 1e-12
        );
        assert_eq!(number(first, "phase_deg"), number(point, "phase_deg"));
        assert_eq!(point["state"].as_array().expect("state").len(), 4);
    }
    let svg = std::fs::read_to_string(&plot).expect("svg");
    for text in [
        "1 impact",
        "no impact",
        "cusp",
        "fold",
        "G1",
        "A/A0",
        "Z (nm)",
        "<polygon",
    ] {
        assert!(svg.contains(text), "{text} missing from the figure");
    }
    assert!(!directory.path().join("map.svg.partial").exists());
}

#[test]
fn bad_input_is_refused_with_a_message_naming_the_option() {
    let cases: [(&[&str], &str); 9] = [
        (
            &["--vary", "mass", "--from", "5", "--to", "20"],
            "a0, drive-frequency, sample-modulus, tip-radius, quality-factor-N, stiffness-N",
        ),
        (
            &["--vary", "stiffness-4", "--from", "1", "--to", "2"],
            "--vary",
        ),
        (&["--vary", "a0", "--from", "-1", "--to", "20"], "--from"),
        (&["--vary", "a0", "--from", "5", "--to", "2e5"], "--to"),
        (&["--vary", "a0", "--from", "20", "--to", "5"], "--to"),
        (
            &["--vary", "a0", "--from", "5", "--to", "20", "--at", "30"],
            "--at",
        ),
        (
            &["--vary", "a0", "--from", "12", "--to", "20"],
            "`--from/--to` = 12 .. 20 is invalid; allowed: a range that contains the case's own a0 = 10",
        ),
        (
            &[
                "--vary", "a0", "--from", "5", "--to", "20", "--labels", "G9",
            ],
            "--labels G9",
        ),
        (
            &[
                "--vary",
                "a0",
                "--from",
                "5",
                "--to",
                "20",
                "--harmonics",
                "0",
            ],
            "--harmonics",
        ),
    ];
    for (args, message) in cases {
        let output = drumroll().arg("map").args(args).output().expect("runs");
        assert!(!output.status.success(), "{args:?} succeeded");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(message), "{args:?}: stderr was {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    }
}

/// A grid file in `drumroll grid`'s format (docs/output-schema.md) is drawn as cells under
/// the curves: one rectangle per cell, in the tint of its impact count, grey where bistable;
/// a grid over another parameter is refused naming `--grid-file`.
#[test]
fn grid_file_cells_are_drawn_under_the_curves() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let grid = directory.path().join("grid.jsonl");
    let header = r#"{"case":"biolever-mica","parameter":{"name":"a0","unit":"nm","from":9.9,"to":10.1,"values":[9.9,10.1]},"z_nm":[10.5,8.0]}"#;
    let row = |r: usize, p: f64| {
        format!(
            r#"{{"row":{r},"parameter_value":{p},"first_contact_z_nm":10.0,"cells":[{{"z_nm":10.5,"approach":{{"amplitude_ratio":1.0,"phase_deg":92.0,"multiplicity":1,"impacts_per_orbit":0,"impacts_per_period":0.0,"stable":true,"converged":true}}}},{{"z_nm":8.0,"approach":{{"amplitude_ratio":0.8,"phase_deg":84.0,"multiplicity":1,"impacts_per_orbit":2,"impacts_per_period":2.0,"stable":true,"converged":true}},"bistable":true}}]}}"#
        )
    };
    std::fs::write(
        &grid,
        format!("{header}\n{}\n{}\n", row(0, 9.9), row(1, 10.1)),
    )
    .expect("grid");
    let plot = directory.path().join("map.svg");
    let args = [
        "map", "--vary", "a0", "--from", "9.9", "--to", "10.1", "--points", "4", "--labels", "G2",
    ];
    let output = drumroll()
        .args(args)
        .args(["--plot", plot.to_str().expect("utf-8")])
        .args(["--grid-file", grid.to_str().expect("utf-8")])
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let svg = std::fs::read_to_string(&plot).expect("svg");
    // Four cells in each of the two planes: two tinted by their impacts, two grey.
    assert_eq!(svg.matches("opacity=\"0.25\"").count(), 4, "tinted cells");
    assert_eq!(
        svg.matches("fill=\"#969696\"").count(),
        4,
        "bistable cells in grey"
    );
    let other = directory.path().join("other.jsonl");
    std::fs::write(&other, header.replace("\"a0\"", "\"tip-radius\"")).expect("grid");
    let output = drumroll()
        .args(args)
        .args(["--plot", plot.to_str().expect("utf-8")])
        .args(["--grid-file", other.to_str().expect("utf-8")])
        .output()
        .expect("runs");
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("--grid-file") && stderr.contains("tip-radius"),
        "{stderr}"
    );
}

/// The curves are continued in parallel (rayon) with the result of the serial loop: the
/// bimodal Biolever's folds and period doublings over `A0 = 10 .. 11 nm` give the same bytes on
/// one thread and on two (`RAYON_NUM_THREADS`). Its seed approach has more fold and
/// period-doubling points than the map has curves (`continue` finds ten; the curves of two
/// pairs pass through both points of the pair at the case's own `A0 = 10`, so the second of
/// each pair is skipped), so the parallel run must also skip what the serial one skips.
#[test]
fn map_is_the_same_on_one_thread_and_on_two() {
    let args = [
        "map",
        "--case",
        "biolever-mica-bimodal",
        "--vary",
        "a0",
        "--from",
        "10",
        "--to",
        "11",
        "--points",
        "4",
        "--labels",
        "fold,period-doubling",
        "--json",
    ];
    let on = |threads: &str| stdout_on_threads(threads, &args);
    let one = on("1");
    assert!(one == on("2"), "the maps on 1 and 2 threads differ");
    let map: Value = serde_json::from_slice(&one).expect("one JSON object");
    let seeds = json_of(&["continue", "--case", "biolever-mica-bimodal"])["special_points"]
        .as_array()
        .expect("special points")
        .iter()
        .filter(|p| p["label"] == "fold" || p["label"] == "period-doubling")
        .count();
    let curves = map["curves"].as_array().expect("curves").len();
    assert!(
        curves < seeds,
        "{curves} curves from {seeds} seeds: none skipped"
    );
}
