//! The contact-law abstraction (MODEL.md section 9): a law's force and slopes on each side of
//! its contact surface, and the [`TipSampleForce`] of a sample (a law plus an optional
//! electrostatic double layer) that the tapping model evaluates per hybrid mode.

use std::ops::AddAssign;

use super::{
    CapillaryContact, DmtContact, DoubleLayer, FilmContact, HertzShape, HydrationForce, JkrContact,
    KelvinVoigtContact, StandardLinearSolid,
};

/// A force `F` (nN, repulsive positive) with its slopes `dF/dd` (nN/nm) and `dF/dd'`
/// (nN us/nm) at one gap `d` and gap rate `d'`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ForceSlopes {
    /// `F`, nN.
    pub force: f64,
    /// `dF/dd`, nN/nm.
    pub gap_slope: f64,
    /// `dF/dd'`, nN us/nm (non-zero only for a viscous law).
    pub rate_slope: f64,
}

impl ForceSlopes {
    /// No force.
    pub const ZERO: Self = Self {
        force: 0.0,
        gap_slope: 0.0,
        rate_slope: 0.0,
    };
}

impl AddAssign for ForceSlopes {
    fn add_assign(&mut self, other: Self) {
        self.force += other.force;
        self.gap_slope += other.gap_slope;
        self.rate_slope += other.rate_slope;
    }
}

/// A contact law: the force inside contact (`d` below the contact surface `d = d_c`) and
/// outside it (MODEL.md section 9).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactLaw {
    /// Hertz: sphere, cone or flat punch on an elastic half-space (no force outside contact).
    Hertz(HertzShape),
    /// DMT: Hertz shifted to `d = a0` with the van der Waals adhesion outside and inside.
    Dmt(DmtContact),
    /// Kelvin-Voigt: Hertz with a viscous term in the indentation rate.
    KelvinVoigt(KelvinVoigtContact),
    /// A film of thickness `h` on a rigid substrate: Hertz times a bottom-effect correction.
    Film(FilmContact),
    /// A standard linear solid: Hertz on a relaxing sample with an internal state.
    StandardLinearSolid(StandardLinearSolid),
    /// JKR adhesion of a sphere: formed at `d = 0` on approach, broken at the pull-off gap
    /// `d_po > 0` on retract (a hysteresis; [`ContactLaw::release_gap_nm`]).
    Jkr(JkrContact),
    /// Hertz sphere plus a capillary meniscus: formed at `d = 0` on approach, ruptured at
    /// `d_r > 0` on retract (a hysteresis; [`ContactLaw::release_gap_nm`]).
    Capillary(CapillaryContact),
}

impl ContactLaw {
    /// The contact surface's gap `d_c`, nm: `a0` for DMT, 0 for every other law.
    pub fn contact_gap_nm(&self) -> f64 {
        match self {
            Self::Dmt(dmt) => dmt.intermolecular_distance_nm,
            _ => 0.0,
        }
    }

    /// The force and slopes inside contact (`d < d_c`), unclipped; a standard linear solid's
    /// for a recovered sample (`rho = 0`; [`ContactLaw::inside_at`] takes the state).
    pub fn inside(&self, gap_nm: f64, gap_rate: f64) -> ForceSlopes {
        self.inside_at(gap_nm, gap_rate, 0.0)
    }

    /// [`ContactLaw::inside`] with the sample's internal state `rho` (nm^{3/2}; used by the
    /// standard linear solid only).
    pub fn inside_at(&self, gap_nm: f64, gap_rate: f64, sample_state: f64) -> ForceSlopes {
        match self {
            Self::StandardLinearSolid(sls) => sls.force_slopes(gap_nm, sample_state),
            Self::Hertz(shape) => shape.force_slopes(gap_nm),
            Self::Dmt(dmt) => dmt.inside(gap_nm),
            Self::KelvinVoigt(kv) => kv.force_slopes(gap_nm, gap_rate),
            Self::Film(film) => film.force_slopes(gap_nm),
            Self::Jkr(jkr) => jkr.force_slopes(gap_nm),
            Self::Capillary(capillary) => capillary.hertz.force_slopes(gap_nm),
        }
    }

    /// The gap `d_r > d_c` (nm) at which a hysteretic law's contact breaks on retract (JKR's
    /// pull-off gap, the meniscus's rupture gap): the law is then attached from the `Down`
    /// crossing of `d = d_c` to the `Up` crossing of `d = d_r`, and exerts no force otherwise
    /// (MODEL.md section 9). `None` for every law without hysteresis.
    pub fn release_gap_nm(&self) -> Option<f64> {
        match self {
            Self::Jkr(jkr) => Some(jkr.pull_off_gap_nm()),
            Self::Capillary(capillary) => Some(capillary.rupture_gap_nm),
            _ => None,
        }
    }

    /// The energy (nN nm) a hysteretic law takes from the cantilever per attachment, where it
    /// is one number: the meniscus's loop area `F_m d_r` (MODEL.md section 9). `None` for
    /// every other law (JKR's loop area is not formed here).
    pub fn formation_loss_nn_nm(&self) -> Option<f64> {
        match self {
            Self::Capillary(capillary) => Some(capillary.loop_area_nn_nm()),
            _ => None,
        }
    }

    /// A hysteretic law's force and slopes while attached, inside contact (`inside`, `d < d_c`)
    /// or in the band `d_c <= d < d_r`: JKR's `F(a(-d))` on both sides, Hertz minus the
    /// meniscus force for the capillary law; [`ContactLaw::inside`] or zero for the others.
    pub fn attached(&self, inside: bool, gap_nm: f64, gap_rate: f64) -> ForceSlopes {
        match self {
            Self::Jkr(jkr) => jkr.force_slopes(gap_nm),
            Self::Capillary(capillary) => capillary.attached(inside, gap_nm),
            _ if inside => self.inside(gap_nm, gap_rate),
            _ => ForceSlopes::ZERO,
        }
    }

    /// The force and slopes outside contact (`d >= d_c`): the van der Waals attraction for
    /// DMT, zero otherwise.
    pub fn outside(&self, gap_nm: f64) -> ForceSlopes {
        match self {
            Self::Dmt(dmt) => dmt.outside(gap_nm),
            _ => ForceSlopes::ZERO,
        }
    }

    /// The standard linear solid, if the law is one (it adds a state to the model).
    pub fn standard_linear_solid(&self) -> Option<&StandardLinearSolid> {
        match self {
            Self::StandardLinearSolid(sls) => Some(sls),
            _ => None,
        }
    }

    /// How far below `d = d_c` the contact surface lies for internal state `rho`: the
    /// standard linear solid's unrecovered depth `sigma = rho^{2/3}` (nm), 0 for other laws.
    pub fn surface_depth_nm(&self, sample_state: f64) -> f64 {
        match self {
            Self::StandardLinearSolid(_) => StandardLinearSolid::unrecovered_depth_nm(sample_state),
            _ => 0.0,
        }
    }

    /// Whether the law exerts a force outside contact (then free flight is not force-free).
    pub fn acts_outside_contact(&self) -> bool {
        matches!(self, Self::Dmt(dmt) if dmt.hamaker_constant_j != 0.0)
    }

    /// The law's force outside contact (`d >= d_c`) while `attached` (a hysteretic law's
    /// attachment, MODEL.md section 9) when it is a constant, nN: the attached meniscus's
    /// `-F_m`, zero wherever the law exerts no force outside contact; `None` where it depends
    /// on the gap (DMT's van der Waals attraction, JKR while attached). A constant force leaves
    /// each mode of Eq. 1 a driven linear oscillator about a shifted rest position, with an
    /// exact flow.
    pub fn constant_outside(&self, attached: bool) -> Option<f64> {
        match self {
            Self::Capillary(capillary) if attached => Some(-capillary.meniscus_force_nn),
            Self::Jkr(_) if attached => None,
            _ if self.acts_outside_contact() => None,
            _ => Some(0.0),
        }
    }

    /// The release time constant `tau = 1.5 eta*/E*` (us) of a clipped Kelvin-Voigt law with
    /// `eta > 0`, whose force-zero surface `h_1 = -d - tau d' = 0` is a second switching
    /// surface; `None` for every other law.
    pub fn release_time_us(&self) -> Option<f64> {
        match self {
            // With eta = 0 the force is Hertz's, never negative: no release surface.
            Self::KelvinVoigt(kv) if kv.clip && kv.effective_viscosity_pa_s > 0.0 => {
                Some(kv.release_time_us())
            }
            _ => None,
        }
    }

    /// The energy `U(d)` (nN nm, zero far from the sample) of a conservative law, whose force
    /// depends on the gap alone, `F = -dU/dd` (MODEL.md section 10): Hertz (every shape), DMT
    /// and the film. `None` for a law that dissipates or carries a state (Kelvin-Voigt, the
    /// standard linear solid, JKR and the meniscus with their hysteresis).
    pub fn potential_nn_nm(&self, gap_nm: f64) -> Option<f64> {
        match self {
            Self::Hertz(shape) => Some(shape.potential_nn_nm(gap_nm)),
            Self::Dmt(dmt) => Some(dmt.potential_nn_nm(gap_nm)),
            Self::Film(film) => Some(film.potential_nn_nm(gap_nm)),
            Self::KelvinVoigt(_)
            | Self::StandardLinearSolid(_)
            | Self::Jkr(_)
            | Self::Capillary(_) => None,
        }
    }

    /// Whether the force inside contact grows with a half-integer power of the indentation
    /// `d_c - d` from the contact surface (sphere Hertz, DMT, Kelvin-Voigt, film), so the
    /// solution is smooth in the square root of the time from a crossing; `false` for the cone
    /// and the flat punch (integer powers).
    pub fn half_power_inside(&self) -> bool {
        match self {
            Self::Hertz(shape) => shape.has_half_powers(),
            Self::Dmt(_)
            | Self::KelvinVoigt(_)
            | Self::Film(_)
            | Self::StandardLinearSolid(_)
            | Self::Capillary(_) => true,
            // JKR's force is analytic in `d` through `d = 0`.
            Self::Jkr(_) => false,
        }
    }
}

/// The tip-sample force of a sample: its contact law plus an optional electrostatic double
/// layer and hydration force (MODEL.md section 9). A clipped Kelvin-Voigt law's force inside contact is zero in
/// the clipped mode (the side `h_1 < 0` of its release surface).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipSampleForce {
    /// The contact law.
    pub law: ContactLaw,
    /// The double-layer term, if any.
    pub double_layer: Option<DoubleLayer>,
    /// The hydration (solvation) term, if any.
    pub hydration: Option<HydrationForce>,
}

impl TipSampleForce {
    /// The contact surface's gap `d_c`, nm ([`ContactLaw::contact_gap_nm`]).
    pub fn contact_gap_nm(&self) -> f64 {
        self.law.contact_gap_nm()
    }

    /// The release gap of a hysteretic law ([`ContactLaw::release_gap_nm`]).
    pub fn release_gap_nm(&self) -> Option<f64> {
        self.law.release_gap_nm()
    }

    /// The force and slopes of mode `(inside, clipped, attached)` with the sample's internal
    /// state `rho` (nm^{3/2}): for a hysteretic law [`ContactLaw::attached`] while `attached`,
    /// zero otherwise, plus the double layer and hydration force as in
    /// [`TipSampleForce::in_region`]; for every other law [`TipSampleForce::in_region_at`].
    pub fn in_mode(
        &self,
        inside: bool,
        clipped: bool,
        attached: bool,
        gap_nm: f64,
        gap_rate: f64,
        sample_state: f64,
    ) -> ForceSlopes {
        if self.law.release_gap_nm().is_none() {
            return self.in_region_at(inside, clipped, gap_nm, gap_rate, sample_state);
        }
        let mut total = if attached {
            self.law.attached(inside, gap_nm, gap_rate)
        } else {
            ForceSlopes::ZERO
        };
        total += self.in_region(inside, true, gap_nm, gap_rate);
        total
    }

    /// Whether any force acts outside contact (DMT's van der Waals, a double layer, a
    /// hydration force).
    pub fn acts_outside_contact(&self) -> bool {
        self.law.acts_outside_contact() || self.double_layer.is_some() || self.hydration.is_some()
    }

    /// The force outside contact while `attached` when it is a constant, nN
    /// ([`ContactLaw::constant_outside`]); `None` with a double layer or a hydration force,
    /// which depend on the gap.
    pub fn constant_outside(&self, attached: bool) -> Option<f64> {
        if self.double_layer.is_some() || self.hydration.is_some() {
            return None;
        }
        self.law.constant_outside(attached)
    }

    /// The force and slopes on one side: inside contact (`inside`), with the contact law
    /// zeroed when `clipped`, or outside, for a recovered sample (`rho = 0`).
    #[inline]
    pub fn in_region(
        &self,
        inside: bool,
        clipped: bool,
        gap_nm: f64,
        gap_rate: f64,
    ) -> ForceSlopes {
        self.in_region_at(inside, clipped, gap_nm, gap_rate, 0.0)
    }

    /// [`TipSampleForce::in_region`] with the sample's internal state `rho` (nm^{3/2}; the
    /// standard linear solid's). The double layer and the hydration force add `F(d)` outside
    /// (for a standard linear solid at `max(d, d_c)`: constant between its rest surface and
    /// its unrecovered surface) and their value on the contact surface, `F(d_c)`, inside (held
    /// constant).
    #[inline]
    pub fn in_region_at(
        &self,
        inside: bool,
        clipped: bool,
        gap_nm: f64,
        gap_rate: f64,
        sample_state: f64,
    ) -> ForceSlopes {
        let mut total = match (inside, clipped) {
            (true, true) => ForceSlopes::ZERO,
            (true, false) => self.law.inside_at(gap_nm, gap_rate, sample_state),
            (false, _) => self.law.outside(gap_nm),
        };
        let contact_gap = self.contact_gap_nm();
        let held = inside || (self.law.standard_linear_solid().is_some() && gap_nm < contact_gap);
        let additive = |slopes: ForceSlopes| {
            if held {
                ForceSlopes {
                    force: slopes.force,
                    ..ForceSlopes::ZERO
                }
            } else {
                slopes
            }
        };
        let at = if held { contact_gap } else { gap_nm };
        if let Some(layer) = &self.double_layer {
            total += additive(layer.force_slopes(at));
        }
        if let Some(hydration) = &self.hydration {
            total += additive(hydration.force_slopes(at));
        }
        total
    }

    /// The energy `U(d)` (nN nm, zero far from the sample) of a conservative tip-sample force,
    /// `F = -dU/dd` (MODEL.md section 10): [`ContactLaw::potential_nn_nm`] plus the double
    /// layer's and the hydration force's energies, which inside contact, where their force is
    /// held at `F(d_c)`, grow as `U(d_c) + F(d_c) (d_c - d)`. `None` when the law has no energy.
    pub fn potential_nn_nm(&self, gap_nm: f64) -> Option<f64> {
        let mut energy = self.law.potential_nn_nm(gap_nm)?;
        let contact_gap = self.contact_gap_nm();
        let at = gap_nm.max(contact_gap);
        let held = contact_gap - gap_nm.min(contact_gap);
        if let Some(layer) = &self.double_layer {
            energy += layer.potential_nn_nm(at) + layer.force(contact_gap) * held;
        }
        if let Some(hydration) = &self.hydration {
            energy += hydration.potential_nn_nm(at) + hydration.force(contact_gap) * held;
        }
        Some(energy)
    }

    /// The force (nN) at gap `d` and rate `d'` with the region taken from the gap itself
    /// (inside when `d < d_c`) and a clipped law clipped at zero: what a sampled state feels.
    /// A hysteretic law counts as attached inside contact and detached outside (its state in
    /// the band `d_c <= d < d_r` depends on the history: [`TipSampleForce::in_mode`]).
    pub fn force(&self, gap_nm: f64, gap_rate: f64) -> f64 {
        self.force_at(gap_nm, gap_rate, 0.0)
    }

    /// [`TipSampleForce::force`] with the sample's internal state `rho` (nm^{3/2}): inside
    /// when `d + sigma < d_c` (`sigma` the standard linear solid's unrecovered depth).
    pub fn force_at(&self, gap_nm: f64, gap_rate: f64, sample_state: f64) -> f64 {
        let inside = gap_nm + self.law.surface_depth_nm(sample_state) < self.contact_gap_nm();
        if self.law.release_gap_nm().is_some() {
            return self
                .in_mode(inside, false, inside, gap_nm, gap_rate, sample_state)
                .force;
        }
        let clipped = inside
            && self
                .law
                .release_time_us()
                .is_some_and(|tau| -gap_nm - tau * gap_rate < 0.0);
        self.in_region_at(inside, clipped, gap_nm, gap_rate, sample_state)
            .force
    }
}
