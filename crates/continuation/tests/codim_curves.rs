//! Two-parameter continuation of codimension-one points against exact answers: the
//! first-grazing curve of the hard impact oscillator in (drive frequency, drive amplitude).

#[path = "../examples/impact_oscillator/oscillator.rs"]
#[allow(dead_code)]
mod oscillator;

use continuation::{
    continue_curve, CodimOneKind, CurveSettings, CurveStart, CurveStop, NewtonSettings,
    SpecialPointKind, TwoParameterProblem,
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

/// The grazing curve continued in `(w, A)` from the G1 of a one-parameter branch at `w = 0.8`
/// over `w` in `[0.5, 1.6]` (through resonance at `w = 1`) lies on the closed form
/// `A_g(w) = d sqrt((k - w^2)^2 + (c w)^2)` to 1e-10 at every point. Error budget: the
/// corrector stops at a residual of 1e-12 (gap and rate of order 1), which moves `A` by at
/// most that over `|dh/dA| = |G| >= 1/3.01` (3e-12); the integration error of the orbit at
/// tolerances 1e-12 relative over one period is of the same order; 1e-10 leaves a margin of 10.
/// Both ends are on the range ends, and the requested `w = 1` is a point computed there.
#[test]
fn grazing_curve_matches_the_closed_form_through_resonance() {
    let w0 = 0.8;
    let branch = continue_in_amplitude(&oscillator(w0), 4.0, 400).expect("branch");
    let g1 = branch
        .special_points
        .iter()
        .find(|s| s.kind == SpecialPointKind::Grazing)
        .expect("G1 on the one-parameter branch");
    let mut system = oscillator(w0);
    system.amplitude = g1.parameter;
    let problem = TwoParameterProblem::new(system, w0, 1, Settings::default()).expect("problem");
    let settings = CurveSettings {
        second_range: (0.5, 1.6),
        targets: vec![1.0],
        max_second_step: 0.02,
        corrector: NewtonSettings {
            tolerance: 1e-12,
            max_iterations: 10,
            ..NewtonSettings::default()
        },
        ..CurveSettings::default()
    };
    let start = CurveStart {
        state: g1.state.as_slice().to_vec(),
        section_time: 0.0,
        parameter: g1.parameter,
        second_parameter: w0,
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
