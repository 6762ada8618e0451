//! `continue --json`'s object written from derived structs
//! ([`drumroll::diagram_json::DiagramJson`]) is byte for byte the object built as a
//! `serde_json::Value` with `json!` (the form it replaced, written out here as the reference):
//! the same keys, in the same (sorted) order, with the same numbers, with and without a
//! retract, the bistable ranges and a branch's error.

use afm::{Case, TappingModel};
use drumroll::continue_diagram::{
    continue_case_until, continue_json, continue_object, ContinueArgs, Continued,
};
use drumroll::model_args::ModelArgs;
use serde_json::{json, Value};

mod json_reference;
use json_reference::{case_and_model, reference_inputs};

/// The object `continue --json` printed before the structs: a `json!` tree of afm's derived
/// records (whose keys `Value` sorts).
fn reference_diagram(
    args: &ContinueArgs,
    case: &Case,
    model: &TappingModel,
    continued: &Continued,
) -> Value {
    let Continued {
        settings,
        approach,
        retract,
        bistable,
        ..
    } = continued;
    let options = json!({
        "floor_nm": settings.z_limit_nm,
        "min_amplitude_ratio": settings.min_amplitude_ratio,
        "max_step_nm": settings.max_step,
        "max_points": settings.max_points,
        "retract": args.retract,
        "harmonics": settings.orbit.harmonics,
    });
    let mut object = json!({
        "inputs": reference_inputs(
            "continue",
            options,
            case,
            model,
            &settings.orbit.integration,
            Some(&settings.orbit),
        ),
        "case": case.name,
        "free_amplitude_nm": model.free_amplitude_nm(),
        "first_contact_z_nm": model.grazing_separation_nm(),
        "points": approach.points,
        "special_points": approach.special_points,
        "stop": approach.stop,
        "completed": approach.completed,
        "error": approach.error,
    });
    if let Some(retract) = &retract {
        object["retract"] = json!({
            "points": retract.points,
            "special_points": retract.special_points,
            "stop": retract.stop,
            "completed": retract.completed,
            "error": retract.error,
        });
        object["bistable_ranges_nm"] = json!(bistable);
    }
    object
}

/// `continue`'s options: `--floor floor --max-points max_points` (and `--retract`), the
/// defaults otherwise.
fn args(floor: Option<f64>, max_points: i64, retract: bool) -> ContinueArgs {
    ContinueArgs {
        model: ModelArgs {
            case: Vec::new(),
            cantilever: None,
            sample: None,
            a0: None,
            drive_frequency: None,
        },
        floor,
        min_amplitude_ratio: 0.3,
        max_step: None,
        max_points,
        retract,
        json: true,
        csv: None,
        plot: None,
        overlay: false,
        panels: None,
        harmonics: drumroll::approach::DEFAULT_HARMONICS,
        threads: None,
    }
}

/// The case `name`, its model and its diagram continued with `args`.
fn continued(name: &str, args: &ContinueArgs) -> (Case, TappingModel, Continued) {
    let (case, model) = case_and_model(name);
    let continued = continue_case_until(args, &case, &model, &mut || false).expect("diagram");
    (case, model, continued)
}

/// `continue --json`'s line of `continued` written from the structs and from the reference
/// `json!` tree: the same bytes, and the `Value` form (`continue_json`) equal to the
/// reference. Returns the reference.
fn same_bytes(
    args: &ContinueArgs,
    case: &Case,
    model: &TappingModel,
    continued: &Continued,
) -> Value {
    let reference = reference_diagram(args, case, model, continued);
    let written =
        serde_json::to_string(&continue_object(args, case, model, continued)).expect("JSON");
    let expected = serde_json::to_string(&reference).expect("JSON");
    assert!(
        written == expected,
        "{}: the bytes differ from the reference at byte {}",
        case.name,
        written
            .bytes()
            .zip(expected.bytes())
            .position(|(a, b)| a != b)
            .unwrap_or(written.len().min(expected.len()))
    );
    let value = continue_json(args, case, model, continued);
    assert!(value == reference, "{} as a Value", case.name);
    reference
}

#[test]
fn the_four_fig2_diagrams_are_written_as_the_value_tree_was() {
    // Biolever on mica down to 2 nm below its first contact (through G1 and G2, completed);
    // the three others stopped by the point cap.
    let (case, model) = case_and_model("biolever-mica");
    let arguments = args(Some(model.grazing_separation_nm() - 2.0), 20_000, false);
    let diagram = continue_case_until(&arguments, &case, &model, &mut || false).expect("diagram");
    let reference = same_bytes(&arguments, &case, &model, &diagram);
    assert_eq!(reference["completed"], true);
    assert!(reference["special_points"].as_array().expect("list").len() >= 2);
    assert!(reference.get("retract").is_none());
    for name in ["biolever-soft", "maclever-mica", "maclever-soft"] {
        let arguments = args(None, 40, false);
        let (case, model, diagram) = continued(name, &arguments);
        let reference = same_bytes(&arguments, &case, &model, &diagram);
        assert_eq!(reference["completed"], false, "{name}");
        assert!(reference.get("bistable_ranges_nm").is_none(), "{name}");
    }
}

#[test]
fn a_retract_and_its_bistable_range_are_written_as_the_value_tree_was() {
    // The MAClever on mica's approach and retract differ between its two folds
    // (crates/cli/tests/continue.rs).
    let arguments = args(None, 20_000, true);
    let (case, model, diagram) = continued("maclever-mica", &arguments);
    let reference = same_bytes(&arguments, &case, &model, &diagram);
    assert!(!reference["bistable_ranges_nm"]
        .as_array()
        .expect("ranges")
        .is_empty());
    assert!(reference["retract"]["points"].is_array());
}

#[test]
fn a_jkr_retract_is_written_as_the_value_tree_was() {
    let arguments = args(None, 20_000, true);
    let (case, model, diagram) = continued("biolever-adhesive", &arguments);
    let reference = same_bytes(&arguments, &case, &model, &diagram);
    assert!(reference["retract"]["special_points"]
        .as_array()
        .expect("list")
        .iter()
        .any(|point| point["label"] == "period-doubling"));
}

#[test]
fn a_bimodal_diagram_is_written_as_the_value_tree_was() {
    let arguments = args(None, 30, false);
    let (case, model, diagram) = continued("biolever-mica-bimodal", &arguments);
    same_bytes(&arguments, &case, &model, &diagram);
}

#[test]
fn errors_and_a_missing_bistable_range_are_written_as_the_value_tree_was() {
    // The fields a computed diagram seldom has, set by hand: a branch's error, and a retract
    // without bistable ranges (`null`).
    let arguments = args(None, 12, true);
    let (case, model, mut diagram) = continued("biolever-soft", &arguments);
    diagram.approach.error = Some(String::from("the corrector \"failed\" at Z = 1 nm"));
    diagram.bistable = None;
    if let Some(retract) = diagram.retract.as_mut() {
        retract.error = Some(String::from("stopped"));
    }
    let reference = same_bytes(&arguments, &case, &model, &diagram);
    assert_eq!(reference["bistable_ranges_nm"], Value::Null);
    assert_eq!(reference["retract"]["error"], "stopped");
    diagram.retract = None;
    let reference = same_bytes(&args(None, 12, false), &case, &model, &diagram);
    assert!(reference.get("retract").is_none());
}
