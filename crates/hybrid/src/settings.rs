//! Settings of the hybrid solver: Runge-Kutta tolerances, step limits, and event location.

use crate::error::HybridError;

/// Integration and event-location settings, validated by [`Settings::validate`] (called by
/// [`crate::Solver::new`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Relative local error tolerance of the DOP853 and Taylor-series steps (applied to the
    /// state, not to the sensitivities). Allowed: `1e-16 ..= 1` (finite). Default `1e-12`.
    pub relative_tolerance: f64,
    /// Absolute local error tolerance, in state units. Allowed: `> 0`, finite. Default `1e-12`.
    pub absolute_tolerance: f64,
    /// First Runge-Kutta step (system time units); `None` uses Hairer's starting-step heuristic
    /// (Hairer, Norsett, Wanner, *Solving ODEs I*, Sec. II.4). Allowed: `> 0`, finite.
    pub initial_step: Option<f64>,
    /// Longest step, Runge-Kutta or exact-flow (system time units). Allowed: `> 0` (may be
    /// infinite). Default `f64::INFINITY`.
    pub max_step: f64,
    /// Step attempts (accepted plus rejected) allowed per solver; exceeding it gives
    /// [`HybridError::TooManySteps`]. Allowed: `>= 1`. Default `1_000_000`.
    pub max_steps: usize,
    /// Events allowed per solver; the next one gives [`HybridError::TooManyEvents`].
    /// Allowed: any. Default `100_000`.
    pub max_events: usize,
    /// Event and extremum times are located to `event_time_tolerance * max(|t|, |step|)`.
    /// Allowed: `1e-16 ..= 1e-3`. Default `1e-13`.
    pub event_time_tolerance: f64,
    /// An event root is also accepted once both ends of the bracket have `|h| <=` this value
    /// (switching-function units). Allowed: `>= 0`, finite. Default `1e-14`.
    pub event_value_tolerance: f64,
    /// Interior sample points per step at which `h_k` and `dh_k/dt` are evaluated (besides both
    /// ends) to find extrema and brief dips through a surface. Allowed: `1 ..= 1000`. Default 8.
    pub samples_per_step: usize,
    /// A crossing with `|dh/dt| <` this value (switching-function units per time unit) is
    /// flagged `grazing`. Allowed: `>= 0`, finite. Default `1e-6`.
    pub grazing_rate: f64,
    /// Error control of the transition matrix and parameter sensitivity (integrated in the
    /// same Runge-Kutta system either way): `None` controls the state only (cheapest, enough
    /// for smooth fields); `Some(tol)` also requires their local error, relative and absolute,
    /// below `tol` (norm taken separately from the state's, the step obeying both).
    ///
    /// Where the Jacobian is not smooth in time (Hertz contact, `J ~ sqrt(-h)` at contact
    /// onset and release), stepping in time with `None` leaves the sensitivities with relative
    /// errors ~1e-5 (over one period of the paper's Biolever on mica at default tolerances);
    /// `Some(1e-8)` brings the monodromy to ~1e-6 and `Some(1e-10)` to ~1e-8, for about a
    /// fifth and two thirds more evaluations of the field. A system that declares its contact
    /// as a half-power surface ([`crate::SwitchingStructure::half_power_surface`], as the AFM
    /// model does) is stepped there on a square-root clock where the Jacobian is smooth: ~1e-7
    /// with `None`, and fewer evaluations than stepping in time (see [`crate::solver`]).
    /// Allowed: `1e-16 ..= 1`, and `None` with [`SensitivityMethod::Decoupled`]. Default
    /// `None`.
    pub sensitivity_tolerance: Option<f64>,
    /// How the transition matrix and parameter sensitivity are carried over Runge-Kutta and
    /// Taylor-series steps (exact-flow steps and events are the same either way). Default
    /// [`SensitivityMethod::Coupled`].
    pub sensitivity_method: SensitivityMethod,
    /// How far above a surface (on the positive side of `h_k`) extrema must still be found, in
    /// switching-function units; on the negative side (inside a contact) every extremum is
    /// found. Every step is sampled inside and its extrema located, except a step that the
    /// system proves above this height throughout (by
    /// [`crate::SwitchingStructure::switching_curvature_bound`], or for an affine `h_k` by the
    /// Bernstein bound of its interpolant): such a step is sampled at its ends only and reports
    /// no extrema; likewise, an extremum between two samples that the curvature bound proves
    /// above the height is neither located nor reported. Crossings are found either way.
    /// `INFINITY` (the default) reports every extremum, as observables of an orbit need; a
    /// time-domain sweep or a Newton iteration that needs only the crossings and the extrema
    /// inside contact sets it to 0. (A step on which every `h_k` is proven strictly monotone,
    /// by the curvature bound or an affine `h_k`'s interpolant, is not sampled inside at any
    /// height: it holds no extremum.) Allowed: `>= 0` (infinity allowed).
    pub extremum_height: f64,
    /// Whether a mode whose system gives the Taylor series of its solution
    /// ([`crate::TaylorExpansion::taylor_series`]) is stepped by series (order 20 in the step's
    /// clock, see the solver's module documentation) rather than DOP853. Default `true`;
    /// `false` gives the Runge-Kutta integration everywhere (a reference to compare against).
    pub taylor_series: bool,
}

/// How the variational equations (transition matrix and parameter sensitivity) are
/// integrated over a Runge-Kutta or Taylor-series step of the state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SensitivityMethod {
    /// In the same DOP853 system as the state, stage by stage: the transition matrix is the
    /// exact derivative of the numerical flow (so Newton on a map built from it converges
    /// quadratically to the numerical fixed point), accurate to about the state's tolerance
    /// (see [`Settings::sensitivity_tolerance`]), at `N + 1` variational products per stage
    /// of every attempted step. On a Taylor-series step, by the tangents' series to the state's
    /// order (under `sensitivity_tolerance` too, where set).
    #[default]
    Coupled,
    /// On a Taylor-series step, by the tangents' own series to order 12 under a tolerance of
    /// 1e-5 on their last two terms (which then also limits the step). After each accepted
    /// Runge-Kutta step of the state, over that step and on its clock, by Butcher's
    /// 7-stage Runge-Kutta method of order 6, the state at its nodes taken from the step's
    /// dense output: 7 variational evaluations per accepted step and none on rejected ones,
    /// no error control (the state's steps are taken as they come), and an error of order
    /// `(step / time scale)^6` per step. Over one period of the Biolever on mica (A/A0 = 0.95
    /// and 0.5, default tolerances; contacts by series) the monodromy is within 1.3e-6 and
    /// 2.3e-6 relative of a tight DOP853 reference, against 6.1e-9 and 4.2e-8 coupled (`cargo
    /// run --release -p afm --example monodromy_error`), at a lower cost per period map.
    /// Enough for Newton iterations, which need the Jacobian only well
    /// enough to contract (each iteration then also reduces the error by about that relative
    /// amount instead of only squaring it), and for stability; not where the derivative of the
    /// numerical flow itself is wanted. `sensitivity_tolerance` must be `None`.
    Decoupled,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            relative_tolerance: 1e-12,
            absolute_tolerance: 1e-12,
            initial_step: None,
            max_step: f64::INFINITY,
            max_steps: 1_000_000,
            max_events: 100_000,
            event_time_tolerance: 1e-13,
            event_value_tolerance: 1e-14,
            samples_per_step: 8,
            grazing_rate: 1e-6,
            sensitivity_tolerance: None,
            sensitivity_method: SensitivityMethod::Coupled,
            extremum_height: f64::INFINITY,
            taylor_series: true,
        }
    }
}

fn check(
    ok: bool,
    field: &'static str,
    value: f64,
    allowed: &'static str,
) -> Result<(), HybridError> {
    if ok {
        Ok(())
    } else {
        Err(HybridError::InvalidSettings {
            field,
            value,
            allowed,
        })
    }
}

impl Settings {
    /// Check every field against its documented range.
    ///
    /// # Errors
    /// [`HybridError::InvalidSettings`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), HybridError> {
        let r = self.relative_tolerance;
        check(
            r.is_finite() && (1e-16..=1.0).contains(&r),
            "relative_tolerance",
            r,
            "1e-16 ..= 1",
        )?;
        let a = self.absolute_tolerance;
        check(
            a.is_finite() && a > 0.0,
            "absolute_tolerance",
            a,
            "> 0, finite",
        )?;
        if let (Some(tol), SensitivityMethod::Decoupled) =
            (self.sensitivity_tolerance, self.sensitivity_method)
        {
            check(
                false,
                "sensitivity_tolerance",
                tol,
                "unset with the decoupled sensitivity method",
            )?;
        }
        if let Some(h) = self.initial_step {
            check(h.is_finite() && h > 0.0, "initial_step", h, "> 0, finite")?;
        }
        let m = self.max_step;
        check(m > 0.0, "max_step", m, "> 0 (infinity allowed)")?;
        check(
            self.max_steps >= 1,
            "max_steps",
            self.max_steps as f64,
            ">= 1",
        )?;
        let e = self.event_time_tolerance;
        check(
            e.is_finite() && (1e-16..=1e-3).contains(&e),
            "event_time_tolerance",
            e,
            "1e-16 ..= 1e-3",
        )?;
        let v = self.event_value_tolerance;
        check(
            v.is_finite() && v >= 0.0,
            "event_value_tolerance",
            v,
            ">= 0, finite",
        )?;
        check(
            (1..=1000).contains(&self.samples_per_step),
            "samples_per_step",
            self.samples_per_step as f64,
            "1 ..= 1000",
        )?;
        if let Some(s) = self.sensitivity_tolerance {
            check(
                s.is_finite() && (1e-16..=1.0).contains(&s),
                "sensitivity_tolerance",
                s,
                "1e-16 ..= 1",
            )?;
        }
        let g = self.grazing_rate;
        check(g.is_finite() && g >= 0.0, "grazing_rate", g, ">= 0, finite")?;
        let e = self.extremum_height;
        check(e >= 0.0, "extremum_height", e, ">= 0 (infinity allowed)")?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_valid() {
        assert_eq!(Settings::default().validate(), Ok(()));
    }

    #[test]
    fn bad_fields_are_named() {
        let cases: [(Settings, &str); 8] = [
            (
                Settings {
                    relative_tolerance: f64::NAN,
                    ..Settings::default()
                },
                "relative_tolerance",
            ),
            (
                Settings {
                    absolute_tolerance: 0.0,
                    ..Settings::default()
                },
                "absolute_tolerance",
            ),
            (
                Settings {
                    initial_step: Some(-1.0),
                    ..Settings::default()
                },
                "initial_step",
            ),
            (
                Settings {
                    samples_per_step: 0,
                    ..Settings::default()
                },
                "samples_per_step",
            ),
            (
                Settings {
                    event_time_tolerance: 1e-20,
                    ..Settings::default()
                },
                "event_time_tolerance",
            ),
            (
                Settings {
                    sensitivity_tolerance: Some(0.0),
                    ..Settings::default()
                },
                "sensitivity_tolerance",
            ),
            (
                Settings {
                    sensitivity_tolerance: Some(1e-8),
                    sensitivity_method: SensitivityMethod::Decoupled,
                    ..Settings::default()
                },
                "sensitivity_tolerance",
            ),
            (
                Settings {
                    extremum_height: f64::NAN,
                    ..Settings::default()
                },
                "extremum_height",
            ),
        ];
        for (settings, name) in cases {
            match settings.validate() {
                Err(HybridError::InvalidSettings { field, .. }) => assert_eq!(field, name),
                other => panic!("expected InvalidSettings for {name}, got {other:?}"),
            }
        }
    }
}
