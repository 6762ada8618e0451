//! Benchmark of the time-domain approach sweep (`afm::Sweep`): the Biolever on mica
//! (A0 = 10 nm) from Z = 11 nm down to 0 at the paper's 1 nm/s, about 100,000 drive cycles,
//! one record per cycle. Reports the wall time, cycles per second and microseconds per cycle
//! overall and per impact regime, and the ratio to a scipy integration with event location at
//! about 24 ms per drive cycle (the reference figure).
//!
//! Run with `cargo bench -p afm --bench approach` (release build, one core). Pass `--quick`
//! after `--` to sweep only 11 nm -> 8 nm, `--from Z --to Z` for another window (nm), `--samples N` to change the solver's samples per
//! step (default `afm::sweep::SAMPLES_PER_STEP`), `--tolerance X` for the contact integration's tolerance (default
//! `afm::sweep::DEFAULT_TOLERANCE`), `--all-extrema` to search every free-flight step for extrema
//! (`extremum_height` infinite, as before the sweep skipped steps proven clear of the sample).
//!
//! The sweep runs twice: first in a pool of one thread (the cycles one after the other; the
//! per-regime table and the "one core" figures), then on rayon's global pool
//! (`RAYON_NUM_THREADS`, default one thread per core), where the cycles ahead run in
//! speculative segments; the second run's wall time is reported, and its records must be the
//! first run's, bit for bit. `--one-thread` stops after the first run (for instruction counts).

use afm::{builtin_case, Sweep, SweepRecord, SweepSettings, TappingModel};
use std::time::Instant;

mod cpu_time;
use cpu_time::thread_cpu_seconds;

/// The reference: scipy `solve_ivp` with event location, seconds per drive cycle.
const SCIPY_SECONDS_PER_CYCLE: f64 = 0.024;

/// The value after `flag` on the command line, if the flag is given (a missing or unreadable
/// value stops the benchmark with `usage`).
fn flag_value<T: std::str::FromStr>(arguments: &[String], flag: &str, usage: &str) -> Option<T> {
    let index = arguments.iter().position(|a| a == flag)?;
    let value = arguments.get(index + 1).and_then(|v| v.parse().ok());
    Some(value.unwrap_or_else(|| panic!("{flag} {usage}")))
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let case = builtin_case("biolever-mica").expect("built-in case");
    let model = TappingModel::from_case(&case).expect("model");
    let mut settings = SweepSettings::for_model(&model);
    settings.from_nm = 11.0;
    settings.to_nm = if quick { 8.0 } else { 0.0 };
    settings.rate_nm_per_s = 1.0;
    settings.settle_cycles = 0;
    let arguments: Vec<String> = std::env::args().collect();
    // `--from Z --to Z`: another window of the sweep, nm (to profile one impact regime).
    if let Some(z) = flag_value(&arguments, "--from", "Z") {
        settings.from_nm = z;
    }
    if let Some(z) = flag_value(&arguments, "--to", "Z") {
        settings.to_nm = z;
    }
    // `--samples N`: the solver's samples per step (extrema search), to weigh its cost.
    if let Some(samples) = flag_value(&arguments, "--samples", "N") {
        settings.integration.samples_per_step = samples;
        println!("samples per step: {samples}");
    }
    // `--tolerance X`: the contact integration's relative and absolute tolerance.
    if let Some(tolerance) = flag_value::<f64>(&arguments, "--tolerance", "X") {
        settings.integration.relative_tolerance = tolerance;
        settings.integration.absolute_tolerance = tolerance;
        println!("tolerance: {tolerance:e}");
    }
    if arguments.iter().any(|a| a == "--all-extrema") {
        settings.integration.extremum_height = f64::INFINITY;
        println!("every free-flight step searched for extrema");
    }
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool of one thread");
    let records = one_thread.install(|| one_core(&model, settings.clone()));
    if arguments.iter().any(|a| a == "--one-thread") {
        return;
    }
    let threads = rayon::current_num_threads();
    let start = Instant::now();
    let segmented: Vec<SweepRecord> = Sweep::new(&model, settings)
        .expect("sweep")
        .map(|record| record.expect("sweep runs"))
        .collect();
    let wall = start.elapsed().as_secs_f64();
    assert!(
        segmented == records,
        "the records on {threads} threads differ from one thread's"
    );
    println!(
        "on {threads} threads (speculative segments): wall time {wall:.3} s, the same {} records \
         bit for bit",
        records.len()
    );
}

/// The sweep on the calling thread's pool (of one thread): prints its per-regime and total
/// times, and returns its records.
fn one_core(model: &TappingModel, settings: SweepSettings) -> Vec<SweepRecord> {
    let mut sweep = Sweep::new(model, settings).expect("sweep");
    let cycles = sweep.total_cycles();
    println!(
        "approach sweep, Biolever on mica, A0 = 10 nm, Z_G1 = {:.4} nm, {} -> {} nm at 1 nm/s: \
         {cycles} drive cycles",
        model.grazing_separation_nm(),
        sweep.settings().from_nm,
        sweep.settings().to_nm
    );
    // Wall time per regime (impacts per cycle), and overall.
    let mut per_regime: Vec<(usize, u64, f64)> = Vec::new(); // (impacts, cycles, seconds)
    let start = Instant::now();
    let cpu_start = thread_cpu_seconds();
    let mut last = Instant::now();
    let mut last_z_print = f64::INFINITY;
    let mut records = Vec::new();
    while let Some(record) = sweep.next_record().expect("sweep runs") {
        let now = Instant::now();
        let seconds = (now - last).as_secs_f64();
        last = now;
        let impacts = record.impacts_per_period as usize;
        match per_regime.iter_mut().find(|r| r.0 == impacts) {
            Some(regime) => {
                regime.1 += 1;
                regime.2 += seconds;
            }
            None => per_regime.push((impacts, 1, seconds)),
        }
        if record.z_nm < last_z_print - 1.0 {
            last_z_print = record.z_nm;
            println!(
                "  Z = {:7.3} nm  A/A0 = {:.4}  phase = {:8.3} deg  impacts = {}",
                record.z_nm, record.amplitude_ratio, record.phase_deg, record.impacts_per_period
            );
        }
        records.push(record);
    }
    let total = start.elapsed().as_secs_f64();
    let cpu = cpu_start.and_then(|s| thread_cpu_seconds().map(|e| e - s));
    per_regime.sort_by_key(|r| r.0);
    println!(
        "{:>8} {:>10} {:>19}",
        "impacts", "cycles", "wall us per cycle"
    );
    for (impacts, count, seconds) in &per_regime {
        println!(
            "{:>8} {:>10} {:>19.2}",
            impacts,
            count,
            seconds / *count as f64 * 1e6
        );
    }
    for (what, seconds) in [("one thread: wall", Some(total)), ("one thread: cpu", cpu)] {
        let Some(seconds) = seconds else { continue };
        let per_cycle = seconds / cycles as f64;
        println!(
            "{what} time {seconds:.3} s, {:.0} cycles/s, {:.2} us per cycle; scipy at 24 ms \
             per cycle: {:.0} s, ratio {:.0}x",
            1.0 / per_cycle,
            per_cycle * 1e6,
            SCIPY_SECONDS_PER_CYCLE * cycles as f64,
            SCIPY_SECONDS_PER_CYCLE / per_cycle
        );
    }
    records
}
