//! The exact free-flight flow of one driven, damped oscillator against independent integrations,
//! for under-, critically and over-damped quality factors.

mod common;

use afm::DrivenOscillator;

/// Natural and drive angular frequencies (rad/us) and static deflection (nm) used throughout:
/// the Biolever's first mode driven at resonance with F_1/k_1 = 0.25 nm.
const OMEGA: f64 = 2.0 * std::f64::consts::PI * 9.3 / 1000.0;
const STATIC_NM: f64 = 0.25;

fn field(oscillator_q: f64, drive: f64) -> impl Fn(f64, &[f64], &mut [f64]) {
    move |t, x, dx| {
        dx[0] = x[1];
        dx[1] =
            OMEGA * OMEGA * (STATIC_NM * (drive * t).cos() - x[0]) - OMEGA / oscillator_q * x[1];
    }
}

/// exp(A t) by scaling and squaring: a 30-term Taylor series of exp(A t / 2^12) (norm < 0.01,
/// tail < 1e-60, no cancellation) squared 12 times (rounding grows ~ 12 eps relative).
fn taylor_exponential(quality: f64, t: f64) -> [[f64; 2]; 2] {
    let scale = t / 4096.0;
    let a = [
        [0.0, scale],
        [-OMEGA * OMEGA * scale, -OMEGA / quality * scale],
    ];
    let mul = |x: [[f64; 2]; 2], y: [[f64; 2]; 2]| {
        let mut z = [[0.0; 2]; 2];
        for r in 0..2 {
            for c in 0..2 {
                z[r][c] = x[r][0] * y[0][c] + x[r][1] * y[1][c];
            }
        }
        z
    };
    let mut term = [[1.0, 0.0], [0.0, 1.0]];
    let mut sum = term;
    for k in 1..30 {
        term = mul(term, a);
        for row in term.iter_mut() {
            for value in row.iter_mut() {
                *value /= k as f64;
            }
        }
        for r in 0..2 {
            for c in 0..2 {
                sum[r][c] += term[r][c];
            }
        }
    }
    for _ in 0..12 {
        sum = mul(sum, sum);
    }
    sum
}

#[test]
fn flow_matches_fine_rk4_for_all_damping_regimes() {
    // Q = 4.3 (MAClever mode 2), 1.2, 0.5 (critical), 0.5 +- 1e-9 (the series branch),
    // 0.3 and 0.05 (over-damped).
    for quality in [4.3, 1.2, 0.5, 0.5 + 1e-9, 0.5 - 1e-9, 0.3, 0.05] {
        for drive in [OMEGA, 0.7 * OMEGA] {
            let oscillator = DrivenOscillator::new(OMEGA, quality, STATIC_NM, drive);
            let x0 = [1.3, -0.02];
            let (t0, dt) = (3.7, 40.0); // dt ~ 0.37 periods of the drive
            let (exact, _) = oscillator.flow(t0, x0, dt);
            // RK4 with 20000 steps: error ~ (h w/Q)^4 per unit; with h = 2e-3 us and
            // w/Q <= 1.2 /us the global error is < 1e-12 nm.
            let reference = common::rk4(field(quality, drive), t0, &x0, dt, 20_000);
            for k in 0..2 {
                assert!(
                    (exact[k] - reference[k]).abs() < 1e-11,
                    "Q = {quality}: component {k}: {} vs {}",
                    exact[k],
                    reference[k]
                );
            }
        }
    }
}

#[test]
fn homogeneous_transition_matches_taylor_series_of_the_matrix_exponential() {
    for quality in [4.3, 0.5, 0.5 + 1e-7, 0.3, 0.05] {
        for t in [1e-6, 0.3, 10.0, 26.0, -7.0] {
            let oscillator = DrivenOscillator::new(OMEGA, quality, STATIC_NM, OMEGA);
            let phi = oscillator.homogeneous_transition(t);
            let reference = taylor_exponential(quality, t);
            let scale = reference
                .iter()
                .flatten()
                .fold(1.0f64, |m, v| m.max(v.abs()));
            for r in 0..2 {
                for c in 0..2 {
                    // Both sides accurate to ~1e-14 of the largest entry (see above).
                    assert!(
                        (phi[r][c] - reference[r][c]).abs() < 1e-12 * scale,
                        "Q = {quality}, t = {t}: [{r}][{c}] {} vs {}",
                        phi[r][c],
                        reference[r][c]
                    );
                }
            }
        }
    }
}

/// Strongly over-damped modes (`Q` = 1e-2 and 1e-3) over long steps, where `2 delta t` reaches
/// 3e4: against Sylvester's formula `exp(A t) = (e^{l1 t} (A - l2 I) - e^{l2 t} (A - l1 I)) /
/// (l1 - l2)` with the eigenvalues `l2 = mu - delta` (fast) and `l1 = w^2 / l2` (slow, without
/// cancellation), both exponentials in (0, 1] forward in time. The transition had factored
/// `S` on the fast exponential, `e^{l2 t} (e^{2 delta t} - 1)`, which is `0 * inf` once `2 delta
/// t > 709`: the state of a contact-free period went NaN.
#[test]
fn strongly_over_damped_transition_is_finite_over_long_steps() {
    for quality in [1e-2, 1e-3] {
        let mu = -OMEGA / (2.0 * quality);
        let delta = (mu * mu - OMEGA * OMEGA).sqrt();
        let fast = mu - delta;
        let slow = OMEGA * OMEGA / fast;
        let a = [[0.0, 1.0], [-OMEGA * OMEGA, -OMEGA / quality]];
        for t in [1.0, 40.0, 500.0] {
            let oscillator = DrivenOscillator::new(OMEGA, quality, STATIC_NM, OMEGA);
            let phi = oscillator.homogeneous_transition(t);
            let (e_slow, e_fast) = ((slow * t).exp(), (fast * t).exp());
            for r in 0..2 {
                for c in 0..2 {
                    let identity = if r == c { 1.0 } else { 0.0 };
                    let reference = (e_slow * (a[r][c] - fast * identity)
                        - e_fast * (a[r][c] - slow * identity))
                        / (slow - fast);
                    assert!(
                        phi[r][c].is_finite()
                            && (phi[r][c] - reference).abs() <= 1e-12 * reference.abs().max(1.0),
                        "Q = {quality}, t = {t}: [{r}][{c}] {} vs {reference}",
                        phi[r][c]
                    );
                }
            }
        }
    }
}

#[test]
fn transition_matrix_matches_finite_differences_and_flow_is_a_group() {
    for quality in [4.3, 0.5, 0.3] {
        let oscillator = DrivenOscillator::new(OMEGA, quality, STATIC_NM, OMEGA);
        let x0 = [0.4, 0.01];
        let (t0, dt) = (1.0, 25.0);
        let (_, phi) = oscillator.flow(t0, x0, dt);
        for c in 0..2 {
            let h = 1e-4;
            let mut plus = x0;
            let mut minus = x0;
            plus[c] += h;
            minus[c] -= h;
            let (xp, _) = oscillator.flow(t0, plus, dt);
            let (xm, _) = oscillator.flow(t0, minus, dt);
            for r in 0..2 {
                // The flow is affine in x0: the central difference is exact up to rounding
                // (~eps |x| / h ~ 1e-12).
                let numeric = (xp[r] - xm[r]) / (2.0 * h);
                assert!((numeric - phi[r][c]).abs() < 1e-9, "{quality} {r}{c}");
            }
        }
        // Flowing dt1 then dt2 equals flowing dt1 + dt2; flowing back returns to x0.
        let (mid, _) = oscillator.flow(t0, x0, 11.0);
        let (end_two, _) = oscillator.flow(t0 + 11.0, mid, 14.0);
        let (end_one, _) = oscillator.flow(t0, x0, 25.0);
        let (back, _) = oscillator.flow(t0 + 25.0, end_one, -25.0);
        for k in 0..2 {
            assert!((end_two[k] - end_one[k]).abs() < 1e-13);
            assert!((back[k] - x0[k]).abs() < 1e-12);
        }
    }
}

#[test]
fn steady_state_solves_the_oscillator_equation() {
    for quality in [4.3, 0.5, 0.3] {
        for drive in [OMEGA, 0.7 * OMEGA, 3.0 * OMEGA] {
            let oscillator = DrivenOscillator::new(OMEGA, quality, STATIC_NM, drive);
            let f = field(quality, drive);
            for t in [0.0, 13.0, 77.7] {
                let x = oscillator.steady_state(t);
                let mut dx = [0.0; 2];
                f(t, &x, &mut dx);
                // d/dt of the steady state by central difference (h = 1e-3 us, truncation
                // ~ w^3 h^2 |x| / 6 ~ 1e-10).
                let h = 1e-3;
                let xp = oscillator.steady_state(t + h);
                let xm = oscillator.steady_state(t - h);
                for k in 0..2 {
                    let numeric = (xp[k] - xm[k]) / (2.0 * h);
                    assert!((numeric - dx[k]).abs() < 1e-9, "{quality} {drive} {t} {k}");
                }
            }
        }
    }
}
