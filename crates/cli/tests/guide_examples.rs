//! Every shell example in README.md and docs/guide/ runs and exits 0, so the guide cannot rot.
//!
//! Two kinds of fenced blocks are examples:
//! - ```` ```sh ````: a script, run whole by `bash -e -o pipefail`;
//! - ```` ```console ````: a transcript; each line starting with `$ ` (with its `\`
//!   continuation lines) is a command, run the same way; the other lines are its output, shown
//!   for the reader and not compared (the commands' own tests check values).
//!
//! Blocks of one page run in order in one fresh directory (a later block may use a file an
//! earlier one wrote), with the repository's `fixtures/`, `docs/`, `python/` and `scripts/`
//! linked into it and the `drumroll` binary under test first on `PATH`. An example that needs
//! what a test cannot have (a Slurm cluster, the network, `cargo` itself) is written in a
//! ```` ```text ```` block, which is not run.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The longest a single example may take before the test calls it hung.
const EXAMPLE_LIMIT: Duration = Duration::from_secs(300);

/// One runnable example: the page it is on, its first line number there, and its script.
struct Example {
    page: PathBuf,
    line: usize,
    script: String,
}

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("the repository root")
}

/// The pages whose examples are run: README.md and every `.md` file under docs/guide/.
fn pages(root: &Path) -> Vec<PathBuf> {
    let mut pages = vec![root.join("README.md")];
    let guide = root.join("docs/guide");
    let mut guide_pages: Vec<PathBuf> = fs::read_dir(&guide)
        .unwrap_or_else(|e| panic!("read {}: {e}", guide.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "md"))
        .collect();
    guide_pages.sort();
    pages.extend(guide_pages);
    pages
}

/// The runnable examples of a page's text, in order.
fn examples(page: &Path, text: &str) -> Vec<Example> {
    let mut found = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let fence = lines[i].trim_start();
        let kind = fence.strip_prefix("```").map(str::trim);
        let Some(kind @ ("sh" | "console")) = kind else {
            i += 1;
            continue;
        };
        let start = i + 1;
        let mut end = start;
        while end < lines.len() && !lines[end].trim_start().starts_with("```") {
            end += 1;
        }
        let body = &lines[start..end];
        if kind == "sh" {
            found.push(Example {
                page: page.to_path_buf(),
                line: start + 1,
                script: body.join("\n"),
            });
        } else {
            let mut j = 0;
            while j < body.len() {
                if let Some(command) = body[j].strip_prefix("$ ") {
                    let line = start + j + 1;
                    let mut script = command.to_string();
                    while script.ends_with('\\') && j + 1 < body.len() {
                        j += 1;
                        script.push('\n');
                        script.push_str(body[j]);
                    }
                    found.push(Example {
                        page: page.to_path_buf(),
                        line,
                        script,
                    });
                }
                j += 1;
            }
        }
        i = end + 1;
    }
    found
}

#[test]
fn the_fence_reader_finds_scripts_and_transcript_commands() {
    let text = "intro\n```sh\ndrumroll cases\necho a \\\n  b\n```\n```console\n$ drumroll simulate \\\n    --z 5\noutput line\n$ drumroll cases\n```\n```text\n$ not run\n```\n";
    let found = examples(Path::new("page.md"), text);
    let scripts: Vec<(usize, &str)> = found.iter().map(|e| (e.line, e.script.as_str())).collect();
    assert_eq!(
        scripts,
        [
            (3, "drumroll cases\necho a \\\n  b"),
            (8, "drumroll simulate \\\n    --z 5"),
            (11, "drumroll cases"),
        ]
    );
}

#[test]
fn every_shell_example_in_the_readme_and_the_guide_runs() {
    let root = repository();
    let binary = PathBuf::from(env!("CARGO_BIN_EXE_drumroll"));
    let bin_dir = binary.parent().expect("the binary's directory");
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut failures = Vec::new();
    let mut count = 0;
    for page in pages(&root) {
        let text = fs::read_to_string(&page).expect("readable page");
        let examples = examples(&page, &text);
        if examples.is_empty() {
            continue;
        }
        let dir = tempfile::tempdir().expect("a scratch directory");
        for linked in ["fixtures", "docs", "python", "scripts"] {
            std::os::unix::fs::symlink(root.join(linked), dir.path().join(linked))
                .expect("link into the scratch directory");
        }
        for example in examples {
            count += 1;
            let started = Instant::now();
            let stderr_path = dir.path().join(format!(".stderr-{count}"));
            let stderr_file = fs::File::create(&stderr_path).expect("a stderr file");
            let mut child = Command::new("bash")
                .args(["-e", "-o", "pipefail", "-c", &example.script])
                .current_dir(dir.path())
                .env("PATH", &path)
                .env("DRUMROLL_REPOSITORY", &root)
                .stdout(std::process::Stdio::null())
                .stderr(stderr_file)
                .spawn()
                .expect("bash starts");
            let status = loop {
                if let Some(status) = child.try_wait().expect("wait") {
                    break Some(status);
                }
                if started.elapsed() > EXAMPLE_LIMIT {
                    let _ = child.kill();
                    let _ = child.wait();
                    break None;
                }
                std::thread::sleep(Duration::from_millis(20));
            };
            let stderr = fs::read_to_string(&stderr_path).unwrap_or_default();
            let place = format!(
                "{}:{}",
                example
                    .page
                    .strip_prefix(&root)
                    .unwrap_or(&example.page)
                    .display(),
                example.line
            );
            match status {
                Some(status) if status.success() => {}
                Some(status) => failures.push(format!(
                    "{place}: exit {status}\n  {}\n  stderr: {}",
                    example.script,
                    stderr.trim()
                )),
                None => failures.push(format!(
                    "{place}: still running after {} s\n  {}",
                    EXAMPLE_LIMIT.as_secs(),
                    example.script
                )),
            }
        }
    }
    assert!(
        count >= 10,
        "only {count} examples found: are the fences marked sh/console?"
    );
    assert!(
        failures.is_empty(),
        "{} of {count} examples failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
