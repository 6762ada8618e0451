//! The SVG document of a figure: each panel's frame, ticks, axis labels, curves (thinned to
//! the figure's resolution), special points with their labels, region names, shaded areas,
//! grid cells and legend. Elements carry ids (`p<panel>-xtick-<k>`, `p<panel>-ytick-<k>`,
//! `p<panel>-label-<k>`, `p<panel>-region-<k>`, `p<panel>-legend`, `p<panel>-curve-<k>`) or
//! classes (`cell`, `shaded`) so that tests and scripts can find them.

use std::fmt::Write as _;

use super::decimate::{decimate_dots, decimate_polyline};
use super::font::{text_box, Anchor, FONT_FAMILY};
use super::geometry::{Pixel, Rect};
use super::labels::{place_labels, Obstacles, PlacedLabel, MARKER_RADIUS};
use super::layout::{
    frame, Frame, AXIS_LABEL_SIZE, LEGEND_SIZE, MARKER_LABEL_SIZE, TICK_LENGTH, TICK_SIZE,
    TITLE_LINE, TITLE_SIZE,
};
use super::legend::{free_corner, legend_size, LegendEntry, LEGEND_LINE, LEGEND_PADDING, SWATCH};
use super::regions::{place_regions, PlacedRegion, REGION_LABEL_SIZE};
use super::{unwrapped_pieces, Panel, Stroke};

/// Fill of a bistable cell of a grid and its opacity.
const GREY_CELL: &str = r##"fill="#969696" fill-opacity="0.5""##;
/// Opacity of a grid cell tinted in its palette colour.
const CELL_OPACITY: &str = "0.25";
/// Fill of a shaded area (a bistable range).
const SHADE: &str = r##"fill="#c8c8c8" fill-opacity="0.6""##;
/// Colour of region names.
const REGION_COLOUR: &str = "#5a5a5a";

/// The palette (Tableau 10's first six, then black), indexed by [`super::Series::colour`].
pub const PALETTE: [&str; 7] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#000000",
];

/// The palette index of black, for keys of line styles.
pub const KEY_COLOUR: usize = 6;

/// A series projected to pixels: its pieces (split at phase wraps), thinned.
struct Drawn {
    pieces: Vec<Vec<Pixel>>,
    stroke: Stroke,
    colour: usize,
}

/// Stroke attributes of a line style.
fn stroke_attributes(stroke: Stroke) -> &'static str {
    match stroke {
        Stroke::Solid => r#"stroke-width="2.6""#,
        Stroke::Dashed => r#"stroke-width="2.6" stroke-dasharray="7 4""#,
        Stroke::DashDot => r#"stroke-width="1.3" stroke-dasharray="9 3 2 3""#,
        Stroke::Dotted => r#"stroke-width="1.3" stroke-dasharray="2 3""#,
        Stroke::Dots => r#"stroke-width="3.6" stroke-linecap="round""#,
        Stroke::FineDots => r#"stroke-width="1.4" stroke-linecap="round""#,
    }
}

fn colour(index: usize) -> &'static str {
    PALETTE[index % PALETTE.len()]
}

/// `&`, `<`, `>` and `"` escaped for SVG text and attributes.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn project(panel: &Panel, frame: &Frame) -> Vec<Drawn> {
    panel
        .series
        .iter()
        .map(|series| {
            let finite: Vec<(f64, f64)> = series
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            let pieces = unwrapped_pieces(finite, panel.y_period)
                .into_iter()
                .map(|piece| {
                    let pixels: Vec<Pixel> = piece.iter().map(|&p| frame.to_pixel(p)).collect();
                    match series.stroke {
                        Stroke::Dots | Stroke::FineDots => decimate_dots(&pixels),
                        _ => decimate_polyline(&pixels),
                    }
                })
                .collect();
            Drawn {
                pieces,
                stroke: series.stroke,
                colour: series.colour,
            }
        })
        .collect()
}

fn segments(drawn: &[Drawn]) -> Vec<(Pixel, Pixel)> {
    let mut all = Vec::new();
    for series in drawn {
        for piece in &series.pieces {
            match (series.stroke, piece.as_slice()) {
                (Stroke::Dots | Stroke::FineDots, _) | (_, [_]) => {
                    all.extend(piece.iter().map(|&p| (p, p)))
                }
                _ => all.extend(piece.windows(2).map(|w| (w[0], w[1]))),
            }
        }
    }
    all
}

/// The panel's frame and legend box: the legend in a free corner, else outside on the right
/// (the plot area narrowed to make room).
fn frame_and_legend(
    panel: &Panel,
    outer: Rect,
    entries: &[LegendEntry],
) -> (Frame, Vec<Drawn>, Option<Rect>) {
    let inside = frame(panel, outer, 0.0);
    let drawn = project(panel, &inside);
    if entries.is_empty() {
        return (inside, drawn, None);
    }
    let size = legend_size(entries);
    let markers: Vec<Rect> = panel
        .markers
        .iter()
        .map(|m| {
            let (x, y) = inside.to_pixel(m.at);
            Rect::new(x - 12.0, y - 12.0, 24.0, 24.0)
        })
        .collect();
    if let Some(corner) = free_corner(inside.plot, size, &segments(&drawn), &markers) {
        return (inside, drawn, Some(corner));
    }
    let outside = frame(panel, outer, size.0 + 12.0);
    let drawn = project(panel, &outside);
    let legend = Rect::new(outside.plot.x1 + 10.0, outside.plot.y0, size.0, size.1);
    (outside, drawn, Some(legend))
}

fn text_element(
    svg: &mut String,
    id: &str,
    (x, y): Pixel,
    size: f64,
    anchor: Anchor,
    extra: &str,
    text: &str,
) {
    let _ = writeln!(
        svg,
        r#"<text id="{id}" x="{x:.1}" y="{y:.1}" font-size="{size}" text-anchor="{}"{extra}>{}</text>"#,
        anchor.svg(),
        escape(text)
    );
}

fn draw_axes(svg: &mut String, index: usize, panel: &Panel, frame: &Frame) {
    let plot = frame.plot;
    let _ = writeln!(
        svg,
        r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="black" stroke-width="1"/>"#,
        plot.x0,
        plot.y0,
        plot.width(),
        plot.height()
    );
    for (k, &value) in frame.x_ticks.values.iter().enumerate() {
        let (x, _) = frame.to_pixel((value, frame.y_range.0));
        let _ = writeln!(
            svg,
            r#"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="black"/>"#,
            plot.y1,
            plot.y1 + TICK_LENGTH
        );
        let at = (x, plot.y1 + TICK_LENGTH + 3.0 + TICK_SIZE);
        let label = frame.x_ticks.label(value);
        text_element(
            svg,
            &format!("p{index}-xtick-{k}"),
            at,
            TICK_SIZE,
            Anchor::Middle,
            "",
            &label,
        );
    }
    for (k, &value) in frame.y_ticks.values.iter().enumerate() {
        let (_, y) = frame.to_pixel((frame.x_range.0, value));
        let _ = writeln!(
            svg,
            r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="black"/>"#,
            plot.x0 - TICK_LENGTH,
            plot.x0
        );
        let at = (plot.x0 - TICK_LENGTH - 3.0, y + 0.35 * TICK_SIZE);
        let label = frame.y_ticks.label(value);
        text_element(
            svg,
            &format!("p{index}-ytick-{k}"),
            at,
            TICK_SIZE,
            Anchor::End,
            "",
            &label,
        );
    }
    let centre_x = 0.5 * (plot.x0 + plot.x1);
    let x_label_at = (
        centre_x,
        plot.y1 + TICK_LENGTH + TICK_SIZE + 10.0 + AXIS_LABEL_SIZE,
    );
    text_element(
        svg,
        &format!("p{index}-xlabel"),
        x_label_at,
        AXIS_LABEL_SIZE,
        Anchor::Middle,
        "",
        &panel.x_label,
    );
    let widest_tick = frame
        .y_ticks
        .values
        .iter()
        .map(|&v| {
            text_box(
                &frame.y_ticks.label(v),
                TICK_SIZE,
                (0.0, 0.0),
                Anchor::Start,
            )
            .width()
        })
        .fold(0.0, f64::max);
    let y_label_x = plot.x0 - TICK_LENGTH - 3.0 - widest_tick - 8.0;
    let y_label_y = 0.5 * (plot.y0 + plot.y1);
    let rotate = format!(r#" transform="rotate(-90 {y_label_x:.1} {y_label_y:.1})""#);
    text_element(
        svg,
        &format!("p{index}-ylabel"),
        (y_label_x, y_label_y),
        AXIS_LABEL_SIZE,
        Anchor::Middle,
        &rotate,
        &panel.y_label,
    );
    for (k, line) in panel.title.lines().enumerate() {
        let at = (
            centre_x,
            plot.y0 - 8.0 - TITLE_LINE * (panel.title.lines().count() - 1 - k) as f64,
        );
        text_element(
            svg,
            &format!("p{index}-title-{k}"),
            at,
            TITLE_SIZE,
            Anchor::Middle,
            "",
            line,
        );
    }
}

fn draw_curves(svg: &mut String, index: usize, drawn: &[Drawn]) {
    let mut k = 0;
    for series in drawn {
        for piece in &series.pieces {
            let mut points = String::with_capacity(piece.len() * 12);
            for (x, y) in piece {
                match series.stroke {
                    Stroke::Dots | Stroke::FineDots => {
                        let _ = write!(points, "M{x:.1} {y:.1}h0");
                    }
                    _ => {
                        let _ = write!(points, "{x:.1},{y:.1} ");
                    }
                }
            }
            let attributes = stroke_attributes(series.stroke);
            let stroke = colour(series.colour);
            let _ = match series.stroke {
                Stroke::Dots | Stroke::FineDots => writeln!(
                    svg,
                    r#"<path id="p{index}-curve-{k}" class="curve" d="{points}" fill="none" stroke="{stroke}" {attributes} clip-path="url(#clip-{index})"/>"#
                ),
                _ => writeln!(
                    svg,
                    r#"<polyline id="p{index}-curve-{k}" class="curve" points="{}" fill="none" stroke="{stroke}" {attributes} stroke-linejoin="round" clip-path="url(#clip-{index})"/>"#,
                    points.trim_end()
                ),
            };
            k += 1;
        }
    }
}

/// The grid cells, then the shaded polygons, clipped to the plot area (under the curves).
fn draw_background(svg: &mut String, index: usize, panel: &Panel, frame: &Frame) {
    for cell in &panel.cells {
        let corners = [cell.x.0, cell.x.1, cell.y.0, cell.y.1];
        if !corners.iter().all(|v| v.is_finite()) {
            continue;
        }
        let (x0, y0) = frame.to_pixel((cell.x.0, cell.y.1));
        let (x1, y1) = frame.to_pixel((cell.x.1, cell.y.0));
        let fill = match cell.colour {
            Some(c) => format!(r#"fill="{}" fill-opacity="{CELL_OPACITY}""#, colour(c)),
            None => GREY_CELL.to_string(),
        };
        let _ = writeln!(
            svg,
            r#"<rect class="cell" x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" {fill} clip-path="url(#clip-{index})"/>"#,
            x0.min(x1),
            y0.min(y1),
            (x1 - x0).abs(),
            (y1 - y0).abs()
        );
    }
    for polygon in &panel.shaded {
        let points: Vec<String> = polygon
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|&p| {
                let (x, y) = frame.to_pixel(p);
                format!("{x:.1},{y:.1}")
            })
            .collect();
        if points.len() >= 3 {
            let _ = writeln!(
                svg,
                r#"<polygon class="shaded" points="{}" {SHADE} clip-path="url(#clip-{index})"/>"#,
                points.join(" ")
            );
        }
    }
}

fn draw_regions(svg: &mut String, index: usize, regions: &[PlacedRegion]) {
    let fill = format!(r#" fill="{REGION_COLOUR}""#);
    for (k, region) in regions.iter().enumerate() {
        text_element(
            svg,
            &format!("p{index}-region-{k}"),
            region.baseline(),
            REGION_LABEL_SIZE,
            Anchor::Middle,
            &fill,
            &region.text,
        );
    }
}

fn draw_labels(svg: &mut String, index: usize, labels: &[PlacedLabel]) {
    for label in labels {
        if let Some((a, b)) = label.leader {
            let _ = writeln!(
                svg,
                r##"<line class="leader" x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#555" stroke-width="0.8"/>"##,
                a.0, a.1, b.0, b.1
            );
        }
        let _ = writeln!(
            svg,
            r#"<circle class="marker" cx="{:.1}" cy="{:.1}" r="{MARKER_RADIUS}" fill="black"/>"#,
            label.at.0, label.at.1
        );
    }
    for (k, label) in labels.iter().enumerate() {
        text_element(
            svg,
            &format!("p{index}-label-{k}"),
            label.baseline,
            MARKER_LABEL_SIZE,
            Anchor::Start,
            "",
            &label.text,
        );
    }
}

fn draw_legend(svg: &mut String, index: usize, entries: &[LegendEntry], at: Rect) {
    let _ = writeln!(
        svg,
        r#"<rect id="p{index}-legend" x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="white" stroke="black" stroke-width="0.8"/>"#,
        at.x0,
        at.y0,
        at.width(),
        at.height()
    );
    for (k, entry) in entries.iter().enumerate() {
        let y = at.y0 + LEGEND_PADDING + LEGEND_LINE * (k as f64 + 0.5);
        let x = at.x0 + LEGEND_PADDING;
        let attributes = stroke_attributes(entry.stroke);
        let stroke = colour(entry.colour);
        let _ = match entry.stroke {
            Stroke::Dots | Stroke::FineDots => writeln!(
                svg,
                r#"<path d="M{:.1} {y:.1}h0M{:.1} {y:.1}h0M{:.1} {y:.1}h0" stroke="{stroke}" {attributes}/>"#,
                x + 4.0,
                x + 0.5 * SWATCH,
                x + SWATCH - 4.0
            ),
            _ => writeln!(
                svg,
                r#"<line x1="{x:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{stroke}" {attributes}/>"#,
                x + SWATCH
            ),
        };
        let baseline = (x + SWATCH + 6.0, y + 0.35 * LEGEND_SIZE);
        text_element(
            svg,
            &format!("p{index}-legend-{k}"),
            baseline,
            LEGEND_SIZE,
            Anchor::Start,
            "",
            &entry.label,
        );
    }
}

/// Draw one panel into `outer`.
pub fn draw_panel(svg: &mut String, index: usize, panel: &Panel, outer: Rect) {
    let entries: Vec<LegendEntry> = panel
        .series
        .iter()
        .filter(|s| !s.label.is_empty())
        .map(|s| LegendEntry {
            label: s.label.clone(),
            colour: s.colour,
            stroke: s.stroke,
        })
        .collect();
    let (frame, drawn, legend) = frame_and_legend(panel, outer, &entries);
    let plot = frame.plot;
    let _ = writeln!(
        svg,
        r#"<clipPath id="clip-{index}"><rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}"/></clipPath>"#,
        plot.x0,
        plot.y0,
        plot.width(),
        plot.height()
    );
    draw_axes(svg, index, panel, &frame);
    draw_background(svg, index, panel, &frame);
    draw_curves(svg, index, &drawn);
    let markers: Vec<(String, Pixel)> = panel
        .markers
        .iter()
        .map(|m| (m.label.clone(), frame.to_pixel(m.at)))
        .collect();
    let boxes: Vec<Rect> = legend.into_iter().collect();
    let curve_segments = segments(&drawn);
    let labels = place_labels(
        &markers,
        Obstacles {
            bounds: plot,
            segments: &curve_segments,
            boxes: &boxes,
        },
    );
    draw_labels(svg, index, &labels);
    if !panel.regions.is_empty() {
        let names: Vec<(String, Vec<Pixel>)> = panel
            .regions
            .iter()
            .map(|r| {
                let anchors = r
                    .anchors
                    .iter()
                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                    .map(|&a| frame.to_pixel(a))
                    .collect();
                (r.label.clone(), anchors)
            })
            .collect();
        let mut taken = boxes.clone();
        let mut lines = curve_segments.clone();
        for label in &labels {
            taken.push(label.bounds);
            taken.push(Rect::new(
                label.at.0 - MARKER_RADIUS,
                label.at.1 - MARKER_RADIUS,
                2.0 * MARKER_RADIUS,
                2.0 * MARKER_RADIUS,
            ));
            lines.extend(label.leader);
        }
        let regions = place_regions(
            &names,
            Obstacles {
                bounds: plot,
                segments: &lines,
                boxes: &taken,
            },
        );
        draw_regions(svg, index, &regions);
    }
    if let Some(at) = legend {
        draw_legend(svg, index, &entries, at);
    }
}

/// The SVG document of `panels` laid out on a grid of `columns` columns, each panel
/// `panel_size` pixels.
pub fn document(panels: &[Panel], columns: usize, panel_size: (u32, u32)) -> String {
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns).max(1);
    let (w, h) = (f64::from(panel_size.0), f64::from(panel_size.1));
    let (width, height) = (w * columns as f64, h * rows as f64);
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="{FONT_FAMILY}, sans-serif">"#
    );
    let _ = writeln!(
        svg,
        r#"<rect width="{width}" height="{height}" fill="white"/>"#
    );
    for (index, panel) in panels.iter().enumerate() {
        let outer = Rect::new(
            w * (index % columns) as f64,
            h * (index / columns) as f64,
            w,
            h,
        );
        let _ = writeln!(svg, r#"<g id="panel-{index}">"#);
        draw_panel(&mut svg, index, panel, outer);
        let _ = writeln!(svg, "</g>");
    }
    svg.push_str("</svg>\n");
    svg
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::Series;

    #[test]
    fn a_legend_with_no_free_corner_goes_outside_the_plot_area() {
        // Both diagonals of the data range pass through all four corners of the plot area.
        let diagonal = |points: Vec<(f64, f64)>, label: &str, colour| Series {
            label: label.to_string(),
            points,
            stroke: Stroke::Solid,
            colour,
        };
        let panel = Panel {
            series: vec![
                diagonal(vec![(0.0, 0.0), (1.0, 1.0)], "rising", 0),
                diagonal(vec![(0.0, 1.0), (1.0, 0.0)], "falling", 1),
            ],
            ..Panel::default()
        };
        let entries: Vec<LegendEntry> = panel
            .series
            .iter()
            .map(|s| LegendEntry {
                label: s.label.clone(),
                colour: s.colour,
                stroke: s.stroke,
            })
            .collect();
        let outer = Rect::new(0.0, 0.0, 500.0, 400.0);
        let (frame, _, legend) = frame_and_legend(&panel, outer, &entries);
        let legend = legend.expect("a legend");
        assert!(
            legend.x0 > frame.plot.x1,
            "{legend:?} beside {:?}",
            frame.plot
        );
        assert!(outer.contains_rect(&legend), "inside the panel");
        // With one diagonal only, two corners stay free and the legend goes inside.
        let one = Panel {
            series: panel.series[..1].to_vec(),
            ..Panel::default()
        };
        let (frame, _, legend) = frame_and_legend(&one, outer, &entries[..1]);
        assert!(frame.plot.contains_rect(&legend.expect("a legend")));
    }
}
