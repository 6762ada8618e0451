//! The paper's nondimensional numbers from the built-in cantilevers (MODEL.md section 7).

mod common;

use afm::MultipleImpactNumbers;

#[test]
fn lambda_1_ratio_of_biolever_to_maclever_is_the_papers_3_4() {
    let bio = MultipleImpactNumbers::of(&afm::builtin_cantilever("biolever").expect("bio"))
        .expect("two modes");
    let mac = MultipleImpactNumbers::of(&afm::builtin_cantilever("maclever").expect("mac"))
        .expect("two modes");
    // The paper states 3.4 (two significant digits): |ratio - 3.4| <= 0.05.
    let ratio = bio.lambda_1 / mac.lambda_1;
    assert!((ratio - 3.4).abs() <= 0.05, "{ratio}");
    // By hand for the Biolever: w_2d/w_1 = (72/9.3) sqrt(1 - 1/16), lambda_3 = 2 * 9.3/72.
    let lambda_2 = 72.0 / 9.3 * (1.0f64 - 1.0 / 16.0).sqrt();
    assert!((bio.lambda_2 - lambda_2).abs() < 1e-13 * lambda_2);
    assert!((bio.lambda_3 - 2.0 * 9.3 / 72.0).abs() < 1e-14);
    // lambda_1 = (72/9.3)^2 (0.036/1.4) / (1.2 lambda_2)... in the paper's form:
    let lambda_1 = (72.0f64 / 9.3).powi(2) * 0.036 / (lambda_2 * 1.4 * 1.2);
    assert!((bio.lambda_1 - lambda_1).abs() < 1e-13 * lambda_1);
    // The paper's condition for q_2 to ring down within a period: Q_2 <= w_2/w_1, i.e.
    // lambda_3 <= 1, holds for both.
    assert!(bio.lambda_3 <= 1.0 && mac.lambda_3 <= 1.0);
    // Not defined for a single mode or an over-damped second mode.
    assert!(MultipleImpactNumbers::of(&common::cantilever(&[(1.0, 1.0, 1.0, 1.0, 1.0)])).is_none());
    assert!(MultipleImpactNumbers::of(&common::cantilever(&[
        (1.0, 1.0, 1.0, 1.0, 1.0),
        (9.0, 8.0, 0.4, 2.0, -0.5)
    ]))
    .is_none());
}
