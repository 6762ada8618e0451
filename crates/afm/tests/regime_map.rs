//! The regime map against independent one-parameter diagrams: at several values of the varied
//! parameter, `approach_diagram` of the case rebuilt at that value locates the same special
//! points as the map's curves hold there.

use afm::{
    approach_diagram, builtin_case, regime_map, regime_map_until, DiagramSettings, ParameterAxis,
    RegimeMapSettings, TappingModel,
};

/// Biolever on mica over `A0 = 8 .. 12 nm`: at six `at` values and at the case's own
/// `A0 = 10 nm`, every curve's point lies within 1e-9 nm in `Z` of the special point of the
/// same label found by an independent approach diagram at that `A0`. Budget: the diagram
/// locates its points to a bracket of 1e-9 nm (the reported precision, added to the
/// tolerance); the map's points solve the grazing equations to a residual of 1e-10 nm, which
/// moves `Z` by at most that over `|dh/dZ| ~ 1`.
#[test]
fn map_points_match_independent_diagrams() {
    let case = builtin_case("biolever-mica").expect("case");
    let model = TappingModel::from_case(&case).expect("model");
    let at = vec![8.0, 8.7, 9.4, 10.6, 11.3, 12.0];
    let settings = RegimeMapSettings {
        at: at.clone(),
        points_per_range: 10,
        ..RegimeMapSettings::new(&model, 8.0, 12.0)
    };
    let map = regime_map(&case, ParameterAxis::FreeAmplitude, &settings).expect("map");
    let labels: Vec<&str> = map.curves.iter().map(|c| c.label.as_str()).collect();
    assert_eq!(labels, ["G1", "G2", "G3"]);
    let mut values = at.clone();
    values.push(10.0);
    for a0 in values {
        let rebuilt = ParameterAxis::FreeAmplitude
            .apply(&case, a0, "test")
            .expect("in range");
        let model = TappingModel::from_case(&rebuilt).expect("model");
        let diagram =
            approach_diagram(&model, &DiagramSettings::approach(&model)).expect("diagram");
        for curve in &map.curves {
            let on_curve: Vec<_> = curve.points.iter().filter(|p| p.parameter == a0).collect();
            assert_eq!(on_curve.len(), 1, "{} at A0 = {a0}", curve.label);
            let point = on_curve[0];
            assert!(point.at_fixed_parameter);
            let special = diagram
                .special_points
                .iter()
                .find(|s| s.label == curve.label)
                .unwrap_or_else(|| panic!("{} in the diagram at A0 = {a0}", curve.label));
            let error = (point.z_nm - special.z_nm).abs();
            assert!(
                error <= 1e-9 + special.precision_nm,
                "{} at A0 = {a0}: map Z = {} vs diagram {} (precision {:e})",
                curve.label,
                point.z_nm,
                special.z_nm,
                special.precision_nm
            );
            let n: usize = curve.label[1..].parse().expect("G<n>");
            assert_eq!((point.impacts_before, point.impacts_after), (n - 1, n));
            // The contrast observables (MODEL.md section 10) of the same orbit: the map's
            // point and the diagram's are within 2e-9 nm in Z, each solved to a residual of
            // 1e-10 nm, and each harmonic's complex amplitude `A_n exp(i phase_n)` moves by at
            // most about 1 nm per nm of Z there, so 1e-7 nm bounds their difference (the
            // complex amplitude, not the phase alone: at G1 the orbit is free and the phases
            // of its vanishing higher harmonics are noise); mica is conservative (Hertz), so
            // both dissipate 0 to 1e-12 eV; the energy balance closes to 1e-9 on every orbit
            // drumroll reports.
            assert_eq!(point.harmonics.len(), special.harmonics.len());
            assert_eq!(point.harmonics.len(), 4, "the default harmonic count");
            for (ours, theirs) in point.harmonics.iter().zip(&special.harmonics) {
                assert_eq!(ours.n, theirs.n);
                let complex = |h: &afm::Harmonic| {
                    let phase = h.phase_deg.to_radians();
                    (h.amplitude_nm * phase.cos(), h.amplitude_nm * phase.sin())
                };
                let ((x0, y0), (x1, y1)) = (complex(ours), complex(theirs));
                assert!(
                    (x0 - x1).hypot(y0 - y1) <= 1e-7,
                    "{} at A0 = {a0}, harmonic {}: {:?} vs {:?}",
                    curve.label,
                    ours.n,
                    ours,
                    theirs
                );
            }
            assert!(
                (point.harmonics[0].amplitude_nm / a0 - point.amplitude_ratio).abs() <= 1e-9,
                "the first harmonic over A0 = {a0} is A/A0"
            );
            // Hertz is conservative: the dissipation is zero up to the solver's tolerance,
            // 1e-11 of the work scale `F_peak s_max` (tests/contrast.rs), which at these
            // grazings (s_max below 0.5 nm, F_peak below 10 nN: below 32 eV) is 3.2e-10 eV.
            assert!(
                point.max_indentation_nm < 0.5,
                "{}",
                point.max_indentation_nm
            );
            assert!(
                point.dissipated_ev.abs() <= 3.2e-10 && special.dissipated_ev.abs() <= 3.2e-10,
                "{} at A0 = {a0}: {:e} and {:e} eV",
                curve.label,
                point.dissipated_ev,
                special.dissipated_ev
            );
            assert!(
                point.energy_balance_residual <= 1e-9,
                "{} at A0 = {a0}: residual {:e}",
                curve.label,
                point.energy_balance_residual
            );
        }
    }
}

/// The MAClever on mica has a pair of folds near first contact. Over `A0 = 5 .. 25 nm` its fold
/// curve passes a cusp (both folds of the pair are one curve) near `A0 = 8.73 nm`: at four `at`
/// values the curve's points at that `A0` are the two folds an independent approach diagram
/// locates there (same tolerance as above), and just below the cusp's `A0` the diagram has no
/// fold, just above it two (0.3 nm either side: closer above it the pair of folds is narrower than
/// the diagram's step).
#[test]
fn fold_curve_and_cusp_match_independent_diagrams() {
    let case = builtin_case("maclever-mica").expect("case");
    let model = TappingModel::from_case(&case).expect("model");
    let at = vec![12.0, 16.0, 22.0, 25.0];
    let settings = RegimeMapSettings {
        at: at.clone(),
        labels: Some(vec!["fold".into()]),
        points_per_range: 20,
        ..RegimeMapSettings::new(&model, 5.0, 25.0)
    };
    let map = regime_map(&case, ParameterAxis::FreeAmplitude, &settings).expect("map");
    assert_eq!(map.curves.len(), 1, "the two folds are one curve");
    let fold = &map.curves[0];
    let cusps: Vec<_> = map
        .codim2_points
        .iter()
        .filter(|c| c.label == "cusp")
        .collect();
    assert_eq!(cusps.len(), 1, "{:?}", map.codim2_points);
    let cusp = cusps[0].parameter;
    let diagram_at = |a0: f64| {
        let rebuilt = ParameterAxis::FreeAmplitude
            .apply(&case, a0, "test")
            .expect("in range");
        let model = TappingModel::from_case(&rebuilt).expect("model");
        approach_diagram(&model, &DiagramSettings::approach(&model)).expect("diagram")
    };
    for a0 in at.iter().copied().chain([20.0]) {
        let mut on_curve: Vec<f64> = fold
            .points
            .iter()
            .filter(|p| p.parameter == a0)
            .map(|p| p.z_nm)
            .collect();
        on_curve.sort_by(f64::total_cmp);
        let diagram = diagram_at(a0);
        let mut folds: Vec<(f64, f64)> = diagram
            .special_points
            .iter()
            .filter(|s| s.label == "fold")
            .map(|s| (s.z_nm, s.precision_nm))
            .collect();
        folds.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert_eq!(on_curve.len(), 2, "A0 = {a0}: {on_curve:?}");
        assert_eq!(folds.len(), 2, "A0 = {a0}: {folds:?}");
        for (z, (zd, precision)) in on_curve.iter().zip(&folds) {
            assert!(
                (z - zd).abs() <= 1e-9 + precision,
                "A0 = {a0}: map fold Z = {z} vs diagram {zd}"
            );
        }
    }
    let count = |a0: f64| {
        diagram_at(a0)
            .special_points
            .iter()
            .filter(|s| s.label == "fold")
            .count()
    };
    assert_eq!(count(cusp - 0.3), 0, "below the cusp at {cusp}");
    assert_eq!(count(cusp + 0.3), 2, "above the cusp at {cusp}");
}

/// Driven at 20 kHz the Biolever on mica has four period doublings on its approach. Their four
/// curves over `A0 = 9 .. 11 nm` hold, at both ends and at 9.5 and 10.5, the period doublings
/// an independent approach diagram locates there (same tolerance as above).
#[test]
fn period_doubling_curves_match_independent_diagrams() {
    let mut case = builtin_case("biolever-mica").expect("case");
    case.drive_frequency_khz = Some(20.0);
    let model = TappingModel::from_case(&case).expect("model");
    let at = vec![9.5, 10.5];
    let settings = RegimeMapSettings {
        at: at.clone(),
        labels: Some(vec!["period-doubling".into()]),
        points_per_range: 4,
        ..RegimeMapSettings::new(&model, 9.0, 11.0)
    };
    let map = regime_map(&case, ParameterAxis::FreeAmplitude, &settings).expect("map");
    assert_eq!(map.curves.len(), 4);
    for a0 in [9.0, 9.5, 10.5, 11.0] {
        let mut on_curves: Vec<f64> = map
            .curves
            .iter()
            .flat_map(|c| {
                c.points
                    .iter()
                    .filter(|p| p.parameter == a0)
                    .map(|p| p.z_nm)
            })
            .collect();
        on_curves.sort_by(f64::total_cmp);
        let rebuilt = ParameterAxis::FreeAmplitude
            .apply(&case, a0, "test")
            .expect("in range");
        let model = TappingModel::from_case(&rebuilt).expect("model");
        let diagram =
            approach_diagram(&model, &DiagramSettings::approach(&model)).expect("diagram");
        let mut found: Vec<(f64, f64)> = diagram
            .special_points
            .iter()
            .filter(|s| s.label == "period-doubling")
            .map(|s| (s.z_nm, s.precision_nm))
            .collect();
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert_eq!(
            on_curves.len(),
            found.len(),
            "A0 = {a0}: {on_curves:?} vs {found:?}"
        );
        for (z, (zd, precision)) in on_curves.iter().zip(&found) {
            assert!(
                (z - zd).abs() <= 1e-9 + precision,
                "A0 = {a0}: map Z = {z} vs diagram {zd}"
            );
        }
    }
}

/// A stop that answers `true` after some questions ends the map with `Interrupted`, whether
/// it comes during the seed diagram (after 5 questions) or during the curves (after the seed
/// diagram's, counted on an uninterrupted map); a stop that never answers `true` gives the
/// map of `regime_map`.
#[test]
fn a_stop_ends_the_map_with_interrupted() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let case = builtin_case("biolever-mica").unwrap();
    let model = TappingModel::from_case(&case).unwrap();
    let settings = RegimeMapSettings {
        points_per_range: 10,
        ..RegimeMapSettings::new(&model, 8.0, 12.0)
    };
    let asked = AtomicUsize::new(0);
    let counting = || {
        asked.fetch_add(1, Ordering::Relaxed);
        false
    };
    let whole =
        regime_map_until(&case, ParameterAxis::FreeAmplitude, &settings, &counting).expect("map");
    let questions = asked.load(Ordering::Relaxed);
    let seed_questions = whole.seed.points.len();
    assert!(questions > seed_questions + 10, "{questions} questions");
    let plain = regime_map(&case, ParameterAxis::FreeAmplitude, &settings).unwrap();
    assert_eq!(
        serde_json::to_string(&whole).unwrap(),
        serde_json::to_string(&plain).unwrap()
    );
    for after in [5, seed_questions + 10] {
        let asked = AtomicUsize::new(0);
        let stop = || asked.fetch_add(1, Ordering::Relaxed) >= after;
        let result = regime_map_until(&case, ParameterAxis::FreeAmplitude, &settings, &stop);
        assert!(
            matches!(result, Err(afm::AfmError::Interrupted)),
            "stopped after {after}: {result:?}"
        );
    }
}
