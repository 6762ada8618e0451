//! `drumroll fit`: least squares of the model's followed approach branch to a measured curve
//! over the parameters named in `--fit` (MODEL.md section 13.3), with standard errors,
//! correlations, the fitted grazing points in data coordinates and their match with the
//! detected transitions, and the contrast observables at every measured point.

use afm::error::AfmError;
use afm::fit::least_squares::{fit_measurement_until, FitParameter, FitResult, FitSettings};
use afm::fit::measurement::Measurement;
use afm::fit::transitions::{detect_transitions, Detection, DetectionSettings};
use afm::model::case::Case;
use anyhow::Result;
use clap::Args;
use serde_json::{json, Map, Value};
use std::path::PathBuf;

use crate::fit_figure::fit_panels;
use crate::measurement_args::MeasurementArgs;
use crate::model_args::ModelArgs;
use crate::output::{check_writable, print_stdout, push_csv_row, write_atomically};
use crate::plot::file::FigureFile;
use crate::plot::render_svg;

/// Options of `drumroll fit`.
#[derive(Debug, Clone, Args)]
pub struct FitArgs {
    /// The measured curve and how to read it.
    #[command(flatten)]
    pub measurement: MeasurementArgs,
    /// The model (its `--a0`, if given, is the measured free amplitude in the data's
    /// amplitude unit converted to nm; else A0 comes from the free rows).
    #[command(flatten)]
    pub model: ModelArgs,
    /// The fitted parameters, comma-separated: z-offset, amplitude-calibration, phase-offset,
    /// and any of map's parameters but a0 (sample-modulus, tip-radius, drive-frequency,
    /// quality-factor-N, stiffness-N).
    #[arg(
        long,
        value_name = "LIST",
        default_value = "z-offset,phase-offset,sample-modulus"
    )]
    pub fit: String,
    /// Budget of Levenberg-Marquardt's evaluations of the residuals (a followed branch each),
    /// in [1, 10000]; rounded up to a multiple of the varied quantities plus one (MINPACK's
    /// patience; `amplitude-calibration` varies two), and the Jacobian's branches come on top.
    #[arg(long, default_value_t = 40)]
    pub max_evaluations: usize,
    /// Print JSON instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Write the measured points with the fitted model (and its contrast observables) to this
    /// CSV file.
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,
    /// Draw the data, the fitted branch, the detected transitions (T1, T2, ...) and the fitted
    /// G_n against A/A0 and against Z, with the residuals; .svg, .png or .pdf.
    #[arg(long, value_name = "FILE.svg|png|pdf")]
    pub plot: Option<PathBuf>,
}

/// The JSON of `drumroll fit --json` (docs/output-schema.md) for `result`, with `detection`'s
/// transitions and their match with the fitted `G_n`.
pub fn fit_json(
    case_name: &str,
    measurement: &Measurement,
    result: &FitResult,
    detection: &Detection,
) -> Value {
    // Each fitted G_n with the nearest detected transition, and their distance in units of the
    // transition's sigma.
    let (z_low, z_high) = measurement
        .approach
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.z_nm), hi.max(p.z_nm))
        });
    let matched: Vec<Value> = result
        .grazing
        .iter()
        .filter(|g| g.label.starts_with('G') && (z_low..=z_high).contains(&g.z_nm))
        .filter_map(|g| {
            let (index, t) = detection.transitions.iter().enumerate().min_by(|a, b| {
                (a.1.z_nm - g.z_nm)
                    .abs()
                    .total_cmp(&(b.1.z_nm - g.z_nm).abs())
            })?;
            let sigmas = (t.z_nm - g.z_nm).abs() / t.z_uncertainty_nm;
            Some(json!({
                "label": g.label,
                "transition": index,
                "z_difference_nm": t.z_nm - g.z_nm,
                "sigmas": sigmas,
                "within_3_sigma": sigmas <= 3.0,
            }))
        })
        .collect();
    let mut parameters = Map::new();
    for p in &result.parameters {
        parameters.insert(
            p.name.clone(),
            json!({ "value": p.value, "stderr": p.stderr, "initial": p.initial }),
        );
    }
    let points: Vec<Value> = result
        .points
        .iter()
        .map(|p| serde_json::to_value(p).expect("plain numbers"))
        .collect();
    json!({
        "data": measurement.source,
        "case": case_name,
        "a0_nm": measurement.a0_nm,
        "parameters": parameters,
        "names": result.parameters.iter().map(|p| p.name.clone()).collect::<Vec<_>>(),
        "correlations": result.correlations,
        "residual_rms": {
            "amplitude_nm": result.residual_rms_amplitude_nm,
            "phase_deg": result.residual_rms_phase_deg,
        },
        "reduced_chi2": result.reduced_chi2,
        "noise": { "amplitude_nm": result.noise[0], "phase_deg": result.noise[1] },
        "grazing": result.grazing,
        "transitions": detection.transitions,
        "matched": matched,
        "evaluations": result.evaluations,
        "termination": result.termination,
        "converged": result.converged,
        "warnings": result.warnings,
        "bad_rows": measurement.bad_rows,
        "points": points,
    })
}

/// Run `drumroll fit`.
///
/// # Errors
/// A bad file or option, a model that cannot be built or continued.
pub fn run(args: &FitArgs) -> Result<()> {
    if let Some(path) = &args.csv {
        check_writable(path, "--csv")?;
    }
    let figure = args
        .plot
        .as_ref()
        .map(|path| FigureFile::new(path, "--plot"))
        .transpose()?;
    let Fitted {
        case,
        measurement,
        result,
        detection,
    } = compute_fit(args)?;
    let object = fit_json(&case.name, &measurement, &result, &detection);
    for warning in &result.warnings {
        crate::output::print_stderr(&format!("drumroll: warning: {warning}"));
    }
    let points = object["points"].as_array().cloned().unwrap_or_default();
    if let Some(path) = &args.csv {
        let columns = [
            "z_nm",
            "amplitude_nm",
            "phase_deg",
            "separation_nm",
            "model_amplitude_nm",
            "model_phase_deg",
            "impacts_per_period",
            "peak_force_nn",
            "dissipated_ev",
            "virial_ev",
            "max_indentation_nm",
            "mean_indentation_nm",
        ];
        let mut text = format!("line,{}\n", columns.join(","));
        for point in &points {
            push_csv_row(&mut text, &point["line"].to_string(), point, &columns);
        }
        write_atomically(path, text.as_bytes())?;
    }
    if let Some(figure) = figure {
        let panels = fit_panels(
            &case.name,
            measurement.a0_nm,
            &result,
            &detection.transitions,
        );
        figure.write(&render_svg(&panels, 2, 2, (640, 480))?)?;
    }
    if args.json {
        print_stdout(&format!("{}\n", serde_json::to_string_pretty(&object)?))?;
    } else {
        let mut text = format!(
            "{} fitted with {} ({} rows, A0 = {:.4} nm): {} after {} evaluations\n",
            measurement.source,
            case.name,
            measurement.approach.len(),
            measurement.a0_nm,
            result.termination,
            result.evaluations
        );
        for p in &result.parameters {
            text.push_str(&format!(
                "  {:<24} {:>12.5} +- {}\n",
                p.name,
                p.value,
                p.stderr
                    .map_or_else(|| String::from("undetermined"), |s| format!("{s:.5}"))
            ));
        }
        text.push_str(&format!(
            "  residual rms: {:.4} nm, {:.4} deg; reduced chi^2 {:.3}\n",
            result.residual_rms_amplitude_nm, result.residual_rms_phase_deg, result.reduced_chi2
        ));
        for g in &result.grazing {
            text.push_str(&format!(
                "  {:<5} at data Z = {:.4} nm, A/A0 = {:.4}, phase {:.3} deg\n",
                g.label, g.z_nm, g.amplitude_ratio, g.phase_deg
            ));
        }
        print_stdout(&text)?;
    }
    Ok(())
}

/// What [`compute_fit`] gives: the case, the measurement as read, the fit and the detected
/// transitions.
pub struct Fitted {
    /// The model's case (with the command line's overrides).
    pub case: Case,
    /// The measured curve, in nm and degrees.
    pub measurement: Measurement,
    /// The fit (MODEL.md section 13.3).
    pub result: FitResult,
    /// The transitions detected in the measured curve (MODEL.md section 13.2).
    pub detection: Detection,
}

/// The fit of `drumroll fit` for `args` and the transitions detected alongside it, without
/// writing anything: the options checked (naming the one at fault), the data read, then both
/// at once.
///
/// # Errors
/// A bad option, an unreadable or malformed data file, or a fit that fails at its start.
pub fn compute_fit(args: &FitArgs) -> Result<Fitted> {
    let case = args.model.case()?;
    if !(1..=10_000).contains(&args.max_evaluations) {
        anyhow::bail!(
            "command line: field `--max-evaluations` = {} is invalid; allowed: [1, 10000]",
            args.max_evaluations
        );
    }
    let modes = case.cantilever.mode_count();
    let parameters = args
        .fit
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|name| FitParameter::parse(name, modes))
        .collect::<Result<Vec<_>, _>>()?;
    let measurement = args.measurement.read(args.model.a0)?;
    let mut settings = FitSettings::new(parameters);
    settings.max_evaluations = args.max_evaluations;
    let (result, detection) = fit_and_detect(&case, &measurement, &settings, &|| false)?;
    Ok(Fitted {
        result,
        detection,
        case,
        measurement,
    })
}

/// The fit of `case` to `measurement` with `settings` and the transitions detected in it
/// (default detection settings), asking `stop` between the fit's branch points
/// ([`fit_measurement_until`]). The two are independent: both run at once (rayon), the fit's
/// error first, as when they ran one after the other.
///
/// # Errors
/// The fit's error, else the detection's.
pub fn fit_and_detect(
    case: &Case,
    measurement: &Measurement,
    settings: &FitSettings,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<(FitResult, Detection), AfmError> {
    let (result, detection) = rayon::join(
        || fit_measurement_until(case, measurement, settings, stop),
        || {
            detect_transitions(
                &measurement.approach,
                measurement.a0_nm,
                &DetectionSettings::default(),
            )
        },
    );
    Ok((result?, detection?))
}
