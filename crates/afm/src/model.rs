//! The tapping cantilever of Eq. 1 as a hybrid system: free flight (exact flow) and Hertz
//! contact (integrated), separated by the surface `d = 0`.

use std::f64::consts::PI;

use hybrid::{
    ClockPolynomial, HybridSystem, LinearisationBuffers, Mode, SwitchingPartials, TaylorSeries,
};
use nalgebra::DMatrix;

use crate::case::check_case_numbers;
use crate::contact_series;
use crate::free_flight::DrivenOscillator;
use crate::phase;
use crate::validation::invalid;
use crate::{AfmError, Cantilever, Case, Drive, FreeResponse, HertzContact, Sample, Separation};

/// The mode in which the tip is free (`d >= 0`): exact flow.
pub const FREE_FLIGHT: Mode = 0;
/// The mode in which the tip indents the sample (`d < 0`): Hertz force, integrated.
pub const CONTACT: Mode = 1;
/// The index of the contact switching surface `h_0 = d`.
pub const GAP_SURFACE: usize = 0;

/// The constants of one line of Eq. 1 in internal units.
#[derive(Debug, Clone)]
pub(crate) struct ModalConstants {
    /// `w_i^2`, 1/us^2.
    pub(crate) omega_squared: f64,
    /// `w_i^2 / k_i`, (1/us^2)(nm/nN).
    pub(crate) omega_squared_over_stiffness: f64,
    /// `w_i / Q_i`, 1/us.
    pub(crate) damping: f64,
    /// `w_i^2 F_i / k_i`, nm/us^2.
    pub(crate) drive_acceleration: f64,
    /// `chi_i`.
    optical_sensitivity: f64,
    /// The free-flight flow of this mode.
    oscillator: DrivenOscillator,
    /// Its homogeneous transition over the standard exact step (`exact_step_limit`) and over
    /// that step's grid spacings (`grid_transitions[c - 1]` for the spacing
    /// `exact_step_limit / c`): computed once, the same numbers the oscillator gives per call.
    step_transition: [[f64; 2]; 2],
    grid_transitions: [[[f64; 2]; 2]; KEPT_GRIDS],
}

/// The grid counts `c = 1..=KEPT_GRIDS` over the standard exact step whose spacings'
/// transitions are kept: the solver asks [`HybridSystem::exact_flow_grid`] for
/// `samples_per_step + 1` intervals (9 with its default, 5 in a sweep), so any
/// `samples_per_step` up to 15 is served without recomputing them.
const KEPT_GRIDS: usize = 16;

/// The spacing of a grid of `count` intervals over `dt`, us (one expression for the kept and
/// the computed transitions, so that they agree bit for bit).
fn grid_spacing(dt: f64, count: usize) -> f64 {
    dt / count as f64
}

/// The N-mode tapping cantilever of Eq. 1 (MODEL.md section 1) as a [`HybridSystem`].
///
/// State `x = [q_1, q_1', ..., q_N, q_N']` (nm, nm/us), time in us, `t = 0` at a zero of the
/// drive phase. One switching surface `h_0 = d = Z(t) + sum_i q_i` (the gap, nm); mode
/// [`FREE_FLIGHT`] (`d >= 0`, exact flow) and [`CONTACT`] (`d < 0`, Hertz force
/// `F_ts = c max(-d, 0)^{3/2}`, integrated). The system's parameter is the separation `Z`.
#[derive(Debug, Clone)]
pub struct TappingModel {
    cantilever: Cantilever,
    sample: Sample,
    hertz: HertzContact,
    drive: Drive,
    free_amplitude_nm: f64,
    free_response: FreeResponse,
    grazing_separation_nm: f64,
    separation: Separation,
    modes: Vec<ModalConstants>,
    exact_step_limit: f64,
    /// `(sin, cos)` of the drive phase advance over the spacing `exact_step_limit / c` at index
    /// `c - 1`.
    grid_rotations: [(f64, f64); KEPT_GRIDS],
}

impl TappingModel {
    /// The model of `cantilever` tapping `sample`, driven at `drive_frequency_khz` (`None`:
    /// the fundamental `f_1`) with `F_1` chosen so the free amplitude of `u` is
    /// `free_amplitude_nm` (MODEL.md section 3), at separation `separation`.
    ///
    /// Validates every input (errors name the cantilever or sample and the field).
    pub fn new(
        cantilever: Cantilever,
        sample: Sample,
        free_amplitude_nm: f64,
        drive_frequency_khz: Option<f64>,
        separation: Separation,
    ) -> Result<Self, AfmError> {
        cantilever.validate(&format!("cantilever `{}`", cantilever.name))?;
        sample.validate(&format!("sample `{}`", sample.name))?;
        check_case_numbers("model parameters", free_amplitude_nm, drive_frequency_khz)?;
        check_separation(&separation)?;
        let frequency_khz =
            drive_frequency_khz.unwrap_or_else(|| cantilever.fundamental_frequency_khz());
        let (lowest, highest) = cantilever.drive_frequency_range_khz();
        if !(lowest..=highest).contains(&frequency_khz) {
            return Err(invalid(
                "model parameters",
                "drive_frequency_khz",
                frequency_khz,
                format!(
                    "[{lowest:.6}, {highest:.6}] kHz (from f_1/100 to 100 times the highest modal frequency)"
                ),
            ));
        }
        let drive = Drive::for_free_amplitude(&cantilever, free_amplitude_nm, frequency_khz)?;
        let free_response = FreeResponse::new(&cantilever, &drive);
        let grazing_separation_nm = free_response.grazing_separation_nm();
        // A quarter of the shortest period present: the undamped modal periods (each no longer
        // than the damped one) and the drive period.
        let shortest_period = cantilever
            .modes
            .iter()
            .map(|mode| 2.0 * PI / mode.angular_frequency())
            .fold(drive.period_us(), f64::min);
        let exact_step_limit = 0.25 * shortest_period;
        let modes: Vec<ModalConstants> = cantilever
            .modes
            .iter()
            .map(|mode| {
                let omega = mode.angular_frequency();
                let static_deflection = mode.force_ratio * drive.force_nn / mode.stiffness_n_per_m;
                let oscillator = DrivenOscillator::new(
                    omega,
                    mode.quality_factor,
                    static_deflection,
                    drive.angular_frequency,
                );
                ModalConstants {
                    omega_squared: omega * omega,
                    omega_squared_over_stiffness: omega * omega / mode.stiffness_n_per_m,
                    damping: omega / mode.quality_factor,
                    drive_acceleration: omega * omega * static_deflection,
                    optical_sensitivity: mode.optical_sensitivity,
                    step_transition: oscillator.homogeneous_transition(exact_step_limit),
                    grid_transitions: std::array::from_fn(|i| {
                        oscillator.homogeneous_transition(grid_spacing(exact_step_limit, i + 1))
                    }),
                    oscillator,
                }
            })
            .collect();
        let grid_rotations = std::array::from_fn(|i| {
            phase::sin_cos(drive.angular_frequency * grid_spacing(exact_step_limit, i + 1))
        });
        Ok(Self {
            hertz: HertzContact::new(&cantilever, &sample),
            cantilever,
            sample,
            drive,
            free_amplitude_nm,
            free_response,
            grazing_separation_nm,
            separation,
            modes,
            exact_step_limit,
            grid_rotations,
        })
    }

    /// The model of a resolved [`Case`] at separation `Z = Z_G1` (first contact); change it
    /// with [`TappingModel::set_separation`].
    pub fn from_case(case: &Case) -> Result<Self, AfmError> {
        let mut model = Self::new(
            case.cantilever.clone(),
            case.sample.clone(),
            case.free_amplitude_nm,
            case.drive_frequency_khz,
            Separation::Constant(0.0),
        )?;
        model.separation = Separation::Constant(model.grazing_separation_nm);
        Ok(model)
    }

    /// The cantilever.
    pub fn cantilever(&self) -> &Cantilever {
        &self.cantilever
    }

    /// The sample.
    pub fn sample(&self) -> &Sample {
        &self.sample
    }

    /// The Hertz contact law (MODEL.md section 1).
    pub fn hertz(&self) -> &HertzContact {
        &self.hertz
    }

    /// The drive (frequency, `w`, `F_1`).
    pub fn drive(&self) -> &Drive {
        &self.drive
    }

    /// Number of eigenmodes N (the state has dimension 2N).
    pub fn mode_count(&self) -> usize {
        self.modes.len()
    }

    /// Drive angular frequency `w`, rad/us.
    pub fn drive_angular_frequency(&self) -> f64 {
        self.drive.angular_frequency
    }

    /// Drive frequency, kHz.
    pub fn drive_frequency_khz(&self) -> f64 {
        self.drive.frequency_khz
    }

    /// Drive period `T = 2 pi / w`, us.
    pub fn period_us(&self) -> f64 {
        self.drive.period_us()
    }

    /// The free amplitude `A0` of `u`, nm (MODEL.md section 3).
    pub fn free_amplitude_nm(&self) -> f64 {
        self.free_amplitude_nm
    }

    /// The drive force amplitude `F_1` of mode 1, nN.
    pub fn drive_force_nn(&self) -> f64 {
        self.drive.force_nn
    }

    /// The separation of first contact `Z_G1` (the free orbit's lowest gap is zero), nm.
    pub fn grazing_separation_nm(&self) -> f64 {
        self.grazing_separation_nm
    }

    /// The free steady orbit in closed form.
    pub fn free_response(&self) -> &FreeResponse {
        &self.free_response
    }

    /// The free steady orbit's phase of `u`, degrees (MODEL.md section 4).
    pub fn free_phase_deg(&self) -> f64 {
        self.free_response.phase_deg()
    }

    /// The free steady orbit's state at `t = 0` (length 2N; nm, nm/us).
    pub fn free_state(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.dim()];
        self.free_response.state_at(0.0, &mut x);
        x
    }

    /// The separation law `Z(t)`.
    pub fn separation(&self) -> Separation {
        self.separation
    }

    /// Replace the separation law. Fails if it is not finite.
    pub fn set_separation(&mut self, separation: Separation) -> Result<(), AfmError> {
        check_separation(&separation)?;
        self.separation = separation;
        Ok(())
    }

    /// Eq. 1's field given the drive factor `cos(w t)` and the Hertz force `F_ts` (nN):
    /// `q_i' = v_i`, `q_i'' = (w_i^2/k_i) (F_i cos(w t) + F_ts) - w_i^2 q_i - (w_i/Q_i) v_i`
    /// (nm/us, nm/us^2), written into `dxdt`.
    #[inline]
    fn modal_field(&self, drive: f64, force: f64, x: &[f64], dxdt: &mut [f64]) {
        for ((m, state), rate) in self
            .modes
            .iter()
            .zip(x.chunks_exact(2))
            .zip(dxdt.chunks_exact_mut(2))
        {
            let (q, v) = (state[0], state[1]);
            rate[0] = v;
            rate[1] = m.drive_acceleration * drive + m.omega_squared_over_stiffness * force
                - m.omega_squared * q
                - m.damping * v;
        }
    }

    /// The field's Jacobian `df/dx` given the Hertz force's slope `F_ts'(d)` (nN/nm; 0 in free
    /// flight), into the column-major `2N x 2N` `matrix` (entry `(r, c)` at `r + 2N c`).
    #[inline]
    fn modal_jacobian(&self, slope: f64, matrix: &mut [f64]) {
        let n = 2 * self.modes.len();
        matrix.fill(0.0);
        for (i, m) in self.modes.iter().enumerate() {
            matrix[2 * i + n * (2 * i + 1)] = 1.0;
            matrix[2 * i + 1 + n * (2 * i)] = -m.omega_squared;
            matrix[2 * i + 1 + n * (2 * i + 1)] = -m.damping;
            if slope != 0.0 {
                let coupling = m.omega_squared_over_stiffness * slope;
                for j in 0..self.modes.len() {
                    matrix[2 * i + 1 + n * (2 * j)] += coupling;
                }
            }
        }
    }

    /// The Hertz force `F_ts = c s^{3/2}` (nN) and its slope `F_ts'(d) = -1.5 c s^{1/2}`
    /// (nN/nm), `s = max(-d, 0)`, from one square root; both 0 in free flight.
    #[inline]
    fn force_and_slope(&self, mode: Mode, t: f64, x: &[f64]) -> (f64, f64) {
        if Self::in_contact(mode) {
            let indentation = (-self.gap(t, x)).max(0.0);
            let root = indentation.sqrt();
            let c = self.hertz.coefficient;
            (c * indentation * root, -1.5 * c * root)
        } else {
            (0.0, 0.0)
        }
    }

    /// `J v` for every column `v` of `tangents` (column-major, `2N` rows) into `rates`, given
    /// the Hertz slope `F_ts'(d)` (nN/nm); with `parameter_column`, the last column also gets
    /// `df/dZ`. See `variational_field` in the `HybridSystem` implementation. One body for any
    /// number of modes, called with the common counts as constants (unrolled loops).
    #[inline]
    fn modal_tangent_rates(
        &self,
        slope: f64,
        tangents: &[f64],
        rates: &mut [f64],
        parameter_column: bool,
    ) {
        // The common mode counts as constants, so that the loops unroll.
        match self.modes.len() {
            1 => self.tangent_rates_with(1, slope, tangents, rates, parameter_column),
            2 => self.tangent_rates_with(2, slope, tangents, rates, parameter_column),
            3 => self.tangent_rates_with(3, slope, tangents, rates, parameter_column),
            4 => self.tangent_rates_with(4, slope, tangents, rates, parameter_column),
            count => self.tangent_rates_with(count, slope, tangents, rates, parameter_column),
        }
    }

    /// [`Self::modal_tangent_rates`] over the first `count` modes (all of them), inlined into
    /// each call so that a constant `count` unrolls it.
    #[inline(always)]
    fn tangent_rates_with(
        &self,
        count: usize,
        slope: f64,
        tangents: &[f64],
        rates: &mut [f64],
        parameter_column: bool,
    ) {
        let modes = &self.modes[..count];
        let n = 2 * count;
        let columns = tangents.len() / n;
        for (c, (v, rate)) in tangents
            .chunks_exact(n)
            .zip(rates.chunks_exact_mut(n))
            .enumerate()
        {
            // The gap's change along this column: the sum of the modal displacements (+1 on
            // the parameter column, `dd/dZ = 1`).
            let mut gap_change = if parameter_column && c + 1 == columns {
                1.0
            } else {
                0.0
            };
            for i in 0..count {
                gap_change += v[2 * i];
            }
            for (i, m) in modes.iter().enumerate() {
                rate[2 * i] = v[2 * i + 1];
                rate[2 * i + 1] = m.omega_squared_over_stiffness * slope * gap_change
                    - m.omega_squared * v[2 * i]
                    - m.damping * v[2 * i + 1];
            }
        }
    }

    /// The field's derivative with respect to the separation, `df/dZ = (w_i^2/k_i) F_ts'(d)`
    /// on every acceleration component, given the slope `F_ts'(d)` (nN/nm), into `dfdp`.
    #[inline]
    fn separation_derivative(&self, slope: f64, dfdp: &mut [f64]) {
        dfdp.fill(0.0);
        if slope != 0.0 {
            for (i, m) in self.modes.iter().enumerate() {
                dfdp[2 * i + 1] = m.omega_squared_over_stiffness * slope;
            }
        }
    }

    /// The tip-sample gap `d = Z(t) + sum_i q_i`, nm.
    #[inline]
    pub fn gap(&self, t: f64, x: &[f64]) -> f64 {
        self.separation.at(t)
            + x[..2 * self.modes.len()]
                .chunks_exact(2)
                .map(|mode| mode[0])
                .sum::<f64>()
    }

    /// The gap's rate `d' = Z'(t) + sum_i q_i'`, nm/us.
    #[inline]
    pub fn gap_rate(&self, x: &[f64]) -> f64 {
        self.separation.rate()
            + x[..2 * self.modes.len()]
                .chunks_exact(2)
                .map(|mode| mode[1])
                .sum::<f64>()
    }

    /// The tip-sample force `F_ts(d)`, nN (repulsive positive).
    #[inline]
    pub fn tip_sample_force(&self, t: f64, x: &[f64]) -> f64 {
        self.hertz.force(self.gap(t, x))
    }

    /// The photodiode signal `u = sum_i chi_i q_i`, nm.
    #[inline]
    pub fn photodiode(&self, x: &[f64]) -> f64 {
        self.modes
            .iter()
            .zip(x.chunks_exact(2))
            .map(|(mode, state)| mode.optical_sensitivity * state[0])
            .sum()
    }

    fn in_contact(mode: Mode) -> bool {
        mode & CONTACT != 0
    }
}

fn check_separation(separation: &Separation) -> Result<(), AfmError> {
    if separation.is_finite() {
        Ok(())
    } else {
        Err(invalid(
            "model parameters",
            "separation",
            separation.at(0.0),
            "finite numbers (nm, nm/us)".to_string(),
        ))
    }
}

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

    /// In contact the Hertz force is `c (-d)^{3/2}`: the gap is the half-power surface of
    /// the contact mode, and the solver integrates next to contact onset and release in the
    /// square root of the time from them.
    fn half_power_surface(&self, mode: Mode) -> Option<usize> {
        Self::in_contact(mode).then_some(0)
    }

    /// `h_0 = d = Z(t) + sum_i q_i`, nm.
    fn switching(&self, _k: usize, t: f64, x: &[f64]) -> f64 {
        self.gap(t, x)
    }

    /// `dh_0/dt = Z'(t) + sum_i q_i'` (the same in both modes), nm/us.
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        self.gap_rate(x)
    }

    /// The gap `Z(t) + sum_i q_i` is affine: `Z(t)` is a constant or a linear ramp.
    fn switching_is_affine(&self, _k: usize) -> bool {
        true
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

    /// In contact, 40: the contact flow's Taylor series come from the recurrences of automatic
    /// differentiation (module `contact_series`), whose intermediate series live on the stack.
    fn taylor_order_limit(&self, mode: Mode) -> usize {
        if Self::in_contact(mode) {
            contact_series::MAX_ORDER
        } else {
            0
        }
    }

    /// In contact, the series of Eq. 1 with the Hertz force in the step's clock (module
    /// `contact_series`); `false` in free flight (which has its exact flow).
    fn taylor_series(
        &self,
        mode: Mode,
        clock: &ClockPolynomial,
        series: &mut TaylorSeries,
    ) -> bool {
        Self::in_contact(mode)
            && contact_series::contact_state_series(
                &self.modes,
                self.hertz.coefficient,
                self.drive.angular_frequency,
                &self.separation,
                clock,
                series,
            )
    }

    /// In contact, the series of the variational equations along the contact series (module
    /// `contact_series`).
    fn taylor_tangents(
        &self,
        mode: Mode,
        clock: &ClockPolynomial,
        state: &TaylorSeries,
        tangents: &mut TaylorSeries,
        parameter_column: bool,
        scratch: &mut Vec<f64>,
    ) {
        if Self::in_contact(mode) {
            contact_series::contact_tangent_series(
                &self.modes,
                self.hertz.coefficient,
                &self.separation,
                clock,
                state,
                tangents,
                parameter_column,
                scratch,
            );
        }
    }

    fn has_exact_flow(&self, mode: Mode) -> bool {
        mode == FREE_FLIGHT
    }

    /// A quarter of the shortest of the drive period and the modal periods `2 pi / w_i`, us.
    fn exact_step_limit(&self, mode: Mode) -> f64 {
        if mode == FREE_FLIGHT {
            self.exact_step_limit
        } else {
            f64::INFINITY
        }
    }

    /// In free flight, a bound on the gap's curvature `|d''| = |Z'' + sum_i q_i''|` over
    /// `[t0, t0 + dt]` (any `dt`), nm/us^2; `Z'' = 0` for both separation laws. Each mode is its
    /// steady drive response `p_i = alpha_i cos(w t) + beta_i sin(w t)` plus a homogeneous part
    /// `y_i` (Eq. 1 with `F_ts = 0`), so `|q_i''| <= w^2 P_i + (w_i + w_i/Q_i) r_i` with
    /// `P_i = hypot(alpha_i, beta_i)` and `r_i = sqrt(y_i'^2 + w_i^2 y_i^2)`, which the damping
    /// never lets grow (`d(r^2)/dt = -2 (w_i/Q_i) y_i'^2`), taken at `t0`. In contact `None`
    /// (extrema inside the sample, the gap's minima, are always wanted).
    fn switching_curvature_bound(
        &self,
        _k: usize,
        mode: Mode,
        t0: f64,
        x0: &[f64],
        _dt: f64,
    ) -> Option<f64> {
        if Self::in_contact(mode) {
            return None;
        }
        let w = self.drive.angular_frequency;
        let (sin, cos) = phase::sin_cos(w * t0);
        let bound = self
            .modes
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let [p, dp] = m.oscillator.steady_state_at_phase(sin, cos);
                let (y, dy) = (x0[2 * i] - p, x0[2 * i + 1] - dp);
                let [alpha, beta] = m.oscillator.steady_coefficients();
                let steady = w * w * alpha.hypot(beta);
                let homogeneous = (m.omega_squared.sqrt() + m.damping)
                    * (dy * dy + m.omega_squared * y * y).sqrt();
                steady + homogeneous
            })
            .sum::<f64>();
        // Slack for the rounding of the sums (relative 1e-12) and of `y` (absolute).
        bound.is_finite().then_some(bound * (1.0 + 1e-12) + 1e-12)
    }

    /// The free flight at `count` equally spaced times: one homogeneous transition over the
    /// spacing per mode and one rotation of the drive phase, applied `count` times (the
    /// steady part by angle addition), instead of the exponentials and trigonometric
    /// functions of a fresh flow per point. Equal to the direct flow up to rounding growing
    /// with `count` (a few ulps for the solver's 9 points; tested).
    fn exact_flow_grid(
        &self,
        _mode: Mode,
        t0: f64,
        x0: &[f64],
        dt: f64,
        count: usize,
        states: &mut [f64],
    ) {
        let n = self.dim();
        let spacing = grid_spacing(dt, count);
        let w = self.drive.angular_frequency;
        // The index of the kept spacing, for a grid over the standard step.
        let kept =
            (dt == self.exact_step_limit && (1..=KEPT_GRIDS).contains(&count)).then(|| count - 1);
        let (sin0, cos0) = phase::sin_cos(w * t0);
        let (sin_step, cos_step) = match kept {
            Some(c) => self.grid_rotations[c],
            None => phase::sin_cos(w * spacing),
        };
        for (i, m) in self.modes.iter().enumerate() {
            let phi = match kept {
                Some(c) => m.grid_transitions[c],
                None => m.oscillator.homogeneous_transition(spacing),
            };
            let start = m.oscillator.steady_state_at_phase(sin0, cos0);
            let mut y = [x0[2 * i] - start[0], x0[2 * i + 1] - start[1]];
            let (mut sin, mut cos) = (sin0, cos0);
            for j in 0..count {
                y = [
                    phi[0][0] * y[0] + phi[0][1] * y[1],
                    phi[1][0] * y[0] + phi[1][1] * y[1],
                ];
                (sin, cos) = (
                    sin * cos_step + cos * sin_step,
                    cos * cos_step - sin * sin_step,
                );
                let steady = m.oscillator.steady_state_at_phase(sin, cos);
                states[j * n + 2 * i] = steady[0] + y[0];
                states[j * n + 2 * i + 1] = steady[1] + y[1];
            }
        }
    }

    /// The free flight's closed-form flow (block diagonal, one [`DrivenOscillator`] per mode);
    /// it does not depend on `Z`, so `dx/dZ = 0`.
    fn exact_flow(
        &self,
        _mode: Mode,
        t0: f64,
        x0: &[f64],
        dt: f64,
        x: &mut [f64],
        mut transition: Option<&mut DMatrix<f64>>,
        dxdp: Option<&mut [f64]>,
    ) {
        if let Some(matrix) = transition.as_deref_mut() {
            matrix.fill(0.0);
        }
        let start_phase = phase::sin_cos(self.drive.angular_frequency * t0);
        let end_phase = phase::sin_cos(self.drive.angular_frequency * (t0 + dt));
        let standard = dt == self.exact_step_limit;
        for (i, m) in self.modes.iter().enumerate() {
            let phi = if standard {
                m.step_transition
            } else {
                m.oscillator.homogeneous_transition(dt)
            };
            let state = m.oscillator.flow_with_transition(
                start_phase,
                end_phase,
                [x0[2 * i], x0[2 * i + 1]],
                &phi,
            );
            x[2 * i] = state[0];
            x[2 * i + 1] = state[1];
            if let Some(matrix) = transition.as_deref_mut() {
                for r in 0..2 {
                    for c in 0..2 {
                        matrix[(2 * i + r, 2 * i + c)] = phi[r][c];
                    }
                }
            }
        }
        if let Some(dxdp) = dxdp {
            dxdp.fill(0.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin_case;

    /// The fused `linearisation` is a performance override: it must give exactly (bit for bit:
    /// the same expressions in the same order) what the three separate calls give, in contact
    /// (at several indentations), at the surface and in free flight.
    #[test]
    fn linearisation_matches_the_separate_calls() {
        let case = builtin_case("biolever-mica").expect("built-in case");
        let model = TappingModel::from_case(&case).expect("model");
        let n = model.dim();
        for (mode, shift) in [
            (CONTACT, -0.3),
            (CONTACT, -1e-6),
            (CONTACT, 0.0),
            (CONTACT, 0.2),
            (FREE_FLIGHT, -0.3),
            (FREE_FLIGHT, 0.5),
        ] {
            let t = 0.37;
            let mut x: Vec<f64> = (0..n).map(|i| 0.1 * (i as f64 + 1.0)).collect();
            // Place the gap at `shift` nm.
            x[0] += shift - model.gap(t, &x);
            let (mut f1, mut f2) = (vec![0.0; n], vec![0.0; n]);
            let (mut j1, mut j2) = (DMatrix::zeros(n, n), DMatrix::from_element(n, n, 7.0));
            let (mut p1, mut p2) = (vec![0.0; n], vec![3.0; n]);
            model.vector_field(mode, t, &x, &mut f1);
            model.jacobian(mode, t, &x, &mut j1);
            model.parameter_derivative(mode, t, &x, &mut p1);
            model.linearisation(mode, t, &x, &mut f2, &mut j2, Some(&mut p2));
            assert_eq!(f1, f2, "field, mode {mode}, gap {shift}");
            assert_eq!(j1, j2, "Jacobian, mode {mode}, gap {shift}");
            assert_eq!(p1, p2, "df/dZ, mode {mode}, gap {shift}");
        }
    }

    /// The transitions and drive rotations kept for the standard exact step and its grid
    /// spacings (every kept count) are the numbers the oscillators compute per call: the flow
    /// and grids over the standard step are bit for bit those over a step computed afresh (the
    /// same expressions on the same inputs).
    #[test]
    fn kept_standard_step_transitions_equal_fresh_ones() {
        for name in ["biolever-mica", "maclever-soft"] {
            let case = builtin_case(name).expect("built-in case");
            let model = TappingModel::from_case(&case).expect("model");
            let n = model.dim();
            let dt = model.exact_step_limit(FREE_FLIGHT);
            let x0: Vec<f64> = (0..n).map(|i| 3.0 - 0.7 * i as f64).collect();
            let t0 = 5.678;
            let mut kept = vec![0.0; n];
            let mut transition = DMatrix::zeros(n, n);
            model.exact_flow(
                FREE_FLIGHT,
                t0,
                &x0,
                dt,
                &mut kept,
                Some(&mut transition),
                None,
            );
            let w = model.drive.angular_frequency;
            for count in 1..=KEPT_GRIDS {
                let spacing = dt / count as f64;
                assert_eq!(
                    model.grid_rotations[count - 1],
                    phase::sin_cos(w * spacing),
                    "{name}, {count} intervals"
                );
                for m in &model.modes {
                    assert_eq!(
                        m.grid_transitions[count - 1],
                        m.oscillator.homogeneous_transition(spacing),
                        "{name}, {count} intervals"
                    );
                }
            }
            for (i, m) in model.modes.iter().enumerate() {
                assert_eq!(m.step_transition, m.oscillator.homogeneous_transition(dt));
                let (fresh, phi) = m.oscillator.flow(t0, [x0[2 * i], x0[2 * i + 1]], dt);
                assert_eq!([kept[2 * i], kept[2 * i + 1]], fresh, "{name} mode {i}");
                assert_eq!(transition[(2 * i, 2 * i + 1)], phi[0][1], "{name} mode {i}");
            }
        }
    }

    /// The grid of free-flight states by recurrence agrees with the direct closed-form flow
    /// at every point: to 1e-13 relative to the largest component (rounding of ~10 products per
    /// point accumulated over at most 16 points is ~1e-14; the trigonometric and exponential
    /// functions of the direct flow are each within an ulp; measured 2e-16..5e-16), over a quarter of the shortest
    /// period (the solver's exact step) and over a whole drive period.
    #[test]
    fn exact_flow_grid_matches_the_direct_flow() {
        for name in ["biolever-mica", "maclever-soft"] {
            let case = builtin_case(name).expect("built-in case");
            let model = TappingModel::from_case(&case).expect("model");
            let n = model.dim();
            let x0: Vec<f64> = (0..n).map(|i| 3.0 - 0.7 * i as f64).collect();
            for (dt, count) in [
                (model.exact_step_limit(FREE_FLIGHT), 9),
                (model.period_us(), 16),
            ] {
                let t0 = 1.234;
                let mut grid = vec![0.0; count * n];
                model.exact_flow_grid(FREE_FLIGHT, t0, &x0, dt, count, &mut grid);
                let mut direct = vec![0.0; count * n];
                for j in 1..=count {
                    let tau = dt * (j as f64 / count as f64);
                    let out = &mut direct[(j - 1) * n..j * n];
                    model.exact_flow(FREE_FLIGHT, t0, &x0, tau, out, None, None);
                }
                // The scale: the largest state component on the grid.
                let scale = direct.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                let mut worst = 0.0f64;
                for j in 1..=count {
                    for c in 0..n {
                        let e = (grid[(j - 1) * n + c] - direct[(j - 1) * n + c]).abs();
                        worst = worst.max(e / scale);
                    }
                }
                eprintln!("{name}: {count} points over {dt} us: worst relative error {worst:e}");
                assert!(worst < 1e-13, "{name}: {worst:e}");
            }
        }
    }

    /// The free flight's curvature bound holds: the largest `|d''|` seen on a fine sampling of
    /// the exact flow (`d'' = sum_i q_i''` from the vector field with `F_ts = 0`) never exceeds
    /// it, for the free steady state, a state with the second mode ringing (as after an impact),
    /// a state at rest, and states with large velocities, over one exact step and over a whole
    /// period, with a constant and a moving separation; and it is tight (within a factor 1.5 of
    /// the maximum over a period of the free orbit, `w^2 |sum_i P_i e^{i phi_i}|`). In contact
    /// there is no bound.
    #[test]
    fn free_flight_curvature_bound_holds() {
        for name in ["biolever-mica", "maclever-soft"] {
            let case = builtin_case(name).expect("built-in case");
            let mut model = TappingModel::from_case(&case).expect("model");
            let n = model.dim();
            let free = model.free_state();
            let mut ringing = free.clone();
            ringing[2] += 2.0;
            ringing[3] -= 1.5;
            let rest = vec![0.0; n];
            let fast: Vec<f64> = (0..n).map(|i| 5.0 * (-1.0f64).powi(i as i32)).collect();
            for separation in [
                Separation::Constant(3.0),
                Separation::Ramp {
                    z0_nm: 3.0,
                    rate_nm_per_us: 1e-3,
                },
            ] {
                model.set_separation(separation).expect("finite");
                for (label, x0) in [
                    ("free", &free),
                    ("ringing", &ringing),
                    ("rest", &rest),
                    ("fast", &fast),
                ] {
                    for dt in [model.exact_step_limit(FREE_FLIGHT), model.period_us()] {
                        let t0 = 0.37;
                        let bound = model
                            .switching_curvature_bound(GAP_SURFACE, FREE_FLIGHT, t0, x0, dt)
                            .expect("a bound in free flight");
                        let (mut x, mut f) = (vec![0.0; n], vec![0.0; n]);
                        let mut seen = 0.0f64;
                        for j in 0..=2000 {
                            let tau = dt * j as f64 / 2000.0;
                            model.exact_flow(FREE_FLIGHT, t0, x0, tau, &mut x, None, None);
                            model.vector_field(FREE_FLIGHT, t0 + tau, &x, &mut f);
                            let curvature: f64 = (0..n / 2).map(|i| f[2 * i + 1]).sum();
                            seen = seen.max(curvature.abs());
                        }
                        assert!(seen <= bound, "{name} {label} dt {dt}: {seen} > {bound}");
                        if label == "free" && dt == model.period_us() {
                            assert!(bound < 1.5 * seen, "{name}: {bound} vs {seen}");
                        }
                    }
                }
            }
            assert!(model
                .switching_curvature_bound(GAP_SURFACE, CONTACT, 0.0, &free, 1.0)
                .is_none());
        }
    }
}
