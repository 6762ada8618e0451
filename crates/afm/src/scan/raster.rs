//! A 2-D sample as a raster of scan lines (MODEL.md section 12): rows at a fixed spacing in
//! `y`, each a line as in a line file (its own segments, heights, samples and edge width),
//! all spanning the same `x` range. A raster file:
//!
//! ```json
//! {"row_spacing_nm": 20, "rows": [{"segments": [...]}, "patch.json", "membrane-patch"]}
//! ```
//!
//! where a row is a line object, a built-in line name or a line file path (relative to the
//! raster file). Each row is scanned as a line; the image's rows are the lines' pixels.

use std::path::Path;

use serde::Deserialize;

use crate::error::AfmError;
use crate::fixtures::{load_relative, parse_json};
use crate::scan::line::ScanLine;
use crate::validation::{check, Interval};

/// The most rows a raster has.
pub const MAX_ROWS: usize = 10_000;

/// A row as written: a line object, or a name or path.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum RowReference {
    Name(String),
    Inline(serde_json::Value),
}

/// A raster file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct RasterFile {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: String,
    row_spacing_nm: f64,
    rows: Vec<RowReference>,
}

/// A resolved, checked raster of scan lines.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanRaster {
    /// The raster's name (the file stem if the file gives none).
    pub name: String,
    /// Free-text description.
    pub description: String,
    /// The distance between rows, nm; row `j` is at `y = j * row_spacing_nm`.
    pub row_spacing_nm: f64,
    /// The rows in order of `y`, each spanning the first row's `x` range.
    pub rows: Vec<ScanLine>,
}

impl ScanRaster {
    /// Parse and check a raster file's text; `file` names it in errors, `base` resolves
    /// relative paths (`None`: inline rows and built-in names only).
    pub fn parse(file: &str, text: &str, base: Option<&Path>) -> Result<Self, AfmError> {
        let raw: RasterFile = parse_json(file, text)?;
        check(
            file,
            "row_spacing_nm",
            raw.row_spacing_nm,
            Interval::positive(crate::scan::line::MAX_LINE_NM, "nm"),
        )?;
        if raw.rows.is_empty() || raw.rows.len() > MAX_ROWS {
            return Err(AfmError::InvalidField {
                file: file.to_string(),
                field: String::from("rows"),
                value: raw.rows.len().to_string(),
                allowed: format!("1 to {MAX_ROWS} rows"),
            });
        }
        let mut rows: Vec<ScanLine> = Vec::with_capacity(raw.rows.len());
        for (index, row) in raw.rows.iter().enumerate() {
            let source = format!("{file}: rows[{index}]");
            let line = match row {
                RowReference::Inline(value) => ScanLine::parse(&source, &value.to_string(), base)?,
                RowReference::Name(name) => {
                    let path = Path::new(name);
                    if path.extension().is_some_and(|e| e == "json") {
                        ScanLine::load(&base.map_or_else(|| path.to_path_buf(), |b| b.join(path)))?
                    } else {
                        ScanLine::builtin(name)?
                    }
                }
            };
            if let Some(first) = rows.first() {
                if line.start_nm() != first.start_nm() || line.end_nm() != first.end_nm() {
                    return Err(AfmError::InvalidField {
                        file: file.to_string(),
                        field: format!("rows[{index}]"),
                        value: format!("x from {} to {} nm", line.start_nm(), line.end_nm()),
                        allowed: format!(
                            "the x range of rows[0], {} to {} nm (an image's rows are equally long)",
                            first.start_nm(),
                            first.end_nm()
                        ),
                    });
                }
            }
            rows.push(line);
        }
        let name = raw.name.unwrap_or_else(|| {
            Path::new(file).file_stem().map_or_else(
                || String::from("raster"),
                |s| s.to_string_lossy().into_owned(),
            )
        });
        Ok(Self {
            name,
            description: raw.description,
            row_spacing_nm: raw.row_spacing_nm,
            rows,
        })
    }

    /// Load a raster file from `path` (paths in it relative to its directory).
    pub fn load(path: &Path) -> Result<Self, AfmError> {
        load_relative(path, Self::parse)
    }
}
