//! A thin elastic film of thickness `h` bonded to (or lying on) a rigid substrate, indented by
//! a sphere (MODEL.md section 9): Hertz times a bottom-effect correction in
//! `chi = sqrt(R s) / h`.

use super::ForceSlopes;

/// The bottom-effect correction `1 + a_1 chi + a_2 chi^2 + a_3 chi^3 + a_4 chi^4`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FilmCorrection {
    /// Garcia & Garcia, Biophys. J. 114, 2923 (2018), paraboloidal tip:
    /// `1 + 1.133 chi + 1.497 chi^2 + 1.469 chi^3 + 0.755 chi^4`.
    Garcia2018,
    /// Dimitriadis et al., Biophys. J. 82, 2798 (2002), film bonded to the substrate
    /// (incompressible film): `1 + 1.133 chi + 1.283 chi^2 + 0.769 chi^3 + 0.0975 chi^4`.
    Dimitriadis2002Bonded,
    /// Dimitriadis et al. (2002), film free to slide on the substrate (incompressible film):
    /// `1 + 0.884 chi + 0.781 chi^2 + 0.386 chi^3 + 0.0048 chi^4`.
    Dimitriadis2002NonBonded,
}

impl FilmCorrection {
    /// The coefficients `[1, a_1, a_2, a_3, a_4]`.
    pub fn coefficients(self) -> [f64; 5] {
        match self {
            Self::Garcia2018 => [1.0, 1.133, 1.497, 1.469, 0.755],
            Self::Dimitriadis2002Bonded => [1.0, 1.133, 1.283, 0.769, 0.0975],
            Self::Dimitriadis2002NonBonded => [1.0, 0.884, 0.781, 0.386, 0.0048],
        }
    }

    /// The largest `chi` the expansion is used for here: 1 (the series are expansions for
    /// indentations small against the film, `sqrt(R s) <= h`).
    pub const VALID_CHI: f64 = 1.0;
}

impl FilmContact {
    /// The deepest indentation inside the correction's range, `s = h^2 / R` (`chi = 1`), nm.
    pub fn deepest_valid_indentation_nm(&self) -> f64 {
        self.indentation_at_chi(FilmCorrection::VALID_CHI)
    }
}

/// A film of thickness `h` on a rigid substrate: `F = (4/3) E* sqrt(R) s^{3/2} P(chi)`,
/// `chi = sqrt(R s) / h`, `s = max(-d, 0)`, `P` the [`FilmCorrection`]; written as
/// `F = c sum_k b_k s^{(3+k)/2}` with `b_k = a_k (sqrt(R)/h)^k`. As `h -> infinity`, Hertz.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmContact {
    /// The reduced modulus `E*` of the film and the tip, GPa.
    pub effective_modulus_gpa: f64,
    /// The tip radius `R`, nm.
    pub tip_radius_nm: f64,
    /// The film thickness `h`, nm.
    pub thickness_nm: f64,
    /// The bottom-effect correction.
    pub correction: FilmCorrection,
}

impl FilmContact {
    /// The indentation `s` (nm) at which `chi` reaches `chi`: `s = chi^2 h^2 / R`.
    pub fn indentation_at_chi(&self, chi: f64) -> f64 {
        chi * chi * self.thickness_nm * self.thickness_nm / self.tip_radius_nm
    }

    /// The force (nN) and `dF/dd` (nN/nm) at gap `d` (nm).
    pub fn force_slopes(&self, gap_nm: f64) -> ForceSlopes {
        let c = 4.0 / 3.0 * self.effective_modulus_gpa * self.tip_radius_nm.sqrt();
        let s = (-gap_nm).max(0.0);
        let root = s.sqrt();
        let ratio = self.tip_radius_nm.sqrt() / self.thickness_nm;
        let (mut force, mut slope) = (0.0, 0.0);
        // b_k s^{(3+k)/2} = a_k (ratio root)^k s root, the weight (ratio root)^k.
        let mut weight = 1.0;
        for (k, a) in self.correction.coefficients().into_iter().enumerate() {
            let exponent = (3 + k) as f64 / 2.0;
            force += a * weight * s * root;
            slope += a * weight * exponent * root;
            weight *= ratio * root;
        }
        ForceSlopes {
            force: c * force,
            gap_slope: -c * slope,
            rate_slope: 0.0,
        }
    }

    /// The elastic energy stored at gap `d` (nm), `U = int_d^0 F dd'` in nN nm (MODEL.md
    /// section 10): `c sum_k b_k s^{(5+k)/2} / ((5+k)/2)`, term by term from
    /// [`FilmContact::force_slopes`]'s series.
    pub fn potential_nn_nm(&self, gap_nm: f64) -> f64 {
        let c = 4.0 / 3.0 * self.effective_modulus_gpa * self.tip_radius_nm.sqrt();
        let s = (-gap_nm).max(0.0);
        let root = s.sqrt();
        let ratio = self.tip_radius_nm.sqrt() / self.thickness_nm;
        let mut energy = 0.0;
        let mut weight = 1.0;
        for (k, a) in self.correction.coefficients().into_iter().enumerate() {
            energy += a * weight * s * s * root / ((5 + k) as f64 / 2.0);
            weight *= ratio * root;
        }
        c * energy
    }
}
