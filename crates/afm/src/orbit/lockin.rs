//! The lock-in amplifier of a time-domain sweep (MODEL.md section 4): the first-harmonic
//! Fourier coefficients of the photodiode signal `u` demodulated over each drive cycle,
//!
//! ```text
//! a = (2/T) int_0^T u cos(w t) dt,   b = (2/T) int_0^T u sin(w t) dt,
//! A = hypot(a, b),   Phi = atan2(b, a)  (degrees, a lag),
//! ```
//!
//! with `t` measured from the cycle's start (drive phase zero), together with the impacts
//! (contact onsets, MODEL.md section 5), the peak Hertz force, the higher harmonics `n = 2..N`
//! likewise and the energy dissipated in the sample (MODEL.md section 10) in the cycle; and the average
//! of those readings over consecutive blocks of `N` cycles, as a lock-in amplifier with an
//! integration time of `N T` reports them.
//!
//! The integrals are taken in closed form over every free-flight interval
//! ([`crate::model::free_flight_fourier`], exact to rounding) and by 4-point Gauss-Legendre quadrature
//! over every contact step (to dense-output accuracy). Nothing here allocates after
//! construction.

use hybrid::{Direction, ExtremumKind, HybridSystem, Mode, Solver, StepOutcome};

use crate::model::free_flight_fourier::FreeFlightFourier;
use crate::model::TappingModel;
use crate::model::GAP_SURFACE;
use crate::orbit::gauss_legendre::GAUSS_LEGENDRE_4;
use crate::orbit::observables::NN_NM_IN_EV;

/// The most harmonics of `u` a lock-in reads per cycle (its readings are fixed-size, so a
/// sweep allocates nothing per cycle).
pub const MAX_LOCKIN_HARMONICS: usize = 20;

/// The number of harmonics n = 1..N of u that orbits, diagram points and lock-in readings
/// report unless told otherwise (MODEL.md section 10).
pub const DEFAULT_HARMONICS: usize = 4;

/// What the lock-in reads over one drive cycle `[0, T]` (time from the cycle's start).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleReading {
    /// `a = (2/T) int u cos(w t) dt`, nm.
    pub cosine_nm: f64,
    /// `b = (2/T) int u sin(w t) dt`, nm.
    pub sine_nm: f64,
    /// Contact onsets in the cycle (`Direction::Down` crossings of `d = 0`); a contact in
    /// progress at the cycle's start was counted in the cycle where it began; a cycle in
    /// contact throughout (no crossing) counts one, as an orbit in permanent contact does
    /// (MODEL.md section 5).
    pub impacts: usize,
    /// The largest Hertz force `F_ts(d)` in the cycle, nN (0 without contact): the deepest gap
    /// minimum of every contact, and the force at the cycle's ends for a contact that spans a
    /// cycle boundary.
    pub peak_force_nn: f64,
    /// `[a_n, b_n] = (2/T) int u [cos(n w t), sin(n w t)] dt`, nm, for `n = 1..=harmonic_count`
    /// (`harmonics[0]` is `[cosine_nm, sine_nm]`; the rest are zero).
    pub harmonics: [[f64; 2]; MAX_LOCKIN_HARMONICS],
    /// The harmonics read (at least 1).
    pub harmonic_count: usize,
    /// The energy dissipated in the sample over the cycle, `-int F_ts w' dt` (`w = sum_i q_i`),
    /// eV (MODEL.md section 10).
    pub dissipated_ev: f64,
}

/// Accumulates a [`CycleReading`] from the steps of a solver that integrates one drive cycle
/// of a [`TappingModel`] with local time `t` in `[0, T]`: call [`CycleLockIn::begin`], then
/// [`CycleLockIn::observe`] after every `Solver::step`, then [`CycleLockIn::finish`].
#[derive(Debug, Clone)]
pub struct CycleLockIn {
    period: f64,
    angular_frequency: f64,
    /// `[int u cos(n w t) dt, int u sin(n w t) dt]`, `n = 1..=harmonic_count`.
    fourier: [[f64; 2]; MAX_LOCKIN_HARMONICS],
    harmonic_count: usize,
    /// `int F_ts (w' + y_base') dt` over the cycle, nN nm (`y_base' = 0` but under an acoustic
    /// drive).
    contact_work: f64,
    impacts: usize,
    peak_force: f64,
    /// The states at a contact step's quadrature nodes (`n` per node).
    node_states: Vec<f64>,
    /// The closed form over free flight (`None` near critical damping: quadrature instead).
    free_flight: Option<FreeFlightFourier>,
    /// The mode at the start of the next step (the solver's mode after the last one).
    mode: Mode,
    /// The state at the end of the last step observed.
    previous_state: Vec<f64>,
    /// The end time of the last step observed (a repeated step is not counted twice).
    previous_end: f64,
    /// Start time and state of the free-flight interval in progress, if any.
    free_start: Option<f64>,
    free_state: Vec<f64>,
    /// Scratch for the state at a gap minimum (a standard linear solid's force needs it).
    minimum_state: Vec<f64>,
    /// Whether the cycle started in contact (`h_0 < 0`), and whether it crossed the contact
    /// surface since: a cycle in contact throughout counts one impact (MODEL.md section 5).
    starts_in_contact: bool,
    crossed: bool,
}

impl CycleLockIn {
    /// A lock-in for cycles of `model`'s drive period `T = 2 pi / w` (us), reading the first
    /// harmonic.
    pub fn new(model: &TappingModel) -> Self {
        Self::with_harmonics(model, 1)
    }

    /// A lock-in reading harmonics `1..=harmonic_count` of `u` (clamped to
    /// `1..=`[`MAX_LOCKIN_HARMONICS`]).
    pub fn with_harmonics(model: &TappingModel, harmonic_count: usize) -> Self {
        Self {
            period: model.period_us(),
            angular_frequency: model.drive_angular_frequency(),
            fourier: [[0.0; 2]; MAX_LOCKIN_HARMONICS],
            harmonic_count: harmonic_count.clamp(1, MAX_LOCKIN_HARMONICS),
            contact_work: 0.0,
            impacts: 0,
            peak_force: 0.0,
            node_states: vec![0.0; GAUSS_LEGENDRE_4.len() * model.dim()],
            free_flight: FreeFlightFourier::new(model),
            mode: 0,
            previous_state: vec![0.0; model.dim()],
            previous_end: 0.0,
            free_start: None,
            free_state: vec![0.0; model.dim()],
            minimum_state: vec![0.0; model.dim()],
            starts_in_contact: false,
            crossed: false,
        }
    }

    /// Start a cycle at local time 0 from state `x0` (the model's separation law must be the
    /// one of this cycle): clears the sums and records the contact force at the start.
    pub fn begin(&mut self, model: &TappingModel, x0: &[f64]) {
        self.fourier = [[0.0; 2]; MAX_LOCKIN_HARMONICS];
        self.contact_work = 0.0;
        self.impacts = 0;
        self.peak_force = model.tip_sample_force(0.0, x0);
        self.mode = model.mode_of(0.0, x0);
        self.previous_state.copy_from_slice(x0);
        self.previous_end = 0.0;
        self.free_start = None;
        self.starts_in_contact = model.switching(GAP_SURFACE, 0.0, x0) < 0.0;
        self.crossed = false;
    }

    /// Accumulate the solver's last step: over free flight (exact-flow steps), the closed form
    /// of [`FreeFlightFourier`] once per free-flight interval; over other steps the 4-point
    /// Gauss-Legendre quadrature of `u cos(w t)` and `u sin(w t)` on `Solver::interpolate`.
    /// Also the Hertz force at every gap minimum of the step, and a contact onset if the step
    /// ended at one. A step reported again (`Solver::step` called at its end time) is skipped.
    pub fn observe(&mut self, solver: &Solver<TappingModel>, outcome: &StepOutcome) {
        let model = solver.system();
        let (a, b) = solver.last_step();
        if b > a && b > self.previous_end {
            let closed_form = self.free_flight.is_some() && model.has_force_free_flight(self.mode);
            if closed_form {
                if self.free_start.is_none() {
                    self.free_start = Some(a);
                    self.free_state.copy_from_slice(&self.previous_state);
                }
                if !matches!(outcome, StepOutcome::Internal) {
                    self.close_free_flight(b);
                }
            } else {
                self.close_free_flight(a);
                self.quadrature(solver, model, a, b);
            }
            self.previous_end = b;
            self.previous_state.copy_from_slice(solver.state());
            self.mode = solver.mode();
        }
        for extremum in solver.step_extrema() {
            if extremum.surface == GAP_SURFACE
                && extremum.kind == ExtremumKind::Minimum
                && extremum.value < 0.0
            {
                let force = if model.sample_state_count() > 0 {
                    solver.interpolate(extremum.t, &mut self.minimum_state);
                    model.tip_sample_force(extremum.t, &self.minimum_state)
                } else {
                    model.force_at_gap_minimum(extremum.value + model.contact_gap_nm())
                };
                self.peak_force = self.peak_force.max(force);
            }
        }
        if let StepOutcome::Event(event) = outcome {
            if event.surface == GAP_SURFACE {
                self.crossed = true;
                if event.direction == Direction::Down {
                    self.impacts += 1;
                }
            }
        }
    }

    /// Add the closed-form integrals over the free-flight interval in progress, up to `end`.
    fn close_free_flight(&mut self, end: f64) {
        if let (Some(start), Some(free_flight)) = (self.free_start.take(), &self.free_flight) {
            free_flight.add_harmonics(
                start,
                &self.free_state,
                end,
                &mut self.fourier[..self.harmonic_count],
            );
        }
    }

    /// 4-point Gauss-Legendre quadrature of `u cos(w t)`, `u sin(w t)` over `[a, b]` (inside
    /// the solver's last step), in the step's clock, for contact steps (and for free flight
    /// only near critical damping). The rule is exact for polynomials of degree 7, the degree of
    /// DOP853's dense output, so there its error comes from the drive factor `cos(w t)`: of
    /// order `6e-10 (w h)^8` relative for a step `h`, about 2e-8 even for a step of a quarter
    /// drive period (contact steps are far shorter). A Taylor step's series has degree 20; 8
    /// points instead of 4 moved the readings of `drumroll approach --case biolever-mica --from
    /// 8.8 --to 8.65 --rate 1` by at most 8e-12 in `A/A0` and 6e-11 deg in phase.
    fn quadrature(&mut self, solver: &Solver<TappingModel>, model: &TappingModel, a: f64, b: f64) {
        for (node, state) in
            GAUSS_LEGENDRE_4.step_nodes(solver, a, b, self.angular_frequency, &mut self.node_states)
        {
            let u = model.photodiode(state);
            let (sin, cos) = node.drive;
            let (mut sin_k, mut cos_k) = (sin, cos);
            for coefficient in self.fourier[..self.harmonic_count].iter_mut() {
                coefficient[0] += node.weight * u * cos_k;
                coefficient[1] += node.weight * u * sin_k;
                (sin_k, cos_k) = (sin_k * cos + cos_k * sin, cos_k * cos - sin_k * sin);
            }
            // `w' + y_base'`: the gap's rate less the ramp's (MODEL.md sections 10 and 14).
            let deflection_rate: f64 = state.chunks_exact(2).map(|mode| mode[1]).sum();
            self.contact_work += node.weight
                * model.tip_sample_force_in_mode(self.mode, node.t, state)
                * (deflection_rate + model.base_velocity(node.t));
        }
    }

    /// The reading of the cycle, given the state `x_end` at its end (local time `T`).
    pub fn finish(&mut self, model: &TappingModel, x_end: &[f64]) -> CycleReading {
        self.close_free_flight(self.previous_end);
        let scale = 2.0 / self.period;
        let mut harmonics = [[0.0; 2]; MAX_LOCKIN_HARMONICS];
        for (reading, [a, b]) in harmonics.iter_mut().zip(self.fourier) {
            *reading = [scale * a, scale * b];
        }
        CycleReading {
            cosine_nm: harmonics[0][0],
            sine_nm: harmonics[0][1],
            harmonics,
            harmonic_count: self.harmonic_count,
            dissipated_ev: -NN_NM_IN_EV * self.contact_work,
            impacts: if self.impacts == 0 && self.starts_in_contact && !self.crossed {
                1
            } else {
                self.impacts
            },
            peak_force_nn: self
                .peak_force
                .max(model.tip_sample_force(self.period, x_end)),
        }
    }
}

/// The lock-in output averaged over a block of cycles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockReading {
    /// Index of the block's first cycle, counted from the start of the sweep.
    pub first_cycle: u64,
    /// Cycles in the block.
    pub cycles: usize,
    /// The mean of the cycles' mid-cycle separations, nm (`Z` at the block's middle on a ramp).
    pub z_nm: f64,
    /// `A / A0` from the block means of `a` and `b`.
    pub amplitude_ratio: f64,
    /// `Phi = atan2(mean b, mean a)`, degrees (a lag).
    pub phase_deg: f64,
    /// Impacts per cycle, averaged over the block (an integer when the block is one cycle).
    pub impacts_per_cycle: f64,
    /// The largest Hertz force over the block, nN.
    pub peak_force_nn: f64,
    /// The block means of `[a_n, b_n]`, nm, `n = 1..=harmonic_count` (the rest zero).
    pub harmonics: [[f64; 2]; MAX_LOCKIN_HARMONICS],
    /// The harmonics read.
    pub harmonic_count: usize,
    /// The energy dissipated in the sample per cycle, averaged over the block, eV.
    pub dissipated_ev: f64,
}

/// Averages consecutive, non-overlapping blocks of `N` cycle readings (a lock-in with an
/// integration time of `N T` read once per block): the Fourier coefficients `a`, `b` are
/// averaged, then turned into amplitude and phase.
#[derive(Debug, Clone)]
pub struct BlockAverage {
    cycles_per_block: usize,
    free_amplitude_nm: f64,
    count: usize,
    first_cycle: u64,
    cosine: f64,
    sine: f64,
    z: f64,
    impacts: usize,
    peak_force: f64,
    harmonics: [[f64; 2]; MAX_LOCKIN_HARMONICS],
    harmonic_count: usize,
    dissipated: f64,
}

impl BlockAverage {
    /// Blocks of `cycles_per_block` cycles (at least 1; 0 is treated as 1), normalised by the
    /// free amplitude `A0` (nm).
    pub fn new(cycles_per_block: usize, free_amplitude_nm: f64) -> Self {
        Self {
            cycles_per_block: cycles_per_block.max(1),
            free_amplitude_nm,
            count: 0,
            first_cycle: 0,
            cosine: 0.0,
            sine: 0.0,
            z: 0.0,
            impacts: 0,
            peak_force: 0.0,
            harmonics: [[0.0; 2]; MAX_LOCKIN_HARMONICS],
            harmonic_count: 1,
            dissipated: 0.0,
        }
    }

    /// Add the reading of cycle `cycle` whose mid-cycle separation is `z_nm`; returns the
    /// block's reading when this cycle completes a block.
    pub fn push(&mut self, cycle: u64, z_nm: f64, reading: &CycleReading) -> Option<BlockReading> {
        let complete = self.count_cycle(cycle);
        self.cosine += reading.cosine_nm;
        self.sine += reading.sine_nm;
        self.z += z_nm;
        self.impacts += reading.impacts;
        self.peak_force = self.peak_force.max(reading.peak_force_nn);
        for (sum, [a, b]) in self.harmonics.iter_mut().zip(reading.harmonics) {
            sum[0] += a;
            sum[1] += b;
        }
        self.harmonic_count = reading.harmonic_count;
        self.dissipated += reading.dissipated_ev;
        complete.then(|| self.flush())
    }

    /// Count cycle `cycle` without a reading, for a block whose reading is not wanted (every
    /// cycle of the block is counted so): `true` when this cycle completes the block, which is
    /// then discarded.
    pub fn skip(&mut self, cycle: u64) -> bool {
        let complete = self.count_cycle(cycle);
        if complete {
            self.clear();
        }
        complete
    }

    /// Count cycle `cycle` into the block (the first counted is the block's first cycle):
    /// whether it completes the block. Shared by [`BlockAverage::push`] and
    /// [`BlockAverage::skip`].
    fn count_cycle(&mut self, cycle: u64) -> bool {
        if self.count == 0 {
            self.first_cycle = cycle;
        }
        self.count += 1;
        self.count == self.cycles_per_block
    }

    /// Discard a partly filled block (at a change of sweep direction).
    pub fn clear(&mut self) {
        self.count = 0;
        self.cosine = 0.0;
        self.sine = 0.0;
        self.z = 0.0;
        self.impacts = 0;
        self.peak_force = 0.0;
        self.harmonics = [[0.0; 2]; MAX_LOCKIN_HARMONICS];
        self.dissipated = 0.0;
    }

    fn flush(&mut self) -> BlockReading {
        let n = self.count as f64;
        let (a, b) = (self.cosine / n, self.sine / n);
        let reading = BlockReading {
            first_cycle: self.first_cycle,
            cycles: self.count,
            z_nm: self.z / n,
            amplitude_ratio: a.hypot(b) / self.free_amplitude_nm,
            phase_deg: b.atan2(a).to_degrees(),
            impacts_per_cycle: self.impacts as f64 / n,
            peak_force_nn: self.peak_force,
            harmonics: self.harmonics.map(|[a, b]| [a / n, b / n]),
            harmonic_count: self.harmonic_count,
            dissipated_ev: self.dissipated / n,
        };
        self.clear();
        reading
    }
}
