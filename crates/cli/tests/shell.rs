//! Shell completions and manual pages: generated for every shell clap knows, loadable by the
//! shell, and covering every subcommand and option.

mod common;

use common::drumroll;

fn stdout_of(args: &[&str]) -> String {
    let output = drumroll().args(args).output().expect("runs");
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).expect("utf-8")
}

#[test]
fn completions_cover_the_subcommands_and_bash_accepts_its_script() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let script = stdout_of(&["completions", shell]);
        for word in ["continue", "approach", "cases", "overlay"] {
            assert!(script.contains(word), "{shell}: `{word}` missing");
        }
    }
    let directory = tempfile::tempdir().expect("temporary directory");
    let file = directory.path().join("drumroll.bash");
    std::fs::write(&file, stdout_of(&["completions", "bash"])).expect("saved");
    let status = std::process::Command::new("bash")
        .arg("-n")
        .arg(&file)
        .status()
        .expect("bash runs");
    assert!(status.success(), "bash -n rejects the completion script");
    let output = drumroll()
        .args(["completions", "tcsh"])
        .output()
        .expect("runs");
    assert!(!output.status.success());
}

#[test]
fn the_manual_has_a_page_per_subcommand() {
    let page = stdout_of(&["man"]);
    assert!(page.contains(".TH drumroll 1"), "{page}");
    assert!(page.contains("continue") && page.contains("completions"));
    let directory = tempfile::tempdir().expect("temporary directory");
    let pages = directory.path().join("man1");
    let dir = pages.to_str().expect("utf-8");
    drumroll()
        .args(["man", "--out-dir", dir])
        .assert()
        .success();
    for name in ["drumroll.1", "drumroll-continue.1", "drumroll-cases-show.1"] {
        let text = std::fs::read_to_string(pages.join(name)).expect(name);
        assert!(text.starts_with(".ie") || text.contains(".TH"), "{name}");
    }
    let continue_page = std::fs::read_to_string(pages.join("drumroll-continue.1")).expect("page");
    assert!(continue_page.contains("overlay"));
}

/// A standard output or error that cannot be written (`/dev/full`: no space left) is an error
/// with exit status 1 for a command's output and its messages, never a panic (101): the
/// completion script, the manual page, and an error message itself.
#[test]
fn a_full_output_stream_is_an_error_not_a_panic() {
    let full = || std::fs::File::create("/dev/full").expect("/dev/full");
    let binary = || std::process::Command::new(env!("CARGO_BIN_EXE_drumroll"));
    for args in [&["completions", "bash"][..], &["man"][..]] {
        let output = binary().args(args).stdout(full()).output().expect("runs");
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains("cannot write to standard output"),
            "{args:?}: {stderr}"
        );
    }
    let output = binary()
        .args(["simulate", "--case", "no-such-case", "--z", "5"])
        .stderr(full())
        .output()
        .expect("runs");
    assert_eq!(output.status.code(), Some(1));
}
