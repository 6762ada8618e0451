//! A sweep's cycles ahead integrated in parallel, in speculative segments whose records are
//! the same bits as one trajectory's.
//!
//! A sweep is one trajectory, each cycle starting from the last one's end. But the cantilever
//! forgets where it started: a transient decays by `exp(-pi / Q_1)` per drive cycle (and
//! faster in contact), so two trajectories of the same sweep that start from different states
//! draw together until, in the last bits, they coincide. Once they reach a block start with
//! bit-identical states, everything after is identical too (the run's future depends only on
//! its cycle and state, [`super::run`]).
//!
//! So the cycles ahead of the sweep's frontier are cut into segments at block starts, and the
//! segments are integrated at once on rayon's pool: the first from the frontier's state (the
//! true one), each later one from the same state as a guess, publishing its state at every
//! block start as it goes. Each segment, at its end, continues cycle by cycle until its state
//! at a block start equals a later segment's there. Then, in order, the true trajectory takes
//! the first segment's records, its continuation's, and from the block where it met the next
//! segment that one's, and so on. A segment the true trajectory never meets (a guess that fell
//! on another attractor, a bistable window, a sweep that does not contract) is only wasted
//! work: the true trajectory runs through it. Nothing is approximated, and the records do not
//! depend on the number of threads or on their timing.

use std::collections::VecDeque;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;

use crate::error::AfmError;
use crate::model::TappingModel;

use super::run::SweepRun;
use super::SweepRecord;

/// Drive cycles per segment, at least (about 50 ms of one core for the paper's cantilevers):
/// a segment's extension until it meets the next one is work done twice, for the Biolever's
/// approach 0 to 1300 cycles, mostly under 150.
const MIN_SEGMENT_CYCLES: u64 = 2048;

/// Drive cycles per segment where the cantilever forgets fast (a segment may be longer for a
/// slowly decaying one, see [`Segmentation::for_model`]).
const SEGMENT_CYCLES: u64 = 4096;

/// Segments integrated at once per thread of the pool (more than one, so that the threads
/// share segments of uneven cost; a segment not started when a continuation reaches it is
/// skipped).
const SEGMENTS_PER_THREAD: u64 = 2;

/// `ln(1e17)`: free decay e-folding times for a transient of the size of the orbit to fall
/// below the last bit of the state.
const E_FOLDINGS_TO_THE_LAST_BIT: f64 = 39.1;

/// Segment lengths at least this many times the cycles a free transient takes to fall below
/// the last bit (so that an extension is at most about an eighth of a segment when the free
/// decay sets the pace).
const MEMORIES_PER_SEGMENT: f64 = 8.0;

/// Drive cycles per segment, at most (a longer one's share of the work done twice is not
/// worth it).
const MAX_SEGMENT_CYCLES: u64 = 65_536;

/// Drive cycles of the segments integrated at once, at most (unless two segments are
/// longer): their records are held in memory, about 300 bytes a cycle read, so about 80 MB
/// (135 MB resident for the humid air lever's four segments of 63,400 cycles).
const MAX_CYCLES_IN_FLIGHT: u64 = 262_144;

/// How the cycles ahead are cut into segments: their length, which doubles after a wave in
/// which the true trajectory ran through a whole segment without meeting it (a sweep that
/// forgets more slowly than its free decay, or not at all); past [`MAX_SEGMENT_CYCLES`] the
/// sweep runs on one thread.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Segmentation {
    /// Drive cycles per segment.
    length: u64,
}

impl Segmentation {
    /// Segments for `model`'s sweep: [`SEGMENT_CYCLES`], or longer where a free transient
    /// outlives an eighth of that. Mode `i` decays by `exp(-pi f_i / (Q_i f))` per drive
    /// period (MODEL.md section 1), so a transient falls below the last bit in
    /// `39.1 max_i Q_i f / (pi f_i)` periods (about 15 for the Biolever in water, 8,000 for
    /// a tapping lever in air with `Q_1 = 637`).
    pub fn for_model(model: &TappingModel) -> Self {
        let drive_khz = model.drive_frequency_khz();
        let memory = model
            .cantilever()
            .modes
            .iter()
            .map(|mode| mode.quality_factor * drive_khz / (PI * mode.frequency_khz))
            .fold(0.0, f64::max)
            * E_FOLDINGS_TO_THE_LAST_BIT;
        let length = (MEMORIES_PER_SEGMENT * memory).ceil();
        Self {
            length: if length <= MAX_SEGMENT_CYCLES as f64 {
                (length as u64).max(SEGMENT_CYCLES)
            } else {
                // Also NaN: longer than segments may be (one thread).
                MAX_SEGMENT_CYCLES + 1
            },
        }
    }

    /// Whether the cycles ahead of `frontier` (settled) are worth integrating in segments on
    /// `threads` threads: more than one thread, segments no longer than
    /// [`MAX_SEGMENT_CYCLES`] and room for two, blocks short enough to leave block starts to
    /// meet at, and the frontier at a block start.
    pub fn worth_it(&self, frontier: &SweepRun, threads: usize) -> bool {
        let plan = frontier.plan();
        let k = frontier.cycles_done();
        threads > 1
            && self.length <= MAX_SEGMENT_CYCLES
            && plan.total_cycles().saturating_sub(k) >= 2 * self.shortest()
            && plan.lockin_cycles * 64 <= MIN_SEGMENT_CYCLES
            && plan.is_block_start(k)
    }

    /// The shortest segment cut (the last cycles are shared among the threads in segments down
    /// to this length).
    fn shortest(&self) -> u64 {
        MIN_SEGMENT_CYCLES.max(self.length / 2)
    }
}

/// A caller's request to stop (answered between cycles; callable from any thread).
pub type Stop<'a> = dyn Fn() -> bool + Sync + 'a;

/// One record of the true trajectory, as handed to the caller: the record (or the failure
/// that ends the sweep), with the cycles done and the cantilever state after it (before the
/// failing cycle, for a failure).
#[derive(Debug)]
pub(super) struct Served {
    /// The block's record, or the solver's failure.
    pub outcome: Result<SweepRecord, AfmError>,
    /// Cycles done since the start of the approach.
    pub cycles_done: u64,
    /// The state then.
    pub state: Vec<f64>,
}

impl Served {
    fn of(run: &SweepRun, outcome: Result<SweepRecord, AfmError>) -> Self {
        Self {
            outcome,
            cycles_done: run.cycles_done(),
            state: run.state().to_vec(),
        }
    }
}

/// A segment as the others see it while it runs: its planned cycles, the states at the block
/// starts it has reached, and whether a continuation has overtaken it.
struct Segment {
    /// Its first and planned end cycle (block starts).
    start: u64,
    end: u64,
    /// Its block starts so far and the states there, `dim` values each.
    landmarks: Mutex<(Vec<u64>, Vec<f64>)>,
    /// The next cycle it integrates.
    reached: AtomicU64,
    /// Set by a continuation that reached a cycle this segment had not: it then stops, being
    /// of no use ahead of it.
    overtaken: AtomicBool,
}

impl Segment {
    fn new(start: u64, end: u64) -> Self {
        Self {
            start,
            end,
            landmarks: Mutex::new((Vec::new(), Vec::new())),
            reached: AtomicU64::new(start),
            overtaken: AtomicBool::new(false),
        }
    }

    /// Whether `state` at block start `k` is, bit for bit, this segment's state there.
    fn meets(&self, k: u64, state: &[f64]) -> bool {
        let landmarks = self.landmarks.lock().unwrap_or_else(|e| e.into_inner());
        let (block_starts, states) = &*landmarks;
        let Ok(index) = block_starts.binary_search(&k) else {
            return false;
        };
        let dim = state.len();
        states[index * dim..(index + 1) * dim]
            .iter()
            .zip(state)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    }
}

/// What a segment integrated: its records, where it stopped, and its continuation.
struct Stretch {
    /// Its records in order.
    records: Vec<Served>,
    /// The run where it stopped: its end, an overtaking, or a failing cycle.
    run: SweepRun,
    /// The failure that stopped it.
    failure: Option<AfmError>,
    /// Its continuation from its end, if it reached its end and a later segment follows.
    extension: Option<Extension>,
}

impl Stretch {
    /// Integrate `segments[j]` of `template`'s sweep from `state` at its start, then continue
    /// it until it meets a later segment or reaches the last one's end (or until `stop`
    /// answers `true`).
    fn integrate(
        template: &SweepRun,
        segments: &[Segment],
        j: usize,
        state: &[f64],
        stop: &Stop<'_>,
    ) -> Self {
        let segment = &segments[j];
        let mut run = template.at(segment.start, state);
        let mut records = Vec::new();
        let mut failure = None;
        while run.cycles_done() < segment.end
            && !segment.overtaken.load(Ordering::Relaxed)
            && !stop()
        {
            let k = run.cycles_done();
            if run.plan().is_block_start(k) {
                let mut landmarks = segment.landmarks.lock().unwrap_or_else(|e| e.into_inner());
                landmarks.0.push(k);
                landmarks.1.extend_from_slice(run.state());
            }
            let outcome = advance(&mut run, &mut records);
            segment.reached.store(run.cycles_done(), Ordering::Relaxed);
            if let Err(error) = outcome {
                failure = Some(error);
                break;
            }
        }
        let end = segments.last().map_or(segment.end, |last| last.end);
        let extension =
            (failure.is_none() && run.cycles_done() == segment.end && segment.end < end)
                .then(|| Extension::integrate(segments, j, run.clone(), end, stop));
        Self {
            records,
            run,
            failure,
            extension,
        }
    }
}

/// Where a segment's continuation went: from the segment's end, cycle by cycle, until its
/// state at a block start met a later segment's (bit for bit) or it reached a given cycle.
struct Extension {
    /// The records of the blocks before the meeting.
    records: Vec<Served>,
    /// The later segment met (its index) and the block start where.
    met: Option<(usize, u64)>,
    /// Whether it ran through the whole of a later segment that was not overtaken without
    /// meeting it.
    passed: bool,
    /// The run where it stopped (at the meeting, the given cycle, or the failing cycle).
    run: SweepRun,
    /// The failure that stopped it.
    failure: Option<AfmError>,
}

impl Extension {
    /// Continue `run`, in or after `segments[j]`, cycle by cycle until it meets a
    /// later segment or reaches cycle `until` (or until `stop` answers `true`). A later
    /// segment that has not reached the cycle it is at is overtaken (told to stop).
    fn integrate(
        segments: &[Segment],
        j: usize,
        mut run: SweepRun,
        until: u64,
        stop: &Stop<'_>,
    ) -> Self {
        let mut records = Vec::new();
        let mut passed = false;
        let (met, failure) = loop {
            let k = run.cycles_done();
            if k >= until || stop() {
                break (None, None);
            }
            // The later segment whose cycles these are (none while still in segment `j`'s
            // own, after it was overtaken).
            let later = segments[j + 1..]
                .iter()
                .position(|later| later.start <= k && k < later.end)
                .map(|i| i + j + 1);
            if let Some(m) = later {
                // Through the whole of segment `m - 1` without meeting it, though it ran (a
                // segment overtaken was only late to start).
                passed |= m > j + 1
                    && k == segments[m].start
                    && !segments[m - 1].overtaken.load(Ordering::Relaxed);
                if segments[m].meets(k, run.state()) {
                    break (Some((m, k)), None);
                }
                if segments[m].reached.load(Ordering::Relaxed) < k {
                    segments[m].overtaken.store(true, Ordering::Relaxed);
                }
            }
            if let Err(error) = advance(&mut run, &mut records) {
                break (None, Some(error));
            }
        };
        Self {
            records,
            met,
            passed,
            run,
            failure,
        }
    }
}

/// Integrate the cycles ahead of `frontier` (settled, at a block start) in segments on
/// rayon's pool, push the true trajectory's records onto `ahead` in order (ending with its
/// failure, if one), and leave `frontier` after the last cycle integrated.
///
/// [`SEGMENTS_PER_THREAD`] segments per thread, at once: the first from the frontier's state,
/// the others from a guess; each, at its end, continues until it meets a later one (reading
/// the later one's states as they come), so that the true trajectory never waits for a guess.
/// Then the true trajectory's walk through them, from the first segment; where it finds no
/// continuation (a segment stopped when overtaken), it continues on this thread. If `stop`
/// answers `true`, the records pushed may end anywhere and `frontier` is not to be used.
pub(super) fn integrate_ahead(
    segmentation: &mut Segmentation,
    frontier: &mut SweepRun,
    ahead: &mut VecDeque<Served>,
    stop: &Stop<'_>,
) {
    let guess = frontier.state().to_vec();
    integrate_ahead_from(segmentation, frontier, &guess, ahead, stop);
}

/// [`integrate_ahead`] with `guess` as the later segments' start state.
fn integrate_ahead_from(
    segmentation: &mut Segmentation,
    frontier: &mut SweepRun,
    guess: &[f64],
    ahead: &mut VecDeque<Served>,
    stop: &Stop<'_>,
) {
    let plan = *frontier.plan();
    let first = frontier.cycles_done();
    // Two segments per thread, as long as the cycles in flight fit in memory (at least two).
    let count = (SEGMENTS_PER_THREAD * rayon::current_num_threads() as u64)
        .min(MAX_CYCLES_IN_FLIGHT / segmentation.length)
        .max(2);
    // Segments of the segmentation's length, shorter (down to its shortest) to share the last
    // cycles of the sweep among the threads.
    let left = plan.total_cycles() - first;
    let length = left
        .div_ceil(count)
        .clamp(segmentation.shortest(), segmentation.length);
    let mut cuts = vec![first];
    for i in 1..=count {
        let cut = plan.block_start_from(first + i * length);
        if cut > *cuts.last().expect("a cut") {
            cuts.push(cut);
        }
    }
    let segments: Vec<Segment> = cuts.windows(2).map(|c| Segment::new(c[0], c[1])).collect();
    let end = segments.last().map_or(first, |last| last.end);
    let mut stretches: Vec<Option<Stretch>> = (0..segments.len())
        .into_par_iter()
        .map(|j| {
            let start = if j == 0 { frontier.state() } else { guess };
            Some(Stretch::integrate(frontier, &segments, j, start, stop))
        })
        .collect();
    // The true trajectory: segment `j`'s records from cycle `from` on, then its extension's.
    let mut j = 0;
    let mut from = first;
    loop {
        if stop() {
            // Told to stop: the records may be incomplete, and the sweep ends.
            return;
        }
        let stretch = stretches[j].take().expect("each segment is walked once");
        ahead.extend(
            stretch
                .records
                .into_iter()
                .filter(|served| served_from(served) >= from),
        );
        if let Some(error) = stretch.failure {
            ahead.push_back(Served::of(&stretch.run, Err(error)));
            return;
        }
        let mut extension = match stretch.extension {
            Some(extension) => extension,
            None if stretch.run.cycles_done() >= end => {
                *frontier = stretch.run;
                return;
            }
            None => Extension::integrate(&segments, j, stretch.run, end, stop),
        };
        loop {
            ahead.extend(extension.records);
            if let Some(error) = extension.failure {
                ahead.push_back(Served::of(&extension.run, Err(error)));
                return;
            }
            if extension.passed {
                // The true trajectory ran through a whole segment without meeting it:
                // segments twice as long from now on.
                segmentation.length = segmentation.length.saturating_mul(2);
            }
            if let Some((m, k)) = extension.met {
                j = m;
                from = k;
                break;
            }
            if extension.run.cycles_done() >= end || stop() {
                *frontier = extension.run;
                return;
            }
            extension = Extension::integrate(&segments, j, extension.run, end, stop);
        }
    }
}

/// Integrate `run`'s next cycle, pushing its block's record onto `records` if it completes
/// one that is returned.
fn advance(run: &mut SweepRun, records: &mut Vec<Served>) -> Result<(), AfmError> {
    if let Some(record) = run.cycle()? {
        records.push(Served::of(run, Ok(record)));
    }
    Ok(())
}

/// The first cycle of a served record's block.
fn served_from(served: &Served) -> u64 {
    match &served.outcome {
        Ok(record) => record.cycle,
        Err(_) => served.cycles_done,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::builtin_case;
    use crate::model::TappingModel;
    use crate::sweep::{Sweep, SweepSettings};

    /// The Biolever on mica from 9 to 8.5 nm and back at 1 nm/s (4650 cycles each way, G2 near
    /// 8.72 nm crossed twice), blocks of 2 cycles, every 3rd returned.
    fn settled_sweep() -> (SweepRun, u64) {
        let case = builtin_case("biolever-mica").expect("case");
        let model = TappingModel::from_case(&case).expect("model");
        let mut settings = SweepSettings::for_model(&model);
        settings.from_nm = 9.0;
        settings.to_nm = 8.5;
        settings.retract = true;
        settings.lockin_cycles = 2;
        settings.every = 3;
        let sweep = Sweep::new(&model, settings).expect("sweep");
        let mut frontier = sweep.frontier;
        frontier.settle().expect("settled");
        let total = frontier.plan().total_cycles();
        (frontier, total)
    }

    /// The records (and final state) of one trajectory, cycle after cycle on this thread.
    fn one_trajectory(mut run: SweepRun) -> (Vec<SweepRecord>, Vec<f64>) {
        let mut records = Vec::new();
        while let Some(record) = run.next_record_until(&|| false).expect("cycle") {
            records.push(record);
        }
        (records, run.state().to_vec())
    }

    /// Segments from `guess` on `threads` threads, to the sweep's end.
    fn in_segments(mut run: SweepRun, guess: &[f64], threads: usize) -> Vec<SweepRecord> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let mut ahead = VecDeque::new();
        let mut segmentation = Segmentation {
            length: SEGMENT_CYCLES,
        };
        pool.install(|| {
            while run.cycles_done() < run.plan().total_cycles() {
                assert!(segmentation.worth_it(&run, threads) || !ahead.is_empty());
                if !segmentation.worth_it(&run, threads) {
                    break;
                }
                integrate_ahead_from(&mut segmentation, &mut run, guess, &mut ahead, &|| false);
            }
        });
        let mut records: Vec<SweepRecord> = ahead
            .into_iter()
            .map(|served| served.outcome.expect("no failure"))
            .collect();
        records.extend(one_trajectory(run).0);
        records
    }

    /// The segments' records are one trajectory's, bit for bit, on 2 and 3 threads, from the
    /// frontier's state as the guess (as the sweep does) and from guesses far from the orbit:
    /// three times the state (the tip driven 20 nm into mica in the first cycle), its negative,
    /// and NaN (every later segment fails in its first cycle and is never met: the true
    /// trajectory runs through them all). Segments that start elsewhere only cost time.
    #[test]
    fn segments_give_the_records_of_one_trajectory_whatever_their_guess() {
        let (frontier, total) = settled_sweep();
        let (expected, _) = one_trajectory(frontier.clone());
        assert_eq!(expected.len() as u64, 2 * (total / 2 / 2).div_ceil(3));
        let state = frontier.state().to_vec();
        let far: Vec<f64> = state.iter().map(|x| 3.0 * x).collect();
        let opposite: Vec<f64> = state.iter().map(|x| -x).collect();
        let nan = vec![f64::NAN; state.len()];
        for guess in [&state, &far, &opposite, &nan] {
            for threads in [2, 3] {
                let records = in_segments(frontier.clone(), guess, threads);
                assert!(records == expected, "{threads} threads, guess {guess:?}");
            }
        }
    }
}
