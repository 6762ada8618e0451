//! Contacts shallower than the rounding of the gap.
//!
//! Next to a grazing point a new contact is only a rounding error deep: at the Biolever's G2
//! on the soft sample it meets the surface at `2e-7` nm/us, and the gap `Z + sum_i q_i` (with
//! `Z` near 9 nm, so rounded to `1.8e-15` nm steps) stays within that rounding for `1e-8` us
//! after the onset. The solver must still see one onset and one release there, with `dh/dt`
//! of each event's sign, and never fail. Before it discounted a sample one rounding step past
//! the surface while `dh/dt` pointed into the contact (`hybrid::solver`'s rules), it fired a
//! release whose rate pointed into the contact and then a second onset (three impacts per
//! period where the orbit has two), and a step that was to land on such a crossing, one
//! rounding step after the onset, could not advance time (`StepSizeUnderflow`). Both showed
//! at 7% (Biolever) and 4% (MAClever) of the separations within 1.5e-12 nm of G2 on the soft
//! sample, and made the continuation label the Biolever's G2 (A0 = 10.0007 nm) `G3`.

use afm::{
    approach_diagram, builtin_case, builtin_sample, Cantilever, DiagramSettings, Separation,
    TappingModel,
};
use hybrid::{flow_map, Direction, Sensitivity};

/// Separations scanned on each side of a grazing point, in steps of [`Z_STEP_NM`].
const STEPS_EACH_SIDE: i32 = 300;

/// Scan step of the separation, nm: the rounding of `Z` near 9 nm is 1.8e-15 nm, so neighbouring
/// separations round the gap differently.
const Z_STEP_NM: f64 = 1e-15;

/// A crossing located within its time tolerance past a tangency (a grazing minimum) may carry
/// a rate of the wrong sign, `|h''|` times that tolerance: measured at most 1.7e-13 nm/us in
/// these scans. Any larger rate of the wrong sign is a crossing that did not happen.
const TANGENCY_RATE: f64 = 1e-10;

/// The approach diagram of `model` with the largest arclength step `max_step` (nm), if given.
fn approach(model: &TappingModel, max_step: Option<f64>) -> afm::BifurcationDiagram {
    let mut settings = DiagramSettings::approach(model);
    if let Some(step) = max_step {
        settings.max_step = step;
    }
    approach_diagram(model, &settings).expect("approach diagram")
}

#[test]
fn every_crossing_next_to_a_new_contact_has_the_rate_of_its_direction() {
    for case in ["biolever-soft", "maclever-soft"] {
        let model = TappingModel::from_case(&builtin_case(case).expect("case")).expect("model");
        let diagram = approach(&model, None);
        let g2 = diagram
            .special_points
            .iter()
            .find(|s| s.label == "G2")
            .unwrap_or_else(|| panic!("{case}: no G2"));
        assert_eq!((g2.impacts_before, g2.impacts_after), (1, 2), "{case}");
        let settings = afm::SteadyOrbitSettings::default().integration;
        let (mut one, mut two) = (0, 0);
        for i in -STEPS_EACH_SIDE..=STEPS_EACH_SIDE {
            let z = g2.z_nm + f64::from(i) * Z_STEP_NM;
            let mut at_z = model.clone();
            at_z.set_separation(Separation::Constant(z))
                .expect("finite");
            let period = at_z.period_us();
            let flow = flow_map(
                &at_z,
                0.0,
                &g2.state,
                period,
                Sensitivity::TransitionAndParameter,
                &settings,
            )
            .unwrap_or_else(|e| panic!("{case} at Z = {z:.17} nm: {e}"));
            for event in &flow.events {
                let inward = match event.direction {
                    Direction::Down => -event.rate,
                    Direction::Up => event.rate,
                };
                assert!(
                    inward >= -TANGENCY_RATE,
                    "{case} at Z = {z:.17} nm: {:?} crossing at t = {} periods with dh/dt = {:e} nm/us",
                    event.direction,
                    event.t / period,
                    event.rate
                );
            }
            let onsets = flow
                .events
                .iter()
                .filter(|e| e.direction == Direction::Down)
                .count();
            match onsets {
                1 => one += 1,
                2 => two += 1,
                _ => panic!("{case} at Z = {z:.17} nm: {onsets} contact onsets in a period"),
            }
        }
        // The scan straddles the grazing point, so both counts occur (measured: one onset at
        // 299 separations and two at 302 for the Biolever; 347 and 254 for the MAClever, whose
        // new contact is within the integration's error of zero depth over the whole scan, so
        // that its count alternates).
        assert!(
            one > 0 && two > 0,
            "{case}: {one} with one onset, {two} with two"
        );
    }
}

#[test]
fn the_biolever_on_soft_at_a0_10_0007_nm_has_its_g2_labelled() {
    // The case that showed the rounding crossings: this diagram labelled its G2 `G3`, with
    // three impacts after it, where `drumroll simulate` finds two.
    let mut case = builtin_case("biolever-soft").expect("case");
    case.free_amplitude_nm = 10.0007;
    let model = TappingModel::from_case(&case).expect("model");
    let diagram = approach(&model, Some(0.013));
    let grazing: Vec<(&str, usize, usize)> = diagram
        .special_points
        .iter()
        .filter(|s| s.label.starts_with('G'))
        .map(|s| (s.label.as_str(), s.impacts_before, s.impacts_after))
        .collect();
    assert_eq!(
        grazing,
        [("G1", 0, 1), ("G2", 1, 2), ("G3", 2, 3)],
        "grazing points of the approach"
    );
    assert!(diagram.error.is_none(), "{:?}", diagram.error);
}

/// A three-mode lever (the Biolever's first mode, with the second and third of an
/// Euler-Bernoulli beam without tip mass, as `drumroll cantilever --tip-mass-ratio 0 --k1 0.036
/// --f1 9.3 --q1 1.2 --q2 2 --q3 3 --modes 3 --radius 30` writes it).
const THREE_MODES: &str = r#"{
  "name": "three",
  "description": "three modes",
  "tip_radius_nm": 30.0,
  "tip_mass_ratio": 0.0,
  "tip_youngs_modulus_gpa": 130.0,
  "tip_poisson_ratio": 0.3,
  "modes": [
    {"stiffness_n_per_m": 0.036, "frequency_khz": 9.3, "quality_factor": 1.2,
     "optical_sensitivity": 1.0, "force_ratio": 1.0},
    {"stiffness_n_per_m": 1.4138621350723086, "frequency_khz": 58.2821051396672,
     "quality_factor": 2.0, "optical_sensitivity": 3.4731270332344217,
     "force_ratio": -0.5542023805021495},
    {"stiffness_n_per_m": 11.084908403614275, "frequency_khz": 163.19158201231855,
     "quality_factor": 3.0, "optical_sensitivity": 5.701877786819476,
     "force_ratio": 0.32493994336925014}
  ]
}"#;

#[test]
fn a_three_mode_lever_on_mica_has_every_grazing_point_located() {
    // Its G2 (A0 = 5 nm, 4.3878 nm) was left unconverged: at the grazing point the new
    // contact meets the surface at 3e-10 nm/us and leaves it 4e-7 us later; the first trial in
    // it estimated the crossing out at its very start, and the landing step past it, the
    // fraction 1e-6 of the trial squared on its square-root clock (7e-14 us), could not
    // advance time (StepSizeUnderflow).
    let cantilever: Cantilever = serde_json::from_str(THREE_MODES).expect("cantilever");
    let model = TappingModel::new(
        cantilever,
        builtin_sample("mica").expect("sample"),
        5.0,
        None,
        Separation::Constant(5.0),
    )
    .expect("model");
    let diagram = approach(&model, None);
    let grazing: Vec<(&str, usize, usize, bool)> = diagram
        .special_points
        .iter()
        .filter(|s| s.label.starts_with('G'))
        .map(|s| {
            (
                s.label.as_str(),
                s.impacts_before,
                s.impacts_after,
                s.converged,
            )
        })
        .collect();
    assert_eq!(
        grazing,
        [
            ("G1", 0, 1, true),
            ("G2", 1, 2, true),
            ("G3", 2, 3, true),
            ("G4", 3, 4, true)
        ],
        "grazing points of the approach"
    );
}
