//! The page's regime map over a second parameter (`drumroll map`, MODEL.md section 8): the
//! grazing, fold and period-doubling points of the approach diagram continued over a range of
//! the parameter, computed and exported by the CLI's own functions.

use afm::{Case, ParameterAxis, RegimeMap, RegimeMapSettings, TappingModel};
use anyhow::Result;
use drumroll::map::{compute_map, csv_text, map_figure, map_json, map_settings, MapArgs};
use drumroll::model_args::ModelArgs;
use serde::Deserialize;
use serde_json::Value;

use crate::case_request::CaseRequest;

/// The page's request of a regime map: the case and `drumroll map`'s options (same names and
/// ranges: `vary` one of `a0`, `drive-frequency`, `sample-modulus`, `tip-radius`,
/// `quality-factor-N`, `stiffness-N`; `from < to` in its unit; `points` per curve in
/// `[2, 100000]`, default 100; `labels` the curves to follow, default all; `at` values where
/// every curve gets a point; `floor_nm`, `min_amplitude_ratio`, `max_step_nm` of the seed
/// approach as in `continue`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapRequest {
    /// The case.
    pub case: CaseRequest,
    /// `--vary`.
    pub vary: String,
    /// `--from`.
    pub from: f64,
    /// `--to`.
    pub to: f64,
    /// `--at`.
    #[serde(default)]
    pub at: Vec<f64>,
    /// `--labels`.
    #[serde(default)]
    pub labels: Vec<String>,
    /// `--points`.
    #[serde(default = "default_points")]
    pub points: usize,
    /// `--floor`, nm.
    #[serde(default)]
    pub floor_nm: Option<f64>,
    /// `--min-amplitude-ratio`.
    #[serde(default = "default_min_amplitude_ratio")]
    pub min_amplitude_ratio: f64,
    /// `--max-step`, nm.
    #[serde(default)]
    pub max_step_nm: Option<f64>,
}

/// `map`'s default `--points`.
fn default_points() -> usize {
    100
}

/// `map`'s default `--min-amplitude-ratio`.
fn default_min_amplitude_ratio() -> f64 {
    0.3
}

impl MapRequest {
    /// `drumroll map`'s options for this request (the case resolved apart).
    fn args(&self) -> MapArgs {
        MapArgs {
            model: ModelArgs {
                case: Vec::new(),
                cantilever: None,
                sample: None,
                a0: None,
                drive_frequency: None,
            },
            vary: self.vary.clone(),
            from: self.from,
            to: self.to,
            at: self.at.clone(),
            labels: self.labels.clone(),
            points: self.points,
            floor: self.floor_nm,
            min_amplitude_ratio: self.min_amplitude_ratio,
            max_step: self.max_step_nm,
            harmonics: drumroll::approach::DEFAULT_HARMONICS,
            json: true,
            csv: None,
            codim2_csv: None,
            plot: None,
            grid_file: None,
        }
    }

    /// Resolve the case and compute its map, as `drumroll map` does.
    pub fn compute(&self) -> Result<MapRun> {
        let (case, model) = self.case.resolve()?;
        let args = self.args();
        let axis = ParameterAxis::parse(&args.vary, case.cantilever.modes.len())?;
        let settings = map_settings(&args, &model)?;
        let map = compute_map(&case, axis, &settings)?;
        Ok(MapRun {
            case,
            model,
            args,
            axis,
            settings,
            map,
        })
    }
}

/// A computed regime map with what its exports need.
#[derive(Debug, Clone)]
pub struct MapRun {
    /// The case.
    pub case: Case,
    /// Its tapping model.
    pub model: TappingModel,
    /// The `map` options.
    pub args: MapArgs,
    /// The parameter varied.
    pub axis: ParameterAxis,
    /// The settings the options gave.
    pub settings: RegimeMapSettings,
    /// The curves and codimension-two points.
    pub map: RegimeMap,
}

impl MapRun {
    /// The `drumroll map --json` object (docs/output-schema.md).
    pub fn json(&self) -> Value {
        map_json(
            &self.args,
            &self.case,
            &self.model,
            self.axis,
            &self.settings,
            &self.map,
        )
    }

    /// The `drumroll map --csv` file's text.
    pub fn csv(&self) -> Result<String> {
        csv_text(&self.map.curves)
    }

    /// The `drumroll map --plot FILE.svg` figure.
    pub fn svg(&self) -> Result<String> {
        map_figure(self.axis, &self.map, None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The G1 curve over A0 is first contact: at each fixed A0 the curve's `Z` equals the
    /// closed-form `Z_G1` of the free orbit of the case at that A0 (independent of the curve
    /// continuation, which locates it to its Newton tolerance).
    #[test]
    fn the_g1_curve_over_a0_is_first_contact() {
        let request = MapRequest {
            case: CaseRequest::builtin("biolever-mica"),
            vary: String::from("a0"),
            from: 8.0,
            to: 12.0,
            at: vec![9.0, 11.0],
            labels: vec![String::from("G1")],
            points: 10,
            floor_nm: None,
            min_amplitude_ratio: 0.3,
            max_step_nm: None,
        };
        let run = request.compute().expect("map");
        let curve = run.map.curves.iter().find(|c| c.label == "G1").expect("G1");
        for a0 in [9.0, 11.0] {
            let point = curve
                .points
                .iter()
                .find(|p| p.at_fixed_parameter && p.parameter == a0)
                .expect("point at --at");
            let (_, model) = CaseRequest {
                free_amplitude_nm: Some(a0),
                ..CaseRequest::builtin("biolever-mica")
            }
            .resolve()
            .expect("case at a0");
            let exact = model.grazing_separation_nm();
            assert!(
                (point.z_nm - exact).abs() < 1e-7,
                "{} vs {exact}",
                point.z_nm
            );
        }
        let csv = run.csv().expect("csv");
        assert!(csv.starts_with("label,parameter,"));
        assert!(run.svg().expect("svg").contains("<svg"));
        assert_eq!(run.json()["parameter"]["name"], "a0");
    }

    #[test]
    fn an_unknown_parameter_is_named() {
        let request = MapRequest {
            case: CaseRequest::builtin("biolever-mica"),
            vary: String::from("colour"),
            from: 1.0,
            to: 2.0,
            at: Vec::new(),
            labels: Vec::new(),
            points: 10,
            floor_nm: None,
            min_amplitude_ratio: 0.3,
            max_step_nm: None,
        };
        let message = format!("{:#}", request.compute().unwrap_err());
        assert!(
            message.contains("--vary") && message.contains("a0"),
            "{message}"
        );
    }
}
