//! Benchmark of `drumroll grid` (issue 23's targets): a 200 x 200 grid of the Biolever on mica
//! (`--vary a0 --from 5 --to 20`, `Z` from 21 down to 0.5 nm: every row from free oscillation
//! through G1, G2 and G3) on 2 threads against 1 thread (target: under 60 s on 2 cores, at
//! least 1.8 times faster than on 1), and the peak memory of 50 against 200 rows (target: the
//! same, since rows stream to the part file as they are finished).
//!
//! Each run is the real binary under `/usr/bin/time` (Debian package `time`): wall time,
//! CPU time (user + system) and the largest resident set. The runs alternate (2 threads, 1
//! thread, ...) so that a load from other processes falls on both; on a shared machine compare
//! the CPU times too (the work itself), since wall time also counts the cores others held.
//!
//! Run with `cargo bench -p drumroll --bench grid`; `-- --repetitions N` (default 1) repeats
//! the pair, `-- --rows N --z-steps M` changes the grid (default 200 x 200).

use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// What `/usr/bin/time` and the clock measured of one run.
struct Measurement {
    wall_s: f64,
    cpu_s: f64,
    max_rss_mb: f64,
}

/// Run `drumroll grid` on the benchmark's grid with `rows` rows, `z_steps` separations and
/// `threads` threads into `directory`, and measure it.
fn run(directory: &Path, rows: usize, z_steps: usize, threads: usize) -> Measurement {
    let output = directory.join(format!("grid-{rows}-{threads}.jsonl"));
    let report = directory.join("time.txt");
    let start = Instant::now();
    let status = Command::new("/usr/bin/time")
        .arg("-f")
        .arg("%U %S %M")
        .arg("-o")
        .arg(&report)
        .arg(env!("CARGO_BIN_EXE_drumroll"))
        .args([
            "grid",
            "--case",
            "biolever-mica",
            "--vary",
            "a0",
            "--from",
            "5",
            "--to",
            "20",
        ])
        .args(["--steps", &rows.to_string()])
        .args([
            "--z-from",
            "21",
            "--z-to",
            "0.5",
            "--z-steps",
            &z_steps.to_string(),
        ])
        .args(["--threads", &threads.to_string(), "--output"])
        .arg(&output)
        .stdout(std::process::Stdio::null())
        .status()
        .expect("/usr/bin/time runs (apt-get install time)");
    let wall_s = start.elapsed().as_secs_f64();
    assert!(status.success(), "drumroll grid failed");
    let text = std::fs::read_to_string(&report).expect("time's report");
    let fields: Vec<f64> = text
        .split_whitespace()
        .map(|f| f.parse().expect("a number"))
        .collect();
    let _ = std::fs::remove_file(&output);
    Measurement {
        wall_s,
        cpu_s: fields[0] + fields[1],
        max_rss_mb: fields[2] / 1024.0,
    }
}

fn option(args: &[String], name: &str, default: usize) -> usize {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map_or(default, |v| v.parse().expect("an integer"))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let repetitions = option(&args, "--repetitions", 1);
    let rows = option(&args, "--rows", 200);
    let z_steps = option(&args, "--z-steps", 200);
    let directory = tempfile::tempdir().expect("temporary directory");
    println!(
        "drumroll grid, Biolever on mica, a0 5..20 nm x Z 21..0.5 nm: {rows} x {z_steps} cells, \
         approach only ({} cores seen)",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    println!(
        "{:>6} {:>8} {:>10} {:>10} {:>12}",
        "rows", "threads", "wall (s)", "CPU (s)", "max RSS (MB)"
    );
    let print = |rows: usize, threads: usize, m: &Measurement| {
        println!(
            "{rows:>6} {threads:>8} {:>10.2} {:>10.2} {:>12.1}",
            m.wall_s, m.cpu_s, m.max_rss_mb
        );
    };
    let (mut two, mut one) = (Vec::new(), Vec::new());
    for _ in 0..repetitions {
        let m = run(directory.path(), rows, z_steps, 2);
        print(rows, 2, &m);
        two.push(m);
        let m = run(directory.path(), rows, z_steps, 1);
        print(rows, 1, &m);
        one.push(m);
    }
    let quarter = (rows / 4).max(1);
    let small = run(directory.path(), quarter, z_steps, 2);
    print(quarter, 2, &small);
    let best = |runs: &[Measurement]| runs.iter().map(|m| m.wall_s).fold(f64::INFINITY, f64::min);
    let (wall_two, wall_one) = (best(&two), best(&one));
    println!(
        "speed-up with 2 threads: {:.2} (best wall times, {wall_one:.2} s / {wall_two:.2} s; \
         target >= 1.8); {rows} x {z_steps} on 2 threads: {wall_two:.2} s (target < 60 s)",
        wall_one / wall_two
    );
    let cpu = |runs: &[Measurement]| runs.iter().map(|m| m.cpu_s).fold(f64::INFINITY, f64::min);
    println!(
        "cores obtained by the 2-thread run (CPU / wall): {:.2}; speed-up on 2 free cores from \
         the CPU times, 2 CPU(1 thread) / CPU(2 threads): {:.2} (the parallel overhead only)",
        two[0].cpu_s / two[0].wall_s,
        2.0 * cpu(&one) / cpu(&two)
    );
    println!(
        "peak memory: {:.1} MB for {quarter} rows, {:.1} MB for {rows} rows (2 threads)",
        small.max_rss_mb, two[0].max_rss_mb
    );
}
