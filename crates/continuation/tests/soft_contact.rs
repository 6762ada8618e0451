//! A forced oscillator against a soft (Hertz-like, `F = K (x - Z)^{3/2}`) wall at `x = Z`,
//! continued in the wall position `Z` decreasing, as the AFM model is in the separation: the
//! contact force is continuous, so the branch crosses grazing with the ordinary corrector.
//! First contact G1 happens where the free steady state's maximum `A |G|` reaches `Z`.

use std::cell::Cell;
use std::time::Instant;

use continuation::{
    Branch, Continuation, ContinuationError, ContinuationSettings, HybridPeriodicProblem,
    ParameterDirection, Parametrised, PeriodMap, PeriodicProblem, SpecialPointKind, StopReason,
};
use hybrid::{HybridSystem, Mode, Settings, SwitchingPartials};
use nalgebra::DMatrix;

/// `x'' + c x' + k x = A cos(w t) - K max(x - Z, 0)^{3/2}`, parameter `p = Z`, switching
/// function `h = Z - x` (the gap), contact mode when `h < 0`.
#[derive(Debug, Clone, Copy)]
struct SoftWall {
    k: f64,
    c: f64,
    w: f64,
    amplitude: f64,
    stiffness: f64,
    wall: f64,
}

impl SoftWall {
    /// `A |G|`, `G = 1 / (k - w^2 + i c w)`: the free steady-state amplitude.
    fn free_amplitude(&self) -> f64 {
        self.amplitude / ((self.k - self.w * self.w).powi(2) + (self.c * self.w).powi(2)).sqrt()
    }
}

impl HybridSystem for SoftWall {
    fn dim(&self) -> usize {
        2
    }
    fn surface_count(&self) -> usize {
        1
    }
    fn vector_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        dxdt[0] = x[1];
        dxdt[1] = self.amplitude * (self.w * t).cos() - self.c * x[1] - self.k * x[0];
        if mode & 1 != 0 {
            let penetration = (x[0] - self.wall).max(0.0);
            dxdt[1] -= self.stiffness * penetration.powf(1.5);
        }
    }
    fn jacobian(&self, mode: Mode, _t: f64, x: &[f64], jacobian: &mut DMatrix<f64>) {
        jacobian[(0, 0)] = 0.0;
        jacobian[(0, 1)] = 1.0;
        jacobian[(1, 0)] = -self.k;
        jacobian[(1, 1)] = -self.c;
        if mode & 1 != 0 {
            let penetration = (x[0] - self.wall).max(0.0);
            jacobian[(1, 0)] -= 1.5 * self.stiffness * penetration.sqrt();
        }
    }
    fn parameter_derivative(&self, mode: Mode, _t: f64, x: &[f64], dfdp: &mut [f64]) {
        dfdp[0] = 0.0;
        dfdp[1] = 0.0;
        if mode & 1 != 0 {
            let penetration = (x[0] - self.wall).max(0.0);
            dfdp[1] = 1.5 * self.stiffness * penetration.sqrt();
        }
    }
    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        self.wall - x[0]
    }
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        -x[1]
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        gradient: &mut [f64],
    ) -> SwitchingPartials {
        gradient[0] = -1.0;
        gradient[1] = 0.0;
        SwitchingPartials { t: 0.0, p: 1.0 }
    }
}

impl Parametrised for SoftWall {
    fn parameter(&self) -> f64 {
        self.wall
    }
    fn set_parameter(&mut self, p: f64) {
        self.wall = p;
    }
    fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.w
    }
}

/// Counts the period-map evaluations of the problem it wraps.
struct Counted<P> {
    inner: P,
    calls: Cell<usize>,
}

impl<P: PeriodicProblem> PeriodicProblem for Counted<P> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        self.calls.set(self.calls.get() + 1);
        self.inner.period_map(x, p)
    }
}

/// G1 at `Z = A |G|` to 1.2e-9: the location tolerance 1e-9 plus the free orbit's state error
/// (Newton residual 1e-10 amplified by `1/(1 - |mu|) = 1.5`, `|mu| = exp(-c T / 2) = 0.35`),
/// which moves the root one to one (`dh/dZ = 1`); the branch goes on in contact with one impact per period, minimum gap
/// negative, down to the floor, and never fails.
/// Continue from the orbit at `(0, 0)` and wall position `wall` with `settings`; the branch
/// must end at its parameter bound.
fn run_to_parameter_bound<P: PeriodicProblem>(
    problem: &P,
    wall: f64,
    settings: ContinuationSettings,
) -> Branch {
    let branch = Continuation::new(problem, &[0.0, 0.0], wall, settings)
        .expect("start")
        .run();
    assert_eq!(
        branch.stop,
        StopReason::ParameterBound,
        "{:?}",
        branch.error
    );
    branch
}

/// The labels of a branch's special points, in order.
fn labels(branch: &Branch) -> Vec<&str> {
    branch
        .special_points
        .iter()
        .map(|s| s.label.as_str())
        .collect()
}

#[test]
fn first_contact_of_a_soft_wall_at_the_free_amplitude() {
    let system = SoftWall {
        k: 1.0,
        c: 0.3,
        w: 0.9,
        amplitude: 1.0,
        stiffness: 50.0,
        wall: 0.0,
    };
    let z_g = system.free_amplitude();
    let mut start = system;
    start.wall = 1.5 * z_g;
    let problem = Counted {
        inner: HybridPeriodicProblem::new(start, 1, Settings::default()).expect("problem"),
        calls: Cell::new(0),
    };
    let settings = ContinuationSettings {
        initial_step: 0.05,
        max_step: 0.05,
        direction: ParameterDirection::Decreasing,
        parameter_min: 0.5 * z_g,
        ..ContinuationSettings::default()
    };
    let started = Instant::now();
    let branch = run_to_parameter_bound(&problem, start.wall, settings);
    let elapsed = started.elapsed();
    let calls = problem.calls.get();
    eprintln!(
        "{} points, {} period maps ({:.1} per point), {:.3} ms per point",
        branch.points.len(),
        calls,
        calls as f64 / branch.points.len() as f64,
        elapsed.as_secs_f64() * 1e3 / branch.points.len() as f64
    );
    // Leanness (the AFM budget is ~1 ms per point at ~30 us per period map): a smooth branch
    // costs the corrector's 2-3 evaluations per point plus the location of G1 (~10 more).
    // Measured 2.2 per point (cubic predictor); a regression in the predictor or the step
    // control shows here.
    assert!(
        calls as f64 <= 3.0 * branch.points.len() as f64,
        "{calls} period maps for {} points",
        branch.points.len()
    );
    let grazings: Vec<_> = branch
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialPointKind::Grazing)
        .collect();
    assert_eq!(grazings.len(), 1, "{:?}", branch.special_points);
    let g1 = grazings[0];
    assert_eq!(g1.label, "G1");
    assert!(g1.converged && g1.precision <= 1e-9, "{g1:?}");
    assert!(
        (g1.parameter - z_g).abs() < 1e-9,
        "{} vs {z_g}",
        g1.parameter
    );
    for point in &branch.points {
        if point.parameter < z_g - 1e-6 {
            assert_eq!(point.structure.impacts, 1, "Z = {}", point.parameter);
            assert!(point.structure.minima.iter().any(|m| m.1 < 0.0));
        } else if point.parameter > z_g + 1e-6 {
            assert_eq!(point.structure.impacts, 0, "Z = {}", point.parameter);
        }
    }
}

/// Above resonance (`w = 1.5`) a stiff wall bends the response: after first contact the branch
/// turns at a fold (the mechanism of the AFM's phase jumps on stiff samples) and goes back up
/// in `Z`. Checks independent of the location: at a fold of fixed points one Floquet
/// multiplier is exactly 1 (here to 1e-3: the fold is bracketed to 1e-9 in `Z`, i.e. to
/// ~3e-5 in arclength, where `mu - 1` is proportional to the arclength); `Z` is a local minimum
/// there (no branch point has a smaller `Z`); and stability changes across it.
#[test]
fn fold_after_first_contact_on_a_stiff_wall() {
    let system = SoftWall {
        k: 1.0,
        c: 0.05,
        w: 1.5,
        amplitude: 1.0,
        stiffness: 100.0,
        wall: 0.0,
    };
    let z_g = system.free_amplitude();
    let mut start = system;
    start.wall = 1.5 * z_g;
    let problem = HybridPeriodicProblem::new(start, 1, Settings::default()).expect("problem");
    let settings = ContinuationSettings {
        initial_step: 0.05,
        max_step: 0.05,
        direction: ParameterDirection::Decreasing,
        parameter_max: 2.0 * z_g,
        ..ContinuationSettings::default()
    };
    let branch = run_to_parameter_bound(&problem, start.wall, settings);
    let labels = labels(&branch);
    assert_eq!(labels, ["G1", "fold"], "{:?}", branch.special_points);
    let (g1, fold) = (&branch.special_points[0], &branch.special_points[1]);
    // Location tolerance plus the state error (Newton residual 1e-10 amplified by at most
    // 1/(1 - exp(-c T / 2)) = 10 for c = 0.05, T = 4.19): 2e-9.
    assert!((g1.parameter - z_g).abs() < 2e-9);
    assert!(fold.converged && fold.precision <= 1e-9, "{fold:?}");
    assert!(fold.parameter < g1.parameter);
    let unit = fold
        .multipliers
        .iter()
        .map(|m| (m - 1.0).norm())
        .fold(f64::INFINITY, f64::min);
    assert!(unit < 1e-3, "closest multiplier to 1 is {unit:e} away");
    let lowest = branch
        .points
        .iter()
        .map(|p| p.parameter)
        .fold(f64::INFINITY, f64::min);
    assert!(
        lowest >= fold.parameter - 1e-9,
        "{lowest} < {}",
        fold.parameter
    );
    let before = &branch.points[fold.branch_index - 1];
    let after = &branch.points[fold.branch_index];
    assert_ne!(before.stable, after.stable);
}

/// Far above resonance (`w = 2.5`) the orbit loses stability by period doubling just after
/// first contact. Independent check: at a period doubling one Floquet multiplier is exactly
/// `-1`; the point is located to 1e-9 in `Z` and the multiplier moves by about 260 per unit
/// of `Z` there (from -1.50 at `Z = 0.1860` to -1 at 0.1879), so it is `-1` to 1e-6. The
/// orbits before it are stable, the ones after it unstable.
#[test]
fn period_doubling_after_first_contact_far_above_resonance() {
    let system = SoftWall {
        k: 1.0,
        c: 0.1,
        w: 2.5,
        amplitude: 1.0,
        stiffness: 100.0,
        wall: 0.0,
    };
    let z_g = system.free_amplitude();
    let mut start = system;
    start.wall = 1.2 * z_g;
    let problem = HybridPeriodicProblem::new(start, 1, Settings::default()).expect("problem");
    let settings = ContinuationSettings {
        initial_step: 0.02,
        max_step: 0.02,
        direction: ParameterDirection::Decreasing,
        parameter_min: 0.1,
        ..ContinuationSettings::default()
    };
    let branch = run_to_parameter_bound(&problem, start.wall, settings);
    let labels = labels(&branch);
    assert_eq!(
        labels,
        ["G1", "period-doubling"],
        "{:?}",
        branch.special_points
    );
    let pd = &branch.special_points[1];
    assert!(pd.converged && pd.precision <= 1e-9, "{pd:?}");
    let closest = pd
        .multipliers
        .iter()
        .map(|m| (m + 1.0).norm())
        .fold(f64::INFINITY, f64::min);
    assert!(
        closest < 1e-6,
        "closest multiplier to -1 is {closest:e} away"
    );
    for point in &branch.points {
        if point.parameter > pd.parameter + 1e-6 {
            assert!(
                point.stable,
                "Z = {}: {:?}",
                point.parameter, point.multipliers
            );
        } else if point.parameter < pd.parameter - 1e-6 {
            assert!(
                !point.stable,
                "Z = {}: {:?}",
                point.parameter, point.multipliers
            );
        }
    }
}
