//! The command-line options that choose the cantilever, sample and drive: a built-in or file
//! case, or a cantilever file and a sample file with a free amplitude.

use afm::{fixtures, Case, TappingModel};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};

use crate::option_ranges;

/// Which cantilever taps which sample, and how it is driven.
#[derive(Debug, Clone, Args)]
pub struct ModelArgs {
    /// A built-in case (`biolever-mica`, `biolever-soft`, `maclever-mica`, `maclever-soft`,
    /// `maclever-mica-experiment`, ...) or the path of a case file (JSON); `drumroll cases`
    /// lists them. `continue` takes several (`--case A --case B`, one panel each).
    #[arg(long, conflicts_with_all = ["cantilever", "sample"], action = clap::ArgAction::Append)]
    pub case: Vec<String>,
    /// A cantilever file (JSON) or built-in cantilever name, used with `--sample` and `--a0`
    /// instead of `--case`.
    #[arg(long, requires_all = ["sample", "a0"])]
    pub cantilever: Option<String>,
    /// A sample file (JSON) or built-in sample name (`mica`, `soft`, `purple-membrane`).
    #[arg(long, requires = "cantilever")]
    pub sample: Option<String>,
    /// Free amplitude A0 of the photodiode signal u, nm (MODEL.md section 3), in
    /// [0.001, 100000] nm (typical 0.1 to 1000 nm). With `--case` it overrides the case's value.
    #[arg(long, allow_negative_numbers = true)]
    pub a0: Option<f64>,
    /// Drive frequency, kHz (default: the case's, else the fundamental f_1), in [0.01, 1000000]
    /// kHz (typical 0.1 to 100000 kHz) and, in every command, from f_1/100 to 100 times the
    /// cantilever's highest modal frequency; a drive over ten times away from every mode is
    /// warned about.
    #[arg(long, allow_negative_numbers = true)]
    pub drive_frequency: Option<f64>,
}

impl ModelArgs {
    /// The resolved case (`biolever-mica` when nothing is given), every option and file
    /// checked (errors name the option or the file and field, and the allowed range; valid but
    /// implausible values are warned about on stderr); an error when `--case` is given more
    /// than once.
    pub fn case(&self) -> Result<Case> {
        if self.case.len() > 1 {
            bail!(
                "--case given {} times: only `drumroll continue` draws several cases",
                self.case.len()
            );
        }
        self.check_overrides()?;
        self.resolve(self.case.first().map(String::as_str))
    }

    /// Every case given (`--case` repeated), in order, each with the `--a0` and
    /// `--drive-frequency` overrides and checked as [`ModelArgs::case`]; the single resolved
    /// case otherwise.
    pub fn cases(&self) -> Result<Vec<Case>> {
        if self.case.len() <= 1 {
            return Ok(vec![self.case()?]);
        }
        self.check_overrides()?;
        self.case
            .iter()
            .map(|name| self.resolve(Some(name)))
            .collect()
    }

    /// Check `--a0` and `--drive-frequency` against the option range table.
    fn check_overrides(&self) -> Result<()> {
        if let Some(a0) = self.a0 {
            option_ranges::A0.check(a0)?;
        }
        if let Some(frequency) = self.drive_frequency {
            // The warning, if any, comes with the cantilever's range in `resolve`.
            option_ranges::DRIVE_FREQUENCY.warning(frequency)?;
        }
        Ok(())
    }

    /// The case named `name` (or built from `--cantilever` and `--sample`), overrides applied
    /// and checked.
    fn resolve(&self, name: Option<&str>) -> Result<Case> {
        let mut case = match (name, &self.cantilever, &self.sample) {
            (Some(name), None, None) => {
                let case = fixtures::find_case(name)?;
                warn_all(case.warnings(name));
                if self.drive_frequency.is_none() {
                    // The case's own drive against its cantilever's range, blamed on the case
                    // (an override is checked below, on the command line's account).
                    case.validate(name).context("invalid model parameters")?;
                }
                case
            }
            (None, Some(cantilever), Some(sample)) => {
                let Some(a0) = self.a0 else {
                    bail!("--cantilever and --sample need --a0 (the free amplitude, nm)");
                };
                let cantilever_model = if is_file_reference(cantilever) {
                    fixtures::load_cantilever(Path::new(cantilever))?
                } else {
                    fixtures::builtin_cantilever(cantilever)?
                };
                warn_all(cantilever_model.warnings(cantilever));
                let sample_model = if is_file_reference(sample) {
                    fixtures::load_sample(Path::new(sample))?
                } else {
                    fixtures::builtin_sample(sample)?
                };
                warn_all(sample_model.warnings(sample));
                Case {
                    name: format!("{}-{}", cantilever_model.name, sample_model.name),
                    description: String::from("from the command line"),
                    cantilever: cantilever_model,
                    sample: sample_model,
                    free_amplitude_nm: a0,
                    drive_frequency_khz: None,
                    drive: afm::model::drive_spec::DriveSpec::Direct,
                }
            }
            (None, None, None) => fixtures::builtin_case(DEFAULT_CASE)?,
            _ => bail!("give either --case, or --cantilever with --sample and --a0"),
        };
        if let Some(a0) = self.a0 {
            case.free_amplitude_nm = a0;
        }
        if let Some(frequency) = self.drive_frequency {
            option_ranges::drive_frequency_for(&case.cantilever).check(frequency)?;
            case.drive_frequency_khz = Some(frequency);
            if let Some(warning) = case.drive_warning() {
                eprintln!("drumroll: warning: --drive-frequency {warning}");
            }
        }
        case.validate("the command line")
            .context("invalid model parameters")?;
        Ok(case)
    }

    /// The tapping model of the resolved case, at first contact `Z = Z_G1`.
    pub fn model(&self) -> Result<(Case, TappingModel)> {
        model_of(self.case()?)
    }
}

/// The tapping model of `case`, at first contact `Z = Z_G1`.
pub fn model_of(case: Case) -> Result<(Case, TappingModel)> {
    let model = TappingModel::from_case(&case)
        .with_context(|| format!("cannot build the model of case `{}`", case.name))?;
    Ok((case, model))
}

/// Print each warning on stderr.
fn warn_all(warnings: Vec<String>) {
    for warning in warnings {
        eprintln!("drumroll: warning: {warning}");
    }
}

/// Whether a command-line reference names a file (it ends in `.json` or exists) rather than a
/// built-in fixture.
fn is_file_reference(reference: &str) -> bool {
    let path = Path::new(reference);
    path.extension().is_some_and(|e| e == "json") || path.exists()
}

/// The case used when none is named.
pub const DEFAULT_CASE: &str = "biolever-mica";

/// A path for an output file, checked to have the expected extension and to be writable
/// (before any computation: [`crate::output::check_writable`]).
pub fn output_path(path: &Path, extension: &str, option: &str) -> Result<PathBuf> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case(extension) => {
            crate::output::check_writable(path, option)?;
            Ok(path.to_path_buf())
        }
        _ => bail!(
            "{option} {}: allowed: a file name ending in .{extension}",
            path.display()
        ),
    }
}
