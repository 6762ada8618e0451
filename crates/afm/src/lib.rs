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

pub mod amplitude_ratio;
pub mod bifurcation_diagram;
pub mod cantilever;
pub mod case;
pub mod contact;
mod contact_series;
pub mod drive;
pub mod eigenmode;
pub mod error;
pub mod film_validity;
pub mod fixtures;
pub mod free_flight;
pub mod free_flight_fourier;
pub mod free_response;
pub mod gauss_legendre;
pub mod hertz;
pub mod impact_numbers;
mod json_path;
pub mod lockin;
mod modal_constants;
pub mod model;
pub mod observables;
pub mod orbit_prediction;
pub mod parameter_axis;
pub mod phase;
pub mod quasi_static;
pub mod regime_map;
pub mod sample;
pub mod separation;
pub mod steady_orbit;
pub mod sweep;
pub mod theory;
pub mod trajectory;
pub mod trigonometric;
pub mod validation;

pub use amplitude_ratio::{find_amplitude_ratio, AmplitudeRatioSearch};
pub use bifurcation_diagram::{
    approach_diagram, diagram, BifurcationDiagram, DiagramPoint, DiagramSettings,
    DiagramSpecialPoint,
};
pub use cantilever::Cantilever;
pub use case::{Case, CaseFile};
pub use drive::Drive;
pub use eigenmode::Eigenmode;
pub use error::AfmError;
pub use film_validity::film_range_warning;
pub use fixtures::{
    builtin_cantilever, builtin_case, builtin_sample, cantilever_names, case_names, find_case,
    load_cantilever, load_case, load_sample, sample_names,
};
pub use free_flight::DrivenOscillator;
pub use free_response::FreeResponse;
pub use hertz::{effective_modulus_gpa, HertzContact};
pub use impact_numbers::MultipleImpactNumbers;
pub use model::TappingModel;
pub use observables::{
    observe_orbit_in, observe_period, observe_period_in, orbit_observables, GapMinimum,
    GapMinimumKind, Harmonic, Impact, OrbitObservables, PeriodObserver, NEAR_IMPACT_FRACTION,
};
pub use orbit_prediction::{hermite_state, tangent_state};
pub use parameter_axis::{CaseFamily, ParameterAxis, PARAMETER_NAMES};
pub use quasi_static::{quasi_static_row, QuasiStaticCell, QuasiStaticRow};
pub use regime_map::{
    regime_map, MapCodim2Point, MapCurve, MapEnd, MapPoint, RegimeMap, RegimeMapSettings,
};
pub use sample::Sample;
pub use separation::Separation;
pub use steady_orbit::{
    state_distance, steady_orbit, steady_orbit_in, OrbitStart, PeriodBreakdown, SteadyOrbit,
    SteadyOrbitSettings, SteadyOrbitWorkspace,
};
pub use sweep::{Sweep, SweepDirection, SweepRecord, SweepSettings};
pub use theory::{
    compare_theory, measure_impacts, AssumptionFailure, ImpactImpulse, ImpactMeasurement,
    ImpactPrediction, ImpactTheory, Ringing, TheoryComparison,
};
pub use trajectory::{sample_trajectory, TrajectorySample};
