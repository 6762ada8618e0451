//! The images of a 2-D scan (`drumroll scan --raster FILE --plot FILE`): measured height,
//! phase and impacts per period as false-colour maps side by side, one cell per pixel, `x`
//! to the right and row 0 at the bottom, each with its colour scale's ends written below
//! (MODEL.md section 12). SVG, PNG or PDF by the plot file's extension.

use std::fmt::Write as _;

use crate::plot::font::FONT_FAMILY;

/// One map: a title and the values, `values[row][column]`.
pub struct ImageMap {
    /// The title above the map, with the unit.
    pub title: String,
    /// `values[row][column]`; non-finite values are drawn grey.
    pub values: Vec<Vec<f64>>,
}

/// The colour of `s` in [0, 1] on a perceptually ordered dark-blue to yellow scale (linear
/// interpolation between five stops of viridis).
fn colour(s: f64) -> (u8, u8, u8) {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let s = s.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - i as f64;
    let mix = |a: f64, b: f64| (a + (b - a) * f).round() as u8;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    (mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The SVG document of `maps` side by side, each image pixel drawn `cell = (width, height)`
/// SVG pixels (in proportion to the scan's pixel width and row spacing).
pub fn image_maps_svg(title: &str, maps: &[ImageMap], cell: (f64, f64)) -> String {
    let rows = maps.first().map_or(0, |m| m.values.len());
    let columns = maps
        .first()
        .and_then(|m| m.values.first())
        .map_or(0, Vec::len);
    let (map_width, map_height) = (columns as f64 * cell.0, rows as f64 * cell.1);
    let (margin, header, footer) = (20.0, 50.0, 40.0);
    let width = margin + maps.len() as f64 * (map_width + margin);
    let height = header + map_height + footer;
    let mut svg = String::new();
    let _ = write!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="{FONT_FAMILY}, sans-serif"><rect width="100%" height="100%" fill="white"/><text x="{margin}" y="20" font-size="15">{title}</text>"#
    );
    for (index, map) in maps.iter().enumerate() {
        let left = margin + index as f64 * (map_width + margin);
        let finite = map
            .values
            .iter()
            .flatten()
            .copied()
            .filter(|v| v.is_finite());
        let (low, high) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
        let _ = write!(
            svg,
            r#"<text x="{left}" y="{}" font-size="13">{}</text>"#,
            header - 8.0,
            map.title
        );
        for (row, values) in map.values.iter().enumerate() {
            // Row 0 at the bottom, as y increases upwards.
            let top = header + (rows - 1 - row) as f64 * cell.1;
            for (column, &value) in values.iter().enumerate() {
                let fill = if value.is_finite() {
                    let s = if high > low {
                        (value - low) / (high - low)
                    } else {
                        0.5
                    };
                    let (r, g, b) = colour(s);
                    format!("rgb({r},{g},{b})")
                } else {
                    String::from("grey")
                };
                let _ = write!(
                    svg,
                    r#"<rect x="{}" y="{top}" width="{}" height="{}" fill="{fill}"/>"#,
                    left + column as f64 * cell.0,
                    cell.0 + 0.05,
                    cell.1 + 0.05
                );
            }
        }
        let (r0, g0, b0) = colour(0.0);
        let (r1, g1, b1) = colour(1.0);
        let _ = write!(
            svg,
            r#"<text x="{left}" y="{y}" font-size="12" fill="rgb({r0},{g0},{b0})">min {low:.4}</text><text x="{right}" y="{y}" font-size="12" text-anchor="end" fill="rgb({r1},{g1},{b1})" stroke="black" stroke-width="0.2">max {high:.4}</text>"#,
            y = header + map_height + 20.0,
            right = left + map_width,
        );
    }
    svg.push_str("</svg>\n");
    svg
}
