//! The paper's Fig. 1 (MODEL.md section 7): the Biolever on mica (A0 = 10 nm, w = w_1),
//! approaching the sample, taps once, twice and three times per period at A/A0 = 0.95, 0.90 and
//! 0.50. A quasi-static approach: Z decreases in small steps from first contact, each orbit
//! settled from the previous one.

use afm::{observe_period, Separation, TappingModel};
use hybrid::{flow_map, Sensitivity, Settings};

#[test]
fn biolever_on_mica_taps_once_twice_and_three_times_as_in_figure_1() {
    let case = afm::builtin_case("biolever-mica").expect("case");
    let mut model = TappingModel::from_case(&case).expect("model");
    let settings = Settings::default();
    let first_contact = model.grazing_separation_nm();
    let mut x = model.free_state();
    // (A/A0, impacts per period) along the approach.
    let mut branch: Vec<(f64, usize)> = Vec::new();
    let steps = 200;
    for j in 1..steps {
        let z = first_contact * (1.0 - 0.8 * j as f64 / steps as f64);
        model
            .set_separation(Separation::Constant(z))
            .expect("finite");
        // 15 periods per step: transients decay by exp(-15 pi / Q_1) ~ 1e-17.
        x = flow_map(
            &model,
            0.0,
            &x,
            15.0 * model.period_us(),
            Sensitivity::None,
            &settings,
        )
        .expect("settle")
        .state;
        let (_, observed) =
            observe_period(&model, 0.0, &x, Sensitivity::None, &settings, 1).expect("observe");
        branch.push((observed.amplitude_ratio, observed.impacts.len()));
    }
    // The amplitude ratio decreases monotonically along this approach (no jump to bracket).
    assert!(branch.windows(2).all(|w| w[1].0 < w[0].0));
    for (ratio, impacts) in [(0.95, 1), (0.90, 2), (0.50, 3)] {
        // The orbits just above and just below the paper's amplitude ratio.
        let index = branch
            .iter()
            .position(|&(r, _)| r < ratio)
            .expect("the approach reaches the ratio");
        assert!(index > 0);
        assert_eq!(
            branch[index - 1].1,
            impacts,
            "A/A0 = {ratio}: {:?}",
            branch[index - 1]
        );
        assert_eq!(
            branch[index].1, impacts,
            "A/A0 = {ratio}: {:?}",
            branch[index]
        );
    }
}
