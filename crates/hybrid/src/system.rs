//! The problem statement of a piecewise-smooth (hybrid) system: what a system *is*, separate
//! from how it is integrated.
//!
//! A hybrid system here is an ODE `x' = f_m(t, x)` whose right-hand side depends on a discrete
//! *mode* `m`, together with `K` scalar *switching functions* `h_k(t, x)`. The state space is cut
//! by the surfaces `h_k = 0`; the mode records on which side of every surface the state lies
//! (bit `k` of the mode is set when `h_k < 0`). When a trajectory reaches a surface the solver
//! stops exactly there, and either
//!
//! * flips the mode bit and carries on with the same state (a *crossing*; this is how a
//!   continuous contact force such as Hertz contact is expressed), or
//! * applies the system's *reset map* `x+ = R(t, x-)` (a hard impact with restitution) and
//!   chooses the new mode from the sign of `dh/dt` after the reset: a reset that sends the
//!   state back (a bounce) is applied at the bracket end on the old side, so the mode bit is
//!   unchanged; otherwise the bit flips. Precisely, the new bit is the side of `h` at the
//!   post-reset state (on the surface: the side `dh/dt` points to); see [`crate::solver`].
//!
//! That is the whole model, the trait [`HybridSystem`]; what a system may add to be integrated
//! faster (closed-form flows, Taylor series, the shape of its switching functions) is apart,
//! in [`crate::accelerations`], and none of it is needed for any event guarantee.
//!
//! Every system carries one scalar *parameter* `p` (for the AFM model, the separation `Z`); the
//! derivatives with respect to it let the solver compute `dx(t)/dp` along with the monodromy
//! matrix, as pseudo-arclength continuation needs.

use nalgebra::DMatrix;

use crate::accelerations::Accelerations;
pub(crate) use crate::mode::side_sign;
pub use crate::mode::{Direction, Mode, MAX_SURFACES};
use crate::sensitivity::{jacobian_products, LinearisationBuffers};

/// The partial derivatives of a switching function `h_k(t, x; p)` other than the gradient
/// with respect to the state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SwitchingPartials {
    /// `dh/dt` at fixed state (non-zero when the surface moves, e.g. a separation ramp `Z(t)`).
    pub t: f64,
    /// `dh/dp` with respect to the system's parameter.
    pub p: f64,
}

/// A piecewise-smooth dynamical system: vector fields per mode with their Jacobians,
/// switching surfaces, and optional reset maps.
///
/// A model implements the required methods (`dim`, `surface_count`, `vector_field`,
/// `jacobian`, `switching`, `switching_rate`, `switching_gradient`), and `parameter_derivative`
/// where the parameter enters the field and `has_reset`/`reset` where it has hard impacts;
/// the solver then finds every event and carries the monodromy matrix through it. The other
/// provided methods compute the same derivatives in fused form and may be overridden for
/// speed (`linearisation`, `variational_field`), or list optional accelerations
/// (`accelerations`, [`crate::accelerations`]).
///
/// All vectors are slices of length [`HybridSystem::dim`]; all matrices are `dim x dim`
/// `nalgebra` matrices supplied (already sized) by the caller, so that an implementation never
/// allocates.
pub trait HybridSystem {
    /// Dimension `n` of the state vector `x`.
    fn dim(&self) -> usize;

    /// Number `K` of switching functions (at most [`MAX_SURFACES`]).
    fn surface_count(&self) -> usize;

    /// The vector field `f_m(t, x)` of mode `mode`, written into `dxdt`.
    ///
    /// The solver evaluates the field of the current mode even at states that lie a rounding
    /// error on the other side of a surface (Runge-Kutta stages, the point just past an event),
    /// so `f_m` must be defined (finite) on a neighbourhood of its region.
    fn vector_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]);

    /// The Jacobian `df_m/dx` at `(t, x)`, written into `jacobian` (`n x n`).
    fn jacobian(&self, mode: Mode, t: f64, x: &[f64], jacobian: &mut DMatrix<f64>);

    /// The derivative `df_m/dp` of the vector field with respect to the system's parameter,
    /// written into `dfdp`. The default is zero (the parameter does not enter the field).
    fn parameter_derivative(&self, mode: Mode, t: f64, x: &[f64], dfdp: &mut [f64]) {
        let _ = (mode, t, x);
        dfdp.fill(0.0);
    }

    /// The field, its Jacobian and (if `dfdp` is `Some`) its parameter derivative at one point,
    /// from which the default [`HybridSystem::variational_field`] forms the variational
    /// equations' right-hand side. The default calls
    /// [`HybridSystem::vector_field`], [`HybridSystem::jacobian`] and
    /// [`HybridSystem::parameter_derivative`]; override it (with the same results) when the
    /// three share expensive work, such as a contact force and its slope.
    fn linearisation(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        dxdt: &mut [f64],
        jacobian: &mut DMatrix<f64>,
        dfdp: Option<&mut [f64]>,
    ) {
        self.vector_field(mode, t, x, dxdt);
        self.jacobian(mode, t, x, jacobian);
        if let Some(dfdp) = dfdp {
            self.parameter_derivative(mode, t, x, dfdp);
        }
    }

    /// The right-hand side of the variational equations at one point: the field `f_m(t, x)`
    /// into `dxdt`, and `J v` (`J = df_m/dx`) for every column `v` of `tangents` into the same
    /// column of `tangent_rates` (both column-major with `n` rows, as many columns as
    /// `tangents.len() / n`), plus `df_m/dp` on the last column when `parameter_column` is
    /// true: `Phi' = J Phi` for the transition matrix and `s' = J s + df/dp` for the parameter
    /// sensitivity (Hairer, Norsett, Wanner I, Sec. I.14).
    ///
    /// The default forms `J` and `df/dp` with [`HybridSystem::linearisation`] in `buffers` and
    /// multiplies (`n^2` multiply-adds per column). Override it, with the same results up to
    /// rounding, when `J` has a structure that makes the products cheaper (a mechanical system's
    /// `[[0, I], [-K, -C]]` blocks with a low-rank contact coupling); `buffers` is then free
    /// scratch space.
    #[allow(clippy::too_many_arguments)]
    fn variational_field(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        dxdt: &mut [f64],
        tangents: &[f64],
        tangent_rates: &mut [f64],
        parameter_column: bool,
        buffers: &mut LinearisationBuffers,
    ) {
        let LinearisationBuffers { jacobian, dfdp } = buffers;
        self.linearisation(
            mode,
            t,
            x,
            dxdt,
            jacobian,
            parameter_column.then_some(&mut dfdp[..]),
        );
        jacobian_products(
            jacobian,
            tangents,
            tangent_rates,
            parameter_column.then_some(&dfdp[..]),
        );
    }

    /// The switching function `h_k(t, x)`; the surface is `h_k = 0`.
    fn switching(&self, k: usize, t: f64, x: &[f64]) -> f64;

    /// The time derivative of `h_k` along the flow of mode `mode`:
    /// `dh_k/dt = dh_k/dt|_x + (grad_x h_k) . f_m(t, x)`.
    ///
    /// Local minima of `h_k` (grazing and near-grazing) are the zeros of this function.
    fn switching_rate(&self, k: usize, mode: Mode, t: f64, x: &[f64]) -> f64;

    /// The gradient `grad_x h_k` written into `gradient`, and the partials with respect to time
    /// and to the parameter. Used for saltation matrices and event-time sensitivities.
    fn switching_gradient(
        &self,
        k: usize,
        t: f64,
        x: &[f64],
        gradient: &mut [f64],
    ) -> SwitchingPartials;

    /// Whether reaching surface `k` in `direction` applies a reset map (a hard impact) rather
    /// than a plain crossing. The default is `false` for every surface.
    fn has_reset(&self, k: usize, direction: Direction) -> bool {
        let _ = (k, direction);
        false
    }

    /// Apply the reset map `x+ = R(t, x-)` at surface `k` in place, and write its Jacobian
    /// `dR/dx` into `jacobian` and its parameter derivative `dR/dp` into `dxdp`.
    ///
    /// Called only where [`HybridSystem::has_reset`] is `true`; the default is the identity.
    fn reset(
        &self,
        k: usize,
        direction: Direction,
        t: f64,
        x: &mut [f64],
        jacobian: &mut DMatrix<f64>,
        dxdp: &mut [f64],
    ) {
        let _ = (k, direction, t, x);
        jacobian.fill_with_identity();
        dxdp.fill(0.0);
    }

    /// The mode entered when an event on surface `k` in `direction` takes the system out of
    /// `mode`; `crossed` is `mode` with bit `k` set to the new side of the surface, and the
    /// default returns it. A system with a discrete state that the signs of its switching
    /// functions do not determine (a hysteresis: a contact formed at one surface and broken at
    /// another) keeps it in bits at or above [`HybridSystem::surface_count`], which the solver
    /// never reads, sets or clears them here, and overrides [`HybridSystem::mode_of`] to start
    /// an integration in the right one. Bit `k` of the result must be that of `crossed`.
    fn mode_after_crossing(
        &self,
        _k: usize,
        _direction: Direction,
        _mode: Mode,
        crossed: Mode,
    ) -> Mode {
        crossed
    }

    /// The optional accelerations this system offers ([`crate::accelerations`]): closed-form
    /// flows, Taylor series, the shape of its switching functions. The default is
    /// [`Accelerations::NONE`]: the solver integrates every mode with DOP853 and samples every
    /// step inside, with every event guarantee intact. A system implementing some of the
    /// traits returns itself for each, e.g.
    /// `Accelerations { exact_flow: Some(self), ..Accelerations::NONE }`.
    fn accelerations(&self) -> Accelerations<'_> {
        Accelerations::NONE
    }

    /// The mode of state `x` at time `t`, from the signs of the switching functions
    /// (bit `k` set when `h_k(t, x) < 0`). Used to start an integration.
    fn mode_of(&self, t: f64, x: &[f64]) -> Mode {
        (0..self.surface_count()).fold(0, |mode, k| {
            if self.switching(k, t, x) < 0.0 {
                mode | (1 << k)
            } else {
                mode
            }
        })
    }
}
