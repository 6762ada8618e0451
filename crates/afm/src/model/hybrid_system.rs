//! The tapping cantilever's core as a hybrid system: its vector field, Jacobians, parameter
//! derivative and the gap as its one switching surface (MODEL.md section 1).

use hybrid::{
    Accelerations, Direction, HybridSystem, LinearisationBuffers, Mode, SwitchingPartials,
};

use crate::contact::standard_linear_solid::StandardLinearSolid;
use crate::contact::ForceSlopes;
use nalgebra::DMatrix;

use super::{TappingModel, ATTACHED, CLIPPED, GAP_SURFACE, PULL_OFF_SURFACE, RELEASE_SURFACE};

impl HybridSystem for TappingModel {
    /// `2N`, plus 1 for a standard linear solid's state `rho` (MODEL.md section 9).
    fn dim(&self) -> usize {
        2 * self.modes.len() + self.sample_state_count()
    }

    /// The contact surface, and a clipped Kelvin-Voigt law's release surface or a hysteretic
    /// law's pull-off surface.
    fn surface_count(&self) -> usize {
        if self.force.law.release_time_us().is_some() || self.force.release_gap_nm().is_some() {
            2
        } else {
            1
        }
    }

    /// Eq. 1 solved for the accelerations:
    /// `q_i'' = w_i^2 [(F_i/k_i) cos(w t) + F_ts/k_i - q_i] - (w_i/Q_i) q_i'`, with the force
    /// `F_ts(d, d')` of the mode's side of each surface (MODEL.md section 9; for the Hertz
    /// sphere 0 in free flight and `c (-d)^{3/2}`, finite on both sides, in contact).
    #[inline(always)]
    fn vector_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        let drive = self.drive_factor(t);
        let force = if !self.plain_hertz {
            self.force_slopes(mode, t, x).force
        } else if Self::in_contact(mode) {
            self.hertz.force(self.gap(t, x))
        } else {
            0.0
        };
        self.modal_field(drive, force, x, dxdt);
        self.sample_state_field(mode, t, x, dxdt);
    }

    /// `df/dx`: the modal blocks `[[0, 1], [-w_i^2, -w_i/Q_i]]`, plus
    /// `d q_i'' / d q_j = (w_i^2 / k_i) dF_ts/dd` and `d q_i'' / d q_j' = (w_i^2 / k_i)
    /// dF_ts/dd'` for every `i, j`.
    fn jacobian(&self, mode: Mode, t: f64, x: &[f64], jacobian: &mut DMatrix<f64>) {
        if self.sample_state_count() > 0 {
            self.relaxing_jacobian(mode, t, x, jacobian.as_mut_slice());
            return;
        }
        let slopes = self.force_slopes(mode, t, x);
        self.modal_jacobian(slopes.gap_slope, slopes.rate_slope, jacobian.as_mut_slice());
    }

    /// `df/dZ`: `(w_i^2 / k_i) dF_ts/dd` on every acceleration component (`dd/dZ = 1`).
    fn parameter_derivative(&self, mode: Mode, t: f64, x: &[f64], dfdp: &mut [f64]) {
        let slope = self.force_slopes(mode, t, x).gap_slope;
        self.separation_derivative(slope, dfdp);
        self.sample_state_parameter_derivative(mode, t, x, dfdp);
    }

    /// The field, Jacobian and `df/dZ` above from one evaluation of the gap, the drive and
    /// the indentation's square root (the Hertz force `c s^{3/2}` and slope `-1.5 c s^{1/2}`,
    /// `s = max(-d, 0)`, share it).
    fn linearisation(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        dxdt: &mut [f64],
        jacobian: &mut DMatrix<f64>,
        dfdp: Option<&mut [f64]>,
    ) {
        if self.sample_state_count() > 0 {
            self.vector_field(mode, t, x, dxdt);
            self.jacobian(mode, t, x, jacobian);
            if let Some(dfdp) = dfdp {
                self.parameter_derivative(mode, t, x, dfdp);
            }
            return;
        }
        let drive = self.drive_factor(t);
        let slopes = self.force_slopes(mode, t, x);
        self.modal_field(drive, slopes.force, x, dxdt);
        self.modal_jacobian(slopes.gap_slope, slopes.rate_slope, jacobian.as_mut_slice());
        if let Some(dfdp) = dfdp {
            self.separation_derivative(slopes.gap_slope, dfdp);
        }
    }

    /// The field and `J v` (`+ df/dZ` on the parameter column) without forming `J`: per
    /// tangent column `v`, `(J v)_{q_i} = v_{v_i}` and `(J v)_{v_i} = -w_i^2 v_{q_i} - (w_i/Q_i)
    /// v_{v_i} + (w_i^2/k_i) F_ts'(d) sum_j v_{q_j}` (the contact couples the modes only
    /// through the gap; `df/dZ` is the same coupling with `dd/dZ = 1`): about `6N` operations
    /// a column instead of the dense `4N^2`.
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
        _buffers: &mut LinearisationBuffers,
    ) {
        if self.sample_state_count() > 0 {
            self.vector_field(mode, t, x, dxdt);
            self.relaxing_tangent_rates(mode, t, x, tangents, tangent_rates, parameter_column);
            return;
        }
        let drive = self.drive_factor(t);
        let slopes = self.force_slopes(mode, t, x);
        self.modal_field(drive, slopes.force, x, dxdt);
        if slopes.rate_slope == 0.0 {
            self.modal_tangent_rates(slopes.gap_slope, tangents, tangent_rates, parameter_column);
        } else {
            self.viscous_tangent_rates(slopes, tangents, tangent_rates, parameter_column);
        }
    }

    /// `h_0 = d - d_c = Z(t) + y_base(t) + sum_i q_i - d_c`, nm (a standard linear solid's
    /// `h_0 = d + sigma`, `sigma = rho^{2/3}` its unrecovered depth); a clipped Kelvin-Voigt
    /// law's `h_1 = -d - tau d'`, nm; a hysteretic law's `h_1 = d - d_r`, nm (MODEL.md
    /// sections 9 and 14).
    #[inline]
    fn switching(&self, k: usize, t: f64, x: &[f64]) -> f64 {
        if k == GAP_SURFACE {
            self.gap(t, x) - self.contact_gap_nm()
                + self.force.law.surface_depth_nm(self.sample_state(x))
        } else if let Some(release) = self.force.release_gap_nm() {
            self.gap(t, x) - release
        } else {
            -self.gap(t, x) - self.release_time() * self.gap_rate_at(t, x)
        }
    }

    /// `dh_0/dt = Z'(t) + sum_i q_i'` (the same in every mode; plus `sigma'` of the mode's
    /// `rho'` for a standard linear solid), nm/us;
    /// `dh_1/dt = -d' - tau d''` with `d'' = sum_i q_i''` of mode `mode` (`Z'' = 0`).
    /// A hysteretic law's `dh_1/dt = d'`.
    #[inline]
    fn switching_rate(&self, k: usize, mode: Mode, t: f64, x: &[f64]) -> f64 {
        if k == GAP_SURFACE {
            self.gap_rate_at(t, x) + self.surface_depth_rate(mode, t, x)
        } else if self.force.release_gap_nm().is_some() {
            self.gap_rate_at(t, x)
        } else {
            -self.gap_rate_at(t, x) - self.release_time() * self.gap_acceleration(mode, t, x)
        }
    }

    /// `grad h_0` = 1 on every `q_i`, 0 on every `q_i'` (and `d sigma/d rho = (2/3)
    /// rho^{-1/3}` on a standard linear solid's `rho`); `dh_0/dt|_x = Z'(t) + y_base'(t)`;
    /// `dh_0/dZ = 1`. `grad h_1` = -1 on every `q_i`, `-tau` on every `q_i'`;
    /// `dh_1/dt|_x = -Z'(t) - y_base'(t) - tau y_base''(t)`;
    /// `dh_1/dZ = -1`.
    fn switching_gradient(
        &self,
        k: usize,
        t: f64,
        x: &[f64],
        gradient: &mut [f64],
    ) -> SwitchingPartials {
        let hysteretic = self.force.release_gap_nm().is_some();
        let (on_gap, on_rate, sign) = if k == RELEASE_SURFACE && !hysteretic {
            (-1.0, -self.release_time(), -1.0)
        } else {
            (1.0, 0.0, 1.0)
        };
        let modal = 2 * self.modes.len();
        for (i, g) in gradient[..modal].iter_mut().enumerate() {
            *g = if i % 2 == 0 { on_gap } else { on_rate };
        }
        if self.sample_state_count() > 0 {
            gradient[modal] = if k == GAP_SURFACE {
                StandardLinearSolid::depth_slope(self.sample_state(x))
            } else {
                0.0
            };
        }
        SwitchingPartials {
            t: sign * (self.separation.rate() + self.base_velocity(t))
                + on_rate * self.base.as_ref().map_or(0.0, |base| base.acceleration(t)),
            p: sign,
        }
    }

    /// A hysteretic law attaches at the `Down` crossing of the contact surface and detaches at
    /// the `Up` crossing of its pull-off surface (bit [`ATTACHED`]); every other crossing
    /// keeps the attachment.
    fn mode_after_crossing(
        &self,
        k: usize,
        direction: Direction,
        _mode: Mode,
        crossed: Mode,
    ) -> Mode {
        if self.force.release_gap_nm().is_none() {
            return crossed;
        }
        match (k, direction) {
            (GAP_SURFACE, Direction::Down) => crossed | ATTACHED,
            (PULL_OFF_SURFACE, Direction::Up) => crossed & !ATTACHED,
            _ => crossed,
        }
    }

    /// The signs of the surfaces; for a hysteretic law also [`ATTACHED`] inside contact and,
    /// in the band `d_c <= d < d_r` where the state alone does not say, when the gap opens
    /// (`d' > 0`: a tip rising from contact is taken as still attached, a descending one as
    /// not yet; MODEL.md section 9).
    fn mode_of(&self, t: f64, x: &[f64]) -> Mode {
        let mut mode = (0..self.surface_count()).fold(0, |mode, k| {
            if self.switching(k, t, x) < 0.0 {
                mode | (1 << k)
            } else {
                mode
            }
        });
        if let Some(release) = self.force.release_gap_nm() {
            let gap = self.gap(t, x);
            if gap < self.contact_gap_nm() || (gap < release && self.gap_rate(x) > 0.0) {
                mode |= ATTACHED;
            }
        }
        mode
    }

    /// The closed-form flow outside contact where the force there is a constant (zero, or an
    /// attached meniscus's; `TappingModel::flight_force_nn`), the Taylor series of the plain
    /// Hertz contact and of DMT (`TappingModel::series_force`), and the surfaces' shape
    /// (affine; the gap's curvature bounded in flight under a constant force; a half-power
    /// surface in contact).
    fn accelerations(&self) -> Accelerations<'_> {
        Accelerations {
            exact_flow: Some(self),
            taylor: Some(self),
            switching: Some(self),
        }
    }
}

impl TappingModel {
    /// A clipped Kelvin-Voigt law's `tau`, us (0 for another law, which has no surface 1).
    fn release_time(&self) -> f64 {
        self.force.law.release_time_us().unwrap_or(0.0)
    }

    /// Whether mode `mode` is on the clipped side of a Kelvin-Voigt law's release surface.
    pub(crate) fn is_clipped(&self, mode: Mode) -> bool {
        mode & CLIPPED != 0 && self.force.law.release_time_us().is_some()
    }

    /// Whether mode `mode` has a hysteretic law attached (bit [`ATTACHED`]).
    pub(crate) fn is_attached(mode: Mode) -> bool {
        mode & ATTACHED != 0
    }

    /// [`Self::modal_tangent_rates`] for a force with a slope in the gap rate: per column `v`
    /// `(J v)_{v_i} = -w_i^2 v_{q_i} - (w_i/Q_i) v_{v_i} + (w_i^2/k_i) (F_d sum_j v_{q_j} +
    /// F_{d'} sum_j v_{v_j})`, plus `(w_i^2/k_i) F_d` on the parameter column.
    fn viscous_tangent_rates(
        &self,
        slopes: ForceSlopes,
        tangents: &[f64],
        rates: &mut [f64],
        parameter_column: bool,
    ) {
        let n = 2 * self.modes.len();
        let columns = tangents.len() / n;
        for (c, (v, rate)) in tangents
            .chunks_exact(n)
            .zip(rates.chunks_exact_mut(n))
            .enumerate()
        {
            let mut gap_change = if parameter_column && c + 1 == columns {
                1.0
            } else {
                0.0
            };
            let mut rate_change = 0.0;
            for i in 0..self.modes.len() {
                gap_change += v[2 * i];
                rate_change += v[2 * i + 1];
            }
            let coupling = slopes.gap_slope * gap_change + slopes.rate_slope * rate_change;
            for (i, m) in self.modes.iter().enumerate() {
                rate[2 * i] = v[2 * i + 1];
                rate[2 * i + 1] = m.omega_squared_over_stiffness * coupling
                    - m.omega_squared * v[2 * i]
                    - m.damping * v[2 * i + 1];
            }
        }
    }
}
