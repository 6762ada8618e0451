//! Settings of the two-parameter continuation of a codimension-one curve: step control, the
//! range of the second parameter and its target values, the physical range of the first, the
//! corrector and the location of codimension-two points.

use crate::error::ContinuationError;
use crate::settings::{check, check_steps};
use crate::shooting::NewtonSettings;

/// Settings of [`crate::continue_curve`], checked by [`CurveSettings::validate`].
///
/// Steps are arclengths in the Euclidean norm of the unknowns `(x, [s,] p, q)` (state, time
/// and parameter units mixed, unit weights).
#[derive(Debug, Clone, PartialEq)]
pub struct CurveSettings {
    /// First arclength step. Allowed: `min_step ..= max_step`. Default `1e-2`.
    pub initial_step: f64,
    /// Smallest step: a corrector failure at it ends the half-curve. `> 0`. Default `1e-8`.
    pub min_step: f64,
    /// Largest arclength step. `>= min_step`, finite. Default `1.0`.
    pub max_step: f64,
    /// Largest change of the second parameter `q` in one step (`q` units; sets the density
    /// of points along `q`). `> 0`. Default infinity.
    pub max_second_step: f64,
    /// Step growth after an easy step (at most `easy_iterations` Newton updates). `>= 1`.
    /// Default `1.5`.
    pub step_growth: f64,
    /// A step is easy when its corrector converged in at most this many updates (derivatives
    /// in `q` by finite differences make Newton converge linearly near the root, so this is
    /// higher than for one-parameter branches). Default 5.
    pub easy_iterations: usize,
    /// Step cut after a failure or a too large turn. `(0, 1)`. Default `0.5`.
    pub step_cut: f64,
    /// Largest angle (radians) between consecutive tangents. `(0, pi]`. Default `0.3`.
    pub max_tangent_angle: f64,
    /// The range `(low, high)` of `q` the curve is traced over, both ways from its start;
    /// a point is computed exactly at an end when the curve reaches it. `low < high`.
    pub second_range: (f64, f64),
    /// Further values of `q` at which a point is computed exactly (at fixed `q`) wherever the
    /// curve crosses them. Inside `second_range`.
    pub targets: Vec<f64>,
    /// The physical range `(low, high)` of the first parameter `p`: a curve that leaves it
    /// ends with a point exactly on the bound. `low < high`. Default unbounded.
    pub parameter_range: (f64, f64),
    /// Largest number of points per direction from the start. `>= 1`. Default 2000.
    pub max_points: usize,
    /// Newton settings of the corrector (tolerance on the Euclidean norm of the defining
    /// system's residual). Default tolerance `1e-10`, 8 updates.
    pub corrector: NewtonSettings,
    /// Codimension-two points are located until their bracket is below this in both
    /// parameters. `> 0`. Default `1e-9`.
    pub location_tolerance: f64,
    /// Bisection steps allowed per codimension-two point. `>= 1`. Default 60.
    pub location_max_iterations: usize,
}

impl Default for CurveSettings {
    fn default() -> Self {
        Self {
            initial_step: 1e-2,
            min_step: 1e-8,
            max_step: 1.0,
            max_second_step: f64::INFINITY,
            step_growth: 1.5,
            easy_iterations: 5,
            step_cut: 0.5,
            max_tangent_angle: 0.3,
            second_range: (f64::NEG_INFINITY, f64::INFINITY),
            targets: Vec::new(),
            parameter_range: (f64::NEG_INFINITY, f64::INFINITY),
            max_points: 2000,
            corrector: NewtonSettings {
                max_iterations: 8,
                ..NewtonSettings::default()
            },
            location_tolerance: 1e-9,
            location_max_iterations: 60,
        }
    }
}

impl CurveSettings {
    /// Check every field against its documented range.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidSettings`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), ContinuationError> {
        check_steps(self.initial_step, self.min_step, self.max_step)?;
        check(
            self.max_second_step > 0.0,
            "max_second_step",
            self.max_second_step,
            "> 0",
        )?;
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
        let (low, high) = self.second_range;
        check(low < high, "second_range", low, "low < high")?;
        for &t in &self.targets {
            check(t >= low && t <= high, "targets", t, "inside second_range")?;
        }
        let (p_low, p_high) = self.parameter_range;
        check(p_low < p_high, "parameter_range", p_low, "low < high")?;
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
        )
    }
}
