//! The heap buffers of a [`crate::Solver`], kept from one run to the next.
//!
//! A time-domain sweep integrates one drive cycle at a time, each under its own separation law
//! (a new system value), so it cannot keep one solver and [`crate::Solver::restart`] it: the
//! solver borrows its system. Instead the spent solver hands its buffers back
//! ([`crate::Solver::into_workspace`]) and the next one takes them
//! ([`crate::Solver::with_workspace`]), so that after the first cycle no run allocates.

use nalgebra::DMatrix;

use crate::decoupled_tangents::DecoupledTangents;
use crate::dop853::Dop853;
use crate::event::Extremum;
use crate::extrema::Samples;
use crate::saltation::Saltation;
use crate::sensitivity::Sensitivity;
use crate::series_step::TaylorStep;
use crate::settings::{SensitivityMethod, Settings};
use crate::variational_field::VariationalField;

/// The buffers a [`crate::Solver`] allocates for a state of dimension `n`, a number of switching
/// surfaces, a [`Sensitivity`] and the sampling and error-control settings that size them.
/// Obtained from [`crate::Solver::into_workspace`] (or empty from [`SolverWorkspace::default`]);
/// it holds no results, only storage.
#[derive(Default)]
pub struct SolverWorkspace {
    pub(crate) buffers: Option<Buffers>,
}

/// A clone is an empty workspace: the buffers hold no results, so a copy of the storage would
/// serve nothing that a fresh allocation by the next solver does not.
impl Clone for SolverWorkspace {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl std::fmt::Debug for SolverWorkspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.buffers {
            Some(b) => write!(
                f,
                "SolverWorkspace {{ n: {}, surfaces: {}, sensitivity: {:?} }}",
                b.n, b.surfaces, b.sensitivity
            ),
            None => write!(f, "SolverWorkspace {{ empty }}"),
        }
    }
}

/// The buffers themselves, with what sized them.
pub(crate) struct Buffers {
    pub n: usize,
    pub surfaces: usize,
    pub sensitivity: Sensitivity,
    pub samples_per_step: usize,
    pub sensitivity_tolerance: Option<f64>,
    pub sensitivity_method: SensitivityMethod,
    pub z: Vec<f64>,
    pub z_start: Vec<f64>,
    pub z_new: Vec<f64>,
    pub transition: DMatrix<f64>,
    pub zero_parameter: Vec<f64>,
    pub field: VariationalField,
    pub rk: Dop853,
    /// The variational integration apart from the state's steps, with
    /// [`SensitivityMethod::Decoupled`] and a tracked transition.
    pub tangents: Option<DecoupledTangents>,
    /// The last Taylor-series step (in modes whose system gives series).
    pub taylor: TaylorStep,
    pub x_ahead: Vec<f64>,
    pub grid: Vec<f64>,
    /// `f(t, x)` at the start of a step, in time units (for the crossing prediction).
    pub velocity: Vec<f64>,
    pub samples: Samples,
    pub extrema: Vec<Extremum>,
    pub x: Vec<f64>,
    /// The state at the earliest far-side point the last crossing search evaluated
    /// ([`crate::solver`]'s `earliest_crossing`), for the event fired there.
    pub x_far: Vec<f64>,
    pub x_after: Vec<f64>,
    pub f_minus: Vec<f64>,
    pub f_plus: Vec<f64>,
    pub gradient: Vec<f64>,
    pub reset_jacobian: DMatrix<f64>,
    pub reset_dxdp: Vec<f64>,
    pub identity: DMatrix<f64>,
    pub saltation: Saltation,
    pub flow_transition: DMatrix<f64>,
    pub flow_dxdp: Vec<f64>,
    pub product: DMatrix<f64>,
    /// `grad_x h_k` of every surface (`k n .. (k + 1) n`) when all are affine
    /// ([`crate::SwitchingStructure::switching_is_affine`]).
    pub affine_gradients: Vec<f64>,
    /// `dh_k/dt` at fixed state of every surface when all are affine.
    pub affine_drifts: Vec<f64>,
    /// The numbers of events and of extrema of the last flow map run on these buffers
    /// ([`crate::flow_map_in`]): the capacities its next result's vectors start with (the maps
    /// of one branch or Newton iteration have about as many), so they do not grow step by step.
    pub result_counts: (usize, usize),
}

impl Buffers {
    /// Fresh buffers for a state of dimension `n` with `surfaces` switching surfaces.
    pub fn allocate(
        n: usize,
        surfaces: usize,
        sensitivity: Sensitivity,
        settings: &Settings,
    ) -> Self {
        let dim = sensitivity.augmented_dim(n);
        // With decoupled sensitivities the Runge-Kutta steps carry the state only.
        let decoupled =
            settings.sensitivity_method == SensitivityMethod::Decoupled && sensitivity.transition();
        let stepped = if decoupled {
            Sensitivity::None
        } else {
            sensitivity
        };
        let samples = Samples::new(surfaces, settings.samples_per_step);
        let extrema_capacity = surfaces * (samples.points() - 1);
        Self {
            n,
            surfaces,
            sensitivity,
            samples_per_step: settings.samples_per_step,
            sensitivity_tolerance: settings.sensitivity_tolerance,
            sensitivity_method: settings.sensitivity_method,
            z: vec![0.0; dim],
            z_start: vec![0.0; dim],
            z_new: vec![0.0; dim],
            transition: DMatrix::identity(n, n),
            zero_parameter: vec![0.0; n],
            field: VariationalField::new(n, stepped),
            rk: Dop853::new(stepped.augmented_dim(n), n, settings.sensitivity_tolerance),
            tangents: decoupled.then(|| DecoupledTangents::new(n, sensitivity)),
            taylor: TaylorStep::new(n, (dim - n) / n.max(1), settings),
            x_ahead: vec![0.0; n],
            grid: vec![0.0; (settings.samples_per_step + 1) * n],
            velocity: vec![0.0; n],
            samples,
            extrema: Vec::with_capacity(extrema_capacity),
            x: vec![0.0; n],
            x_far: vec![0.0; n],
            x_after: vec![0.0; n],
            f_minus: vec![0.0; n],
            f_plus: vec![0.0; n],
            gradient: vec![0.0; n],
            reset_jacobian: DMatrix::identity(n, n),
            reset_dxdp: vec![0.0; n],
            identity: DMatrix::identity(n, n),
            saltation: Saltation::new(n),
            flow_transition: DMatrix::identity(n, n),
            flow_dxdp: vec![0.0; n],
            product: DMatrix::zeros(n, n),
            affine_gradients: vec![0.0; surfaces * n],
            affine_drifts: vec![0.0; surfaces],
            result_counts: (0, 0),
        }
    }

    /// Whether these buffers serve a solver of this shape and these settings (the sensitivity
    /// method sizes nothing where no sensitivities are carried).
    pub fn fits(
        &self,
        n: usize,
        surfaces: usize,
        sensitivity: Sensitivity,
        settings: &Settings,
    ) -> bool {
        self.n == n
            && self.surfaces == surfaces
            && self.sensitivity == sensitivity
            && self.samples_per_step == settings.samples_per_step
            && self.sensitivity_tolerance == settings.sensitivity_tolerance
            && (sensitivity == Sensitivity::None
                || self.sensitivity_method == settings.sensitivity_method)
    }
}
