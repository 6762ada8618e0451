//! `drumroll continue`: the bifurcation diagram in `Z` (the paper's Fig. 2): the branch of
//! periodic orbits from above first contact down to a floor, every special point labelled and
//! located, and optionally the retract branch back up.

use afm::{approach_diagram, diagram, BifurcationDiagram, Case, DiagramSettings, TappingModel};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;

use crate::continue_figure::{figure, CaseDiagrams};
use crate::inputs::orbit_inputs_json;
use crate::model_args::{model_of, output_path, ModelArgs};
use crate::output::write_atomically;
use crate::plot::FigureFile;
use crate::progress::Progress;

/// Options of `drumroll continue`.
#[derive(Debug, Clone, Args)]
pub struct ContinueArgs {
    /// The cantilever, sample and drive.
    #[command(flatten)]
    pub model: ModelArgs,
    /// Lowest separation of the approach, nm, in [-A0, Z_G1) (default 0.05 A0).
    #[arg(long, allow_negative_numbers = true)]
    pub floor: Option<f64>,
    /// The approach also stops when A/A0 falls below this ratio (default 0.3; 0 disables).
    #[arg(long, default_value_t = 0.3)]
    pub min_amplitude_ratio: f64,
    /// Largest arclength step, in nm (default A0/250: several hundred points per diagram).
    #[arg(long)]
    pub max_step: Option<f64>,
    /// After the approach, continue back up from its lowest point (Z increasing), so that
    /// hysteresis shows; the bistable range is reported.
    #[arg(long)]
    pub retract: bool,
    /// Print one JSON object `{"points": [...], "special_points": [...]}` (with `retract` too
    /// when asked) instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Write the branch points to this CSV file.
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,
    /// Draw phase vs A/A0 (the paper's Fig. 2) with the special points labelled, stable parts
    /// solid and unstable dashed, beside A/A0 vs Z and impacts per period vs Z; with several
    /// --case, one phase panel per case, (a), (b), ... The format follows the extension:
    /// .svg, .png or .pdf.
    #[arg(long, value_name = "FILE.svg|png|pdf")]
    pub plot: Option<PathBuf>,
    /// With several --case and --plot: draw every case on one set of axes (the three panels,
    /// a legend naming the cases) instead of one panel per case.
    #[arg(long, requires = "plot")]
    pub overlay: bool,
}

/// One case's approach, its optional retract and their bistable ranges.
struct Continued {
    settings: DiagramSettings,
    approach: BifurcationDiagram,
    retract: Option<BifurcationDiagram>,
    bistable: Option<Vec<[f64; 2]>>,
}

/// Run `drumroll continue`: each `--case` in turn (tables or JSON lines printed as they are
/// computed), then the CSV (one case) and the figure.
pub fn run(args: &ContinueArgs) -> Result<()> {
    let cases = args.model.cases()?;
    let csv_path = args
        .csv
        .as_ref()
        .map(|p| output_path(p, "csv", "--csv"))
        .transpose()?;
    if cases.len() > 1 && csv_path.is_some() {
        bail!(
            "--csv takes one case ({} given): run once per case",
            cases.len()
        );
    }
    let plot = args
        .plot
        .as_ref()
        .map(|p| FigureFile::new(p, "--plot"))
        .transpose()?;
    let mut drawn = Vec::new();
    let mut progress = Progress::new(
        cases.len() as u64,
        "{wide_bar} {pos}/{len} cases, now {msg}, {eta} left",
    );
    for (done, case) in cases.into_iter().enumerate() {
        progress.update(done as u64, || case.name.clone());
        let (case, model) = model_of(case)?;
        let continued = continue_case(args, &case, &model)?;
        print_report(args, &case, &model, &continued)?;
        if let Some(path) = &csv_path {
            let mut text = csv_text(&continued.approach, "approach")?;
            if let Some(retract) = &continued.retract {
                text.push_str(
                    csv_text(retract, "retract")?
                        .split_once('\n')
                        .map_or("", |(_, rows)| rows),
                );
            }
            write_atomically(path, text.as_bytes())?;
        }
        drawn.push(CaseDiagrams {
            case,
            model,
            approach: continued.approach,
            retract: continued.retract,
        });
    }
    progress.finish();
    if let Some(plot) = plot {
        plot.write(&figure(&drawn, args.overlay)?)?;
    }
    Ok(())
}

/// The diagram settings of `model` with the options applied and checked.
fn settings(args: &ContinueArgs, model: &TappingModel) -> Result<DiagramSettings> {
    let mut settings = DiagramSettings::approach(model);
    if let Some(floor) = args.floor {
        let lowest = -model.free_amplitude_nm();
        if !(floor >= lowest && floor < model.grazing_separation_nm()) {
            bail!(
                "--floor {floor}: allowed [{lowest}, {:.6}) nm, from -A0 up to just below first contact Z_G1",
                model.grazing_separation_nm()
            );
        }
        settings.z_limit_nm = floor;
    }
    if !(0.0..1.0).contains(&args.min_amplitude_ratio) {
        bail!(
            "--min-amplitude-ratio {}: allowed 0 <= R < 1",
            args.min_amplitude_ratio
        );
    }
    settings.min_amplitude_ratio = args.min_amplitude_ratio;
    if let Some(step) = args.max_step {
        if !(step.is_finite() && step > 0.0 && step <= model.free_amplitude_nm()) {
            bail!(
                "--max-step {step}: allowed 0 < step <= A0 = {} nm",
                model.free_amplitude_nm()
            );
        }
        settings.max_step = step;
    }
    Ok(settings)
}

/// The approach (and retract) of one case.
fn continue_case(args: &ContinueArgs, case: &Case, model: &TappingModel) -> Result<Continued> {
    let settings = settings(args, model)?;
    let approach = approach_diagram(model, &settings)
        .with_context(|| format!("continuation of case `{}` failed", case.name))?;
    let retract = if args.retract {
        let Some(lowest) = approach
            .points
            .iter()
            .min_by(|a, b| a.z_nm.total_cmp(&b.z_nm))
        else {
            bail!("the approach produced no point to retract from");
        };
        let retract_settings = DiagramSettings {
            max_step: settings.max_step,
            ..DiagramSettings::retract(model)
        };
        Some(
            diagram(model, &lowest.state, lowest.z_nm, &retract_settings)
                .context("retract continuation failed")?,
        )
    } else {
        None
    };
    let bistable = retract.as_ref().map(|retract| {
        let mut ranges = approach.bistable_ranges();
        ranges.extend(retract.bistable_ranges());
        merge_ranges(ranges)
    });
    Ok(Continued {
        settings,
        approach,
        retract,
        bistable,
    })
}

/// Print one case's table (or JSON object, one line).
fn print_report(
    args: &ContinueArgs,
    case: &Case,
    model: &TappingModel,
    continued: &Continued,
) -> Result<()> {
    let Continued {
        settings,
        approach,
        retract,
        bistable,
    } = continued;
    if args.json {
        let options = json!({
            "floor_nm": settings.z_limit_nm,
            "min_amplitude_ratio": settings.min_amplitude_ratio,
            "max_step_nm": settings.max_step,
            "max_points": settings.max_points,
            "retract": args.retract,
        });
        let mut object = json!({
            "inputs": orbit_inputs_json("continue", options, case, model, &settings.orbit),
            "case": case.name,
            "free_amplitude_nm": model.free_amplitude_nm(),
            "first_contact_z_nm": model.grazing_separation_nm(),
            "points": approach.points,
            "special_points": approach.special_points,
            "stop": approach.stop,
            "error": approach.error,
        });
        if let Some(retract) = &retract {
            object["retract"] = json!({
                "points": retract.points,
                "special_points": retract.special_points,
                "stop": retract.stop,
                "error": retract.error,
            });
            object["bistable_ranges_nm"] = json!(bistable);
        }
        println!("{}", serde_json::to_string(&object)?);
    } else {
        print!("{}", table(&case.name, model, "approach", approach));
        if let Some(retract) = &retract {
            print!("{}", table(&case.name, model, "retract", retract));
            match bistable.as_deref() {
                Some([]) | None => {
                    println!("no bistable range: approach and retract follow one stable orbit")
                }
                Some(ranges) => {
                    for [low, high] in ranges {
                        println!(
                            "bistable range: Z in [{low:.9}, {high:.9}] nm (two stable orbits: approach and retract differ)"
                        );
                    }
                }
            }
        }
    }
    Ok(())
}

/// The readable table of special points of one diagram.
fn table(
    case: &str,
    model: &TappingModel,
    direction: &str,
    diagram: &BifurcationDiagram,
) -> String {
    let mut s = String::new();
    let z: Vec<f64> = diagram.points.iter().map(|p| p.z_nm).collect();
    let (low, high) = z
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &z| {
            (l.min(z), h.max(z))
        });
    let _ = writeln!(
        s,
        "case {case} ({direction}): A0 = {} nm, first contact Z_G1 = {:.9} nm; {} branch points, Z from {high:.4} to {low:.4} nm; {}",
        model.free_amplitude_nm(),
        model.grazing_separation_nm(),
        diagram.points.len(),
        diagram.stop
    );
    if let Some(error) = &diagram.error {
        let _ = writeln!(s, "  the branch ended early: {error}");
    }
    let _ = writeln!(
        s,
        "{:<16} {:>16} {:>10} {:>10} {:>8} {:>10} {:>10}",
        "label", "Z (nm)", "A/A0", "phase", "impacts", "|dZ| (nm)", "located"
    );
    for p in &diagram.special_points {
        let _ = writeln!(
            s,
            "{:<16} {:>16.10} {:>10.6} {:>10.4} {:>4} -> {:<2} {:>10.1e} {:>10}",
            p.label,
            p.z_nm,
            p.amplitude_ratio,
            p.phase_deg,
            p.impacts_before,
            p.impacts_after,
            p.precision_nm,
            if p.converged { "yes" } else { "NO" }
        );
    }
    s
}

/// Sort and merge overlapping `[low, high]` ranges.
fn merge_ranges(mut ranges: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    ranges.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut merged: Vec<[f64; 2]> = Vec::new();
    for range in ranges {
        match merged.last_mut() {
            Some(last) if range[0] <= last[1] => last[1] = last[1].max(range[1]),
            _ => merged.push(range),
        }
    }
    merged
}

/// The CSV columns after `direction`: the scalar keys of a JSON branch point, in this order
/// (docs/output-schema.md).
pub const CSV_COLUMNS: [&str; 15] = [
    "z_nm",
    "amplitude_ratio",
    "phase_deg",
    "multiplicity",
    "impacts_per_period",
    "impacts_per_orbit",
    "min_gap_nm",
    "peak_force_nn",
    "mean_force_nn",
    "impulse_nn_us",
    "contact_time_periods",
    "spectral_radius",
    "stable",
    "iterations",
    "residual",
];

/// The CSV of a diagram's points (header line first): `direction` (`approach` or `retract`),
/// then [`CSV_COLUMNS`], each the value of the JSON point's key of that name (empty for
/// `null`).
fn csv_text(diagram: &BifurcationDiagram, direction: &str) -> Result<String> {
    let mut text = format!("direction,{}\n", CSV_COLUMNS.join(","));
    for point in &diagram.points {
        let value = serde_json::to_value(point)?;
        text.push_str(direction);
        for column in CSV_COLUMNS {
            text.push(',');
            match &value[column] {
                serde_json::Value::Null => {}
                other => text.push_str(&other.to_string()),
            }
        }
        text.push('\n');
    }
    Ok(text)
}
