//! Fitting the model's followed approach branch to a measured curve (MODEL.md section 13.3):
//! weighted least squares of the measured amplitude and phase over the piezo offset, the
//! amplitude calibration, the phase offset and any of the map's case parameters, by
//! Levenberg-Marquardt (the `levenberg-marquardt` crate), with standard errors and correlations
//! from the Jacobian at the optimum (MODEL.md section 13.4).

use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, PoisonError};

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::storage::Owned;
use nalgebra::{DMatrix, DVector, Dyn};
use rayon::prelude::*;
use serde::Serialize;

use crate::diagram::bifurcation_diagram::{approach_diagram_until, DiagramPoint, DiagramSettings};
use crate::error::AfmError;
use crate::fit::followed_branch::{FollowedBranch, Reading};
use crate::fit::measurement::{noise_sigma, MeasuredPoint, Measurement};
use crate::map::parameter_axis::ParameterAxis;
use crate::model::case::Case;
use crate::model::TappingModel;

/// A fitted quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FitParameter {
    /// `z_offset`, nm: drumroll's `Z = Z_data - z_offset` (`z-offset`).
    ZOffset,
    /// `c`: the instrument reports `c A` and `c A0` (`amplitude-calibration`).
    AmplitudeCalibration,
    /// `phase_data = phase + offset`, degrees (`phase-offset`).
    PhaseOffset,
    /// A case parameter of the regime map (`sample-modulus`, `tip-radius`, ...).
    Case(ParameterAxis),
}

impl FitParameter {
    /// Parse a `--fit` name: `z-offset`, `amplitude-calibration`, `phase-offset`, or a name of
    /// [`crate::map::parameter_axis::PARAMETER_NAMES`] other than `a0` (the free amplitude is
    /// the measured one over the calibration).
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] naming `--fit` and the allowed names.
    pub fn parse(name: &str, modes: usize) -> Result<Self, AfmError> {
        match name.trim() {
            "z-offset" => Ok(Self::ZOffset),
            "amplitude-calibration" => Ok(Self::AmplitudeCalibration),
            "phase-offset" => Ok(Self::PhaseOffset),
            other => match ParameterAxis::parse(other, modes) {
                Ok(ParameterAxis::FreeAmplitude) | Err(_) => Err(AfmError::InvalidField {
                    file: String::from("command line"),
                    field: String::from("--fit"),
                    value: format!("{other:?}"),
                    allowed: format!(
                        "a comma-separated list of z-offset, amplitude-calibration, phase-offset, drive-frequency, sample-modulus, tip-radius, quality-factor-N, stiffness-N (N from 1 to {modes})"
                    ),
                }),
                Ok(axis) => Ok(Self::Case(axis)),
            },
        }
    }

    /// The output key: `z_offset_nm`, `amplitude_calibration`, `phase_offset_deg`,
    /// `sample_modulus_gpa`, `tip_radius_nm`, `drive_frequency_khz`, `quality_factor_N`,
    /// `stiffness_N_n_per_m`.
    pub fn key(self) -> String {
        match self {
            Self::ZOffset => String::from("z_offset_nm"),
            Self::AmplitudeCalibration => String::from("amplitude_calibration"),
            Self::PhaseOffset => String::from("phase_offset_deg"),
            Self::Case(axis) => match axis {
                ParameterAxis::SampleModulus => String::from("sample_modulus_gpa"),
                ParameterAxis::TipRadius => String::from("tip_radius_nm"),
                ParameterAxis::DriveFrequency => String::from("drive_frequency_khz"),
                ParameterAxis::QualityFactor(n) => format!("quality_factor_{n}"),
                ParameterAxis::Stiffness(n) => format!("stiffness_{n}_n_per_m"),
                ParameterAxis::FreeAmplitude => String::from("a0_nm"),
            },
        }
    }

    /// Whether the fit works in the logarithm of the value (positive scale parameters).
    fn logarithmic(self) -> bool {
        matches!(self, Self::AmplitudeCalibration | Self::Case(_))
    }
}

/// A quantity Levenberg-Marquardt varies. The calibration `c` is fitted as the model's free
/// amplitude `A0 = A0_rep / c` together with the reported free amplitude `A0_rep` (both
/// through their logarithms, `ln c = ln A0_rep - ln A0`), so that the error of the measured
/// `A0_rep` reaches every parameter through the covariance (MODEL.md section 13.4).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Internal {
    /// `z_offset`, nm.
    ZOffset,
    /// The phase offset, degrees.
    PhaseOffset,
    /// `ln A0` of the model, `A0` in nm.
    ModelAmplitude,
    /// `ln A0_rep`, the free amplitude as the instrument reports it, nm.
    ReportedAmplitude,
    /// The logarithm of a case parameter.
    Case(ParameterAxis),
}

/// The quantities varied for `parameters`, in order, and the matrix `T` (one row per fitted
/// parameter) with `theta_user = T theta_internal` (in the logarithms for `c` and the case
/// parameters).
fn internal_parameters(parameters: &[FitParameter]) -> (Vec<Internal>, DMatrix<f64>) {
    let mut internal: Vec<Internal> = parameters
        .iter()
        .map(|p| match p {
            FitParameter::ZOffset => Internal::ZOffset,
            FitParameter::PhaseOffset => Internal::PhaseOffset,
            FitParameter::AmplitudeCalibration => Internal::ModelAmplitude,
            FitParameter::Case(axis) => Internal::Case(*axis),
        })
        .collect();
    let calibration = parameters.contains(&FitParameter::AmplitudeCalibration);
    if calibration {
        internal.push(Internal::ReportedAmplitude);
    }
    let mut transform = DMatrix::zeros(parameters.len(), internal.len());
    for (k, p) in parameters.iter().enumerate() {
        if *p == FitParameter::AmplitudeCalibration {
            transform[(k, k)] = -1.0;
            transform[(k, internal.len() - 1)] = 1.0;
        } else {
            transform[(k, k)] = 1.0;
        }
    }
    (internal, transform)
}

/// How a fit is made.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSettings {
    /// The fitted quantities (at least one, no repeats).
    pub parameters: Vec<FitParameter>,
    /// Step of the central differences in the logarithm of the model's free amplitude and case
    /// parameters (default 0.002).
    pub difference_step: f64,
    /// Budget of Levenberg-Marquardt's residual evaluations (default 40): MINPACK's patience,
    /// `ceil(max_evaluations / (q + 1))` times `q + 1` for `q` varied quantities, so rounded up
    /// to that multiple; the Jacobian's central differences are not counted.
    pub max_evaluations: usize,
}

impl FitSettings {
    /// The defaults for `parameters`.
    pub fn new(parameters: Vec<FitParameter>) -> Self {
        Self {
            parameters,
            difference_step: 0.002,
            max_evaluations: 40,
        }
    }
}

/// A fitted value with its standard error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedValue {
    /// The output key (see [`FitParameter::key`]).
    pub name: String,
    /// The value at the optimum, in the key's unit.
    pub value: f64,
    /// Its standard error (1 sigma, from the Jacobian with the residuals' scale); `None` if
    /// the data cannot determine it.
    pub stderr: Option<f64>,
    /// The starting value.
    pub initial: f64,
}

/// A grazing point of the fitted model, in data coordinates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedGrazing {
    /// `G1`, `G2`, ... or `fold`.
    pub label: String,
    /// `Z` in data coordinates (`Z + z_offset`), nm.
    pub z_nm: f64,
    /// `A/A0` there.
    pub amplitude_ratio: f64,
    /// The phase there as the instrument shows it (with the offset), degrees.
    pub phase_deg: f64,
}

/// One measured point with the fitted model there (contrast observables of MODEL.md section
/// 10, on the followed branch).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedPoint {
    /// Line in the file.
    pub line: usize,
    /// Data `Z`, nm.
    pub z_nm: f64,
    /// Measured amplitude, nm.
    pub amplitude_nm: f64,
    /// Measured phase, degrees.
    pub phase_deg: f64,
    /// drumroll's separation `Z = z_nm - z_offset`, nm.
    pub separation_nm: f64,
    /// The model's amplitude as the instrument reports it (`A/A0` times the fitted reported
    /// `A0`, `c A0`), nm.
    pub model_amplitude_nm: f64,
    /// The model's phase plus the offset, degrees.
    pub model_phase_deg: f64,
    /// The model's impacts per period.
    pub impacts_per_period: f64,
    /// The model's peak force, nN.
    pub peak_force_nn: f64,
    /// The energy dissipated in the sample per period, eV.
    pub dissipated_ev: f64,
    /// The virial, eV.
    pub virial_ev: f64,
    /// The largest indentation, nm.
    pub max_indentation_nm: f64,
    /// The mean indentation in contact, nm.
    pub mean_indentation_nm: f64,
}

/// The result of a fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitResult {
    /// The fitted values, in the order asked.
    pub parameters: Vec<FittedValue>,
    /// Their correlation matrix, in the same order (`None` entries: undetermined).
    pub correlations: Vec<Vec<Option<f64>>>,
    /// RMS of the amplitude residuals, nm.
    pub residual_rms_amplitude_nm: f64,
    /// RMS of the phase residuals, degrees.
    pub residual_rms_phase_deg: f64,
    /// `chi^2` per degree of freedom with the noise estimated from second differences.
    pub reduced_chi2: f64,
    /// The noise used as weights: amplitude nm, phase degrees.
    pub noise: [f64; 2],
    /// The fitted model's grazing points and folds on its approach.
    pub grazing: Vec<FittedGrazing>,
    /// The measured approach with the fitted model.
    pub points: Vec<FittedPoint>,
    /// Residual evaluations made.
    pub evaluations: usize,
    /// Why Levenberg-Marquardt stopped.
    pub termination: String,
    /// Whether it stopped at a converged optimum.
    pub converged: bool,
    /// Warnings (undetermined parameters, a poor fit).
    pub warnings: Vec<String>,
}

/// The cached followed branches, by the model's parameter values (bit patterns).
type BranchCache = HashMap<Vec<u64>, Arc<FollowedBranch>>;

/// The weighted residuals, amplitude (over its noise) then phase, as a function of the varied
/// quantities `theta`, and their Jacobian; the followed branches are cached, and shared by the
/// threads that evaluate the Jacobian's central differences.
struct Residuals<'a> {
    case: &'a Case,
    points: &'a [MeasuredPoint],
    parameters: Vec<Internal>,
    fixed: Fixed,
    sigma: [f64; 2],
    step: f64,
    z_floor: f64,
    cache: Mutex<BranchCache>,
    /// Asked after every branch point of every followed branch, from any thread: `true` ends
    /// the fit with [`AfmError::Interrupted`].
    stop: &'a (dyn Fn() -> bool + Sync),
}

/// The least-squares problem Levenberg-Marquardt sees: the residuals at its current `theta`,
/// the first error met kept (the trait's residuals and Jacobian can only say `None`).
///
/// A trial step whose model cannot be built or followed (a parameter pushed out of its range,
/// a continuation that fails there) is rejected, not fatal: its residuals are
/// [`REJECTED_RESIDUAL`] each, far above any accepted norm, so that Levenberg-Marquardt counts
/// the step as a failed reduction, shrinks its trust region and tries a shorter one. Only the
/// starting point and the Jacobian's differences fail the fit.
struct Problem<'a> {
    residuals: Residuals<'a>,
    theta: DVector<f64>,
    failure: RefCell<Option<AfmError>>,
    /// Whether the starting point's residuals have been evaluated (later evaluations are
    /// trial steps).
    started: Cell<bool>,
    /// The trial steps rejected, and the first one's error.
    rejected: RefCell<(usize, Option<AfmError>)>,
}

/// Each residual of a rejected trial step (weighted, dimensionless): with `m` residuals its norm
/// `1e100 sqrt(m)` exceeds ten times any accepted norm, which Levenberg-Marquardt (MINPACK's
/// `lmder`) takes as an increase: the step is not taken and the trust region shrinks tenfold.
/// Its square stays finite.
const REJECTED_RESIDUAL: f64 = 1e100;

/// Values of the parameters that are not fitted.
#[derive(Debug, Clone, Copy)]
struct Fixed {
    z_offset: f64,
    model_a0: f64,
    reported_a0: f64,
    phase_offset: f64,
}

/// The full set of values of a parameter vector.
struct Values {
    z_offset: f64,
    /// The model's free amplitude, nm.
    model_a0: f64,
    /// The free amplitude the instrument reports, nm.
    reported_a0: f64,
    phase_offset: f64,
    case: Vec<(ParameterAxis, f64)>,
}

impl Residuals<'_> {
    fn values(&self, theta: &DVector<f64>) -> Values {
        let mut values = Values {
            z_offset: self.fixed.z_offset,
            model_a0: self.fixed.model_a0,
            reported_a0: self.fixed.reported_a0,
            phase_offset: self.fixed.phase_offset,
            case: Vec::new(),
        };
        for (k, p) in self.parameters.iter().enumerate() {
            match p {
                Internal::ZOffset => values.z_offset = theta[k],
                Internal::ModelAmplitude => values.model_a0 = theta[k].exp(),
                Internal::ReportedAmplitude => values.reported_a0 = theta[k].exp(),
                Internal::PhaseOffset => values.phase_offset = theta[k],
                Internal::Case(axis) => values.case.push((*axis, theta[k].exp())),
            }
        }
        values
    }

    /// The followed branch of the model at `values` (cached; computed outside the cache's
    /// lock, so threads asking for different branches compute them at the same time).
    fn branch(&self, values: &Values) -> Result<Arc<FollowedBranch>, AfmError> {
        let mut key: Vec<u64> = vec![values.model_a0.to_bits()];
        key.extend(values.case.iter().map(|(_, v)| v.to_bits()));
        let cached = self
            .cache
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&key)
            .cloned();
        if let Some(branch) = cached {
            return Ok(branch);
        }
        let mut case = self.case.clone();
        case.free_amplitude_nm = values.model_a0;
        for (axis, value) in &values.case {
            case = axis.apply(&case, *value, "fit")?;
        }
        let model = TappingModel::from_case(&case)?;
        let a0 = model.free_amplitude_nm();
        let mut settings = DiagramSettings::approach(&model);
        settings.min_amplitude_ratio = 0.0;
        settings.z_limit_nm = self
            .z_floor
            .clamp(-0.95 * a0, 0.9 * model.grazing_separation_nm());
        let branch = Arc::new(FollowedBranch::new(approach_diagram_until(
            &model,
            &settings,
            &mut || (self.stop)(),
        )?));
        let mut cache = self.cache.lock().unwrap_or_else(PoisonError::into_inner);
        if cache.len() > 64 {
            cache.clear();
        }
        cache.insert(key, branch.clone());
        Ok(branch)
    }

    fn residuals_at(&self, theta: &DVector<f64>) -> Result<DVector<f64>, AfmError> {
        let values = self.values(theta);
        let branch = self.branch(&values)?;
        let n = self.points.len();
        let mut r = DVector::zeros(2 * n);
        for (i, p) in self.points.iter().enumerate() {
            let z = p.z_nm - values.z_offset;
            let ratio = branch.value(z, |d| d.amplitude_ratio).value;
            let phase = branch.value(z, |d| d.phase_deg).value;
            r[i] = (p.amplitude_nm - values.reported_a0 * ratio) / self.sigma[0];
            r[n + i] = (p.phase_deg - phase - values.phase_offset) / self.sigma[1];
        }
        Ok(r)
    }

    /// The Jacobian of the residuals at `theta`, its columns computed in parallel (a model
    /// parameter's central differences are two followed branches); the first failing column's
    /// error, in parameter order.
    fn jacobian_at(&self, theta: &DVector<f64>) -> Result<DMatrix<f64>, AfmError> {
        let values = self.values(theta);
        let branch = self.branch(&values)?;
        let columns: Vec<Result<DVector<f64>, AfmError>> = (0..self.parameters.len())
            .into_par_iter()
            .map(|k| self.jacobian_column(k, theta, &values, &branch))
            .collect();
        let mut jacobian = DMatrix::zeros(2 * self.points.len(), self.parameters.len());
        for (k, column) in columns.into_iter().enumerate() {
            jacobian.set_column(k, &column?);
        }
        Ok(jacobian)
    }

    /// Column `k` of the Jacobian at `theta` (whose values and followed branch are `values`
    /// and `branch`): exact for the offsets and the reported amplitude, central differences
    /// in the logarithm for the model's parameters (`(r(up) - r(down)) / (2 step)`, both
    /// branches at once), one-sided where one of them fails (`(r(up) - r) / step` or `(r -
    /// r(down)) / step`: next to a parameter's bound); the `up` one's error where both fail.
    fn jacobian_column(
        &self,
        k: usize,
        theta: &DVector<f64>,
        values: &Values,
        branch: &FollowedBranch,
    ) -> Result<DVector<f64>, AfmError> {
        let n = self.points.len();
        let mut column = DVector::zeros(2 * n);
        match self.parameters[k] {
            Internal::ZOffset => {
                for (i, point) in self.points.iter().enumerate() {
                    let z = point.z_nm - values.z_offset;
                    let ratio = branch.value(z, |d| d.amplitude_ratio).slope;
                    let phase = branch.value(z, |d| d.phase_deg).slope;
                    column[i] = values.reported_a0 * ratio / self.sigma[0];
                    column[n + i] = phase / self.sigma[1];
                }
            }
            Internal::PhaseOffset => {
                for i in 0..n {
                    column[n + i] = -1.0 / self.sigma[1];
                }
            }
            Internal::ReportedAmplitude => {
                // d/d(ln A0_rep) of (A_i - A0_rep ratio_i) / sigma, exact.
                for (i, point) in self.points.iter().enumerate() {
                    let z = point.z_nm - values.z_offset;
                    let ratio = branch.value(z, |d| d.amplitude_ratio).value;
                    column[i] = -values.reported_a0 * ratio / self.sigma[0];
                }
            }
            Internal::ModelAmplitude | Internal::Case(_) => {
                // Central differences in the logarithm; one-sided (against the residuals at
                // `theta`) where one side leaves the model's valid range or fails, as at a
                // parameter's bound.
                let mut up = theta.clone();
                up[k] += self.step;
                let mut down = theta.clone();
                down[k] -= self.step;
                let (up, down) =
                    rayon::join(|| self.residuals_at(&up), || self.residuals_at(&down));
                column = match (up, down) {
                    (Err(AfmError::Interrupted), _) | (_, Err(AfmError::Interrupted)) => {
                        return Err(AfmError::Interrupted)
                    }
                    (Ok(up), Ok(down)) => (up - down) / (2.0 * self.step),
                    (Ok(up), Err(_)) => (up - self.residuals_at(theta)?) / self.step,
                    (Err(_), Ok(down)) => (self.residuals_at(theta)? - down) / self.step,
                    (Err(error), Err(_)) => return Err(error),
                };
            }
        }
        Ok(column)
    }
}

impl Problem<'_> {
    fn note(&self, error: AfmError) {
        let mut failure = self.failure.borrow_mut();
        if failure.is_none() {
            *failure = Some(error);
        }
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.theta.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.theta.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        match self.residuals.residuals_at(&self.theta) {
            Ok(r) => {
                self.started.set(true);
                Some(r)
            }
            Err(error) if self.started.get() && !matches!(error, AfmError::Interrupted) => {
                let mut rejected = self.rejected.borrow_mut();
                rejected.0 += 1;
                rejected.1.get_or_insert(error);
                Some(DVector::from_element(
                    2 * self.residuals.points.len(),
                    REJECTED_RESIDUAL,
                ))
            }
            Err(error) => {
                self.note(error);
                None
            }
        }
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        self.residuals
            .jacobian_at(&self.theta)
            .map_err(|e| self.note(e))
            .ok()
    }
}

/// The `Z` (nm) where `ratio(Z)` first falls below `level` going down from the top of a curve
/// sorted by decreasing `Z`, from a running median of 5 (robust to noise).
fn crossing(z: &[f64], ratio: &[f64], level: f64) -> Option<f64> {
    (2..ratio.len().saturating_sub(2)).find_map(|i| {
        let mut window = ratio[i - 2..=i + 2].to_vec();
        window.sort_by(f64::total_cmp);
        (window[2] < level).then_some(z[i])
    })
}

/// Fit the followed approach branch of `case` to `measurement`'s approach over
/// `settings.parameters` (MODEL.md section 13.3); parameters not fitted stay at `z_offset` from
/// aligning `A/A0 = 0.9`, `c = 1`, the phase offset that matches the free phase, and the
/// case's values.
///
/// # Errors
/// [`AfmError::InvalidField`] for an empty or repeated parameter list; a model error if the
/// model cannot be built or continued at the starting values.
pub fn fit_measurement(
    case: &Case,
    measurement: &Measurement,
    settings: &FitSettings,
) -> Result<FitResult, AfmError> {
    fit_measurement_until(case, measurement, settings, &|| false)
}

/// As [`fit_measurement`], asking `stop` (from any thread) after every branch point of every
/// followed branch whether to give up: when it answers `true` the fit ends with
/// [`AfmError::Interrupted`] (a caller's Ctrl-C or cancel button).
///
/// # Errors
/// As [`fit_measurement`], and [`AfmError::Interrupted`].
pub fn fit_measurement_until(
    case: &Case,
    measurement: &Measurement,
    settings: &FitSettings,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<FitResult, AfmError> {
    let parameters = &settings.parameters;
    if parameters.is_empty()
        || (0..parameters.len()).any(|i| parameters[..i].contains(&parameters[i]))
    {
        return Err(AfmError::InvalidField {
            file: String::from("command line"),
            field: String::from("--fit"),
            value: format!("{} parameters", parameters.len()),
            allowed: String::from("one or more parameters, each once"),
        });
    }
    let points = &measurement.approach;
    let a0 = measurement.a0_nm;
    let amplitudes: Vec<f64> = points.iter().map(|p| p.amplitude_nm).collect();
    let phases: Vec<f64> = points.iter().map(|p| p.phase_deg).collect();
    let sigma = [
        noise_sigma(&amplitudes).max(1e-6 * a0),
        noise_sigma(&phases).max(1e-6),
    ];
    // Starting values from the case's model.
    let initial_problem = Residuals {
        case,
        points,
        parameters: Vec::new(),
        fixed: Fixed {
            z_offset: 0.0,
            model_a0: a0,
            reported_a0: a0,
            phase_offset: 0.0,
        },
        sigma,
        step: settings.difference_step,
        z_floor: 0.0,
        cache: Mutex::new(HashMap::new()),
        stop,
    };
    let start_values = Values {
        z_offset: 0.0,
        model_a0: a0,
        reported_a0: a0,
        phase_offset: 0.0,
        case: Vec::new(),
    };
    let start = initial_problem.branch(&start_values)?;
    let zs: Vec<f64> = points.iter().map(|p| p.z_nm).collect();
    let ratios: Vec<f64> = amplitudes.iter().map(|a| a / a0).collect();
    let model_z: Vec<f64> = start.diagram.points.iter().map(|p| p.z_nm).collect();
    let model_ratio: Vec<f64> = start
        .diagram
        .points
        .iter()
        .map(|p| p.amplitude_ratio)
        .collect();
    let z_offset = match (
        crossing(&zs, &ratios, 0.9),
        crossing(&model_z, &model_ratio, 0.9),
    ) {
        (Some(data), Some(model)) => data - model,
        _ => zs[0] - start.z_top(),
    };
    let free = measurement.free_rows.max(1).min(points.len());
    let free_phase = phases[..free].iter().sum::<f64>() / free as f64;
    let phase_offset = free_phase - start.value(f64::INFINITY, |p| p.phase_deg).value;
    let fixed = Fixed {
        z_offset,
        model_a0: a0,
        reported_a0: a0,
        phase_offset,
    };
    let (internal, transform) = internal_parameters(parameters);
    let mut theta = DVector::zeros(internal.len());
    for (k, p) in internal.iter().enumerate() {
        theta[k] = match p {
            Internal::ZOffset => fixed.z_offset,
            Internal::PhaseOffset => fixed.phase_offset,
            Internal::ModelAmplitude | Internal::ReportedAmplitude => a0.ln(),
            Internal::Case(axis) => axis.value(case)?.ln(),
        };
    }
    let initial: Vec<f64> = parameters
        .iter()
        .zip((&transform * &theta).iter())
        .map(|(p, &t)| if p.logarithmic() { t.exp() } else { t })
        .collect();
    let z_floor = zs.iter().copied().fold(f64::INFINITY, f64::min) - z_offset - 0.15 * a0;
    let problem = Problem {
        residuals: Residuals {
            case,
            points,
            parameters: internal,
            fixed,
            sigma,
            step: settings.difference_step,
            z_floor,
            cache: Mutex::new(HashMap::new()),
            stop,
        },
        theta: theta.clone(),
        failure: RefCell::new(None),
        started: Cell::new(false),
        rejected: RefCell::new((0, None)),
    };
    let patience = settings
        .max_evaluations
        .div_ceil(problem.residuals.parameters.len() + 1)
        .max(1);
    let (problem, report) = LevenbergMarquardt::new()
        .with_patience(patience)
        .with_ftol(1e-7)
        .with_xtol(1e-7)
        .minimize(problem);
    if let Some(error) = problem.failure.borrow_mut().take() {
        if !report.termination.was_successful() {
            return Err(error);
        }
    }
    let theta = problem.theta.clone();
    let (rejected, rejection) = problem.rejected.take();
    let problem = problem.residuals;
    let residuals = problem.residuals_at(&theta)?;
    let jacobian = problem.jacobian_at(&theta)?;
    let n = points.len();
    let p = parameters.len();
    let q = problem.parameters.len();
    let chi2 = residuals.norm_squared();
    let dof = (2 * n).saturating_sub(q).max(1);
    let reduced_chi2 = chi2 / dof as f64;
    // Covariance: s^2 (J^T J)^{-1} by SVD; directions with singular values below 1e-8 of the
    // largest are undetermined.
    let svd = jacobian.clone().svd(false, true);
    let largest = svd.singular_values.max();
    let v_t = svd.v_t.expect("v_t asked for");
    let mut internal_covariance = DMatrix::zeros(q, q);
    let mut undetermined = vec![false; p];
    for (j, &s) in svd.singular_values.iter().enumerate() {
        let row = v_t.row(j);
        if s <= 1e-8 * largest {
            // A fitted parameter with a component on an undetermined direction.
            let components = &transform * row.transpose();
            for k in 0..p {
                if components[k].abs() > 1e-3 {
                    undetermined[k] = true;
                }
            }
            continue;
        }
        internal_covariance += row.transpose() * row / (s * s);
    }
    let covariance = &transform * internal_covariance * transform.transpose() * reduced_chi2;
    let user_theta = &transform * &theta;
    let values = problem.values(&theta);
    let mut warnings = Vec::new();
    let mut fitted = Vec::new();
    for (k, parameter) in parameters.iter().enumerate() {
        let raw = covariance[(k, k)].max(0.0).sqrt();
        let value = if parameter.logarithmic() {
            user_theta[k].exp()
        } else {
            user_theta[k]
        };
        let stderr = if parameter.logarithmic() {
            value * raw
        } else {
            raw
        };
        if let FitParameter::Case(axis) = parameter {
            // Within one difference step of a bound, the fit stopped against the range.
            let range = axis.physical_range(case);
            let margin = settings.difference_step.exp();
            if value * margin > range.max || value / margin < range.min {
                warnings.push(format!(
                    "{}: stopped at the bound of its range, {}: the data pull it out of the model's range",
                    parameter.key(),
                    range.describe()
                ));
            }
        }
        let relative = stderr / value.abs().max(1e-300);
        let stderr = if undetermined[k] {
            warnings.push(format!(
                "{}: the data cannot determine it (a direction of zero sensitivity); its value is the start's",
                parameter.key()
            ));
            None
        } else {
            if parameter.logarithmic() && relative > 0.5 {
                warnings.push(format!(
                    "{}: poorly determined (stderr {:.0}% of the value)",
                    parameter.key(),
                    100.0 * relative
                ));
            }
            Some(stderr)
        };
        fitted.push(FittedValue {
            name: parameter.key(),
            value,
            stderr,
            initial: initial[k],
        });
    }
    let correlations = (0..p)
        .map(|i| {
            (0..p)
                .map(|j| {
                    let scale = (covariance[(i, i)] * covariance[(j, j)]).sqrt();
                    (!undetermined[i] && !undetermined[j] && scale > 0.0)
                        .then(|| covariance[(i, j)] / scale)
                })
                .collect()
        })
        .collect();
    if let Some(rejection) = rejection {
        warnings.push(format!(
            "{rejected} trial step{} could not be evaluated (a parameter out of its range, or a branch that could not be followed) and {} rejected (the first: {rejection})",
            if rejected == 1 { "" } else { "s" },
            if rejected == 1 { "was" } else { "were" },
        ));
    }
    if reduced_chi2 > 4.0 {
        warnings.push(format!(
            "reduced chi^2 = {reduced_chi2:.2}: the model does not describe the data within its noise; the standard errors are scaled by sqrt of it"
        ));
    }
    let branch = problem.branch(&values)?;
    let read = |z: f64, f: Reading| branch.value(z, f).value;
    let fitted_points = points
        .iter()
        .map(|point| {
            let z = point.z_nm - values.z_offset;
            FittedPoint {
                line: point.line,
                z_nm: point.z_nm,
                amplitude_nm: point.amplitude_nm,
                phase_deg: point.phase_deg,
                separation_nm: z,
                model_amplitude_nm: values.reported_a0 * read(z, |d| d.amplitude_ratio),
                model_phase_deg: read(z, |d| d.phase_deg) + values.phase_offset,
                impacts_per_period: read(z, |d| d.impacts_per_period),
                peak_force_nn: read(z, |d: &DiagramPoint| d.peak_force_nn),
                dissipated_ev: read(z, |d| d.dissipated_ev),
                virial_ev: read(z, |d| d.virial_ev),
                max_indentation_nm: read(z, |d| d.max_indentation_nm),
                mean_indentation_nm: read(z, |d| d.mean_indentation_nm),
            }
        })
        .collect::<Vec<_>>();
    let rms = |range: std::ops::Range<usize>, sigma: f64| {
        (residuals.rows(range.start, range.len()).norm_squared() / n as f64).sqrt() * sigma
    };
    let grazing = branch
        .diagram
        .special_points
        .iter()
        .filter(|s| s.label.starts_with('G') || s.label == "fold")
        .map(|s| FittedGrazing {
            label: s.label.clone(),
            z_nm: s.z_nm + values.z_offset,
            amplitude_ratio: s.amplitude_ratio,
            phase_deg: s.phase_deg + values.phase_offset,
        })
        .collect();
    Ok(FitResult {
        parameters: fitted,
        correlations,
        residual_rms_amplitude_nm: rms(0..n, sigma[0]),
        residual_rms_phase_deg: rms(n..2 * n, sigma[1]),
        reduced_chi2,
        noise: sigma,
        grazing,
        points: fitted_points,
        evaluations: report.number_of_evaluations,
        termination: format!("{:?}", report.termination),
        converged: report.termination.was_successful(),
        warnings,
    })
}
