//! The paper's Fig. 1 (Melcher, Xu, Raman 2008; MODEL.md section 7): the Biolever approaching
//! mica with A0 = 10 nm taps once, twice and three times per period at A/A0 = 0.95, 0.90 and
//! 0.50. The orbits come from `drumroll simulate --amplitude-ratio` (slow approach, Newton on
//! the stroboscopic map); each impact count is then confirmed by a plain time-domain run of 60
//! periods from that orbit's state, which uses no Newton iteration.

use acceptance::time_domain_impacts;
use afm::{
    builtin_case, find_amplitude_ratio, AmplitudeRatioSearch, SteadyOrbitSettings, TappingModel,
};

#[test]
fn biolever_on_mica_taps_once_twice_three_times_at_the_papers_amplitude_ratios() {
    let case = builtin_case("biolever-mica").expect("built-in case");
    let model = TappingModel::from_case(&case).expect("model");
    let settings = SteadyOrbitSettings::default();
    for (ratio, impacts) in [(0.95, 1), (0.90, 2), (0.50, 3)] {
        let search = AmplitudeRatioSearch::new(ratio).expect("ratio in range");
        let orbit = find_amplitude_ratio(&model, &search, &settings).expect("ratio reached");
        assert!(orbit.converged && orbit.multiplicity == 1 && orbit.stable);
        let (found, _) = orbit.lockin(model.free_amplitude_nm());
        // The ratio is located by root finding on Z to 1e-9 nm; dA/dZ ~ 0.1 per nm.
        assert!(
            (found - ratio).abs() < 1e-8,
            "A/A0 = {found} for target {ratio}"
        );
        assert_eq!(orbit.observables().impacts.len(), impacts, "A/A0 = {ratio}");
        // Independent: the time domain, started on the orbit, keeps the same impact count.
        assert_eq!(
            time_domain_impacts(&model, orbit.z_nm, &orbit.state, 60),
            impacts
        );
    }
}
