//! The orbit of a point the page's user clicks on the diagram: the steady orbit at its `Z`
//! from its state (Newton from a state near the orbit, as `drumroll.orbit(start=state)` in
//! Python), with `drumroll simulate --json`'s object and the orbit sampled in time (MODEL.md
//! section 1: `u(t)`, the gap `d(t)`, `F_ts(t)`).

use afm::{sample_trajectory, Separation, SteadyOrbit, SteadyOrbitSettings};
use anyhow::{bail, Context, Result};
use drumroll::option_ranges;
use drumroll::simulate::{check_orbit_options, orbit_figure, simulate_json};
use serde::Deserialize;
use serde_json::{json, Value};

use crate::diagram_request::DiagramRun;

/// The page's request of an orbit: the separation `z_nm` (nm, in `[-A0, 100000]`) and a state
/// near the orbit there (`2 N` numbers: `q_i` in nm, `q_i'` in nm/us, a diagram point's
/// `state`), sampled at `samples_per_period` instants per drive period (in `[10, 5000]`,
/// default 500).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitRequest {
    /// `Z`, nm.
    pub z_nm: f64,
    /// A state near the orbit at `t = 0`.
    pub state: Vec<f64>,
    /// Samples per drive period of the time series.
    #[serde(default = "default_samples_per_period")]
    pub samples_per_period: usize,
}

/// Samples per drive period of the page's time series: an impact of 1 % of a period gets five.
fn default_samples_per_period() -> usize {
    500
}

/// The name of the orbit's start in `simulate`'s JSON (`start`): Newton from a nearby state.
const START: &str = "near";

impl OrbitRequest {
    /// The orbit of `diagram`'s case at this request's `Z` and its JSON: `orbit` (the
    /// `simulate --json` object, without the coexisting-orbit search) and `trajectory`
    /// (`t_periods` in drive periods from the orbit's start, `u_nm`, `gap_nm`, `force_nn` in
    /// nN, over `max(2, multiplicity)` drive periods, both ends included).
    pub fn compute(&self, diagram: &DiagramRun) -> Result<(SteadyOrbit, Value)> {
        let model = &diagram.model;
        if !(10..=5000).contains(&self.samples_per_period) {
            bail!(
                "samples_per_period {}: allowed 10 ..= 5000",
                self.samples_per_period
            );
        }
        check_orbit_options(Some(self.z_nm), None)?;
        option_ranges::separation_for(model.free_amplitude_nm()).check(self.z_nm)?;
        let modes = model.mode_count();
        if self.state.len() != 2 * modes || self.state.iter().any(|x| !x.is_finite()) {
            bail!(
                "state: 2 x {modes} finite numbers (q_i in nm, q_i' in nm/us for each of the {modes} modes), got {}",
                self.state.len()
            );
        }
        let settings = SteadyOrbitSettings::default();
        let orbit = afm::steady_orbit(
            model,
            self.z_nm,
            afm::OrbitStart::Near(&self.state),
            &settings,
        )
        .with_context(|| format!("no steady orbit at Z = {} nm", self.z_nm))?;
        let options = json!({"z_nm": self.z_nm, "amplitude_ratio": null, "start": START});
        let object = simulate_json(
            &diagram.case,
            model,
            &settings,
            &orbit,
            START,
            None,
            options,
        );
        let mut at_z = model.clone();
        at_z.set_separation(Separation::Constant(orbit.z_nm))?;
        let samples = sample_trajectory(
            &at_z,
            &orbit.state,
            orbit.multiplicity.max(2),
            self.samples_per_period,
            &hybrid::Settings::default(),
        )?;
        let period = model.period_us();
        let column = |value: fn(&afm::TrajectorySample) -> f64| -> Vec<f64> {
            samples.iter().map(value).collect()
        };
        let trajectory = json!({
            "t_periods": samples.iter().map(|s| s.t_us / period).collect::<Vec<f64>>(),
            "u_nm": column(|s| s.u_nm),
            "gap_nm": column(|s| s.gap_nm),
            "force_nn": column(|s| s.force_nn),
        });
        Ok((orbit, json!({"orbit": object, "trajectory": trajectory})))
    }
}

/// The `drumroll simulate --plot FILE.svg` figure of `orbit` on `diagram`'s case.
pub fn orbit_svg(diagram: &DiagramRun, orbit: &SteadyOrbit) -> Result<String> {
    orbit_figure(&diagram.case.name, &diagram.model, orbit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagram_request::DiagramRequest;

    /// A clicked branch point's orbit is the branch's orbit: its A/A0 and impacts per period
    /// equal the point's (Newton converges to the same orbit to 1e-10), and the time series'
    /// lowest gap matches the orbit's gap minimum to the sampling's resolution.
    #[test]
    fn a_branch_points_orbit_is_that_points_orbit() {
        let run = DiagramRequest::builtin("biolever-mica")
            .compute()
            .expect("diagram");
        let json = run.json();
        let points = json["points"].as_array().expect("points");
        let point = &points[points.len() / 2];
        let request = OrbitRequest {
            z_nm: point["z_nm"].as_f64().expect("z"),
            state: serde_json::from_value(point["state"].clone()).expect("state"),
            samples_per_period: 2000,
        };
        let (orbit, object) = request.compute(&run).expect("orbit");
        assert!(orbit.converged);
        let ratio = object["orbit"]["amplitude_ratio"].as_f64().expect("ratio");
        let expected = point["amplitude_ratio"].as_f64().expect("point ratio");
        assert!((ratio - expected).abs() < 1e-8, "{ratio} vs {expected}");
        assert_eq!(
            object["orbit"]["impacts_per_orbit"],
            point["impacts_per_orbit"]
        );
        let gaps = object["trajectory"]["gap_nm"].as_array().expect("gaps");
        assert_eq!(gaps.len(), 2 * 2000 + 1);
        let lowest = gaps
            .iter()
            .filter_map(Value::as_f64)
            .fold(f64::INFINITY, f64::min);
        let min_gap = object["orbit"]["min_gap_nm"].as_f64().expect("min gap");
        // One sample step is 1/2000 of a period; the gap's speed is at most w A ~ 0.6 nm/us
        // times T/2000 ~ 0.05 us: 0.03 nm.
        assert!(
            lowest >= min_gap - 1e-9 && lowest - min_gap < 0.03,
            "{lowest} vs {min_gap}"
        );
        assert!(orbit_svg(&run, &orbit).expect("svg").contains("<svg"));
    }

    #[test]
    fn a_state_of_the_wrong_size_is_refused() {
        let run = DiagramRequest::builtin("biolever-mica")
            .compute()
            .expect("diagram");
        let request = OrbitRequest {
            z_nm: 5.0,
            state: vec![0.0; 3],
            samples_per_period: 100,
        };
        let message = format!("{:#}", request.compute(&run).unwrap_err());
        assert!(message.contains("2 x 2"), "{message}");
    }
}
