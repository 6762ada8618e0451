//! Benchmark of `RectangularCantilever::modes_in_fluid` (MODEL.md section 11): the modes of the
//! built-in `rectangular-silicon-water` geometry (200 x 20 x 1 um silicon) in water, for 2 and
//! 10 modes, without and with a tip mass (the fixed point then re-solves the eigenvalue at each
//! iterate). Target: under a millisecond per mode, so that `drumroll cantilever --geometry`
//! answers at once. Measured 2026-11-26 on the shared 2-core machine: 0.17 to 0.26 ms per mode
//! (each fixed-point iteration evaluates one Bessel quadrature and one eigenvalue).
//!
//! Run with `cargo bench -p beam --bench fluid_modes`; prints the median wall time of 200 runs.

use beam::{Fluid, RectangularCantilever};

fn median_microseconds(mut run: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..200)
        .map(|_| {
            let start = std::time::Instant::now();
            run();
            start.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() {
    let water = Fluid::water();
    for tip_mass_ratio in [0.0, 0.16] {
        let cantilever = RectangularCantilever {
            length_um: 200.0,
            width_um: 20.0,
            thickness_um: 1.0,
            youngs_modulus_gpa: 169.0,
            density_kg_m3: 2330.0,
            tip_mass_ratio,
        };
        for count in [2, 10] {
            let median = median_microseconds(|| {
                std::hint::black_box(
                    cantilever
                        .modes_in_fluid(std::hint::black_box(&water), count)
                        .expect("modes"),
                );
            });
            println!(
                "modes_in_fluid: m_tip/m_c = {tip_mass_ratio}, {count} modes: median {median:.1} us \
                 ({:.1} us per mode)",
                median / count as f64
            );
        }
    }
}
