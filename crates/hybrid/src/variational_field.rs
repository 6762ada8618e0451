//! The right-hand side the integrators see: the vector field of one mode augmented with the
//! variational equations `Phi' = J Phi`, `s' = J s + df/dp` ([`crate::sensitivity`]), on the
//! time clock or a square-root clock (`dz/dsigma = (dt/dsigma) f(t(sigma), z)`).

use crate::clock::Clock;
use crate::sensitivity::{LinearisationBuffers, Sensitivity};
use crate::system::{HybridSystem, Mode};

/// The augmented right-hand side `[f, J Phi, J s + df/dp]` of one mode, with preallocated
/// linearisation buffers and a count of vector-field evaluations.
pub(crate) struct VariationalField {
    n: usize,
    sensitivity: Sensitivity,
    buffers: LinearisationBuffers,
    /// Number of calls of `HybridSystem::vector_field` made through this object.
    pub evaluations: usize,
}

impl VariationalField {
    pub fn new(n: usize, sensitivity: Sensitivity) -> Self {
        Self {
            n,
            sensitivity,
            buffers: LinearisationBuffers::new(n),
            evaluations: 0,
        }
    }

    /// Dimension `n` of the state (the leading part of the augmented state).
    pub fn state_dim(&self) -> usize {
        self.n
    }

    /// Evaluate `dz/dt` at `(t, z)` in `mode`; with `variational == false` only the state part
    /// `dz[..n]` is written.
    #[inline(always)]
    pub fn eval<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        t: f64,
        z: &[f64],
        dz: &mut [f64],
        variational: bool,
    ) {
        let n = self.n;
        self.evaluations += 1;
        if !variational || !self.sensitivity.transition() {
            system.vector_field(mode, t, &z[..n], &mut dz[..n]);
            return;
        }
        // The columns of Phi (and s) follow the state, column-major and contiguous.
        let parameter = self.sensitivity.parameter();
        let columns = if parameter { n + 1 } else { n };
        let (x, tangents) = z.split_at(n);
        let (dx, tangent_rates) = dz.split_at_mut(n);
        system.variational_field(
            mode,
            t,
            x,
            dx,
            &tangents[..columns * n],
            &mut tangent_rates[..columns * n],
            parameter,
            &mut self.buffers,
        );
    }
}

impl VariationalField {
    /// At the crossing a square-root clock is centred on (`dt/dsigma = 0`), the tangent part
    /// of `dz` from [`crate::SwitchingStructure::crossing_tangent_limit`] where the system
    /// gives that limit (a Jacobian growing as `|h|^{-1/2}`); else left zero.
    fn crossing_limit<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        t: f64,
        z: &[f64],
        dz: &mut [f64],
    ) {
        let n = self.n;
        if !self.sensitivity.transition() {
            return;
        }
        let Some(structure) = system.accelerations().switching else {
            return;
        };
        let parameter = self.sensitivity.parameter();
        let columns = if parameter { n + 1 } else { n };
        let (x, tangents) = z.split_at(n);
        structure.crossing_tangent_limit(
            mode,
            t,
            x,
            &tangents[..columns * n],
            &mut dz[n..n + columns * n],
            parameter,
        );
    }
}

/// The field of `mode` on `clock`: `dz/dsigma = (dt/dsigma) f(t(sigma), z)`, augmented with
/// the variational equations when `variational` (else only the state part is written).
pub(crate) fn clocked_field<'b, S: HybridSystem + ?Sized>(
    field: &'b mut VariationalField,
    system: &'b S,
    mode: Mode,
    clock: Clock,
    variational: bool,
) -> impl FnMut(f64, &[f64], &mut [f64]) + 'b {
    move |sigma: f64, z: &[f64], dz: &mut [f64]| match clock {
        Clock::Time => field.eval(system, mode, sigma, z, dz, variational),
        Clock::SquareRoot { .. } => {
            let t = clock.time(sigma);
            field.eval(system, mode, t, z, dz, variational);
            let rate = clock.rate(sigma);
            let written = if variational {
                dz.len()
            } else {
                field.state_dim()
            };
            for v in &mut dz[..written] {
                *v *= rate;
            }
            if rate == 0.0 && variational {
                field.crossing_limit(system, mode, t, z, dz);
            }
        }
    }
}
