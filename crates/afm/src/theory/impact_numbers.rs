//! The paper's nondimensional numbers for multiple impacts (below its Eq. 4; MODEL.md
//! section 7), from the first two eigenmodes of a cantilever.

use crate::model::cantilever::Cantilever;

/// `lambda_1 = w_2^2 k_1 / (w_1 w_2d k_2 Q_1)` (initial amplitude of the momentary excitation of
/// mode 2), `lambda_2 = w_2d / w_1` (how many times `q_2` rings while the tip is near the
/// sample), `lambda_3 = Q_2 w_1 / w_2` (decay of that ringing over a period), with
/// `w_2d = w_2 sqrt(1 - 1/(4 Q_2^2))`. All dimensionless.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultipleImpactNumbers {
    /// `lambda_1 = w_2^2 k_1 / (w_1 w_2d k_2 Q_1)`.
    pub lambda_1: f64,
    /// `lambda_2 = w_2d / w_1`.
    pub lambda_2: f64,
    /// `lambda_3 = Q_2 w_1 / w_2`.
    pub lambda_3: f64,
}

impl MultipleImpactNumbers {
    /// The numbers of `cantilever`; `None` with fewer than two modes or an over-damped second
    /// mode (`Q_2 <= 0.5`, no damped frequency `w_2d`).
    pub fn of(cantilever: &Cantilever) -> Option<Self> {
        let [first, second] = match cantilever.modes.as_slice() {
            [first, second, ..] => [first, second],
            _ => return None,
        };
        if second.quality_factor <= 0.5 {
            return None;
        }
        let w1 = first.angular_frequency();
        let w2 = second.angular_frequency();
        let q2 = second.quality_factor;
        let w2d = w2 * (1.0 - 1.0 / (4.0 * q2 * q2)).sqrt();
        Some(Self {
            lambda_1: w2 * w2 * first.stiffness_n_per_m
                / (w1 * w2d * second.stiffness_n_per_m * first.quality_factor),
            lambda_2: w2d / w1,
            lambda_3: q2 * w1 / w2,
        })
    }
}
