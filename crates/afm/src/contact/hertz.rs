//! Hertz contact on an elastic half-space for three tip shapes (MODEL.md section 9): a sphere
//! of radius `R` (the paper's law), a cone of half-angle `alpha` (Sneddon) and a flat punch of
//! radius `a`.

use std::f64::consts::PI;

use super::ForceSlopes;

/// The tip's shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HertzTip {
    /// A sphere of radius `R` (nm): `F = (4/3) E* sqrt(R) s^{3/2}`.
    Sphere {
        /// The tip radius `R`, nm.
        radius_nm: f64,
    },
    /// A cone of half-angle `alpha` (degrees): `F = (2/pi) E* tan(alpha) s^2`.
    Cone {
        /// The half-angle `alpha`, degrees.
        half_angle_deg: f64,
    },
    /// A flat cylindrical punch of radius `a` (nm): `F = 2 E* a s`.
    FlatPunch {
        /// The punch radius `a`, nm.
        radius_nm: f64,
    },
}

/// Hertz contact of one tip shape with reduced modulus `E*`: the force at indentation
/// `s = max(-d, 0)` (nm), in nN with `E*` in GPa.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzShape {
    /// The reduced modulus `E*`, GPa (MODEL.md section 1).
    pub effective_modulus_gpa: f64,
    /// The tip's shape.
    pub tip: HertzTip,
}

impl HertzShape {
    /// Whether the force has half-integer powers of the indentation (the sphere).
    pub fn has_half_powers(&self) -> bool {
        matches!(self.tip, HertzTip::Sphere { .. })
    }

    /// The force (nN) and its slope `dF/dd` (nN/nm) at gap `d` (nm): zero for `d >= 0`.
    pub fn force_slopes(&self, gap_nm: f64) -> ForceSlopes {
        let indentation = (-gap_nm).max(0.0);
        let e = self.effective_modulus_gpa;
        let (force, slope) = match self.tip {
            HertzTip::Sphere { radius_nm } => {
                // c = (4/3) E* sqrt(R), as `HertzContact::from_modulus` forms it.
                let c = 4.0 / 3.0 * e * radius_nm.sqrt();
                let root = indentation.sqrt();
                (c * indentation * root, -1.5 * c * root)
            }
            HertzTip::Cone { half_angle_deg } => {
                let c = 2.0 / PI * e * half_angle_deg.to_radians().tan();
                (c * indentation * indentation, -2.0 * c * indentation)
            }
            HertzTip::FlatPunch { radius_nm } => {
                let c = 2.0 * e * radius_nm;
                if indentation > 0.0 {
                    (c * indentation, -c)
                } else {
                    (0.0, 0.0)
                }
            }
        };
        ForceSlopes {
            force,
            gap_slope: slope,
            rate_slope: 0.0,
        }
    }

    /// The elastic energy stored at gap `d` (nm), `U = int_d^0 F dd'` in nN nm (zero for
    /// `d >= 0`; `F = -dU/dd`, MODEL.md section 10): `(2/5) c s^{5/2}` for the sphere,
    /// `c s^3 / 3` for the cone, `c s^2 / 2` for the punch, with each shape's `c` of
    /// [`HertzShape::force_slopes`].
    pub fn potential_nn_nm(&self, gap_nm: f64) -> f64 {
        let indentation = (-gap_nm).max(0.0);
        let e = self.effective_modulus_gpa;
        match self.tip {
            HertzTip::Sphere { radius_nm } => {
                let c = 4.0 / 3.0 * e * radius_nm.sqrt();
                0.4 * c * indentation * indentation * indentation.sqrt()
            }
            HertzTip::Cone { half_angle_deg } => {
                let c = 2.0 / PI * e * half_angle_deg.to_radians().tan();
                c * indentation * indentation * indentation / 3.0
            }
            HertzTip::FlatPunch { radius_nm } => {
                let c = 2.0 * e * radius_nm;
                0.5 * c * indentation * indentation
            }
        }
    }
}
