//! Where the paper's approximate theory (Eqs. 3 and 4, MODEL.md section 7) does not apply to a
//! compared orbit: each assumption it rests on, checked on the orbit, and whether a failure
//! withholds the predictions (they would be numbers with no meaning) or only flags them.

use std::fmt;

use serde::Serialize;

/// The lowest separation `Z` at which the theory's picture holds, nm: at `Z <= 0` the undriven,
/// undeflected tip (`d = Z`, MODEL.md section 1) rests at or inside the sample surface, so the
/// cantilever is pressed into the sample even without drive, while Eqs. 3-4 describe a free
/// oscillation interrupted by short impacts.
pub const THEORY_MIN_SEPARATION_NM: f64 = 0.0;

/// The longest contact per period, in drive periods, of the paper's short-contact argument
/// (`t_c <= 0.2 T`, below its Eq. 3): past it `cos(theta) = -1` over the contact is no longer
/// a fair approximation.
pub const THEORY_MAX_CONTACT_PERIODS: f64 = 0.2;

/// One assumption of the approximate theory that a compared orbit violates.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum AssumptionFailure {
    /// The orbit has no contact: Eqs. 3-4 describe an impact, and there is none. Withholds the
    /// predictions.
    NoContact {
        /// The orbit's separation, nm.
        z_nm: f64,
        /// First contact `Z_G1`, nm.
        first_contact_z_nm: f64,
    },
    /// `Z <= THEORY_MIN_SEPARATION_NM`: the tip rests in the sample without drive. Withholds
    /// the predictions.
    SeparationBelowSurface {
        /// The orbit's separation, nm.
        z_nm: f64,
    },
    /// `cos(phi) <= 0` for the phase `phi` used: Eq. 3 gives a non-positive impulse for a
    /// repulsive force, and Eq. 4 a non-positive amplitude. Withholds that prediction.
    NonPositiveImpulse {
        /// Which phase: `q1` (the comparison proper) or `u` (the instrument's).
        phase: &'static str,
        /// The phase, degrees.
        phase_deg: f64,
    },
    /// The measured ringing of `q_2` does not decay from one impact to the next (other impacts
    /// in between kick it again), so it has no decay time. Withholds the measured decay time
    /// and the decay's relative error.
    RingingDoesNotDecay {
        /// The measured envelope ratio over a period.
        amplitude_ratio_over_period: f64,
    },
    /// The drive is not at `w_1` (Eq. 3 is derived at `w = w_1`). The predictions are computed
    /// anyway, with `a_0` at the actual drive, and flagged.
    DriveOffFundamental {
        /// The drive frequency, kHz.
        drive_frequency_khz: f64,
        /// `f_1`, kHz.
        fundamental_frequency_khz: f64,
        /// The first-harmonic balance's impulse at the actual drive, nN us.
        harmonic_balance_impulse_nn_us: f64,
    },
    /// More than one impact per period: the theory is that of the single-impact regime.
    /// Flagged; the predictions stay (Eq. 3 then bounds the total impulse).
    MultipleImpacts {
        /// Impacts per period.
        impacts: usize,
    },
    /// Contact longer than [`THEORY_MAX_CONTACT_PERIODS`] of a period. Flagged.
    LongContact {
        /// Contact time per period, drive periods.
        contact_time_periods: f64,
    },
}

impl AssumptionFailure {
    /// The failure's name in `snake_case` (the JSON's `kind`), e.g. `no_contact`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::NoContact { .. } => "no_contact",
            Self::SeparationBelowSurface { .. } => "separation_below_surface",
            Self::NonPositiveImpulse { .. } => "non_positive_impulse",
            Self::RingingDoesNotDecay { .. } => "ringing_does_not_decay",
            Self::DriveOffFundamental { .. } => "drive_off_fundamental",
            Self::MultipleImpacts { .. } => "multiple_impacts",
            Self::LongContact { .. } => "long_contact",
        }
    }

    /// Whether the failure withholds the predictions of Eqs. 3-4 altogether.
    pub fn withholds_predictions(&self) -> bool {
        matches!(
            self,
            Self::NoContact { .. } | Self::SeparationBelowSurface { .. }
        )
    }
}

impl fmt::Display for AssumptionFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoContact {
                z_nm,
                first_contact_z_nm,
            } => write!(
                f,
                "no contact at Z = {z_nm} nm (first contact is at Z_G1 = {first_contact_z_nm:.6} \
                 nm): Eqs. 3-4 describe an impact, so no prediction is given"
            ),
            Self::SeparationBelowSurface { z_nm } => write!(
                f,
                "Z = {z_nm} nm is at or below {THEORY_MIN_SEPARATION_NM} nm, the lowest \
                 separation of the theory: the undriven tip rests inside the sample, while \
                 Eqs. 3-4 assume a free oscillation interrupted by short impacts; no prediction \
                 is given"
            ),
            Self::NonPositiveImpulse { phase, phase_deg } => write!(
                f,
                "the {phase} phase {phase_deg:.4} deg has cos <= 0: Eq. 3 would give a \
                 non-positive impulse for a repulsive force; that prediction is not given"
            ),
            Self::RingingDoesNotDecay {
                amplitude_ratio_over_period,
            } => write!(
                f,
                "the measured ringing of q_2 grows or stays over a period (envelope ratio \
                 {amplitude_ratio_over_period:.4e} >= 1, other impacts kick it again): it has no \
                 decay time, and Eq. 4's decay is not compared"
            ),
            Self::DriveOffFundamental {
                drive_frequency_khz,
                fundamental_frequency_khz,
                harmonic_balance_impulse_nn_us,
            } => write!(
                f,
                "the drive ({drive_frequency_khz:.4} kHz) is not at f_1 = \
                 {fundamental_frequency_khz:.4} kHz: Eqs. 3-4 assume w = w_1 and do not hold \
                 here (computed anyway with a_0 at the actual drive); the first-harmonic \
                 balance at the actual w gives {harmonic_balance_impulse_nn_us:.6} nN us"
            ),
            Self::MultipleImpacts { impacts } => write!(
                f,
                "{impacts} impacts per period: Eqs. 3-4 are the single-impact theory (Eq. 3 then \
                 approximates the total impulse, Eq. 4 the ringing after the main impact only)"
            ),
            Self::LongContact {
                contact_time_periods,
            } => write!(
                f,
                "contact lasts {contact_time_periods:.4} periods, longer than the \
                 {THEORY_MAX_CONTACT_PERIODS} T of the theory's short-contact argument"
            ),
        }
    }
}
