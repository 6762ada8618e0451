//! Sader's hydrodynamic function and the modes of a rectangular cantilever in a fluid, checked
//! against independent forms: the Bessel functions' ascending series and asymptotic expansion
//! (Abramowitz & Stegun 9.6.11, 9.6.13, 9.7.2), Sader, Chon & Mulvaney's published calibration
//! formula (Rev. Sci. Instrum. 70, 3967 (1999), Eq. 1), the textbook vacuum frequency
//! `f_1 = (1.8751^2 / 2 pi) sqrt(E I / (rho_c b h L^4))`, and the inviscid added mass of a flat
//! plate.

use beam::bessel::bessel_k0_k1;
use beam::{
    circular_hydrodynamic_function, modal_table, rectangular_hydrodynamic_function,
    reynolds_number, BeamError, Fluid, RectangularCantilever,
};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Euler's constant.
const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

/// `[K_0, K_1]` by the ascending series (A&S 9.6.13 and 9.6.11), summed to convergence.
fn series_k0_k1(z: Complex64) -> [Complex64; 2] {
    let quarter = z * z / 4.0;
    let log = (z / 2.0).ln();
    // K_0 = -(ln(z/2) + gamma) I_0 + sum_{k>=1} H_k (z^2/4)^k / (k!)^2
    // K_1 = 1/z + ln(z/2) I_1 - (z/4) sum_{k>=0} (psi(k+1) + psi(k+2)) (z^2/4)^k / (k! (k+1)!)
    let mut i0 = Complex64::new(0.0, 0.0);
    let mut i1 = Complex64::new(0.0, 0.0);
    let mut k0_sum = Complex64::new(0.0, 0.0);
    let mut k1_sum = Complex64::new(0.0, 0.0);
    let mut power = Complex64::new(1.0, 0.0); // (z^2/4)^k / (k!)^2
    let mut harmonic = 0.0; // H_k
    for k in 0..60 {
        let kf = k as f64;
        if k > 0 {
            power *= quarter / (kf * kf);
            harmonic += 1.0 / kf;
        }
        let next_harmonic = harmonic + 1.0 / (kf + 1.0);
        let psi_sum = (-EULER_GAMMA + harmonic) + (-EULER_GAMMA + next_harmonic);
        i0 += power;
        i1 += power / (kf + 1.0);
        k0_sum += power * harmonic;
        k1_sum += power / (kf + 1.0) * psi_sum;
    }
    let i1 = i1 * z / 2.0;
    [
        -(log + EULER_GAMMA) * i0 + k0_sum,
        z.inv() + log * i1 - z / 4.0 * k1_sum,
    ]
}

/// `[K_0, K_1]` by the asymptotic expansion (A&S 9.7.2) with 12 terms, accurate to far below
/// 1e-14 relative for `|z| >= 40`.
fn asymptotic_k0_k1(z: Complex64) -> [Complex64; 2] {
    let prefactor = (PI / (2.0 * z)).sqrt() * (-z).exp();
    let sum = |nu: f64| {
        let mu = 4.0 * nu * nu;
        let mut term = Complex64::new(1.0, 0.0);
        let mut total = term;
        for k in 1..12 {
            let odd = (2 * k - 1) as f64;
            term *= (mu - odd * odd) / (k as f64 * 8.0 * z);
            total += term;
        }
        total
    };
    [prefactor * sum(0.0), prefactor * sum(1.0)]
}

fn relative_error(a: Complex64, b: Complex64) -> f64 {
    (a - b).norm() / b.norm()
}

/// Sader's arguments `-i sqrt(i Re)` lie on `arg z = -pi/4`; the quadrature matches the series
/// for small `|z|` and the asymptotic expansion for large `|z|` to 1e-12 relative.
#[test]
fn bessel_functions_match_series_and_asymptotics() {
    for r in [1e-3, 0.05, 0.5, 1.0, 2.0] {
        let z = Complex64::from_polar(r, -PI / 4.0);
        let [k0, k1] = bessel_k0_k1(z);
        let [s0, s1] = series_k0_k1(z);
        assert!(relative_error(k0, s0) < 1e-12, "K0({z}) {k0} vs {s0}");
        assert!(relative_error(k1, s1) < 1e-12, "K1({z}) {k1} vs {s1}");
    }
    for r in [40.0, 70.0, 100.0] {
        let z = Complex64::from_polar(r, -PI / 4.0);
        let [k0, k1] = bessel_k0_k1(z);
        let [a0, a1] = asymptotic_k0_k1(z);
        assert!(relative_error(k0, a0) < 1e-12, "K0({z}) {k0} vs {a0}");
        assert!(relative_error(k1, a1) < 1e-12, "K1({z}) {k1} vs {a1}");
    }
    // A real argument: K_0(1) = 0.42102443824070834, K_1(1) = 0.60190723019723457 (A&S
    // Table 9.8, e^x K_n(x) at x = 1: 1.1444630798, 1.6361534863).
    let [k0, k1] = bessel_k0_k1(Complex64::new(1.0, 0.0));
    assert!((k0.re - 1.144_463_079_8 / 1f64.exp()).abs() < 1e-10);
    assert!((k1.re - 1.636_153_486_3 / 1f64.exp()).abs() < 1e-10);
    // Outside the domain: NaN, never a wrong number.
    assert!(bessel_k0_k1(Complex64::new(-1.0, 0.0))[0].re.is_nan());
}

/// The hydrodynamic function's shape: added mass and damping positive; at large `Re` the
/// circular cylinder's added mass tends to the potential-flow value 1 and the damping to the
/// Stokes boundary layer's `2 sqrt(2) / sqrt(Re)` (from K_1/K_0 -> 1 in Sader 1998 Eq. 18);
/// the thin blade's `Omega_r -> 1` there too (a flat plate's inviscid added mass is
/// `(pi/4) rho b^2`, that of the circumscribed cylinder).
#[test]
fn hydrodynamic_function_limits() {
    for reynolds in [1e-6, 1e-3, 0.1, 1.0, 10.0, 1e3, 1e4] {
        let gamma = rectangular_hydrodynamic_function(reynolds, 1).unwrap();
        assert!(gamma.re > 0.0 && gamma.im > 0.0, "Re {reynolds}: {gamma}");
    }
    let reynolds = 1e4;
    let circular = circular_hydrodynamic_function(reynolds);
    let boundary_layer = 2.0 * 2f64.sqrt() / reynolds.sqrt();
    // Next order of K_1/K_0 = 1 + 1/(2z): relative O(1/sqrt(Re)) = 1e-2.
    assert!((circular.re - 1.0 - boundary_layer).abs() < 2e-2 * boundary_layer);
    assert!((circular.im - boundary_layer).abs() < 2e-2 * boundary_layer);
    let rectangular = rectangular_hydrodynamic_function(reynolds, 1).unwrap();
    assert!((rectangular.re - 1.0).abs() < 0.05, "{rectangular}");
    // Outside Sader's fit: refused, naming the mode.
    let error = rectangular_hydrodynamic_function(2e4, 3).unwrap_err();
    assert!(matches!(
        error,
        BeamError::ReynoldsOutOfRange { mode: 3, .. }
    ));
    assert!(error.to_string().contains("mode 3"));
}

/// A silicon cantilever like those of Sader, Chon & Mulvaney 1999 (L = 397 um, b = 29 um,
/// h = 2 um; E = 169 GPa, rho_c = 2330 kg/m^3).
fn silicon() -> RectangularCantilever {
    RectangularCantilever {
        length_um: 397.0,
        width_um: 29.0,
        thickness_um: 2.0,
        youngs_modulus_gpa: 169.0,
        density_kg_m3: 2330.0,
        tip_mass_ratio: 0.0,
    }
}

/// Sader, Chon & Mulvaney (1999) Eq. 1: `k = 0.1906 rho b^2 L Q Gamma_i(w_R) w_R^2`, the
/// static spring constant `3 E I / L^3` from the frequency and quality factor in air. Our
/// mode 1 in air (computed from the geometry, not from this formula) must satisfy it to the
/// formula's four printed digits (5e-4).
#[test]
fn air_mode_satisfies_sader_calibration_formula() {
    let cantilever = silicon();
    let air = Fluid::air();
    let mode = cantilever.modes_in_fluid(&air, 1).unwrap()[0];
    let w = 2.0 * PI * mode.frequency_khz * 1e3;
    let width = cantilever.width_um * 1e-6;
    let length = cantilever.length_um * 1e-6;
    let gamma = rectangular_hydrodynamic_function(
        reynolds_number(air.density_kg_m3, air.viscosity_pa_s, w, width),
        1,
    )
    .unwrap();
    let sader = 0.1906
        * air.density_kg_m3
        * width
        * width
        * length
        * mode.quality_factor
        * gamma.im
        * w
        * w;
    let static_stiffness = cantilever.static_stiffness_n_per_m();
    assert!(
        (sader / static_stiffness - 1.0).abs() < 5e-4,
        "Sader's k {sader} vs 3EI/L^3 {static_stiffness}"
    );
    // In air the quality factor is high and the frequency barely shifted.
    assert!(mode.quality_factor > 20.0, "{mode:?}");
    assert!(mode.frequency_khz < mode.vacuum_frequency_khz);
    assert!(mode.frequency_khz > 0.99 * mode.vacuum_frequency_khz);
}

/// The vacuum frequency is the textbook `(1.875104^2 / 2 pi) sqrt(E I / (rho_c b h L^4))`
/// (1e-6, the digits of 1.875104), and in a thin, nearly inviscid gas (rho = 0.01 kg/m^3,
/// eta = 1e-6 Pa s) the fluid frequency is within 1e-3 of it and Q above 1000.
#[test]
fn vacuum_limit() {
    let cantilever = silicon();
    let length: f64 = 397e-6;
    let (width, thickness): (f64, f64) = (29e-6, 2e-6);
    let inertia = width * thickness.powi(3) / 12.0;
    let textbook = 1.875_104_f64.powi(2) / (2.0 * PI)
        * (169e9 * inertia / (2330.0 * width * thickness * length.powi(4))).sqrt()
        / 1e3;
    let thin_gas = Fluid {
        name: String::from("thin gas"),
        density_kg_m3: 0.01,
        viscosity_pa_s: 1e-6,
    };
    let modes = cantilever.modes_in_fluid(&thin_gas, 3).unwrap();
    assert!((modes[0].vacuum_frequency_khz / textbook - 1.0).abs() < 1e-6);
    for mode in &modes {
        assert!((mode.frequency_khz / mode.vacuum_frequency_khz - 1.0).abs() < 1e-3);
        assert!(mode.quality_factor > 1e3);
    }
    // Stiffness of mode 1 without tip mass: b_1^4 / 4 E I / L^3 = 1.0302 times 3 E I / L^3.
    let ratio = modes[0].stiffness_n_per_m / cantilever.static_stiffness_n_per_m();
    assert!(
        (ratio - 1.875_104_f64.powi(4) / 12.0).abs() < 1e-5,
        "{ratio}"
    );
}

/// Without tip mass, mode `n` in the fluid obeys Sader 1998 Eqs. 22-23 with `Gamma` at its own
/// frequency: `w_n = w_vac,n (1 + T Gamma_r)^{-1/2}`, `Q_n = (1/T + Gamma_r) / Gamma_i`,
/// `T = pi rho b / (4 rho_c h)` (to rounding), with higher modes at higher `Re_n` and so
/// higher `Q_n`; the stiffnesses and sensitivities are the vacuum table's (the shape does not
/// change without tip mass).
#[test]
fn water_modes_follow_sader_equations() {
    let cantilever = silicon();
    let water = Fluid::water();
    let modes = cantilever.modes_in_fluid(&water, 4).unwrap();
    let table = modal_table(0.0, 4).unwrap();
    let loading = PI * water.density_kg_m3 * 29.0 / (4.0 * 2330.0 * 2.0);
    for (mode, row) in modes.iter().zip(&table) {
        let w = 2.0 * PI * mode.frequency_khz * 1e3;
        let gamma = rectangular_hydrodynamic_function(
            reynolds_number(water.density_kg_m3, water.viscosity_pa_s, w, 29e-6),
            mode.index,
        )
        .unwrap();
        let predicted = mode.vacuum_frequency_khz / (1.0 + loading * gamma.re).sqrt();
        assert!((mode.frequency_khz / predicted - 1.0).abs() < 1e-12);
        let quality = (1.0 / loading + gamma.re) / gamma.im;
        assert!((mode.quality_factor / quality - 1.0).abs() < 1e-12);
        assert!((mode.optical_sensitivity - row.chi).abs() < 1e-12);
        assert!((mode.force_ratio_distributed - row.force_ratio_distributed).abs() < 1e-12);
        let stiffness = modes[0].stiffness_n_per_m * row.stiffness_ratio;
        assert!((mode.stiffness_n_per_m / stiffness - 1.0).abs() < 1e-12);
    }
    for pair in modes.windows(2) {
        assert!(pair[1].reynolds_number > pair[0].reynolds_number);
        assert!(pair[1].quality_factor > pair[0].quality_factor);
    }
    // Mode 1's base participation factor without tip mass: int phi / int phi^2 = 1.566.
    assert!((modes[0].base_participation - 1.566).abs() < 1e-3);
    // Water lowers the frequency far more than air.
    assert!(modes[0].frequency_khz < 0.6 * modes[0].vacuum_frequency_khz);
}

/// A wide beam in water whose modes' Reynolds numbers lie inside Sader's fit, though the
/// vacuum frequencies' do not (2000 x 1000 x 10 um silicon: `Re` at the vacuum frequency of
/// mode 2 is `(1 + T Gamma_r)^{1/2}` times its fluid value and above 1e4): the modes are built,
/// each converged `Re_n` is in the fit's range, and each frequency obeys Sader 1998 Eq. 22 with
/// `Gamma` at its own `Re_n` (to 1e-12); a thicker beam whose mode 2 converges above 1e4 is
/// refused naming mode 2 and that converged value.
#[test]
fn modes_are_built_where_only_the_vacuum_frequency_leaves_the_fit() {
    let water = Fluid::water();
    let wide = |thickness_um: f64| RectangularCantilever {
        length_um: 2000.0,
        width_um: 1000.0,
        thickness_um,
        ..silicon()
    };
    let cantilever = wide(10.0);
    let modes = cantilever.modes_in_fluid(&water, 2).unwrap();
    let loading = PI * water.density_kg_m3 * 1000.0 / (4.0 * 2330.0 * 10.0);
    let vacuum_reynolds = |mode: &beam::FluidMode| {
        reynolds_number(
            water.density_kg_m3,
            water.viscosity_pa_s,
            2.0 * PI * mode.vacuum_frequency_khz * 1e3,
            1e-3,
        )
    };
    assert!(
        vacuum_reynolds(&modes[1]) > 1e4,
        "{}",
        vacuum_reynolds(&modes[1])
    );
    for mode in &modes {
        assert!(
            (1e-6..=1e4).contains(&mode.reynolds_number),
            "mode {}: Re {}",
            mode.index,
            mode.reynolds_number
        );
        let w = 2.0 * PI * mode.frequency_khz * 1e3;
        let reynolds = reynolds_number(water.density_kg_m3, water.viscosity_pa_s, w, 1e-3);
        let gamma = rectangular_hydrodynamic_function(reynolds, mode.index).unwrap();
        let predicted = mode.vacuum_frequency_khz / (1.0 + loading * gamma.re).sqrt();
        assert!((mode.frequency_khz / predicted - 1.0).abs() < 1e-12);
    }
    let error = wide(30.0).modes_in_fluid(&water, 2).unwrap_err();
    match &error {
        BeamError::ReynoldsOutOfRange { mode, value, .. } => {
            assert_eq!(*mode, 2);
            assert!(*value > 1e4, "{value}");
            // The value reported is the converged mode's, below the vacuum frequency's `Re`
            // (the textbook `f_2 = (4.6941^2 / 2 pi) sqrt(E I / (rho_c b h L^4))`).
            let (e, rho_c, b, h, l): (f64, f64, f64, f64, f64) = (169e9, 2330.0, 1e-3, 30e-6, 2e-3);
            let inertia = b * h.powi(3) / 12.0;
            let w_vacuum =
                4.694_091_f64.powi(2) * (e * inertia / (rho_c * b * h * l.powi(4))).sqrt();
            let vacuum = reynolds_number(water.density_kg_m3, water.viscosity_pa_s, w_vacuum, b);
            assert!(*value < vacuum, "{value} vs {vacuum}");
        }
        other => panic!("{other}"),
    }
}

/// A tip mass: the loaded beam's mass ratio `mu_eff = mu / (1 + T Gamma_r)` is smaller than
/// `mu`, and in a thin gas the fluid modes tend to the vacuum table at `mu`.
#[test]
fn tip_mass_in_fluid() {
    let cantilever = RectangularCantilever {
        tip_mass_ratio: 0.16,
        ..silicon()
    };
    let modes = cantilever.modes_in_fluid(&Fluid::water(), 2).unwrap();
    for mode in &modes {
        assert!(mode.effective_tip_mass_ratio < 0.16 && mode.effective_tip_mass_ratio > 0.0);
    }
    let thin_gas = Fluid {
        name: String::from("thin gas"),
        density_kg_m3: 0.01,
        viscosity_pa_s: 1e-6,
    };
    let modes = cantilever.modes_in_fluid(&thin_gas, 2).unwrap();
    let table = modal_table(0.16, 2).unwrap();
    let ratio = modes[1].frequency_khz / modes[0].frequency_khz;
    assert!((ratio / table[1].frequency_ratio - 1.0).abs() < 2e-4);
    assert!((modes[1].optical_sensitivity - table[1].chi).abs() < 1e-3);
}

/// Bad geometry is refused with the field and the range.
#[test]
fn refuses_bad_geometry() {
    let short = RectangularCantilever {
        length_um: 40.0,
        ..silicon()
    };
    let error = short.modes_in_fluid(&Fluid::water(), 2).unwrap_err();
    assert!(error.to_string().contains("slender"), "{error}");
    let negative = RectangularCantilever {
        thickness_um: -1.0,
        ..silicon()
    };
    let error = negative.modes_in_fluid(&Fluid::water(), 2).unwrap_err();
    assert!(error.to_string().contains("thickness_um"), "{error}");
    let nan_fluid = Fluid {
        name: String::from("bad"),
        density_kg_m3: f64::NAN,
        viscosity_pa_s: 1e-3,
    };
    let error = silicon().modes_in_fluid(&nan_fluid, 2).unwrap_err();
    assert!(error.to_string().contains("density_kg_m3"), "{error}");
}
