//! The quantities of the paper's approximate theory measured on a simulated period-1 orbit:
//! the first harmonic of `q_1` (its phase `phi` enters Eqs. 3 and 4), the impulse of every
//! impact, and the free ringing of `q_2` after the main impact.
//!
//! All integrals are 8-point Gauss-Legendre quadratures over every solver step inside the
//! period (steps never cross the contact surface, so each is smooth: exact to rounding in free
//! flight, to dense-output accuracy in contact).
//!
//! **What "the ringing of `q_2`" means here.** On the orbit, `q_2` is the sum of its free
//! steady response to the drive (`F_2 = r_2 F_1 != 0`, known in closed form:
//! [`crate::model::free_response::FreeResponse`]) and of the response to the tip-sample force. Eq. 4 sets `F_2 = 0`;
//! since Eq. 1 is linear in free flight, the difference `h = q_2 - q_2^free` is, between
//! impacts, exactly a free damped oscillation `h = C e^{-(t - t_0)/tau} sin(w_2d (t - t_0) + psi)`
//! with `tau = 2 Q_2 / w_2`. Its envelope `C` and phase `psi` follow from `(h, h')` at any
//! instant of free flight; they are read at the release of the main impact and referred back
//! to its force centroid `t_0` (the "moment of impact" of an equivalent impulse), which is what
//! Eq. 4's initial amplitude (with `psi = 0`) predicts. `h` also holds what is left of the
//! previous periods' ringing (a fraction `exp(-T/tau)` of it), which Eq. 4 ignores.

use std::f64::consts::PI;

use hybrid::{
    flow_map_observed, Direction, HybridSystem, Sensitivity, Settings, Solver, StepOutcome,
};
use serde::Serialize;

use crate::error::AfmError;
use crate::model::separation::Separation;
use crate::model::TappingModel;
use crate::model::GAP_SURFACE;
use crate::orbit::gauss_legendre::{ClockNode, GAUSS_LEGENDRE_8};
use crate::orbit::steady_orbit::SteadyOrbit;
use crate::validation::invalid;

/// One impact of the orbit with its impulse (MODEL.md section 5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImpactImpulse {
    /// Onset, drive periods from `t = 0`, in `[0, 1)`.
    pub start_periods: f64,
    /// Release, drive periods; greater than 1 for an impact that wraps around `t = T`.
    pub end_periods: f64,
    /// The impulse `int F_ts dt` over the impact, nN us.
    pub impulse_nn_us: f64,
    /// The force centroid `int t F_ts dt / int F_ts dt`, drive periods (between start and end).
    pub centroid_periods: f64,
    /// The largest `|theta_bar|`, `theta_bar = pi - theta`, `theta = w t - phi` (wrapped to
    /// `(-pi, pi]`), over the impact, degrees: how far from the lowest point of `q_1`'s first
    /// harmonic the contact extends (Eq. 3 expands `cos(theta) = -1 + O(theta_bar^2)`).
    pub largest_theta_bar_deg: f64,
    /// `theta_bar` at the force centroid, degrees in `(-180, 180]` (positive: before the
    /// lowest point of `q_1`'s first harmonic): the offset of the impact from where Eq. 3
    /// places it, caused by `q_2` and the higher harmonics of `q_1` in the gap.
    pub centroid_theta_bar_deg: f64,
}

/// The free ringing of `q_2` after the main impact (the homogeneous part `h = q_2 - q_2^free`;
/// see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ringing {
    /// The reference time `t_0`: the main impact's force centroid, drive periods.
    pub reference_time_periods: f64,
    /// The envelope `C` of `h` referred back to `t_0` (`C e^{(t_e - t_0)/tau}` from the envelope
    /// at the release `t_e`), nm: the measured counterpart of Eq. 4's initial amplitude.
    pub initial_amplitude_nm: f64,
    /// The phase `psi` of `h = C e^{-(t - t_0)/tau} sin(w_2d (t - t_0) + psi)`, degrees in
    /// `(-180, 180]`; Eq. 4 has `psi = 0`.
    pub phase_deg: f64,
    /// The envelope of `h` at the release of the main impact, nm.
    pub amplitude_at_release_nm: f64,
    /// The envelope of `h` at the next onset of the main impact (one period after its onset),
    /// nm: what is left of the ringing when the tip reaches the sample again.
    pub amplitude_at_next_impact_nm: f64,
    /// `amplitude_at_next_impact_nm / initial_amplitude_nm`: the measured decay over one
    /// period (Eq. 4 predicts `exp(-T/tau)`). In a single-impact orbit the ringing is free from
    /// `t_e` to the next onset, so this is `exp(-(T - (t_0 - t_s))/tau)` by construction; other
    /// impacts in between change it.
    pub decay_over_period: f64,
    /// The decay time that the envelope's fall from `t_0` to the next onset implies,
    /// `(t_s + T - t_0) / ln(C / C_next)`, us; equals `tau` when no other impact intervenes.
    /// `None` when the envelope does not fall (`C_next >= C`: other impacts kick `q_2` again),
    /// where the formula would give a negative or infinite time.
    pub effective_decay_time_us: Option<f64>,
}

/// The theory's quantities measured on one period of a period-1 steady orbit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImpactMeasurement {
    /// The separation `Z`, nm.
    pub z_nm: f64,
    /// `A / A0` of `u` (MODEL.md section 4).
    pub amplitude_ratio: f64,
    /// The phase lag `Phi` of `u`'s first harmonic, degrees (MODEL.md section 4).
    pub u_phase_deg: f64,
    /// The first-harmonic amplitude `a` of `q_1 ~ a cos(w t - phi)`, nm.
    pub q1_amplitude_nm: f64,
    /// The first-harmonic phase lag `phi` of `q_1`, degrees: the `phi` of Eqs. 2-4.
    pub q1_phase_deg: f64,
    /// The impulse per period `int_0^T F_ts dt`, nN us.
    pub impulse_nn_us: f64,
    /// `int_0^T F_ts (1 + cos theta) dt`, `theta = w t - phi`, nN us: exactly what Eq. 3's
    /// expansion `cos(theta) = -1` neglects. At `w = w_1` the first-harmonic balance of Eq. 1
    /// (Eq. 2, exact for the first harmonic of `q_1`) gives
    /// `impulse_nn_us - cos_expansion_residual_nn_us = pi F_1 cos(phi) / w_1` = Eq. 3.
    pub cos_expansion_residual_nn_us: f64,
    /// `(pi / w) [F_1 cos(phi) - k_1 a (1 - (w/w_1)^2)]`, nN us: the impulse the first-harmonic
    /// balance of Eq. 1 gives with `cos(theta) = -1` at any drive frequency (Eq. 3 at
    /// `w = w_1`). It differs from `impulse_nn_us` only by `cos_expansion_residual_nn_us`.
    pub harmonic_balance_impulse_nn_us: f64,
    /// The time in contact per period, drive periods.
    pub contact_time_periods: f64,
    /// The impacts in order of onset (an impact wrapping around `t = T` last).
    pub impacts: Vec<ImpactImpulse>,
    /// Index in `impacts` of the main impact (the largest impulse); `None` without contact.
    pub main_impact: Option<usize>,
    /// The ringing of `q_2` after the main impact; `None` without an impact that begins and
    /// ends (no contact, or contact throughout).
    pub ringing: Option<Ringing>,
}

/// A contact interval being integrated: onset and release (time, state) when inside the
/// window, impulse and first moment `int t F dt`.
#[derive(Debug, Clone)]
struct Fragment {
    start: Option<(f64, Vec<f64>)>,
    end: Option<(f64, Vec<f64>)>,
    impulse: f64,
    moment: f64,
}

impl Fragment {
    fn open(start: Option<(f64, Vec<f64>)>) -> Self {
        Self {
            start,
            end: None,
            impulse: 0.0,
            moment: 0.0,
        }
    }
}

/// Running integrals over the period.
struct Accumulator {
    period: f64,
    angular_frequency: f64,
    /// `int q_1 cos(w t) dt`, `int q_1 sin(w t) dt`.
    q1_fourier: [f64; 2],
    /// `int F dt`, `int F cos(w t) dt`, `int F sin(w t) dt`.
    force: [f64; 3],
    fragments: Vec<Fragment>,
    /// The states at a step's quadrature nodes (`n` per node).
    node_states: Vec<f64>,
}

impl Accumulator {
    fn observe(&mut self, solver: &Solver<TappingModel>, outcome: &StepOutcome) {
        let model = solver.system();
        let (a, b) = solver.last_step();
        let b = b.min(self.period);
        if b > a {
            for (node, state) in GAUSS_LEGENDRE_8.step_nodes(
                solver,
                a,
                b,
                self.angular_frequency,
                &mut self.node_states,
            ) {
                let ClockNode {
                    t,
                    weight: w,
                    drive: (sin, cos),
                    ..
                } = node;
                let q1 = state[0];
                self.q1_fourier[0] += w * q1 * cos;
                self.q1_fourier[1] += w * q1 * sin;
                let force = model.tip_sample_force(t, state);
                self.force[0] += w * force;
                self.force[1] += w * force * cos;
                self.force[2] += w * force * sin;
                if let Some(fragment) = self.fragments.last_mut().filter(|f| f.end.is_none()) {
                    fragment.impulse += w * force;
                    fragment.moment += w * force * t;
                }
            }
        }
        if let StepOutcome::Event(event) = outcome {
            if event.surface == GAP_SURFACE && event.t <= self.period {
                match event.direction {
                    Direction::Down => self
                        .fragments
                        .push(Fragment::open(Some((event.t, event.state.clone())))),
                    Direction::Up => {
                        if let Some(fragment) =
                            self.fragments.last_mut().filter(|f| f.end.is_none())
                        {
                            fragment.end = Some((event.t, event.state.clone()));
                        }
                    }
                }
            }
        }
    }
}

/// Wrap an angle to `(-pi, pi]`.
fn wrap(angle: f64) -> f64 {
    let wrapped = (angle + PI).rem_euclid(2.0 * PI) - PI;
    if wrapped <= -PI {
        wrapped + 2.0 * PI
    } else {
        wrapped
    }
}

/// Measure the theory's quantities on `orbit`, a converged period-1 steady orbit of `model`
/// (at the orbit's separation), over the period `[0, T]` from `orbit.state`.
///
/// Fails when the orbit has a period of several drive periods (the theory describes a
/// period-1 orbit), when the model has fewer than two modes, or when the solver fails.
pub fn measure_impacts(
    model: &TappingModel,
    orbit: &SteadyOrbit,
    settings: &Settings,
) -> Result<ImpactMeasurement, AfmError> {
    check_measurable(model, orbit)?;
    let mut model = model.clone();
    model.set_separation(Separation::Constant(orbit.z_nm))?;
    let period = model.period_us();
    let w = model.drive_angular_frequency();
    let starts_in_contact = model.gap(0.0, &orbit.state) < 0.0;
    let mut accumulator = Accumulator {
        period,
        angular_frequency: w,
        q1_fourier: [0.0; 2],
        force: [0.0; 3],
        fragments: if starts_in_contact {
            vec![Fragment::open(None)]
        } else {
            Vec::new()
        },
        node_states: vec![0.0; GAUSS_LEGENDRE_8.len() * model.dim()],
    };
    flow_map_observed(
        &model,
        0.0,
        &orbit.state,
        period,
        Sensitivity::None,
        settings,
        &mut |solver: &Solver<TappingModel>, outcome: &StepOutcome| {
            accumulator.observe(solver, outcome)
        },
    )?;

    let scale = 2.0 / period;
    let [q1_cos, q1_sin] = accumulator.q1_fourier.map(|c| scale * c);
    let q1_amplitude = q1_cos.hypot(q1_sin);
    let phi = q1_sin.atan2(q1_cos);
    let [impulse, force_cos, force_sin] = accumulator.force;
    // int F (1 + cos(w t - phi)) dt = int F + cos(phi) int F cos(wt) + sin(phi) int F sin(wt).
    let residual = impulse + phi.cos() * force_cos + phi.sin() * force_sin;
    let first = &model.cantilever().modes[0];
    let ratio = w / first.angular_frequency();
    let harmonic_balance = PI / w
        * (model.drive_force_nn() * phi.cos()
            - first.stiffness_n_per_m * q1_amplitude * (1.0 - ratio * ratio));

    let fragments = merge_wrapped(accumulator.fragments, period);
    let impacts = impact_impulses(&fragments, period, w, phi);
    let main_impact = impacts
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.impulse_nn_us.total_cmp(&y.1.impulse_nn_us))
        .map(|(index, _)| index);
    let ringing = main_impact.and_then(|index| {
        let fragment = &fragments[index];
        let (Some((t_start, x_start)), Some((t_end, x_end))) = (&fragment.start, &fragment.end)
        else {
            return None;
        };
        Some(ringing(
            &model,
            *t_start,
            x_start,
            *t_end,
            x_end,
            impacts[index].centroid_periods * period,
        ))
    });
    let orbit_observables = orbit.observables();
    Ok(ImpactMeasurement {
        z_nm: orbit.z_nm,
        amplitude_ratio: orbit_observables.amplitude_ratio,
        u_phase_deg: orbit_observables.phase_deg,
        q1_amplitude_nm: q1_amplitude,
        q1_phase_deg: phi.to_degrees(),
        impulse_nn_us: impulse,
        cos_expansion_residual_nn_us: residual,
        harmonic_balance_impulse_nn_us: harmonic_balance,
        contact_time_periods: impacts
            .iter()
            .map(|impact| impact.end_periods - impact.start_periods)
            .fold(0.0, |total, duration| total + duration),
        impacts,
        main_impact,
        ringing,
    })
}

/// The theory of Eqs. 2-4 measures a period-1 orbit of a cantilever with at least 2 modes (the
/// ringing of `q_2`): an [`AfmError::InvalidField`] for any other.
fn check_measurable(model: &TappingModel, orbit: &SteadyOrbit) -> Result<(), AfmError> {
    if orbit.multiplicity != 1 {
        return Err(invalid(
            "impact measurement",
            "orbit.multiplicity",
            orbit.multiplicity as f64,
            String::from("1: the theory of Eqs. 2-4 describes a period-1 orbit"),
        ));
    }
    if model.mode_count() < 2 {
        return Err(invalid(
            "impact measurement",
            "mode_count",
            model.mode_count() as f64,
            String::from("at least 2 eigenmodes (the ringing of q_2 is measured)"),
        ));
    }
    Ok(())
}

/// Each contact of the period as an [`ImpactImpulse`]: onset and release (periods), impulse
/// (nN us), centroid, and the drive-relative angles `theta_bar = pi - (w t - phi)` of Eq. 3
/// (degrees), for the drive angular frequency `w` (rad/us), period `period` (us) and the phase
/// `phi` (rad) of `q_1`'s first harmonic.
fn impact_impulses(fragments: &[Fragment], period: f64, w: f64, phi: f64) -> Vec<ImpactImpulse> {
    let theta_bar = |t: f64| wrap(PI - (w * t - phi));
    fragments
        .iter()
        .map(|fragment| {
            let start = fragment.start.as_ref().map_or(0.0, |(t, _)| *t);
            let end = fragment.end.as_ref().map_or(start + period, |(t, _)| *t);
            let centroid = if fragment.impulse > 0.0 {
                fragment.moment / fragment.impulse
            } else {
                0.5 * (start + end)
            };
            ImpactImpulse {
                start_periods: start / period,
                end_periods: end / period,
                impulse_nn_us: fragment.impulse,
                centroid_periods: centroid / period,
                largest_theta_bar_deg: theta_bar(start)
                    .abs()
                    .max(theta_bar(end).abs())
                    .to_degrees(),
                centroid_theta_bar_deg: theta_bar(centroid).to_degrees(),
            }
        })
        .collect()
}

/// A contact in progress at `t = 0` (open head fragment) and at `t = T` (open tail) is one
/// impact of the periodic orbit: join them, the head shifted by one period. Contact
/// throughout leaves one fragment with neither onset nor release.
fn merge_wrapped(mut fragments: Vec<Fragment>, period: f64) -> Vec<Fragment> {
    let head_is_open = fragments.first().is_some_and(|f| f.start.is_none());
    let tail_is_open = fragments.last().is_some_and(|f| f.end.is_none());
    if fragments.len() >= 2 && head_is_open && tail_is_open {
        let head = fragments.remove(0);
        if let Some(tail) = fragments.last_mut() {
            tail.end = head.end.map(|(t, x)| (t + period, x));
            tail.impulse += head.impulse;
            tail.moment += head.moment + period * head.impulse;
        }
    }
    fragments
}

/// The envelope `C` and phase `psi` of the free damped oscillation through `(h, h')`:
/// `h(s) = C e^{-sigma s} sin(w_d s + psi)`, `sigma = w_2 / (2 Q_2)`.
fn envelope(model: &TappingModel, t: f64, x: &[f64], free: &mut [f64]) -> (f64, f64) {
    let second = &model.cantilever().modes[1];
    let w2 = second.angular_frequency();
    let sigma = w2 / (2.0 * second.quality_factor);
    let wd = w2 * (1.0 - 1.0 / (4.0 * second.quality_factor.powi(2))).sqrt();
    model.free_response().state_at(t, free);
    let h = x[2] - free[2];
    let rate = x[3] - free[3];
    let quadrature = (rate + sigma * h) / wd;
    (h.hypot(quadrature), h.atan2(quadrature))
}

/// The ringing of `q_2` after a main impact with onset `(t_start, x_start)`, release
/// `(t_end, x_end)` (`t_end` may exceed `T` for a wrapped impact) and force centroid
/// `t_reference`.
fn ringing(
    model: &TappingModel,
    t_start: f64,
    x_start: &[f64],
    t_end: f64,
    x_end: &[f64],
    t_reference: f64,
) -> Ringing {
    let second = &model.cantilever().modes[1];
    let w2 = second.angular_frequency();
    let sigma = w2 / (2.0 * second.quality_factor);
    let wd = w2 * (1.0 - 1.0 / (4.0 * second.quality_factor.powi(2))).sqrt();
    let period = model.period_us();
    let mut free = vec![0.0; model.dim()];
    let (at_release, psi_release) = envelope(model, t_end, x_end, &mut free);
    // The orbit is T-periodic, and so is the free steady response: the state at the next onset
    // (t_start + T) is the state at t_start.
    let (at_next, _) = envelope(model, t_start, x_start, &mut free);
    let back = t_end - t_reference;
    let initial = at_release * (sigma * back).exp();
    let elapsed = t_start + period - t_reference;
    Ringing {
        reference_time_periods: t_reference / period,
        initial_amplitude_nm: initial,
        phase_deg: wrap(psi_release - wd * back).to_degrees(),
        amplitude_at_release_nm: at_release,
        amplitude_at_next_impact_nm: at_next,
        decay_over_period: at_next / initial,
        effective_decay_time_us: (at_next < initial && at_next > 0.0)
            .then(|| elapsed / (initial / at_next).ln())
            .filter(|time| time.is_finite() && *time > 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::{merge_wrapped, wrap, Fragment};
    use std::f64::consts::PI;

    /// An impact in progress at both ends of the window is one impact: onset from the tail,
    /// release from the head shifted by T, impulses added, and the first moment of the head
    /// taken at `t + T` (so the centroid lies between onset and release).
    #[test]
    fn wrapped_contact_is_one_impact() {
        let period = 10.0;
        let head = Fragment {
            start: None,
            end: Some((0.5, vec![1.0])),
            impulse: 2.0,
            moment: 2.0 * 0.25,
        };
        let middle = Fragment {
            start: Some((4.0, vec![2.0])),
            end: Some((4.5, vec![3.0])),
            impulse: 1.0,
            moment: 4.25,
        };
        let tail = Fragment {
            start: Some((9.5, vec![4.0])),
            end: None,
            impulse: 2.0,
            moment: 2.0 * 9.75,
        };
        let merged = merge_wrapped(vec![head, middle, tail], period);
        assert_eq!(merged.len(), 2);
        let wrapped = &merged[1];
        assert_eq!(wrapped.start.as_ref().map(|s| s.0), Some(9.5));
        assert_eq!(wrapped.end.as_ref().map(|e| e.0), Some(10.5));
        assert_eq!(wrapped.impulse, 4.0);
        // A symmetric pulse around t = 10: centroid exactly there.
        assert_eq!(wrapped.moment / wrapped.impulse, 10.0);
        // Contact throughout: one fragment, neither onset nor release, left alone.
        let throughout = merge_wrapped(vec![Fragment::open(None)], period);
        assert_eq!(throughout.len(), 1);
        assert!(throughout[0].start.is_none() && throughout[0].end.is_none());
    }

    #[test]
    fn angles_wrap_into_the_half_open_interval() {
        assert_eq!(wrap(PI), PI);
        assert_eq!(wrap(-PI), PI);
        assert!((wrap(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
        assert!((wrap(-5.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
    }
}
