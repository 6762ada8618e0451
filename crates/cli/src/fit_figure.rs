//! The figure of `drumroll fit --plot`: the measured curve, the fitted branch, the detected
//! transitions and the fitted `G_n`, against `A/A0` and against `Z` (data coordinates), with
//! the residuals in units of the noise (MODEL.md section 13).

use afm::fit::least_squares::FitResult;
use afm::fit::transitions::Transition;

use crate::plot::{Marker, Panel, Series, Stroke};

/// A panel with the defaults of this figure.
fn panel(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: Vec<Series>,
    markers: Vec<Marker>,
) -> Panel {
    Panel {
        title: title.to_string(),
        x_label: x_label.to_string(),
        y_label: y_label.to_string(),
        series,
        markers,
        y_period: None,
        y_integer_ticks: false,
        regions: Vec::new(),
        shaded: Vec::new(),
        cells: Vec::new(),
    }
}

/// The four panels: phase vs `A/A0`, `A/A0` vs `Z`, phase vs `Z`, residuals over their noise
/// vs `Z`. Data as dots, the fitted model as a line; transitions marked `T1, T2, ...`, the
/// fitted grazing points by their labels.
pub fn fit_panels(
    case: &str,
    a0_nm: f64,
    result: &FitResult,
    transitions: &[Transition],
) -> Vec<Panel> {
    let points = &result.points;
    let data = |f: &dyn Fn(&afm::fit::least_squares::FittedPoint) -> (f64, f64)| Series {
        label: String::from("measured"),
        points: points.iter().map(f).collect(),
        stroke: Stroke::Dots,
        colour: 0,
    };
    let model = |f: &dyn Fn(&afm::fit::least_squares::FittedPoint) -> (f64, f64)| Series {
        label: String::from("fitted model"),
        points: points.iter().map(f).collect(),
        stroke: Stroke::Solid,
        colour: 1,
    };
    let z_range = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.z_nm), hi.max(p.z_nm))
        });
    let in_range = |z: f64| z >= z_range.0 && z <= z_range.1;
    let markers = |f: &dyn Fn(f64, f64, f64) -> (f64, f64)| {
        let mut markers: Vec<Marker> = transitions
            .iter()
            .enumerate()
            .map(|(i, t)| Marker {
                label: format!("T{}", i + 1),
                at: f(t.z_nm, t.amplitude_ratio, t.phase_deg),
            })
            .collect();
        markers.extend(
            result
                .grazing
                .iter()
                .filter(|g| g.label.starts_with('G') && in_range(g.z_nm))
                .map(|g| Marker {
                    label: g.label.clone(),
                    at: f(g.z_nm, g.amplitude_ratio, g.phase_deg),
                }),
        );
        markers
    };
    let sigma = result.noise;
    vec![
        panel(
            &format!("{case}: phase vs amplitude ratio"),
            "amplitude ratio A/A0",
            "phase (deg)",
            vec![
                data(&|p| (p.amplitude_nm / a0_nm, p.phase_deg)),
                model(&|p| (p.model_amplitude_nm / a0_nm, p.model_phase_deg)),
            ],
            markers(&|_, r, phi| (r, phi)),
        ),
        panel(
            "amplitude ratio vs Z (data coordinates)",
            "piezo Z (nm)",
            "amplitude ratio A/A0",
            vec![
                data(&|p| (p.z_nm, p.amplitude_nm / a0_nm)),
                model(&|p| (p.z_nm, p.model_amplitude_nm / a0_nm)),
            ],
            markers(&|z, r, _| (z, r)),
        ),
        panel(
            "phase vs Z (data coordinates)",
            "piezo Z (nm)",
            "phase (deg)",
            vec![
                data(&|p| (p.z_nm, p.phase_deg)),
                model(&|p| (p.z_nm, p.model_phase_deg)),
            ],
            markers(&|z, _, phi| (z, phi)),
        ),
        panel(
            "residuals / noise vs Z",
            "piezo Z (nm)",
            "residual / sigma",
            vec![
                Series {
                    label: String::from("amplitude"),
                    points: points
                        .iter()
                        .map(|p| (p.z_nm, (p.amplitude_nm - p.model_amplitude_nm) / sigma[0]))
                        .collect(),
                    stroke: Stroke::Dots,
                    colour: 0,
                },
                Series {
                    label: String::from("phase"),
                    points: points
                        .iter()
                        .map(|p| (p.z_nm, (p.phase_deg - p.model_phase_deg) / sigma[1]))
                        .collect(),
                    stroke: Stroke::FineDots,
                    colour: 2,
                },
            ],
            Vec::new(),
        ),
    ]
}
