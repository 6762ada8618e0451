//! The hard impact oscillator through the hybrid solver: shooting against the closed-form
//! free steady state and against a long time-domain run, and the continuation in the drive
//! amplitude against the closed-form grazing amplitude `A_g = d sqrt((k - w^2)^2 + (c w)^2)`.

#[path = "../examples/impact_oscillator/oscillator.rs"]
#[allow(dead_code)]
mod oscillator;

use continuation::{
    floquet_multipliers, shoot, Continuation, ContinuationSettings, HybridPeriodicProblem,
    NewtonSettings, PeriodicProblem, SpecialPointKind, StopReason,
};
use hybrid::{flow_map, Sensitivity, Settings};
use nalgebra::Complex;
use oscillator::{continue_in_amplitude, first_grazing, ImpactOscillator};

fn oscillator(w: f64, amplitude: f64) -> ImpactOscillator {
    ImpactOscillator {
        k: 1.0,
        c: 0.1,
        w,
        d: 1.0,
        e: 0.8,
        amplitude,
    }
}

/// Below grazing the orbit is the linear steady state. Newton on an affine map converges in
/// one update; the state matches the closed form to 1e-9 (integration tolerance 1e-12
/// relative on states of order 1, amplified by `|(M - I)^-1| < 1 / (1 - 0.54)`, with margin);
/// the multipliers are `exp(lambda T)`, `lambda = -c/2 +- i sqrt(k - c^2/4)`, to 1e-6 (the
/// solver controls the error of the state, not of the variational equations).
#[test]
fn shooting_matches_the_free_steady_state() {
    for w in [0.5, 0.8, 1.2, 2.0] {
        let osc = oscillator(w, 0.5 * oscillator(w, 0.0).grazing_amplitude_closed_form());
        let problem = HybridPeriodicProblem::new(osc, 1, Settings::default()).expect("problem");
        let result = shoot(
            &problem,
            &[0.0, 0.0],
            osc.amplitude,
            &NewtonSettings::default(),
        )
        .expect("shooting");
        assert!(result.converged, "w = {w}: {result:?}");
        assert!(
            result.iterations <= 2,
            "w = {w}: {} iterations",
            result.iterations
        );
        let exact = osc.free_steady_state();
        for i in 0..2 {
            assert!(
                (result.state[i] - exact[i]).abs() < 1e-9,
                "w = {w}: {:?} vs {exact:?}",
                result.state
            );
        }
        assert_eq!(result.period_map.structure.impacts, 0);
        let t = 2.0 * std::f64::consts::PI / w;
        let lambda = Complex::new(-0.05, (1.0f64 - 0.0025).sqrt());
        let exact_mu = (lambda * t).exp();
        let mu = floquet_multipliers(&result.period_map.monodromy);
        for m in &mu {
            let error = (m - exact_mu).norm().min((m - exact_mu.conj()).norm());
            assert!(error < 1e-6, "w = {w}: {m} vs {exact_mu}");
        }
    }
}

/// Past grazing at `w = 2` the period-one orbit impacts once per period and is stable
/// (multipliers about 0.68 +- 0.05i). A time-domain run of 300 periods from the free steady
/// state (no Newton, no sensitivities) must end on the shot orbit: contraction 0.69^300 is
/// negligible, so the difference is the integration error, below 1e-8.
#[test]
fn impacting_orbit_agrees_with_a_long_time_domain_run() {
    let w = 2.0;
    let osc = oscillator(w, 1.1 * oscillator(w, 0.0).grazing_amplitude_closed_form());
    let problem = HybridPeriodicProblem::new(osc, 1, Settings::default()).expect("problem");
    let guess = osc.free_steady_state();
    let shot = shoot(
        &problem,
        &guess,
        osc.amplitude,
        &NewtonSettings {
            max_iterations: 30,
            ..NewtonSettings::default()
        },
    )
    .expect("shooting");
    assert!(shot.converged, "{shot:?}");
    assert_eq!(shot.period_map.structure.impacts, 1);
    let mu = floquet_multipliers(&shot.period_map.monodromy);
    assert!(mu.iter().all(|m| m.norm() < 0.75), "{mu:?}");
    let t = 2.0 * std::f64::consts::PI / w;
    let run = flow_map(
        &osc,
        0.0,
        &guess,
        300.0 * t,
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("time-domain run");
    for i in 0..2 {
        assert!(
            (run.state[i] - shot.state[i]).abs() < 1e-8,
            "{:?} vs {:?}",
            run.state,
            shot.state
        );
    }
    assert_eq!(problem.dim(), 2);
}

/// The continuation in `A` finds the first contact G1 at the closed-form grazing amplitude.
/// Error budget: the location tolerance 1e-9, plus the error of the free orbits themselves:
/// Newton stops at a residual of 1e-10, i.e. a state error up to 1e-10 |(M - I)^-1| <= 4e-10
/// (multipliers of modulus <= 0.75), which moves the minimum of `h` by as much and the root
/// by that over `|dh_min/dA| = |G| >= 1/3.01` (w = 2): 1.2e-9. Hence 2.5e-9, for the point
/// and for the closed form lying in the reported bracket.
#[test]
fn grazing_amplitude_matches_the_closed_form() {
    for w in [0.5, 0.8, 1.0, 1.2, 2.0] {
        let osc = oscillator(w, 0.0);
        let exact = osc.grazing_amplitude_closed_form();
        let branch =
            continue_in_amplitude(&osc, 2.0 * (1.0 + w * w + 0.1 * w), 400).expect("branch starts");
        let a_g = first_grazing(&branch).unwrap_or_else(|| {
            panic!(
                "w = {w}: no G1; stop {:?} {:?}, special points {:?}",
                branch.stop, branch.error, branch.special_points
            )
        });
        let g1 = branch
            .special_points
            .iter()
            .find(|s| s.kind == SpecialPointKind::Grazing)
            .expect("G1");
        assert_eq!(g1.label, "G1");
        assert_eq!((g1.impacts_before, g1.impacts_after), (0, 1));
        assert!(g1.converged && g1.precision <= 1e-9, "w = {w}: {g1:?}");
        assert!(
            (a_g - exact).abs() <= 2.5e-9,
            "w = {w}: A_g = {a_g} vs {exact} (error {:e})",
            a_g - exact
        );
        assert!(
            g1.bracket.0 - 1.5e-9 <= exact && exact <= g1.bracket.1 + 1.5e-9,
            "w = {w}: {exact} outside {:?}",
            g1.bracket
        );
        // Before G1 every orbit is free (no impact), after it the orbits impact.
        for point in &branch.points {
            if point.parameter < g1.bracket.0 && point.index <= g1.branch_index {
                assert_eq!(point.structure.impacts, 0, "w = {w}: {}", point.parameter);
            }
        }
    }
}

/// At `w = 1` the impacting branch's impact time drifts to the section time `t0 = 0` near
/// `A = 4.13`, where the stroboscopic map of a system with a reset is discontinuous: the
/// branch stops there cleanly (minimum step, the last orbit impacting at `t = 0`). With the
/// section at `T/4` it passes that amplitude, G1 is the same to the location tolerance, and
/// the orbit found from either section at `A = 4` is the same orbit (the `t0 = 0` state
/// propagated over `T/4` is the `t0 = T/4` state, to the Newton tolerance amplified by the
/// integration over a quarter period, 1e-8).
#[test]
fn moving_the_section_carries_the_branch_past_the_impact_at_the_section_time() {
    let osc = oscillator(1.0, 0.05);
    let t = 2.0 * std::f64::consts::PI;
    let mut ends = Vec::new();
    let mut orbits = Vec::new();
    for t0 in [0.0, 0.25 * t] {
        let problem = HybridPeriodicProblem::new(osc, 1, Settings::default())
            .expect("problem")
            .with_start_time(t0)
            .expect("section");
        // The free steady state x(t) = Re(X e^{i t}) (w = 1) at the section time.
        let [re, v0] = osc.free_steady_state();
        let im = -v0;
        let guess = [
            re * t0.cos() - im * t0.sin(),
            -(re * t0.sin() + im * t0.cos()),
        ];
        let settings = ContinuationSettings {
            initial_step: 1e-2,
            max_step: 0.1,
            min_step: 1e-9,
            parameter_max: 5.0,
            ..ContinuationSettings::default()
        };
        let branch = Continuation::new(&problem, &guess, osc.amplitude, settings)
            .expect("start")
            .run();
        let g1 = first_grazing(&branch).expect("G1");
        // Location tolerance 1e-9 plus the state error 4e-10 over |G| = 10 (see above).
        assert!((g1 - 0.1).abs() <= 1.1e-9, "t0 = {t0}: {g1}");
        ends.push((branch.stop, branch.points.last().expect("points").clone()));
        // The orbit at A = 4 from the branch point nearest to it.
        let near = branch
            .points
            .iter()
            .min_by(|a, b| {
                (a.parameter - 4.0)
                    .abs()
                    .total_cmp(&(b.parameter - 4.0).abs())
            })
            .expect("points");
        let orbit = shoot(
            &problem,
            near.state.as_slice(),
            4.0,
            &NewtonSettings::default(),
        )
        .expect("shoot");
        assert!(orbit.converged && orbit.period_map.structure.impacts == 1);
        orbits.push(orbit.state);
    }
    let (stop0, last0) = &ends[0];
    assert_eq!(*stop0, StopReason::StepTooSmall);
    assert!((last0.parameter - 4.13).abs() < 0.01, "{}", last0.parameter);
    let impact_time = last0.structure.minima[0].0;
    assert!(
        impact_time.min(t - impact_time) < 1e-3,
        "{:?}",
        last0.structure
    );
    let (stop1, last1) = &ends[1];
    assert_eq!(*stop1, StopReason::ParameterBound);
    assert!((last1.parameter - 5.0).abs() < 1e-12);
    let mut at_four = osc;
    at_four.amplitude = 4.0;
    let quarter = flow_map(
        &at_four,
        0.0,
        orbits[0].as_slice(),
        0.25 * t,
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("quarter period");
    for i in 0..2 {
        assert!(
            (quarter.state[i] - orbits[1][i]).abs() < 1e-8,
            "{:?} vs {:?}",
            quarter.state,
            orbits[1]
        );
    }
}
