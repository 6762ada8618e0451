//! Bad input gives typed errors, never a panic.

mod common;

use common::{BouncingBall, ForcedOscillator};
use hybrid::{
    flow_map, HybridError, HybridSystem, Mode, Sensitivity, Settings, Solver, SwitchingPartials,
};
use nalgebra::DMatrix;

const BALL: BouncingBall = BouncingBall {
    gravity: 9.81,
    restitution: 0.8,
};

#[test]
fn non_finite_initial_state() {
    for x0 in [[f64::NAN, 0.0], [0.0, f64::INFINITY]] {
        let r = Solver::new(&BALL, 0.0, &x0, Sensitivity::None, Settings::default());
        assert!(matches!(r, Err(HybridError::NonFiniteState { .. })));
    }
}

#[test]
fn dimension_mismatch() {
    let r = Solver::new(&BALL, 0.0, &[1.0], Sensitivity::None, Settings::default());
    assert_eq!(
        r.err(),
        Some(HybridError::DimensionMismatch {
            expected: 2,
            found: 1
        })
    );
}

#[test]
fn invalid_settings_name_the_field() {
    let settings = Settings {
        max_step: 0.0,
        ..Settings::default()
    };
    let r = flow_map(&BALL, 0.0, &[1.0, 0.0], 1.0, Sensitivity::None, &settings);
    match r {
        Err(HybridError::InvalidSettings { field, .. }) => assert_eq!(field, "max_step"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn invalid_end_time() {
    let mut solver = Solver::new(
        &BALL,
        1.0,
        &[1.0, 0.0],
        Sensitivity::None,
        Settings::default(),
    )
    .unwrap();
    assert!(matches!(
        solver.step(0.5),
        Err(HybridError::InvalidEndTime { .. })
    ));
    assert!(matches!(
        solver.step(f64::NAN),
        Err(HybridError::InvalidEndTime { .. })
    ));
    let r = flow_map(
        &BALL,
        0.0,
        &[1.0, 0.0],
        -1.0,
        Sensitivity::None,
        &Settings::default(),
    );
    assert!(matches!(r, Err(HybridError::InvalidEndTime { .. })));
}

/// A step limit of 3 attempts cannot cover 20 time units of the oscillator (it needs 128).
#[test]
fn too_many_steps() {
    let settings = Settings {
        max_steps: 3,
        ..Settings::default()
    };
    let r = flow_map(
        &ForcedOscillator::reference(),
        0.0,
        &[0.4, -0.3],
        20.0,
        Sensitivity::None,
        &settings,
    );
    assert!(matches!(r, Err(HybridError::TooManySteps { steps: 3, .. })));
}

/// `x' = x^2` from 1 blows up at t = 1: the step size must underflow (or the state become
/// non-finite) before, with an error rather than a hang.
struct BlowUp;

impl HybridSystem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn surface_count(&self) -> usize {
        0
    }
    fn vector_field(&self, _mode: Mode, _t: f64, x: &[f64], dxdt: &mut [f64]) {
        dxdt[0] = x[0] * x[0];
    }
    fn jacobian(&self, _mode: Mode, _t: f64, x: &[f64], j: &mut DMatrix<f64>) {
        j[(0, 0)] = 2.0 * x[0];
    }
    fn switching(&self, _k: usize, _t: f64, _x: &[f64]) -> f64 {
        1.0
    }
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, _x: &[f64]) -> f64 {
        0.0
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        g: &mut [f64],
    ) -> SwitchingPartials {
        g.fill(0.0);
        SwitchingPartials::default()
    }
}

#[test]
fn blow_up_gives_step_size_underflow() {
    let r = flow_map(
        &BlowUp,
        0.0,
        &[1.0],
        2.0,
        Sensitivity::None,
        &Settings::default(),
    );
    match r {
        Err(HybridError::StepSizeUnderflow { t, .. }) | Err(HybridError::NonFiniteState { t }) => {
            // The blow-up time is 1 (exact solution 1 / (1 - t)); the numerical solution
            // (relative accuracy ~1e-12 while finite) fails within 1e-6 of it.
            assert!((t - 1.0).abs() < 1e-6, "t = {t}");
        }
        other => panic!("{other:?}"),
    }
}

/// Errors carry their context in `Display`.
#[test]
fn error_messages_name_the_context() {
    let e = HybridError::InvalidSettings {
        field: "samples_per_step",
        value: 0.0,
        allowed: "1 ..= 1000",
    };
    let text = e.to_string();
    assert!(text.contains("samples_per_step") && text.contains("1 ..= 1000"));
}
