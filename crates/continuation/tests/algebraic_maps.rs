//! Continuation on algebraic maps whose special points are known in closed form.

use continuation::{
    floquet_multipliers, is_stable, Continuation, ContinuationError, ContinuationSettings,
    OrbitStructure, ParameterDirection, PeriodMap, PeriodicProblem, SpecialPointKind, StopReason,
};
use nalgebra::{DMatrix, DVector};

/// The quadratic map `P(x; p) = x + p - x^2`: fixed points `x = +-sqrt(p)`, a fold at
/// `p = 0` (`x = 0`), multiplier `1 - 2x`, so a period doubling at `x = 1`, `p = 1`.
///
/// Its synthetic "contact" structure (times in a period of 1) makes structure events happen
/// at known `x`, hence at known `p = x^2` on the upper branch:
/// minima `m1 = g1 - x` at `t = 0.25 + 0.05 x` and `m2 = g2 - x` at `t = 0.5 + 0.05 x`,
/// a maximum `0.8 - x` between them at `t = 0.375`; impacts: one per negative minimum, the two
/// counting as one once the maximum between them is negative, and none at all for
/// `x > 1.1` (an impact count change with no extremum crossing zero).
struct Quadratic {
    g1: f64,
    g2: f64,
}

impl PeriodicProblem for Quadratic {
    fn dim(&self) -> usize {
        1
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        let x = x[0];
        let m1 = self.g1 - x;
        let m2 = self.g2 - x;
        let max = 0.8 - x;
        let mut impacts = usize::from(m1 < 0.0) + usize::from(m2 < 0.0);
        if impacts == 2 && max < 0.0 {
            impacts = 1;
        }
        if x > 1.1 {
            impacts = 0;
        }
        Ok(PeriodMap {
            image: DVector::from_element(1, x + p - x * x),
            monodromy: DMatrix::from_element(1, 1, 1.0 - 2.0 * x),
            parameter_derivative: DVector::from_element(1, 1.0),
            structure: OrbitStructure {
                minima: vec![(0.25 + 0.05 * x, m1), (0.5 + 0.05 * x, m2)],
                maxima: vec![(0.375, max)],
                impacts,
                duration: 1.0,
                permanent_contact: false,
                release_maxima: vec![],
            },
        })
    }
}

fn settings() -> ContinuationSettings {
    ContinuationSettings {
        initial_step: 0.05,
        max_step: 0.1,
        direction: ParameterDirection::Decreasing,
        parameter_max: 1.5,
        ..ContinuationSettings::default()
    }
}

#[test]
fn quadratic_map_fold_grazings_merge_period_doubling_and_vanish() {
    let problem = Quadratic { g1: 0.3, g2: 0.5 };
    // Start on the lower (unstable) branch x = -sqrt(0.25), going down in p to the fold.
    let branch = Continuation::new(&problem, &[-0.45], 0.25, settings())
        .expect("start converges")
        .run();
    assert_eq!(
        branch.stop,
        StopReason::ParameterBound,
        "{:?}",
        branch.error
    );
    let last = branch.points.last().expect("points");
    // The last point lies on the ceiling p = 1.5, at x = sqrt(1.5).
    assert!((last.parameter - 1.5).abs() < 1e-14);
    assert!((last.state[0] - 1.5f64.sqrt()).abs() < 1e-9);

    // Every point is a fixed point: x^2 = p to the Newton tolerance (residual 1e-10 in x,
    // amplified by 1/|1 - mu| = 1/(2|x|) <= 1/(2*0.2) away from the fold).
    for point in &branch.points {
        let x = point.state[0];
        assert!(
            (x * x - point.parameter).abs() < 1e-9,
            "p {}",
            point.parameter
        );
        // Stability: the multiplier 1 - 2x is inside the unit circle exactly for 0 < x < 1.
        let mu = 1.0 - 2.0 * x;
        assert!((point.multipliers[0].re - mu).abs() < 1e-12);
        if (x - 0.0).abs() > 1e-6 && (x - 1.0).abs() > 1e-6 {
            assert_eq!(point.stable, x > 0.0 && x < 1.0, "x {x}");
        }
    }

    let labels: Vec<&str> = branch
        .special_points
        .iter()
        .map(|s| s.label.as_str())
        .collect();
    assert_eq!(
        labels,
        [
            "fold",
            "G1",
            "G2",
            "merge",
            "period-doubling",
            "impact-vanish"
        ]
    );
    // Closed-form parameters: fold p = 0; G1 at x = 0.3, G2 at x = 0.5, merge at x = 0.8,
    // period doubling at x = 1, vanish at x = 1.1, each at p = x^2. Tolerance: the location
    // tolerance 1e-9 plus the state error of the corrector (1e-10 / (2x)) times dp/dx = 2x.
    let exact = [0.0, 0.09, 0.25, 0.64, 1.0, 1.21];
    for (point, p) in branch.special_points.iter().zip(exact) {
        assert!(point.converged, "{point:?}");
        assert!(point.precision <= 1e-9, "{point:?}");
        assert!(
            (point.parameter - p).abs() < 1.2e-9,
            "{} at {} instead of {p}",
            point.label,
            point.parameter
        );
        assert!(point.bracket.0 <= point.parameter + 1e-15);
        assert!(point.bracket.1 >= point.parameter - 1e-15);
    }
    let counts: Vec<(usize, usize)> = branch
        .special_points
        .iter()
        .map(|s| (s.impacts_before, s.impacts_after))
        .collect();
    assert_eq!(counts, [(0, 0), (0, 1), (1, 2), (2, 1), (1, 1), (1, 0)]);
    assert_eq!(branch.special_points[3].kind, SpecialPointKind::Merge);
    assert_eq!(
        branch.special_points[5].kind,
        SpecialPointKind::ImpactVanish
    );
}

#[test]
fn two_grazings_within_one_step_are_located_apart() {
    // Minima crossing zero at x = 0.3 and x = 0.3 + 1e-7: closer than any step the branch
    // takes there, so both fall in one step (p = 0.09 and 0.09000006).
    let problem = Quadratic {
        g1: 0.3,
        g2: 0.3 + 1e-7,
    };
    let branch = Continuation::new(&problem, &[-0.45], 0.25, settings())
        .expect("start")
        .run();
    let grazings: Vec<_> = branch
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialPointKind::Grazing)
        .collect();
    assert_eq!(grazings.len(), 2, "{:?}", branch.special_points);
    assert_eq!(grazings[0].label, "G1");
    assert_eq!(grazings[1].label, "G2");
    let x2 = 0.3 + 1e-7;
    for (g, p) in grazings.iter().zip([0.09, x2 * x2]) {
        assert!(g.converged);
        assert!((g.parameter - p).abs() < 1.2e-9, "{g:?}");
    }
}

/// `P(x; p) = (1 + p) R(theta) x - |x|^2 x` in the plane: the fixed point `x = 0` for every
/// `p` with multipliers `(1 + p) exp(+-i theta)`, a Neimark-Sacker point at `p = 0`.
struct Rotation {
    theta: f64,
}

impl PeriodicProblem for Rotation {
    fn dim(&self) -> usize {
        2
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        let (c, s) = (self.theta.cos(), self.theta.sin());
        let r2 = x[0] * x[0] + x[1] * x[1];
        let a = 1.0 + p;
        let rx = [c * x[0] - s * x[1], s * x[0] + c * x[1]];
        let image = DVector::from_vec(vec![a * rx[0] - r2 * x[0], a * rx[1] - r2 * x[1]]);
        let mut monodromy = DMatrix::from_row_slice(2, 2, &[a * c, -a * s, a * s, a * c]);
        for i in 0..2 {
            for j in 0..2 {
                monodromy[(i, j)] -= 2.0 * x[i] * x[j];
            }
            monodromy[(i, i)] -= r2;
        }
        Ok(PeriodMap {
            image,
            monodromy,
            parameter_derivative: DVector::from_vec(rx.to_vec()),
            structure: OrbitStructure::default(),
        })
    }
}

#[test]
fn rotation_map_neimark_sacker_at_zero() {
    let problem = Rotation { theta: 1.0 };
    let branch = Continuation::new(
        &problem,
        &[0.01, -0.02],
        -0.5,
        ContinuationSettings {
            initial_step: 0.03,
            parameter_max: 0.5,
            ..ContinuationSettings::default()
        },
    )
    .expect("start")
    .run();
    assert_eq!(branch.stop, StopReason::ParameterBound);
    assert_eq!(
        branch.special_points.len(),
        1,
        "{:?}",
        branch.special_points
    );
    let ns = &branch.special_points[0];
    assert_eq!(ns.label, "neimark-sacker");
    // Exact p = 0; the fixed point x = 0 is solved exactly (the map is odd), so only the
    // location tolerance 1e-9 remains.
    assert!(ns.converged && ns.parameter.abs() < 1e-9, "{ns:?}");
    // Multipliers at the point: exp(+-i) on the unit circle, to the same precision.
    for m in &ns.multipliers {
        assert!((m.norm() - 1.0).abs() < 2e-9);
        assert!((m.im.abs() - 1f64.sin()).abs() < 2e-9);
    }
    // Stable before (p < 0), unstable after.
    for point in &branch.points {
        if point.parameter.abs() > 1e-6 {
            assert_eq!(point.stable, point.parameter < 0.0);
        }
    }
}

#[test]
fn floquet_multipliers_of_a_known_matrix() {
    // Upper triangular block matrix: eigenvalues 2, -0.5 and the pair 0.3 +- 0.4i of the
    // rotation-scaling block [[0.3, -0.4], [0.4, 0.3]].
    let m = DMatrix::from_row_slice(
        4,
        4,
        &[
            2.0, 1.0, 0.5, 0.1, //
            0.0, -0.5, 0.2, 0.3, //
            0.0, 0.0, 0.3, -0.4, //
            0.0, 0.0, 0.4, 0.3,
        ],
    );
    let mu = floquet_multipliers(&m);
    assert_eq!(mu.len(), 4);
    // Sorted by modulus: 2, then 0.5 (both -0.5 and |0.3+0.4i| = 0.5: the pair first by
    // imaginary part order), to rounding (1e-12 on entries of order 1).
    assert!((mu[0].re - 2.0).abs() < 1e-12 && mu[0].im.abs() < 1e-12);
    let rest: Vec<_> = mu[1..].to_vec();
    let has = |re: f64, im: f64| {
        rest.iter()
            .any(|m| (m.re - re).abs() < 1e-12 && (m.im - im).abs() < 1e-12)
    };
    assert!(has(-0.5, 0.0) && has(0.3, 0.4) && has(0.3, -0.4), "{mu:?}");
    assert!(!is_stable(&mu));
    assert!(is_stable(&mu[1..]));
}

#[test]
fn settings_out_of_range_are_rejected() {
    let problem = Rotation { theta: 1.0 };
    let bad = ContinuationSettings {
        min_step: 1.0,
        max_step: 0.1,
        ..ContinuationSettings::default()
    };
    match Continuation::new(&problem, &[0.0, 0.0], 0.0, bad) {
        Err(ContinuationError::InvalidSettings { field, .. }) => assert_eq!(field, "max_step"),
        other => panic!("expected invalid settings, got {:?}", other.err()),
    };
    match Continuation::new(&problem, &[0.0], 0.0, ContinuationSettings::default()) {
        Err(ContinuationError::DimensionMismatch {
            expected, found, ..
        }) => assert_eq!((expected, found), (2, 1)),
        other => panic!("expected a dimension error, got {:?}", other.err()),
    };
}
