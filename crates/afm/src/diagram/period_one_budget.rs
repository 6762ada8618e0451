//! The energy budget of a period-1 orbit that forms a lossy attachment every period (MODEL.md
//! section 9, "Capillary meniscus"): what one drive period can replace against what one
//! formation takes. Used by the diagram's walk past a hysteretic law's branch break to skip
//! the search for period-k attractors where no period-1 orbit can end the walk.

use crate::model::TappingModel;

/// Whether the energy budget of one drive period admits a period-1 orbit of `model` at the
/// separation `z_nm` (nm). Over a period-1 orbit of one mode driven by `F_1 cos(w t)` (nN) with
/// first-harmonic amplitude `A` and phase lag `phi`, the drive does `pi F_1 A sin(phi)` and the
/// damping takes at least `pi k w A^2 / (w_1 Q)` (its first harmonic alone), so an orbit that
/// forms the attachment once per period, losing `E_m` (the meniscus's `F_m d_r`), needs
/// `pi F_1 A - pi k w A^2 / (w_1 Q) >= E_m` (at resonance, `F_1 = k A0 / Q`: MODEL.md's
/// `A (A0 sin(phi) - A) >= E_m Q / (pi k)`). An orbit that taps the sample from `Z` needs an
/// amplitude of about `Z` (at the built-in `rectangular-air-mica-humid`'s branch end `A - Z` =
/// 0.257 nm), so with `A = Z` past the budget's maximum (`Z >= F_1 w_1 Q / (2 k w)`, where a
/// larger `A` only costs more) the budget rules a period-1 orbit out where
/// `pi F_1 Z - pi k w Z^2 / (w_1 Q) < E_m`. Above first contact (`Z >= Z_G1`) the free orbit
/// needs no tap: admitted. Returns `true` (admitted) for every case the budget does not
/// cover: a law without a fixed loss per formation
/// ([`crate::contact::ContactLaw::formation_loss_nn_nm`]), more than one mode, an acoustic or
/// bimodal drive.
pub fn admits_period_one(model: &TappingModel, z_nm: f64) -> bool {
    let Some(loss) = model.contact_force().law.formation_loss_nn_nm() else {
        return true;
    };
    let modes = &model.cantilever().modes;
    if modes.len() != 1
        || model.base_motion().is_some()
        || model.second_drive().is_some()
        || z_nm >= model.grazing_separation_nm()
    {
        return true;
    }
    let mode = &modes[0];
    let force = model.drive_force_nn().abs();
    let stiffness = mode.stiffness_n_per_m;
    // `k w / (w_1 Q)`, nN us/nm per us: the first harmonic's damping coefficient.
    let damping = stiffness * model.drive_angular_frequency()
        / (mode.angular_frequency() * mode.quality_factor);
    let budget_peak = force / (2.0 * damping);
    if z_nm < budget_peak {
        return true;
    }
    let pi = std::f64::consts::PI;
    pi * force * z_nm - pi * damping * z_nm * z_nm >= loss
}
