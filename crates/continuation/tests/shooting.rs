//! Shooting on maps with known fixed points, and the reporting of failures.

use continuation::{
    shoot, Continuation, ContinuationError, ContinuationSettings, NewtonSettings, OrbitStructure,
    PeriodMap, PeriodicProblem, StopReason,
};
use nalgebra::{DMatrix, DVector};

/// The affine map `P(x; p) = A x + p b` with `A = [[0.5, 0.2], [-0.1, 0.3]]`, `b = (1, 2)`:
/// fixed point `x* = p (I - A)^-1 b`.
struct Affine;

impl Affine {
    fn matrix() -> DMatrix<f64> {
        DMatrix::from_row_slice(2, 2, &[0.5, 0.2, -0.1, 0.3])
    }
}

impl PeriodicProblem for Affine {
    fn dim(&self) -> usize {
        2
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        let b = DVector::from_vec(vec![1.0, 2.0]);
        let a = Self::matrix();
        Ok(PeriodMap {
            image: &a * DVector::from_column_slice(x) + p * &b,
            monodromy: a,
            parameter_derivative: b,
            structure: OrbitStructure::default(),
        })
    }
}

#[test]
fn newton_on_an_affine_map_converges_in_one_update() {
    let p = 3.0;
    let result = shoot(&Affine, &[10.0, -7.0], p, &NewtonSettings::default()).expect("shoot");
    assert!(result.converged);
    // One Newton update solves an affine equation exactly (up to rounding).
    assert_eq!(result.iterations, 1);
    // (I - A)^-1 b by hand: I - A = [[0.5, -0.2], [0.1, 0.7]], det = 0.37,
    // x* = p [0.7*1 + 0.2*2, -0.1*1 + 0.5*2] / 0.37 = p [1.1, 0.9] / 0.37.
    let exact = [p * 1.1 / 0.37, p * 0.9 / 0.37];
    for (x, e) in result.state.iter().zip(exact) {
        assert!((x - e).abs() < 1e-13);
    }
    assert!(result.residual < 1e-13);
}

/// `P(x; p) = x + p + x^2`: for `p > 0` there is no fixed point (`x^2 + p = 0`), so Newton
/// cannot converge; the result must say so with its iterations and residual.
struct NoFixedPoint;

impl PeriodicProblem for NoFixedPoint {
    fn dim(&self) -> usize {
        1
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        Ok(PeriodMap {
            image: DVector::from_element(1, x[0] + p + x[0] * x[0]),
            monodromy: DMatrix::from_element(1, 1, 1.0 + 2.0 * x[0]),
            parameter_derivative: DVector::from_element(1, 1.0),
            structure: OrbitStructure::default(),
        })
    }
}

#[test]
fn non_convergence_is_reported_with_iterations_and_residual() {
    let settings = NewtonSettings {
        max_iterations: 7,
        divergence_factor: 1e12,
        ..NewtonSettings::default()
    };
    let result = shoot(&NoFixedPoint, &[0.3], 1.0, &settings).expect("evaluations succeed");
    assert!(!result.converged);
    assert_eq!(result.iterations, 7);
    // The residual is x^2 + p >= p = 1 whatever the iterate.
    assert!(result.residual >= 1.0);
    // Continuation refuses to start there, naming the parameter and the residual.
    match Continuation::new(&NoFixedPoint, &[0.3], 1.0, ContinuationSettings::default()) {
        Err(ContinuationError::StartNotConverged {
            parameter,
            residual,
            ..
        }) => {
            assert_eq!(parameter, 1.0);
            assert!(residual >= 1.0);
        }
        other => panic!("expected StartNotConverged, got {:?}", other.err()),
    };
}

#[test]
fn stop_predicate_and_point_limit_end_the_branch() {
    // The affine branch x*(p) is a straight line: steps grow to max_step.
    let settings = ContinuationSettings {
        initial_step: 0.1,
        max_step: 0.5,
        ..ContinuationSettings::default()
    };
    let branch = Continuation::new(&Affine, &[0.0, 0.0], 0.0, settings.clone())
        .expect("start")
        .stop_when(|point| point.parameter > 0.2)
        .run();
    assert_eq!(branch.stop, StopReason::UserStop);
    let last = branch.points.last().expect("points");
    assert!(last.parameter > 0.2);
    assert!(branch.points[..branch.points.len() - 1]
        .iter()
        .all(|p| p.parameter <= 0.2));
    let limited = Continuation::new(
        &Affine,
        &[0.0, 0.0],
        0.0,
        ContinuationSettings {
            max_points: 5,
            ..settings
        },
    )
    .expect("start")
    .run();
    assert_eq!(limited.stop, StopReason::MaxPoints);
    assert_eq!(limited.points.len(), 5);
    // The parameter increases (default direction) and every point is on the exact line.
    for pair in limited.points.windows(2) {
        assert!(pair[1].parameter > pair[0].parameter);
    }
    for point in &limited.points {
        let exact = [point.parameter * 1.1 / 0.37, point.parameter * 0.9 / 0.37];
        assert!((point.state[0] - exact[0]).abs() < 1e-12);
        assert!((point.state[1] - exact[1]).abs() < 1e-12);
        assert!(point.stable, "multipliers of A have modulus < 1");
    }
}

#[test]
fn stop_predicate_sees_every_point_including_the_last() {
    for (max_points, parameter_max) in [(4, f64::INFINITY), (10_000, 0.7)] {
        let settings = ContinuationSettings {
            initial_step: 0.1,
            max_step: 0.5,
            max_points,
            parameter_max,
            ..ContinuationSettings::default()
        };
        let mut seen = Vec::new();
        let branch = Continuation::new(&Affine, &[0.0, 0.0], 0.0, settings)
            .expect("start")
            .stop_when(|point| {
                seen.push(point.index);
                false
            })
            .run();
        let indices: Vec<usize> = branch.points.iter().map(|p| p.index).collect();
        assert_eq!(seen, indices);
        let expected = if max_points == 4 {
            StopReason::MaxPoints
        } else {
            StopReason::ParameterBound
        };
        assert_eq!(branch.stop, expected);
    }
}
