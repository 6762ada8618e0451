//! The figure of `drumroll scan --plot`: aligned profiles over `x` (MODEL.md section 12):
//! true and measured height, phase, impacts per period (integer ticks) and peak force, trace
//! and retrace in two colours.

use afm::scan::pixel::{ScanDirection, ScanPixel};

use crate::plot::{Panel, Series, Stroke, PHASE_PERIOD_DEG};

/// The four panels of the profiles of `pixels` along the line `line`.
pub fn scan_panels(line: &str, pixels: &[ScanPixel]) -> Vec<Panel> {
    let pass = |direction: ScanDirection, value: fn(&ScanPixel) -> f64| -> Vec<(f64, f64)> {
        let mut points: Vec<(f64, f64)> = pixels
            .iter()
            .filter(|p| p.direction == direction)
            .map(|p| (p.x_nm, value(p)))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        points
    };
    let passes = |value: fn(&ScanPixel) -> f64, first_colour: usize| -> Vec<Series> {
        [
            (ScanDirection::Trace, Stroke::Solid, first_colour),
            (ScanDirection::Retrace, Stroke::Dashed, first_colour + 1),
        ]
        .into_iter()
        .map(|(direction, stroke, colour)| Series {
            label: direction.name().to_string(),
            points: pass(direction, value),
            stroke,
            colour,
        })
        .filter(|series| !series.points.is_empty())
        .collect()
    };
    let panel = |title: &str, y_label: &str, series: Vec<Series>| Panel {
        title: format!("{line}: {title}"),
        x_label: String::from("x (nm)"),
        y_label: y_label.to_string(),
        series,
        ..Panel::default()
    };
    let mut heights = vec![Series {
        label: String::from("true"),
        points: pass(
            pixels.first().map_or(ScanDirection::Trace, |p| p.direction),
            |p| p.height_true_nm,
        ),
        stroke: Stroke::Dotted,
        colour: 2,
    }];
    heights.extend(passes(|p| p.height_nm, 0));
    let mut phase = panel("phase", "phase (deg)", passes(|p| p.phase_deg, 0));
    phase.y_period = Some(PHASE_PERIOD_DEG);
    let mut impacts = panel(
        "impacts per period",
        "impacts per period",
        passes(|p| p.impacts_per_period, 0),
    );
    impacts.y_integer_ticks = true;
    vec![
        panel("true and measured height", "height (nm)", heights),
        phase,
        impacts,
        panel(
            "peak force",
            "peak force (nN)",
            passes(|p| p.peak_force_nn, 0),
        ),
    ]
}
