//! Time-domain approach and retract sweeps, as in the paper's simulations and in every
//! experiment: the separation moves at a constant rate, `Z(t) = Z_start - rate t` (approach)
//! and then, optionally, `Z(t) = Z_floor + rate t` (retract), while the cantilever of Eq. 1 is
//! integrated without interruption and a lock-in amplifier ([`crate::orbit::lockin`]) reads the
//! first harmonic of `u` once per block of drive cycles (MODEL.md section 4).
//!
//! # Time keeping
//!
//! The clock restarts at every drive cycle: cycle `k` is integrated over local time
//! `t in [0, T]` with
//! [`Separation::Ramp`](crate::model::separation::Separation::Ramp) whose `z0` is `Z` at the
//! cycle's start, computed from the cycle index (`Z_start -/+ k rate T`, no accumulated
//! sum). The drive `cos(w t)` is `T`-periodic, so the restart changes nothing physically,
//! while every time, drive phase and event tolerance stays that of a single period
//! (absolute times would reach 1e7 us over a paper-rate sweep). The free flight is propagated
//! by the model's exact flow (the gap moves with `Z(t)`, the free dynamics do not); contacts
//! are integrated with event location, and a gap that dips below zero between samples is still
//! found (see `hybrid::solver`).
//!
//! # Records
//!
//! Cycles are grouped in consecutive, non-overlapping blocks of `lockin_cycles`; each block
//! gives one [`SweepRecord`] (Fourier coefficients averaged over the block), and every
//! `every`-th record is returned. A block never spans the turn from approach to retract: the
//! unfinished block at the floor is discarded. The cycles of the blocks not returned, and the
//! settling cycles, are integrated without the lock-in ([`advance_cycle`]: the same steps,
//! no reading).
//!
//! # Threads
//!
//! One trajectory (`sweep/run.rs`) is integrated cycle after cycle. On rayon's pool of more
//! than one thread the cycles ahead are integrated in speculative segments
//! (`sweep/segments.rs`), whose records are used only from where the true trajectory meets
//! them bit for bit: the records are the same on any number of threads.

pub mod amplitude_ratio;
mod run;
mod segments;

use std::collections::VecDeque;

use hybrid::{HybridSystem, Sensitivity, Settings, Solver, SolverWorkspace, StepOutcome};
use serde::Serialize;

use crate::error::AfmError;
use crate::model::TappingModel;
use crate::orbit::lockin::{BlockReading, CycleLockIn, CycleReading, MAX_LOCKIN_HARMONICS};
use crate::orbit::observables::Harmonic;
use crate::validation::{check, invalid, Interval};
use run::{SweepPlan, SweepRun};
pub use segments::Stop;
use segments::{Segmentation, Served};

/// Microseconds per second: rates are given in nm/s, the model's time is in us.
const US_PER_S: f64 = 1e6;
/// The largest sweep rate accepted, nm/s (Z would move 1 mm per second).
pub const MAX_RATE_NM_PER_S: f64 = 1e6;
/// The largest separation accepted for either end of a sweep, nm.
pub const MAX_SEPARATION_NM: f64 = 1e5;
/// The largest number of cycles in a lock-in block, a decimation step, the settling or one
/// direction of a sweep (at about 46 us per cycle, the Biolever on mica's approach from first
/// contact at 1 nm/s, 1e8 cycles take over an hour).
pub const MAX_CYCLE_COUNT: usize = 100_000_000;
/// The default start of a sweep above first contact `Z_G1`, nm: the free orbit is exact there,
/// so the first records show the free amplitude and phase before the first impact.
pub const DEFAULT_START_MARGIN_NM: f64 = 0.2;

/// The default relative and absolute tolerance of the contact integration in a sweep
/// (nm and nm/us): DOP853 at 1e-8 takes about half the steps it takes at 1e-12, and the
/// readings differ from a run at 1e-13 by ~1e-8 in `A/A0` (see the tests).
pub const DEFAULT_TOLERANCE: f64 = 1e-8;

/// The solver's interior samples per step in a sweep (its default is 8). What is left to
/// sample are contact steps (a few per cent of the ~0.6 us contact of the paper's cantilevers,
/// with one gap minimum per contact) and free flight near the sample (exact steps of a quarter
/// of the second mode's period, whose gap extrema are half a period apart): four points per
/// step resolve both with room to spare, and the test against a brute-force sweep with 64
/// samples per step finds the same impacts in every cycle.
pub const SAMPLES_PER_STEP: usize = 4;

/// Which way the separation moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SweepDirection {
    /// `Z` decreasing (towards the sample).
    Approach,
    /// `Z` increasing (away from the sample).
    Retract,
}

impl SweepDirection {
    /// `approach` or `retract`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Approach => "approach",
            Self::Retract => "retract",
        }
    }
}

/// One lock-in reading of a sweep: a block of `lockin_cycles` drive cycles.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepRecord {
    /// Index of the block's first drive cycle, counted from the start of the approach (the
    /// retract continues the count); settling cycles are not counted.
    pub cycle: u64,
    /// `Z` at the block's middle (the mean of the cycles' mid-cycle separations), nm.
    pub z_nm: f64,
    /// `A / A0`, the first-harmonic amplitude of `u` from the block means of `a` and `b`
    /// (MODEL.md section 4) over the free amplitude.
    pub amplitude_ratio: f64,
    /// The phase lag `Phi = atan2(b, a)` of the first harmonic of `u`, degrees.
    pub phase_deg: f64,
    /// Impacts (contact onsets) per drive cycle, averaged over the block (an integer for a
    /// block of one cycle).
    pub impacts_per_period: f64,
    /// The largest tip-sample force in the block, nN.
    pub peak_force_nn: f64,
    /// Harmonics `1..=N` of `u` from the block means of `a_n` and `b_n` (N =
    /// [`SweepSettings::harmonics`]; MODEL.md section 10).
    pub harmonics: Vec<Harmonic>,
    /// The energy dissipated in the sample per cycle, averaged over the block, eV.
    pub dissipated_ev: f64,
    /// Approach or retract.
    pub direction: SweepDirection,
}

impl SweepRecord {
    fn new(direction: SweepDirection, block: BlockReading) -> Self {
        Self {
            cycle: block.first_cycle,
            z_nm: block.z_nm,
            amplitude_ratio: block.amplitude_ratio,
            phase_deg: block.phase_deg,
            impacts_per_period: block.impacts_per_cycle,
            peak_force_nn: block.peak_force_nn,
            harmonics: block.harmonics[..block.harmonic_count]
                .iter()
                .enumerate()
                .map(|(index, &[a, b])| Harmonic {
                    n: index + 1,
                    amplitude_nm: a.hypot(b),
                    phase_deg: b.atan2(a).to_degrees(),
                })
                .collect(),
            dissipated_ev: block.dissipated_ev,
            direction,
        }
    }
}

/// What a sweep does. Every field is checked by [`SweepSettings::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSettings {
    /// Separation at the start of the approach, nm, in `(to_nm, 1e5]`. Default: first contact
    /// `Z_G1` plus [`DEFAULT_START_MARGIN_NM`].
    pub from_nm: f64,
    /// The floor: separation at the end of the approach, nm, in `[0, from_nm)`. Default 0
    /// (the base at the sample's surface, as in the paper).
    pub to_nm: f64,
    /// The speed `|dZ/dt|`, nm/s, in `(0, 1e6]`. Default 1 (the paper's rate).
    pub rate_nm_per_s: f64,
    /// Whether to retract from the floor back up to `from_nm` after the approach.
    /// Default `false`.
    pub retract: bool,
    /// Drive cycles integrated at the fixed separation `from_nm`, from the free steady state,
    /// before the sweep starts (transients decay by `exp(-pi / Q_1)` per cycle). Range
    /// `0..=1e8`; default 20. Not reported.
    pub settle_cycles: usize,
    /// Cycles per lock-in block (consecutive, non-overlapping), `1..=1e8`; default 1.
    pub lockin_cycles: usize,
    /// Return every `every`-th block's record (the first of each direction included),
    /// `1..=1e8`; default 1.
    pub every: usize,
    /// The harmonics `1..=harmonics` of `u` each reading gives, `1..=`
    /// [`crate::orbit::lockin::MAX_LOCKIN_HARMONICS`]; default 4.
    pub harmonics: usize,
    /// Settings of the hybrid solver. Default: `hybrid::Settings::default()` with relative and
    /// absolute tolerances [`DEFAULT_TOLERANCE`] (the lock-in's targets, 1e-3 in `A/A0` and 0.1
    /// deg, are six orders above the error this leaves; the free flight is exact regardless),
    /// `extremum_height` 0 (the lock-in reads gap minima only in contact, so free flight that
    /// the model proves clear of the sample is not searched for extrema) and
    /// [`SAMPLES_PER_STEP`] samples per step.
    pub integration: Settings,
}

impl SweepSettings {
    /// The defaults for `model`: from `Z_G1 + 0.2 nm` down to 0 at 1 nm/s, no retract, 20
    /// settling cycles, one cycle per record.
    pub fn for_model(model: &TappingModel) -> Self {
        Self {
            from_nm: model.grazing_separation_nm() + DEFAULT_START_MARGIN_NM,
            to_nm: 0.0,
            rate_nm_per_s: 1.0,
            retract: false,
            settle_cycles: 20,
            lockin_cycles: 1,
            every: 1,
            harmonics: 4,
            integration: Settings {
                relative_tolerance: DEFAULT_TOLERANCE,
                absolute_tolerance: DEFAULT_TOLERANCE,
                // The lock-in reads only gap minima in contact, which are found at any height
                // (they lie inside the sample): free flight proven clear of the sample is not
                // searched for extrema.
                extremum_height: 0.0,
                samples_per_step: SAMPLES_PER_STEP,
                ..Settings::default()
            },
        }
    }

    /// Check every field (errors name the field and its allowed range).
    pub fn validate(&self) -> Result<(), AfmError> {
        const FILE: &str = "sweep settings";
        check(
            FILE,
            "rate_nm_per_s",
            self.rate_nm_per_s,
            Interval::positive(MAX_RATE_NM_PER_S, "nm/s"),
        )?;
        check(
            FILE,
            "to_nm",
            self.to_nm,
            Interval::closed(0.0, MAX_SEPARATION_NM, "nm"),
        )?;
        check(
            FILE,
            "from_nm",
            self.from_nm,
            Interval::left_open(self.to_nm, MAX_SEPARATION_NM, "nm (above to_nm)"),
        )?;
        for (field, value, min) in [
            ("settle_cycles", self.settle_cycles, 0),
            ("lockin_cycles", self.lockin_cycles, 1),
            ("every", self.every, 1),
        ] {
            if value < min || value > MAX_CYCLE_COUNT {
                return Err(invalid(
                    FILE,
                    field,
                    value as f64,
                    format!("an integer in [{min}, {MAX_CYCLE_COUNT}]"),
                ));
            }
        }
        if !(1..=MAX_LOCKIN_HARMONICS).contains(&self.harmonics) {
            return Err(invalid(
                FILE,
                "harmonics",
                self.harmonics as f64,
                format!("an integer in [1, {MAX_LOCKIN_HARMONICS}]"),
            ));
        }
        self.integration.validate()?;
        Ok(())
    }
}

/// A time-domain approach (and retract) sweep of a [`TappingModel`], run cycle by cycle.
///
/// An iterator of [`SweepRecord`]s: each call of [`Sweep::next_record`] returns the next
/// record, so a caller can stream the records as they come and stop at any time. The first
/// call also integrates the settling cycles. On rayon's pool of more than one thread the
/// cycles ahead are integrated in speculative segments (`sweep/segments.rs`) whose records
/// are the same bits as one thread's; with one thread each call integrates cycles until the
/// next record is due.
#[derive(Debug)]
pub struct Sweep {
    /// The trajectory's frontier: the run after the last cycle integrated.
    frontier: SweepRun,
    /// Records integrated ahead of the caller (by segments), in order.
    ahead: VecDeque<Served>,
    /// How the cycles ahead are cut into segments on several threads.
    segmentation: Segmentation,
    /// Cycles done at the last record returned and the state then, when it came from
    /// `ahead` (else the frontier's).
    served: Option<(u64, Vec<f64>)>,
    finished: bool,
}

impl Sweep {
    /// A sweep of `model` (its separation law is replaced) with `settings`, starting from the
    /// free steady state (exact above first contact) at `settings.from_nm`.
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] for invalid settings, a sweep shorter than one drive cycle,
    /// or a lock-in block longer than one sweep direction.
    pub fn new(model: &TappingModel, settings: SweepSettings) -> Result<Self, AfmError> {
        settings.validate()?;
        let period = model.period_us();
        let rate_nm_per_us = settings.rate_nm_per_s / US_PER_S;
        let z_step_nm = rate_nm_per_us * period;
        let span = settings.from_nm - settings.to_nm;
        // Full cycles that fit between `from` and `to` (a relative slack of 1e-9 keeps an
        // exact multiple from losing its last cycle to rounding).
        let cycles_per_leg = (span / z_step_nm * (1.0 + 1e-9)).floor();
        if !(1.0..=MAX_CYCLE_COUNT as f64).contains(&cycles_per_leg) {
            return Err(invalid(
                "sweep settings",
                "from_nm - to_nm",
                span,
                format!(
                    "at least one drive cycle at the rate given ({z_step_nm:e} nm per cycle) \
                     and at most {MAX_CYCLE_COUNT:e} cycles per direction (tens of \
                     microseconds each: {MAX_CYCLE_COUNT:e} take over an hour)"
                ),
            ));
        }
        let cycles_per_leg = cycles_per_leg as u64;
        if settings.lockin_cycles as u64 > cycles_per_leg {
            return Err(invalid(
                "sweep settings",
                "lockin_cycles",
                settings.lockin_cycles as f64,
                format!("at most the {cycles_per_leg} drive cycles of one sweep direction"),
            ));
        }
        let plan = SweepPlan {
            from_nm: settings.from_nm,
            rate_nm_per_us,
            z_step_nm,
            cycles_per_leg,
            floor_nm: settings.from_nm - cycles_per_leg as f64 * z_step_nm,
            lockin_cycles: settings.lockin_cycles as u64,
            retract: settings.retract,
        };
        Ok(Self {
            frontier: SweepRun::new(model.clone(), settings, plan)?,
            ahead: VecDeque::new(),
            segmentation: Segmentation::for_model(model),
            served: None,
            finished: false,
        })
    }

    /// The settings in use.
    pub fn settings(&self) -> &SweepSettings {
        self.frontier.settings()
    }

    /// Drive cycles in each direction (the approach, and the retract if asked).
    pub fn cycles_per_leg(&self) -> u64 {
        self.frontier.plan().cycles_per_leg
    }

    /// Drive cycles of the whole sweep (settling excluded).
    pub fn total_cycles(&self) -> u64 {
        self.frontier.plan().total_cycles()
    }

    /// Drive cycles integrated up to the last record returned (settling excluded); after an
    /// error, the cycles before the failing one.
    pub fn cycles_done(&self) -> u64 {
        match &self.served {
            Some((cycles, _)) => *cycles,
            None => self.frontier.cycles_done(),
        }
    }

    /// `Z` at the end of the approach (where the retract starts), nm: `from_nm` minus a whole
    /// number of cycles, within one cycle's travel above `to_nm`.
    pub fn floor_nm(&self) -> f64 {
        self.frontier.plan().floor_nm
    }

    /// The direction of the next cycle (of the last one once the sweep has finished).
    pub fn direction(&self) -> SweepDirection {
        let plan = self.frontier.plan();
        if self.cycles_done() < plan.cycles_per_leg || !plan.retract {
            SweepDirection::Approach
        } else {
            SweepDirection::Retract
        }
    }

    /// The separation at the end of the cycles counted by [`Sweep::cycles_done`], nm.
    pub fn z_nm(&self) -> f64 {
        self.frontier.plan().z_nm(self.cycles_done())
    }

    /// The cantilever state `[q_1, q_1', ..., q_N, q_N']` (nm, nm/us; and the sample's state
    /// for a standard linear solid) at the end of the cycles counted by
    /// [`Sweep::cycles_done`].
    pub fn state(&self) -> &[f64] {
        match &self.served {
            Some((_, state)) => state,
            None => self.frontier.state(),
        }
    }

    /// The next record; `None` when the sweep is over. After an error the sweep is over.
    ///
    /// # Errors
    /// [`AfmError::Solver`] if the hybrid solver fails in a cycle.
    pub fn next_record(&mut self) -> Result<Option<SweepRecord>, AfmError> {
        self.next_record_until(&|| false)
    }

    /// [`Sweep::next_record`], asking `stop` between cycles (on every thread the sweep uses):
    /// once it answers `true` (and from then on), the sweep ends and `None` is returned.
    ///
    /// # Errors
    /// [`AfmError::Solver`] if the hybrid solver fails in a cycle.
    pub fn next_record_until(&mut self, stop: &Stop<'_>) -> Result<Option<SweepRecord>, AfmError> {
        if self.finished {
            return Ok(None);
        }
        // Segments until one holds a record (a group of them may hold none), or the cycles
        // left one after the other.
        while self.ahead.is_empty() {
            if stop() {
                self.finished = true;
                return Ok(None);
            }
            let threads = rayon::current_num_threads();
            let settled = self.frontier.settle();
            if settled.is_ok() && self.segmentation.worth_it(&self.frontier, threads) {
                segments::integrate_ahead(
                    &mut self.segmentation,
                    &mut self.frontier,
                    &mut self.ahead,
                    stop,
                );
                if stop() {
                    self.finished = true;
                    self.ahead.clear();
                    return Ok(None);
                }
                continue;
            }
            self.served = None;
            let result = settled.and_then(|()| self.frontier.next_record_until(stop));
            if !matches!(result, Ok(Some(_))) {
                self.finished = true;
            }
            return result;
        }
        let served = self.ahead.pop_front().expect("records ahead");
        self.served = Some((served.cycles_done, served.state));
        match served.outcome {
            Ok(record) => Ok(Some(record)),
            Err(error) => {
                self.finished = true;
                self.ahead.clear();
                Err(error)
            }
        }
    }
}

/// Integrate one drive cycle (local time `[0, T]`) of `model` under its separation law from
/// `state` (replaced by the state at the cycle's end), and return `lockin`'s reading of it
/// (MODEL.md section 4). The solver's buffers are taken from `workspace` and given back, so
/// that a sequence of cycles allocates nothing. Shared by the sweep and the time-domain scan
/// (`crate::scan`).
pub fn integrate_cycle(
    model: &TappingModel,
    integration: &Settings,
    state: &mut [f64],
    workspace: &mut SolverWorkspace,
    lockin: &mut CycleLockIn,
) -> Result<CycleReading, AfmError> {
    lockin.begin(model, state);
    step_through_cycle(model, integration, state, workspace, |solver, outcome| {
        lockin.observe(solver, outcome);
    })?;
    let reading = lockin.finish(model, state);
    debug_assert_eq!(state.len(), model.dim());
    Ok(reading)
}

/// Integrate one drive cycle (local time `[0, T]`) of `model` under its separation law from
/// `state` (replaced by the state at the cycle's end) without reading it: the same steps and
/// states as [`integrate_cycle`], for cycles whose reading nobody asks for. The solver's
/// buffers are taken from `workspace` and given back.
pub fn advance_cycle(
    model: &TappingModel,
    integration: &Settings,
    state: &mut [f64],
    workspace: &mut SolverWorkspace,
) -> Result<(), AfmError> {
    step_through_cycle(model, integration, state, workspace, |_, _| {})
}

/// The solver's steps over one drive cycle from `state` (replaced by the state at the cycle's
/// end), each handed to `observe` as it is taken; the solver's buffers are taken from
/// `workspace` and given back. The one loop of [`integrate_cycle`] and [`advance_cycle`].
#[inline(always)]
fn step_through_cycle(
    model: &TappingModel,
    integration: &Settings,
    state: &mut [f64],
    workspace: &mut SolverWorkspace,
    mut observe: impl FnMut(&Solver<TappingModel>, &StepOutcome),
) -> Result<(), AfmError> {
    let period = model.period_us();
    let mut solver = Solver::with_workspace(
        model,
        0.0,
        state,
        Sensitivity::None,
        integration.clone(),
        std::mem::take(workspace),
    )?;
    loop {
        let outcome = solver.step(period)?;
        observe(&solver, &outcome);
        if matches!(outcome, StepOutcome::EndTime) {
            break;
        }
    }
    state.copy_from_slice(solver.state());
    *workspace = solver.into_workspace();
    Ok(())
}

impl Iterator for Sweep {
    type Item = Result<SweepRecord, AfmError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.next_record().transpose()
    }
}
