//! The files of `drumroll grid` (docs/output-schema.md): JSON Lines, a header line with the
//! inputs, then one line per row. A part file (one shard's, or a single run's work in
//! progress) holds the header and its rows in the order they were finished, appended one
//! complete line at a time, so that a killed run leaves at most a truncated last line, which
//! is discarded when the file is read again. The map file is the header and every row in row
//! order: [`assemble`] writes it from parts, byte for byte the lines the parts hold, so that it
//! does not depend on how the rows were shared out.

use anyhow::{bail, Context, Result};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::file_lock::{lock_exclusive, lock_shared, same_file};
use crate::grid_row::GridShape;
use crate::output::write_atomically_with;

/// Where one row's line lies in a part file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct RowLine {
    /// Byte offset of the line's start.
    offset: u64,
    /// Its length in bytes, the newline included.
    length: u64,
    /// Its line number in the file, from 1.
    number: usize,
}

/// What a part file holds: its header line, the complete row lines by row index, and the
/// length of its complete content (a truncated last line excluded).
#[derive(Debug)]
pub struct PartContent {
    /// The header line, newline included (`None`: the file is empty or its header was cut
    /// short).
    pub header: Option<String>,
    rows: BTreeMap<usize, RowLine>,
    complete_length: u64,
}

impl PartContent {
    /// The indices of the rows the part holds.
    pub fn row_indices(&self) -> BTreeSet<usize> {
        self.rows.keys().copied().collect()
    }
}

/// How to recover from a damaged line `number` of the part `path`.
fn recovery(path: &Path, number: usize) -> String {
    format!(
        "the other lines are intact: delete line {number} (`sed -i '{number}d' {path}`) and \
         rerun the same command to compute that row again, or remove the file to start afresh",
        path = path.display()
    )
}

/// Read a part file: its header and the position of every complete row line, each checked
/// against the header ([`GridShape::check_row`]: checksum, index, parameter value, cells). A
/// last line without its newline (a run killed while writing it) is left out. A damaged line
/// is an error naming the file, the line, what is wrong and how to recover; the same row twice
/// is kept once when the lines are identical and an error naming both lines otherwise.
pub fn read_part(path: &Path) -> Result<PartContent> {
    let file = File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    read_part_from(file, path)
}

/// [`read_part`] on an open file (read from its start).
fn read_part_from(mut file: File, path: &Path) -> Result<PartContent> {
    file.seek(SeekFrom::Start(0))
        .with_context(|| format!("cannot read {}", path.display()))?;
    let mut reader = BufReader::new(file);
    let mut line = Vec::new();
    let mut offset = 0u64;
    let mut header = None;
    let mut shape = None;
    let mut rows: BTreeMap<usize, RowLine> = BTreeMap::new();
    let mut number = 0usize;
    loop {
        line.clear();
        let length = reader
            .read_until(b'\n', &mut line)
            .with_context(|| format!("cannot read {}", path.display()))?
            as u64;
        if length == 0 || line.last() != Some(&b'\n') {
            break;
        }
        number += 1;
        let Ok(text) = std::str::from_utf8(&line[..line.len() - 1]) else {
            bail!(
                "{} line {number}: not UTF-8 text (a damaged line); {}",
                path.display(),
                recovery(path, number)
            );
        };
        let Some(grid) = &shape else {
            let value: Value = serde_json::from_str(text).with_context(|| {
                format!(
                    "{} line 1: not a JSON object (not a drumroll grid file?)",
                    path.display()
                )
            })?;
            if value.get("inputs").is_none() {
                bail!(
                    "{} line 1: not a drumroll grid header (no `inputs`)",
                    path.display()
                );
            }
            shape = Some(GridShape::of_header(text).map_err(|reason| {
                anyhow::anyhow!(
                    "{} line 1: {reason} (not a drumroll grid file?)",
                    path.display()
                )
            })?);
            header = Some(format!("{text}\n"));
            offset += length;
            continue;
        };
        let row = grid.check_row(text).map_err(|reason| {
            anyhow::anyhow!(
                "{} line {number}: {reason}; {}",
                path.display(),
                recovery(path, number)
            )
        })?;
        match rows.get(&row) {
            None => {
                rows.insert(
                    row,
                    RowLine {
                        offset,
                        length,
                        number,
                    },
                );
            }
            Some(first) if read_line(path, *first)? == line => {}
            Some(first) => bail!(
                "{} lines {} and {number} both hold row {row}, with different contents; \
                 delete one of them (`sed -i '{number}d' {}` keeps the first) and rerun",
                path.display(),
                first.number,
                path.display()
            ),
        }
        offset += length;
    }
    Ok(PartContent {
        header,
        rows,
        complete_length: offset,
    })
}

/// A part file open for appending rows under an exclusive lock ([`lock_exclusive`]), shared by
/// the threads that compute them.
#[derive(Debug)]
pub struct PartWriter {
    path: PathBuf,
    file: Mutex<AppendState>,
}

/// The part file and the length of its complete lines; `failed` once an append failed (the
/// file was cut back to `length`, and no line goes after it).
#[derive(Debug)]
struct AppendState {
    file: File,
    length: u64,
    failed: bool,
}

impl PartWriter {
    /// Open `path` for the rows of a grid with `header` (newline included), locked against a
    /// second writer (an error naming `option`, the file and the other process): a new file
    /// gets the header; an existing one must have been made with the same header (else an
    /// error naming `option` and the file), loses a truncated last line, and its rows (each
    /// checked, [`read_part`]) are returned as done.
    pub fn open(path: &Path, header: &str, option: &str) -> Result<(Self, BTreeSet<usize>)> {
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .with_context(|| format!("{option} {}: cannot open it", path.display()))?;
        lock_exclusive(&file, path, option)?;
        if !same_file(&file, path) {
            bail!(
                "{option} {}: the file was removed or replaced while this run opened it (by \
                 another run finishing?); run again",
                path.display()
            );
        }
        let reading = file
            .try_clone()
            .with_context(|| format!("cannot read {}", path.display()))?;
        let content = read_part_from(reading, path)
            .with_context(|| format!("{option} {}: cannot resume", path.display()))?;
        if content.header.as_deref().is_some_and(|h| h != header) {
            bail!(
                "{option} {}: the file holds rows of a grid with other inputs ({}); \
                 remove it or choose another file",
                path.display(),
                header_difference(content.header.as_deref().unwrap_or_default(), header)
            );
        }
        let mut file = file;
        if content.header.is_none() {
            // New, or killed before its header was written (its bytes a beginning of the
            // header): start the file afresh. Anything else is not this run's to wipe.
            let length = file
                .metadata()
                .with_context(|| format!("cannot read {}", path.display()))?
                .len();
            if length > 0 && !starts_the_header(&file, length, header) {
                bail!(
                    "{option} {}: the file exists and is not a drumroll grid file (no header \
                     line); remove it or choose another file",
                    path.display()
                );
            }
            file.set_len(0)
                .and_then(|()| file.seek(SeekFrom::Start(0)).map(|_| ()))
                .and_then(|()| file.write_all(header.as_bytes()))
                .and_then(|()| file.flush())
                .with_context(|| format!("cannot write {}", path.display()))?;
        } else {
            file.set_len(content.complete_length)
                .with_context(|| format!("cannot truncate {}", path.display()))?;
        }
        let length = file
            .seek(SeekFrom::End(0))
            .with_context(|| format!("cannot append to {}", path.display()))?;
        Ok((
            Self {
                path: path.to_path_buf(),
                file: Mutex::new(AppendState {
                    file,
                    length,
                    failed: false,
                }),
            },
            content.row_indices(),
        ))
    }

    /// Append one row's line (newline included) in one write and sync its data to the disk
    /// (a row costs far more to compute than to sync, and a synced row survives a crash of the
    /// machine). A write that fails part way (a full disk) is cut back off the file, and no
    /// later line is appended: the file keeps whole lines only, for the rerun to resume.
    pub fn append(&self, line: &str) -> Result<()> {
        let mut state = self
            .file
            .lock()
            .map_err(|_| anyhow::anyhow!("{}: a writer thread failed", self.path.display()))?;
        if state.failed {
            bail!(
                "cannot write {}: an earlier row failed to be written",
                self.path.display()
            );
        }
        let written = state
            .file
            .write_all(line.as_bytes())
            .and_then(|()| state.file.sync_data());
        match written {
            Ok(()) => {
                state.length += line.len() as u64;
                Ok(())
            }
            Err(error) => {
                state.failed = true;
                let length = state.length;
                let _ = state
                    .file
                    .set_len(length)
                    .and_then(|()| state.file.seek(SeekFrom::Start(length)).map(|_| ()));
                Err(error).with_context(|| format!("cannot write {}", self.path.display()))
            }
        }
    }
}

/// Whether the `length` bytes of `file` (which holds no complete line) are a beginning of
/// `header`: what a run killed while writing the header leaves.
fn starts_the_header(file: &File, length: u64, header: &str) -> bool {
    if length > header.len() as u64 {
        return false;
    }
    let mut bytes = Vec::with_capacity(length as usize);
    let read = file
        .try_clone()
        .and_then(|mut reading| {
            reading.seek(SeekFrom::Start(0))?;
            reading.take(length).read_to_end(&mut bytes)
        })
        .is_ok();
    read && header.as_bytes().starts_with(&bytes)
}

/// The number of rows of the grid a header describes (`inputs.options.steps`).
pub fn row_count(header: &str, path: &Path) -> Result<usize> {
    let value: Value = serde_json::from_str(header)
        .with_context(|| format!("{}: the header is not JSON", path.display()))?;
    value["inputs"]["options"]["steps"]
        .as_u64()
        .map(|n| n as usize)
        .with_context(|| {
            format!(
                "{}: the header has no `inputs.options.steps` (not a drumroll grid file?)",
                path.display()
            )
        })
}

/// Write the map file `output` (atomically) from `parts`, each read under a shared lock (a
/// part still being written by a shard is refused, naming its process): the header, then
/// every row in row order, each line copied byte for byte from the part that holds it.
/// Refuses parts whose headers differ (naming the parts and the first differing key), damaged
/// rows ([`read_part`]), a row held twice with different content, and rows that no part holds
/// (naming them).
pub fn assemble(parts: &[PathBuf], output: &Path) -> Result<()> {
    let mut locks = Vec::with_capacity(parts.len());
    for path in parts {
        let file = File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
        lock_shared(&file, path, "part")?;
        locks.push(file);
    }
    let result = assemble_locked(parts, output);
    drop(locks);
    result
}

/// [`assemble`] of parts the caller holds locked (a single run's own work file).
pub fn assemble_locked(parts: &[PathBuf], output: &Path) -> Result<()> {
    let Some(first) = parts.first() else {
        bail!("no part file given");
    };
    let contents = parts
        .iter()
        .map(|path| read_part(path))
        .collect::<Result<Vec<_>>>()?;
    let mut headers = Vec::with_capacity(parts.len());
    for (path, content) in parts.iter().zip(&contents) {
        let Some(header) = content.header.as_deref() else {
            bail!(
                "part {}: no complete header line (an empty or cut-short file)",
                path.display()
            );
        };
        headers.push(header);
    }
    let header = headers[0];
    for (path, other) in parts.iter().zip(&headers).skip(1) {
        if *other != header {
            bail!(
                "part {} was made with other inputs than part {} ({}): parts of different \
                 grids cannot be merged",
                path.display(),
                first.display(),
                header_difference(header, other)
            );
        }
    }
    let rows = row_count(header, first)?;
    // Row index -> (part, line).
    let mut holder: BTreeMap<usize, (usize, RowLine)> = BTreeMap::new();
    for (part, content) in contents.iter().enumerate() {
        for (&row, &line) in &content.rows {
            match holder.get(&row) {
                None => {
                    holder.insert(row, (part, line));
                }
                Some(&(other, other_line)) => {
                    let a = read_line(&parts[other], other_line)?;
                    let b = read_line(&parts[part], line)?;
                    if a != b {
                        bail!(
                            "row {row} differs between parts {} (line {}) and {} (line {}); \
                             delete it from one of them (or remove that part and rerun its \
                             shard)",
                            parts[other].display(),
                            other_line.number,
                            parts[part].display(),
                            line.number
                        );
                    }
                }
            }
        }
    }
    let missing: Vec<usize> = (0..rows).filter(|row| !holder.contains_key(row)).collect();
    if !missing.is_empty() {
        bail!(
            "rows missing from the parts: {} ({} of the grid's {rows} rows, in none of {}; rerun \
             the shards that hold them, which resume where they stopped)",
            list_rows(&missing),
            missing.len(),
            list_parts(parts)
        );
    }
    write_atomically_with(output, |writer| {
        writer.write_all(header.as_bytes())?;
        for (part, line) in holder.values() {
            writer.write_all(&read_line(&parts[*part], *line)?)?;
        }
        Ok(())
    })
}

/// The bytes of one row line of a part file.
fn read_line(path: &Path, line: RowLine) -> Result<Vec<u8>> {
    let mut file = File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    file.seek(SeekFrom::Start(line.offset))
        .with_context(|| format!("cannot read {}", path.display()))?;
    let mut bytes = vec![0; line.length as usize];
    file.read_exact(&mut bytes)
        .with_context(|| format!("cannot read {} (changed while merging?)", path.display()))?;
    Ok(bytes)
}

/// Part file names as a short list: the first 5, then how many more.
fn list_parts(parts: &[PathBuf]) -> String {
    let shown: Vec<String> = parts
        .iter()
        .take(5)
        .map(|part| part.display().to_string())
        .collect();
    let mut text = shown.join(", ");
    if parts.len() > 5 {
        text.push_str(&format!(", ... ({} more)", parts.len() - 5));
    }
    text
}

/// Row indices as a short list: the first 20, then how many more.
fn list_rows(rows: &[usize]) -> String {
    let shown: Vec<String> = rows.iter().take(20).map(usize::to_string).collect();
    let mut text = shown.join(", ");
    if rows.len() > 20 {
        text.push_str(&format!(", ... ({} more)", rows.len() - 20));
    }
    text
}

/// Where two header lines differ, in words: the first key path whose values differ.
fn header_difference(a: &str, b: &str) -> String {
    match (
        serde_json::from_str::<Value>(a),
        serde_json::from_str::<Value>(b),
    ) {
        (Ok(a), Ok(b)) => first_difference(&a, &b, "")
            .map(|path| format!("`{path}` differs"))
            .unwrap_or_else(|| String::from("the headers differ in formatting")),
        _ => String::from("a header is not JSON"),
    }
}

/// The first key path (depth first, keys in order) at which `a` and `b` differ.
fn first_difference(a: &Value, b: &Value, path: &str) -> Option<String> {
    let join = |key: &str| {
        if path.is_empty() {
            key.to_string()
        } else {
            format!("{path}.{key}")
        }
    };
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            keys.into_iter()
                .find_map(|key| match (x.get(key), y.get(key)) {
                    (Some(u), Some(v)) => first_difference(u, v, &join(key)),
                    _ => Some(join(key)),
                })
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .find_map(|(u, v)| first_difference(u, v, &format!("{path}[]"))),
        _ if a == b => None,
        _ => Some(path.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn the_first_difference_names_the_key_path() {
        let a = json!({"inputs": {"options": {"steps": 3, "z_to_nm": 1.0}}});
        let b = json!({"inputs": {"options": {"steps": 3, "z_to_nm": 2.0}}});
        assert_eq!(
            first_difference(&a, &b, "").as_deref(),
            Some("inputs.options.z_to_nm")
        );
        assert_eq!(first_difference(&a, &a, ""), None);
    }

    #[test]
    fn long_row_lists_are_shortened() {
        let rows: Vec<usize> = (0..25).collect();
        assert!(list_rows(&rows).ends_with("19, ... (5 more)"));
    }
}
