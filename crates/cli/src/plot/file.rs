//! Figure files: the format follows the file name's extension (`.svg`, `.png`, `.pdf`), and
//! the file is written atomically (see [`crate::output::write_atomically`]).

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

use super::raster;
use crate::output::{check_writable, write_atomically};

/// The file format of a figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FigureFormat {
    /// Scalable vector graphics, the figure's native form.
    Svg,
    /// A raster image, rendered at [`raster::PNG_SCALE`] times the SVG's size.
    Png,
    /// A one-page vector PDF.
    Pdf,
}

/// A figure file: where, and in which format.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FigureFile {
    /// The path as given.
    pub path: PathBuf,
    /// The format its extension names.
    pub format: FigureFormat,
}

impl FigureFile {
    /// The figure file `path` given to `option`; its name must end in `.svg`, `.png` or `.pdf`
    /// (any case), and it must be writable (checked before any computation:
    /// [`crate::output::check_writable`]).
    pub fn new(path: &Path, option: &str) -> Result<Self> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let format = match extension.as_deref() {
            Some("svg") => FigureFormat::Svg,
            Some("png") => FigureFormat::Png,
            Some("pdf") => FigureFormat::Pdf,
            _ => bail!(
                "{option} {}: allowed: a file name ending in .svg, .png or .pdf (the format follows the extension)",
                path.display()
            ),
        };
        check_writable(path, option)?;
        Ok(Self {
            path: path.to_path_buf(),
            format,
        })
    }

    /// Write the figure `svg` in this file's format.
    pub fn write(&self, svg: &str) -> Result<()> {
        let bytes = match self.format {
            FigureFormat::Svg => svg.as_bytes().to_vec(),
            FigureFormat::Png => raster::png(svg)?,
            FigureFormat::Pdf => raster::pdf(svg)?,
        };
        write_atomically(&self.path, &bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_extension_chooses_the_format_and_others_are_refused() {
        let directory = tempfile::tempdir().expect("temporary directory");
        let f = FigureFile::new(&directory.path().join("fig.PNG"), "--plot").expect("png");
        assert_eq!(f.format, FigureFormat::Png);
        let error = FigureFile::new(Path::new("fig.jpg"), "--plot").unwrap_err();
        let message = error.to_string();
        assert!(message.contains("--plot fig.jpg") && message.contains(".svg, .png or .pdf"));
    }
}
