//! The cantilever file `drumroll cantilever --out` writes (from measured values or from the
//! geometry): checked as a cantilever file before it is written.

use anyhow::{Context, Result};
use std::path::Path;

use crate::output::write_atomically;

/// Write `cantilever` as a cantilever file at `path` (`--out`), once its text has been read
/// back as a valid cantilever: a text that would not load is an error and leaves an existing
/// file as it was; the file is written atomically ([`write_atomically`]).
pub fn write_cantilever_file(path: &Path, cantilever: &afm::Cantilever) -> Result<()> {
    let mut text = serde_json::to_string_pretty(cantilever)?;
    text.push('\n');
    afm::fixtures::parse_cantilever(&path.display().to_string(), &text).with_context(|| {
        format!(
            "{}: the cantilever built does not read back as a valid cantilever file; nothing \
             was written",
            path.display()
        )
    })?;
    write_atomically(path, text.as_bytes())
}
