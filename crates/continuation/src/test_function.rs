//! Continuous test functions along a branch, whose sign changes signal special points.
//!
//! * fold: the parameter component `t_p` of the unit tangent (zero at a turning point);
//! * period doubling: `Re prod_i (1 + mu_i)` = `det(M + I)` (zero when a real multiplier is
//!   `-1`);
//! * Neimark-Sacker: `Re prod_{i<j} (mu_i mu_j - 1)` = `det(M (.) M - I)` on the bialternate
//!   product (zero when a complex pair crosses the unit circle, `mu conj(mu) = 1`; also at a
//!   neutral saddle, `mu_i mu_j = 1` real, which is no bifurcation and not reported: a
//!   located sign change counts only with a complex pair on the unit circle);
//! * structure (MODEL.md Sec. 5): the value of each local minimum of the contact switching
//!   function (zero at grazing), of each local maximum (zero when two contacts merge), and the
//!   impact count per period; with a release surface (a hysteretic contact), each maximum of
//!   its switching function while the contact is held (zero at the grazing of that surface,
//!   `pull-off`). Extrema of two orbits are matched by their time in the period.
//!
//! (Kuznetsov, *Elements of Applied Bifurcation Theory*, Sec. 10.2, for the bialternate test.)

use nalgebra::{Complex, DVector};

use crate::problem::OrbitStructure;

/// The multiplier- and tangent-based test functions of one branch point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TestValues {
    /// Fold test: the parameter component of the unit tangent.
    pub fold: f64,
    /// Period-doubling test `Re prod (1 + mu_i)`.
    pub period_doubling: f64,
    /// Neimark-Sacker test `Re prod_{i<j} (mu_i mu_j - 1)` (1 for `n = 1`).
    pub neimark_sacker: f64,
}

impl TestValues {
    /// The test values of a point with unit tangent `tangent` (length `n + 1`, parameter
    /// last) and Floquet multipliers `multipliers`.
    pub fn new(tangent: &DVector<f64>, multipliers: &[Complex<f64>]) -> Self {
        Self {
            fold: tangent[tangent.len() - 1],
            period_doubling: period_doubling_test(multipliers),
            neimark_sacker: neimark_sacker_test(multipliers),
        }
    }
}

/// `Re prod_i (1 + mu_i)`: changes sign when a real multiplier crosses `-1`.
pub fn period_doubling_test(multipliers: &[Complex<f64>]) -> f64 {
    multipliers
        .iter()
        .fold(Complex::new(1.0, 0.0), |acc, m| acc * (m + 1.0))
        .re
}

/// `Re prod_{i<j} (mu_i mu_j - 1)`: changes sign when a complex pair of multipliers crosses
/// the unit circle (or at a neutral saddle).
pub fn neimark_sacker_test(multipliers: &[Complex<f64>]) -> f64 {
    let mut acc = Complex::new(1.0, 0.0);
    for (i, a) in multipliers.iter().enumerate() {
        for b in &multipliers[i + 1..] {
            acc *= a * b - 1.0;
        }
    }
    acc.re
}

/// A multiplier is complex when its imaginary part exceeds this fraction of its modulus
/// (eigenvalues of a real matrix that are real come out with rounding-level imaginary parts).
const COMPLEX_FRACTION: f64 = 1e-8;

/// A located Neimark-Sacker point's complex pair is on the unit circle when its modulus is
/// within this of 1 (the location's precision in the parameter leaves the modulus this close).
const UNIT_CIRCLE_DISTANCE: f64 = 1e-3;

/// Whether a complex pair of `multipliers` lies on the unit circle: what tells a true
/// Neimark-Sacker point from a neutral saddle (two real multipliers with product 1, where the
/// bialternate test also vanishes but no bifurcation happens).
pub(crate) fn has_complex_pair_on_unit_circle(multipliers: &[Complex<f64>]) -> bool {
    multipliers.iter().any(|m| {
        m.im.abs() > COMPLEX_FRACTION * m.norm() && (m.norm() - 1.0).abs() < UNIT_CIRCLE_DISTANCE
    })
}

/// Whether `multipliers` hold a complex pair (a multiplier whose imaginary part exceeds
/// [`COMPLEX_FRACTION`] of its modulus), on the unit circle or not. Where neither end of a step
/// holds one, a sign change of [`neimark_sacker_test`] over the step is a product of two real
/// multipliers passing 1 (a neutral saddle), not a Neimark-Sacker point: that would need a
/// pair to turn complex, cross the unit circle and turn real again within the one step.
pub(crate) fn has_complex_pair(multipliers: &[Complex<f64>]) -> bool {
    multipliers
        .iter()
        .any(|m| m.im.abs() > COMPLEX_FRACTION * m.norm())
}

/// Which kind of extremum of the switching function a structure test follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum ExtremumKind {
    /// A local minimum of `h` (a near impact, an impact, or grazing at value 0).
    Minimum,
    /// A local maximum of `h` (between two contacts when negative).
    Maximum,
    /// A local maximum of a release surface's `h_r` while the contact is held, or the virtual
    /// maximum at a release ([`OrbitStructure::release_maxima`]): 0 at the grazing of the
    /// release surface (`pull-off`).
    ReleaseMaximum,
}

/// A structure test between two branch points: an extremum followed from one to the other
/// (its value changes sign), or the impact count (which changes without any extremum
/// changing sign).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum StructureTest {
    /// An extremum at time `t_a` in the first orbit and `t_b` in the second.
    Extremum {
        kind: ExtremumKind,
        t_a: f64,
        t_b: f64,
        value_a: f64,
        value_b: f64,
        duration: f64,
    },
    /// The impact count goes from `n_a` to `n_b`.
    ImpactCount { n_a: usize, n_b: usize },
}

/// The periodic time difference `b - a` wrapped to `[-duration/2, duration/2]`.
fn wrapped(a: f64, b: f64, duration: f64) -> f64 {
    if !(duration.is_finite() && duration > 0.0) {
        return b - a;
    }
    let d = (b - a).rem_euclid(duration);
    if d > 0.5 * duration {
        d - duration
    } else {
        d
    }
}

/// Mutually nearest pairs (by periodic time) of two lists of `(time, value)`.
fn matched(a: &[(f64, f64)], b: &[(f64, f64)], duration: f64) -> Vec<(usize, usize)> {
    let nearest = |t: f64, list: &[(f64, f64)]| -> Option<usize> {
        list.iter()
            .enumerate()
            .min_by(|x, y| {
                wrapped(t, x.1 .0, duration)
                    .abs()
                    .total_cmp(&wrapped(t, y.1 .0, duration).abs())
            })
            .map(|(i, _)| i)
    };
    let mut pairs = Vec::new();
    for (i, &(t, _)) in a.iter().enumerate() {
        if let Some(j) = nearest(t, b) {
            if nearest(b[j].0, a) == Some(i) {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

/// The structure tests whose value changes sign between orbits `a` and `b`: every matched
/// minimum or maximum whose value changes sign, or, when there is none, the impact count if
/// it changed.
pub(crate) fn structure_changes(a: &OrbitStructure, b: &OrbitStructure) -> Vec<StructureTest> {
    let duration = if a.duration > 0.0 {
        a.duration
    } else {
        b.duration
    };
    let mut tests = Vec::new();
    for (kind, la, lb) in [
        (ExtremumKind::Minimum, &a.minima, &b.minima),
        (ExtremumKind::Maximum, &a.maxima, &b.maxima),
        (
            ExtremumKind::ReleaseMaximum,
            &a.release_maxima,
            &b.release_maxima,
        ),
    ] {
        for (i, j) in matched(la, lb, duration) {
            let (t_a, value_a) = la[i];
            let (t_b, value_b) = lb[j];
            if (value_a < 0.0) != (value_b < 0.0) {
                tests.push(StructureTest::Extremum {
                    kind,
                    t_a,
                    t_b,
                    value_a,
                    value_b,
                    duration,
                });
            }
        }
    }
    if tests.is_empty() && a.impacts != b.impacts {
        tests.push(StructureTest::ImpactCount {
            n_a: a.impacts,
            n_b: b.impacts,
        });
    }
    tests
}

impl StructureTest {
    /// The value of this test on an orbit at fraction `sigma` of the segment from the first
    /// orbit to the second: the extremum of the right kind nearest in time to the
    /// interpolated time (NaN if there is none), or `impacts - (n_a + n_b)/2`.
    pub(crate) fn value(&self, sigma: f64, structure: &OrbitStructure) -> f64 {
        match *self {
            StructureTest::Extremum {
                kind,
                t_a,
                t_b,
                duration,
                ..
            } => {
                let t = t_a + sigma * wrapped(t_a, t_b, duration);
                let list = match kind {
                    ExtremumKind::Minimum => &structure.minima,
                    ExtremumKind::Maximum => &structure.maxima,
                    ExtremumKind::ReleaseMaximum => &structure.release_maxima,
                };
                list.iter()
                    .min_by(|x, y| {
                        wrapped(t, x.0, duration)
                            .abs()
                            .total_cmp(&wrapped(t, y.0, duration).abs())
                    })
                    .map_or(f64::NAN, |e| e.1)
            }
            StructureTest::ImpactCount { n_a, n_b } => {
                structure.impacts as f64 - 0.5 * (n_a + n_b) as f64
            }
        }
    }

    /// The fraction of the segment where the test crosses zero by linear interpolation of
    /// its end values (used to tell apart several events in one step).
    pub(crate) fn linear_root(&self) -> f64 {
        match *self {
            StructureTest::Extremum {
                value_a, value_b, ..
            } => {
                if value_a == value_b {
                    0.5
                } else {
                    (value_a / (value_a - value_b)).clamp(0.0, 1.0)
                }
            }
            StructureTest::ImpactCount { .. } => 0.5,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn period_doubling_test_changes_sign_through_minus_one() {
        // prod(1 + mu): 1 + (-0.9) = 0.1 and 1 + (-1.1) = -0.1, times 1 + 0.5 = 1.5.
        let before = [Complex::new(-0.9, 0.0), Complex::new(0.5, 0.0)];
        let after = [Complex::new(-1.1, 0.0), Complex::new(0.5, 0.0)];
        assert!((period_doubling_test(&before) - 0.15).abs() < 1e-15);
        assert!((period_doubling_test(&after) + 0.15).abs() < 1e-15);
    }

    #[test]
    fn a_neutral_saddle_has_no_complex_pair() {
        // Two real multipliers with product 1 zero the Neimark-Sacker test without a pair.
        let saddle = [Complex::new(2.0, 0.0), Complex::new(0.5, 0.0)];
        assert!(neimark_sacker_test(&saddle).abs() < 1e-15);
        assert!(!has_complex_pair(&saddle));
        // Rounding-level imaginary parts of real eigenvalues are not a pair either.
        let rounded = [Complex::new(2.0, 1e-12), Complex::new(0.5, -1e-12)];
        assert!(!has_complex_pair(&rounded));
        let pair = [
            Complex::from_polar(1.0, 0.3),
            Complex::from_polar(1.0, -0.3),
        ];
        assert!(has_complex_pair(&pair));
    }

    #[test]
    fn neimark_sacker_test_is_the_modulus_squared_minus_one_of_a_pair() {
        // For a pair r e^{+-i}: mu conj(mu) - 1 = r^2 - 1.
        for r in [0.9, 1.1] {
            let pair = [Complex::from_polar(r, 1.0), Complex::from_polar(r, -1.0)];
            assert!((neimark_sacker_test(&pair) - (r * r - 1.0)).abs() < 1e-14);
        }
    }

    #[test]
    fn extrema_are_matched_across_the_period_boundary() {
        // A minimum moving from t = 0.99 to t = 0.01 (period 1) through zero, next to another
        // minimum at t = 0.5 that stays positive.
        let a = OrbitStructure {
            minima: vec![(0.5, 0.3), (0.99, 0.01)],
            maxima: vec![],
            impacts: 0,
            duration: 1.0,
            permanent_contact: false,
            release_maxima: vec![],
        };
        let b = OrbitStructure {
            minima: vec![(0.01, -0.01), (0.5, 0.3)],
            maxima: vec![],
            impacts: 1,
            duration: 1.0,
            permanent_contact: false,
            release_maxima: vec![],
        };
        let tests = structure_changes(&a, &b);
        assert_eq!(tests.len(), 1, "{tests:?}");
        // Half-way the followed minimum is the one nearest t = 0.99 + 0.5 * 0.02 = 1.0 = 0.0.
        let mid = OrbitStructure {
            minima: vec![(0.0, 0.002), (0.5, 0.3)],
            maxima: vec![],
            impacts: 0,
            duration: 1.0,
            permanent_contact: false,
            release_maxima: vec![],
        };
        assert_eq!(tests[0].value(0.5, &mid), 0.002);
        assert!((tests[0].linear_root() - 0.5).abs() < 1e-15);
    }
}
