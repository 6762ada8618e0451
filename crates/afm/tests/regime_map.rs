//! The regime map against independent one-parameter diagrams: at several values of the varied
//! parameter, `approach_diagram` of the case rebuilt at that value locates the same special
//! points as the map's curves hold there.

use afm::{
    approach_diagram, builtin_case, regime_map, DiagramSettings, ParameterAxis, RegimeMapSettings,
    TappingModel,
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
            .apply(&case, a0)
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
        }
    }
}
