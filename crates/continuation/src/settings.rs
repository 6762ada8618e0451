//! Settings of pseudo-arclength continuation: step control, direction, bounds, corrector and
//! the location of special points.

use crate::error::ContinuationError;
use crate::shooting::NewtonSettings;

/// The direction in which the parameter moves at the start of a branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ParameterDirection {
    /// `p` increases at the start (it may turn at folds).
    #[default]
    Increasing,
    /// `p` decreases at the start (for the AFM approach curve: `Z` decreasing).
    Decreasing,
}

impl ParameterDirection {
    /// `+1` for [`ParameterDirection::Increasing`], `-1` for [`ParameterDirection::Decreasing`].
    pub fn sign(self) -> f64 {
        match self {
            ParameterDirection::Increasing => 1.0,
            ParameterDirection::Decreasing => -1.0,
        }
    }
}

/// Settings of [`crate::Continuation`], validated by [`ContinuationSettings::validate`]
/// (called by [`crate::Continuation::new`]).
///
/// Steps are arclengths in the Euclidean norm of `(x, p)` (state and parameter units mixed,
/// as in AUTO with unit weights).
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationSettings {
    /// First arclength step. Allowed: `min_step ..= max_step`. Default `1e-2`.
    pub initial_step: f64,
    /// Smallest step: a corrector failure at this step ends the branch with
    /// [`ContinuationError::StepTooSmall`]. Allowed: `> 0`. Default `1e-8`.
    pub min_step: f64,
    /// Largest step. Allowed: `>= min_step`, finite. Default `1.0`.
    pub max_step: f64,
    /// Factor by which the step grows after an easy step. Allowed: `>= 1`. Default `1.5`.
    pub step_growth: f64,
    /// Factor by which the step is cut on a corrector failure, a too large turn of the
    /// tangent, or several structure events in one step. Allowed: `(0, 1)`. Default `0.5`.
    pub step_cut: f64,
    /// A step is easy (the next one grows) when the corrector converged in at most this many
    /// Newton updates. Allowed: any. Default 3.
    pub easy_iterations: usize,
    /// Largest angle (radians) between consecutive tangents before the step is cut.
    /// Allowed: `(0, pi]`. Default `0.3`.
    pub max_tangent_angle: f64,
    /// Direction of the parameter at the start. Default increasing.
    pub direction: ParameterDirection,
    /// The branch stops at this floor of the parameter (a last point is computed exactly at
    /// it). Default `-infinity`.
    pub parameter_min: f64,
    /// The branch stops at this ceiling of the parameter. Default `+infinity`.
    pub parameter_max: f64,
    /// Largest number of branch points, the start included. Allowed: `>= 1`. Default 10_000.
    pub max_points: usize,
    /// Newton settings of the corrector (and of the shooting at the start, which is allowed
    /// four times as many iterations). Default tolerance `1e-10`, 6 iterations.
    pub corrector: NewtonSettings,
    /// Special points are located until their parameter bracket is narrower than this
    /// (parameter units; for the AFM, nm). Allowed: `> 0`. Default `1e-9`.
    pub location_tolerance: f64,
    /// Root-finding iterations allowed per special point. Allowed: `>= 1`. Default 100.
    pub location_max_iterations: usize,
    /// Whether to test for period doubling and Neimark-Sacker (multiplier-based tests).
    /// Folds and structure changes (grazing) are always detected. Default `true`.
    pub detect_bifurcations: bool,
    /// Whether the period map jumps at every grazing of the contact surface and of the
    /// release surface (a hysteretic contact law, MODEL.md Sec. 9: the attachment's force sets
    /// in at a finite value, and drops to zero at pull-off), so that no orbit lies just past
    /// such a grazing and the branch ends there. Then a failed correction whose tangent
    /// prediction lies past such a grazing cuts the step to 0.99 of the way to the grazing
    /// extrapolated from the last two points, instead of by `step_cut`, and the steps after it
    /// are aimed the same way (`branch/hysteretic_break.rs`); the branch reaches the minimum
    /// step, where it ends, in a few steps instead of about twenty failed corrections, or ends
    /// before it where a correction fails at the period map's noise floor (within 100 times
    /// Newton's tolerance) once the grazing's zero is extrapolated from the branch to within
    /// `location_tolerance`; the corner jump tried there shoots at its largest offset only
    /// (`branch/corner.rs`). Default `false`.
    pub hysteretic_grazing: bool,
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        Self {
            initial_step: 1e-2,
            min_step: 1e-8,
            max_step: 1.0,
            step_growth: 1.5,
            step_cut: 0.5,
            easy_iterations: 3,
            max_tangent_angle: 0.3,
            direction: ParameterDirection::Increasing,
            parameter_min: f64::NEG_INFINITY,
            parameter_max: f64::INFINITY,
            max_points: 10_000,
            corrector: NewtonSettings {
                max_iterations: 6,
                ..NewtonSettings::default()
            },
            location_tolerance: 1e-9,
            location_max_iterations: 100,
            detect_bifurcations: true,
            hysteretic_grazing: false,
        }
    }
}

/// `Ok` if `ok`, else the invalid-settings error for `field` with its `value` and the
/// `allowed` range in words.
pub(crate) fn check(
    ok: bool,
    field: &'static str,
    value: f64,
    allowed: &'static str,
) -> Result<(), ContinuationError> {
    if ok {
        Ok(())
    } else {
        Err(ContinuationError::InvalidSettings {
            field,
            value,
            allowed,
        })
    }
}

/// Check the step bounds of a pseudo-arclength continuation (branch or curve): `min_step > 0`,
/// `max_step >= min_step`, both finite, and `initial_step` in `min_step ..= max_step`.
pub(crate) fn check_steps(
    initial_step: f64,
    min_step: f64,
    max_step: f64,
) -> Result<(), ContinuationError> {
    check(
        min_step.is_finite() && min_step > 0.0,
        "min_step",
        min_step,
        "> 0, finite",
    )?;
    check(
        max_step.is_finite() && max_step >= min_step,
        "max_step",
        max_step,
        ">= min_step, finite",
    )?;
    check(
        initial_step >= min_step && initial_step <= max_step,
        "initial_step",
        initial_step,
        "min_step ..= max_step",
    )
}

impl ContinuationSettings {
    /// Check every field against its documented range.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidSettings`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), ContinuationError> {
        check_steps(self.initial_step, self.min_step, self.max_step)?;
        check(
            self.step_growth >= 1.0 && self.step_growth.is_finite(),
            "step_growth",
            self.step_growth,
            ">= 1, finite",
        )?;
        check(
            self.step_cut > 0.0 && self.step_cut < 1.0,
            "step_cut",
            self.step_cut,
            "(0, 1)",
        )?;
        check(
            self.max_tangent_angle > 0.0 && self.max_tangent_angle <= std::f64::consts::PI,
            "max_tangent_angle",
            self.max_tangent_angle,
            "(0, pi]",
        )?;
        check(
            !self.parameter_min.is_nan()
                && !self.parameter_max.is_nan()
                && self.parameter_min < self.parameter_max,
            "parameter_min",
            self.parameter_min,
            "< parameter_max",
        )?;
        check(
            self.max_points >= 1,
            "max_points",
            self.max_points as f64,
            ">= 1",
        )?;
        self.corrector.validate()?;
        check(
            self.location_tolerance.is_finite() && self.location_tolerance > 0.0,
            "location_tolerance",
            self.location_tolerance,
            "> 0, finite",
        )?;
        check(
            self.location_max_iterations >= 1,
            "location_max_iterations",
            self.location_max_iterations as f64,
            ">= 1",
        )?;
        Ok(())
    }
}
