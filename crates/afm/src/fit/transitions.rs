//! Regime boundaries in a measured curve (MODEL.md section 13.2): points where the amplitude
//! and the phase versus `Z` change slope (a `kink`, as at a grazing `G_n`) or jump (a fold of
//! the branch, bistability), located with a 1-sigma uncertainty, at a controlled family-wise
//! false-alarm rate.
//!
//! At every gap between consecutive rows a window of `w` rows on each side is fitted by a
//! quadratic in `Z` (the smooth null), and by the quadratic plus a rounded hinge and a free
//! curvature below the onset `c` (the shape of a grazing with Hertz contact: a jump of
//! curvature turning into a change of slope) or plus a step `H(c - Z)`, for `A/A0` and phase
//! together, each weighted by its noise (from second differences); a long window of
//! [`LONG_WINDOW_FACTOR`] `w` rows against a quartic null adds the weak kinks whose slope
//! change builds up over more than the short window. The drop `T` of `chi^2` from the null is
//! `chi^2` with 4 (kink) or 2 (jump) degrees of freedom on a smooth curve with white Gaussian
//! noise, and over `M` tests the Bonferroni bound `M P(T)` bounds the probability that any
//! test on a smooth curve exceeds its `T`. A transition is reported where that bound is below
//! the significance level. A kink's onset is the minimum of its profile likelihood, its
//! uncertainty the larger of the profile's and a parametric bootstrap's.

use nalgebra::DVector;
use rayon::prelude::*;
use serde::Serialize;

use crate::error::AfmError;
use crate::fit::kink_onset::kink_onset;
use crate::fit::measurement::{noise_sigma, MeasuredPoint};
use crate::fit::window_models::{
    design, explained, orthonormal_basis, window_values, Extra, Scale, Signals, KINK_ROUNDING,
};

/// How transitions are searched for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectionSettings {
    /// Family-wise false-alarm probability on a smooth curve (default 0.01). In `(0, 0.5]`.
    pub significance: f64,
    /// Rows on each side of a candidate in its window; 0 picks `clamp(n / 25, 12, 80)`.
    pub half_window: usize,
}

impl Default for DetectionSettings {
    fn default() -> Self {
        Self {
            significance: 0.01,
            half_window: 0,
        }
    }
}

impl DetectionSettings {
    /// Check the fields; `source` names their origin in errors.
    ///
    /// # Errors
    /// [`AfmError::InvalidField`] for a significance outside `(0, 0.5]` or a window below 6.
    pub fn validate(&self, source: &str) -> Result<(), AfmError> {
        if !(self.significance > 0.0 && self.significance <= 0.5) {
            return Err(AfmError::InvalidField {
                file: source.to_string(),
                field: String::from("significance"),
                value: self.significance.to_string(),
                allowed: String::from("(0, 0.5]: the false-alarm probability per curve"),
            });
        }
        if self.half_window != 0 && self.half_window < MIN_HALF_WINDOW {
            return Err(AfmError::InvalidField {
                file: source.to_string(),
                field: String::from("window"),
                value: self.half_window.to_string(),
                allowed: format!("0 (automatic) or at least {MIN_HALF_WINDOW} rows"),
            });
        }
        Ok(())
    }
}

/// The noise of a curve, estimated from second differences.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurveNoise {
    /// Standard deviation of the amplitude, nm.
    pub amplitude_nm: f64,
    /// Standard deviation of the phase, degrees.
    pub phase_deg: f64,
}

/// The kind of a transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TransitionKind {
    /// A change of slope (a grazing).
    Kink,
    /// A discontinuity (a jump between coexisting orbits).
    Jump,
}

/// A detected transition.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Transition {
    /// Its `Z` in data coordinates, nm.
    pub z_nm: f64,
    /// 1-sigma uncertainty of `z_nm`, nm (kink: the larger of the `Delta chi^2 = 1` profile
    /// interval's half width, with one grid step as a floor, and the parametric bootstrap's
    /// spread; jump: the gap between the rows over `sqrt(12)`).
    pub z_uncertainty_nm: f64,
    /// Measured `A/A0` there (the curve's smooth fit at `z_nm`, upper side).
    pub amplitude_ratio: f64,
    /// Measured phase there, degrees.
    pub phase_deg: f64,
    /// Kink or jump.
    pub kind: TransitionKind,
    /// The family-wise false-alarm probability `min(1, M P(T))` of its statistic, `P` the tail
    /// of `chi^2` with 4 (kink) or 2 (jump) degrees of freedom: the chance that a smooth curve
    /// gives one as large anywhere (smaller is more significant).
    pub significance: f64,
    /// The statistic `T` (drop of `chi^2` from the smooth null).
    pub statistic: f64,
    /// Rows on each side of the window that found it (the short scan window, or the long one
    /// for a kink only the long window resolves).
    pub half_window: usize,
}

/// The result of a detection.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Detection {
    /// `A0` used, nm.
    pub a0_nm: f64,
    /// The noise estimates.
    pub noise: CurveNoise,
    /// Rows on each side of the short window (the long one has [`LONG_WINDOW_FACTOR`] times
    /// as many).
    pub half_window: usize,
    /// Tests made (`M`, both windows).
    pub tests: usize,
    /// The threshold on a jump's `T`, `2 ln(M / significance)` (a kink's is higher: its tail
    /// is `exp(-T/2) (1 + T/2)`).
    pub threshold: f64,
    /// The transitions by decreasing `Z`.
    pub transitions: Vec<Transition>,
}

/// The long scan window's half width in short ones: a weak kink whose slope change builds up
/// over more than the short window is found at this scale, against a quartic null (MODEL.md
/// section 13.2).
pub const LONG_WINDOW_FACTOR: usize = 3;

/// The fewest rows on each side of a test window (the automatic window's lower clamp): a
/// kink's onset is profiled over all but 6 rows at each end of its `2 w` rows (MODEL.md
/// section 13.2), which leaves a grid only where `w` is well above 6.
pub const MIN_HALF_WINDOW: usize = 12;

/// The statistic at candidate gap `g` (between rows `g` and `g + 1`) on `scale`: the larger of
/// the kink's (maximised over [`KINK_ROUNDING`]) and the jump's (the one with the smaller tail
/// probability), its kind and the natural logarithm of its single-test tail probability.
fn candidate_score(signals: &Signals, g: usize, scale: Scale) -> (f64, TransitionKind, f64) {
    let w = scale.half_window;
    let c = 0.5 * (signals.z[g] + signals.z[g + 1]);
    let range = g + 1 - w..g + w + 1;
    let z = &signals.z[range.clone()];
    let ys = window_values(signals, range);
    let null = orthonormal_basis(&design(z, c, scale.degree, None));
    let null_explained: f64 = ys.iter().map(|y| explained(&null, y)).sum();
    let drop = |extra: Extra| {
        let basis = orthonormal_basis(&design(z, c, scale.degree, Some(extra)));
        ys.iter().map(|y| explained(&basis, y)).sum::<f64>() - null_explained
    };
    let kink = KINK_ROUNDING
        .iter()
        .map(|&epsilon| drop(Extra::Hinge(epsilon)))
        .fold(f64::NEG_INFINITY, f64::max);
    let jump = drop(Extra::Step);
    // The tails' logarithms: `exp(-T/2)` underflows to 0 beyond T = 1489, where a strong jump
    // and its kink alternative would tie.
    let kink_log_tail = -0.5 * kink + (0.5 * kink).ln_1p();
    let jump_log_tail = -0.5 * jump;
    if jump_log_tail < kink_log_tail {
        (jump, TransitionKind::Jump, jump_log_tail)
    } else {
        (kink, TransitionKind::Kink, kink_log_tail)
    }
}

/// Detect transitions on a curve sorted by decreasing `Z` (an approach) or increasing `Z`.
///
/// The candidates' scores, the transitions' onsets and their profiles and bootstrap replicates
/// are computed in parallel on rayon's current pool; the result does not depend on the number
/// of threads.
///
/// # Errors
/// [`AfmError::InvalidField`] for bad settings or fewer than `4 w` rows.
pub fn detect_transitions(
    points: &[MeasuredPoint],
    a0_nm: f64,
    settings: &DetectionSettings,
) -> Result<Detection, AfmError> {
    settings.validate("detection settings")?;
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| b.z_nm.total_cmp(&a.z_nm));
    let n = sorted.len();
    let w = if settings.half_window == 0 {
        (n / 25).clamp(MIN_HALF_WINDOW, 80)
    } else {
        settings.half_window
    };
    if n / 4 < w {
        return Err(AfmError::InvalidField {
            file: String::from("measurement"),
            field: String::from("rows"),
            value: n.to_string(),
            allowed: format!("at least {} rows (4 windows of {w})", w.saturating_mul(4)),
        });
    }
    let ratios: Vec<f64> = sorted.iter().map(|p| p.amplitude_nm / a0_nm).collect();
    let phases: Vec<f64> = sorted.iter().map(|p| p.phase_deg).collect();
    let sigma_ratio = noise_sigma(&ratios).max(1e-12);
    let sigma_phase = noise_sigma(&phases).max(1e-12);
    let signals = Signals {
        z: sorted.iter().map(|p| p.z_nm).collect(),
        values: [
            ratios.iter().map(|r| r / sigma_ratio).collect(),
            phases.iter().map(|p| p / sigma_phase).collect(),
        ],
    };
    // The scales: the short window with the quadratic null, and, where the curve is long
    // enough, the long one with the quartic null (MODEL.md section 13.2).
    let mut scales = vec![Scale {
        half_window: w,
        degree: 2,
    }];
    let long = LONG_WINDOW_FACTOR * w;
    if n / 4 >= long {
        scales.push(Scale {
            half_window: long,
            degree: 4,
        });
    }
    // Candidate g lies between rows g and g + 1, window rows g + 1 - w ..= g + w.
    let per_scale: Vec<Vec<usize>> = scales
        .iter()
        .map(|scale| (scale.half_window - 1..n - scale.half_window).collect())
        .collect();
    let tests = (KINK_ROUNDING.len() + 1) * per_scale.iter().map(Vec::len).sum::<usize>();
    let threshold = 2.0 * (tests as f64 / settings.significance).ln();
    let mut chosen: Vec<(usize, Scale, f64, TransitionKind, f64)> = Vec::new();
    for (scale, candidates) in scales.iter().zip(&per_scale) {
        // Per candidate: the larger alternative's statistic, its kind and its single-test tail
        // probability (kink: chi^2 with 4 degrees of freedom, the hinge and the free curvature
        // for each signal; jump: chi^2 with 2).
        // In parallel (rayon), collected in candidate order.
        let scores: Vec<(f64, TransitionKind, f64)> = candidates
            .par_iter()
            .map(|&g| candidate_score(&signals, g, *scale))
            .collect();
        // Above the threshold, strongest first; a candidate whose window holds a stronger
        // chosen one of its scale (within 2 w rows) is that one's shadow, and a longer scale
        // adds only what lies 2 of its windows away from every transition already found.
        let mut order: Vec<usize> = (0..candidates.len())
            .filter(|&k| (tests as f64).ln() + scores[k].2 < settings.significance.ln())
            .collect();
        order.sort_by(|&a, &b| scores[a].2.total_cmp(&scores[b].2));
        let before = chosen.len();
        for k in order {
            let g = candidates[k];
            if chosen[..before]
                .iter()
                .all(|c| c.0.abs_diff(g) > 2 * scale.half_window)
                && chosen[before..]
                    .iter()
                    .all(|c| c.0.abs_diff(g) > 2 * scale.half_window)
            {
                chosen.push((g, *scale, scores[k].0, scores[k].1, scores[k].2));
            }
        }
    }
    // Each transition's onset and values in parallel (rayon), collected in order.
    let mut transitions: Vec<Transition> = chosen
        .into_par_iter()
        .map(|(g, scale, score, kind, log_tail)| {
            let w = scale.half_window;
            let range = g + 1 - w..g + w + 1;
            let (z_nm, z_uncertainty_nm) = match kind {
                TransitionKind::Jump => (
                    0.5 * (signals.z[g] + signals.z[g + 1]),
                    (signals.z[g] - signals.z[g + 1]) / 12f64.sqrt(),
                ),
                TransitionKind::Kink => kink_onset(&signals, g, scale),
            };
            let (ratio, phase) = smooth_value(&signals, range, z_nm, [sigma_ratio, sigma_phase]);
            Transition {
                z_nm,
                z_uncertainty_nm,
                amplitude_ratio: ratio,
                phase_deg: phase,
                kind,
                significance: ((tests as f64).ln() + log_tail).exp().min(1.0),
                statistic: score,
                half_window: w,
            }
        })
        .collect();
    transitions.sort_by(|a, b| b.z_nm.total_cmp(&a.z_nm));
    Ok(Detection {
        a0_nm,
        noise: CurveNoise {
            amplitude_nm: sigma_ratio * a0_nm,
            phase_deg: sigma_phase,
        },
        half_window: w,
        tests,
        threshold,
        transitions,
    })
}

/// `A/A0` and phase of the window's null (quadratic) fit on the upper side at `z`.
fn smooth_value(
    signals: &Signals,
    range: std::ops::Range<usize>,
    z: f64,
    sigma: [f64; 2],
) -> (f64, f64) {
    let rows: Vec<usize> = range.filter(|&i| signals.z[i] >= z).collect();
    let zs: Vec<f64> = rows.iter().map(|&i| signals.z[i]).collect();
    if zs.len() < 3 {
        let i = rows.last().copied().unwrap_or(0);
        return (
            signals.values[0][i] * sigma[0],
            signals.values[1][i] * sigma[1],
        );
    }
    let d = design(&zs, z, 2, None);
    let mut out = [0.0; 2];
    for (k, values) in signals.values.iter().enumerate() {
        let y = DVector::from_iterator(rows.len(), rows.iter().map(|&i| values[i]));
        let coefficients = d
            .clone()
            .svd(true, true)
            .solve(&y, 1e-12)
            .unwrap_or_else(|_| DVector::zeros(3));
        out[k] = coefficients[0] * sigma[k];
    }
    (out[0], out[1])
}
