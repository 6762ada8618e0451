//! The approach and retract diagrams of a built-in case as `drumroll continue --case C
//! --retract [--a0 A0] [--max-step S]` computes them, shared by the tests of hysteretic branch
//! ends and located grazings.
#![allow(dead_code)]

use afm::TappingModel;
use afm::{approach_diagram, builtin_case, diagram, BifurcationDiagram, DiagramSettings};

/// The model of built-in `case`, with free amplitude `a0` (nm) where given.
pub fn model(case: &str, a0: Option<f64>) -> TappingModel {
    let mut case = builtin_case(case).unwrap();
    if let Some(a0) = a0 {
        case.free_amplitude_nm = a0;
    }
    TappingModel::from_case(&case).unwrap()
}

/// The approach of `model` with largest step `max_step` (nm; the default `A0 / 250` where
/// `None`).
pub fn approach(model: &TappingModel, max_step: Option<f64>) -> BifurcationDiagram {
    let defaults = DiagramSettings::approach(model);
    let settings = DiagramSettings {
        max_step: max_step.unwrap_or(defaults.max_step),
        ..defaults
    };
    approach_diagram(model, &settings).unwrap()
}

/// The approach of `model` with largest step `max_step` (nm; the default `A0 / 250` where
/// `None`), and the retract from its lowest point with the same largest step.
pub fn approach_and_retract(
    model: &TappingModel,
    max_step: Option<f64>,
) -> (BifurcationDiagram, BifurcationDiagram) {
    let approach = approach(model, max_step);
    let max_step = max_step.unwrap_or(DiagramSettings::approach(model).max_step);
    let lowest = approach
        .points
        .iter()
        .min_by(|a, b| a.z_nm.total_cmp(&b.z_nm))
        .unwrap();
    let retract_settings = DiagramSettings {
        max_step,
        ..DiagramSettings::retract(model)
    };
    let retract = diagram(model, &lowest.state, lowest.z_nm, &retract_settings).unwrap();
    (approach, retract)
}

/// The retract of built-in `case` with free amplitude `a0` (nm) and largest step `max_step`
/// (nm), from the lowest point of its approach.
pub fn retract(case: &str, a0: f64, max_step: f64) -> BifurcationDiagram {
    approach_and_retract(&model(case, Some(a0)), Some(max_step)).1
}
