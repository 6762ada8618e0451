//! `drumroll continue`: the bifurcation diagram in `Z` (the paper's Fig. 2): the branch of
//! periodic orbits from above first contact down to a floor, every special point labelled and
//! located, and optionally the retract branch back up.

use afm::validation::Interval;
use afm::{
    approach_diagram_until, diagram_until, BifurcationDiagram, Case, DiagramSettings, TappingModel,
};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

use crate::continue_figure::{contrast_figure, figure, CaseDiagrams, PanelQuantity};
use crate::diagram_json::DiagramJson;
use crate::exit_status::Incomplete;
use crate::json_value::plain_value;
use crate::model_args::{model_of, output_path, ModelArgs};
use crate::option_ranges::{self, OptionRange};
use crate::output::{
    harmonic_columns, print_stdout, push_csv_row, push_harmonic_cells, write_atomically,
};
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
    /// The approach also stops when A/A0 falls below this ratio, in [0, 1) (default 0.3; 0
    /// disables).
    #[arg(long, default_value_t = 0.3, allow_negative_numbers = true)]
    pub min_amplitude_ratio: f64,
    /// Largest arclength step, in nm, in [1e-7, A0] (default A0/250: several hundred points per
    /// diagram).
    #[arg(long, allow_negative_numbers = true)]
    pub max_step: Option<f64>,
    /// Largest number of points per branch, in [2, 10000000]. A branch that reaches it before
    /// its end stops there: the points so far are printed and written, stderr says so, and the
    /// exit status is 3.
    #[arg(long, default_value_t = 20_000, allow_negative_numbers = true)]
    pub max_points: i64,
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
    /// With --plot: draw these quantities against A/A0 instead, one panel each in a column
    /// sharing the A/A0 axis and the special points' marks, comma-separated: phase,
    /// dissipated, virial, max-indentation, mean-indentation, harmonic-N (MODEL.md section
    /// 10), e.g. `phase,dissipated,harmonic-2`.
    #[arg(long, requires = "plot", value_name = "LIST")]
    pub panels: Option<String>,
    /// The harmonics n = 1..N of u reported at every point, N in [1, 1000] (raised to the
    /// highest harmonic --panels draws).
    #[arg(long, default_value_t = crate::approach::DEFAULT_HARMONICS, allow_negative_numbers = true)]
    pub harmonics: i64,
    /// With several --case: how many cases are computed at once, one per thread (default: the
    /// environment's RAYON_NUM_THREADS, else one per core). The output does not depend on it:
    /// each case is printed, in the order given, as soon as it and the cases before it are
    /// done.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
}

/// One case's approach, its optional retract and their bistable ranges.
#[derive(Debug, Clone)]
pub struct Continued {
    /// The approach's settings (the retract's are [`DiagramSettings::retract`] with the same
    /// `max_step` and `max_points`).
    pub settings: DiagramSettings,
    /// The approach diagram (`Z` decreasing from above first contact).
    pub approach: BifurcationDiagram,
    /// The retract diagram (`Z` increasing from the approach's lowest point), if asked.
    pub retract: Option<BifurcationDiagram>,
    /// With a retract: the merged `[Z_low, Z_high]` ranges (nm) where two stable orbits
    /// coexist.
    pub bistable: Option<Vec<[f64; 2]>>,
    /// The warning of [`afm::film_range_warning`] on the branches' orbits, if any.
    pub warning: Option<String>,
}

/// Run `drumroll continue`: every `--case`'s model built and its options checked first, the
/// cases then computed on up to `--threads` threads ([`continue_cases`]), each printed (tables
/// or JSON lines) in the order given as soon as it and those before it are done; then the CSV
/// (one case) and the figure.
pub fn run(args: &ContinueArgs) -> Result<()> {
    // The options that need no model, checked before the output paths and the models.
    option_ranges::MIN_AMPLITUDE_RATIO.check(args.min_amplitude_ratio)?;
    option_ranges::MAX_POINTS.count(args.max_points)?;
    option_ranges::HARMONICS.count(args.harmonics)?;
    if args.threads == Some(0) {
        bail!("--threads 0: allowed 1 or more");
    }
    let panels = args
        .panels
        .as_deref()
        .map(PanelQuantity::parse_list)
        .transpose()?;
    let csv_path = args
        .csv
        .as_ref()
        .map(|p| output_path(p, "csv", "--csv"))
        .transpose()?;
    let plot = args
        .plot
        .as_ref()
        .map(|p| FigureFile::new(p, "--plot"))
        .transpose()?;
    let cases = args.model.cases()?;
    if cases.len() > 1 && csv_path.is_some() {
        bail!(
            "--csv takes one case ({} given): run once per case",
            cases.len()
        );
    }
    // Every case's model and model-dependent options (--floor, --max-step) before any
    // computation, so that a bad input is reported at once, not after the cases before it.
    let models = cases
        .into_iter()
        .map(model_of)
        .collect::<Result<Vec<_>>>()?;
    let several = models.len() > 1;
    for (case, model) in &models {
        let checked = diagram_settings(args, model);
        if several {
            checked.with_context(|| format!("case `{}`", case.name))?;
        } else {
            checked?;
        }
    }
    let mut drawn = Vec::new();
    let mut unfinished = Vec::new();
    let mut progress = Progress::new(
        models.len() as u64,
        "{wide_bar} {pos}/{len} cases, last {msg}, {eta} left",
    );
    continue_cases(args, &models, |done, (case, model), continued| {
        progress.update(done as u64 + 1, || case.name.clone());
        if let Some(warning) = &continued.warning {
            crate::output::print_stderr(&format!("warning: {warning}"));
        }
        print_report(args, case, model, &continued)?;
        if let Some(path) = &csv_path {
            write_atomically(path, continued_csv(&continued)?.as_bytes())?;
        }
        if let Some(why) = unfinished_branches(&continued.approach, continued.retract.as_ref()) {
            unfinished.push(if several {
                format!("case `{}`: {why}", case.name)
            } else {
                why
            });
        }
        drawn.push(CaseDiagrams {
            case: case.clone(),
            model: model.clone(),
            approach: continued.approach,
            retract: continued.retract,
        });
        Ok(())
    })?;
    progress.finish();
    if let Some(plot) = plot {
        let svg = match &panels {
            Some(quantities) => contrast_figure(&drawn, quantities)?,
            None => figure(&drawn, args.overlay)?,
        };
        plot.write(&svg)?;
    }
    if unfinished.is_empty() {
        return Ok(());
    }
    let hint = if unfinished
        .iter()
        .any(|u| u.contains("maximum number of points"))
    {
        format!(
            "; raise --max-points (now {}) or --max-step",
            args.max_points
        )
    } else {
        String::new()
    };
    Err(Incomplete(format!("{}{hint}", unfinished.join("; "))).into())
}

/// Compute the approach (and retract) of every case of `models` with `continue`'s options
/// `args`, up to `args.threads` cases at once (default: rayon's thread count,
/// `RAYON_NUM_THREADS` or one per core; at most one per case), and hand each to `report` in the
/// order of `models` (its index, the case and model, the result) as soon as it and every case
/// before it are done. The first error in that order
/// (a case's continuation, or `report`'s) is returned after the cases before it were reported;
/// the cases still running are then interrupted ([`afm::diagram_until`]'s predicate) and
/// dropped. Each case's computation is that of one thread alone, so the results do not depend
/// on the number of threads; with one thread the cases run on the calling thread.
fn continue_cases<F>(
    args: &ContinueArgs,
    models: &[(Case, TappingModel)],
    mut report: F,
) -> Result<()>
where
    F: FnMut(usize, &(Case, TappingModel), Continued) -> Result<()>,
{
    // By default as many as rayon's pool has (`RAYON_NUM_THREADS`, else one per core), like
    // `map`, `fit` and `detect`.
    let threads = args
        .threads
        .unwrap_or_else(rayon::current_num_threads)
        .clamp(1, models.len().max(1));
    if threads == 1 {
        // One at a time, on this thread (its stack, no thread started).
        for (index, case_model) in models.iter().enumerate() {
            let (case, model) = case_model;
            report(
                index,
                case_model,
                continue_case_until(args, case, model, &mut || false)?,
            )?;
        }
        return Ok(());
    }
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let (sender, receiver) = mpsc::channel::<(usize, Result<Continued>)>();
    std::thread::scope(|scope| {
        for _ in 0..threads {
            let sender = sender.clone();
            let (next, stop) = (&next, &stop);
            scope.spawn(move || loop {
                let index = next.fetch_add(1, Ordering::Relaxed);
                if index >= models.len() || stop.load(Ordering::Relaxed) {
                    break;
                }
                let (case, model) = &models[index];
                let continued =
                    continue_case_until(args, case, model, &mut || stop.load(Ordering::Relaxed));
                if sender.send((index, continued)).is_err() {
                    break;
                }
            });
        }
        drop(sender);
        let mut waiting = BTreeMap::new();
        let mut reported = 0;
        let outcome = receiver.iter().try_for_each(|(index, continued)| {
            waiting.insert(index, continued);
            while let Some(continued) = waiting.remove(&reported) {
                report(reported, &models[reported], continued?)?;
                reported += 1;
            }
            Ok(())
        });
        if outcome.is_err() {
            stop.store(true, Ordering::Relaxed);
        }
        outcome
    })
}

/// `None` when every branch reached its requested end, else which did not and why (the run
/// then ends with an [`Incomplete`] error: `main` exits with status 3).
fn unfinished_branches(
    approach: &BifurcationDiagram,
    retract: Option<&BifurcationDiagram>,
) -> Option<String> {
    let unfinished: Vec<String> = std::iter::once(("approach", approach))
        .chain(retract.map(|retract| ("retract", retract)))
        .filter(|(_, diagram)| !diagram.completed)
        .map(|(direction, diagram)| {
            let error = diagram
                .error
                .as_deref()
                .map_or_else(String::new, |error| format!(" ({error})"));
            format!("the {direction} ended because {}{error}", diagram.stop)
        })
        .collect();
    (!unfinished.is_empty()).then(|| unfinished.join("; "))
}

/// The approach's settings for `model` from `continue`'s options, every option checked
/// against [`crate::option_ranges`] (see [`approach_settings`]; `--max-points` besides).
pub fn diagram_settings(args: &ContinueArgs, model: &TappingModel) -> Result<DiagramSettings> {
    let mut settings =
        approach_settings(model, args.floor, args.min_amplitude_ratio, args.max_step)?;
    settings.max_points = option_ranges::MAX_POINTS.count(args.max_points)?;
    let drawn = args
        .panels
        .as_deref()
        .map(PanelQuantity::parse_list)
        .transpose()?
        .map_or(0, |quantities| PanelQuantity::highest_harmonic(&quantities));
    settings.orbit.harmonics = option_ranges::HARMONICS.count(args.harmonics)?.max(drawn);
    Ok(settings)
}

/// The approach diagram's settings of `model` with the options `--floor` (in `[-A0, Z_G1)`),
/// `--min-amplitude-ratio` and `--max-step` (in `[1e-7, A0]`: [`afm::smallest_max_step_nm`])
/// applied, each checked against [`crate::option_ranges`] (errors name the option and its
/// range); shared by `continue` and `map`.
pub fn approach_settings(
    model: &TappingModel,
    floor: Option<f64>,
    min_amplitude_ratio: f64,
    max_step: Option<f64>,
) -> Result<DiagramSettings> {
    option_ranges::MIN_AMPLITUDE_RATIO.check(min_amplitude_ratio)?;
    let mut settings = DiagramSettings::approach(model);
    let a0 = model.free_amplitude_nm();
    if let Some(floor) = floor {
        OptionRange::new(
            "--floor",
            Interval::right_open(-a0, model.grazing_separation_nm(), "nm"),
        )
        .check(floor)?;
        settings.z_limit_nm = floor;
    }
    settings.min_amplitude_ratio = min_amplitude_ratio;
    if let Some(step) = max_step {
        OptionRange::new(
            "--max-step",
            Interval::closed(afm::smallest_max_step_nm(), a0, "nm"),
        )
        .check(step)?;
        settings.max_step = step;
    }
    Ok(settings)
}

/// The approach (and retract) of one case with `continue`'s options `args`; `interrupted` is
/// asked after every branch point whether to give up ([`afm::diagram_until`]).
pub fn continue_case_until(
    args: &ContinueArgs,
    case: &Case,
    model: &TappingModel,
    interrupted: &mut dyn FnMut() -> bool,
) -> Result<Continued> {
    let settings = diagram_settings(args, model)?;
    let approach = approach_diagram_until(model, &settings, interrupted)
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
            max_points: settings.max_points,
            ..DiagramSettings::retract(model)
        };
        Some(
            diagram_until(
                model,
                &lowest.state,
                lowest.z_nm,
                &retract_settings,
                interrupted,
            )
            .context("retract continuation failed")?,
        )
    } else {
        None
    };
    let orbits = approach
        .points
        .iter()
        .chain(retract.iter().flat_map(|r| r.points.iter()))
        .map(|point| (point.z_nm, point.min_gap_nm));
    let warning = afm::film_range_warning(model, orbits);
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
        warning,
    })
}

/// The `continue --json` object of one case (docs/output-schema.md): [`DiagramJson`] of
/// `continued`, computed from `continue`'s options `args` for `case` (resolved into `model`).
pub fn continue_object<'a>(
    args: &ContinueArgs,
    case: &'a Case,
    model: &TappingModel,
    continued: &'a Continued,
) -> DiagramJson<'a> {
    let Continued {
        settings,
        approach,
        retract,
        bistable,
        ..
    } = continued;
    let options = json!({
        "floor_nm": settings.z_limit_nm,
        "min_amplitude_ratio": settings.min_amplitude_ratio,
        "max_step_nm": settings.max_step,
        "max_points": settings.max_points,
        "retract": args.retract,
        "harmonics": settings.orbit.harmonics,
    });
    DiagramJson::new(
        case,
        model,
        &settings.orbit,
        options,
        approach,
        retract
            .as_ref()
            .map(|retract| (retract, bistable.as_deref())),
    )
}

/// [`continue_object`] as a `serde_json::Value`.
pub fn continue_json(
    args: &ContinueArgs,
    case: &Case,
    model: &TappingModel,
    continued: &Continued,
) -> serde_json::Value {
    plain_value(&continue_object(args, case, model, continued))
}

/// Print one case's table (or JSON object, one line).
fn print_report(
    args: &ContinueArgs,
    case: &Case,
    model: &TappingModel,
    continued: &Continued,
) -> Result<()> {
    let Continued {
        approach,
        retract,
        bistable,
        ..
    } = continued;
    if args.json {
        let mut line = serde_json::to_string(&continue_object(args, case, model, continued))?;
        line.push('\n');
        print_stdout(&line)?;
    } else {
        print_stdout(&table(&case.name, model, "approach", approach))?;
        if let Some(retract) = &retract {
            print_stdout(&table(&case.name, model, "retract", retract))?;
            match bistable.as_deref() {
                Some([]) | None => print_stdout(
                    "no bistable range: approach and retract follow one stable orbit\n",
                )?,
                Some(ranges) => {
                    for [low, high] in ranges {
                        print_stdout(&format!(
                            "bistable range: Z in [{low:.9}, {high:.9}] nm (two stable orbits: approach and retract differ)\n"
                        ))?;
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

/// What `continue --csv` writes: the approach's rows, then the retract's (one header line).
pub fn continued_csv(continued: &Continued) -> Result<String> {
    let mut text = csv_text(&continued.approach, "approach")?;
    if let Some(retract) = &continued.retract {
        text.push_str(
            csv_text(retract, "retract")?
                .split_once('\n')
                .map_or("", |(_, rows)| rows),
        );
    }
    Ok(text)
}

/// The CSV columns after `direction`: the scalar keys of a JSON branch point, in this order
/// (docs/output-schema.md).
pub const CSV_COLUMNS: [&str; 20] = [
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
    "dissipated_ev",
    "virial_ev",
    "max_indentation_nm",
    "mean_indentation_nm",
    "energy_balance_residual",
    "spectral_radius",
    "stable",
    "iterations",
    "residual",
];

/// The header line of a diagram's CSV (no newline) with harmonics `1..=harmonics`:
/// `direction`, then [`CSV_COLUMNS`], then `harmonic_<n>_amplitude_nm,harmonic_<n>_phase_deg`
/// for each `n`.
pub fn csv_header(harmonics: usize) -> String {
    format!(
        "direction,{}{}",
        CSV_COLUMNS.join(","),
        harmonic_columns(harmonics)
    )
}

/// The CSV of a diagram's points (header line first): `direction` (`approach` or `retract`),
/// then [`CSV_COLUMNS`], each the value of the JSON point's key of that name (empty for
/// `null`), then `harmonic_<n>_amplitude_nm` and `harmonic_<n>_phase_deg` for `n = 1..N`
/// (the JSON point's `harmonics[n - 1]`).
fn csv_text(diagram: &BifurcationDiagram, direction: &str) -> Result<String> {
    let count = diagram.points.first().map_or(0, |p| p.harmonics.len());
    let mut text = csv_header(count);
    text.push('\n');
    for point in &diagram.points {
        push_csv_row(
            &mut text,
            direction,
            &serde_json::to_value(point)?,
            &CSV_COLUMNS,
        );
        // The row's newline moves after the harmonics.
        text.pop();
        push_harmonic_cells(&mut text, &point.harmonics, count);
        text.push('\n');
    }
    Ok(text)
}
