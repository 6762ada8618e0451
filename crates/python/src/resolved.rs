//! A case resolved into its tapping model (MODEL.md sections 1-3), shared by the results
//! computed on it, and its JSON form (the case files' format, cantilever and sample inline).

use afm::{Case as AfmCase, TappingModel};
use anyhow::Context;
use serde::Deserialize;
use serde_json::{json, Value};

/// A case resolved into its model, shared by the results computed on it.
#[derive(Debug)]
pub struct Resolved {
    /// The case as given.
    pub case: AfmCase,
    /// Its tapping model (Eq. 1 with Hertz contact), at first contact `Z = Z_G1`.
    pub model: TappingModel,
}

impl Resolved {
    /// Validate `case` and build its model (errors as the CLI words them).
    pub fn new(case: AfmCase) -> anyhow::Result<Self> {
        case.validate("the Python arguments")
            .context("invalid model parameters")?;
        let model = TappingModel::from_case(&case)
            .with_context(|| format!("cannot build the model of case `{}`", case.name))?;
        Ok(Self { case, model })
    }

    /// The case in the case files' format with the cantilever and sample inline: what
    /// `Case.to_dict()` returns and pickling stores.
    pub fn case_json(&self) -> Value {
        json!({
            "name": self.case.name,
            "description": self.case.description,
            "cantilever": self.case.cantilever,
            "sample": self.case.sample,
            "free_amplitude_nm": self.case.free_amplitude_nm,
            "drive_frequency_khz": self.case.drive_frequency_khz,
            "drive": self.case.drive,
        })
    }

    /// The case of [`Resolved::case_json`]'s object (`source` names it in errors).
    pub fn from_case_json(value: &Value, source: &str) -> anyhow::Result<Self> {
        let number = |key: &str| value[key].as_f64();
        let Some(free_amplitude_nm) = number("free_amplitude_nm") else {
            anyhow::bail!("{source}: `free_amplitude_nm` must be a number of nm");
        };
        let case = AfmCase {
            name: value["name"].as_str().unwrap_or("python").to_string(),
            description: value["description"].as_str().unwrap_or("").to_string(),
            cantilever: from_value(
                &value["cantilever"],
                &format!("{source}: cantilever"),
                afm::fixtures::parse_cantilever,
            )?,
            sample: from_value(
                &value["sample"],
                &format!("{source}: sample"),
                afm::fixtures::parse_sample,
            )?,
            free_amplitude_nm,
            drive_frequency_khz: number("drive_frequency_khz"),
            drive: match value.get("drive") {
                None | Some(Value::Null) => afm::model::drive_spec::DriveSpec::Direct,
                Some(drive) => afm::model::drive_spec::DriveSpec::deserialize(drive)
                    .map_err(|error| anyhow::anyhow!("{source}: drive: {error}"))?,
            },
        };
        Self::new(case)
    }
}

/// A cantilever or sample of its file's JSON object, numbers taken exactly (checked when the
/// case is resolved; `file` names it in errors). On a malformed object the error is the one
/// `parse` (`afm::fixtures::parse_cantilever` or `parse_sample`) gives for the object's text,
/// which names the field.
pub fn from_value<T: serde::de::DeserializeOwned>(
    value: &Value,
    file: &str,
    parse: fn(&str, &str) -> Result<T, afm::AfmError>,
) -> Result<T, afm::AfmError> {
    T::deserialize(value).map_err(|source| {
        let text = serde_json::to_string_pretty(value).unwrap_or_default();
        match parse(file, &text) {
            Err(error) => error,
            Ok(_) => afm::AfmError::Json {
                file: file.to_string(),
                field: String::new(),
                source,
            },
        }
    })
}

/// The CLI's model options left empty: for building a command's options (whose checks the
/// Python API reuses) when the case is already resolved.
pub fn resolved_model_args() -> drumroll::model_args::ModelArgs {
    drumroll::model_args::ModelArgs {
        case: Vec::new(),
        cantilever: None,
        sample: None,
        a0: None,
        drive_frequency: None,
    }
}
