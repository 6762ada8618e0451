//! Predicting the steady orbit at a new separation from orbits already found on its branch,
//! the way a continuation predicts its next point: the state `x(Z)` at `t = 0` is a smooth
//! function of `Z` between grazing points and folds, and each [`SteadyOrbit`] carries its
//! slope `dx/dZ` ([`SteadyOrbit::tangent`]).
//!
//! Two orbits with their slopes fix the cubic Hermite interpolant of `x(Z)`: its error is
//! `|x''''| h^4 / 384` at the middle of an interval `h` and `|x''''| h^4 / 6` one interval
//! beyond it, against `|x''| h^2 / 2` for the tangent line of one orbit, plus about `4 h` times
//! the slopes' own error (1e-6 relative with the decoupled sensitivities of the default
//! settings). At the paper's Fig. 1 points (Biolever on mica, A/A0 = 0.95, 0.90, 0.50), from
//! the orbits 0.01 and 0.02 nm above, the cubic is 6.1e-8, 1.3e-6 and 2.4e-8 nm off the orbit,
//! the tangent line of the nearer orbit 4.8e-5, 3.5e-4 and 3.3e-5 nm, and the nearer orbit's
//! own state 7.3e-3, 2.2e-2 and 3.2e-4 nm (`tests/orbit_prediction.rs` checks these ratios,
//! the slope against central differences and the cubic's fourth order): the cubic is close
//! enough for one Newton update to converge ([`crate::orbit::steady_orbit::OrbitStart::Predicted`]).

use continuation::hermite_basis;

use crate::orbit::steady_orbit::SteadyOrbit;

/// The cubic Hermite interpolant in `Z` of the states of `a` and `b` and their slopes
/// `dx/dZ`, evaluated at `z_nm` (between the two an interpolation, outside an extrapolation):
///
/// `x(Z) = h00(s) x_a + h10(s) h x'_a + h01(s) x_b + h11(s) h x'_b`, `s = (Z - Z_a) / h`,
/// `h = Z_b - Z_a`,
///
/// with the cubic Hermite basis [`continuation::hermite_basis`] (the branch's cubic
/// predictor's). State units (nm, nm/us).
///
/// For orbits of period `k T` (`k > 1`) the two states must be the same phase of the cycle
/// (the same drive period of it at `t = 0`), which the multiplicity alone does not check.
///
/// `None` when either orbit has no tangent, the two are at the same separation or of
/// different multiplicity or dimension, or the result is not finite.
pub fn hermite_state(z_nm: f64, a: &SteadyOrbit, b: &SteadyOrbit) -> Option<Vec<f64>> {
    let (slope_a, slope_b) = (a.tangent.as_ref()?, b.tangent.as_ref()?);
    let h = b.z_nm - a.z_nm;
    let n = a.state.len();
    let comparable = a.multiplicity == b.multiplicity
        && b.state.len() == n
        && slope_a.len() == n
        && slope_b.len() == n;
    if !(comparable && h != 0.0 && h.is_finite()) {
        return None;
    }
    let [h00, h10, h01, h11] = hermite_basis((z_nm - a.z_nm) / h);
    let state: Vec<f64> = (0..n)
        .map(|i| h00 * a.state[i] + h10 * h * slope_a[i] + h01 * b.state[i] + h11 * h * slope_b[i])
        .collect();
    state.iter().all(|v| v.is_finite()).then_some(state)
}

/// The tangent line of `orbit` at `z_nm`: `x + (Z - Z_orbit) dx/dZ`, state units. `None`
/// without a tangent or for a non-finite result.
pub fn tangent_state(z_nm: f64, orbit: &SteadyOrbit) -> Option<Vec<f64>> {
    let slope = orbit.tangent.as_ref()?;
    let dz = z_nm - orbit.z_nm;
    let state: Vec<f64> = orbit
        .state
        .iter()
        .zip(slope)
        .map(|(x, t)| x + dz * t)
        .collect();
    (slope.len() == orbit.state.len() && state.iter().all(|v| v.is_finite())).then_some(state)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::orbit::observables::OrbitObservables;

    /// An orbit whose state and slope are those of the cubic `x_i(Z) = c_i(Z)` at `z`.
    fn on_cubic(z: f64, cubics: &[[f64; 4]]) -> SteadyOrbit {
        let value = |c: &[f64; 4]| c[0] + z * (c[1] + z * (c[2] + z * c[3]));
        let slope = |c: &[f64; 4]| c[1] + z * (2.0 * c[2] + z * 3.0 * c[3]);
        SteadyOrbit {
            z_nm: z,
            multiplicity: 1,
            converged: true,
            iterations: 0,
            residual: 0.0,
            state: cubics.iter().map(value).collect(),
            multipliers: Vec::new(),
            stable: true,
            monodromy: None,
            tangent: Some(cubics.iter().map(slope).collect()),
            whole_orbit: OrbitObservables::default(),
            periods: Vec::new(),
            period_states: Vec::new(),
        }
    }

    const CUBICS: [[f64; 4]; 2] = [[1.5, -2.0, 0.25, 0.75], [-3.0, 0.5, 4.0, -1.25]];

    #[test]
    fn hermite_reproduces_a_cubic_inside_and_beyond() {
        let (a, b) = (on_cubic(2.0, &CUBICS), on_cubic(2.5, &CUBICS));
        for z in [1.0, 1.9, 2.0, 2.2, 2.5, 3.0, 4.0] {
            let exact = on_cubic(z, &CUBICS).state;
            let predicted = hermite_state(z, &a, &b).expect("prediction");
            for (p, e) in predicted.iter().zip(&exact) {
                assert!(
                    (p - e).abs() <= 1e-12 * (1.0 + e.abs()),
                    "z {z}: {p} vs {e}"
                );
            }
        }
    }

    #[test]
    fn tangent_line_is_exact_to_first_order() {
        // On a cubic, the tangent line's error at distance dz is c2 dz^2 + c3 (3 z dz^2 + dz^3).
        let orbit = on_cubic(1.0, &CUBICS);
        let dz = 1e-3;
        let predicted = tangent_state(1.0 + dz, &orbit).expect("prediction");
        let exact = on_cubic(1.0 + dz, &CUBICS).state;
        for (i, c) in CUBICS.iter().enumerate() {
            let error = c[2] * dz * dz + c[3] * (3.0 * dz * dz + dz * dz * dz);
            assert!((exact[i] - predicted[i] - error).abs() < 1e-14);
        }
    }

    #[test]
    fn degenerate_inputs_give_none() {
        let a = on_cubic(2.0, &CUBICS);
        assert!(hermite_state(2.1, &a, &a).is_none(), "same separation");
        let mut untangented = on_cubic(2.5, &CUBICS);
        untangented.tangent = None;
        assert!(hermite_state(2.1, &a, &untangented).is_none());
        assert!(tangent_state(2.1, &untangented).is_none());
        let mut doubled = on_cubic(2.5, &CUBICS);
        doubled.multiplicity = 2;
        assert!(hermite_state(2.1, &a, &doubled).is_none());
    }
}
