//! The base-sample separation `Z(t)` (MODEL.md section 1): constant for periodic orbits and
//! continuation, a linear ramp for time-domain approach and retract sweeps.

/// The separation `Z(t)` between the cantilever base and the sample, nm (`Z > 0` above).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Separation {
    /// `Z(t) = z_nm`.
    Constant(f64),
    /// `Z(t) = z0_nm - rate_nm_per_us * t` (approach for a positive rate, retract for a
    /// negative one).
    Ramp {
        /// `Z(0)`, nm.
        z0_nm: f64,
        /// Approach speed `-dZ/dt`, nm/us.
        rate_nm_per_us: f64,
    },
}

impl Separation {
    /// `Z(t)`, nm (t in us).
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            Self::Constant(z) => z,
            Self::Ramp {
                z0_nm,
                rate_nm_per_us,
            } => z0_nm - rate_nm_per_us * t,
        }
    }

    /// `dZ/dt`, nm/us.
    #[inline]
    pub fn rate(&self) -> f64 {
        match *self {
            Self::Constant(_) => 0.0,
            Self::Ramp { rate_nm_per_us, .. } => -rate_nm_per_us,
        }
    }

    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        match *self {
            Self::Constant(z) => z.is_finite(),
            Self::Ramp {
                z0_nm,
                rate_nm_per_us,
            } => z0_nm.is_finite() && rate_nm_per_us.is_finite(),
        }
    }
}
