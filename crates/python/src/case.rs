//! `drumroll.Case`: a cantilever tapping a sample at a free amplitude and drive frequency
//! (MODEL.md section 3), resolved into the tapping model, and the computations on it.

use afm::{fixtures, Case as AfmCase};
use drumroll::model_args::ModelArgs;
use drumroll::option_ranges;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::path::Path;
use std::sync::Arc;

use crate::convert::{json_to_py, py_to_json, reduce_by_from_dict};
use crate::errors::to_py_err;
use crate::resolved::{from_value, Resolved};

/// A cantilever or sample given from Python: a built-in name, a file path, or a dict in the
/// files' format.
#[derive(FromPyObject)]
pub enum Reference<'py> {
    /// A built-in name or the path of a JSON file.
    #[pyo3(transparent, annotation = "str")]
    Name(String),
    /// The file's content as a dict.
    #[pyo3(transparent, annotation = "dict")]
    Dict(Bound<'py, pyo3::types::PyDict>),
}

/// Whether a reference names a file (it ends in `.json` or exists) rather than a built-in
/// fixture, as on the command line.
fn is_file_reference(reference: &str) -> bool {
    let path = Path::new(reference);
    path.extension().is_some_and(|e| e == "json") || path.exists()
}

fn resolve_cantilever(reference: &Reference<'_>) -> PyResult<afm::Cantilever> {
    let result = match reference {
        Reference::Name(name) if is_file_reference(name) => {
            fixtures::load_cantilever(Path::new(name))
        }
        Reference::Name(name) => fixtures::builtin_cantilever(name),
        Reference::Dict(dict) => from_value(
            &py_to_json(dict.as_any())?,
            "cantilever (a Python dict)",
            fixtures::parse_cantilever,
        ),
    };
    result.map_err(crate::errors::afm_to_py_err)
}

fn resolve_sample(reference: &Reference<'_>) -> PyResult<afm::Sample> {
    let result = match reference {
        Reference::Name(name) if is_file_reference(name) => fixtures::load_sample(Path::new(name)),
        Reference::Name(name) => fixtures::builtin_sample(name),
        Reference::Dict(dict) => from_value(
            &py_to_json(dict.as_any())?,
            "sample (a Python dict)",
            fixtures::parse_sample,
        ),
    };
    result.map_err(crate::errors::afm_to_py_err)
}

/// `sample` with its contact law and electrostatic double layer replaced by the dicts given
/// (in the sample files' format: `{"law": "dmt", ...}`, `{"debye_length_nm": ...}`; MODEL.md
/// section 9); errors name the field as for a sample file.
fn with_contact_law(
    sample: &afm::Sample,
    contact: Option<Bound<'_, pyo3::types::PyDict>>,
    electrostatic: Option<Bound<'_, pyo3::types::PyDict>>,
) -> PyResult<afm::Sample> {
    let mut value = serde_json::to_value(sample)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    if let Some(contact) = contact {
        value["contact"] = py_to_json(contact.as_any())?;
    }
    if let Some(electrostatic) = electrostatic {
        value["electrostatic"] = py_to_json(electrostatic.as_any())?;
    }
    from_value(
        &value,
        "sample with the contact law given in Python",
        fixtures::parse_sample,
    )
    .map_err(crate::errors::afm_to_py_err)
}

/// A simulation case: a cantilever tapping a sample at free amplitude `a0` (nm) and a drive
/// frequency (kHz), resolved into the model of MODEL.md (Eq. 1 with Hertz contact).
///
/// `Case("biolever-mica")` takes a built-in case or a case file path;
/// `Case(cantilever="biolever", sample="soft", a0=10.0)` combines a cantilever and a sample
/// (built-in names, file paths, or dicts in the files' format). `a0` and
/// `drive_frequency_khz` override a named case's values. `Case()` is the default case
/// (`biolever-mica`), as on the command line. `contact` and `electrostatic` (dicts in the
/// sample files' format, MODEL.md section 9: `contact={"law": "dmt",
/// "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}`) set the sample's
/// contact law and double layer; without them the sample's own (Hertz by default). `drive`
/// (a dict in the case files' format, MODEL.md section 14: `drive={"kind": "acoustic"}`)
/// sets the excitation; without it the case's own (direct by default).
#[pyclass(module = "drumroll", frozen)]
pub struct Case {
    /// The resolved case and its model.
    pub resolved: Arc<Resolved>,
}

#[pymethods]
impl Case {
    #[new]
    #[pyo3(signature = (name_or_path=None, *, cantilever=None, sample=None, a0=None, drive_frequency_khz=None, contact=None, electrostatic=None, drive=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        name_or_path: Option<String>,
        cantilever: Option<Reference<'_>>,
        sample: Option<Reference<'_>>,
        a0: Option<f64>,
        drive_frequency_khz: Option<f64>,
        contact: Option<Bound<'_, pyo3::types::PyDict>>,
        electrostatic: Option<Bound<'_, pyo3::types::PyDict>>,
        drive: Option<Bound<'_, pyo3::types::PyDict>>,
    ) -> PyResult<Self> {
        let has_dict = matches!(cantilever, Some(Reference::Dict(_)))
            || matches!(sample, Some(Reference::Dict(_)));
        let mut case = if has_dict {
            let (Some(cantilever), Some(sample), None) = (&cantilever, &sample, &name_or_path)
            else {
                return Err(to_py_err(anyhow::anyhow!(
                    "give either --case, or --cantilever with --sample and --a0"
                )));
            };
            let Some(a0) = a0 else {
                return Err(to_py_err(anyhow::anyhow!(
                    "--cantilever and --sample need --a0 (the free amplitude, nm)"
                )));
            };
            // The command line's checks of --a0 and --drive-frequency, with its messages.
            option_ranges::A0.check(a0).map_err(to_py_err)?;
            let cantilever = resolve_cantilever(cantilever)?;
            if let Some(frequency) = drive_frequency_khz {
                option_ranges::drive_frequency_for(&cantilever)
                    .check(frequency)
                    .map_err(to_py_err)?;
            }
            let sample = resolve_sample(sample)?;
            AfmCase {
                name: format!("{}-{}", cantilever.name, sample.name),
                description: String::from("from Python"),
                cantilever,
                sample,
                free_amplitude_nm: a0,
                drive_frequency_khz,
                drive: afm::model::drive_spec::DriveSpec::Direct,
            }
        } else {
            let name = |r: Option<Reference<'_>>| match r {
                Some(Reference::Name(name)) => Some(name),
                _ => None,
            };
            let args = ModelArgs {
                case: name_or_path.into_iter().collect(),
                cantilever: name(cantilever),
                sample: name(sample),
                a0,
                drive_frequency: drive_frequency_khz,
            };
            py.allow_threads(|| args.case()).map_err(to_py_err)?
        };
        if contact.is_some() || electrostatic.is_some() {
            case.sample = with_contact_law(&case.sample, contact, electrostatic)?;
        }
        if let Some(drive) = drive {
            case.drive = serde_json::from_value(py_to_json(drive.as_any())?).map_err(|e| {
                pyo3::exceptions::PyValueError::new_err(format!(
                    "the Python arguments: field `drive`: {e} (a case file's drive object: \
                     {{\"kind\": \"direct\" | \"acoustic\" | \"bimodal\", ...}}, MODEL.md section 14)"
                ))
            })?;
        }
        let resolved = py
            .allow_threads(|| Resolved::new(case))
            .map_err(to_py_err)?;
        Ok(Self {
            resolved: Arc::new(resolved),
        })
    }

    /// The case's name, e.g. `biolever-mica`.
    #[getter]
    fn name(&self) -> String {
        self.resolved.case.name.clone()
    }

    /// The free amplitude A0 of the photodiode signal u, nm (MODEL.md section 3).
    #[getter]
    fn a0(&self) -> f64 {
        self.resolved.model.free_amplitude_nm()
    }

    /// The drive frequency, kHz (the case's, else the fundamental f_1).
    #[getter]
    fn drive_frequency_khz(&self) -> f64 {
        self.resolved.model.drive_frequency_khz()
    }

    /// The drive period T = 1/f, us.
    #[getter]
    fn period_us(&self) -> f64 {
        self.resolved.model.period_us()
    }

    /// First contact Z_G1: the separation where the free orbit's lowest gap is zero, nm.
    #[getter]
    fn first_contact_z_nm(&self) -> f64 {
        self.resolved.model.grazing_separation_nm()
    }

    /// The phase of the free orbit (no contact), degrees (a lag; MODEL.md section 4).
    #[getter]
    fn free_phase_deg(&self) -> f64 {
        self.resolved.model.free_phase_deg()
    }

    /// The steady periodic orbit at separation `z` (nm), or, with `amplitude_ratio` instead,
    /// where the quasi-static approach reaches that A/A0 (refined to 1e-9 nm), as
    /// `drumroll simulate`. `start`: `"approach"` (default: the orbit of the quasi-static
    /// approach, the one the paper and `continue` report), `"transient"` (the attractor of
    /// transients from the free orbit), or a state near the orbit: a previous `Orbit` (at a
    /// nearby Z, as along a branch: the fast warm start) or the state `[q_1, q_1', ...]` (nm,
    /// nm/us). `harmonics`: the harmonics n = 1..N of u among the attributes (`harmonics`,
    /// N in [1, 1000], as `simulate --harmonics`). Runs without the GIL.
    #[pyo3(signature = (z=None, *, amplitude_ratio=None, start=None, harmonics=drumroll::approach::DEFAULT_HARMONICS))]
    fn orbit(
        &self,
        py: Python<'_>,
        z: Option<f64>,
        amplitude_ratio: Option<f64>,
        start: Option<&Bound<'_, PyAny>>,
        harmonics: i64,
    ) -> PyResult<crate::orbit::Orbit> {
        let default = pyo3::types::PyString::new(py, "approach");
        let start = start.unwrap_or(default.as_any());
        crate::orbit::compute_orbit(py, &self.resolved, z, amplitude_ratio, start, harmonics)
    }

    /// The bifurcation diagram in Z (the paper's Fig. 2), as `drumroll continue`: the
    /// periodic orbits continued from above first contact down to `floor` (nm, in
    /// [-A0, Z_G1); default 0.05 A0) or until A/A0 < `min_amplitude_ratio` (default 0.3; 0
    /// disables), arclength steps of at most `max_step` (nm; default A0/250), special points
    /// located to |dZ| < 1e-9 nm, at most `max_points` points per branch (a branch that
    /// reaches it stops there: `completed` is then False); with `retract=True` also back up
    /// from the lowest point; `harmonics`: the harmonics n = 1..N of u at every point (the
    /// table's `harmonic_<n>_amplitude_nm`, `harmonic_<n>_phase_deg` columns; N in [1, 1000]).
    /// Runs without the GIL; Ctrl-C interrupts it between branch points.
    #[pyo3(signature = (*, floor=None, min_amplitude_ratio=0.3, max_step=None, max_points=20000, retract=false, harmonics=drumroll::approach::DEFAULT_HARMONICS))]
    #[allow(clippy::too_many_arguments)]
    fn diagram(
        &self,
        py: Python<'_>,
        floor: Option<f64>,
        min_amplitude_ratio: f64,
        max_step: Option<f64>,
        max_points: i64,
        retract: bool,
        harmonics: i64,
    ) -> PyResult<crate::diagram::Diagram> {
        let options = crate::diagram::DiagramOptions {
            floor,
            min_amplitude_ratio,
            max_step,
            max_points,
            retract,
            harmonics,
        };
        crate::diagram::compute_diagram(py, &self.resolved, &options)
    }

    /// Fit this case's approach branch to `measurement` (a `drumroll.Measurement`) over the
    /// parameters in `fit` (`z-offset`, `amplitude-calibration`, `phase-offset`,
    /// `sample-modulus`, `tip-radius`, ...), as `drumroll fit` (MODEL.md section 13.3):
    /// a `drumroll.FitResult`. Runs without the GIL; Ctrl-C stops it (between the branch points
    /// of its followed branches) and raises KeyboardInterrupt.
    #[pyo3(signature = (measurement, *, fit=vec![String::from("z-offset"), String::from("phase-offset"), String::from("sample-modulus")], max_evaluations=40))]
    fn fit(
        &self,
        py: Python<'_>,
        measurement: &crate::measurement::Measurement,
        fit: Vec<String>,
        max_evaluations: usize,
    ) -> PyResult<crate::measurement::FitResult> {
        crate::measurement::fit_case(py, &self.resolved, measurement, fit, max_evaluations)
    }

    /// A time-domain approach sweep as in the lab, as `drumroll approach`: Z falls from
    /// `from_nm` (default 0.2 nm above first contact) to `to_nm` (nm, default 0) at
    /// `rate_nm_per_s` (nm/s, default the paper's 1), read by a lock-in over blocks of
    /// `lockin_cycles` drive cycles, every `every`-th reading kept, after `settle_cycles`
    /// cycles at the start; `retract=True` sweeps back up; `tolerance` is the contact
    /// integration's. Returns a pandas DataFrame (dict of numpy arrays without pandas), one
    /// row per reading: `cycle`, `z_nm`, `amplitude_ratio`, `phase_deg` (deg),
    /// `impacts_per_period`, `peak_force_nn` (nN), `dissipated_ev` (eV per cycle),
    /// `direction`, then `harmonic_<n>_amplitude_nm` and `harmonic_<n>_phase_deg` for
    /// `n = 1..harmonics` (N in [1, 1000]); `attrs["inputs"]` holds the
    /// inputs. Runs without the GIL; Ctrl-C stops it and raises KeyboardInterrupt.
    #[pyo3(signature = (*, from_nm=None, to_nm=0.0, rate_nm_per_s=1.0, retract=false, lockin_cycles=1, every=1, settle_cycles=20, tolerance=afm::sweep::DEFAULT_TOLERANCE, harmonics=drumroll::approach::DEFAULT_HARMONICS))]
    #[allow(clippy::too_many_arguments)]
    fn approach<'py>(
        &self,
        py: Python<'py>,
        from_nm: Option<f64>,
        to_nm: f64,
        rate_nm_per_s: f64,
        retract: bool,
        lockin_cycles: i64,
        every: i64,
        settle_cycles: i64,
        tolerance: f64,
        harmonics: i64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let options = crate::approach::ApproachOptions {
            from_nm,
            to_nm,
            rate_nm_per_s,
            retract,
            lockin_cycles,
            every,
            settle_cycles,
            tolerance,
            harmonics,
        };
        crate::approach::compute_approach(py, &self.resolved, &options)
    }

    /// An image line with amplitude feedback, as `drumroll scan` (MODEL.md section 12): the
    /// case's cantilever, drive and A0 over `line` (a built-in line name, a line file path, or
    /// a dict in the line files' format), `pixels` pixels at the setpoint A/A0 `setpoint`,
    /// `feedback` `"ideal"` (steady orbits followed along their branches, jumps marked) or
    /// `"pi"` (the time-domain loop: `gain_p` nm/nm, `gain_i_per_ms` 1/ms,
    /// `scan_rate_nm_per_s`, `lockin_time_constant_ms`), `direction` `"trace"`, `"retrace"`
    /// or `"both"`. Returns a pandas DataFrame (dict of numpy arrays without pandas), one row
    /// per pixel with the CLI's CSV columns (`height_nm`, `z_nm`, `phase_deg`,
    /// `impacts_per_period`, ...); `attrs["inputs"]` and `attrs["line"]` as in `--json`.
    /// `raster` (a raster file path or a dict in the raster files' format) instead of `line`
    /// scans every row as a line, as `drumroll scan --raster` (the rows in parallel): the
    /// columns `row` and `y_nm` (nm) follow `direction`, and `attrs["raster"]` replaces
    /// `attrs["line"]`. Runs without the GIL; Ctrl-C stops it and raises KeyboardInterrupt.
    #[pyo3(signature = (line=None, *, raster=None, setpoint=0.8, pixels=64, feedback="ideal", direction="trace", gain_p=0.2, gain_i_per_ms=0.5, scan_rate_nm_per_s=100.0, lockin_time_constant_ms=0.0, harmonics=4))]
    #[allow(clippy::too_many_arguments)]
    fn scan<'py>(
        &self,
        py: Python<'py>,
        line: Option<&Bound<'py, PyAny>>,
        raster: Option<&Bound<'py, PyAny>>,
        setpoint: f64,
        pixels: i64,
        feedback: &str,
        direction: &str,
        gain_p: f64,
        gain_i_per_ms: f64,
        scan_rate_nm_per_s: f64,
        lockin_time_constant_ms: f64,
        harmonics: i64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let options = crate::scan::ScanOptions {
            setpoint,
            pixels,
            feedback: feedback.to_string(),
            direction: direction.to_string(),
            gain_p,
            gain_i_per_ms,
            scan_rate_nm_per_s,
            lockin_time_constant_ms,
            harmonics,
        };
        if let Some(raster) = raster {
            if line.is_some() {
                return Err(pyo3::exceptions::PyValueError::new_err(
                    "scan: give a line or a raster, not both",
                ));
            }
            return crate::scan::compute_raster_scan(py, &self.resolved, raster, &options);
        }
        let default = pyo3::types::PyString::new(py, "membrane-patch");
        let line = line.cloned().unwrap_or_else(|| default.into_any());
        crate::scan::compute_scan(py, &self.resolved, &line, &options)
    }

    /// The impact-regime map, as `drumroll map`: every special point of the case's approach
    /// diagram (G_n, fold, period doubling; or those named in `labels`) continued as a curve
    /// over the parameter `vary` (`"a0"` nm, `"drive-frequency"` kHz, `"sample-modulus"` GPa,
    /// `"tip-radius"` nm, `"quality-factor-N"`, `"stiffness-N"` N/m for mode N) from the
    /// case's own value over [`start`, `stop`], with a point exactly at each value of `at`
    /// and at least `points` points per curve over the range. `floor`,
    /// `min_amplitude_ratio` and `max_step` set the seed approach as in `diagram`;
    /// `harmonics`: the harmonics n = 1..N of u at every curve point (N in [1, 1000]). Runs
    /// without the GIL; Ctrl-C stops it (between the steps of its curves) and raises
    /// KeyboardInterrupt.
    #[pyo3(signature = (vary, start, stop, *, at=None, labels=None, points=100, floor=None, min_amplitude_ratio=0.3, max_step=None, harmonics=drumroll::approach::DEFAULT_HARMONICS))]
    #[allow(clippy::too_many_arguments)]
    fn map(
        &self,
        py: Python<'_>,
        vary: String,
        start: f64,
        stop: f64,
        at: Option<Vec<f64>>,
        labels: Option<Vec<String>>,
        points: usize,
        floor: Option<f64>,
        min_amplitude_ratio: f64,
        max_step: Option<f64>,
        harmonics: i64,
    ) -> PyResult<crate::regime_map::RegimeMap> {
        let options = crate::regime_map::MapOptions {
            vary,
            start,
            stop,
            at: at.unwrap_or_default(),
            labels: labels.unwrap_or_default(),
            points,
            floor,
            min_amplitude_ratio,
            max_step,
            harmonics,
        };
        crate::regime_map::compute_regime_map(py, &self.resolved, options)
    }

    /// The case as a dict in the case files' format, the cantilever and the sample inline
    /// (`Case.from_dict` builds it back).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.resolved.case_json())
    }

    /// The case of a dict as `to_dict` returns it.
    #[classmethod]
    fn from_dict(_cls: &Bound<'_, pyo3::types::PyType>, data: &Bound<'_, PyAny>) -> PyResult<Self> {
        let value = py_to_json(data)?;
        let resolved = Resolved::from_case_json(&value, "the case dict").map_err(to_py_err)?;
        Ok(Self {
            resolved: Arc::new(resolved),
        })
    }

    /// Pickling: the case travels as its dict (so it reaches Dask workers).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let state = slf.get().to_dict(slf.py())?;
        reduce_by_from_dict::<Self>(slf.py(), state)
    }

    fn __repr__(&self) -> String {
        let model = &self.resolved.model;
        format!(
            "<drumroll.Case '{}': A0 = {} nm, drive {:.4} kHz, first contact Z_G1 = {:.6} nm>",
            self.resolved.case.name,
            model.free_amplitude_nm(),
            model.drive_frequency_khz(),
            model.grazing_separation_nm()
        )
    }
}
