//! The JSON object of one case's bifurcation diagram (`continue --json`, docs/output-schema.md)
//! as a derived `Serialize` of borrowed fields: `continue --json` writes it without building a
//! `serde_json::Value` tree. The fields of every object are declared in alphabetical order of
//! their keys, so that the bytes are those of the same object as a `serde_json::Value` (whose
//! objects are sorted maps); the entries of the points' lists (gap minima, harmonics) are
//! written in key order by [`crate::observable_records_json`].

use afm::{
    BifurcationDiagram, Case, DiagramPoint, DiagramSpecialPoint, GapMinimum, Harmonic,
    SteadyOrbitSettings, TappingModel,
};
use serde::{Serialize, Serializer};
use serde_json::Value;

use crate::inputs::InputsJson;
use crate::observable_records_json::{gap_minima_in_key_order, harmonics_in_key_order};

/// One case's `continue --json` object (units in the key names; docs/output-schema.md): the
/// approach branch's points and special points and how it ended, the case's `A0` and `Z_G1`,
/// the command's inputs, and with a retract the retract branch and the bistable ranges.
#[derive(Debug, Serialize)]
pub struct DiagramJson<'a> {
    /// With a retract: the merged `[Z_low, Z_high]` ranges (nm) of two stable orbits
    /// (`Some(None)`: `null`); absent without a retract (`None`).
    #[serde(skip_serializing_if = "Option::is_none")]
    bistable_ranges_nm: Option<Option<&'a [[f64; 2]]>>,
    /// The case's name.
    case: &'a str,
    /// Whether the approach reached its requested end.
    completed: bool,
    /// The error that ended the approach early, if any.
    error: Option<&'a str>,
    /// The separation of first contact `Z_G1`, nm.
    first_contact_z_nm: f64,
    /// The free amplitude `A0`, nm.
    free_amplitude_nm: f64,
    /// The command's inputs.
    inputs: InputsJson<'a>,
    /// The approach's branch points.
    #[serde(serialize_with = "points_in_key_order")]
    points: &'a [DiagramPoint],
    /// The retract branch (absent without a retract).
    #[serde(skip_serializing_if = "Option::is_none")]
    retract: Option<BranchJson<'a>>,
    /// The approach's special points.
    #[serde(serialize_with = "special_points_in_key_order")]
    special_points: &'a [DiagramSpecialPoint],
    /// Why the approach ended, in words.
    stop: &'a str,
}

/// The `retract` object of [`DiagramJson`]: one branch's points, special points and how it
/// ended.
#[derive(Debug, Serialize)]
struct BranchJson<'a> {
    /// Whether the branch reached its requested end.
    completed: bool,
    /// The error that ended the branch early, if any.
    error: Option<&'a str>,
    /// The branch points.
    #[serde(serialize_with = "points_in_key_order")]
    points: &'a [DiagramPoint],
    /// The special points.
    #[serde(serialize_with = "special_points_in_key_order")]
    special_points: &'a [DiagramSpecialPoint],
    /// Why the branch ended, in words.
    stop: &'a str,
}

impl<'a> BranchJson<'a> {
    /// The object of `diagram`.
    fn new(diagram: &'a BifurcationDiagram) -> Self {
        Self {
            completed: diagram.completed,
            error: diagram.error.as_deref(),
            points: &diagram.points,
            special_points: &diagram.special_points,
            stop: &diagram.stop,
        }
    }
}

/// An entry of a branch's `points` (afm's [`DiagramPoint`], its fields in key order).
#[derive(Debug, Serialize)]
struct DiagramPointJson<'a> {
    amplitude_ratio: f64,
    contact_time_periods: f64,
    dissipated_ev: f64,
    energy_balance_residual: f64,
    floquet_multipliers: &'a [[f64; 2]],
    #[serde(serialize_with = "gap_minima_in_key_order")]
    gap_minima: &'a [GapMinimum],
    #[serde(serialize_with = "harmonics_in_key_order")]
    harmonics: &'a [Harmonic],
    impacts_per_orbit: usize,
    impacts_per_period: f64,
    impulse_nn_us: f64,
    iterations: usize,
    max_indentation_nm: f64,
    mean_force_nn: f64,
    mean_indentation_nm: f64,
    min_gap_nm: Option<f64>,
    multiplicity: usize,
    peak_force_nn: f64,
    phase_deg: f64,
    residual: f64,
    spectral_radius: f64,
    stable: bool,
    state: &'a [f64],
    virial_ev: f64,
    z_nm: f64,
}

impl<'a> From<&'a DiagramPoint> for DiagramPointJson<'a> {
    fn from(point: &'a DiagramPoint) -> Self {
        Self {
            amplitude_ratio: point.amplitude_ratio,
            contact_time_periods: point.contact_time_periods,
            dissipated_ev: point.dissipated_ev,
            energy_balance_residual: point.energy_balance_residual,
            floquet_multipliers: &point.floquet_multipliers,
            gap_minima: &point.gap_minima,
            harmonics: &point.harmonics,
            impacts_per_orbit: point.impacts_per_orbit,
            impacts_per_period: point.impacts_per_period,
            impulse_nn_us: point.impulse_nn_us,
            iterations: point.iterations,
            max_indentation_nm: point.max_indentation_nm,
            mean_force_nn: point.mean_force_nn,
            mean_indentation_nm: point.mean_indentation_nm,
            min_gap_nm: point.min_gap_nm,
            multiplicity: point.multiplicity,
            peak_force_nn: point.peak_force_nn,
            phase_deg: point.phase_deg,
            residual: point.residual,
            spectral_radius: point.spectral_radius,
            stable: point.stable,
            state: &point.state,
            virial_ev: point.virial_ev,
            z_nm: point.z_nm,
        }
    }
}

/// An entry of a branch's `special_points` (afm's [`DiagramSpecialPoint`], its fields in key
/// order).
#[derive(Debug, Serialize)]
struct SpecialPointJson<'a> {
    amplitude_ratio: f64,
    bracket_nm: [f64; 2],
    converged: bool,
    dissipated_ev: f64,
    #[serde(serialize_with = "harmonics_in_key_order")]
    harmonics: &'a [Harmonic],
    impacts_after: usize,
    impacts_before: usize,
    label: &'a str,
    max_indentation_nm: f64,
    mean_indentation_nm: f64,
    phase_deg: f64,
    precision_nm: f64,
    state: &'a [f64],
    virial_ev: f64,
    z_nm: f64,
}

impl<'a> From<&'a DiagramSpecialPoint> for SpecialPointJson<'a> {
    fn from(point: &'a DiagramSpecialPoint) -> Self {
        Self {
            amplitude_ratio: point.amplitude_ratio,
            bracket_nm: point.bracket_nm,
            converged: point.converged,
            dissipated_ev: point.dissipated_ev,
            harmonics: &point.harmonics,
            impacts_after: point.impacts_after,
            impacts_before: point.impacts_before,
            label: &point.label,
            max_indentation_nm: point.max_indentation_nm,
            mean_indentation_nm: point.mean_indentation_nm,
            phase_deg: point.phase_deg,
            precision_nm: point.precision_nm,
            state: &point.state,
            virial_ev: point.virial_ev,
            z_nm: point.z_nm,
        }
    }
}

/// `points` written as the list of their [`DiagramPointJson`].
fn points_in_key_order<S: Serializer>(
    points: &[DiagramPoint],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(points.iter().map(DiagramPointJson::from))
}

/// `points` written as the list of their [`SpecialPointJson`].
fn special_points_in_key_order<S: Serializer>(
    points: &[DiagramSpecialPoint],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(points.iter().map(SpecialPointJson::from))
}

impl<'a> DiagramJson<'a> {
    /// The object of the approach `approach` of `case` (resolved into `model`), with the
    /// retract `retract` and its merged bistable ranges `bistable` (nm) when there is one, and
    /// `inputs` from the command's `options` and the orbits' `settings`.
    pub fn new(
        case: &'a Case,
        model: &TappingModel,
        settings: &SteadyOrbitSettings,
        options: Value,
        approach: &'a BifurcationDiagram,
        retract: Option<(&'a BifurcationDiagram, Option<&'a [[f64; 2]]>)>,
    ) -> Self {
        Self {
            bistable_ranges_nm: retract.map(|(_, bistable)| bistable),
            case: &case.name,
            completed: approach.completed,
            error: approach.error.as_deref(),
            first_contact_z_nm: model.grazing_separation_nm(),
            free_amplitude_nm: model.free_amplitude_nm(),
            inputs: InputsJson::orbit("continue", options, case, model, settings),
            points: &approach.points,
            retract: retract.map(|(diagram, _)| BranchJson::new(diagram)),
            special_points: &approach.special_points,
            stop: &approach.stop,
        }
    }
}
