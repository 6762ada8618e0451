//! The page's bifurcation diagram in `Z` (the paper's Fig. 2, MODEL.md section 5): the options
//! of `drumroll continue`, computed and exported by the CLI's own functions.

use afm::{Case, TappingModel};
use anyhow::Result;
use drumroll::continue_diagram::{
    continue_case_until, continue_json, continued_csv, ContinueArgs, Continued,
};
use drumroll::continue_figure::{figure, CaseDiagrams};
use drumroll::model_args::ModelArgs;
use serde::Deserialize;
use serde_json::Value;

use crate::case_request::CaseRequest;

/// The page's request of a diagram: the case and `drumroll continue`'s options (same names
/// and ranges: `floor_nm` in `[-A0, Z_G1)` nm, default `0.05 A0`; `min_amplitude_ratio` in
/// `[0, 1)`, default 0.3; `max_step_nm` in `[1e-7, A0]`, default `A0/250`; `max_points` in
/// `[2, 10000000]`, default 20000; `retract`, default false).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagramRequest {
    /// The case.
    pub case: CaseRequest,
    /// `--floor`, nm.
    #[serde(default)]
    pub floor_nm: Option<f64>,
    /// `--min-amplitude-ratio`.
    #[serde(default = "default_min_amplitude_ratio")]
    pub min_amplitude_ratio: f64,
    /// `--max-step`, nm.
    #[serde(default)]
    pub max_step_nm: Option<f64>,
    /// `--max-points`.
    #[serde(default = "default_max_points")]
    pub max_points: i64,
    /// `--retract`.
    #[serde(default)]
    pub retract: bool,
}

/// `continue`'s default `--min-amplitude-ratio`.
fn default_min_amplitude_ratio() -> f64 {
    0.3
}

/// `continue`'s default `--max-points`.
fn default_max_points() -> i64 {
    20_000
}

impl DiagramRequest {
    /// The approach diagram of the built-in case `name` with `continue`'s defaults: what
    /// `drumroll continue --case NAME` computes.
    pub fn builtin(name: &str) -> Self {
        Self {
            case: CaseRequest::builtin(name),
            floor_nm: None,
            min_amplitude_ratio: default_min_amplitude_ratio(),
            max_step_nm: None,
            max_points: default_max_points(),
            retract: false,
        }
    }

    /// `drumroll continue`'s options for this request (the case resolved apart).
    fn args(&self) -> ContinueArgs {
        ContinueArgs {
            model: ModelArgs {
                case: Vec::new(),
                cantilever: None,
                sample: None,
                a0: None,
                drive_frequency: None,
            },
            floor: self.floor_nm,
            min_amplitude_ratio: self.min_amplitude_ratio,
            max_step: self.max_step_nm,
            max_points: self.max_points,
            retract: self.retract,
            json: true,
            csv: None,
            plot: None,
            overlay: false,
            panels: None,
            harmonics: drumroll::approach::DEFAULT_HARMONICS,
            threads: None,
        }
    }

    /// Resolve the case and continue its approach (and retract), as `drumroll continue` does.
    pub fn compute(&self) -> Result<DiagramRun> {
        let (case, model) = self.case.resolve()?;
        let args = self.args();
        let continued = continue_case_until(&args, &case, &model, &mut || false)?;
        Ok(DiagramRun {
            case,
            model,
            args,
            continued,
        })
    }
}

/// A computed diagram with what its exports need.
#[derive(Debug, Clone)]
pub struct DiagramRun {
    /// The case.
    pub case: Case,
    /// Its tapping model.
    pub model: TappingModel,
    /// The `continue` options it was computed with.
    pub args: ContinueArgs,
    /// The approach, retract and bistable ranges.
    pub continued: Continued,
}

impl DiagramRun {
    /// The `drumroll continue --json` object (docs/output-schema.md).
    pub fn json(&self) -> Value {
        continue_json(&self.args, &self.case, &self.model, &self.continued)
    }

    /// The `drumroll continue --csv` file's text.
    pub fn csv(&self) -> Result<String> {
        continued_csv(&self.continued)
    }

    /// The `drumroll continue --plot FILE.svg` figure.
    pub fn svg(&self) -> Result<String> {
        figure(
            &[CaseDiagrams {
                case: self.case.clone(),
                model: self.model.clone(),
                approach: self.continued.approach.clone(),
                retract: self.continued.retract.clone(),
            }],
            false,
        )
    }

    /// The warnings for the page: the case's plausibility warnings and the film-range warning
    /// of the branches' orbits.
    pub fn warnings(&self) -> Vec<String> {
        let mut warnings = crate::case_request::warnings(&self.case);
        warnings.extend(self.continued.warning.clone());
        warnings
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use drumroll::approach::DEFAULT_HARMONICS;
    use drumroll::continue_diagram::csv_header;

    /// G1 is where the free orbit's lowest gap is zero: `Z_G1` of the closed-form free orbit
    /// (`TappingModel::grazing_separation_nm`), independent of the continuation that locates
    /// it to `|dZ| < 1e-9` nm.
    #[test]
    fn the_biolever_mica_diagram_starts_with_g1_at_first_contact() {
        let run = DiagramRequest::builtin("biolever-mica")
            .compute()
            .expect("diagram");
        let json = run.json();
        let special = json["special_points"].as_array().expect("special points");
        let g1 = special.iter().find(|p| p["label"] == "G1").expect("G1");
        let z = g1["z_nm"].as_f64().expect("z");
        assert!((z - run.model.grazing_separation_nm()).abs() < 1e-8, "{z}");
        assert_eq!(json["completed"], true);
        let csv = run.csv().expect("csv");
        let mut lines = csv.lines();
        assert_eq!(
            lines.next(),
            Some(csv_header(DEFAULT_HARMONICS as usize).as_str())
        );
        assert_eq!(
            lines.count(),
            json["points"].as_array().expect("points").len()
        );
        let svg = run.svg().expect("svg");
        assert!(
            svg.starts_with("<svg") && svg.contains("G1"),
            "{}",
            &svg[..80]
        );
    }

    #[test]
    fn an_option_out_of_range_is_named() {
        let request = DiagramRequest {
            max_step_nm: Some(-1.0),
            ..DiagramRequest::builtin("biolever-mica")
        };
        let message = format!("{:#}", request.compute().unwrap_err());
        assert!(message.contains("--max-step"), "{message}");
    }
}
