//! Harmonic balance of Eq. 1 on simulated periodic orbits: projecting Eq. 1 for mode i onto
//! cos(w t) and sin(w t) over a period gives, exactly, for any T-periodic solution with first
//! harmonic q_i ~ alpha_i cos(w t) + beta_i sin(w t),
//!
//!   alpha_i (1 - (w/w_i)^2) + beta_i (w/w_i)/Q_i = F_i/k_i + (2/T) int F_ts cos(w t) dt / k_i
//!   beta_i (1 - (w/w_i)^2) - alpha_i (w/w_i)/Q_i =         (2/T) int F_ts sin(w t) dt / k_i
//!
//! (the basis of the paper's Eq. 2). Checked by brute-force sampling of the solver's trajectory:
//! a test of the model (units, signs, forcing) and of the integration through contact.

use afm::{Separation, TappingModel};
use hybrid::{
    flow_map, flow_map_observed, HybridSystem, Sensitivity, Settings, Solver, StepOutcome,
};

#[test]
fn periodic_orbits_satisfy_the_harmonic_balance_of_eq1() {
    for (case, offset) in [
        ("biolever-mica", -2.0),
        ("maclever-mica-experiment", -3.0),
        ("maclever-soft", -5.0),
    ] {
        let mut model =
            TappingModel::from_case(&afm::builtin_case(case).expect("case")).expect("model");
        let z = model.grazing_separation_nm() + offset;
        model
            .set_separation(Separation::Constant(z))
            .expect("finite");
        let period = model.period_us();
        let settings = Settings::default();
        // 40 periods: transients decay by exp(-40 pi / Q_1) (Q_1 <= 1.6).
        let x0 = flow_map(
            &model,
            0.0,
            &model.free_state(),
            40.0 * period,
            Sensitivity::None,
            &settings,
        )
        .expect("transient")
        .state;
        let n = model.mode_count();
        let m = 100_000;
        let w = model.drive_angular_frequency();
        // (2/m) sums: rectangle rule, spectrally accurate for the smooth part; the force's
        // (t - t_c)^{3/2} corners cost ~h^{5/2}, ~1e-10 relative here.
        let mut q_harmonics = vec![[0.0; 2]; n];
        let mut force_harmonic = [0.0; 2];
        let mut next = 0usize;
        let mut x = vec![0.0; model.dim()];
        flow_map_observed(
            &model,
            0.0,
            &x0,
            period,
            Sensitivity::None,
            &settings,
            &mut |solver: &Solver<TappingModel>, _: &StepOutcome| {
                let (_, end) = solver.last_step();
                while next < m && period * next as f64 / m as f64 <= end {
                    let t = period * next as f64 / m as f64;
                    solver.interpolate(t, &mut x);
                    let (sin, cos) = (w * t).sin_cos();
                    let scale = 2.0 / m as f64;
                    for (i, h) in q_harmonics.iter_mut().enumerate() {
                        h[0] += scale * x[2 * i] * cos;
                        h[1] += scale * x[2 * i] * sin;
                    }
                    let force = model.tip_sample_force(t, &x);
                    force_harmonic[0] += scale * force * cos;
                    force_harmonic[1] += scale * force * sin;
                    next += 1;
                }
            },
        )
        .expect("sampling");
        assert!(force_harmonic[0].abs() > 1e-3, "{case}: no contact");
        for (i, mode) in model.cantilever().modes.iter().enumerate() {
            let ratio = w / mode.angular_frequency();
            let k = mode.stiffness_n_per_m;
            let [alpha, beta] = q_harmonics[i];
            let static_drive = mode.force_ratio * model.drive_force_nn() / k;
            let cos_left = alpha * (1.0 - ratio * ratio) + beta * ratio / mode.quality_factor;
            let cos_right = static_drive + force_harmonic[0] / k;
            let sin_left = beta * (1.0 - ratio * ratio) - alpha * ratio / mode.quality_factor;
            let sin_right = force_harmonic[1] / k;
            let scale = static_drive.abs() + force_harmonic[0].abs() / k;
            // Sampling ~1e-10, periodicity of the settled orbit ~1e-12: 1e-7 relative.
            assert!(
                (cos_left - cos_right).abs() < 1e-7 * scale,
                "{case} mode {i} cos: {cos_left} vs {cos_right}"
            );
            assert!(
                (sin_left - sin_right).abs() < 1e-7 * scale,
                "{case} mode {i} sin: {sin_left} vs {sin_right}"
            );
        }
    }
}
