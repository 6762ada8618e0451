//! `drumroll continue` run as a user runs it: the real binary's JSON, CSV and SVG outputs,
//! checked against numbers computed independently of the continuation (the regression
//! fixtures of the grazing points, confirmed in the time domain by `tests/grazing_points.rs`;
//! the free solution's first contact; plain time-domain runs from the reported orbit states),
//! bad options refused with a message naming the option and its range, and the MAClever on
//! mica's hysteresis between its two folds.

use afm::{builtin_case, state_distance, Separation, TappingModel};
use assert_cmd::Command;
use hybrid::{flow_map, Direction, Sensitivity, Settings};
use serde_json::Value;

fn drumroll() -> Command {
    Command::cargo_bin("drumroll").expect("binary built")
}

/// Run `drumroll continue <args>` and parse its standard output as one JSON object.
fn continue_json(args: &[&str]) -> Value {
    let output = drumroll()
        .arg("continue")
        .args(args)
        .arg("--json")
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("one JSON object")
}

fn number(value: &Value) -> f64 {
    value.as_f64().expect("a number")
}

fn model(case: &str) -> TappingModel {
    TappingModel::from_case(&builtin_case(case).expect("built-in case")).expect("model")
}

/// A plain time-domain run (no Newton) of `periods` periods at `z_nm` from `x0`: the impacts
/// (onsets of contact) in the last period, the final state and `|x(nT) - x((n-1)T)|`.
fn time_domain(
    model: &TappingModel,
    z_nm: f64,
    x0: &[f64],
    periods: usize,
) -> (usize, Vec<f64>, f64) {
    let mut model = model.clone();
    model
        .set_separation(Separation::Constant(z_nm))
        .expect("finite");
    let settings = Settings::default();
    let period = model.period_us();
    let settled = flow_map(
        &model,
        0.0,
        x0,
        (periods - 1) as f64 * period,
        Sensitivity::None,
        &settings,
    )
    .expect("transient")
    .state;
    let last =
        flow_map(&model, 0.0, &settled, period, Sensitivity::None, &settings).expect("last period");
    let impacts = last
        .events
        .iter()
        .filter(|e| e.surface == 0 && e.direction == Direction::Down)
        .count();
    let drift = state_distance(&last.state, &settled);
    (impacts, last.state, drift)
}

fn state_of(point: &Value) -> Vec<f64> {
    point["state"]
        .as_array()
        .expect("state")
        .iter()
        .map(number)
        .collect()
}

#[test]
fn json_has_the_documented_fields_and_the_fixtures_grazing_points() {
    let diagram = continue_json(&["--case", "biolever-mica"]);
    let points = diagram["points"].as_array().expect("points");
    let special = diagram["special_points"]
        .as_array()
        .expect("special_points");
    // The size: several hundred points per diagram.
    assert!(points.len() >= 300, "{} points", points.len());
    for point in points {
        for key in [
            "z_nm",
            "amplitude_ratio",
            "phase_deg",
            "impacts_per_period",
            "stable",
        ] {
            assert!(point.get(key).is_some(), "point without `{key}`");
        }
    }
    for s in special {
        for key in [
            "label",
            "z_nm",
            "amplitude_ratio",
            "phase_deg",
            "impacts_before",
            "impacts_after",
            "precision_nm",
            "converged",
        ] {
            assert!(s.get(key).is_some(), "special point without `{key}`");
        }
        assert_eq!(s["converged"], true);
        assert!(number(&s["precision_nm"]) < 1e-9, "{s}");
    }
    // The special points are the regression fixture's (time-domain confirmed; 1e-8 nm: the
    // location precision 1e-9 nm with a factor 10 for a recomputation along other points).
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/grazing");
    let fixture: Value = serde_json::from_str(
        &std::fs::read_to_string(format!("{root}/biolever-mica.json")).expect("fixture"),
    )
    .expect("fixture JSON");
    let expected = fixture["special_points"].as_array().expect("list");
    assert_eq!(special.len(), expected.len());
    for (s, f) in special.iter().zip(expected) {
        assert_eq!(s["label"], f["label"]);
        assert_eq!(s["impacts_before"], f["impacts_before"]);
        assert_eq!(s["impacts_after"], f["impacts_after"]);
        assert!(
            (number(&s["z_nm"]) - number(&f["z_nm"])).abs() < 1e-8,
            "{s} vs {f}"
        );
    }
    // G1 is the free solution's first contact (to 1e-9 nm, the tolerance), which the
    // output also reports.
    let first_contact = model("biolever-mica").grazing_separation_nm();
    assert!((number(&diagram["first_contact_z_nm"]) - first_contact).abs() < 1e-12);
    assert!((number(&special[0]["z_nm"]) - first_contact).abs() < 1e-9);
    // One branch point in each impact regime is confirmed by the time domain from its state
    // (60 periods: transients decay by exp(-pi/Q_1) = 0.07 per period or faster).
    let m = model("biolever-mica");
    for n in 0..=3 {
        let point = points
            .iter()
            .find(|p| {
                p["impacts_per_orbit"] == n
                    && p["stable"] == true
                    && p["gap_minima"]
                        .as_array()
                        .expect("gap minima")
                        .iter()
                        .all(|g| number(&g["gap_nm"]).abs() > 1e-2)
            })
            .unwrap_or_else(|| panic!("a point with {n} impacts away from grazing"));
        let (impacts, _, drift) = time_domain(&m, number(&point["z_nm"]), &state_of(point), 60);
        assert_eq!(impacts, n, "time domain at Z = {}", point["z_nm"]);
        assert!(drift < 1e-8, "settled on a period-1 orbit: drift {drift}");
    }
}

#[test]
fn csv_and_svg_are_written_whole() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let csv = dir.path().join("diagram.csv");
    let svg = dir.path().join("diagram.svg");
    let diagram = continue_json(&[
        "--case",
        "maclever-soft",
        "--csv",
        csv.to_str().expect("utf-8 path"),
        "--plot",
        svg.to_str().expect("utf-8 path"),
    ]);
    let points = diagram["points"].as_array().expect("points");
    let text = std::fs::read_to_string(&csv).expect("CSV written");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    for column in [
        "direction",
        "z_nm",
        "amplitude_ratio",
        "phase_deg",
        "impacts_per_period",
        "stable",
    ] {
        assert!(header.contains(&column), "CSV header lacks `{column}`");
    }
    let column = |name: &str| header.iter().position(|c| *c == name).expect("column");
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), points.len(), "one row per branch point");
    for (row, point) in rows.iter().zip(points) {
        assert_eq!(row.len(), header.len());
        assert_eq!(row[column("direction")], "approach");
        // Both print f64 in shortest round-trip form; serde_json's default parser (without
        // `float_roundtrip`) may be off by an ulp or two: 1e-15 relative.
        let same = |a: f64, b: f64| (a - b).abs() <= 1e-15 * a.abs().max(b.abs());
        let z: f64 = row[column("z_nm")].parse().expect("a number");
        assert!(same(z, number(&point["z_nm"])), "{z} vs {}", point["z_nm"]);
        let ratio: f64 = row[column("amplitude_ratio")].parse().expect("a number");
        assert!(same(ratio, number(&point["amplitude_ratio"])), "{ratio}");
        let impacts: f64 = row[column("impacts_per_period")].parse().expect("a number");
        assert_eq!(impacts, number(&point["impacts_per_period"]));
        let impacts: u64 = row[column("impacts_per_orbit")]
            .parse()
            .expect("an integer");
        assert_eq!(impacts, point["impacts_per_orbit"].as_u64().expect("count"));
        let stable: bool = row[column("stable")].parse().expect("true or false");
        assert_eq!(stable, point["stable"] == true);
    }
    let svg_text = std::fs::read_to_string(&svg).expect("SVG written");
    assert!(svg_text.trim_start().starts_with("<svg") || svg_text.starts_with("<?xml"));
    assert!(svg_text.trim_end().ends_with("</svg>"), "a whole SVG");
    assert!(svg_text.contains("G2"), "the special points are marked");
}

#[test]
fn bad_options_are_refused_with_a_message_naming_the_option_and_its_range() {
    let cases: [(&[&str], &[&str]); 6] = [
        // First contact of the Biolever is 10.0115 nm: a floor above it is refused.
        (
            &["--case", "biolever-mica", "--floor", "12"],
            &["--floor 12: allowed [-10, 10.011526"],
        ),
        // A floor deeper than -A0 (-10 nm) is refused: Hertz contact is long invalid there and
        // the branch would run through ever more impacts.
        (
            &["--case", "biolever-mica", "--floor", "-11"],
            &["--floor -11", "allowed [-10,"],
        ),
        (
            &["--case", "biolever-mica", "--min-amplitude-ratio", "2"],
            &["--min-amplitude-ratio 2: allowed [0, 1)"],
        ),
        (
            &["--case", "biolever-mica", "--max-step", "0"],
            &["--max-step 0: allowed [1e-7, 10] nm"],
        ),
        // Below 1e-7 nm the first step (a tenth of it) would fall below the continuation's
        // smallest step: named as the option's range, not as an internal setting.
        (
            &["--case", "biolever-mica", "--max-step", "1e-9"],
            &["--max-step 1e-9: allowed [1e-7, 10] nm"],
        ),
        (
            &["--case", "biolever-mica", "--csv", "diagram.txt"],
            &["--csv"],
        ),
    ];
    for (args, messages) in cases {
        let output = drumroll()
            .arg("continue")
            .args(args)
            .output()
            .expect("runs");
        assert!(!output.status.success(), "{args:?} should fail");
        let stderr = String::from_utf8_lossy(&output.stderr);
        for message in messages {
            assert!(stderr.contains(message), "{args:?}: stderr was {stderr}");
        }
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    }
}

#[test]
fn maclever_on_mica_retract_reports_the_bistable_range_between_the_folds() {
    let diagram = continue_json(&["--case", "maclever-mica", "--retract"]);
    // Each fold's Z and stated precision (its bracket's width, nm).
    let folds_of = |branch: &Value| -> Vec<(f64, f64)> {
        branch["special_points"]
            .as_array()
            .expect("special points")
            .iter()
            .filter(|s| s["label"] == "fold")
            .map(|s| (number(&s["z_nm"]), number(&s["precision_nm"])))
            .collect()
    };
    let folds = folds_of(&diagram);
    assert_eq!(folds.len(), 2, "two folds on the approach");
    let (fold_low, fold_high) = (folds[0].0.min(folds[1].0), folds[0].0.max(folds[1].0));
    // The retract meets the same folds, located independently along its own points: each
    // within the two locations' stated precisions of the approach's (half of each bracket,
    // which carries the located orbit's own Newton error), and within 2e-9 nm.
    let retract_folds = folds_of(&diagram["retract"]);
    assert_eq!(retract_folds.len(), 2);
    for (z, precision) in retract_folds {
        let (z_a, precision_a) = folds
            .iter()
            .copied()
            .min_by(|a, b| (a.0 - z).abs().total_cmp(&(b.0 - z).abs()))
            .expect("a fold");
        let stated = 0.5 * (precision + precision_a);
        assert!(
            (z - z_a).abs() <= stated && stated < 2e-9,
            "retract fold at {z} nm (precision {precision:.1e}) against the approach's {z_a} \
             nm ({precision_a:.1e})"
        );
    }
    let ranges = diagram["bistable_ranges_nm"].as_array().expect("ranges");
    assert_eq!(ranges.len(), 1, "one bistable range: {ranges:?}");
    let (low, high) = (number(&ranges[0][0]), number(&ranges[0][1]));
    // Bracketed by the folds: the range is made of branch points, so it lies inside
    // [fold_low, fold_high] and reaches to within one branch step of each fold (the
    // continuation refines its steps near special points; more than half the interval).
    assert!(
        fold_low <= low && low < high && high <= fold_high,
        "range [{low}, {high}] vs folds [{fold_low}, {fold_high}]"
    );
    assert!(high - low > 0.5 * (fold_high - fold_low));
    // Independently, in the time domain: at the middle of the range, runs started on the two
    // stable orbits of the approach branch (before the first fold, after the second) stay on
    // two different period-1 orbits, each with one impact per period.
    let z = 0.5 * (low + high);
    let points = diagram["points"].as_array().expect("points");
    let first_fold_index = points
        .iter()
        .position(|p| p["stable"] == false)
        .expect("an unstable part between the folds");
    let nearest_stable = |range: &[Value]| -> Vec<f64> {
        let point = range
            .iter()
            .filter(|p| p["stable"] == true)
            .min_by(|a, b| {
                (number(&a["z_nm"]) - z)
                    .abs()
                    .total_cmp(&(number(&b["z_nm"]) - z).abs())
            })
            .expect("a stable point");
        state_of(point)
    };
    let upper = nearest_stable(&points[..first_fold_index]);
    let last_unstable = points
        .iter()
        .rposition(|p| p["stable"] == false)
        .expect("unstable part");
    let lower = nearest_stable(&points[last_unstable + 1..]);
    let m = model("maclever-mica");
    // 400 periods: the slowest multiplier in the range is below 0.98 away from the folds
    // (0.98^400 = 3e-4 of a start within ~0.01 nm of the orbit).
    let (impacts_a, end_a, drift_a) = time_domain(&m, z, &upper, 400);
    let (impacts_b, end_b, drift_b) = time_domain(&m, z, &lower, 400);
    assert!(
        drift_a < 1e-8 && drift_b < 1e-8,
        "drifts {drift_a}, {drift_b}"
    );
    assert_eq!((impacts_a, impacts_b), (1, 1));
    eprintln!(
        "folds [{fold_low}, {fold_high}] nm, bistable range [{low}, {high}] nm; at Z = {z} nm \
         the two runs end {} apart (drifts {drift_a:.1e}, {drift_b:.1e})",
        state_distance(&end_a, &end_b)
    );
    assert!(
        state_distance(&end_a, &end_b) > 1e-2,
        "two distinct orbits at Z = {z} nm: {}",
        state_distance(&end_a, &end_b)
    );
}

/// Run `drumroll continue <args> --json -q`: its exit success, stdout and stderr.
fn continue_lines(args: &[&str]) -> (bool, String, String) {
    let output = drumroll()
        .arg("continue")
        .args(args)
        .args(["--json", "-q"])
        .output()
        .expect("runs");
    (
        output.status.success(),
        String::from_utf8(output.stdout).expect("UTF-8"),
        String::from_utf8(output.stderr).expect("UTF-8"),
    )
}

#[test]
fn several_cases_on_several_threads_print_each_case_as_alone_in_the_order_given() {
    // The reference: each case computed by a run of its own (one thread).
    let alone: Vec<String> = ["biolever-soft", "maclever-soft"]
        .iter()
        .map(|case| {
            let (ok, out, err) = continue_lines(&["--case", case]);
            assert!(ok, "{err}");
            out
        })
        .collect();
    // Given in the reverse of the order they finish in on two threads (the MAClever's diagram
    // is the cheaper), on one thread, two and three (more threads than cases).
    for threads in ["1", "2", "3"] {
        let (ok, out, err) = continue_lines(&[
            "--case",
            "biolever-soft",
            "--case",
            "maclever-soft",
            "--threads",
            threads,
        ]);
        assert!(ok, "{err}");
        assert_eq!(out, alone.concat(), "--threads {threads}");
    }
    let (ok, out, err) = continue_lines(&["--case", "maclever-soft", "--threads", "0"]);
    assert!(!ok && out.is_empty());
    assert!(err.contains("--threads 0: allowed 1 or more"), "{err}");
}

#[test]
fn a_bad_option_for_a_later_case_is_refused_before_any_case_is_computed() {
    // --floor 15 nm is inside the MAClever's range (Z_G1 = 19.999 nm), not the Biolever's
    // (Z_G1 = 10.012 nm): the run stops before printing the MAClever's diagram.
    let (ok, out, err) = continue_lines(&[
        "--case",
        "maclever-soft",
        "--case",
        "biolever-soft",
        "--floor",
        "15",
    ]);
    assert!(!ok);
    assert!(out.is_empty(), "nothing printed: {out}");
    assert!(
        err.contains("case `biolever-soft`") && err.contains("--floor 15: allowed [-10, 10.01"),
        "{err}"
    );
}

#[test]
fn silicon_in_air_locates_each_fold_and_grazing_alike_on_approach_and_retract() {
    // The attractive-repulsive bistability of the silicon cantilever in air: two folds and G1,
    // each met by the approach and again by the retract, located independently along each
    // branch's own points. Next to a fold `M - I` is nearly singular, so an orbit within
    // Newton's residual tolerance can sit 1e-8 nm off in Z (the two locations of the lower
    // fold differed by 3.2e-8 nm while each stated 1e-12): each location must agree with the
    // other within the two stated precisions (half of each bracket), and be converged (to the
    // 1e-9 nm location tolerance).
    let diagram = continue_json(&["--case", "silicon-air-polymer", "--retract"]);
    let located = |branch: &Value| -> Vec<(String, f64, f64, bool)> {
        branch["special_points"]
            .as_array()
            .expect("special points")
            .iter()
            .map(|s| {
                (
                    s["label"].as_str().expect("label").to_string(),
                    number(&s["z_nm"]),
                    number(&s["precision_nm"]),
                    s["converged"].as_bool().expect("converged"),
                )
            })
            .collect()
    };
    let approach = located(&diagram);
    let retract = located(&diagram["retract"]);
    let mut matched = 0;
    for (label, z, precision, converged) in &approach {
        assert!(converged, "approach {label} at {z} nm not converged");
        let Some((_, z_r, precision_r, converged_r)) = retract
            .iter()
            .find(|(l, z_r, _, _)| l == label && (z_r - z).abs() < 1e-6)
        else {
            continue;
        };
        assert!(converged_r, "retract {label} at {z_r} nm not converged");
        let stated = 0.5 * (precision + precision_r);
        assert!(
            (z - z_r).abs() <= stated,
            "{label}: approach {z} nm ({precision:.1e}) against retract {z_r} nm \
             ({precision_r:.1e})"
        );
        matched += 1;
    }
    assert_eq!(
        matched, 3,
        "two folds and G1 on both branches: {approach:?} {retract:?}"
    );
}
