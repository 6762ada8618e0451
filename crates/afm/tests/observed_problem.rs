//! The diagram's observables, recorded during the corrector's accepted period map
//! (`afm::diagram::observed_problem`), against an independent integration of each branch
//! point's period from its state (`orbit_observables`, state only, a solver of its own): the
//! same numbers, to 1e-12 relative (they agree bit for bit: the solver's steps do not depend on
//! the sensitivities it carries).

use afm::{approach_diagram, builtin_case, orbit_observables, DiagramSettings, TappingModel};
use continuation::Parametrised;

/// `|a - b| <= 1e-12 max(|a|, |b|, scale)`: relative 1e-12, with `scale` for numbers that
/// vanish (a conservative law's dissipation).
fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(scale)
}

#[test]
fn recorded_observables_equal_a_separate_integration_of_each_point() {
    for name in ["biolever-mica", "biolever-soft-viscoelastic"] {
        let model = TappingModel::from_case(&builtin_case(name).expect("case")).expect("model");
        let mut settings = DiagramSettings::approach(&model);
        // Through G1 and G2 of the Biolever (10.0 and 8.7-8.8 nm).
        settings.z_limit_nm = 8.5;
        let diagram = approach_diagram(&model, &settings).expect("diagram");
        assert!(
            diagram.points.len() > 40,
            "{name}: {}",
            diagram.points.len()
        );
        let mut at = model.clone();
        for point in &diagram.points {
            at.set_parameter(point.z_nm);
            let reference = orbit_observables(
                &at,
                &point.state,
                &settings.orbit.integration,
                settings.orbit.harmonics,
            )
            .expect("observables");
            let what = format!("{name} at Z = {} nm", point.z_nm);
            assert!(
                close(point.amplitude_ratio, reference.amplitude_ratio, 0.0),
                "{what}"
            );
            assert!(close(point.phase_deg, reference.phase_deg, 0.0), "{what}");
            // Energies in eV, indentations in nm: the scale of a vanishing one is 1e-12 of
            // the orbit's damping loss and of the free amplitude.
            let energy: f64 = reference
                .mode_energy
                .iter()
                .map(|mode| mode.damping_loss_ev)
                .sum();
            assert!(
                close(point.dissipated_ev, reference.dissipated_ev, energy),
                "{what}"
            );
            assert!(
                close(point.virial_ev, reference.virial_ev, energy),
                "{what}"
            );
            let a0 = model.free_amplitude_nm();
            assert!(
                close(point.max_indentation_nm, reference.max_indentation_nm, a0),
                "{what}"
            );
            assert!(
                close(point.mean_indentation_nm, reference.mean_indentation_nm, a0),
                "{what}"
            );
            assert!(
                close(point.peak_force_nn, reference.peak_force_nn, 0.0),
                "{what}"
            );
            assert_eq!(point.impacts_per_orbit, reference.impacts.len(), "{what}");
            assert_eq!(point.harmonics.len(), reference.harmonics.len());
            for (h, r) in point.harmonics.iter().zip(&reference.harmonics) {
                assert!(
                    close(h.amplitude_nm, r.amplitude_nm, 1e-3 * a0),
                    "{what}: {h:?}"
                );
                // A phase is meaningful where its harmonic is above the rounding.
                if r.amplitude_nm > 1e-9 * a0 {
                    assert!((h.phase_deg - r.phase_deg).abs() <= 1e-9, "{what}: {h:?}");
                }
            }
        }
    }
}
