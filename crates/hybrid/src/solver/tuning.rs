//! The heuristic constants of the step control, each with the reason for its value.

/// Fraction of a step past the estimated crossing at which a retried step lands.
pub(super) const LANDING_OVERSHOOT: f64 = 1e-6;

/// Fraction of the predicted distance past the predicted crossing at which a step aimed at it
/// ends (covers the prediction's error, so the crossing lies inside the step).
pub(super) const PREDICTED_OVERSHOOT: f64 = 1e-3;

/// A proposed step reaching this fraction of the predicted distance to a crossing is stretched
/// to land just past it.
pub(super) const LANDING_REACH: f64 = 0.6;

/// Once a landing has failed, steps towards the crossing are at most this fraction of the
/// predicted distance (a graded approach to the non-smooth point, the mirror image of the
/// step growth after a contact onset).
pub(super) const APPROACH_FRACTION: f64 = 0.5;

/// Fraction of the predicted distance past a predicted crossing of a half-power surface at
/// which a square-root-clock landing is centred (the crossing's non-smooth remainder inside
/// the step is then of relative size ~`ROOT_OVERSHOOT^2.5`, far below the tolerance).
pub(super) const ROOT_OVERSHOOT: f64 = 1e-6;

/// Steps run on a square-root clock centred on a crossing of a half-power surface once it is
/// predicted within this many proposed steps.
pub(super) const ROOT_APPROACH: f64 = 3.0;

/// Fraction of the predicted distance past the predicted crossing of a half-power surface at
/// which a probe ends (covers the quadratic prediction's error of a few per cent).
pub(super) const PROBE_OVERSHOOT: f64 = 0.05;

/// After entering a mode through its half-power surface, steps run on the square-root clock
/// from the event while the time since it is below this many proposed steps. Far from its
/// reference the clock is the worse one (the solution oscillates ever faster in `sigma`), and
/// a step that grows there is rejected: with 4 instead of 1 the approach benchmark's sweep
/// took 13% more instructions (callgrind: 54.0e9 against 47.7e9) and the Fig. 1 period maps
/// 4-8% more evaluations, for a monodromy 2-20 times more accurate (2.0e-9 and 5.1e-8
/// relative at A/A0 = 0.95 and 0.5, against 4.2e-8 and 1.1e-7 now; both far below the
/// 1e-6 that Newton and the Floquet multipliers are granted).
pub(super) const ROOT_CLOCK_SPAN: f64 = 1.0;

/// How many of its own reaches from a Taylor step's start its series is searched for the next
/// crossing of the half-power surface: this step and about the next one's length (the series
/// converges out to about four reaches; searching three cost 3% more per period map at A/A0 =
/// 0.5 for no fewer steps).
pub(super) const RELEASE_LOOKAHEAD: f64 = 2.0;

/// A Taylor step shorter than this fraction of the previous one gives way to Runge-Kutta.
pub(super) const MIN_SERIES_FRACTION: f64 = 1e-3;

/// Points at which a rejected trial's dense output is sampled to bracket the crossing it
/// passed.
pub(super) const TRIAL_SAMPLES: usize = 16;

/// Re-centred square-root landings allowed per step after a landing passed its crossing.
pub(super) const MAX_RETARGETS: usize = 3;
