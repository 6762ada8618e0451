//! The linear models of a detection window (MODEL.md section 13.2): the two noise-scaled
//! signals, the smooth null polynomial, the rounded-hinge kink and the step added to it, and
//! their residual sums of squares through orthonormal bases.

use nalgebra::{DMatrix, DVector};

/// The rounding widths tried when a kink is located, as fractions of the window's `Z` span: the
/// kink term is a hinge whose slope change builds up linearly over the width `epsilon` below
/// the onset `c` (a grazing's new impact grows from zero depth; MODEL.md section 13.2).
pub const KINK_ROUNDING: [f64; 7] = [0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3];

/// The two signals of a window, scaled by their noise: `A/A0 / sigma_r` and `phase / sigma_phi`.
pub(crate) struct Signals {
    /// `Z` of the rows, nm.
    pub(crate) z: Vec<f64>,
    /// `A/A0 / sigma_r` and `phase / sigma_phi` at the rows.
    pub(crate) values: [Vec<f64>; 2],
}

/// The term added to the smooth null at `c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Extra {
    /// The rounded hinge of width `epsilon` (a fraction of the window's span): with
    /// `s = (c - Z) / span`, `0` above `c`, `s^2 / (2 epsilon)` for `0 < s < epsilon`, then
    /// `s - epsilon / 2` (a sharp hinge for `epsilon = 0`).
    Hinge(f64),
    /// The step `H(c - Z)`.
    Step,
}

/// The design matrix over the window's `z` centred at `c`: the null polynomial `1, u, ...,
/// u^degree` (u scaled to the window) and, if any, the `extra` term (a hinge also frees the
/// curvature below `c`: `(c - Z)_+^2`).
pub(crate) fn design(z: &[f64], c: f64, degree: usize, extra: Option<Extra>) -> DMatrix<f64> {
    let scale = (z[0] - z[z.len() - 1]).abs().max(1e-300);
    let columns = degree
        + 1
        + match extra {
            None => 0,
            Some(Extra::Step) => 1,
            Some(Extra::Hinge(_)) => 2,
        };
    DMatrix::from_fn(z.len(), columns, |i, j| {
        let u = (z[i] - c) / scale;
        if j <= degree {
            return u.powi(j as i32);
        }
        if j == degree + 2 {
            return u.min(0.0).powi(2);
        }
        match extra {
            Some(Extra::Hinge(epsilon)) => {
                let s = -u;
                if s <= 0.0 {
                    0.0
                } else if s < epsilon {
                    s * s / (2.0 * epsilon)
                } else {
                    s - 0.5 * epsilon
                }
            }
            _ => {
                if u < 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
        }
    })
}

/// The sum of squares of `y` explained by the orthonormal `basis`: `|basis^T y|^2` (the
/// residual of the least-squares fit is `|y|^2` minus it).
pub(crate) fn explained(basis: &DMatrix<f64>, y: &DVector<f64>) -> f64 {
    (basis.transpose() * y).norm_squared()
}

/// The window's rows of both signals, less their mean over the window (every model holds the
/// constant, so residuals are unchanged, and `|y|^2 - |U^T y|^2` loses no digits to a large
/// offset).
pub(crate) fn window_values(signals: &Signals, range: std::ops::Range<usize>) -> [DVector<f64>; 2] {
    [0, 1].map(|k| {
        let y = DVector::from_column_slice(&signals.values[k][range.clone()]);
        let mean = y.mean();
        y.add_scalar(-mean)
    })
}

/// The `chi^2` (both signals) of the null polynomial of `degree` plus the kink term `extra` at
/// `c` over the window's rows.
pub(crate) fn alternative_chi2(
    signals: &Signals,
    range: std::ops::Range<usize>,
    c: f64,
    degree: usize,
    extra: Extra,
) -> f64 {
    let z = &signals.z[range.clone()];
    let basis = orthonormal_basis(&design(z, c, degree, Some(extra)));
    window_values(signals, range)
        .iter()
        .map(|y| (y.norm_squared() - explained(&basis, y)).max(0.0))
        .sum()
}

/// A scan's window: rows on each side of a candidate and the degree of the null polynomial.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Scale {
    /// Rows on each side of a candidate.
    pub(crate) half_window: usize,
    /// Degree of the null polynomial.
    pub(crate) degree: usize,
}

/// An orthonormal basis of the column space of `design` (left singular vectors of the
/// singular values above `1e-10` of the largest).
pub(crate) fn orthonormal_basis(design: &DMatrix<f64>) -> DMatrix<f64> {
    let svd = design.clone().svd(true, false);
    let u = svd.u.expect("left singular vectors requested");
    let largest = svd.singular_values.max();
    let kept: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] > 1e-10 * largest)
        .collect();
    DMatrix::from_fn(u.nrows(), kept.len(), |i, j| u[(i, kept[j])])
}
