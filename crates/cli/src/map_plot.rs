//! The figure of `drumroll map`: the regime map in the `(p, Z)` and `(p, A/A0)` planes, curves
//! labelled (stable parts solid, unstable dashed), the regions between consecutive grazing
//! curves named by their impacts per period, the area inside the fold curves (two stable
//! orbits: bistable) shaded, and codimension-two points marked; under them, optionally, the
//! cells of a brute-force grid coloured by impacts per period (grey: bistable).

use afm::{MapCurve, MapPoint, ParameterAxis, RegimeMap};

use crate::grid_overlay::{grid_cells, Grid, GridCell};
use crate::plot::{Marker, Panel, Region, Series, Stroke};

/// The vertical coordinate of a panel, read from a curve point.
type Ordinate = fn(&MapPoint) -> f64;
/// The same coordinate read from a grid cell.
type GridOrdinate = fn(&GridCell) -> f64;

/// The figure's two panels, with the cells of a brute-force `grid` under the curves if given.
pub fn map_panels(axis: ParameterAxis, map: &RegimeMap, grid: Option<&Grid>) -> Vec<Panel> {
    let unit = axis.unit();
    let x_label = if unit.is_empty() {
        axis.name()
    } else {
        format!("{} ({unit})", axis.name())
    };
    let planes: [(&str, &str, Ordinate, GridOrdinate); 2] = [
        (
            "Z (nm)",
            "regime map in (parameter, Z)",
            |p| p.z_nm,
            |c| c.z_nm,
        ),
        (
            "A/A0",
            "regime map in (parameter, A/A0)",
            |p| p.amplitude_ratio,
            |c| c.amplitude_ratio,
        ),
    ];
    planes
        .iter()
        .map(|(y_label, title, y, grid_y)| Panel {
            title: format!("{title} (dashed: unstable; shaded: bistable)"),
            x_label: x_label.clone(),
            y_label: y_label.to_string(),
            series: map
                .curves
                .iter()
                .enumerate()
                .flat_map(|(i, c)| curve_series(c, i, *y))
                .collect(),
            markers: map
                .codim2_points
                .iter()
                .filter_map(|c| {
                    let value = if *y_label == "Z (nm)" {
                        c.z_nm
                    } else {
                        c.amplitude_ratio
                    };
                    value.is_finite().then(|| Marker {
                        label: c.label.clone(),
                        at: (c.parameter, value),
                    })
                })
                .collect(),
            y_period: None,
            y_integer_ticks: false,
            regions: region_labels(&map.curves, *y),
            shaded: bistable_polygons(&map.curves, *y),
            cells: grid.map_or_else(Vec::new, |g| grid_cells(g, *grid_y)),
        })
        .collect()
}

/// A curve cut into runs of equal stability (joined at the changes).
fn curve_series(curve: &MapCurve, colour: usize, y: fn(&MapPoint) -> f64) -> Vec<Series> {
    let mut runs: Vec<(bool, Vec<(f64, f64)>)> = Vec::new();
    for p in &curve.points {
        let xy = (p.parameter, y(p));
        match runs.last_mut() {
            Some((stable, line)) if *stable == p.stable => line.push(xy),
            Some((_, line)) => {
                let last = *line.last().unwrap_or(&xy);
                runs.push((p.stable, vec![last, xy]));
            }
            None => runs.push((p.stable, vec![xy])),
        }
    }
    runs.into_iter()
        .enumerate()
        .map(|(i, (stable, points))| Series {
            label: if i == 0 {
                curve.label.clone()
            } else {
                String::new()
            },
            points,
            stroke: if stable {
                Stroke::Solid
            } else {
                Stroke::Dashed
            },
            colour,
        })
        .collect()
}

/// The value of `y` on `curve` at the point nearest the parameter `x`, when the curve
/// reaches `x` (its parameter range holds it).
fn value_near(curve: &MapCurve, x: f64, y: fn(&MapPoint) -> f64) -> Option<f64> {
    let (low, high) = curve
        .points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.parameter), h.max(p.parameter))
        });
    if !(low <= x && x <= high) {
        return None;
    }
    curve
        .points
        .iter()
        .min_by(|a, b| (a.parameter - x).abs().total_cmp(&(b.parameter - x).abs()))
        .map(y)
}

/// Where region names are tried along the parameter range, in fractions of it, preferred
/// first.
const REGION_FRACTIONS: [f64; 9] = [0.5, 0.35, 0.65, 0.2, 0.8, 0.1, 0.9, 0.03, 0.97];

/// `1 impact`, `2 impacts`, ... between consecutive grazing curves `G_n`, `G_{n+1}` (below
/// `G_n` on approach the orbit has `n` impacts per period), `no impact` above `G1`; each
/// anchored midway between its two curves (or a little beyond the first and last curve) at
/// several parameter values, the middle of the range first.
fn region_labels(curves: &[MapCurve], y: fn(&MapPoint) -> f64) -> Vec<Region> {
    let mut grazing: Vec<(usize, &MapCurve)> = curves
        .iter()
        .filter_map(|c| Some((c.label.strip_prefix('G')?.parse().ok()?, c)))
        .collect();
    grazing.sort_by_key(|(n, _)| *n);
    let (low, high) = curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.parameter))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
    if grazing.is_empty() || !low.is_finite() {
        return Vec::new();
    }
    let xs: Vec<f64> = REGION_FRACTIONS
        .iter()
        .map(|f| low + f * (high - low))
        .collect();
    let values: Vec<Vec<Option<f64>>> = grazing
        .iter()
        .map(|(_, c)| xs.iter().map(|&x| value_near(c, x, y)).collect())
        .collect();
    let all = values.iter().flatten().flatten();
    let span = all.clone().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
        - all.fold(f64::INFINITY, |a, &b| a.min(b));
    let offset = 0.08 * span.max(1e-9);
    let name = |n: usize| match n {
        0 => String::from("no impact"),
        1 => String::from("1 impact"),
        _ => format!("{n} impacts"),
    };
    let anchors = |at: &dyn Fn(usize) -> Option<f64>| -> Vec<(f64, f64)> {
        xs.iter()
            .enumerate()
            .filter_map(|(i, &x)| Some((x, at(i)?)))
            .collect()
    };
    let count = grazing.len();
    let mut regions = vec![Region {
        label: name(grazing[0].0 - 1),
        anchors: anchors(&|i| Some(values[0][i]? + offset)),
    }];
    for k in 0..count - 1 {
        regions.push(Region {
            label: name(grazing[k].0),
            anchors: anchors(&|i| Some(0.5 * (values[k][i]? + values[k + 1][i]?))),
        });
    }
    regions.push(Region {
        label: name(grazing[count - 1].0),
        anchors: anchors(&|i| Some(values[count - 1][i]? - offset)),
    });
    regions
}

/// The bistable area: inside the fold curves (between the first two fold curves, or inside a
/// single fold curve that turns at a cusp).
fn bistable_polygons(curves: &[MapCurve], y: fn(&MapPoint) -> f64) -> Vec<Vec<(f64, f64)>> {
    let folds: Vec<&MapCurve> = curves.iter().filter(|c| c.label == "fold").collect();
    let line = |c: &MapCurve| -> Vec<(f64, f64)> {
        c.points.iter().map(|p| (p.parameter, y(p))).collect()
    };
    match folds.as_slice() {
        [] => Vec::new(),
        [single] => vec![line(single)],
        [first, second, ..] => {
            let mut polygon = line(first);
            let mut back = line(second);
            back.reverse();
            polygon.extend(back);
            vec![polygon]
        }
    }
}
