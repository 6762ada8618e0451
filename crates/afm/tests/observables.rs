//! Observables of one period against independent computations: the closed-form free orbit and
//! brute-force fine sampling of the trajectory.

mod common;

use afm::model::CONTACT;
use afm::{observe_period, orbit_observables, OrbitObservables, Separation, TappingModel};
use hybrid::{
    flow_map, flow_map_observed, Direction, HybridSystem, Sensitivity, Settings, Solver,
    StepOutcome,
};

/// The model of `case` at `Z = Z_G1 + offset`, and a state on its (converged) periodic orbit at
/// t = 0: 40 periods from the free orbit (the slowest transient decays as exp(-w_1 t / 2Q_1),
/// i.e. by exp(-40 pi / Q_1) < 1e-40 for Q_1 <= 1.6).
fn settled(case: &str, offset_nm: f64) -> (TappingModel, Vec<f64>) {
    let mut model = TappingModel::from_case(&afm::builtin_case(case).expect("case")).expect("m");
    let z = model.grazing_separation_nm() + offset_nm;
    model
        .set_separation(Separation::Constant(z))
        .expect("finite");
    let x0 = model.free_state();
    let flow = flow_map(
        &model,
        0.0,
        &x0,
        40.0 * model.period_us(),
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("transient");
    // Restart the clock: the system is T-periodic, so the state at 40 T is a state at t = 0.
    (model, flow.state)
}

/// Brute-force samples of one period: `(t, u, gap, force)` at `m` uniform times from the solver's
/// dense output (every grid time falls in exactly one step).
fn samples(model: &TappingModel, t0: f64, x0: &[f64], m: usize) -> Vec<(f64, f64, f64, f64)> {
    let period = model.period_us();
    let mut out = Vec::with_capacity(m + 1);
    let mut next = 0usize;
    let mut x = vec![0.0; model.dim()];
    flow_map_observed(
        model,
        t0,
        x0,
        period,
        Sensitivity::None,
        &Settings::default(),
        &mut |solver: &Solver<TappingModel>, _: &StepOutcome| {
            let (_, end) = solver.last_step();
            while next <= m && t0 + period * next as f64 / m as f64 <= end {
                let t = t0 + period * next as f64 / m as f64;
                solver.interpolate(t, &mut x);
                let gap = model.gap(t, &x);
                out.push((t, model.photodiode(&x), gap, model.hertz().force(gap)));
                next += 1;
            }
        },
    )
    .expect("sampling run");
    out
}

#[test]
fn free_orbit_observables_equal_the_closed_form() {
    for case in ["biolever-mica", "maclever-mica-experiment"] {
        let mut model =
            TappingModel::from_case(&afm::builtin_case(case).expect("case")).expect("model");
        let z = model.grazing_separation_nm() + 5.0;
        model
            .set_separation(Separation::Constant(z))
            .expect("finite");
        let x0 = model.free_state();
        let observed =
            orbit_observables(&model, &x0, &Settings::default(), 1).expect("observables");
        // Exact flow + 8-point Gauss-Legendre on steps of <= a quarter of the shortest period:
        // quadrature error < 1e-15 relative; allow rounding of a few hundred nodes.
        assert!(
            (observed.amplitude_nm - model.free_amplitude_nm()).abs()
                < 1e-12 * model.free_amplitude_nm(),
            "{case}: A = {}",
            observed.amplitude_nm
        );
        assert!((observed.amplitude_ratio - 1.0).abs() < 1e-12);
        assert!(
            (observed.phase_deg - model.free_phase_deg()).abs() < 1e-10,
            "{case}"
        );
        assert!(observed.impacts.is_empty());
        assert_eq!(observed.impulse_nn_us, 0.0);
        assert_eq!(observed.peak_force_nn, 0.0);
        // One gap minimum per period, 5 nm above the sample at the closed form's time.
        assert_eq!(observed.gap_minima.len(), 1, "{:?}", observed.gap_minima);
        let minimum = observed.gap_minima[0];
        assert!((minimum.gap_nm - 5.0).abs() < 1e-11, "{}", minimum.gap_nm);
        let expected_t = model.free_response().lowest_gap_time_us() / model.period_us();
        // The minimum's time is located from dh/dt = 0 (a simple root): ~1e-12 of a period.
        assert!(
            (minimum.t_periods - expected_t).abs() < 1e-9,
            "{} vs {expected_t}",
            minimum.t_periods
        );
    }
}

fn check_against_samples(model: &TappingModel, t0: f64, x0: &[f64], observed: &OrbitObservables) {
    let m = 200_000;
    let grid = samples(model, t0, x0, m);
    assert_eq!(grid.len(), m + 1);
    let period = model.period_us();
    let h = period / m as f64;
    // Trapezoid rule (= rectangle rule for the periodic Fourier integrands). The force has
    // (t - t_c)^{3/2} corners at contact onset and release: error ~ h^{5/2} per corner, about
    // 1e-11 relative with 2e5 points; dense output ~1e-10. Tolerance 1e-8 relative.
    let impulse: f64 = grid.windows(2).map(|w| 0.5 * h * (w[0].3 + w[1].3)).sum();
    assert!(
        (observed.impulse_nn_us - impulse).abs() < 1e-8 * impulse,
        "impulse {} vs {impulse}",
        observed.impulse_nn_us
    );
    assert!((observed.mean_force_nn - impulse / period).abs() < 1e-8 * impulse / period);
    let w = model.drive_angular_frequency();
    let (mut a, mut b) = (0.0, 0.0);
    for &(t, u, _, _) in &grid[..m] {
        a += 2.0 / m as f64 * u * (w * t).cos();
        b += 2.0 / m as f64 * u * (w * t).sin();
    }
    assert!((observed.amplitude_nm - a.hypot(b)).abs() < 1e-9 * a.hypot(b));
    assert!((observed.phase_deg - b.atan2(a).to_degrees()).abs() < 1e-7);
    // Contact time: the fraction of grid points with d < 0, within a grid spacing per impact
    // boundary.
    let inside = grid[..m].iter().filter(|s| s.2 < 0.0).count() as f64 / m as f64;
    let boundaries = 2.0 * observed.impacts.len() as f64;
    assert!((observed.contact_time_periods - inside).abs() <= boundaries / m as f64);
    // Peak force: the Hertz force at the deepest gap minimum, and no sample exceeds it.
    let deepest = observed
        .gap_minima
        .iter()
        .map(|m| m.gap_nm)
        .fold(f64::INFINITY, f64::min);
    let hertz_peak = model.hertz().force(deepest);
    assert!((observed.peak_force_nn - hertz_peak).abs() < 1e-12 * hertz_peak);
    let (peak_index, sampled_peak) = grid
        .iter()
        .enumerate()
        .map(|(i, s)| (i, s.3))
        .fold((0, 0.0), |best, x| if x.1 > best.1 { x } else { best });
    assert!(sampled_peak <= hertz_peak * (1.0 + 1e-10));
    // The nearest grid point is at most h/2 from the peak, where F falls by F'' h^2 / 8; F'' h^2
    // is estimated by the second difference at the sampled peak (allow twice that).
    if peak_index > 0 && peak_index < m {
        let second = (grid[peak_index + 1].3 - 2.0 * sampled_peak + grid[peak_index - 1].3).abs();
        assert!(
            hertz_peak - sampled_peak <= 0.25 * second + 1e-12 * hertz_peak,
            "{sampled_peak} vs {hertz_peak} (second difference {second})"
        );
    }
    // Impacts per period = contact intervals seen on the grid (none shorter than h here).
    let mut crossings = 0;
    for w in grid.windows(2) {
        if w[0].2 >= 0.0 && w[1].2 < 0.0 {
            crossings += 1;
        }
    }
    // An impact in progress at the window start is counted by its onset at the window end.
    if grid[0].2 < 0.0 && grid[m].2 >= 0.0 {
        crossings += 1;
    }
    assert_eq!(observed.impacts.len(), crossings, "{:?}", observed.impacts);
}

#[test]
fn tapping_orbit_observables_match_brute_force_sampling() {
    // Biolever on mica 1 nm and 3 nm below first contact; MAClever on the soft sample 4 nm.
    for (case, offset) in [
        ("biolever-mica", -1.0),
        ("biolever-mica", -3.0),
        ("maclever-soft", -4.0),
    ] {
        let (model, x0) = settled(case, offset);
        let (flow, observed) =
            observe_period(&model, 0.0, &x0, Sensitivity::None, &Settings::default(), 3)
                .expect("observables");
        // Periodic orbit: the state returns (transients gone, see `settled`).
        for (k, (end, start)) in flow.state.iter().zip(&x0).enumerate() {
            assert!(
                (end - start).abs() < 1e-8 * (1.0 + start.abs()),
                "{case} {k}"
            );
        }
        let downs = flow
            .events
            .iter()
            .filter(|e| e.direction == Direction::Down)
            .count();
        assert_eq!(observed.impacts.len(), downs, "{case}");
        assert!(
            !observed.impacts.is_empty(),
            "{case} at {offset} nm must tap"
        );
        for impact in &observed.impacts {
            assert!(impact.velocity_nm_per_us < 0.0);
            assert!(impact.end_periods > impact.start_periods);
            // Each impact contains a negative gap minimum whose Hertz force is its peak.
            let inside: Vec<_> = observed
                .gap_minima
                .iter()
                .filter(|m| m.t_periods > impact.start_periods && m.t_periods < impact.end_periods)
                .collect();
            assert!(inside.iter().all(|m| m.gap_nm < 0.0));
            let deepest = inside.iter().map(|m| m.gap_nm).fold(0.0, f64::min);
            assert_eq!(impact.peak_force_nn, model.hertz().force(deepest));
        }
        assert_eq!(observed.harmonics.len(), 3);
        assert_eq!(observed.harmonics[0].amplitude_nm, observed.amplitude_nm);
        assert!(observed.amplitude_ratio < 1.0);
        check_against_samples(&model, 0.0, &x0, &observed);
        println!(
            "{case} Z = Z_G1 {offset:+} nm: A/A0 = {:.6}, Phi = {:.4} deg, n = {}, peak {:.4} nN, impulse {:.6} nN us",
            observed.amplitude_ratio,
            observed.phase_deg,
            observed.impacts.len(),
            observed.peak_force_nn,
            observed.impulse_nn_us
        );
    }
}

#[test]
fn impact_in_progress_at_the_window_start_wraps_around() {
    let (model, x0) = settled("biolever-mica", -2.0);
    let settings = Settings::default();
    let (_, reference) =
        observe_period(&model, 0.0, &x0, Sensitivity::None, &settings, 1).expect("reference");
    // Start the window in the middle of the first impact.
    let first = reference.impacts[0].clone();
    let t_mid = 0.5 * (first.start_periods + first.end_periods) * model.period_us();
    let shifted = flow_map(&model, 0.0, &x0, t_mid, Sensitivity::None, &settings).expect("shift");
    assert_eq!(model.mode_of(t_mid, &shifted.state), CONTACT);
    let (_, observed) = observe_period(
        &model,
        t_mid,
        &shifted.state,
        Sensitivity::None,
        &settings,
        1,
    )
    .expect("shifted window");
    // Same periodic orbit, another window: impacts, integrals and harmonics (with absolute time
    // in cos(w t)) agree to the solver's accuracy.
    assert_eq!(observed.impacts.len(), reference.impacts.len());
    let wrapped = observed.impacts.last().expect("an impact");
    assert!(wrapped.end_periods > 1.0, "{wrapped:?}");
    let shift = t_mid / model.period_us();
    assert!((wrapped.start_periods + shift - 1.0 - first.start_periods).abs() < 1e-9);
    assert!((wrapped.end_periods + shift - 1.0 - first.end_periods).abs() < 1e-9);
    assert!((wrapped.velocity_nm_per_us - first.velocity_nm_per_us).abs() < 1e-7);
    assert!((wrapped.peak_force_nn - first.peak_force_nn).abs() < 1e-8 * first.peak_force_nn);
    assert!(
        (observed.impulse_nn_us - reference.impulse_nn_us).abs() < 1e-8 * reference.impulse_nn_us
    );
    assert!((observed.contact_time_periods - reference.contact_time_periods).abs() < 1e-9);
    assert!((observed.amplitude_nm - reference.amplitude_nm).abs() < 1e-9);
    assert!((observed.phase_deg - reference.phase_deg).abs() < 1e-7);
    assert_eq!(observed.gap_minima.len(), reference.gap_minima.len());
    check_against_samples(&model, t_mid, &shifted.state, &observed);
}
