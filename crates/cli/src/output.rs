//! Writing output files so that a user never finds a half-written one: the whole content goes
//! to a temporary file beside the target, which is then renamed over it.

use anyhow::{Context, Result};
use std::io::{BufWriter, Write};
use std::path::Path;

/// Write `content` to `path` atomically: into `path` + a temporary suffix in the same
/// directory, flushed and synced, then renamed to `path`. On any error the temporary file is
/// removed and the target is left as it was.
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
    let mut temporary_name = file_name.to_os_string();
    temporary_name.push(format!(".{}.partial", std::process::id()));
    let temporary = path.with_file_name(temporary_name);
    let result = (|| -> Result<()> {
        let file = std::fs::File::create(&temporary)
            .with_context(|| format!("cannot create {}", temporary.display()))?;
        let mut writer = BufWriter::new(file);
        write(&mut writer).with_context(|| format!("cannot write {}", path.display()))?;
        let file = writer
            .into_inner()
            .map_err(|error| error.into_error())
            .with_context(|| format!("cannot write {}", temporary.display()))?;
        file.sync_all()
            .with_context(|| format!("cannot sync {}", temporary.display()))?;
        std::fs::rename(&temporary, path)
            .with_context(|| format!("cannot move {} to {}", temporary.display(), path.display()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result
}
