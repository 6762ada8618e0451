//! `drumroll scan`: a tapping-mode image line with amplitude feedback over a heterogeneous
//! sample (MODEL.md section 12): the ideal feedback (the setpoint orbit followed along its
//! branch, jumps marked) or the time-domain PI loop; per pixel the measured height and every
//! contrast observable, as CSV or one JSON object, and `--plot` profiles.

use afm::scan::ideal::ideal_scan_until;
use afm::scan::line::ScanLine;
use afm::scan::pi::{pi_scan_until, PiSettings};
use afm::scan::pixel::ScanPixel;
use afm::scan::raster::ScanRaster;
use afm::scan::settings::{ScanDirections, ScanSettings, MAX_PIXELS};
use afm::validation::Interval;
use afm::{Case, TappingModel};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use rayon::prelude::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use crate::inputs::orbit_inputs_json;
use crate::model_args::{apply_overrides, cantilever_of, case_of, check_overrides, named_case};
use crate::option_ranges::OptionRange;
use crate::output::{check_writable, print_stdout, push_csv_row, write_atomically};
use crate::plot::{render_svg, FigureFile};
use crate::progress::{note, Progress};
use crate::scan_image::{image_maps_svg, ImageMap};
use crate::scan_plot::scan_panels;

/// The built-in line scanned when none is named.
pub const DEFAULT_LINE: &str = "membrane-patch";
/// The case whose cantilever, drive and A0 are used when none is named.
pub const DEFAULT_CASE: &str = "maclever-membrane-experiment";

/// The CSV columns after `direction`: the JSON pixels' scalar keys in their order
/// (docs/output-schema.md); the harmonic columns follow.
pub const CSV_COLUMNS: &[&str] = &[
    "index",
    "x_nm",
    "sample",
    "height_true_nm",
    "height_nm",
    "height_error_nm",
    "z_nm",
    "amplitude_ratio",
    "phase_deg",
    "impacts_per_period",
    "peak_force_nn",
    "mean_force_nn",
    "dissipated_ev",
    "virial_ev",
    "max_indentation_nm",
    "mean_indentation_nm",
    "multiplicity",
    "stable",
    "jumped",
    "jump_from_z_nm",
];

/// The feedback.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Feedback {
    /// The steady orbit at the setpoint on every pixel, followed along its branch.
    Ideal,
    /// The time-domain PI loop.
    Pi,
}

/// The passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Direction {
    /// Left to right.
    Trace,
    /// Right to left.
    Retrace,
    /// Trace, then retrace with the feedback still engaged.
    Both,
}

/// Options of `drumroll scan`.
#[derive(Debug, Clone, Args)]
pub struct ScanArgs {
    /// The sample line: a built-in line (`membrane-patch`) or a line file (JSON: segments with
    /// from_nm, to_nm, height_nm and a sample name, file or object; optional edge_width_nm).
    #[arg(long, value_name = "NAME|FILE", default_value = DEFAULT_LINE)]
    pub line: String,
    /// A 2-D sample instead of --line: a raster file (JSON: row_spacing_nm and rows, each a
    /// line object, line name or line file); every row is scanned as a line, and --plot draws
    /// images of height, phase and impacts per period.
    #[arg(long, value_name = "FILE", conflicts_with = "line")]
    pub raster: Option<PathBuf>,
    /// A built-in case or case file: its cantilever, drive and A0 (its sample is replaced by
    /// the line's). Default: maclever-membrane-experiment.
    #[arg(long, value_name = "NAME|FILE", conflicts_with = "cantilever")]
    pub case: Option<String>,
    /// A cantilever (built-in name or file) instead of --case; needs --a0.
    #[arg(long, value_name = "NAME|FILE", requires = "a0")]
    pub cantilever: Option<String>,
    /// Free amplitude A0, nm, in [0.001, 100000] (overrides the case's).
    #[arg(long, value_name = "NM", allow_negative_numbers = true)]
    pub a0: Option<f64>,
    /// Drive frequency, kHz (default: the case's, else f_1).
    #[arg(long, value_name = "KHZ", allow_negative_numbers = true)]
    pub drive_frequency: Option<f64>,
    /// The setpoint A/A0, in (0, 1).
    #[arg(long, default_value_t = 0.8, allow_negative_numbers = true)]
    pub setpoint: f64,
    /// Pixels along the line, in [1, 100000].
    #[arg(long, default_value_t = 64, allow_negative_numbers = true)]
    pub pixels: i64,
    /// The feedback: ideal (steady orbits) or pi (time domain).
    #[arg(long, value_enum, default_value_t = Feedback::Ideal)]
    pub feedback: Feedback,
    /// Trace, retrace, or both (the retrace goes on from the trace's end).
    #[arg(long, value_enum, default_value_t = Direction::Trace)]
    pub direction: Direction,
    /// PI: proportional gain, nm of base per nm of amplitude error, in [0, 100].
    #[arg(long, default_value_t = 0.2, allow_negative_numbers = true)]
    pub gain_p: f64,
    /// PI: integral gain, 1/ms (nm/ms of base per nm of error), in [0, 10000].
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub gain_i: f64,
    /// PI: the tip's speed along the line, nm/s, in (0, 1e9]; at least one drive cycle per
    /// pixel.
    #[arg(
        long,
        value_name = "NM_PER_S",
        default_value_t = 100.0,
        allow_negative_numbers = true
    )]
    pub scan_rate: f64,
    /// PI: the lock-in's output time constant, ms, in [0, 10000] (0: each cycle's reading).
    #[arg(
        long,
        value_name = "MS",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub lockin_time_constant: f64,
    /// The harmonics n = 1..N of u per pixel, N in [1, 20].
    #[arg(long, default_value_t = crate::approach::DEFAULT_HARMONICS, allow_negative_numbers = true)]
    pub harmonics: i64,
    /// Print one JSON object `{"inputs", "line", "pixels"}` instead of CSV.
    #[arg(long)]
    pub json: bool,
    /// Write the output to FILE (atomically) instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Draw the profiles (true and measured height, phase, impacts per period, peak force vs
    /// x; trace and retrace) into this file (.svg, .png or .pdf).
    #[arg(long, value_name = "FILE.svg|png|pdf")]
    pub plot: Option<PathBuf>,
}

impl ScanArgs {
    /// The case: `--case` (default maclever-membrane-experiment) or `--cantilever` with
    /// `--a0`, overrides applied; its sample is the line's first material.
    pub fn case(&self, line: &ScanLine) -> Result<Case> {
        check_overrides(self.a0, self.drive_frequency)?;
        let mut case = match &self.cantilever {
            Some(reference) => {
                let a0 = self.a0.unwrap_or(1.0);
                let mut case = case_of(cantilever_of(reference)?, line.materials[0].clone(), a0);
                case.name = format!("{}-{}", case.cantilever.name, line.name);
                case
            }
            None => named_case(
                self.case.as_deref().unwrap_or(DEFAULT_CASE),
                self.drive_frequency.is_some(),
            )?,
        };
        case.sample = line.materials[0].clone();
        apply_overrides(case, self.a0, self.drive_frequency)
    }

    /// The scan settings, every option checked.
    pub fn settings(&self) -> Result<ScanSettings> {
        OptionRange::new(
            "--setpoint",
            Interval {
                min_inclusive: false,
                ..Interval::right_open(0.0, 1.0, "")
            },
        )
        .check(self.setpoint)?;
        let pixels = OptionRange::new("--pixels", Interval::closed(1.0, MAX_PIXELS as f64, ""))
            .count(self.pixels)?;
        let harmonics = OptionRange::new(
            "--harmonics",
            Interval::closed(1.0, afm::orbit::lockin::MAX_LOCKIN_HARMONICS as f64, ""),
        )
        .count(self.harmonics)?;
        let mut settings = ScanSettings::new(self.setpoint, pixels);
        settings.directions = match self.direction {
            Direction::Trace => ScanDirections::Trace,
            Direction::Retrace => ScanDirections::Retrace,
            Direction::Both => ScanDirections::Both,
        };
        settings.orbit.harmonics = harmonics;
        Ok(settings)
    }

    /// The PI settings for `case`, every option checked.
    pub fn pi(&self, case: &Case) -> Result<PiSettings> {
        OptionRange::new("--gain-p", Interval::closed(0.0, 100.0, "nm/nm")).check(self.gain_p)?;
        OptionRange::new("--gain-i", Interval::closed(0.0, 1e4, "1/ms")).check(self.gain_i)?;
        OptionRange::new("--scan-rate", Interval::positive(1e9, "nm/s")).check(self.scan_rate)?;
        OptionRange::new("--lockin-time-constant", Interval::closed(0.0, 1e4, "ms"))
            .check(self.lockin_time_constant)?;
        let mut pi = PiSettings::for_case(case)?;
        pi.gain_p = self.gain_p;
        pi.gain_i_per_ms = self.gain_i;
        pi.scan_rate_nm_per_s = self.scan_rate;
        pi.lockin_time_constant_ms = self.lockin_time_constant;
        Ok(pi)
    }
}

/// The JSON object of one pixel (docs/output-schema.md): [`ScanPixel`]'s fields with `jump`
/// split into `jumped` and `jump_from_z_nm`.
pub fn pixel_json(pixel: &ScanPixel) -> Value {
    let mut value = serde_json::to_value(pixel).unwrap_or(Value::Null);
    value["jumped"] = json!(pixel.jump.is_some());
    value["jump_from_z_nm"] = json!(pixel.jump.map(|j| j.from_z_nm));
    value
}

/// The CSV text: a header (`direction`, [`CSV_COLUMNS`], harmonic columns) and one row per
/// pixel.
pub fn scan_csv(pixels: &[ScanPixel], harmonics: usize) -> String {
    let mut text = String::from("direction,");
    text.push_str(&CSV_COLUMNS.join(","));
    text.push_str(&crate::output::harmonic_columns(harmonics));
    text.push('\n');
    for pixel in pixels {
        let mut row = String::new();
        push_csv_row(
            &mut row,
            pixel.direction.name(),
            &pixel_json(pixel),
            CSV_COLUMNS,
        );
        row.pop();
        for harmonic in &pixel.harmonics {
            row.push_str(&format!(
                ",{},{}",
                harmonic.amplitude_nm, harmonic.phase_deg
            ));
        }
        row.push('\n');
        text.push_str(&row);
    }
    text
}

/// The `line` object of the JSON output: the line as resolved.
pub fn line_json(line: &ScanLine) -> Value {
    json!({
        "name": line.name,
        "description": line.description,
        "edge_width_nm": line.edge_width_nm,
        "segments": line.segments.iter().map(|s| json!({
            "from_nm": s.from_nm,
            "to_nm": s.to_nm,
            "height_nm": s.height_nm,
            "sample": line.materials[s.material].name,
        })).collect::<Vec<_>>(),
        "materials": line.materials,
    })
}

/// A PI setting's error named by the option that sets it (`--scan-rate 1e9: allowed ...`), as
/// every other option's is; other errors as they are.
fn pi_option_error(error: afm::AfmError) -> anyhow::Error {
    if let afm::AfmError::InvalidField {
        file,
        field,
        value,
        allowed,
    } = &error
    {
        let option = match field.as_str() {
            "gain_p" => Some("--gain-p"),
            "gain_i_per_ms" => Some("--gain-i"),
            "scan_rate_nm_per_s" => Some("--scan-rate"),
            "lockin_time_constant_ms" => Some("--lockin-time-constant"),
            _ => None,
        };
        if let (Some(option), "PI settings") = (option, file.as_str()) {
            return anyhow::anyhow!("{option} {value}: allowed {allowed}");
        }
    }
    error.into()
}

/// The pixels of the scan of `line` with the cantilever, drive and A0 of `case`, `settings`
/// and the PI options of `args`, and the `inputs` object of the output; `progress` is told
/// the pixels done after each and stops the scan by answering `true`. Shared with the Python
/// module's `Case.scan`.
pub fn scan_pixels(
    args: &ScanArgs,
    case: &Case,
    line: &ScanLine,
    settings: &ScanSettings,
    progress: &mut dyn FnMut(usize) -> bool,
) -> Result<ScannedLine> {
    let model = TappingModel::from_case(case)?;
    let (pixels, integration, feedback_options) = match args.feedback {
        Feedback::Ideal => (
            ideal_scan_until(case, line, settings, progress)?,
            settings.orbit.integration.clone(),
            json!({ "feedback": "ideal" }),
        ),
        Feedback::Pi => {
            let pi = args.pi(case)?;
            let pixels =
                pi_scan_until(case, line, settings, &pi, progress).map_err(pi_option_error)?;
            (
                pixels,
                pi.integration.clone(),
                json!({
                    "feedback": "pi",
                    "gain_p": pi.gain_p,
                    "gain_i_per_ms": pi.gain_i_per_ms,
                    "scan_rate_nm_per_s": pi.scan_rate_nm_per_s,
                    "lockin_time_constant_ms": pi.lockin_time_constant_ms,
                }),
            )
        }
    };
    let mut options = json!({
        "line": args.line,
        "setpoint": settings.setpoint,
        "pixels": settings.pixels,
        "direction": format!("{:?}", args.direction).to_lowercase(),
        "harmonics": settings.orbit.harmonics,
    });
    if let (Some(options), Some(extra)) = (options.as_object_mut(), feedback_options.as_object()) {
        options.extend(extra.clone());
    }
    let mut orbit_settings = settings.orbit.clone();
    orbit_settings.integration = integration;
    let inputs = orbit_inputs_json("scan", options, case, &model, &orbit_settings);
    Ok((pixels, inputs))
}

/// Run `drumroll scan`.
pub fn run(args: &ScanArgs) -> Result<()> {
    let plot_path = args
        .plot
        .as_ref()
        .map(|p| FigureFile::new(p, "--plot"))
        .transpose()?;
    if let Some(path) = &args.out {
        check_writable(path, "--out")?;
    }
    if let Some(raster) = &args.raster {
        return run_raster(args, raster, plot_path);
    }
    let line = ScanLine::find(&args.line).with_context(|| format!("--line {}", args.line))?;
    let case = args.case(&line)?;
    let settings = args.settings()?;
    let total = (settings.pixels * settings.directions.passes().len()) as u64;
    let mut progress = Progress::new(
        total,
        "{wide_bar} {human_pos}/{human_len} pixels, {eta} left",
    );
    let (pixels, inputs) = scan_pixels(args, &case, &line, &settings, &mut |done| {
        progress.update(done as u64, String::new);
        false
    })?;
    progress.finish();
    let text = if args.json {
        let value = json!({
            "inputs": inputs,
            "line": line_json(&line),
            "pixels": pixels.iter().map(pixel_json).collect::<Vec<_>>(),
        });
        format!("{}\n", serde_json::to_string(&value)?)
    } else {
        scan_csv(&pixels, settings.orbit.harmonics)
    };
    match &args.out {
        Some(path) => {
            write_atomically(path, text.as_bytes())?;
            note(&format!("pixels: {}", path.display()));
        }
        None => print_stdout(&text)?,
    }
    let jumps = pixels.iter().filter(|p| p.jump.is_some()).count();
    if jumps > 0 {
        note(&format!(
            "the feedback jumped between branches at {jumps} pixel(s) (column `jumped`)"
        ));
    }
    if let Some(path) = plot_path {
        let panels = scan_panels(&line.name, &pixels);
        path.write(&render_svg(&panels, panels.len(), 1, (720, 220))?)?;
        note(&format!("figure: {}", path.path.display()));
    }
    if pixels.is_empty() {
        bail!("the scan produced no pixels");
    }
    Ok(())
}

/// One line's pixels and the `inputs` object of its output ([`scan_pixels`]).
pub type ScannedLine = (Vec<ScanPixel>, Value);

/// The rows of `raster` (named `source` in errors) each scanned as a line with the case `case`
/// and `settings` (as [`scan_pixels`]), their pixels in row order, with the `inputs` object of
/// the last row. `pixels_done(n)` is told of every `n` pixels finished, from any row's thread;
/// answering `true` stops the scan (the rows end with `Interrupted`).
///
/// The rows are independent (each is scanned from the case's own start, MODEL.md section 12),
/// so they are scanned in parallel on rayon's pool (`RAYON_NUM_THREADS`, else one thread per
/// core); their pixels are kept in row order, so the result is the same on any number of
/// threads. The first failing row in row order is the error, named (`row J of SOURCE`; rows
/// after a failed one are not started). Shared with the Python module's `Case.scan`.
pub fn scan_raster(
    args: &ScanArgs,
    case: &Case,
    raster: &ScanRaster,
    source: &str,
    settings: &ScanSettings,
    pixels_done: &(dyn Fn(u64) -> bool + Sync),
) -> Result<(Vec<Vec<ScanPixel>>, Value)> {
    let first_failed = AtomicUsize::new(usize::MAX);
    let scanned: Vec<Option<Result<ScannedLine>>> = raster
        .rows
        .par_iter()
        .enumerate()
        .map(|(row, line)| {
            if row > first_failed.load(Ordering::Relaxed) {
                return None;
            }
            let mut row_done = 0;
            let result = scan_pixels(args, case, line, settings, &mut |done| {
                let added = done.saturating_sub(row_done) as u64;
                row_done = row_done.max(done);
                pixels_done(added)
            })
            .with_context(|| format!("row {row} of {source}"));
            if result.is_err() {
                first_failed.fetch_min(row, Ordering::Relaxed);
            }
            Some(result)
        })
        .collect();
    let mut rows: Vec<Vec<ScanPixel>> = Vec::with_capacity(raster.rows.len());
    let mut inputs = Value::Null;
    for result in scanned.into_iter().flatten() {
        let (pixels, row_inputs) = result?;
        rows.push(pixels);
        inputs = row_inputs;
    }
    Ok((rows, inputs))
}

/// The `raster` object of `drumroll scan --raster --json` (docs/output-schema.md).
pub fn raster_json(raster: &ScanRaster) -> Value {
    json!({
        "name": raster.name,
        "description": raster.description,
        "row_spacing_nm": raster.row_spacing_nm,
        "rows": raster.rows.iter().map(line_json).collect::<Vec<_>>(),
    })
}

/// A raster pixel's JSON object: [`pixel_json`] with its `row` and `y_nm` (nm).
pub fn raster_pixel_json(raster: &ScanRaster, row: usize, pixel: &ScanPixel) -> Value {
    let mut value = pixel_json(pixel);
    value["row"] = json!(row);
    value["y_nm"] = json!(row as f64 * raster.row_spacing_nm);
    value
}

/// `drumroll scan --raster FILE`: every row scanned as a line (the case and settings of the
/// first row; [`scan_raster`]), the pixels tagged with `row` and `y_nm`; `--plot` draws the
/// trace's images.
fn run_raster(args: &ScanArgs, path: &Path, plot_path: Option<FigureFile>) -> Result<()> {
    let raster = ScanRaster::load(path).with_context(|| format!("--raster {}", path.display()))?;
    let case = args.case(&raster.rows[0])?;
    let settings = args.settings()?;
    let total = (settings.pixels * settings.directions.passes().len() * raster.rows.len()) as u64;
    // The bar and the pixels done in all rows, moved together.
    let progress = Mutex::new((
        Progress::new(
            total,
            "{wide_bar} {human_pos}/{human_len} pixels, {eta} left",
        ),
        0u64,
    ));
    let source = format!("--raster {}", path.display());
    let (rows, mut inputs) = scan_raster(args, &case, &raster, &source, &settings, &|added| {
        if let Ok(mut guard) = progress.lock() {
            let (bar, pixels_done) = &mut *guard;
            *pixels_done += added;
            bar.update(*pixels_done, String::new);
        }
        false
    })?;
    if let Ok((bar, _)) = progress.into_inner() {
        bar.finish();
    }
    inputs["options"]["raster"] = json!(path.display().to_string());
    let tagged = |row: usize, pixel: &ScanPixel| raster_pixel_json(&raster, row, pixel);
    let text = if args.json {
        let value = json!({
            "inputs": inputs,
            "raster": raster_json(&raster),
            "pixels": rows.iter().enumerate().flat_map(|(j, row)| row.iter().map(move |p| (j, p)))
                .map(|(j, p)| tagged(j, p)).collect::<Vec<_>>(),
        });
        format!("{}\n", serde_json::to_string(&value)?)
    } else {
        let mut columns = vec!["row", "y_nm"];
        columns.extend(CSV_COLUMNS);
        let mut text = String::from("direction,");
        text.push_str(&columns.join(","));
        text.push_str(&crate::output::harmonic_columns(settings.orbit.harmonics));
        text.push('\n');
        for (j, row) in rows.iter().enumerate() {
            for pixel in row {
                let mut line = String::new();
                push_csv_row(
                    &mut line,
                    pixel.direction.name(),
                    &tagged(j, pixel),
                    &columns,
                );
                line.pop();
                for harmonic in &pixel.harmonics {
                    line.push_str(&format!(
                        ",{},{}",
                        harmonic.amplitude_nm, harmonic.phase_deg
                    ));
                }
                line.push('\n');
                text.push_str(&line);
            }
        }
        text
    };
    match &args.out {
        Some(out) => {
            write_atomically(out, text.as_bytes())?;
            note(&format!("pixels: {}", out.display()));
        }
        None => print_stdout(&text)?,
    }
    if let Some(figure) = plot_path {
        let map = |title: &str, value: fn(&ScanPixel) -> f64| ImageMap {
            title: title.to_string(),
            values: rows
                .iter()
                .map(|row| {
                    let mut values = vec![f64::NAN; settings.pixels];
                    // The first pass of each row (the trace unless only retrace is asked).
                    let first = row.first().map(|p| p.direction);
                    for pixel in row.iter().filter(|p| Some(p.direction) == first) {
                        values[pixel.index] = value(pixel);
                    }
                    values
                })
                .collect(),
        };
        let maps = [
            map("measured height (nm)", |p| p.height_nm),
            map("phase (deg)", |p| p.phase_deg),
            map("impacts per period", |p| p.impacts_per_period),
        ];
        // Physical proportions: the longer side 360 SVG pixels.
        let first = &raster.rows[0];
        let pixel_width = (first.end_nm() - first.start_nm()) / settings.pixels as f64;
        let extent = (first.end_nm() - first.start_nm())
            .max(raster.rows.len() as f64 * raster.row_spacing_nm);
        let scale = 360.0 / extent;
        let cell = (pixel_width * scale, raster.row_spacing_nm * scale);
        figure.write(&image_maps_svg(&raster.name, &maps, cell))?;
        note(&format!("images: {}", figure.path.display()));
    }
    Ok(())
}
