//! The steady-orbit benchmark's problem for an outside integrator: the Biolever on mica at a
//! Fig. 1 point (A/A0 = 0.5 unless given, as `cargo run --release -p afm --example
//! transient_reference -- 0.9`), printed as JSON: the separation `z_nm` on the approach branch,
//! the drive (`omega_rad_per_us`, `period_us`), the Hertz coefficient `c` of `F_ts = c
//! (-d)^{3/2}` (`hertz_nn_per_nm_1_5`), each mode's `omega_rad_per_us`, `quality_factor`,
//! `stiffness_n_per_m` and drive force `force_nn` (`F_i = r_i F_1`), the neighbouring orbit's
//! state (`neighbour_state`, at `Z + 0.01` nm: where `cargo bench -p afm --bench steady_orbit`
//! starts Newton) and the converged orbit's (`orbit_state`), `[q_1, q_1', ...]` in nm and
//! nm/us at drive phase zero.
//!
//! `crates/afm/benches/scipy_transient.py` integrates Eq. 1 from these numbers with scipy
//! (the "plain Python/scipy transient integration of the same orbit") for the speed
//! ratio.

use afm::{
    builtin_case, find_amplitude_ratio, steady_orbit, AmplitudeRatioSearch, OrbitStart,
    SteadyOrbitSettings, TappingModel,
};
use serde_json::json;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ratio: f64 = match std::env::args().nth(1) {
        Some(text) => text.parse()?,
        None => 0.5,
    };
    let case = builtin_case("biolever-mica")?;
    let model = TappingModel::from_case(&case)?;
    let settings = SteadyOrbitSettings::default();
    let target = find_amplitude_ratio(&model, &AmplitudeRatioSearch::new(ratio)?, &settings)?;
    let z = target.z_nm;
    let neighbour = steady_orbit(&model, z + 0.01, OrbitStart::Near(&target.state), &settings)?;
    let orbit = steady_orbit(&model, z, OrbitStart::Near(&neighbour.state), &settings)?;
    let modes: Vec<_> = model
        .cantilever()
        .modes
        .iter()
        .map(|mode| {
            json!({
                "omega_rad_per_us": mode.angular_frequency(),
                "quality_factor": mode.quality_factor,
                "stiffness_n_per_m": mode.stiffness_n_per_m,
                "force_nn": mode.force_ratio * model.drive_force_nn(),
            })
        })
        .collect();
    let problem = json!({
        "case": "biolever-mica",
        "amplitude_ratio": ratio,
        "z_nm": z,
        "omega_rad_per_us": model.drive_angular_frequency(),
        "period_us": model.period_us(),
        "hertz_nn_per_nm_1_5": model.hertz().coefficient,
        "modes": modes,
        "neighbour_state": neighbour.state,
        "orbit_state": orbit.state,
        "orbit_converged": orbit.converged,
    });
    println!("{}", serde_json::to_string_pretty(&problem)?);
    Ok(())
}
