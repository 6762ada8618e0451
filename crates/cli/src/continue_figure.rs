//! The figure of `drumroll continue --plot`: for one case, phase vs A/A0 (the paper's Fig. 2)
//! beside A/A0 vs Z and impacts per period vs Z; for several cases, one phase panel per case,
//! (a), (b), ..., on a grid of two columns (the paper's Fig. 2 layout), or with `--overlay`
//! the three panels with every case on the same axes. Stable parts are solid, unstable
//! dashed; a retract branch is drawn over the approach dash-dotted (dotted where unstable).
//! Quantities and labels: MODEL.md (amplitude ratio, phase lag, impacts, special points).

use afm::{BifurcationDiagram, Case, DiagramPoint, DiagramSpecialPoint, Harmonic, TappingModel};
use anyhow::{bail, Result};

use crate::plot::{render_svg, Marker, Panel, Series, Stroke, PHASE_PERIOD_DEG};

/// One case's diagrams, as computed by `drumroll continue`.
#[derive(Debug, Clone)]
pub struct CaseDiagrams {
    /// The case.
    pub case: Case,
    /// Its model (for A0 and the drive).
    pub model: TappingModel,
    /// The approach branch.
    pub approach: BifurcationDiagram,
    /// The retract branch, when asked for.
    pub retract: Option<BifurcationDiagram>,
}

/// Size of one panel, pixels.
const PANEL_SIZE: (u32, u32) = (600, 460);
/// Columns of the grid of several cases.
const GRID_COLUMNS: usize = 2;

/// The SVG figure of `cases` (one or more); `overlay` draws several cases on shared axes.
pub fn figure(cases: &[CaseDiagrams], overlay: bool) -> Result<String> {
    let panels = if cases.len() == 1 || overlay {
        shared_panels(cases)
    } else {
        cases
            .iter()
            .enumerate()
            .map(|(i, c)| case_panel(i, c))
            .collect()
    };
    let columns = if cases.len() == 1 || overlay {
        3
    } else {
        GRID_COLUMNS
    };
    let rows = panels.len().div_ceil(columns);
    render_svg(&panels, rows, columns, PANEL_SIZE)
}

/// The case's name and key parameters on two title lines, after the panel's letter (if any).
fn case_title(letter: Option<usize>, c: &CaseDiagrams) -> String {
    let prefix = letter.map_or(String::new(), |i| {
        format!("({}) ", char::from(b'a' + (i % 26) as u8))
    });
    let mode = c.case.cantilever.modes.first();
    format!(
        "{prefix}{}: A0 = {} nm, drive {:.3} kHz\n{} k1 = {} N/m, Q1 = {}, R = {} nm; {} E = {} GPa",
        c.case.name,
        c.model.free_amplitude_nm(),
        c.case.drive_frequency_or_fundamental_khz(),
        c.case.cantilever.name,
        mode.map_or(f64::NAN, |m| m.stiffness_n_per_m),
        mode.map_or(f64::NAN, |m| m.quality_factor),
        c.case.cantilever.tip_radius_nm,
        c.case.sample.name,
        c.case.sample.youngs_modulus_gpa,
    )
}

/// Runs of equal stability of a diagram's points, as polylines of `(x, y)`, each joined to
/// the previous run so the curve stays continuous.
fn runs(
    points: &[DiagramPoint],
    xy: impl Fn(&DiagramPoint) -> (f64, f64),
) -> Vec<(bool, Vec<(f64, f64)>)> {
    let mut runs: Vec<(bool, Vec<(f64, f64)>)> = Vec::new();
    for p in points {
        match runs.last_mut() {
            Some((stable, line)) if *stable == p.stable => line.push(xy(p)),
            Some((_, line)) => {
                let last = *line.last().unwrap_or(&xy(p));
                runs.push((p.stable, vec![last, xy(p)]));
            }
            None => runs.push((p.stable, vec![xy(p)])),
        }
    }
    runs
}

/// Which branch a series belongs to: its name in the legend, colour and line styles.
#[derive(Debug, Clone, Copy)]
struct Branch<'a> {
    name: &'a str,
    colour: usize,
    stable: Stroke,
    unstable: Stroke,
}

/// The series of one branch; the first stable and the first unstable run carry the legend
/// entries `name` and `name, unstable`.
fn branch_series(
    diagram: &BifurcationDiagram,
    branch: Branch<'_>,
    xy: impl Fn(&DiagramPoint) -> (f64, f64),
) -> Vec<Series> {
    let (mut stable_named, mut unstable_named) = (false, false);
    runs(&diagram.points, xy)
        .into_iter()
        .map(|(stable, points)| {
            let named = if stable {
                &mut stable_named
            } else {
                &mut unstable_named
            };
            let label = if *named {
                String::new()
            } else if stable {
                branch.name.to_string()
            } else {
                format!("{}, unstable", branch.name)
            };
            *named = true;
            Series {
                label,
                points,
                stroke: if stable {
                    branch.stable
                } else {
                    branch.unstable
                },
                colour: branch.colour,
            }
        })
        .collect()
}

/// Every branch of `cases` as series of `xy`: approach solid/dashed, retract dash-dot/dotted.
/// One case: approach and retract in two colours, each style in the legend. Several: one
/// colour per case, the legend naming each case once, then a key of the line styles in black.
fn all_series(
    cases: &[CaseDiagrams],
    xy: impl Fn(&DiagramPoint) -> (f64, f64) + Copy,
) -> Vec<Series> {
    if let [one] = cases {
        let mut series = branch_series(&one.approach, APPROACH, xy);
        if let Some(retract) = &one.retract {
            series.extend(branch_series(retract, RETRACT, xy));
        }
        return series;
    }
    let mut series = Vec::new();
    for (i, c) in cases.iter().enumerate() {
        let mut approach = branch_series(
            &c.approach,
            Branch {
                colour: i,
                ..APPROACH
            },
            xy,
        );
        for s in &mut approach {
            s.label = String::new();
        }
        if let Some(first) = approach.first_mut() {
            first.label = c.case.name.clone();
        }
        series.extend(approach);
        if let Some(retract) = &c.retract {
            series.extend(
                branch_series(
                    retract,
                    Branch {
                        colour: i,
                        ..RETRACT
                    },
                    xy,
                )
                .into_iter()
                .map(|s| Series {
                    label: String::new(),
                    ..s
                }),
            );
        }
    }
    let unstable = series.iter().any(|s| s.stroke == Stroke::Dashed);
    let retract = cases.iter().any(|c| c.retract.is_some());
    let key = |label: &str, stroke: Stroke| Series {
        label: label.to_string(),
        points: Vec::new(),
        stroke,
        colour: KEY_COLOUR,
    };
    let mut keys = Vec::new();
    if unstable {
        keys.push(key("unstable", Stroke::Dashed));
    }
    if retract {
        keys.push(key("retract", Stroke::DashDot));
    }
    series.extend(keys);
    series
}

/// The approach branch of one case: first colour, solid where stable, dashed where unstable.
const APPROACH: Branch<'static> = Branch {
    name: "approach",
    colour: 0,
    stable: Stroke::Solid,
    unstable: Stroke::Dashed,
};

/// The retract branch of one case: second colour, dash-dot where stable, dotted where unstable.
const RETRACT: Branch<'static> = Branch {
    name: "retract",
    colour: 1,
    stable: Stroke::DashDot,
    unstable: Stroke::Dotted,
};

/// The palette index of the line-style key (black).
const KEY_COLOUR: usize = crate::plot::svg::KEY_COLOUR;

/// The special points of the approach branches, at `xy`.
fn markers(
    cases: &[CaseDiagrams],
    xy: impl Fn(&afm::DiagramSpecialPoint) -> (f64, f64),
) -> Vec<Marker> {
    cases
        .iter()
        .flat_map(|c| c.approach.special_points.iter())
        .map(|p| Marker {
            label: p.label.clone(),
            at: xy(p),
        })
        .collect()
}

/// Phase vs A/A0, A/A0 vs Z and impacts per period vs Z, every case on each.
fn shared_panels(cases: &[CaseDiagrams]) -> Vec<Panel> {
    let (phase_title, ratio_title) = match cases {
        [one] => {
            let title = case_title(None, one);
            let (line1, line2) = title.split_once('\n').unwrap_or((&title, ""));
            (
                format!("phase vs A/A0\n{line1}"),
                format!("A/A0 vs Z\n{line2}"),
            )
        }
        _ => (String::from("phase vs A/A0"), String::from("A/A0 vs Z")),
    };
    vec![
        Panel {
            title: phase_title,
            x_label: String::from("amplitude ratio A/A0"),
            y_label: String::from("phase (deg)"),
            series: all_series(cases, |p| (p.amplitude_ratio, p.phase_deg)),
            markers: markers(cases, |p| (p.amplitude_ratio, p.phase_deg)),
            y_period: Some(PHASE_PERIOD_DEG),
            y_integer_ticks: false,
            ..Panel::default()
        },
        Panel {
            title: ratio_title,
            x_label: String::from("separation Z (nm)"),
            y_label: String::from("amplitude ratio A/A0"),
            series: all_series(cases, |p| (p.z_nm, p.amplitude_ratio)),
            markers: markers(cases, |p| (p.z_nm, p.amplitude_ratio)),
            y_period: None,
            y_integer_ticks: false,
            ..Panel::default()
        },
        Panel {
            title: String::from("impacts per period vs Z"),
            x_label: String::from("separation Z (nm)"),
            y_label: String::from("impacts per period"),
            series: all_series(cases, |p| (p.z_nm, p.impacts_per_period)),
            markers: Vec::new(),
            y_period: None,
            y_integer_ticks: true,
            ..Panel::default()
        },
    ]
}

/// The paper's Fig. 2 panel of case number `index`: phase vs A/A0, special points labelled.
fn case_panel(index: usize, c: &CaseDiagrams) -> Panel {
    let one = std::slice::from_ref(c);
    Panel {
        title: case_title(Some(index), c),
        x_label: String::from("amplitude ratio A/A0"),
        y_label: String::from("phase (deg)"),
        series: all_series(one, |p| (p.amplitude_ratio, p.phase_deg)),
        markers: markers(one, |p| (p.amplitude_ratio, p.phase_deg)),
        y_period: Some(PHASE_PERIOD_DEG),
        y_integer_ticks: false,
        ..Panel::default()
    }
}

/// A quantity `continue --plot --panels` draws against `A/A0` (MODEL.md sections 4 and 10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PanelQuantity {
    /// The phase lag `Phi`, degrees.
    Phase,
    /// The energy dissipated in the sample per drive period, eV.
    Dissipated,
    /// The virial, eV.
    Virial,
    /// The largest indentation, nm.
    MaxIndentation,
    /// The mean indentation over the time in contact, nm.
    MeanIndentation,
    /// The amplitude of harmonic `n` of `u`, nm.
    Harmonic(usize),
}

/// The names `--panels` takes, for its help and errors.
pub const PANEL_NAMES: &str =
    "phase, dissipated, virial, max-indentation, mean-indentation, harmonic-N (N >= 1)";

impl PanelQuantity {
    /// Parse the comma-separated `--panels` list (`phase,dissipated,harmonic-2`); an error names
    /// the unknown entry and the allowed ones.
    pub fn parse_list(list: &str) -> Result<Vec<Self>> {
        let mut quantities = Vec::new();
        for word in list.split(',').map(str::trim) {
            let quantity = match word {
                "phase" => Self::Phase,
                "dissipated" => Self::Dissipated,
                "virial" => Self::Virial,
                "max-indentation" => Self::MaxIndentation,
                "mean-indentation" => Self::MeanIndentation,
                _ => match word
                    .strip_prefix("harmonic-")
                    .and_then(|n| n.parse::<usize>().ok())
                {
                    Some(n) if (1..=1000).contains(&n) => Self::Harmonic(n),
                    _ => bail!(
                        "--panels: `{word}` is not a panel; the panels are {PANEL_NAMES} (N in [1, 1000]), comma-separated"
                    ),
                },
            };
            quantities.push(quantity);
        }
        Ok(quantities)
    }

    /// The highest harmonic the panels need (0 for none).
    pub fn highest_harmonic(quantities: &[Self]) -> usize {
        quantities
            .iter()
            .map(|q| match q {
                Self::Harmonic(n) => *n,
                _ => 0,
            })
            .max()
            .unwrap_or(0)
    }

    /// The axis label, with units.
    fn label(self) -> String {
        match self {
            Self::Phase => String::from("phase (deg)"),
            Self::Dissipated => String::from("dissipated energy E_ts (eV per period)"),
            Self::Virial => String::from("virial V_ts (eV)"),
            Self::MaxIndentation => String::from("max indentation (nm)"),
            Self::MeanIndentation => String::from("mean indentation (nm)"),
            Self::Harmonic(n) => format!("harmonic {n} amplitude |U_{n}| (nm)"),
        }
    }

    /// Its value at a branch point.
    fn of_point(self, p: &DiagramPoint) -> f64 {
        self.value(
            p.phase_deg,
            [
                p.dissipated_ev,
                p.virial_ev,
                p.max_indentation_nm,
                p.mean_indentation_nm,
            ],
            &p.harmonics,
        )
    }

    /// Its value at a special point.
    fn of_special(self, p: &DiagramSpecialPoint) -> f64 {
        self.value(
            p.phase_deg,
            [
                p.dissipated_ev,
                p.virial_ev,
                p.max_indentation_nm,
                p.mean_indentation_nm,
            ],
            &p.harmonics,
        )
    }

    fn value(
        self,
        phase: f64,
        [dissipated, virial, max, mean]: [f64; 4],
        harmonics: &[Harmonic],
    ) -> f64 {
        match self {
            Self::Phase => phase,
            Self::Dissipated => dissipated,
            Self::Virial => virial,
            Self::MaxIndentation => max,
            Self::MeanIndentation => mean,
            Self::Harmonic(n) => harmonics.get(n - 1).map_or(f64::NAN, |h| h.amplitude_nm),
        }
    }
}

/// Size of one panel of the `--panels` column, pixels.
const CONTRAST_PANEL_SIZE: (u32, u32) = (700, 300);

/// The figure of `continue --plot --panels`: the chosen quantities against `A/A0`, one panel
/// each, stacked in one column on the same `A/A0` axis, every case's special points (`G_n`,
/// folds, ...) marked on each.
pub fn contrast_figure(cases: &[CaseDiagrams], quantities: &[PanelQuantity]) -> Result<String> {
    let title = match cases {
        [one] => case_title(None, one),
        _ => String::new(),
    };
    let panels: Vec<Panel> = quantities
        .iter()
        .enumerate()
        .map(|(i, &quantity)| Panel {
            title: if i == 0 { title.clone() } else { String::new() },
            x_label: String::from("amplitude ratio A/A0"),
            y_label: quantity.label(),
            series: all_series(cases, move |p| (p.amplitude_ratio, quantity.of_point(p))),
            markers: markers(cases, move |p| (p.amplitude_ratio, quantity.of_special(p))),
            y_period: (quantity == PanelQuantity::Phase).then_some(PHASE_PERIOD_DEG),
            y_integer_ticks: false,
            ..Panel::default()
        })
        .collect();
    render_svg(&panels, panels.len(), 1, CONTRAST_PANEL_SIZE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panel_lists_parse_and_bad_entries_name_the_allowed_ones() {
        assert_eq!(
            PanelQuantity::parse_list("phase,dissipated,harmonic-2").expect("valid"),
            vec![
                PanelQuantity::Phase,
                PanelQuantity::Dissipated,
                PanelQuantity::Harmonic(2)
            ]
        );
        assert_eq!(
            PanelQuantity::highest_harmonic(&[PanelQuantity::Harmonic(7), PanelQuantity::Phase]),
            7
        );
        for bad in ["phase,amplitude", "harmonic-0", "harmonic-x", ""] {
            let error = PanelQuantity::parse_list(bad).expect_err(bad).to_string();
            assert!(
                error.contains("--panels") && error.contains("dissipated"),
                "{error}"
            );
        }
    }
}
