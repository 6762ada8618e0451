//! Impact-regime maps: the grazing `G_n`, fold and period-doubling points of the approach
//! diagram continued in a second parameter (a [`ParameterAxis`]) over a range, as curves in
//! the `(p, Z)` plane with `A/A0` and the phase along them (MODEL.md section 5; the
//! continuation itself is [`continuation::continue_curve`]).
//!
//! ```
//! use afm::{builtin_case, regime_map, ParameterAxis, RegimeMapSettings, TappingModel};
//!
//! // The G2 boundary (onset of two impacts per period) of the Biolever on mica over A0.
//! let case = builtin_case("biolever-mica")?;
//! let model = TappingModel::from_case(&case)?;
//! let settings = RegimeMapSettings {
//!     labels: Some(vec!["G2".into()]),
//!     at: vec![9.5, 10.5],
//!     points_per_range: 10,
//!     ..RegimeMapSettings::new(&model, 9.0, 11.0)
//! };
//! let map = regime_map(&case, ParameterAxis::FreeAmplitude, &settings)?;
//! let g2 = &map.curves[0];
//! assert_eq!(g2.label, "G2");
//! for point in g2.points.iter().filter(|p| p.at_fixed_parameter) {
//!     println!("A0 = {:.3} nm: G2 at Z = {:.9} nm, A/A0 = {:.6}", point.parameter,
//!         point.z_nm, point.amplitude_ratio);
//! }
//! // The boundary spans the range: both ends are range ends, every point is a grazing of the
//! // second minimum (one impact above it, two below).
//! assert!(g2.ends.iter().all(|e| e.reason == "range-end"));
//! assert!(g2.points.iter().all(|p| (p.impacts_before, p.impacts_after) == (1, 2)));
//! # Ok::<(), afm::AfmError>(())
//! ```

use continuation::{
    continue_curve_until, spectral_radius, CodimOneKind, Curve, CurveEnd, CurveSettings,
    CurveStart, CurveStop, NewtonSettings, TwoParameterProblem,
};
use hybrid::{flow_map, Sensitivity};
use rayon::prelude::*;
use serde::Serialize;

use crate::diagram::bifurcation_diagram::{
    approach_diagram_until, BifurcationDiagram, DiagramSettings,
};
use crate::error::AfmError;
use crate::map::parameter_axis::{CaseFamily, ParameterAxis};
use crate::map::seed_order::continue_in_seed_order;
use crate::model::case::Case;
use crate::model::TappingModel;
use crate::orbit::observables::{orbit_observables, Harmonic, OrbitObservables};
use crate::orbit::steady_orbit::MAX_SEPARATION_NM;

/// How a regime map is computed; [`RegimeMapSettings::new`] gives the defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct RegimeMapSettings {
    /// The approach diagram at the case's own parameter value whose special points seed the
    /// curves; its floor `z_limit_nm` is also the lower bound of `Z` along every curve.
    pub diagram: DiagramSettings,
    /// One end of the parameter range (the axis's unit); `from < to`, and the case's own value
    /// must lie in `[from, to]`.
    pub from: f64,
    /// The other end of the range.
    pub to: f64,
    /// Parameter values at which every curve spanning them gets a point computed exactly.
    pub at: Vec<f64>,
    /// Curve labels to compute (`G2`, `fold`, ...); `None`: every `G_n`, fold and period
    /// doubling of the seed diagram.
    pub labels: Option<Vec<String>>,
    /// Smallest number of points per curve over the whole range (sets the largest parameter
    /// step, `(to - from) / points_per_range`). `>= 2`. Default 100.
    pub points_per_range: usize,
}

impl RegimeMapSettings {
    /// The defaults for `model` over `[from, to]`: its approach diagram's settings, no extra
    /// values, every label, 100 points over the range.
    pub fn new(model: &TappingModel, from: f64, to: f64) -> Self {
        Self {
            diagram: DiagramSettings::approach(model),
            from,
            to,
            at: Vec::new(),
            labels: None,
            points_per_range: 100,
        }
    }
}

/// One point of a map curve.
#[derive(Debug, Clone, Serialize)]
pub struct MapPoint {
    /// The varied parameter's value (its unit).
    pub parameter: f64,
    /// Separation `Z`, nm.
    pub z_nm: f64,
    /// `A / A0` of the orbit there (`A0` the free amplitude at this parameter value).
    pub amplitude_ratio: f64,
    /// Phase lag of the first harmonic, degrees.
    pub phase_deg: f64,
    /// Impacts per period on the far side of the point along an approach (`Z` above it).
    pub impacts_before: usize,
    /// Impacts per period on the near side (`Z` below it): one more at a grazing.
    pub impacts_after: usize,
    /// Whether the orbit is stable.
    pub stable: bool,
    /// Largest modulus of the Floquet multipliers.
    pub spectral_radius: f64,
    /// Floquet multipliers `[re, im]`, by decreasing modulus.
    pub floquet_multipliers: Vec<[f64; 2]>,
    /// Residual of the curve's defining system at the point.
    pub residual: f64,
    /// Whether the point was computed at a fixed parameter value (a range end, an `at` value
    /// or the case's own value) rather than along the arclength.
    pub at_fixed_parameter: bool,
    /// Energy dissipated in the sample per drive period, `-int F_ts w' dt`, eV (MODEL.md
    /// section 10; 0 for a conservative law).
    pub dissipated_ev: f64,
    /// The virial `(1/T) int F_ts w dt`, eV (MODEL.md section 10).
    pub virial_ev: f64,
    /// The largest indentation of the law's contact geometry over the period, nm (0 without
    /// contact).
    pub max_indentation_nm: f64,
    /// The mean indentation over the time in contact, nm (0 without contact).
    pub mean_indentation_nm: f64,
    /// The largest mode's energy-balance residual over the total damping loss (MODEL.md
    /// section 10).
    pub energy_balance_residual: f64,
    /// Harmonics `n = 1..N` of `u` (`N = settings.diagram.orbit.harmonics`; MODEL.md
    /// section 10).
    pub harmonics: Vec<Harmonic>,
    /// The orbit's state at `t = 0` (nm, nm/us).
    pub state: Vec<f64>,
}

/// One end of a map curve.
#[derive(Debug, Clone, Serialize)]
pub struct MapEnd {
    /// Why the curve stopped there: `range-end`, `separation-limit`, `closed` (the curve is
    /// a closed loop inside the range: both ends say so), `max-points`, `corrector-failed` or
    /// `error`.
    pub reason: String,
    /// The parameter value of the last point.
    pub parameter: f64,
    /// Its separation, nm.
    pub z_nm: f64,
    /// The error, if one stopped the curve.
    pub error: Option<String>,
}

/// A continued curve of the map.
#[derive(Debug, Clone, Serialize)]
pub struct MapCurve {
    /// `G<n>`, `fold` or `period-doubling`, as the seed diagram names its special point.
    pub label: String,
    /// The points in order of the curve, from its first end to its second.
    pub points: Vec<MapPoint>,
    /// The curve's two ends (the first traced with the parameter decreasing from the seed).
    pub ends: Vec<MapEnd>,
}

/// A codimension-two point met along a curve.
#[derive(Debug, Clone, Serialize)]
pub struct MapCodim2Point {
    /// `grazing-fold`, `grazing-period-doubling`, `double-grazing` or `cusp`.
    pub label: String,
    /// The curve it was met on.
    pub curve: String,
    /// Parameter value.
    pub parameter: f64,
    /// Separation, nm.
    pub z_nm: f64,
    /// `A / A0` there.
    pub amplitude_ratio: f64,
    /// Impacts per period on either side along the curve.
    pub impacts: [usize; 2],
    /// Extent of the location bracket in the parameter and `Z`.
    pub precision: f64,
    /// Whether the location converged.
    pub converged: bool,
    /// Phase lag of the first harmonic there, degrees.
    pub phase_deg: f64,
    /// Energy dissipated in the sample per drive period, `-int F_ts w' dt`, eV (MODEL.md
    /// section 10; 0 for a conservative law).
    pub dissipated_ev: f64,
    /// The virial `(1/T) int F_ts w dt`, eV (MODEL.md section 10).
    pub virial_ev: f64,
    /// The largest indentation of the law's contact geometry over the period, nm (0 without
    /// contact).
    pub max_indentation_nm: f64,
    /// The mean indentation over the time in contact, nm (0 without contact).
    pub mean_indentation_nm: f64,
    /// The largest mode's energy-balance residual over the total damping loss (MODEL.md
    /// section 10).
    pub energy_balance_residual: f64,
    /// Harmonics `n = 1..N` of `u` (`N = settings.diagram.orbit.harmonics`; MODEL.md
    /// section 10).
    pub harmonics: Vec<Harmonic>,
    /// The orbit's state at `t = 0` (nm, nm/us).
    pub state: Vec<f64>,
}

/// A computed regime map.
#[derive(Debug, Clone, Serialize)]
pub struct RegimeMap {
    /// The case's own value of the parameter, where the curves start.
    pub seed_parameter: f64,
    /// The seed approach diagram.
    #[serde(skip)]
    pub seed: BifurcationDiagram,
    /// The continued curves.
    pub curves: Vec<MapCurve>,
    /// Codimension-two points met along them.
    pub codim2_points: Vec<MapCodim2Point>,
}

/// The kind of curve a seed label starts, if any.
fn kind_of(label: &str) -> Option<CodimOneKind> {
    if label == "fold" {
        Some(CodimOneKind::Fold)
    } else if label == "period-doubling" {
        Some(CodimOneKind::PeriodDoubling)
    } else if label.len() > 1 && label.starts_with('G') && label[1..].parse::<usize>().is_ok() {
        Some(CodimOneKind::Grazing)
    } else {
        None
    }
}

/// Check the range and the `at` values against the axis (errors name the option).
fn check_range(case: &Case, axis: ParameterAxis, s: &RegimeMapSettings) -> Result<(), AfmError> {
    let allowed = axis.describe_range(case);
    let bad = |field: &str, value: f64, allowed: String| AfmError::InvalidField {
        file: "command line".into(),
        field: field.into(),
        value: value.to_string(),
        allowed,
    };
    for (field, value) in [("--from", s.from), ("--to", s.to)] {
        if !axis.allows(case, value) {
            return Err(bad(field, value, format!("{} in {allowed}", axis.name())));
        }
    }
    if s.from >= s.to {
        return Err(bad("--to", s.to, format!("> --from = {}", s.from)));
    }
    let own = axis.value(case)?;
    if !(s.from..=s.to).contains(&own) {
        return Err(AfmError::InvalidField {
            file: "command line".into(),
            field: "--from/--to".into(),
            value: format!("{} .. {}", s.from, s.to),
            allowed: format!(
                "a range that contains the case's own {} = {own} (the curves start there)",
                axis.name()
            ),
        });
    }
    for &v in &s.at {
        if !(v.is_finite() && (s.from..=s.to).contains(&v)) {
            return Err(bad(
                "--at",
                v,
                format!("[{}, {}] (the range)", s.from, s.to),
            ));
        }
    }
    if s.points_per_range < 2 {
        return Err(bad(
            "points_per_range",
            s.points_per_range as f64,
            ">= 2".into(),
        ));
    }
    Ok(())
}

/// The regime map of `case` along `axis` over `[settings.from, settings.to]`.
///
/// The seed points' curves are continued in parallel on rayon's current pool, and their
/// points' observables computed in parallel; the result does not depend on the number of
/// threads (a seed on an earlier kept curve of its kind is skipped, as in seed order).
///
/// # Errors
/// Invalid settings (naming the option), a failed seed diagram, or a failed evaluation of a
/// point's observables. A curve that cannot start is returned without points, its ends saying
/// why.
pub fn regime_map(
    case: &Case,
    axis: ParameterAxis,
    settings: &RegimeMapSettings,
) -> Result<RegimeMap, AfmError> {
    regime_map_until(case, axis, settings, &|| false)
}

/// As [`regime_map`], asking `stop` (from any thread) after every point of the seed diagram,
/// before every step of every curve and before the curve points' observables whether to give up:
/// when it answers `true` the map ends with [`AfmError::Interrupted`] (a caller's Ctrl-C or
/// cancel button).
///
/// # Errors
/// As [`regime_map`], and [`AfmError::Interrupted`].
pub fn regime_map_until(
    case: &Case,
    axis: ParameterAxis,
    settings: &RegimeMapSettings,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<RegimeMap, AfmError> {
    check_range(case, axis, settings)?;
    settings.diagram.validate()?;
    let q0 = axis.value(case)?;
    let family = CaseFamily {
        case: case.clone(),
        axis,
    };
    let model = family.model_at(q0)?;
    let seed = approach_diagram_until(&model, &settings.diagram, &mut || stop())?;
    let integration = settings.diagram.orbit.integration.clone();
    // The problem's inputs checked once, before any curve, as the serial loop did; each curve
    // builds its own problem from them.
    let _ = TwoParameterProblem::new(family.clone(), q0, 1, integration.clone())?;
    let targets = settings.at.clone();
    let curve_settings = CurveSettings {
        initial_step: 1e-3 * model.free_amplitude_nm(),
        max_step: model.free_amplitude_nm(),
        min_step: 1e-9 * model.free_amplitude_nm(),
        max_second_step: (settings.to - settings.from) / settings.points_per_range as f64 * 0.999,
        second_range: (settings.from, settings.to),
        targets,
        parameter_range: (settings.diagram.z_limit_nm, MAX_SEPARATION_NM),
        corrector: NewtonSettings {
            max_iterations: 8,
            ..settings.diagram.orbit.newton.clone()
        },
        ..CurveSettings::default()
    };
    // The seeds in diagram order; the serial rule skips one whose point lies on an earlier
    // kept curve of its kind (`seed_order`), the curves run in parallel.
    let seeds: Vec<(CodimOneKind, &str, CurveStart)> = seed
        .special_points
        .iter()
        .filter(|special| {
            settings
                .labels
                .as_ref()
                .is_none_or(|labels| labels.contains(&special.label))
        })
        .filter_map(|special| {
            let kind = kind_of(&special.label)?;
            let start = CurveStart {
                state: special.state.clone(),
                section_time: 0.0,
                parameter: special.z_nm,
                second_parameter: q0,
            };
            Some((kind, special.label.as_str(), start))
        })
        .collect();
    let kinds: Vec<CodimOneKind> = seeds.iter().map(|(kind, _, _)| *kind).collect();
    let continued = continue_in_seed_order(
        &kinds,
        |i| {
            let (kind, _, start) = &seeds[i];
            // Each curve has a problem of its own (the members it keeps built are its own).
            let curve = TwoParameterProblem::new(family.clone(), q0, 1, integration.clone())
                .and_then(|problem| {
                    continue_curve_until(&problem, *kind, start, &curve_settings, stop)
                });
            // A curve that cannot start is kept, empty, with the reason at both ends.
            curve.unwrap_or_else(|error| {
                let end = CurveEnd {
                    reason: CurveStop::Error,
                    parameters: (start.parameter, q0),
                    error: Some(error),
                };
                Curve {
                    kind: *kind,
                    points: Vec::new(),
                    start_index: 0,
                    codim2_points: Vec::new(),
                    ends: [end.clone(), end],
                }
            })
        },
        |curve, i| {
            let z = seeds[i].2.parameter;
            curve.points.iter().any(|p| {
                p.second_parameter == q0 && (p.parameter - z).abs() <= 1e-6 * z.abs().max(1.0)
            })
        },
    );
    if stop() {
        return Err(AfmError::Interrupted);
    }
    // The observables of every point, in parallel; the first error in curve order (a curve's
    // points, then its codimension-two points) stops the map, as serially.
    let harmonics = settings.diagram.orbit.harmonics;
    let observed: Vec<_> = continued
        .par_iter()
        .map(|(i, curve)| {
            let (kind, label, _) = &seeds[*i];
            let map = map_curve(&family, *kind, curve, label, &integration, harmonics);
            let codim2: Vec<_> = curve
                .codim2_points
                .par_iter()
                .map(|point| {
                    observe(
                        &family,
                        point.second_parameter,
                        point.parameter,
                        point.state.as_slice(),
                        point.section_time,
                        &integration,
                        harmonics,
                    )
                })
                .collect();
            (map, codim2)
        })
        .collect();
    let mut map_curves = Vec::new();
    let mut codim2_points = Vec::new();
    for ((i, curve), (map, codim2)) in continued.iter().zip(observed) {
        map_curves.push(map?);
        for (point, observed) in curve.codim2_points.iter().zip(codim2) {
            let (state, observables) = observed?;
            codim2_points.push(MapCodim2Point {
                label: point.kind.label().to_string(),
                curve: seeds[*i].1.to_string(),
                parameter: point.second_parameter,
                z_nm: point.parameter,
                amplitude_ratio: observables.amplitude_ratio,
                impacts: [point.impacts.0, point.impacts.1],
                precision: point.precision,
                converged: point.converged,
                phase_deg: observables.phase_deg,
                dissipated_ev: observables.dissipated_ev,
                virial_ev: observables.virial_ev,
                max_indentation_nm: observables.max_indentation_nm,
                mean_indentation_nm: observables.mean_indentation_nm,
                energy_balance_residual: observables.energy_balance_residual,
                harmonics: observables.harmonics,
                state,
            });
        }
    }
    Ok(RegimeMap {
        seed_parameter: q0,
        seed,
        curves: map_curves,
        codim2_points,
    })
}

/// The state at `t = 0` and the observables (harmonics `1..=harmonics` of `u`) of the orbit
/// through `state` at `section_time`.
fn observe(
    family: &CaseFamily,
    q: f64,
    z: f64,
    state: &[f64],
    section_time: f64,
    integration: &hybrid::Settings,
    harmonics: usize,
) -> Result<(Vec<f64>, OrbitObservables), AfmError> {
    let mut model = family.model_at(q)?;
    continuation::Parametrised::set_parameter(&mut model, z);
    let period = model.period_us();
    let shift = (-section_time).rem_euclid(period);
    let at_zero = if shift == 0.0 || (period - shift) <= 1e-12 * period {
        state.to_vec()
    } else {
        flow_map(
            &model,
            section_time,
            state,
            shift,
            Sensitivity::None,
            integration,
        )?
        .state
    };
    let observables = orbit_observables(&model, &at_zero, integration, harmonics)?;
    Ok((at_zero, observables))
}

/// Words for why a curve end stopped.
fn end_words(end: &CurveEnd) -> &'static str {
    match end.reason {
        CurveStop::RangeEnd => "range-end",
        CurveStop::ParameterBound => "separation-limit",
        CurveStop::MaxPoints => "max-points",
        CurveStop::Closed => "closed",
        CurveStop::StepTooSmall => "corrector-failed",
        CurveStop::Error => "error",
        CurveStop::Interrupted => "interrupted",
    }
}

/// The map curve of a continued curve, with the observables of every point (harmonics
/// `1..=harmonics` of `u`), computed in parallel; the first failing point's error.
fn map_curve(
    family: &CaseFamily,
    kind: CodimOneKind,
    curve: &Curve,
    label: &str,
    integration: &hybrid::Settings,
    harmonics: usize,
) -> Result<MapCurve, AfmError> {
    let observed: Vec<_> = curve
        .points
        .par_iter()
        .map(|point| {
            observe(
                family,
                point.second_parameter,
                point.parameter,
                point.state.as_slice(),
                point.section_time,
                integration,
                harmonics,
            )
        })
        .collect();
    let mut points = Vec::with_capacity(curve.points.len());
    for (point, observed) in curve.points.iter().zip(observed) {
        let (state, observables) = observed?;
        let impacts = point.structure.impacts;
        let after = if kind == CodimOneKind::Grazing {
            impacts + 1
        } else {
            impacts
        };
        points.push(MapPoint {
            parameter: point.second_parameter,
            z_nm: point.parameter,
            amplitude_ratio: observables.amplitude_ratio,
            phase_deg: observables.phase_deg,
            impacts_before: impacts,
            impacts_after: after,
            stable: point.stable,
            spectral_radius: spectral_radius(&point.multipliers),
            floquet_multipliers: point.multipliers.iter().map(|m| [m.re, m.im]).collect(),
            residual: point.residual,
            at_fixed_parameter: point.at_fixed_second,
            dissipated_ev: observables.dissipated_ev,
            virial_ev: observables.virial_ev,
            max_indentation_nm: observables.max_indentation_nm,
            mean_indentation_nm: observables.mean_indentation_nm,
            energy_balance_residual: observables.energy_balance_residual,
            harmonics: observables.harmonics,
            state,
        });
    }
    let ends = curve
        .ends
        .iter()
        .map(|end| MapEnd {
            reason: end_words(end).into(),
            parameter: end.parameters.1,
            z_nm: end.parameters.0,
            error: end.error.as_ref().map(|e| e.to_string()),
        })
        .collect();
    Ok(MapCurve {
        label: label.to_string(),
        points,
        ends,
    })
}
