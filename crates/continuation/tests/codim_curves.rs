//! Two-parameter continuation of codimension-one points against exact answers: the
//! first-grazing curve of the hard impact oscillator in (drive frequency, drive amplitude).

#[path = "../examples/impact_oscillator/oscillator.rs"]
#[allow(dead_code)]
mod oscillator;

use continuation::{
    continue_curve, continue_curve_until, CodimOneKind, CurveSettings, CurveStart, CurveStop,
    NewtonSettings, SpecialPointKind, TwoParameterProblem,
};
use hybrid::Settings;
use oscillator::{continue_in_amplitude, ImpactOscillator};

fn oscillator(w: f64) -> ImpactOscillator {
    ImpactOscillator {
        k: 1.0,
        c: 0.1,
        w,
        d: 1.0,
        e: 0.8,
        amplitude: 0.0,
    }
}

/// The grazing curve's settings from 0.5 to 1.6 in the frequency ratio (through resonance),
/// steps of at most 0.02, Newton to 1e-12 in at most 10 updates.
fn through_resonance() -> CurveSettings {
    CurveSettings {
        second_range: (0.5, 1.6),
        max_second_step: 0.02,
        corrector: NewtonSettings {
            tolerance: 1e-12,
            max_iterations: 10,
            ..NewtonSettings::default()
        },
        ..CurveSettings::default()
    }
}

/// The curve problem in `(w, A)` of the oscillator at `w0` and the start of its grazing curve:
/// the G1 located on the one-parameter branch in the amplitude `A` at `w0`.
fn first_grazing_at(w0: f64) -> (TwoParameterProblem<ImpactOscillator>, CurveStart) {
    let branch = continue_in_amplitude(&oscillator(w0), 4.0, 400).expect("branch");
    let g1 = branch
        .special_points
        .iter()
        .find(|s| s.kind == SpecialPointKind::Grazing)
        .expect("G1 on the one-parameter branch");
    let mut system = oscillator(w0);
    system.amplitude = g1.parameter;
    let problem = TwoParameterProblem::new(system, w0, 1, Settings::default()).expect("problem");
    let start = CurveStart {
        state: g1.state.as_slice().to_vec(),
        section_time: 0.0,
        parameter: g1.parameter,
        second_parameter: w0,
    };
    (problem, start)
}

/// The grazing curve continued in `(w, A)` from the G1 of a one-parameter branch at `w = 0.8`
/// over `w` in `[0.5, 1.6]` (through resonance at `w = 1`) lies on the closed form
/// `A_g(w) = d sqrt((k - w^2)^2 + (c w)^2)` to 1e-10 at every point. Error budget: the
/// corrector stops at a residual of 1e-12 (gap and rate of order 1), which moves `A` by at
/// most that over `|dh/dA| = |G| >= 1/3.01` (3e-12); the integration error of the orbit at
/// tolerances 1e-12 relative over one period is of the same order; 1e-10 leaves a margin of 10.
/// Both ends are on the range ends, and the requested `w = 1` is a point computed there.
#[test]
fn grazing_curve_matches_the_closed_form_through_resonance() {
    let (problem, start) = first_grazing_at(0.8);
    let settings = CurveSettings {
        targets: vec![1.0],
        ..through_resonance()
    };
    let curve = continue_curve(&problem, CodimOneKind::Grazing, &start, &settings).expect("curve");
    assert_eq!(
        curve.ends[0].reason,
        CurveStop::RangeEnd,
        "{:?}",
        curve.ends
    );
    assert_eq!(
        curve.ends[1].reason,
        CurveStop::RangeEnd,
        "{:?}",
        curve.ends
    );
    assert!(curve.points.len() >= 55, "{} points", curve.points.len());
    for point in &curve.points {
        let w = point.second_parameter;
        let exact = oscillator(w).grazing_amplitude_closed_form();
        assert!(
            (point.parameter - exact).abs() <= 1e-10,
            "w = {w}: A = {} vs {exact}",
            point.parameter
        );
        assert_eq!(point.structure.impacts, 0, "w = {w}");
    }
    let first = curve.points.first().expect("points");
    let last = curve.points.last().expect("points");
    assert_eq!(first.second_parameter, 0.5);
    assert_eq!(last.second_parameter, 1.6);
    assert!(curve
        .points
        .iter()
        .any(|p| p.second_parameter == 1.0 && p.at_fixed_second));
    assert!(curve.codim2_points.is_empty(), "{:?}", curve.codim2_points);
}

/// `x' = -(x^3 - q x - p)` with a nominal forcing period 1: its period map's fixed points are
/// the roots of `x^3 - q x - p`, with multiplier `exp(-(3 x^2 - q))`, so the folds lie exactly
/// on `q = 3 x^2`, `p = -2 x^3`, which meet at the cusp `(p, q) = (0, 0)`.
#[derive(Debug, Clone, Copy)]
struct CuspField {
    p: f64,
    q: f64,
}

impl hybrid::HybridSystem for CuspField {
    fn dim(&self) -> usize {
        1
    }
    fn surface_count(&self) -> usize {
        1
    }
    fn vector_field(&self, _mode: hybrid::Mode, _t: f64, x: &[f64], dxdt: &mut [f64]) {
        dxdt[0] = -(x[0] * x[0] * x[0] - self.q * x[0] - self.p);
    }
    fn jacobian(&self, _mode: hybrid::Mode, _t: f64, x: &[f64], j: &mut nalgebra::DMatrix<f64>) {
        j[(0, 0)] = -(3.0 * x[0] * x[0] - self.q);
    }
    fn parameter_derivative(&self, _mode: hybrid::Mode, _t: f64, _x: &[f64], dfdp: &mut [f64]) {
        dfdp[0] = 1.0;
    }
    /// A surface far from every orbit of the test (`x = 10`).
    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        10.0 - x[0]
    }
    fn switching_rate(&self, _k: usize, mode: hybrid::Mode, t: f64, x: &[f64]) -> f64 {
        let mut f = [0.0];
        self.vector_field(mode, t, x, &mut f);
        -f[0]
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        gradient: &mut [f64],
    ) -> hybrid::SwitchingPartials {
        gradient[0] = -1.0;
        hybrid::SwitchingPartials::default()
    }
}

impl continuation::Parametrised for CuspField {
    fn parameter(&self) -> f64 {
        self.p
    }
    fn set_parameter(&mut self, p: f64) {
        self.p = p;
    }
    fn period(&self) -> f64 {
        1.0
    }
}

impl continuation::TwoParametrised for CuspField {
    fn second_parameter(&self) -> f64 {
        self.q
    }
    fn set_second_parameter(&mut self, q: f64) -> Result<(), String> {
        self.q = q;
        Ok(())
    }
}

/// The fold curve from `(x, p, q) = (1, -2, 3)` over `q` in `[-1, 3]` runs through the cusp
/// and back to `q = 3` on the other fold (`x = -1, p = 2`): every point on `p^2 = 4 (q/3)^3`
/// to 1e-8 (the corrector's residual 1e-10 in `x` and in the test function, amplified by the
/// curve's slope, at most 3 here, plus the integration error 1e-12 relative), both ends on
/// `q = 3`, and one cusp located at `(0, 0)` within 1e-6 (the bisection brackets the sign
/// change of `dq/ds` to 1e-9 in `p` and `q`; the bound is loose).
#[test]
fn fold_curve_of_the_cusp_normal_form_is_exact_and_turns_at_the_cusp() {
    use continuation::Codim2Kind;
    let problem =
        TwoParameterProblem::new(CuspField { p: -2.0, q: 3.0 }, 3.0, 1, Settings::default())
            .expect("problem");
    let settings = CurveSettings {
        second_range: (-1.0, 3.0),
        max_second_step: 0.1,
        ..CurveSettings::default()
    };
    let start = CurveStart {
        state: vec![1.0],
        section_time: 0.0,
        parameter: -2.0,
        second_parameter: 3.0,
    };
    let curve = continue_curve(&problem, CodimOneKind::Fold, &start, &settings).expect("curve");
    for end in &curve.ends {
        assert_eq!(end.reason, CurveStop::RangeEnd, "{:?}", curve.ends);
        assert_eq!(end.parameters.1, 3.0);
    }
    // Traced with q decreasing from the start, the curve's first point is its far end.
    let far = curve.points.first().expect("points");
    assert!((far.state[0] + 1.0).abs() < 1e-8 && (far.parameter - 2.0).abs() < 1e-8);
    assert_eq!(curve.start_index, curve.points.len() - 1);
    for point in &curve.points {
        let (p, q) = (point.parameter, point.second_parameter);
        assert!(q >= -1e-9, "no fold at q < 0: {q}");
        assert!(
            (p * p - 4.0 * (q / 3.0).powi(3)).abs() <= 1e-8,
            "p = {p}, q = {q}"
        );
        assert!((point.multipliers[0].re - 1.0).abs() < 1e-8);
    }
    let cusps: Vec<_> = curve
        .codim2_points
        .iter()
        .filter(|c| c.kind == Codim2Kind::Cusp)
        .collect();
    assert_eq!(cusps.len(), 1, "{:?}", curve.codim2_points);
    assert!(cusps[0].parameter.abs() < 1e-6 && cusps[0].second_parameter.abs() < 1e-6);
}

/// A stop that answers `true` from its 6th question on ends each half of the grazing curve
/// with `Interrupted` (the first half after the five steps it allowed, the second at once),
/// keeping the points found, each on the closed form `A_g(w)` to 1e-10 as above.
#[test]
fn a_stop_ends_the_curve_with_interrupted_and_keeps_its_points() {
    let (problem, start) = first_grazing_at(0.8);
    let settings = through_resonance();
    let asked = std::cell::Cell::new(0);
    let stop = || {
        asked.set(asked.get() + 1);
        asked.get() > 5
    };
    let curve = continue_curve_until(&problem, CodimOneKind::Grazing, &start, &settings, &stop)
        .expect("curve");
    assert_eq!(
        [curve.ends[0].reason, curve.ends[1].reason],
        [CurveStop::Interrupted, CurveStop::Interrupted],
        "{:?}",
        curve.ends
    );
    // Five steps accepted (a step is a point, or a cut step retried), and the start.
    assert!(
        (2..=6).contains(&curve.points.len()),
        "{} points",
        curve.points.len()
    );
    assert_eq!(curve.start_index, curve.points.len() - 1);
    for point in &curve.points {
        let exact = oscillator(point.second_parameter).grazing_amplitude_closed_form();
        assert!((point.parameter - exact).abs() <= 1e-10, "{point:?}");
    }
}
