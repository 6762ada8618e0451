//! `afm`: the cantilever model of Melcher, Xu and Raman, "Multiple impact regimes in liquid
//! environment dynamic atomic force microscopy", Appl. Phys. Lett. 93, 093111 (2008).
//!
//! Eq. 1 of the paper generalised to N eigenmodes (MODEL.md section 1, at the repository root),
//!
//! ```text
//! q_i'' / w_i^2 + q_i' / (w_i Q_i) + q_i = (F_i / k_i) cos(w t) + F_ts(d) / k_i,
//! d = Z + sum_i q_i,   u = sum_i chi_i q_i,
//! ```
//!
//! with Hertz contact `F_ts(d) = (4/3) E* sqrt(R) (-d)^{3/2}` for `d < 0`, expressed as a
//! [`hybrid::HybridSystem`] ([`TappingModel`]) whose free flight has an exact flow.
//!
//! Internal units: time in microseconds, lengths in nm, velocities in nm/us, forces in nN,
//! stiffness in N/m (= nN/nm), angular frequencies in rad/us (`w = 2 pi f[kHz] / 1000`).
//! The state is `x = [q_1, q_1', q_2, q_2', ..., q_N, q_N']`; `t = 0` is a zero of the drive
//! phase (`cos(w t) = 1`).
#![warn(missing_docs)]

pub mod contact;
pub mod diagram;
pub mod error;
pub mod fit;
pub mod fixtures;
mod json_path;
pub mod map;
pub mod model;
pub mod orbit;
pub mod scan;
pub mod sweep;
pub mod theory;
pub mod validation;

pub use diagram::bifurcation_diagram::{
    approach_diagram, approach_diagram_until, diagram, diagram_until, smallest_max_step_nm,
    BifurcationDiagram, DiagramPoint, DiagramSettings, DiagramSpecialPoint,
};
pub use diagram::quasi_static::{quasi_static_row, QuasiStaticCell, QuasiStaticRow};
pub use error::AfmError;
pub use fixtures::{
    builtin_cantilever, builtin_case, builtin_sample, cantilever_names, case_names, find_case,
    load_cantilever, load_case, load_sample, sample_names,
};
pub use map::parameter_axis::{CaseFamily, ParameterAxis, PARAMETER_NAMES};
pub use map::regime_map::{
    regime_map, regime_map_until, MapCodim2Point, MapCurve, MapEnd, MapPoint, RegimeMap,
    RegimeMapSettings,
};
pub use model::cantilever::{Cantilever, MAX_MODES};
pub use model::case::{Case, CaseFile};
pub use model::drive::Drive;
pub use model::eigenmode::Eigenmode;
pub use model::film_validity::film_range_warning;
pub use model::free_flight::DrivenOscillator;
pub use model::free_response::FreeResponse;
pub use model::hertz_contact::{effective_modulus_gpa, HertzContact};
pub use model::sample::Sample;
pub use model::separation::Separation;
pub use model::TappingModel;
pub use orbit::observables::{
    observe_orbit_in, observe_period, observe_period_in, orbit_observables, GapMinimum,
    GapMinimumKind, Harmonic, Impact, ModeEnergy, OrbitObservables, PeriodObserver,
    NEAR_IMPACT_FRACTION, NN_NM_IN_EV,
};
pub use orbit::prediction::{hermite_state, tangent_state};
pub use orbit::steady_orbit::{
    state_distance, steady_orbit, steady_orbit_in, OrbitStart, PeriodBreakdown, SteadyOrbit,
    SteadyOrbitSettings, SteadyOrbitWorkspace,
};
pub use orbit::trajectory::{sample_trajectory, TrajectorySample};
pub use sweep::amplitude_ratio::{find_amplitude_ratio, AmplitudeRatioSearch};
pub use sweep::{Sweep, SweepDirection, SweepRecord, SweepSettings};
pub use theory::impact_numbers::MultipleImpactNumbers;
pub use theory::{
    compare_theory, measure_impacts, AssumptionFailure, ImpactImpulse, ImpactMeasurement,
    ImpactPrediction, ImpactTheory, Ringing, TheoryComparison,
};
