//! Accuracy and cost of the monodromy matrix over one period of the Biolever on mica at the
//! paper's Fig. 1 points A/A0 = 0.95 and 0.5: the default settings (error control on the state
//! only) against a reference run with the sensitivities under error control and tolerances ten
//! times tighter.
//!
//! Run with `cargo run --release -p afm --example monodromy_error`.

use afm::{
    builtin_case, find_amplitude_ratio, AmplitudeRatioSearch, Separation, SteadyOrbitSettings,
    TappingModel,
};
use hybrid::{flow_map, FlowMap, Sensitivity, Settings};

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
            ..Settings::default()
        })?;
        let error =
            (&default.transition - &reference.transition).amax() / reference.transition.amax();
        println!(
            "A/A0 {ratio}: Z = {:.6} nm, monodromy relative error {error:.2e}, RHS evaluations {} (reference {})",
            target.z_nm, default.statistics.rhs_evaluations, reference.statistics.rhs_evaluations
        );
    }
    Ok(())
}
