//! The command-line options that choose the cantilever, sample and drive: a built-in or file
//! case, or a cantilever file and a sample file with a free amplitude.

use afm::{fixtures, Case, TappingModel};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};

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
    /// Free amplitude A0 of the photodiode signal u, nm (MODEL.md section 3). With `--case`
    /// it overrides the case's value.
    #[arg(long, allow_negative_numbers = true)]
    pub a0: Option<f64>,
    /// Drive frequency, kHz (default: the case's, else the fundamental f_1).
    #[arg(long, allow_negative_numbers = true)]
    pub drive_frequency: Option<f64>,
}

impl ModelArgs {
    /// The resolved case (`biolever-mica` when nothing is given); an error when `--case` is
    /// given more than once.
    pub fn case(&self) -> Result<Case> {
        if self.case.len() > 1 {
            bail!(
                "--case given {} times: only `drumroll continue` draws several cases",
                self.case.len()
            );
        }
        self.resolve(self.case.first().map(String::as_str))
    }

    /// Every case given (`--case` repeated), in order, each with the `--a0` and
    /// `--drive-frequency` overrides; the single resolved case otherwise.
    pub fn cases(&self) -> Result<Vec<Case>> {
        if self.case.len() <= 1 {
            return Ok(vec![self.case()?]);
        }
        self.case
            .iter()
            .map(|name| self.resolve(Some(name)))
            .collect()
    }

    /// The case named `name` (or built from `--cantilever` and `--sample`), overrides applied.
    fn resolve(&self, name: Option<&str>) -> Result<Case> {
        let mut case = match (name, &self.cantilever, &self.sample) {
            (Some(name), None, None) => fixtures::find_case(name)?,
            (None, Some(cantilever), Some(sample)) => {
                let Some(a0) = self.a0 else {
                    bail!("--cantilever and --sample need --a0 (the free amplitude, nm)");
                };
                let cantilever = if is_file_reference(cantilever) {
                    fixtures::load_cantilever(Path::new(cantilever))?
                } else {
                    fixtures::builtin_cantilever(cantilever)?
                };
                let sample = if is_file_reference(sample) {
                    fixtures::load_sample(Path::new(sample))?
                } else {
                    fixtures::builtin_sample(sample)?
                };
                Case {
                    name: format!("{}-{}", cantilever.name, sample.name),
                    description: String::from("from the command line"),
                    cantilever,
                    sample,
                    free_amplitude_nm: a0,
                    drive_frequency_khz: None,
                }
            }
            (None, None, None) => fixtures::builtin_case(DEFAULT_CASE)?,
            _ => bail!("give either --case, or --cantilever with --sample and --a0"),
        };
        if let Some(a0) = self.a0 {
            case.free_amplitude_nm = a0;
        }
        if let Some(frequency) = self.drive_frequency {
            case.drive_frequency_khz = Some(frequency);
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

/// Whether a command-line reference names a file (it ends in `.json` or exists) rather than a
/// built-in fixture.
fn is_file_reference(reference: &str) -> bool {
    let path = Path::new(reference);
    path.extension().is_some_and(|e| e == "json") || path.exists()
}

/// The case used when none is named.
pub const DEFAULT_CASE: &str = "biolever-mica";

/// A path for an output file, checked to have the expected extension.
pub fn output_path(path: &Path, extension: &str, option: &str) -> Result<PathBuf> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case(extension) => Ok(path.to_path_buf()),
        _ => bail!(
            "{option} {}: the file name must end in .{extension}",
            path.display()
        ),
    }
}
