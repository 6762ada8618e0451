//! Sine and cosine of the phases that Eq. 1 evaluates at every Runge-Kutta stage and every
//! exact free-flight step (the drive phase `w t`, the damped oscillators' `w_d t`): the
//! argument reduced by the nearest multiple `k` of `pi/2` in two parts (Cody and Waite: the
//! first part has 33 significant bits, so `k` times it is exact for `|k| < 2^20`), then
//! polynomial kernels on `[-pi/4, pi/4]` (the Taylor series with minimax-corrected
//! coefficients, as published with fdlibm's `__kernel_sin` / `__kernel_cos`), and the quadrant
//! from `k mod 4`.
//!
//! Within 2 ulps of the correctly rounded value for `|x| < 2^19 pi` (tested against libm over
//! 10^6 arguments, including the neighbourhoods of multiples of `pi/2`); beyond that, libm's
//! `sin_cos` is called. The point is speed: one reduction serves both functions and there is
//! no branch for huge arguments.

// The constants are written with the digits they were published with; each rounds to the
// intended double.
#![allow(clippy::excessive_precision)]

/// The first 33 bits of `pi/2`.
const FRAC_PI_2_HIGH: f64 = 1.570_796_326_734_125_614_17e0;
/// `pi/2 - FRAC_PI_2_HIGH`.
const FRAC_PI_2_LOW: f64 = 6.077_100_506_506_192_249_32e-11;
/// Arguments up to this magnitude are reduced here (`|k| < 2^19`).
const REDUCTION_LIMIT: f64 = 823_549.6;
/// `1.5 * 2^52`: adding it to a number of magnitude below `2^51` rounds that number to an
/// integer (ties to even); subtracting it again leaves the integer.
const ROUNDING_SHIFT: f64 = 6_755_399_441_055_744.0;

/// Kernel coefficients of `sin r = r + r^3 (S1 + r^2 S2 + ...)` on `[-pi/4, pi/4]`.
const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;
/// Kernel coefficients of `cos r = 1 - r^2/2 + r^4 (C1 + r^2 C2 + ...)` on `[-pi/4, pi/4]`.
const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// `sin r` for `|r| <= pi/4` (plus the reduction's rounding).
#[inline]
fn kernel_sin(r: f64) -> f64 {
    let z = r * r;
    r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))))
}

/// `cos r` for `|r| <= pi/4` (plus the reduction's rounding).
#[inline]
fn kernel_cos(r: f64) -> f64 {
    let z = r * r;
    let tail = z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    // 1 - z/2 + tail, with the rounding of 1 - z/2 recovered (fdlibm's compensation).
    let half = 0.5 * z;
    let w = 1.0 - half;
    w + (((1.0 - w) - half) + tail)
}

/// `x` reduced by the nearest multiple `k` of `pi/2`: `(r, k mod 4)`, for `|x|` within the
/// reduction limit.
#[inline]
fn reduce(x: f64) -> (f64, i64) {
    // The nearest integer to `x / (pi/2)` (ties to even), by adding and subtracting
    // `1.5 * 2^52`: exact for quotients below 2^51, far above the reduction limit, and an
    // addition where `f64::round` is a library call on the baseline x86-64 target.
    let k = (x * std::f64::consts::FRAC_2_PI + ROUNDING_SHIFT) - ROUNDING_SHIFT;
    let r = (x - k * FRAC_PI_2_HIGH) - k * FRAC_PI_2_LOW;
    (r, (k as i64).rem_euclid(4))
}

/// `(sin x, cos x)`, within 2 ulps (see the module docs).
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.is_nan() || x.abs() > REDUCTION_LIMIT {
        return x.sin_cos();
    }
    let (r, quadrant) = reduce(x);
    let (s, c) = (kernel_sin(r), kernel_cos(r));
    match quadrant {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `cos x`, within 2 ulps (see the module docs): bit for bit the cosine of [`sin_cos`], with
/// only the one kernel the quadrant needs (the drive factor of every field evaluation).
#[inline]
pub fn cos(x: f64) -> f64 {
    if x.is_nan() || x.abs() > REDUCTION_LIMIT {
        return x.sin_cos().1;
    }
    match reduce(x) {
        (r, 0) => kernel_cos(r),
        (r, 1) => -kernel_sin(r),
        (r, 2) => -kernel_cos(r),
        (r, _) => kernel_sin(r),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative distance from the reference in units of the machine epsilon.
    fn ulps(value: f64, reference: f64) -> f64 {
        (value - reference).abs() / (reference.abs() * f64::EPSILON)
    }

    /// Against libm (correctly rounded to within an ulp itself) over a million arguments in
    /// `[-2^19 pi, 2^19 pi]`, spread logarithmically, and around the multiples of `pi/2`
    /// where the result's magnitude is smallest: at most 2 ulps of libm's value, or 2e-16
    /// absolute where the value is below 1e-1 in magnitude (the reduction's absolute
    /// rounding of ~1e-17 dominates there).
    #[test]
    fn agrees_with_libm() {
        let mut worst_ulps = 0.0f64;
        let mut worst_absolute = 0.0f64;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            // `cos` alone is the same value, bit for bit.
            assert_eq!(cos(x).to_bits(), c.to_bits(), "cos({x:e})");
            let (rs, rc) = x.sin_cos();
            for (value, reference) in [(s, rs), (c, rc)] {
                if reference.abs() >= 0.1 {
                    worst_ulps = worst_ulps.max(ulps(value, reference));
                } else {
                    worst_absolute = worst_absolute.max((value - reference).abs());
                }
            }
        };
        for _ in 0..1_000_000 {
            let magnitude = 10f64.powf(-6.0 + 12.2 * uniform());
            let sign = if uniform() < 0.5 { -1.0 } else { 1.0 };
            check(sign * magnitude.min(REDUCTION_LIMIT));
        }
        for k in -2000..=2000 {
            let centre = k as f64 * std::f64::consts::FRAC_PI_2;
            for offset in [-1e-9, -1e-15, 0.0, 1e-15, 1e-9, 0.7, -0.7] {
                check(centre + offset);
            }
        }
        eprintln!("worst {worst_ulps} ulps, worst absolute {worst_absolute:e} near zeros");
        assert!(worst_ulps <= 2.0, "{worst_ulps}");
        assert!(worst_absolute <= 2e-16, "{worst_absolute:e}");
        // Beyond the reduction's range, and at non-finite arguments, libm's values.
        for x in [1e7, -3.3e9, f64::INFINITY, f64::NAN] {
            let (s, c) = sin_cos(x);
            let (rs, rc) = x.sin_cos();
            assert!(s.to_bits() == rs.to_bits() || (s.is_nan() && rs.is_nan()));
            assert!(c.to_bits() == rc.to_bits() || (c.is_nan() && rc.is_nan()));
            assert!(cos(x).to_bits() == c.to_bits() || (c.is_nan() && cos(x).is_nan()));
        }
    }
}
