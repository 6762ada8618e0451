//! Floquet multipliers and stability of a periodic orbit.
//!
//! The multipliers are the eigenvalues of the monodromy matrix `M = dP/dx` at a fixed point of
//! the period map; the orbit is asymptotically stable when every multiplier lies strictly
//! inside the unit circle (Floquet theory; for hybrid systems the monodromy includes the
//! saltation matrices of the events; the hybrid crate's documentation).

use nalgebra::{Complex, DMatrix};

/// The Floquet multipliers: the eigenvalues of `monodromy`, sorted by decreasing modulus
/// (complex pairs adjacent, positive imaginary part first). Dimensionless.
///
/// Uses nalgebra's real Schur decomposition; returns an empty vector for a non-square or
/// empty matrix, and NaN multipliers if the decomposition does not converge.
pub fn floquet_multipliers(monodromy: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let n = monodromy.nrows();
    if n == 0 || monodromy.ncols() != n {
        return Vec::new();
    }
    let mut multipliers: Vec<Complex<f64>> = match monodromy.clone().try_schur(f64::EPSILON, 10_000)
    {
        Some(schur) => schur.complex_eigenvalues().iter().copied().collect(),
        None => vec![Complex::new(f64::NAN, f64::NAN); n],
    };
    multipliers.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    multipliers
}

/// The largest modulus of the multipliers (the spectral radius of the monodromy); 0 for an
/// empty list, NaN if a multiplier is NaN.
pub fn spectral_radius(multipliers: &[Complex<f64>]) -> f64 {
    multipliers.iter().fold(0.0, |r: f64, m| {
        let a = m.norm();
        if a.is_nan() || r.is_nan() {
            f64::NAN
        } else {
            r.max(a)
        }
    })
}

/// Whether the orbit is asymptotically stable: every multiplier strictly inside the unit
/// circle (`spectral_radius < 1`). False if any multiplier is NaN.
pub fn is_stable(multipliers: &[Complex<f64>]) -> bool {
    spectral_radius(multipliers) < 1.0
}
