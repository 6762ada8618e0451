//! The tapping cantilever's optional accelerations of the hybrid solver: the exact free flight,
//! the Taylor series of the contact, and the shape of the gap as a switching function. They
//! change how fast an orbit is integrated, never what it is.

use hybrid::{
    ClockPolynomial, ExactFlow, HybridSystem, Mode, SwitchingStructure, TaylorExpansion,
    TaylorSeries,
};
use nalgebra::DMatrix;

use super::{TappingModel, CONTACT, FREE_FLIGHT, GAP_SURFACE, PULL_OFF_SURFACE};
use crate::contact::standard_linear_solid::StandardLinearSolid;
use crate::contact::{ContactLaw, HertzShape, HertzTip};
use crate::model::contact_series::{self, SeriesDrive, SeriesForce};
use crate::model::modal_constants::{grid_spacing, KEPT_GRIDS};
use crate::model::phase;
use crate::model::relaxing_series;
use crate::model::second_drive::SecondDrive;

/// The most grid times at which [`ExactFlow::exact_flow_grid`] computes a bimodal drive's second
/// phase once for every mode (the solver's grids have 8).
const SHARED_SECOND_PHASES: usize = 33;

/// Every mode outside contact whose force is a constant `F_c` ([`TappingModel::flight_force_nn`]:
/// zero in free flight, `-F_m` while a meniscus is attached) is Eq. 1 about a shifted rest
/// position: mode `i`'s particular solution gains the static deflection `F_c / k_i`, so the
/// flow is the force-free one of `x - s` plus `s` (`s` the offsets; the transition matrix is the
/// force-free one, and `F_c` does not depend on `Z`; MODEL.md section 9, "Capillary meniscus").
impl ExactFlow for TappingModel {
    fn has_exact_flow(&self, mode: Mode) -> bool {
        self.flight_force_nn(mode).is_some()
    }

    /// A quarter of the shortest of the drive period and the modal periods `2 pi / w_i`, us.
    fn exact_step_limit(&self, mode: Mode) -> f64 {
        if self.has_exact_flow(mode) {
            self.exact_step_limit
        } else {
            f64::INFINITY
        }
    }

    /// The free flight at `count` equally spaced times: one homogeneous transition over the
    /// spacing per mode and one rotation of the drive phase, applied `count` times (the
    /// steady part by angle addition), instead of the exponentials and trigonometric
    /// functions of a fresh flow per point. Equal to the direct flow up to rounding growing
    /// with `count` (a few ulps for the solver's 9 points; tested).
    fn exact_flow_grid(
        &self,
        mode: Mode,
        t0: f64,
        x0: &[f64],
        dt: f64,
        count: usize,
        states: &mut [f64],
    ) {
        let n = self.dim();
        let force = self.constant_flight_force_nn(mode);
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
        // A bimodal drive's second phase at the grid's times (shared by the modes), index 0 at
        // `t0`.
        let mut second_phases = [(0.0, 0.0); SHARED_SECOND_PHASES];
        let shared = match &self.second {
            Some(second) if count < SHARED_SECOND_PHASES => {
                let w_b = second.angular_frequency;
                second_phases[0] = phase::sin_cos(w_b * t0);
                for (j, slot) in second_phases[1..=count].iter_mut().enumerate() {
                    *slot = phase::sin_cos(w_b * (t0 + (j + 1) as f64 * spacing));
                }
                true
            }
            _ => false,
        };
        let second_at = |i: usize, j: usize| {
            if shared {
                let (sin, cos) = second_phases[j];
                self.second_steady_state_at_phase(i, sin, cos)
            } else {
                self.second_steady_state(i, t0 + j as f64 * spacing)
            }
        };
        for (i, m) in self.modes.iter().enumerate() {
            let phi = match kept {
                Some(c) => m.grid_transitions[c],
                None => m.oscillator.homogeneous_transition(spacing),
            };
            let start = m.oscillator.steady_state_at_phase(sin0, cos0);
            let second = if shared {
                second_at(i, 0)
            } else {
                self.second_steady_state(i, t0)
            };
            let mut y = [
                x0[2 * i] - start[0] - second[0],
                x0[2 * i + 1] - start[1] - second[1],
            ];
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
                let second = if shared {
                    second_at(i, j + 1)
                } else {
                    self.second_steady_state(i, t0 + (j + 1) as f64 * spacing)
                };
                states[j * n + 2 * i] = steady[0] + second[0] + y[0];
                states[j * n + 2 * i + 1] = steady[1] + second[1] + y[1];
            }
        }
        if force != 0.0 {
            self.add_constant_force_response(force, dt, count, states);
        }
        if let Some(sls) = self.force.law.standard_linear_solid() {
            // The unloaded surface's recovery `rho(t) = rho_0 exp(-(1 - beta) (t - t_0) / tau)`.
            let last = 2 * self.modes.len();
            let decay = (-sls.recovery_rate_per_us() * spacing).exp();
            let mut state = x0[last];
            for j in 0..count {
                state *= decay;
                states[j * n + last] = state;
            }
        }
    }

    /// The free flight's closed-form flow (block diagonal, one [`DrivenOscillator`] per mode,
    /// about the rest position shifted by a constant force); it does not depend on `Z`, so
    /// `dx/dZ = 0`.
    fn exact_flow(
        &self,
        mode: Mode,
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
        let force = self.constant_flight_force_nn(mode);
        // A bimodal drive's second phase at both ends, shared by the modes.
        let second_phases = self.second.as_ref().map(|second| {
            (
                phase::sin_cos(second.angular_frequency * t0),
                phase::sin_cos(second.angular_frequency * (t0 + dt)),
            )
        });
        for (i, m) in self.modes.iter().enumerate() {
            let phi = if standard {
                m.step_transition
            } else {
                m.oscillator.homogeneous_transition(dt)
            };
            // A bimodal drive's second response is a further particular solution: the flow of
            // `x0 - s_b(t0)` under the first drive, plus `s_b(t0 + dt)`.
            let (start, end) = match second_phases {
                Some(((sin0, cos0), (sin1, cos1))) => (
                    self.second_steady_state_at_phase(i, sin0, cos0),
                    self.second_steady_state_at_phase(i, sin1, cos1),
                ),
                None => ([0.0, 0.0], [0.0, 0.0]),
            };
            let state = m.oscillator.flow_with_transition(
                start_phase,
                end_phase,
                [x0[2 * i] - start[0], x0[2 * i + 1] - start[1]],
                &phi,
            );
            x[2 * i] = state[0] + end[0];
            x[2 * i + 1] = state[1] + end[1];
            if let Some(matrix) = transition.as_deref_mut() {
                for r in 0..2 {
                    for c in 0..2 {
                        matrix[(2 * i + r, 2 * i + c)] = phi[r][c];
                    }
                }
            }
        }
        if force != 0.0 {
            self.add_constant_force_response(force, dt, 1, x);
        }
        if let Some(sls) = self.force.law.standard_linear_solid() {
            let last = 2 * self.modes.len();
            let decay = (-sls.recovery_rate_per_us() * dt).exp();
            x[last] = x0[last] * decay;
            if let Some(matrix) = transition {
                matrix[(last, last)] = decay;
            }
        }
        if let Some(dxdp) = dxdp {
            dxdp.fill(0.0);
        }
    }
}

impl TappingModel {
    /// The force outside contact in mode `mode` when it is a constant, nN: 0 in free flight
    /// where no force acts outside contact, `-F_m` while a capillary meniscus is attached
    /// ([`crate::contact::TipSampleForce::constant_outside`]); `None` in contact and wherever
    /// the force outside contact depends on the gap. Where it is `Some`, the mode has the exact
    /// flow of [`ExactFlow`].
    #[inline]
    pub(crate) fn flight_force_nn(&self, mode: Mode) -> Option<f64> {
        if mode & CONTACT != FREE_FLIGHT {
            return None;
        }
        if self.plain_hertz {
            return Some(0.0);
        }
        self.force.constant_outside(Self::is_attached(mode))
    }

    /// The constant force of a mode with an exact flow ([`TappingModel::flight_force_nn`]), nN:
    /// zero unless the mode is attached (a law's force outside contact while detached is zero
    /// or depends on the gap), so that the force-free flight pays one bit test for it.
    #[inline(always)]
    fn constant_flight_force_nn(&self, mode: Mode) -> f64 {
        if Self::is_attached(mode) {
            self.flight_force_nn(mode).unwrap_or(0.0)
        } else {
            0.0
        }
    }

    /// Adds the response to a constant force `F` (nN) outside contact to the force-free flows
    /// of [`ExactFlow::exact_flow_grid`] (`count` states `n` apart in `states`, the grid over
    /// `dt`) or of [`ExactFlow::exact_flow`] (`count` = 1): the flow about the rest position
    /// shifted by `s_i = F / k_i` is `s + phi(t) (x0 - s)`, the force-free flow plus
    /// `(I - phi(t)) s`, with `phi(t) s` advanced over the grid by the transition over one
    /// spacing. The transition matrix is the force-free one. Apart from the force-free path
    /// (cold, its transitions computed again): only an attached meniscus has such a force.
    #[cold]
    #[inline(never)]
    fn add_constant_force_response(&self, force: f64, dt: f64, count: usize, states: &mut [f64]) {
        let n = self.dim();
        let spacing = grid_spacing(dt, count);
        let kept = dt == self.exact_step_limit && (1..=KEPT_GRIDS).contains(&count);
        for (i, m) in self.modes.iter().enumerate() {
            let phi = if kept {
                m.grid_transitions[count - 1]
            } else {
                m.oscillator.homogeneous_transition(spacing)
            };
            let offset = m.static_offset(force);
            // `phi(j spacing) s`, from `s = [offset, 0]`.
            let mut shifted = [offset, 0.0];
            for j in 0..count {
                shifted = [
                    phi[0][0] * shifted[0] + phi[0][1] * shifted[1],
                    phi[1][0] * shifted[0] + phi[1][1] * shifted[1],
                ];
                states[j * n + 2 * i] += offset - shifted[0];
                states[j * n + 2 * i + 1] -= shifted[1];
            }
        }
    }

    /// Whether mode `mode` is force-free flight with an exact flow (no force at all): the
    /// modes where the observers' closed-form free-flight integrals hold
    /// ([`crate::model::free_flight_fourier`], [`crate::model::free_flight_energy`]); a
    /// flight under a constant force (the attached meniscus) is integrated by quadrature on
    /// its exact flow.
    #[inline]
    pub(crate) fn has_force_free_flight(&self, mode: Mode) -> bool {
        self.flight_force_nn(mode) == Some(0.0)
    }

    /// Mode `i`'s steady response to a bimodal drive's second drive at a time whose second
    /// phase `w_b t` has sine `sin` and cosine `cos`, `[q, q']` (nm, nm/us); zero for another
    /// drive.
    #[inline]
    fn second_steady_state_at_phase(&self, i: usize, sin: f64, cos: f64) -> [f64; 2] {
        self.second.as_ref().map_or([0.0, 0.0], |second| {
            second.oscillators[i].steady_state_at_phase(sin, cos)
        })
    }

    /// Mode `i`'s steady response to a bimodal drive's second drive at `t`, `[q, q']` (nm,
    /// nm/us); zero for another drive. Always inlined (without a second drive it is a test
    /// and two zeros): as `Option::map_or` (whose closure holds `steady_state`'s sine and
    /// cosine) or a plain `match` it was an out-of-line call per mode and per step. The
    /// response itself stays a call ([`second_drive_response`]): inlined into the callers of
    /// every step it cost the bimodal diagram 1% more.
    #[inline(always)]
    fn second_steady_state(&self, i: usize, t: f64) -> [f64; 2] {
        match &self.second {
            Some(second) => second_drive_response(second, i, t),
            None => [0.0, 0.0],
        }
    }

    /// The drives of the Taylor series: `w`, an acoustic drive's base amplitude, a bimodal
    /// drive's second frequency and relative force (MODEL.md section 14).
    fn series_drive(&self) -> SeriesDrive {
        SeriesDrive {
            frequency: self.drive.angular_frequency,
            base_amplitude: self.base.as_ref().map_or(0.0, |base| base.amplitude_nm),
            second: self
                .second
                .as_ref()
                .map(|second| (second.angular_frequency, second.relative_force)),
        }
    }

    /// The standard linear solid whose contact mode `mode` is, when the sample is one without a
    /// double layer or hydration force: its Taylor series are module `relaxing_series`'s.
    fn relaxing_contact(&self, mode: Mode) -> Option<&StandardLinearSolid> {
        if self.force.double_layer.is_some() || self.force.hydration.is_some() {
            return None;
        }
        self.force
            .law
            .standard_linear_solid()
            .filter(|_| Self::in_contact(mode))
    }

    /// The force whose Taylor series (module `contact_series`) mode `mode` has: the Hertz
    /// sphere in contact, DMT in contact (Hertz shifted to `a0` minus the adhesion) and
    /// outside it (van der Waals, when `H > 0`), the Hertz sphere with a hydration force (in
    /// contact plus `F_h(0)`, outside `F_h(d)`), JKR while attached (its series in `sqrt(a)`),
    /// the capillary meniscus inside contact (the Hertz sphere minus `F_m`);
    /// `None` for every other law, mode, or with a double layer (those integrate by the adaptive Runge-Kutta path; MODEL.md section 9).
    pub(crate) fn series_force(&self, mode: Mode) -> Option<SeriesForce> {
        if self.plain_hertz {
            return Self::in_contact(mode).then_some(SeriesForce::Hertz {
                coefficient: self.hertz.coefficient,
                contact_gap: 0.0,
                constant: 0.0,
            });
        }
        if let (
            ContactLaw::Hertz(HertzShape {
                tip: HertzTip::Sphere { .. },
                ..
            }),
            None,
            Some(hydration),
        ) = (
            &self.force.law,
            &self.force.double_layer,
            &self.force.hydration,
        ) {
            // The Hertz sphere with the hydration force: in contact Hertz plus the constant
            // `F_h(0)`, outside the hydration force's own series.
            return Some(if Self::in_contact(mode) {
                SeriesForce::Hertz {
                    coefficient: self.hertz.coefficient,
                    contact_gap: 0.0,
                    constant: -hydration.force(0.0),
                }
            } else {
                SeriesForce::Hydration {
                    amplitude: hydration.amplitude_nn,
                    wavenumber: 2.0 * std::f64::consts::PI / hydration.layer_spacing_nm,
                    decay_length: hydration.decay_length_nm,
                }
            });
        }
        if let (ContactLaw::Capillary(capillary), None, None) = (
            &self.force.law,
            &self.force.double_layer,
            &self.force.hydration,
        ) {
            // Inside contact the meniscus is attached (it forms at the `Down` crossing of
            // `d = 0`): the Hertz sphere minus `F_m`. Outside contact the force is a constant
            // (`-F_m` attached, 0 detached): the exact flow.
            let HertzShape {
                effective_modulus_gpa,
                tip: HertzTip::Sphere { radius_nm },
            } = &capillary.hertz
            else {
                return None;
            };
            return (Self::in_contact(mode) && Self::is_attached(mode)).then_some(
                SeriesForce::Hertz {
                    // `(4/3) E* sqrt(R)`, as `HertzShape::force_slopes` forms it.
                    coefficient: 4.0 / 3.0 * effective_modulus_gpa * radius_nm.sqrt(),
                    contact_gap: 0.0,
                    constant: capillary.meniscus_force_nn,
                },
            );
        }
        if let (ContactLaw::Jkr(law), None, None) = (
            &self.force.law,
            &self.force.double_layer,
            &self.force.hydration,
        ) {
            // Attached, on both sides of d = 0 (MODEL.md section 9, JKR); detached the tip
            // flies freely (the exact flow).
            return Self::is_attached(mode).then_some(SeriesForce::Jkr { law: *law });
        }
        let (ContactLaw::Dmt(dmt), None, None) = (
            &self.force.law,
            &self.force.double_layer,
            &self.force.hydration,
        ) else {
            return None;
        };
        if Self::in_contact(mode) {
            Some(SeriesForce::Hertz {
                coefficient: dmt.hertz_coefficient(),
                contact_gap: dmt.intermolecular_distance_nm,
                constant: dmt.adhesion_force_nn(),
            })
        } else {
            (dmt.hamaker_constant_j != 0.0).then_some(SeriesForce::VanDerWaals {
                scale: dmt.adhesion_scale(),
            })
        }
    }
}

/// Offered for the plain Hertz sphere (its contact), DMT (its contact and, with `H > 0`, its
/// free flight), the hydration force, attached JKR and the meniscus inside contact ([`HybridSystem::accelerations`]): the
/// series of module `contact_series`.
/// Every other law integrates by the adaptive Runge-Kutta path.
impl TaylorExpansion for TappingModel {
    /// Where [`TappingModel::series_force`] has a force, 40: the Taylor series come from the
    /// recurrences of automatic differentiation (module `contact_series`), whose intermediate
    /// series live on the stack.
    fn taylor_order_limit(&self, mode: Mode) -> usize {
        if self.series_force(mode).is_some() || self.relaxing_contact(mode).is_some() {
            contact_series::MAX_ORDER
        } else {
            0
        }
    }

    /// The series of Eq. 1 with the mode's force in the step's clock (module
    /// `contact_series`); `false` where the mode has none (the Hertz free flight has its exact
    /// flow).
    fn taylor_series(
        &self,
        mode: Mode,
        clock: &ClockPolynomial,
        series: &mut TaylorSeries,
        shared: &mut Vec<f64>,
    ) -> bool {
        if let Some(sls) = self.relaxing_contact(mode) {
            return relaxing_series::relaxing_state_series(
                &self.modes,
                sls,
                &self.series_drive(),
                &self.separation,
                clock,
                series,
            );
        }
        self.series_force(mode).is_some_and(|force| {
            contact_series::contact_state_series(
                &self.modes,
                force,
                &self.series_drive(),
                &self.separation,
                clock,
                series,
                shared,
            )
        })
    }

    /// Where the mode has a series, the series of the variational equations along it (module
    /// `contact_series`).
    fn taylor_tangents(
        &self,
        mode: Mode,
        clock: &ClockPolynomial,
        state: &TaylorSeries,
        shared: &mut Vec<f64>,
        tangents: &mut TaylorSeries,
        parameter_column: bool,
        scratch: &mut Vec<f64>,
    ) {
        if let Some(sls) = self.relaxing_contact(mode) {
            relaxing_series::relaxing_tangent_series(
                &self.modes,
                sls,
                &self.series_drive(),
                &self.separation,
                clock,
                state,
                tangents,
                parameter_column,
                scratch,
            );
        } else if let Some(force) = self.series_force(mode) {
            contact_series::contact_tangent_series(
                &self.modes,
                force,
                &self.series_drive(),
                &self.separation,
                clock,
                state,
                shared,
                tangents,
                parameter_column,
                scratch,
            );
        }
    }
}

impl SwitchingStructure for TappingModel {
    /// In contact the Hertz sphere's force is `c (-d)^{3/2}` (DMT's, Kelvin-Voigt's and the
    /// film's have half-integer powers of `d_c - d` too): the contact surface is the
    /// half-power surface of the contact mode (not of a clipped mode, whose force is zero, nor
    /// of the cone's or punch's integer powers), and the solver integrates next to contact
    /// onset and release in the square root of the time from them.
    /// JKR while attached: its force is `F_po + K sqrt(d_po - d) + ...` next to pull-off, so
    /// the pull-off surface is the attached mode's half-power surface.
    fn half_power_surface(&self, mode: Mode) -> Option<usize> {
        if let ContactLaw::Jkr(_) = self.force.law {
            return Self::is_attached(mode).then_some(PULL_OFF_SURFACE);
        }
        (Self::in_contact(mode) && !self.is_clipped(mode) && self.force.law.half_power_inside())
            .then_some(GAP_SURFACE)
    }

    /// Kelvin-Voigt in contact (unclipped side) and JKR while attached: the laws whose
    /// [`SwitchingStructure::crossing_tangent_limit`] is given below (`dF/dd ~ s^{-1/2}` at the
    /// half-power surface), so that a Runge-Kutta step through a release or a pull-off is
    /// redone on the square-root clock centred exactly on the crossing.
    fn jacobian_diverges_at_crossing(&self, mode: Mode) -> bool {
        match self.force.law {
            ContactLaw::KelvinVoigt(_) => Self::in_contact(mode) && !self.is_clipped(mode),
            ContactLaw::Jkr(_) => Self::is_attached(mode),
            _ => false,
        }
    }

    /// Kelvin-Voigt in contact (unclipped side): `F = c s^{1/2} (s + tau s')` has
    /// `dF/dd = -c s^{-1/2} (1.5 s + 0.5 tau s')`, whose part `-0.5 c tau s' s^{-1/2}` is
    /// unbounded at the crossing; there `s = |s'| sigma^2` on the square-root clock, so
    /// `(dt/dsigma) dF/dd -> K = -c tau sign(s') |s'|^{1/2}` (`s' = -d'`, nm/us), and the
    /// limit of `(dt/dsigma) J v` is `(w_i^2/k_i) K sum_j v_{q_j}` on each `v_i` row (`+ K`
    /// times `(w_i^2/k_i)` on the parameter column, `dd/dZ = 1`), zero on the `q_i` rows.
    /// JKR attached, at pull-off: `dF/dd = -K / (2 sqrt(s))`, `s = d_po - d = |d'| sigma^2`,
    /// so `(dt/dsigma) dF/dd -> -K / |d'|^{1/2}` (`K` of
    /// [`crate::contact::JkrContact::pull_off_root_coefficient`]), on the same rows.
    /// Every other law's Jacobian is bounded next to its surface: `false`.
    fn crossing_tangent_limit(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        tangents: &[f64],
        tangent_rates: &mut [f64],
        parameter_column: bool,
    ) -> bool {
        let limit = match self.force.law {
            ContactLaw::KelvinVoigt(kv) if Self::in_contact(mode) && !self.is_clipped(mode) => {
                let c = 4.0 / 3.0 * kv.effective_modulus_gpa * kv.tip_radius_nm.sqrt();
                let indentation_rate = -self.gap_rate_at(t, x);
                -c * kv.release_time_us()
                    * indentation_rate.signum()
                    * indentation_rate.abs().sqrt()
            }
            ContactLaw::Jkr(jkr) if Self::is_attached(mode) => {
                -jkr.pull_off_root_coefficient() / self.gap_rate_at(t, x).abs().sqrt()
            }
            _ => return false,
        };
        let n = self.dim();
        let columns = tangents.len() / n;
        for (column, (v, rate)) in tangents
            .chunks_exact(n)
            .zip(tangent_rates.chunks_exact_mut(n))
            .enumerate()
        {
            let mut gap_change: f64 = v.iter().step_by(2).sum();
            if parameter_column && column + 1 == columns {
                gap_change += 1.0;
            }
            for (m, rows) in self.modes.iter().zip(rate.chunks_exact_mut(2)) {
                rows[0] = 0.0;
                rows[1] = m.omega_squared_over_stiffness * limit * gap_change;
            }
        }
        true
    }

    /// The gap `Z(t) + sum_i q_i` is affine (`Z(t)` is a constant or a linear ramp), and so
    /// are `h_0 = d - d_c` and `h_1 = -d - tau d'`; not with an acoustic drive's base motion
    /// `Y cos(w t)` in the gap (MODEL.md section 14), nor with a standard linear solid's
    /// `h_0 = d + rho^{2/3}` unless `E_0 = E_inf` keeps `rho = 0`.
    fn switching_is_affine(&self, _k: usize) -> bool {
        self.base.is_none()
            && self
                .force
                .law
                .standard_linear_solid()
                .is_none_or(|sls| sls.relaxing_fraction() == 0.0)
    }

    /// Under an acoustic drive the gap `Z(t) + Y cos(w t) + sum_i q_i` is affine in the state
    /// (gradient 1 on every `q_i`) with the time part `Z(t) + Y cos(w t)` (MODEL.md section 14),
    /// and so are `h_0 = d - d_c`, a hysteretic law's `h_1 = d - d_r` and a clipped
    /// Kelvin-Voigt law's `h_1 = -d - tau d'`; not a relaxing standard linear solid's
    /// `h_0 = d + rho^{2/3}`.
    fn switching_is_affine_in_state(&self, _k: usize) -> bool {
        self.force
            .law
            .standard_linear_solid()
            .is_none_or(|sls| sls.relaxing_fraction() == 0.0)
    }

    /// A relaxing standard linear solid's contact surface `h_0 = d + rho^{2/3}`: its series
    /// along a Taylor step's (module `relaxing_series`).
    fn switching_has_series(&self, k: usize) -> bool {
        k == GAP_SURFACE && self.force.law.standard_linear_solid().is_some()
    }

    /// The series of `h_0 = d + rho^{2/3}` along `state` (module `relaxing_series`); `false`
    /// for another surface or law, or from a recovered sample (`rho = 0`, where `rho^{2/3}` is
    /// not analytic).
    fn switching_series(
        &self,
        k: usize,
        _mode: Mode,
        clock: &ClockPolynomial,
        state: &TaylorSeries,
        coefficients: &mut [f64],
    ) -> bool {
        self.switching_has_series(k)
            && relaxing_series::relaxing_surface_series(
                &self.series_drive(),
                &self.separation,
                clock,
                state,
                coefficients,
            )
    }

    /// The time part of `h_k` along the clock: `Z(t(s)) + Y cos(w t(s))` (nm) for `h_0` and a
    /// hysteretic law's `h_1`, `-(Z + Y cos(w t)) - tau (Z' - w Y sin(w t))` for a clipped
    /// Kelvin-Voigt law's `h_1`; its coefficients `1..` from the drive phase's series (module
    /// `contact_series`).
    fn switching_time_series(&self, k: usize, clock: &ClockPolynomial, coefficients: &mut [f64]) {
        let order = coefficients
            .len()
            .saturating_sub(1)
            .min(contact_series::MAX_ORDER);
        let mut cos = [0.0; contact_series::MAX_ORDER + 1];
        let mut sin = [0.0; contact_series::MAX_ORDER + 1];
        let (amplitude, w) = self.base.as_ref().map_or((0.0, 0.0), |base| {
            (base.amplitude_nm, base.angular_frequency)
        });
        if amplitude != 0.0 {
            contact_series::phase_series(w, clock, order, &mut cos, &mut sin);
        }
        let separation = contact_series::separation_coefficients(&self.separation, clock);
        let (on_gap, on_rate) = if k == GAP_SURFACE || self.force.release_gap_nm().is_some() {
            (1.0, 0.0)
        } else {
            (-1.0, -self.force.law.release_time_us().unwrap_or(0.0))
        };
        for (j, c) in coefficients.iter_mut().enumerate().take(order + 1).skip(1) {
            let gap = separation.get(j).copied().unwrap_or(0.0) + amplitude * cos[j];
            // `Z'` is constant: the rate's coefficients from 1 on are the base's.
            let rate = -w * amplitude * sin[j];
            *c = on_gap * gap + on_rate * rate;
        }
    }

    /// In free flight, a bound on the gap's curvature `|d''| = |Z'' + sum_i q_i''|` over
    /// `[t0, t0 + dt]` (any `dt`), nm/us^2; `Z'' = 0` for both separation laws. Each mode is its
    /// steady drive response `p_i = alpha_i cos(w t) + beta_i sin(w t)` plus a homogeneous part
    /// `y_i` (Eq. 1 with `F_ts = 0`), so `|q_i''| <= w^2 P_i + (w_i + w_i/Q_i) r_i` (plus a
    /// standard linear solid's `|sigma''|`, below) with
    /// `P_i = hypot(alpha_i, beta_i)` and `r_i = sqrt(y_i'^2 + w_i^2 y_i^2)`, which the damping
    /// never lets grow (`d(r^2)/dt = -2 (w_i/Q_i) y_i'^2`), taken at `t0`. Under a constant
    /// force `F_c` (an attached meniscus) `y_i` is measured from the shifted rest position
    /// `F_c / k_i`, which adds nothing to `q_i''`. In contact `None` (extrema inside the
    /// sample, the gap's minima, are always wanted), and `None` for Kelvin-Voigt's release
    /// surface (a hysteretic law's pull-off surface `d - d_r` has the gap's curvature) and
    /// wherever the force outside contact is not a constant (attached JKR, DMT's van der
    /// Waals, a double layer, a hydration force: the bound assumes a constant `F_ts`).
    fn switching_curvature_bound(
        &self,
        k: usize,
        mode: Mode,
        t0: f64,
        x0: &[f64],
        _dt: f64,
    ) -> Option<f64> {
        if Self::in_contact(mode)
            || (k != GAP_SURFACE && self.force.release_gap_nm().is_none())
            || self.force.acts_outside_contact()
        {
            return None;
        }
        let force = if Self::is_attached(mode) {
            self.flight_force_nn(mode)?
        } else {
            0.0
        };
        let w = self.drive.angular_frequency;
        let (sin, cos) = phase::sin_cos(w * t0);
        // The base's `|y_base''| <= w^2 |Y|` (acoustic drive, MODEL.md section 14).
        let base = match &self.base {
            Some(base) => w * w * base.amplitude_nm.abs(),
            None => 0.0,
        };
        let bound = base
            + self
                .modes
                .iter()
                .enumerate()
                .map(|(i, m)| {
                    let [p, dp] = m.oscillator.steady_state_at_phase(sin, cos);
                    let [pb, dpb] = self.second_steady_state(i, t0);
                    let (mut y, dy) = (x0[2 * i] - p - pb, x0[2 * i + 1] - dp - dpb);
                    if force != 0.0 {
                        y -= m.static_offset(force);
                    }
                    // A bimodal drive's second steady response adds `w_b^2 P_bi`.
                    let second = self.second.as_ref().map_or(0.0, |second| {
                        let [a, b] = second.oscillators[i].steady_coefficients();
                        second.angular_frequency * second.angular_frequency * a.hypot(b)
                    });
                    // `w^2 hypot(alpha_i, beta_i)` and `sqrt(w_i^2) + w_i/Q_i`, kept with the
                    // mode's constants.
                    let steady = m.steady_curvature + second;
                    let homogeneous =
                        m.homogeneous_rate * (dy * dy + m.omega_squared * y * y).sqrt();
                    steady + homogeneous
                })
                .sum::<f64>();
        // A standard linear solid's unrecovered depth `sigma = rho^{2/3}` decays as
        // `exp(-(2/3) r t)` (`r` the recovery rate): `|sigma''| <= (4/9) r^2 sigma(t0)`.
        let surface = self.force.law.standard_linear_solid().map_or(0.0, |sls| {
            let rate = sls.recovery_rate_per_us();
            4.0 / 9.0 * rate * rate * self.force.law.surface_depth_nm(self.sample_state(x0))
        });
        let bound = bound + surface;
        // Slack for the rounding of the sums (relative 1e-12) and of `y` (absolute).
        bound.is_finite().then_some(bound * (1.0 + 1e-12) + 1e-12)
    }
}

/// Mode `i`'s steady response `[q, q']` (nm, nm/us) to the second drive `second` at `t` (us)
/// ([`crate::model::free_flight::DrivenOscillator::steady_state`]), out of line.
#[inline(never)]
fn second_drive_response(second: &SecondDrive, i: usize, t: f64) -> [f64; 2] {
    second.oscillators[i].steady_state(t)
}
