//! The hysteretic contact laws (MODEL.md section 9, "JKR" and "Capillary meniscus") against
//! references written here: a fixed-step RK4 brute force with its own JKR force (the contact
//! radius by bisection of `delta(a)`) and its own attachment flag (set where the gap falls
//! below 0, cleared where it rises above the pull-off gap), sharing with drumroll only the
//! cantilever's free field; the exact hysteresis loop area as the dissipated energy; and
//! `W = 0` against the Hertz sphere's grazing points.

mod hertz_limit;
mod hysteretic_reference;

use afm::{
    approach_diagram, builtin_cantilever, steady_orbit, DiagramSettings, OrbitStart, Sample,
    Separation, SteadyOrbitSettings, TappingModel,
};
use hysteretic_reference::{attached_force, rk4, Jkr};

/// Work of adhesion of the test sample, mJ/m^2 (= 1e-3 nN/nm).
const W_MJ: f64 = 0.2;

fn model_with(contact: Option<&str>, z: f64) -> TappingModel {
    let contact = contact.map_or(String::new(), |c| format!(r#", "contact": {c}"#));
    let text =
        format!(r#"{{"name": "test", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.3{contact}}}"#);
    let sample: Sample = afm::fixtures::parse_sample("test.json", &text).unwrap();
    let cantilever = builtin_cantilever("biolever").unwrap();
    TappingModel::new(cantilever, sample, 10.0, None, Separation::Constant(z)).unwrap()
}

fn jkr_model(z: f64) -> TappingModel {
    model_with(
        Some(&format!(
            r#"{{"law": "jkr", "work_of_adhesion_mj_per_m2": {W_MJ}}}"#
        )),
        z,
    )
}

/// Whether the attachment changes over a step ending at state `x` (time `t`).
fn switches(model: &TappingModel, jkr: &Jkr, attached: bool, t: f64, x: &[f64]) -> bool {
    let gap = model.gap(t, x);
    if attached {
        gap > jkr.pull_off_gap()
    } else {
        gap < 0.0
    }
}

/// Fixed-step RK4 over `duration` from `(0, x0)` with `steps` steps, each step that changes
/// the attachment split at the change (bisection of its length to 1e-14 us); returns the final
/// state and the times of attachment and detachment.
fn brute_force(
    model: &TappingModel,
    x0: &[f64],
    attached0: bool,
    duration: f64,
    steps: usize,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let jkr = Jkr::of(model, W_MJ);
    let h = duration / steps as f64;
    let (mut t, mut x, mut attached) = (0.0, x0.to_vec(), attached0);
    let (mut attach, mut detach) = (Vec::new(), Vec::new());
    while t < duration - 1e-9 * h {
        let step = h.min(duration - t);
        let next = rk4(model, attached_force(&jkr, attached), t, &x, step);
        if !switches(model, &jkr, attached, t + step, &next) {
            x = next;
            t += step;
            continue;
        }
        let (mut lo, mut hi) = (0.0, step);
        while hi - lo > 1e-14 {
            let mid = 0.5 * (lo + hi);
            let y = rk4(model, attached_force(&jkr, attached), t, &x, mid);
            if switches(model, &jkr, attached, t + mid, &y) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        x = rk4(model, attached_force(&jkr, attached), t, &x, hi);
        t += hi;
        if attached {
            detach.push(t);
        } else {
            attach.push(t);
        }
        attached = !attached;
    }
    (x, attach, detach)
}

/// The steady orbit at `Z = Z_G1 - 0.5 nm` (one attachment per period), flowed by drumroll over
/// two periods and by the brute force (400 000 steps): the states agree to 2e-8 nm (nm/us)
/// and the attachment and pull-off times to 1e-8 us. Measured: 3.8e-9 in the state, 2e-9 us
/// in the events; halving the brute force's step moves its state by 1.8e-9 (its own error,
/// RK4's fourth order spoiled at pull-off, where the force has a square-root singularity in
/// the gap), so the tolerances are ten times what the reference can resolve.
#[test]
fn jkr_flow_matches_the_brute_force() {
    let probe = jkr_model(0.0);
    let z = probe.grazing_separation_nm() - 0.5;
    let model = jkr_model(z);
    let settings = SteadyOrbitSettings::default();
    let orbit = steady_orbit(&model, z, OrbitStart::Transient, &settings).unwrap();
    assert!(orbit.converged && orbit.multiplicity == 1);
    let jkr = Jkr::of(&model, W_MJ);
    assert!(
        model.gap(0.0, &orbit.state) > jkr.pull_off_gap(),
        "t = 0 is in free flight"
    );
    let duration = 2.0 * model.period_us();
    let flow = hybrid::flow_map(
        &model,
        0.0,
        &orbit.state,
        duration,
        hybrid::Sensitivity::None,
        &settings.integration,
    )
    .unwrap();
    let (x, attach, detach) = brute_force(&model, &orbit.state, false, duration, 400_000);
    for (a, b) in x.iter().zip(&flow.state) {
        assert!((a - b).abs() < 2e-8, "state {a} vs {b}");
    }
    let events = |surface: usize, direction: hybrid::Direction| -> Vec<f64> {
        flow.events
            .iter()
            .filter(|e| e.surface == surface && e.direction == direction)
            .map(|e| e.t)
            .collect()
    };
    let formed = events(0, hybrid::Direction::Down);
    let broken = events(1, hybrid::Direction::Up);
    assert_eq!(formed.len(), 2);
    assert_eq!(attach.len(), 2);
    assert_eq!(broken.len(), detach.len());
    for (a, b) in formed.iter().zip(&attach).chain(broken.iter().zip(&detach)) {
        assert!((a - b).abs() < 1e-8, "event at {a} vs {b}");
    }
}

/// On that orbit the sample takes the hysteresis loop's area per attachment,
/// `-int_0^{d_po} F_JKR dd` (by 20 000-point Simpson here, in `sqrt` of the distance to
/// pull-off to absorb its square-root singularity), converted at 1 nN nm = 6.241509074 eV:
/// `dissipated_ev` agrees to 1e-8 relative (measured 2e-10, the Simpson rule's error), and
/// the energy balance closes below 1e-9 (measured 9e-14).
#[test]
fn jkr_dissipates_the_hysteresis_loop() {
    let probe = jkr_model(0.0);
    let z = probe.grazing_separation_nm() - 0.5;
    let model = jkr_model(z);
    let orbit = steady_orbit(
        &model,
        z,
        OrbitStart::Transient,
        &SteadyOrbitSettings::default(),
    )
    .unwrap();
    let observables = orbit.observables();
    let jkr = Jkr::of(&model, W_MJ);
    let d_po = jkr.pull_off_gap();
    // d = d_po - s^2, s in [0, sqrt(d_po)]: dd = -2 s ds.
    let n = 20_000;
    let top = d_po.sqrt();
    let integrand = |s: f64| jkr.force(d_po - s * s) * 2.0 * s;
    let h = top / n as f64;
    let mut sum = integrand(0.0) + integrand(top);
    for i in 1..n {
        sum += integrand(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    let loop_area_ev = -sum * h / 3.0 * 6.241509074;
    assert!(loop_area_ev > 0.0);
    let impacts = observables.impacts_per_period;
    assert_eq!(impacts, 1.0);
    assert!(
        (observables.dissipated_ev - loop_area_ev).abs() < 1e-8 * loop_area_ev,
        "{} vs {loop_area_ev}",
        observables.dissipated_ev
    );
    assert!(observables.energy_balance_residual < 1e-9);
}

/// `W = 0` is the Hertz sphere: the approach diagram's grazing points agree to 1e-9 nm (the
/// sample file's `jkr` with `W = 0` builds Hertz's law, so they are equal; measured 0).
#[test]
fn zero_adhesion_reproduces_hertz_grazing() {
    let jkr = model_with(
        Some(r#"{"law": "jkr", "work_of_adhesion_mj_per_m2": 0.0}"#),
        0.0,
    );
    let hertz = model_with(None, 0.0);
    hertz_limit::assert_hertz_grazing(&jkr, &hertz, 2, 1e-9);
}

/// The Biolever's approach on the adhesive sample: G1 located to 1e-9 nm at the free orbit's
/// first contact (the force-free closed form, where the adhesion has not yet acted), and past
/// it the diagram jumps to attached orbits with one impact per period whose dissipated energy
/// is positive and whose energy balance closes below 1e-9.
#[test]
fn adhesive_approach_diagram_jumps_to_contact() {
    let model = jkr_model(0.0);
    let diagram = approach_diagram(&model, &DiagramSettings::approach(&model)).unwrap();
    let g1 = diagram
        .special_points
        .iter()
        .find(|p| p.label == "G1")
        .expect("G1");
    assert!((g1.z_nm - model.grazing_separation_nm()).abs() < 1e-9);
    let attached: Vec<_> = diagram
        .points
        .iter()
        .filter(|p| p.z_nm < g1.z_nm - 0.1)
        .collect();
    assert!(attached.len() >= 5, "{} points past G1", attached.len());
    for point in attached {
        assert!(point.impacts_per_orbit >= 1);
        assert!(point.dissipated_ev > 0.0);
        assert!(point.energy_balance_residual < 1e-9);
    }
}

/// No `fold` at the jumps of a JKR approach: the built-in `biolever-adhesive` (default largest
/// step, 0.04 nm) reports `G1`, `G2`, `G3` only, and `biolever-sticky --a0 12 --max-step 0.02`
/// no `fold` next to its `pull-off` at 10.1143 nm. Neither branch turns in `Z` there (the
/// points on both sides are monotone, and the orbits past the jump exist up to within 5e-10 nm
/// of the `pull-off`); before, the trials next to the jump took their tangents' orientation from
/// the jump's secant and a `fold` was located where that flipped the sign of `t_Z`: 7e-10 nm
/// from `G2` (8.8492558068 nm) and at 10.11411566 nm, moving by 2.5e-4 nm with the step size.
#[test]
fn jkr_approach_reports_no_fold_at_its_jumps() {
    for (case, a0, max_step) in [
        ("biolever-adhesive", None, None),
        ("biolever-sticky", Some(12.0), Some(0.02)),
    ] {
        let mut case = afm::builtin_case(case).unwrap();
        if let Some(a0) = a0 {
            case.free_amplitude_nm = a0;
        }
        let model = TappingModel::from_case(&case).unwrap();
        let defaults = DiagramSettings::approach(&model);
        let settings = DiagramSettings {
            max_step: max_step.unwrap_or(defaults.max_step),
            ..defaults
        };
        let diagram = approach_diagram(&model, &settings).unwrap();
        let labels: Vec<&str> = diagram
            .special_points
            .iter()
            .map(|p| p.label.as_str())
            .collect();
        assert!(!labels.contains(&"fold"), "{}: {labels:?}", case.name);
        assert!(labels.contains(&"G2"), "{}: {labels:?}", case.name);
    }
}

/// A regime map through JKR (`drumroll map --case biolever-adhesive --vary quality-factor-1`):
/// the `G3` curve of the attached orbits over `Q_1 = 1.0 .. 1.4`, at `Q_1` = 1.1 and 1.3 and
/// the case's 1.2, agrees with the `G3` of an independent approach diagram of the case
/// rebuilt at that `Q_1` to 1e-9 nm plus the diagram's located precision (the map's points
/// solve the grazing equations to a residual of 1e-10; the diagram brackets its point). The
/// map's grazing system splits each period at the grazing time and continues the second leg
/// in the mode the first ended in (`hybrid::flow_map_from_mode`): from the state alone, the
/// attached bit is undecidable at `d' = 0`, and without it the map's start did not converge.
#[test]
fn jkr_map_matches_independent_diagrams() {
    let case = afm::builtin_case("biolever-adhesive").unwrap();
    let model = TappingModel::from_case(&case).unwrap();
    let axis = afm::ParameterAxis::QualityFactor(1);
    let at = vec![1.1, 1.3];
    let settings = afm::RegimeMapSettings {
        at: at.clone(),
        labels: Some(vec![String::from("G3")]),
        points_per_range: 10,
        ..afm::RegimeMapSettings::new(&model, 1.0, 1.4)
    };
    let map = afm::regime_map(&case, axis, &settings).unwrap();
    assert_eq!(map.curves.len(), 1);
    let curve = &map.curves[0];
    assert_eq!(curve.label, "G3");
    for q in [1.1, 1.2, 1.3] {
        let point = curve
            .points
            .iter()
            .find(|p| (p.parameter - q).abs() < 1e-12)
            .unwrap_or_else(|| panic!("G3 at Q_1 = {q}"));
        let rebuilt = axis.apply(&case, q, "test").unwrap();
        let model = TappingModel::from_case(&rebuilt).unwrap();
        let diagram = approach_diagram(&model, &DiagramSettings::approach(&model)).unwrap();
        let special = diagram
            .special_points
            .iter()
            .find(|s| s.label == "G3")
            .unwrap_or_else(|| panic!("G3 in the diagram at Q_1 = {q}"));
        let error = (point.z_nm - special.z_nm).abs();
        assert!(
            error <= 1e-9 + special.precision_nm,
            "Q_1 = {q}: map {} vs diagram {} (precision {:e})",
            point.z_nm,
            special.z_nm,
            special.precision_nm
        );
        assert_eq!((point.impacts_before, point.impacts_after), (2, 3));
    }
}
