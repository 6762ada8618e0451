//! The figures' typeface: DejaVu Sans, embedded in the binary (its licence:
//! `crates/cli/assets/fonts/LICENSE-DejaVu.txt`), used to measure text while laying out a
//! figure and to draw it in PNG and PDF files, so that every format looks the same and no
//! system font is needed.

use std::sync::OnceLock;

use super::geometry::Rect;

/// The family name written in SVG files (viewers without it fall back to `sans-serif`).
pub const FONT_FAMILY: &str = "DejaVu Sans";

/// The TrueType file of DejaVu Sans 2.37.
pub static FONT_DATA: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Horizontal alignment of a text at its anchor `x` (SVG's `text-anchor`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// The text starts at `x`.
    Start,
    /// The text is centred on `x`.
    Middle,
    /// The text ends at `x`.
    End,
}

impl Anchor {
    /// The SVG attribute value.
    pub fn svg(self) -> &'static str {
        match self {
            Self::Start => "start",
            Self::Middle => "middle",
            Self::End => "end",
        }
    }
}

/// Advance widths and vertical extent of the embedded font, in font units.
struct Metrics {
    face: Option<ttf_parser::Face<'static>>,
}

fn metrics() -> &'static Metrics {
    static METRICS: OnceLock<Metrics> = OnceLock::new();
    METRICS.get_or_init(|| Metrics {
        face: ttf_parser::Face::parse(FONT_DATA, 0).ok(),
    })
}

/// Width in pixels of `text` set in DejaVu Sans at `size` pixels (the sum of the glyphs'
/// advances, no kerning; 0.6 em for a character the font lacks).
pub fn text_width(text: &str, size: f64) -> f64 {
    let Some(face) = &metrics().face else {
        return 0.6 * size * text.chars().count() as f64;
    };
    let per_unit = size / f64::from(face.units_per_em());
    text.chars()
        .map(|c| {
            face.glyph_index(c)
                .and_then(|g| face.glyph_hor_advance(g))
                .map_or(0.6 * size, |advance| f64::from(advance) * per_unit)
        })
        .sum()
}

/// The box a text occupies: from the font's ascender above the baseline `y` to its descender
/// below, across its advance width placed at `x` by `anchor`.
pub fn text_box(text: &str, size: f64, (x, y): (f64, f64), anchor: Anchor) -> Rect {
    let width = text_width(text, size);
    let (ascent, descent) = match &metrics().face {
        Some(face) => {
            let per_unit = size / f64::from(face.units_per_em());
            (
                f64::from(face.ascender()) * per_unit,
                -f64::from(face.descender()) * per_unit,
            )
        }
        None => (0.93 * size, 0.24 * size),
    };
    let left = match anchor {
        Anchor::Start => x,
        Anchor::Middle => x - 0.5 * width,
        Anchor::End => x - width,
    };
    Rect {
        x0: left,
        y0: y - ascent,
        x1: left + width,
        y1: y + descent,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_font_measures_text() {
        // DejaVu Sans: 'G' advances 1587 of 2048 units, '1' advances 1303 (the font's hmtx
        // table, read with a 40-line Python parser of the TrueType file).
        let expected = (1587.0 + 1303.0) / 2048.0 * 12.0;
        assert!((text_width("G1", 12.0) - expected).abs() < 1e-9);
        let b = text_box("G1", 12.0, (100.0, 50.0), Anchor::Middle);
        assert!((b.width() - expected).abs() < 1e-9);
        assert!(b.y0 < 50.0 - 8.0 && b.y1 > 50.0 + 2.0);
    }
}
