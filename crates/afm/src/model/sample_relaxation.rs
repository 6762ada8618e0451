//! The standard linear solid's internal state in the tapping model (MODEL.md section 9,
//! "Standard linear solid"): the state's last component `rho` (nm^{3/2}), its rate in each
//! mode, and the Jacobian and tangent rates of the extended state `[q_1, q_1', ..., q_N, q_N',
//! rho]`, so that shooting, the monodromy and the saltation at each contact carry it.

use hybrid::Mode;

use super::{tangent_gap_change, TappingModel, CONTACT};
use crate::contact::standard_linear_solid::StandardLinearSolid;

/// The slopes that couple the sample's state to the cantilever at one `(t, x)`.
struct RelaxingSlopes {
    /// `dF_ts/dd`, nN/nm.
    force_gap: f64,
    /// `dF_ts/drho`, nN/nm^{3/2}.
    force_state: f64,
    /// `d rho'/dd`, nm^{1/2}/us.
    rate_gap: f64,
    /// `d rho'/d rho`, 1/us.
    rate_state: f64,
}

impl TappingModel {
    fn relaxing_slopes(
        &self,
        sls: &StandardLinearSolid,
        mode: Mode,
        t: f64,
        x: &[f64],
    ) -> RelaxingSlopes {
        let inside = mode & CONTACT != 0;
        let state = self.sample_state(x);
        let gap = self.gap(t, x);
        let force = self.force_slopes(mode, t, x);
        let (_, rate_gap, rate_state) = sls.state_rate(inside, gap, state);
        RelaxingSlopes {
            force_gap: force.gap_slope,
            force_state: sls.state_force_slope(inside),
            rate_gap,
            rate_state,
        }
    }

    /// Write `rho'` of mode `mode` into the last component of `dxdt` (nothing without a
    /// standard linear solid): in contact `(beta s^{3/2} - rho) / tau`, outside
    /// `-(1 - beta) rho / tau`.
    pub(crate) fn sample_state_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        if let Some(sls) = self.force.law.standard_linear_solid() {
            let inside = mode & CONTACT != 0;
            let (rate, _, _) = sls.state_rate(inside, self.gap(t, x), self.sample_state(x));
            dxdt[2 * self.modes.len()] = rate;
        }
    }

    /// `sigma' = (d sigma/d rho) rho'` of mode `mode`, nm/us (0 without a standard linear
    /// solid): the unrecovered surface's rate, part of `dh_0/dt`.
    #[inline]
    pub(crate) fn surface_depth_rate(&self, mode: Mode, t: f64, x: &[f64]) -> f64 {
        match self.force.law.standard_linear_solid() {
            Some(sls) => {
                let state = self.sample_state(x);
                let (rate, _, _) = sls.state_rate(mode & CONTACT != 0, self.gap(t, x), state);
                StandardLinearSolid::depth_slope(state) * rate
            }
            None => 0.0,
        }
    }

    /// `d rho'/dZ = d rho'/dd` into the last component of `dfdp` (`dd/dZ = 1`).
    pub(crate) fn sample_state_parameter_derivative(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        dfdp: &mut [f64],
    ) {
        if let Some(sls) = self.force.law.standard_linear_solid() {
            let inside = mode & CONTACT != 0;
            let (_, rate_gap, _) = sls.state_rate(inside, self.gap(t, x), self.sample_state(x));
            dfdp[2 * self.modes.len()] = rate_gap;
        }
    }

    /// The Jacobian of the extended field into the column-major `(2N+1) x (2N+1)` `matrix`:
    /// the modal blocks, `d q_i''/d q_j = (w_i^2/k_i) dF/dd`, `d q_i''/d rho = (w_i^2/k_i)
    /// dF/drho`, `d rho'/d q_j = d rho'/dd`, `d rho'/d rho`.
    pub(crate) fn relaxing_jacobian(&self, mode: Mode, t: f64, x: &[f64], matrix: &mut [f64]) {
        let Some(sls) = self.force.law.standard_linear_solid() else {
            return;
        };
        let slopes = self.relaxing_slopes(sls, mode, t, x);
        let count = self.modes.len();
        let n = 2 * count + 1;
        let last = 2 * count;
        matrix.fill(0.0);
        for (i, m) in self.modes.iter().enumerate() {
            matrix[2 * i + n * (2 * i + 1)] = 1.0;
            matrix[2 * i + 1 + n * (2 * i)] = -m.omega_squared;
            matrix[2 * i + 1 + n * (2 * i + 1)] = -m.damping;
            let coupling = m.omega_squared_over_stiffness * slopes.force_gap;
            for j in 0..count {
                matrix[2 * i + 1 + n * (2 * j)] += coupling;
            }
            matrix[2 * i + 1 + n * last] = m.omega_squared_over_stiffness * slopes.force_state;
        }
        for j in 0..count {
            matrix[last + n * (2 * j)] = slopes.rate_gap;
        }
        matrix[last + n * last] = slopes.rate_state;
    }

    /// `J v` of the extended field for every column `v` of `tangents` (column-major, `2N+1`
    /// rows) into `rates`, plus `df/dZ` on the last column with `parameter_column`.
    pub(crate) fn relaxing_tangent_rates(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        tangents: &[f64],
        rates: &mut [f64],
        parameter_column: bool,
    ) {
        let Some(sls) = self.force.law.standard_linear_solid() else {
            return;
        };
        let slopes = self.relaxing_slopes(sls, mode, t, x);
        let count = self.modes.len();
        let n = 2 * count + 1;
        let columns = tangents.len() / n;
        for (c, (v, rate)) in tangents
            .chunks_exact(n)
            .zip(rates.chunks_exact_mut(n))
            .enumerate()
        {
            let gap_change = tangent_gap_change(v, count, parameter_column && c + 1 == columns);
            let state_change = v[2 * count];
            let coupling = slopes.force_gap * gap_change + slopes.force_state * state_change;
            for (i, m) in self.modes.iter().enumerate() {
                rate[2 * i] = v[2 * i + 1];
                rate[2 * i + 1] = m.omega_squared_over_stiffness * coupling
                    - m.omega_squared * v[2 * i]
                    - m.damping * v[2 * i + 1];
            }
            rate[2 * count] = slopes.rate_gap * gap_change + slopes.rate_state * state_change;
        }
    }
}
