//! The contact series (module `contact_series`) against the plain vector field and finite
//! differences, through the model's `TaylorExpansion`.

use hybrid::{
    ClockPolynomial, Direction, HybridSystem, Sensitivity, Settings, Solver, StepOutcome,
    TaylorExpansion, TaylorSeries,
};
use nalgebra::DMatrix;

use crate::fixtures::builtin_case;
use crate::model::separation::Separation;
use crate::model::TappingModel;
use crate::model::CONTACT;

const ORDER: usize = 24;

/// The Biolever on mica with the free orbit 1 nm into the sample.
fn indenting_model() -> TappingModel {
    let case = builtin_case("biolever-mica").expect("built-in case");
    let mut model = TappingModel::from_case(&case).expect("model");
    let z = model.grazing_separation_nm() - 1.0;
    model
        .set_separation(Separation::Constant(z))
        .expect("finite");
    model
}

fn tight() -> Settings {
    Settings {
        relative_tolerance: 1e-14,
        absolute_tolerance: 1e-14,
        ..Settings::default()
    }
}

/// A DOP853 solver (tolerance 1e-14) from the free state at t = 0, stopped at the first
/// contact onset: the solver and the onset time.
fn at_first_onset(
    model: &TappingModel,
    sensitivity: Sensitivity,
) -> (Solver<'_, TappingModel>, f64) {
    let x0 = model.free_state();
    let mut solver = Solver::new(model, 0.0, &x0, sensitivity, tight()).expect("solver");
    loop {
        match solver.step(10.0 * model.period_us()).expect("step") {
            StepOutcome::Event(event) if event.direction == Direction::Down => {
                return (solver, event.t)
            }
            StepOutcome::EndTime => panic!("no contact"),
            _ => {}
        }
    }
}

/// The solver advanced to `t` (no event on the way).
fn advance(solver: &mut Solver<'_, TappingModel>, t: f64) {
    while solver.t() < t {
        if let StepOutcome::Event(event) = solver.step(t).expect("step") {
            panic!("event at {}", event.t);
        }
    }
}

fn state_series(model: &TappingModel, clock: &ClockPolynomial, x0: &[f64]) -> TaylorSeries {
    state_series_shared(model, clock, x0).0
}

/// The state's series and what its recurrence leaves for the tangents' (`shared`).
fn state_series_shared(
    model: &TappingModel,
    clock: &ClockPolynomial,
    x0: &[f64],
) -> (TaylorSeries, Vec<f64>) {
    let mut series = TaylorSeries::new(model.dim(), ORDER);
    let mut shared = Vec::new();
    series.start_at(x0);
    assert!(model.taylor_series(CONTACT, clock, &mut series, &mut shared));
    (series, shared)
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The first contact's onset and release times (us) and the solver stopped at the onset.
fn first_contact(
    model: &TappingModel,
    sensitivity: Sensitivity,
) -> (Solver<'_, TappingModel>, f64, f64) {
    let (mut probe, onset) = at_first_onset(model, Sensitivity::None);
    let release = loop {
        if let StepOutcome::Event(event) = probe.step(onset + model.period_us()).expect("step") {
            assert_eq!(event.direction, Direction::Up);
            break event.t;
        }
    };
    let (solver, again) = at_first_onset(model, sensitivity);
    assert_eq!(onset, again);
    (solver, onset, release)
}

/// From the onset on the square-root clock centred there (the series in `sigma`, where the
/// solution is analytic), from the middle of the contact on the time clock, and up to the
/// release on the square-root clock centred on it: each series evaluated along a step of a
/// fifth of its reach (so that order 24 is converged far below the tolerance) agrees with
/// DOP853 at tolerance 1e-14 to 1e-11 (nm, nm/us). The contact lasts `T_c`; the onset's
/// and release's square roots are `sqrt(T_c)` from the other end.
#[test]
fn state_series_follow_the_integrated_contact_on_every_clock() {
    let model = indenting_model();
    let (mut solver, onset, release) = first_contact(&model, Sensitivity::None);
    let duration = release - onset;
    let root = duration.sqrt();
    let x_onset = solver.state().to_vec();
    let onset_clock = ClockPolynomial {
        start: onset,
        rate: 0.0,
        curvature: 1.0,
    };
    let series = state_series(&model, &onset_clock, &x_onset);
    let mut x = vec![0.0; model.dim()];
    for sigma in [0.05 * root, 0.1 * root, 0.2 * root] {
        advance(&mut solver, onset + sigma * sigma);
        series.evaluate(sigma, &mut x);
        let error = max_difference(&x, solver.state());
        assert!(error < 1e-11, "onset clock, sigma {sigma}: {error:e}");
    }
    // The time clock from the middle.
    let t0 = onset + 0.5 * duration;
    advance(&mut solver, t0);
    let x0 = solver.state().to_vec();
    let time_clock = ClockPolynomial {
        start: t0,
        rate: 1.0,
        curvature: 0.0,
    };
    let series = state_series(&model, &time_clock, &x0);
    for dt in [0.05 * duration, 0.1 * duration] {
        advance(&mut solver, t0 + dt);
        series.evaluate(dt, &mut x);
        let error = max_difference(&x, solver.state());
        assert!(error < 1e-11, "time clock, dt {dt}: {error:e}");
    }
    // The release clock from sigma0 = -0.2 sqrt(T_c) to the release (sigma = 0), where the
    // solver's event state is.
    let sigma0 = 0.2 * root;
    let before = release - sigma0 * sigma0;
    advance(&mut solver, before);
    let x_before = solver.state().to_vec();
    let event = loop {
        match solver.step(release + 1.0).expect("step") {
            StepOutcome::Event(event) => break event,
            StepOutcome::EndTime => panic!("no release"),
            StepOutcome::Internal => {}
        }
    };
    assert!(
        (event.t - release).abs() < 1e-12 * release,
        "{} vs {release}",
        event.t
    );
    // Centred on the event the solver located (within 1e-12 of the first run's).
    let sigma0 = (event.t - before).sqrt();
    let release_clock = ClockPolynomial {
        start: before,
        rate: 2.0 * sigma0,
        curvature: -1.0,
    };
    let series = state_series(&model, &release_clock, &x_before);
    series.evaluate(sigma0, &mut x);
    let error = max_difference(&x, &event.state);
    assert!(error < 1e-11, "release clock: {error:e}");
}

/// The tangent series against DOP853's variational equations from the onset on the
/// square-root clock, and against central differences of the state series (in the initial
/// state and in Z) on the time and release clocks.
#[test]
fn tangent_series_are_the_derivatives_of_the_flow() {
    let model = indenting_model();
    let n = model.dim();
    let (mut solver, onset, release) = first_contact(&model, Sensitivity::Transition);
    let duration = release - onset;
    let root = duration.sqrt();
    let x_onset = solver.state().to_vec();
    let before = solver.transition().clone();
    let sigma = 0.2 * root;
    advance(&mut solver, onset + sigma * sigma);
    // The contact's own transition from the onset (the saltation there is the identity).
    let expected = solver.transition() * before.try_inverse().expect("invertible");
    let onset_clock = ClockPolynomial {
        start: onset,
        rate: 0.0,
        curvature: 1.0,
    };
    let tangents = tangent_series(&model, &onset_clock, &x_onset, false);
    let mut v = vec![0.0; n * n];
    tangents.evaluate(sigma, &mut v);
    // Row-major series, column-major nalgebra.
    let computed = DMatrix::from_row_slice(n, n, &v);
    let error = (&computed - &expected).amax() / expected.amax();
    assert!(error < 1e-9, "onset transition: {error:e}");

    // From the middle of the contact, with dx/dZ, on the time clock and on the release
    // clock (sigma0 = -0.2 sqrt(T_c)).
    let t0 = onset + 0.5 * duration;
    advance(&mut solver, t0);
    let x0 = solver.state().to_vec();
    let sigma0 = 0.2 * root;
    let release_start = release - sigma0 * sigma0;
    advance(&mut solver, release_start);
    let x_release = solver.state().to_vec();
    for (clock, x0, s) in [
        (
            ClockPolynomial {
                start: t0,
                rate: 1.0,
                curvature: 0.0,
            },
            &x0,
            0.1 * duration,
        ),
        (
            ClockPolynomial {
                start: release_start,
                rate: 2.0 * sigma0,
                curvature: -1.0,
            },
            &x_release,
            0.5 * sigma0,
        ),
    ] {
        let tangents = tangent_series(&model, &clock, x0, true);
        let mut v = vec![0.0; n * (n + 1)];
        tangents.evaluate(s, &mut v);
        let step = 1e-6;
        let mut plus = vec![0.0; n];
        let mut minus = vec![0.0; n];
        for column in 0..=n {
            let (mut up, mut down) = (model.clone(), model.clone());
            let (mut x_up, mut x_down) = (x0.clone(), x0.clone());
            if column < n {
                x_up[column] += step;
                x_down[column] -= step;
            } else {
                let z = model.separation().at(0.0);
                up.set_separation(Separation::Constant(z + step))
                    .expect("finite");
                down.set_separation(Separation::Constant(z - step))
                    .expect("finite");
            }
            state_series(&up, &clock, &x_up).evaluate(s, &mut plus);
            state_series(&down, &clock, &x_down).evaluate(s, &mut minus);
            for row in 0..n {
                let difference = (plus[row] - minus[row]) / (2.0 * step);
                let derivative = v[row * (n + 1) + column];
                assert!(
                    (difference - derivative).abs() < 1e-6 * (1.0 + derivative.abs()),
                    "clock {clock:?} column {column} row {row}: {difference} vs {derivative}"
                );
            }
        }
    }
}

/// The tangents' series (the identity at the start, with `dx/dZ = 0` when `parameter`) along
/// the state's series from `x0`.
fn tangent_series(
    model: &TappingModel,
    clock: &ClockPolynomial,
    x0: &[f64],
    parameter: bool,
) -> TaylorSeries {
    let (state, mut shared) = state_series_shared(model, clock, x0);
    let n = model.dim();
    let columns = n + usize::from(parameter);
    let mut tangents = TaylorSeries::new(n * columns, ORDER);
    let mut start = vec![0.0; n * columns];
    for i in 0..n {
        start[i * columns + i] = 1.0;
    }
    tangents.start_at(&start);
    model.taylor_tangents(
        CONTACT,
        clock,
        &state,
        &mut shared,
        &mut tangents,
        parameter,
        &mut Vec::new(),
    );
    tangents
}

/// The blocked [`crate::model::contact_series::convolution`] is the plain sum
/// `sum_{j=0}^{m} a_j b_{m-j}` of `Iterator::sum` (written here) bit for bit, for every length
/// of the series (0 to 41 terms, the remainders of the blocks of four included) on values
/// spread over 40 orders of magnitude and both signs, where any other order of the additions
/// would round differently; and an empty sum is `-0.0`, as `Iterator::sum`'s.
#[test]
fn blocked_convolution_adds_in_the_plain_order() {
    use crate::model::contact_series::convolution;
    let plain = |a: &[f64], b: &[f64]| -> f64 {
        a.iter()
            .zip(b[..a.len()].iter().rev())
            .map(|(x, y)| x * y)
            .sum()
    };
    // A deterministic spread of magnitudes and signs (a linear congruential sequence).
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let unit = (seed >> 11) as f64 / (1u64 << 53) as f64;
        let exponent = ((seed >> 3) % 40) as i32 - 20;
        (unit - 0.5) * 10f64.powi(exponent)
    };
    let a: Vec<f64> = (0..42).map(|_| next()).collect();
    let b: Vec<f64> = (0..42).map(|_| next()).collect();
    let mut differs_from_reversed_order = 0;
    for m in 0..=41 {
        let (x, y) = (&a[..m], &b[..m]);
        let blocked = convolution(x, y);
        assert_eq!(blocked.to_bits(), plain(x, y).to_bits(), "{m} terms");
        let reversed: f64 = x.iter().zip(y.iter().rev()).map(|(p, q)| p * q).rev().sum();
        differs_from_reversed_order += usize::from(reversed.to_bits() != blocked.to_bits());
    }
    // The data do tell the orders of summation apart (else the test could not fail).
    assert!(
        differs_from_reversed_order > 10,
        "{differs_from_reversed_order}"
    );
    assert!(convolution(&[], &[]).is_sign_negative());
}
