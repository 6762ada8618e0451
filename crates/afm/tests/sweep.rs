//! The sweep engine's bookkeeping and exactness: the free orbit above first contact (closed
//! form), lock-in blocks as averages of single-cycle readings, decimation, the retract leg,
//! agreement with a brute-force integration, and validation messages.

use afm::TappingModel;
use afm::{builtin_case, AfmError, OrbitStart, Sweep, SweepDirection, SweepRecord, SweepSettings};

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
        assert_eq!(record.impacts_per_period, 0.0);
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
        let impacts = cycles.iter().map(|c| c.impacts_per_period).sum::<f64>() / 4.0;
        assert_eq!(block.impacts_per_period, impacts);
        let peak = cycles.iter().map(|c| c.peak_force_nn).fold(0.0, f64::max);
        assert_eq!(block.peak_force_nn, peak);
        assert!(
            block.impacts_per_period >= 1.0 && block.peak_force_nn > 0.0,
            "in contact at 9 nm"
        );
    }
    settings.every = 3;
    let decimated = run(&model, settings);
    let expected: Vec<_> = blocks.iter().step_by(3).cloned().collect();
    assert_eq!(decimated, expected);
}

/// The cycles of blocks that `every` drops are integrated without the lock-in: the records
/// kept are, bit for bit, every N-th record of the sweep that reads every cycle, in both legs
/// (blocks of 2 cycles, every 3rd, approach and retract).
#[test]
fn dropped_blocks_leave_the_kept_records_unchanged() {
    let model = biolever_on_mica();
    let mut settings = window(&model, 9.0, 8.95, 20.0);
    settings.lockin_cycles = 2;
    settings.retract = true;
    let all = run(&model, settings.clone());
    settings.every = 3;
    let decimated = run(&model, settings);
    let expected: Vec<_> = [SweepDirection::Approach, SweepDirection::Retract]
        .into_iter()
        .flat_map(|direction| {
            all.iter()
                .filter(move |record| record.direction == direction)
                .step_by(3)
                .cloned()
        })
        .collect();
    assert!(expected.len() >= 6, "{} records", expected.len());
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
            assert_eq!(record.impacts_per_period, 2.0);
        }
    }
}

/// The sweep at its default settings (tolerance 1e-8, 4 samples per step, free flight proven
/// clear of the sample left unsampled) against a brute-force run of the same sweep (tolerance
/// 1e-13, 64 samples in every step, extrema and events searched 16 times more finely): the
/// same impacts in every cycle (none missed), and readings
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
        fine_settings.integration.extremum_height = f64::INFINITY;
        let fine = run(&model, fine_settings);
        assert_eq!(coarse.len(), fine.len());
        for (c, f) in coarse.iter().zip(&fine) {
            assert_eq!(
                c.impacts_per_period, f.impacts_per_period,
                "impacts at Z = {}",
                c.z_nm
            );
            assert!(c.impacts_per_period >= 2.0);
            // DOP853 at 1e-8 per step over ~50 contact steps per cycle: the readings differ by
            // ~1e-8 in A/A0 and ~1e-6 deg (measured ~7e-8 and 1e-5 deg even at 1e-7); 1e-6 and
            // 1e-4 deg keep a margin of 100 and still sit 1000 times inside the lock-in targets.
            assert!(
                (c.amplitude_ratio - f.amplitude_ratio).abs() < 1e-6,
                "{c:?} {f:?}"
            );
            assert!((c.phase_deg - f.phase_deg).abs() < 1e-4, "{c:?} {f:?}");
            assert!((c.peak_force_nn - f.peak_force_nn).abs() < 1e-4 * f.peak_force_nn);
        }
    }
}

/// Free flight that the model proves clear of the sample (`extremum_height = 0`, the default)
/// is neither sampled nor cut into quarter-period steps: that changes nothing the sweep reports
/// beyond rounding. Against the same sweep with every step sampled (`extremum_height`
/// infinite): the same impacts in every cycle, readings equal to rounding (the free flight
/// composed of fewer, longer exact steps), in windows just below first contact (where the free
/// flight's lowest gap comes within nanometres of the sample, so the bound decides most often)
/// and around G2 and G3 of the Biolever on mica.
#[test]
fn skipping_clear_free_flight_changes_no_record() {
    let model = biolever_on_mica();
    let g1 = model.grazing_separation_nm();
    for (from, to) in [(g1 + 0.005, g1 - 0.02), (8.74, 8.71), (3.39, 3.36)] {
        let skipping = run(&model, window(&model, from, to, 100.0));
        let mut full_settings = window(&model, from, to, 100.0);
        full_settings.integration.extremum_height = f64::INFINITY;
        let full = run(&model, full_settings);
        assert!(!skipping.is_empty());
        assert_eq!(skipping.len(), full.len());
        let (mut ratio, mut phase, mut force) = (0.0f64, 0.0f64, 0.0f64);
        for (s, f) in skipping.iter().zip(&full) {
            assert_eq!(
                (s.cycle, s.z_nm, s.impacts_per_period),
                (f.cycle, f.z_nm, f.impacts_per_period)
            );
            ratio = ratio.max((s.amplitude_ratio - f.amplitude_ratio).abs());
            phase = phase.max((s.phase_deg - f.phase_deg).abs());
            force =
                force.max((s.peak_force_nn - f.peak_force_nn).abs() / f.peak_force_nn.max(1e-300));
        }
        eprintln!(
            "{from} -> {to} nm: |dA/A0| {ratio:e}, |dPhi| {phase:e} deg, peak force {force:e}"
        );
        // Rounding only: measured at most 1e-14, 1e-12 deg and 1e-12 relative.
        assert!(ratio < 1e-12 && phase < 1e-10 && force < 1e-10);
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
        // A lock-in block longer than the sweep (1 nm at 1 nm/s is 9300 cycles).
        (
            SweepSettings {
                lockin_cycles: 10_000,
                ..base.clone()
            },
            "lockin_cycles: at most the 9300 drive cycles",
        ),
        // Shorter than one drive cycle's travel (1e6 nm/s moves 107 nm per cycle).
        (
            SweepSettings {
                rate_nm_per_s: 1e6,
                ..base.clone()
            },
            "from_nm - to_nm",
        ),
        // Longer than 1e8 cycles in one direction (1 nm at 1e-6 nm/s is 9.3e9 cycles).
        (
            SweepSettings {
                rate_nm_per_s: 1e-6,
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

/// The lock-in of one cycle (closed form over free flight, 4-point Gauss-Legendre over
/// contact steps) against `observe_period` (8-point Gauss-Legendre over every step, an
/// independent quadrature of the same integrals) on a steady cycle with two impacts.
#[test]
fn cycle_lockin_matches_the_period_observables() {
    use afm::orbit::lockin::CycleLockIn;
    use afm::{observe_period, steady_orbit, Separation, SteadyOrbitSettings};
    use hybrid::{Sensitivity, Solver, StepOutcome};
    let mut model = biolever_on_mica();
    let orbit = steady_orbit(
        &model,
        8.0,
        OrbitStart::Transient,
        &SteadyOrbitSettings::default(),
    )
    .expect("orbit");
    model
        .set_separation(Separation::Constant(8.0))
        .expect("finite");
    let settings = hybrid::Settings::default();
    let (_, observables) =
        observe_period(&model, 0.0, &orbit.state, Sensitivity::None, &settings, 1).expect("period");
    assert_eq!(observables.impacts.len(), 2);
    let mut lockin = CycleLockIn::new(&model);
    let mut solver =
        Solver::new(&model, 0.0, &orbit.state, Sensitivity::None, settings).expect("solver");
    lockin.begin(&model, &orbit.state);
    loop {
        let outcome = solver.step(model.period_us()).expect("step");
        lockin.observe(&solver, &outcome);
        if matches!(outcome, StepOutcome::EndTime) {
            break;
        }
    }
    // Call step again at the end time: a repeated step must not be counted twice.
    let outcome = solver.step(model.period_us()).expect("step");
    lockin.observe(&solver, &outcome);
    let reading = lockin.finish(&model, solver.state());
    let amplitude = reading.cosine_nm.hypot(reading.sine_nm);
    let phase = reading.sine_nm.atan2(reading.cosine_nm).to_degrees();
    // Both quadratures are accurate to ~1e-10 nm on contact steps of at most a few tenths of a
    // microsecond; 1e-8 nm and 1e-7 deg leave room for the 4-point rule.
    assert!(
        (amplitude - observables.amplitude_nm).abs() < 1e-8,
        "{amplitude} vs {}",
        observables.amplitude_nm
    );
    assert!(
        (phase - observables.phase_deg).abs() < 1e-7,
        "{phase} vs {}",
        observables.phase_deg
    );
    assert_eq!(reading.impacts, 2);
    assert!(
        (reading.peak_force_nn - observables.peak_force_nn).abs()
            < 1e-12 * observables.peak_force_nn.max(1.0)
    );
}

/// A cycle in contact throughout (the Biolever's rest position 10 nm, `A0`, inside mica: the
/// tip never leaves the sample; its highest gap minimum is -0.016 nm) counts one impact, as the steady orbit's observables count an orbit in
/// permanent contact (MODEL.md section 5); the lock-in read 0 before.
#[test]
fn a_cycle_in_permanent_contact_counts_one_impact() {
    use afm::{observe_period, steady_orbit, Separation, SteadyOrbitSettings};
    use hybrid::Sensitivity;
    let z = -10.0;
    let mut model = biolever_on_mica();
    let orbit = steady_orbit(
        &model,
        z,
        OrbitStart::Transient,
        &SteadyOrbitSettings::default(),
    )
    .expect("orbit");
    model
        .set_separation(Separation::Constant(z))
        .expect("finite");
    let settings = hybrid::Settings::default();
    let (_, observables) =
        observe_period(&model, 0.0, &orbit.state, Sensitivity::None, &settings, 1).expect("period");
    assert!(observables.gap_minima.iter().all(|m| m.gap_nm < 0.0));
    assert_eq!(observables.impacts_per_period, 1.0);
    let (reading, events) = read_one_cycle(&model, &orbit.state, 1);
    assert_eq!(events, 0, "a crossing");
    assert_eq!(reading.impacts, 1);
}

/// One drive cycle of `model` from `x0` read by a lock-in of `harmonics` harmonics (default
/// settings): its reading and the number of events the solver met.
fn read_one_cycle(
    model: &afm::TappingModel,
    x0: &[f64],
    harmonics: usize,
) -> (afm::orbit::lockin::CycleReading, usize) {
    use afm::orbit::lockin::CycleLockIn;
    use hybrid::{Sensitivity, Solver, StepOutcome};
    let mut lockin = CycleLockIn::with_harmonics(model, harmonics);
    let mut solver = Solver::new(
        model,
        0.0,
        x0,
        Sensitivity::None,
        hybrid::Settings::default(),
    )
    .expect("solver");
    lockin.begin(model, x0);
    let mut events = 0;
    loop {
        let outcome = solver.step(model.period_us()).expect("step");
        events += usize::from(matches!(outcome, StepOutcome::Event(_)));
        lockin.observe(&solver, &outcome);
        if matches!(outcome, StepOutcome::EndTime) {
            break;
        }
    }
    (lockin.finish(model, solver.state()), events)
}

/// The closed-form free-flight integrals (harmonics 1 to 3) against composite 8-point
/// Gauss-Legendre quadrature of the model's exact flow (100 panels over 1.7 periods: converged
/// to rounding), for the Biolever (both modes under-damped) and for a copy with an over-damped
/// second mode (Q_2 = 0.3), from a state off the steady orbit so that the homogeneous part
/// matters.
#[test]
fn free_flight_fourier_matches_quadrature_of_the_exact_flow() {
    use afm::model::free_flight_fourier::FreeFlightFourier;
    use afm::{Separation, TappingModel};
    use hybrid::ExactFlow;
    let nodes = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    let weights = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let case = builtin_case("biolever-mica").expect("case");
    let mut overdamped = case.cantilever.clone();
    overdamped.modes[1].quality_factor = 0.3;
    for cantilever in [case.cantilever.clone(), overdamped] {
        let model = TappingModel::new(
            cantilever,
            case.sample.clone(),
            10.0,
            None,
            Separation::Constant(50.0),
        )
        .expect("model");
        let closed = FreeFlightFourier::new(&model).expect("not critically damped");
        let x_a = [3.0, -0.4, -1.5, 2.0];
        let (a, b) = (17.3, 17.3 + 1.7 * model.period_us());
        let w = model.drive_angular_frequency();
        let panels = 100;
        let h = (b - a) / panels as f64;
        let mut x = [0.0; 4];
        for k in 1..=3 {
            let kw = k as f64 * w;
            let (mut cosine, mut sine) = (0.0, 0.0);
            for panel in 0..panels {
                let middle = a + (panel as f64 + 0.5) * h;
                for (node, weight) in nodes.iter().zip(weights) {
                    for t in [middle - 0.5 * h * node, middle + 0.5 * h * node] {
                        model.exact_flow(0, a, &x_a, t - a, &mut x, None, None);
                        let u = model.photodiode(&x);
                        cosine += 0.5 * h * weight * u * (kw * t).cos();
                        sine += 0.5 * h * weight * u * (kw * t).sin();
                    }
                }
            }
            let [c, s] = closed.integrate_harmonic(k, a, &x_a, b);
            if k == 1 {
                assert_eq!([c, s], closed.integrate(a, &x_a, b));
            }
            // Integrals of size ~1e3 nm us (harmonic 1; the others are smaller); rounding of
            // the exponentials and sums ~1e-12 relative to the largest.
            assert!(
                (c - cosine).abs() < 1e-9 * cosine.abs().max(1.0),
                "k {k}: {c} vs {cosine}"
            );
            assert!(
                (s - sine).abs() < 1e-9 * sine.abs().max(1.0),
                "k {k}: {s} vs {sine}"
            );
        }
        // An empty interval integrates to zero.
        assert_eq!(closed.integrate(a, &x_a, a), [0.0, 0.0]);
    }
}

/// The lock-in's harmonics 1..=6 and the cycle's dissipated energy against `observe_period`
/// (8-point Gauss-Legendre, an independent quadrature) on a steady cycle of the Biolever on a
/// clipped Kelvin-Voigt sample, where the dissipation is not zero; driven directly and
/// acoustically (where the sample's share is `-int F_ts (w' + y_base') dt`: the base's work,
/// several eV a cycle, is not the sample's, MODEL.md section 14).
#[test]
fn cycle_lockin_reads_harmonics_and_dissipation() {
    for drive in [
        afm::model::drive_spec::DriveSpec::Direct,
        afm::model::drive_spec::DriveSpec::Acoustic {
            base_participation: None,
        },
    ] {
        lockin_reads_harmonics_and_dissipation(&drive);
    }
}

fn lockin_reads_harmonics_and_dissipation(drive: &afm::model::drive_spec::DriveSpec) {
    use afm::{observe_period, steady_orbit, Separation, SteadyOrbitSettings, TappingModel};
    use hybrid::Sensitivity;
    let sample = afm::fixtures::parse_sample(
        "kv.json",
        r#"{"name": "kv", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.3,
            "contact": {"law": "kelvin-voigt", "viscosity_pa_s": 100}}"#,
    )
    .expect("sample");
    let cantilever = afm::builtin_cantilever("biolever").expect("cantilever");
    let model = TappingModel::with_drive(
        cantilever,
        sample,
        10.0,
        None,
        drive,
        Separation::Constant(8.5),
    )
    .expect("model");
    let orbit = steady_orbit(
        &model,
        8.5,
        OrbitStart::Approach,
        &SteadyOrbitSettings::default(),
    )
    .expect("orbit");
    let settings = hybrid::Settings::default();
    let (_, observables) =
        observe_period(&model, 0.0, &orbit.state, Sensitivity::None, &settings, 6).expect("period");
    assert!(observables.dissipated_ev > 0.0);
    let (reading, _) = read_one_cycle(&model, &orbit.state, 6);
    assert_eq!(reading.harmonic_count, 6);
    for (harmonic, [a, b]) in observables.harmonics.iter().zip(reading.harmonics) {
        assert!(
            (a.hypot(b) - harmonic.amplitude_nm).abs() < 1e-8,
            "n = {}: {} vs {}",
            harmonic.n,
            a.hypot(b),
            harmonic.amplitude_nm
        );
    }
    // The 4-point rule against the 8-point one: 1e-8 of the dissipation.
    assert!(
        (reading.dissipated_ev - observables.dissipated_ev).abs()
            < 1e-8 * observables.dissipated_ev,
        "{} vs {}",
        reading.dissipated_ev,
        observables.dissipated_ev
    );
}

/// A sweep whose solver fails in a cycle ends there on any number of threads: the same records
/// before it, the same error, cycle count and separation (the segments integrated ahead fail
/// too, or are never reached). The solver's step budget is cut so that free-flight cycles fit
/// in it and a cycle with deep enough contact does not.
#[test]
fn a_failing_cycle_ends_the_sweep_at_the_same_record_on_any_number_of_threads() {
    let model = biolever_on_mica();
    let mut settings = window(&model, 9.6, 7.0, 1.0);
    settings.integration.max_steps = 22;
    let outcome = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut sweep = Sweep::new(&model, settings.clone()).expect("sweep");
            let mut records = Vec::new();
            loop {
                match sweep.next_record() {
                    Ok(Some(record)) => records.push(record),
                    Ok(None) => panic!("the sweep did not fail"),
                    Err(error) => {
                        return (
                            records,
                            error.to_string(),
                            sweep.cycles_done(),
                            sweep.z_nm(),
                            sweep.state().to_vec(),
                        )
                    }
                }
            }
        })
    };
    let one = outcome(1);
    assert!(one.0.len() > 4096, "{} records", one.0.len());
    for threads in [2, 3] {
        assert!(outcome(threads) == one, "{threads} threads");
    }
}

/// A sweep whose records are far apart (every 35,000th of 37,200 cycles) returns each of them
/// on several threads, where a group of segments may hold no record at all (on 2 threads the
/// second group, cycles 16,384 to 32,768): the same two records as on one thread.
#[test]
fn records_far_apart_are_all_returned_on_several_threads() {
    let model = biolever_on_mica();
    let mut settings = window(&model, 9.0, 5.0, 1.0);
    settings.every = 35_000;
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| run(&model, settings.clone()))
    };
    let one = on(1);
    assert_eq!(
        one.iter().map(|record| record.cycle).collect::<Vec<_>>(),
        [0, 35_000]
    );
    assert!(on(2) == one);
}

/// Cases of the random sweeps: `DRUMROLL_SWEEP_CASES`, default 10 (about 6 s; 150 took
/// 110 s).
fn random_sweep_cases() -> u32 {
    std::env::var("DRUMROLL_SWEEP_CASES")
        .ok()
        .and_then(|cases| cases.parse().ok())
        .unwrap_or(10)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: random_sweep_cases(),
        ..Default::default()
    })]

    /// Random sweeps long enough for the segments (4,200 to 12,000 cycles a leg) of three
    /// cases (Hertz in water, the MAClever, JKR's pull-off hysteresis), with or without the
    /// retract, any block length, decimation and settling: the same records on 1, 2 and 3
    /// threads, and no panic.
    #[test]
    fn random_sweeps_give_the_same_records_on_any_number_of_threads(
        case in proptest::sample::select(vec!["biolever-mica", "maclever-mica", "biolever-sticky"]),
        from in 7.0..9.6f64,
        cycles in 4200.0..12000.0f64,
        lockin_cycles in 1usize..=4,
        every in 1usize..=50,
        retract in proptest::bool::ANY,
        settle_cycles in 0usize..=30,
    ) {
        let model = TappingModel::from_case(&builtin_case(case).expect("case")).expect("model");
        let mut settings = SweepSettings::for_model(&model);
        settings.from_nm = from;
        settings.to_nm = from - cycles * 1e-6 * model.period_us();
        settings.rate_nm_per_s = 1.0;
        settings.retract = retract;
        settings.lockin_cycles = lockin_cycles;
        settings.every = every;
        settings.settle_cycles = settle_cycles;
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| {
                    Sweep::new(&model, settings.clone())
                        .expect("sweep")
                        .map(|record| record.map_err(|error| error.to_string()))
                        .collect::<Vec<_>>()
                })
        };
        let one = on(1);
        proptest::prop_assert!(!one.is_empty());
        for threads in [2, 3] {
            proptest::prop_assert!(on(threads) == one, "{} threads", threads);
        }
    }
}
