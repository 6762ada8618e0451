//! A located grazing's stated precision covers the error its own orbit carries (MODEL.md
//! section 8): Newton's method accepts an orbit whose residual `r = P(x) - x` is below its
//! tolerance (1e-10), and the orbit is then `(I - M)^{-1} r` from the fixed point, which a
//! lightly damped cantilever (multipliers near 1, `Q_1` = 637 in air) amplifies to about
//! 1e-8 nm. The `G1` of a force-free orbit has an exact reference: the separation of first
//! contact of the closed-form free orbit, `TappingModel::grazing_separation_nm`; elsewhere the
//! same grazing located from both sides (approach and retract) is.

mod approach_retract;

use afm::{BifurcationDiagram, DiagramSpecialPoint};
use approach_retract::{approach_and_retract, model};

/// The `G1` of a diagram.
fn g1(diagram: &BifurcationDiagram) -> Option<&DiagramSpecialPoint> {
    diagram.special_points.iter().find(|p| p.label == "G1")
}

/// The capillary meniscus in air (`rectangular-air-mica-humid --max-step 0.02`, where the free
/// orbit's `G1` lands 8.0e-9 nm below the exact 20 nm, its free flight exact): the approach's
/// `G1` bracket holds the exact separation of first contact (to its rounding, 1e-12 nm).
/// A bracket of the location alone (2.6e-10 nm wide) misses it; measured 1.6e-8 nm (not
/// converged).
#[test]
fn capillary_g1_bracket_holds_the_free_orbits_first_contact() {
    let model = model("rectangular-air-mica-humid", None);
    let (approach, _) = approach_and_retract(&model, Some(0.02));
    let exact = model.grazing_separation_nm();
    let point = g1(&approach).expect("G1");
    println!(
        "G1 {} bracket {:?} precision {:e} converged {}, exact {exact}",
        point.z_nm, point.bracket_nm, point.precision_nm, point.converged
    );
    assert!(
        point.bracket_nm[0] - 1e-12 <= exact && exact <= point.bracket_nm[1] + 1e-12,
        "exact {exact} outside {:?}",
        point.bracket_nm
    );
    assert_eq!(point.converged, point.precision_nm <= 1e-9, "{point:?}");
}

/// The Hertz sphere in air (`silicon-air-polymer`, built-in settings), whose approach and
/// retract locate the same `G1` of the same branch 4.1e-9 nm apart: their brackets overlap.
/// Brackets of the locations alone (1.4e-13 and 1.6e-10 nm wide) do not; measured 8.8e-10 and
/// 8.5e-9 nm (the retract's not converged).
#[test]
fn hertz_in_air_g1_brackets_of_approach_and_retract_overlap() {
    let (approach, retract) = approach_and_retract(&model("silicon-air-polymer", None), None);
    let (a, r) = (g1(&approach).expect("G1"), g1(&retract).expect("G1"));
    println!(
        "approach G1 {} {:?} {:e}, retract G1 {} {:?} {:e}",
        a.z_nm, a.bracket_nm, a.precision_nm, r.z_nm, r.bracket_nm, r.precision_nm
    );
    assert!(
        a.bracket_nm[0] <= r.bracket_nm[1] && r.bracket_nm[0] <= a.bracket_nm[1],
        "{:?} and {:?} apart",
        a.bracket_nm,
        r.bracket_nm
    );
    for point in [a, r] {
        assert_eq!(point.converged, point.precision_nm <= 1e-9, "{point:?}");
    }
}
