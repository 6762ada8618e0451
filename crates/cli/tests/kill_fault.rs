//! Kill -9 at random moments (issue 35): a grid (two threads appending rows), an approach
//! sweep streaming to `--out` with a `--plot`, a `continue` with `--csv` and `--plot`, and a
//! `map` with `--csv` and `--plot`, each killed (SIGKILL) at seeded random moments of its
//! measured run time and then run again. After each kill every output file is absent or byte
//! for byte the uninterrupted run's (never partial or malformed), and the only other files
//! left are the resumable `.part` file and the `.<host>.<PID>-<n>.partial` temporary of the killed
//! process (or its writability probe); after the rerun every output is the uninterrupted run's and nothing else is left.
//!
//! `cargo test --release -p drumroll --test kill_fault` kills each command 3 times;
//! `DRUMROLL_KILLS=30 cargo test --release -p drumroll --test kill_fault -- --nocapture` is
//! the long form (`DRUMROLL_KILL_SEED` changes the moments; it prints what each kill left).

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One command: its arguments (output files relative to its directory) and its outputs.
struct Scenario {
    name: &'static str,
    args: &'static [&'static str],
    outputs: &'static [&'static str],
}

const SCENARIOS: [Scenario; 4] = [
    Scenario {
        name: "grid",
        args: &[
            "grid",
            "--case",
            "biolever-mica",
            "--vary",
            "a0",
            "--from",
            "9",
            "--to",
            "11",
            "--steps",
            "6",
            "--z-from",
            "11",
            "--z-to",
            "7",
            "--z-steps",
            "30",
            "--retract",
            "--threads",
            "2",
            "--output",
            "map.jsonl",
        ],
        outputs: &["map.jsonl"],
    },
    Scenario {
        name: "approach",
        args: &[
            "approach",
            "--case",
            "biolever-mica",
            "--to",
            "8.5",
            "--retract",
            "--out",
            "sweep.csv",
            "--plot",
            "sweep.svg",
        ],
        outputs: &["sweep.csv", "sweep.svg"],
    },
    Scenario {
        name: "continue",
        args: &[
            "continue",
            "--case",
            "biolever-mica",
            "--csv",
            "diagram.csv",
            "--plot",
            "diagram.svg",
        ],
        outputs: &["diagram.csv", "diagram.svg"],
    },
    Scenario {
        name: "map",
        args: &[
            "map",
            "--case",
            "biolever-mica",
            "--vary",
            "a0",
            "--from",
            "8",
            "--to",
            "12",
            "--csv",
            "regimes.csv",
            "--plot",
            "regimes.svg",
        ],
        outputs: &["regimes.csv", "regimes.svg"],
    },
];

/// A seeded xorshift64* generator: the kill moments repeat from run to run.
struct Moments(u64);

impl Moments {
    /// A number in [0, 1).
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Run `scenario` in `directory` to the end; its run time.
fn complete(scenario: &Scenario, directory: &Path) -> Duration {
    let started = Instant::now();
    let output = Command::new(env!("CARGO_BIN_EXE_drumroll"))
        .args(scenario.args)
        .current_dir(directory)
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "{}: {}",
        scenario.name,
        String::from_utf8_lossy(&output.stderr)
    );
    started.elapsed()
}

/// The files of `directory` by name.
fn files(directory: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(directory)
        .expect("list")
        .map(|entry| {
            let entry = entry.expect("entry");
            let name = entry.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(entry.path()).unwrap_or_default())
        })
        .collect()
}

/// Whether `name` is a file a killed run may leave beside the outputs: the resumable
/// `OUTPUT.part`, or a temporary `OUTPUT.<host>.<PID>-<n>.partial` or writability probe
/// `.OUTPUT.<PID>.probe` of process `pid` (removed by the next run writing `OUTPUT`).
fn left_by_a_kill(name: &str, outputs: &[&str], pid: u32) -> bool {
    outputs.iter().any(|output| {
        let temporary = name
            .strip_prefix(&format!("{output}."))
            .and_then(|rest| rest.strip_suffix(".partial"))
            .and_then(|rest| rest.rsplit_once('.'))
            .and_then(|(_, process)| process.split_once('-'))
            .is_some_and(|(process, n)| {
                process == pid.to_string() && n.chars().all(|c| c.is_ascii_digit())
            });
        name == format!("{output}.part") || temporary || name == format!(".{output}.{pid}.probe")
    })
}

#[test]
fn killed_commands_leave_complete_outputs_or_none_and_rerun_identically() {
    let kills: usize = std::env::var("DRUMROLL_KILLS")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(3);
    let seed: u64 = std::env::var("DRUMROLL_KILL_SEED")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(35);
    let mut moments = Moments(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
    for scenario in &SCENARIOS {
        let reference_directory = tempfile::tempdir().expect("temporary directory");
        let took = complete(scenario, reference_directory.path());
        let reference = files(reference_directory.path());
        let mut expected = scenario.outputs.to_vec();
        expected.sort_unstable();
        assert_eq!(
            reference.keys().map(String::as_str).collect::<Vec<_>>(),
            expected,
            "{}: the uninterrupted run's files",
            scenario.name
        );
        let directory = tempfile::tempdir().expect("temporary directory");
        let (mut absent, mut identical) = (0, 0);
        for kill in 0..kills {
            // Every other kill starts with the outputs of the last rerun in place (a killed
            // run must leave them as they were), the others from an empty directory.
            if kill % 2 == 0 {
                for output in scenario.outputs {
                    let _ = std::fs::remove_file(directory.path().join(output));
                }
            }
            let at = took.mul_f64(1.2 * moments.next());
            let mut child = Command::new(env!("CARGO_BIN_EXE_drumroll"))
                .args(scenario.args)
                .current_dir(directory.path())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("starts");
            let pid = child.id();
            std::thread::sleep(at);
            let _ = child.kill();
            child.wait().expect("reaped");
            let left = files(directory.path());
            for output in scenario.outputs {
                match left.get(*output) {
                    None => absent += 1,
                    Some(bytes) => {
                        assert!(
                            bytes == &reference[*output],
                            "{} killed after {at:?}: {output} is partial or different",
                            scenario.name
                        );
                        identical += 1;
                    }
                }
            }
            for name in left.keys() {
                assert!(
                    scenario.outputs.contains(&name.as_str())
                        || left_by_a_kill(name, scenario.outputs, pid),
                    "{} killed after {at:?}: {name} left",
                    scenario.name
                );
            }
            if std::env::var_os("DRUMROLL_KILLS").is_some() {
                println!(
                    "{} kill {kill} after {at:?}: left {:?}",
                    scenario.name,
                    left.keys().collect::<Vec<_>>()
                );
            }
            complete(scenario, directory.path());
            assert_eq!(
                files(directory.path()),
                reference,
                "{}: the rerun after a kill at {at:?} differs or left files",
                scenario.name
            );
        }
        println!(
            "{}: {kills} kills in its {took:?}: outputs absent {absent} times, identical \
             {identical} times",
            scenario.name
        );
    }
}
