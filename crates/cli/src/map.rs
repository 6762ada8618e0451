//! `drumroll map`: the impact-regime map of a case over a second parameter: the grazing `G_n`,
//! fold and period-doubling points of the approach diagram continued from the case's own value
//! over a range (`afm::map::regime_map`), as curves in the `(p, Z)` and `(p, A/A0)` planes.

use afm::map::regime_map::regime_map_until;
use afm::{
    Case, MapCodim2Point, MapCurve, ParameterAxis, RegimeMap, RegimeMapSettings, TappingModel,
};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;

use crate::continue_diagram::approach_settings;
use crate::grid_overlay::{read_grid, Grid};
use crate::inputs::orbit_inputs_json;
use crate::map_plot::map_panels;
use crate::model_args::{output_path, ModelArgs};
use crate::option_ranges;
use crate::output::write_atomically;
use crate::output::{harmonic_columns, print_stdout, push_csv_row, push_harmonic_cells};
use crate::plot::{render_svg, FigureFile};

/// Options of `drumroll map`.
#[derive(Debug, Clone, Args)]
pub struct MapArgs {
    /// The cantilever, sample and drive (the case's own value of PARAM is where the curves
    /// start).
    #[command(flatten)]
    pub model: ModelArgs,
    /// The parameter varied along the map: a0 (nm), drive-frequency (kHz), sample-modulus
    /// (GPa), tip-radius (nm), quality-factor-N, stiffness-N (N/m) for mode N.
    #[arg(long, value_name = "PARAM")]
    pub vary: String,
    /// One end of the range of PARAM (its unit).
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// The other end of the range (greater than --from).
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Values of PARAM at which every curve spanning them gets a point computed exactly,
    /// comma-separated.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub at: Vec<f64>,
    /// The curves to compute, comma-separated labels as `continue` names its special points
    /// (`G2,G3,fold,period-doubling`); default every G_n, fold and period doubling.
    #[arg(long, value_delimiter = ',')]
    pub labels: Vec<String>,
    /// Points per curve over the whole range, at least (sets the largest step in PARAM).
    #[arg(long, default_value_t = 100)]
    pub points: usize,
    /// Lowest separation of the seed approach and of every curve, nm (default 0.05 A0).
    #[arg(long, allow_negative_numbers = true)]
    pub floor: Option<f64>,
    /// The seed approach also stops when A/A0 falls below this ratio (default 0.3).
    #[arg(long, default_value_t = 0.3)]
    pub min_amplitude_ratio: f64,
    /// Largest arclength step of the seed approach, nm (default A0/250).
    #[arg(long)]
    pub max_step: Option<f64>,
    /// The harmonics n = 1..N of u reported at every curve point, N in [1, 1000].
    #[arg(long, default_value_t = crate::approach::DEFAULT_HARMONICS, allow_negative_numbers = true)]
    pub harmonics: i64,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Write the curve points to this CSV file (one row per point).
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,
    /// Write the codimension-two points to this CSV file (one row per point, with the
    /// observables of the orbit there).
    #[arg(long, value_name = "FILE.csv")]
    pub codim2_csv: Option<PathBuf>,
    /// Draw the map in the (PARAM, Z) and (PARAM, A/A0) planes; the format follows the
    /// extension (.svg, .png or .pdf).
    #[arg(long, value_name = "FILE.svg|.png|.pdf")]
    pub plot: Option<PathBuf>,
    /// With --plot: draw this `drumroll grid` result (JSON Lines, the same PARAM) as cells
    /// under the curves, coloured by impacts per period (grey: bistable).
    #[arg(long, value_name = "FILE.jsonl", requires = "plot")]
    pub grid_file: Option<PathBuf>,
}

/// The labels `--labels` accepts: `G<n>` (n >= 1), `fold`, `period-doubling`.
fn valid_label(label: &str) -> bool {
    label == "fold"
        || label == "period-doubling"
        || (label.len() > 1
            && label.starts_with('G')
            && label[1..].parse::<usize>().is_ok_and(|n| n >= 1))
}

/// Run `drumroll map`.
pub fn run(args: &MapArgs) -> Result<()> {
    let (case, model) = args.model.model()?;
    let csv_path = args
        .csv
        .as_ref()
        .map(|p| output_path(p, "csv", "--csv"))
        .transpose()?;
    let codim2_csv_path = args
        .codim2_csv
        .as_ref()
        .map(|p| output_path(p, "csv", "--codim2-csv"))
        .transpose()?;
    let plot_path = args
        .plot
        .as_ref()
        .map(|p| FigureFile::new(p, "--plot"))
        .transpose()?;
    let axis = ParameterAxis::parse(&args.vary, case.cantilever.modes.len())?;
    let grid = args
        .grid_file
        .as_ref()
        .map(|path| read_grid(path, &axis.name()))
        .transpose()?;
    let settings = map_settings(args, &model)?;
    let map = compute_map(&case, axis, &settings)?;
    if args.json {
        let object = map_json(args, &case, &model, axis, &settings, &map);
        print_stdout(&format!("{}\n", serde_json::to_string(&object)?))?;
    } else {
        print_stdout(&table(&case.name, axis, &args.at, &map))?;
    }
    if let Some(path) = csv_path {
        write_atomically(&path, csv_text(&map.curves)?.as_bytes())?;
    }
    if let Some(path) = codim2_csv_path {
        write_atomically(&path, codim2_csv_text(&map.codim2_points)?.as_bytes())?;
    }
    if let Some(path) = plot_path {
        path.write(&map_figure(axis, &map, grid.as_ref())?)?;
    }
    Ok(())
}

/// The settings of the map of `model` from `map`'s options, every option checked (errors name
/// the option and its allowed values).
pub fn map_settings(args: &MapArgs, model: &TappingModel) -> Result<RegimeMapSettings> {
    for label in &args.labels {
        if !valid_label(label) {
            bail!("--labels {label}: allowed G<n> (n >= 1), fold, period-doubling");
        }
    }
    if args.points < 2 || args.points > 100_000 {
        bail!("--points {}: allowed 2 ..= 100000", args.points);
    }
    let mut diagram =
        approach_settings(model, args.floor, args.min_amplitude_ratio, args.max_step)?;
    diagram.orbit.harmonics = option_ranges::HARMONICS.count(args.harmonics)?;
    Ok(RegimeMapSettings {
        diagram,
        from: args.from,
        to: args.to,
        at: args.at.clone(),
        labels: (!args.labels.is_empty()).then(|| args.labels.clone()),
        points_per_range: args.points,
    })
}

/// The regime map of `case` over `axis` with `settings` ([`afm::map::regime_map`]); an error when a
/// curve asked for by its label does not start at the case's own value.
pub fn compute_map(
    case: &Case,
    axis: ParameterAxis,
    settings: &RegimeMapSettings,
) -> Result<RegimeMap> {
    compute_map_until(case, axis, settings, &|| false)
}

/// As [`compute_map`], asking `stop` (from any thread) between the map's steps whether to give
/// up ([`regime_map_until`]).
pub fn compute_map_until(
    case: &Case,
    axis: ParameterAxis,
    settings: &RegimeMapSettings,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<RegimeMap> {
    let map = regime_map_until(case, axis, settings, stop)
        .with_context(|| format!("regime map of case `{}` failed", case.name))?;
    for label in settings.labels.iter().flatten() {
        if !map.curves.iter().any(|c| c.label == *label) {
            let found: Vec<&str> = map
                .seed
                .special_points
                .iter()
                .map(|s| s.label.as_str())
                .collect();
            bail!(
                "--labels {label}: the approach at the case's {} = {} has no such point (it has: {})",
                axis.name(),
                map.seed_parameter,
                found.join(", ")
            );
        }
    }
    Ok(map)
}

/// The `map --json` object of `map`, computed from `args` with `settings`
/// (docs/output-schema.md).
pub fn map_json(
    args: &MapArgs,
    case: &Case,
    model: &TappingModel,
    axis: ParameterAxis,
    settings: &RegimeMapSettings,
    map: &RegimeMap,
) -> serde_json::Value {
    let options = json!({
        "vary": axis.name(),
        "from": args.from,
        "to": args.to,
        "at": args.at,
        "labels": args.labels,
        "points": args.points,
        "floor_nm": settings.diagram.z_limit_nm,
        "min_amplitude_ratio": settings.diagram.min_amplitude_ratio,
        "max_step_nm": settings.diagram.max_step,
        "harmonics": settings.diagram.orbit.harmonics,
    });
    json!({
        "case": case.name,
        "inputs": orbit_inputs_json("map", options, case, model, &settings.diagram.orbit),
        "parameter": {
            "name": axis.name(),
            "unit": axis.unit(),
            "from": args.from,
            "to": args.to,
            "case_value": map.seed_parameter,
        },
        "curves": map.curves,
        "codim2_points": map.codim2_points,
    })
}

/// The readable summary: per curve its ends and its points at the range ends, the `--at`
/// values and the case's own value; then the codimension-two points.
fn table(case: &str, axis: ParameterAxis, at: &[f64], map: &RegimeMap) -> String {
    let mut s = String::new();
    let unit = axis.unit();
    let _ = writeln!(
        s,
        "case {case}: map over {} ({}), curves from the case's value {}",
        axis.name(),
        if unit.is_empty() { "-" } else { unit },
        map.seed_parameter
    );
    for curve in &map.curves {
        let ends: Vec<String> = curve
            .ends
            .iter()
            .map(|e| {
                let error = e
                    .error
                    .as_ref()
                    .map_or(String::new(), |m| format!(" ({m})"));
                format!(
                    "{} at {} = {:.6}{error}",
                    e.reason,
                    axis.name(),
                    e.parameter
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "{}: {} points; ends: {}",
            curve.label,
            curve.points.len(),
            ends.join("; ")
        );
        let _ = writeln!(
            s,
            "  {:>14} {:>16} {:>10} {:>10} {:>8} {:>7}",
            axis.name(),
            "Z (nm)",
            "A/A0",
            "phase",
            "impacts",
            "stable"
        );
        for point in curve.points.iter().filter(|p| {
            p.at_fixed_parameter
                && (at.contains(&p.parameter)
                    || p.parameter == map.seed_parameter
                    || curve
                        .points
                        .first()
                        .is_some_and(|f| f.parameter == p.parameter)
                    || curve
                        .points
                        .last()
                        .is_some_and(|l| l.parameter == p.parameter))
        }) {
            let _ = writeln!(
                s,
                "  {:>14.6} {:>16.10} {:>10.6} {:>10.4} {:>3} -> {:<2} {:>7}",
                point.parameter,
                point.z_nm,
                point.amplitude_ratio,
                point.phase_deg,
                point.impacts_before,
                point.impacts_after,
                if point.stable { "yes" } else { "no" }
            );
        }
    }
    for point in &map.codim2_points {
        let _ = writeln!(
            s,
            "codimension two: {} on {} at {} = {:.9}, Z = {:.9} nm (precision {:.1e}{})",
            point.label,
            point.curve,
            axis.name(),
            point.parameter,
            point.z_nm,
            point.precision,
            if point.converged {
                ""
            } else {
                ", NOT converged"
            }
        );
    }
    s
}

/// The CSV columns after `label`: the scalar keys of a JSON curve point, in this order
/// (docs/output-schema.md); the harmonics' columns follow them.
pub const CSV_COLUMNS: [&str; 15] = [
    "parameter",
    "z_nm",
    "amplitude_ratio",
    "phase_deg",
    "impacts_before",
    "impacts_after",
    "stable",
    "spectral_radius",
    "residual",
    "at_fixed_parameter",
    "dissipated_ev",
    "virial_ev",
    "max_indentation_nm",
    "mean_indentation_nm",
    "energy_balance_residual",
];

/// The CSV columns of `map --codim2-csv` after `label`: the scalar keys of a JSON
/// codimension-two point, in this order (docs/output-schema.md); the harmonics' columns follow
/// them.
pub const CODIM2_CSV_COLUMNS: [&str; 12] = [
    "curve",
    "parameter",
    "z_nm",
    "amplitude_ratio",
    "phase_deg",
    "precision",
    "converged",
    "dissipated_ev",
    "virial_ev",
    "max_indentation_nm",
    "mean_indentation_nm",
    "energy_balance_residual",
];

/// The CSV of the codimension-two points (`map --codim2-csv`): `label`, then
/// [`CODIM2_CSV_COLUMNS`], then `harmonic_<n>_amplitude_nm` and
/// `harmonic_<n>_phase_deg` for `n = 1..N` (the JSON point's `harmonics[n - 1]`).
pub fn codim2_csv_text(points: &[MapCodim2Point]) -> Result<String> {
    let count = points.first().map_or(0, |point| point.harmonics.len());
    let mut text = format!("label,{}", CODIM2_CSV_COLUMNS.join(","));
    text.push_str(&harmonic_columns(count));
    text.push('\n');
    for point in points {
        let value = serde_json::to_value(point)?;
        // `curve` is a label like the first column's, written bare.
        let labels = format!("{},{}", point.label, point.curve);
        push_csv_row(&mut text, &labels, &value, &CODIM2_CSV_COLUMNS[1..]);
        // The row's newline moves after the harmonics.
        text.pop();
        push_harmonic_cells(&mut text, &point.harmonics, count);
        text.push('\n');
    }
    Ok(text)
}

/// The figure `map --plot` draws (SVG): the map in the `(PARAM, Z)` and `(PARAM, A/A0)`
/// planes, with the cells of a `drumroll grid` result under the curves when `grid` is given.
pub fn map_figure(axis: ParameterAxis, map: &RegimeMap, grid: Option<&Grid>) -> Result<String> {
    render_svg(&map_panels(axis, map, grid), 1, 2, (620, 480))
}

/// The CSV of every curve's points: `label`, then [`CSV_COLUMNS`], then
/// `harmonic_<n>_amplitude_nm` and `harmonic_<n>_phase_deg` for `n = 1..N` (the JSON point's
/// `harmonics[n - 1]`), as `continue --csv` writes them (what `map --csv` writes).
pub fn csv_text(curves: &[MapCurve]) -> Result<String> {
    let count = curves
        .iter()
        .find_map(|curve| curve.points.first())
        .map_or(0, |point| point.harmonics.len());
    let mut text = format!("label,{}", CSV_COLUMNS.join(","));
    text.push_str(&harmonic_columns(count));
    text.push('\n');
    for curve in curves {
        for point in &curve.points {
            push_csv_row(
                &mut text,
                &curve.label,
                &serde_json::to_value(point)?,
                &CSV_COLUMNS,
            );
            // The row's newline moves after the harmonics.
            text.pop();
            push_harmonic_cells(&mut text, &point.harmonics, count);
            text.push('\n');
        }
    }
    Ok(text)
}
