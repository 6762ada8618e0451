//! The command-line options that choose the cantilever, sample and drive: a built-in or file
//! case, or a cantilever file and a sample file with a free amplitude.

use afm::{fixtures, Cantilever, Case, Sample, TappingModel};
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
        check_overrides(self.a0, self.drive_frequency)
    }

    /// The case named `name` (or built from `--cantilever` and `--sample`), overrides applied
    /// and checked.
    fn resolve(&self, name: Option<&str>) -> Result<Case> {
        let case = match (name, &self.cantilever, &self.sample) {
            (Some(name), None, None) => named_case(name, self.drive_frequency.is_some())?,
            (None, Some(cantilever), Some(sample)) => {
                let Some(a0) = self.a0 else {
                    bail!("--cantilever and --sample need --a0 (the free amplitude, nm)");
                };
                case_of(cantilever_of(cantilever)?, sample_of(sample)?, a0)
            }
            (None, None, None) => fixtures::builtin_case(DEFAULT_CASE)?,
            _ => bail!("give either --case, or --cantilever with --sample and --a0"),
        };
        apply_overrides(case, self.a0, self.drive_frequency)
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

/// Check the `--a0` (nm) and `--drive-frequency` (kHz) overrides against the option range
/// table (the drive frequency's range for the cantilever is checked by [`apply_overrides`]).
pub fn check_overrides(a0: Option<f64>, drive_frequency: Option<f64>) -> Result<()> {
    if let Some(a0) = a0 {
        option_ranges::A0.check(a0)?;
    }
    if let Some(frequency) = drive_frequency {
        // The warning, if any, comes with the cantilever's range in `apply_overrides`.
        option_ranges::DRIVE_FREQUENCY.warning(frequency)?;
    }
    Ok(())
}

/// The built-in case or case file `name`, its warnings printed; its own drive frequency is
/// checked against its cantilever's range (blamed on the case) unless `frequency_overridden`
/// (an override is checked by [`apply_overrides`], on the command line's account).
pub fn named_case(name: &str, frequency_overridden: bool) -> Result<Case> {
    let case = fixtures::find_case(name)?;
    warn_all(case.warnings(name));
    if !frequency_overridden {
        case.validate(name).context("invalid model parameters")?;
    }
    Ok(case)
}

/// A cantilever named on the command line: a cantilever file (a path ending in `.json`, or an
/// existing file) or a built-in cantilever; its warnings printed.
pub fn cantilever_of(reference: &str) -> Result<Cantilever> {
    let cantilever = file_or_builtin(
        reference,
        fixtures::load_cantilever,
        fixtures::builtin_cantilever,
    )?;
    warn_all(cantilever.warnings(reference));
    Ok(cantilever)
}

/// A sample named on the command line: a sample file or a built-in sample; its warnings
/// printed.
pub fn sample_of(reference: &str) -> Result<Sample> {
    let sample = file_or_builtin(reference, fixtures::load_sample, fixtures::builtin_sample)?;
    warn_all(sample.warnings(reference));
    Ok(sample)
}

/// `load` the file `reference` names, or else the built-in `builtin(reference)`.
fn file_or_builtin<T>(
    reference: &str,
    load: fn(&Path) -> Result<T, afm::AfmError>,
    builtin: fn(&str) -> Result<T, afm::AfmError>,
) -> Result<T> {
    Ok(if is_file_reference(reference) {
        load(Path::new(reference))?
    } else {
        builtin(reference)?
    })
}

/// The case of `cantilever` tapping `sample` with the free amplitude `a0_nm` (nm), directly
/// driven at the default frequency (MODEL.md section 14), named `CANTILEVER-SAMPLE`.
pub fn case_of(cantilever: Cantilever, sample: Sample, a0_nm: f64) -> Case {
    Case {
        name: format!("{}-{}", cantilever.name, sample.name),
        description: String::from("from the command line"),
        cantilever,
        sample,
        free_amplitude_nm: a0_nm,
        drive_frequency_khz: None,
        drive: afm::model::drive_spec::DriveSpec::Direct,
    }
}

/// `case` with the `--a0` (nm) and `--drive-frequency` (kHz) overrides applied, the frequency
/// checked against the cantilever's range (and warned about far from every mode), and the
/// whole case validated on the command line's account.
pub fn apply_overrides(
    mut case: Case,
    a0: Option<f64>,
    drive_frequency: Option<f64>,
) -> Result<Case> {
    if let Some(a0) = a0 {
        case.free_amplitude_nm = a0;
    }
    if let Some(frequency) = drive_frequency {
        option_ranges::drive_frequency_for(&case.cantilever).check(frequency)?;
        case.drive_frequency_khz = Some(frequency);
        if let Some(warning) = case.drive_warning() {
            crate::output::print_stderr(&format!("drumroll: warning: --drive-frequency {warning}"));
        }
    }
    // A case file's bimodal drive may not be commensurate with an overriding frequency: the
    // error names the option that made it so.
    let source = match drive_frequency {
        Some(frequency) => format!("the command line (--drive-frequency {frequency})"),
        None => String::from("the command line"),
    };
    case.validate(&source).context("invalid model parameters")?;
    Ok(case)
}

/// Print each warning on stderr.
fn warn_all(warnings: Vec<String>) {
    for warning in warnings {
        crate::output::print_stderr(&format!("drumroll: warning: {warning}"));
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
