//! What the page offers to choose from: the built-in cases (each with its cantilever and sample
//! inline, ready to edit), the built-in cantilevers and samples, and the regime map's
//! parameters.

use afm::{fixtures, PARAMETER_NAMES};
use anyhow::Result;
use drumroll::model_args::DEFAULT_CASE;
use serde_json::{json, Value};

/// The catalogue object: `cases` (one `{name, description, case, fundamental_frequency_khz}`
/// per built-in case, `case` in the form [`crate::case_request::CaseRequest`] reads: cantilever
/// and sample inline, A0 in nm, drive frequency in kHz or `null` for `f_1`, the
/// drive's kind), `cantilevers` and `samples`
/// (the built-in files' objects by name), `parameters` (the names `drumroll map --vary`
/// takes, `N` a mode number) and `default_case`.
pub fn catalogue() -> Result<Value> {
    let cases = fixtures::case_names()
        .into_iter()
        .map(|name| {
            let case = fixtures::builtin_case(name)?;
            Ok(json!({
                "name": case.name,
                "description": case.description,
                "fundamental_frequency_khz": case.cantilever.fundamental_frequency_khz(),
                "case": {
                    "name": case.name,
                    "description": case.description,
                    "cantilever": case.cantilever,
                    "sample": case.sample,
                    "free_amplitude_nm": case.free_amplitude_nm,
                    "drive_frequency_khz": case.drive_frequency_khz,
                    "drive": case.drive,
                },
            }))
        })
        .collect::<Result<Vec<Value>>>()?;
    let cantilevers = fixtures::cantilever_names()
        .into_iter()
        .map(|name| Ok((name.to_string(), json!(fixtures::builtin_cantilever(name)?))))
        .collect::<Result<serde_json::Map<String, Value>>>()?;
    let samples = fixtures::sample_names()
        .into_iter()
        .map(|name| Ok((name.to_string(), json!(fixtures::builtin_sample(name)?))))
        .collect::<Result<serde_json::Map<String, Value>>>()?;
    Ok(json!({
        "cases": cases,
        "cantilevers": cantilevers,
        "samples": samples,
        "parameters": PARAMETER_NAMES,
        "default_case": DEFAULT_CASE,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case_request::CaseRequest;

    #[test]
    fn every_listed_case_resolves_inline_to_its_builtin() {
        let catalogue = catalogue().expect("catalogue");
        let cases = catalogue["cases"].as_array().expect("cases");
        assert_eq!(cases.len(), fixtures::case_names().len());
        for entry in cases {
            let request: CaseRequest =
                serde_json::from_value(entry["case"].clone()).expect("request");
            let (case, _) = request.resolve().expect("inline case");
            let name = entry["name"].as_str().expect("name");
            assert_eq!(
                case,
                fixtures::builtin_case(name).expect("builtin"),
                "{name}"
            );
        }
    }
}
