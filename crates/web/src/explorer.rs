//! The page's entry points: one [`Explorer`] per Web Worker holds the last diagram, orbit and
//! regime map, so that the exports (the CLI's JSON, CSV and SVG) need no recomputation. Every
//! method takes JSON text and returns JSON (or CSV, SVG) text; an error is the message of the
//! command line's (the chain of causes joined by `: `), never a panic.

use anyhow::{anyhow, Context, Result};
use serde::de::DeserializeOwned;
use serde_json::json;

#[cfg(target_arch = "wasm32")]
use wasm_bindgen::prelude::wasm_bindgen;

use crate::diagram_request::{DiagramRequest, DiagramRun};
use crate::map_request::{MapRequest, MapRun};
use crate::orbit_request::{orbit_svg, OrbitRequest};

/// The state of one page: the last diagram (with its case), the last orbit clicked on it and
/// the last regime map.
#[cfg_attr(target_arch = "wasm32", wasm_bindgen)]
#[derive(Debug, Default)]
pub struct Explorer {
    diagram: Option<DiagramRun>,
    orbit: Option<afm::SteadyOrbit>,
    map: Option<MapRun>,
}

/// The error text the page shows: the chain of causes, as the command line prints it.
fn message(error: anyhow::Error) -> String {
    format!("{error:#}")
}

/// A request of type `T` parsed from the page's JSON `text` (`what` names it in errors).
fn parse<T: DeserializeOwned>(text: &str, what: &str) -> Result<T> {
    serde_json::from_str(text).with_context(|| format!("the page's {what} request"))
}

/// Compact JSON text of `value` and a newline, as the CLI prints `--json` objects.
fn json_line(value: &serde_json::Value) -> Result<String> {
    Ok(format!("{}\n", serde_json::to_string(value)?))
}

#[cfg_attr(target_arch = "wasm32", wasm_bindgen)]
impl Explorer {
    /// An explorer with nothing computed yet.
    #[cfg_attr(target_arch = "wasm32", wasm_bindgen(constructor))]
    pub fn new() -> Self {
        Self::default()
    }

    /// The catalogue of built-in cases, cantilevers, samples and map parameters
    /// ([`crate::catalogue::catalogue`]) as JSON text.
    pub fn catalogue(&self) -> Result<String, String> {
        crate::catalogue::catalogue()
            .and_then(|value| Ok(serde_json::to_string(&value)?))
            .map_err(message)
    }

    /// Compute the diagram of `request` (a [`DiagramRequest`] as JSON) and keep it; returns
    /// `{"diagram": <drumroll continue --json object>, "warnings": [...]}`. The last orbit is
    /// forgotten.
    pub fn diagram(&mut self, request: &str) -> Result<String, String> {
        (|| {
            let run = parse::<DiagramRequest>(request, "diagram")?.compute()?;
            let text = serde_json::to_string(&json!({
                "diagram": run.json(),
                "warnings": run.warnings(),
            }))?;
            self.diagram = Some(run);
            self.orbit = None;
            Ok(text)
        })()
        .map_err(message)
    }

    /// The last diagram's special points (the `special_points` array of `drumroll continue
    /// --json`) as JSON text: what the page's test hook `?report=1` shows.
    pub fn special_points(&self) -> Result<String, String> {
        self.last_diagram()
            .and_then(|run| Ok(serde_json::to_string(&run.json()["special_points"])?))
            .map_err(message)
    }

    /// The last diagram as `drumroll continue --json` prints it.
    pub fn diagram_json(&self) -> Result<String, String> {
        self.last_diagram()
            .and_then(|run| json_line(&run.json()))
            .map_err(message)
    }

    /// The last diagram as `drumroll continue --csv` writes it.
    pub fn diagram_csv(&self) -> Result<String, String> {
        self.last_diagram()
            .and_then(DiagramRun::csv)
            .map_err(message)
    }

    /// The last diagram as `drumroll continue --plot FILE.svg` draws it.
    pub fn diagram_svg(&self) -> Result<String, String> {
        self.last_diagram()
            .and_then(DiagramRun::svg)
            .map_err(message)
    }

    /// Compute the orbit of `request` (an [`OrbitRequest`] as JSON) on the last diagram's case
    /// and keep it; returns `{"orbit": <simulate --json object>, "trajectory": {...}}`.
    pub fn orbit(&mut self, request: &str) -> Result<String, String> {
        (|| {
            let request = parse::<OrbitRequest>(request, "orbit")?;
            let (orbit, object) = request.compute(self.last_diagram()?)?;
            self.orbit = Some(orbit);
            Ok(serde_json::to_string(&object)?)
        })()
        .map_err(message)
    }

    /// The last orbit as `drumroll simulate --json` prints it (pretty, without the
    /// coexisting-orbit search: `coexisting_orbit` is `null`).
    pub fn orbit_json(&self) -> Result<String, String> {
        (|| {
            let (run, orbit) = self.last_orbit()?;
            let options = json!({"z_nm": orbit.z_nm, "amplitude_ratio": null, "start": "near"});
            let object = drumroll::simulate::simulate_json(
                &run.case,
                &run.model,
                &afm::SteadyOrbitSettings::default(),
                orbit,
                "near",
                None,
                options,
            );
            Ok(format!("{}\n", serde_json::to_string_pretty(&object)?))
        })()
        .map_err(message)
    }

    /// The last orbit as `drumroll simulate --plot FILE.svg` draws it.
    pub fn orbit_svg(&self) -> Result<String, String> {
        self.last_orbit()
            .and_then(|(run, orbit)| orbit_svg(run, orbit))
            .map_err(message)
    }

    /// Compute the regime map of `request` (a [`MapRequest`] as JSON) and keep it; returns the
    /// `drumroll map --json` object.
    pub fn map(&mut self, request: &str) -> Result<String, String> {
        (|| {
            let run = parse::<MapRequest>(request, "map")?.compute()?;
            let text = serde_json::to_string(&run.json())?;
            self.map = Some(run);
            Ok(text)
        })()
        .map_err(message)
    }

    /// The last map as `drumroll map --json` prints it.
    pub fn map_json(&self) -> Result<String, String> {
        self.last_map()
            .and_then(|run| json_line(&run.json()))
            .map_err(message)
    }

    /// The last map as `drumroll map --csv` writes it.
    pub fn map_csv(&self) -> Result<String, String> {
        self.last_map().and_then(MapRun::csv).map_err(message)
    }

    /// The last map as `drumroll map --plot FILE.svg` draws it.
    pub fn map_svg(&self) -> Result<String, String> {
        self.last_map().and_then(MapRun::svg).map_err(message)
    }
}

impl Explorer {
    fn last_diagram(&self) -> Result<&DiagramRun> {
        self.diagram
            .as_ref()
            .ok_or_else(|| anyhow!("no diagram computed yet"))
    }

    fn last_orbit(&self) -> Result<(&DiagramRun, &afm::SteadyOrbit)> {
        let run = self.last_diagram()?;
        let orbit = self
            .orbit
            .as_ref()
            .ok_or_else(|| anyhow!("no orbit computed yet: click a point of the diagram"))?;
        Ok((run, orbit))
    }

    fn last_map(&self) -> Result<&MapRun> {
        self.map
            .as_ref()
            .ok_or_else(|| anyhow!("no regime map computed yet"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_special_points_are_the_diagrams_and_exports_need_a_diagram() {
        let mut explorer = Explorer::new();
        assert!(explorer.diagram_csv().unwrap_err().contains("no diagram"));
        let text = explorer
            .diagram(r#"{"case": {"name": "biolever-mica"}}"#)
            .expect("diagram");
        let object: serde_json::Value = serde_json::from_str(&text).expect("json");
        let special: serde_json::Value =
            serde_json::from_str(&explorer.special_points().expect("special")).expect("json");
        assert_eq!(special, object["diagram"]["special_points"]);
        assert!(explorer.orbit_svg().unwrap_err().contains("click a point"));
    }

    #[test]
    fn malformed_requests_give_messages() {
        let mut explorer = Explorer::new();
        let message = explorer.diagram("{").unwrap_err();
        assert!(
            message.starts_with("the page's diagram request"),
            "{message}"
        );
        let message = explorer
            .diagram(r#"{"case": {"name": "biolever-mica"}, "colour": 1}"#)
            .unwrap_err();
        assert!(message.contains("colour"), "{message}");
        let message = explorer
            .diagram(r#"{"case": {"name": "no-such-case"}}"#)
            .unwrap_err();
        assert!(message.contains("no-such-case"), "{message}");
    }
}
