//! Progress bars: drawn on a terminal for runs longer than about 2 s, never when standard
//! error is piped, never with --quiet. A pseudo-terminal comes from util-linux `script`.

mod common;

use common::drumroll;

/// Run the drumroll binary with `args` on a pseudo-terminal (standard error included) and
/// return everything the terminal received.
fn on_terminal(args: &str) -> String {
    let binary = assert_cmd::cargo::cargo_bin("drumroll");
    let output = std::process::Command::new("script")
        .args(["-qec", &format!("{} {args}", binary.display()), "/dev/null"])
        .output()
        .expect("util-linux `script` runs");
    assert!(output.status.success(), "{args}: {output:?}");
    String::from_utf8_lossy(&output.stdout).to_string()
}

#[test]
fn a_long_sweep_shows_a_bar_on_a_terminal_and_nothing_piped_or_quiet() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let out = directory.path().join("sweep.csv");
    let out = out.to_str().expect("utf-8");
    // 10.2 nm to 0 at 0.5 nm/s: about 190 000 drive cycles, about 4 s on an idle core (twice
    // the 2 s after which a bar appears).
    let long = format!("approach --case biolever-mica --from 10.2 --to 0 --rate 0.5 --out {out}");
    let screen = on_terminal(&long);
    assert!(
        screen.contains("cycles,") && screen.contains("left"),
        "no bar: {screen}"
    );
    let screen = on_terminal(&format!("{long} --quiet"));
    assert!(screen.trim().is_empty(), "--quiet printed: {screen}");
    let output = drumroll()
        .args(long.split_whitespace())
        .output()
        .expect("runs");
    assert!(output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(stderr.trim(), format!("records: {out}"), "piped stderr");
}

#[test]
fn a_short_run_shows_no_bar_even_on_a_terminal() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let out = directory.path().join("short.csv");
    let screen = on_terminal(&format!(
        "approach --case biolever-mica --from 8.8 --to 8.65 --out {}",
        out.display()
    ));
    assert!(
        !screen.contains("cycles,"),
        "a bar for a short run: {screen}"
    );
}
