//! The tapping cantilever's core as a hybrid system: its vector field, Jacobians, parameter
//! derivative and the gap as its one switching surface (MODEL.md section 1).

use hybrid::{Accelerations, HybridSystem, LinearisationBuffers, Mode, SwitchingPartials};
use nalgebra::DMatrix;

use super::TappingModel;
use crate::phase;

impl HybridSystem for TappingModel {
    fn dim(&self) -> usize {
        2 * self.modes.len()
    }

    fn surface_count(&self) -> usize {
        1
    }

    /// Eq. 1 solved for the accelerations:
    /// `q_i'' = w_i^2 [(F_i/k_i) cos(w t) + F_ts(d)/k_i - q_i] - (w_i/Q_i) q_i'`, with
    /// `F_ts = 0` in free flight and the Hertz force (finite on both sides) in contact.
    #[inline(always)]
    fn vector_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        let drive = phase::cos(self.drive.angular_frequency * t);
        let force = if Self::in_contact(mode) {
            self.hertz.force(self.gap(t, x))
        } else {
            0.0
        };
        self.modal_field(drive, force, x, dxdt);
    }

    /// `df/dx`: the modal blocks `[[0, 1], [-w_i^2, -w_i/Q_i]]`, plus in contact
    /// `d q_i'' / d q_j = (w_i^2 / k_i) F_ts'(d)` for every `i, j`.
    fn jacobian(&self, mode: Mode, t: f64, x: &[f64], jacobian: &mut DMatrix<f64>) {
        let slope = if Self::in_contact(mode) {
            self.hertz.force_derivative(self.gap(t, x))
        } else {
            0.0
        };
        self.modal_jacobian(slope, jacobian.as_mut_slice());
    }

    /// `df/dZ`: `(w_i^2 / k_i) F_ts'(d)` on every acceleration component in contact, 0 in
    /// free flight.
    fn parameter_derivative(&self, mode: Mode, t: f64, x: &[f64], dfdp: &mut [f64]) {
        let slope = if Self::in_contact(mode) {
            self.hertz.force_derivative(self.gap(t, x))
        } else {
            0.0
        };
        self.separation_derivative(slope, dfdp);
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
        let drive = phase::cos(self.drive.angular_frequency * t);
        let (force, slope) = self.force_and_slope(mode, t, x);
        self.modal_field(drive, force, x, dxdt);
        self.modal_jacobian(slope, jacobian.as_mut_slice());
        if let Some(dfdp) = dfdp {
            self.separation_derivative(slope, dfdp);
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
        let drive = phase::cos(self.drive.angular_frequency * t);
        let (force, slope) = self.force_and_slope(mode, t, x);
        self.modal_field(drive, force, x, dxdt);
        self.modal_tangent_rates(slope, tangents, tangent_rates, parameter_column);
    }

    /// `h_0 = d = Z(t) + sum_i q_i`, nm.
    fn switching(&self, _k: usize, t: f64, x: &[f64]) -> f64 {
        self.gap(t, x)
    }

    /// `dh_0/dt = Z'(t) + sum_i q_i'` (the same in both modes), nm/us.
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        self.gap_rate(x)
    }

    /// `grad h_0` = 1 on every `q_i`, 0 on every `q_i'`; `dh/dt|_x = Z'(t)`; `dh/dZ = 1`.
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        gradient: &mut [f64],
    ) -> SwitchingPartials {
        for (i, g) in gradient.iter_mut().enumerate() {
            *g = if i % 2 == 0 { 1.0 } else { 0.0 };
        }
        SwitchingPartials {
            t: self.separation.rate(),
            p: 1.0,
        }
    }

    /// The free flight's closed-form flow, the contact's Taylor series, and the gap's shape
    /// (affine; its curvature bounded in free flight; a half-power surface in contact).
    fn accelerations(&self) -> Accelerations<'_> {
        Accelerations {
            exact_flow: Some(self),
            taylor: Some(self),
            switching: Some(self),
        }
    }
}
