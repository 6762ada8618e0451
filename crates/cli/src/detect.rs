//! `drumroll detect`: the transitions (kinks and jumps) of a measured approach curve with their
//! Z, 1-sigma uncertainty, A/A0, phase and significance (MODEL.md section 13.2).

use afm::fit::measurement::Measurement;
use afm::fit::transitions::{detect_transitions, Detection, DetectionSettings, MIN_HALF_WINDOW};
use afm::validation::Interval;
use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::{json, Value};

use crate::measurement_args::MeasurementArgs;
use crate::option_ranges::OptionRange;
use crate::output::print_stdout;

/// Options of `drumroll detect`.
#[derive(Debug, Clone, Args)]
pub struct DetectArgs {
    /// The measured curve and how to read it.
    #[command(flatten)]
    pub measurement: MeasurementArgs,
    /// The free amplitude as measured, nm (default: the mean of the free rows far from the
    /// sample).
    #[arg(long)]
    pub a0: Option<f64>,
    /// Family-wise false-alarm probability on a smooth curve, in (0, 0.5].
    #[arg(long, default_value_t = 0.01)]
    pub significance: f64,
    /// Rows on each side of a test window (0: n/25 clamped to 12..80), 0 or at least 12.
    #[arg(long, default_value_t = 0)]
    pub window: usize,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// The JSON of `drumroll detect --json` (docs/output-schema.md): `A0`, the noise, the test
/// counts and threshold, the bad rows and the transitions.
pub fn detect_json(measurement: &Measurement, detection: &Detection, significance: f64) -> Value {
    json!({
        "a0_nm": detection.a0_nm,
        "a0_stderr_nm": measurement.a0_stderr_nm,
        "noise": detection.noise,
        "significance_level": significance,
        "tests": detection.tests,
        "threshold": detection.threshold,
        "half_window": detection.half_window,
        "rows": measurement.approach.len(),
        "bad_rows": measurement.bad_rows,
        "transitions": detection.transitions,
    })
}

/// The most rows on each side of a test window `--window` takes.
pub const MAX_WINDOW: usize = 100_000;

/// The detection settings of `--significance` and `--window`, checked (errors name the
/// option and its allowed range).
///
/// # Errors
/// A significance outside `(0, 0.5]`, a window from 1 to 11 or above [`MAX_WINDOW`].
pub fn detection_settings(args: &DetectArgs) -> Result<DetectionSettings> {
    OptionRange::new("--significance", Interval::left_open(0.0, 0.5, ""))
        .check(args.significance)?;
    if args.window != 0 && !(MIN_HALF_WINDOW..=MAX_WINDOW).contains(&args.window) {
        bail!(
            "--window {}: allowed: 0 (automatic) or {MIN_HALF_WINDOW} to {MAX_WINDOW} rows",
            args.window
        );
    }
    Ok(DetectionSettings {
        significance: args.significance,
        half_window: args.window,
    })
}

/// Run `drumroll detect`.
///
/// # Errors
/// A bad file or option.
pub fn run(args: &DetectArgs) -> Result<()> {
    let settings = detection_settings(args)?;
    let measurement = args.measurement.read(args.a0)?;
    let detection = detect_transitions(&measurement.approach, measurement.a0_nm, &settings)
        .with_context(|| format!("--data {}", args.measurement.data))?;
    if args.json {
        let object = detect_json(&measurement, &detection, args.significance);
        print_stdout(&format!("{}\n", serde_json::to_string_pretty(&object)?))?;
    } else {
        let mut text = format!(
            "{}: {} approach rows, A0 = {:.4} nm, noise {:.3} nm and {:.3} deg; {} transitions at false-alarm level {}\n",
            measurement.source,
            measurement.approach.len(),
            detection.a0_nm,
            detection.noise.amplitude_nm,
            detection.noise.phase_deg,
            detection.transitions.len(),
            args.significance
        );
        text.push_str("  kind   z_nm        +-sigma_nm  A/A0     phase_deg  p\n");
        for t in &detection.transitions {
            text.push_str(&format!(
                "  {:<6} {:<11.4} {:<11.4} {:<8.4} {:<10.3} {:.1e}\n",
                match t.kind {
                    afm::fit::transitions::TransitionKind::Kink => "kink",
                    afm::fit::transitions::TransitionKind::Jump => "jump",
                },
                t.z_nm,
                t.z_uncertainty_nm,
                t.amplitude_ratio,
                t.phase_deg,
                t.significance
            ));
        }
        print_stdout(&text)?;
    }
    Ok(())
}
