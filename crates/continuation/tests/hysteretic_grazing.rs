//! A branch that ends at a hysteretic grazing: the period map jumps where the orbit first
//! touches the contact surface, so no orbit lies past it, and the continuation cuts its step
//! towards the grazing (`ContinuationSettings::hysteretic_grazing`) instead of halving it.

use std::cell::Cell;

use continuation::{
    Continuation, ContinuationError, ContinuationSettings, OrbitStructure, ParameterDirection,
    PeriodMap, PeriodicProblem, SpecialPointKind, StopReason,
};
use nalgebra::{DMatrix, DVector};

/// The contraction `P(x; p) = a x + (1 - a) (p + J [x < 0])` of a "gap" `x` whose only minimum
/// is `x` itself: free (`x >= 0`) its fixed point is `x = p`, so the orbit grazes the contact
/// surface at `p = 0` exactly; attached (`x < 0`) the map jumps by `(1 - a) J`, and its fixed
/// point `p + J` is free for `-J < p < 0`, where no fixed point exists at all (the branch of
/// free orbits ends at the grazing; the attached orbits exist only for `p < -J`).
struct JumpAtGrazing {
    contraction: f64,
    jump: f64,
    /// Period maps evaluated.
    maps: Cell<usize>,
}

impl PeriodicProblem for JumpAtGrazing {
    fn dim(&self) -> usize {
        1
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        self.maps.set(self.maps.get() + 1);
        let x = x[0];
        let a = self.contraction;
        let attached = x < 0.0;
        let shift = if attached { self.jump } else { 0.0 };
        Ok(PeriodMap {
            image: DVector::from_element(1, a * x + (1.0 - a) * (p + shift)),
            monodromy: DMatrix::from_element(1, 1, a),
            parameter_derivative: DVector::from_element(1, 1.0 - a),
            structure: OrbitStructure {
                minima: vec![(0.5, x)],
                maxima: vec![],
                impacts: usize::from(attached),
                duration: 1.0,
                permanent_contact: false,
                release_maxima: vec![],
            },
        })
    }
}

/// The branch from `p = 1` (free orbit `x = 1`) downwards with `hysteretic_grazing` set or not:
/// its grazing's parameter, its stop, and the period maps it took.
fn run(hysteretic_grazing: bool) -> (f64, StopReason, usize) {
    let problem = JumpAtGrazing {
        contraction: 0.5,
        jump: 2.0,
        maps: Cell::new(0),
    };
    let settings = ContinuationSettings {
        initial_step: 0.05,
        max_step: 0.1,
        direction: ParameterDirection::Decreasing,
        parameter_min: -1.0,
        hysteretic_grazing,
        ..ContinuationSettings::default()
    };
    let branch = Continuation::new(&problem, &[1.0], 1.0, settings)
        .expect("start converges")
        .run();
    let grazings: Vec<f64> = branch
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialPointKind::Grazing)
        .map(|s| s.parameter)
        .collect();
    assert_eq!(grazings.len(), 1, "{:?}", branch.special_points);
    (grazings[0], branch.stop, problem.maps.get())
}

#[test]
fn the_branch_ends_at_the_exact_grazing_in_fewer_maps_than_by_halving() {
    let (halved, halved_stop, halved_maps) = run(false);
    let (cut, cut_stop, cut_maps) = run(true);
    // Exact grazing p = 0; the branch's last point lies within the smallest step (1e-8) of it
    // and the grazing is located from there.
    for (grazing, stop) in [(halved, halved_stop), (cut, cut_stop)] {
        assert!(grazing.abs() <= 1e-8, "grazing at {grazing}");
        assert_eq!(stop, StopReason::StepTooSmall);
    }
    // Halving from the largest step 0.1 to the smallest 1e-8 takes 23 failed corrections
    // (each several maps); cutting to 0.99 of the way to the grazing extrapolated from the
    // last two points (exact here: the minimum is linear along the branch), and aiming the
    // steps after it the same way, takes a few. Both end with the same corner shots and
    // terminal location (about 100 maps here), so the measured 342 against 118 maps is
    // asserted as at least halved.
    assert!(
        2 * cut_maps < halved_maps,
        "maps: cut {cut_maps}, halved {halved_maps}"
    );
    println!("maps: halved {halved_maps}, cut {cut_maps}; grazing {halved:e}, {cut:e}");
}

/// [`JumpAtGrazing`] with a second state `y` slaved to `p` whose attached fixed point lies far
/// off the free one: free, `P(x, y; p) = (a x + (1 - a) p, a y - (1 - a) 10 p)` (fixed point
/// `x = p`, `y = -10 p`: grazing at `p = 0`); attached (`x < 0`), `x` shifted by `J` and `y` by
/// `-Y`, `P = (a x + (1 - a) (p + J), a y - (1 - a) (10 p + Y))` (fixed point `x = p + J`,
/// `y = -10 p - Y`: attached orbits for `p < -J`). `x` and `y` are straight lines in `p` on both
/// branches, so `Z` turns nowhere: the fold test `t_p` has one sign along each.
struct JumpAcrossTheTangent {
    contraction: f64,
    jump_x: f64,
    jump_y: f64,
}

impl PeriodicProblem for JumpAcrossTheTangent {
    fn dim(&self) -> usize {
        2
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        let a = self.contraction;
        let attached = x[0] < 0.0;
        let (shift_x, shift_y) = if attached {
            (self.jump_x, self.jump_y)
        } else {
            (0.0, 0.0)
        };
        Ok(PeriodMap {
            image: DVector::from_vec(vec![
                a * x[0] + (1.0 - a) * (p + shift_x),
                a * x[1] - (1.0 - a) * (10.0 * p + shift_y),
            ]),
            monodromy: DMatrix::from_diagonal_element(2, 2, a),
            parameter_derivative: DVector::from_vec(vec![1.0 - a, -10.0 * (1.0 - a)]),
            structure: OrbitStructure {
                minima: vec![(0.5, x[0])],
                maxima: vec![],
                impacts: usize::from(attached),
                duration: 1.0,
                permanent_contact: false,
                release_maxima: vec![],
            },
        })
    }
}

/// The branch of free orbits from `p = 1` downwards jumps at the grazing `p = 0` to the attached
/// orbits (the corner jump's shot at the largest step, `p = -0.1`), whose `y` lies 100 below:
/// the jump's secant points against the free branch's tangent in `y`, and the attached orbit's
/// tangent, oriented along that secant, points up in `p`. No `fold` is reported (`Z` turns on
/// neither branch), the grazing is. Trials next to the grazing that took their tangents'
/// orientation from the secant too would flip `t_p` between the last free orbit and them: a
/// `fold` located there, converged.
#[test]
fn no_fold_at_the_jump_of_a_hysteretic_grazing() {
    let problem = JumpAcrossTheTangent {
        contraction: 0.5,
        jump_x: 0.01,
        jump_y: 100.0,
    };
    let settings = ContinuationSettings {
        initial_step: 0.05,
        max_step: 0.1,
        direction: ParameterDirection::Decreasing,
        parameter_min: -1.0,
        hysteretic_grazing: true,
        ..ContinuationSettings::default()
    };
    // Stop at the first attached orbit, past the jump.
    let branch = Continuation::new(&problem, &[1.0, -10.0], 1.0, settings)
        .expect("start converges")
        .stop_when(|point| point.parameter < -0.05)
        .run();
    assert_eq!(branch.stop, StopReason::UserStop, "{:?}", branch.error);
    let last = branch.points.last().expect("points");
    assert!(
        (last.state[1] - (-10.0 * last.parameter - 100.0)).abs() < 1e-6,
        "the jump reached the attached orbit: {last:?}"
    );
    let kinds: Vec<(SpecialPointKind, f64)> = branch
        .special_points
        .iter()
        .map(|s| (s.kind, s.parameter))
        .collect();
    assert!(
        !kinds.iter().any(|(k, _)| *k == SpecialPointKind::Fold),
        "{kinds:?}"
    );
    assert!(
        kinds
            .iter()
            .any(|(k, p)| *k == SpecialPointKind::Grazing && p.abs() < 1e-6),
        "{kinds:?}"
    );
}

/// A branch `x = p` (`p > 0`) whose gap minimum `g = -x^2` vanishes quadratically at the
/// grazing `p = 0` (the side of a hysteretic grazing that crosses the surface, one impact:
/// `sqrt(|g|) = x` is linear in `p`), past which the map jumps (`x <= 0`: minimum `x^2`, no
/// impact, the map shifted by `J`, no fixed point for `-J < p <= 0`); within `band` of the grazing (`0 < x < band`) the map carries a
/// deterministic noise of amplitude `noise` (a hash of `x` and `p`), above Newton's tolerance
/// 1e-10 and below its noise floor 1e-8, as a JKR period map's `sqrt(|g|)` term puts its error
/// there.
struct NoisyQuadraticGrazing {
    contraction: f64,
    jump: f64,
    band: f64,
    noise: f64,
    /// Period maps evaluated, and those within the noise band.
    maps: Cell<usize>,
    maps_in_band: Cell<usize>,
}

impl NoisyQuadraticGrazing {
    /// A value in `[-1, 1)` fixed by the bits of `x` and `p`.
    fn hash(x: f64, p: f64) -> f64 {
        let bits = (x.to_bits() ^ p.to_bits().rotate_left(17)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        (bits >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

impl PeriodicProblem for NoisyQuadraticGrazing {
    fn dim(&self) -> usize {
        1
    }

    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
        self.maps.set(self.maps.get() + 1);
        let x = x[0];
        let a = self.contraction;
        let past = x <= 0.0;
        let in_band = !past && x < self.band;
        if in_band {
            self.maps_in_band.set(self.maps_in_band.get() + 1);
        }
        let shift = if past { self.jump } else { 0.0 };
        let noise = if in_band {
            self.noise * Self::hash(x, p)
        } else {
            0.0
        };
        Ok(PeriodMap {
            image: DVector::from_element(1, a * x + (1.0 - a) * (p + shift) + noise),
            monodromy: DMatrix::from_element(1, 1, a),
            parameter_derivative: DVector::from_element(1, 1.0 - a),
            structure: OrbitStructure {
                minima: vec![(0.5, if past { x * x } else { -x * x })],
                maxima: vec![],
                impacts: usize::from(!past),
                duration: 1.0,
                permanent_contact: false,
                release_maxima: vec![],
            },
        })
    }
}

/// The branch of [`NoisyQuadraticGrazing`] from `p = 1` downwards (`hysteretic_grazing`): its
/// steps aimed at the grazing reach the noise band, where corrections fail at the noise floor
/// (or converge by chance onto orbits the noise shifts by up to `noise / (1 - a)` = 1e-8); the
/// zero of `sqrt(|g|)`, exactly linear outside the band, is extrapolated to within the location
/// tolerance from the branch's points, so such a failure, or after one the point that resolves
/// the zero, ends the branch, and the terminal location shoots no trials into the band. The
/// grazing's bracket holds the exact `p = 0` (measured width 1.8e-9), and fewer maps are spent
/// in the band: measured 18 (of 62 in all), against 138 (of 182) when the branch halved its
/// step down to the smallest through the band and the terminal location shot its trials
/// there; asserted as below a quarter of that.
#[test]
fn a_failure_at_the_noise_floor_next_to_a_resolved_grazing_ends_the_branch() {
    let problem = NoisyQuadraticGrazing {
        contraction: 0.5,
        jump: 2.0,
        band: 1e-5,
        noise: 5e-9,
        maps: Cell::new(0),
        maps_in_band: Cell::new(0),
    };
    let settings = ContinuationSettings {
        initial_step: 0.05,
        max_step: 0.1,
        direction: ParameterDirection::Decreasing,
        parameter_min: -1.0,
        hysteretic_grazing: true,
        ..ContinuationSettings::default()
    };
    let branch = Continuation::new(&problem, &[1.0], 1.0, settings)
        .expect("start converges")
        .run();
    assert_eq!(branch.stop, StopReason::StepTooSmall);
    let grazings: Vec<_> = branch
        .special_points
        .iter()
        .filter(|s| s.kind == SpecialPointKind::Grazing)
        .collect();
    assert_eq!(grazings.len(), 1, "{:?}", branch.special_points);
    let grazing = grazings[0];
    // The exact grazing p = 0 inside the claimed bracket.
    assert!(
        grazing.bracket.0 <= 0.0 && 0.0 <= grazing.bracket.1 && grazing.precision <= 1e-8,
        "{grazing:?}"
    );
    let (maps, in_band) = (problem.maps.get(), problem.maps_in_band.get());
    println!("maps {maps}, in the noise band {in_band}; grazing {grazing:?}");
    assert!(4 * in_band < 138, "maps in the noise band: {in_band}");
}
