//! The sweep engine's bookkeeping and exactness: the free orbit above first contact (closed
//! form), lock-in blocks as averages of single-cycle readings, decimation, the retract leg,
//! agreement with a brute-force integration, and validation messages.

use afm::TappingModel;
use afm::{builtin_case, AfmError, Sweep, SweepDirection, SweepRecord, SweepSettings};

fn biolever_on_mica() -> TappingModel {
    let case = builtin_case("biolever-mica").expect("case");
    TappingModel::from_case(&case).expect("model")
}

fn run(model: &TappingModel, settings: SweepSettings) -> Vec<SweepRecord> {
    Sweep::new(model, settings)
        .expect("sweep")
        .map(|record| record.expect("cycle"))
        .collect()
}

fn window(model: &TappingModel, from: f64, to: f64, rate: f64) -> SweepSettings {
    let mut settings = SweepSettings::for_model(model);
    settings.from_nm = from;
    settings.to_nm = to;
    settings.rate_nm_per_s = rate;
    settings.settle_cycles = 50;
    settings
}

/// Above first contact the cantilever never touches the sample, and the free steady state is
/// the exact start: every cycle reads the closed-form free orbit (A/A0 = 1, the free phase of
/// MODEL.md section 4), whatever Z does.
#[test]
fn above_first_contact_the_lockin_reads_the_free_orbit() {
    let model = biolever_on_mica();
    let from = model.grazing_separation_nm() + 1.0;
    let settings = window(&model, from, from - 0.5, 100.0);
    let z_step = 100.0e-6 * model.period_us();
    let records = run(&model, settings);
    assert_eq!(records.len(), (0.5 / z_step).floor() as usize);
    for (k, record) in records.iter().enumerate() {
        assert_eq!(record.cycle, k as u64);
        assert_eq!(record.direction, SweepDirection::Approach);
        // Z at mid-cycle, from the cycle index (rounding only).
        assert!((record.z_nm - (from - (k as f64 + 0.5) * z_step)).abs() < 1e-12);
        // The free orbit is exact and the quadrature of a pure first harmonic over steps of at
        // most a quarter modal period is exact to rounding (1e-12 leaves room for 100 steps'
        // accumulated rounding).
        assert!((record.amplitude_ratio - 1.0).abs() < 1e-12, "{record:?}");
        assert!(
            (record.phase_deg - model.free_phase_deg()).abs() < 1e-9,
            "{record:?}"
        );
        assert_eq!(record.impacts, 0.0);
        assert_eq!(record.peak_force_nn, 0.0);
    }
}

/// A block of N cycles is the average of the Fourier coefficients of its N single-cycle
/// readings (the same integration), its impacts the mean, its peak force the maximum; and
/// `every` keeps every N-th block.
#[test]
fn blocks_average_single_cycle_readings_and_every_decimates() {
    let model = biolever_on_mica();
    let single = run(&model, window(&model, 9.0, 8.95, 20.0));
    let mut settings = window(&model, 9.0, 8.95, 20.0);
    settings.lockin_cycles = 4;
    let blocks = run(&model, settings.clone());
    assert_eq!(blocks.len(), single.len() / 4);
    for (index, block) in blocks.iter().enumerate() {
        let cycles = &single[4 * index..4 * index + 4];
        assert_eq!(block.cycle, cycles[0].cycle);
        let (mut a, mut b) = (0.0, 0.0);
        for cycle in cycles {
            let phase = cycle.phase_deg.to_radians();
            a += cycle.amplitude_ratio * phase.cos() / 4.0;
            b += cycle.amplitude_ratio * phase.sin() / 4.0;
        }
        // Rounding only: the amplitudes are O(1).
        assert!((block.amplitude_ratio - a.hypot(b)).abs() < 1e-12);
        assert!((block.phase_deg - b.atan2(a).to_degrees()).abs() < 1e-10);
        let z_mean = cycles.iter().map(|c| c.z_nm).sum::<f64>() / 4.0;
        assert!((block.z_nm - z_mean).abs() < 1e-12);
        let impacts = cycles.iter().map(|c| c.impacts).sum::<f64>() / 4.0;
        assert_eq!(block.impacts, impacts);
        let peak = cycles.iter().map(|c| c.peak_force_nn).fold(0.0, f64::max);
        assert_eq!(block.peak_force_nn, peak);
        assert!(
            block.impacts >= 1.0 && block.peak_force_nn > 0.0,
            "in contact at 9 nm"
        );
    }
    settings.every = 3;
    let decimated = run(&model, settings);
    let expected: Vec<_> = blocks.iter().step_by(3).copied().collect();
    assert_eq!(decimated, expected);
}

/// With `retract`, the sweep comes back from the floor to the start at the same rate: as many
/// cycles as the approach, Z rising by one cycle's travel per cycle, the cycle count continued.
#[test]
fn retract_mirrors_the_approach() {
    let model = biolever_on_mica();
    let mut settings = window(&model, 8.0, 7.95, 20.0);
    settings.retract = true;
    let z_step = 20.0e-6 * model.period_us();
    let sweep = Sweep::new(&model, settings).expect("sweep");
    let leg = sweep.cycles_per_leg();
    let floor = sweep.floor_nm();
    assert!(floor >= 7.95 && floor < 7.95 + z_step);
    let records: Vec<_> = sweep.map(|r| r.expect("cycle")).collect();
    assert_eq!(records.len() as u64, 2 * leg);
    for (k, record) in records.iter().enumerate() {
        assert_eq!(record.cycle, k as u64);
        let k = k as u64;
        if k < leg {
            assert_eq!(record.direction, SweepDirection::Approach);
        } else {
            assert_eq!(record.direction, SweepDirection::Retract);
            let expected = floor + ((k - leg) as f64 + 0.5) * z_step;
            assert!((record.z_nm - expected).abs() < 1e-12);
            // Two impacts per cycle both ways in this window (G2 is near 8.72 nm, G3 lower).
            assert_eq!(record.impacts, 2.0);
        }
    }
}

/// The sweep at its default settings (tolerance 1e-9, 8 samples per step) against a
/// brute-force run of the same sweep (tolerance 1e-13, 64 samples per step, extrema and events
/// searched 8 times more finely): the same impacts in every cycle (none missed), and readings
/// that agree far inside the lock-in's targets (1e-3, 0.1 deg). Windows with two and three
/// impacts per cycle, away from the grazing points.
#[test]
fn default_settings_agree_with_a_brute_force_run() {
    let model = biolever_on_mica();
    for (from, to) in [(6.0, 5.98), (2.0, 1.98)] {
        let coarse = run(&model, window(&model, from, to, 10.0));
        let mut fine_settings = window(&model, from, to, 10.0);
        fine_settings.integration.relative_tolerance = 1e-13;
        fine_settings.integration.absolute_tolerance = 1e-13;
        fine_settings.integration.samples_per_step = 64;
        let fine = run(&model, fine_settings);
        assert_eq!(coarse.len(), fine.len());
        for (c, f) in coarse.iter().zip(&fine) {
            assert_eq!(c.impacts, f.impacts, "impacts at Z = {}", c.z_nm);
            assert!(c.impacts >= 2.0);
            // DOP853 at 1e-9 per step over ~50 contact steps per cycle: 1e-6 is a generous
            // bound on the difference in A/A0 (nm-scale amplitudes, 1e-9 nm local errors).
            assert!(
                (c.amplitude_ratio - f.amplitude_ratio).abs() < 1e-6,
                "{c:?} {f:?}"
            );
            assert!((c.phase_deg - f.phase_deg).abs() < 1e-4, "{c:?} {f:?}");
            assert!((c.peak_force_nn - f.peak_force_nn).abs() < 1e-4 * f.peak_force_nn);
        }
    }
}

fn field_of(error: AfmError) -> String {
    match error {
        AfmError::InvalidField { field, allowed, .. } => format!("{field}: {allowed}"),
        other => panic!("unexpected error {other}"),
    }
}

#[test]
fn invalid_settings_name_the_field_and_range() {
    let model = biolever_on_mica();
    let base = window(&model, 9.0, 8.0, 1.0);
    let cases: Vec<(SweepSettings, &str)> = vec![
        (
            SweepSettings {
                rate_nm_per_s: 0.0,
                ..base.clone()
            },
            "rate_nm_per_s: (0, 1000000] nm/s",
        ),
        (
            SweepSettings {
                rate_nm_per_s: f64::NAN,
                ..base.clone()
            },
            "rate_nm_per_s",
        ),
        (
            SweepSettings {
                to_nm: -1.0,
                ..base.clone()
            },
            "to_nm: [0, 100000] nm",
        ),
        (
            SweepSettings {
                from_nm: 7.0,
                ..base.clone()
            },
            "from_nm: (8, 100000]",
        ),
        (
            SweepSettings {
                lockin_cycles: 0,
                ..base.clone()
            },
            "lockin_cycles: an integer in [1,",
        ),
        (
            SweepSettings {
                every: 0,
                ..base.clone()
            },
            "every: an integer in [1,",
        ),
        // Shorter than one drive cycle's travel (1e6 nm/s moves 107 nm per cycle).
        (
            SweepSettings {
                rate_nm_per_s: 1e6,
                ..base.clone()
            },
            "from_nm - to_nm",
        ),
    ];
    for (settings, expected) in cases {
        let message = field_of(Sweep::new(&model, settings).expect_err("invalid"));
        assert!(message.starts_with(expected), "{message} vs {expected}");
    }
}
