//! `drumroll continue` deep into the sample (issue 21, defect 3): the MAClever on mica
//! (experiment's drive) from first contact to Z = -19 nm, where the tip ends up in contact
//! throughout the period. Only true special points are labelled (no `neutral-saddle`: a pair
//! of real multipliers with product 1 is no bifurcation), the entry into permanent contact has
//! its own name, and the table, the JSON and the CSV agree on every impact count, checked
//! against a plain time-domain run of a permanent-contact orbit.

mod common;
use common::drumroll;

use afm::{builtin_case, Separation, TappingModel};
use hybrid::{flow_map, HybridSystem, Sensitivity, Settings};
use serde_json::Value;

/// Every label `continue` may print (docs/output-schema.md), besides `G<n>`.
const LABELS: [&str; 9] = [
    "fold",
    "period-doubling",
    "neimark-sacker",
    "merge",
    "split",
    "permanent-contact",
    "lift-off",
    "impact-vanish",
    "impact-appear",
];

fn number(value: &Value) -> f64 {
    value.as_f64().expect("a number")
}

#[test]
fn deep_in_the_sample_labels_and_impact_counts_agree_everywhere() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let csv = directory.path().join("branch.csv");
    let args = [
        "continue",
        "--case",
        "maclever-mica-experiment",
        "--min-amplitude-ratio",
        "0",
        "--floor",
        "-19",
    ];
    let output = drumroll()
        .args(args)
        .args(["--json", "--csv", csv.to_str().expect("utf-8 path")])
        .output()
        .expect("runs");
    assert!(output.status.success());
    let diagram: Value = serde_json::from_slice(&output.stdout).expect("JSON");
    let points = diagram["points"].as_array().expect("points");
    let special = diagram["special_points"]
        .as_array()
        .expect("special points");

    // Only documented labels.
    for s in special {
        let label = s["label"].as_str().expect("label");
        let grazing = label
            .strip_prefix('G')
            .is_some_and(|n| n.parse::<u32>().is_ok());
        assert!(
            grazing || LABELS.contains(&label),
            "undocumented label {label}"
        );
    }

    // The branch ends in permanent contact: every gap minimum negative, no free flight. A
    // plain time-domain run from its last orbit crosses the surface nowhere over 3 periods
    // and stays below it: one impact per period (a maximal interval with d < 0), as JSON says.
    let last = points.last().expect("a last point");
    assert!(number(&last["z_nm"]) < -18.0);
    let mut model =
        TappingModel::from_case(&builtin_case("maclever-mica-experiment").expect("case"))
            .expect("model");
    model
        .set_separation(Separation::Constant(number(&last["z_nm"])))
        .expect("separation");
    let state: Vec<f64> = last["state"]
        .as_array()
        .expect("state")
        .iter()
        .map(number)
        .collect();
    let run = flow_map(
        &model,
        0.0,
        &state,
        3.0 * model.period_us(),
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("time domain");
    assert!(run.events.is_empty(), "no crossing of the surface");
    assert!(model.switching(0, 0.0, &state) < 0.0, "in contact at t = 0");
    assert_eq!(last["impacts_per_orbit"], 1);
    assert_eq!(last["impacts_per_period"], 1.0);
    let into_contact: Vec<&Value> = special
        .iter()
        .filter(|s| s["label"] == "permanent-contact")
        .collect();
    assert_eq!(into_contact.len(), 1, "one entry into permanent contact");
    assert_eq!(
        (
            &into_contact[0]["impacts_before"],
            &into_contact[0]["impacts_after"]
        ),
        (&Value::from(1), &Value::from(1))
    );

    // A special point that does not change the impact count (fold, period doubling, ...)
    // has the count of the branch points on both sides of it, when those two agree.
    let distance = |s: &Value, p: &Value| {
        (number(&s["z_nm"]) - number(&p["z_nm"]))
            .hypot(number(&s["amplitude_ratio"]) - number(&p["amplitude_ratio"]))
    };
    let mut checked = 0;
    for s in special {
        if s["impacts_before"] != s["impacts_after"] {
            continue;
        }
        let mut nearest: Vec<&Value> = points.iter().collect();
        nearest.sort_by(|a, b| distance(s, a).total_cmp(&distance(s, b)));
        if nearest[0]["impacts_per_orbit"] == nearest[1]["impacts_per_orbit"] {
            assert_eq!(
                s["impacts_before"], nearest[0]["impacts_per_orbit"],
                "{} at Z = {}",
                s["label"], s["z_nm"]
            );
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked} special points checked");

    // The CSV has the JSON's numbers for the same points.
    let text = std::fs::read_to_string(&csv).expect("CSV");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = |name: &str| header.iter().position(|c| *c == name).expect("column");
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), points.len());
    for (row, point) in rows.iter().zip(points) {
        let impacts: u64 = row[column("impacts_per_orbit")].parse().expect("integer");
        assert_eq!(Some(impacts), point["impacts_per_orbit"].as_u64());
    }

    // The table prints the same special points with the same counts, in the same order.
    let table = drumroll().args(args).output().expect("runs");
    let table = String::from_utf8(table.stdout).expect("utf-8");
    let rows: Vec<&str> = table.lines().skip(2).collect();
    assert_eq!(rows.len(), special.len());
    for (row, s) in rows.iter().zip(special) {
        let fields: Vec<&str> = row.split_whitespace().collect();
        assert_eq!(fields[0], s["label"].as_str().expect("label"));
        assert_eq!(fields[4], s["impacts_before"].to_string());
        assert_eq!(fields[6], s["impacts_after"].to_string());
    }
}
