//! The check that a law in its Hertz limit (JKR with `W = 0`, a standard linear solid with
//! `E_0 = E_inf`, a vanishing meniscus) reproduces the Hertz sphere's approach diagram: the
//! same contact grazing points `G_n`, each at the same separation.

use afm::{approach_diagram, DiagramSettings, TappingModel};

/// The contact grazing points (`G1`, `G2`, ...) of `model`'s approach diagram
/// (`DiagramSettings::approach`): label and separation `Z`, nm.
pub fn grazing_points(model: &TappingModel) -> Vec<(String, f64)> {
    let diagram = approach_diagram(model, &DiagramSettings::approach(model)).expect("diagram");
    diagram
        .special_points
        .iter()
        .filter(|p| p.label.starts_with('G'))
        .map(|p| (p.label.clone(), p.z_nm))
        .collect()
}

/// Assert that `limit`'s approach diagram has the grazing points of `hertz`'s (at least
/// `at_least` of them), label by label, each within `tolerance_nm` in `Z`.
pub fn assert_hertz_grazing(
    limit: &TappingModel,
    hertz: &TappingModel,
    at_least: usize,
    tolerance_nm: f64,
) {
    let (found, expected) = (grazing_points(limit), grazing_points(hertz));
    assert!(expected.len() >= at_least, "Hertz: {expected:?}");
    assert_eq!(
        found.len(),
        expected.len(),
        "{found:?} vs Hertz {expected:?}"
    );
    for ((label, z), (hertz_label, hertz_z)) in found.iter().zip(&expected) {
        assert_eq!(label, hertz_label);
        assert!(
            (z - hertz_z).abs() < tolerance_nm,
            "{label}: {z} nm vs Hertz {hertz_z} nm"
        );
    }
}
