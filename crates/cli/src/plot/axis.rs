//! Axis ticks: "nice" values (1, 2 or 5 times a power of ten) covering a data range, and their
//! labels with no more decimals than the step needs (in scientific notation below a step of
//! [`SCIENTIFIC_BELOW`], such as the roundoff-sized dissipation of a conservative law);
//! integer-only ticks for counted quantities such as impacts per period.

/// Tick steps below this are labelled in scientific notation (`-2e-13`) rather than with
/// their many decimals.
pub const SCIENTIFIC_BELOW: f64 = 1e-4;

/// The tick values of one axis and the number of decimals their labels need.
#[derive(Debug, Clone, PartialEq)]
pub struct Ticks {
    /// Tick values in data units, increasing, all inside the axis range.
    pub values: Vec<f64>,
    /// Decimals printed in each label.
    pub decimals: usize,
    /// With a step below [`SCIENTIFIC_BELOW`], the common power of ten `p` of the labels (that
    /// of the largest tick): each label is `value / 10^p` with `decimals` decimals, then
    /// `e{p}`.
    pub exponent: Option<i32>,
}

impl Ticks {
    /// The label of tick `value` (never `-0`).
    pub fn label(&self, value: f64) -> String {
        if let Some(p) = self.exponent {
            let mantissa = format!("{:.*}", self.decimals, value / 10f64.powi(p));
            return if mantissa
                .trim_start_matches('-')
                .chars()
                .all(|c| c == '0' || c == '.')
            {
                String::from("0")
            } else {
                format!("{mantissa}e{p}")
            };
        }
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
            exponent: None,
        };
    }
    let mut step = nice_step(span / target.max(1) as f64);
    if integer {
        step = step.max(1.0).round();
    }
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    let values = (first..=last).map(|k| k as f64 * step).collect();
    let step_power = (step.log10() + 1e-9).floor() as i32;
    let exponent = (!integer && step < SCIENTIFIC_BELOW).then(|| {
        let largest = lo.abs().max(hi.abs());
        (largest.log10() + 1e-9).floor() as i32
    });
    let decimals = match exponent {
        _ if integer => 0,
        Some(p) => (p - step_power).max(0) as usize,
        None => (-step_power).max(0) as usize,
    };
    Ticks {
        values,
        decimals,
        exponent,
    }
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

    #[test]
    fn tiny_steps_are_labelled_in_scientific_notation() {
        // A conservative law's dissipation: roundoff between -1.3e-12 and 0 eV.
        let t = ticks(-1.3e-12, 0.05e-12, 6, false);
        assert_eq!(t.exponent, Some(-12));
        let labels: Vec<String> = t.values.iter().map(|&v| t.label(v)).collect();
        assert_eq!(
            labels,
            ["-1.2e-12", "-1.0e-12", "-0.8e-12", "-0.6e-12", "-0.4e-12", "-0.2e-12", "0"]
        );
        // Ordinary steps keep their decimals.
        assert_eq!(ticks(0.27, 1.03, 6, false).exponent, None);
    }
}
