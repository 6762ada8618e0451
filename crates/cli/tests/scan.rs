//! `drumroll scan` as a user runs it: outputs (CSV columns, JSON pixels, the figure) and bad
//! input (clear errors naming the option or the file and field; no output file left behind).

mod common;
use common::{drumroll, json_of, number, stdout_on_threads};

#[test]
fn the_paper_line_reads_the_film_lower_than_it_is_in_csv_json_and_figure() {
    let pixels_json = json_of(&["scan", "--pixels", "4"]);
    let pixels = pixels_json["pixels"].as_array().expect("pixels");
    assert_eq!(pixels.len(), 4);
    // Over mica the first pixel reads 0 exactly (its own reference); the film (6 nm high)
    // reads its height plus the difference of its setpoint separation from mica's, which the
    // film's softness makes negative.
    assert_eq!(number(&pixels[0], "height_nm"), 0.0);
    let film = &pixels[1];
    assert_eq!(film["sample"], "purple-membrane-film");
    let expected = 6.0 + number(film, "z_nm") - number(&pixels[0], "z_nm");
    assert!((number(film, "height_nm") - expected).abs() < 1e-12);
    assert!(number(film, "height_error_nm") < 0.0);
    assert_eq!(film["jumped"], false);

    let directory = tempfile::tempdir().expect("temporary directory");
    let csv = directory.path().join("scan.csv");
    let figure = directory.path().join("scan.svg");
    let output = drumroll()
        .args(["scan", "--pixels", "4", "--direction", "both", "--out"])
        .arg(&csv)
        .arg("--plot")
        .arg(&figure)
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = std::fs::read_to_string(&csv).expect("CSV");
    let mut lines = text.lines();
    let header = lines.next().expect("header");
    assert!(header.starts_with("direction,index,x_nm,sample,height_true_nm,height_nm"));
    assert!(header.ends_with("harmonic_4_amplitude_nm,harmonic_4_phase_deg"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 8);
    assert!(rows[..4].iter().all(|r| r.starts_with("trace,")));
    assert!(rows[4..].iter().all(|r| r.starts_with("retrace,")));
    let columns = header.split(',').count();
    assert!(rows.iter().all(|r| r.split(',').count() == columns));
    let svg = std::fs::read_to_string(&figure).expect("figure");
    assert!(svg.contains("<svg") && svg.contains("impacts per period"));
}

#[test]
fn bad_input_names_the_option_or_the_field_and_writes_nothing() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let out = directory.path().join("never.csv");
    let bad_line = directory.path().join("bad.json");
    std::fs::write(
        &bad_line,
        r#"{"segments": [{"from_nm": 0, "to_nm": 10, "height_nm": 0, "sample": "mica"},
                         {"from_nm": 11, "to_nm": 20, "height_nm": 1, "sample": "mica"}]}"#,
    )
    .expect("line file");
    let bad_line = bad_line.to_str().expect("utf-8 path");
    let cases: [(&[&str], &str); 7] = [
        (&["--setpoint", "1.2"], "--setpoint"),
        (&["--pixels", "0"], "--pixels"),
        (&["--line", "no-such-line"], "membrane-patch"),
        (&["--line", bad_line], "segments[1].from_nm"),
        (&["--feedback", "pi", "--gain-p", "-1"], "--gain-p"),
        // Too fast for one drive cycle per pixel: named as the option, not the library's field.
        (
            &["--feedback", "pi", "--scan-rate", "1e7"],
            "--scan-rate 10000000: allowed a rate giving at least one drive cycle per pixel",
        ),
        (&["--harmonics", "50"], "--harmonics"),
    ];
    for (args, expected) in cases {
        let output = drumroll()
            .arg("scan")
            .args(args)
            .arg("--out")
            .arg(&out)
            .output()
            .expect("runs");
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out.exists(), "{args:?} left {}", out.display());
    }
}

#[test]
fn a_raster_scans_every_row_and_draws_the_images() {
    // The round membrane patch: every row of 4 pixels, the film where the row crosses it,
    // and the three images in one PNG.
    let directory = tempfile::tempdir().expect("temporary directory");
    let image = directory.path().join("disc.png");
    let disc = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/rasters/membrane-disc.json"
    );
    let value = json_of(&[
        "scan",
        "--raster",
        disc,
        "--pixels",
        "4",
        "--plot",
        image.to_str().unwrap(),
    ]);
    let pixels = value["pixels"].as_array().expect("pixels");
    assert_eq!(pixels.len(), 9 * 4);
    for pixel in pixels {
        let y = number(pixel, "y_nm");
        assert_eq!(y, 50.0 * number(pixel, "row"));
        // On the disc (radius 150 nm about (200, 200)) the sample is the film.
        let (x, r) = (number(pixel, "x_nm"), 150.0);
        let inside = (x - 200.0).powi(2) + (y - 200.0).powi(2) < (r - 30.0) * (r - 30.0);
        if inside {
            assert_eq!(pixel["sample"], "purple-membrane-film", "{pixel}");
        }
    }
    let bytes = std::fs::read(&image).expect("image");
    assert_eq!(&bytes[1..4], b"PNG");

    // Rows of different lengths are refused, naming the row.
    let bad = directory.path().join("bad.json");
    std::fs::write(
        &bad,
        r#"{"row_spacing_nm": 10, "rows": [
            {"segments": [{"from_nm": 0, "to_nm": 10, "height_nm": 0, "sample": "mica"}]},
            {"segments": [{"from_nm": 0, "to_nm": 20, "height_nm": 0, "sample": "mica"}]}]}"#,
    )
    .expect("raster");
    let output = drumroll()
        .args(["scan", "--raster", bad.to_str().unwrap()])
        .output()
        .expect("runs");
    assert_eq!(output.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&output.stderr).contains("rows[1]"));
}

/// A raster of four rows: two flat mica rows and two whose right half is the humid mica of
/// a capillary meniscus, where the ideal feedback cannot hold `A/A0 = 0.8` (its approach
/// branch has no stable orbit there).
const RASTER_WITH_FAILING_ROWS: &str = r#"{"row_spacing_nm": 10, "rows": [
    {"segments": [{"from_nm": 0, "to_nm": 100, "height_nm": 0, "sample": "mica"}]},
    {"segments": [{"from_nm": 0, "to_nm": 50, "height_nm": 0, "sample": "mica"},
                  {"from_nm": 50, "to_nm": 100, "height_nm": 0, "sample": "mica-humid"}]},
    {"segments": [{"from_nm": 0, "to_nm": 100, "height_nm": 2, "sample": "soft"}]},
    {"segments": [{"from_nm": 0, "to_nm": 50, "height_nm": 0, "sample": "mica"},
                  {"from_nm": 50, "to_nm": 100, "height_nm": 0, "sample": "mica-humid"}]}]}"#;

#[test]
fn raster_rows_run_in_parallel_as_the_lines_run_alone_and_the_first_failing_row_is_named() {
    // Every row of a raster is the scan of its line alone (the rows are independent), on one
    // thread and on several (the rows, and a line's materials, run in parallel: the bytes
    // must not depend on it).
    let directory = tempfile::tempdir().expect("temporary directory");
    let step = r#"{"segments": [{"from_nm": 0, "to_nm": 60, "height_nm": 0, "sample": "mica"},
        {"from_nm": 60, "to_nm": 120, "height_nm": 3, "sample": "soft"}]}"#;
    let line = directory.path().join("step.json");
    std::fs::write(&line, step).expect("line file");
    let raster = directory.path().join("raster.json");
    std::fs::write(
        &raster,
        format!(r#"{{"row_spacing_nm": 25, "rows": ["step.json", {step}, "step.json"]}}"#),
    )
    .expect("raster file");
    for feedback in ["ideal", "pi"] {
        let options = ["--feedback", feedback, "--pixels", "5", "--json", "-q"];
        // The line alone, whose materials' branches are computed in parallel: the same bytes
        // on one thread and on two.
        let line_args = [&["scan", "--line", line.to_str().unwrap()][..], &options].concat();
        let line_outputs: Vec<Vec<u8>> = ["1", "2"]
            .iter()
            .map(|threads| stdout_on_threads(threads, &line_args))
            .collect();
        assert_eq!(
            line_outputs[0], line_outputs[1],
            "{feedback}: the line alone"
        );
        let alone: serde_json::Value = serde_json::from_slice(&line_outputs[0]).expect("JSON");
        let alone = alone["pixels"].as_array().expect("pixels");
        let raster_args = [
            &["scan", "--raster", raster.to_str().unwrap()][..],
            &options,
        ]
        .concat();
        let outputs: Vec<Vec<u8>> = ["1", "2", "3"]
            .iter()
            .map(|threads| stdout_on_threads(threads, &raster_args))
            .collect();
        assert_eq!(outputs[0], outputs[1], "{feedback}: 1 and 2 threads");
        assert_eq!(outputs[0], outputs[2], "{feedback}: 1 and 3 threads");
        let value: serde_json::Value = serde_json::from_slice(&outputs[0]).expect("JSON");
        let pixels = value["pixels"].as_array().expect("pixels");
        assert_eq!(pixels.len(), 3 * alone.len());
        for (index, pixel) in pixels.iter().enumerate() {
            let (row, column) = (index / alone.len(), index % alone.len());
            assert_eq!(number(pixel, "row"), row as f64);
            let mut pixel = pixel.clone();
            let fields = pixel.as_object_mut().expect("pixel object");
            fields.remove("row");
            fields.remove("y_nm");
            assert_eq!(
                &pixel, &alone[column],
                "{feedback}: row {row}, pixel {column}"
            );
        }
    }

    // Rows 1 and 3 fail; the error names row 1 however many threads ran, and nothing is
    // printed on standard output.
    let failing = directory.path().join("failing.json");
    std::fs::write(&failing, RASTER_WITH_FAILING_ROWS).expect("raster file");
    for threads in ["1", "2", "3"] {
        let output = drumroll()
            .env("RAYON_NUM_THREADS", threads)
            .args([
                "scan",
                "--raster",
                failing.to_str().unwrap(),
                "--pixels",
                "4",
            ])
            .output()
            .expect("runs");
        assert_eq!(output.status.code(), Some(1), "{threads} threads");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains("row 1 of --raster"),
            "{threads} threads: {stderr}"
        );
        assert!(stderr.contains("mica-humid"), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(output.stdout.is_empty(), "{threads} threads printed output");
    }
}

#[test]
fn a_failing_material_is_named_where_the_scan_first_reaches_it() {
    // Mica, then the strong van der Waals polymer (an air sample: under the liquid MAClever of
    // the default case its branch does not start), then humid mica (A/A0 = 0.8 lies in a jump
    // of its approach). Both failing branches are computed in parallel before the first pixel;
    // the error is the one a serial scan meets first: the polymer on a trace, the humid mica
    // on a retrace, on any number of threads, with the sample named.
    let directory = tempfile::tempdir().expect("temporary directory");
    let line = directory.path().join("two-failing.json");
    std::fs::write(
        &line,
        r#"{"segments": [{"from_nm": 0, "to_nm": 30, "height_nm": 0, "sample": "mica"},
            {"from_nm": 30, "to_nm": 60, "height_nm": 0, "sample": "polymer-strong-vdw"},
            {"from_nm": 60, "to_nm": 90, "height_nm": 0, "sample": "mica-humid"}]}"#,
    )
    .expect("line file");
    for (direction, failing) in [("trace", "polymer-strong-vdw"), ("retrace", "mica-humid")] {
        for threads in ["1", "2"] {
            let output = drumroll()
                .env("RAYON_NUM_THREADS", threads)
                .args(["scan", "--line", line.to_str().unwrap(), "--pixels", "6"])
                .args(["--direction", direction])
                .output()
                .expect("runs");
            assert_eq!(
                output.status.code(),
                Some(1),
                "{direction}, {threads} threads"
            );
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert!(
                stderr.contains(&format!("A/A0 = 0.8 on sample `{failing}` not reached")),
                "{direction}, {threads} threads: {stderr}"
            );
            assert!(!stderr.contains("panicked"), "{stderr}");
            assert!(output.stdout.is_empty());
        }
    }
}
