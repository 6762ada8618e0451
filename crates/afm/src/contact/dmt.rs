//! The DMT law (Derjaguin-Muller-Toporov; MODEL.md section 9): van der Waals attraction of a
//! sphere outside contact and Hertz repulsion shifted to the intermolecular distance inside.

use super::ForceSlopes;

/// One joule in nN nm.
pub const JOULE_IN_NN_NM: f64 = 1e18;

/// DMT contact: `F = -H R / (6 d^2)` for `d >= a0`, and
/// `F = (4/3) E* sqrt(R) (a0 - d)^{3/2} - H R / (6 a0^2)` for `d < a0` (nN, nm, GPa; `H` in J
/// converted with [`JOULE_IN_NN_NM`]). Continuous at `d = a0`; its slope jumps there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DmtContact {
    /// The reduced modulus `E*`, GPa.
    pub effective_modulus_gpa: f64,
    /// The tip radius `R`, nm.
    pub tip_radius_nm: f64,
    /// The Hamaker constant `H`, J.
    pub hamaker_constant_j: f64,
    /// The intermolecular distance `a0`, nm: the contact surface is `d = a0`.
    pub intermolecular_distance_nm: f64,
}

impl DmtContact {
    /// `A = H R / 6`, nN nm (the van der Waals force is `-A / d^2`).
    pub fn adhesion_scale(&self) -> f64 {
        self.hamaker_constant_j * JOULE_IN_NN_NM * self.tip_radius_nm / 6.0
    }

    /// The adhesion force in contact, `F_ad = H R / (6 a0^2)`, nN.
    pub fn adhesion_force_nn(&self) -> f64 {
        let a0 = self.intermolecular_distance_nm;
        self.adhesion_scale() / (a0 * a0)
    }

    /// Outside contact: `F = -H R / (6 d^2)`, `dF/dd = H R / (3 d^3)`.
    pub fn outside(&self, gap_nm: f64) -> ForceSlopes {
        let scale = self.adhesion_scale();
        let d = gap_nm;
        ForceSlopes {
            force: -scale / (d * d),
            gap_slope: 2.0 * scale / (d * d * d),
            rate_slope: 0.0,
        }
    }

    /// The Hertz coefficient `c = (4/3) E* sqrt(R)`, nN/nm^{3/2}.
    pub fn hertz_coefficient(&self) -> f64 {
        4.0 / 3.0 * self.effective_modulus_gpa * self.tip_radius_nm.sqrt()
    }

    /// Inside contact: `F = c s^{3/2} - H R/(6 a0^2)` with `s = max(a0 - d, 0)`,
    /// `c = (4/3) E* sqrt(R)`; `dF/dd = -1.5 c s^{1/2}`.
    pub fn inside(&self, gap_nm: f64) -> ForceSlopes {
        let c = self.hertz_coefficient();
        let s = (self.intermolecular_distance_nm - gap_nm).max(0.0);
        let root = s.sqrt();
        ForceSlopes {
            force: c * s * root - self.adhesion_force_nn(),
            gap_slope: -1.5 * c * root,
            rate_slope: 0.0,
        }
    }

    /// The interaction energy at gap `d` (nm), nN nm, zero at infinite gap (`F = -dU/dd`,
    /// MODEL.md section 10): `-A / d` outside contact, and inside
    /// `-A / a0 + (2/5) c s^{5/2} - F_ad s` with `s = a0 - d` (continuous at `d = a0`).
    pub fn potential_nn_nm(&self, gap_nm: f64) -> f64 {
        let a0 = self.intermolecular_distance_nm;
        if gap_nm >= a0 {
            return -self.adhesion_scale() / gap_nm;
        }
        let s = a0 - gap_nm;
        -self.adhesion_scale() / a0 + 0.4 * self.hertz_coefficient() * s * s * s.sqrt()
            - self.adhesion_force_nn() * s
    }
}
