//! Commensurate frequency ratios of a bimodal drive (MODEL.md section 14): the ratio
//! `f_b / f_a = p / q` in lowest terms that makes the two drives periodic with the common period
//! `q T_a = p T_b`, or the nearest such ratios to suggest when a ratio is not one.

/// The largest denominator `q` of a commensurate ratio `p / q`: the common period is `q` drive
/// periods of the first drive, and a steady orbit over more than 16 of them is out of reach of
/// a diagram.
pub const MAX_DENOMINATOR: u32 = 16;

/// The relative tolerance within which a ratio equals `p / q`: `|r - p/q| <= 1e-9 r` (a
/// frequency typed with ten significant digits).
pub const RATIO_TOLERANCE: f64 = 1e-9;

/// A ratio `p / q` in lowest terms (`p, q >= 1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ratio {
    /// The numerator `p`: the common period holds `p` periods of the second drive.
    pub numerator: u32,
    /// The denominator `q`: the common period holds `q` periods of the first drive.
    pub denominator: u32,
}

impl Ratio {
    /// `p / q` as a number.
    pub fn value(&self) -> f64 {
        f64::from(self.numerator) / f64::from(self.denominator)
    }
}

fn gcd(mut a: u32, mut b: u32) -> u32 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// The ratio `p / q` (lowest terms, `q <= MAX_DENOMINATOR`) equal to `ratio` within
/// [`RATIO_TOLERANCE`], or `None` (also for a ratio that is not finite and positive, or whose
/// numerator would exceed `u32`).
pub fn commensurate_ratio(ratio: f64) -> Option<Ratio> {
    if !(ratio.is_finite() && ratio > 0.0 && ratio * f64::from(MAX_DENOMINATOR) < 1e9) {
        return None;
    }
    (1..=MAX_DENOMINATOR).find_map(|q| {
        let p = (ratio * f64::from(q)).round();
        let exact = p >= 1.0 && (ratio - p / f64::from(q)).abs() <= RATIO_TOLERANCE * ratio;
        // `p < 1e9` by the check above.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let p = p as u32;
        (exact && gcd(p, q) == 1).then_some(Ratio {
            numerator: p,
            denominator: q,
        })
    })
}

/// The `count` ratios `p / q` (lowest terms, `q <= MAX_DENOMINATOR`, `p >= 1`) nearest to
/// `ratio`, nearest first (ties: the smaller denominator first); empty for a ratio that is not
/// finite and positive.
pub fn nearest_ratios(ratio: f64, count: usize) -> Vec<Ratio> {
    if !(ratio.is_finite() && ratio > 0.0 && ratio * f64::from(MAX_DENOMINATOR) < 1e9) {
        return Vec::new();
    }
    let mut candidates: Vec<Ratio> = (1..=MAX_DENOMINATOR)
        .flat_map(|q| {
            let centre = (ratio * f64::from(q)).round();
            [centre - 1.0, centre, centre + 1.0]
                .into_iter()
                .filter(|p| *p >= 1.0)
                .map(move |p| {
                    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
                    let p = p as u32;
                    (p, q)
                })
        })
        .filter(|&(p, q)| gcd(p, q) == 1)
        .map(|(numerator, denominator)| Ratio {
            numerator,
            denominator,
        })
        .collect();
    candidates.sort_by(|a, b| {
        (a.value() - ratio)
            .abs()
            .total_cmp(&(b.value() - ratio).abs())
            .then(a.denominator.cmp(&b.denominator))
    });
    candidates.dedup();
    candidates.truncate(count);
    candidates
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_ratios_are_found_in_lowest_terms() {
        assert_eq!(
            commensurate_ratio(31.0 / 4.0),
            Some(Ratio {
                numerator: 31,
                denominator: 4
            })
        );
        assert_eq!(
            commensurate_ratio(8.0),
            Some(Ratio {
                numerator: 8,
                denominator: 1
            })
        );
        // 6/4 is 3/2.
        assert_eq!(commensurate_ratio(1.5).map(|r| r.denominator), Some(2));
    }

    #[test]
    fn irrational_ratios_are_refused_with_neighbours() {
        // 72 / 9.3 = 7.7419...; sqrt(60) = 7.7459... has no p/q with q <= 16 within 1e-9.
        let ratio = 60f64.sqrt();
        assert_eq!(commensurate_ratio(ratio), None);
        let nearest = nearest_ratios(ratio, 3);
        assert_eq!(nearest.len(), 3);
        // Brute force over every p/q with q <= 16: none nearer than the first suggestion.
        let best = (1..=16u32)
            .flat_map(|q| (1..=200u32).map(move |p| f64::from(p) / f64::from(q)))
            .map(|v| (v - ratio).abs())
            .fold(f64::INFINITY, f64::min);
        assert_eq!((nearest[0].value() - ratio).abs(), best);
        assert!(nearest
            .windows(2)
            .all(|w| (w[0].value() - ratio).abs() <= (w[1].value() - ratio).abs()));
    }
}
