//! `beam`: Euler-Bernoulli modal analysis of a uniform rectangular cantilever, clamped at the
//! base, carrying a point tip mass (ratio `mu = m_tip / m_c`, no rotary inertia).
//!
//! It computes what Eq. 1 of the paper (Melcher, Xu, Raman, APL 93, 093111 (2008); MODEL.md
//! section 1) needs for each mode, with the modes normalised to unit tip deflection
//! (`phi_n(L) = 1`, so `q_n` is the tip deflection in mode `n`):
//!
//! - the eigenvalues `b_n`, roots of `1 + cos b cosh b + mu b (cos b sinh b - sin b cosh b) = 0`
//!   ([`characteristic`]), and the vacuum frequency ratios `w_n / w_1 = (b_n / b_1)^2`;
//! - the equivalent stiffnesses `k_n = w_n^2 M_n`, `M_n = m_c int phi_n^2 + m_tip`
//!   ([`ModeShape::stiffness`]);
//! - the optical-lever sensitivities `chi_n = phi_n'(L) / phi_1'(L)` ([`ModeShape::tip_slope`]);
//! - the generalised forces of a uniformly distributed drive (`int phi_n`, magnetic excitation)
//!   and of a tip force (`phi_n(L) = 1`).
//!
//! [`modal_table()`] returns all of them as ratios to mode 1. It reproduces the paper's numbers
//! (MODEL.md section 7): `k_2/k_1 = 39.27` at `mu = 0` and `73.83` at `mu = 0.1`;
//! `chi_2 = 3.473` at `mu = 0` and `5.256` at `mu = 0.16`; `F_2/F_1 = -0.5542` at `mu = 0` and
//! `-1.544` at `mu = 0.16`.
//!
//! [`RectangularCantilever::modes_in_fluid`] builds the modes of a rectangular cantilever in a
//! viscous fluid from its geometry: frequencies, quality factors and stiffnesses from Sader's
//! hydrodynamic function (J. Appl. Phys. 84, 64 (1998); [`hydrodynamic`], [`rectangular`]).
#![warn(missing_docs)]

pub mod bessel;
pub mod cantilever;
pub mod characteristic;
pub mod error;
pub mod fluid;
pub mod hydrodynamic;
pub mod inner_product;
pub mod modal_table;
pub mod mode_shape;
pub mod quadrature;
pub mod rectangular;

pub use cantilever::{Beam, MAX_MODES, MAX_TIP_MASS_RATIO};
pub use characteristic::{characteristic_function, eigenvalue, eigenvalue_bracket};
pub use error::BeamError;
pub use fluid::Fluid;
pub use hydrodynamic::{
    circular_hydrodynamic_function, rectangular_correction, rectangular_hydrodynamic_function,
    reynolds_number,
};
pub use inner_product::{distributed_force_by_quadrature, mass_product, stiffness_product};
pub use modal_table::{modal_table, ModalProperties};
pub use mode_shape::ModeShape;
pub use quadrature::GaussLegendre;
pub use rectangular::{FluidMode, RectangularCantilever};
