//! The constants of one line of Eq. 1 (MODEL.md section 1) in internal units, and the free
//! flight's homogeneous transitions kept for the exact steps, per mode.

use crate::model::drive::Drive;
use crate::model::eigenmode::Eigenmode;
use crate::model::free_flight::DrivenOscillator;

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
    pub(crate) optical_sensitivity: f64,
    /// The free-flight flow of this mode.
    pub(crate) oscillator: DrivenOscillator,
    /// Its homogeneous transition over the standard exact step (`exact_step_limit`) and over
    /// that step's grid spacings (`grid_transitions[c - 1]` for the spacing
    /// `exact_step_limit / c`): computed once, the same numbers the oscillator gives per call.
    pub(crate) step_transition: [[f64; 2]; 2],
    pub(crate) grid_transitions: [[[f64; 2]; 2]; KEPT_GRIDS],
    /// `w^2 P_i = w^2 hypot(alpha_i, beta_i)`, nm/us^2: the bound on the steady free
    /// response's `|q_p''|` under the drive `w` (of `TappingModel::switching_curvature_bound`,
    /// computed once, the same number).
    pub(crate) steady_curvature: f64,
    /// `sqrt(w_i^2) + w_i/Q_i`, 1/us: the rate that bounds the homogeneous part's `|y''|` from
    /// its energy (of `TappingModel::switching_curvature_bound`, computed once).
    pub(crate) homogeneous_rate: f64,
}

impl ModalConstants {
    /// The static deflection `F / k_i` (nm) of this mode under a constant tip-sample force `F`
    /// (nN): Eq. 1's particular solution for it, `(w_i^2 / k_i) F / w_i^2`, the offset of the
    /// rest position about which an exact flow under a constant force runs.
    #[inline]
    pub(crate) fn static_offset(&self, force_nn: f64) -> f64 {
        self.omega_squared_over_stiffness * force_nn / self.omega_squared
    }

    /// The constants of `mode` under `drive` (`F_i = r_i F_1`, MODEL.md section 3), with its
    /// free flight's homogeneous transitions over the standard exact step `exact_step_limit`
    /// (us) and over that step's kept grid spacings.
    pub(crate) fn new(mode: &Eigenmode, drive: &Drive, exact_step_limit: f64) -> Self {
        let omega = mode.angular_frequency();
        let static_deflection = mode.force_ratio * drive.force_nn / mode.stiffness_n_per_m;
        let oscillator = DrivenOscillator::new(
            omega,
            mode.quality_factor,
            static_deflection,
            drive.angular_frequency,
        );
        let w = drive.angular_frequency;
        let [alpha, beta] = oscillator.steady_coefficients();
        let omega_squared = omega * omega;
        let damping = omega / mode.quality_factor;
        Self {
            omega_squared,
            omega_squared_over_stiffness: omega * omega / mode.stiffness_n_per_m,
            damping,
            steady_curvature: w * w * alpha.hypot(beta),
            homogeneous_rate: omega_squared.sqrt() + damping,
            drive_acceleration: omega * omega * static_deflection,
            optical_sensitivity: mode.optical_sensitivity,
            step_transition: oscillator.homogeneous_transition(exact_step_limit),
            grid_transitions: std::array::from_fn(|i| {
                oscillator.homogeneous_transition(grid_spacing(exact_step_limit, i + 1))
            }),
            oscillator,
        }
    }
}

/// The grid counts `c = 1..=KEPT_GRIDS` over the standard exact step whose spacings'
/// transitions are kept: the solver asks [`hybrid::ExactFlow::exact_flow_grid`] for
/// `samples_per_step + 1` intervals (9 with its default, 5 in a sweep), so any
/// `samples_per_step` up to 15 is served without recomputing them.
pub(crate) const KEPT_GRIDS: usize = 16;

/// The spacing of a grid of `count` intervals over `dt`, us (one expression for the kept and
/// the computed transitions, so that they agree bit for bit).
pub(crate) fn grid_spacing(dt: f64, count: usize) -> f64 {
    dt / count as f64
}
