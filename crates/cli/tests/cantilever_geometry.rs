//! `drumroll cantilever --geometry rectangular` run as a user runs it: the modes in water and
//! air from the geometry (Sader 1998), the built-in `rectangular-silicon-water` reproduced, a
//! fluid file, and refusals naming the option or the file's field.

mod common;
use common::{drumroll, json_of, number};

/// The geometry of the built-in `rectangular-silicon-water` (its description): a silicon
/// beam 200 x 20 x 1 um.
const GEOMETRY: [&str; 12] = [
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
    "--tip-mass-ratio",
    "0",
];

fn in_fluid(fluid: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["cantilever", "--geometry", "rectangular", "--fluid", fluid];
    args.extend(GEOMETRY);
    args.extend(extra);
    json_of(&args)
}

/// The fixture is what the command writes (to the last digit: the same computation), and its
/// `k_1` is the Euler-Bernoulli `(1.875104^4 / 4) E I / L^3` (1e-6, the digits of the
/// eigenvalue); water lowers `f_1` to about a quarter (here 0.25) and `Q_1` to order 1, air
/// barely moves `f_1` and leaves `Q_1` in the tens (Sader 1998, Sec. IV).
#[test]
fn water_and_air_from_the_geometry() {
    let water = in_fluid(
        "water",
        &["--radius", "10", "--name", "rectangular-silicon-water"],
    );
    let built: afm::Cantilever =
        serde_json::from_value(water["cantilever"].clone()).expect("cantilever");
    let fixture = afm::builtin_cantilever("rectangular-silicon-water").expect("fixture");
    assert_eq!(built, fixture);
    let inertia = 20e-6 * 1e-6_f64.powi(3) / 12.0;
    let euler_bernoulli = 1.875_104_f64.powi(4) / 4.0 * 169e9 * inertia / 200e-6_f64.powi(3);
    let modes = water["modes"].as_array().expect("modes");
    assert!((number(&modes[0], "stiffness_n_per_m") / euler_bernoulli - 1.0).abs() < 1e-6);
    let ratio = number(&modes[0], "frequency_khz") / number(&modes[0], "vacuum_frequency_khz");
    assert!(ratio > 0.2 && ratio < 0.3, "{ratio}");
    let q1 = number(&modes[0], "quality_factor");
    assert!(q1 > 1.0 && q1 < 3.0, "{q1}");

    let air = in_fluid("air", &[]);
    let air_mode = &air["modes"][0];
    let ratio = number(air_mode, "frequency_khz") / number(air_mode, "vacuum_frequency_khz");
    assert!(ratio > 0.98 && ratio < 1.0, "{ratio}");
    assert!(number(air_mode, "quality_factor") > 10.0);
    assert!(air.get("cantilever").is_none(), "no --radius: table only");
}

/// A fluid file with water's numbers gives water's modes exactly.
#[test]
fn fluid_file_equals_builtin() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("my-water.json");
    std::fs::write(
        &path,
        r#"{"name": "my water", "density_kg_m3": 998.2, "viscosity_pa_s": 1.002e-3}"#,
    )
    .expect("write");
    let from_file = in_fluid(path.to_str().expect("utf-8"), &[]);
    let builtin = in_fluid("water", &[]);
    assert_eq!(from_file["modes"], builtin["modes"]);
    assert_eq!(from_file["fluid"]["name"], "my water");
}

/// Bad input is refused, naming the option or the fluid file and field; nothing is written.
#[test]
fn bad_geometry_is_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bad_fluid = dir.path().join("bad.json");
    std::fs::write(
        &bad_fluid,
        r#"{"name": "bad", "density_kg_m3": -1, "viscosity_pa_s": 1e-3}"#,
    )
    .expect("write");
    let out = dir.path().join("never.json");
    let bad_fluid = bad_fluid.display().to_string();
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["--fluid", "water", "--length-um", "-5"],
            String::from("invalid --length-um = -5"),
        ),
        (
            vec!["--fluid", "oil"],
            String::from("--fluid `oil` is neither `water`, `air` nor a readable fluid file"),
        ),
        (
            vec!["--fluid", &bad_fluid],
            format!("fluid file {bad_fluid}"),
        ),
        (
            vec!["--fluid", "water", "--width-um", "150"],
            String::from("slender beams"),
        ),
        (
            vec!["--fluid", "water", "--out", out.to_str().expect("utf-8")],
            String::from("--out needs --radius"),
        ),
    ];
    for (extra, expected) in cases {
        // An option of `extra` replaces GEOMETRY's value of the same option.
        let mut args = vec!["cantilever", "--geometry", "rectangular"];
        for pair in GEOMETRY.chunks(2) {
            if !extra.contains(&pair[0]) {
                args.extend(pair);
            }
        }
        args.extend(&extra);
        let output = drumroll().args(&args).output().expect("runs");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{extra:?} accepted");
        assert!(stderr.contains(&expected), "{extra:?}: {stderr}");
    }
    assert!(!out.exists(), "no file written on error");
    // Geometry options without --geometry are named, not ignored.
    let output = drumroll()
        .args(["cantilever", "--tip-mass-ratio", "0", "--length-um", "200"])
        .output()
        .expect("runs");
    assert!(String::from_utf8_lossy(&output.stderr).contains("add --geometry rectangular"));
    // --geometry with measured values is a usage error.
    let output = drumroll()
        .args([
            "cantilever",
            "--tip-mass-ratio",
            "0",
            "--geometry",
            "rectangular",
            "--k1",
            "1",
        ])
        .output()
        .expect("runs");
    assert!(!output.status.success());
}
