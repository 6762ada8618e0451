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

use crate::output::write_atomically_with;

/// Where one row's line lies in a part file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct RowLine {
    /// Byte offset of the line's start.
    offset: u64,
    /// Its length in bytes, the newline included.
    length: u64,
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

/// Read a part file: its header and the position of every complete row line. A last line
/// without its newline (a run killed while writing it) is left out; any other line that is
/// not a row object with a `row` index is an error naming the file and the line.
pub fn read_part(path: &Path) -> Result<PartContent> {
    let file = File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut reader = BufReader::new(file);
    let mut line = Vec::new();
    let mut offset = 0u64;
    let mut header = None;
    let mut rows = BTreeMap::new();
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
        let value: Value = serde_json::from_slice(&line).with_context(|| {
            format!(
                "{} line {number}: not a JSON object (not a drumroll grid file?)",
                path.display()
            )
        })?;
        if header.is_none() {
            if value.get("inputs").is_none() {
                bail!(
                    "{} line 1: not a drumroll grid header (no `inputs`)",
                    path.display()
                );
            }
            header = Some(
                String::from_utf8(line.clone())
                    .with_context(|| format!("{} line 1: not UTF-8", path.display()))?,
            );
        } else {
            let Some(row) = value.get("row").and_then(Value::as_u64) else {
                bail!(
                    "{} line {number}: not a grid row (no `row`)",
                    path.display()
                );
            };
            rows.insert(row as usize, RowLine { offset, length });
        }
        offset += length;
    }
    Ok(PartContent {
        header,
        rows,
        complete_length: offset,
    })
}

/// A part file open for appending rows, shared by the threads that compute them.
#[derive(Debug)]
pub struct PartWriter {
    path: PathBuf,
    file: Mutex<File>,
}

impl PartWriter {
    /// Open `path` for the rows of a grid with `header` (newline included): a new file gets
    /// the header; an existing one must have been made with the same header (else an error
    /// naming `option` and the file), loses a truncated last line, and its rows are returned
    /// as done.
    pub fn open(path: &Path, header: &str, option: &str) -> Result<(Self, BTreeSet<usize>)> {
        let (file, done) = if path.exists() {
            let content = read_part(path)
                .with_context(|| format!("{option} {}: cannot resume", path.display()))?;
            if content.header.as_deref().is_some_and(|h| h != header) {
                bail!(
                    "{option} {}: the file holds rows of a grid with other inputs ({}); \
                     remove it or choose another file",
                    path.display(),
                    header_difference(content.header.as_deref().unwrap_or_default(), header)
                );
            }
            let file = OpenOptions::new()
                .write(true)
                .open(path)
                .with_context(|| format!("cannot open {} to append", path.display()))?;
            file.set_len(content.complete_length)
                .with_context(|| format!("cannot truncate {}", path.display()))?;
            let mut file = file;
            if content.header.is_none() {
                // Killed before its header was written: start the file afresh.
                file.write_all(header.as_bytes())
                    .with_context(|| format!("cannot write {}", path.display()))?;
            }
            (file, content.row_indices())
        } else {
            let mut file = File::create(path)
                .with_context(|| format!("{option} {}: cannot create", path.display()))?;
            file.write_all(header.as_bytes())
                .with_context(|| format!("cannot write {}", path.display()))?;
            (file, BTreeSet::new())
        };
        let mut file = file;
        file.seek(SeekFrom::End(0))
            .with_context(|| format!("cannot append to {}", path.display()))?;
        Ok((
            Self {
                path: path.to_path_buf(),
                file: Mutex::new(file),
            },
            done,
        ))
    }

    /// Append one row's line (newline included) in one write, flushed to the file.
    pub fn append(&self, line: &str) -> Result<()> {
        let mut file = self
            .file
            .lock()
            .map_err(|_| anyhow::anyhow!("{}: a writer thread failed", self.path.display()))?;
        file.write_all(line.as_bytes())
            .and_then(|()| file.flush())
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
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

/// Write the map file `output` (atomically) from `parts`: the header, then every row in row
/// order, each line copied byte for byte from the part that holds it. Refuses parts whose
/// headers differ (naming the parts and the first differing key), a row held twice with
/// different content, and rows that no part holds (naming them).
pub fn assemble(parts: &[PathBuf], output: &Path) -> Result<()> {
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
            if row >= rows {
                bail!(
                    "part {}: row {row} is outside the grid's {rows} rows",
                    parts[part].display()
                );
            }
            match holder.get(&row) {
                None => {
                    holder.insert(row, (part, line));
                }
                Some(&(other, other_line)) => {
                    let a = read_line(&parts[other], other_line)?;
                    let b = read_line(&parts[part], line)?;
                    if a != b {
                        bail!(
                            "row {row} differs between parts {} and {}",
                            parts[other].display(),
                            parts[part].display()
                        );
                    }
                }
            }
        }
    }
    let missing: Vec<usize> = (0..rows).filter(|row| !holder.contains_key(row)).collect();
    if !missing.is_empty() {
        bail!(
            "rows missing from the parts: {} ({} of the grid's {rows} rows; rerun the shards \
             that hold them, which resume where they stopped)",
            list_rows(&missing),
            missing.len()
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
