//! The Taylor series of Eq. 1 in contact with a standard linear solid (MODEL.md section 9,
//! "Standard linear solid"), with the sample's state `rho` as the state's last component, and
//! of its contact surface `h_0 = d + rho^{2/3}` along them: the recurrences of automatic
//! differentiation in the clock offset `s` of a solver step (`t = t(s)`, a quadratic
//! [`ClockPolynomial`]), as for the Hertz sphere (module `contact_series`).
//!
//! With `tau = dt/ds`, the indentation `delta = -d` (`d` with an acoustic drive's base motion)
//! and `P = delta^{3/2}` (the Hertz sphere's series, `P = delta r`, `r = sqrt(delta)`):
//! `dq_i/ds = tau v_i`, `dv_i/ds = tau R_i` with `R_i` Eq. 1's acceleration under `F_ts =
//! c_0 (P - rho)`, and `d rho/ds = tau (beta P - rho) / tau_r`. Entering contact from a
//! recovered sample (`rho = 0`) on the square-root clock centred on the crossing, `delta` has a
//! double zero and `P` follows Hertz's onset recurrence; from an unrecovered one (`rho > 0`) the
//! crossing is at `delta = rho^{2/3} > 0`, where `P` is analytic.
//!
//! The tangents obey `dV/ds = tau J V` with `J`'s coupling `dF/dd = -(3/2) c_0 r` on every
//! `q_j`, `dF/drho = -c_0`, `d rho'/dd = -(3/2) beta r / tau_r`, `d rho'/d rho = -1/tau_r`.
//! The surface's `sigma = rho^{2/3}` follows from `rho sigma' = (2/3) rho' sigma`:
//! `k rho_0 sigma_k = sum_{j=1}^{k} ((2/3) j - (k - j)) rho_j sigma_{k-j}` (`rho_0 > 0`).

use hybrid::{ClockPolynomial, TaylorSeries};

use crate::contact::standard_linear_solid::StandardLinearSolid;
use crate::model::contact_series::{
    clocked_drive_coefficient, convolution, indentation_coefficient, indentation_root,
    modal_coefficients, phase_series, separation_coefficients, SeriesDrive, MAX_ORDER,
};
use crate::model::modal_constants::ModalConstants;
use crate::model::separation::Separation;

/// Whether a series from the state `x0` (`rho` its last component) on `clock` starts at a
/// Hertz onset: on the square-root clock centred on the crossing that entered contact
/// (`tau(0) = 0`) from a recovered sample (`rho = 0`), where the indentation has a double
/// zero.
fn hertz_onset(clock: &ClockPolynomial, x0: &[f64]) -> bool {
    clock.rate == 0.0 && x0.last().is_none_or(|&rho| rho <= 0.0)
}

/// Coefficient `k` of `P = delta^{3/2}` from the indentation's coefficients to `k` and the
/// root's below `k` (which it extends): `delta r` off an onset, `s^3 g sqrt(g)` (`g_j =
/// delta_{j+2}`) on one (module `contact_series`, as for the Hertz sphere).
#[inline(always)]
fn power_coefficient(root: &mut [f64], delta: &[f64], k: usize, onset: bool) -> f64 {
    if onset {
        if k >= 3 {
            indentation_root(root, delta, k - 2, true);
            convolution(&delta[2..k], &root[1..k - 1])
        } else {
            0.0
        }
    } else {
        indentation_root(root, delta, k, false);
        convolution(&delta[..=k], &root[..=k])
    }
}

/// The Taylor coefficients of the flow of Eq. 1 in contact with the standard linear solid
/// `sls` (`N` modes `modes`, drives `drive`, separation `separation`) in the clock offset `s`
/// of `clock`, through the state held in the constant terms of `series` (`2N + 1` components:
/// `q_i`, `q_i'` in nm, nm/us, then `rho` in nm^{3/2}); `false` (series unusable) if the order
/// exceeds [`MAX_ORDER`], the dimension is not `2N + 1`, or a coefficient is not finite (the
/// indentation not positive off an onset, or not growing at one).
pub(crate) fn relaxing_state_series(
    modes: &[ModalConstants],
    sls: &StandardLinearSolid,
    drive: &SeriesDrive,
    separation: &Separation,
    clock: &ClockPolynomial,
    series: &mut TaylorSeries,
) -> bool {
    let n = 2 * modes.len() + 1;
    if series.order() > MAX_ORDER || series.dim() != n {
        return false;
    }
    let p = series.order();
    let last = n - 1;
    let (a, b2) = (clock.rate, 2.0 * clock.curvature);
    let onset = hertz_onset(clock, series.row(0));
    let separation = separation_coefficients(separation, clock);
    let (c0, beta) = (sls.coefficient(), sls.relaxing_fraction());
    let inverse_time = 1.0 / sls.relaxation_time_us;
    let mut cos = [0.0; MAX_ORDER + 1];
    let mut sin = [0.0; MAX_ORDER + 1];
    phase_series(drive.frequency, clock, p, &mut cos, &mut sin);
    let (second_frequency, second_factor) = drive.second.unwrap_or((0.0, 0.0));
    let mut second_cos = [0.0; MAX_ORDER + 1];
    let mut second_sin = [0.0; MAX_ORDER + 1];
    if drive.second.is_some() {
        phase_series(second_frequency, clock, p, &mut second_cos, &mut second_sin);
    }
    let mut delta = [0.0; MAX_ORDER + 1];
    let mut root = [0.0; MAX_ORDER + 1];
    let mut force = [0.0; MAX_ORDER + 1];
    let mut relaxation = [0.0; MAX_ORDER + 1];
    let x = series.coefficients_mut();
    let mut total: f64 = x[..n].iter().sum();
    for k in 0..p {
        let (done, rest) = x.split_at_mut((k + 1) * n);
        let (earlier, row) = done.split_at(k * n);
        let next = &mut rest[..n];
        delta[k] = indentation_coefficient(&separation, row, k) - drive.base_amplitude * cos[k];
        let power = power_coefficient(&mut root, &delta, k, onset);
        let rho = row[last];
        force[k] = c0 * (power - rho);
        relaxation[k] = (beta * power - rho) * inverse_time;
        total += force[k] + relaxation[k];
        let scale = 1.0 / (k + 1) as f64;
        let rate = a * scale;
        let (curvature, below, previous) = if k > 0 {
            (b2 * scale, k - 1, &earlier[(k - 1) * n..])
        } else {
            (0.0, 0, row)
        };
        let tau_force = rate * force[k] + curvature * force[below];
        let tau_drive = clocked_drive_coefficient(
            rate * cos[k] + curvature * cos[below],
            drive.second.map(|_| (second_factor, &second_cos[..])),
            (rate, curvature),
            (k, below),
        );
        total += modal_coefficients(
            modes,
            (rate, curvature),
            (tau_drive, tau_force),
            row,
            previous,
            next,
        );
        next[last] = rate * relaxation[k] + curvature * relaxation[below];
        total += next[last];
    }
    total.is_finite()
}

/// The Taylor coefficients of the tangent matrix `V` (`2N + 1` rows: the transition matrix's
/// columns, then, with `parameter_column`, `dx/dZ`) along the contact flow whose state series
/// is `state` (from [`relaxing_state_series`] with the same arguments): `dV/ds = tau J V`
/// (`+ tau df/dZ` on the parameter column, `dd/dZ = 1`). Each coefficient of `tangents` is
/// `V`'s row-major matrix; the constant terms hold `V` at the step start. `scratch` holds the
/// gap's coefficients of every column (resized here).
#[allow(clippy::too_many_arguments)]
pub(crate) fn relaxing_tangent_series(
    modes: &[ModalConstants],
    sls: &StandardLinearSolid,
    drive: &SeriesDrive,
    separation: &Separation,
    clock: &ClockPolynomial,
    state: &TaylorSeries,
    tangents: &mut TaylorSeries,
    parameter_column: bool,
    scratch: &mut Vec<f64>,
) {
    let p = tangents.order().min(state.order());
    let n = state.dim();
    let columns = tangents.dim() / n;
    let (a, b2) = (clock.rate, 2.0 * clock.curvature);
    let onset = hertz_onset(clock, state.row(0));
    let separation = separation_coefficients(separation, clock);
    // The indentation's square root to order p - 1 (on an onset that needs delta to p).
    let mut base = [0.0; MAX_ORDER + 1];
    if drive.base_amplitude != 0.0 {
        let mut sin = [0.0; MAX_ORDER + 1];
        phase_series(drive.frequency, clock, p, &mut base, &mut sin);
    }
    let mut delta = [0.0; MAX_ORDER + 1];
    for (k, (d, row)) in delta[..=p]
        .iter_mut()
        .zip(state.coefficients().chunks_exact(n))
        .enumerate()
    {
        *d = indentation_coefficient(&separation, row, k) - drive.base_amplitude * base[k];
    }
    let mut root = [0.0; MAX_ORDER + 1];
    for m in 0..p {
        indentation_root(&mut root, &delta, m, onset);
    }
    let recurrence = RelaxingTangents {
        modes,
        root: &root[..p],
        force_gain: sls.coefficient(),
        relaxation_gain: 1.0 / sls.relaxation_time_us,
        beta: sls.relaxing_fraction(),
        rate: a,
        curvature: b2,
        parameter_column,
    };
    let v = tangents.coefficients_mut();
    // The common column counts (N = 1, 2 with and without dZ) as constants, so that the loops
    // over columns unroll.
    match columns {
        3 => recurrence.run(3, v, scratch),
        4 => recurrence.run(4, v, scratch),
        5 => recurrence.run(5, v, scratch),
        6 => recurrence.run(6, v, scratch),
        _ => recurrence.run(columns, v, scratch),
    }
}

/// The coefficients of the tangent recurrence of [`relaxing_tangent_series`].
struct RelaxingTangents<'a> {
    modes: &'a [ModalConstants],
    /// The indentation's square root to order `p - 1`.
    root: &'a [f64],
    /// `c_0`, nN/nm^{3/2}.
    force_gain: f64,
    /// `1 / tau_r`, 1/us.
    relaxation_gain: f64,
    /// `beta = 1 - E_inf*/E_0*`.
    beta: f64,
    /// `tau = rate + curvature s` (`curvature` twice the clock's).
    rate: f64,
    curvature: f64,
    parameter_column: bool,
}

impl RelaxingTangents<'_> {
    /// Rows `1..=p` of `v` (row-major `(2N + 1) x columns` matrices) from row 0: with the gap
    /// `g = sum_j V_{q_j}` of each column (plus `dZ/dZ = 1` on the parameter column) and the
    /// coupling `(r g)_k`, `(k + 1) q_{i,k+1} = (tau v_i)_k`, `(k + 1) v_{i,k+1} = (w_i^2/k_i)
    /// (tau dF)_k - w_i^2 (tau q_i)_k - (w_i/Q_i) (tau v_i)_k` with `dF = -(3/2) c_0 (r g) -
    /// c_0 rho`, and `(k + 1) rho_{k+1} = (tau drho')_k` with `drho' = (-(3/2) beta (r g) -
    /// rho) / tau_r`. `scratch` holds the gaps' rows and `dF`, `drho'` at the power below.
    #[inline(always)]
    fn run(&self, columns: usize, v: &mut [f64], scratch: &mut Vec<f64>) {
        let modes = self.modes;
        let p = self.root.len();
        let n = 2 * modes.len() + 1;
        let last = n - 1;
        let dim = n * columns;
        let (a, b2) = (self.rate, self.curvature);
        let (c0, beta, inverse_time) = (self.force_gain, self.beta, self.relaxation_gain);
        scratch.clear();
        scratch.resize((p + 2) * columns, 0.0);
        let (gaps, previous) = scratch.split_at_mut(p * columns);
        let (previous_force, previous_relaxation) = previous.split_at_mut(columns);
        for k in 0..p {
            let (done, after) = v.split_at_mut((k + 1) * dim);
            let (earlier, row) = done.split_at(k * dim);
            let next = &mut after[..dim];
            let scale = 1.0 / (k + 1) as f64;
            let rate = a * scale;
            let (curvature, below) = if k > 0 {
                (b2 * scale, &earlier[(k - 1) * dim..])
            } else {
                (0.0, row)
            };
            {
                let gap_row = &mut gaps[k * columns..(k + 1) * columns];
                gap_row.fill(0.0);
                for q in row.chunks_exact(2 * columns).take(modes.len()) {
                    for (g, q) in gap_row.iter_mut().zip(&q[..columns]) {
                        *g += q;
                    }
                }
                if k == 0 && self.parameter_column {
                    gap_row[columns - 1] += 1.0;
                }
            }
            let gaps = &gaps[..(k + 1) * columns];
            for start in (0..columns).step_by(COLUMN_BLOCK) {
                let width = COLUMN_BLOCK.min(columns - start);
                let block = start..start + width;
                // (r g)_k, the coupling's coefficient k, for the block's columns.
                let mut coupling = [0.0; COLUMN_BLOCK];
                for (gap, r) in gaps.chunks_exact(columns).zip(self.root[..=k].iter().rev()) {
                    for (c, g) in coupling[..width].iter_mut().zip(&gap[block.clone()]) {
                        *c += r * g;
                    }
                }
                let mut tau_force = [0.0; COLUMN_BLOCK];
                let mut tau_relaxation = [0.0; COLUMN_BLOCK];
                let rho = &row[last * columns..][block.clone()];
                for c in 0..width {
                    let force = -1.5 * c0 * coupling[c] - c0 * rho[c];
                    let relaxation = (-1.5 * beta * coupling[c] - rho[c]) * inverse_time;
                    let column = start + c;
                    tau_force[c] = rate * force + curvature * previous_force[column];
                    tau_relaxation[c] = rate * relaxation + curvature * previous_relaxation[column];
                    previous_force[column] = force;
                    previous_relaxation[column] = relaxation;
                }
                for ((m, out), (qv, below_qv)) in
                    modes.iter().zip(next.chunks_exact_mut(2 * columns)).zip(
                        row.chunks_exact(2 * columns)
                            .zip(below.chunks_exact(2 * columns)),
                    )
                {
                    let (q, velocity) = qv.split_at(columns);
                    let (below_q, below_velocity) = below_qv.split_at(columns);
                    let (next_q, next_v) = out.split_at_mut(columns);
                    for (column, tau_force) in block.clone().zip(&tau_force[..width]) {
                        let tau_q = rate * q[column] + curvature * below_q[column];
                        let tau_v = rate * velocity[column] + curvature * below_velocity[column];
                        next_q[column] = tau_v;
                        next_v[column] = m.omega_squared_over_stiffness * tau_force
                            - m.omega_squared * tau_q
                            - m.damping * tau_v;
                    }
                }
                next[last * columns..][block].copy_from_slice(&tau_relaxation[..width]);
            }
        }
    }
}

/// The widest block of tangent columns [`relaxing_tangent_series`] forms at once in registers
/// (`2N + 2` columns for `N` up to 3 in one).
const COLUMN_BLOCK: usize = 8;

/// The Taylor coefficients `0..coefficients.len()` of the contact surface `h_0 = d +
/// rho^{2/3}` along the state series `state` (any mode: `rho` is its last component) on
/// `clock`, `d = Z(t) + Y cos(w t) + sum_i q_i` (`base_amplitude` `Y`, drive frequency `w`);
/// `false` where `rho^{2/3}` is not analytic at the start (`rho_0 <= 0`) or a coefficient is
/// not finite.
pub(crate) fn relaxing_surface_series(
    drive: &SeriesDrive,
    separation: &Separation,
    clock: &ClockPolynomial,
    state: &TaylorSeries,
    coefficients: &mut [f64],
) -> bool {
    let n = state.dim();
    let order = coefficients.len().saturating_sub(1).min(state.order());
    let rho0 = state.row(0)[n - 1];
    if rho0.is_nan() || rho0 <= 0.0 || order > MAX_ORDER {
        return false;
    }
    let separation = separation_coefficients(separation, clock);
    let mut base = [0.0; MAX_ORDER + 1];
    if drive.base_amplitude != 0.0 {
        let mut sin = [0.0; MAX_ORDER + 1];
        phase_series(drive.frequency, clock, order, &mut base, &mut sin);
    }
    let mut rho = [0.0; MAX_ORDER + 1];
    let mut depth = [0.0; MAX_ORDER + 1];
    let root = rho0.cbrt();
    depth[0] = root * root;
    let mut total = 0.0;
    for (k, (c, row)) in coefficients[..=order]
        .iter_mut()
        .zip(state.coefficients().chunks_exact(n))
        .enumerate()
    {
        rho[k] = row[n - 1];
        if k > 0 {
            let sum: f64 = (1..=k)
                .map(|j| (2.0 / 3.0 * j as f64 - (k - j) as f64) * rho[j] * depth[k - j])
                .sum();
            depth[k] = sum / (k as f64 * rho0);
        }
        *c = -indentation_coefficient(&separation, &row[..n - 1], k)
            + drive.base_amplitude * base[k]
            + depth[k];
        total += *c;
    }
    coefficients[order + 1..].fill(0.0);
    total.is_finite()
}
