//! Tip-sample contact laws (MODEL.md section 9): the force `F_ts(d, d')` a law exerts at gap
//! `d` (nm) and gap rate `d'` (nm/us), its slopes, and the switching surfaces it needs.
//!
//! One law per file: [`hertz`] (sphere, cone, flat punch), [`dmt`] (adhesion, van der Waals
//! outside contact), [`kelvin_voigt`] (viscoelastic, clipped at zero force by default),
//! [`film`] (a layer on a rigid substrate), [`standard_linear_solid`] (a relaxing sample with
//! an internal state), the hysteretic [`jkr`] (adhesion broken at pull-off) and [`capillary`]
//! (a meniscus ruptured at a larger gap), plus the optional electrostatic [`double_layer`] and
//! [`hydration`] terms; [`law`] combines them into the [`TipSampleForce`] the model uses, and
//! [`spec`] reads and checks the sample file's `contact` and `electrostatic` objects.

pub mod capillary;
pub mod dmt;
pub mod double_layer;
pub mod film;
pub mod hertz;
pub mod hydration;
pub mod jkr;
pub mod kelvin_voigt;
pub mod law;
pub mod spec;
pub mod standard_linear_solid;

pub use capillary::CapillaryContact;
pub use dmt::DmtContact;
pub use double_layer::DoubleLayer;
pub use film::{FilmContact, FilmCorrection};
pub use hertz::{HertzShape, HertzTip};
pub use hydration::HydrationForce;
pub use jkr::JkrContact;
pub use kelvin_voigt::KelvinVoigtContact;
pub use law::{ContactLaw, ForceSlopes, TipSampleForce};
pub use spec::{ContactSpec, ElectrostaticSpec, HydrationSpec};
pub use standard_linear_solid::StandardLinearSolid;
