//! A kink's onset and its uncertainty (MODEL.md section 13.2): the profile likelihood of the
//! kink model over the onset, re-centred until the window holds it, and the parametric
//! bootstrap of the onset.

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::SeedableRng;
use rayon::prelude::*;

use crate::fit::synthetic::gaussian;
use crate::fit::window_models::{
    alternative_chi2, design, orthonormal_basis, window_values, Extra, Scale, Signals,
    KINK_ROUNDING,
};

/// The rounding widths over which a kink's onset is profiled, as fractions of its window's `Z`
/// span: denser than [`KINK_ROUNDING`] so that the profile of `chi^2` over the onset is smooth
/// (a rounded hinge starting at `c` and a sharper one a little below it fit a rounded kink
/// about equally well; the profile must show that spread; MODEL.md section 13.2).
pub const KINK_PROFILE_ROUNDING: [f64; 13] = [
    0.0, 0.01, 0.02, 0.035, 0.05, 0.075, 0.1, 0.125, 0.15, 0.2, 0.25, 0.3, 0.4,
];

/// Rows kept on each side of a profiled onset inside its window (the kink model has 5
/// coefficients per signal).
const PROFILE_MARGIN: usize = 6;

/// The kink's onset `Z` and its 1-sigma uncertainty: the alternative's `chi^2`, minimised over
/// the rounding width ([`KINK_PROFILE_ROUNDING`]), profiled over the onset `c` on a 200-step
/// grid across the window (all but [`PROFILE_MARGIN`] rows at each end); if the minimum falls
/// in the outer quarter of that range the window is re-centred on it and the profile repeated
/// (4 profiles at most), so that the scan's candidate, which maximises the statistic rather than
/// locating the onset, never truncates the profile. The onset is the minimum; the uncertainty
/// the largest of the half width of the set where `chi^2 <= min + 1` (profile likelihood), one
/// grid step, and the parametric bootstrap's spread ([`bootstrap_spread`]).
pub(crate) fn kink_onset(signals: &Signals, g: usize, scale: Scale) -> (f64, f64) {
    let (w, degree) = (scale.half_window, scale.degree);
    let n = signals.z.len();
    let mut centre = g;
    let mut result = (signals.z[g], f64::INFINITY);
    let mut window = 0..0;
    for _ in 0..4 {
        let start = (centre + 1).saturating_sub(w).min(n - 2 * w);
        let range = start..start + 2 * w;
        let z = &signals.z;
        let high = z[range.start + PROFILE_MARGIN];
        let low = z[range.end - 1 - PROFILE_MARGIN];
        let steps = 200;
        // The grid's onsets in parallel (rayon), collected in grid order.
        let profile: Vec<(f64, f64)> = (0..=steps)
            .into_par_iter()
            .map(|s| {
                let c = high + (low - high) * s as f64 / steps as f64;
                let chi2 = KINK_PROFILE_ROUNDING
                    .iter()
                    .map(|&epsilon| {
                        alternative_chi2(signals, range.clone(), c, degree, Extra::Hinge(epsilon))
                    })
                    .fold(f64::INFINITY, f64::min);
                (c, chi2)
            })
            .collect();
        let (best_index, minimum) = profile
            .iter()
            .enumerate()
            .map(|(k, p)| (k, p.1))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("non-empty profile");
        let best = profile[best_index].0;
        let inside: Vec<f64> = profile
            .iter()
            .filter(|(_, chi2)| *chi2 <= minimum + 1.0)
            .map(|(c, _)| *c)
            .collect();
        let top = inside.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let bottom = inside.iter().copied().fold(f64::INFINITY, f64::min);
        let grid = (high - low).abs() / steps as f64;
        result = (best, (0.5 * (top - bottom)).max(grid));
        window = range.clone();
        let central = (steps / 4..=3 * steps / 4).contains(&best_index);
        // The row just above the estimate becomes the new centre.
        let next = z.partition_point(|&zi| zi >= best).saturating_sub(1);
        let edge_of_data = (next + 1 < w && start == 0) || (next + w >= n && start == n - 2 * w);
        if central || next == centre || edge_of_data {
            break;
        }
        centre = next.max(w - 1).min(n - w - 1);
    }
    let spread = bootstrap_spread(signals, window, result.0, degree, g as u64);
    (result.0, result.1.max(spread))
}

/// Replicates of the parametric bootstrap of a kink's onset.
pub const BOOTSTRAP_REPLICATES: usize = 60;

/// The parametric bootstrap of a kink's onset (MODEL.md section 13.2): the kink model fitted at
/// the onset `c` (rounding minimising `chi^2`) is taken as the truth, white Gaussian noise of
/// the estimated levels is added [`BOOTSTRAP_REPLICATES`] times (seeded by `seed`, so a
/// detection is reproducible), and each replicate's onset is located by the same profile (on a
/// 100-step grid, [`KINK_ROUNDING`]); the result is the standard deviation of those onsets
/// about `c`, nm. It holds what the `Delta chi^2 = 1` interval misses when the profile is
/// flat or has several minima (a rounded onset trades against a sharper hinge below it).
fn bootstrap_spread(
    signals: &Signals,
    range: std::ops::Range<usize>,
    c: f64,
    degree: usize,
    seed: u64,
) -> f64 {
    let z = &signals.z[range.clone()];
    let len = z.len();
    // The fitted kink model at c.
    let best_epsilon = KINK_PROFILE_ROUNDING
        .iter()
        .copied()
        .min_by(|&a, &b| {
            alternative_chi2(signals, range.clone(), c, degree, Extra::Hinge(a)).total_cmp(
                &alternative_chi2(signals, range.clone(), c, degree, Extra::Hinge(b)),
            )
        })
        .unwrap_or(0.0);
    let fitted_design = design(z, c, degree, Some(Extra::Hinge(best_epsilon)));
    let fitted_svd = fitted_design.clone().svd(true, true);
    let fitted: Vec<DVector<f64>> = window_values(signals, range.clone())
        .into_iter()
        .map(|y| match fitted_svd.solve(&y, 1e-12) {
            Ok(coefficients) => &fitted_design * coefficients,
            Err(_) => y,
        })
        .collect();
    // Orthonormal bases of every (onset, rounding) alternative: the residual of y is
    // |y|^2 - |U^T y|^2.
    let (high, low) = (z[PROFILE_MARGIN], z[len - 1 - PROFILE_MARGIN]);
    let steps = 100;
    let grid: Vec<f64> = (0..=steps)
        .map(|s| high + (low - high) * s as f64 / steps as f64)
        .collect();
    let bases: Vec<Vec<DMatrix<f64>>> = grid
        .par_iter()
        .map(|&onset| {
            KINK_ROUNDING
                .iter()
                .map(|&epsilon| {
                    orthonormal_basis(&design(z, onset, degree, Some(Extra::Hinge(epsilon))))
                })
                .collect()
        })
        .collect();
    // The replicates drawn in order from the one seeded generator, then located in parallel
    // (rayon) and summed in replicate order.
    let mut rng = StdRng::seed_from_u64(seed);
    let replicates: Vec<Vec<DVector<f64>>> = (0..BOOTSTRAP_REPLICATES)
        .map(|_| {
            fitted
                .iter()
                .map(|f| f.map(|v| v + gaussian(&mut rng)))
                .collect()
        })
        .collect();
    let onsets: Vec<f64> = replicates
        .par_iter()
        .map(|replicate| {
            let mut best = (f64::NEG_INFINITY, c);
            for (onset, row) in grid.iter().zip(&bases) {
                // The largest explained sum of squares is the smallest residual.
                let explained = row
                    .iter()
                    .map(|u| {
                        replicate
                            .iter()
                            .map(|y| (u.transpose() * y).norm_squared())
                            .sum::<f64>()
                    })
                    .fold(f64::NEG_INFINITY, f64::max);
                if explained > best.0 {
                    best = (explained, *onset);
                }
            }
            best.1
        })
        .collect();
    let mut sum2 = 0.0;
    for onset in onsets {
        sum2 += (onset - c).powi(2);
    }
    (sum2 / BOOTSTRAP_REPLICATES as f64).sqrt()
}
