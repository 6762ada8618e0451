//! The entries of an orbit's observable lists (impacts, gap minima, harmonics, periods;
//! MODEL.md section 10) as the JSON objects of docs/output-schema.md: copies of `afm`'s
//! records with their fields declared in alphabetical order of their keys, so that a derived
//! `Serialize` writes the bytes of the same record as a `serde_json::Value` (whose objects are
//! sorted maps). Shared by `simulate --json` and `continue --json`.

use afm::{GapMinimum, GapMinimumKind, Harmonic, Impact, PeriodBreakdown};
use serde::{Serialize, Serializer};

/// An entry of an orbit's `impacts` (afm's [`Impact`]): one interval in contact.
#[derive(Debug, Serialize)]
struct ImpactJson {
    end_periods: f64,
    peak_force_nn: f64,
    start_periods: f64,
    velocity_nm_per_us: f64,
}

impl From<&Impact> for ImpactJson {
    fn from(impact: &Impact) -> Self {
        Self {
            end_periods: impact.end_periods,
            peak_force_nn: impact.peak_force_nn,
            start_periods: impact.start_periods,
            velocity_nm_per_us: impact.velocity_nm_per_us,
        }
    }
}

/// An entry of an orbit's `gap_minima` (afm's [`GapMinimum`]): a local minimum of the gap.
#[derive(Debug, Serialize)]
struct GapMinimumJson {
    gap_nm: f64,
    kind: GapMinimumKind,
    t_periods: f64,
}

impl From<&GapMinimum> for GapMinimumJson {
    fn from(minimum: &GapMinimum) -> Self {
        Self {
            gap_nm: minimum.gap_nm,
            kind: minimum.kind,
            t_periods: minimum.t_periods,
        }
    }
}

/// An entry of an orbit's `harmonics` (afm's [`Harmonic`]): one harmonic of `u`.
#[derive(Debug, Serialize)]
struct HarmonicJson {
    amplitude_nm: f64,
    n: usize,
    phase_deg: f64,
}

impl From<&Harmonic> for HarmonicJson {
    fn from(harmonic: &Harmonic) -> Self {
        Self {
            amplitude_nm: harmonic.amplitude_nm,
            n: harmonic.n,
            phase_deg: harmonic.phase_deg,
        }
    }
}

/// An entry of an orbit's `periods` (afm's [`PeriodBreakdown`]): one drive period's
/// observables.
#[derive(Debug, Serialize)]
struct PeriodJson {
    amplitude_ratio: f64,
    contact_time_periods: f64,
    dissipated_ev: f64,
    energy_balance_residual: f64,
    impacts: usize,
    impulse_nn_us: f64,
    max_indentation_nm: f64,
    mean_force_nn: f64,
    mean_indentation_nm: f64,
    min_gap_nm: Option<f64>,
    peak_force_nn: f64,
    period: usize,
    phase_deg: f64,
    virial_ev: f64,
}

impl From<&PeriodBreakdown> for PeriodJson {
    fn from(period: &PeriodBreakdown) -> Self {
        Self {
            amplitude_ratio: period.amplitude_ratio,
            contact_time_periods: period.contact_time_periods,
            dissipated_ev: period.dissipated_ev,
            energy_balance_residual: period.energy_balance_residual,
            impacts: period.impacts,
            impulse_nn_us: period.impulse_nn_us,
            max_indentation_nm: period.max_indentation_nm,
            mean_force_nn: period.mean_force_nn,
            mean_indentation_nm: period.mean_indentation_nm,
            min_gap_nm: period.min_gap_nm,
            peak_force_nn: period.peak_force_nn,
            period: period.period,
            phase_deg: period.phase_deg,
            virial_ev: period.virial_ev,
        }
    }
}

/// `impacts` written as the list of their [`ImpactJson`] (for `#[serde(serialize_with)]`).
pub(crate) fn impacts_in_key_order<S: Serializer>(
    impacts: &[Impact],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(impacts.iter().map(ImpactJson::from))
}

/// `minima` written as the list of their [`GapMinimumJson`] (for `#[serde(serialize_with)]`).
pub(crate) fn gap_minima_in_key_order<S: Serializer>(
    minima: &[GapMinimum],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(minima.iter().map(GapMinimumJson::from))
}

/// `harmonics` written as the list of their [`HarmonicJson`] (for `#[serde(serialize_with)]`).
pub(crate) fn harmonics_in_key_order<S: Serializer>(
    harmonics: &[Harmonic],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(harmonics.iter().map(HarmonicJson::from))
}

/// `periods` written as the list of their [`PeriodJson`] (for `#[serde(serialize_with)]`).
pub(crate) fn periods_in_key_order<S: Serializer>(
    periods: &[PeriodBreakdown],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(periods.iter().map(PeriodJson::from))
}
