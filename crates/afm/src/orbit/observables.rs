//! Observables of a trajectory over a window of whole drive periods (MODEL.md sections 4 and
//! 5): one period, or the `k` periods of a period-`k` orbit. The first (and higher) harmonics
//! of `u`, the impacts with their onset velocities and peak forces, every local minimum of the
//! gap, and the force integrals, all over the whole window.
//!
//! The Fourier coefficients are integrated in closed form over free flight
//! ([`crate::model::free_flight_fourier`], exact to rounding; by quadrature near critical damping),
//! and they and the force integrals by 8-point Gauss-Legendre quadrature over every contact
//! step (to dense-output accuracy). Impacts come from the
//! solver's events, gap minima from its extrema, so none is missed between samples.

use hybrid::{
    flow_map_in, Direction, ExtremumKind, FlowMap, HybridSystem, Mode, Sensitivity, Settings,
    Solver, SolverWorkspace, StepOutcome,
};

use serde::Serialize;

use crate::contact::standard_linear_solid::StandardLinearSolid;
use crate::error::AfmError;
use crate::model::free_flight_energy::{FreeFlightEnergy, ModeIntegrals};
use crate::model::free_flight_fourier::FreeFlightFourier;
use crate::model::phase;
use crate::model::TappingModel;
use crate::model::{CONTACT, GAP_SURFACE};
use crate::orbit::gauss_legendre::{ClockNode, GAUSS_LEGENDRE_8};
use crate::validation::invalid;

/// Minima of the gap closer together than this fraction of a period are one minimum (the same
/// extremum reported by two adjacent steps).
const DUPLICATE_FRACTION: f64 = 1e-9;

/// One impact: a maximal interval with `d < 0` (MODEL.md section 5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Impact {
    /// Onset time, in drive periods from the window start (in `[0, k)` for a window of `k`
    /// periods).
    pub start_periods: f64,
    /// Release time, in drive periods from the window start; greater than `k` for an impact
    /// that wraps around the window's end (in progress at the start and at the end of the
    /// window of a periodic orbit: one impact).
    pub end_periods: f64,
    /// The gap's rate `d'` at onset (negative: approach speed), nm/us; NaN when the onset is not
    /// in the window (the tip is in contact at the start and free at the end, or in contact
    /// throughout).
    pub velocity_nm_per_us: f64,
    /// The largest Hertz force during the impact, nN.
    pub peak_force_nn: f64,
}

/// A gap minimum above the sample is a near impact when it lies within this fraction of the
/// free amplitude `A0` of the surface (MODEL.md section 5): close enough that a small change of
/// `Z` (a tenth of the approach from first contact to `Z = 0`) turns it into an impact.
pub const NEAR_IMPACT_FRACTION: f64 = 0.1;

/// What a local minimum of the gap is, by its depth (MODEL.md section 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GapMinimumKind {
    /// `d < 0`: the deepest point of an impact.
    Impact,
    /// `0 <= d <= NEAR_IMPACT_FRACTION * A0`: a near impact, which becomes one at grazing.
    NearImpact,
    /// `d > NEAR_IMPACT_FRACTION * A0`: clear of the sample.
    Clear,
}

impl GapMinimumKind {
    /// The kind of a gap minimum `gap_nm` above the contact surface (`d - d_c`; the gap itself
    /// for every law but DMT) for a free amplitude `free_amplitude_nm`.
    pub fn of(gap_nm: f64, free_amplitude_nm: f64) -> Self {
        if gap_nm < 0.0 {
            Self::Impact
        } else if gap_nm <= NEAR_IMPACT_FRACTION * free_amplitude_nm {
            Self::NearImpact
        } else {
            Self::Clear
        }
    }

    /// The kind's name as in the JSON output: `impact`, `near-impact` or `clear`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Impact => "impact",
            Self::NearImpact => "near-impact",
            Self::Clear => "clear",
        }
    }
}

/// A local minimum of the gap `d(t)` (MODEL.md section 5): an impact's deepest point when
/// negative, a near impact when a little positive; zero at grazing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GapMinimum {
    /// Time, in drive periods from the window start (in `[0, k)` for a window of `k` periods).
    pub t_periods: f64,
    /// The gap `d` there, nm.
    pub gap_nm: f64,
    /// Impact, near impact or clear (from `d - d_c`, MODEL.md section 9), by [`GapMinimumKind::of`] with the model's `A0`.
    pub kind: GapMinimumKind,
}

/// One harmonic `k` of the photodiode signal: `u ~ sum_k A_k cos(k w t - Phi_k)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Harmonic {
    /// The order `k` (1 for the drive frequency).
    pub n: usize,
    /// `A_k = hypot(a_k, b_k)`, nm, with `a_k = (2/W) int u cos(k w t) dt` and `b_k` with sin,
    /// over the window `W` of whole drive periods (the lock-in reading of the whole window).
    pub amplitude_nm: f64,
    /// `Phi_k = atan2(b_k, a_k)`, degrees (a lag).
    pub phase_deg: f64,
}

/// One nN nm in eV (1 nN nm = 1e-18 J; 1 eV = 1.602176634e-19 J, exact in the SI).
pub const NN_NM_IN_EV: f64 = 1e-18 / 1.602_176_634e-19;

/// The energy balance of one mode over the window, per drive period (MODEL.md section 10):
/// Eq. 1 times `m_i q_i'` (`m_i = k_i / w_i^2`) integrated over the window gives
/// `drive_work_ev = damping_loss_ev + dissipated_share_ev + stored_energy_change_ev`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct ModeEnergy {
    /// The drive's work on the mode `W_i = int F_i cos(w t) q_i' dt`, eV.
    pub drive_work_ev: f64,
    /// The loss in the mode's damping `D_i = (k_i / (w_i Q_i)) int q_i'^2 dt`, eV.
    pub damping_loss_ev: f64,
    /// The mode's share of the tip-sample dissipation `-int F_ts q_i' dt`, eV, by quadrature
    /// (the shares sum to `dissipated_ev + base_work_ev`, for a conservative law to the
    /// quadrature's accuracy).
    pub dissipated_share_ev: f64,
    /// The change of the mode's energy `m_i q_i'^2 / 2 + k_i q_i^2 / 2` from the window's
    /// start to its end, eV (zero on a periodic orbit to Newton's tolerance).
    pub stored_energy_change_ev: f64,
}

impl ModeEnergy {
    /// The balance's residual `W_i - D_i - E_i - dE_i`, eV.
    pub fn residual_ev(&self) -> f64 {
        self.drive_work_ev
            - self.damping_loss_ev
            - self.dissipated_share_ev
            - self.stored_energy_change_ev
    }
}

/// The observables of a trajectory over a window of `k` whole drive periods
/// `[t0, t0 + k T]` (MODEL.md sections 4 and 5): for a period-`k` orbit, the whole orbit.
/// Lists (impacts, gap minima) cover the whole window; integrals are given per drive period.
/// The default is an empty record (no window, no contact), for placeholders in tests.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct OrbitObservables {
    /// The window's length `k` in drive periods (the orbit's multiplicity when the window is
    /// a whole period-`k` orbit).
    pub window_periods: usize,
    /// First-harmonic amplitude `A` of `u` over the window, nm.
    pub amplitude_nm: f64,
    /// `A / A0`.
    pub amplitude_ratio: f64,
    /// Phase lag `Phi` of the first harmonic of `u` over the window, degrees.
    pub phase_deg: f64,
    /// Harmonics `k = 1..=K` of `u` (`harmonics[0]` repeats `A`, `Phi`).
    pub harmonics: Vec<Harmonic>,
    /// The impacts of the window in order of onset (a wrapped impact last).
    pub impacts: Vec<Impact>,
    /// Impacts per drive period: `impacts.len() / k` (an integer for a period-1 window).
    pub impacts_per_period: f64,
    /// Every local minimum of the gap in the window, in time order.
    pub gap_minima: Vec<GapMinimum>,
    /// The largest tip-sample force in the window, nN (0 without contact).
    pub peak_force_nn: f64,
    /// The mean tip-sample force `(1/(k T)) int F_ts dt` over the window, nN.
    pub mean_force_nn: f64,
    /// The time in contact (`d < 0`) per drive period, in periods (the window's contact
    /// time over `k`: the fraction of time in contact).
    pub contact_time_periods: f64,
    /// The impulse per drive period `(1/k) int F_ts dt` over the window, nN us.
    pub impulse_nn_us: f64,
    /// The energy dissipated in the sample per drive period,
    /// `E_ts = -(1/k) int F_ts (w' + y_base') dt` over the window (`w = sum_i q_i` the tip
    /// deflection, `y_base` an acoustic drive's base motion, else 0), eV (MODEL.md sections 10
    /// and 14): zero for a conservative law (computed from its energy `U(d)`, exact), positive
    /// for a dissipative one.
    pub dissipated_ev: f64,
    /// The contact force's work on the moving base per drive period,
    /// `(1/k) int F_ts y_base' dt` over the window, eV (MODEL.md section 14; 0 but under an
    /// acoustic drive): the modes' dissipated shares add up to `dissipated_ev + base_work_ev`.
    pub base_work_ev: f64,
    /// The virial `V_ts = (1/(k T)) int F_ts w dt` over the window, eV.
    pub virial_ev: f64,
    /// The largest indentation in the window, nm (0 without contact): the depth `s = -h_0`
    /// below the contact surface, `d_c - d` in the law's contact geometry, and for a standard
    /// linear solid `-d - sigma`, below its unrecovered surface (MODEL.md section 10).
    pub max_indentation_nm: f64,
    /// The mean indentation `s` over the time in contact, `int s dt / t_contact`, nm (0 without
    /// contact).
    pub mean_indentation_nm: f64,
    /// The energy balance's relative residual: the largest `|W_i - D_i - E_i - dE_i|` of the
    /// modes over the total damping loss `sum_i D_i` (MODEL.md section 10); 0 at rest.
    pub energy_balance_residual: f64,
    /// Each mode's energy balance per drive period.
    pub mode_energy: Vec<ModeEnergy>,
    /// A bimodal drive's lock-in reading of `u` at the second frequency `w_b` over the window
    /// (MODEL.md section 14); `None` for another drive.
    pub second_drive: Option<SecondDriveResponse>,
}

/// The first harmonic of `u` at a bimodal drive's second frequency `w_b` over a window:
/// `a = (2/kT) int u cos(w_b t) dt`, `b = (2/kT) int u sin(w_b t) dt` (MODEL.md section 14).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct SecondDriveResponse {
    /// `A_b = hypot(a, b)`, nm.
    pub amplitude_nm: f64,
    /// The phase lag `Phi_b = atan2(b, a)`, degrees (`u ~ A_b cos(w_b t - Phi_b)`).
    pub phase_deg: f64,
}

impl OrbitObservables {
    /// The impacts over the whole window (`n k` for a period-`k` orbit with `n` impacts per
    /// period on average).
    pub fn impacts_per_window(&self) -> usize {
        self.impacts.len()
    }

    /// The lowest gap minimum of the window, nm (`+inf` when the window has none).
    pub fn min_gap_nm(&self) -> f64 {
        self.gap_minima
            .iter()
            .map(|m| m.gap_nm)
            .fold(f64::INFINITY, f64::min)
    }
}

/// An observer of the solver's steps that accumulates the observables of the window
/// `[t0, t0 + T]`: pass [`PeriodObserver::observe`] to `hybrid::flow_map_observed` (or call it
/// after every `Solver::step` of a sweep), then call [`PeriodObserver::finish`].
///
/// Steps (or parts of steps) outside the window are ignored; it allocates only when it records
/// an event or a gap minimum.
#[derive(Debug, Clone)]
pub struct PeriodObserver {
    start: f64,
    end: f64,
    period: f64,
    /// The window's length in drive periods.
    window_periods: usize,
    angular_frequency: f64,
    free_amplitude: f64,
    /// The contact surface's gap `d_c`, nm (the minima are recorded as `d - d_c`).
    contact_gap: f64,
    starts_in_contact: bool,
    gap_at_start: f64,
    gap_at_end: f64,
    /// `[int u cos(k w t), int u sin(k w t)]`, k = 1..=K.
    fourier: Vec<[f64; 2]>,
    impulse: f64,
    /// `(t, direction, rate)` of every contact event in the window.
    events: Vec<(f64, Direction, f64)>,
    minima: Vec<(f64, f64)>,
    /// The states at a contact step's quadrature nodes (`n` per node).
    node_states: Vec<f64>,
    /// The closed-form Fourier integrals over free flight (`None` near critical damping, where
    /// free flight is integrated by quadrature like contact).
    free_flight: Option<FreeFlightFourier>,
    /// The closed-form energy integrals over free flight (`None` where `free_flight` is).
    free_flight_energy: Option<FreeFlightEnergy>,
    /// The mode of the next step (the solver's mode after the last one observed).
    mode: Mode,
    /// Start time and state of the free-flight interval in progress, if any.
    free_start: Option<f64>,
    free_state: Vec<f64>,
    /// Each mode's constants for the energy balance.
    modes: Vec<ModeConstants>,
    /// Each mode's drive work and `int q_i'^2 dt` over the window.
    mode_integrals: Vec<ModeIntegrals>,
    /// Each mode's `int F_ts q_i' dt` over the window, nN nm.
    contact_work: Vec<f64>,
    /// `int F_ts w dt` over the window, nN nm us.
    virial: f64,
    /// `int s dt` over the window (`s = max(d_c - d, 0)`), nm us.
    indentation: f64,
    /// `int F_ts y_base' dt` over the window (acoustic drive, MODEL.md section 14), nN nm.
    base_work: f64,
    /// A bimodal drive's `w_b` (rad/us) and `[int u cos(w_b t), int u sin(w_b t)]`.
    second_fourier: Option<(f64, [f64; 2])>,
    /// The states at the window's start and end.
    start_state: Vec<f64>,
    end_state: Vec<f64>,
    /// A standard linear solid's law (its state is the model state's last component).
    relaxing: Option<StandardLinearSolid>,
    /// The standard linear solid's dashpot loss `int D dt` over the window, nN nm.
    dashpot_loss: f64,
    /// `(t, F_ts)` at every gap minimum, for a standard linear solid (whose force at a
    /// minimum of `h_0 = d + sigma` depends on its state).
    minimum_forces: Vec<(f64, f64)>,
    /// Scratch for a state at a gap minimum.
    scratch: Vec<f64>,
}

/// One mode's constants in the energy balance (MODEL.md section 10).
#[derive(Debug, Clone, Copy)]
struct ModeConstants {
    /// `k_i`, nN/nm.
    stiffness: f64,
    /// The modal mass `m_i = k_i / w_i^2`, nN us^2/nm.
    mass: f64,
    /// The damping coefficient `k_i / (w_i Q_i)`, nN us/nm.
    damping: f64,
    /// The drive amplitude `F_i`, nN.
    drive_force: f64,
}

impl ModeConstants {
    /// The mode's energy `m q'^2 / 2 + k q^2 / 2` at `(q, q')`, nN nm.
    fn energy(&self, q: f64, velocity: f64) -> f64 {
        0.5 * (self.mass * velocity * velocity + self.stiffness * q * q)
    }
}

impl PeriodObserver {
    /// An observer of the period `[t0, t0 + T]` of `model` started from state `x0` at `t0`,
    /// recording harmonics `1..=harmonic_count` of `u` (at least 1).
    pub fn new(model: &TappingModel, t0: f64, x0: &[f64], harmonic_count: usize) -> Self {
        Self::over_periods(model, t0, x0, 1, harmonic_count)
    }

    /// An observer of the window `[t0, t0 + k T]` of `k = window_periods` drive periods (at
    /// least 1) of `model` started from state `x0` at `t0`, recording harmonics
    /// `1..=harmonic_count` of `u` (at least 1). For a period-`k` orbit the window is the whole
    /// orbit, and an impact in progress at both of its ends is one impact.
    pub fn over_periods(
        model: &TappingModel,
        t0: f64,
        x0: &[f64],
        window_periods: usize,
        harmonic_count: usize,
    ) -> Self {
        let period = model.period_us();
        let window_periods = window_periods.max(1);
        Self {
            start: t0,
            end: t0 + window_periods as f64 * period,
            period,
            window_periods,
            angular_frequency: model.drive_angular_frequency(),
            free_amplitude: model.free_amplitude_nm(),
            contact_gap: model.contact_gap_nm(),
            starts_in_contact: model.mode_of(t0, x0) & CONTACT != 0,
            gap_at_start: model.gap(t0, x0),
            gap_at_end: f64::NAN,
            fourier: vec![[0.0, 0.0]; harmonic_count.max(1)],
            impulse: 0.0,
            events: Vec::new(),
            minima: Vec::new(),
            node_states: vec![0.0; GAUSS_LEGENDRE_8.len() * model.dim()],
            free_flight: FreeFlightFourier::new(model),
            free_flight_energy: FreeFlightEnergy::new(model),
            mode: model.mode_of(t0, x0),
            free_start: None,
            free_state: vec![0.0; model.dim()],
            modes: model
                .cantilever()
                .modes
                .iter()
                .map(|mode| {
                    let omega = mode.angular_frequency();
                    ModeConstants {
                        stiffness: mode.stiffness_n_per_m,
                        mass: mode.stiffness_n_per_m / (omega * omega),
                        damping: mode.stiffness_n_per_m / (omega * mode.quality_factor),
                        drive_force: mode.force_ratio * model.drive_force_nn(),
                    }
                })
                .collect(),
            mode_integrals: vec![ModeIntegrals::default(); model.mode_count()],
            contact_work: vec![0.0; model.mode_count()],
            virial: 0.0,
            indentation: 0.0,
            base_work: 0.0,
            second_fourier: model
                .second_drive()
                .map(|second| (second.angular_frequency, [0.0, 0.0])),
            start_state: x0.to_vec(),
            end_state: vec![f64::NAN; model.dim()],
            relaxing: model.contact_force().law.standard_linear_solid().copied(),
            dashpot_loss: 0.0,
            minimum_forces: Vec::new(),
            scratch: vec![0.0; model.dim()],
        }
    }

    /// Accumulate the last step of `solver` (its part inside the window): the integrals of
    /// `u cos(k w t)`, `u sin(k w t)` and `F_ts`, the step's gap minima and its contact event.
    /// Over free flight (exact-flow steps, `F_ts = 0`) the Fourier integrals are taken in
    /// closed form ([`FreeFlightFourier`]) once per free-flight interval, when it ends; over
    /// contact steps by 8-point Gauss-Legendre quadrature in the step's clock on `Solver::interpolate_clock`.
    pub fn observe(&mut self, solver: &Solver<TappingModel>, outcome: &StepOutcome) {
        let model = solver.system();
        let (step_start, step_end) = solver.last_step();
        let a = step_start.max(self.start);
        let b = step_end.min(self.end);
        if b > a {
            if self.free_flight.is_some() && model.has_force_free_flight(self.mode) {
                if self.free_start.is_none() {
                    self.free_start = Some(a);
                    solver.interpolate(a, &mut self.free_state);
                }
                if !matches!(outcome, StepOutcome::Internal) || b >= self.end {
                    self.close_free_flight(b);
                }
            } else {
                self.close_free_flight(a);
                let mut states = std::mem::take(&mut self.node_states);
                for (node, state) in
                    GAUSS_LEGENDRE_8.step_nodes(solver, a, b, self.angular_frequency, &mut states)
                {
                    self.accumulate(model, &node, state);
                }
                self.node_states = states;
            }
        }
        self.mode = solver.mode();
        for extremum in solver.step_extrema() {
            if extremum.surface == GAP_SURFACE
                && extremum.kind == ExtremumKind::Minimum
                && extremum.t >= self.start
                && extremum.t < self.end
            {
                self.minima.push((extremum.t, extremum.value));
                if self.relaxing.is_some() {
                    solver.interpolate(extremum.t, &mut self.scratch);
                    let force = model.tip_sample_force(extremum.t, &self.scratch);
                    self.minimum_forces.push((extremum.t, force));
                }
            }
        }
        if let StepOutcome::Event(event) = outcome {
            if event.surface == GAP_SURFACE && event.t >= self.start && event.t <= self.end {
                self.events.push((event.t, event.direction, event.rate));
            }
        }
        if step_end >= self.end && step_start < self.end {
            if step_end == self.end {
                self.end_state.copy_from_slice(solver.state());
            } else {
                solver.interpolate(self.end, &mut self.end_state);
            }
            self.gap_at_end = model.gap(self.end, &self.end_state);
        }
    }

    /// Add the closed-form Fourier and energy integrals of the free-flight interval in
    /// progress, up to `end`, and close it (`F_ts = 0` there: no force integral).
    fn close_free_flight(&mut self, end: f64) {
        if let (Some(start), Some(free_flight)) = (self.free_start.take(), &self.free_flight) {
            free_flight.add_harmonics(start, &self.free_state, end, &mut self.fourier);
            if let (Some((_, coefficients)), Some([cosine, sine])) = (
                &mut self.second_fourier,
                free_flight.integrate_second(start, &self.free_state, end),
            ) {
                coefficients[0] += cosine;
                coefficients[1] += sine;
            }
            if let Some(energy) = &self.free_flight_energy {
                energy.accumulate(start, &self.free_state, end, &mut self.mode_integrals);
            }
            if let Some(sls) = &self.relaxing {
                // Unloaded, `D = -dU/dt`: the loss is the stored energy's fall as `rho` decays
                // by `exp(-(1 - beta) t / tau)`.
                let state = self.free_state[2 * self.modes.len()];
                let later = state * (-sls.recovery_rate_per_us() * (end - start)).exp();
                self.dashpot_loss += sls.stored_energy(f64::INFINITY, state)
                    - sls.stored_energy(f64::INFINITY, later);
            }
        }
    }

    /// Add the quadrature node `node` with the state `state` there.
    fn accumulate(&mut self, model: &TappingModel, node: &ClockNode, state: &[f64]) {
        let ClockNode {
            t,
            weight,
            drive: (sin, cos),
            ..
        } = *node;
        let u = model.photodiode(state);
        let force = model.tip_sample_force_in_mode(self.mode, t, state);
        self.impulse += weight * force;
        self.base_work += weight * force * model.base_velocity(t);
        // Both drives' factor `D(t)` (MODEL.md section 14; `cos(w t)` for a single drive).
        let drive = match &mut self.second_fourier {
            None => cos,
            Some((second_frequency, coefficients)) => {
                let (sin_b, cos_b) = phase::sin_cos(*second_frequency * t);
                coefficients[0] += weight * u * cos_b;
                coefficients[1] += weight * u * sin_b;
                model.drive_factor(t)
            }
        };
        let mut deflection = 0.0;
        for (((constants, integrals), work), mode_state) in self
            .modes
            .iter()
            .zip(self.mode_integrals.iter_mut())
            .zip(self.contact_work.iter_mut())
            .zip(state.chunks_exact(2))
        {
            let (q, velocity) = (mode_state[0], mode_state[1]);
            deflection += q;
            integrals.drive_work += weight * constants.drive_force * drive * velocity;
            integrals.velocity_square += weight * velocity * velocity;
            *work += weight * force * velocity;
        }
        self.virial += weight * force * deflection;
        if let Some(sls) = &self.relaxing {
            self.dashpot_loss +=
                weight * sls.dissipation_rate(model.gap(t, state), model.sample_state(state));
        }
        self.indentation += weight * (-model.switching(GAP_SURFACE, t, state)).max(0.0);
        let (mut sin_k, mut cos_k) = (sin, cos);
        for coefficient in self.fourier.iter_mut() {
            coefficient[0] += weight * u * cos_k;
            coefficient[1] += weight * u * sin_k;
            (sin_k, cos_k) = (sin_k * cos + cos_k * sin, cos_k * cos - sin_k * sin);
        }
    }

    /// The observables of the window (call after the solver has reached `t0 + T`).
    pub fn finish(&self, model: &TappingModel) -> OrbitObservables {
        let k = self.window_periods as f64;
        let scale = 2.0 / (k * self.period);
        let harmonics: Vec<Harmonic> = self
            .fourier
            .iter()
            .enumerate()
            .map(|(index, &[a, b])| Harmonic {
                n: index + 1,
                amplitude_nm: scale * a.hypot(b),
                phase_deg: b.atan2(a).to_degrees(),
            })
            .collect();
        let gap_minima = self.gap_minima();
        let impacts = self.impacts(model, &gap_minima);
        let peak_force_nn = impacts
            .iter()
            .map(|impact| impact.peak_force_nn)
            .fold(0.0, f64::max);
        let contact_time_periods = impacts.iter().fold(0.0, |sum, impact| {
            sum + (impact.end_periods - impact.start_periods)
        }) / k;
        let per_period = NN_NM_IN_EV / k;
        let mode_energy: Vec<ModeEnergy> = self
            .modes
            .iter()
            .zip(&self.mode_integrals)
            .zip(&self.contact_work)
            .enumerate()
            .map(|(i, ((constants, integrals), work))| {
                let energy = |x: &[f64]| constants.energy(x[2 * i], x[2 * i + 1]);
                ModeEnergy {
                    drive_work_ev: per_period * integrals.drive_work,
                    damping_loss_ev: per_period * constants.damping * integrals.velocity_square,
                    dissipated_share_ev: -per_period * work,
                    stored_energy_change_ev: per_period
                        * (energy(&self.end_state) - energy(&self.start_state)),
                }
            })
            .collect();
        let total_damping: f64 = mode_energy.iter().map(|mode| mode.damping_loss_ev).sum();
        let largest_residual = mode_energy
            .iter()
            .map(|mode| mode.residual_ev().abs())
            .fold(0.0, f64::max);
        let largest_residual = largest_residual.max(self.sample_residual_ev(model, &mode_energy));
        let energy_balance_residual = if total_damping > 0.0 {
            largest_residual / total_damping
        } else {
            0.0
        };
        // The deepest point below the contact surface `h_0 = 0`: a gap minimum (recorded as
        // `h_0 + d_c`), or a window end in contact.
        let max_indentation_nm = gap_minima
            .iter()
            .map(|minimum| self.contact_gap - minimum.gap_nm)
            .chain(
                [
                    (self.gap_at_start, self.start, &self.start_state),
                    (self.gap_at_end, self.end, &self.end_state),
                ]
                .into_iter()
                .filter(|(gap, _, _)| gap.is_finite())
                .map(|(_, t, x)| -model.switching(GAP_SURFACE, t, x)),
            )
            .fold(0.0, f64::max);
        let contact_time_us = contact_time_periods * k * self.period;
        let mean_indentation_nm = if contact_time_us > 0.0 {
            self.indentation / contact_time_us
        } else {
            0.0
        };
        OrbitObservables {
            window_periods: self.window_periods,
            amplitude_nm: harmonics[0].amplitude_nm,
            amplitude_ratio: harmonics[0].amplitude_nm / self.free_amplitude,
            phase_deg: harmonics[0].phase_deg,
            harmonics,
            impacts_per_period: impacts.len() as f64 / k,
            impacts,
            gap_minima,
            peak_force_nn,
            mean_force_nn: self.impulse / (k * self.period),
            contact_time_periods,
            impulse_nn_us: self.impulse / k,
            dissipated_ev: self.dissipated_ev(model, &mode_energy),
            base_work_ev: per_period * self.base_work,
            second_drive: self.second_fourier.map(|(_, [a, b])| SecondDriveResponse {
                amplitude_nm: scale * a.hypot(b),
                phase_deg: b.atan2(a).to_degrees(),
            }),
            virial_ev: NN_NM_IN_EV * self.virial / (k * self.period),
            max_indentation_nm,
            mean_indentation_nm,
            energy_balance_residual,
            mode_energy,
        }
    }

    /// The energy dissipated in the sample per drive period, `E_ts = -int F_ts (w' + y_base')
    /// dt`, eV (MODEL.md section 10). For a force with an energy `U(d)` (a conservative law),
    /// exactly `U(d_end) - U(d_start) + Z' int F_ts dt`, as `w' + y_base' = d' - Z'`: zero
    /// over a closed orbit, with no quadrature error. Otherwise the modes' shares (quadrature
    /// on the dense output) less the base's work.
    fn dissipated_ev(&self, model: &TappingModel, mode_energy: &[ModeEnergy]) -> f64 {
        let per_period = NN_NM_IN_EV / self.window_periods as f64;
        let force = model.contact_force();
        match (
            force.potential_nn_nm(self.gap_at_start),
            force.potential_nn_nm(self.gap_at_end),
        ) {
            (Some(start), Some(end)) => {
                per_period * (end - start + model.separation().rate() * self.impulse)
            }
            _ => {
                mode_energy
                    .iter()
                    .map(|mode| mode.dissipated_share_ev)
                    .sum::<f64>()
                    - per_period * self.base_work
            }
        }
    }

    /// A standard linear solid's balance `W_s = D_s + dU_s` per drive period (MODEL.md
    /// section 10): the work done on the sample along the whole gap, `W_s = -int F_ts d' dt =
    /// -sum_i int F_ts q_i' dt - int F_ts y_base' dt - Z' int F_ts dt`, against the dashpot's
    /// loss and the change of the sample's stored energy (both functions of the gap `d`), eV
    /// (0 for other laws).
    fn sample_residual_ev(&self, model: &TappingModel, mode_energy: &[ModeEnergy]) -> f64 {
        let Some(sls) = &self.relaxing else {
            return 0.0;
        };
        let k = self.window_periods as f64;
        let per_period = NN_NM_IN_EV / k;
        let work: f64 = mode_energy
            .iter()
            .map(|mode| mode.dissipated_share_ev)
            .sum::<f64>()
            - per_period * (self.base_work + model.separation().rate() * self.impulse);
        let stored = |t: f64, x: &[f64]| sls.stored_energy(model.gap(t, x), model.sample_state(x));
        let change = stored(self.end, &self.end_state) - stored(self.start, &self.start_state);
        (work - per_period * (self.dashpot_loss + change)).abs()
    }

    fn periods(&self, t: f64) -> f64 {
        (t - self.start) / self.period
    }

    fn gap_minima(&self) -> Vec<GapMinimum> {
        let mut minima: Vec<(f64, f64)> = self.minima.clone();
        minima.sort_by(|x, y| x.0.total_cmp(&y.0));
        minima.dedup_by(|later, earlier| (later.0 - earlier.0) < DUPLICATE_FRACTION * self.period);
        minima
            .iter()
            .map(|&(t, height)| GapMinimum {
                t_periods: self.periods(t),
                gap_nm: height + self.contact_gap,
                kind: GapMinimumKind::of(height, self.free_amplitude),
            })
            .collect()
    }

    /// Impacts from the events; an impact in progress at both ends of the window is one impact
    /// (the window of a periodic orbit), reported last with `end_periods > 1`.
    fn impacts(&self, model: &TappingModel, minima: &[GapMinimum]) -> Vec<Impact> {
        // (start, end, velocity) in periods; a start of 0 with NaN velocity is a head fragment.
        let mut intervals: Vec<(f64, f64, f64)> = Vec::new();
        let mut open: Option<(f64, f64)> = self.starts_in_contact.then_some((0.0, f64::NAN));
        for &(t, direction, rate) in &self.events {
            match direction {
                Direction::Down => open = Some((self.periods(t), rate)),
                Direction::Up => {
                    if let Some((start, velocity)) = open.take() {
                        intervals.push((start, self.periods(t), velocity));
                    }
                }
            }
        }
        let tail = open;
        let head_fragment = self.starts_in_contact && !intervals.is_empty();
        let peak_in = |from: f64, to: f64| {
            if self.relaxing.is_some() {
                return self
                    .minimum_forces
                    .iter()
                    .filter(|(t, _)| (from..=to).contains(&self.periods(*t)))
                    .map(|&(_, force)| force)
                    .fold(0.0, f64::max);
            }
            minima
                .iter()
                .filter(|minimum| minimum.t_periods >= from && minimum.t_periods <= to)
                .map(|minimum| model.force_at_gap_minimum(minimum.gap_nm))
                .fold(0.0, f64::max)
        };
        let (boundary_start, boundary_end) = if self.relaxing.is_some() {
            let at = |t: f64, x: &[f64]| {
                if x.iter().all(|v| v.is_finite()) {
                    model.tip_sample_force(t, x)
                } else {
                    0.0
                }
            };
            (
                at(self.start, &self.start_state),
                at(self.end, &self.end_state),
            )
        } else {
            (
                model.force_at_gap_minimum(self.gap_at_start),
                model.force_at_gap_minimum(self.gap_at_end),
            )
        };
        let mut impacts = Vec::with_capacity(intervals.len() + 1);
        let mut head: Option<(f64, f64)> = None; // (end, peak) of the head fragment
        for (index, &(start, end, velocity)) in intervals.iter().enumerate() {
            let mut peak = peak_in(start, end);
            if index == 0 && head_fragment {
                peak = peak.max(boundary_start);
                if tail.is_some() {
                    head = Some((end, peak));
                    continue;
                }
            }
            impacts.push(Impact {
                start_periods: start,
                end_periods: end,
                velocity_nm_per_us: velocity,
                peak_force_nn: peak,
            });
        }
        let window = self.window_periods as f64;
        if let Some((start, velocity)) = tail {
            let mut peak = peak_in(start, window).max(boundary_end);
            let mut end = window;
            if let Some((head_end, head_peak)) = head {
                end = window + head_end;
                peak = peak.max(head_peak);
            } else if self.starts_in_contact && intervals.is_empty() {
                // In contact throughout the window.
                peak = peak.max(boundary_start);
            }
            impacts.push(Impact {
                start_periods: start,
                end_periods: end,
                velocity_nm_per_us: velocity,
                peak_force_nn: peak,
            });
        }
        impacts
    }
}

/// Integrate `model` over one period from `(t0, x0)` and return the flow map (state, monodromy
/// and `dx/dZ` as `sensitivity` asks, events, extrema) with the period's observables, harmonics
/// `1..=harmonic_count` of `u` included ([`observe_window_in`] over one period).
pub fn observe_period(
    model: &TappingModel,
    t0: f64,
    x0: &[f64],
    sensitivity: Sensitivity,
    settings: &Settings,
    harmonic_count: usize,
) -> Result<(FlowMap, OrbitObservables), AfmError> {
    observe_period_in(
        model,
        t0,
        x0,
        sensitivity,
        settings,
        harmonic_count,
        &mut SolverWorkspace::default(),
    )
}

/// As [`observe_period`], the solver's buffers taken from `workspace` and handed back to it
/// ([`hybrid::flow_map_in`]): the same result, without the allocations of a new solver.
pub fn observe_period_in(
    model: &TappingModel,
    t0: f64,
    x0: &[f64],
    sensitivity: Sensitivity,
    settings: &Settings,
    harmonic_count: usize,
    workspace: &mut SolverWorkspace,
) -> Result<(FlowMap, OrbitObservables), AfmError> {
    check_state(model, x0)?;
    let observer = PeriodObserver::new(model, t0, x0, harmonic_count);
    observe_in(model, observer, x0, sensitivity, settings, workspace)
}

/// The observables of the whole period-`k` orbit of `model` through `x0` at `t = 0`
/// (`k = multiplicity`, at least 1): one window of `k` drive periods, so that an impact in
/// progress across a period boundary is one impact and every list and integral covers the
/// orbit. Also returns the state after the `k` periods (`x0` again, to the integration's
/// accuracy, on a converged orbit), with harmonics `1..=harmonic_count` of `u`. The solver's
/// buffers come from `workspace`.
pub fn observe_orbit_in(
    model: &TappingModel,
    x0: &[f64],
    multiplicity: usize,
    settings: &Settings,
    harmonic_count: usize,
    workspace: &mut SolverWorkspace,
) -> Result<(Vec<f64>, OrbitObservables), AfmError> {
    check_state(model, x0)?;
    let observer = PeriodObserver::over_periods(model, 0.0, x0, multiplicity, harmonic_count);
    observe_in(model, observer, x0, Sensitivity::None, settings, workspace)
        .map(|(flow, observables)| (flow.state, observables))
}

/// An error unless `x0` has the model's dimension.
fn check_state(model: &TappingModel, x0: &[f64]) -> Result<(), AfmError> {
    if x0.len() != model.dim() {
        return Err(invalid(
            "orbit observables",
            "x0.len()",
            x0.len() as f64,
            format!("the model's dimension 2N = {}", model.dim()),
        ));
    }
    Ok(())
}

/// Integrate `model` from `x0` over the window of `observer` (from its start) and return the
/// flow map with the window's observables.
fn observe_in(
    model: &TappingModel,
    mut observer: PeriodObserver,
    x0: &[f64],
    sensitivity: Sensitivity,
    settings: &Settings,
    workspace: &mut SolverWorkspace,
) -> Result<(FlowMap, OrbitObservables), AfmError> {
    let flow = flow_map_in(
        model,
        observer.start,
        x0,
        observer.window_periods as f64 * observer.period,
        sensitivity,
        settings,
        &mut |solver: &Solver<TappingModel>, outcome: &StepOutcome| {
            observer.observe(solver, outcome)
        },
        workspace,
    )?;
    let observables = observer.finish(model);
    Ok((flow, observables))
}

/// The observables of one period of `model` from state `x0` at `t = 0` (MODEL.md sections 4
/// and 10), with harmonics `1..=harmonic_count` of `u`.
pub fn orbit_observables(
    model: &TappingModel,
    x0: &[f64],
    settings: &Settings,
    harmonic_count: usize,
) -> Result<OrbitObservables, AfmError> {
    observe_period(model, 0.0, x0, Sensitivity::None, settings, harmonic_count)
        .map(|(_, observables)| observables)
}
