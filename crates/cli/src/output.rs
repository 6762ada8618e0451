//! Writing output files so that a user never finds a half-written one: the whole content goes
//! to a temporary file beside the target, which is then renamed over it; and checking, before
//! computing, that the target can be written at all.

use anyhow::{bail, Context, Result};
use std::io::{BufWriter, Write};
use std::path::Path;

/// Check, before any computation, that `path` (the value of `option`) can be written: its
/// directory exists and takes a new file (a probe file is created there and removed), and
/// `path` is not a directory. The error names the option and the user's path.
pub fn check_writable(path: &Path, option: &str) -> Result<()> {
    let fail = |reason: String| -> Result<()> {
        bail!("{option} {}: cannot write there: {reason}", path.display())
    };
    if path.is_dir() {
        return fail(String::from("it is a directory"));
    }
    let Some(file_name) = path.file_name() else {
        return fail(String::from("it names no file"));
    };
    let mut probe_name = std::ffi::OsString::from(".");
    probe_name.push(file_name);
    probe_name.push(format!(".{}.probe", std::process::id()));
    let probe = path.with_file_name(probe_name);
    remove_stale_temporaries(path);
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
        }
        Err(error) => return fail(error.to_string()),
    }
    if path.exists() {
        if let Err(error) = std::fs::OpenOptions::new().append(true).open(path) {
            return fail(error.to_string());
        }
    }
    Ok(())
}

/// Print `text` on standard output; a reader that closed the pipe (`drumroll ... | head`)
/// ends the output quietly instead of a panic.
pub fn print_stdout(text: &str) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Err(error) if error.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(error).context("cannot write to standard output")
        }
        _ => Ok(()),
    }
}

/// Print `line` and a newline on standard error, ignoring a failure (a closed pipe, a full
/// disk): a note or a message must never make the program panic, as `eprintln!` would.
pub fn print_stderr(line: &str) {
    let mut stderr = std::io::stderr().lock();
    let _ = stderr
        .write_all(line.as_bytes())
        .and_then(|()| stderr.write_all(b"\n"));
}

/// Write `content` to `path` atomically: into `path` + a temporary suffix in the same
/// directory, flushed and synced, then renamed to `path`. On any error the temporary file is
/// removed and the target is left as it was. Every output file of every command is written by
/// this function (or [`write_atomically_with`], or streamed by [`StreamedFile`]); two
/// commands writing the same path leave one complete file, and a killed one the old file or
/// none.
pub fn write_atomically(path: &Path, content: &[u8]) -> Result<()> {
    write_atomically_with(path, |writer| {
        writer.write_all(content)?;
        Ok(())
    })
}

/// As [`write_atomically`], the content streamed by `write` into a buffered writer of the
/// temporary file (for content too large to hold in memory at once); an error of `write`
/// leaves the target as it was.
pub fn write_atomically_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> Result<()>,
) -> Result<()> {
    let file_name = path
        .file_name()
        .with_context(|| format!("output path {} names no file", path.display()))?;
    remove_stale_temporaries(path);
    let (file, temporary) = create_temporary(path, file_name)
        .with_context(|| format!("cannot write {}", path.display()))?;
    let result = (|| -> Result<()> {
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        let file = writer.into_inner().map_err(|error| error.into_error())?;
        file.sync_all()?;
        std::fs::rename(&temporary, path)?;
        sync_directory(path);
        Ok(())
    })()
    .with_context(|| format!("cannot write {}", path.display()));
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

/// A new temporary file beside `path` (file name `file_name`), `<name>.<host>.<PID>-<n>.partial`
/// with `n` counting this process's temporaries, created exclusively (`create_new`): two
/// writers never share one, even on a file system several hosts mount (a cluster's nodes,
/// where process ids repeat).
fn create_temporary(
    path: &Path,
    file_name: &std::ffi::OsStr,
) -> std::io::Result<(std::fs::File, std::path::PathBuf)> {
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    loop {
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let mut name = file_name.to_os_string();
        name.push(format!(
            ".{}.{}-{n}.partial",
            host_name(),
            std::process::id()
        ));
        let temporary = path.with_file_name(name);
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temporary)
        {
            Ok(file) => return Ok((file, temporary)),
            Err(error) if error.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(error) => return Err(error),
        }
    }
}

/// This machine's name as a file-name part (letters, digits, `-` and `_`; `host` where it
/// cannot be told): what tells one host's temporary files from another's. Read once per
/// process.
fn host_name() -> &'static str {
    static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    NAME.get_or_init(|| {
        let name = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .ok()
            .or_else(|| std::env::var("HOSTNAME").ok())
            .unwrap_or_default();
        let name: String = name
            .trim()
            .chars()
            .filter(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
            .collect();
        if name.is_empty() {
            String::from("host")
        } else {
            name
        }
    })
}

/// Sync the directory holding `path`, so that a rename into it survives a crash of the
/// machine (best effort: not every platform opens a directory).
pub fn sync_directory(path: &Path) {
    let directory = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    if let Ok(directory) = std::fs::File::open(directory) {
        let _ = directory.sync_all();
    }
}

/// Remove the temporary files `<path>.<host>.<PID>-<n>.partial` (and the probes
/// `.<name>.<PID>.probe` of [`check_writable`]) that killed runs on this host left beside
/// `path` (Linux: those whose process no longer runs, `/proc/<PID>` absent); another host's
/// are left alone (their processes cannot be seen from here); elsewhere nothing.
fn remove_stale_temporaries(path: &Path) {
    if !cfg!(target_os = "linux") || !Path::new("/proc/self").exists() {
        return;
    }
    let (Some(name), Some(directory)) = (path.file_name(), path.parent()) else {
        return;
    };
    let directory = if directory.as_os_str().is_empty() {
        Path::new(".")
    } else {
        directory
    };
    let mut prefix = name.to_os_string();
    prefix.push(".");
    let Some(prefix) = prefix.to_str().map(str::to_owned) else {
        return;
    };
    let this_host = format!("{prefix}{}.", host_name());
    let Ok(entries) = std::fs::read_dir(directory) else {
        return;
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(pid) = file_name.to_str().and_then(|n| {
            n.strip_prefix(this_host.as_str())
                .and_then(|rest| rest.strip_suffix(".partial"))
                .and_then(|rest| rest.split_once('-').map(|(pid, _)| pid))
                .or_else(|| {
                    n.strip_prefix('.')
                        .and_then(|n| n.strip_prefix(prefix.as_str()))
                        .and_then(|rest| rest.strip_suffix(".probe"))
                })
                .and_then(|pid| pid.parse::<u32>().ok())
        }) else {
            continue;
        };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Append one CSV row to `text`: `first` (the row's label column), then the value of each of
/// `columns` as a key of the JSON object `value` (numbers and strings as JSON prints them, empty
/// for `null`), and a newline. The CSV columns are thus the JSON keys (docs/output-schema.md).
pub fn push_csv_row(text: &mut String, first: &str, value: &serde_json::Value, columns: &[&str]) {
    text.push_str(first);
    for column in columns {
        text.push(',');
        match &value[*column] {
            serde_json::Value::Null => {}
            other => text.push_str(&other.to_string()),
        }
    }
    text.push('\n');
}

/// An output file written while it is computed (an approach sweep's `--out`): the lines go to
/// `<path>.part`, held under an exclusive lock ([`crate::file_lock::lock_exclusive`]) so that
/// a second run on the same path refuses at once, and [`StreamedFile::finish`] renames it to
/// `path`. A killed run thus leaves the old `path` (or none) and a `.part` file, which the
/// next run on the same path starts afresh.
#[derive(Debug)]
pub struct StreamedFile {
    file: std::fs::File,
    part: std::path::PathBuf,
    path: std::path::PathBuf,
}

impl StreamedFile {
    /// Open `<path>.part` (the value of `option`), locked and emptied.
    pub fn create(path: &Path, option: &str) -> Result<Self> {
        let mut part_name = path.as_os_str().to_os_string();
        part_name.push(".part");
        let part = std::path::PathBuf::from(part_name);
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(false)
            .open(&part)
            .with_context(|| format!("{option} {}: cannot create it", part.display()))?;
        crate::file_lock::lock_exclusive(&file, &part, option)?;
        if !crate::file_lock::same_file(&file, &part) {
            bail!(
                "{option} {}: the file was renamed or replaced while this run opened it (by \
                 another run finishing?); run again",
                part.display()
            );
        }
        file.set_len(0)
            .with_context(|| format!("cannot write {}", part.display()))?;
        Ok(Self {
            file,
            part,
            path: path.to_path_buf(),
        })
    }

    /// The `.part` file the lines go to until [`StreamedFile::finish`].
    pub fn part(&self) -> &Path {
        &self.part
    }

    /// Append `line` (newline included) in one write, flushed to the file.
    pub fn write_line(&mut self, line: &str) -> Result<()> {
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.flush())
            .with_context(|| format!("cannot write {}", self.part.display()))
    }

    /// Sync the `.part` file and rename it to the output path (the lock goes with the file
    /// and is released when `self` is dropped).
    pub fn finish(self) -> Result<()> {
        self.file
            .sync_all()
            .and_then(|()| std::fs::rename(&self.part, &self.path))
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        sync_directory(&self.path);
        Ok(())
    }
}

/// The CSV header cells of harmonics `n = 1..=count`, appended after a command's columns:
/// `,harmonic_<n>_amplitude_nm,harmonic_<n>_phase_deg` for each `n` (docs/output-schema.md).
pub fn harmonic_columns(count: usize) -> String {
    (1..=count)
        .map(|n| format!(",harmonic_{n}_amplitude_nm,harmonic_{n}_phase_deg"))
        .collect()
}

/// Append the cells of the first `count` harmonics of a CSV row: `,amplitude_nm,phase_deg` of
/// `harmonics[n - 1]` for `n = 1..=count` (`NaN` where the row has fewer).
pub fn push_harmonic_cells(text: &mut String, harmonics: &[afm::Harmonic], count: usize) {
    for n in 0..count {
        let harmonic = harmonics.get(n);
        text.push_str(&format!(
            ",{},{}",
            harmonic.map_or(f64::NAN, |h| h.amplitude_nm),
            harmonic.map_or(f64::NAN, |h| h.phase_deg)
        ));
    }
}
