//! The mode shapes of the cantilever with a point tip mass, normalised to unit tip deflection,
//! their derivatives, and their modal integrals in closed form.
//!
//! # Shape
//!
//! With `b` a root of the characteristic equation ([`crate::characteristic`]) and
//! `sigma = (cosh b + cos b) / (sinh b + sin b)` (which makes `phi''(1) = 0`),
//!
//! ```text
//! U(xi)   = cosh b xi - cos b xi - sigma (sinh b xi - sin b xi),      phi(xi) = U(xi) / U(1),
//! ```
//!
//! so `phi(0) = phi'(0) = 0`, `phi''(1) = 0`, `phi'''(1) = -mu b^4` and `phi(1) = 1`: `q_n`, the
//! coordinate of Eq. 1 of the paper, is the tip deflection in mode `n`.
//!
//! # Numerically stable evaluation
//!
//! Written as above, `cosh b xi - sigma sinh b xi` subtracts two numbers of size `e^{b xi} / 2`
//! to leave a result of order one, so the absolute error is about `eps e^{b}`: the shape is
//! garbage once `b > ~ 36` (mode 12 and up) and `cosh` overflows past `b ~ 710`. Using
//! `sinh b cosh b xi - cosh b sinh b xi = sinh(b (1 - xi))`, the hyperbolic part is rewritten as
//!
//! ```text
//! cosh b xi - sigma sinh b xi = [sinh(b(1-xi)) + sin b cosh(b xi) - cos b sinh(b xi)] / (sinh b + sin b)
//! sinh b xi - sigma cosh b xi = [-cosh(b(1-xi)) + sin b sinh(b xi) - cos b cosh(b xi)] / (sinh b + sin b)
//! ```
//!
//! and numerator and denominator are multiplied by `2 e^{-b}`, leaving only the decaying
//! exponentials `e^{-b xi}`, `e^{-b (1 - xi)}`, `e^{-b (1 + xi)}`, `e^{-b (2 - xi)}`. Every term
//! is then of order one for every `b`, with no overflow and no cancellation at large `b`; what
//! limits the number of modes is no longer the arithmetic but the physics (Euler-Bernoulli theory
//! and the neglected tip rotary inertia fail once the wavelength `~ 2 pi L / b` approaches the
//! cantilever's thickness or the tip's size). At small `b` (a heavy tip mass) the shape is of
//! order `b^2` and is obtained by cancellation of order-one terms: relative error
//! `~ eps / b^2`, below `1e-14` for every accepted tip mass ratio (`b_1 > 0.23`).
//!
//! # Accuracy
//!
//! One numerical limit remains. With a tip mass, the tip of a high mode barely moves (the mode
//! tends to that of a beam pinned at the tip), so normalising to unit tip deflection divides by a
//! small `U(1)` that depends sensitively on `b`: the half-ulp rounding of `b` becomes a relative
//! error of about `eps |phi'(1)|` in the shape and its integrals, with `|phi'(1)| ~ b + mu b^2`.
//! That is `~1e-13` for the paper's cantilevers (`mu <= 0.2`, 20 modes), `~1e-9` for mode 50 at
//! `mu = 1000` (measured against quadrature in the tests). The closed-form integrals below
//! assume the tip boundary condition holds exactly and share that error.
//!
//! # Closed-form integrals (with `phi(1) = 1`)
//!
//! Since `d/dxi [xi (b^4 phi^2 - 2 phi' phi''' + phi''^2) + 3 phi phi''' - phi' phi''] = 4 b^4 phi^2`,
//! the boundary conditions give
//!
//! ```text
//! int_0^1 phi^2 dxi = (1 - 3 mu + 2 mu phi'(1)) / 4
//! modal mass  M / m_c = int_0^1 phi^2 dxi + mu = (1 + mu + 2 mu phi'(1)) / 4
//! stiffness   k L^3 / EI = b^4 M / m_c = int_0^1 phi''^2 dxi        (Rayleigh quotient)
//! ```
//!
//! and integrating `phi'''' = b^4 phi` once, `int_0^1 phi dxi = -mu - phi'''(0) / b^4
//! = -mu + 2 sigma / (b U(1))`. The test suite checks each against Gauss-Legendre quadrature.

/// One mode of the cantilever with a point tip mass, normalised to unit tip deflection
/// (`phi(1) = 1`), with its derivatives and modal integrals (module documentation).
///
/// Positions are `xi = x / L` in `[0, 1]`; derivatives are with respect to `xi` (multiply the
/// `k`-th by `L^{-k}` for derivatives in `x`). Outside `[0, 1]` the methods return the
/// analytic continuation of the shape, which has no physical meaning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeShape {
    /// 1-based mode number `n`.
    index: usize,
    /// Eigenvalue `b_n` (dimensionless root of the characteristic equation).
    eigenvalue: f64,
    /// Tip mass ratio `mu = m_tip / m_c`.
    tip_mass_ratio: f64,
    /// `sigma = (cosh b + cos b) / (sinh b + sin b)`.
    sigma: f64,
    /// `sin b`, `cos b`.
    sin_b: f64,
    cos_b: f64,
    /// `e^{-b}`.
    decay: f64,
    /// `1 / (2 e^{-b} (sinh b + sin b)) = 1 / (1 - e^{-2b} + 2 sin b e^{-b})`.
    inverse_denominator: f64,
    /// `1 / U(1)`: the unit-tip normalisation.
    tip_normalisation: f64,
}

impl ModeShape {
    /// The mode with 1-based number `index`, eigenvalue `b` (a root of
    /// [`crate::characteristic_function`] for `tip_mass_ratio`) and tip mass ratio `mu`.
    ///
    /// Normally obtained from [`crate::Beam::mode`], which solves for `b` and validates `mu`.
    /// For `b` not a root, the shape still has `phi(0) = phi'(0) = phi''(1) = 0` and `phi(1) = 1`
    /// but violates the tip-mass shear condition, and the closed-form integrals do not hold.
    #[must_use]
    pub fn new(index: usize, eigenvalue: f64, tip_mass_ratio: f64) -> Self {
        let b = eigenvalue;
        let decay = (-b).exp();
        let (sin_b, cos_b) = b.sin_cos();
        let inverse_denominator = 1.0 / (1.0 - decay * decay + 2.0 * sin_b * decay);
        let sigma = (1.0 + decay * decay + 2.0 * cos_b * decay) * inverse_denominator;
        let mut shape = Self {
            index,
            eigenvalue,
            tip_mass_ratio,
            sigma,
            sin_b,
            cos_b,
            decay,
            inverse_denominator,
            tip_normalisation: 1.0,
        };
        shape.tip_normalisation = 1.0 / shape.unnormalised(1.0)[0];
        shape
    }

    /// `[U, U'/b, U''/b^2, U'''/b^3]` at `xi` for the unnormalised shape
    /// `U = cosh b xi - cos b xi - sigma (sinh b xi - sin b xi)`, in the overflow-free form.
    fn unnormalised(&self, xi: f64) -> [f64; 4] {
        let b = self.eigenvalue;
        let e1 = (-b * xi).exp(); // e^{-b xi}
        let e3 = (-b * (1.0 - xi)).exp(); // e^{-b (1 - xi)}
        let e2 = self.decay * e3; // e^{-b (2 - xi)}
        let e4 = self.decay * e1; // e^{-b (1 + xi)}
        let (s, c) = (self.sin_b, self.cos_b);
        // cosh b xi - sigma sinh b xi and sinh b xi - sigma cosh b xi.
        let hyperbolic_even = (e1 - e2 + s * (e3 + e4) - c * (e3 - e4)) * self.inverse_denominator;
        let hyperbolic_odd =
            (-(e1 + e2) + s * (e3 - e4) - c * (e3 + e4)) * self.inverse_denominator;
        let (sx, cx) = (b * xi).sin_cos();
        let sigma = self.sigma;
        [
            hyperbolic_even - cx + sigma * sx,
            hyperbolic_odd + sx + sigma * cx,
            hyperbolic_even + cx - sigma * sx,
            hyperbolic_odd - sx - sigma * cx,
        ]
    }

    /// `[phi, phi', phi'', phi''']` at `xi = x / L` (derivatives with respect to `xi`), for the
    /// unit-tip-normalised shape. One evaluation costs two exponentials and one sine/cosine pair.
    #[must_use]
    pub fn derivatives(&self, xi: f64) -> [f64; 4] {
        let u = self.unnormalised(xi);
        let b = self.eigenvalue;
        let scale = self.tip_normalisation;
        [
            u[0] * scale,
            u[1] * scale * b,
            u[2] * scale * b * b,
            u[3] * scale * b * b * b,
        ]
    }

    /// Deflection `phi(xi)` per unit tip deflection (dimensionless), `xi = x / L`.
    #[must_use]
    pub fn deflection(&self, xi: f64) -> f64 {
        self.unnormalised(xi)[0] * self.tip_normalisation
    }

    /// Slope `dphi/dxi` per unit tip deflection (multiply by `1 / L` for `dphi/dx`).
    #[must_use]
    pub fn slope(&self, xi: f64) -> f64 {
        self.derivatives(xi)[1]
    }

    /// Curvature `d^2 phi / dxi^2` per unit tip deflection (multiply by `1 / L^2`).
    #[must_use]
    pub fn curvature(&self, xi: f64) -> f64 {
        self.derivatives(xi)[2]
    }

    /// 1-based mode number `n`.
    #[must_use]
    pub fn index(&self) -> usize {
        self.index
    }

    /// Eigenvalue `b_n` (dimensionless): `w_n = b_n^2 sqrt(EI / (rho A L^4))`.
    #[must_use]
    pub fn eigenvalue(&self) -> f64 {
        self.eigenvalue
    }

    /// Tip mass ratio `mu = m_tip / m_c` (dimensionless).
    #[must_use]
    pub fn tip_mass_ratio(&self) -> f64 {
        self.tip_mass_ratio
    }

    /// Tip slope `phi'(1)` in units of `1 / L` per unit tip deflection: what an optical lever
    /// reads. `chi_n = phi_n'(1) / phi_1'(1)` (MODEL.md section 1, `u = sum chi_i q_i`).
    #[must_use]
    pub fn tip_slope(&self) -> f64 {
        self.slope(1.0)
    }

    /// `int_0^1 phi^2 dxi = (1 - 3 mu + 2 mu phi'(1)) / 4` (closed form, module documentation):
    /// the beam's share of the modal mass, in units of `m_c`.
    #[must_use]
    pub fn beam_mass_integral(&self) -> f64 {
        let mu = self.tip_mass_ratio;
        (1.0 - 3.0 * mu + 2.0 * mu * self.tip_slope()) / 4.0
    }

    /// Modal mass `M_n / m_c = int_0^1 phi^2 dxi + mu phi(1)^2 = (1 + mu + 2 mu phi'(1)) / 4`
    /// (dimensionless; multiply by `m_c`): the mass of Eq. 1's oscillator `q_n`.
    #[must_use]
    pub fn modal_mass(&self) -> f64 {
        let mu = self.tip_mass_ratio;
        (1.0 + mu + 2.0 * mu * self.tip_slope()) / 4.0
    }

    /// Equivalent stiffness `k_n L^3 / EI = b_n^4 M_n / m_c = int_0^1 phi''^2 dxi`
    /// (dimensionless; multiply by `EI / L^3` for N/m): Eq. 1's `k_i`, as `k_i = w_i^2 M_i`.
    #[must_use]
    pub fn stiffness(&self) -> f64 {
        self.eigenvalue.powi(4) * self.modal_mass()
    }

    /// Generalised force of a uniformly distributed load `p` (force per length) on the beam
    /// alone, per `p L`: `int_0^1 phi dxi = -mu + 2 sigma / (b U(1))` (closed form). This is the
    /// magnetic drive of the paper: the load acts on the coated beam, not on the tip mass.
    #[must_use]
    pub fn distributed_force_integral(&self) -> f64 {
        -self.tip_mass_ratio + 2.0 * self.sigma * self.tip_normalisation / self.eigenvalue
    }

    /// Generalised force of a point force at the tip, per unit force: `phi(1) = 1` for every
    /// mode, by the unit-tip normalisation. This is how the tip-sample force `F_ts` enters
    /// every mode of Eq. 1 (`F_ts / k_i`).
    #[must_use]
    pub fn tip_force_integral(&self) -> f64 {
        1.0
    }
}
