//! Axis ticks: "nice" values (1, 2 or 5 times a power of ten) covering a data range, and their
//! labels with no more decimals than the step needs; integer-only ticks for counted quantities
//! such as impacts per period.

/// The tick values of one axis and the number of decimals their labels need.
#[derive(Debug, Clone, PartialEq)]
pub struct Ticks {
    /// Tick values in data units, increasing, all inside the axis range.
    pub values: Vec<f64>,
    /// Decimals printed in each label.
    pub decimals: usize,
}

impl Ticks {
    /// The label of tick `value` (never `-0`).
    pub fn label(&self, value: f64) -> String {
        let text = format!("{value:.*}", self.decimals);
        if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
            text[1..].to_string()
        } else {
            text
        }
    }
}

/// The step `1, 2, 5 x 10^k` nearest to `raw` (a raw step of `(hi - lo) / target`).
fn nice_step(raw: f64) -> f64 {
    let magnitude = 10f64.powf(raw.log10().floor());
    let normalised = raw / magnitude;
    let factor = if normalised < 1.5 {
        1.0
    } else if normalised < 3.0 {
        2.0
    } else if normalised < 7.0 {
        5.0
    } else {
        10.0
    };
    factor * magnitude
}

/// About `target` ticks covering `[lo, hi]` at a step of 1, 2 or 5 times a power of ten; with
/// `integer`, the step is a whole number (at least 1), so every tick is an integer.
pub fn ticks(lo: f64, hi: f64, target: usize, integer: bool) -> Ticks {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return Ticks {
            values: vec![lo],
            decimals: 0,
        };
    }
    let mut step = nice_step(span / target.max(1) as f64);
    if integer {
        step = step.max(1.0).round();
    }
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    let values = (first..=last).map(|k| k as f64 * step).collect();
    let decimals = if integer {
        0
    } else {
        (-(step.log10() + 1e-9).floor()).max(0.0) as usize
    };
    Ticks { values, decimals }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_ticks_are_whole_numbers_even_on_a_short_range() {
        // An impacts axis from -0.15 to 3.15 (0..3 padded by 5 %): 0, 1, 2, 3.
        let t = ticks(-0.15, 3.15, 5, true);
        assert_eq!(t.values, vec![0.0, 1.0, 2.0, 3.0]);
        assert_eq!(t.label(2.0), "2");
        // A range of one impact still gets only whole numbers (never 0.5).
        let t = ticks(0.9, 2.1, 6, true);
        assert_eq!(t.values, vec![1.0, 2.0]);
    }

    #[test]
    fn real_ticks_use_nice_steps_and_enough_decimals() {
        let t = ticks(0.27, 1.03, 6, false);
        assert_eq!(t.decimals, 1);
        let expected = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0];
        assert_eq!(t.values.len(), expected.len());
        for (v, e) in t.values.iter().zip(expected) {
            assert!((v - e).abs() < 1e-12);
        }
        assert_eq!(t.label(-0.0), "0.0");
        let t = ticks(-180.0, 180.0, 6, false);
        assert_eq!(
            t.values,
            vec![-150.0, -100.0, -50.0, 0.0, 50.0, 100.0, 150.0]
        );
        assert_eq!(t.decimals, 0);
    }
}
