//! Accuracy and cost of the monodromy matrix over one period of the Biolever on mica at the
//! paper's Fig. 1 points A/A0 = 0.95 and 0.5, against a reference run by DOP853 alone (no
//! Taylor-series steps) with the sensitivities under error control and tolerances ten times
//! tighter: the default settings (tangents at the state's order, error control on the state
//! only), the decoupled tangents (`SensitivityMethod::Decoupled`, as the steady orbit's Newton
//! maps use them), and the latter at the loose tolerances of 1e-9 (the steady orbit's first
//! Newton map) and 1e-8. Contacts are stepped by
//! Taylor series (the series steps); the evaluation counts are the DOP853 stages elsewhere.
//!
//! Run with `cargo run --release -p afm --example monodromy_error`.

use afm::{
    builtin_case, find_amplitude_ratio, AmplitudeRatioSearch, Separation, SteadyOrbitSettings,
    TappingModel,
};
use hybrid::{flow_map, FlowMap, Sensitivity, SensitivityMethod, Settings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let case = builtin_case("biolever-mica")?;
    let model = TappingModel::from_case(&case)?;
    for ratio in [0.95, 0.5] {
        let search = AmplitudeRatioSearch::new(ratio)?;
        let target = find_amplitude_ratio(&model, &search, &SteadyOrbitSettings::default())?;
        let mut at_z = model.clone();
        at_z.set_separation(Separation::Constant(target.z_nm))?;
        let period = |settings: Settings| -> Result<FlowMap, hybrid::HybridError> {
            flow_map(
                &at_z,
                0.0,
                &target.state,
                at_z.period_us(),
                Sensitivity::Transition,
                &settings,
            )
        };
        let default = period(Settings::default())?;
        let reference = period(Settings {
            sensitivity_tolerance: Some(1e-12),
            relative_tolerance: 1e-13,
            absolute_tolerance: 1e-13,
            taylor_series: false,
            ..Settings::default()
        })?;
        let decoupled = period(Settings {
            sensitivity_method: SensitivityMethod::Decoupled,
            ..Settings::default()
        })?;
        let loose = |tolerance: f64| {
            period(Settings {
                sensitivity_method: SensitivityMethod::Decoupled,
                relative_tolerance: tolerance,
                absolute_tolerance: tolerance,
                ..Settings::default()
            })
        };
        let (decoupled_9, decoupled_8) = (loose(1e-9)?, loose(1e-8)?);
        let error = |run: &FlowMap| {
            (&run.transition - &reference.transition).amax() / reference.transition.amax()
        };
        println!(
            "A/A0 {ratio}: Z = {:.6} nm, reference (DOP853 only) {} RHS evaluations",
            target.z_nm, reference.statistics.rhs_evaluations
        );
        for (name, run) in [
            ("coupled (default)", &default),
            ("decoupled", &decoupled),
            ("decoupled, tolerance 1e-9", &decoupled_9),
            ("decoupled, tolerance 1e-8", &decoupled_8),
        ] {
            println!(
                "  {name:26}: monodromy relative error {:.2e}, series steps {}, RHS evaluations {}",
                error(run),
                run.statistics.series_steps,
                run.statistics.rhs_evaluations
            );
        }
    }
    Ok(())
}
