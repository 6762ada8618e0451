//! The monodromy of a period with a grazing Hertz contact.
//!
//! A contact `d` deep (the free orbit's lowest gap at `-d`) lasts a time `~ d^{1/2}` under a
//! force `~ d^{3/2}`; the period map's Jacobian moves off the free flight's by `~ d`, linearly,
//! down to the shallowest contacts, and so does its derivative in `Z` (the impulse `~ d^2`
//! changes by `~ d` per unit of `Z`), which is zero in free flight. The free flight is linear, so its monodromy is the same
//! from every state and at every separation: the one from the same state 1 nm above first
//! contact is an exact reference, and the slope measured on a well-resolved contact (1e-5 nm
//! deep) predicts the difference at every smaller depth. Before the solver kept a grazing
//! contact's first step on the onset's clock, a series expanded next to the onset's half
//! power on a clock centred on the release gave differences of 1e5 (instead of 1e-7) at
//! 1e-11 nm with coupled sensitivities, and 1e-4 with decoupled ones.

use afm::{builtin_case, Separation, TappingModel};
use hybrid::{flow_map, Sensitivity, SensitivityMethod, Settings};

#[test]
fn a_grazing_contact_moves_the_monodromy_and_dp_dz_in_proportion_to_its_depth() {
    for case in ["biolever-soft", "biolever-mica", "maclever-mica"] {
        let mut model = TappingModel::from_case(&builtin_case(case).expect("case")).expect("model");
        let free_state = model.free_state();
        let period = model.period_us();
        let grazing = model.grazing_separation_nm();
        for method in [SensitivityMethod::Coupled, SensitivityMethod::Decoupled] {
            let settings = Settings {
                sensitivity_method: method,
                ..Settings::default()
            };
            let mut map_at = |z: f64| {
                model
                    .set_separation(Separation::Constant(z))
                    .expect("finite");
                flow_map(
                    &model,
                    0.0,
                    &free_state,
                    period,
                    Sensitivity::TransitionAndParameter,
                    &settings,
                )
                .expect("period map")
            };
            let free = map_at(grazing + 1.0);
            assert!(free.events.is_empty(), "{case}: no contact 1 nm above G1");
            // Z does not enter the free flight: its parameter sensitivity is exactly zero.
            assert!(
                free.parameter_sensitivity.iter().all(|&v| v == 0.0),
                "{case}"
            );
            let mut offset = |depth: f64| {
                let grazed = map_at(grazing - depth);
                assert_eq!(
                    grazed.events.len(),
                    2,
                    "{case}: one contact {depth} nm deep"
                );
                let parameter = grazed
                    .parameter_sensitivity
                    .iter()
                    .fold(0.0_f64, |m, v| m.max(v.abs()));
                ((&grazed.transition - &free.transition).amax(), parameter)
            };
            let (transition_at, parameter_at) = offset(1e-5);
            let (transition_slope, parameter_slope) = (transition_at / 1e-5, parameter_at / 1e-5);
            for depth in [1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6] {
                let (transition, parameter) = offset(depth);
                for (what, ratio) in [
                    ("monodromy", transition / (transition_slope * depth)),
                    ("dP/dZ", parameter / (parameter_slope * depth)),
                ] {
                    assert!(
                        (0.8..1.25).contains(&ratio),
                        "{case} {method:?}: a contact {depth} nm deep moves the {what} by {ratio} times the slope at 1e-5 nm"
                    );
                }
            }
        }
    }
}
