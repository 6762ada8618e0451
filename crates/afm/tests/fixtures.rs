//! Fixture loading: every built-in case loads and matches the paper's table; bad files give
//! errors naming the file, the field and the allowed range.

mod common;

use std::path::Path;

use afm::{AfmError, TappingModel};

#[test]
fn every_builtin_case_loads_and_builds_a_model() {
    let names = afm::case_names();
    for required in [
        "biolever-mica",
        "biolever-soft",
        "maclever-mica",
        "maclever-soft",
        "maclever-mica-experiment",
    ] {
        assert!(names.contains(&required), "{required}");
    }
    for name in names {
        let case = afm::builtin_case(name).expect("built-in case");
        assert_eq!(case.name, name);
        let model = TappingModel::from_case(&case).expect("model");
        assert!(model.grazing_separation_nm() > 0.0);
        assert_eq!(afm::find_case(name).expect("find"), case);
    }
    for name in afm::cantilever_names() {
        assert_eq!(
            afm::builtin_cantilever(name).expect("cantilever").name,
            name
        );
    }
    for name in afm::sample_names() {
        assert_eq!(afm::builtin_sample(name).expect("sample").name, name);
    }
}

#[test]
fn builtin_values_are_the_papers() {
    // MODEL.md section 6, typed in independently in tests/common.
    let bio = afm::builtin_cantilever("biolever").expect("biolever");
    assert_eq!(bio.modes, common::biolever().modes);
    assert_eq!(bio.tip_radius_nm, 30.0);
    let mac = afm::builtin_cantilever("maclever").expect("maclever");
    assert_eq!(
        mac.modes,
        common::cantilever(&[(0.1, 3.5, 1.6, 1.0, 1.0), (10.0, 28.0, 4.3, 5.26, -1.54)]).modes
    );
    assert_eq!((mac.tip_radius_nm, mac.tip_mass_ratio), (50.0, 0.16));
    for cantilever in [&bio, &mac] {
        assert_eq!(cantilever.tip_youngs_modulus_gpa, 130.0);
        assert_eq!(cantilever.tip_poisson_ratio, 0.3);
    }
    let moduli: Vec<f64> = ["mica", "soft", "purple-membrane"]
        .iter()
        .map(|name| {
            afm::builtin_sample(name)
                .expect("sample")
                .youngs_modulus_gpa
        })
        .collect();
    assert_eq!(moduli, vec![60.0, 1.0, 0.05]);
    let experiment = afm::builtin_case("maclever-mica-experiment").expect("case");
    assert_eq!(experiment.drive_frequency_khz, Some(3.3));
    assert_eq!(experiment.free_amplitude_nm, 20.0);
    let fig1 = afm::builtin_case("biolever-mica").expect("case");
    assert_eq!(fig1.drive_frequency_khz, None);
    assert_eq!(fig1.drive_frequency_or_fundamental_khz(), 9.3);
    assert_eq!(fig1.free_amplitude_nm, 10.0);
}

const GOOD_CANTILEVER: &str = r#"{
  "name": "mine",
  "tip_radius_nm": 20.0,
  "tip_mass_ratio": 0.0,
  "modes": [
    {"stiffness_n_per_m": 0.05, "frequency_khz": 8.0, "quality_factor": 2.0,
     "optical_sensitivity": 1.0, "force_ratio": 1.0},
    {"stiffness_n_per_m": 2.0, "frequency_khz": 50.0, "quality_factor": 3.0,
     "optical_sensitivity": 3.0, "force_ratio": -0.5}
  ]
}"#;

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write temp file");
    path
}

fn cantilever_error(text: &str) -> (String, AfmError) {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = write(dir.path(), "bad.json", text);
    let error = afm::load_cantilever(&path).expect_err("must fail");
    (path.display().to_string(), error)
}

#[test]
fn user_files_load_with_defaults_and_relative_references() {
    let dir = tempfile::tempdir().expect("tempdir");
    write(dir.path(), "mine.json", GOOD_CANTILEVER);
    let case_path = write(
        dir.path(),
        "case.json",
        r#"{"name": "c", "cantilever": "mine.json", "sample": "mica", "free_amplitude_nm": 5.0}"#,
    );
    let case = afm::load_case(&case_path).expect("case");
    // Defaults of the paper's note 15.
    assert_eq!(case.cantilever.tip_youngs_modulus_gpa, 130.0);
    assert_eq!(case.cantilever.tip_poisson_ratio, 0.3);
    assert_eq!(case.cantilever.modes.len(), 2);
    assert_eq!(case.sample.youngs_modulus_gpa, 60.0);
    let found = afm::find_case(&case_path.display().to_string()).expect("by path");
    assert_eq!(found, case);
}

#[test]
fn negative_stiffness_names_file_field_and_range() {
    let (file, error) = cantilever_error(&GOOD_CANTILEVER.replace("0.05,", "-0.05,"));
    let message = error.to_string();
    assert!(matches!(error, AfmError::InvalidField { .. }));
    assert!(message.contains(&file), "{message}");
    assert!(message.contains("modes[0].stiffness_n_per_m"), "{message}");
    assert!(message.contains("-0.05"), "{message}");
    assert!(message.contains("[1e-6, 1000000] N/m"), "{message}");
}

#[test]
fn zero_or_vanishing_quality_factor_is_rejected() {
    // 1e-9 was accepted while the range was (0, 1e6], and then exhausted the solver's step
    // limit deep inside `simulate` (an error naming neither the file nor the field).
    for value in ["0", "1e-9"] {
        let (file, error) = cantilever_error(&GOOD_CANTILEVER.replace(
            "\"quality_factor\": 3.0",
            &format!("\"quality_factor\": {value}"),
        ));
        let message = error.to_string();
        assert!(message.contains(&file), "{message}");
        assert!(message.contains("modes[1].quality_factor"), "{message}");
        assert!(message.contains("[0.001, 1000000]"), "{message}");
    }
}

#[test]
fn first_mode_sensitivity_other_than_one_is_rejected() {
    let text = GOOD_CANTILEVER.replacen(
        "\"optical_sensitivity\": 1.0",
        "\"optical_sensitivity\": 1.2",
        1,
    );
    let (file, error) = cantilever_error(&text);
    let message = error.to_string();
    assert!(message.contains(&file), "{message}");
    assert!(
        message.contains("modes[0].optical_sensitivity"),
        "{message}"
    );
    assert!(message.contains("= 1.2"), "{message}");
    assert!(
        message.contains("exactly 1 for the first mode"),
        "{message}"
    );
}

#[test]
fn unknown_field_and_bad_json_name_the_file() {
    let (file, error) =
        cantilever_error(&GOOD_CANTILEVER.replace("\"tip_mass_ratio\"", "\"tip_mass\""));
    let message = error.to_string();
    assert!(matches!(error, AfmError::Json { .. }));
    assert!(message.contains(&file), "{message}");
    assert!(message.contains("unknown field `tip_mass`"), "{message}");
    assert!(message.contains("tip_mass_ratio"), "{message}"); // the expected fields are listed
    let (file, error) = cantilever_error("{ \"name\": \"x\", ");
    let message = error.to_string();
    assert!(
        message.contains(&file) && message.contains("line 1"),
        "{message}"
    );
}

#[test]
fn other_range_violations() {
    let (_, error) = cantilever_error(&GOOD_CANTILEVER.replace("50.0", "8.0"));
    let message = error.to_string();
    assert!(message.contains("modes[1].frequency_khz"), "{message}");
    assert!(message.contains("strictly increasing"), "{message}");
    let (_, error) = cantilever_error(
        &GOOD_CANTILEVER.replace("\"tip_radius_nm\": 20.0", "\"tip_radius_nm\": 0.0"),
    );
    assert!(error.to_string().contains("tip_radius_nm"), "{error}");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = write(
        dir.path(),
        "s.json",
        r#"{"name": "s", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.7}"#,
    );
    let message = afm::load_sample(&path).expect_err("nu > 0.5").to_string();
    assert!(
        message.contains("poisson_ratio") && message.contains("(-1, 0.5]"),
        "{message}"
    );
    let path = write(
        dir.path(),
        "c.json",
        r#"{"name": "c", "cantilever": "biolever", "sample": "mica", "free_amplitude_nm": -3}"#,
    );
    let message = afm::load_case(&path).expect_err("A0 < 0").to_string();
    assert!(
        message.contains("free_amplitude_nm") && message.contains("[0.001, 100000] nm"),
        "{message}"
    );
    let path = write(
        dir.path(),
        "d.json",
        r#"{"name": "d", "cantilever": "nolever", "sample": "mica", "free_amplitude_nm": 3}"#,
    );
    let message = afm::load_case(&path)
        .expect_err("unknown cantilever")
        .to_string();
    assert!(
        message.contains("nolever") && message.contains("biolever, maclever"),
        "{message}"
    );
    let message = afm::builtin_case("nocase")
        .expect_err("unknown")
        .to_string();
    assert!(message.contains("biolever-mica") && message.contains("maclever-mica-experiment"));
    let missing = dir.path().join("missing.json");
    let message = afm::find_case(&missing.display().to_string())
        .expect_err("missing")
        .to_string();
    assert!(message.contains("missing.json"), "{message}");
}
