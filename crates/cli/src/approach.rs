//! `drumroll approach`: a time-domain approach (and retract) sweep at a constant rate, read by
//! a lock-in amplifier once per block of drive cycles, as in the paper's simulations and in
//! every experiment. The records stream out as they are computed (CSV or JSON Lines).

use afm::sweep::{MAX_CYCLE_COUNT, MAX_SEPARATION_NM};
use afm::validation::Interval;
use afm::{Sweep, SweepDirection, SweepRecord, SweepSettings, TappingModel};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;
use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::exit_status::Incomplete;
use crate::inputs::inputs_json;
use crate::model_args::ModelArgs;
use crate::option_ranges::{self, OptionRange};
use crate::output::{check_writable, harmonic_columns, StreamedFile};
use crate::plot::{render_svg, FigureFile, Panel, Series, Stroke, PHASE_PERIOD_DEG};
use crate::progress::{note, Progress};

/// The CSV header: the JSON Lines records' scalar keys, in their order (docs/output-schema.md);
/// the harmonic columns ([`harmonic_columns`]) follow.
pub const CSV_HEADER: &str =
    "cycle,z_nm,amplitude_ratio,phase_deg,impacts_per_period,peak_force_nn,dissipated_ev,direction";

/// The harmonics each reading gives by default (`--harmonics`).
pub const DEFAULT_HARMONICS: i64 = afm::orbit::lockin::DEFAULT_HARMONICS as i64;

/// Progress bar updates: at most one per this many cycles (indicatif also limits redraws).
const PROGRESS_STRIDE: u64 = 256;

/// Options of `drumroll approach`.
#[derive(Debug, Clone, Args)]
pub struct ApproachArgs {
    /// The cantilever, sample and drive.
    #[command(flatten)]
    pub model: ModelArgs,
    /// Separation at the start of the approach, nm, in (--to, 1e5]. The cantilever starts
    /// from the free steady state there and settles for --settle-cycles cycles. Default: 0.2 nm
    /// above first contact Z_G1.
    #[arg(long, allow_negative_numbers = true, value_name = "NM")]
    pub from: Option<f64>,
    /// The floor: separation at the end of the approach, nm, in [0, 100000] nm and below
    /// --from. Default 0.
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "NM",
        default_value_t = 0.0
    )]
    pub to: f64,
    /// Sweep speed |dZ/dt|, nm/s, in (0, 1000000] nm/s (typical 0.001 to 100000 nm/s). The
    /// paper's simulations use 1 nm/s.
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "NM_PER_S",
        default_value_t = 1.0
    )]
    pub rate: f64,
    /// After the approach, retract from the floor back up to --from at the same rate (rows
    /// labelled `retract`), so that approach/retract hysteresis shows.
    #[arg(long)]
    pub retract: bool,
    /// Drive cycles per lock-in reading: each record averages the Fourier coefficients of u
    /// over this many consecutive, non-overlapping cycles (an integration time of N periods);
    /// impacts are then per cycle, averaged; the peak force is the block's maximum.
    /// In [1, 100000000].
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1,
        allow_negative_numbers = true
    )]
    pub lockin_cycles: i64,
    /// Output every N-th lock-in reading of each direction (the first included). In
    /// [1, 100000000].
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1,
        allow_negative_numbers = true
    )]
    pub every: i64,
    /// Drive cycles integrated at --from before the sweep starts (not reported). In
    /// [0, 100000000].
    #[arg(
        long,
        value_name = "N",
        default_value_t = 20,
        allow_negative_numbers = true
    )]
    pub settle_cycles: i64,
    /// Relative and absolute tolerance of the contact integration (nm, nm/us), in
    /// [1e-14, 0.0001]. Free flight is exact regardless.
    #[arg(
        long,
        value_name = "TOL",
        default_value_t = afm::sweep::DEFAULT_TOLERANCE,
        allow_negative_numbers = true
    )]
    pub tolerance: f64,
    /// The harmonics n = 1..N of u each reading gives (amplitude and phase of the block's
    /// lock-in at n times the drive frequency), N in [1, 20].
    #[arg(long, default_value_t = DEFAULT_HARMONICS, allow_negative_numbers = true)]
    pub harmonics: i64,
    /// Write JSON Lines (one object per reading) instead of CSV.
    #[arg(long)]
    pub jsonl: bool,
    /// Write the records to FILE instead of standard output. FILE is written while the sweep
    /// runs, one complete record per write, flushed at once: an interrupted run leaves every
    /// record computed so far, and never half a record.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Draw phase vs A/A0 and A/A0 vs Z (approach and retract in two colours) into this file
    /// when the sweep ends (written atomically; .svg, .png or .pdf by the extension; thinned to
    /// one point per pixel, so the file stays small however long the sweep).
    #[arg(long, value_name = "FILE.svg|png|pdf")]
    pub plot: Option<PathBuf>,
}

impl ApproachArgs {
    /// The sweep settings for `model`, every option checked (errors name the option and its
    /// allowed range).
    pub fn settings(&self, model: &TappingModel) -> Result<SweepSettings> {
        let mut settings = SweepSettings::for_model(model);
        option_ranges::RATE.check(self.rate)?;
        option_ranges::TO.check(self.to)?;
        let from = self.from.unwrap_or(settings.from_nm);
        OptionRange::new(
            "--from",
            Interval::left_open(self.to, MAX_SEPARATION_NM, "nm (above --to)"),
        )
        .check(from)?;
        let lockin_cycles = option_ranges::LOCKIN_CYCLES.count(self.lockin_cycles)?;
        let harmonics = option_ranges::LOCKIN_HARMONICS.count(self.harmonics)?;
        let every = option_ranges::EVERY.count(self.every)?;
        let settle_cycles = option_ranges::SETTLE_CYCLES.count(self.settle_cycles)?;
        option_ranges::TOLERANCE.check(self.tolerance)?;
        let cycle_travel = self.rate * 1e-6 * model.period_us();
        if from - self.to < cycle_travel {
            bail!(
                "--from {from} --to {}: the sweep must span at least one drive cycle's travel \
                 ({cycle_travel:e} nm at --rate {} nm/s)",
                self.to,
                self.rate
            );
        }
        let cycles = (from - self.to) / cycle_travel;
        if cycles > MAX_CYCLE_COUNT as f64 {
            bail!(
                "--from {from} --to {} at --rate {} nm/s: {cycles:.3e} drive cycles in each \
                 direction, allowed at most {MAX_CYCLE_COUNT:e} (tens of microseconds each: \
                 {MAX_CYCLE_COUNT:e} take over an hour); raise --rate or narrow --from/--to",
                self.to,
                self.rate
            );
        }
        settings.from_nm = from;
        settings.to_nm = self.to;
        settings.rate_nm_per_s = self.rate;
        settings.retract = self.retract;
        settings.settle_cycles = settle_cycles;
        settings.lockin_cycles = lockin_cycles;
        settings.every = every;
        settings.harmonics = harmonics;
        settings.integration.relative_tolerance = self.tolerance;
        settings.integration.absolute_tolerance = self.tolerance;
        settings.validate().context("invalid sweep settings")?;
        Ok(settings)
    }
}

/// Where the records go: standard output or a file, one complete line per write.
enum RecordSink {
    Stdout(std::io::Stdout),
    File(StreamedFile),
}

impl RecordSink {
    /// Write one line; `Ok(false)` when standard output was closed by its reader (a pipe into
    /// `head`): the sweep then stops quietly.
    fn write_line(&mut self, line: &str) -> Result<bool> {
        match self {
            Self::Stdout(stdout) => {
                let mut lock = stdout.lock();
                match lock.write_all(line.as_bytes()).and_then(|()| lock.flush()) {
                    Ok(()) => Ok(true),
                    Err(error) if error.kind() == std::io::ErrorKind::BrokenPipe => Ok(false),
                    Err(error) => Err(error).context("cannot write to standard output"),
                }
            }
            Self::File(file) => file.write_line(line).map(|()| true),
        }
    }
}

/// Format one record as a CSV line or a JSON Lines object (with the newline) into `line`.
pub fn format_record(record: &SweepRecord, jsonl: bool, line: &mut String) -> Result<()> {
    line.clear();
    if jsonl {
        line.push_str(&serde_json::to_string(record)?);
        line.push('\n');
    } else {
        write!(
            line,
            "{},{},{},{},{},{},{},{}",
            record.cycle,
            record.z_nm,
            record.amplitude_ratio,
            record.phase_deg,
            record.impacts_per_period,
            record.peak_force_nn,
            record.dissipated_ev,
            record.direction.name()
        )?;
        for harmonic in &record.harmonics {
            write!(line, ",{},{}", harmonic.amplitude_nm, harmonic.phase_deg)?;
        }
        line.push('\n');
    }
    Ok(())
}

/// The `inputs` object of an approach sweep (the first line of `--jsonl`): the sweep's
/// settings as options, with the case, model and integration settings (docs/output-schema.md).
pub fn approach_inputs_json(
    case: &afm::Case,
    model: &TappingModel,
    settings: &SweepSettings,
) -> serde_json::Value {
    let options = json!({
        "from_nm": settings.from_nm,
        "to_nm": settings.to_nm,
        "rate_nm_per_s": settings.rate_nm_per_s,
        "retract": settings.retract,
        "settle_cycles": settings.settle_cycles,
        "lockin_cycles": settings.lockin_cycles,
        "every": settings.every,
        "harmonics": settings.harmonics,
    });
    inputs_json("approach", options, case, model, &settings.integration)
}

/// Run `drumroll approach`.
pub fn run(args: &ApproachArgs) -> Result<()> {
    let plot_path = args
        .plot
        .as_ref()
        .map(|p| FigureFile::new(p, "--plot"))
        .transpose()?;
    if let Some(path) = &args.out {
        check_writable(path, "--out")?;
    }
    let (case, model) = args.model.model()?;
    let settings = args.settings(&model)?;
    let first_line = if args.jsonl {
        let inputs = approach_inputs_json(&case, &model, &settings);
        format!("{}\n", json!({ "inputs": inputs }))
    } else {
        format!("{CSV_HEADER}{}\n", harmonic_columns(settings.harmonics))
    };
    let mut sweep = Sweep::new(&model, settings).context("cannot set up the sweep")?;
    let mut sink = match &args.out {
        None => RecordSink::Stdout(std::io::stdout()),
        Some(path) => RecordSink::File(StreamedFile::create(path, "--out")?),
    };
    if !sink.write_line(&first_line)? {
        return Ok(());
    }
    let mut progress = Progress::new(
        sweep.total_cycles(),
        "Z = {msg} nm {wide_bar} {human_pos}/{human_len} cycles, {eta} left",
    );
    let mut kept: Vec<SweepRecord> = Vec::new();
    let mut line = String::with_capacity(160);
    let mut shown = 0;
    loop {
        let record = match sweep.next_record() {
            Ok(Some(record)) => record,
            Ok(None) => break,
            Err(error) => {
                progress.abandon();
                let kept_in = match &sink {
                    RecordSink::Stdout(_) => String::from("written"),
                    RecordSink::File(file) => format!(
                        "in {} (the --out file is written only by a complete sweep)",
                        file.part().display()
                    ),
                };
                return Err(Incomplete(format!(
                    "the sweep of case `{}` failed at Z = {} nm after {} cycles ({error}); the \
                     records before it are {kept_in}",
                    case.name,
                    sweep.z_nm(),
                    sweep.cycles_done()
                ))
                .into());
            }
        };
        format_record(&record, args.jsonl, &mut line)?;
        if !sink.write_line(&line)? {
            progress.finish();
            return Ok(());
        }
        if plot_path.is_some() {
            kept.push(record);
        }
        if sweep.cycles_done() >= shown + PROGRESS_STRIDE {
            shown = sweep.cycles_done();
            progress.update(shown, || format!("{:8.4}", sweep.z_nm()));
        }
    }
    progress.finish();
    if let RecordSink::File(file) = sink {
        file.finish()?;
    }
    if let Some(path) = plot_path {
        let panels = sweep_panels(&case.name, &kept);
        path.write(&render_svg(&panels, 1, 2, (640, 480))?)?;
        note(&format!("figure: {}", path.path.display()));
    }
    if let Some(path) = &args.out {
        note(&format!("records: {}", Path::new(path).display()));
    }
    Ok(())
}

/// The two panels of `--plot`: phase vs A/A0, and A/A0 vs Z; approach and retract as dots of
/// two colours, the retract's smaller and on top so that both show where they coincide.
pub fn sweep_panels(case: &str, records: &[SweepRecord]) -> Vec<Panel> {
    let series =
        |direction: SweepDirection, colour: usize, point: fn(&SweepRecord) -> (f64, f64)| {
            let stroke = match direction {
                SweepDirection::Approach => Stroke::Dots,
                SweepDirection::Retract => Stroke::FineDots,
            };
            let selected: Vec<&SweepRecord> = records
                .iter()
                .filter(|r| r.direction == direction)
                .collect();
            Series {
                label: direction.name().to_string(),
                points: selected.iter().map(|r| point(r)).collect(),
                stroke,
                colour,
            }
        };
    let both = |point: fn(&SweepRecord) -> (f64, f64)| {
        let mut all = vec![series(SweepDirection::Approach, 0, point)];
        let retract = series(SweepDirection::Retract, 1, point);
        if !retract.points.is_empty() {
            all.push(retract);
        }
        all
    };
    vec![
        Panel {
            title: format!("{case}: phase vs amplitude ratio"),
            x_label: String::from("amplitude ratio A/A0"),
            y_label: String::from("phase (deg)"),
            series: both(|r| (r.amplitude_ratio, r.phase_deg)),
            markers: Vec::new(),
            y_period: Some(PHASE_PERIOD_DEG),
            y_integer_ticks: false,
            regions: Vec::new(),
            shaded: Vec::new(),
            cells: Vec::new(),
        },
        Panel {
            title: format!("{case}: amplitude ratio vs separation"),
            x_label: String::from("separation Z (nm)"),
            y_label: String::from("amplitude ratio A/A0"),
            series: both(|r| (r.z_nm, r.amplitude_ratio)),
            markers: Vec::new(),
            y_period: None,
            y_integer_ticks: false,
            regions: Vec::new(),
            shaded: Vec::new(),
            cells: Vec::new(),
        },
    ]
}
