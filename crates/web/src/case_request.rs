//! The page's case: a built-in case by name (with the A0 and drive overrides of the command
//! line's `--a0` and `--drive-frequency`), or a case with its cantilever and sample inline in
//! the fixture files' format (MODEL.md sections 1-3 and 9), checked as the CLI checks them.

use afm::model::drive_spec::DriveSpec;
use afm::{fixtures, Case, TappingModel};
use anyhow::{bail, Context, Result};
use drumroll::model_args::{model_of, ModelArgs, DEFAULT_CASE};
use drumroll::option_ranges;
use serde::Deserialize;
use serde_json::Value;

/// What the page's errors call the inline case (in place of a file name).
pub const SOURCE: &str = "the page's case";

/// The page's case as it sends it: either `name` alone (a built-in case; `free_amplitude_nm`
/// and `drive_frequency_khz` override its values, as `--case NAME --a0 --drive-frequency` do),
/// or `cantilever` and `sample` (each a built-in name or the file's object inline) with
/// `free_amplitude_nm` (nm, in [0.001, 100000]), optionally `drive_frequency_khz` (kHz; absent
/// or `null`: the fundamental `f_1`) and `drive` (absent: direct).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseRequest {
    /// The built-in case's name, or the inline case's name (default `cantilever-sample`).
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// A built-in cantilever's name or a cantilever file's object.
    #[serde(default)]
    pub cantilever: Option<Value>,
    /// A built-in sample's name or a sample file's object (`contact`, `electrostatic` inline).
    #[serde(default)]
    pub sample: Option<Value>,
    /// The free amplitude A0 of the photodiode signal u, nm.
    #[serde(default)]
    pub free_amplitude_nm: Option<f64>,
    /// The drive frequency, kHz.
    #[serde(default)]
    pub drive_frequency_khz: Option<f64>,
    /// The excitation as a case file gives it (`{"kind": "direct" | "acoustic" | "bimodal",
    /// ...}`, MODEL.md section 14); absent: direct.
    #[serde(default)]
    pub drive: Option<DriveSpec>,
}

impl CaseRequest {
    /// The built-in case `name` as the command line's `--case NAME` gives it.
    pub fn builtin(name: &str) -> Self {
        Self {
            name: Some(name.to_string()),
            ..Self::default()
        }
    }

    /// The case and its tapping model at first contact `Z = Z_G1`, every field checked (errors
    /// name the field and its allowed range, as the command line's do).
    pub fn resolve(&self) -> Result<(Case, TappingModel)> {
        let case = match (&self.cantilever, &self.sample) {
            (None, None) => ModelArgs {
                case: vec![self.name.clone().unwrap_or(DEFAULT_CASE.to_string())],
                cantilever: None,
                sample: None,
                a0: self.free_amplitude_nm,
                drive_frequency: self.drive_frequency_khz,
            }
            .case()?,
            (Some(cantilever), Some(sample)) => self.inline_case(cantilever, sample)?,
            _ => bail!("{SOURCE}: give a built-in case's name, or both a cantilever and a sample"),
        };
        model_of(case)
    }

    /// The case of an inline (or named) cantilever and sample, checked.
    fn inline_case(&self, cantilever: &Value, sample: &Value) -> Result<Case> {
        let Some(a0) = self.free_amplitude_nm else {
            bail!("{SOURCE}: a cantilever and a sample need `free_amplitude_nm` (A0, nm)");
        };
        option_ranges::A0.check(a0)?;
        let cantilever = part(
            cantilever,
            "cantilever",
            fixtures::builtin_cantilever,
            fixtures::parse_cantilever,
        )?;
        if let Some(frequency) = self.drive_frequency_khz {
            option_ranges::drive_frequency_for(&cantilever).check(frequency)?;
        }
        let sample = part(
            sample,
            "sample",
            fixtures::builtin_sample,
            fixtures::parse_sample,
        )?;
        let case = Case {
            name: self
                .name
                .clone()
                .filter(|name| !name.trim().is_empty())
                .unwrap_or_else(|| format!("{}-{}", cantilever.name, sample.name)),
            description: self.description.clone().unwrap_or_default(),
            cantilever,
            sample,
            free_amplitude_nm: a0,
            drive_frequency_khz: self.drive_frequency_khz,
            drive: self.drive.clone().unwrap_or_default(),
        };
        case.validate(SOURCE).context("invalid model parameters")?;
        Ok(case)
    }
}

/// A cantilever or sample given as a built-in name (`builtin`) or as its file's object,
/// parsed and checked by `parse` (errors name `the page's cantilever` or `sample` and the
/// field).
fn part<T>(
    value: &Value,
    what: &str,
    builtin: fn(&str) -> Result<T, afm::AfmError>,
    parse: fn(&str, &str) -> Result<T, afm::AfmError>,
) -> Result<T> {
    let file = format!("the page's {what}");
    match value {
        Value::String(name) => Ok(builtin(name)?),
        Value::Object(_) => Ok(parse(&file, &serde_json::to_string_pretty(value)?)?),
        _ => bail!("{file}: a built-in name or an object in the {what} files' format"),
    }
}

/// The plausibility warnings of `case` (valid values outside the range typical of AFM).
pub fn warnings(case: &Case) -> Vec<String> {
    case.warnings(SOURCE)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_builtin_name_gives_the_command_lines_case() {
        let (case, model) = CaseRequest::builtin("biolever-mica")
            .resolve()
            .expect("case");
        let expected = afm::builtin_case("biolever-mica").expect("fixture");
        assert_eq!(case, expected);
        assert_eq!(model.free_amplitude_nm(), 10.0);
    }

    #[test]
    fn an_inline_case_equals_the_builtin_it_copies() {
        let builtin = afm::builtin_case("maclever-membrane-film").expect("fixture");
        let request: CaseRequest = serde_json::from_value(json!({
            "name": builtin.name,
            "description": builtin.description,
            "cantilever": builtin.cantilever,
            "sample": builtin.sample,
            "free_amplitude_nm": builtin.free_amplitude_nm,
            "drive_frequency_khz": builtin.drive_frequency_khz,
        }))
        .expect("request");
        let (case, _) = request.resolve().expect("case");
        assert_eq!(case, builtin);
    }

    #[test]
    fn bad_fields_are_named_with_their_range() {
        let mut sample =
            serde_json::to_value(afm::builtin_sample("mica").expect("mica")).expect("sample json");
        sample["contact"] =
            json!({"law": "dmt", "hamaker_constant_j": 1.0, "intermolecular_distance_nm": 0.2});
        let request = CaseRequest {
            cantilever: Some(json!("biolever")),
            sample: Some(sample),
            free_amplitude_nm: Some(10.0),
            ..CaseRequest::default()
        };
        let message = format!("{:#}", request.resolve().unwrap_err());
        assert!(
            message.contains("the page's sample") && message.contains("hamaker_constant_j"),
            "{message}"
        );
        let request = CaseRequest {
            free_amplitude_nm: Some(-1.0),
            ..CaseRequest::builtin("biolever-mica")
        };
        let message = format!("{:#}", request.resolve().unwrap_err());
        assert!(message.contains("--a0"), "{message}");
    }
}
