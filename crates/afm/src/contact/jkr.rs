//! The JKR law (Johnson, Kendall, Roberts, Proc. R. Soc. Lond. A 324, 301 (1971); in the form
//! of Maugis, *Contact, Adhesion and Rupture of Elastic Solids*, Springer 2000, ch. 4; MODEL.md
//! section 9 "JKR"): a sphere of radius `R` adhering to an elastic half-space with work of
//! adhesion `W`, parametric in the contact radius `a`.

use std::f64::consts::PI;

use super::ForceSlopes;

/// One mJ/m^2 (= 1e-3 N/m) in nN/nm.
pub const MJ_PER_M2_IN_NN_PER_NM: f64 = 1e-3;

/// JKR contact of a sphere: at contact radius `a` (nm) the indentation and the force are
/// `delta(a) = a^2/R - sqrt(2 pi W a / E*)` and `F(a) = 4 E* a^3 / (3 R) - sqrt(8 pi W E* a^3)`
/// (nm, nN; `E*` in GPa = nN/nm^2, `W` in nN/nm), on the stable branch `a >= a_c`. With
/// `b = sqrt(a)` and `k = sqrt(2 pi W / E*)` the indentation is `b^4/R - k b`, whose minimum
/// over `b` is at `b_c^3 = k R / 4`: the contact breaks there, at the indentation
/// `delta_c = -(3/4) k b_c = -(3/4) (pi^2 W^2 R / E*^2)^{1/3}` (the gap `d_po = -delta_c`,
/// pull-off under fixed grips) with the force `-(5/6) pi W R`. It forms at `d = 0` on approach
/// with the force `-(4/3) pi W R` there (`a^3 = 2 pi W R^2 / E*`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JkrContact {
    /// The reduced modulus `E*`, GPa.
    pub effective_modulus_gpa: f64,
    /// The tip radius `R`, nm.
    pub tip_radius_nm: f64,
    /// The work of adhesion `W`, nN/nm (= N/m; the sample file gives mJ/m^2).
    pub work_of_adhesion_nn_per_nm: f64,
    /// `k = sqrt(2 pi W / E*)`, nm^{1/2}, computed once by [`Self::new`].
    adhesion_root: f64,
    /// `b_c = (k R / 4)^{1/3}`, nm^{1/2}.
    critical_root: f64,
    /// `4 / (k b_c)`, nm^{-1}: the indentation's scale in [`Self::contact_root`]'s `u`.
    indentation_scale: f64,
}

impl JkrContact {
    /// The law of reduced modulus `E*` (GPa), tip radius `R` (nm) and work of adhesion `W`
    /// (nN/nm), with its constants `k`, `b_c` and `4 / (k b_c)` computed once (the force is
    /// evaluated at every stage of every integration step).
    pub fn new(
        effective_modulus_gpa: f64,
        tip_radius_nm: f64,
        work_of_adhesion_nn_per_nm: f64,
    ) -> Self {
        let adhesion_root = (2.0 * PI * work_of_adhesion_nn_per_nm / effective_modulus_gpa).sqrt();
        let critical_root = (adhesion_root * tip_radius_nm / 4.0).cbrt();
        Self {
            effective_modulus_gpa,
            tip_radius_nm,
            work_of_adhesion_nn_per_nm,
            adhesion_root,
            critical_root,
            indentation_scale: 4.0 / (adhesion_root * critical_root),
        }
    }

    /// `k = sqrt(2 pi W / E*)`, nm^{1/2}.
    pub fn adhesion_root(&self) -> f64 {
        self.adhesion_root
    }

    /// `b_c = sqrt(a_c) = (k R / 4)^{1/3}`, nm^{1/2}: the square root of the contact radius at
    /// pull-off.
    fn critical_root(&self) -> f64 {
        self.critical_root
    }

    /// The pull-off gap `d_po = (3/4) k b_c = (3/4) (pi^2 W^2 R / E*^2)^{1/3}`, nm: the
    /// release surface, where the contact breaks on retract.
    pub fn pull_off_gap_nm(&self) -> f64 {
        0.75 * self.adhesion_root() * self.critical_root()
    }

    /// The force at pull-off, `-(5/6) pi W R`, nN (from [`Self::force_at_radius`] at `a_c`).
    pub fn pull_off_force_nn(&self) -> f64 {
        let b = self.critical_root();
        self.force_at_radius(b * b)
    }

    /// `F(a) = 4 E* a^3 / (3 R) - sqrt(8 pi W E* a^3)`, nN, at contact radius `a` (nm).
    pub fn force_at_radius(&self, radius_nm: f64) -> f64 {
        let a = radius_nm;
        let e = self.effective_modulus_gpa;
        4.0 * e * a * a * a / (3.0 * self.tip_radius_nm)
            - (8.0 * PI * self.work_of_adhesion_nn_per_nm * e * a * a * a).sqrt()
    }

    /// `delta(a) = a^2/R - sqrt(2 pi W a / E*)`, nm, at contact radius `a` (nm).
    pub fn indentation_at_radius(&self, radius_nm: f64) -> f64 {
        radius_nm * radius_nm / self.tip_radius_nm - self.adhesion_root() * radius_nm.sqrt()
    }

    /// The contact radius `a` (nm) at indentation `delta` (nm) on the stable branch: `b^2` with
    /// `b = sqrt(a)` from [`Self::contact_root`]. Below `delta_c` (past pull-off) it returns
    /// `a_c`.
    pub fn contact_radius_nm(&self, indentation_nm: f64) -> f64 {
        let b = self.contact_root(indentation_nm);
        b * b
    }

    /// `b = sqrt(a)` (nm^{1/2}) at indentation `delta` (nm): the root `b >= b_c` of `b^4/R - k b
    /// = delta` (MODEL.md section 9, JKR), `b_c (1 + e)` with `e` from
    /// [`Self::pull_off_offset`]. `b_c` past pull-off (`delta <= delta_c`); `(R delta)^{1/4}`
    /// (Hertz) for `W = 0`.
    pub fn contact_root(&self, indentation_nm: f64) -> f64 {
        if self.adhesion_root == 0.0 {
            return (self.tip_radius_nm * indentation_nm.max(0.0)).sqrt().sqrt();
        }
        self.critical_root * (1.0 + self.pull_off_offset(indentation_nm))
    }

    /// The stable root's offset from pull-off, `e = b / b_c - 1 >= 0` (dimensionless), at
    /// indentation `delta` (nm). In `x = b / b_c = 1 + e` and `v = 4 (delta - delta_c) / (k
    /// b_c)` (`delta - delta_c = delta + d_po` is exact next to pull-off) the quartic is `x^4 -
    /// 4 x + 3 = e^2 (e^2 + 4 e + 6) = v`, a single function `e(v)` for every law, whose root is
    /// well conditioned relative to itself (unlike `b`, which rounding moves by `sqrt(eps)` next
    /// to pull-off). Start: for `v < 1e-2` the expansion `e = w - w^2/3 + 7 w^3/36` in `w =
    /// sqrt(v/6)`; above, `x^2 = t + g` with `t = sqrt(v)` and `g = (1 + c s) / (1 + c s + c t /
    /// 2)`, `s = sqrt(t)`, `c = 2 - 4/sqrt(6)`, which has `x^2`'s value and slope at `t = 0` and
    /// its asymptote `t + 2/sqrt(t)` (relative error in `e` below 2.6e-2). Then two Halley steps
    /// (cubic convergence: 1 ulp over `v` in [1e-300, 1e16]). 0 past pull-off (`v <= 0`);
    /// `v^{1/4} - 1` above `v = 1e200`. Requires `W > 0`.
    pub fn pull_off_offset(&self, indentation_nm: f64) -> f64 {
        /// `c = 2 - 4/sqrt(6)`: `g(t) = 1 - (c/2) t + ...` as `x^2 - t = 1 + (2/sqrt(6) - 1) t`.
        const SHAPE: f64 = 0.367_006_838_144_547_7;
        let v = (indentation_nm + self.pull_off_gap_nm()) * self.indentation_scale;
        if v <= 0.0 {
            return 0.0;
        }
        let start = if v < 1e-2 {
            let w = (v / 6.0).sqrt();
            w * (1.0 - w / 3.0 + 7.0 / 36.0 * w * w)
        } else if v < 1e200 {
            let t = v.sqrt();
            let s = t.sqrt();
            let g = (1.0 + SHAPE * s) / (1.0 + SHAPE * s + 0.5 * SHAPE * t);
            (t + g).sqrt() - 1.0
        } else {
            // x^4 = v (1 + (4 x - 3) / v): the correction is below 1e-150 relative.
            return v.sqrt().sqrt() - 1.0;
        };
        let halley = |e: f64| {
            let value = e * e * (e * e + 4.0 * e + 6.0) - v;
            let slope = 4.0 * e * (e * e + 3.0 * e + 3.0);
            let curvature = 12.0 * (e + 1.0) * (e + 1.0);
            e - 2.0 * value * slope / (2.0 * slope * slope - value * curvature)
        };
        halley(halley(start))
    }

    /// `b = sqrt(a)` (nm^{1/2}) at indentation `delta` (nm) with the indentation's slope
    /// `d delta/db = 4 b^3/R - k` (nm^{1/2}), the latter as `k e (e^2 + 3 e + 3)` from the
    /// offset `e` of [`Self::pull_off_offset`] (no cancellation next to pull-off, where it
    /// vanishes; MODEL.md section 9, JKR). `(b_c, 0)` past pull-off; for `W = 0`, `(R
    /// delta)^{1/4}` and `4 b^3/R`.
    pub fn root_and_slope(&self, indentation_nm: f64) -> (f64, f64) {
        if self.adhesion_root == 0.0 {
            let b = self.contact_root(indentation_nm);
            return (b, 4.0 * b * b * b / self.tip_radius_nm);
        }
        let e = self.pull_off_offset(indentation_nm);
        (
            self.critical_root * (1.0 + e),
            self.adhesion_root * e * (e * e + 3.0 * e + 3.0),
        )
    }

    /// The coefficient `K` (nN/nm^{1/2}) of the force's square-root singularity at pull-off,
    /// `F = F_po + K sqrt(d_po - d) + O(d_po - d)`: with `delta - delta_c = (1/2) delta''(a_c)
    /// (a - a_c)^2`, `K = F'(a_c) sqrt(2 / delta''(a_c))`, `F'(a_c) = -2 sqrt(2 pi W E* a_c)`,
    /// `delta''(a) = 2/R + (1/4) k a^{-3/2}`. Negative: the force falls below `F_po` inside.
    pub fn pull_off_root_coefficient(&self) -> f64 {
        let b = self.critical_root();
        let a = b * b;
        let e = self.effective_modulus_gpa;
        let force_rate = -2.0 * (2.0 * PI * self.work_of_adhesion_nn_per_nm * e * a).sqrt();
        let curvature = 2.0 / self.tip_radius_nm + 0.25 * self.adhesion_root() / (a * b);
        force_rate * (2.0 / curvature).sqrt()
    }

    /// The force (nN) and `dF/dd` (nN/nm) at gap `d` (nm) while in contact (`d <= d_po`):
    /// `F(a(-d))` and `dF/dd = -(dF/da) / (d delta/da)` with `dF/da = 4 E* a^2/R - (3/2)
    /// sqrt(8 pi W E* a)` and `d delta/da = 2 a/R - sqrt(pi W / (2 E* a))`. The slope is
    /// unbounded at pull-off (`d delta/da = 0`); there it is evaluated with `d delta/da` floored
    /// at `1e-12 (2 a / R)` (finite, the force continuous).
    pub fn force_slopes(&self, gap_nm: f64) -> ForceSlopes {
        // In b = sqrt(a), with sqrt(8 pi W E*) = 2 E* k and sqrt(pi W / (2 E*)) = k / 2, the
        // relations above need no further square roots.
        let r = self.tip_radius_nm;
        let k = self.adhesion_root;
        let (b, indentation_rate) = if k == 0.0 {
            let b = self.contact_root(-gap_nm);
            (b, 2.0 * b * b / r)
        } else {
            // d delta/da = (4 b^3/R - k) / (2 b) = k (x^3 - 1) / (2 b), x^3 - 1 = e (e^2 + 3 e
            // + 3): no cancellation next to pull-off.
            let offset = self.pull_off_offset(-gap_nm);
            let b = self.critical_root * (1.0 + offset);
            let x3_minus_one = offset * (offset * offset + 3.0 * offset + 3.0);
            (b, k * x3_minus_one / (2.0 * b))
        };
        let (a, b3) = (b * b, b * b * b);
        let e = self.effective_modulus_gpa;
        let adhesion = 2.0 * e * k; // sqrt(8 pi W E*), nN/nm^{3/2}
        let force = 4.0 * e * b3 * b3 / (3.0 * r) - adhesion * b3;
        let force_rate = 4.0 * e * a * a / r - 1.5 * adhesion * b;
        let floor = 1e-12 * 2.0 * a / r;
        let indentation_rate = indentation_rate.max(floor);
        ForceSlopes {
            force,
            gap_slope: -force_rate / indentation_rate,
            rate_slope: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> JkrContact {
        JkrContact::new(1.2, 30.0, 0.02)
    }

    /// The closed forms of Maugis 2000 (ch. 4): pull-off under fixed grips at
    /// `delta_c = -(3/4) (pi^2 W^2 R / E*^2)^{1/3}` with `F = -(5/6) pi W R`, and `F = -(4/3) pi
    /// W R` at zero indentation; to 1e-12 relative.
    #[test]
    fn pull_off_and_zero_indentation_match_the_closed_forms() {
        let jkr = law();
        let (w, r, e) = (0.02, 30.0, 1.2);
        let gap = 0.75 * (PI * PI * w * w * r / (e * e)).cbrt();
        assert!((jkr.pull_off_gap_nm() - gap).abs() < 1e-12 * gap);
        let pull_off = -5.0 / 6.0 * PI * w * r;
        assert!((jkr.pull_off_force_nn() - pull_off).abs() < 1e-12 * pull_off.abs());
        let at_zero = -4.0 / 3.0 * PI * w * r;
        let f = jkr.force_slopes(0.0).force;
        assert!(
            (f - at_zero).abs() < 1e-12 * at_zero.abs(),
            "{f} vs {at_zero}"
        );
    }

    /// The contact radius inverts `delta(a)` (to 1e-12 nm) from pull-off to deep indentation,
    /// and the slope is the derivative of the force (central difference, step 1e-6 nm, to
    /// 1e-6 relative).
    #[test]
    fn radius_inverts_the_indentation_and_the_slope_is_the_derivative() {
        let jkr = law();
        let lowest = -jkr.pull_off_gap_nm();
        for i in 1..200 {
            let delta = lowest + f64::from(i) * 0.05;
            let a = jkr.contact_radius_nm(delta);
            assert!((jkr.indentation_at_radius(a) - delta).abs() < 1e-12 * delta.abs().max(1.0));
            let h = 1e-6;
            let numeric = (jkr.force_slopes(-delta + h).force - jkr.force_slopes(-delta - h).force)
                / (2.0 * h);
            let slope = jkr.force_slopes(-delta).gap_slope;
            if delta > lowest + 0.01 {
                assert!(
                    (numeric - slope).abs() < 1e-6 * slope.abs().max(1.0),
                    "delta {delta}: {slope} vs {numeric}"
                );
            }
        }
    }

    /// As `W -> 0` the force tends to Hertz's `(4/3) E* sqrt(R) delta^{3/2}` (W = 1e-12 nN/nm:
    /// to 1e-3 relative at delta = 1 nm, the correction being of order `(W/(E* delta))^{1/2}`).
    #[test]
    fn vanishing_adhesion_tends_to_hertz() {
        let jkr = JkrContact::new(1.2, 30.0, 1e-12);
        let hertz = 4.0 / 3.0 * 1.2 * 30f64.sqrt();
        let f = jkr.force_slopes(-1.0).force;
        assert!((f - hertz).abs() < 1e-3 * hertz, "{f} vs {hertz}");
    }

    /// The Newton iteration that [`JkrContact::contact_root`] replaced (before issue 33's
    /// start-and-Halley solve): from the upper bound `b_u = (R max(delta, 0))^{1/4} + (k R)^{1/3}`,
    /// tightened by one fixed-point step, decreasing monotonically to the root.
    fn newton_root(jkr: &JkrContact, delta: f64) -> f64 {
        let (r, k, critical) = (jkr.tip_radius_nm, jkr.adhesion_root, jkr.critical_root);
        if delta <= -jkr.pull_off_gap_nm() {
            return critical;
        }
        let loose = (r * delta.max(0.0)).sqrt().sqrt() + (k * r).cbrt();
        let mut b = (r * (delta + k * loose)).sqrt().sqrt().min(loose);
        for _ in 0..200 {
            let b3 = b * b * b;
            let value = b3 * b / r - k * b - delta;
            let slope = 4.0 * b3 / r - k;
            if value <= 0.0 || slope <= 0.0 {
                break;
            }
            let next = (b - value / slope).max(critical);
            if next >= b {
                break;
            }
            let change = b - next;
            b = next;
            if change <= 1e-16 * b {
                break;
            }
        }
        b
    }

    /// The root of the increasing `value` above `lo` (`value(lo) <= 0`) by bisection to adjacent
    /// doubles, its bracket's upper end grown by `grow` from `hi` until `value` is positive.
    fn bisection(
        value: impl Fn(f64) -> f64,
        mut lo: f64,
        mut hi: f64,
        grow: impl Fn(f64) -> f64,
    ) -> f64 {
        while value(hi) < 0.0 {
            hi = grow(hi);
        }
        loop {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                return if value(hi).abs() < value(lo).abs() {
                    hi
                } else {
                    lo
                };
            }
            if value(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
    }

    /// The root of `b^4/R - k b = delta` on `[b_c, b_hi]` by bisection to adjacent doubles (the
    /// function increases there).
    fn bisection_root(jkr: &JkrContact, delta: f64) -> f64 {
        let (r, k) = (jkr.tip_radius_nm, jkr.adhesion_root);
        let value = |b: f64| b * b * b * b / r - k * b - delta;
        bisection(value, jkr.critical_root, jkr.critical_root, |hi| {
            2.0 * hi + 1.0
        })
    }

    /// The root of `e^2 (e^2 + 4 e + 6) = v` (`e >= 0`) by bisection to adjacent doubles (the
    /// left side increases from 0).
    fn bisection_offset(v: f64) -> f64 {
        let value = |e: f64| e * e * (e * e + 4.0 * e + 6.0) - v;
        bisection(value, 0.0, 1.0, |hi| 2.0 * hi)
    }

    /// The offset from pull-off `e = b / b_c - 1` against a bisection of its quartic, to 1e-14
    /// relative over `v = 4 (delta - delta_c) / (k b_c)` from 1e-300 to 1e200 (`e` from 4e-151
    /// to 3e49; 1e-16 to 1e12 in steps of 10^{1/8}, both sides of the switch of starts at
    /// 1e-2), on three laws; `e = 0` at and past pull-off.
    #[test]
    fn offset_from_pull_off_matches_bisection() {
        let laws = [
            JkrContact::new(1.2, 30.0, 0.02),
            JkrContact::new(0.5, 500.0, 1.0),
            JkrContact::new(100.0, 2.0, 1e-3),
        ];
        let mut vs: Vec<f64> = (0..=224)
            .map(|j| 10f64.powf(-16.0 + f64::from(j) / 8.0))
            .collect();
        vs.extend([
            1e-300, 1e-100, 1e-30, 0.99e-4, 1.01e-4, 3.0, 1e50, 1e99, 1.01e100, 1e200,
        ]);
        for jkr in &laws {
            let scale = 4.0 / (jkr.adhesion_root * jkr.critical_root);
            let d_po = jkr.pull_off_gap_nm();
            assert_eq!(jkr.pull_off_offset(-d_po), 0.0);
            assert_eq!(jkr.pull_off_offset(-2.0 * d_po), 0.0);
            for &v in &vs {
                let delta = v / scale - d_po;
                // The v the law sees from this delta (rounded through delta).
                let v = (delta + d_po) * scale;
                if v <= 0.0 {
                    continue;
                }
                let e = jkr.pull_off_offset(delta);
                let reference = bisection_offset(v);
                assert!(
                    (e - reference).abs() <= 1e-14 * reference,
                    "{jkr:?} v {v}: {e} vs {reference}"
                );
            }
        }
    }

    /// [`JkrContact::contact_root`] against the bisection and the old Newton iteration, on four laws
    /// (`W` from 1e-12 to 1 nN/nm, `E*` 0.5 to 100 GPa, `R` 2 to 500 nm) over the whole attached
    /// range: `b = b_c x` with `x - 1` from 1e-15 to 1e4 (from next to pull-off to `a = 1e8
    /// a_c`), `delta` at and one ulp above `delta_c`, `delta = 0` and `delta < delta_c`. Each
    /// root is at least `b_c` and backward stable, its residual within 8 ulps of the largest
    /// term (`b^4/R`, `k b`, `|delta|`), as the references' are. Where the root is well
    /// conditioned (those 8 ulps move it by less than 1e-14 relative: `8 eps (terms) / (d
    /// delta/db) < 1e-14 b`) it agrees with both references to 1e-14 relative (measured: 1.3e-15
    /// at most). Near pull-off `d delta/db -> 0` and no solve in doubles fixes the root better
    /// than the rounding of `delta` allows: there it agrees with both to twice the spread `sqrt(8
    /// eps (terms) R / (6 b_c^2))` of the roots that rounding admits (about `sqrt(eps)` relative
    /// at `delta_c` itself; measured: 9e-9).
    #[test]
    fn contact_root_matches_bisection_and_newton() {
        let laws = [
            JkrContact::new(1.2, 30.0, 0.02),
            JkrContact::new(0.5, 500.0, 1.0),
            JkrContact::new(100.0, 2.0, 1e-3),
            JkrContact::new(1.2, 30.0, 1e-12),
        ];
        let eps = f64::EPSILON;
        let mut conditioned = 0;
        for jkr in &laws {
            let (r, k, critical) = (jkr.tip_radius_nm, jkr.adhesion_root, jkr.critical_root);
            let terms = |b: f64, delta: f64| (b.powi(4) / r).max(k * b).max(delta.abs());
            let mut deltas = vec![
                -jkr.pull_off_gap_nm(),
                (-jkr.pull_off_gap_nm()).next_up(),
                0.0,
                -2.0 * jkr.pull_off_gap_nm(),
            ];
            for j in 0..=15 {
                deltas.push(jkr.indentation_at_radius((critical * (1.0 + 10f64.powi(-j))).powi(2)));
            }
            for j in 0..=80 {
                let x = 1.0 + 10f64.powf(-3.0 + 7.0 * f64::from(j) / 80.0);
                deltas.push(jkr.indentation_at_radius((critical * x).powi(2)));
            }
            for delta in deltas {
                let b = jkr.contact_root(delta);
                assert!(
                    b >= critical,
                    "{jkr:?} delta {delta}: {b} below b_c {critical}"
                );
                if delta <= -jkr.pull_off_gap_nm() {
                    assert_eq!(b, critical);
                    assert_eq!(newton_root(jkr, delta), critical);
                    continue;
                }
                let residual = (b.powi(4) / r - k * b - delta).abs();
                assert!(
                    residual <= 8.0 * eps * terms(b, delta),
                    "{jkr:?} delta {delta}: residual {residual} at {b}"
                );
                let bisected = bisection_root(jkr, delta);
                let newton = newton_root(jkr, delta);
                for reference in [bisected, newton] {
                    let residual = (reference.powi(4) / r - k * reference - delta).abs();
                    assert!(residual <= 8.0 * eps * terms(reference, delta));
                }
                let slope = 4.0 * bisected.powi(3) / r - k;
                let noise = 8.0 * eps * terms(bisected, delta);
                // Everywhere: within what that rounding allows next to pull-off, where
                // `delta - delta_c = (6 b_c^2 / R) (b - b_c)^2 + ...`.
                let pull_off_spread = 2.0 * (noise * r / (6.0 * critical * critical)).sqrt();
                for reference in [bisected, newton] {
                    assert!(
                        (b - reference).abs() <= 1e-14 * reference + pull_off_spread,
                        "{jkr:?} delta {delta}: {b} vs {reference}"
                    );
                }
                if noise < 1e-14 * bisected * slope {
                    conditioned += 1;
                    for reference in [bisected, newton] {
                        assert!(
                            (b - reference).abs() <= 1e-14 * reference,
                            "{jkr:?} delta {delta}: {b} vs {reference}"
                        );
                    }
                }
            }
        }
        // The well-conditioned points are most of the grid (x - 1 above about 0.06: 256).
        assert!(conditioned >= 200, "{conditioned} well-conditioned points");
    }
}
