//! Timing of `flow_map` on reference problems (a plain bench binary: `cargo bench -p hybrid`).
//!
//! Prints the median wall time of repeated runs and the solver statistics, per drive period,
//! for the forced linear oscillator (DOP853 and exact flow) and the Hertz contact oscillator.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{ForcedOscillator, HertzOscillator};
use hybrid::{flow_map, HybridSystem, Mode, Sensitivity, Settings, SwitchingPartials};
use nalgebra::DMatrix;

/// Two driven modes (frequencies 1 and 6.3, Q 3 and 2) sharing a Hertz contact on the gap
/// `d = Z + q1 + q2`, like the paper's two-mode cantilever (state `(q1, v1, q2, v2)`,
/// parameter `Z`).
struct TwoModeContact {
    separation: f64,
}

const W2: f64 = 6.3;
const CONTACT: f64 = 30.0;

impl TwoModeContact {
    fn force(&self, mode: Mode, x: &[f64]) -> (f64, f64) {
        let d = self.separation + x[0] + x[2];
        if mode & 1 != 0 && d < 0.0 {
            (CONTACT * (-d).powf(1.5), 1.5 * CONTACT * (-d).sqrt())
        } else {
            (0.0, 0.0)
        }
    }
}

impl HybridSystem for TwoModeContact {
    fn dim(&self) -> usize {
        4
    }
    fn surface_count(&self) -> usize {
        1
    }
    fn vector_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        let (f, _) = self.force(mode, x);
        let drive = t.cos();
        dxdt[0] = x[1];
        dxdt[1] = -x[1] / 3.0 - x[0] + drive + f;
        dxdt[2] = x[3];
        dxdt[3] = W2 * W2 * (-x[3] / (2.0 * W2) - x[2] - 0.5 * drive / 40.0 + f / 40.0);
    }
    fn jacobian(&self, mode: Mode, _t: f64, x: &[f64], j: &mut DMatrix<f64>) {
        let (_, df) = self.force(mode, x);
        j.fill(0.0);
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -1.0 - df;
        j[(1, 1)] = -1.0 / 3.0;
        j[(1, 2)] = -df;
        j[(2, 3)] = 1.0;
        j[(3, 0)] = -W2 * W2 * df / 40.0;
        j[(3, 2)] = -W2 * W2 * (1.0 + df / 40.0);
        j[(3, 3)] = -W2 / 2.0;
    }
    fn parameter_derivative(&self, mode: Mode, _t: f64, x: &[f64], dfdp: &mut [f64]) {
        let (_, df) = self.force(mode, x);
        dfdp.fill(0.0);
        dfdp[1] = -df;
        dfdp[3] = -W2 * W2 * df / 40.0;
    }
    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        self.separation + x[0] + x[2]
    }
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        x[1] + x[3]
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        g: &mut [f64],
    ) -> SwitchingPartials {
        g.copy_from_slice(&[1.0, 0.0, 1.0, 0.0]);
        SwitchingPartials { t: 0.0, p: 1.0 }
    }
}

/// A benchmark case: runs with the given sensitivity, returns (median us, statistics).
type Case<'a> = &'a dyn Fn(Sensitivity) -> (f64, hybrid::Statistics);

fn median_micros<S: HybridSystem>(
    system: &S,
    x0: &[f64],
    duration: f64,
    sensitivity: Sensitivity,
    settings: &Settings,
) -> (f64, hybrid::Statistics) {
    let mut times = Vec::new();
    let mut statistics = None;
    for _ in 0..201 {
        let start = Instant::now();
        let result = flow_map(system, 0.0, x0, duration, sensitivity, settings);
        times.push(start.elapsed().as_secs_f64() * 1e6);
        match result {
            Ok(r) => statistics = Some(r.statistics),
            Err(e) => {
                eprintln!("benchmark run failed: {e}");
                std::process::exit(1);
            }
        }
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], statistics.unwrap_or_default())
}

fn main() {
    let settings = Settings::default();
    let oscillator = ForcedOscillator::reference();
    let period = 2.0 * std::f64::consts::PI / oscillator.drive;
    let exact = ForcedOscillator {
        exact_flow_limit: Some(period / 8.0),
        ..oscillator
    };
    let hertz = HertzOscillator::reference();
    let hertz_period = 2.0 * std::f64::consts::PI / hertz.drive;
    let two_mode = TwoModeContact { separation: 2.0 };
    let two_mode_period = 2.0 * std::f64::consts::PI;
    let cases: [(&str, Case); 4] = [
        ("linear oscillator, DOP853, 1 period", &|s| {
            median_micros(&oscillator, &[0.4, -0.3], period, s, &settings)
        }),
        ("linear oscillator, exact flow, 1 period", &|s| {
            median_micros(&exact, &[0.4, -0.3], period, s, &settings)
        }),
        ("Hertz contact oscillator, 3 periods from rest", &|s| {
            median_micros(&hertz, &[0.0, 0.0], 3.0 * hertz_period, s, &settings)
        }),
        ("two-mode Hertz contact, 3 periods from rest", &|s| {
            median_micros(
                &two_mode,
                &[3.0, 0.0, 0.0, 0.0],
                3.0 * two_mode_period,
                s,
                &settings,
            )
        }),
    ];
    for (name, run) in cases {
        for s in [Sensitivity::None, Sensitivity::TransitionAndParameter] {
            let (micros, statistics) = run(s);
            println!("{name}, {s:?}: {micros:.1} us  {statistics:?}");
        }
    }
}
