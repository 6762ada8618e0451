//! PNG and PDF from a figure's SVG, in pure Rust: `usvg` parses the SVG with the embedded
//! DejaVu Sans as its only font, `resvg` renders it to pixels, `svg2pdf` writes it as vector
//! PDF; the three formats thus share one look.

use std::sync::Arc;

use anyhow::{anyhow, Context, Result};
use resvg::{tiny_skia, usvg};

use super::font::{FONT_DATA, FONT_FAMILY};

/// PNG pixels per SVG pixel: twice the SVG's size, sharp in print at the SVG's size.
pub const PNG_SCALE: f32 = 2.0;

/// The parsed figure, its text set in the embedded font.
pub fn parse(svg: &str) -> Result<usvg::Tree> {
    let mut fonts = usvg::fontdb::Database::new();
    fonts.load_font_data(FONT_DATA.to_vec());
    let options = usvg::Options {
        font_family: FONT_FAMILY.to_string(),
        fontdb: Arc::new(fonts),
        ..usvg::Options::default()
    };
    usvg::Tree::from_str(svg, &options).context("cannot parse the figure's SVG")
}

/// The figure as a PNG image of [`PNG_SCALE`] times its SVG size.
pub fn png(svg: &str) -> Result<Vec<u8>> {
    let tree = parse(svg)?;
    let size = tree
        .size()
        .to_int_size()
        .scale_by(PNG_SCALE)
        .ok_or_else(|| anyhow!("the figure's size cannot be scaled by {PNG_SCALE}"))?;
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).ok_or_else(|| {
        anyhow!(
            "cannot allocate a {} x {} image",
            size.width(),
            size.height()
        )
    })?;
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(PNG_SCALE, PNG_SCALE),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|error| anyhow!("cannot encode the PNG: {error}"))
}

/// The figure as a one-page vector PDF (page size: the SVG's size at 72 pixels per inch).
pub fn pdf(svg: &str) -> Result<Vec<u8>> {
    let tree = parse(svg)?;
    svg2pdf::to_pdf(
        &tree,
        svg2pdf::ConversionOptions::default(),
        svg2pdf::PageOptions::default(),
    )
    .map_err(|error| anyhow!("cannot convert the figure to PDF: {error}"))
}
