//! `drumroll.Orbit`: one steady periodic orbit (MODEL.md section 4) and its observables, with
//! the keys of `drumroll simulate --json` as attributes.

use afm::{sample_trajectory, Separation, SteadyOrbit, SteadyOrbitSettings};
use drumroll::simulate::{coexisting_orbit, orbit_json, simulate_json, Start};
use pyo3::exceptions::{PyAttributeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use serde_json::{json, Value};
use std::sync::{Arc, OnceLock};

use crate::convert::{float_array, json_to_py, py_to_json};
use crate::errors::{afm_to_py_err, to_py_err, warn};
use crate::resolved::Resolved;

/// How an orbit was found: the CLI's starts, or Newton from a given state near the orbit.
#[derive(Debug, Clone)]
pub enum Origin {
    /// `approach` or `transient`, as `simulate --start`; `z` or `amplitude_ratio` as asked.
    Cli {
        /// The start that found the orbit.
        start: Start,
        /// The separation asked for, nm, if any.
        z: Option<f64>,
        /// The amplitude ratio asked for, if any.
        amplitude_ratio: Option<f64>,
    },
    /// Newton from a state near the orbit (`afm::OrbitStart::Near`).
    Near,
}

/// A steady orbit computed here: the library's orbit, its JSON built when first asked for.
struct Computed {
    orbit: SteadyOrbit,
    origin: Origin,
}

/// One steady periodic orbit of a case at a separation Z, found by Newton on the
/// stroboscopic map (MODEL.md section 4), converged to 1e-10 in state.
///
/// Every key of `drumroll simulate --json` is an attribute: `z_nm` (nm), `amplitude_ratio`
/// (A/A0), `phase_deg` (degrees, a lag), `impacts_per_period`, `impacts_per_orbit`,
/// `multiplicity` (drive periods per orbit), `peak_force_nn` (nN), `mean_force_nn` (nN),
/// `impulse_nn_us` (nN us per period), `contact_time_periods`, `min_gap_nm`, `gap_minima`,
/// `impacts`, `stable`, `floquet_multipliers` ([re, im] pairs), `state` (q_i in nm and q_i'
/// in nm/us at t = 0), `periods`, `converged`, `residual`, the contrast observables
/// `dissipated_ev` and `virial_ev` (eV), `max_indentation_nm`, `mean_indentation_nm` (nm),
/// `energy_balance_residual`, `harmonics` (a list of dicts `n`, `amplitude_nm`, `phase_deg`;
/// MODEL.md section 10), ... (docs/output-schema.md).
/// `to_dict()` is the whole JSON object, `inputs` and `coexisting_orbit` included.
#[pyclass(module = "drumroll", frozen)]
pub struct Orbit {
    resolved: Arc<Resolved>,
    computed: Option<Computed>,
    /// `orbit_json` with `start`: the attributes.
    core: OnceLock<Value>,
    /// The whole `simulate --json` object (with `coexisting_orbit` and `inputs`).
    full: OnceLock<Value>,
}

impl Orbit {
    /// The orbit `orbit` of `resolved`'s model, found as `origin` says; the CLI's warning (a
    /// film law used beyond its range at this orbit) is issued as a Python warning.
    pub fn new(
        py: Python<'_>,
        resolved: Arc<Resolved>,
        orbit: SteadyOrbit,
        origin: Origin,
    ) -> PyResult<Self> {
        let min_gap = orbit.observables().min_gap_nm();
        let orbits = [(orbit.z_nm, min_gap.is_finite().then_some(min_gap))];
        if let Some(warning) = afm::film_range_warning(&resolved.model, orbits) {
            warn(py, &warning)?;
        }
        Ok(Self {
            resolved,
            computed: Some(Computed { orbit, origin }),
            core: OnceLock::new(),
            full: OnceLock::new(),
        })
    }

    /// The orbit's state at `t = 0` (a start for the next orbit along a branch).
    pub fn state(&self) -> Vec<f64> {
        match &self.computed {
            Some(computed) => computed.orbit.state.clone(),
            None => json_numbers(&self.core_json()["state"]),
        }
    }

    fn core_json(&self) -> &Value {
        self.core.get_or_init(|| {
            let Some(computed) = &self.computed else {
                return Value::Null;
            };
            let mut object = orbit_json(
                &self.resolved.case.name,
                &self.resolved.model,
                &computed.orbit,
            );
            object["start"] = json!(origin_name(&computed.origin));
            object
        })
    }

    fn full_json(&self, py: Python<'_>) -> &Value {
        self.full.get_or_init(|| {
            let Some(computed) = &self.computed else {
                return Value::Null;
            };
            let resolved = &self.resolved;
            // The harmonic count the orbit was computed with (`harmonics=`), so that the
            // coexisting orbit and the inputs say the same as `simulate --harmonics`.
            let settings = SteadyOrbitSettings {
                harmonics: computed.orbit.observables().harmonics.len().max(1),
                ..SteadyOrbitSettings::default()
            };
            let (options, coexisting) = match computed.origin {
                Origin::Cli {
                    start,
                    z,
                    amplitude_ratio,
                } => {
                    let coexisting = match z {
                        Some(_) => py.allow_threads(|| {
                            coexisting_orbit(&resolved.model, &computed.orbit, start, &settings)
                        }),
                        None => None,
                    };
                    let options = json!({
                        "z_nm": z,
                        "amplitude_ratio": amplitude_ratio,
                        "start": start.name(),
                        "harmonics": settings.harmonics,
                    });
                    (
                        options,
                        coexisting.map(|other| (other, start.other().name())),
                    )
                }
                Origin::Near => (
                    json!({"z_nm": computed.orbit.z_nm, "amplitude_ratio": null, "start": "near", "harmonics": settings.harmonics}),
                    None,
                ),
            };
            simulate_json(
                &resolved.case,
                &resolved.model,
                &settings,
                &computed.orbit,
                origin_name(&computed.origin),
                coexisting.as_ref().map(|(orbit, name)| (orbit, *name)),
                options,
            )
        })
    }
}

fn origin_name(origin: &Origin) -> &'static str {
    match origin {
        Origin::Cli { start, .. } => start.name(),
        Origin::Near => "near",
    }
}

fn json_numbers(value: &Value) -> Vec<f64> {
    value
        .as_array()
        .map(|items| items.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default()
}

#[pymethods]
impl Orbit {
    /// The value of a `simulate --json` key (the attributes listed in the class docstring).
    fn __getattr__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let value = match name {
            "coexisting_orbit" | "inputs" => &self.full_json(py)[name],
            _ => match self.core_json().get(name) {
                Some(value) => value,
                None => {
                    return Err(PyAttributeError::new_err(format!(
                        "drumroll.Orbit has no attribute `{name}` (its attributes are the keys of `drumroll simulate --json`)"
                    )))
                }
            },
        };
        json_to_py(py, value)
    }

    fn __dir__(&self, py: Python<'_>) -> Vec<String> {
        let mut names: Vec<String> = self
            .core_json()
            .as_object()
            .map(|o| o.keys().cloned().collect())
            .unwrap_or_default();
        names.extend(["coexisting_orbit", "inputs"].map(String::from));
        names.extend(["to_dict", "time_series"].map(String::from));
        let _ = py;
        names.sort();
        names.dedup();
        names
    }

    /// The whole `drumroll simulate --json` object of this orbit as a dict (for an orbit
    /// found by `case.orbit(z=...)` the other start's coexisting orbit is looked for here, as
    /// the CLI does, the first time: it costs one more orbit).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, self.full_json(py))
    }

    /// The orbit sampled in time: `(t, u, force)` as numpy arrays of `periods * samples + 1`
    /// points (both ends): time since the orbit's start `t` in us, the photodiode signal `u`
    /// in nm and the tip-sample force `F_ts` in nN (MODEL.md section 1). `samples` points per
    /// drive period (default 1000), over `periods` drive periods (default: the orbit's
    /// multiplicity, one whole orbit).
    #[pyo3(signature = (samples=1000, periods=None))]
    fn time_series<'py>(
        &self,
        py: Python<'py>,
        samples: usize,
        periods: Option<usize>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (z, multiplicity) = match &self.computed {
            Some(c) => (c.orbit.z_nm, c.orbit.multiplicity),
            None => {
                let core = self.core_json();
                let z = core["z_nm"].as_f64().unwrap_or(f64::NAN);
                (z, core["multiplicity"].as_u64().unwrap_or(1) as usize)
            }
        };
        let periods = periods.unwrap_or(multiplicity);
        let state = self.state();
        let mut model = self.resolved.model.clone();
        let trajectory = py
            .allow_threads(|| {
                model.set_separation(Separation::Constant(z))?;
                sample_trajectory(
                    &model,
                    &state,
                    periods,
                    samples,
                    &hybrid::Settings::default(),
                )
            })
            .map_err(afm_to_py_err)?;
        let column = |value: fn(&afm::TrajectorySample) -> f64| {
            float_array(py, trajectory.iter().map(value).collect())
        };
        PyTuple::new(
            py,
            [
                column(|s| s.t_us)?,
                column(|s| s.u_nm)?,
                column(|s| s.force_nn)?,
            ],
        )
    }

    /// Pickling: the case and the orbit's whole JSON (so it comes back from Dask workers;
    /// `to_dict()`'s coexisting-orbit search runs before it travels).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let orbit = slf.get();
        let case = json_to_py(py, &orbit.resolved.case_json())?;
        let rebuild = py.import("drumroll")?.getattr("_restore_orbit")?;
        let args = PyTuple::new(py, [case, orbit.to_dict(py)?])?;
        PyTuple::new(py, [rebuild, args.into_any()])
    }

    fn __repr__(&self) -> String {
        let core = self.core_json();
        format!(
            "<drumroll.Orbit Z = {} nm: A/A0 = {}, phase = {} deg, {} impacts per period>",
            core["z_nm"], core["amplitude_ratio"], core["phase_deg"], core["impacts_per_period"]
        )
    }
}

/// Rebuild a pickled orbit: its case's dict (`Case.to_dict()`) and its `simulate --json`
/// object.
#[pyfunction]
pub fn _restore_orbit(case: &Bound<'_, PyAny>, data: &Bound<'_, PyAny>) -> PyResult<Orbit> {
    let resolved =
        Resolved::from_case_json(&py_to_json(case)?, "the orbit's case").map_err(to_py_err)?;
    let value = py_to_json(data)?;
    if !value.is_object() {
        return Err(PyValueError::new_err("an orbit's data must be a dict"));
    }
    let core = OnceLock::new();
    let _ = core.set(value.clone());
    let full = OnceLock::new();
    let _ = full.set(value);
    Ok(Orbit {
        resolved: Arc::new(resolved),
        computed: None,
        core,
        full,
    })
}

/// The steady orbit of the case `resolved` at `z` (or where the approach reaches `amplitude_ratio`), from
/// `start`: `"approach"`, `"transient"`, or a state (an `Orbit`, or a sequence of floats)
/// near the orbit; with harmonics `1..=harmonics` of `u` (checked as `simulate --harmonics`).
pub fn compute_orbit(
    py: Python<'_>,
    resolved: &Arc<Resolved>,
    z: Option<f64>,
    amplitude_ratio: Option<f64>,
    start: &Bound<'_, PyAny>,
    harmonics: i64,
) -> PyResult<Orbit> {
    let resolved = resolved.clone();
    let settings = SteadyOrbitSettings {
        harmonics: drumroll::option_ranges::HARMONICS
            .count(harmonics)
            .map_err(to_py_err)?,
        ..SteadyOrbitSettings::default()
    };
    if let Ok(name) = start.extract::<String>() {
        let start = match name.as_str() {
            "approach" => Start::Approach,
            "transient" => Start::Transient,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "start {name:?}: allowed \"approach\", \"transient\", or a state near the orbit (an Orbit or a sequence of floats)"
                )))
            }
        };
        let (orbit, start) = py
            .allow_threads(|| {
                drumroll::simulate::orbit_at(&resolved.model, z, amplitude_ratio, start, &settings)
            })
            .map_err(to_py_err)?;
        let origin = Origin::Cli {
            start,
            z,
            amplitude_ratio,
        };
        return Orbit::new(py, resolved, orbit, origin);
    }
    let state = match start.downcast::<Orbit>() {
        Ok(previous) => previous.get().state(),
        Err(_) => start.extract::<Vec<f64>>().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(
                "start: expected \"approach\", \"transient\", an Orbit, or a sequence of floats",
            )
        })?,
    };
    let (Some(z), None) = (z, amplitude_ratio) else {
        return Err(PyValueError::new_err(
            "a start state needs z (nm), and no amplitude_ratio",
        ));
    };
    let modes = resolved.model.mode_count();
    if state.len() != 2 * modes {
        return Err(PyValueError::new_err(format!(
            "start: a state has 2 x {modes} numbers (q_i in nm, q_i' in nm/us for each of the {modes} modes), got {}",
            state.len()
        )));
    }
    drumroll::simulate::check_orbit_options(Some(z), None)
        .and_then(|()| {
            drumroll::option_ranges::separation_for(resolved.model.free_amplitude_nm()).check(z)
        })
        .map_err(to_py_err)?;
    let orbit = py
        .allow_threads(|| {
            afm::steady_orbit(&resolved.model, z, afm::OrbitStart::Near(&state), &settings)
        })
        .map_err(|e| {
            to_py_err(anyhow::Error::new(e).context(format!("no steady orbit at Z = {z} nm")))
        })?;
    Orbit::new(py, resolved, orbit, Origin::Near)
}
