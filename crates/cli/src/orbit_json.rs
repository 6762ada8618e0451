//! The JSON object of one steady orbit (docs/output-schema.md) as a derived `Serialize` of
//! borrowed fields: `simulate --json` writes it without building a `serde_json::Value` tree.
//! The fields are declared in alphabetical order of their keys, so that the bytes are those of
//! the same object as a `serde_json::Value` (whose objects are sorted maps); the entries of its
//! lists (impacts, gap minima, harmonics, periods) are written in key order by
//! [`crate::observable_records_json`].

use afm::{GapMinimum, Harmonic, Impact, PeriodBreakdown, SteadyOrbit, TappingModel};
use serde::Serialize;

use crate::inputs::InputsJson;
use crate::observable_records_json::{
    gap_minima_in_key_order, harmonics_in_key_order, impacts_in_key_order, periods_in_key_order,
};

/// One steady orbit's JSON object (units in the key names; docs/output-schema.md): the
/// observables of the whole orbit (all its `multiplicity` drive periods, MODEL.md section 10),
/// the per-period breakdown in `periods`, and, for `simulate`, the start that found it, the
/// other start's orbit and the command's inputs.
#[derive(Debug, Serialize)]
pub struct OrbitJson<'a> {
    /// `A/A0` of the first harmonic of `u` (MODEL.md section 10).
    amplitude_ratio: f64,
    /// The case's name.
    case: &'a str,
    /// `simulate`'s other start's orbit where it differs (`Some(None)`: `null`); absent when not
    /// asked (`None`).
    #[serde(skip_serializing_if = "Option::is_none")]
    coexisting_orbit: Option<Option<Box<OrbitJson<'a>>>>,
    /// The time in contact, in drive periods per period.
    contact_time_periods: f64,
    /// Whether Newton converged.
    converged: bool,
    /// The energy dissipated in the sample per period, eV.
    dissipated_ev: f64,
    /// The drive frequency, kHz.
    drive_frequency_khz: f64,
    /// The relative residual of the energy balance.
    energy_balance_residual: f64,
    /// The separation of first contact `Z_G1`, nm.
    first_contact_z_nm: f64,
    /// The Floquet multipliers as `[re, im]`.
    floquet_multipliers: Vec<[f64; 2]>,
    /// The free amplitude `A0`, nm.
    free_amplitude_nm: f64,
    /// The free orbit's phase lag, degrees.
    free_phase_deg: f64,
    /// The gap's local minima.
    #[serde(serialize_with = "gap_minima_in_key_order")]
    gap_minima: &'a [GapMinimum],
    /// The harmonics of `u`.
    #[serde(serialize_with = "harmonics_in_key_order")]
    harmonics: &'a [Harmonic],
    /// The impacts.
    #[serde(serialize_with = "impacts_in_key_order")]
    impacts: &'a [Impact],
    /// The impacts over the whole orbit.
    impacts_per_orbit: usize,
    /// The impacts per drive period, on average over the orbit.
    impacts_per_period: f64,
    /// The impulse `int F_ts dt` per period, nN us.
    impulse_nn_us: f64,
    /// `simulate`'s inputs (absent when not given).
    #[serde(skip_serializing_if = "Option::is_none")]
    inputs: Option<InputsJson<'a>>,
    /// The largest indentation, nm.
    max_indentation_nm: f64,
    /// The mean tip-sample force, nN.
    mean_force_nn: f64,
    /// The mean indentation in contact, nm.
    mean_indentation_nm: f64,
    /// The lowest gap minimum, nm (`null` if none).
    min_gap_nm: Option<f64>,
    /// The orbit's period in drive periods.
    multiplicity: usize,
    /// Newton's iterations.
    newton_iterations: usize,
    /// The largest tip-sample force, nN.
    peak_force_nn: f64,
    /// The orbit's drive period, us.
    period_us: f64,
    /// The per-period breakdown.
    #[serde(serialize_with = "periods_in_key_order")]
    periods: Vec<PeriodBreakdown>,
    /// The first harmonic's phase lag, degrees.
    phase_deg: f64,
    /// Newton's last residual.
    residual: f64,
    /// The response at a bimodal drive's second frequency (`null` for one frequency).
    second_drive: Option<SecondDriveJson>,
    /// The largest `|Floquet multiplier|`.
    spectral_radius: f64,
    /// Whether the orbit is stable.
    stable: bool,
    /// The start that found the orbit (absent when not given).
    #[serde(skip_serializing_if = "Option::is_none")]
    start: Option<&'a str>,
    /// The orbit's state at `t = 0` (`q_i` in nm, `q_i'` in nm/us).
    state: &'a [f64],
    /// The virial per period, eV.
    virial_ev: f64,
    /// The separation `Z`, nm.
    z_nm: f64,
}

/// The `second_drive` object of [`OrbitJson`] (MODEL.md section 14): the bimodal drive's
/// second frequency and free amplitude, and the orbit's and the free orbit's response there.
#[derive(Debug, Serialize)]
struct SecondDriveJson {
    /// `A_b`, nm.
    amplitude_nm: f64,
    /// The second drive's free amplitude, nm.
    free_amplitude_nm: Option<f64>,
    /// The free orbit's phase lag at the second frequency, degrees.
    free_phase_deg: Option<f64>,
    /// The second drive's frequency, kHz.
    frequency_khz: Option<f64>,
    /// `Phi_b`, degrees.
    phase_deg: f64,
}

impl<'a> OrbitJson<'a> {
    /// The object of `orbit` of the model `model` of the case named `case`, without `start`,
    /// `coexisting_orbit` and `inputs`.
    pub fn new(case: &'a str, model: &TappingModel, orbit: &'a SteadyOrbit) -> Self {
        let observables = orbit.observables();
        let (amplitude_ratio, phase_deg) = orbit.lockin(model.free_amplitude_nm());
        let min_gap = observables.min_gap_nm();
        let second_drive = observables.second_drive.map(|response| SecondDriveJson {
            amplitude_nm: response.amplitude_nm,
            free_amplitude_nm: model.second_drive().map(|second| second.free_amplitude_nm),
            free_phase_deg: model
                .free_response()
                .second_photodiode_harmonic()
                .map(|[a, b]| b.atan2(a).to_degrees()),
            frequency_khz: model.second_drive().map(|second| second.frequency_khz),
            phase_deg: response.phase_deg,
        });
        Self {
            amplitude_ratio,
            case,
            coexisting_orbit: None,
            contact_time_periods: observables.contact_time_periods,
            converged: orbit.converged,
            dissipated_ev: observables.dissipated_ev,
            drive_frequency_khz: model.drive_frequency_khz(),
            energy_balance_residual: observables.energy_balance_residual,
            first_contact_z_nm: model.grazing_separation_nm(),
            floquet_multipliers: orbit.multipliers.iter().map(|m| [m.re, m.im]).collect(),
            free_amplitude_nm: model.free_amplitude_nm(),
            free_phase_deg: model.free_phase_deg(),
            gap_minima: &observables.gap_minima,
            harmonics: &observables.harmonics,
            impacts: &observables.impacts,
            impacts_per_orbit: orbit.impacts_per_orbit(),
            impacts_per_period: orbit.impacts_per_period(),
            impulse_nn_us: observables.impulse_nn_us,
            inputs: None,
            max_indentation_nm: observables.max_indentation_nm,
            mean_force_nn: observables.mean_force_nn,
            mean_indentation_nm: observables.mean_indentation_nm,
            min_gap_nm: min_gap.is_finite().then_some(min_gap),
            multiplicity: orbit.multiplicity,
            newton_iterations: orbit.iterations,
            peak_force_nn: observables.peak_force_nn,
            period_us: model.period_us(),
            periods: orbit.period_breakdown(model.free_amplitude_nm()),
            phase_deg,
            residual: orbit.residual,
            second_drive,
            spectral_radius: continuation::spectral_radius(&orbit.multipliers),
            stable: orbit.stable,
            start: None,
            state: &orbit.state,
            virial_ev: observables.virial_ev,
            z_nm: orbit.z_nm,
        }
    }

    /// This object with `start`: the name of the start that found the orbit (`approach`,
    /// `transient`, `near`, ...).
    pub fn with_start(self, start: &'a str) -> Self {
        Self {
            start: Some(start),
            ..self
        }
    }

    /// This object with `coexisting_orbit` (the other start's orbit, or `null`) and `inputs`:
    /// the whole `simulate --json` object.
    pub fn with_coexisting_and_inputs(
        self,
        coexisting: Option<OrbitJson<'a>>,
        inputs: InputsJson<'a>,
    ) -> Self {
        Self {
            coexisting_orbit: Some(coexisting.map(Box::new)),
            inputs: Some(inputs),
            ..self
        }
    }
}
