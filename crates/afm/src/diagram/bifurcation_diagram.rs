//! The bifurcation diagram of the tapping cantilever in the separation `Z`: the branch of
//! periodic orbits continued by pseudo-arclength from the free orbit above first contact down to
//! a floor (the paper's approach, Fig. 2), or back up (retract), with the observables of every
//! branch point and every special point (grazing `G_n`, folds, period doubling, ...) located to
//! `|dZ| < 1e-9 nm` (MODEL.md section 5).

use continuation::{
    BranchPoint, Continuation, ContinuationSettings, ParameterDirection, Parametrised,
    SpecialPoint, SpecialPointKind, StopReason,
};
use nalgebra::Complex;
use serde::Serialize;

use crate::diagram::branch_end::{extrapolated_grazing, pull_off_at_fold, BranchEnd};
use crate::diagram::observed_problem::ObservedPeriodProblem;
use crate::diagram::period_one_budget::admits_period_one;
use crate::error::AfmError;
use crate::model::separation::Separation;
use crate::model::TappingModel;
use crate::orbit::observables::{orbit_observables, GapMinimum, Harmonic, OrbitObservables};
use crate::orbit::steady_orbit::{
    period_one_after_transients, steady_orbit, OrbitStart, SteadyOrbit, SteadyOrbitSettings,
};

/// The first arclength step of every branch as a fraction of [`DiagramSettings::max_step`].
const INITIAL_STEP_FRACTION: f64 = 0.1;

/// The smallest [`DiagramSettings::max_step`] (nm): a branch's first step,
/// `max_step / 10`, must not fall below the continuation's smallest step (1e-8).
pub fn smallest_max_step_nm() -> f64 {
    ContinuationSettings::default().min_step / INITIAL_STEP_FRACTION
}

/// How a diagram is computed. [`DiagramSettings::approach`] and [`DiagramSettings::retract`]
/// give the defaults; every field is checked by [`DiagramSettings::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct DiagramSettings {
    /// Integration and Newton settings of every orbit.
    pub orbit: SteadyOrbitSettings,
    /// Direction of `Z` at the start: decreasing for an approach, increasing for a retract.
    pub direction: ParameterDirection,
    /// The branch stops at this separation, nm (the floor of an approach or the ceiling of a
    /// retract; a last point is computed exactly there).
    pub z_limit_nm: f64,
    /// An approach also stops once `A/A0` falls below this ratio (default 0.3). In `[0, 1)`.
    pub min_amplitude_ratio: f64,
    /// How far in `Z` (nm) below the point where `A/A0` fell below `min_amplitude_ratio` the
    /// approach goes on before it stops there (default 0: at once). A branch that turns at a
    /// fold within this margin and comes back above the ratio (the attractive regime's fold
    /// and the repulsive branch beyond it, MODEL.md section 12) is followed on; `>= 0`.
    pub ratio_floor_margin_nm: f64,
    /// Largest arclength step in the `(x, Z)` space, nm and nm/us (default `A0 / 250`, so that
    /// a diagram from first contact to `A/A0 = 0.3` has several hundred points). At least
    /// [`smallest_max_step_nm`].
    pub max_step: f64,
    /// Largest number of branch points (default 20000). `>= 2`.
    pub max_points: usize,
}

impl DiagramSettings {
    /// The approach of `model`: from `Z_G1 + 0.02 A0` down to `Z = 0.05 A0` or `A/A0 = 0.3`,
    /// whichever comes first (the brief's floor: a small fraction of A0, or A/A0 = 0.3).
    pub fn approach(model: &TappingModel) -> Self {
        let a0 = model.free_amplitude_nm();
        Self {
            orbit: SteadyOrbitSettings::default(),
            direction: ParameterDirection::Decreasing,
            z_limit_nm: 0.05 * a0,
            min_amplitude_ratio: 0.3,
            ratio_floor_margin_nm: 0.0,
            max_step: a0 / 250.0,
            max_points: 20_000,
        }
    }

    /// The retract of `model`: from the lowest point of an approach up to above first contact.
    pub fn retract(model: &TappingModel) -> Self {
        let a0 = model.free_amplitude_nm();
        Self {
            direction: ParameterDirection::Increasing,
            z_limit_nm: model.grazing_separation_nm() + 0.02 * a0,
            min_amplitude_ratio: 0.0,
            ..Self::approach(model)
        }
    }

    /// Check every field against its documented range.
    pub fn validate(&self) -> Result<(), AfmError> {
        self.orbit.validate()?;
        let invalid = |field: &str, value: String, allowed: &str| AfmError::InvalidField {
            file: String::from("diagram settings"),
            field: field.to_string(),
            value,
            allowed: allowed.to_string(),
        };
        if !self.z_limit_nm.is_finite() {
            return Err(invalid(
                "z_limit_nm",
                self.z_limit_nm.to_string(),
                "a finite separation, nm",
            ));
        }
        if !(0.0..1.0).contains(&self.min_amplitude_ratio) {
            return Err(invalid(
                "min_amplitude_ratio",
                self.min_amplitude_ratio.to_string(),
                "0 <= ratio < 1",
            ));
        }
        if !(self.ratio_floor_margin_nm.is_finite() && self.ratio_floor_margin_nm >= 0.0) {
            return Err(invalid(
                "ratio_floor_margin_nm",
                self.ratio_floor_margin_nm.to_string(),
                ">= 0, finite, nm",
            ));
        }
        if !(self.max_step.is_finite() && self.max_step >= smallest_max_step_nm()) {
            return Err(invalid(
                "max_step",
                self.max_step.to_string(),
                &format!(">= {:e}, finite, nm", smallest_max_step_nm()),
            ));
        }
        if self.max_points < 2 {
            return Err(invalid("max_points", self.max_points.to_string(), ">= 2"));
        }
        Ok(())
    }
}

/// One point of the diagram: a periodic orbit at a separation, with its observables. The
/// branch is one of period-1 orbits (the period map over one drive period), so its orbits have
/// multiplicity 1 and an integer number of impacts per period.
#[derive(Debug, Clone, Serialize)]
pub struct DiagramPoint {
    /// Separation `Z`, nm.
    pub z_nm: f64,
    /// `A / A0` of the photodiode signal's first harmonic.
    pub amplitude_ratio: f64,
    /// Phase lag `Phi` of that harmonic, degrees.
    pub phase_deg: f64,
    /// The orbit's period in drive periods (always 1 on the branch).
    pub multiplicity: usize,
    /// Impacts per drive period (impacts over the orbit over its multiplicity).
    pub impacts_per_period: f64,
    /// Impacts over the whole orbit.
    pub impacts_per_orbit: usize,
    /// Every local minimum of the gap over the period.
    pub gap_minima: Vec<GapMinimum>,
    /// The lowest of `gap_minima`, nm (`None` if there is none).
    pub min_gap_nm: Option<f64>,
    /// Largest tip-sample force, nN.
    pub peak_force_nn: f64,
    /// Mean tip-sample force over the period, nN.
    pub mean_force_nn: f64,
    /// Impulse `int F_ts dt` per drive period, nN us.
    pub impulse_nn_us: f64,
    /// Time in contact per drive period, in periods.
    pub contact_time_periods: f64,
    /// Harmonics `1..=N` of `u` (N = `SteadyOrbitSettings::harmonics`; MODEL.md section 10).
    pub harmonics: Vec<Harmonic>,
    /// Energy dissipated in the sample per drive period, eV (MODEL.md section 10).
    pub dissipated_ev: f64,
    /// The virial, eV.
    pub virial_ev: f64,
    /// The largest indentation, nm.
    pub max_indentation_nm: f64,
    /// The mean indentation over the time in contact, nm.
    pub mean_indentation_nm: f64,
    /// The energy balance's relative residual.
    pub energy_balance_residual: f64,
    /// Floquet multipliers `[re, im]`, by decreasing modulus.
    pub floquet_multipliers: Vec<[f64; 2]>,
    /// The largest modulus of the Floquet multipliers.
    pub spectral_radius: f64,
    /// Whether every multiplier lies inside the unit circle.
    pub stable: bool,
    /// The orbit's state at `t = 0`, `[q_1, q_1', ..., q_N, q_N']` (nm, nm/us).
    pub state: Vec<f64>,
    /// Newton updates of the corrector at this point.
    pub iterations: usize,
    /// `|P(x) - x|` at this point (state units).
    pub residual: f64,
}

/// A located special point with the observables of its orbit.
#[derive(Debug, Clone, Serialize)]
pub struct DiagramSpecialPoint {
    /// `G1`, `G2`, ... (grazing onset of n impacts on approach; the same name when met on a
    /// retract), `fold`, `period-doubling`,
    /// `neimark-sacker`, `merge`, `split`, `impact-vanish`, `impact-appear`, ...
    pub label: String,
    /// Separation `Z` at the point, nm.
    pub z_nm: f64,
    /// `A / A0` there.
    pub amplitude_ratio: f64,
    /// Phase lag there, degrees.
    pub phase_deg: f64,
    /// Impacts per period on the side before the point (in the direction of continuation).
    pub impacts_before: usize,
    /// Impacts per period after it.
    pub impacts_after: usize,
    /// The Z range `[Z_low, Z_high]` of the final location bracket along the branch and of the
    /// point, nm. At a fold `Z` is extremal: both ends of the branch bracket lie on one side of
    /// the fold's `Z`, so one end of this range is the point itself.
    pub bracket_nm: [f64; 2],
    /// Achieved precision of `Z`, nm.
    pub precision_nm: f64,
    /// Whether the location reached its tolerance.
    pub converged: bool,
    /// The orbit's state at the point; at a hysteretic grazing whose `Z` is extrapolated past
    /// the last orbit Newton's method converged on (MODEL.md section 8), that orbit's state
    /// (and the observables below are that orbit's).
    pub state: Vec<f64>,
    /// Harmonics `1..=N` of `u` there (MODEL.md section 10).
    pub harmonics: Vec<Harmonic>,
    /// Energy dissipated in the sample per drive period there, eV.
    pub dissipated_ev: f64,
    /// The virial there, eV.
    pub virial_ev: f64,
    /// The largest indentation there, nm.
    pub max_indentation_nm: f64,
    /// The mean indentation over the time in contact there, nm.
    pub mean_indentation_nm: f64,
}

/// A computed diagram.
#[derive(Debug, Clone, Serialize)]
pub struct BifurcationDiagram {
    /// Branch points in branch order.
    pub points: Vec<DiagramPoint>,
    /// Special points in branch order.
    pub special_points: Vec<DiagramSpecialPoint>,
    /// Why the branch ended, in words.
    pub stop: String,
    /// Whether the branch reached its requested end (the separation limit, or an approach's
    /// amplitude-ratio floor); false when the point cap, a failed corrector or an error ended
    /// it first.
    pub completed: bool,
    /// The error that ended the branch early, if any, in words.
    pub error: Option<String>,
}

impl BifurcationDiagram {
    /// The separation ranges where the branch holds two or more stable orbits at the same `Z`
    /// (hysteresis: an approach and a retract follow different ones there), as sorted
    /// `[Z_low, Z_high]` intervals, nm. Computed from the branch's stable segments (consecutive
    /// stable points): a `Z` covered by two or more of them is bistable.
    pub fn bistable_ranges(&self) -> Vec<[f64; 2]> {
        let segments: Vec<[f64; 2]> = self
            .points
            .windows(2)
            .filter(|w| w[0].stable && w[1].stable)
            .map(|w| [w[0].z_nm.min(w[1].z_nm), w[0].z_nm.max(w[1].z_nm)])
            .collect();
        let mut edges: Vec<f64> = self.points.iter().map(|p| p.z_nm).collect();
        edges.sort_by(f64::total_cmp);
        edges.dedup();
        let mut ranges: Vec<[f64; 2]> = Vec::new();
        for pair in edges.windows(2) {
            let middle = 0.5 * (pair[0] + pair[1]);
            let cover = segments
                .iter()
                .filter(|s| s[0] < middle && middle < s[1])
                .count();
            if cover < 2 {
                continue;
            }
            match ranges.last_mut() {
                Some(last) if last[1] == pair[0] => last[1] = pair[1],
                _ => ranges.push([pair[0], pair[1]]),
            }
        }
        ranges
    }
}

/// The approach diagram of `model` (its separation is ignored): the branch from the free orbit
/// at `Z_G1 + 0.02 A0` with `Z` decreasing, continued through every grazing and fold.
pub fn approach_diagram(
    model: &TappingModel,
    settings: &DiagramSettings,
) -> Result<BifurcationDiagram, AfmError> {
    approach_diagram_until(model, settings, &mut || false)
}

/// As [`approach_diagram`], asking `interrupted` after every branch point whether to give up:
/// when it answers `true` the computation ends with [`AfmError::Interrupted`] (a caller's
/// Ctrl-C or cancel button).
pub fn approach_diagram_until(
    model: &TappingModel,
    settings: &DiagramSettings,
    interrupted: &mut dyn FnMut() -> bool,
) -> Result<BifurcationDiagram, AfmError> {
    let z_start = model.grazing_separation_nm() + 0.02 * model.free_amplitude_nm();
    diagram_until(model, &model.free_state(), z_start, settings, interrupted)
}

/// The diagram of `model` continued from the periodic orbit near `x0` at `z_start` in the
/// direction and to the limit of `settings`.
pub fn diagram(
    model: &TappingModel,
    x0: &[f64],
    z_start: f64,
    settings: &DiagramSettings,
) -> Result<BifurcationDiagram, AfmError> {
    diagram_until(model, x0, z_start, settings, &mut || false)
}

/// The most jumps of a hysteretic law's diagram between its branches (MODEL.md section 9).
const MAX_JUMPS: usize = 16;

/// As [`diagram`], asking `interrupted` after every branch point whether to give up: when it
/// answers `true` the computation ends with [`AfmError::Interrupted`].
///
/// With a hysteretic law (JKR, the capillary meniscus; MODEL.md section 9) the branch of
/// period-1 orbits is broken where an orbit first touches the contact surface (a grazing
/// `G_n`: the attachment's force sets in at a finite value) and where an attached orbit last
/// reaches the release surface (`pull-off`: the force drops to zero there), so the period map
/// jumps and the corrector fails just past the point. There the diagram does what the
/// cantilever does: it takes the orbit that transients from the last branch point settle on,
/// half a largest step further (`steady_orbit` with [`OrbitStart::AfterTransients`]; past a
/// band where they settle on no stable period-1 orbit, [`settle_on_period_one`]), and
/// continues from it. On a retract, the end of an attached branch that is not a located
/// grazing is labelled `pull-off`: at a fold of the attached orbits (where `Z` turns back) the
/// located fold, else the last point (the corrector failed at the continuation's smallest
/// step), not located: its bracket runs to the grazing extrapolated from the branch. On an
/// approach, a branch stuck short of a grazing it ran into (none located there) ends with
/// that grazing, `pull-off` or the next `G<n>`, not located, bracketed the same way. A
/// branch whose `Z` turned back with no fold located in the step (the tangent's orientation
/// reversed after a corner jump) is no end: the branch goes on from its last point, on the
/// approach as on the retract.
pub fn diagram_until(
    model: &TappingModel,
    x0: &[f64],
    z_start: f64,
    settings: &DiagramSettings,
    interrupted: &mut dyn FnMut() -> bool,
) -> Result<BifurcationDiagram, AfmError> {
    let (mut diagram, mut end) = branch_until(model, x0, z_start, settings, interrupted)?;
    if model.release_gap_nm().is_none() {
        return Ok(diagram);
    }
    let sign = match settings.direction {
        ParameterDirection::Decreasing => -1.0,
        ParameterDirection::Increasing => 1.0,
    };
    let mut system = model.clone();
    // The `Z` a reversed branch last went on from (a second reversal there ends the branch).
    let mut resumed_at: Option<f64> = None;
    for _ in 0..MAX_JUMPS {
        if end.is_none() {
            break;
        }
        let Some(last) = diagram.points.last().cloned() else {
            break;
        };
        // A branch whose tangent only turned backwards goes on from its last point.
        if matches!(end, Some(BranchEnd::Reversed)) && resumed_at != Some(last.z_nm) {
            resumed_at = Some(last.z_nm);
            let next;
            (next, end) = branch_until(model, &last.state, last.z_nm, settings, interrupted)?;
            // The resumed branch starts at the last point itself.
            diagram.points.extend(next.points.into_iter().skip(1));
            diagram.special_points.extend(next.special_points);
            diagram.stop = next.stop;
            diagram.completed = next.completed;
            diagram.error = next.error;
            continue;
        }
        let z_jump = last.z_nm + sign * 0.5 * settings.max_step;
        if sign * (z_jump - settings.z_limit_nm) >= 0.0 {
            break;
        }
        // A branch stuck short of a grazing ends there, between its last point and the
        // grazing's farthest extrapolation (no farther than the jump).
        let stuck = match &end {
            Some(BranchEnd::Stuck(Some(grazing))) => {
                let beyond = if sign > 0.0 {
                    grazing.z_nm.min(z_jump)
                } else {
                    grazing.z_nm.max(z_jump)
                };
                Some((grazing.release, beyond))
            }
            _ => None,
        };
        // A grazing the continuation located within 1e-6 nm of the last point, or between it
        // and that end's far side, is already this end's.
        let far = stuck.map_or(last.z_nm, |(_, beyond)| beyond);
        let (low, high) = (last.z_nm.min(far) - 1e-6, last.z_nm.max(far) + 1e-6);
        let grazing_at_end = diagram
            .special_points
            .iter()
            .any(|p| is_grazing(&p.label) && low <= p.z_nm && p.z_nm <= high);
        let end_observables = |system: &mut TappingModel| {
            system.set_parameter(last.z_nm);
            orbit_observables(
                system,
                &last.state,
                &settings.orbit.integration,
                settings.orbit.harmonics,
            )
        };
        // On a retract, an attached branch ends where the orbit can no longer stay attached.
        if !grazing_at_end && sign > 0.0 && last.impacts_per_orbit > 0 {
            let observables = end_observables(&mut system)?;
            let impacts = observables.impacts_per_window();
            let point = match (&end, stuck) {
                (Some(BranchEnd::Fold(fold)), _) => pull_off_at_fold(fold, impacts),
                (_, Some((_, beyond))) => branch_end_point("pull-off", &last, beyond, (impacts, 0)),
                _ => branch_end_point("pull-off", &last, z_jump, (impacts, 0)),
            };
            diagram.special_points.push(point);
        }
        // On an approach, a branch stuck short of the grazing it ran into ends there, not
        // located: a `pull-off` of the release surface or the next `G<n>`.
        if let (false, true, Some((release, beyond))) = (grazing_at_end, sign < 0.0, stuck) {
            let observables = end_observables(&mut system)?;
            let impacts = observables.impacts_per_window();
            let (label, after) = if release {
                (String::from("pull-off"), impacts)
            } else {
                (format!("G{}", impacts + 1), impacts + 1)
            };
            let point = branch_end_point(&label, &last, beyond, (impacts, after));
            diagram.special_points.push(point);
        }
        let Some((z_jump, orbit)) =
            settle_on_period_one(&mut system, &last.state, z_jump, sign, settings)
        else {
            break;
        };
        let next;
        (next, end) = branch_until(model, &orbit.state, z_jump, settings, interrupted)?;
        diagram.points.extend(next.points);
        diagram.special_points.extend(next.special_points);
        diagram.stop = next.stop;
        diagram.completed = next.completed;
        diagram.error = next.error;
    }
    // The jump of the period map at a grazing of the contact surface reads, to the branch's
    // test functions, as a fold or period doubling that cannot be located (its bracket is the
    // jump): not a bifurcation of smooth orbits, so not reported.
    let grazings: Vec<f64> = diagram
        .special_points
        .iter()
        .filter(|p| is_grazing(&p.label))
        .map(|p| p.z_nm)
        .collect();
    diagram.special_points.retain(|p| {
        p.converged || is_grazing(&p.label) || !grazings.iter().any(|z| (z - p.z_nm).abs() < 1e-6)
    });
    Ok(diagram)
}

/// Whether `label` names a grazing where a hysteretic law's branch breaks: `G<n>` of the
/// contact surface or `pull-off`, the grazing of the pull-off surface (MODEL.md section 8).
fn is_grazing(label: &str) -> bool {
    label.starts_with('G') || label == "pull-off"
}

/// The most steps of [`settle_on_period_one`]'s walk past a branch break.
const MAX_WALK_STEPS: usize = 100;

/// The recurrence periods of each step of [`settle_on_period_one`]'s walk after the first
/// (the first uses the settings' own): the walk looks for a stable period-1 orbit, not for the
/// period-k attractors it passes.
const WALK_RECURRENCE_PERIODS: usize = 400;

/// The steady period-1 orbit the cantilever settles on past a hysteretic law's branch break:
/// transients from `state` at `z_jump`, polished by Newton (`steady_orbit` with
/// [`OrbitStart::AfterTransients`]); where they settle on no stable period-1 orbit (a
/// dissipative attachment in a high-Q cantilever taps only every few periods just below
/// `G1`: each tap's loss, the loop's area, exceeds what one period's drive can replace) the
/// walk goes on in steps of `A0 / 100` in the direction of `sign`, each from the state the
/// previous step reported (its recurrence search cut to [`WALK_RECURRENCE_PERIODS`]), until a
/// stable period-1 orbit converges, `Z` passes `z_limit_nm`, or [`MAX_WALK_STEPS`] steps.
/// Where the energy budget of a period rules a period-1 orbit out
/// ([`admits_period_one`]: a formation's loss more than one period's drive can replace), the
/// step skips the recurrence search, whose period-k attractors would serve only as the next
/// step's start: it takes the transients and Newton on the period-1 map (a stable period-1
/// orbit Newton finds still ends the walk) and goes on from the state the transients reached.
/// Returns the `Z` and the orbit.
fn settle_on_period_one(
    system: &mut TappingModel,
    state: &[f64],
    z_jump: f64,
    sign: f64,
    settings: &DiagramSettings,
) -> Option<(f64, SteadyOrbit)> {
    let step = system.free_amplitude_nm() / 100.0;
    let mut z = z_jump;
    let mut from = state.to_vec();
    // Only a stable period-1 orbit ends the walk: past its first step, the search for another
    // attractor by recurrence is cut to WALK_RECURRENCE_PERIODS periods.
    let walking = SteadyOrbitSettings {
        recurrence_periods: settings
            .orbit
            .recurrence_periods
            .min(WALK_RECURRENCE_PERIODS),
        ..settings.orbit.clone()
    };
    let mut first = true;
    for _ in 0..MAX_WALK_STEPS {
        if sign * (z - settings.z_limit_nm) >= 0.0 {
            return None;
        }
        system.set_parameter(z);
        let orbit_settings = if first { &settings.orbit } else { &walking };
        let search = admits_period_one(system, z);
        first = false;
        if !search {
            let (orbit, after) =
                period_one_after_transients(system, z, &from, orbit_settings).ok()?;
            if let Some(orbit) = orbit {
                return Some((z, orbit));
            }
            from = after;
            z += sign * step;
            continue;
        }
        let orbit = steady_orbit(
            system,
            z,
            OrbitStart::AfterTransients(&from),
            orbit_settings,
        )
        .ok()?;
        if orbit.converged && orbit.multiplicity == 1 && orbit.stable {
            return Some((z, orbit));
        }
        from = orbit.state;
        z += sign * step;
    }
    None
}

/// The special point `label` at the last point `last` of a branch that ends there unlocated
/// (a hysteretic law's grazing or pull-off where the corrector failed at the smallest step),
/// with `impacts_before` and `impacts_after` impacts per period: the end lies between `last`
/// and `beyond_nm` (nm; the grazing the branch was running into, extrapolated, or where the
/// diagram jumps to), which is its bracket; its width is the precision, converged only within
/// the location tolerance (1e-9 nm).
fn branch_end_point(
    label: &str,
    last: &DiagramPoint,
    beyond_nm: f64,
    (impacts_before, impacts_after): (usize, usize),
) -> DiagramSpecialPoint {
    let bracket = [last.z_nm.min(beyond_nm), last.z_nm.max(beyond_nm)];
    let precision = bracket[1] - bracket[0];
    DiagramSpecialPoint {
        label: label.to_string(),
        z_nm: last.z_nm,
        amplitude_ratio: last.amplitude_ratio,
        phase_deg: last.phase_deg,
        impacts_before,
        impacts_after,
        bracket_nm: bracket,
        precision_nm: precision,
        converged: precision <= ContinuationSettings::default().location_tolerance,
        state: last.state.clone(),
        harmonics: last.harmonics.clone(),
        dissipated_ev: last.dissipated_ev,
        virial_ev: last.virial_ev,
        max_indentation_nm: last.max_indentation_nm,
        mean_indentation_nm: last.mean_indentation_nm,
    }
}

/// One branch of [`diagram_until`]: the continuation from `(x0, z_start)` until it stops, and,
/// where a hysteretic law's branch was stopped because `Z` turned back, how it turned (the
/// point past the turn and the special points located beyond the last point are dropped; a
/// fold among them is the turn's).
fn branch_until(
    model: &TappingModel,
    x0: &[f64],
    z_start: f64,
    settings: &DiagramSettings,
    interrupted: &mut dyn FnMut() -> bool,
) -> Result<(BifurcationDiagram, Option<BranchEnd>), AfmError> {
    let hysteretic = model.release_gap_nm().is_some();
    let sign = match settings.direction {
        ParameterDirection::Decreasing => -1.0,
        ParameterDirection::Increasing => 1.0,
    };
    let mut previous_z = z_start;
    let mut turned = false;
    settings.validate()?;
    let mut system = model.clone();
    system.set_separation(Separation::Constant(z_start))?;
    let problem = ObservedPeriodProblem::new(
        &system,
        &settings.orbit.integration,
        settings.orbit.harmonics,
    )?;
    let (parameter_min, parameter_max) = match settings.direction {
        ParameterDirection::Decreasing => (settings.z_limit_nm, f64::INFINITY),
        ParameterDirection::Increasing => (f64::NEG_INFINITY, settings.z_limit_nm),
    };
    let continuation_settings = ContinuationSettings {
        initial_step: settings.max_step * INITIAL_STEP_FRACTION,
        max_step: settings.max_step,
        direction: settings.direction,
        parameter_min,
        parameter_max,
        max_points: settings.max_points,
        corrector: settings.orbit.newton.clone(),
        hysteretic_grazing: hysteretic,
        ..ContinuationSettings::default()
    };
    let a0 = model.free_amplitude_nm();
    let min_ratio = settings.min_amplitude_ratio;
    let margin = settings.ratio_floor_margin_nm;
    // The `Z` where `A/A0` last fell below `min_ratio` (none while it is above).
    let mut below_since: Option<f64> = None;
    // Observables are recorded by the corrector's accepted evaluation (or computed once if it
    // did not record them), read inside the stop predicate, and kept.
    let mut observed: Vec<Result<OrbitObservables, AfmError>> = Vec::new();
    let mut was_interrupted = false;
    let branch = {
        let observed = &mut observed;
        let was_interrupted = &mut was_interrupted;
        let turned = &mut turned;
        let observing = &problem;
        Continuation::new(&problem, x0, z_start, continuation_settings)?
            .stop_when(move |point: &BranchPoint| {
                if interrupted() {
                    *was_interrupted = true;
                    return true;
                }
                // A hysteretic law's branch breaks where the period map jumps; the
                // corrector may converge across it onto the branch turning back.
                if hysteretic && sign * (point.parameter - previous_z) < 0.0 {
                    *turned = true;
                    return true;
                }
                previous_z = point.parameter;
                let observables = observing.observables(point.state.as_slice(), point.parameter);
                let stop = match &observables {
                    Ok(o) if o.amplitude_nm / a0 < min_ratio => {
                        let since = *below_since.get_or_insert(point.parameter);
                        sign * (point.parameter - since) >= margin
                    }
                    Ok(_) => {
                        below_since = None;
                        false
                    }
                    Err(_) => true,
                };
                observed.push(observables);
                stop
            })
            .run()
    };
    if was_interrupted {
        return Err(AfmError::Interrupted);
    }
    let mut points = Vec::with_capacity(branch.points.len());
    for (point, observables) in branch.points.iter().zip(observed) {
        points.push(diagram_point(point, &observables?));
    }
    let mut special_points = Vec::with_capacity(branch.special_points.len());
    for special in &branch.special_points {
        special_points.push(diagram_special_point(
            &system,
            special,
            &settings.orbit.integration,
            settings.orbit.harmonics,
        )?);
    }
    if turned {
        let last_z = points.last().map_or(z_start, |p: &DiagramPoint| p.z_nm);
        let fold = special_points
            .iter()
            .zip(&branch.special_points)
            .find(|(p, special)| {
                special.kind == SpecialPointKind::Fold && sign * (p.z_nm - last_z) > 1e-9
            })
            .map(|(p, _)| p.clone());
        special_points.retain(|p| sign * (p.z_nm - last_z) <= 1e-9);
        let end = match fold {
            Some(fold) => BranchEnd::Fold(fold),
            None => BranchEnd::Reversed,
        };
        return Ok((
            BifurcationDiagram {
                points,
                special_points,
                stop: "the branch broke at a jump of the hysteretic contact".to_string(),
                completed: false,
                error: None,
            },
            Some(end),
        ));
    }
    let end = (hysteretic && branch.stop == StopReason::StepTooSmall)
        .then(|| BranchEnd::Stuck(extrapolated_grazing(&branch.points, sign)));
    Ok((
        BifurcationDiagram {
            points,
            special_points,
            stop: stop_words(branch.stop),
            completed: matches!(
                branch.stop,
                StopReason::ParameterBound | StopReason::UserStop
            ),
            error: branch.error.map(|e| e.to_string()),
        },
        end,
    ))
}

fn stop_words(stop: StopReason) -> String {
    match stop {
        StopReason::MaxPoints => "the maximum number of points was reached",
        StopReason::ParameterBound => "the separation limit was reached",
        StopReason::UserStop => "the amplitude ratio fell below its floor",
        StopReason::StepTooSmall => "the corrector failed at the smallest step",
        StopReason::Error => "an error ended the branch",
    }
    .to_string()
}

fn multipliers_of(multipliers: &[Complex<f64>]) -> Vec<[f64; 2]> {
    multipliers.iter().map(|m| [m.re, m.im]).collect()
}

fn diagram_point(point: &BranchPoint, observables: &OrbitObservables) -> DiagramPoint {
    let min_gap = observables.min_gap_nm();
    DiagramPoint {
        z_nm: point.parameter,
        amplitude_ratio: observables.amplitude_ratio,
        phase_deg: observables.phase_deg,
        multiplicity: observables.window_periods,
        impacts_per_period: observables.impacts_per_period,
        impacts_per_orbit: observables.impacts_per_window(),
        gap_minima: observables.gap_minima.clone(),
        min_gap_nm: min_gap.is_finite().then_some(min_gap),
        peak_force_nn: observables.peak_force_nn,
        mean_force_nn: observables.mean_force_nn,
        impulse_nn_us: observables.impulse_nn_us,
        contact_time_periods: observables.contact_time_periods,
        harmonics: observables.harmonics.clone(),
        dissipated_ev: observables.dissipated_ev,
        virial_ev: observables.virial_ev,
        max_indentation_nm: observables.max_indentation_nm,
        mean_indentation_nm: observables.mean_indentation_nm,
        energy_balance_residual: observables.energy_balance_residual,
        floquet_multipliers: multipliers_of(&point.multipliers),
        spectral_radius: continuation::spectral_radius(&point.multipliers),
        stable: point.stable,
        state: point.state.as_slice().to_vec(),
        iterations: point.iterations,
        residual: point.residual,
    }
}

fn diagram_special_point(
    system: &TappingModel,
    special: &SpecialPoint,
    integration: &hybrid::Settings,
    harmonics: usize,
) -> Result<DiagramSpecialPoint, AfmError> {
    let mut at_point = system.clone();
    at_point.set_parameter(special.orbit_parameter);
    let observables =
        orbit_observables(&at_point, special.state.as_slice(), integration, harmonics)?;
    // A grazing is named after the impact count on its impacting side, whichever way the
    // branch runs: G_n is the onset of n impacts per period on approach (MODEL.md section 5),
    // and the same point met on a retract (n -> n - 1) keeps its name.
    let label = match special.kind {
        SpecialPointKind::Grazing => {
            format!("G{}", special.impacts_before.max(special.impacts_after))
        }
        _ => special.label.clone(),
    };
    Ok(DiagramSpecialPoint {
        label,
        z_nm: special.parameter,
        amplitude_ratio: observables.amplitude_ratio,
        phase_deg: observables.phase_deg,
        impacts_before: special.impacts_before,
        impacts_after: special.impacts_after,
        // The location brackets the point along the branch; at a fold both ends of that
        // bracket lie on one side of the fold's Z (Z is extremal there), so the Z range
        // reported spans the ends and the point itself.
        bracket_nm: [
            special
                .bracket
                .0
                .min(special.bracket.1)
                .min(special.parameter),
            special
                .bracket
                .0
                .max(special.bracket.1)
                .max(special.parameter),
        ],
        precision_nm: special.precision,
        converged: special.converged,
        state: special.state.as_slice().to_vec(),
        harmonics: observables.harmonics,
        dissipated_ev: observables.dissipated_ev,
        virial_ev: observables.virial_ev,
        max_indentation_nm: observables.max_indentation_nm,
        mean_indentation_nm: observables.mean_indentation_nm,
    })
}
