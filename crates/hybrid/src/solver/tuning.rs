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

/// In a mode whose Jacobian diverges at its half-power crossing, the first Runge-Kutta step after
/// the series (which take no square-root clock centred ahead) is a step in time of at most this
/// fraction of the distance to the crossing the series predicted: it ends more than twice its
/// length from the crossing's `|h|^{-1/2}` in the Jacobian, which the state's error control does
/// not see (half the way left the tangents' error several times larger).
pub(super) const SERIES_HANDOVER_FRACTION: f64 = 0.3;

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
/// a step that grows there is rejected; a longer span buys a more accurate monodromy (already
/// far below the 1e-6 Newton and the Floquet multipliers need) for more steps.
pub(super) const ROOT_CLOCK_SPAN: f64 = 1.0;

/// How many of its own reaches from a Taylor step's start its series is searched for the next
/// crossing of the half-power surface: this step and about the next one's length (the series
/// converges out to about four reaches; a longer search costs evaluations and saves no steps).
pub(super) const RELEASE_LOOKAHEAD: f64 = 2.0;

/// A Taylor step shorter than this fraction of the previous one gives way to Runge-Kutta.
pub(super) const MIN_SERIES_FRACTION: f64 = 1e-3;

/// Points at which a rejected trial's dense output is sampled to bracket the crossing it
/// passed.
pub(super) const TRIAL_SAMPLES: usize = 16;

/// Re-centred square-root landings allowed per step after a landing passed its crossing.
pub(super) const MAX_RETARGETS: usize = 3;

/// A re-centred square-root clock must move its reference by more than this many
/// [`ROOT_OVERSHOOT`]s of the distance: nearer, the clock is already where the crossing is,
/// and re-centring would repeat the same landing.
pub(super) const RETARGET_MOVE: f64 = 10.0;

/// A Runge-Kutta step no longer than this many ulps of `|t|` cannot advance time: the step
/// size has underflowed.
pub(super) const MIN_STEP_EPSILONS: f64 = 8.0;

/// After a trial with a non-finite error (the state blew up inside it), the next is this
/// fraction of its length: a drastic cut, as the error estimate says nothing about the scale.
pub(super) const NON_FINITE_RETRY: f64 = 0.1;

/// The error a step chosen after a rejection aims at (Hairer's controller aims at about
/// `0.9^8`): a margin below the acceptance threshold 1 for an order that is only estimated.
pub(super) const REJECTION_TARGET_ERROR: f64 = 0.5;

/// The order in the step length assumed for the error of a landing on a non-smooth crossing:
/// a Hertz contact's kink gives errors like `s^3.5` (smoother kinks a higher power, so the
/// landing distance derived from it is conservative).
pub(super) const FAILED_LANDING_ORDER: f64 = 3.5;

/// The bounds on the ratio of a step chosen after a rejection to the rejected one: at least
/// a hundredth (an implausibly large error cannot collapse the step), at most 0.9 (a rejected
/// step is never retried at nearly its length).
pub(super) const STEP_RATIO_AFTER_REJECTION: (f64, f64) = (0.01, 0.9);

/// The range of error orders in the step estimated from two successive rejections that the
/// controller trusts: below 0.5 the error barely depends on the step (the estimate is noise),
/// above 9 it exceeds DOP853's order 8 (not a singularity of the field).
pub(super) const ORDER_ESTIMATE_RANGE: std::ops::RangeInclusive<f64> = 0.5..=9.0;

/// A crossing nearer than this many ulps of `|t|` cannot be landed on: a few hundred rounding
/// steps of time, the scale at which a Zeno accumulation or a state on the surface puts it.
pub(super) const RESOLVABLE_EPSILONS: f64 = 1024.0;

/// The forward difference, in fractions of the proposed step, over which the crossing
/// predictor takes the derivative of `dh/dt` along the field: small against the step (the
/// quadratic's curvature is local) and large against rounding.
pub(super) const PREDICTION_DIFFERENCE: f64 = 1e-4;

/// The tolerance, in fractions of a rejected trial, to which the crossing of its cubic Hermite
/// estimate of `h` is located: far finer than the estimate itself needs, at negligible cost
/// (the cubic is evaluated in closed form).
pub(super) const HERMITE_FRACTION_TOLERANCE: f64 = 1e-9;

/// The relative margin by which a rigorous curvature-bound test is tightened, for the rounding
/// of its own products and square roots.
pub(super) const BOUND_ROUNDING_MARGIN: f64 = 1e-9;
