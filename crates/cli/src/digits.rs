//! How numbers print in readable output: with the digits that carry meaning, never a float's
//! rounding noise (`1.0000000000000002`). JSON and CSV keep full precision.

/// Impacts per drive period of an orbit with `impacts_per_orbit` impacts over its
/// `multiplicity` drive periods: the integer when it divides evenly (`2`), else the exact
/// fraction with three decimals (`1/3 = 0.333`).
pub fn impacts_per_period(impacts_per_orbit: usize, multiplicity: usize) -> String {
    let k = multiplicity.max(1);
    if impacts_per_orbit.is_multiple_of(k) {
        (impacts_per_orbit / k).to_string()
    } else {
        format!(
            "{impacts_per_orbit}/{k} = {:.3}",
            impacts_per_orbit as f64 / k as f64
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_counts_print_as_integers_and_fractions_exactly() {
        assert_eq!(impacts_per_period(3, 1), "3");
        assert_eq!(impacts_per_period(4, 2), "2");
        assert_eq!(impacts_per_period(1, 3), "1/3 = 0.333");
        assert_eq!(impacts_per_period(1, 4), "1/4 = 0.250");
        assert_eq!(impacts_per_period(0, 4), "0");
    }
}
