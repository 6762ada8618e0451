//! The tapping cantilever of Eq. 1 as a hybrid system: free flight (exact flow where no force
//! acts outside contact) and contact (integrated), separated by the contact surface `d = d_c`
//! of the sample's contact law (MODEL.md sections 1 and 9).

use std::f64::consts::PI;

use hybrid::{HybridSystem, Mode};

mod accelerations;
pub mod base_motion;
pub mod cantilever;
pub mod case;
pub mod commensurate;
pub(crate) mod contact_series;
#[cfg(test)]
mod contact_series_tests;
pub mod drive;
pub mod drive_spec;
pub mod eigenmode;
pub mod film_validity;
pub mod free_flight;
pub mod free_flight_energy;
pub mod free_flight_fourier;
pub mod free_response;
pub mod hertz_contact;
mod hybrid_system;
pub(crate) mod modal_constants;
pub mod phase;
pub(crate) mod relaxing_series;
pub mod sample;
mod sample_relaxation;
pub mod second_drive;
pub mod separation;
#[cfg(test)]
mod tests;
pub mod trigonometric;

use crate::contact::spec::tip_sample_force;
use crate::contact::{ContactLaw, ForceSlopes, HertzShape, HertzTip, TipSampleForce};
use crate::error::AfmError;
use crate::model::base_motion::{
    acoustic_cantilever, beam_participation, inertial_force_per_nm, BaseMotion,
};
use crate::model::cantilever::Cantilever;
use crate::model::case::check_case_numbers;
use crate::model::case::Case;
use crate::model::drive::Drive;
use crate::model::drive_spec::{bimodal_ratio, DriveSpec};
use crate::model::free_response::FreeResponse;
use crate::model::hertz_contact::effective_modulus_gpa;
use crate::model::hertz_contact::HertzContact;
use crate::model::modal_constants::{grid_spacing, ModalConstants, KEPT_GRIDS};
use crate::model::sample::Sample;
use crate::model::second_drive::SecondDrive;
use crate::model::separation::Separation;
use crate::validation::invalid;

/// The mode in which the tip is free (`d >= d_c`): exact flow where no force acts outside
/// contact.
pub const FREE_FLIGHT: Mode = 0;
/// The mode bit set while the tip indents the sample (`d < d_c`): contact force, integrated.
pub const CONTACT: Mode = 1;
/// The mode bit set on the side `h_1 < 0` of a clipped Kelvin-Voigt law's release surface,
/// where the contact force is clipped to zero (MODEL.md section 9).
pub const CLIPPED: Mode = 2;
/// The mode bit set while a hysteretic law (JKR, the capillary meniscus) is attached: from the
/// `Down` crossing of the contact surface to the `Up` crossing of its release surface
/// [`PULL_OFF_SURFACE`] (MODEL.md section 9). It is no surface's sign: the solver carries it
/// through [`hybrid::HybridSystem::mode_after_crossing`].
pub const ATTACHED: Mode = 4;
/// The index of a hysteretic law's release surface `h_1 = d - d_r` (JKR's pull-off gap, the
/// meniscus's rupture gap; the same index as Kelvin-Voigt's release surface, which no
/// hysteretic law has).
pub const PULL_OFF_SURFACE: usize = 1;
/// The index of the contact switching surface `h_0 = d - d_c`.
pub const GAP_SURFACE: usize = 0;
/// The index of a clipped Kelvin-Voigt law's release surface `h_1 = -d - tau d'`.
pub const RELEASE_SURFACE: usize = 1;

/// The N-mode tapping cantilever of Eq. 1 (MODEL.md section 1) as a [`HybridSystem`].
///
/// State `x = [q_1, q_1', ..., q_N, q_N']` (nm, nm/us), time in us, `t = 0` at a zero of the
/// drive phase. The contact switching surface `h_0 = d - d_c` (`d = Z(t) + sum_i q_i` the gap,
/// nm; `d_c` the law's contact gap, 0 except DMT's `a0`); mode [`FREE_FLIGHT`] (`d >= d_c`)
/// and [`CONTACT`] (`d < d_c`, the contact force, integrated); a clipped Kelvin-Voigt law adds
/// the release surface `h_1` ([`RELEASE_SURFACE`], mode bit [`CLIPPED`]). With the paper's
/// Hertz sphere, `F_ts = c max(-d, 0)^{3/2}`. The system's parameter is the separation `Z`.
#[derive(Debug, Clone)]
pub struct TappingModel {
    cantilever: Cantilever,
    sample: Sample,
    hertz: HertzContact,
    force: TipSampleForce,
    /// Whether the force is the paper's Hertz sphere with nothing added (its fast paths:
    /// Taylor series, half-power surface, exact free flight).
    plain_hertz: bool,
    drive: Drive,
    /// The drive as the case states it (MODEL.md sections 3 and 14).
    drive_spec: DriveSpec,
    /// An acoustic drive's base motion `y_base(t)` (MODEL.md section 14).
    base: Option<BaseMotion>,
    /// A bimodal drive's second drive (MODEL.md section 14).
    second: Option<SecondDrive>,
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
        Self::with_drive(
            cantilever,
            sample,
            free_amplitude_nm,
            drive_frequency_khz,
            &DriveSpec::Direct,
            separation,
        )
    }

    /// As [`TappingModel::new`], with the drive `drive_spec` (MODEL.md section 14): for an
    /// acoustic drive the base amplitude `Y` is solved from `A0` and the model's cantilever
    /// carries the base motion's effective forcing ratios; a bimodal drive adds its second drive
    /// and the model's period becomes the common period `q T`.
    pub fn with_drive(
        cantilever: Cantilever,
        sample: Sample,
        free_amplitude_nm: f64,
        drive_frequency_khz: Option<f64>,
        drive_spec: &DriveSpec,
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
        let drive_file = format!("the drive of cantilever `{}`", cantilever.name);
        drive_spec.validate(&drive_file, &cantilever, frequency_khz)?;
        let (cantilever, base) = match drive_spec {
            DriveSpec::Acoustic { base_participation } => {
                let participation = match base_participation {
                    Some(factors) => factors.clone(),
                    None => beam_participation(&cantilever, &drive_file)?,
                };
                let w = crate::model::eigenmode::angular_frequency_rad_per_us(frequency_khz);
                let acoustic = acoustic_cantilever(&cantilever, &participation, w);
                let per_nm = inertial_force_per_nm(&cantilever, &participation, w)[0];
                (acoustic, Some((participation, w, per_nm)))
            }
            _ => (cantilever, None),
        };
        let drive = Drive::for_free_amplitude(&cantilever, free_amplitude_nm, frequency_khz)?;
        let base = base.map(|(participation, angular_frequency, per_nm)| BaseMotion {
            amplitude_nm: drive.force_nn / per_nm,
            angular_frequency,
            participation,
        });
        let second = match drive_spec {
            DriveSpec::Bimodal {
                second_frequency_khz,
                second_free_amplitude_nm,
            } => Some(SecondDrive::new(
                &cantilever,
                &drive,
                *second_frequency_khz,
                *second_free_amplitude_nm,
                bimodal_ratio(&drive_file, frequency_khz, *second_frequency_khz)?,
            )?),
            _ => None,
        };
        let free_response = FreeResponse::new(&cantilever, &drive)
            .with_base_amplitude(base.as_ref().map_or(0.0, |b| b.amplitude_nm))
            .with_second_drive(second.as_ref());

        // A quarter of the shortest period present: the undamped modal periods (each no longer
        // than the damped one) and the drive periods.
        let shortest_period = cantilever
            .modes
            .iter()
            .map(|mode| 2.0 * PI / mode.angular_frequency())
            .chain(second.as_ref().map(|s| 2.0 * PI / s.angular_frequency))
            .fold(drive.period_us(), f64::min);
        let exact_step_limit = 0.25 * shortest_period;
        let modes: Vec<ModalConstants> = cantilever
            .modes
            .iter()
            .map(|mode| ModalConstants::new(mode, &drive, exact_step_limit))
            .collect();
        let grid_rotations = std::array::from_fn(|i| {
            phase::sin_cos(drive.angular_frequency * grid_spacing(exact_step_limit, i + 1))
        });
        let mut force = tip_sample_force(
            sample.contact.as_ref(),
            sample.electrostatic.as_ref(),
            effective_modulus_gpa(
                sample.youngs_modulus_gpa,
                sample.poisson_ratio,
                cantilever.tip_youngs_modulus_gpa,
                cantilever.tip_poisson_ratio,
            ),
            cantilever.tip_radius_nm,
            sample.poisson_ratio,
        );
        let reduced = |modulus_gpa: f64| {
            effective_modulus_gpa(
                modulus_gpa,
                sample.poisson_ratio,
                cantilever.tip_youngs_modulus_gpa,
                cantilever.tip_poisson_ratio,
            )
        };
        if let (ContactLaw::StandardLinearSolid(sls), Some((instant, relaxed))) = (
            &mut force.law,
            sample.contact.as_ref().and_then(|c| c.sample_moduli_gpa()),
        ) {
            sls.instant_modulus_gpa = reduced(instant);
            sls.relaxed_modulus_gpa = reduced(relaxed);
        }
        force.hydration = sample
            .hydration
            .as_ref()
            .map(|spec| spec.force(cantilever.tip_radius_nm));
        // The free orbit's lowest gap reaches the contact surface `d = d_c`.
        let grazing_separation_nm = free_response.grazing_separation_nm() + force.contact_gap_nm();
        let plain_hertz = matches!(
            force.law,
            ContactLaw::Hertz(HertzShape {
                tip: HertzTip::Sphere { .. },
                ..
            })
        ) && force.double_layer.is_none()
            && force.hydration.is_none();
        Ok(Self {
            hertz: HertzContact::new(&cantilever, &sample),
            force,
            plain_hertz,
            cantilever,
            sample,
            drive,
            drive_spec: drive_spec.clone(),
            base,
            second,
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
        let mut model = Self::with_drive(
            case.cantilever.clone(),
            case.sample.clone(),
            case.free_amplitude_nm,
            case.drive_frequency_khz,
            &case.drive,
            Separation::Constant(0.0),
        )?;
        model.separation = Separation::Constant(model.grazing_separation_nm);
        Ok(model)
    }

    /// The cantilever. Under an acoustic drive its forcing ratios are the base motion's
    /// effective ones, `r_i = k_i gamma_i w_1^2 / (k_1 gamma_1 w_i^2)` (MODEL.md section 14).
    pub fn cantilever(&self) -> &Cantilever {
        &self.cantilever
    }

    /// The sample.
    pub fn sample(&self) -> &Sample {
        &self.sample
    }

    /// The spherical Hertz law of the sample's modulus and the tip's radius (MODEL.md
    /// section 1), whatever the sample's contact law.
    pub fn hertz(&self) -> &HertzContact {
        &self.hertz
    }

    /// The sample's tip-sample force: its contact law and double layer (MODEL.md section 9).
    pub fn contact_force(&self) -> &TipSampleForce {
        &self.force
    }

    /// Whether the force is the paper's Hertz sphere with nothing added (the law with the
    /// Taylor-series path; MODEL.md section 9).
    pub fn is_plain_hertz(&self) -> bool {
        self.plain_hertz
    }

    /// The contact surface's gap `d_c`, nm: `a0` for DMT, 0 otherwise.
    pub fn contact_gap_nm(&self) -> f64 {
        self.force.contact_gap_nm()
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

    /// The orbit's forcing period, us: the drive period `T = 2 pi / w`, or for a bimodal drive
    /// of ratio `p / q` the common period `q T` (MODEL.md section 14). Every "per period"
    /// observable is per this period.
    pub fn period_us(&self) -> f64 {
        self.drive.period_us() * self.periods_per_orbit_period() as f64
    }

    /// The number `q` of first-drive periods in [`TappingModel::period_us`]: 1, or a bimodal
    /// drive's denominator.
    pub fn periods_per_orbit_period(&self) -> u32 {
        self.second.as_ref().map_or(1, |s| s.ratio.denominator)
    }

    /// The drive as the case states it (MODEL.md sections 3 and 14).
    pub fn drive_spec(&self) -> &DriveSpec {
        &self.drive_spec
    }

    /// An acoustic drive's base motion `y_base(t) = Y cos(w t)` (MODEL.md section 14).
    pub fn base_motion(&self) -> Option<&BaseMotion> {
        self.base.as_ref()
    }

    /// A bimodal drive's second drive (MODEL.md section 14).
    pub fn second_drive(&self) -> Option<&SecondDrive> {
        self.second.as_ref()
    }

    /// The drive factor `D(t)` of Eq. 1's forcing `F_i D(t)`: `cos(w t)`, plus
    /// `(F_1b / F_1) cos(w_b t)` under a bimodal drive (MODEL.md section 14).
    #[inline]
    pub fn drive_factor(&self, t: f64) -> f64 {
        let first = phase::cos(self.drive.angular_frequency * t);
        match &self.second {
            None => first,
            Some(second) => {
                first + second.relative_force * phase::cos(second.angular_frequency * t)
            }
        }
    }

    /// The base's displacement `y_base(t)` in the gap, nm: 0 but under an acoustic drive.
    #[inline]
    pub fn base_displacement(&self, t: f64) -> f64 {
        self.base.as_ref().map_or(0.0, |base| base.displacement(t))
    }

    /// The base's velocity `y_base'(t)`, nm/us: 0 but under an acoustic drive.
    #[inline]
    pub fn base_velocity(&self, t: f64) -> f64 {
        self.base.as_ref().map_or(0.0, |base| base.velocity(t))
    }

    /// The free amplitude `A0` of `u`, nm (MODEL.md section 3).
    pub fn free_amplitude_nm(&self) -> f64 {
        self.free_amplitude_nm
    }

    /// The drive force amplitude `F_1` of mode 1, nN.
    pub fn drive_force_nn(&self) -> f64 {
        self.drive.force_nn
    }

    /// The separation of first contact `Z_G1` (the free orbit's lowest gap reaches the contact
    /// surface `d_c`, 0 except for DMT), nm. Where a force acts outside contact (DMT, a double
    /// layer) the free orbit is not force-free and this is the force-free estimate; the
    /// diagram's `G1` locates the true grazing.
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

    /// The field's Jacobian `df/dx` given the force's slopes `dF_ts/dd` (nN/nm) and
    /// `dF_ts/dd'` (nN us/nm; 0 but for a viscous law), into the column-major `2N x 2N`
    /// `matrix` (entry `(r, c)` at `r + 2N c`).
    #[inline]
    fn modal_jacobian(&self, slope: f64, rate_slope: f64, matrix: &mut [f64]) {
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
            if rate_slope != 0.0 {
                let coupling = m.omega_squared_over_stiffness * rate_slope;
                for j in 0..self.modes.len() {
                    matrix[2 * i + 1 + n * (2 * j + 1)] += coupling;
                }
            }
        }
    }

    /// The force of mode `mode` at `(t, x)` with its slopes: for the plain Hertz sphere
    /// `F_ts = c s^{3/2}` (nN) and `F_ts'(d) = -1.5 c s^{1/2}` (nN/nm), `s = max(-d, 0)`, from
    /// one square root, both 0 in free flight; for another law [`TipSampleForce::in_region`]
    /// on the mode's side of each surface.
    #[inline]
    fn force_slopes(&self, mode: Mode, t: f64, x: &[f64]) -> ForceSlopes {
        if !self.plain_hertz {
            return self.force.in_mode(
                Self::in_contact(mode),
                mode & CLIPPED != 0,
                mode & ATTACHED != 0,
                self.gap(t, x),
                self.gap_rate_at(t, x),
                self.sample_state(x),
            );
        }
        let (force, gap_slope) = self.hertz_force_and_slope(mode, t, x);
        ForceSlopes {
            force,
            gap_slope,
            rate_slope: 0.0,
        }
    }

    /// The plain Hertz sphere's force and slope of [`Self::force_slopes`].
    #[inline]
    fn hertz_force_and_slope(&self, mode: Mode, t: f64, x: &[f64]) -> (f64, f64) {
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
            let gap_change = tangent_gap_change(v, count, parameter_column && c + 1 == columns);
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

    /// The tip-sample gap `d = Z(t) + y_base(t) + sum_i q_i`, nm (`y_base = 0` but under an
    /// acoustic drive, MODEL.md section 14).
    #[inline]
    pub fn gap(&self, t: f64, x: &[f64]) -> f64 {
        self.separation.at(t)
            + self.base_displacement(t)
            + x[..2 * self.modes.len()]
                .chunks_exact(2)
                .map(|mode| mode[0])
                .sum::<f64>()
    }

    /// The gap's rate at time `t`, `d' = Z'(t) + y_base'(t) + sum_i q_i'`, nm/us (MODEL.md
    /// section 14).
    #[inline]
    pub fn gap_rate_at(&self, t: f64, x: &[f64]) -> f64 {
        self.gap_rate(x) + self.base_velocity(t)
    }

    /// The gap's rate without the base's motion, `Z'(t) + sum_i q_i'`, nm/us: `d'` but under an
    /// acoustic drive ([`TappingModel::gap_rate_at`]).
    #[inline]
    pub fn gap_rate(&self, x: &[f64]) -> f64 {
        self.separation.rate()
            + x[..2 * self.modes.len()]
                .chunks_exact(2)
                .map(|mode| mode[1])
                .sum::<f64>()
    }

    /// The tip-sample force `F_ts(d, d')`, nN (repulsive positive), on the side of each
    /// surface where the state lies.
    #[inline]
    pub fn tip_sample_force(&self, t: f64, x: &[f64]) -> f64 {
        if self.plain_hertz {
            self.hertz.force(self.gap(t, x))
        } else {
            self.force
                .force_at(self.gap(t, x), self.gap_rate_at(t, x), self.sample_state(x))
        }
    }

    /// The sample's internal state `rho` (nm^{3/2}): the last component of the state for a
    /// standard linear solid (MODEL.md section 9), 0 for every other law.
    #[inline]
    pub fn sample_state(&self, x: &[f64]) -> f64 {
        if self.force.law.standard_linear_solid().is_some() {
            x[2 * self.modes.len()]
        } else {
            0.0
        }
    }

    /// The number of the sample's internal states in the model's state after the `2N` modal
    /// ones: 1 for a standard linear solid, 0 otherwise.
    pub fn sample_state_count(&self) -> usize {
        usize::from(self.force.law.standard_linear_solid().is_some())
    }

    /// The tip-sample force `F_ts(d, d')`, nN, of mode `mode` at `(t, x)`: for a hysteretic law
    /// (JKR, capillary) the attached state is the mode's ([`ATTACHED`]), which the state alone
    /// does not give in the band `d_c <= d < d_r`.
    #[inline]
    pub fn tip_sample_force_in_mode(&self, mode: Mode, t: f64, x: &[f64]) -> f64 {
        if self.force.release_gap_nm().is_some() {
            self.force_slopes(mode, t, x).force
        } else {
            self.tip_sample_force(t, x)
        }
    }

    /// The release gap `d_r` (nm) of a hysteretic law (JKR's pull-off gap, the meniscus's
    /// rupture gap; MODEL.md section 9), `None` for every other law.
    pub fn release_gap_nm(&self) -> Option<f64> {
        self.force.release_gap_nm()
    }

    /// The tip-sample force (nN) at a gap minimum (gap rate 0) of gap `d` (nm), for a
    /// recovered sample (a standard linear solid's force needs its state: use
    /// [`TappingModel::tip_sample_force`]).
    #[inline]
    pub fn force_at_gap_minimum(&self, gap_nm: f64) -> f64 {
        if self.plain_hertz {
            self.hertz.force(gap_nm)
        } else {
            self.force.force(gap_nm, 0.0)
        }
    }

    /// The gap's acceleration `d'' - Z'' = y_base'' + sum_i q_i''` of mode `mode` (nm/us^2).
    pub(crate) fn gap_acceleration(&self, mode: Mode, t: f64, x: &[f64]) -> f64 {
        let drive = self.drive_factor(t);
        let force = self.force_slopes(mode, t, x).force;
        let base = self.base.as_ref().map_or(0.0, |base| base.acceleration(t));
        base + self
            .modes
            .iter()
            .zip(x.chunks_exact(2))
            .map(|(m, state)| {
                m.drive_acceleration * drive + m.omega_squared_over_stiffness * force
                    - m.omega_squared * state[0]
                    - m.damping * state[1]
            })
            .sum::<f64>()
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

/// The gap's change `dd` along a tangent column `v` of the state `[q_1, q_1', ..., q_N, q_N',
/// ...]`: the sum of the `count` modal displacements `v[2i]`, plus `dd/dZ = 1` on the
/// parameter column (`parameter`).
#[inline(always)]
pub(crate) fn tangent_gap_change(v: &[f64], count: usize, parameter: bool) -> f64 {
    let mut change = if parameter { 1.0 } else { 0.0 };
    for i in 0..count {
        change += v[2 * i];
    }
    change
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
