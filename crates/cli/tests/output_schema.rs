//! Every command's output against the schema document, `docs/output-schema.md`: each key the
//! real binary prints is listed there with the type it has, each listed key is printed by some
//! run, and the CSV columns are the JSON keys in the documented order.

mod common;
use common::drumroll;

use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};

/// The schema document's rows: section heading -> (key path -> allowed JSON types).
type Schema = BTreeMap<String, BTreeMap<String, BTreeSet<&'static str>>>;

fn document() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/output-schema.md");
    std::fs::read_to_string(path).expect("docs/output-schema.md")
}

/// The JSON types a documented type admits (`number or null` admits both).
fn allowed(text: &str) -> BTreeSet<&'static str> {
    let mut types = BTreeSet::new();
    for word in text.split(" or ") {
        types.insert(match word.trim() {
            "number" => "number",
            "integer" => "integer",
            "string" => "string",
            "boolean" => "boolean",
            "array" => "array",
            "object" => "object",
            "null" => "null",
            other => panic!("unknown type `{other}` in the schema"),
        });
    }
    types
}

/// The key tables of the document, by the section (`## ...` heading) they stand in.
fn schema(text: &str) -> Schema {
    let mut schema = Schema::new();
    let mut section = String::new();
    for line in text.lines() {
        if let Some(heading) = line.strip_prefix("## ") {
            section = heading.to_string();
            continue;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // `| `key` | type | unit | meaning |`: cells 1 and 2 (cell 0 is before the first bar).
        if cells.len() < 5 || !cells[1].starts_with('`') {
            continue;
        }
        let Some(key) = cells[1].strip_prefix('`').and_then(|k| k.strip_suffix('`')) else {
            continue;
        };
        if section.starts_with("Special point labels") {
            continue;
        }
        schema
            .entry(section.clone())
            .or_default()
            .insert(key.to_string(), allowed(cells[2]));
    }
    schema
}

fn json_type(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "boolean",
        Value::Number(n) if n.is_f64() => "number",
        Value::Number(_) => "integer",
        Value::String(_) => "string",
        Value::Array(_) => "array",
        Value::Object(_) => "object",
    }
}

/// Every key path of `value` under `path` with the types seen there. The keys of the
/// `retract` and `coexisting_orbit` objects are those of the top level (the schema documents
/// them once).
fn flatten(value: &Value, path: &str, seen: &mut BTreeMap<String, BTreeSet<&'static str>>) {
    if !path.is_empty() {
        seen.entry(path.to_string())
            .or_default()
            .insert(json_type(value));
    }
    match value {
        Value::Object(map) => {
            for (key, child) in map {
                let child_path = match path {
                    "" => key.clone(),
                    "retract" | "coexisting_orbit" => key.clone(),
                    _ => format!("{path}.{key}"),
                };
                flatten(child, &child_path, seen);
            }
        }
        Value::Array(items) => {
            for item in items {
                flatten(item, &format!("{path}[]"), seen);
            }
        }
        _ => {}
    }
}

/// The standard output of `drumroll ARGS`, required to succeed.
fn stdout_of(args: &[&str]) -> String {
    let output = drumroll().args(args).output().expect("runs");
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).expect("utf-8")
}

/// Check the outputs of `runs` (each parsed into JSON values) against `section` and the
/// `inputs` section: every key printed is documented with its type, and every key of
/// `section` is printed by one of the runs.
fn check(schema: &Schema, section: &str, runs: &[Vec<Value>]) -> BTreeSet<String> {
    let documented = &schema[section];
    let inputs = &schema["The `inputs` object"];
    let mut seen = BTreeMap::new();
    for run in runs {
        for value in run {
            flatten(value, "", &mut seen);
        }
    }
    for (path, types) in &seen {
        // An array's element objects are documented by their keys (`points[].z_nm`).
        if path.ends_with("[]") && types.len() == 1 && types.contains("object") {
            continue;
        }
        let allowed = documented
            .get(path)
            .or_else(|| inputs.get(path))
            .unwrap_or_else(|| panic!("{section}: `{path}` is printed but not documented"));
        assert!(
            types.is_subset(allowed),
            "{section}: `{path}` is printed as {types:?}, documented as {allowed:?}"
        );
    }
    for path in documented.keys() {
        assert!(
            seen.contains_key(path),
            "{section}: `{path}` is documented but no run printed it"
        );
    }
    seen.into_keys().collect()
}

#[test]
fn every_command_prints_exactly_the_documented_keys_and_types() {
    let schema = schema(&document());
    let one = |args: &[&str]| vec![serde_json::from_str::<Value>(&stdout_of(args)).expect("JSON")];
    let mut printed = BTreeSet::new();

    // simulate: a period-1 orbit with impacts, the period-4 orbit at 72 kHz (a period
    // without gap minimum: `null`), and one found by its amplitude ratio.
    let simulate = [
        one(&[
            "simulate",
            "--case",
            "biolever-mica",
            "--z",
            "8.5",
            "--json",
        ]),
        one(&[
            "simulate",
            "--case",
            "biolever-mica",
            "--drive-frequency",
            "72",
            "--z",
            "0.5",
            "--json",
        ]),
        one(&["simulate", "--amplitude-ratio", "0.9", "--json"]),
        // The acoustic and bimodal drives (MODEL.md section 14: `inputs.drive`, `second_drive`).
        one(&[
            "simulate",
            "--case",
            "biolever-mica-acoustic",
            "--z",
            "9",
            "--json",
        ]),
        one(&[
            "simulate",
            "--case",
            "biolever-mica-bimodal",
            "--z",
            "8",
            "--json",
        ]),
    ];

    // simulate with each contact law's sample file (the inputs' `contact`, `electrostatic`
    // and `hydration` objects, MODEL.md section 9).
    let directory = tempfile::tempdir().expect("temporary directory");
    let laws = [
        r#""contact": {"law": "dmt", "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}"#,
        r#""contact": {"law": "kelvin-voigt", "viscosity_pa_s": 100, "clip": true}"#,
        r#""contact": {"law": "film", "thickness_nm": 6, "correction": "garcia-2018"}"#,
        r#""contact": {"law": "hertz", "tip_shape": "cone", "cone_half_angle_deg": 20}, "electrostatic": {"debye_length_nm": 1, "tip_charge_c_per_m2": 0.02, "sample_charge_c_per_m2": 0.02, "relative_permittivity": 80}"#,
        r#""contact": {"law": "hertz", "tip_shape": "flat-punch", "punch_radius_nm": 2}"#,
        r#""contact": {"law": "standard-linear-solid", "instant_modulus_gpa": 1, "relaxed_modulus_gpa": 0.4, "relaxation_time_us": 5}, "hydration": {"pressure_mpa": 10, "layer_spacing_nm": 0.25, "decay_length_nm": 0.3}"#,
        r#""contact": {"law": "jkr", "work_of_adhesion_mj_per_m2": 20}"#,
        r#""contact": {"law": "capillary", "relative_humidity": 0.4, "surface_tension_mn_per_m": 72.8, "contact_angle_deg": 10, "temperature_k": 293.15, "molar_volume_m3_per_mol": 18e-6}"#,
    ];
    let mut with_laws = Vec::new();
    for (i, law) in laws.iter().enumerate() {
        let path = directory.path().join(format!("sample-{i}.json"));
        let text = format!(r#"{{"name": "law-{i}", "youngs_modulus_gpa": 1, {law}}}"#);
        std::fs::write(&path, text).expect("sample file");
        let path = path.to_str().expect("utf-8 path").to_string();
        with_laws.push(one(&[
            "simulate",
            "--cantilever",
            "biolever",
            "--sample",
            &path,
            "--a0",
            "10",
            "--z",
            "8.5",
            "--json",
        ]));
    }
    // One check over all of them: a drive's keys are printed by its own runs only.
    let mut simulate = simulate.to_vec();
    simulate.extend(with_laws);
    printed.extend(check(&schema, "`drumroll simulate --json`", &simulate));

    // continue: the MAClever on mica with its retract (folds, bistable range).
    let continued = [one(&[
        "continue",
        "--case",
        "maclever-mica",
        "--retract",
        "--json",
    ])];
    printed.extend(check(&schema, "`drumroll continue --json`", &continued));

    // map: the MAClever on mica over Q_1 (a closed fold curve with two cusps), with --at and
    // --labels.
    let mapped = [one(&[
        "map",
        "--case",
        "maclever-mica",
        "--vary",
        "quality-factor-1",
        "--from",
        "1",
        "--to",
        "8",
        "--at",
        "2,3",
        "--labels",
        "G1,fold",
        "--points",
        "10",
        "--json",
    ])];
    printed.extend(check(&schema, "`drumroll map --json`", &mapped));

    // approach, JSON Lines: the inputs line, then records of both directions.
    let text = stdout_of(&[
        "approach",
        "--from",
        "8.8",
        "--to",
        "8.79",
        "--rate",
        "10",
        "--retract",
        "--jsonl",
    ]);
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("one object per line"))
        .collect();
    assert!(lines[0].get("inputs").is_some() && lines[0].get("cycle").is_none());
    printed.extend(check(
        &schema,
        "`drumroll approach` (CSV, `--jsonl`)",
        &[lines],
    ));

    // scan: the ideal feedback and the PI loop over the paper's line (null where the time
    // domain reads nothing).
    let scanned = [
        one(&["scan", "--pixels", "4", "--direction", "both", "--json"]),
        one(&[
            "scan",
            "--pixels",
            "4",
            "--feedback",
            "pi",
            "--scan-rate",
            "4000",
            "--json",
        ]),
    ];
    let disc = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/rasters/membrane-disc.json"
    );
    let rastered = [one(&["scan", "--raster", disc, "--pixels", "3", "--json"])];
    printed.extend(check(
        &schema,
        "`drumroll scan` (CSV, `--json`)",
        &[scanned.concat(), rastered.concat()],
    ));

    // grid, JSON Lines: the header line, then rows with approach, retract and bistable.
    let directory = tempfile::tempdir().expect("temporary directory");
    let map = directory.path().join("map.jsonl");
    stdout_of(&[
        "grid",
        "--vary",
        "a0",
        "--from",
        "9",
        "--to",
        "10",
        "--steps",
        "2",
        "--z-from",
        "9.5",
        "--z-to",
        "8.5",
        "--z-steps",
        "3",
        "--retract",
        "--output",
        map.to_str().expect("utf-8 path"),
    ]);
    let lines: Vec<Value> = std::fs::read_to_string(&map)
        .expect("map")
        .lines()
        .map(|l| serde_json::from_str(l).expect("one object per line"))
        .collect();
    assert!(lines[0].get("inputs").is_some() && lines[0].get("row").is_none());
    printed.extend(check(&schema, "`drumroll grid` (JSON Lines)", &[lines]));

    // theory: the paper's example (every number), below the surface and without contact
    // (predictions withheld: `null`).
    let theory = [
        one(&["theory", "--case", "biolever-mica", "--json"]),
        one(&["theory", "--case", "biolever-mica", "--z", "-5", "--json"]),
        one(&["theory", "--case", "biolever-mica", "--z", "11", "--json"]),
    ];
    printed.extend(check(&schema, "`drumroll theory --json`", &theory));

    // cantilever: the table alone, and a cantilever built and written.
    let directory = tempfile::tempdir().expect("temporary directory");
    let out = directory.path().join("lever.json");
    let cantilever = [
        one(&["cantilever", "--tip-mass-ratio", "0", "--json"]),
        one(&[
            "cantilever",
            "--tip-mass-ratio",
            "0.16",
            "--k1",
            "0.1",
            "--f1",
            "3.5",
            "--f2",
            "28",
            "--q1",
            "1.6",
            "--q2",
            "4.3",
            "--radius",
            "50",
            "--name",
            "lever",
            "--out",
            out.to_str().expect("utf-8 path"),
            "--json",
        ]),
        one(&[
            "cantilever",
            "--geometry",
            "rectangular",
            "--length-um",
            "200",
            "--width-um",
            "20",
            "--thickness-um",
            "1",
            "--youngs-modulus-gpa",
            "169",
            "--density-kg-m3",
            "2330",
            "--fluid",
            "water",
            "--tip-mass-ratio",
            "0",
            "--radius",
            "10",
            "--json",
        ]),
    ];
    printed.extend(check(&schema, "`drumroll cantilever --json`", &cantilever));

    // Every documented key of the inputs object is printed by some command.
    for path in schema["The `inputs` object"].keys() {
        assert!(
            printed.contains(path),
            "`{path}` is documented, never printed"
        );
    }
}

#[test]
fn csv_columns_are_the_documented_json_keys_in_order() {
    let text = document();
    let schema = schema(&text);
    let directory = tempfile::tempdir().expect("temporary directory");
    let csv = directory.path().join("branch.csv");
    stdout_of(&[
        "continue",
        "--floor",
        "9.5",
        "--csv",
        csv.to_str().expect("utf-8 path"),
    ]);
    let written = std::fs::read_to_string(&csv).expect("CSV");
    let full_header: Vec<&str> = written.lines().next().expect("header").split(',').collect();
    // The harmonic columns `harmonic_<n>_amplitude_nm`, `harmonic_<n>_phase_deg`, n = 1..N,
    // come last, from the point's `harmonics[n - 1]`.
    let (header, harmonic_columns): (Vec<&str>, Vec<&str>) = full_header
        .iter()
        .partition(|column| !column.starts_with("harmonic_"));
    assert!(!harmonic_columns.is_empty());
    for (index, pair) in harmonic_columns.chunks(2).enumerate() {
        let n = index + 1;
        assert_eq!(
            pair,
            [
                format!("harmonic_{n}_amplitude_nm"),
                format!("harmonic_{n}_phase_deg")
            ]
        );
    }
    assert_eq!(&full_header[..header.len()], &header[..]);
    assert_eq!(header[0], "direction");
    let points = &schema["`drumroll continue --json`"];
    for column in &header[1..] {
        let types = points
            .get(&format!("points[].{column}"))
            .unwrap_or_else(|| panic!("CSV column `{column}` is no JSON point key"));
        assert!(!types.contains("array") && !types.contains("object"));
    }
    // The CSV section lists the columns in the header's order.
    let section = text
        .split("## `drumroll continue --csv FILE`")
        .nth(1)
        .and_then(|rest| rest.split("\n## ").next())
        .expect("the CSV section");
    let listed: Vec<&str> = section
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|word| header.contains(word))
        .collect();
    assert_eq!(listed, header);

    // map's CSV: `label`, then the documented point keys in order.
    let map_csv = directory.path().join("map.csv");
    stdout_of(&[
        "map",
        "--vary",
        "a0",
        "--from",
        "9.9",
        "--to",
        "10.1",
        "--points",
        "4",
        "--labels",
        "G2",
        "--csv",
        map_csv.to_str().expect("utf-8 path"),
    ]);
    let written = std::fs::read_to_string(&map_csv).expect("CSV");
    let full_header: Vec<&str> = written.lines().next().expect("header").split(',').collect();
    // As continue's: the harmonic columns come last, n = 1..4 by default.
    let (header, harmonic_columns): (Vec<&str>, Vec<&str>) = full_header
        .iter()
        .partition(|column| !column.starts_with("harmonic_"));
    assert_eq!(harmonic_columns.len(), 8);
    for (index, pair) in harmonic_columns.chunks(2).enumerate() {
        let n = index + 1;
        assert_eq!(
            pair,
            [
                format!("harmonic_{n}_amplitude_nm"),
                format!("harmonic_{n}_phase_deg")
            ]
        );
    }
    assert_eq!(&full_header[..header.len()], &header[..]);
    assert_eq!(header[0], "label");
    let curve_points = &schema["`drumroll map --json`"];
    for column in &header[1..] {
        let types = curve_points
            .get(&format!("curves[].points[].{column}"))
            .unwrap_or_else(|| panic!("map CSV column `{column}` is no JSON point key"));
        assert!(!types.contains("array") && !types.contains("object"));
    }
    let section = text
        .split("## `drumroll map --csv FILE`")
        .nth(1)
        .and_then(|rest| rest.split("\n## ").next())
        .expect("the map CSV section");
    let listed: Vec<&str> = section
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|word| header.contains(word))
        .collect();
    assert_eq!(listed, header);
    assert!(written.lines().skip(1).all(|l| l.starts_with("G2,")));

    // map's codimension-two CSV: `label`, then the documented point keys in order, then the
    // harmonics; the MAClever on mica's fold curve over Q1 = 1..8 has two cusps.
    let codim2_csv = directory.path().join("codim2.csv");
    stdout_of(&[
        "map",
        "--case",
        "maclever-mica",
        "--vary",
        "quality-factor-1",
        "--from",
        "1",
        "--to",
        "8",
        "--labels",
        "fold",
        "--points",
        "10",
        "--codim2-csv",
        codim2_csv.to_str().expect("utf-8 path"),
    ]);
    let written = std::fs::read_to_string(&codim2_csv).expect("CSV");
    let full_header: Vec<&str> = written.lines().next().expect("header").split(',').collect();
    let (header, harmonic_columns): (Vec<&str>, Vec<&str>) = full_header
        .iter()
        .partition(|column| !column.starts_with("harmonic_"));
    assert_eq!(harmonic_columns.len(), 8);
    assert_eq!(&full_header[..header.len()], &header[..]);
    assert_eq!(header[0], "label");
    let map_keys = &schema["`drumroll map --json`"];
    for column in &header[1..] {
        let types = map_keys
            .get(&format!("codim2_points[].{column}"))
            .unwrap_or_else(|| panic!("codim-2 CSV column `{column}` is no JSON point key"));
        assert!(!types.contains("array") && !types.contains("object"));
    }
    let section = text
        .split("## `drumroll map --codim2-csv FILE`")
        .nth(1)
        .and_then(|rest| rest.split("\n## ").next())
        .expect("the codim-2 CSV section");
    let listed: Vec<&str> = section
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|word| header.contains(word))
        .collect();
    assert_eq!(listed, header);
    let rows: Vec<&str> = written.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{written}");
    assert!(rows.iter().all(|row| row.starts_with("cusp,fold,")));
    assert!(rows
        .iter()
        .all(|row| row.split(',').count() == full_header.len()));

    // approach's CSV header is the documented line, each column a record key.
    let sweep = stdout_of(&["approach", "--from", "8.8", "--to", "8.79", "--rate", "10"]);
    let full_header = sweep.lines().next().expect("header");
    // The harmonic columns (4 by default) follow the documented scalar columns.
    let header = full_header
        .split_once(",harmonic_")
        .map_or(full_header, |(scalars, _)| scalars);
    let harmonics: String = (1..=4)
        .map(|n| format!(",harmonic_{n}_amplitude_nm,harmonic_{n}_phase_deg"))
        .collect();
    assert_eq!(full_header, format!("{header}{harmonics}"));
    assert!(
        text.contains(&format!("`{header}`")),
        "header {header} not documented"
    );
    let records = &schema["`drumroll approach` (CSV, `--jsonl`)"];
    for column in header.split(',') {
        assert!(records.contains_key(column), "column `{column}`");
    }
}
