//! The capillary meniscus (MODEL.md section 9, "Capillary meniscus") against references
//! written here: a fixed-step RK4 brute force with its own force (Hertz's sphere from the
//! moduli, the Laplace force `4 pi R gamma cos(theta)` and the Kelvin rupture gap
//! `2 r_K cos(theta)`, all computed here) and its own meniscus flag (set where the gap falls
//! below 0, cleared where it rises above the rupture gap), sharing with drumroll only the
//! cantilever's free field; the loop's exact area `F_m d_r` as the dissipated energy; and the
//! vanishing meniscus against the Hertz sphere's grazing points.

mod hertz_limit;
mod hysteretic_reference;

use afm::{
    approach_diagram, builtin_cantilever, builtin_case, diagram, steady_orbit, DiagramSettings,
    OrbitStart, Sample, Separation, SteadyOrbitSettings, TappingModel,
};
use hysteretic_reference::rk4;

/// The built-in air case: the stiff silicon lever on mica at 40 % relative humidity.
const CASE: &str = "rectangular-air-mica-humid";

fn humid_model(z: f64) -> TappingModel {
    let mut model = TappingModel::from_case(&builtin_case(CASE).unwrap()).unwrap();
    model.set_separation(Separation::Constant(z)).unwrap();
    model
}

/// The meniscus written out independently from the case's inputs: the tip (`R` = 10 nm,
/// silicon's 130 GPa, 0.3) on mica (60 GPa, 0.3); water at 20 C (72.8 mN/m, 18.0e-6 m^3/mol,
/// 293.15 K, contact angle 0) at `RH` = 0.4.
struct Meniscus {
    /// Hertz's `(4/3) E* sqrt(R)`, nN/nm^{3/2}.
    hertz: f64,
    /// `F_m = 4 pi R gamma`, nN.
    force: f64,
    /// `d_r = 2 gamma V_m / (R_g T ln(1/RH))`, nm.
    rupture: f64,
}

impl Meniscus {
    fn water() -> Self {
        let r: f64 = 10.0;
        let e_star = 1.0 / ((1.0 - 0.09) / 130.0 + (1.0 - 0.09) / 60.0);
        let gamma = 72.8e-3; // nN/nm
        let kelvin_m = 72.8e-3 * 18.0e-6 / (8.314_462_618 * 293.15 * (1.0f64 / 0.4).ln());
        Self {
            hertz: 4.0 / 3.0 * e_star * r.sqrt(),
            force: 4.0 * std::f64::consts::PI * r * gamma,
            rupture: 2.0 * kelvin_m * 1e9,
        }
    }

    fn force(&self, gap: f64) -> f64 {
        let hertz = if gap < 0.0 {
            self.hertz * (-gap).powf(1.5)
        } else {
            0.0
        };
        hertz - self.force
    }
}

/// The brute force's force: Hertz inside contact, minus the meniscus while it exists (`wet`),
/// nN at the gap `d`.
fn meniscus_force(m: &Meniscus, wet: bool) -> impl Fn(f64) -> f64 + '_ {
    move |gap| {
        if wet {
            m.force(gap)
        } else if gap < 0.0 {
            m.hertz * (-gap).powf(1.5)
        } else {
            0.0
        }
    }
}

/// The first place where the force's form changes over a step ending at `x` (time `t`):
/// the meniscus's formation (`d < 0`) or rupture (`d > d_r`), or the tip entering or
/// leaving the sample while wet (Hertz's `3/2` power starts there).
fn changes(model: &TappingModel, m: &Meniscus, wet: bool, inside: bool, t: f64, x: &[f64]) -> bool {
    let gap = model.gap(t, x);
    (gap < 0.0) != inside || (wet && gap > m.rupture)
}

/// Fixed-step RK4 over `duration` from `(0, x0)` (dry, free) with `steps` steps, each step
/// that changes the force's form split there (bisection of its length to 1e-14 us); returns
/// the final state and the times the meniscus formed and ruptured.
fn brute_force(
    model: &TappingModel,
    x0: &[f64],
    duration: f64,
    steps: usize,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let m = Meniscus::water();
    let h = duration / steps as f64;
    let (mut t, mut x, mut wet, mut inside) = (0.0, x0.to_vec(), false, false);
    let (mut formed, mut ruptured) = (Vec::new(), Vec::new());
    while t < duration - 1e-9 * h {
        let step = h.min(duration - t);
        let next = rk4(model, meniscus_force(&m, wet), t, &x, step);
        if !changes(model, &m, wet, inside, t + step, &next) {
            x = next;
            t += step;
            continue;
        }
        let (mut lo, mut hi) = (0.0, step);
        while hi - lo > 1e-14 {
            let mid = 0.5 * (lo + hi);
            let y = rk4(model, meniscus_force(&m, wet), t, &x, mid);
            if changes(model, &m, wet, inside, t + mid, &y) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        x = rk4(model, meniscus_force(&m, wet), t, &x, hi);
        t += hi;
        let gap = model.gap(t, &x);
        if wet && gap > m.rupture {
            wet = false;
            ruptured.push(t);
        } else {
            inside = !inside;
            if inside && !wet {
                wet = true;
                formed.push(t);
            }
        }
    }
    (x, formed, ruptured)
}

/// The case's inputs give the meniscus of the reference: `F_m` to 1e-12 nN and `d_r` to
/// 1e-12 nm.
#[test]
fn the_case_builds_the_meniscus_of_the_reference() {
    let model = humid_model(15.0);
    let m = Meniscus::water();
    let d_r = model.release_gap_nm().expect("a hysteretic law");
    assert!((d_r - m.rupture).abs() < 1e-12, "{d_r} vs {}", m.rupture);
    // Attached, outside contact, the force is -F_m.
    let z = 15.0;
    let x = [m.rupture / 2.0 - z, 0.0];
    let f = model.tip_sample_force_in_mode(afm::model::ATTACHED, 0.0, &x);
    assert!((f + m.force).abs() < 1e-12, "{f} vs {}", -m.force);
    assert!(
        (model.hertz().coefficient - m.hertz).abs() < 1e-12 * m.hertz,
        "Hertz"
    );
}

/// From the free orbit's state at `Z = Z_G1 - 2 nm` (in free flight at `t = 0`), drumroll's
/// flow over three periods (three meniscus formations and ruptures through the transient)
/// against the brute force with 300 000 steps: the states agree to 2e-8 nm (nm/us) and the
/// formation and rupture times to 1e-10 us. Measured: 6.5e-10 in the state, 1.2e-11 us in the
/// events; halving the brute force's step moves its state by 1.7e-9 (its own error: Hertz's
/// 3/2 power spoils RK4's order at the contact's edges), so the tolerances are ten times what
/// the reference resolves.
#[test]
fn capillary_flow_matches_the_brute_force() {
    let probe = humid_model(0.0);
    let z = probe.grazing_separation_nm() - 2.0;
    let model = humid_model(z);
    let m = Meniscus::water();
    let x0 = model.free_state();
    assert!(model.gap(0.0, &x0) > m.rupture, "t = 0 is in free flight");
    let duration = 3.0 * model.period_us();
    let settings = SteadyOrbitSettings::default();
    let flow = hybrid::flow_map(
        &model,
        0.0,
        &x0,
        duration,
        hybrid::Sensitivity::None,
        &settings.integration,
    )
    .unwrap();
    let (x, formed, ruptured) = brute_force(&model, &x0, duration, 300_000);
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
    let down: Vec<f64> = events(0, hybrid::Direction::Down);
    let broken = events(1, hybrid::Direction::Up);
    assert_eq!(formed.len(), 3, "three formations");
    assert_eq!(ruptured.len(), 3, "three ruptures");
    // Every formation is a Down crossing of d = 0 (the others, inside the meniscus, re-enter
    // contact without forming one).
    for t in &formed {
        assert!(
            down.iter().any(|d| (d - t).abs() < 1e-10),
            "formation at {t} not among {down:?}"
        );
    }
    assert_eq!(broken.len(), ruptured.len());
    for (a, b) in broken.iter().zip(&ruptured) {
        assert!((a - b).abs() < 1e-10, "rupture at {a} vs {b}");
    }
}

/// On the case's steady orbit at `0.75 Z_G1` (one contact per period) the meniscus takes the
/// loop's exact area per formation, `F_m d_r` (the force `-F_m` acts from `d = 0` to `d_r` on
/// the way out only), at 1 nN nm = 6.241509074 eV: `dissipated_ev` agrees to 1e-9 relative
/// (measured 7.4e-11, the quadrature's) and the energy balance closes below 1e-9 (measured
/// 1.0e-12).
#[test]
fn capillary_dissipates_the_loop_area() {
    let probe = humid_model(0.0);
    let z = 0.75 * probe.grazing_separation_nm();
    let model = humid_model(z);
    let orbit = steady_orbit(
        &model,
        z,
        OrbitStart::Approach,
        &SteadyOrbitSettings::default(),
    )
    .unwrap();
    assert!(
        orbit.converged && orbit.multiplicity == 1,
        "a period-1 orbit"
    );
    let observables = orbit.observables();
    assert_eq!(observables.impacts_per_period, 1.0);
    let m = Meniscus::water();
    let loop_area_ev = m.force * m.rupture * 6.241509074;
    assert!(
        (observables.dissipated_ev - loop_area_ev).abs() < 1e-9 * loop_area_ev,
        "{} vs {loop_area_ev}",
        observables.dissipated_ev
    );
    assert!(observables.energy_balance_residual < 1e-9);
}

/// The meniscus's force `4 pi R gamma cos(theta)` vanishes with the surface tension: at
/// `gamma = 1e-12 mN/m` (`F_m` = 1.1e-13 nN for the Biolever's 30 nm tip on the soft
/// sample) the approach diagram's grazing points are the Hertz sphere's to 1e-9 nm (the
/// meniscus moves them by about `F_m / k_1` = 3e-12 nm; the contact is integrated by DOP853
/// instead of Hertz's Taylor series, both to 1e-12). Measured: G1 2e-15, G2 1.4e-11, G3
/// 7.1e-11 nm.
#[test]
fn vanishing_meniscus_reproduces_hertz_grazing() {
    let sample = |contact: &str| -> Sample {
        let text = format!(
            r#"{{"name": "test", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.3{contact}}}"#
        );
        afm::fixtures::parse_sample("test.json", &text).unwrap()
    };
    let build = |s: Sample| {
        let cantilever = builtin_cantilever("biolever").unwrap();
        TappingModel::new(cantilever, s, 10.0, None, Separation::Constant(0.0)).unwrap()
    };
    let wet = build(sample(
        r#", "contact": {"law": "capillary", "relative_humidity": 0.4, "surface_tension_mn_per_m": 1e-12}"#,
    ));
    let dry = build(sample(""));
    hertz_limit::assert_hertz_grazing(&wet, &dry, 3, 1e-9);
}

/// The case's approach and retract diagrams (MODEL.md section 9, "Capillary meniscus"): each
/// formation costs the loop's area `E_m = F_m d_r`, and a period-1 orbit of one mode driven at
/// its resonance replaces `pi k A (A0 sin(phi) - A) / Q` per period (drive work minus damping;
/// the higher harmonics of `u` are 1e-3 of `A`), so a period-1 orbit needs
/// `A (A0 sin(phi) - A) >= E_m Q / (pi k)`: just below `G1` (`A -> A0`) it cannot exist and the
/// cantilever taps only every few periods. Checked: the approach jumps from `G1` (located at
/// the free orbit's closed form to 2e-8 nm: Newton's residual 1e-10 over the free orbit's
/// distance from a multiplier 1, `1 - exp(-pi/Q)` = 5e-3; measured 8e-9) over that band to stable period-1 orbits with one
/// formation per period, each dissipating `E_m` (1e-8 relative) with its energy balance
/// closed (1e-9); the retract's branch ends (`pull-off`) where the inequality becomes an
/// equality, its `A/A0` to 1e-5 of the root `A` of `A (A0 sin(phi) - A) = E_m Q / (pi k)` at
/// its phase (the higher harmonics' share of the damping; the branch end is the located fold
/// of the attached orbits; measured 6.8e-7), and the approach's first point past the jump
/// lies below it, within one step of the walk past the jump (`A0/100`: the walk skips no
/// separation where a stable period-1 orbit exists).
#[test]
fn the_approach_jumps_over_the_band_of_intermittent_taps() {
    let model = humid_model(0.0);
    let m = Meniscus::water();
    let loop_area = m.force * m.rupture;
    let approach = approach_diagram(&model, &DiagramSettings::approach(&model)).unwrap();
    let g1 = approach
        .special_points
        .iter()
        .find(|p| p.label == "G1")
        .expect("G1");
    assert!((g1.z_nm - model.grazing_separation_nm()).abs() < 2e-8);
    let below: Vec<_> = approach
        .points
        .iter()
        .filter(|p| p.z_nm < g1.z_nm - 1e-6)
        .collect();
    assert!(below.len() >= 100, "{} points below G1", below.len());
    for point in &below {
        assert!(point.stable && point.multiplicity == 1 && point.impacts_per_orbit == 1);
        let ev = point.dissipated_ev / 6.241509074;
        assert!(
            (ev - loop_area).abs() < 1e-8 * loop_area,
            "{ev} vs {loop_area}"
        );
        assert!(point.energy_balance_residual < 1e-9);
    }

    let lowest = approach
        .points
        .iter()
        .min_by(|a, b| a.z_nm.total_cmp(&b.z_nm))
        .unwrap();
    let retract = diagram(
        &model,
        &lowest.state,
        lowest.z_nm,
        &DiagramSettings::retract(&model),
    )
    .unwrap();
    let end = retract
        .special_points
        .iter()
        .find(|p| p.label == "pull-off")
        .expect("the retract's branch end");
    let mode = &model.cantilever().modes[0];
    let a0 = model.free_amplitude_nm();
    let bound = loop_area * mode.quality_factor / (std::f64::consts::PI * mode.stiffness_n_per_m);
    let reach = a0 * end.phase_deg.to_radians().sin();
    let root = 0.5 * (reach + (reach * reach - 4.0 * bound).sqrt()) / a0;
    assert!(
        (end.amplitude_ratio - root).abs() < 1e-5,
        "branch end at A/A0 = {} vs {root}",
        end.amplitude_ratio
    );
    // Above the band's lower edge on the approach: the first point past the jump.
    let first = below[0];
    assert!(
        first.amplitude_ratio < root + 1e-5,
        "{}",
        first.amplitude_ratio
    );
    // The walk past the jump (steps of A0/100 from half a largest step below G1) lands on the
    // first of its separations below the retract's branch end, where the stable period-1
    // orbit exists: it skips none.
    let walk_step = a0 / 100.0;
    assert!(
        first.z_nm < end.z_nm && first.z_nm > end.z_nm - walk_step,
        "landed at {} nm, branch end at {} nm",
        first.z_nm,
        end.z_nm
    );
}

/// The energy budget that lets the diagram's walk skip its recurrence search (MODEL.md section
/// 9, "Capillary meniscus") rules a period-1 orbit out exactly between the root of
/// `Z (A0 - Z) = E_m Q / (pi k)` (the meniscus's loss `E_m = F_m d_r` from the reference's own
/// constants; one mode driven at resonance, `F_1 = k A0 / Q`) and first contact: admitted
/// 1e-6 nm below the root, ruled out 1e-6 nm above it and just below `Z_G1`, admitted above
/// `Z_G1` (no tap needed) and below the budget's peak `A0 / 2` (a larger amplitude than `Z`
/// gains there); never ruled out for JKR (no
/// fixed loss per formation: its walk is unchanged).
#[test]
fn energy_budget_rules_out_the_band_above_its_root() {
    use afm::diagram::period_one_budget::admits_period_one;
    let model = humid_model(0.0);
    let m = Meniscus::water();
    let mode = &model.cantilever().modes[0];
    let a0 = model.free_amplitude_nm();
    let bound =
        m.force * m.rupture * mode.quality_factor / (std::f64::consts::PI * mode.stiffness_n_per_m);
    let root = 0.5 * (a0 + (a0 * a0 - 4.0 * bound).sqrt());
    let g1 = model.grazing_separation_nm();
    assert!(root > 0.5 * a0 && root < g1, "root {root} nm");
    assert!(admits_period_one(&model, root - 1e-6));
    assert!(!admits_period_one(&model, root + 1e-6));
    assert!(!admits_period_one(&model, g1 - 1e-6));
    assert!(admits_period_one(&model, g1 + 1e-6));
    // At 1 nm, below the peak, `Z (A0 - Z)` = 19 nm^2 is short of the bound (50.7 nm^2), but an
    // amplitude nearer the peak would meet it: admitted.
    assert!(1.0 * (a0 - 1.0) < bound);
    assert!(admits_period_one(&model, 1.0));
    let sticky = TappingModel::from_case(&builtin_case("biolever-sticky").unwrap()).unwrap();
    for z in [1.0, 5.0, 9.0, 9.99] {
        assert!(admits_period_one(&sticky, z));
    }
}
