//! One trajectory of a sweep, integrated cycle by cycle from a state at a cycle: the
//! sequential machine behind [`super::Sweep`], and each speculative segment of
//! [`super::segments`].
//!
//! A run's future depends on nothing but the cycle index it stands at (which fixes `Z` and the
//! block bookkeeping, MODEL.md section 4) and the cantilever state there: the solver's
//! workspace holds storage, not results, the lock-in restarts every cycle and a block's
//! averages are empty at its first cycle. So two runs that reach the same block start with
//! bit-identical states give bit-identical records from there on.

use hybrid::SolverWorkspace;

use crate::error::AfmError;
use crate::model::separation::Separation;
use crate::model::TappingModel;
use crate::orbit::lockin::{BlockAverage, CycleLockIn, CycleReading};

use super::segments::Stop;
use super::{advance_cycle, integrate_cycle, SweepDirection, SweepRecord, SweepSettings};

/// The sweep's schedule: which separation law, direction and lock-in block each drive cycle
/// belongs to, from the settings and the drive period alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SweepPlan {
    /// `Z` at the start of the approach, nm.
    pub from_nm: f64,
    /// `|dZ/dt|`, nm/us.
    pub rate_nm_per_us: f64,
    /// `|dZ|` per drive cycle, nm.
    pub z_step_nm: f64,
    /// Cycles in each direction.
    pub cycles_per_leg: u64,
    /// `Z` at the end of the approach (the retract's start), nm.
    pub floor_nm: f64,
    /// Cycles per lock-in block.
    pub lockin_cycles: u64,
    /// Whether the retract follows the approach.
    pub retract: bool,
}

impl SweepPlan {
    /// Cycles of the whole sweep (settling excluded).
    pub fn total_cycles(&self) -> u64 {
        if self.retract {
            2 * self.cycles_per_leg
        } else {
            self.cycles_per_leg
        }
    }

    /// `Z` at the start of cycle `k` (at the end of cycle `k - 1`), nm.
    pub fn z_nm(&self, k: u64) -> f64 {
        if k <= self.cycles_per_leg {
            self.from_nm - k as f64 * self.z_step_nm
        } else {
            self.floor_nm + (k - self.cycles_per_leg) as f64 * self.z_step_nm
        }
    }

    /// The direction, separation law (local time restarting at 0) and mid-cycle `Z` (nm) of
    /// cycle `k`.
    pub fn cycle(&self, k: u64) -> (SweepDirection, Separation, f64) {
        if k < self.cycles_per_leg {
            let z0 = self.from_nm - k as f64 * self.z_step_nm;
            (
                SweepDirection::Approach,
                Separation::Ramp {
                    z0_nm: z0,
                    rate_nm_per_us: self.rate_nm_per_us,
                },
                z0 - 0.5 * self.z_step_nm,
            )
        } else {
            let z0 = self.floor_nm + (k - self.cycles_per_leg) as f64 * self.z_step_nm;
            (
                SweepDirection::Retract,
                Separation::Ramp {
                    z0_nm: z0,
                    rate_nm_per_us: -self.rate_nm_per_us,
                },
                z0 + 0.5 * self.z_step_nm,
            )
        }
    }

    /// The first cycle of the leg that cycle `k` belongs to (0, or `cycles_per_leg` for the
    /// retract).
    fn leg_start(&self, k: u64) -> u64 {
        if k < self.cycles_per_leg {
            0
        } else {
            self.cycles_per_leg
        }
    }

    /// Whether a lock-in block starts at cycle `k`: its leg's start plus a whole number of
    /// blocks, or the turn (where the approach's unfinished block is discarded), or the end.
    pub fn is_block_start(&self, k: u64) -> bool {
        k >= self.total_cycles() || (k - self.leg_start(k)).is_multiple_of(self.lockin_cycles)
    }

    /// The first block start at or after cycle `k` (at most the end of the sweep).
    pub fn block_start_from(&self, k: u64) -> u64 {
        let total = self.total_cycles();
        if k >= total {
            return total;
        }
        let leg = self.leg_start(k);
        let start = leg + (k - leg).div_ceil(self.lockin_cycles) * self.lockin_cycles;
        if leg == 0 && start >= self.cycles_per_leg {
            self.cycles_per_leg.min(total)
        } else {
            start.min(total)
        }
    }

    /// The blocks completed in cycle `k`'s leg before a block that starts at `k`.
    fn blocks_before(&self, k: u64) -> u64 {
        (k - self.leg_start(k)) / self.lockin_cycles
    }
}

/// One trajectory of the sweep: the cantilever state at a cycle, and the buffers that
/// integrate the next cycles.
#[derive(Debug, Clone)]
pub(super) struct SweepRun {
    model: TappingModel,
    settings: SweepSettings,
    plan: SweepPlan,
    state: Vec<f64>,
    /// The solver's buffers between cycles (each cycle's solver takes them and gives them
    /// back, so that cycles allocate nothing).
    workspace: SolverWorkspace,
    lockin: CycleLockIn,
    average: BlockAverage,
    /// Cycles done since the start of the approach.
    cycles_done: u64,
    /// Blocks completed in the current direction.
    blocks_in_leg: u64,
    settled: bool,
}

impl SweepRun {
    /// The run from the free steady state at `settings.from_nm`, before its settling cycles.
    /// `model`'s separation law is replaced cycle by cycle.
    pub fn new(
        model: TappingModel,
        settings: SweepSettings,
        plan: SweepPlan,
    ) -> Result<Self, AfmError> {
        let mut model = model;
        model.set_separation(Separation::Constant(settings.from_nm))?;
        let state = model.free_state();
        Ok(Self::standing(model, settings, plan, 0, state, false))
    }

    /// A run of the same sweep standing at block start `cycle` with `state` (settled): what
    /// this run would do from there if its state at `cycle` were `state`.
    pub fn at(&self, cycle: u64, state: &[f64]) -> Self {
        debug_assert!(self.plan.is_block_start(cycle));
        Self::standing(
            self.model.clone(),
            self.settings.clone(),
            self.plan,
            cycle,
            state.to_vec(),
            true,
        )
    }

    /// The run at block start `cycle` with `state`, fresh buffers, an empty block and the
    /// blocks before `cycle` in its leg counted.
    fn standing(
        model: TappingModel,
        settings: SweepSettings,
        plan: SweepPlan,
        cycle: u64,
        state: Vec<f64>,
        settled: bool,
    ) -> Self {
        Self {
            state,
            workspace: SolverWorkspace::default(),
            lockin: CycleLockIn::with_harmonics(&model, settings.harmonics),
            average: BlockAverage::new(settings.lockin_cycles, model.free_amplitude_nm()),
            blocks_in_leg: plan.blocks_before(cycle.min(plan.total_cycles())),
            model,
            settings,
            plan,
            cycles_done: cycle,
            settled,
        }
    }

    /// The settings.
    pub fn settings(&self) -> &SweepSettings {
        &self.settings
    }

    /// The schedule.
    pub fn plan(&self) -> &SweepPlan {
        &self.plan
    }

    /// Cycles done since the start of the approach (settling excluded).
    pub fn cycles_done(&self) -> u64 {
        self.cycles_done
    }

    /// The cantilever state at the end of the last cycle integrated.
    pub fn state(&self) -> &[f64] {
        &self.state
    }

    /// Integrate the settling cycles at `from_nm` (unread), once.
    pub fn settle(&mut self) -> Result<(), AfmError> {
        if !self.settled {
            self.model
                .set_separation(Separation::Constant(self.settings.from_nm))?;
            for _ in 0..self.settings.settle_cycles {
                self.advance_unread_cycle()?;
            }
            self.settled = true;
        }
        Ok(())
    }

    /// Integrate cycle `cycles_done` (settled first if not yet): its block's record when this
    /// cycle completes a block whose record is returned (every `every`-th of its leg).
    pub fn cycle(&mut self) -> Result<Option<SweepRecord>, AfmError> {
        self.settle()?;
        let k = self.cycles_done;
        let (direction, separation, z_mid) = self.plan.cycle(k);
        if k == self.plan.cycles_per_leg {
            // The turn: the approach's unfinished block is discarded.
            self.average.clear();
            self.blocks_in_leg = 0;
        }
        // Only the blocks whose records are returned (every `every`-th) are read: the cycles
        // of the others are integrated without the lock-in.
        let due = self
            .blocks_in_leg
            .is_multiple_of(self.settings.every as u64);
        self.model.set_separation(separation)?;
        let (completed, block) = if due {
            let reading = self.read_cycle()?;
            let block = self.average.push(k, z_mid, &reading);
            (block.is_some(), block)
        } else {
            self.advance_unread_cycle()?;
            (self.average.skip(k), None)
        };
        self.cycles_done += 1;
        if completed {
            self.blocks_in_leg += 1;
        }
        Ok(block.map(|block| SweepRecord::new(direction, block)))
    }

    /// Integrate cycles until the next record is due and return it; `None` at the sweep's end,
    /// or once `stop` (asked before each cycle) answers `true`.
    pub fn next_record_until(&mut self, stop: &Stop<'_>) -> Result<Option<SweepRecord>, AfmError> {
        self.settle()?;
        while self.cycles_done < self.plan.total_cycles() && !stop() {
            if let Some(record) = self.cycle()? {
                return Ok(Some(record));
            }
        }
        Ok(None)
    }

    /// Integrate one drive period at the separation already set without the lock-in (a
    /// settling cycle, or a cycle of a block whose record is not returned).
    fn advance_unread_cycle(&mut self) -> Result<(), AfmError> {
        advance_cycle(
            &self.model,
            &self.settings.integration,
            &mut self.state,
            &mut self.workspace,
        )
    }

    /// Integrate the current cycle (its separation already set) and return the lock-in's
    /// reading of it.
    fn read_cycle(&mut self) -> Result<CycleReading, AfmError> {
        integrate_cycle(
            &self.model,
            &self.settings.integration,
            &mut self.state,
            &mut self.workspace,
            &mut self.lockin,
        )
    }
}
