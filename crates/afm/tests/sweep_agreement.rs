//! The time-domain sweep against the steady orbit (shooting on the stroboscopic map, an
//! independent computation): at the paper's rate of 1 nm/s, on a short window around G2 of the
//! Biolever on mica (A0 = 10 nm), the lock-in's per-cycle A/A0 and phase follow the steady orbit
//! at the same Z to better than 1e-3 and 0.1 deg, and the impact count per cycle changes from
//! 1 to 2 within 0.01 nm of G2, which is located here independently from the steady orbits'
//! gap minima.

use afm::TappingModel;
use afm::{
    builtin_case, steady_orbit, OrbitStart, SteadyOrbit, SteadyOrbitSettings, Sweep, SweepSettings,
};

/// The second-lowest gap minimum of the steady orbit over its period, nm: positive with one
/// impact per period (the lowest near impact), negative with two; zero at G2.
fn second_minimum(orbit: &SteadyOrbit) -> f64 {
    let mut minima: Vec<f64> = orbit
        .observables()
        .gap_minima
        .iter()
        .map(|m| m.gap_nm)
        .collect();
    minima.sort_by(f64::total_cmp);
    minima[1]
}

/// G2 by bisection on the second-lowest gap minimum of the steady orbit, warm-started from
/// the orbit at the bracket end on the same side; returns (Z_G2, the orbit there).
fn locate_g2(model: &TappingModel, settings: &SteadyOrbitSettings) -> (f64, SteadyOrbit) {
    // Scan down from 9.5 nm in 0.1 nm steps for the first orbit with two impacts.
    let mut above =
        steady_orbit(model, 9.5, OrbitStart::Transient, settings).expect("orbit at 9.5 nm");
    assert_eq!(above.observables().impacts.len(), 1);
    let mut below = None;
    let mut z = 9.5;
    while z > 6.0 {
        z -= 0.1;
        let orbit =
            steady_orbit(model, z, OrbitStart::Near(&above.state), settings).expect("orbit");
        assert!(
            orbit.converged && orbit.multiplicity == 1,
            "period-1 orbit at {z}"
        );
        if orbit.observables().impacts.len() == 2 {
            below = Some(orbit);
            break;
        }
        above = orbit;
    }
    let mut below = below.expect("two impacts reached above 6 nm");
    // Bisection to 1e-7 nm.
    while above.z_nm - below.z_nm > 1e-7 {
        let middle = 0.5 * (above.z_nm + below.z_nm);
        let orbit =
            steady_orbit(model, middle, OrbitStart::Near(&above.state), settings).expect("orbit");
        if second_minimum(&orbit) > 0.0 {
            above = orbit;
        } else {
            below = orbit;
        }
    }
    (0.5 * (above.z_nm + below.z_nm), above)
}

/// Half-width of the sweep window around G2, nm: 0.1 nm at 1 nm/s is about 930 drive cycles.
const WINDOW_NM: f64 = 0.1;
/// The tolerances: the per-cycle lock-in reading against the steady orbit at the
/// cycle's mid-point Z. At 1 nm/s the separation moves 1.1e-4 nm per cycle; the orbit's
/// relaxation takes about a cycle (multipliers well inside the unit circle, Q1 = 1.2), so the
/// quasi-static lag is ~1e-4 nm, i.e. ~1e-5 in A/A0 and ~1e-2 deg (dA/dZ ~ 0.1 /nm, dPhi/dZ ~
/// 20 deg/nm near G2): the tolerances hold with a margin of about 10 unless the sweep leaves the
/// orbit.
const RATIO_TOLERANCE: f64 = 1e-3;
const PHASE_TOLERANCE_DEG: f64 = 0.1;
/// The impact count must change within this distance of G2, nm (the requirement).
const G2_TOLERANCE_NM: f64 = 0.01;

#[test]
fn sweep_follows_the_steady_orbit_around_g2() {
    let case = builtin_case("biolever-mica").expect("case");
    let model = TappingModel::from_case(&case).expect("model");
    let orbit_settings = SteadyOrbitSettings::default();
    let (z_g2, at_g2) = locate_g2(&model, &orbit_settings);
    // G2 is a grazing (the near impact touches zero continuously), not a jump.
    assert!(second_minimum(&at_g2).abs() < 1e-5, "grazing at G2");

    let mut settings = SweepSettings::for_model(&model);
    settings.from_nm = z_g2 + WINDOW_NM;
    settings.to_nm = z_g2 - WINDOW_NM;
    settings.rate_nm_per_s = 1.0;
    // Settling from the free state at the window's top: transients shrink by exp(-pi/Q1) ~ 0.07
    // per cycle, so 300 cycles leave nothing.
    settings.settle_cycles = 300;
    let sweep = Sweep::new(&model, settings).expect("sweep");
    let cycles = sweep.total_cycles();
    let records: Vec<_> = sweep.map(|r| r.expect("cycle")).collect();
    assert_eq!(records.len() as u64, cycles, "one record per cycle");

    // Agreement with the steady orbit, every 10th cycle away from G2 (warm-started along the
    // sweep, so each orbit is the one on the branch the sweep follows).
    let mut previous: Option<SteadyOrbit> = None;
    let mut compared = 0;
    for record in records.iter().step_by(10) {
        if (record.z_nm - z_g2).abs() < G2_TOLERANCE_NM {
            continue;
        }
        let orbit = steady_orbit(
            &model,
            record.z_nm,
            OrbitStart::near_or_transient(previous.as_ref().map(|o| o.state.as_slice())),
            &orbit_settings,
        )
        .expect("orbit");
        assert!(
            orbit.converged && orbit.stable,
            "stable orbit at {}",
            record.z_nm
        );
        let (ratio, phase) = orbit.lockin(model.free_amplitude_nm());
        assert!(
            (record.amplitude_ratio - ratio).abs() < RATIO_TOLERANCE,
            "A/A0 at Z = {}: sweep {} vs orbit {ratio}",
            record.z_nm,
            record.amplitude_ratio
        );
        assert!(
            (record.phase_deg - phase).abs() < PHASE_TOLERANCE_DEG,
            "phase at Z = {}: sweep {} vs orbit {phase}",
            record.z_nm,
            record.phase_deg
        );
        assert_eq!(
            record.impacts_per_period,
            orbit.observables().impacts.len() as f64,
            "impacts at Z = {}",
            record.z_nm
        );
        compared += 1;
        previous = Some(orbit);
    }
    assert!(compared > 80, "compared {compared} cycles");

    // The impact count changes from 1 to 2 within 0.01 nm of G2.
    for record in &records {
        if record.z_nm > z_g2 + G2_TOLERANCE_NM {
            assert_eq!(
                record.impacts_per_period, 1.0,
                "one impact at Z = {}",
                record.z_nm
            );
        } else if record.z_nm < z_g2 - G2_TOLERANCE_NM {
            assert_eq!(
                record.impacts_per_period, 2.0,
                "two impacts at Z = {}",
                record.z_nm
            );
        }
    }
    let lowest_single = records
        .iter()
        .filter(|r| r.impacts_per_period == 1.0)
        .map(|r| r.z_nm)
        .fold(f64::INFINITY, f64::min);
    let highest_double = records
        .iter()
        .filter(|r| r.impacts_per_period == 2.0)
        .map(|r| r.z_nm)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        lowest_single - z_g2 < G2_TOLERANCE_NM && z_g2 - highest_double < G2_TOLERANCE_NM,
        "the count changes between {highest_double} and {lowest_single} nm, G2 at {z_g2} nm"
    );
}
