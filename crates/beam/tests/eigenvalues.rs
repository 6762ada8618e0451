//! Roots of the characteristic equation against independent facts: published free-cantilever
//! eigenvalues, asymptotic forms, the heavy-tip-mass limit, and a brute-force sign scan.

use std::f64::consts::PI;

use beam::{characteristic_function, eigenvalue_bracket, Beam, MAX_MODES};

/// Free cantilever eigenvalues (mu = 0), as tabulated to 15 digits in e.g. Blevins,
/// "Formulas for natural frequency and mode shape", Table 8-1.
const FREE_CANTILEVER: [f64; 5] = [
    1.875_104_068_711_96,
    4.694_091_132_974_17,
    7.854_757_438_237_61,
    10.995_540_734_875_5,
    14.137_168_391_046_5,
];

#[test]
fn free_cantilever_roots_match_tabulated_values() {
    let beam = Beam::new(0.0).expect("valid");
    for (n, expected) in FREE_CANTILEVER.iter().enumerate() {
        let b = beam.eigenvalue(n + 1).expect("root");
        // Tabulated to 15 significant digits: agree to 1e-13 relative.
        assert!(
            (b - expected).abs() <= 1e-13 * expected,
            "b_{} = {b}",
            n + 1
        );
    }
}

#[test]
fn free_cantilever_roots_approach_odd_multiples_of_half_pi() {
    // For mu = 0, g = sech b + cos b = 0, so cos b_n = -sech b_n and
    // |b_n - (2n-1) pi / 2| ~ sech b_n < 2 e^{-b_n}: the bound 2.1 e^{-(2n-1) pi/2} (5% slack for
    // the first-order expansion) holds for every n, and shrinks to rounding by n ~ 12.
    let beam = Beam::new(0.0).expect("valid");
    for n in 1..=MAX_MODES {
        let b = beam.eigenvalue(n).expect("root");
        let asymptote = (2 * n - 1) as f64 * PI / 2.0;
        let bound = 2.1 * (-asymptote).exp() + 4.0 * f64::EPSILON * asymptote;
        assert!(
            (b - asymptote).abs() <= bound,
            "n = {n}: b = {b}, asymptote {asymptote}"
        );
    }
}

#[test]
fn roots_with_tip_mass_approach_the_pinned_tip_asymptote() {
    // For large b, g = cos b + mu b (cos b - sin b) + O(e^{-b}), so
    // b_n = (n-1) pi + atan(1 + 1 / (mu b_n)) up to O(e^{-b_n}) (below rounding for n >= 15).
    for mu in [0.16, 1.0, 100.0] {
        let beam = Beam::new(mu).expect("valid");
        for n in 15..=MAX_MODES {
            let b = beam.eigenvalue(n).expect("root");
            let asymptotic = (n - 1) as f64 * PI + (1.0 + 1.0 / (mu * b)).atan();
            assert!(
                (b - asymptotic).abs() <= 1e-12 * b,
                "mu = {mu}, n = {n}: {b} vs {asymptotic}"
            );
        }
    }
}

#[test]
fn heavy_tip_mass_gives_a_spring_mass_first_mode() {
    // Massless beam + point mass: k = 3 EI / L^3, w^2 = k / m_tip, i.e. b_1^4 = 3 / mu.
    // Rayleigh's quotient with the static tip-load shape adds 33/140 of the beam's mass and is an
    // upper bound: b_1^4 <= 3 / (mu + 33/140), with an error second order in the shape error,
    // O(1/mu^2). Checked over three decades (0.01 / mu^2 is a generous constant; the scaling is
    // what is tested).
    for mu in [10.0, 100.0, 1000.0] {
        let b1 = Beam::new(mu).expect("valid").eigenvalue(1).expect("root");
        let spring_mass = b1.powi(4) * mu / 3.0;
        assert!(
            (spring_mass - 1.0).abs() <= 1.0 / mu,
            "mu = {mu}: b1^4 mu / 3 = {spring_mass}"
        );
        let rayleigh = b1.powi(4) * (mu + 33.0 / 140.0) / 3.0 - 1.0;
        assert!(
            rayleigh <= 1e-14,
            "Rayleigh bound violated at mu = {mu}: {rayleigh}"
        );
        assert!(
            rayleigh >= -0.01 / (mu * mu),
            "mu = {mu}: Rayleigh error {rayleigh}"
        );
    }
}

#[test]
fn heavy_tip_mass_pins_the_tip_for_higher_modes() {
    // As mu -> infinity the tip stops moving in modes n >= 2, which tend to the clamped-pinned
    // beam: tan b = tanh b, first root 3.926602312047919 (Blevins Table 8-1). The approach is
    // from above (more mass lowers frequencies) and O(1/mu) (0.2 / mu is a generous constant).
    let clamped_pinned = 3.926_602_312_047_919;
    for mu in [10.0, 100.0, 1000.0] {
        let b2 = Beam::new(mu).expect("valid").eigenvalue(2).expect("root");
        let excess = b2 - clamped_pinned;
        assert!(excess > 0.0 && excess <= 0.2 / mu, "mu = {mu}: b2 = {b2}");
    }
}

#[test]
fn one_root_per_bracket_by_brute_force_scan() {
    // Scan g on a grid 100 times finer than the root spacing and count sign changes: exactly one
    // in each (n-1) pi .. n pi, and it matches the Brent root to the grid spacing.
    for mu in [0.0, 0.05, 0.16, 1.0, 30.0, 1000.0] {
        let beam = Beam::new(mu).expect("valid");
        for n in 1..=20 {
            let (lower, upper) = eigenvalue_bracket(n);
            let steps = 1000;
            let h = (upper - lower) / steps as f64;
            let mut changes = Vec::new();
            let mut previous = characteristic_function(lower, mu);
            for i in 1..=steps {
                let b = lower + i as f64 * h;
                let value = characteristic_function(b, mu);
                if previous.signum() != value.signum() {
                    changes.push(b);
                }
                previous = value;
            }
            assert_eq!(changes.len(), 1, "mu = {mu}, bracket {n}: {changes:?}");
            let root = beam.eigenvalue(n).expect("root");
            // The sign flips at the first grid point past the root (a root that falls on a grid
            // point, as b_12 = 23 pi / 2 to rounding at mu = 0 does, flips one point later).
            let distance = changes[0] - root;
            assert!(
                distance >= 0.0 && distance <= h * (1.0 + 1e-9),
                "mu = {mu}, n = {n}"
            );
        }
    }
}

#[test]
fn roots_satisfy_the_unscaled_characteristic_equation() {
    // Direct check against f(b) = 1 + cos b cosh b + mu b (cos b sinh b - sin b cosh b), written
    // out independently of the scaled form, where cosh b is still small (n <= 6, cosh b < 1e8):
    // f(b_n) must vanish to the rounding level of its largest term, eps (1 + mu b) cosh b.
    for mu in [0.0, 0.1, 0.16, 5.0] {
        let beam = Beam::new(mu).expect("valid");
        for n in 1..=6 {
            let b: f64 = beam.eigenvalue(n).expect("root");
            let f = 1.0 + b.cos() * b.cosh() + mu * b * (b.cos() * b.sinh() - b.sin() * b.cosh());
            let scale = (1.0 + mu * b) * b.cosh();
            assert!(
                f.abs() <= 64.0 * f64::EPSILON * scale,
                "mu = {mu}, n = {n}: f = {f:e}"
            );
        }
    }
}

#[test]
fn eigenvalues_decrease_with_tip_mass() {
    // Adding mass at a point where every mode moves lowers every frequency (Rayleigh).
    let ratios = [0.0, 0.01, 0.1, 0.16, 1.0, 10.0, 100.0, 1000.0];
    for n in 1..=10 {
        let roots: Vec<f64> = ratios
            .iter()
            .map(|&mu| Beam::new(mu).expect("valid").eigenvalue(n).expect("root"))
            .collect();
        assert!(roots.windows(2).all(|w| w[1] < w[0]), "mode {n}: {roots:?}");
    }
}
