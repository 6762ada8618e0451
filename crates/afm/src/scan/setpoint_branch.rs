//! The ideal amplitude feedback on one material (MODEL.md section 12): the approach branch of
//! the material's periodic orbits in `Z` (pseudo-arclength, through every grazing and fold,
//! [`approach_diagram`]), and the walk along it that a slow feedback makes from the orbit the
//! cantilever is on to the orbit whose `A/A0` is the setpoint.
//!
//! The feedback moves `Z` down while `A/A0` is above the setpoint and up while it is below,
//! slowly enough that the cantilever stays on its attractor: the walk follows the stable part
//! of the branch that holds the current orbit, in the direction of `Z` the error asks for,
//! until `A/A0` crosses the setpoint (refined on `Z` by the Illinois method of
//! [`crate::sweep::amplitude_ratio`]). If the stable part ends first (a fold), the cantilever
//! jumps: it is released from the fold's orbit just past the fold, settles by transients on
//! another attractor, and the walk resumes from there. Where two stable orbits coexist at the
//! setpoint, the scan stays on the one it came from.

use crate::diagram::bifurcation_diagram::{approach_diagram, BifurcationDiagram, DiagramSettings};
use crate::error::AfmError;
use crate::model::TappingModel;
use crate::orbit::steady_orbit::{
    state_distance, steady_orbit_in, OrbitStart, SteadyOrbit, SteadyOrbitSettings,
    SteadyOrbitWorkspace,
};
use crate::scan::pixel::BranchJump;
use crate::sweep::amplitude_ratio::{refine_ratio_bracket, AmplitudeRatioSearch};

/// Drive periods of transients after a jump or a change of material, before Newton (the
/// MAClever in water, `Q_1 = 1.6`, loses a factor `exp(-pi / Q_1) = 0.14` per period).
pub const SETTLE_PERIODS: usize = 200;

/// How far past a fold's `Z` the cantilever is released when the feedback jumps, as a fraction
/// of `A0`.
pub const JUMP_PAST_FOLD: f64 = 1e-4;

/// How far below the setpoint's floor `A/A0 = ratio - 0.05` the branch is followed on, as a
/// fraction of `A0` in `Z`: far enough to pass an attractive regime's fold and reach the
/// repulsive branch beyond it, where two stable orbits hold the setpoint (MODEL.md section 12).
pub const RATIO_FLOOR_MARGIN: f64 = 0.25;

/// The most jumps one walk makes before giving up (a feedback that never settles).
pub const MAX_JUMPS: usize = 8;

/// The approach branch of one material with its stable parts, for walks to a setpoint.
#[derive(Debug, Clone)]
pub struct SetpointBranch {
    model: TappingModel,
    search: AmplitudeRatioSearch,
    settings: SteadyOrbitSettings,
    diagram: BifurcationDiagram,
    /// The stable parts `[first, last]` of the branch (indices of consecutive stable points,
    /// at least two).
    stable_parts: Vec<[usize; 2]>,
}

/// Where a walk starts: an orbit and the stable part and interval of the branch it lies on.
struct Entry {
    orbit: SteadyOrbit,
    part: usize,
    /// The branch interval `[i, i + 1]` whose `Z` range holds the orbit's `Z`.
    interval: usize,
}

impl SetpointBranch {
    /// The branch of `model` for the setpoint `search.ratio`: the approach diagram from first
    /// contact down to [`RATIO_FLOOR_MARGIN`]` A0` below where `A/A0` falls under
    /// `ratio - 0.05`, or to `Z = search.floor_fraction * A0`.
    pub fn new(
        model: &TappingModel,
        search: &AmplitudeRatioSearch,
        settings: &SteadyOrbitSettings,
    ) -> Result<Self, AfmError> {
        let diagram_settings = DiagramSettings {
            ratio_floor_margin_nm: RATIO_FLOOR_MARGIN * model.free_amplitude_nm(),
            ..search.diagram_settings(model, settings)
        };
        let diagram = approach_diagram(model, &diagram_settings)?;
        let mut stable_parts = Vec::new();
        let mut start: Option<usize> = None;
        for (index, point) in diagram.points.iter().enumerate() {
            match (point.stable, start) {
                (true, None) => start = Some(index),
                (false, Some(first)) => {
                    if index - first >= 2 {
                        stable_parts.push([first, index - 1]);
                    }
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(first) = start {
            if diagram.points.len() - first >= 2 {
                stable_parts.push([first, diagram.points.len() - 1]);
            }
        }
        Ok(Self {
            model: model.clone(),
            search: search.clone(),
            settings: settings.clone(),
            diagram,
            stable_parts,
        })
    }

    /// The branch (the material's approach diagram).
    pub fn diagram(&self) -> &BifurcationDiagram {
        &self.diagram
    }

    /// The setpoint orbit a slow approach from far above reaches first (engaging the
    /// feedback): the first crossing of the setpoint on a stable part, in branch order.
    pub fn engage(
        &self,
        workspace: &mut SteadyOrbitWorkspace,
    ) -> Result<(SteadyOrbit, Option<BranchJump>), AfmError> {
        let Some(&[first, _]) = self.stable_parts.first() else {
            return Err(self.not_reached("the approach branch has no stable part"));
        };
        let point = &self.diagram.points[first];
        let orbit = steady_orbit_in(
            &self.model,
            point.z_nm,
            OrbitStart::Near(&point.state),
            &self.settings,
            workspace,
        )?;
        self.walk(
            Entry {
                orbit,
                part: 0,
                interval: first,
            },
            workspace,
        )
    }

    /// The setpoint orbit the feedback reaches from `state` at separation `z_nm` (the orbit
    /// the cantilever was on over another material, or on this one before the feedback moved):
    /// the cantilever settles by transients at `z_nm`, then the walk follows its stable part.
    pub fn follow(
        &self,
        z_nm: f64,
        state: &[f64],
        workspace: &mut SteadyOrbitWorkspace,
    ) -> Result<(SteadyOrbit, Option<BranchJump>), AfmError> {
        let entry = self.settle(z_nm, state, workspace)?;
        self.walk(entry, workspace)
    }

    /// The attractor reached by transients from `state` at `z_nm`, located on the branch.
    fn settle(
        &self,
        z_nm: f64,
        state: &[f64],
        workspace: &mut SteadyOrbitWorkspace,
    ) -> Result<Entry, AfmError> {
        let settings = SteadyOrbitSettings {
            transient_periods: SETTLE_PERIODS,
            ..self.settings.clone()
        };
        let orbit = steady_orbit_in(
            &self.model,
            z_nm,
            OrbitStart::AfterTransients(state),
            &settings,
            workspace,
        )?;
        let points = &self.diagram.points;
        // Above the branch's start the orbit is the free one: enter at the top.
        if let Some(&[first, _]) = self.stable_parts.first() {
            if first == 0 && z_nm >= points[0].z_nm {
                return Ok(Entry {
                    orbit,
                    part: 0,
                    interval: 0,
                });
            }
        }
        let mut best: Option<(f64, usize, usize)> = None;
        for (part, &[first, last]) in self.stable_parts.iter().enumerate() {
            for i in first..last {
                let (a, b) = (&points[i], &points[i + 1]);
                let (low, high) = (a.z_nm.min(b.z_nm), a.z_nm.max(b.z_nm));
                if !(low..=high).contains(&z_nm) {
                    continue;
                }
                let s = if b.z_nm == a.z_nm {
                    0.0
                } else {
                    (z_nm - a.z_nm) / (b.z_nm - a.z_nm)
                };
                let interpolated: Vec<f64> = a
                    .state
                    .iter()
                    .zip(&b.state)
                    .map(|(x, y)| x + s * (y - x))
                    .collect();
                let distance = state_distance(&interpolated, &orbit.state);
                if best.is_none_or(|(d, _, _)| distance < d) {
                    best = Some((distance, part, i));
                }
            }
        }
        let Some((_, part, interval)) = best else {
            return Err(self.not_reached(&format!(
                "no stable orbit of the approach branch lies at Z = {z_nm:.6} nm (the branch \
                 spans Z in [{:.6}, {:.6}] nm)",
                points.iter().map(|p| p.z_nm).fold(f64::INFINITY, f64::min),
                points[0].z_nm
            )));
        };
        Ok(Entry {
            orbit,
            part,
            interval,
        })
    }

    /// Walk from `entry` along its stable part towards the setpoint, jumping at folds.
    fn walk(
        &self,
        mut entry: Entry,
        workspace: &mut SteadyOrbitWorkspace,
    ) -> Result<(SteadyOrbit, Option<BranchJump>), AfmError> {
        let a0 = self.model.free_amplitude_nm();
        let ratio = self.search.ratio;
        let points = &self.diagram.points;
        let mut first_jump: Option<BranchJump> = None;
        for walk in 0..=MAX_JUMPS {
            let current = entry.orbit.lockin(a0).0;
            if current == ratio {
                return Ok((entry.orbit, first_jump));
            }
            // The feedback lowers Z while the amplitude is too large.
            let z_sign = if current > ratio { -1.0 } else { 1.0 };
            let [first, last] = self.stable_parts[entry.part];
            let i = entry.interval;
            let step_sign = (points[i + 1].z_nm - points[i].z_nm).signum();
            let forward = step_sign == z_sign;
            let mut index = if forward { i + 1 } else { i };
            let mut cursor_ratio = current;
            let mut cursor: Option<usize> = None;
            loop {
                let point = &points[index];
                // A point behind the entry in Z (the entry lies inside its interval) is skipped.
                let ahead = (point.z_nm - entry.orbit.z_nm) * z_sign >= 0.0;
                if ahead
                    && (point.amplitude_ratio - ratio).signum() != (cursor_ratio - ratio).signum()
                {
                    let near = match cursor {
                        Some(c) => steady_orbit_in(
                            &self.model,
                            points[c].z_nm,
                            OrbitStart::Near(&points[c].state),
                            &self.settings,
                            workspace,
                        )?,
                        None => entry.orbit.clone(),
                    };
                    let far = steady_orbit_in(
                        &self.model,
                        point.z_nm,
                        OrbitStart::Near(&point.state),
                        &self.settings,
                        workspace,
                    )?;
                    let (above, below) = if z_sign < 0.0 {
                        (near, far)
                    } else {
                        (far, near)
                    };
                    let orbit = refine_ratio_bracket(
                        &self.model,
                        &self.search,
                        &self.settings,
                        above,
                        below,
                        workspace,
                    )?;
                    return Ok((orbit, first_jump));
                }
                if ahead {
                    cursor = Some(index);
                    cursor_ratio = point.amplitude_ratio;
                }
                let at_end = if forward {
                    index == last
                } else {
                    index == first
                };
                if at_end {
                    break;
                }
                index = if forward { index + 1 } else { index - 1 };
            }
            // The stable part ended before the setpoint.
            let end = &points[index];
            if (forward && index == points.len() - 1) || (!forward && index == 0) {
                return Err(self.not_reached(&format!(
                    "the feedback reached the end of the computed branch at Z = {:.6} nm with \
                     A/A0 = {:.6} ({})",
                    end.z_nm, end.amplitude_ratio, self.diagram.stop
                )));
            }
            if walk == MAX_JUMPS {
                break;
            }
            // Where the stable part loses its stability: the special point (a fold) the
            // diagram located on the branch step from its last point to the next, else that
            // last point. At a fold `Z` is extremal, so both points may lie on one side of the
            // fold's `Z`: the step's point is told by its state, on the branch between theirs
            // (the two distances add up to at most 1.5 times the step's).
            let beyond = &points[if forward { index + 1 } else { index - 1 }];
            let distance = |a: &[f64], b: &[f64]| {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| (x - y) * (x - y))
                    .sum::<f64>()
                    .sqrt()
            };
            let chord = distance(&end.state, &beyond.state);
            let detour = |state: &[f64]| {
                distance(state, &end.state) + distance(state, &beyond.state) - chord
            };
            let (from_z, from_ratio, from_impacts, from_state) = match self
                .diagram
                .special_points
                .iter()
                .filter(|s| s.converged && s.state.len() == end.state.len())
                .map(|s| (detour(&s.state), s))
                .filter(|(detour, _)| *detour <= 0.5 * chord)
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, point)| point)
            {
                Some(fold) => (
                    fold.z_nm,
                    fold.amplitude_ratio,
                    fold.impacts_before.max(fold.impacts_after) as f64,
                    fold.state.as_slice(),
                ),
                None => (
                    end.z_nm,
                    end.amplitude_ratio,
                    end.impacts_per_period,
                    end.state.as_slice(),
                ),
            };
            if first_jump.is_none() {
                first_jump = Some(BranchJump {
                    from_z_nm: from_z,
                    from_amplitude_ratio: from_ratio,
                    from_impacts_per_period: from_impacts,
                });
            }
            let release = from_z + z_sign * JUMP_PAST_FOLD * a0;
            entry = self.settle(release, from_state, workspace)?;
        }
        Err(self.not_reached(&format!(
            "the feedback jumped {MAX_JUMPS} times without settling (no stable orbit at the \
             setpoint reachable from here)"
        )))
    }

    /// `error` of a search for this branch's setpoint, with the sample named (see
    /// [`on_sample`]).
    pub fn named(&self, error: AfmError) -> AfmError {
        on_sample(error, self.search.ratio, &self.model.sample().name)
    }

    fn not_reached(&self, reason: &str) -> AfmError {
        AfmError::NotReached {
            what: format!(
                "A/A0 = {} on sample `{}`",
                self.search.ratio,
                self.model.sample().name
            ),
            reason: reason.to_string(),
        }
    }
}

/// `error` of the search for the setpoint `A/A0 = ratio` on sample `sample` (its branch, the
/// feedback's engaging or its walk), naming the sample, so that a scan over several materials
/// says which one failed: a setpoint not reached gets the sample in what was searched for, a
/// failed orbit or continuation becomes the setpoint not reached on that sample for that
/// reason; other errors (an interruption, bad input) are returned as they are.
pub fn on_sample(error: AfmError, ratio: f64, sample: &str) -> AfmError {
    let what = format!("A/A0 = {ratio} on sample `{sample}`");
    match error {
        AfmError::NotReached {
            what: searched,
            reason,
        } if !searched.contains("on sample") => AfmError::NotReached { what, reason },
        AfmError::Continuation(_) | AfmError::Solver(_) => AfmError::NotReached {
            what,
            reason: error.to_string(),
        },
        other => other,
    }
}
