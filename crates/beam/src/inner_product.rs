//! Mass and stiffness inner products of two mode shapes by quadrature: the entries of the
//! modal mass and stiffness matrices, which are diagonal when the modes are the true
//! eigenmodes of the beam with its tip mass.

use crate::error::BeamError;
use crate::mode_shape::ModeShape;
use crate::quadrature::GaussLegendre;

/// Points per panel of the rule [`mass_product`] and [`stiffness_product`] use.
pub const QUADRATURE_ORDER: usize = 16;

/// Panels for integrating products of modes with eigenvalues up to `b_max`: one per unit of
/// `b_max / 2` (at least 4). On a panel of width `h` the integrand varies on the scale `1 / b`;
/// with `b h / 2 <= 1/4` the 16-point rule's error term `~ (b h / 2)^32 / 32!` is far below
/// rounding.
#[must_use]
pub fn panels_for(b_max: f64) -> usize {
    let panels = (2.0 * b_max).ceil();
    if panels.is_finite() && panels > 4.0 {
        // Bounded by the eigenvalues the crate accepts (b <= 50 pi), far below MAX_PANELS.
        (panels as usize).min(crate::quadrature::MAX_PANELS)
    } else {
        4
    }
}

/// Mass inner product `int_0^1 phi_m phi_n dxi + mu phi_m(1) phi_n(1)` (units of `m_c`): the
/// `(m, n)` entry of the modal mass matrix (zero for `m != n`; `M_n / m_c` for `m = n`).
/// Computed by composite 16-point Gauss-Legendre quadrature, independently of the closed form
/// [`ModeShape::modal_mass`]. Both modes must have the same tip mass ratio; `first`'s is used.
///
/// # Errors
/// Only if the quadrature cannot be set up (not for valid modes).
pub fn mass_product(first: &ModeShape, second: &ModeShape) -> Result<f64, BeamError> {
    let rule = GaussLegendre::new(QUADRATURE_ORDER)?;
    let panels = panels_for(first.eigenvalue().max(second.eigenvalue()));
    let beam = rule.integrate(
        |xi| first.deflection(xi) * second.deflection(xi),
        0.0,
        1.0,
        panels,
    )?;
    Ok(beam + first.tip_mass_ratio() * first.deflection(1.0) * second.deflection(1.0))
}

/// Stiffness inner product `int_0^1 phi_m'' phi_n'' dxi` (units of `EI / L^3`): the `(m, n)`
/// entry of the modal stiffness matrix (zero for `m != n`; `k_n L^3 / EI` for `m = n`), by the
/// same quadrature as [`mass_product`], independently of [`ModeShape::stiffness`].
///
/// # Errors
/// Only if the quadrature cannot be set up (not for valid modes).
pub fn stiffness_product(first: &ModeShape, second: &ModeShape) -> Result<f64, BeamError> {
    let rule = GaussLegendre::new(QUADRATURE_ORDER)?;
    let panels = panels_for(first.eigenvalue().max(second.eigenvalue()));
    rule.integrate(
        |xi| first.curvature(xi) * second.curvature(xi),
        0.0,
        1.0,
        panels,
    )
}

/// `int_0^1 phi dxi` by quadrature: the generalised force of a unit uniformly distributed load
/// on the beam (units of `p L`), independently of [`ModeShape::distributed_force_integral`].
///
/// # Errors
/// Only if the quadrature cannot be set up (not for valid modes).
pub fn distributed_force_by_quadrature(mode: &ModeShape) -> Result<f64, BeamError> {
    let rule = GaussLegendre::new(QUADRATURE_ORDER)?;
    rule.integrate(
        |xi| mode.deflection(xi),
        0.0,
        1.0,
        panels_for(mode.eigenvalue()),
    )
}
